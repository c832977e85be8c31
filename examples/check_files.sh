#!/bin/sh
# example_files against the rsmooth command: on a noisy cylinder from rsmooth-demo-shape (PLY),
# the example's output must equal `rsmooth IN -o OUT --device D` byte for byte, on the reference
# path and on the default OpenCL device (that part skipped when there is none, unless
# RSMOOTH_REQUIRE_OPENCL=1).
# usage: check_files.sh EXAMPLE_FILES RSMOOTH RSMOOTH_DEMO_SHAPE WORK_DIR
set -eu
example=$1 rsmooth=$2 shape=$3 work=$4
rm -rf "$work" && mkdir -p "$work"
"$shape" make "$work/noisy.ply" "$work/truth.ply" --noise 0.3 --triangles 6000 >/dev/null
for input in noisy.ply; do
  for device in reference auto; do
    out=$work/example-$device-$input rsmooth_out=$work/rsmooth-$device-$input
    status=0
    "$example" "$work/$input" "$out" "$device" || status=$?
    if [ "$status" = 77 ] && [ "${RSMOOTH_REQUIRE_OPENCL:-0}" != 1 ]; then
      echo "device $device: none here, skipped"
      continue
    fi
    [ "$status" = 0 ] || { echo "example_files failed ($status)"; exit 1; }
    "$rsmooth" "$work/$input" -o "$rsmooth_out" --device "$device" --force >/dev/null 2>&1
    if cmp "$out" "$rsmooth_out"; then
      echo "device $device, $input: same bytes as rsmooth ($(wc -c <"$out") bytes)"
    else
      echo "device $device, $input: differs from rsmooth's output"; exit 1
    fi
  done
done
