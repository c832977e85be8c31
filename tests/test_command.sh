#!/usr/bin/env bash
# The rsmooth command end to end: results written, files never clobbered or half-written, and each
# kind of failure with its exit status (2 usage/input, 3 device) and a message naming the file.
set -uo pipefail
rsmooth=$1
shape=$2
. "$(dirname "$0")/command_util.sh"

expect 0 "$shape" make noisy.ply truth.ply --noise 0.3 --triangles 3000
expect 0 "$rsmooth" noisy.ply -o smooth.ply --confidence conf.ply --json
grep -q '"mollify":' out.txt || fail "--json printed no stage times: $(cat out.txt)"
grep -q '"device":' out.txt || fail "--json printed no device"
expect 0 "$shape" compare noisy.ply truth.ply
before=$(sed -n 's/.*normal error \([0-9.]*\) deg.*/\1/p' out.txt)
expect 0 "$shape" compare smooth.ply truth.ply
after=$(sed -n 's/.*normal error \([0-9.]*\) deg.*/\1/p' out.txt)
echo "normal error before $before, after $after degrees"
awk -v a="$after" -v b="$before" 'BEGIN { exit !(a < b / 2) }' || fail "normal error not halved"
head -c 400 conf.ply | grep -q "property float quality" || fail "confidence mesh has no quality"
head -c 400 conf.ply | grep -q "property uchar red" || fail "confidence mesh has no colours"
# The colours are normalised to the mesh's range: both ends of the ramp appear.
expect 0 "$rsmooth" noisy.ply -o smooth_a.ply --confidence conf_a.ply --ascii
grep -q "conf_a.ply: confidence from" err.txt || fail "no confidence range printed: $(cat err.txt)"
awk '/^end_header/ { body = 1; next } body && NF == 7 { c[$5 " " $6 " " $7]++ }
     END { exit !(c["215 48 39"] > 0 && c["69 117 180"] > 0) }' conf_a.ply ||
  fail "confidence colours do not span red to blue"

# OBJ out keeps the vertex and face counts; the reference path gives nearly the same result.
expect 0 "$rsmooth" noisy.ply -o smooth.obj --device reference -q
[ "$(grep -c '^v ' smooth.obj)" -eq "$(sed -n 's/^element vertex //p' noisy.ply)" ] ||
  fail "vertex count changed in OBJ output"
[ "$(grep -c '^f ' smooth.obj)" -eq "$(sed -n 's/^element face //p' noisy.ply)" ] ||
  fail "face count changed in OBJ output"
[ -s err.txt ] && fail "--quiet printed: $(cat err.txt)"

# Nothing is replaced without --force, the input never, and failures leave no files behind.
cp smooth.ply before.ply
expect 2 "$rsmooth" noisy.ply -o smooth.ply
grep -q "smooth.ply: already exists" err.txt || fail "no 'already exists' message: $(cat err.txt)"
cmp -s smooth.ply before.ply || fail "existing output changed without --force"
expect 0 "$rsmooth" noisy.ply -o smooth.ply --force -q --sigma-g inf
cmp -s smooth.ply before.ply && fail "--force did not replace the output"
expect 2 "$rsmooth" noisy.ply -o noisy.ply --force
grep -q "refusing to overwrite the input" err.txt || fail "input overwrite not refused"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n' > bad.obj
expect 2 "$rsmooth" bad.obj -o bad_out.ply
grep -q "bad.obj:4" err.txt || fail "parse error does not name file and line: $(cat err.txt)"
[ -e bad_out.ply ] && fail "output written for a bad input"
expect 2 "$rsmooth" missing.obj -o x.ply
grep -q "missing.obj" err.txt || fail "missing input not named"
expect 2 "$rsmooth" . -o x.ply
expect 2 "$rsmooth" noisy.ply -o x.xyz
expect 2 "$rsmooth" noisy.ply -o x.ply --sigma-f -1
expect 2 "$rsmooth" noisy.ply -o x.ply --sigma-g nan
expect 2 "$rsmooth" noisy.ply -o x.ply --cutoff 9

# The comparison methods: each smooths (normal error drops), and misuse is a usage error.
for method in gaussian "laplacian --iterations 3" "taubin --iterations 5 --lambda 0.4 --mu -0.45"; do
  expect 0 "$rsmooth" noisy.ply -o method.ply --force -q --json --method $method
  grep -q "\"method\":\"${method%% *}\"" out.txt || fail "--json does not name --method $method"
  expect 0 "$shape" compare method.ply truth.ply
  err=$(sed -n 's/.*normal error \([0-9.]*\) deg.*/\1/p' out.txt)
  awk -v a="$err" -v b="$before" 'BEGIN { exit !(a < b) }' ||
    fail "--method $method did not lower the normal error ($before -> $err)"
