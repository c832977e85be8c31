#!/usr/bin/env bash
# The command where no OpenCL loader can be found (RSMOOTH_OPENCL_LIBRARY names a missing file): it
# starts, the reference path runs, auto falls back with a warning that says why, an OpenCL device is
# refused with the reason. Then a loader without platforms, and a library that is no loader. And
# nothing built needs libOpenCL: rsmooth opens the loader at run time.
# Arguments: rsmooth, rsmooth-demo-shape, then libraries and programs that must not need libOpenCL.
set -uo pipefail
rsmooth=$1
shape=$2
shift 2
. "$(dirname "$0")/command_util.sh"
missing=/nonexistent/libOpenCL.so.1
unset RSMOOTH_DEVICE # the default device is auto here, whatever the caller chose

# Linked: no libOpenCL among the NEEDED libraries, no undefined OpenCL function (each goes
# through lib/opencl/cl_loader.c's table).
for file in "$rsmooth" "$shape" "$@"; do
  needed=$(readelf -d "$file" 2>/dev/null | grep NEEDED)
  grep -q libOpenCL <<<"$needed" && fail "$file needs libOpenCL: $needed"
  case $file in
    *.a) undefined=$(nm -u "$file" 2>/dev/null) ;;
    *) undefined=$(nm -D -u "$file" 2>/dev/null) ;;
  esac
  grep -qE ' cl[A-Z][A-Za-z]*$' <<<"$undefined" &&
    fail "$file calls OpenCL directly: $(grep -E ' cl[A-Z]' <<<"$undefined" | head -3)"
done

expect 0 "$shape" make noisy.ply truth.ply --noise 0.3 --triangles 600
mkdir empty

# No loader at all.
export RSMOOTH_OPENCL_LIBRARY=$missing
expect 0 "$rsmooth" --version
expect 0 "$rsmooth" noisy.ply -o reference.ply --device reference
[ -s reference.ply ] || fail "--device reference wrote nothing without a loader"
grep -q loader err.txt && fail "--device reference mentions the loader: $(cat err.txt)"
for device in "" "--device auto"; do
  rm -f auto.ply
  expect 0 "$rsmooth" noisy.ply -o auto.ply $device
  grep -q "warning: no OpenCL loader: $missing" err.txt ||
    fail "auto ($device) gives no warning naming the missing loader: $(cat err.txt)"
  grep -q "reference path" err.txt || fail "auto ($device) does not say it falls back: $(cat err.txt)"
  cmp -s auto.ply reference.ply || fail "auto ($device) without a loader differs from the reference"
done
expect 0 "$rsmooth" noisy.ply -o quiet.ply -q
[ -s err.txt ] && fail "--quiet printed the fallback warning: $(cat err.txt)"
expect 2 "$rsmooth" noisy.ply -o cpu.ply --device cpu
grep -q "no OpenCL loader: $missing" err.txt || fail "--device cpu: loader not named: $(cat err.txt)"
[ -e cpu.ply ] && fail "--device cpu wrote its output without a loader"
expect 0 "$rsmooth" --list-devices
grep -q "no OpenCL loader: $missing" out.txt || fail "--list-devices: no loader not said: $(cat out.txt)"
grep -q "reference" out.txt || fail "--list-devices does not point at --device reference"

# Empty is unset: the default loader.
RSMOOTH_OPENCL_LIBRARY= expect 0 "$rsmooth" --list-devices
grep -q "$missing" out.txt && fail "an empty RSMOOTH_OPENCL_LIBRARY was used: $(cat out.txt)"
unset RSMOOTH_OPENCL_LIBRARY

# A library that is no OpenCL loader (the C library, when it goes by the glibc name).
if ldd "$rsmooth" 2>/dev/null | grep -q 'libc\.so\.6'; then
  RSMOOTH_OPENCL_LIBRARY=libc.so.6 expect 2 "$rsmooth" noisy.ply -o x.ply --device cpu
  grep -q "libc.so.6 (RSMOOTH_OPENCL_LIBRARY) lacks cl" err.txt ||
    fail "a library without OpenCL functions is not refused so: $(cat err.txt)"
fi

# The loader where it is installed, named: as good as finding it (the same device list).
loader=$( (ldconfig -p || /sbin/ldconfig -p) 2>/dev/null | sed -n 's/.*libOpenCL\.so\.1 .*=> //p' |
  head -1)
