#!/usr/bin/env bash
# rsmooth --max-memory and rsmooth-mpi end to end: the streamed result against the in-memory one
# (rsmooth compare: RMS and Hausdorff distance, in mean edge lengths), rsmooth-mpi on 1, 2 and 3
# ranks against the single process byte for byte, the refusals with their exit status, a full disk
# named, and no temporary or partial file left behind.
# usage: test_stream_command.sh RSMOOTH SHAPE [RSMOOTH_MPI MPIRUN]
set -uo pipefail
rsmooth=$1
shape=$2
mpi=${3:-}
mpirun=${4:-}
. "$(dirname "$0")/command_util.sh"

expect 0 "$shape" make noisy.ply truth.ply --noise 0.3 --triangles 60000
# the pieces do not run the fold guard yet: the in-memory result to match is the unguarded one
expect 0 "$rsmooth" noisy.ply -o memory.ply -q --no-guard
# 60k triangles hold about 12 MB in memory; 10 MB of cap cut them into pieces
expect 0 "$rsmooth" noisy.ply -o streamed.ply --max-memory 10M --json
grep -q "fold guard does not run on pieces" err.txt || fail "no word of the fold guard: $(cat err.txt)"
pieces=$(grep -o '"pieces":[0-9]*' out.txt | head -1 | cut -d: -f2)
echo "streamed in $pieces pieces: $(cat err.txt)"
[ "${pieces:-0}" -ge 2 ] || fail "--max-memory 10M did not cut 60k triangles into pieces"
expect 0 "$rsmooth" compare streamed.ply memory.ply --json
read -r rms hausdorff edge diag < <(sed 's/[{}",:]/ /g' out.txt |
  awk '{ for (i = 1; i < NF; i++) v[$i] = $(i + 1); print v["rms_v"], v["hausdorff"], v["mean_edge"], v["bbox_diag"] }')
worst=$(awk -v h="$hausdorff" -v d="$diag" -v e="$edge" 'BEGIN { printf "%.3g", h * d / 1000 / e }')
echo "streamed vs in memory: rms $rms, Hausdorff $worst mean edge lengths"
awk -v r="$rms" -v w="$worst" 'BEGIN { exit !(r <= 1e-6 && w <= 1e-6) }' ||
  fail "streamed result differs from the in-memory one by more than 1e-6 mean edge lengths"
cmp -s streamed.ply memory.ply || fail "the streamed file is not the in-memory one byte for byte"
expect 0 "$rsmooth" noisy.ply -o reference_memory.ply --device reference -q --no-guard
expect 0 "$rsmooth" noisy.ply -o reference_streamed.ply --device reference --max-memory 10M -q
cmp -s reference_memory.ply reference_streamed.ply ||
  fail "the reference path streamed is not the in-memory file byte for byte"

# what needs the whole mesh is refused before any work, with the usage status
for option in --auto "--best --stage learned" --stats "--method taubin" \
              "--confidence c.ply" --ascii "--format obj"; do
  # shellcheck disable=SC2086
  expect 2 "$rsmooth" noisy.ply -o refused.ply --max-memory 64M $option
  grep -q "max-memory" err.txt || fail "$option under --max-memory: $(cat err.txt)"
done
expect 2 "$rsmooth" noisy.ply -o refused.obj --max-memory 64M
grep -q "name the output .ply" err.txt || fail "-o .obj under --max-memory: $(cat err.txt)"
# vertices thrown 1000 edges off: outliers, which the pieces do not keep apart yet
expect 0 "$rsmooth" noise noisy.ply thrown.ply --sigma 1000 --impulsive 0.0005
expect 2 "$rsmooth" thrown.ply -o refused.ply --max-memory 64M
grep -q "far off the surface" err.txt || fail "outliers under --max-memory: $(cat err.txt)"
[ ! -e refused.ply ] || fail "a refused stream left refused.ply"
expect 2 "$rsmooth" noisy.ply -o refused.ply --tmpdir .
grep -q "give --max-memory" err.txt || fail "--tmpdir alone: $(cat err.txt)"
expect 2 "$rsmooth" - -o refused.ply --max-memory 64M < noisy.ply
expect 0 "$rsmooth" noisy.ply -o ascii.ply --ascii -q
expect 2 "$rsmooth" ascii.ply -o refused.ply --max-memory 64M
grep -q "binary PLY only" err.txt || fail "ascii input: $(cat err.txt)"
expect 0 "$rsmooth" noisy.ply -o noisy.obj -q
expect 2 "$rsmooth" noisy.obj -o refused.ply --max-memory 64M
grep -q "not a PLY file.*bytes of memory per triangle" err.txt || fail "OBJ input: $(cat err.txt)"
expect 1 "$rsmooth" noisy.ply -o refused.ply --max-memory 1M
grep -q "give at least" err.txt || fail "too small a cap: $(cat err.txt)"
expect 2 "$rsmooth" noisy.ply -o streamed.ply --max-memory 64M
grep -q "exists" err.txt || fail "existing output: $(cat err.txt)"
[ ! -e refused.ply ] && [ ! -e refused.obj ] || fail "a refused run wrote its output"
mkdir -p scratch
expect 0 "$rsmooth" noisy.ply -o streamed.ply --max-memory 10M --tmpdir scratch --force -q
[ -z "$(ls -A scratch)" ] || fail "temporary files left in --tmpdir: $(ls -A scratch)"

