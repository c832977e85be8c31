#!/usr/bin/env bash
# The rsmooth command on scanners' PLY range grids (lib/io/ply_range_grid.c): the grids
# test_ply_range_grid writes (a sheared plane with a depth step and missing cells; ascii, binary
# little- and big-endian) are smoothed as triangle meshes with one note on stderr, the output a
# mesh PLY with the triangles counted by brute force; each malformed grid fails with its message,
# exit status 2 and nothing written; --max-memory refuses a range grid rather than misreading it.
set -uo pipefail
rsmooth=$1
writer=$2
. "$(dirname "$0")/command_util.sh"

"$writer" write "$dir" || { echo "FAIL: $writer write"; exit 1; }
read -r triangles cols rows samples <expected.txt

for grid in grid.ply grid_le.ply grid_be.ply; do
  rm -f out.ply
  expect 0 "$rsmooth" "$grid" -o out.ply --ascii --device reference
  note="rsmooth: note: $grid is a range grid ($cols x $rows cells, $samples samples): read as $triangles triangles; the output is a triangle mesh, not a range grid"
  [ "$(grep -c "range grid" err.txt)" -eq 1 ] || fail "$grid: not one note: $(cat err.txt)"
  grep -qxF "$note" err.txt || fail "$grid: wanted '$note', got: $(cat err.txt)"
  grep -qx "element face $triangles" out.ply || fail "$grid: no 'element face $triangles' in the output"
  grep -q "range_grid\|num_cols" out.ply && fail "$grid: the output still describes a range grid"
  # every face a triangle: the lines after the vertices start with 3
  awk -v nv="$samples" '/^end_header/ { body = 1; next } body && ++i > nv && $1 != 3 { bad++ }
                        END { exit bad > 0 }' out.ply || fail "$grid: a face that is no triangle"
done
# ascii and binary give the same result
expect 0 "$rsmooth" grid.ply -o a.ply --ascii --device reference
expect 0 "$rsmooth" grid_be.ply -o b.ply --ascii --device reference
cmp -s a.ply b.ply || fail "ascii and big-endian grids smooth to different files"

for bad in bad_*.ply; do
  rm -f out.ply
  expect 2 "$rsmooth" "$bad" -o out.ply --device reference
  want=$(cat "${bad%.ply}.txt")
  grep -qF "rsmooth: $bad" err.txt || fail "$bad: the message does not name the file: $(cat err.txt)"
  grep -qF "$want" err.txt || fail "$bad: wanted '$want', got: $(cat err.txt)"
  [ -e out.ply ] && fail "$bad: an output was written"
done

# streamed: refused, never read as a point cloud
rm -f out.ply
expect 2 "$rsmooth" grid_le.ply -o out.ply --max-memory 1G --device reference
grep -qF "does not triangulate range grids" err.txt || fail "--max-memory: $(cat err.txt)"
[ -e out.ply ] && fail "--max-memory wrote an output"

[ "$failures" -eq 0 ] || { echo "$failures failure(s)"; exit 1; }
echo "range_grid_command: all checks passed"
