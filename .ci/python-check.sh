#!/usr/bin/env bash
# The Python package end to end, as a user gets it: `pip install .` into a fresh virtual
# environment (PyPI supplies scikit-build-core, numpy, pytest, trimesh, meshio, tqdm, open3d), the pytest
# suite tests/python/ against the command built in BUILD (the C oracle), then `pip wheel . -w`
# and that wheel installed into a second fresh environment and used from outside the checkout.
# Usage: .ci/python-check.sh [PYTHON] [BUILD] [WERROR]   (make python-check)
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
python=${1:-python3}
build=${2:-build}
werror=${3:-OFF}
work=$build-python
rm -rf "$work"
mkdir -p "$work"

echo "== pip install . (fresh venv $work/venv)"
"$python" -m venv "$work/venv"
"$work/venv/bin/pip" install -q --upgrade pip
"$work/venv/bin/pip" install -q pytest trimesh meshio tqdm
# Open3D's wheel is 400 MB and exists for few platforms: its test skips where it does not install.
"$work/venv/bin/pip" install -q open3d || echo "open3d did not install here: test_open3d skips"
# PyOpenCL's wheel bundles an ICD loader that reads /etc/OpenCL/vendors (PoCL's ICD): no variable.
"$work/venv/bin/pip" install -q pyopencl || echo "pyopencl did not install here: test_pyopencl skips"
"$work/venv/bin/pip" install . --config-settings=cmake.define.RSMOOTH_WERROR="$werror" 2>&1 | tail -3

echo "== pytest tests/python"
RSMOOTH_CLI="$PWD/$build/rsmooth" RSMOOTH_REQUIRE_CLI=1 POCL_CACHE_DIR="$PWD/$build/pocl-cache" \
  "$work/venv/bin/python" -m pytest -q -rs tests/python

echo "== pip wheel . -w $work/dist, installed into a second fresh venv"
"$work/venv/bin/pip" wheel . --no-deps -w "$work/dist" 2>&1 | tail -1
wheel=$(ls "$work"/dist/rsmooth-*.whl)
ls -l "$wheel"
"$python" -c "import sys, zipfile
for i in zipfile.ZipFile(sys.argv[1]).infolist(): print(f'{i.file_size:>9}  {i.filename}')" "$wheel"
"$python" -m venv "$work/venv2"
"$work/venv2/bin/pip" install -q "$wheel"
(cd / && "$root/$work/venv2/bin/python" - <<'PY'
import numpy as np, rsmooth
v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0.2]], dtype=np.float32)
f = np.array([[0, 1, 2], [1, 3, 2]], dtype=np.int32)
out = rsmooth.smooth(v, f, device="reference")
assert out.dtype == np.float32 and out.shape == (4, 3) and np.isfinite(out).all()
print("wheel", rsmooth.__version__, "from", rsmooth.__file__, "devices:", len(rsmooth.devices()))
PY
)