done
expect 2 "$rsmooth" noisy.ply -o x.ply --method median
expect 2 "$rsmooth" noisy.ply -o x.ply --method gaussian --sigma-g 1
expect 2 "$rsmooth" noisy.ply -o x.ply --iterations 3
expect 2 "$rsmooth" noisy.ply -o x.ply --method taubin --iterations 2.5
expect 2 "$rsmooth" noisy.ply -o x.ply --method taubin --mu 0.2
expect 2 "$rsmooth" noisy.ply -o x.ply --method laplacian --lambda 0
expect 2 "$rsmooth" noisy.ply -o x.ply --method laplacian --confidence c.ply
[ -e x.ply ] && fail "a refused --method call wrote its output"
expect 2 "$rsmooth" noisy.ply -o x.ply --bogus
expect 2 "$rsmooth" noisy.ply
# A device choice that names no device here is a usage error (2), as is junk in a tuning variable.
expect 2 "$rsmooth" noisy.ply -o x.ply --device "no such device"
grep -q "no such device" err.txt || fail "unknown device not explained: $(cat err.txt)"
grep -q "list-devices" err.txt || fail "unknown device: no hint at --list-devices: $(cat err.txt)"
RSMOOTH_DEVICE=99:99 expect 2 "$rsmooth" noisy.ply -o x.ply
grep -q "RSMOOTH_DEVICE" err.txt || fail "a device from RSMOOTH_DEVICE is not named so: $(cat err.txt)"
RSMOOTH_HOST_THREADS=two expect 2 "$rsmooth" noisy.ply -o x.ply
grep -q "RSMOOTH_HOST_THREADS" err.txt || fail "junk RSMOOTH_HOST_THREADS not named: $(cat err.txt)"
RSMOOTH_CELLS_PER_REACH=0 expect 2 "$rsmooth" noisy.ply -o x.ply
[ -e x.ply ] && fail "output written after a failure"
ls -A | grep -qE 'tmp-|^\.rsmooth-' && fail "temporary files left behind: $(ls -A)"

# With no OpenCL platform at all, auto falls back to the reference path with a warning.
OCL_ICD_VENDORS=/nonexistent OCL_ICD_FILENAMES= expect 0 "$rsmooth" noisy.ply -o fallback.ply
grep -q "reference path" err.txt || fail "no fallback warning: $(cat err.txt)"

# Same format in and out keeps every property; converting says what it drops.
cat > rich.ply <<'PLY'
ply
format ascii 1.0
comment made by hand
element vertex 4
property float x
property float y
property float z
property uchar red
property uchar green
property uchar blue
property float quality
element face 2
property list uchar int vertex_indices
property uchar flags
end_header
0 0 0 255 0 0 0.5
1 0 0 0 255 0 0.25
0 1 0 0 0 255 1
1 1 0.1 10 20 30 0
3 0 1 2 7
3 1 3 2 9
PLY
expect 0 "$rsmooth" rich.ply -o rich_out.ply --ascii
grep -q "comment made by hand" rich_out.ply || fail "PLY comment lost"
grep -q "property float quality" rich_out.ply || fail "PLY quality property lost"
grep -q "property uchar flags" rich_out.ply || fail "PLY face property lost"
grep -q "^3 1 3 2 9" rich_out.ply || fail "PLY face flags changed: $(tail -2 rich_out.ply)"
grep -q "drops" err.txt && fail "PLY to PLY claims to drop something: $(cat err.txt)"
expect 0 "$rsmooth" rich.ply -o rich_out.obj
grep -q "rich_out.obj: this format cannot hold, so drops: PLY vertex property 'quality', PLY face property 'flags', PLY comments" err.txt ||
  fail "conversion losses not reported: $(cat err.txt)"
expect 0 "$rsmooth" rich.ply -o rich_out.stl
grep -q "drops: vertex colours" err.txt || fail "STL colour loss not reported: $(cat err.txt)"
expect 0 "$rsmooth" rich_out.stl -o rich_stl.off
[ "$(sed -n 2p rich_stl.off)" = "6 2 0" ] || fail "STL is not read back as a soup: $(head -2 rich_stl.off)"

# --in-place replaces the input atomically; with -o it is a usage error.
cp noisy.ply inplace.ply
expect 0 "$rsmooth" inplace.ply --in-place -q
cmp -s inplace.ply noisy.ply && fail "--in-place left the input unchanged"
expect 0 "$shape" compare inplace.ply truth.ply
expect 2 "$rsmooth" inplace.ply --in-place -o other.ply

# --stats and --list-devices
expect 0 "$rsmooth" noisy.ply -o stats.ply --stats
grep -q "^moved:" err.txt && grep -q "^confidence:" err.txt || fail "--stats printed: $(cat err.txt)"
expect 0 "$rsmooth" --list-devices
grep -q "P:D" out.txt || fail "--list-devices printed: $(cat out.txt)"

# A progress bar appears on a terminal for work over a second (script(1) provides the terminal).
if command -v script >/dev/null; then
  expect 0 "$shape" make big.ply bigtruth.ply --triangles 150000
  script -qec "'$rsmooth' big.ply -o bigout.ply --device reference --sigma-f 4" /dev/null >tty.txt 2>&1 ||
    fail "rsmooth under script failed: $(cat tty.txt)"
  grep -q "smoothing" tty.txt || fail "no progress bar on a terminal: $(head -c 300 tty.txt)"
  expect 0 "$rsmooth" big.ply -o bigout2.ply --device reference
  grep -q "smoothing" err.txt && fail "progress bar drawn when stderr is not a terminal"
fi

