#!/usr/bin/env bash
# The "Large meshes" benchmark (README): generated terrains of 4M, 16M and 100M triangles
# (rsmooth-big-mesh, binary PLY, float), each filtered in memory where it fits and under
# --max-memory, with the peak resident memory (GNU time), the wall time, the temporary disk the
# streaming run reports, how often it read the positions, and the capped result against the
# in-memory one (with --no-guard, as streaming has no fold guard yet; compare_ply_positions.py
# needs numpy); at 16M also a cap below the positions (MPI_CAP) and rsmooth-mpi on 1, 2 and 4
# ranks under it (each rank's bytes of the input read on stderr); at 4M the best mode (--best
# --no-guard) in memory and under the cap, byte for byte. Figures, not assertions: run it on a
# quiet machine.
#
# usage: scripts/large_meshes.sh BUILD WORKDIR [MAX_TRIANGLES_IN_MEMORY ["TRIANGLES:CAP ..."]
#        [MPI_CAP]]
#   BUILD    the build folder (rsmooth, rsmooth-big-mesh, rsmooth-mpi)
#   WORKDIR  where the meshes go (about 5 GB free for 100M triangles, 10 GB with the outputs)
set -euo pipefail
build=$(cd "$1" && pwd)
work=$2
in_memory_max=${3:-16000000}
sizes=${4:-"4000000:256M 16000000:512M 100000000:2G"}
mpi_cap=${5:-64M}
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$work"
cd "$work"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1

# run NAME COMMAND...: wall seconds and peak RSS (MB) into NAME.time; stderr kept in NAME.err
run() {
  local name=$1; shift
  /usr/bin/time -f "%e %M" -o "$name.time" "$@" >"$name.out" 2>"$name.err"
  read -r wall kb <"$name.time"
  echo "$wall $((kb / 1024))"
}

# capped NAME CAP: one streamed run of $mesh ($n triangles) and its table line
capped() {
  read -r wall rss < <(run "$1" "$build/rsmooth" "$mesh" -o "$1.ply" --force --max-memory "$2" --json)
  pieces=$(grep -o '"pieces":[0-9]*' "$1.out" | head -1 | cut -d: -f2)
  runs=$(grep -o '"position_runs":[0-9]*' "$1.out" | cut -d: -f2)
  temp=$(grep -o '"temporary_bytes":[0-9]*' "$1.out" | cut -d: -f2)
  versus=""
  if [ -n "$edge" ]; then
    versus=$(python3 "$here/compare_ply_positions.py" "$1.ply" mem$n.ply "$edge")
  fi
  echo "| $n | --max-memory $2 | $wall | $rss | $pieces | $runs | $((temp >> 20)) | $versus |"
  grep "streamed" "$1.err" | sed 's/^/    /' >&2
}

echo "| triangles | run | wall s | peak RSS MB | pieces | position runs | temporary MB | vs in memory |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- |"
"$build/rsmooth-big-mesh" tiny.ply --triangles 1000 --force 2>/dev/null
read -r wall rss < <(run tiny "$build/rsmooth" tiny.ply -o tiny_out.ply --force --max-memory 64M)
echo "| 1000 | --max-memory 64M (the runtime's own memory) | $wall | $rss | | | | |"
for spec in $sizes; do
  n=${spec%%:*}
  cap=${spec##*:}
  mesh=terrain$n.ply
  [ -e "$mesh" ] || "$build/rsmooth-big-mesh" "$mesh" --triangles "$n" 2>/dev/null
  edge=""
  if [ "$n" -le "$in_memory_max" ]; then
    # --no-guard: the pieces have no fold guard yet, so that is what streaming must equal
    read -r wall rss < <(run mem$n "$build/rsmooth" "$mesh" -o mem$n.ply --force --no-guard)
    edge=$(sed -n 's/.*mean edge \([0-9.e+-]*\);.*/\1/p' mem$n.err)
    echo "| $n | in memory, --no-guard | $wall | $rss | | | | |"
  fi
  capped cap$n "$cap"
  if [ "$n" -eq 4000000 ]; then # the best mode: the stage a streamed step per cycle
    read -r wall rss < <(run best_mem$n "$build/rsmooth" "$mesh" -o best_mem$n.ply --force --best \
      --no-guard)
    echo "| $n | --best, in memory | $wall | $rss | | | | |"
    read -r wall rss < <(run best_cap$n "$build/rsmooth" "$mesh" -o best_cap$n.ply --force --best \
      --no-guard --max-memory "$cap" --json)
    pieces=$(grep -o '"pieces":[0-9]*' best_cap$n.out | cut -d: -f2)
    temp=$(grep -o '"temporary_bytes":[0-9]*' best_cap$n.out | cut -d: -f2)
    same=$(cmp -s best_mem$n.ply best_cap$n.ply && echo "the in-memory bytes" || echo "DIFFERS")
    echo "| $n | --best --max-memory $cap | $wall | $rss | $pieces | | $((temp >> 20)) | $same |"
    rm -f best_mem$n.ply best_cap$n.ply
  fi
  if [ "$n" -eq 16000000 ]; then
    capped low$n "$mpi_cap" # below the positions (96 MB at 16M)
    for ranks in 1 2 4; do
      [ -x "$build/rsmooth-mpi" ] || break
      read -r wall rss < <(run mpi$ranks "$(command -v mpirun)" -n $ranks --oversubscribe \
        "$build/rsmooth-mpi" "$mesh" -o mpi$ranks.ply --force --max-memory "$mpi_cap")
      same=$(cmp -s mpi$ranks.ply cap$n.ply && echo "the --max-memory bytes" || echo "DIFFERS")
      echo "| $n | rsmooth-mpi -n $ranks --max-memory $mpi_cap (peak of one rank) | $wall | $rss | | | | $same |"
      grep "rank\|statistics" mpi$ranks.err | sed 's/^/    /' >&2
    done
  fi
  rm -f mem$n.ply mpi1.ply mpi2.ply mpi4.ply low$n.ply
done
