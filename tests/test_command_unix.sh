#!/usr/bin/env bash
# The command's Unix conventions: --opt=value, -oFILE, '--', options after the files; '-' for
# standard input and output, byte for byte what files give; several inputs into a folder or
# beside themselves with --suffix, going on past a broken one; render --size per panel.
set -uo pipefail
rsmooth=$1
shape=$2
. "$(dirname "$0")/command_util.sh"

expect 0 "$shape" make noisy.ply truth.ply --noise 0.3 --triangles 1500
ref="--device reference"
# --opt=value, -oFILE, options after the operand and '--' give what the spaced forms give
expect 0 "$rsmooth" noisy.ply -o spaced.ply --sigma-f 1.5 --sigma-g 0.4 --passes 2 $ref -q
expect 0 "$rsmooth" --sigma-f=1.5 -oequals.ply --passes=2 --device=reference -q --sigma-g=0.4 \
  -- noisy.ply
cmp -s spaced.ply equals.ply || fail "--opt=value forms give another result than --opt value"
expect 0 "$rsmooth" -qf noisy.ply --output=equals.ply --sigma-f=1.5 --sigma-g=0.4 --passes=2 $ref
cmp -s spaced.ply equals.ply || fail "-qf and --output= give another result"
expect 0 "$rsmooth" -fqfqfqfqfqfqfqfq noisy.ply -o equals.ply --sigma-f=1.5 --sigma-g=0.4 --passes=2 $ref
cmp -s spaced.ply equals.ply || fail "many grouped flags give another result"
expect 0 "$rsmooth" noisy.ply -o neg.ply --method=taubin --mu=-0.45 --iterations=3 -q
expect 2 "$rsmooth" noisy.ply -o x.ply --sigma-f=abc
grep -q -- "--sigma-f: not a number: 'abc'" err.txt || fail "bad --sigma-f= value: $(cat err.txt)"
expect 2 "$rsmooth" noisy.ply -o x.ply --force=yes
grep -q -- "--force takes no value" err.txt || fail "--force=yes: $(cat err.txt)"
expect 2 "$rsmooth" noisy.ply -o x.ply --sigma-q=1
grep -q -- "unknown option '--sigma-q'" err.txt || fail "unknown option not named: $(cat err.txt)"
expect 2 "$rsmooth" noisy.ply -o x.ply --forc
grep -q -- "unknown option '--forc'" err.txt || fail "an abbreviation is taken: $(cat err.txt)"
expect 2 "$rsmooth" -o x.ply -- noisy.ply --quiet
grep -q "2 inputs" err.txt || fail "an option after -- is not an operand: $(cat err.txt)"
expect 2 "$rsmooth" noisy.ply -o
grep -q -- "-o needs a value" err.txt || fail "-o without a value: $(cat err.txt)"
expect 2 "$rsmooth" noisy.ply -o x.ply --format=xyz
grep -q -- "--format: 'xyz'" err.txt || fail "bad --format: $(cat err.txt)"
expect 0 "$rsmooth" noise noisy.ply noisier.ply --sigma=0.1 --seed=2
expect 0 "$rsmooth" compare noisier.ply noisy.ply --json
expect 2 "$rsmooth" compare noisier.ply noisy.ply --jsn
[ -e x.ply ] && fail "an output written after a usage error"

# '-' and '-o -': the bytes of file to file, for binary PLY and for OBJ (and --format)
expect 0 "$rsmooth" noisy.ply -o file.ply $ref -q
cat noisy.ply | "$rsmooth" - -o - $ref > pipe.ply 2> err.txt || fail "- -o - failed: $(cat err.txt)"
cmp -s file.ply pipe.ply || fail "cat in.ply | rsmooth - -o - differs from rsmooth in.ply -o out.ply"
grep -q "wrote <stdout>" err.txt || fail "no status line on stderr for -o -: $(cat err.txt)"
expect 0 "$rsmooth" noisy.ply -o noisy.obj $ref -q
expect 0 "$rsmooth" noisy.obj -o file.obj $ref -q
"$rsmooth" - -o - $ref < noisy.obj > pipe.obj 2> err.txt || fail "OBJ - -o - failed: $(cat err.txt)"
cmp -s file.obj pipe.obj || fail "OBJ through pipes differs from file to file"
"$rsmooth" - -o - $ref -q --format obj < noisy.ply > format.obj || fail "--format obj failed"
expect 0 "$rsmooth" noisy.ply -o format_file.obj $ref -q
cmp -s format.obj format_file.obj || fail "--format obj to stdout differs from -o x.obj"
"$rsmooth" noisy.ply -o - $ref -q --format=stl --ascii > format.stl || fail "--format=stl failed"
head -c 6 format.stl | grep -q "^solid" || fail "--format stl --ascii wrote: $(head -c 20 format.stl)"
expect 0 "$rsmooth" noisy.ply -o written.off --format ply $ref -q
head -c 3 written.off | grep -q "^ply" || fail "--format ply did not win over the extension .off"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n' > bad.obj
"$rsmooth" - -o - < bad.obj > none.ply 2> err.txt
[ $? -eq 2 ] || fail "a bad standard input did not exit 2"
grep -q "<stdin>:4" err.txt || fail "a bad standard input is not located: $(cat err.txt)"
[ -s none.ply ] && fail "something went to stdout for a bad input"
expect 2 "$rsmooth" - -o - --json
grep -q -- "--json" err.txt || fail "--json with -o - not refused: $(cat err.txt)"
expect 2 "$rsmooth" - noisy.ply -o out/

