#!/usr/bin/env python3
"""Classic anchors for issue 15, each tuned against the ground truth per case.

What it measures
----------------
For every case of the manifest (noisy/truth OBJ pairs with the same vertex order) and
for three classic smoothers, the best E_v and the best theta (degrees) reachable when the
smoother's parameters are tuned against the truth on that very case:

  open3d_taubin    Open3D's TriangleMesh.filter_smooth_taubin(number_of_iterations=k),
                   its defaults lambda 0.5, mu -0.53 (Open3D's inverse-distance Laplacian).
                   The mesh is built from numpy arrays parsed here (no merging or
                   reordering of vertices) and written back as OBJ.
  rsmooth_taubin   `rsmooth NOISY -o OUT.obj --method taubin --iterations k -f -q`
                   (defaults lambda 0.5, mu -0.53; uniform Laplacian, 1 thread).
  meshlab_twostep  MeshLab's "TwoStep Smooth" (Belyaev & Ohtake) through meshlabserver
                   (Debian's meshlab 2020.09) under a private Xvfb display; the noisy mesh
                   is given as OFF (MeshLab's OBJ reader aborts on these files) and the
                   output OFF is read back; vertex count must be unchanged.

Every result is scored with `rsmooth compare RESULT TRUTH --json` (ev, theta).

Tuning
------
Taubin (both): k over a 1-D grid (1..300); if the optimum of either figure lies at the
largest value the grid is extended upwards (400, 500, 700, 1000, ...) until it does not.
k = 1 is the smallest value k can take, so an optimum there is recorded as at_edge with
edge "min (smallest possible)".

TwoStep: steepest descent on the lattice normalThr x stepSmoothNum x stepNormalNum x
stepFitNum, moving to the best of the neighbours one lattice step away in one coordinate,
until no such move improves; from two starting points, once for E_v and once for theta.
When a local optimum sits on the lattice's last value of a coordinate, that coordinate's
list is extended (or, at the low end of normalThr, extended downwards) and the descent
continues; ints at 1 are at their smallest possible value.

Every evaluation is cached in WORK/cache/<case>.json, so a rerun repeats nothing; the
output json is rewritten after each case and anchor.

Timing: the wall time of one run at the E_v-optimal setting, median of 3:
  open3d_taubin: the filter_smooth_taubin call only (in process; cpu time also recorded to
                 show whether Open3D used more than one thread);
  rsmooth_taubin: the whole command (read, filter, write) and rsmooth's own "filter" ms;
  meshlab_twostep: the whole meshlabserver process (start, OFF read, filter, OFF write),
                 display already up.

Usage:
  python anchors_classic.py --cases /work/cases/manifest.json --rsmooth /work/h1/rsmooth \
      --work /work/h1/anchors --out docs/results/anchors_classic.json \
      [--anchors open3d_taubin,rsmooth_taubin,meshlab_twostep] [--only NAME,...]
"""
import argparse
import json
import os
import statistics
import subprocess
import time

import numpy as np
from obj_mesh import read_obj, write_obj  # scripts/obj_mesh.py

TAUBIN_GRID = [1, 2, 3, 4, 5, 7, 10, 14, 20, 30, 40, 50, 70, 100, 140, 200, 300]
TAUBIN_EXT = [400, 500, 700, 1000, 1400, 2000, 3000, 5000]
TS_DIMS = ["normalThr", "stepSmoothNum", "stepNormalNum", "stepFitNum"]
TS_LATTICE = {
    "normalThr": [30, 45, 60, 75, 90, 105, 120],
    "stepSmoothNum": [1, 2, 3, 5, 8, 12, 20, 30, 40, 60, 80],
    "stepNormalNum": [1, 2, 3, 4, 6, 8, 12, 16],
    "stepFitNum": [1, 2, 3, 5, 8, 12],
}
# extensions when an optimum sits on the last value (upwards) or first value (downwards)
TS_EXT_UP = {
    "normalThr": [135, 150, 165, 180],
    "stepSmoothNum": [120, 160, 240, 320],
    "stepNormalNum": [24, 32, 48, 64],
    "stepFitNum": [16, 24, 32, 48],
}
TS_EXT_DOWN = {"normalThr": [20, 10, 5]}  # the ints start at 1, their smallest value
TS_STARTS = [(60, 3, 1, 1), (90, 20, 4, 3)]
TS_MLX = """<!DOCTYPE FilterScript>
<FilterScript>
 <filter name="TwoStep Smooth">
  <Param type="RichInt" value="{stepSmoothNum}" name="stepSmoothNum"/>
  <Param type="RichFloat" value="{normalThr}" name="normalThr"/>
  <Param type="RichInt" value="{stepNormalNum}" name="stepNormalNum"/>
  <Param type="RichInt" value="{stepFitNum}" name="stepFitNum"/>
  <Param type="RichBool" value="false" name="Selected"/>
 </filter>
</FilterScript>
"""


