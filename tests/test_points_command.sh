#!/usr/bin/env bash
# The rsmooth command on point clouds: a PLY with normals and no faces is filtered as points (the
# noise drops, the normals are written), and a cloud without normals, or asked for an edge-based
# method, fails with exit status 2 and a message naming the file.
set -uo pipefail
rsmooth=$1
. "$(dirname "$0")/command_util.sh"

# A 40 x 40 grid of spacing 1 on z = 0 with noise of about 0.3 in z, normals +z (a little noisy),
# and a colour per point: an ascii PLY cloud.
awk 'BEGIN {
  srand(7); n = 40
  print "ply\nformat ascii 1.0\ncomment a scan\nelement vertex " n * n
  print "property float x\nproperty float y\nproperty float z"
  print "property float nx\nproperty float ny\nproperty float nz"
  print "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header"
  for (i = 0; i < n; i++) for (j = 0; j < n; j++) {
    z = 0.3 * sqrt(12) * (rand() - 0.5)
    printf "%d %d %.6f %.4f %.4f 1 10 20 30\n", i, j, z, 0.2 * (rand() - 0.5), 0.2 * (rand() - 0.5)
  }
}' >cloud.ply
# mean |z| over the interior points of a cloud PLY written as ascii x y z nx ny nz ...
mean_z() {
  awk '/^end_header/ { body = 1; next }
       body && $1 >= 4 && $1 <= 35 && $2 >= 4 && $2 <= 35 { s += ($3 < 0 ? -$3 : $3); m++ }
       END { printf "%.6f\n", s / m }' "$1"
}

expect 0 "$rsmooth" cloud.ply -o smooth.ply --ascii --confidence conf.ply
grep -q "point cloud" err.txt || fail "no note that the input is a point cloud: $(cat err.txt)"
grep -q "1600 points with normals" err.txt || fail "summary does not count points: $(cat err.txt)"
grep -q "property float nx" smooth.ply || fail "no normals written"
grep -q "element face" smooth.ply && fail "the output gained faces"
grep -q "comment a scan" smooth.ply || fail "the input's comment was lost"
before=$(mean_z cloud.ply)
after=$(mean_z smooth.ply)
echo "mean |z| before $before, after $after"
awk -v a="$after" -v b="$before" 'BEGIN { exit !(a < 0.6 * b) }' || fail "noise not reduced by 40%"
# The filtered normals are unit and near +z; the colours are kept.
awk '/^end_header/ { body = 1; next }
     body { l = sqrt($4 * $4 + $5 * $5 + $6 * $6); if (l < 0.999 || l > 1.001 || $6 < 0.9) bad++
            if ($7 != 10 || $9 != 30) bad++ }
     END { exit bad > 0 }' smooth.ply || fail "written normals are not unit and near +z, or colours lost"
grep -q "property float quality" conf.ply || fail "confidence cloud has no quality"

# Binary and other formats; JSON says it was a point cloud.
expect 0 "$rsmooth" cloud.ply -o smooth.obj -q --json
grep -q '"point_cloud":true' out.txt || fail "--json does not say point_cloud: $(cat out.txt)"
[ "$(grep -c '^vn ' smooth.obj)" -eq 1600 ] || fail "OBJ output lacks the 1600 normals"
[ -s err.txt ] && fail "-q printed: $(cat err.txt)"
expect 0 "$rsmooth" smooth.obj -o again.ply -q
expect 0 "$rsmooth" cloud.ply -o best.ply --best --passes 2 -q

# The device named, and the reference path: each says where it ran, and the two agree (the
# library's own comparison is tests/test_cl_points.c; the spacing here is 1).
expect 0 "$rsmooth" cloud.ply -o ref.ply --ascii --device reference
grep -q "on the reference path" err.txt || fail "no note of the reference path: $(cat err.txt)"
"$rsmooth" --list-devices 2>/dev/null | grep -qE "^[0-9]+:[0-9]+ +cpu" && {
  expect 0 "$rsmooth" cloud.ply -o dev.ply --ascii --device cpu
  grep -q "on device '" err.txt || fail "no note that the device ran: $(cat err.txt)"
  paste -d ' ' <(awk '/^end_header/ { b = 1; next } b' ref.ply) \
               <(awk '/^end_header/ { b = 1; next } b' dev.ply) |
    awk '{ d = 0; for (k = 1; k <= 3; k++) { e = $k - $(k + 9); d += e * e }
           if (sqrt(d) > m) m = sqrt(d) }
         END { printf "device against reference: max %.3g spacings\n", m; exit !(m < 1e-3) }' ||
    fail "device and reference results differ"
}

# No normals: a clear error naming the file.
grep -v -e "property float n[xyz]" cloud.ply | awk '/^end_header/ { print; body = 1; next }
  !body { print; next } { print $1, $2, $3, $7, $8, $9 }' >bare.ply
expect 2 "$rsmooth" bare.ply -o out.ply
grep -qE "bare.ply: byte [0-9]+ \(the end\): 1600 vertices but no faces and no vertex normals" err.txt ||
  fail "message: $(cat err.txt)"
[ -e out.ply ] && fail "a failed run wrote its output"
expect 2 "$rsmooth" cloud.ply -o out.ply --method taubin
grep -q "cloud.ply is a point cloud" err.txt || fail "taubin message: $(cat err.txt)"

[ "$failures" -eq 0 ] || exit 1
echo "point cloud command: all checks passed"