# Several inputs into one folder, one of them broken: the others written, a summary, exit 2
mkdir out
cp noisy.obj a.obj
printf 'ply\nformat ascii 1.0\nelement vertex 3\n' > b.ply
cp file.ply c.ply
expect 2 "$rsmooth" a.obj b.ply c.ply -o out/ $ref
[ -s out/a.obj ] && [ -s out/c.ply ] || fail "the good inputs were not written: $(ls out)"
[ -e out/b.ply ] && fail "the broken input was written"
grep -q "^rsmooth: b.ply" err.txt || fail "the broken file is not named: $(cat err.txt)"
grep -q "3 files: 2 smoothed, 1 failed (b.ply)" err.txt || fail "no summary: $(cat err.txt)"
[ "$(grep -c 'wrote out/' err.txt)" -eq 2 ] || fail "not one status line per file: $(cat err.txt)"
"$rsmooth" a.obj -o single.obj $ref -q
cmp -s single.obj out/a.obj || fail "a.obj in a folder differs from a.obj alone"
# existing results are not replaced without --force; with it they are
expect 2 "$rsmooth" a.obj c.ply -o out $ref
grep -q "out/a.obj: already exists" err.txt || fail "existing output replaced: $(cat err.txt)"
expect 0 "$rsmooth" a.obj c.ply -o out --force $ref -q
[ -s err.txt ] && fail "-q printed: $(cat err.txt)"
# one input and an existing folder named without the '/': the mistake it always was (nothing
# written into the folder); with the '/' it is the folder
mkdir one
expect 2 "$rsmooth" a.obj -o one $ref -q
grep -q "one: is a directory" err.txt || fail "-o FOLDER for one input: $(cat err.txt)"
[ -z "$(ls one)" ] || fail "-o FOLDER for one input wrote into it: $(ls one)"
expect 0 "$rsmooth" a.obj -o one/ $ref -q
[ -s one/a.obj ] || fail "-o FOLDER/ for one input did not write one/a.obj"
expect 2 "$rsmooth" a.obj c.ply -o one.ply
grep -q "2 inputs: -o must be a folder" err.txt || fail "two inputs to one file: $(cat err.txt)"
expect 2 "$rsmooth" a.obj out/../a.obj -o out/
grep -q "would both be written to out/a.obj" err.txt || fail "same output twice: $(cat err.txt)"
expect 0 "$rsmooth" a.obj -o missing/ $ref
[ -s missing/a.obj ] || fail "-o missing/ did not make the folder: $(cat err.txt)"
grep -q "created the folder missing" err.txt || fail "-o missing/ made it silently"
expect 2 "$rsmooth" a.obj -o a.obj/ $ref
grep -q "a.obj/: is not a folder\|'a.obj' is not a folder" err.txt || fail "-o FILE/: $(cat err.txt)"

# --suffix: beside each input; with --format the format's extension
mkdir sub
cp c.ply sub/d.ply
expect 0 "$rsmooth" a.obj sub/d.ply --suffix _smooth $ref
[ -s a_smooth.obj ] && [ -s sub/d_smooth.ply ] || fail "--suffix did not write beside: $(ls . sub)"
grep -q "2 files: 2 smoothed" err.txt || fail "no summary for --suffix: $(cat err.txt)"
cmp -s a_smooth.obj single.obj || fail "--suffix result differs"
expect 0 "$rsmooth" a.obj --suffix=_s --format=off $ref -q
head -c 3 a_s.off | grep -q OFF || fail "--suffix with --format off did not write a_s.off"
expect 2 "$rsmooth" a.obj --suffix _smooth $ref
grep -q "a_smooth.obj: already exists" err.txt || fail "--suffix replaced a file: $(cat err.txt)"