# The instruments: reproducible noise, and the errors against the ground truth.
expect 0 "$rsmooth" noise truth.ply noise_a.ply --sigma 0.3 --seed 5
expect 0 "$rsmooth" noise truth.ply noise_b.ply --sigma 0.3 --seed 5
cmp -s noise_a.ply noise_b.ply || fail "the same seed gave different noise"
expect 0 "$rsmooth" noise_a.ply -o noise_smooth.ply -q
expect 0 "$rsmooth" compare noise_a.ply truth.ply --json
ev_before=$(sed -n 's/.*"ev": *\([0-9.eE+-]*\).*/\1/p' out.txt)
expect 0 "$rsmooth" compare noise_smooth.ply truth.ply --json
ev_after=$(sed -n 's/.*"ev": *\([0-9.eE+-]*\).*/\1/p' out.txt)
echo "ev before $ev_before, after $ev_after"
awk -v a="$ev_after" -v b="$ev_before" 'BEGIN { exit !(a > 0 && a < b) }' || fail "ev did not fall"
expect 2 "$rsmooth" compare noise_a.ply big.ply
# The figures (the library's rsmooth_compare) are the same at every scale: two triangles with
# edges of 1e-200 measure as they do at 1, where squared distances would underflow unscaled.
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\n' > unit_truth.obj
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 2\nf 1 2 3\nf 1 2 4\n' > unit_result.obj
for f in unit_truth unit_result; do
  awk '/^v / { printf "v %s %s %s\n", $2 * 1e-200, $3 * 1e-200, $4 * 1e-200; next } { print }' \
    $f.obj > tiny_${f#unit_}.obj
done
expect 0 "$rsmooth" compare unit_result.obj unit_truth.obj
unit=$(head -n 4 out.txt)
expect 0 "$rsmooth" compare tiny_result.obj tiny_truth.obj
tiny=$(head -n 4 out.txt)
[ -n "$unit" ] && [ "$unit" = "$tiny" ] ||
  fail "compare at 1e-200 ($tiny) differs from compare at 1 ($unit)"
grep -q "^mean_edge  1.16569e-200 (the truth's units)" out.txt &&
  grep -q "^bbox_diag  1.73205e-200 (the truth's units)" out.txt ||
  fail "compare at 1e-200: lengths not in the mesh's units: $(cat out.txt)"
# its plain figures say their units
for line in "theta .* degrees" "ev .* thousandths of the bounding-box diagonal" \
            "rms_v .* mean edge lengths" "hausdorff .* thousandths of the bounding-box diagonal"; do
  grep -q "^$line\$" out.txt || fail "compare prints no line '$line': $(cat out.txt)"
done

# Pictures: the input, the result and its confidence side by side, as PNG, never clobbered.
expect 0 "$rsmooth" render noisy.ply smooth.ply conf.ply -o pair.png --size 480x160
[ "$(head -c 8 pair.png | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] ||
  fail "render did not write a PNG: $(head -c 8 pair.png | od -An -tx1)"
expect 2 "$rsmooth" render noisy.ply smooth.ply -o pair.png
grep -q "pair.png: already exists" err.txt || fail "render replaced a file without --force"
expect 0 "$rsmooth" render noisy.ply -o pair.png --force --azimuth 200 --elevation -10
expect 2 "$rsmooth" render missing.ply -o missing.png
[ -e missing.png ] && fail "render wrote a picture of a missing mesh"
expect 2 "$rsmooth" render noisy.ply -o bad.png --elevation 90
ls -A | grep -qE 'tmp-|^\.rsmooth-' && fail "render left a temporary file: $(ls -A)"

# Beyond the paper: the best mode beats the paper's defaults on the same noisy shape, and every
# new option is checked before any file is read.
expect 0 "$rsmooth" noisy.ply -o best.ply --best -q --device reference --json
grep -q '"normals":"bilateral"' out.txt || fail "--best did not select bilateral normals"
grep -q '"passes":1' out.txt || fail "--best did not run 1 pass after the stage"
grep -q '"vertex_updates":10,.*"guided_radius":3,"guided_rounds":1,"stage_repeats":10' out.txt ||
  fail "--best did not run the normal update stage's 10 cycles"
expect 0 "$rsmooth" noisy.ply -o best_tukey.ply --best --influence tukey --passes 2 \
  --pass-confidence 0.8 -q --device reference --json
grep -q '"influence":"tukey","passes":2' out.txt || fail "options after --best were not applied"
expect 0 "$rsmooth" compare best.ply truth.ply --json
ev_best=$(sed -n 's/.*"ev": *\([0-9.eE+-]*\).*/\1/p' out.txt)
expect 0 "$rsmooth" noisy.ply -o paper.ply --force -q --device reference
expect 0 "$rsmooth" compare paper.ply truth.ply --json
ev_paper=$(sed -n 's/.*"ev": *\([0-9.eE+-]*\).*/\1/p' out.txt)
echo "ev paper defaults $ev_paper, best mode $ev_best"
awk -v a="$ev_best" -v b="$ev_paper" 'BEGIN { exit !(a > 0 && a < b) }' ||
  fail "the best mode is not better than the paper's defaults"
expect 0 "$rsmooth" noisy.ply -o auto.ply --best --auto --sigma-g 0.25 --device reference --json
grep -q '"noise_estimate":0\.[1-4]' out.txt || fail "--auto did not estimate 0.3 edges of noise"
sg=$(sed -n 's/.*"sigma_g":\([0-9.eE+-]*\).*/\1/p' out.txt)
mel=$(sed -n 's/.*"mean_edge_length":\([0-9.eE+-]*\).*/\1/p' out.txt)
awk -v a="$sg" -v m="$mel" 'BEGIN { r = a / m; exit !(r > 0.2499 && r < 0.2501) }' ||
  fail "--sigma-g 0.25 given with --auto was not kept (sigma_g $sg, mean edge $mel)"
grep -q "noise estimate" err.txt || fail "--auto did not say what it estimated"
expect 2 "$rsmooth" noisy.ply -o x.ply --auto --method taubin
expect 2 "$rsmooth" noisy.ply -o x.ply --normals gaussian
expect 2 "$rsmooth" noisy.ply -o x.ply --influence cauchy
expect 2 "$rsmooth" noisy.ply -o x.ply --passes 0
expect 2 "$rsmooth" noisy.ply -o x.ply --passes 2.5
expect 2 "$rsmooth" noisy.ply -o x.ply --normal-iterations 101
expect 2 "$rsmooth" noisy.ply -o x.ply --normal-sigma-n 3
expect 2 "$rsmooth" noisy.ply -o x.ply --pass-confidence 1.5
[ -e x.ply ] && fail "a bad option wrote an output"

# Colour in the weight: --sigma-c uses the input's vertex colours (a two-tone copy of the noisy
# shape, built from the ascii confidence mesh: x y z quality r g b), on both paths alike; an input
# without colours is refused.
awk '/^element vertex/ { nv = $3 } /^element face/ { nf = $3 }
  /^end_header/ { body = 1; printf "ply\nformat ascii 1.0\nelement vertex %d\nproperty double x\n" \
    "property double y\nproperty double z\nproperty uchar red\nproperty uchar green\n" \
    "property uchar blue\nelement face %d\nproperty list uchar int vertex_indices\n" \
    "end_header\n", nv, nf; next }
  body && NF == 7 { print $1, $2, $3, ($1 < 0 ? "255 0 0" : "0 0 255"); next } body { print }' \
  conf_a.ply > two_tone.ply
expect 0 "$rsmooth" two_tone.ply -o colour.ply -q --sigma-c 0.1 --json
grep -q '"sigma_c":0.1,' out.txt || fail "--json does not report sigma_c: $(cat out.txt)"
head -c 400 colour.ply | grep -q "property uchar red" || fail "--sigma-c output lost its colours"
expect 0 "$rsmooth" two_tone.ply -o colourless.ply -q --json
grep -q '"sigma_c":null' out.txt || fail "--json reports a colour width without --sigma-c"
cmp -s colour.ply colourless.ply && fail "--sigma-c changed nothing"
expect 0 "$rsmooth" two_tone.ply -o colour_ref.ply -q --sigma-c 0.1 --device reference
expect 0 "$rsmooth" compare colour.ply colour_ref.ply --json
ev_colour=$(sed -n 's/.*"ev": *\([0-9.eE+-]*\).*/\1/p' out.txt)
awk -v a="$ev_colour" 'BEGIN { exit !(a < 1e-4) }' ||
  fail "--sigma-c: the OpenCL and reference paths differ (ev $ev_colour)"
expect 2 "$rsmooth" noisy.ply -o x.ply --sigma-c 0.1
grep -q "noisy.ply has no vertex colours: --sigma-c needs them" err.txt ||
  fail "an uncoloured input with --sigma-c is not explained: $(cat err.txt)"
expect 2 "$rsmooth" two_tone.ply -o x.ply --sigma-c 0
expect 2 "$rsmooth" two_tone.ply -o x.ply --sigma-c 0.1 --method taubin
[ -e x.ply ] && fail "a refused --sigma-c call wrote its output"

# ---- Files on disk ----------------------------------------------------------------------------
# mode_owner FILE: "MODE UID GID"
mode_owner() { stat -c '%a %u %g' "$1"; }
# only_files DIR NAME...: fails unless DIR holds exactly these names (nothing left behind)
only_files() {
  local where=$1; shift
  local have want
  have=$(ls -A "$where" | sort | tr '\n' ' ')
  want=$(printf '%s\n' "$@" | sort | tr '\n' ' ')
  [ "$have" = "$want" ] || fail "$where holds '$have', wanted '$want'"
}
expect 0 "$shape" make small.ply smalltruth.ply --noise 0.3 --triangles 2000
expect 0 "$rsmooth" small.ply -o small_a.ply -q --device reference --sigma-g inf
expect 0 "$rsmooth" small.ply -o small_b.ply -q --device reference
cmp -s small_a.ply small_b.ply && fail "two settings give the same result: the tests below cannot tell them apart"

# Two runs racing to one new output without --force: exactly one exits 0, the file is complete and
# the winner's; the other exits 2 saying the file exists, and leaves nothing behind. Also with the
# named temporary the command falls back to where O_TMPFILE is missing (RSMOOTH_NAMED_TEMPORARY=1;
# RSMOOTH_UNUSED=1 changes nothing).
for temporary in RSMOOTH_UNUSED RSMOOTH_NAMED_TEMPORARY; do
  rm -rf race && mkdir race
  late=0
  for i in $(seq 1 20); do
    env $temporary=1 "$rsmooth" small.ply -o race/out$i.ply -q --device reference --sigma-g inf \
      2>race.a &
    a=$!
    env $temporary=1 "$rsmooth" small.ply -o race/out$i.ply -q --device reference 2>race.b &
    b=$!
    wait $a; sa=$?
    wait $b; sb=$?
    if [ "$sa" -eq 0 ] && [ "$sb" -eq 2 ]; then winner=small_a.ply loser=race.b
    elif [ "$sa" -eq 2 ] && [ "$sb" -eq 0 ]; then winner=small_b.ply loser=race.a
    else fail "racing runs ($temporary temporary) exited $sa and $sb: $(cat race.a race.b)"; continue
    fi
    grep -q "race/out$i.ply: already exists" $loser || fail "the racing loser says: $(cat $loser)"
    grep -q "while" $loser && late=$((late + 1))
    cmp -s race/out$i.ply $winner || fail "race/out$i.ply is not the winner's result"
  done
  only_files race $(for i in $(seq 1 20); do echo out$i.ply; done)
  echo "races ($temporary temporary): 20 pairs, $late of the losers lost at the final no-replace step"
done

# kill -9 while the result is being written (a 300,000-triangle OBJ: about 0.3 s of writing) leaves
# nothing but the previous target, untouched; the kill lands once the process holds a file open in
# the output's folder, which it does only while writing.
# kill_while_writing DIR COMMAND... (a run that ends before the poll sees it writing, as on a
# loaded machine, is tried again, up to 5 times; its output is the full result, removed first)
kill_while_writing() {
  local where caught=0 status pid try
  where=$(cd "$1" && pwd -P); shift
  for try in 1 2 3 4 5; do
    "$@" 2>/dev/null &
    pid=$!
    for _ in $(seq 1 20000); do
      if ls -l /proc/$pid/fd 2>/dev/null | grep -q -- "-> $where/"; then
        kill -9 $pid && caught=1
        break
      fi
      kill -0 $pid 2>/dev/null || break
    done
    { wait $pid; } 2>/dev/null # no "Killed" notice from the shell
    status=$?
    [ $caught -eq 1 ] && break
    [ $status -eq 0 ] || break
    echo "kill -9: the run ended before it was seen writing (try $try): again"
    cp target_before.obj "$where/target.obj"
    rm -f "$where/new.obj"
  done
  [ $caught -eq 1 ] && [ $status -eq 137 ] ||
    fail "could not kill the command while it wrote (status $status): $*"
}
expect 0 "$shape" make large.ply largetruth.ply --triangles 300000
rm -rf killed && mkdir killed
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' > killed/target.obj
cp killed/target.obj target_before.obj
kill_while_writing killed "$rsmooth" large.ply -o killed/target.obj --force --method laplacian --iterations 1
only_files killed target.obj
cmp -s killed/target.obj target_before.obj || fail "kill -9 changed the previous target"
kill_while_writing killed "$rsmooth" large.ply -o killed/new.obj --method laplacian --iterations 1
only_files killed target.obj
# where O_TMPFILE is missing the temporary has a name: a short hidden one, the target untouched
RSMOOTH_NAMED_TEMPORARY=1 kill_while_writing killed "$rsmooth" large.ply -o killed/target.obj --force --method laplacian --iterations 1
cmp -s killed/target.obj target_before.obj || fail "kill -9 changed the previous target (named)"
ls -A killed | grep -v '^target\.obj$' | grep -qv '^\.rsmooth-' &&
  fail "the named temporary is not .rsmooth-XXXXXX: $(ls -A killed)"

# An output name of 255 bytes (the longest a name may be): created, replaced and smoothed in place.
long=$(printf '%0251d' 0 | tr 0 n).ply
for temporary in RSMOOTH_UNUSED RSMOOTH_NAMED_TEMPORARY; do
  rm -f "$long"
  env $temporary=1 "$rsmooth" small.ply -o "$long" -q --device reference 2>err.txt ||
    fail "a 255-byte output name failed: $(cat err.txt)"
  cmp -s "$long" small_b.ply || fail "the 255-byte output does not hold the result"
  env $temporary=1 "$rsmooth" small.ply -o "$long" --force -q --device reference --sigma-g inf 2>err.txt ||
    fail "replacing a 255-byte output name failed: $(cat err.txt)"
  cmp -s "$long" small_a.ply || fail "--force did not replace the 255-byte output"
  env $temporary=1 "$rsmooth" "$long" --in-place -q --device reference 2>err.txt ||
    fail "--in-place on a 255-byte name failed: $(cat err.txt)"
done
rm -f "$long"

# --in-place and --force keep the mode, owner and group of the file they replace; a new file gets
# the umask's mode.
cp small.ply perm.ply && chmod 0600 perm.ply
cp small_a.ply permout.ply && chmod 0640 permout.ply
if [ "$(id -u)" -eq 0 ]; then
  chown 1234:1234 perm.ply
  chown 1234:5678 permout.ply
  owner_600="600 1234 1234" owner_640="640 1234 5678"
else
  echo "not root: checking that modes are kept (owners are the runner's own)"
  owner_600="600 $(id -u) $(id -g)" owner_640="640 $(id -u) $(id -g)"
fi
expect 0 "$rsmooth" perm.ply --in-place -q --device reference
[ "$(mode_owner perm.ply)" = "$owner_600" ] ||
  fail "--in-place changed the mode or owner: $(mode_owner perm.ply), was $owner_600"
cmp -s perm.ply small_b.ply || fail "--in-place did not write the result"
expect 0 "$rsmooth" small.ply -o permout.ply --force -q --device reference
[ "$(mode_owner permout.ply)" = "$owner_640" ] ||
  fail "--force changed the mode or owner: $(mode_owner permout.ply), was $owner_640"
cmp -s permout.ply small_b.ply || fail "--force did not write the result"
(umask 027 && "$rsmooth" small.ply -o umask.ply -q --device reference) || fail "umask run failed"
[ "$(stat -c %a umask.ply)" = 640 ] || fail "a new file ignores the umask: $(stat -c %a umask.ply)"
# Not root: another user's file replaced keeps its mode; its owner cannot be kept, and that is said.
if [ "$(id -u)" -eq 0 ] && command -v setpriv >/dev/null &&
  setpriv --reuid=1234 --regid=1234 --clear-groups true 2>/dev/null; then
  as_user() { setpriv --reuid=1234 --regid=1234 --clear-groups "$@"; }
  chmod 0711 "$dir"
  mkdir -m 0777 shared
  cp small.ply shared/in.ply && chmod 0644 shared/in.ply
  cp small_a.ply shared/theirs.ply && chown 4321:4321 shared/theirs.ply && chmod 0604 shared/theirs.ply
  expect 0 as_user "$rsmooth" shared/in.ply -o shared/theirs.ply --force --device reference
  [ "$(mode_owner shared/theirs.ply)" = "604 1234 1234" ] ||
    fail "another user's file replaced: $(mode_owner shared/theirs.ply), wanted 604 1234 1234"
  grep -q "shared/theirs.ply: warning: .*owner" err.txt ||
    fail "the changed owner is not said: $(cat err.txt)"
  cp small.ply shared/mine.ply && chown 1234:1234 shared/mine.ply && chmod 0600 shared/mine.ply
  expect 0 as_user "$rsmooth" shared/mine.ply --in-place --device reference
  [ "$(mode_owner shared/mine.ply)" = "600 1234 1234" ] ||
    fail "a user's own file in place: $(mode_owner shared/mine.ply)"
  grep -q "warning" err.txt && fail "a warning for a file whose owner was kept: $(cat err.txt)"
  cmp -s shared/mine.ply small_b.ply || fail "--in-place as a user did not write the result"
  only_files shared in.ply theirs.ply mine.ply
  mkdir -m 0755 locked
  expect 2 as_user "$rsmooth" shared/in.ply -o locked/x.ply --device reference
  grep -q "locked/x.ply: cannot write in folder 'locked'" err.txt ||
    fail "an output folder the user may not write in is not explained: $(cat err.txt)"
else
  echo "skipping the non-root ownership checks (needs root and setpriv)"
fi

# Symbolic links: --in-place writes through to the file a link names (the link stays); -o naming a
# link to a file needs --force and then writes through too; a link to nothing is never written
# through; a file that is not a regular file is never replaced.
rm -rf real && mkdir real
cp small.ply real/target.ply && chmod 0640 real/target.ply
ln -s real/target.ply link.ply
ln -s link.ply link2.ply
expect 0 "$rsmooth" link2.ply --in-place -q --device reference
[ -L link.ply ] && [ "$(readlink link.ply)" = real/target.ply ] || fail "--in-place replaced the link"
[ -L link2.ply ] && [ "$(readlink link2.ply)" = link.ply ] || fail "--in-place replaced the link"
cmp -s real/target.ply small_b.ply || fail "--in-place on a link did not smooth its target"
[ "$(stat -c %a real/target.ply)" = 640 ] || fail "--in-place on a link changed the target's mode"
only_files real target.ply
# the format follows the file written: a link named .obj to a PLY file stays PLY
ln -s real/target.ply objlink.obj
expect 0 "$rsmooth" objlink.obj --in-place -q --device reference
[ "$(head -c 3 real/target.ply)" = ply ] || fail "--in-place through a .obj link wrote OBJ into a .ply"
cp small_a.ply real/out.ply
ln -s real/out.ply outlink.ply
expect 2 "$rsmooth" small.ply -o outlink.ply --device reference
grep -q "outlink.ply: already exists" err.txt || fail "a link to a file replaced: $(cat err.txt)"
cmp -s real/out.ply small_a.ply || fail "a link's target changed without --force"
expect 0 "$rsmooth" small.ply -o outlink.ply --force -q --device reference
[ -L outlink.ply ] || fail "-o LINK --force replaced the link"
cmp -s real/out.ply small_b.ply || fail "-o LINK --force did not write the link's target"
ln -s real/nothing.ply dangling.ply
for force in "" --force; do
  expect 2 "$rsmooth" small.ply -o dangling.ply $force --device reference
  grep -q "dangling.ply: is a symbolic link to .*nothing.ply.*, which does not exist" err.txt ||
    fail "a dangling link $force is not explained: $(cat err.txt)"
  [ -L dangling.ply ] && [ ! -e real/nothing.ply ] || fail "a dangling link was written $force"
done
only_files real target.ply out.ply
# A file with another hard link: this name gets the result, the other keeps the old content, and
# a warning says so.
cp small.ply hard.ply && ln hard.ply hard_other.ply
expect 0 "$rsmooth" hard.ply --in-place --device reference
grep -q "hard.ply: warning: the file has 2 hard links" err.txt ||
  fail "--in-place on a file with two hard links says nothing: $(cat err.txt)"
cmp -s hard.ply small_b.ply && cmp -s hard_other.ply small.ply ||
  fail "--in-place on a hard link: the name or its other link does not hold what it should"
# An output folder that is missing, or that the user may not write in, is found before the work.
# A missing folder is made (mode 0777 less the umask, said on stderr); a part of the path that
# is a file is named before the work.
(umask 027; "$rsmooth" small.ply -o nofolder/sub/x.ply --device reference) >out.txt 2>err.txt ||
  fail "-o into missing folders failed: $(cat err.txt)"
[ -s nofolder/sub/x.ply ] || fail "-o nofolder/sub/x.ply wrote nothing"
grep -q "created the folder nofolder/sub" err.txt || fail "made folders not said: $(cat err.txt)"
[ "$(stat -c %a nofolder) $(stat -c %a nofolder/sub)" = "750 750" ] ||
  fail "made folders' modes ignore the umask: $(stat -c %a nofolder nofolder/sub)"
expect 0 "$rsmooth" small.ply -o nofolder/q/x.ply --device reference -q --confidence c2/c.ply
[ -s nofolder/q/x.ply ] && [ -s c2/c.ply ] && [ ! -s err.txt ] ||
  fail "-q with missing folders: $(cat err.txt)"
expect 2 "$rsmooth" small.ply -o small.ply/sub/x.ply --device reference
grep -q "small.ply/sub/x.ply: 'small.ply' is not a folder" err.txt ||
  fail "a file in the output's path is not named before the work: $(cat err.txt)"
grep -q "vertices" err.txt && fail "the work was done before finding the output folder wrong"
mkfifo fifo.ply
expect 2 "$rsmooth" small.ply -o fifo.ply --force --device reference
grep -q "fifo.ply: is not a regular file" err.txt || fail "a FIFO output is not refused: $(cat err.txt)"
[ -p fifo.ply ] || fail "a FIFO was replaced"

# rsmooth noise never writes what rsmooth refuses: an absurd sigma is a usage error, and noise that
# would carry a vertex beyond the supported magnitude (1e150) is refused before writing.
expect 2 "$rsmooth" noise smalltruth.ply huge.ply --sigma 1e308
grep -q -- "--sigma" err.txt || fail "--sigma 1e308 is not explained: $(cat err.txt)"
[ -e huge.ply ] && fail "rsmooth noise wrote a result for --sigma 1e308"
printf 'v 0 0 0\nv 1e148 0 0\nv 0 1e148 0\nv 0 0 1e148\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n' > vast.obj
expect 2 "$rsmooth" noise vast.obj vast_noisy.obj --sigma 1e4
grep -q "vast_noisy.obj: .*beyond" err.txt || fail "noise beyond 1e150 is not explained: $(cat err.txt)"
[ -e vast_noisy.obj ] && fail "rsmooth noise wrote coordinates beyond 1e150"
expect 0 "$rsmooth" noise vast.obj vast_noisy.obj --sigma 1e-3 -q
expect 0 "$rsmooth" vast_noisy.obj -o vast_smooth.obj -q --device reference

# The memory budget: junk or 0 is a usage error (2) from the option and from the variable alike;
# the option wins over the variable.
for budget in lots 0; do
  RSMOOTH_MEMORY_BUDGET=$budget expect 2 "$rsmooth" small.ply -o x.ply
  grep -q "RSMOOTH_MEMORY_BUDGET='$budget'" err.txt ||
    fail "RSMOOTH_MEMORY_BUDGET=$budget is not named: $(cat err.txt)"
done
expect 2 "$rsmooth" small.ply -o x.ply --memory-budget 0
grep -q "leave it out" err.txt || fail "--memory-budget 0 does not say how to get the default: $(cat err.txt)"
RSMOOTH_MEMORY_BUDGET=lots expect 0 "$rsmooth" small.ply -o budget.ply -q --memory-budget 256M
[ -e x.ply ] && fail "a refused memory budget wrote its output"

# Every scale alike: a tetrahedron reaching 1e39 and a noisy grid at 1e-20 and 1e120
# come out finite on both paths, moved, and the same on both; vertices only, no faces and no
# normals, is refused naming the end of the file.
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1e39\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n' > tall.obj
for device in cpu reference; do
  expect 0 "$rsmooth" tall.obj -o tall_$device.obj --device $device
  grep -qiE 'nan|inf' tall_$device.obj && fail "non-finite output on $device: $(cat tall_$device.obj)"
done
expect 0 "$shape" make grid.obj grid_truth.obj --noise 0.3 --triangles 800
for scale in 1e-20 1e120; do
  awk -v s=$scale '/^v / { printf "v %.17g %.17g %.17g\n", $2 * s, $3 * s, $4 * s; next } { print }' \
    grid.obj > grid_$scale.obj
  expect 0 "$rsmooth" grid_$scale.obj -o grid_${scale}_cpu.obj --device cpu
  expect 0 "$rsmooth" grid_$scale.obj -o grid_${scale}_ref.obj --device reference
  grep -qiE 'nan|inf' grid_${scale}_cpu.obj && fail "non-finite output at $scale"
  cmp -s grid_$scale.obj grid_${scale}_ref.obj && fail "nothing moved at $scale"
  # largest OpenCL - reference difference against the largest move, both in mesh units
  paste -d' ' <(grep '^v ' grid_$scale.obj) <(grep '^v ' grid_${scale}_cpu.obj) \
    <(grep '^v ' grid_${scale}_ref.obj) | awk -v s=$scale '
    function abs(x) { return x < 0 ? -x : x }
    { for (k = 2; k <= 4; k++) { m = abs($(k + 8) - $k); if (m > move) move = m
                                 d = abs($(k + 4) - $(k + 8)); if (d > diff) diff = d } }
    END { printf "grid at %s: largest move %.3g, OpenCL - reference %.3g\n", s, move, diff
          exit !(move > 0 && diff < 1e-3 * move) }' || fail "OpenCL and reference disagree at $scale"
done
# An output whose number type cannot hold the input at its scale is refused before any work, with
# nothing written (binary STL stores float32: a mesh at 1e-150 would come out all zeros).
printf 'v 0 0 0\nv 1e-150 0 0\nv 0 1e-150 0\nv 0 0 1e-150\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n' \
  > small150.obj
expect 2 "$rsmooth" small150.obj -o small150.stl
grep -q "small150.stl: cannot hold small150.obj" err.txt || fail "float32 STL at 1e-150: $(cat err.txt)"
[ -e small150.stl ] && fail "a binary STL was written for a mesh at 1e-150"
expect 2 "$rsmooth" small150.obj -o small150.obj.out.ply --confidence small150_conf.stl
[ -e small150.obj.out.ply ] && fail "output written although the confidence file cannot hold it"
expect 2 "$rsmooth" noise small150.obj small150_noisy.stl --sigma 0.1
grep -q "small150_noisy.stl: cannot hold small150.obj" err.txt || fail "noise to STL at 1e-150: $(cat err.txt)"
[ -e small150_noisy.stl ] && fail "rsmooth noise wrote a binary STL of a mesh at 1e-150"
expect 0 "$rsmooth" small150.obj -o small150.ply
expect 0 "$rsmooth" small150.obj -o small150_ascii.stl --ascii
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\n' > vertices_only.obj
expect 2 "$rsmooth" vertices_only.obj -o x.obj
grep -q "vertices_only.obj: byte 24" err.txt || fail "no faces, no normals: not located: $(cat err.txt)"
# rsmooth noise works at every scale too (its mean edge and normals are scale-free)
printf 'v 0 0 0\nv 1e-300 0 0\nv 0 1e-300 0\nv 0 0 1e-300\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n' \
  > tiny.obj
expect 0 "$rsmooth" noise tiny.obj tiny_noisy.obj --sigma 0.1
cmp -s tiny.obj tiny_noisy.obj && fail "rsmooth noise did not move a mesh at 1e-300"

# Typos: "did you mean" for an option and for a subcommand (unless the word is a file)
expect 2 "$rsmooth" --sigma_f 1 noisy.ply -o typo.ply
grep -q "unknown option '--sigma_f' (did you mean --sigma-f?)" err.txt ||
  fail "no suggestion for --sigma_f: $(cat err.txt)"
expect 2 "$rsmooth" noisy.ply -o typo.ply --jsn
grep -q "(did you mean --json?)" err.txt || fail "no suggestion for --jsn: $(cat err.txt)"
expect 2 "$rsmooth" noisy.ply -o typo.ply --zzzzzz
grep -q "did you mean" err.txt && fail "a suggestion for a word near nothing: $(cat err.txt)"
expect 2 "$rsmooth" compre a.ply b.ply
grep -q 'did you mean "compare"?' err.txt || fail "no suggestion for compre: $(cat err.txt)"
grep -q "no output file" err.txt && fail "compre taken for an input: $(cat err.txt)"
expect 2 "$rsmooth" rendr noisy.ply -o x.png
grep -q 'did you mean "render"?' err.txt || fail "no suggestion for rendr: $(cat err.txt)"
cp noisy.ply nois
expect 0 "$rsmooth" nois -o nois_out.ply -q --format ply
[ -s nois_out.ply ] || fail "an input file named like a subcommand (nois) was not smoothed"

# --progress: the bar into a file (whole lines, no carriage returns); -q still wins
expect 0 "$rsmooth" noisy.ply -o progress.ply --progress --device reference
grep -q '^\[[#.]*\] *[0-9]*% reading' err.txt || fail "--progress drew no bar: $(cat err.txt)"
grep -q "$(printf '\r')" err.txt && fail "--progress wrote carriage returns into a file"
expect 0 "$rsmooth" noisy.ply -o progress_q.ply --progress -q --device reference
[ -s err.txt ] && fail "--progress -q printed: $(cat err.txt)"

# --auto's choice per region hands a coarse curved mesh to Taubin smoothing: the status line and
# --json say so
awk 'BEGIN { pi = atan2(0, -1); R = 12; C = 24; print "v 0 0 1"
  for (i = 1; i < R; i++) for (j = 0; j < C; j++) {
    t = pi * i / R; p = 2 * pi * j / C; printf "v %.9f %.9f %.9f\n", sin(t) * cos(p), sin(t) * sin(p), cos(t) }
  print "v 0 0 -1"; n = 2 + (R - 1) * C
  for (j = 0; j < C; j++) printf "f 1 %d %d\n", 2 + j, 2 + (j + 1) % C
  for (i = 0; i < R - 2; i++) for (j = 0; j < C; j++) {
    a = 2 + i * C + j; b = 2 + i * C + (j + 1) % C; printf "f %d %d %d\nf %d %d %d\n", a, a + C, b + C, a, b + C, b }
  for (j = 0; j < C; j++) printf "f %d %d %d\n", 2 + (R - 2) * C + j, n, 2 + (R - 2) * C + (j + 1) % C }' > uv.obj
expect 0 "$rsmooth" noise uv.obj uv_noisy.obj --sigma 0.3 --seed 1
expect 0 "$rsmooth" uv_noisy.obj -o uv_out.obj --best --auto --json --device reference
grep -q '"region_choice":{"taubin_iterations":[1-9][0-9]*,"lambda":0.5,"mu":-0.53,"filter_share":0\.0' out.txt ||
  fail "--json after --auto's choice per region does not say Taubin took the sphere: $(cat out.txt)"
status=$(grep "wrote uv_out.obj" err.txt)
echo "$status" | grep -q "; the filter ([0-9]*%) blended per region with Taubin smoothing, [1-9][0-9]* iterations" ||
  fail "the status line after --auto's choice per region: $status"
echo "$status" | grep -q "sigma_f" && fail "the status line names the filter's sigmas: $status"
grep -q -- "--auto: a choice per region" err.txt || fail "--auto does not explain its choice: $(cat err.txt)"

expect 0 "$rsmooth" --help
grep -q "sigma-g" out.txt || fail "--help does not explain sigma-g"
grep -q "\-\-sigma-c" out.txt || fail "--help does not explain --sigma-c"
grep -q "\-\-best" out.txt || fail "--help does not explain --best"
grep -q "symbolic link" out.txt || fail "--help does not say what happens to symbolic links"
grep -q "owner" out.txt || fail "--help does not say that the mode and owner are kept"
grep -q "concurrent" out.txt || fail "--help does not say what concurrent runs do"
expect 0 "$rsmooth" --version

if [ "$failures" -ne 0 ]; then
  echo "$failures failure(s)"
  exit 1
fi
echo "command: all checks passed"