# killed mid-run (SIGTERM, and even SIGKILL), a run leaves neither its output nor a temporary file:
# every file it makes is unnamed until the output is named at the end
mkdir -p killed
expect 0 "$shape" make killed/big.ply killed/big_truth.ply --noise 0.3 --triangles 400000
for signal in TERM KILL; do  # (a background job ignores SIGINT)
  "$rsmooth" killed/big.ply -o killed/out.ply --max-memory 20M -q &
  pid=$!
  sleep 0.3 # into the work (about 1.5 s of it on 2 cores)
  kill -"$signal" "$pid" 2>/dev/null || fail "the run ended before SIG$signal could stop it"
  wait "$pid" 2>/dev/null
  [ $? -gt 128 ] || fail "the run was not ended by SIG$signal"
  left=$(ls -A killed | grep -v '^big' || true)
  [ -z "$left" ] || fail "killed with SIG$signal, it left: $left"
done

# a full disk (a limit on the size of the files it writes stands in for one, SIGXFSZ ignored): the
# run stops with the folder's name in its message, leaving no temporary and no output. 2 MB: the
# triangles' file fills it; 6 MB: the pieces' lists do (the reference path: no kernel cache is
# written either)
mkdir -p full
for limit in 2000 6000; do # (bash's ulimit -f counts KB)
  (
    trap '' XFSZ
    ulimit -f "$limit"
    exec "$rsmooth" killed/big.ply -o full/out.ply --max-memory 20M --tmpdir full \
      --device reference -q
  ) >out.txt 2>err.txt
  got=$?
  [ "$got" -eq 2 ] || fail "a full disk ($limit KB): exit $got -- $(cat err.txt)"
  grep -q "cannot write a temporary file in full (disk full?)" err.txt ||
    fail "a full disk ($limit KB): $(cat err.txt)"
  [ -z "$(ls -A full)" ] || fail "a full disk ($limit KB) left: $(ls -A full)"
  echo "a full disk at $limit KB: $(cat err.txt)"
done

