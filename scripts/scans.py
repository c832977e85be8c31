#!/usr/bin/python3
"""rsmooth on real range scans: the two Stanford bunny scans (bun000, bun045; raw Cyberware range
grids, read directly by rsmooth as triangle meshes) measured against the reconstruction merged from
ten scans (bun_zipper.ply), the nearest thing to a truth.

For each scan: run an rsmooth command line on the raw .ply, place the result in the common frame
with bun.conf (each 'bmesh' line: translation t, quaternion x y z w; aligned point = R^T p + t),
write it as an OBJ to a temporary folder and measure it against the reconstruction with the
functions of /work/shared/tools/meshmetrics.py. That tool's own command refuses meshes with other
vertices than the truth's; here the vertices differ, so only its surface figure is meaningful:
  ev     area-weighted RMS distance of the result's vertices to the reconstruction's surface, in
         thousandths of the reconstruction's bounding-box diagonal (meshmetrics' E_v);
  theta  mean angle, degrees, between each result triangle's normal and that of the
         reconstruction triangle nearest its centroid (a stand-in for meshmetrics' theta, which
         needs the same faces).

    scripts/scans.py                        # the table: raw, paper, --auto, --best --auto, Taubin
    scripts/scans.py --extra "--best --passes 2"      # one more command line
    python3 -c "import scans; print(scans.evaluate(['--auto']))"   (from scripts/)

Writes docs/results/scans.json (the table) unless --extra or --no-write. Needs numpy and scipy.
"""
import argparse
import json
import os
import re
import shlex
import subprocess
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
DATA = os.path.join(os.path.dirname(ROOT), "shared", "data", "scans", "stanford-bunny")
TOOLS = os.path.join(os.path.dirname(ROOT), "shared", "tools")
SCANS = ("bun000", "bun045")
TAUBIN_GRID = (1, 2, 3, 5, 8, 12, 18, 27, 40, 60, 90)

sys.path.insert(0, TOOLS)
import meshmetrics  # noqa: E402  (the independent measure; numpy, scipy)
from scipy.spatial import cKDTree  # noqa: E402

_truth = {}


def alignment(name):
    """(R, t) of bun.conf's 'bmesh NAME.ply tx ty tz qx qy qz qw' line."""
    with open(os.path.join(DATA, "bun.conf")) as fh:
        for line in fh:
            w = line.split()
            if len(w) == 9 and w[0] == "bmesh" and w[1] == name + ".ply":
                t = np.array(w[2:5], float)
                x, y, z, s = (float(v) for v in w[5:9])
                R = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - s * z), 2 * (x * z + s * y)],
                              [2 * (x * y + s * z), 1 - 2 * (x * x + z * z), 2 * (y * z - s * x)],
                              [2 * (x * z - s * y), 2 * (y * z + s * x), 1 - 2 * (x * x + y * y)]])
                return R, t
    raise SystemExit("bun.conf has no bmesh line for %s" % name)


def truth():
    """The reconstruction: vertices, triangles, face normals, bbox diagonal, centroid tree."""
    if not _truth:
        v, f = meshmetrics.read_mesh(os.path.join(DATA, "bun_zipper.ply"))
        n, _ = meshmetrics.face_normals(v, f)
        _truth.update(v=v, f=f, n=n, diag=float(np.linalg.norm(v.max(0) - v.min(0))),
                      tree=cKDTree(v[f].mean(1)))
    return _truth


def write_obj(path, v, f):
    with open(path, "w") as fh:
        fh.write("".join("v %.9g %.9g %.9g\n" % tuple(p) for p in v))
        fh.write("".join("f %d %d %d\n" % tuple(t + 1) for t in f))


def measure(v, f):
    """ev, theta and the per-vertex distances of an aligned mesh against the reconstruction."""
    T = truth()
    n, area = meshmetrics.face_normals(v, f)
    va = np.zeros(len(v))
    for j in range(3):
        np.add.at(va, f[:, j], area)
    used = va > 0
    d = meshmetrics.dist_to_surface(v[used], T["v"], T["f"])
    ev = float(np.sqrt((va[used] * d ** 2).sum() / va[used].sum())) / T["diag"] * 1e3
    _, nearest = T["tree"].query(v[f].mean(1))
    cos = np.clip((n * T["n"][nearest]).sum(1), -1, 1)
    ok = np.isfinite(cos)
    theta = float(np.degrees(np.arccos(cos[ok])).mean())
    agree = float((cos[ok] > 0).mean())  # orientation: share of normals facing the truth's way
    return {"ev": ev, "theta": theta, "agree": agree, "distances": d}


def run(rsmooth, name, args, folder):
    """Runs `rsmooth RAW -o OUT.obj ARGS`; the aligned result (v, f) and rsmooth's stderr."""
    out = os.path.join(folder, "%s-out.obj" % name)
    if os.path.exists(out):
        os.remove(out)
    cmd = [rsmooth, os.path.join(DATA, name + ".ply"), "-o", out] + list(args)
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        raise SystemExit("%s failed (%d):\n%s" % (" ".join(cmd), p.returncode, p.stderr))
    v, f = meshmetrics.read_mesh(out)
    R, t = alignment(name)
    v = v @ R + t  # each row: R^T p + t
    write_obj(os.path.join(folder, "%s-aligned.obj" % name), v, f)
    return v, f, p.stderr


