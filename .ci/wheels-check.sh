#!/usr/bin/env bash
# The wheels and the sdist of dist/ (.ci/wheels.sh) as users get them. Each wheel must be
# manylinux_2_17 (its tag, auditwheel show, and no symbol of its module newer than GLIBC_2.17), and
# is installed into a fresh virtual environment of every CPython here its tags accept (abi3: 3.11
# and later, pyenv's and /usr/bin's; cpXY: that version; a Python not here is said and skipped),
# with numpy, pytest, trimesh, meshio and tqdm from PyPI (in the first also Open3D, PyVista, PyOpenCL
# and mypy, where their wheels exist: their tests skip in the others). The pytest suite tests/python/ runs from a copy outside the checkout,
# so only the installed package can be imported, against the command built in
# BUILD (the C oracle). The sdist is built and installed by pip into one more venv (the system's C
# compiler, WERROR) and used from /. A table gives each wheel, Python and the tests passed, skipped
# and failed; any failed test, unusable wheel or failed install fails the script.
# Usage: .ci/wheels-check.sh [DIST] [BUILD] [WERROR]   (make wheels-check, make python-check)
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
. .ci/find-python.sh
dist=$(cd "${1:-dist}" && pwd)
build=$(cd "${2:-build}" && pwd)
werror=${3:-OFF}
work=$build-python
rm -rf "$work"
mkdir -p "$work/tree/tests"
cp -r tests/python "$work/tree/tests/python"
export RSMOOTH_CLI="$build/rsmooth" RSMOOTH_REQUIRE_CLI=1 POCL_CACHE_DIR="$build/pocl-cache"
export PIP_DISABLE_PIP_VERSION_CHECK=1
t0=$SECONDS
tools=${WHEELS_WORK:-build-wheels}/venv/bin # .ci/wheels.sh's: auditwheel, and a recent pip
auditwheel=$tools/auditwheel
# venv DIR PYTHON [own]: a fresh venv. Where .ci/wheels.sh's recent pip supports PYTHON, that pip
# installs into the venv (--python), which then needs no pip of its own; nor are .pyc files written
# ahead (--no-compile): 6 s, not 20. Otherwise (Python 3.9 for pip 26), or with `own`, the venv
# gets its own pip.
venv() {
  if [ -z "${3:-}" ] && [ -x "$tools/pip" ] && "$2" -c 'import sys; sys.exit(sys.version_info < (3, 10))'; then
    "$2" -m venv --without-pip "$1"
  else
    "$2" -m venv "$1"
  fi
}
pip_in() {
  local v=$1; shift
  if [ -x "$v/bin/pip" ]; then
    "$v/bin/pip" install -q --no-compile "$@"
  else
    "$tools/pip" --python "$v/bin/python" install -q --no-compile "$@"
  fi
}
status=0
rows=()
fail() { echo "FAILED: $*" >&2; status=1; }

# manylinux WHEEL: the tag, auditwheel's verdict, and the newest GLIBC symbol version the module needs.
manylinux() {
  local w=$1 x=$work/unpacked/$(basename "$1" .whl) newest
  case $(basename "$w") in *manylinux_2_17_x86_64*) ;; *) fail "$w: no manylinux_2_17_x86_64 tag"; return ;; esac
  if [ -x "$auditwheel" ]; then
    "$auditwheel" show "$w" 2>&1 | tr -s '\n ' '  ' \
      | grep -q 'consistent with the following platform tag: "manylinux_2_17_x86_64"' \
      || fail "$w: auditwheel show does not say manylinux_2_17_x86_64"
  else
    echo "($auditwheel not here: the tag and objdump only)"
  fi
  mkdir -p "$x"
  python3 -m zipfile -e "$w" "$x"
  newest=$(find "$x" -name '*.so' -exec objdump -T {} + | grep -o 'GLIBC_[0-9.]*' | sort -uV | tail -1)
  echo "$(basename "$w"): $(du -k "$w" | cut -f1) KiB, newest symbol version $newest"
  [ "$(printf '%s\n' "$newest" GLIBC_2.17 | sort -V | tail -1)" = GLIBC_2.17 ] \
    || fail "$w needs $newest"
}

