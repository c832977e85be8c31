#!/usr/bin/env bash
# rsmooth-mpi refuses ranks that were not given the same job: two ranks
# started with different --max-memory (different pieces: 12,800 of 50,625 vertices were left
# unsmoothed), a different input file, different parameters, a different output or --mask: each
# exits 2, names rank 1 and what differs, and writes nothing. A different --device per rank (MPMD) is
# allowed and gives the single process's bytes.
# usage: test_mpi_agree.sh RSMOOTH SHAPE RSMOOTH_MPI MPIRUN
set -uo pipefail
rsmooth=$1
shape=$2
mpi=$3
mpirun=$4
. "$(dirname "$0")/command_util.sh"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 # CI runs as root
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0" # see test_stream_command.sh

expect 0 "$shape" make in.ply truth.ply --noise 0.3 --triangles 100000
expect 0 "$rsmooth" in.ply -o single.ply --max-memory 12M -q
expect 0 "$shape" make other.ply other_truth.ply --noise 0.2 --triangles 100000

# mpmd RANK0-ARGS -- RANK1-ARGS: one rank each, with their own arguments
mpmd() {
  local first=() second=()
  while [ "$1" != -- ]; do first+=("$1"); shift; done
  shift
  second=("$@")
  "$mpirun" --oversubscribe -n 1 "$mpi" "${first[@]}" : -n 1 "$mpi" "${second[@]}"
}

# each case: rank 0's arguments, rank 1's, and the part the message must name
check_refused() {
  local what=$1; shift
  expect 2 mpmd "$@"
  grep -q "rank 1 was not given what rank 0 was: it differs in.*$what" err.txt ||
    fail "$*: not refused for $what: $(cat err.txt)"
  if [ -e out.ply ]; then fail "$*: wrote out.ply"; rm -f out.ply; fi
}
base=(-o out.ply --max-memory 12M)
check_refused "--max-memory" in.ply "${base[@]}" -- in.ply -o out.ply --max-memory 24M
check_refused "the input file" in.ply "${base[@]}" -- other.ply "${base[@]}"
cp -p in.ply copy.ply # the same bytes, another time: another file as far as anyone can tell
touch -d '2001-01-01' copy.ply
check_refused "the input file" in.ply "${base[@]}" -- copy.ply "${base[@]}"
check_refused "the parameters" in.ply "${base[@]}" -- in.ply "${base[@]}" --sigma-f 3
check_refused "the parameters" in.ply "${base[@]}" -- in.ply "${base[@]}" --normals bilateral
check_refused "the output" in.ply "${base[@]}" -- in.ply -o elsewhere.ply --max-memory 12M
# each rank reads --mask: another list on one rank, or a mask on one rank only, would smooth a
# mesh neither asked for
seq 0 3 40000 > mask_a.txt
seq 1 3 40000 > mask_b.txt
check_refused "--mask" in.ply "${base[@]}" --mask mask_a.txt -- in.ply "${base[@]}" --mask mask_b.txt
check_refused "--mask" in.ply "${base[@]}" --mask mask_a.txt -- in.ply "${base[@]}"
[ -e elsewhere.ply ] && fail "a refused run wrote elsewhere.ply"
left=$(ls -A | grep '^\.rsmooth' || true)
[ -z "$left" ] || fail "refused runs left: $left"

# --device may differ per rank (here two names of one device); --quiet too: the single process's bytes
expect 0 mpmd in.ply -o mpmd.ply --max-memory 12M --device auto -- in.ply -o mpmd.ply \
  --max-memory 12M --device cpu -q
cmp -s mpmd.ply single.ply || fail "ranks with different --device differ from one process"

[ "$failures" -eq 0 ] && echo "mpi_agree: all checks passed" || echo "$failures failure(s)"
exit $((failures > 0))