if [ -n "$loader" ]; then
  expect 0 "$rsmooth" --list-devices
  mv out.txt default.txt
  RSMOOTH_OPENCL_LIBRARY=$loader expect 0 "$rsmooth" --list-devices
  cmp -s out.txt default.txt || fail "RSMOOTH_OPENCL_LIBRARY=$loader lists other devices"
fi

# Named files that must never reach dlopen: a truncated copy of the loader
# (dlopen maps segments past the file's end: SIGBUS), copies ending in zeros or with zeroed code
# (SIGSEGV inside dlopen or the constructors), a FIFO (blocks forever), a device, a folder, a text
# file. Each refused before dlopen, naming the file and why, within seconds.
if [ -n "$loader" ]; then
  real=$(readlink -f "$loader")
  head -c 30000 "$real" >truncated.so
  head -c 200 "$real" >headers-only.so
  mkfifo fifo.so
  echo "not a library" >text.so
  # copies whose end, or a block of whose code, is zeros (an incomplete copy, a sparse file):
  # dlopen crashed in their relocations, versions or constructors
  size=$(stat -Lc %s "$real")
  head -c 8192 "$real" >zero-padded.so
  truncate -s "$size" zero-padded.so
  cp "$real" zero-tail.so
  dd if=/dev/zero of=zero-tail.so bs=1 seek=$((size - 4096)) count=4096 conv=notrunc 2>/dev/null
  head -c 8192 "$real" >sparse.so
  truncate -s 1G sparse.so
  text=$((0x$(readelf -SW "$real" | awk '$2 == ".text" { print $5 }')))
  cp "$real" zero-code.so
  dd if=/dev/zero of=zero-code.so bs=1 seek=$((text + 64)) count=400 conv=notrunc 2>/dev/null
  for case in "truncated.so:truncated" "headers-only.so:truncated" "fifo.so:not a regular file" \
              "/dev/zero:not a regular file" "empty:a folder" "text.so:not an ELF file" \
              "zero-padded.so:damaged" "zero-tail.so:damaged" "sparse.so:damaged" \
              "zero-code.so:damaged (its code holds a block of zeros"; do
    file=${case%%:*} why=${case#*:}
    [ "${file#/}" = "$file" ] && file=$PWD/$file
    RSMOOTH_OPENCL_LIBRARY=$file expect_within 20 2 "$rsmooth" noisy.ply -o x.ply --device cpu
    grep -q "no OpenCL loader: $file (RSMOOTH_OPENCL_LIBRARY) could not be loaded ($why" err.txt ||
      fail "RSMOOTH_OPENCL_LIBRARY=$file: not refused as '$why': $(cat err.txt)"
    RSMOOTH_OPENCL_LIBRARY=$file expect_within 20 0 "$rsmooth" noisy.ply -o auto-$$.ply --force
    grep -q "warning: no OpenCL loader: $file" err.txt ||
      fail "RSMOOTH_OPENCL_LIBRARY=$file: auto gives no warning: $(cat err.txt)"
  done
fi

# Really absent, where a user namespace can hide the installed loader (/dev/null over its file).
if [ -n "$loader" ] && unshare -r -m true 2>/dev/null; then
  unshare -r -m sh -c 'mount --bind /dev/null "$1" && exec "$2" noisy.ply -o hidden.ply' \
    sh "$(readlink -f "$loader")" "$rsmooth" >out.txt 2>err.txt
  status=$?
  [ "$status" -eq 0 ] || fail "with the loader hidden, exit $status: $(cat err.txt)"
  grep -q "warning: no OpenCL loader: libOpenCL.so.1 could not be loaded" err.txt ||
    fail "with the loader hidden, the warning does not say so: $(cat err.txt)"
  cmp -s hidden.ply reference.ply || fail "with the loader hidden, auto differs from the reference"
fi

# A loader without platforms: auto falls back too, saying there is no platform.
OCL_ICD_VENDORS=$PWD/empty OCL_ICD_FILENAMES= expect 0 "$rsmooth" noisy.ply -o none.ply
grep -q "reference path" err.txt || fail "no platform: no fallback warning: $(cat err.txt)"
if [ -n "$loader" ]; then
  grep -q "no OpenCL platform" err.txt || fail "no platform: warning says otherwise: $(cat err.txt)"
fi
cmp -s none.ply reference.ply || fail "auto without a platform differs from the reference"

if [ "$failures" -ne 0 ]; then
  echo "$failures failure(s)"
  exit 1
fi
echo "loader_command: all checks passed"