# run LABEL PYTHON WHEEL [EXTRA]: a fresh venv, the wheel and the test dependencies, the suite.
# The first run's is $work/venv, with a pip of its own: `make docs` adds pdoc to it.
run() {
  local label=$1 py=$2 wheel=$3 extra=${4:-} venv=$work/venv-$1 t=$SECONDS ver own=""
  if [ -n "$extra" ]; then venv=$work/venv own=own; fi
  ver=$("$py" -c 'import sys; print(sys.version.split()[0])')
  echo "== $(basename "$wheel") on Python $ver ($py)"
  if ! { venv "$venv" "$py" $own && pip_in "$venv" numpy pytest trimesh meshio tqdm "$wheel"; }; then
    fail "install into Python $ver"; rows+=("$(basename "$wheel")|$ver|install failed|||")
    return
  fi
  local lib
  for lib in $extra; do
    pip_in "$venv" "$lib" || echo "$lib did not install for Python $ver: its tests skip"
  done
  (cd "$work/tree/tests/python" && "$venv/bin/python" -c "import rsmooth, sys
assert rsmooth.__file__.startswith(sys.prefix), rsmooth.__file__
print('rsmooth', rsmooth.__version__, 'from', rsmooth.__file__)") || { fail "import on $ver"; return; }
  local rc=0
  (cd "$work/tree/tests/python" && "$venv/bin/python" -m pytest -q -rs -p no:cacheprovider \
     --junitxml="$work/junit-$label.xml" .) || rc=$?
  local counts
  counts=$(python3 - "$work/junit-$label.xml" <<'PY'
import sys, xml.etree.ElementTree as ET
r = ET.parse(sys.argv[1]).getroot()
s = r if r.tag == "testsuite" else r.find("testsuite")
n, f, e, k = (int(s.get(a, 0)) for a in ("tests", "failures", "errors", "skipped"))
print(f"{n - f - e - k}|{k}|{f + e}")
PY
) || counts="?|?|?"
  [ $rc -eq 0 ] || fail "pytest on Python $ver ($(basename "$wheel")): exit $rc"
  rows+=("$(basename "$wheel")|$ver|$counts|$((SECONDS - t)) s")
}

echo "== the wheels in $dist"
shopt -s nullglob
wheels=("$dist"/rsmooth-*-abi3-*.whl) # the abi3 wheel first: its first Python gets Open3D
for w in "$dist"/rsmooth-*.whl; do case $w in *-abi3-*) ;; *) wheels+=("$w") ;; esac; done
[ ${#wheels[@]} -gt 0 ] || { echo "no wheel in $dist: make wheels" >&2; exit 1; }
for w in "${wheels[@]}"; do manylinux "$w"; done
for abi in cp311-abi3 cp39-cp39 cp310-cp310; do
  ls "$dist"/rsmooth-*-"$abi"-*.whl >/dev/null 2>&1 || echo "no $abi wheel in $dist (make wheels skips a Python it does not find)"
done

first=1
for w in "${wheels[@]}"; do
  case $(basename "$w") in
    *-abi3-*) minors="3.11 3.12 3.13 3.14" ;;
    *-cp3*-cp3*) abi=$(basename "$w" | sed -E 's/.*-cp3([0-9]+)-cp3[0-9]+-.*/\1/'); minors="3.$abi" ;;
    *) fail "$w: which Python?"; continue ;;
  esac
  for v in $minors; do
    found=$(pythons "$v")
    if [ -z "$found" ]; then
      echo "== $(basename "$w") on Python $v: skipped, no Python $v here"
      rows+=("$(basename "$w")|$v|not here|||")
      continue
    fi
    while read -r py; do
      extra=""
      # The mesh libraries (Open3D alone is 400 MB), PyOpenCL and mypy: once, on the first Python;
      # the other Pythons run the same suite, those libraries' tests skipping there.
      if [ $first = 1 ]; then extra="open3d pyvista pyopencl mypy"; first=0; fi
      run "$(echo "$py" | tr / _)" "$py" "$w" "$extra"
    done <<<"$found"
  done
done

echo "== the sdist, built by pip (the system's compiler) into a fresh venv, used from /"
sdist=$(ls "$dist"/rsmooth-*.tar.gz | head -1)
contents=$(tar tzf "$sdist")
for need in pyproject.toml CMakeLists.txt LICENSE README.md python/README.md cmake/embed_kernels.cmake \
            kernels/common.cl lib/include/rsmooth.h python/CMakeLists.txt python/rsmooth/__init__.py; do
  echo "$contents" | grep -q "^[^/]*/$need\$" || fail "$sdist lacks $need"
done
if echo "$contents" | grep -E '^[^/]*/(build[^/]*|dist|out|\.venv[^/]*|\.git)/' | head -3 | grep .; then
  fail "$sdist holds build output"
fi
t=$SECONDS
py=$(first_python --dev 3.11)
py=${py:-python3}
venv "$work/venv-sdist" "$py"
# No cache: pip would reuse the wheel it built from an sdist of the same name before.
if pip_in "$work/venv-sdist" --no-cache-dir "$sdist" --config-settings=cmake.define.RSMOOTH_WERROR="$werror"; then
  (cd / && "$work/venv-sdist/bin/python" - <<'PY'
import numpy as np, rsmooth, sys
assert rsmooth.__file__.startswith(sys.prefix), rsmooth.__file__
v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0.2]], dtype=np.float32)
f = np.array([[0, 1, 2], [1, 3, 2]], dtype=np.int32)
out = rsmooth.smooth(v, f, device="reference")
assert out.dtype == np.float32 and out.shape == (4, 3) and np.isfinite(out).all()
print("sdist", rsmooth.__version__, "from", rsmooth.__file__, "devices:", len(rsmooth.devices()))
PY
  ) || fail "the sdist's package does not work"
else
  fail "pip install $sdist"
fi
echo "   sdist $(basename "$sdist") ($(du -k "$sdist" | cut -f1) KiB, $(echo "$contents" | wc -l) files) in $((SECONDS - t)) s"

echo
echo "== wheels x Pythons ($((SECONDS - t0)) s)"
printf '%s\n' "wheel|Python|passed|skipped|failed|time" "${rows[@]}" \
  | awk -F'|' '{printf "%-72s %-8s %7s %8s %7s %6s\n", $1, $2, $3, $4, $5, $6}'
[ $status = 0 ] && echo "all wheels pass" || echo "FAILURES above"
exit $status
