#!/usr/bin/env bash
# make train: the learned normals' model from ../shared/data, end to end, resumable (each step
# is skipped when its output exists; training resumes from its last epoch's checkpoint).
#   train/run.sh BUILD OUT
# BUILD: a build folder with rsmooth and rsmooth-train-features; OUT: where everything goes
# (default out/train). TRAIN_VENV: the virtual environment (default BUILD/train-venv, made from
# train/requirements.txt when missing). Leaves OUT/model.rsnn (the model trained on every fold),
# OUT/model-fold{0..3}.rsnn (each without one fold's shapes) and OUT/evaluation.json (those
# folds' left-out figures); it does not replace models/learned-normals.rsnn (see train/README.md).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=$(realpath "${1:-build}")
OUT=$(realpath -m "${2:-out/train}")
VENV=${TRAIN_VENV:-$BUILD/train-venv}
EPOCHS=${TRAIN_EPOCHS:-12}
# The folds to train (each without one fold's shapes, for the left-out figures), and "all" (the
# model shipped). Fewer folds, fewer left-out figures: about 20 minutes a fold on 2 cores.
FOLDS=${TRAIN_FOLDS:-0 1 2 3 all}
SHARED=$(realpath -m ../shared/data)
if [ ! -d "$SHARED/clean" ]; then
  echo "train/run.sh: $SHARED is missing: the training reads ../shared/data (clean meshes, pairs, scans)" >&2
  exit 2
fi
for tool in rsmooth rsmooth-train-features; do
  [ -x "$BUILD/$tool" ] || { echo "train/run.sh: $BUILD/$tool is missing (make build)" >&2; exit 2; }
done
if [ ! -x "$VENV/bin/python" ]; then
  python3 -m venv "$VENV"
  "$VENV/bin/pip" install -q -r train/requirements.txt
fi
PY="$VENV/bin/python"
mkdir -p "$OUT"
start=$SECONDS
step() { echo "== train: $* ($((SECONDS - start)) s) =="; }
step "CAD parts"
[ -f "$OUT/cad/shapes.json" ] || "$PY" train/shapes.py "$OUT/cad" --count 80 --seed 1
step "stage 1 data"
[ -f "$OUT/cache/stage1.npz" ] || "$PY" train/dataset.py "$BUILD" "$OUT/cache" --cad "$OUT/cad"
for fold in $FOLDS; do
  leave=(); [ "$fold" = all ] || leave=(--leave-out "$fold")
  step "stage 1, fold $fold"
  [ -f "$OUT/models/stage1-fold$fold.npz" ] ||
    "$PY" train/train.py "$OUT/cache" "$OUT/models" --stage 1 --epochs "$EPOCHS" "${leave[@]}"
  "$PY" train/export.py "$OUT/models" "$OUT/models/stage1-fold$fold.rsnn" --fold "$fold" \
    --stages 1 --manifest "$OUT/cache/manifest.json" > /dev/null
  step "stage 2 data, fold $fold"
  [ -f "$OUT/cache/stage2-fold$fold.npz" ] ||
    "$PY" train/dataset.py "$BUILD" "$OUT/cache" --cad "$OUT/cad" --stage 2 \
      --model "$OUT/models/stage1-fold$fold.rsnn" --name "stage2-fold$fold"
  step "stage 2, fold $fold"
  [ -f "$OUT/models/stage2-fold$fold.npz" ] ||
    "$PY" train/train.py "$OUT/cache" "$OUT/models" --stage 2 --epochs "$EPOCHS" "${leave[@]}"
  name=model-fold$fold; [ "$fold" = all ] && name=model
  "$PY" train/export.py "$OUT/models" "$OUT/$name.rsnn" --fold "$fold" --stages 2 \
    --manifest "$OUT/cache/manifest.json"
done
step "left-out evaluation"
[ -f "$OUT/evaluation.json" ] ||
  "$PY" train/evaluate.py "$BUILD" "$OUT/cache" "$OUT" --models "$OUT" --cad "$OUT/cad" \
    --folds "$(echo $FOLDS | tr ' ' '\n' | grep -v all | paste -sd,)"
step "done"
echo "train: the model is $OUT/model.rsnn; docs/model.md's figures: $OUT/evaluation.json"
