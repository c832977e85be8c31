"""Writes a model file from trained stages (train/train.py's OUT/stage{S}-fold{F}.npz).

    python train/export.py OUT MODEL --fold F [--stages N] [--manifest CACHE/manifest.json]

The manifest's BLAKE2b-256 (the training data's recipe and sources) goes into the file's header,
so a shipped model names the data it was trained on (tests/test_learned_manifest checks it).
"""
import argparse
import hashlib
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import model_file  # noqa: E402


def stage_layers(path):
    data = np.load(path)
    count = sum(1 for k in data.files if k.startswith("w"))
    return [(data[f"w{i}"], data[f"b{i}"], 1 if i < count - 1 else 0) for i in range(count)]


def manifest_digest(path):
    with open(path, "rb") as f:
        return hashlib.blake2b(f.read(), digest_size=32).digest()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out")
    ap.add_argument("model")
    ap.add_argument("--fold", default="all")
    ap.add_argument("--stages", type=int, default=2)
    ap.add_argument("--manifest", required=True)
    args = ap.parse_args()
    stages = [stage_layers(os.path.join(args.out, f"stage{s}-fold{args.fold}.npz"))
              for s in range(1, args.stages + 1)]
    model_file.write(args.model, stages, manifest_digest(args.manifest))
    size = os.path.getsize(args.model)
    params = sum(w.size + b.size for layers in stages for w, b, a in layers)
    print(f"{args.model}: {len(stages)} stages, {params} parameters, {size} bytes")


if __name__ == "__main__":
    main()