def write_off(path, v, f):
    with open(path, "w") as fh:
        fh.write("OFF\n%d %d 0\n" % (len(v), len(f)))
        fh.write("".join("%.10g %.10g %.10g\n" % tuple(p) for p in v))
        fh.write("".join("3 %d %d %d\n" % tuple(t) for t in f))


def off_vertex_count(path):
    with open(path) as fh:
        tok = []
        for line in fh:
            line = line.split("#")[0].strip()
            if not line:
                continue
            tok += line.split()
            if tok[0].upper().endswith("OFF") and len(tok) >= 3:
                return int(tok[1])
    return -1


def read_off_vertices(path):
    with open(path) as fh:
        tok = []
        for line in fh:
            line = line.split("#")[0].strip()
            if line:
                tok += line.split()
            if len(tok) >= 4:
                break
        nv = int(tok[1])
        rows = []
        for line in fh:
            line = line.split("#")[0].strip()
            if line:
                rows.append([float(x) for x in line.split()[:3]])
                if len(rows) == nv:
                    break
    return np.array(rows)


class Ctx:
    def __init__(self, args):
        self.args = args
        self.rsmooth = args.rsmooth
        self.work = args.work
        os.makedirs(os.path.join(self.work, "cache"), exist_ok=True)
        os.makedirs(os.path.join(self.work, "tmp"), exist_ok=True)
        os.makedirs(os.path.join(self.work, "off"), exist_ok=True)
        self.display = None
        self.xvfb = None

    # ---- cache -------------------------------------------------------------------
    def cache_path(self, case):
        return os.path.join(self.work, "cache", case["name"] + ".json")

    def load_cache(self, case):
        p = self.cache_path(case)
        if os.path.exists(p):
            with open(p) as fh:
                return json.load(fh)
        return {}

    def save_cache(self, case, cache):
        p = self.cache_path(case)
        with open(p + ".tmp", "w") as fh:
            json.dump(cache, fh, indent=0, sort_keys=True)
        os.replace(p + ".tmp", p)

    def compare(self, result, truth):
        out = subprocess.run([self.rsmooth, "compare", result, truth, "--json"],
                             check=True, capture_output=True, text=True).stdout
        d = json.loads(out)
        return {"ev": d["ev"], "theta": d["theta"]}

    # ---- display for meshlab --------------------------------------------------------
    def ensure_display(self):
        if self.display:
            return
        for n in range(71, 99):
            if os.path.exists("/tmp/.X11-unix/X%d" % n) or os.path.exists("/tmp/.X%d-lock" % n):
                continue
            self.xvfb = subprocess.Popen(["Xvfb", ":%d" % n, "-screen", "0", "640x480x24",
                                          "-nolisten", "tcp"],
                                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            for _ in range(50):
                if os.path.exists("/tmp/.X11-unix/X%d" % n):
                    break
                time.sleep(0.1)
            time.sleep(0.3)
            if self.xvfb.poll() is None:
                self.display = ":%d" % n
                return
        raise RuntimeError("could not start Xvfb")

    def close(self):
        if self.xvfb is not None:
            self.xvfb.terminate()
            self.xvfb.wait()


# ---- the anchors -----------------------------------------------------------------
class Open3DTaubin:
    name = "open3d_taubin"

    def __init__(self, ctx, case):
        import open3d as o3d
        self.o3d = o3d
        self.ctx, self.case = ctx, case
        self.v, self.f = read_obj(case["noisy"])

    def key(self, k):
        return "%s|%d" % (self.name, k)

    def run(self, k, out):
        o3d = self.o3d
        m = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(self.v),
                                      o3d.utility.Vector3iVector(self.f.astype(np.int32)))
        t0, c0 = time.perf_counter(), time.process_time()
        r = m.filter_smooth_taubin(number_of_iterations=int(k))
        t1, c1 = time.perf_counter(), time.process_time()
        rv = np.asarray(r.vertices)
        assert rv.shape == self.v.shape, "open3d changed the vertex count"
        if out:
            write_obj(out, rv, self.f, digits=10)
        return t1 - t0, c1 - c0

    def evaluate(self, k):
        out = os.path.join(self.ctx.work, "tmp", "o3d.obj")
        self.run(k, out)
        return self.ctx.compare(out, self.case["truth"])

    def timing(self, k):
        ts = [self.run(k, None) for _ in range(3)]
        return {"time_s": statistics.median(t for t, _ in ts),
                "cpu_s": statistics.median(c for _, c in ts),
                "time_what": "filter_smooth_taubin call only, in process, median of 3; "
                             "cpu_s/time_s shows the threads used"}


