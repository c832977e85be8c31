#!/usr/bin/env bash
# Every command shown in README.md, docs/*.md and docs/maintainers/*.md runs. The convention, for
# whoever writes docs:
#   - every line of a ```sh block is a command (a line ending in \ continues on the next; blank
#     lines and lines starting with # are not commands);
#   - the commands of a block run in order, with bash, in a fresh folder holding the inputs the
#     docs name (scan.ply, scan.obj, part.stl, clean.ply, cloud.ply, a.obj, b.ply, c.stl, scans/,
#     selected.txt: a small generated shape), with this build's rsmooth, rsmooth-demo-shape,
#     rsmooth-bench, rsmooth-big-mesh and rsmooth-mpi first on PATH and build/ naming the build;
#   - a block that cannot run here (it needs data outside the repository, an install, MPI ranks,
#     or minutes) is preceded by the line <!-- docs-test: skip (REASON) --> and its commands are
#     counted as skipped.
# Fails naming the file and line of each command that exits non-zero (or runs past 120 s), and of
# each skip marker without a reason or without a ```sh block after it.
# usage: test_docs_commands.sh BUILD/rsmooth SOURCE_DIR
set -uo pipefail
rsmooth=$1
source_dir=$2
build_dir=$(cd "$(dirname "$rsmooth")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

# The tools under the names the docs use.
mkdir -p "$work/bin"
for tool in rsmooth rsmooth-demo-shape rsmooth-bench rsmooth-big-mesh rsmooth-mpi; do
  [ -x "$build_dir/$tool" ] && ln -s "$build_dir/$tool" "$work/bin/$tool"
done
ln -sf "$(cd "$(dirname "$rsmooth")" && pwd)/$(basename "$rsmooth")" "$work/bin/rsmooth"
export PATH="$work/bin:$PATH"

# The inputs: a small noisy cylinder and its truth, in every format, and a point cloud.
fixtures=$work/fixtures
mkdir -p "$fixtures/scans" && cd "$fixtures" || exit 1
quiet() { "$@" >/dev/null 2>"$work/fixture.err" || { cat "$work/fixture.err"; echo "FAIL: $*"; exit 1; }; }
quiet rsmooth-demo-shape make scan.ply clean.ply --triangles 2000 --noise 0.3 --seed 1
quiet rsmooth scan.ply -o scan.obj --method taubin --iterations 0 -q
quiet rsmooth scan.ply -o part.stl --method taubin --iterations 0 -q
cp scan.obj a.obj && cp scan.ply b.ply && cp part.stl c.stl
cp scan.ply scans/one.ply && cp clean.ply scans/two.ply
seq 0 99 >selected.txt
awk 'BEGIN { srand(3); n = 30; print "ply\nformat ascii 1.0\nelement vertex " n * n
             print "property float x\nproperty float y\nproperty float z"
             print "property float nx\nproperty float ny\nproperty float nz\nend_header"
             for (i = 0; i < n; i++) for (j = 0; j < n; j++)
               printf "%d %d %.4f 0 0 1\n", i, j, 0.3 * (rand() - 0.5) }' >cloud.ply

# Lists the blocks as records: FILE<TAB>LINE<TAB>SKIP<TAB>COMMAND (SKIP: the reason, or "-"),
# and BLOCK<TAB>FILE<TAB>LINE between blocks; bad markers as ERROR<TAB>FILE<TAB>LINE<TAB>WHY.
extract() {
  awk -v file="$1" '
    function flush() { if (cmd != "") { printf "%s\t%d\t%s\t%s\n", file, cmdline, skip, cmd; cmd = "" } }
    /^<!-- docs-test: skip/ {
      if (pending != "") printf "ERROR\t%s\t%d\tmarker without a sh block after it\n", file, markerline
      reason = $0; sub(/^<!-- docs-test: skip */, "", reason); sub(/ *-->$/, "", reason)
      if (reason !~ /^\(.+\)$/) printf "ERROR\t%s\t%d\tskip marker without a (reason)\n", file, NR
      pending = reason; markerline = NR; next }
    !inside && /^```/ {
      inside = 1; shell = ($0 ~ /^```(sh|bash)$/)
      if (pending != "" && !shell) printf "ERROR\t%s\t%d\tmarker before a block that is not sh\n", file, markerline
      skip = pending == "" ? "-" : pending; pending = ""
      if (shell) printf "BLOCK\t%s\t%d\n", file, NR
      next }
    inside && /^```$/ { flush(); inside = 0; next }
    inside && shell {
      if (cmd == "") { if ($0 ~ /^[ \t]*(#|$)/) next; cmdline = NR; cmd = $0 } else cmd = cmd "\037" $0
      if ($0 !~ /\\$/) flush()
      next }
    pending != "" && !/^[ \t]*$/ {
      printf "ERROR\t%s\t%d\tmarker without a sh block after it\n", file, markerline; pending = "" }
    END { if (pending != "") printf "ERROR\t%s\t%d\tmarker without a sh block after it\n", file, markerline }
  ' "$source_dir/$1"
}

ran=0 skipped=0 blocks=0 files=0 block_dir=
cd "$source_dir" || exit 1
docs=(README.md docs/*.md docs/maintainers/*.md)
cd "$work" || exit 1
for doc in "${docs[@]}"; do
  files=$((files + 1))
  while IFS=$'\t' read -r file line skip command; do
    if [ "$file" = ERROR ]; then
      fail "$line:$skip: $command"
      continue
    fi
    if [ "$file" = BLOCK ]; then # a fresh folder for each block
      blocks=$((blocks + 1))
      block_dir=$work/block$blocks
      cp -r "$fixtures" "$block_dir" && ln -s "$build_dir" "$block_dir/build"
      continue
    fi
    command=${command//$'\037'/$'\n'} # continued lines
    if [ "$skip" != - ]; then
      skipped=$((skipped + 1))
      continue
    fi
    ran=$((ran + 1))
    (cd "$block_dir" && timeout -k 5 120 bash -c "$command" </dev/null >"$work/out.txt" 2>"$work/err.txt")
    status=$?
    if [ "$status" -ne 0 ]; then
      fail "$file:$line: exit $status: $command"
      tail -n 5 "$work/err.txt" | sed 's/^/    /'
    fi
  done < <(extract "$doc")
done

echo "docs_commands: $ran commands run, $skipped skipped (marked), in $blocks sh blocks of $files files"
[ "$ran" -gt 0 ] || fail "no command found to run in README.md and docs/*.md"
[ "$failures" -eq 0 ] || { echo "$failures failure(s)"; exit 1; }
echo "every command shown in README.md and docs/*.md ran"
