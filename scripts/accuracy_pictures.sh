#!/usr/bin/env bash
# Before/after pictures of docs/accuracy.md: noisy | `--best --auto` | truth, flat
# shaded, for the scanned models among the cases (the Stanford bunny, the rocker arm, the
# beetle) and two machined parts. The cases come from scripts/make_cases.py.
#   scripts/accuracy_pictures.sh build/rsmooth /work/cases docs/img
set -euo pipefail
rsmooth=$1 cases=$2 out=$3
shared=$(cd "$(dirname "$0")/../../shared/data" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
picture() { # name noisy truth [render options]
  local name=$1 noisy=$2 truth=$3
  shift 3
  "$rsmooth" "$noisy" -o "$work/$name.obj" -f --best --auto 2> "$work/$name.txt"
  "$rsmooth" render "$noisy" "$work/$name.obj" "$truth" -o "$out/accuracy-$name.png" -f \
    --size 360x360 "$@"
  echo "$name: $(head -c 300 "$work/$name.txt" | head -1)"
}
picture bunny0.2 "$shared/benchmark/Bunny0.2/Noisy.obj" "$shared/benchmark/Bunny0.2/Original.obj"
picture stanford-bunny-r0.3 "$cases/stanford-bunny-r0.3.obj" "$shared/clean/stanford-bunny.obj"
picture rocker-arm-n0.5 "$cases/rocker-arm-n0.5.obj" "$shared/clean/rocker-arm.obj"
picture beetle-alt-n0.5 "$cases/beetle-alt-n0.5.obj" "$shared/clean/beetle-alt.obj"
picture trimstar0.5 "$shared/train/TrimStar0.5/Noisy.obj" "$shared/train/TrimStar0.5/Original.obj"
picture twelve0.5impulsive "$shared/benchmark/Twelve0.5Impulsive/Noisy.obj" \
  "$shared/benchmark/Twelve0.5Impulsive/Original.obj"
