"""What rsmooth does to what it should leave alone: clean meshes, a clean mesh with one stray
vertex, parts of very different size in one file, a point sphere with one far point. Runs the
command in each mode and prints the tables of docs/do-no-harm.md (with --json, the figures too).

    python3 scripts/do_no_harm.py [--rsmooth build/rsmooth] [--device reference] [--json F]

The shapes are made here (numpy); the clean meshes of ../shared/data/clean and the Originals of
the benchmark pairs are used when that folder exists. Measures, all against the input:
  - largest move, in the vertex's local mean edge length (the mean of its own edges' lengths in
    the input) and in % of the bounding-box diagonal;
  - reversed triangles: whose normal turned by more than 90 degrees from the input's;
  - stray vertex: the largest move of any other vertex, in the clean mesh's mean edge lengths;
  - parts: each sphere's centre offset over its radius and its mean radius over the true one;
  - points: the unit sphere's mean radius and the largest move of any other point."""
import argparse
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from obj_mesh import read_obj, write_obj  # noqa: E402

SHARED = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "shared", "data")
MODES = {"paper": [], "--auto": ["--auto"], "--best": ["--best"],
         "--best --auto": ["--best", "--auto"]}
CLEAN = ["cow", "suzanne", "teapot", "woody", "beetle", "fandisk", "spot"]
ORIGINALS = ["Bunny0.2", "SharpSphere0.3", "Fandisk0.3"]


def cube(n, size=2.0):
    """The surface lattice of an n x n x n cube (6 n^2 + 2 vertices), outward triangles."""
    verts, index, faces = [], {}, []
    for axis in range(3):
        for side in (0, 1):
            u, w = (axis + 1) % 3, (axis + 2) % 3
            first, second = (u, w) if side else (w, u)
            ids = np.zeros((n + 1, n + 1), dtype=np.int64)
            for j in range(n + 1):
                for i in range(n + 1):
                    lat = [0, 0, 0]
                    lat[axis] = n if side else 0
                    lat[first], lat[second] = i, j
                    key = tuple(lat)
                    if key not in index:
                        index[key] = len(verts)
                        verts.append([-size / 2 + size * k / n for k in lat])
                    ids[j, i] = index[key]
            for j in range(n):
                for i in range(n):
                    a, b, c, d = ids[j, i], ids[j, i + 1], ids[j + 1, i + 1], ids[j + 1, i]
                    faces += [(a, b, c), (a, c, d)]
    return np.array(verts, dtype=np.float64), np.array(faces, dtype=np.int64)


def icosphere(levels, radius=1.0, centre=(0, 0, 0)):
    g = (1 + 5 ** 0.5) / 2
    v = [(-1, g, 0), (1, g, 0), (-1, -g, 0), (1, -g, 0), (0, -1, g), (0, 1, g), (0, -1, -g),
         (0, 1, -g), (g, 0, -1), (g, 0, 1), (-g, 0, -1), (-g, 0, 1)]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
         (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
         (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    v = [np.array(p, dtype=np.float64) / np.linalg.norm(p) for p in v]
    for _ in range(levels):
        mid, out = {}, []

        def m(a, b):
            k = (min(a, b), max(a, b))
            if k not in mid:
                p = (v[a] + v[b]) / 2
                v.append(p / np.linalg.norm(p))
                mid[k] = len(v) - 1
            return mid[k]
        for a, b, c in f:
            ab, bc, ca = m(a, b), m(b, c), m(c, a)
            out += [(a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca)]
        f = out
    return np.array(v) * radius + np.array(centre, dtype=np.float64), np.array(f, dtype=np.int64)


def edges(f):
    e = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    e = e[e[:, 0] != e[:, 1]]
    return np.unique(e, axis=0)


def mean_edge(v, f):
    e = edges(f)
    return float(np.linalg.norm(v[e[:, 0]] - v[e[:, 1]], axis=1).mean())


def local_edge(v, f):
    """Per vertex: the mean length of its own edges (0 for a vertex on none)."""
    e = edges(f)
    length = np.linalg.norm(v[e[:, 0]] - v[e[:, 1]], axis=1)
    s = np.bincount(e.ravel(), weights=np.repeat(length, 2), minlength=len(v))
    c = np.bincount(e.ravel(), minlength=len(v))
    return np.where(c > 0, s / np.maximum(c, 1), 0.0)


def normals(v, f):
    return np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])


