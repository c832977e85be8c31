#!/usr/bin/env bash
# Issue 25's pictures (docs/accuracy.md): noisy | `--best --auto` | truth for the cases named
# (the worst three of docs/results/accuracy_stage.md), and a raw range scan before and after.
#   scripts/stage_pictures.sh build/rsmooth /work/cases/manifest.json docs/img CASE...
set -euo pipefail
rsmooth=$1 manifest=$2 out=$3
shift 3
scans=$(cd "$(dirname "$0")/../../shared/data/scans/stanford-bunny" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for name in "$@"; do
  read -r noisy truth < <(/usr/bin/python3 -c "import json, sys
c = {c['name']: c for c in json.load(open(sys.argv[1]))['cases']}[sys.argv[2]]
print(c['noisy'], c['truth'])" "$manifest" "$name")
  "$rsmooth" "$noisy" -o "$work/$name.obj" -f --best --auto 2> "$work/$name.txt"
  "$rsmooth" render "$noisy" "$work/$name.obj" "$truth" -o "$out/stage-$name.png" -f \
    --size 360x360
  echo "$name: $(tail -1 "$work/$name.txt")"
done
for scan in bun000; do # the scanner's own file, read directly; raw | --best --auto
  "$rsmooth" "$scans/$scan.ply" -o "$work/$scan.ply" -f --best --auto 2> "$work/$scan.txt"
  "$rsmooth" render "$scans/$scan.ply" "$work/$scan.ply" -o "$out/stage-scan-$scan.png" -f \
    --size 480x480
  echo "$scan: $(tail -1 "$work/$scan.txt")"
done