class RsmoothTaubin:
    name = "rsmooth_taubin"

    def __init__(self, ctx, case):
        self.ctx, self.case = ctx, case

    def key(self, k):
        return "%s|%d" % (self.name, k)

    def cmd(self, k, out):
        return [self.ctx.rsmooth, self.case["noisy"], "-o", out, "--method", "taubin",
                "--iterations", str(int(k)), "-f"]

    def evaluate(self, k):
        out = os.path.join(self.ctx.work, "tmp", "rs.obj")
        subprocess.run(self.cmd(k, out) + ["-q"], check=True)
        return self.ctx.compare(out, self.case["truth"])

    def timing(self, k):
        out = os.path.join(self.ctx.work, "tmp", "rs_t.obj")
        walls, filt = [], []
        for _ in range(3):
            t0 = time.perf_counter()
            p = subprocess.run(self.cmd(k, out) + ["--json"], check=True,
                               capture_output=True, text=True)
            walls.append(time.perf_counter() - t0)
            filt.append(json.loads(p.stdout.strip().splitlines()[0])["ms"]["filter"] / 1000)
        return {"time_s": statistics.median(walls), "filter_s": statistics.median(filt),
                "time_what": "whole command (read, filter, write), median of 3; filter_s: "
                             "rsmooth's own filter stage; 1 thread (double)"}


class MeshlabTwoStep:
    name = "meshlab_twostep"

    def __init__(self, ctx, case):
        self.ctx, self.case = ctx, case
        ctx.ensure_display()
        # MeshLab's TwoStep throws vcg::MissingCompactnessException on a mesh with
        # vertices no face uses (stanford-bunny has ~1100): such a mesh is given to MeshLab
        # without them, and they are put back, unmoved, in the input's order afterwards
        # (as rsmooth's Taubin leaves them).
        self.v, self.f = read_obj(case["noisy"])
        used = np.zeros(len(self.v), bool)
        used[self.f.ravel()] = True
        self.used = None if used.all() else np.nonzero(used)[0]
        self.off = os.path.join(ctx.work, "off", case["name"] +
                                (".off" if self.used is None else ".compact.off"))
        if not os.path.exists(self.off):
            if self.used is None:
                write_off(self.off + ".tmp", self.v, self.f)
            else:
                remap = np.full(len(self.v), -1, np.int64)
                remap[self.used] = np.arange(len(self.used))
                write_off(self.off + ".tmp", self.v[self.used], remap[self.f])
            os.replace(self.off + ".tmp", self.off)
        self.nv = off_vertex_count(self.off)

    def key(self, p):
        return "%s|%g,%d,%d,%d" % (self.name, p[0], p[1], p[2], p[3])

    def run(self, p, out):
        mlx = os.path.join(self.ctx.work, "tmp", "ts.mlx")
        with open(mlx, "w") as fh:
            fh.write(TS_MLX.format(**dict(zip(TS_DIMS, p))))
        if os.path.exists(out):
            os.remove(out)
        env = dict(os.environ, DISPLAY=self.ctx.display)
        t0 = time.perf_counter()
        r = subprocess.run(["meshlabserver", "-i", self.off, "-o", out, "-s", mlx],
                           capture_output=True, text=True, env=env)
        dt = time.perf_counter() - t0
        if r.returncode != 0 or not os.path.exists(out):
            raise RuntimeError("meshlabserver failed: %s" % (r.stdout + r.stderr)[-2000:])
        nv = off_vertex_count(out)
        if nv != self.nv:
            raise RuntimeError("meshlab changed the vertex count %d -> %d" % (self.nv, nv))
        if self.used is not None:
            full = self.v.copy()
            full[self.used] = read_off_vertices(out)
            write_off(out, full, self.f)
        return dt

    def evaluate(self, p):
        out = os.path.join(self.ctx.work, "tmp", "ml.off")
        self.run(p, out)
        return self.ctx.compare(out, self.case["truth"])

    def timing(self, p):
        out = os.path.join(self.ctx.work, "tmp", "ml_t.off")
        ts = [self.run(p, out) for _ in range(3)]
        return {"time_s": statistics.median(ts),
                "time_what": "whole meshlabserver process (start, OFF read, filter, OFF "
                             "write; Xvfb already up), median of 3; TwoStep is single-threaded"}


