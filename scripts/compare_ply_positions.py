#!/usr/bin/env python3
"""Compares the vertex positions of two binary little-endian PLY files with the same layout of
x, y, z first (as rsmooth-big-mesh and rsmooth write them), block by block so that files of any
size fit: the largest difference in mean edge lengths, how many vertices differ, and for float32
files the largest difference beyond one float step of the coordinate (two runs 1e-7 edge lengths
apart can round to neighbouring floats) and how many vertices exceed 1e-6 mean edge lengths
beyond it. Also whether the headers and everything after the
vertex block are equal byte for byte.

usage: compare_ply_positions.py A.ply B.ply MEAN_EDGE"""
import sys

import numpy as np


def layout(path):
    with open(path, "rb") as f:
        head = f.read(1 << 16)
    end = head.index(b"end_header\n") + 11
    text = head[:end].decode()
    count = int(text.split("element vertex ")[1].split("\n")[0])
    props = text.split("element vertex")[1].split("element")[0].strip().split("\n")[1:]
    kinds = [p.split()[1] for p in props]
    dtype = np.dtype("<f4") if kinds[0] == "float" else np.dtype("<f8")
    stride = sum(4 if k in ("float", "int", "uint", "float32", "int32", "uint32") else
                 8 if k in ("double", "float64") else 2 if "short" in k or "16" in k else 1
                 for k in kinds)
    return head[:end], end, count, dtype, stride


def main():
    a_path, b_path, edge = sys.argv[1], sys.argv[2], float(sys.argv[3])
    ha, sa, n, dt, stride = layout(a_path)
    hb, sb, nb, _, _ = layout(b_path)
    worst = beyond = 0.0
    differing = over = 0
    block = 1 << 20
    with open(a_path, "rb") as fa, open(b_path, "rb") as fb:
        fa.seek(sa)
        fb.seek(sb)
        for first in range(0, n, block):
            m = min(block, n - first)
            ra = np.frombuffer(fa.read(m * stride), dtype=np.uint8).reshape(m, stride)
            rb = np.frombuffer(fb.read(m * stride), dtype=np.uint8).reshape(m, stride)
            xa = ra[:, :3 * dt.itemsize].copy().view(dt).astype(float)
            xb = rb[:, :3 * dt.itemsize].copy().view(dt).astype(float)
            d = np.abs(xa - xb)
            worst = max(worst, float(d.max()))
            differing += int((d.max(axis=1) > 0).sum())
            if dt.itemsize == 4:
                step = np.spacing(np.maximum(np.abs(xa), np.abs(xb)).astype(np.float32))
                excess = np.maximum(d - step, 0).max(axis=1)
            else:
                excess = d.max(axis=1)
            beyond = max(beyond, float(excess.max()))
            over += int((excess > 1e-6 * edge).sum())
        tail_equal = True
        while tail_equal:
            x, y = fa.read(1 << 24), fb.read(1 << 24)
            tail_equal = x == y
            if not x:
                break
    print("max difference %.3g mean edge lengths (%.3g beyond one float step; %d vertices more "
          "than 1e-6 beyond it); %d of %d vertices differ; headers equal: %s; after the vertex "
          "block equal: %s" % (worst / edge, beyond / edge, over, differing, n, ha == hb,
                               tail_equal))


if __name__ == "__main__":
    main()
