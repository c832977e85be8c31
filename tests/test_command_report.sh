#!/usr/bin/env bash
# What the command says about a run: --progress ends at 100% however quick the run, a long option
# typed with one dash gets the two-dash spelling suggested, --json's "method" is what ran, and
# rsmooth compare --json has the keys Python's rsmooth.compare returns.
set -uo pipefail
rsmooth=$1
shape=$2
. "$(dirname "$0")/command_util.sh"

expect 0 "$shape" make noisy.ply truth.ply --noise 0.3 --triangles 3000

# --progress into a file: a run of some milliseconds still ends with the bar full
expect 0 "$rsmooth" noisy.ply -o progress.ply --progress --device reference
grep -q '^\[[#.]*\] *[0-9]*% reading' err.txt || fail "--progress drew no bar: $(cat err.txt)"
last=$(grep '^\[' err.txt | tail -1)
case $last in
  "[##############################] 100% done"*) ;;
  *) fail "--progress's last line is not the full bar: '$last'" ;;
esac
# and on a failure it does not claim to be done
expect 2 "$rsmooth" noisy.ply -o progress.ply --progress --device reference
grep -q '100% done' err.txt && fail "--progress said done on a failed run: $(cat err.txt)"

# a long option with one dash: the two-dash spelling suggested, nothing run
for typo in "-sigma-f 2" "-sigmaf 2" "-force" "-sigma-g=0.4"; do
  # shellcheck disable=SC2086 # the typo is the words it holds
  expect 2 "$rsmooth" noisy.ply -o typo.ply $typo
  want=$(printf '%s' "$typo" | sed 's/^-\([a-z-]*\).*/\1/; s/sigmaf/sigma-f/')
  grep -q "did you mean --$want?" err.txt || fail "$typo: no --$want suggested: $(cat err.txt)"
  [ -e typo.ply ] && fail "$typo: wrote an output"
done
# groups of letters still work
expect 0 "$rsmooth" noisy.ply -o group.ply -fq --device reference

# --json's method: what ran
expect 0 "$rsmooth" noisy.ply -o plain.ply --json --device reference
grep -q '"method":"robust",' out.txt || fail "plain run: method not robust: $(head -c 200 out.txt)"
expect 0 "$rsmooth" noisy.ply -o blend.ply --best --auto --json --device reference
if grep -q '"region_choice":{"taubin_iterations":[1-9]' out.txt; then
  grep -q '"method":"robust+taubin",' out.txt ||
    fail "--best --auto blended with Taubin, but method says: $(head -c 200 out.txt)"
else
  fail "--best --auto made no choice per region on this noisy mesh: $(head -c 300 out.txt)"
fi
expect 0 "$rsmooth" truth.ply -o clean.ply --auto --json --device reference
grep -q '"passes":0' out.txt || fail "--auto on the clean mesh ran a pass: $(head -c 300 out.txt)"
grep -q '"method":"none",' out.txt || fail "--auto ran nothing, method says: $(head -c 200 out.txt)"

# compare --json: the keys of Python's rsmooth.compare, the counts those of the files
expect 0 "$rsmooth" compare noisy.ply truth.ply --json
for key in theta ev rms_v hausdorff mean_edge bbox_diag theta_count vertices triangles; do
  grep -q "\"$key\": " out.txt || fail "compare --json has no $key: $(cat out.txt)"
done
nv=$(sed -n 's/^element vertex //p' truth.ply)
nf=$(sed -n 's/^element face //p' truth.ply)
grep -q "\"vertices\": $nv," out.txt || fail "compare --json: vertices not $nv: $(cat out.txt)"
grep -q "\"triangles\": $nf," out.txt || fail "compare --json: triangles not $nf: $(cat out.txt)"

# the command's mean edge length and compare's, for the same file, to the last digit
expect 0 "$rsmooth" noisy.ply -o edge.ply --json --device reference
command_edge=$(grep -o '"mean_edge_length":[^,]*' out.txt | cut -d: -f2)
expect 0 "$rsmooth" compare noisy.ply noisy.ply --json
compare_edge=$(grep -o '"mean_edge": [^,]*' out.txt | cut -d' ' -f2)
[ -n "$command_edge" ] && [ "$command_edge" = "$compare_edge" ] ||
  fail "mean edge length: the command says $command_edge, compare $compare_edge"

[ "$failures" -eq 0 ] || exit 1
echo "all checks passed"
