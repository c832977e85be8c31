#!/usr/bin/env bash
# The Blender add-on's headless test: tests/blender/run.sh BUILD ZIP
# Makes a noisy shape with BUILD/rsmooth-demo-shape, then runs tests/blender/run_addon.py inside
# `blender -b --factory-startup` with BLENDER_USER_SCRIPTS in a temporary folder (the zip is
# installed there, not in the user's Blender), comparing the add-on with BUILD/rsmooth on the same
# device (RSMOOTH_BLENDER_DEVICE, default cpu: PoCL's CPU device; or reference).
# Skips (exit 0, with a message) where there is no Blender: $BLENDER, default `blender` on PATH;
# fails there instead with RSMOOTH_REQUIRE_BLENDER=1 (.ci/run).
set -euo pipefail
build=${1:?usage: tests/blender/run.sh BUILD ZIP}
zip=${2:?usage: tests/blender/run.sh BUILD ZIP}
blender=${BLENDER:-blender}
device=${RSMOOTH_BLENDER_DEVICE:-cpu}
if ! command -v "$blender" >/dev/null 2>&1; then
  if [ "${RSMOOTH_REQUIRE_BLENDER:-0}" = 1 ]; then # CI: a missing Blender fails, not skips
    echo "blender-check: no Blender ('$blender' not found) and RSMOOTH_REQUIRE_BLENDER=1" >&2
    exit 1
  fi
  echo "blender-check: skipped: no Blender ('$blender' not found; apt-get install blender, or BLENDER=PATH)"
  exit 0
fi
[ -f "$zip" ] || { echo "blender-check: no add-on zip at $zip (make blender-addon)" >&2; exit 1; }
here=$(cd "$(dirname "$0")" && pwd)
build=$(cd "$build" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
start=$(date +%s%N)
"$build/rsmooth-demo-shape" make "$work/noisy.ply" "$work/truth.ply" --noise 0.3 --triangles 10000
mkdir -p "$work/scripts"
set +e
POCL_CACHE_DIR="$build/pocl-cache" BLENDER_USER_SCRIPTS="$work/scripts" \
  "$blender" -b --factory-startup --python-exit-code 1 --python "$here/run_addon.py" -- \
  --zip "$zip" --mesh "$work/noisy.ply" --rsmooth "$build/rsmooth" --work "$work" \
  --device "$device" 2>&1 | grep -v -e '^Blender quit$' -e '^$'
status=${PIPESTATUS[0]}
set -e
ms=$((($(date +%s%N) - start) / 1000000))
printf 'blender-check: %s in %d.%d s\n' "$([ "$status" -eq 0 ] && echo passed || echo FAILED)" \
  $((ms / 1000)) $((ms % 1000 / 100))
exit "$status"
