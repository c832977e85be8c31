#!/usr/bin/env bash
# One way of writing an output file for all three writers: the
# in-memory command, the streamed command (--max-memory) and rsmooth-mpi on 2 ranks, each checked
# the same way: a replaced file keeps its mode, owner and group (also --in-place); the hard-link
# warning; -o LINK --force writes through the link; a FIFO or device is never replaced; output
# names of 250 bytes; a file that appears while the run works is never replaced without --force;
# two MPI runs to one new name: one wins, nothing is lost; SIGTERM between naming the temporary and
# renaming it leaves no temporary and the old file whole; --tmpdir '' and an overlong --tmpdir
# are refused.
# usage: test_output_command.sh RSMOOTH SHAPE [RSMOOTH_MPI MPIRUN]
set -uo pipefail
rsmooth=$1
shape=$2
mpi=${3:-}
mpirun=${4:-}
. "$(dirname "$0")/command_util.sh"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 # CI runs as root
# Open MPI's own allocations read as leaks under AddressSanitizer (see test_stream_command.sh)
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"
root=false
[ "$(id -u)" -eq 0 ] && root=true

expect 0 "$shape" make in.ply truth.ply --noise 0.3 --triangles 3000
expect 0 "$rsmooth" in.ply -o expected.ply -q

writers="memory stream"
[ -n "$mpi" ] && writers="$writers mpi"
# run WRITER ARGS...: smooths with that writer (a script of its own, so timeout can run it)
cat >run.sh <<RUN
#!/usr/bin/env bash
writer=\$1; shift
case \$writer in
  memory) exec "$rsmooth" "\$@" ;;
  stream) exec "$rsmooth" --max-memory "\${CAP:-10M}" "\$@" ;;
  mpi) exec "$mpirun" -n 2 --oversubscribe "$mpi" --max-memory "\${CAP:-10M}" "\$@" ;;
esac
RUN
chmod +x run.sh
run() { ./run.sh "$@"; }
mode_owner() { stat -c '%a %u %g' "$1"; }

for w in $writers; do
  # a replaced file keeps its mode, owner and group; -o and --in-place alike
  cp expected.ply "$w-old.ply"
  chmod 600 "$w-old.ply"
  $root && chown 65534:65534 "$w-old.ply"
  before=$(mode_owner "$w-old.ply")
  expect 0 run "$w" in.ply -o "$w-old.ply" --force -q
  [ "$(mode_owner "$w-old.ply")" = "$before" ] ||
    fail "$w: --force made $before into $(mode_owner "$w-old.ply")"
  cmp -s "$w-old.ply" expected.ply || fail "$w: --force result differs from the in-memory one"
  cp in.ply "$w-inplace.ply"
  chmod 640 "$w-inplace.ply"
  $root && chown 65534:65534 "$w-inplace.ply"
  before=$(mode_owner "$w-inplace.ply")
  expect 0 run "$w" "$w-inplace.ply" --in-place -q
  [ "$(mode_owner "$w-inplace.ply")" = "$before" ] ||
    fail "$w: --in-place made $before into $(mode_owner "$w-inplace.ply")"
  cmp -s "$w-inplace.ply" expected.ply || fail "$w: --in-place result differs"

  # other hard links keep the old content, and the user is told
  cp in.ply "$w-linked.ply"
  ln "$w-linked.ply" "$w-other-name.ply"
  expect 0 run "$w" in.ply -o "$w-linked.ply" --force
  grep -q "$w-linked.ply: warning: the file has 2 hard links" err.txt ||
    fail "$w: no hard-link warning: $(cat err.txt)"
  cmp -s "$w-other-name.ply" in.ply || fail "$w: the other hard link changed"
  cmp -s "$w-linked.ply" expected.ply || fail "$w: the named link did not get the result"

  # -o LINK --force writes through the link, which stays
  cp in.ply "$w-target.ply"
  ln -s "$w-target.ply" "$w-link.ply"
  expect 0 run "$w" in.ply -o "$w-link.ply" --force -q
  [ -L "$w-link.ply" ] || fail "$w: -o LINK --force replaced the link by a file"
  cmp -s "$w-target.ply" expected.ply || fail "$w: the link's target did not get the result"

  # a FIFO (and, as root, a device node) is never replaced, even with --force
  mkfifo "$w-fifo.ply"
  expect_within 60 2 ./run.sh "$w" in.ply -o "$w-fifo.ply" --force
  grep -q "$w-fifo.ply: is not a regular file" err.txt || fail "$w: FIFO output: $(cat err.txt)"
  [ -p "$w-fifo.ply" ] || fail "$w: the FIFO was replaced"
  if $root; then
    mknod "$w-null.ply" c 1 3
    expect 2 run "$w" in.ply -o "$w-null.ply" --force
    [ -c "$w-null.ply" ] || fail "$w: a device node was replaced by a regular file"
  fi

  # an output name of 250 bytes (the usual limit is 255), new and replaced
  long=$w-$(printf 'x%.0s' $(seq 1 240)).ply
  expect 0 run "$w" in.ply -o "$long" -q
  expect 0 run "$w" in.ply -o "$long" --force -q
  cmp -s "$long" expected.ply || fail "$w: a 250-byte output name: $(cat err.txt)"
  rm -f "$long"

  # --tmpdir must name a folder: '' is not one (it put temporaries in /), nor are 5000 bytes
  if [ "$w" != memory ]; then
    expect 2 run "$w" in.ply -o "$w-tmp.ply" --tmpdir ''
    grep -q "tmpdir" err.txt || fail "$w: --tmpdir '': $(cat err.txt)"
    expect 2 run "$w" in.ply -o "$w-tmp.ply" --tmpdir "/$(printf 'd%.0s' $(seq 1 5000))"
    grep -q "tmpdir" err.txt || fail "$w: a 5000-byte --tmpdir: $(cat err.txt)"
    [ -e "$w-tmp.ply" ] && fail "$w: an output written after a bad --tmpdir"
  fi
