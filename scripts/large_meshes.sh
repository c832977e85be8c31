#!/usr/bin/env bash
# The "Large meshes" benchmark (README): generated terrains of 4M, 16M and 100M triangles
# (rsmooth-big-mesh, binary PLY, float), each filtered in memory where it fits and under
# --max-memory, with the peak resident memory (GNU time), the wall time, the temporary disk the
# streaming run reports, and the capped result against the in-memory one; rsmooth-mpi on 1 and 2
# ranks at 16M. Figures, not assertions: run it on a quiet machine.
#
# usage: scripts/large_meshes.sh BUILD WORKDIR [MAX_TRIANGLES_IN_MEMORY ["TRIANGLES:CAP ..."]]
#   BUILD    the build folder (rsmooth, rsmooth-big-mesh, rsmooth-mpi)
#   WORKDIR  where the meshes go (about 5 GB free for 100M triangles, 10 GB with the outputs)
set -euo pipefail
build=$(cd "$1" && pwd)
work=$2
in_memory_max=${3:-16000000}
sizes=${4:-"4000000:256M 16000000:512M 100000000:2G"}
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

echo "| triangles | run | wall s | peak RSS MB | pieces | temporary MB | vs in memory |"
echo "| --- | --- | --- | --- | --- | --- | --- |"
"$build/rsmooth-big-mesh" tiny.ply --triangles 1000 --force 2>/dev/null
read -r wall rss < <(run tiny "$build/rsmooth" tiny.ply -o tiny_out.ply --force --max-memory 64M)
echo "| 1000 | --max-memory 64M (the runtime's own memory) | $wall | $rss | | | |"
for spec in $sizes; do
  n=${spec%%:*}
  cap=${spec##*:}
  mesh=terrain$n.ply
  [ -e "$mesh" ] || "$build/rsmooth-big-mesh" "$mesh" --triangles "$n" 2>/dev/null
  edge=""
  if [ "$n" -le "$in_memory_max" ]; then
    read -r wall rss < <(run mem$n "$build/rsmooth" "$mesh" -o mem$n.ply --force)
    edge=$(sed -n 's/.*mean edge \([0-9.e+-]*\);.*/\1/p' mem$n.err)
    echo "| $n | in memory | $wall | $rss | | | |"
  fi
  read -r wall rss < <(run cap$n "$build/rsmooth" "$mesh" -o cap$n.ply --force --max-memory "$cap" --json)
  pieces=$(grep -o '"pieces":[0-9]*' cap$n.out | head -1 | cut -d: -f2)
  temp=$(grep -o '"temporary_bytes":[0-9]*' cap$n.out | cut -d: -f2)
  versus=""
  if [ -n "$edge" ]; then
    versus=$(python3 "$here/compare_ply_positions.py" cap$n.ply mem$n.ply "$edge")
  fi
  echo "| $n | --max-memory $cap | $wall | $rss | $pieces | $((temp >> 20)) | $versus |"
  if [ "$n" -eq 16000000 ] && [ -x "$build/rsmooth-mpi" ]; then
    for ranks in 1 2; do
      read -r wall rss < <(run mpi$ranks "$(command -v mpirun)" -n $ranks --oversubscribe \
        "$build/rsmooth-mpi" "$mesh" -o mpi$ranks.ply --force --max-memory "$cap")
      same=$(cmp -s mpi$ranks.ply cap$n.ply && echo "the --max-memory bytes" || echo "DIFFERS")
      echo "| $n | rsmooth-mpi -n $ranks --max-memory $cap (peak of one rank) | $wall | $rss | | | $same |"
      grep "rank" mpi$ranks.err | sed 's/^/    /' >&2
    done
  fi
  rm -f mem$n.ply mpi1.ply mpi2.ply
  grep "streamed" cap$n.err | sed 's/^/    /' >&2
done