def reversed_count(v_in, v_out, f):
    a, b = normals(v_in, f), normals(v_out, f)
    ok = (np.linalg.norm(a, axis=1) > 0) & (np.linalg.norm(b, axis=1) > 0)
    return int(np.sum((np.sum(a * b, axis=1) < 0) & ok))


class Runner:
    def __init__(self, rsmooth, device, tmp):
        self.rsmooth, self.device, self.tmp = rsmooth, device, tmp

    def smooth(self, v, f, mode, name="in"):
        src, dst = os.path.join(self.tmp, name + ".obj"), os.path.join(self.tmp, name + "-out.obj")
        write_obj(src, v, f)
        cmd = [self.rsmooth, src, "-o", dst, "-f", "--json", "--device", self.device] + mode
        p = subprocess.run(cmd, capture_output=True, text=True)
        if p.returncode:
            return None, p.stderr.strip().splitlines()[-1] if p.stderr.strip() else "failed"
        report = json.loads(p.stdout.strip().splitlines()[-1]) if p.stdout.strip() else {}
        return read_obj(dst)[0], report

    def smooth_points(self, p, n, device):
        src, dst = os.path.join(self.tmp, "pts.obj"), os.path.join(self.tmp, "pts-out.obj")
        with open(src, "w") as fh:
            fh.write("".join("v %.17g %.17g %.17g\n" % tuple(a) for a in p))
            fh.write("".join("vn %.17g %.17g %.17g\n" % tuple(b) for b in n))
        cmd = [self.rsmooth, src, "-o", dst, "-f", "--json", "--device", device]
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode:
            return None, r.stderr.strip()
        report = json.loads(r.stdout.strip().splitlines()[-1]) if r.stdout.strip() else {}
        return read_obj(dst)[0], report


def clean_rows(run, meshes):
    rows = []
    for name, (v, f) in meshes:
        le = local_edge(v, f)
        diag = float(np.linalg.norm(v.max(0) - v.min(0)))
        for mode, opts in MODES.items():
            out, rep = run.smooth(v, f, opts)
            if out is None:
                rows.append({"mesh": name, "mode": mode, "error": rep})
                continue
            move = np.linalg.norm(out - v, axis=1)
            used = le > 0
            rows.append({"mesh": name, "mode": mode, "vertices": len(v),
                         "move_local": float(np.max(move[used] / le[used])),
                         "move_diag_pct": 100 * float(move.max()) / diag,
                         "reversed": reversed_count(v, out, f), "triangles": len(f),
                         "preset": rep.get("preset", "")})
    return rows


def stray_rows(run, ks=(1e2, 1e4, 1e6)):
    v0, f = cube(12)
    unit = mean_edge(v0, f)
    # a vertex in the middle of the +x face, moved along the face normal
    target = int(np.argmin(np.linalg.norm(v0 - np.array([1.0, 0.0, 0.0]), axis=1)))
    clean = {mode: run.smooth(v0, f, opts)[0] for mode, opts in MODES.items()}
    rows = []
    for k in ks:
        v = v0.copy()
        v[target, 0] += k * unit
        for mode, opts in MODES.items():
            out, rep = run.smooth(v, f, opts)
            if out is None:
                rows.append({"k": k, "mode": mode, "error": rep})
                continue
            others = np.ones(len(v), bool)
            others[target] = False
            move = np.linalg.norm(out - v, axis=1)[others] / unit
            diff = np.linalg.norm(out - clean[mode], axis=1)[others] / unit
            rows.append({"k": k, "mode": mode, "others_max_move": float(move.max()),
                         "others_beyond_1_edge": int(np.sum(move > 1)),
                         "others_vs_clean_run": float(diff.max()),
                         "stray_move": float(np.linalg.norm(out[target] - v[target]) / unit),
                         "outliers": (rep.get("outliers") if isinstance(rep, dict) else None)})
    return rows