# ---- search ------------------------------------------------------------------------
def cached_eval(ctx, case, cache, anchor, p):
    k = anchor.key(p)
    if k not in cache:
        cache[k] = anchor.evaluate(p)
        ctx.save_cache(case, cache)
    return cache[k]


def tune_1d(ctx, case, cache, anchor):
    grid = list(TAUBIN_GRID)
    ext = list(TAUBIN_EXT)
    while True:
        res = {k: cached_eval(ctx, case, cache, anchor, k) for k in grid}
        top = max(grid)
        best = {m: min(grid, key=lambda k: res[k][m]) for m in ("ev", "theta")}
        if any(best[m] == top for m in best) and ext:
            grid.append(ext.pop(0))
            continue
        break
    out = {"grid": grid}
    for m in ("ev", "theta"):
        k = best[m]
        edge = None
        if k == grid[0]:
            edge = "min (1, smallest possible)"
        elif k == grid[-1]:
            edge = "max (extensions exhausted)"
        out[m + "_opt"] = {"params": {"iterations": k}, "ev": res[k]["ev"],
                           "theta": res[k]["theta"], "at_edge": edge is not None}
        if edge:
            out[m + "_opt"]["edge"] = edge
    return out


def tune_lattice(ctx, case, cache, anchor, log):
    lat = {d: list(v) for d, v in TS_LATTICE.items()}
    up = {d: list(v) for d, v in TS_EXT_UP.items()}
    down = {d: list(v) for d, v in TS_EXT_DOWN.items()}

    def ev(p):
        return cached_eval(ctx, case, cache, anchor, p)

    result = {}
    for m in ("ev", "theta"):
        cands = []
        for start in TS_STARTS:
            p = tuple(start)
            steps = 0
            while True:
                cur = ev(p)[m]
                nbrs = []
                for i, d in enumerate(TS_DIMS):
                    vals = lat[d]
                    j = vals.index(p[i])
                    for jj in (j - 1, j + 1):
                        if 0 <= jj < len(vals):
                            q = list(p)
                            q[i] = vals[jj]
                            nbrs.append(tuple(q))
                scored = [(ev(q)[m], q) for q in nbrs]
                bv, bq = min(scored)
                if bv < cur:
                    p = bq
                    steps += 1
                    continue
                # local optimum: extend any coordinate sitting on an extendable end
                grew = False
                for i, d in enumerate(TS_DIMS):
                    vals = sorted(lat[d])
                    if p[i] == vals[-1] and up.get(d):
                        lat[d] = vals + [up[d].pop(0)]
                        grew = True
                    elif p[i] == vals[0] and down.get(d):
                        lat[d] = [down[d].pop(0)] + vals
                        grew = True
                if not grew:
                    break
            r = ev(p)
            log("  %s %s from %s -> %s ev %.4f theta %.3f (%d moves)" %
                (anchor.name, m, start, p, r["ev"], r["theta"], steps))
            cands.append((r[m], p))
        bv, bp = min(cands)
        r = ev(bp)
        edges = []
        for i, d in enumerate(TS_DIMS):
            vals = sorted(lat[d])
            if bp[i] == vals[0]:
                edges.append("%s min%s" % (d, " (1, smallest possible)" if d != "normalThr" else ""))
            elif bp[i] == vals[-1]:
                edges.append("%s max (extensions exhausted)" % d)
        at_edge = bool(edges)
        result[m + "_opt"] = {"params": dict(zip(TS_DIMS, bp)), "ev": r["ev"],
                              "theta": r["theta"], "at_edge": at_edge,
                              "starts": {str(s): {"opt": list(c[1]), m: c[0]}
                                         for s, c in zip(TS_STARTS, cands)}}
        if edges:
            result[m + "_opt"]["edge"] = edges
    result["lattice_final"] = lat
    result["evaluations"] = sum(1 for k in cache if k.startswith(anchor.name + "|"))
    return result


