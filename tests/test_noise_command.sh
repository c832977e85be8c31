#!/usr/bin/env bash
# rsmooth noise --depth-sensor through the command: the same seed gives the same bytes, the vertex
# and face counts and the faces are the clean mesh's, and every bad value or conflicting option is
# a usage error (2) whose message names the option, with nothing written.
set -uo pipefail
rsmooth=$1
shape=$2
. "$(dirname "$0")/command_util.sh"

expect 0 "$shape" make noisy.ply clean.ply --noise 0.3 --triangles 2000
expect 0 "$rsmooth" noise clean.ply a.ply --sigma 0.3 --depth-sensor --seed 4
grep -q "depth sensor at" err.txt || fail "no camera reported: $(cat err.txt)"
expect 0 "$rsmooth" noise clean.ply b.ply --sigma 0.3 --depth-sensor --seed 4
cmp -s a.ply b.ply || fail "the same seed gave different depth noise"
expect 0 "$rsmooth" noise clean.ply c.ply --sigma 0.3 --depth-sensor --seed 5
cmp -s a.ply c.ply && fail "another seed gave the same depth noise"

# the faces and vertex count stay the clean mesh's (no hole is cut at grazing angles)
expect 0 "$rsmooth" clean.ply -o clean.obj --method taubin --iterations 0 -q
expect 0 "$rsmooth" noise clean.ply d.obj --sigma 0.3 --depth-sensor --view=0,-1,2 --quantum 0.1 \
  --grazing 0.2 --ridges 0.5 --ridge-period 3
grep -q "view 0,-0.447214,0.894427 " err.txt || fail "--view not normalised in the report: $(cat err.txt)"
[ "$(grep -c '^v ' d.obj)" -eq "$(grep -c '^v ' clean.obj)" ] || fail "vertex count changed"
cmp -s <(grep '^f ' clean.obj) <(grep '^f ' d.obj) || fail "the faces changed"
cmp -s clean.obj d.obj && fail "--depth-sensor moved nothing"

# refused: nothing written, the option named
refuse() {
  local message=$1; shift
  expect 2 "$rsmooth" noise clean.ply bad.ply --sigma 0.3 "$@"
  grep -qF -- "$message" err.txt || fail "$* is not explained with '$message': $(cat err.txt)"
  if [ -e bad.ply ]; then
    fail "$* wrote a result"
    rm -f bad.ply
  fi
}
refuse "--view must be three finite numbers" --depth-sensor --view 0,0,0
refuse "--view must be three finite numbers" --depth-sensor --view 1,2
refuse "--view must be three finite numbers" --depth-sensor --view 1,2,3,4
refuse "--view must be three finite numbers" --depth-sensor --view 1,x,2
refuse "--view must be three finite numbers" --depth-sensor --view 1,inf,2
refuse "--quantum must be in [0, " --depth-sensor --quantum -1
refuse "--grazing must be in [0.01, 1]" --depth-sensor --grazing 0
refuse "--grazing must be in [0.01, 1]" --depth-sensor --grazing 1.5
refuse "--ridges must be in [0, 10]" --depth-sensor --ridges -0.1
refuse "--ridges must be in [0, 10]" --depth-sensor --ridges nan
refuse "--ridge-period must be in (0, " --depth-sensor --ridge-period 0
refuse "--quantum is an option of --depth-sensor" --quantum 0.2
refuse "--view is an option of --depth-sensor" --view 0,0,1
refuse "--depth-sensor and --direction exclude each other" --depth-sensor --direction normal
refuse "--depth-sensor and --impulsive exclude each other" --depth-sensor --impulsive 0.5
refuse "--depth-sensor and --correlation exclude each other" --depth-sensor --correlation 2
refuse "--depth-sensor and --stripes exclude each other" --stripes 3 --depth-sensor
refuse "--depth-sensor takes no value" --depth-sensor=1

# noise that would carry a coordinate beyond 1e150 is refused before writing, as for the others
printf 'v 0 0 0\nv 1e148 0 0\nv 0 1e148 0\nv 0 0 1e148\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n' >vast.obj
expect 2 "$rsmooth" noise vast.obj vast_noisy.obj --sigma 1e4 --depth-sensor
grep -q "vast_noisy.obj: .*beyond" err.txt || fail "depth noise beyond 1e150 not explained: $(cat err.txt)"
[ -e vast_noisy.obj ] && fail "--depth-sensor wrote coordinates beyond 1e150"
expect 0 "$rsmooth" noise vast.obj vast_noisy.obj --sigma 1e-3 --depth-sensor -q

if [ "$failures" -ne 0 ]; then
  echo "$failures failure(s)"
  exit 1
fi
echo "noise_command: all checks passed"