# render --size is each panel's, as the default (800x800 per panel) is
expect 0 "$rsmooth" render noisy.ply file.ply -o two.png --size=100x80
size=$(od -An -tu1 -j16 -N8 two.png | tr -s ' ')
[ "$size" = " 0 0 0 206 0 0 0 80" ] || fail "render --size 100x80 of 2 panels is not 206x80: $size"

# --mask FILE: the listed vertices move, the others keep their input bit for bit; on the
# listed ones the result is the unmasked one (one pass: every triangle still supports them)
expect 0 "$shape" make mnoisy.obj mtruth.obj --noise 0.3 --triangles 1500
expect 0 "$rsmooth" mnoisy.obj -o plain.obj $ref -q
printf '# every third vertex\n' > mask.txt
awk '$1 == "v" { n++ } END { for (i = 0; i < n; i += 3) printf "%d%s", i, (i % 30 == 27 ? "\n" : ", ") }' \
  mnoisy.obj >> mask.txt
expect 0 "$rsmooth" mnoisy.obj -o masked.obj --mask=mask.txt $ref -q
awk 'FNR == 1 { file++ } $1 == "v" { v[file, n[file]++] = $2 " " $3 " " $4 }
     END {
       bad = 0
       for (i = 0; i < n[1]; i++) {
         want = (i % 3 == 0) ? v[2, i] : v[3, i]   # listed: the unmasked result; else the input
         split(want, w); split(v[1, i], g)
         if (g[1] != w[1] || g[2] != w[2] || g[3] != w[3]) bad++
       }
       moved = 0
       for (i = 0; i < n[1]; i += 3) { split(v[1, i], g); split(v[3, i], w); moved += g[1] != w[1] }
       if (bad || n[1] != n[2] || n[1] != n[3] || moved < n[1] / 6) {
         print bad " of " n[1] " vertices wrong, " moved " listed moved"; exit 1 }
     }' masked.obj plain.obj mnoisy.obj ||
  fail "--mask: the listed vertices are not the unmasked result or the others moved"
printf '3\n12 x\n' > badmask.txt
expect 2 "$rsmooth" noisy.ply -o x.obj --mask badmask.txt $ref
grep -q "badmask.txt:2: 'x' is not a vertex index" err.txt || fail "bad --mask token: $(cat err.txt)"
printf '99999999\n' > farmask.txt
expect 2 "$rsmooth" noisy.ply -o x.obj --mask farmask.txt $ref
grep -q "farmask.txt:1: vertex 99999999 is beyond" err.txt || fail "far --mask: $(cat err.txt)"
expect 2 "$rsmooth" noisy.ply -o x.obj --mask mask.txt --method taubin
[ -e x.obj ] && fail "an output written after a bad --mask"
# Masks that are not text: a device is refused at once instead of read
# forever, a NUL byte is an error at its line and column instead of cutting the line, an endless
# pipe stops at the size bound; a pipe of indices works as the file does.
expect_within 20 2 "$rsmooth" noisy.ply -o x.obj --mask /dev/zero $ref
grep -q "mask /dev/zero: is a device or special file" err.txt || fail "--mask /dev/zero: $(cat err.txt)"
printf '1\0002\n' > nulmask.txt
expect_within 20 2 "$rsmooth" noisy.ply -o x.obj --mask nulmask.txt $ref
grep -q "nulmask.txt:1: a NUL byte at column 2" err.txt || fail "NUL in --mask: $(cat err.txt)"
expect_within 20 2 "$rsmooth" noisy.ply -o x.obj --mask . $ref
grep -q "mask \.: is a folder" err.txt || fail "--mask of a folder: $(cat err.txt)"
expect_within 60 2 "$rsmooth" noisy.ply -o x.obj --mask <(yes 1) $ref
grep -q "longer than .* bytes" err.txt || fail "--mask of an endless pipe: $(cat err.txt)"
[ -e x.obj ] && fail "an output written after a mask that is not text"
expect_within 60 0 "$rsmooth" mnoisy.obj -o piped.obj --mask <(cat mask.txt) $ref -q
cmp -s piped.obj masked.obj || fail "--mask from a pipe differs from the file"

[ "$failures" -eq 0 ] && echo "command (unix): all checks passed" || echo "$failures failure(s)"
exit $((failures > 0))