done

# A file that appears while the run works is never replaced without --force (the run fails and
# says so): a mesh big enough to take a while, and the output made as soon as the run's named
# file is seen (the streamed run's copy, named by RSMOOTH_NAMED_TEMPORARY=1; the ranks' partial
# file). The in-memory command's race is test_command.sh's.
expect 0 "$shape" make big.ply big_truth.ply --noise 0.3 --triangles 300000
export CAP=32M
for w in ${writers#memory }; do
  mkdir "appear-$w"
  RSMOOTH_NAMED_TEMPORARY=1 ./run.sh "$w" big.ply -o "appear-$w/out.ply" -q >/dev/null 2>"appear-$w.err" &
  pid=$!
  for _ in $(seq 1 1000); do
    compgen -G "appear-$w/.rsmooth-*" >/dev/null && break
    sleep 0.01
  done
  compgen -G "appear-$w/.rsmooth-*" >/dev/null || fail "$w: the run's named file never appeared"
  echo precious >"appear-$w/out.ply"
  wait "$pid"
  status=$?
  [ "$status" -eq 2 ] || fail "$w: a file made during the run: exit $status: $(cat "appear-$w.err")"
  [ "$(cat "appear-$w/out.ply")" = precious ] || fail "$w: a file made during the run was replaced"
  grep -q "already exists: another program created it while this run was working" "appear-$w.err" ||
    fail "$w: a file made during the run: $(cat "appear-$w.err")"
  left=$(ls -A "appear-$w" | grep -v '^out.ply$' || true)
  [ -z "$left" ] || fail "$w: left behind: $left"
done

# Two MPI runs to one new name: one writes it, the other fails; nothing else is left.
if [ -n "$mpi" ]; then
  mkdir twice
  ./run.sh mpi big.ply -o twice/out.ply -q >twice1.out 2>twice1.err &
  a=$!
  ./run.sh mpi big.ply -o twice/out.ply -q >twice2.out 2>twice2.err &
  b=$!
  wait "$a"; sa=$?
  wait "$b"; sb=$?
  [ $((sa == 0)) -ne $((sb == 0)) ] ||
    fail "two MPI runs to one name: exits $sa and $sb: $(cat twice1.err twice2.err)"
  left=$(ls -A twice | grep -v '^out.ply$' || true)
  [ -z "$left" ] || fail "two MPI runs to one name left: $left"
fi

# SIGTERM between naming the temporary and renaming it over the output (strace holds the run
# right after linkat returns): the temporary goes, the old output stays whole.
if command -v strace >/dev/null && strace -f -o /dev/null true 2>/dev/null; then
  for w in memory stream; do
    mkdir "window-$w"
    cp in.ply "window-$w/out.ply"
    strace -f -o /dev/null -e trace=linkat -e inject=linkat:delay_exit=3000000 \
      "$rsmooth" in.ply -o "window-$w/out.ply" --force -q $([ "$w" = stream ] && echo --max-memory 10M) &
    tracer=$!
    for _ in $(seq 1 1000); do
      compgen -G "window-$w/.rsmooth-*" >/dev/null && break
      sleep 0.01
    done
    compgen -G "window-$w/.rsmooth-*" >/dev/null || fail "$w: the linked temporary never appeared"
    pkill -TERM -P "$tracer"
    wait "$tracer"
    left=$(ls -A "window-$w" | grep -v '^out.ply$' || true)
    [ -z "$left" ] || fail "$w: SIGTERM between link and rename left: $left"
    cmp -s "window-$w/out.ply" in.ply || fail "$w: SIGTERM between link and rename damaged the output"
  done
else
  echo "(strace cannot trace here: the signal window is not tried)"
fi

[ "$failures" -eq 0 ] && echo "output_command: all checks passed" || echo "$failures failure(s)"
exit $((failures > 0))