if [ -n "$mpi" ]; then
  export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 # CI runs as root
  # Under AddressSanitizer (make sanitize), Open MPI's own allocations, many from components it
  # has unloaded by exit, read as leaks that no suppression can name; leaks of rsmooth's own code
  # on this path are checked without MPI (test_stream runs 3 ranks as threads).
  export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"
  for n in 1 2 3; do
    expect 0 "$mpirun" -n "$n" --oversubscribe "$mpi" noisy.ply -o "mpi$n.ply" --max-memory 10M
    grep -q "over $n ranks" err.txt || fail "rsmooth-mpi -n $n: $(cat err.txt)"
    cmp -s streamed.ply "mpi$n.ply" && echo "rsmooth-mpi on $n ranks: the single process's bytes" ||
      fail "rsmooth-mpi on $n ranks differs from rsmooth --max-memory"
  done
  # bilateral normals widen the halo: still the single process's bytes
  expect 0 "$rsmooth" noisy.ply -o bilateral.ply --max-memory 10M --normals bilateral -q
  expect 0 "$mpirun" -n 3 --oversubscribe "$mpi" noisy.ply -o mpi_bilateral.ply --max-memory 10M \
    --normals bilateral -q
  cmp -s bilateral.ply mpi_bilateral.ply ||
    fail "rsmooth-mpi --normals bilateral differs from rsmooth --max-memory"
  expect 2 "$mpirun" -n 2 --oversubscribe "$mpi" noisy.ply -o refused.ply --auto
  grep -q "max-memory" err.txt || fail "rsmooth-mpi --auto: $(cat err.txt)"
  ls ./*partial* >/dev/null 2>&1 && fail "a partial output was left behind"
fi

# ---- The streamed file is the in-memory command's, byte for byte, and
# what the in-memory writer refuses is refused with its status and message, nothing written.
# header_end FILE: bytes up to and with the 'end_header' line
header_end() { echo $(($(grep -a -b -m1 '^end_header' "$1" | cut -d: -f1) + 11)); }
# agree NAME INPUT [OPTIONS]: both runs exit 0 and write the same bytes (streamed under
# AGREE_CAP, 10M unless set)
agree() {
  local name=$1 input=$2; shift 2
  rm -f "agree_$name.memory.ply" "agree_$name.streamed.ply"
  expect 0 "$rsmooth" "$input" -o "agree_$name.memory.ply" -q "$@"
  expect 0 "$rsmooth" "$input" -o "agree_$name.streamed.ply" --max-memory "${AGREE_CAP:-10M}" \
    -q "$@"
  cmp -s "agree_$name.memory.ply" "agree_$name.streamed.ply" &&
    echo "$name: streamed = in memory, $(wc -c < "agree_$name.memory.ply") bytes" ||
    fail "$name: the streamed file differs from the in-memory one"
}
# grid_ply OUT TYPE SCALE COMMENT [TOP]: an ascii PLY of a 24 x 24 grid with bumps, coordinates
# times SCALE, of TYPE (float, double), with a comment line when COMMENT is 1; TOP: a plateau at
# that height with a third of its vertices 10% lower (the tilted planes of their triangles reach
# past it), made binary by 'rsmooth noise --sigma 0' (positions as read)
grid_ply() {
  awk -v type="$2" -v s="$3" -v comment="$4" -v top="${5:-0}" 'BEGIN {
    n = 24; print "ply"; print "format ascii 1.0"; if (comment) print "comment grid"
    print "element vertex " n * n
    print "property " type " x"; print "property " type " y"; print "property " type " z"
    print "element face " 2 * (n - 1) * (n - 1); print "property list uchar int vertex_indices"
    print "end_header"
    for (j = 0; j < n; j++) for (i = 0; i < n; i++) {
      h = sin(i * 12.9898 + j * 78.233) * 43758.5453; h -= int(h); h -= 0.5
      if (top) printf "%.9g %.9g %.9g\n", i * 0.02 * top, j * 0.02 * top, ((7 * i + 3 * j) % 3 ? top : 0.9 * top)
      else printf "%.17g %.17g %.17g\n", i * 0.1 * s, j * 0.1 * s, 0.05 * h * s
    }
    for (j = 0; j < n - 1; j++) for (i = 0; i < n - 1; i++) {
      a = j * n + i; print 3, a, a + 1, a + n + 1; print 3, a, a + n + 1, a + n
    }
  }' > "$1.txt"
  expect 0 "$rsmooth" noise "$1.txt" "$1" --sigma 0 -q --force
}
grid_ply grid.ply double 1 0
header=$(header_end grid.ply)
# (a) a PLY with no comment: the in-memory writer adds "comment written by rsmooth"
{ head -c "$header" grid.ply | grep -av '^comment'; tail -c +"$((header + 1))" grid.ply; } > bare.ply
grep -aq '^comment' bare.ply && fail "bare.ply kept a comment"
agree no_comment bare.ply
# (b) a byte-order mark, which the in-memory writer keeps
{ printf '\357\273\277'; cat bare.ply; } > bom.ply
agree byte_order_mark bom.ply
# (c) a header over 1 MB, with 'end_header' inside a comment before its end
head -c 1200000 /dev/zero | tr '\0' x | sed 's/^/comment /' > long_comment.txt
echo >> long_comment.txt
{ head -c "$header" grid.ply | head -n 2; echo "comment the end_header line comes later"
  cat long_comment.txt; head -c "$header" grid.ply | tail -n +3
  tail -c +"$((header + 1))" grid.ply; } > long_header.ply
agree long_header long_header.ply
# (d) double coordinates at 1e-300: the mean area (1e-602) has no double in the mesh's units
grid_ply tiny.ply double 1e-300 1
agree tiny_double tiny.ply
agree tiny_double_reference tiny.ply --device reference
# (e) a negative list count in an element before the vertices: the in-memory reader's refusal
awk 'NR == 3 { print "element extra 1"; print "property list char int data" } { print }
     /^end_header/ { print "3 1 2 3" }' grid.ply.txt > extra.txt
expect 0 "$rsmooth" noise extra.txt extra.ply --sigma 0 -q
printf '\375' | dd of=extra.ply bs=1 seek="$(header_end extra.ply)" conv=notrunc 2>/dev/null
expect 2 "$rsmooth" extra.ply -o refused.ply -q
memory=$(cat err.txt)
expect 2 "$rsmooth" extra.ply -o refused.ply --max-memory 10M -q
[ "$(cat err.txt)" = "$memory" ] && echo "negative count: $memory" ||
  fail "negative list count: streamed '$(cat err.txt)', in memory '$memory'"
# (f) passes, each streamed from the one before, their confidence rule and a mask: the in-memory
# bytes (the guard off, as on pieces); a mask naming a vertex the file lacks is refused, naming it
seq 0 4 29000 > m.txt
agree passes noisy.ply --no-guard --passes 3 --pass-confidence 0.6 --mask m.txt
# (g) the best mode: the normal update stage a step per cycle, then its robust pass (end to end:
# the stage's halo holds this small mesh in each piece; test_stream cuts a larger one)
AGREE_CAP=48M agree best noisy.ply --no-guard --best
echo 99999 > bad_mask.txt
expect 2 "$rsmooth" noisy.ply -o refused.ply --max-memory 10M --mask bad_mask.txt
grep -q "bad_mask.txt" err.txt || fail "a mask index out of range: $(cat err.txt)"
[ ! -e refused.ply ] || fail "a refused mask left refused.ply"
if [ -n "$mpi" ]; then # the ranks write the same file
  rm -f mpi_passes.ply
  expect 0 "$mpirun" -n 2 --oversubscribe "$mpi" noisy.ply -o mpi_passes.ply --max-memory 10M -q \
    --no-guard --passes 3 --pass-confidence 0.6 --mask m.txt
  cmp -s mpi_passes.ply agree_passes.memory.ply &&
    echo "rsmooth-mpi -n 2, 3 passes with a mask: the in-memory bytes" ||
    fail "rsmooth-mpi -n 2 with passes and a mask differs from the in-memory file"
  rm -f mpi_best.ply
  expect 0 "$mpirun" -n 2 --oversubscribe "$mpi" noisy.ply -o mpi_best.ply --max-memory 48M -q \
    --no-guard --best
  cmp -s mpi_best.ply agree_best.memory.ply &&
    echo "rsmooth-mpi -n 2, the best mode: the in-memory bytes" ||
    fail "rsmooth-mpi -n 2 --best differs from the in-memory file"
  for pair in bom.ply:byte_order_mark tiny.ply:tiny_double; do
    input=${pair%%:*} name=${pair#*:}
    rm -f "mpi_$input"
    expect 0 "$mpirun" -n 2 --oversubscribe "$mpi" "$input" -o "mpi_$input" --max-memory 10M -q
    cmp -s "mpi_$input" "agree_$name.memory.ply" ||
      fail "rsmooth-mpi -n 2 on $input differs from the in-memory file"
  done
fi
# 4. float32 results beyond FLT_MAX, and a float32 mesh at 1e-44 (subnormal): refused as in
# memory, exit 1, the same message (the scale the streamed check holds float32 to is the input's
# largest coordinate, known before any piece: the figure it prints after "largest" may differ)
grid_ply plateau.ply float 1 1 3.40282347e38
grid_ply subnormal.ply float 1e-43 1
for input in plateau.ply subnormal.ply; do
  rm -f refused.ply
  expect 1 "$rsmooth" "$input" -o refused.ply -q
  memory=$(sed 's/(largest [^)]*)//' err.txt)
  expect 1 "$rsmooth" "$input" -o refused.ply --max-memory 10M -q
  [ "$(sed 's/(largest [^)]*)//' err.txt)" = "$memory" ] && echo "$input: $memory" ||
    fail "$input: streamed '$(cat err.txt)', in memory '$memory'"
  [ ! -e refused.ply ] || fail "$input: a refused streamed run wrote its output"
done

# A width whose reach overflows (--sigma-f 1e308): refused alike in memory (it left every vertex
# where it was, exit 0) and streamed (a halo of inf), on both paths.
for device in reference cpu; do
  expect 2 "$rsmooth" noisy.ply -o refused.ply --sigma-f 1e308 --cutoff 5 --device "$device"
  grep -q "range of numbers" err.txt || fail "--sigma-f 1e308 on $device: $(cat err.txt)"
  expect 2 "$rsmooth" noisy.ply -o refused.ply --sigma-f 1e308 --cutoff 5 --device "$device" \
    --max-memory 64M
  [ ! -e refused.ply ] || fail "--sigma-f 1e308 on $device wrote its output"
done
# A finite reach thousands of times the mesh's size: the device's float sums lost the result
# (0.14 edge lengths off, exit 0; nothing moved from sigma_f 1e20): refused there, in memory and
# streamed; the reference path runs it.
expect 0 "$shape" make wide.ply wide_truth.ply --noise 0.3 --triangles 2000
for extra in "" "--max-memory 64M"; do
  # shellcheck disable=SC2086
  expect 2 "$rsmooth" wide.ply -o refused.ply --sigma-f 1e5 --cutoff 5 --device cpu $extra
  grep -q "times the mesh's size" err.txt || fail "--sigma-f 1e5 $extra on the device: $(cat err.txt)"
  # shellcheck disable=SC2086
  expect 0 "$rsmooth" wide.ply -o wide_ref.ply --sigma-f 1e5 --cutoff 5 --device reference $extra --force
done

[ "$failures" -eq 0 ] && echo ok
exit "$((failures > 0))"
