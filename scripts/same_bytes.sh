#!/usr/bin/env bash
# Prints a sha256 for each of a fixed set of rsmooth runs on generated shapes (every method and
# path the command has, the stream and MPI writers, compare, noise), so that two builds (before
# and after a change that must not change results) can be compared with diff:
#   scripts/same_bytes.sh build-old > old.txt; scripts/same_bytes.sh build > new.txt; diff old.txt new.txt
# Timings and versions are left out of what is hashed; the last line is rsmooth-bench filter's
# figures but its timings.
set -euo pipefail
build=$(cd "${1:-build}" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
export POCL_CACHE_DIR=$build/pocl-cache RSMOOTH_CACHE_DIR=$build/rsmooth-cache
"$build/rsmooth-demo-shape" make n.ply t.ply --noise 0.3 --triangles 8000 >/dev/null
"$build/rsmooth-demo-shape" make c.ply ct.ply --noise 0.5 --triangles 3000 --seed 7 >/dev/null
run() { # name, then the command's arguments after `rsmooth`; hashes the output file
  local name=$1
  shift
  if "$build/rsmooth" "$@" -o "$name.ply" -q --force >/dev/null 2>"$name.err"; then
    printf '%-28s %s\n' "$name" "$(sha256sum <"$name.ply" | cut -c1-16)"
  else
    printf '%-28s exit %d: %s\n' "$name" $? "$(head -c 200 "$name.err")"
  fi
}
for dev in reference cpu; do
  run "default-$dev" n.ply --device "$dev"
  run "best-$dev" n.ply --device "$dev" --best
  run "auto-$dev" n.ply --device "$dev" --auto
  run "bilateral-$dev" n.ply --device "$dev" --normals bilateral
  run "tukey-$dev" n.ply --device "$dev" --influence tukey
  run "passes3-$dev" n.ply --device "$dev" --passes 3
  run "coarse-$dev" c.ply --device "$dev"
  run "stream-$dev" n.ply --device "$dev" --max-memory 10M
  run "budget-$dev" n.ply --device "$dev" --memory-budget 1M
done
run taubin n.ply --method taubin
run laplacian n.ply --method laplacian
if command -v mpirun >/dev/null && [ -x "$build/rsmooth-mpi" ]; then
  OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun --oversubscribe -n 2 "$build/rsmooth-mpi" n.ply -o mpi.ply -q --device reference \
    --max-memory 10M >/dev/null 2>&1 && printf '%-28s %s\n' mpi-2 "$(sha256sum <mpi.ply | cut -c1-16)"
fi
printf '%-28s %s\n' compare "$("$build/rsmooth" compare default-reference.ply t.ply 2>&1 | sha256sum | cut -c1-16)"
printf '%-28s %s\n' noise "$("$build/rsmooth" noise n.ply 2>&1 | sha256sum | cut -c1-16)"
printf '%-28s %s\n' json "$("$build/rsmooth" n.ply -o j.ply --force --device reference --json 2>/dev/null |
  sed 's/"ms":{[^}]*}//' | sha256sum | cut -c1-16)"
# rsmooth-bench filter on a generated mesh: every field but timings, memory and cache states
printf '%-28s %s\n' bench "$("$build/rsmooth-bench" filter --triangles 20000 --repeat 2 --no-roofline 2>/dev/null |
  python3 -c '
import json, sys
skip = ("ms", "time", "per_s", "peak", "rss", "build", "cache", "bytes_per", "memory_budget")
def strip(x):
    return {k: strip(v) for k, v in x.items() if not any(t in k for t in skip)} if isinstance(x, dict) else x
print(json.dumps(strip(json.load(sys.stdin)), sort_keys=True))' | sha256sum | cut -c1-16)"