ANCHORS = {"open3d_taubin": Open3DTaubin, "rsmooth_taubin": RsmoothTaubin,
           "meshlab_twostep": MeshlabTwoStep}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cases", default="/work/cases/manifest.json")
    ap.add_argument("--rsmooth", required=True)
    ap.add_argument("--work", required=True, help="scratch dir (cache, temporaries)")
    ap.add_argument("--out", required=True)
    ap.add_argument("--anchors", default="open3d_taubin,rsmooth_taubin,meshlab_twostep")
    ap.add_argument("--only", default="", help="comma-separated case names")
    ap.add_argument("--first-sources", default="benchmark,train",
                    help="run cases of these sources first")
    args = ap.parse_args()

    cases = json.load(open(args.cases))["cases"]
    if args.only:
        want = args.only.split(",")
        cases = [c for c in cases if c["name"] in want]
    first = args.first_sources.split(",")
    # the named sources first, then the rest, smaller meshes first
    cases.sort(key=lambda c: (0 if c.get("source") in first else 1,
                              0 if c.get("source") in first else os.path.getsize(c["noisy"])))

    ctx = Ctx(args)
    res = {"grids": {}, "cases": {}}
    if os.path.exists(args.out):
        res = json.load(open(args.out))
    res["grids"] = {
        "open3d_taubin": {"iterations": TAUBIN_GRID, "extension_up": TAUBIN_EXT,
                          "fixed": {"lambda_filter": 0.5, "mu": -0.53},
                          "tool": "open3d %s" % __import__("open3d").__version__},
        "rsmooth_taubin": {"iterations": TAUBIN_GRID, "extension_up": TAUBIN_EXT,
                           "fixed": {"lambda": 0.5, "mu": -0.53}},
        "meshlab_twostep": {"lattice": TS_LATTICE, "extension_up": TS_EXT_UP,
                            "extension_down": TS_EXT_DOWN, "starts": TS_STARTS,
                            "search": "steepest descent over one-lattice-step moves in one "
                                      "coordinate, per figure, from each start; lattice "
                                      "extended when an optimum sits on an extendable end",
                            "tool": "meshlabserver 2020.09 (Debian meshlab 2020.09+dfsg1-2) "
                                    "under Xvfb, OFF in/out"},
        "measure": "rsmooth compare RESULT TRUTH --json: ev (E_v) and theta (degrees)",
    }

    def log(s):
        print(s, flush=True)

    def save():
        tmp = args.out + ".tmp"
        with open(tmp, "w") as fh:
            json.dump(res, fh, indent=1)
        os.replace(tmp, args.out)

    try:
        for aname in args.anchors.split(","):
            for case in cases:
                cache = ctx.load_cache(case)
                t0 = time.time()
                anchor = ANCHORS[aname](ctx, case)
                if aname == "meshlab_twostep":
                    out = tune_lattice(ctx, case, cache, anchor, log)
                else:
                    out = tune_1d(ctx, case, cache, anchor)
                tk = "timing|" + aname
                p = out["ev_opt"]["params"]
                pv = tuple(p[d] for d in TS_DIMS) if aname == "meshlab_twostep" \
                    else p["iterations"]
                if tk not in cache or cache[tk].get("at") != anchor.key(pv):
                    cache[tk] = dict(anchor.timing(pv), at=anchor.key(pv))
                    ctx.save_cache(case, cache)
                out.update({k: v for k, v in cache[tk].items() if k != "at"})
                res["cases"].setdefault(case["name"], {})[aname] = out
                save()
                log("%s %s: ev %.4f @%s | theta %.3f @%s | %.1fs tuning" % (
                    case["name"], aname, out["ev_opt"]["ev"], out["ev_opt"]["params"],
                    out["theta_opt"]["theta"], out["theta_opt"]["params"], time.time() - t0))
    finally:
        ctx.close()


if __name__ == "__main__":
    main()
