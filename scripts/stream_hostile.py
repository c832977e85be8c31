#!/usr/bin/env python3
"""Hostile inputs for `rsmooth --max-memory` (the streaming reader), judged against the in-memory
reader of the same command: every prefix of small binary PLY files (little- and big-endian, float
and double, colours, a face property, quads, an element with lists, faces before vertices) and
seeded corruptions of their bytes. For each case both runs go through the reference path:

  - a crash, a signal or a sanitizer report is a defect;
  - streaming succeeds where the in-memory reader refuses the file: a wrong answer with exit 0;
  - both succeed but the positions differ (`rsmooth compare`): a wrong answer;
  - streaming fails without a message, with a status other than 1 or 2, or leaves its output
    or any other file behind: a defect.

usage: stream_hostile.py RSMOOTH [--cases N] [--seed S]   (RSMOOTH: best an ASan build)"""
import argparse
import json
import os
import random
import struct
import subprocess
import sys
import tempfile


def ply(vertices, faces, endian="<", double=False, colours=False, face_flag=False,
        lists_element=False, faces_first=False):
    fmt = "binary_little_endian" if endian == "<" else "binary_big_endian"
    t = "double" if double else "float"
    vhead = "element vertex %d\nproperty %s x\nproperty %s y\nproperty %s z\n" % (
        len(vertices), t, t, t)
    if colours:
        vhead += "property uchar red\nproperty uchar green\nproperty uchar blue\n"
    fhead = "element face %d\nproperty list uchar int vertex_indices\n" % len(faces)
    if face_flag:
        fhead += "property short flag\n"
    ehead = "element edge 2\nproperty list uchar int pair\n" if lists_element else ""
    head = "ply\nformat %s 1.0\ncomment hostile\n" % fmt
    head += (fhead + ehead + vhead) if faces_first else (vhead + fhead + ehead)
    head += "end_header\n"
    c = "d" if double else "f"
    vdata = b"".join(struct.pack(endian + "3" + c, *v) +
                     (bytes([i % 256, 7, 9]) if colours else b"")
                     for i, v in enumerate(vertices))
    fdata = b"".join(struct.pack(endian + "B%di" % len(f), len(f), *f) +
                     (struct.pack(endian + "h", i) if face_flag else b"")
                     for i, f in enumerate(faces))
    edata = (struct.pack(endian + "B2i", 2, 0, 1) + struct.pack(endian + "B2i", 2, 1, 2)
             if lists_element else b"")
    body = (fdata + edata + vdata) if faces_first else (vdata + fdata + edata)
    return head.encode() + body


def grid(n, rng):
    vertices = [(x + rng.uniform(-.1, .1), y + rng.uniform(-.1, .1), rng.uniform(-.2, .2))
                for y in range(n) for x in range(n)]
    quads = [(y * n + x, y * n + x + 1, (y + 1) * n + x + 1, (y + 1) * n + x)
             for y in range(n - 1) for x in range(n - 1)]
    return vertices, quads


def run(cmd, cwd):
    p = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, errors="replace",
                       timeout=120)
    return p.returncode, p.stderr


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("rsmooth")
    ap.add_argument("--cases", type=int, default=1500)
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args()
    rng = random.Random(a.seed)
    rsmooth = os.path.abspath(a.rsmooth)
    v, q = grid(6, rng)
    tris = [t for f in q for t in ((f[0], f[1], f[2]), (f[0], f[2], f[3]))]
    bases = {
        "le-float": ply(v, tris),
        "be-double-colours": ply(v, tris, ">", True, True),
        "quads-flag-lists": ply(v, q, "<", False, False, True, True),
        "faces-first": ply(v, tris, "<", False, True, False, True, True),
    }
    cases = []
    for name, data in bases.items():
        for n in range(0, len(data) + 1, 1 if len(data) < 900 else 3):
            cases.append(("%s prefix %d" % (name, n), data[:n]))
    while len(cases) < a.cases + 4 * 300:
        name, data = rng.choice(list(bases.items()))
        b = bytearray(data)
        for _ in range(rng.randint(1, 4)):
            i = rng.randrange(len(b))
            b[i] = rng.randrange(256) if rng.random() < 0.7 else b[i] ^ (1 << rng.randrange(8))
        cases.append(("%s corrupted" % name, bytes(b)))
    tally = {"cases": 0, "both ok, same": 0, "both refused": 0, "streaming refused only": 0,
             "crashes": 0, "wrong with exit 0": 0, "files left": 0, "no message": 0}
    failures = []
    env = dict(os.environ, ASAN_OPTIONS="detect_leaks=1:abort_on_error=0")
    with tempfile.TemporaryDirectory() as tmp:
        for label, data in cases:
            tally["cases"] += 1
            for f in os.listdir(tmp):
                os.unlink(os.path.join(tmp, f))
            with open(os.path.join(tmp, "in.ply"), "wb") as f:
                f.write(data)
            base = [rsmooth, "in.ply", "--device", "reference", "-q", "--force"]
            cs, es = run(base + ["-o", "s.ply", "--max-memory", "16M"], tmp)
            cm, em = run(base + ["-o", "m.ply"], tmp)
            bad = []
            if cs < 0 or cs > 3 or "Sanitizer" in es or "runtime error" in es:
                tally["crashes"] += 1
                bad.append("streaming crashed (%d): %s" % (cs, es[-300:]))
            elif cs == 0 and cm != 0:
                tally["wrong with exit 0"] += 1
                bad.append("streaming accepted what the in-memory reader refuses: " + em)
            elif cs == 0:
                try:
                    m = json.loads(subprocess.run([rsmooth, "compare", "s.ply", "m.ply",
                                                   "--json"], cwd=tmp, capture_output=True,
                                                  text=True).stdout)
                    same = m["rms_v"] == 0 and m["hausdorff"] == 0
                except (ValueError, KeyError):
                    same = open(os.path.join(tmp, "s.ply"), "rb").read() == \
                        open(os.path.join(tmp, "m.ply"), "rb").read()
                if same:
                    tally["both ok, same"] += 1
                else:
                    tally["wrong with exit 0"] += 1
                    bad.append("positions differ from the in-memory result")
            else:
                tally["both refused" if cm != 0 else "streaming refused only"] += 1
                if not es.strip():
                    tally["no message"] += 1
                    bad.append("refused without a message")
                left = sorted(set(os.listdir(tmp)) - {"in.ply", "m.ply"})
                if left:
                    tally["files left"] += 1
                    bad.append("left behind: %s" % left)
            if bad:
                failures.append((label, bad))
                with open("stream_hostile_%d.ply" % len(failures), "wb") as f:
                    f.write(data)
    print(json.dumps(tally))
    for label, bad in failures[:20]:
        print("FAIL", label, "; ".join(bad))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