def parts_rows(run):
    spheres = [icosphere(3, r, (c, 0, 0)) for r, c in ((1e-3, 0.0), (1.0, 3.0), (1e3, 3e3))]
    v = np.concatenate([s[0] for s in spheres])
    offs = np.cumsum([0] + [len(s[0]) for s in spheres])
    f = np.concatenate([s[1] + o for s, o in zip(spheres, offs[:-1])])
    rows = []
    for mode, opts in MODES.items():
        out, rep = run.smooth(v, f, opts)
        if out is None:
            rows.append({"mode": mode, "error": rep})
            continue
        row = {"mode": mode, "reversed": reversed_count(v, out, f)}
        for i, (r, c) in enumerate(((1e-3, 0.0), (1.0, 3.0), (1e3, 3e3))):
            part = out[offs[i]:offs[i + 1]]
            centre = part.mean(axis=0)
            row["r%g_centre" % r] = float(np.linalg.norm(centre - np.array([c, 0, 0])) / r)
            row["r%g_radius" % r] = float(np.linalg.norm(part - centre, axis=1).mean() / r)
        rows.append(row)
    return rows


def points_rows(run):
    rng = np.random.default_rng(7)
    p = rng.normal(size=(4000, 3))
    p /= np.linalg.norm(p, axis=1)[:, None]
    n = p.copy()
    rows = []
    for far in (None, 1e6):
        q = p.copy()
        if far:
            q[0] = np.array([far, 0, 0])
        for mode, device in (("paper, reference", "reference"), ("paper, OpenCL", "auto")):
            out, _ = run.smooth_points(q, n, device)
            if out is None:
                rows.append({"far": far or 0, "mode": mode, "error": _})
                continue
            rest = out[1:] if far else out
            rows.append({"far": far or 0, "mode": mode,
                         "radius": float(np.linalg.norm(rest, axis=1).mean()),
                         "others_max_move": float(np.linalg.norm(out[1:] - q[1:], axis=1).max())})
    return rows


def read_any(rsmooth, path, tmp):
    """An OBJ as it is; another format through the command (unchanged positions, as OBJ)."""
    if path.endswith(".obj"):
        return read_obj(path)
    out = os.path.join(tmp, "converted.obj")
    subprocess.run([rsmooth, path, "-o", out, "-f", "-q", "--method", "taubin", "--iterations",
                    "0"], check=True, capture_output=True)
    return read_obj(out)


def noisy_rows(run, manifest, modes):
    """Per case and mode: triangles facing away from the truth's (normals over 90 degrees apart)
    in the result and in the input, and E_v by `rsmooth compare`."""
    rows = []
    for case in json.load(open(manifest))["cases"]:
        v_in, f = read_obj(case["noisy"])
        truth = read_obj(case["truth"])[0]
        n_truth = normals(truth, f)
        flipped_in = int(np.sum(np.sum(normals(v_in, f) * n_truth, axis=1) < 0))
        for mode in modes:
            out, rep = run.smooth(v_in, f, MODES[mode], name="case")
            if out is None:
                rows.append({"case": case["name"], "mode": mode, "error": rep})
                continue
            m = json.loads(subprocess.run([run.rsmooth, "compare", os.path.join(run.tmp,
                                           "case-out.obj"), case["truth"], "--json"],
                                          capture_output=True, text=True, check=True).stdout)
            rows.append({"case": case["name"], "mode": mode, "flipped_input": flipped_in,
                         "flipped": int(np.sum(np.sum(normals(out, f) * n_truth, axis=1) < 0)),
                         "ev": m["ev"], "guarded": rep.get("guarded_vertices", 0)})
    return rows