def evaluate(args, rsmooth=None, folder=None):
    """{scan: {"ev": .., "theta": ..}} of `rsmooth RAW -o OUT ARGS` on each scan (args: a list)."""
    rsmooth = rsmooth or os.path.join(ROOT, "build", "rsmooth")
    with tempfile.TemporaryDirectory(prefix="rsmooth-scans-") as tmp:
        result = {}
        for name in SCANS:
            v, f, _ = run(rsmooth, name, args, folder or tmp)
            m = measure(v, f)
            result[name] = {"ev": m["ev"], "theta": m["theta"]}
        return result


def noise_truth(rsmooth, name, folder):
    """The raw scan: its ev/theta, the orientation check, the RMS and median distance of its
    vertices to the reconstruction in its mean edge lengths, and --auto's noise estimate."""
    v, f, err = run(rsmooth, name, ["--method", "laplacian", "--iterations", "0"], folder)
    m = measure(v, f)
    mel = meshmetrics.mean_edge_length(v, f)
    grid = re.search(r"range grid \((\d+) x (\d+) cells, (\d+) samples\): read as (\d+) triangles",
                     err)
    _, _, err = run(rsmooth, name, ["--auto"], folder)
    auto = re.search(r"noise estimate ([0-9.eE+-]+) mean edge lengths", err)
    d = m["distances"]
    return {"ev": m["ev"], "theta": m["theta"], "normals_agree": m["agree"],
            "vertices": len(v), "triangles": len(f),
            "grid": [int(g) for g in grid.groups()] if grid else None,
            "mean_edge": mel,
            "rms_distance_edges": float(np.sqrt((d ** 2).mean()) / mel),
            "median_distance_edges": float(np.median(d) / mel),
            "auto_noise_edges": float(auto.group(1)) if auto else None}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rsmooth", default=os.path.join(ROOT, "build", "rsmooth"))
    ap.add_argument("--extra", help="evaluate this command line (quoted) only")
    ap.add_argument("--no-write", action="store_true", help="do not write docs/results/scans.json")
    a = ap.parse_args()
    if not os.path.isdir(DATA):
        raise SystemExit("no scans at %s" % DATA)
    if a.extra is not None:
        print(json.dumps(evaluate(shlex.split(a.extra), a.rsmooth), indent=1))
        return
    table = {"truth": "bun_zipper.ply", "ev_unit": "1e-3 of the reconstruction's bbox diagonal",
             "taubin_grid": list(TAUBIN_GRID), "scans": {}}
    modes = {"paper": [], "auto": ["--auto"], "best_auto": ["--best", "--auto"]}
    with tempfile.TemporaryDirectory(prefix="rsmooth-scans-") as tmp:
        for name in SCANS:
            row = {"raw": noise_truth(a.rsmooth, name, tmp)}
            for mode, args in modes.items():
                row[mode] = measure(*run(a.rsmooth, name, args, tmp)[:2])
                del row[mode]["distances"]
            taubin = {}
            for n in TAUBIN_GRID:
                m = measure(*run(a.rsmooth, name, ["--method", "taubin", "--iterations", str(n)],
                                 tmp)[:2])
                taubin[n] = {"ev": m["ev"], "theta": m["theta"]}
            best = min(taubin, key=lambda n: taubin[n]["ev"])
            row["taubin"] = {"best_iterations": best, "ev": taubin[best]["ev"],
                             "theta": taubin[best]["theta"], "at_grid_edge":
                             best in (TAUBIN_GRID[0], TAUBIN_GRID[-1]), "grid": taubin}
            table["scans"][name] = row
            raw = row["raw"]
            print("%s: %d x %d cells, %d samples -> %d triangles; normals agreeing with the "
                  "reconstruction's: %.2f%%" % (name, *raw["grid"], raw["normals_agree"] * 100))
            print("  true noise: RMS %.3f, median %.3f mean edge lengths; --auto estimates %s" %
                  (raw["rms_distance_edges"], raw["median_distance_edges"],
                   raw["auto_noise_edges"]))
            for mode in ("raw", "paper", "auto", "best_auto"):
                print("  %-10s ev %.4f  theta %.2f" % (mode, row[mode]["ev"], row[mode]["theta"]))
            print("  taubin N=%d ev %.4f theta %.2f (grid: %s)" % (
                best, taubin[best]["ev"], taubin[best]["theta"],
                " ".join("%d:%.4f" % (n, taubin[n]["ev"]) for n in TAUBIN_GRID)))
    if not a.no_write:
        path = os.path.join(ROOT, "docs", "results", "scans.json")
        with open(path, "w") as fh:
            json.dump(table, fh, indent=1, sort_keys=False)
            fh.write("\n")
        print("wrote", os.path.relpath(path, ROOT))


if __name__ == "__main__":
    main()