def load_clean(shared, names, rsmooth, tmp):
    meshes = [("cube-8", cube(1)), ("cube-98", cube(4)), ("cube-866", cube(12)),
              ("icosphere-642", icosphere(3)), ("icosphere-2562", icosphere(4))]
    folder = os.path.join(shared, "clean")
    if names == ["all"] and os.path.isdir(folder):
        names = sorted(os.path.splitext(f)[0] for f in os.listdir(folder))
    for name in names:
        for ext in (".obj", ".off"):
            path = os.path.join(folder, name + ext)
            if os.path.exists(path):
                meshes.append((name, read_any(rsmooth, path, tmp)))
    for name in ORIGINALS:
        path = os.path.join(shared, "benchmark", name, "Original.obj")
        if os.path.exists(path):
            meshes.append((name + " Original", read_obj(path)))
    return meshes


def print_table(header, rows, names, cells):
    """A markdown table: per row its `names` columns, then cells(row) or the error that row met."""
    print("| %s |" % " | ".join(header))
    print("|%s" % (" --- |" * len(header)))
    for r in rows:
        lead = ["%g" % r[k] if isinstance(r[k], float) else str(r[k]) for k in names]
        rest = ["error: %s" % r["error"]] if "error" in r else cells(r)
        print("| %s |" % " | ".join(lead + rest))
    print()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rsmooth", default="build/rsmooth")
    ap.add_argument("--device", default="reference")
    ap.add_argument("--shared", default=SHARED)
    ap.add_argument("--json", default="")
    ap.add_argument("--only", default="clean,stray,parts,points")
    ap.add_argument("--cases", default="",
                    help="scripts/make_cases.py's manifest: the reversed-triangle table of the "
                         "noisy cases (section 'noisy')")
    ap.add_argument("--modes", default=",".join(MODES), help="modes of the noisy table")
    ap.add_argument("--clean", default=",".join(CLEAN),
                    help="clean meshes of SHARED/clean by name, or 'all' (default: %(default)s)")
    args = ap.parse_args()
    only = args.only.split(",")
    result = {}
    with tempfile.TemporaryDirectory() as tmp:
        run = Runner(args.rsmooth, args.device, tmp)
        if "clean" in only:
            names = args.clean.split(",")
            result["clean"] = clean_rows(run, load_clean(args.shared, names, args.rsmooth, tmp))
            print_table(["clean mesh", "mode", "largest move (local edges)", "(% diagonal)",
                         "reversed", "--auto chose"], result["clean"], ["mesh", "mode"],
                        lambda r: ["%.3g" % r["move_local"], "%.3g" % r["move_diag_pct"],
                                   "%d of %d" % (r["reversed"], r["triangles"]), r["preset"]])
        if "stray" in only:
            result["stray"] = stray_rows(run)
            print_table(["K", "mode", "others' largest move", "beyond 1 edge", "vs the clean run",
                         "stray"], result["stray"], ["k", "mode"],
                        lambda r: ["%.3g" % r["others_max_move"], "%d" % r["others_beyond_1_edge"],
                                   "%.3g" % r["others_vs_clean_run"], "%.3g" % r["stray_move"]])
        if "parts" in only:
            result["parts"] = parts_rows(run)
            print_table(["mode"] + ["r %s: centre / radius" % r for r in ("1e-3", "1", "1e3")] +
                        ["reversed"], result["parts"], ["mode"],
                        lambda r: ["%.3g / %.4f" % (r["r%s_centre" % k], r["r%s_radius" % k])
                                   for k in ("0.001", "1", "1000")] + ["%d" % r["reversed"]])
        if "points" in only:
            result["points"] = points_rows(run)
            print_table(["far point", "mode", "sphere's mean radius", "others' largest move"],
                        result["points"], ["far", "mode"],
                        lambda r: ["%.4f" % r["radius"], "%.3g" % r["others_max_move"]])
        if "noisy" in only and args.cases:
            result["noisy"] = noisy_rows(run, args.cases, args.modes.split(","))
            print_table(["case", "mode", "reversed (input)", "E_v", "vertices guarded"],
                        result["noisy"], ["case", "mode"],
                        lambda r: ["%d (%d)" % (r["flipped"], r["flipped_input"]), "%.3f" % r["ev"],
                                   "%d" % r["guarded"]])
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(result, fh, indent=1)


if __name__ == "__main__":
    main()
