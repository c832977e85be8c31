"""The choice per region (lib/passes/region_choice.c): its bounds fitted with cross-validation that
leaves whole meshes out, from an independent numpy implementation of the blend.

    python3 scripts/region_study.py --cases /work/cases/manifest.json \
        --stage docs/results/calibration_stage.json --out docs/results/region_study.json

For every case: F, the best mode's result with the stage setting the case's fold chose
(calibration_stage.json, from scripts/calibrate_stage.py fit; no --auto, so no blend), and T,
Taubin's smoothing of the input with the iterations the command's --auto reports (the discrepancy
principle at the estimated noise). Then, for each candidate (low, high, spread): per vertex, the
share of the pairs of facets sharing an edge at it whose normals in F lie within 2 degrees,
spread over `spread` rings, the weight w = clamp((share - low) / (high - low)), the result
w F + (1 - w) T, boundary vertices limited to the noise level in their edge lengths from the
input; E_v and theta by `rsmooth compare`. The bounds are chosen per left-out group on the other
groups (lowest mean ratio of E_v to each case's best candidate); the figures reported for a case
come from bounds that never saw that mesh.

`--check` compares the library's own blend (`--best --auto` with the fold's stage) with this
script's at the library's bounds: the largest vertex difference, in mean edge lengths."""
import argparse
import itertools
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from obj_mesh import read_obj, write_obj  # noqa: E402

LOWS = [0.1, 0.2, 0.3, 0.4]
WIDTHS = [0.3, 0.4, 0.6]
SPREADS = [3, 6]
LIBRARY = (0.2, 0.8, 6)  # region_choice.c's SHARE_LOW, SHARE_HIGH, SHARE_SPREAD
FLAT_ANGLE = np.radians(2.0)


def weld(x):
    """Each vertex's representative: the lowest-numbered vertex at exactly its position."""
    _, first, inverse = np.unique(x, axis=0, return_index=True, return_inverse=True)
    return first[inverse.ravel()]


def facet_geometry(x, faces):
    a, b, c = x[faces[:, 0]], x[faces[:, 1]], x[faces[:, 2]]
    n = np.cross(b - a, c - a)
    area2 = np.linalg.norm(n, axis=1)
    keep = area2 > 0
    return faces[keep], n[keep] / area2[keep, None]


def vertex_shares(f_xyz, faces):
    """share[r] (NaN without pairs) and boundary[r] per welded vertex r, as region_choice.c."""
    rep = weld(f_xyz)
    tri, normal = facet_geometry(f_xyz, faces)
    t = rep[tri]
    nv = len(f_xyz)
    # one row per (vertex r, other corner o, facet): the edges at r and who holds them
    rows = []
    for a in range(3):
        for b in range(3):
            if a != b:
                rows.append(np.stack([t[:, a], t[:, b], np.arange(len(t))], axis=1))
    e = np.concatenate(rows)
    e = e[e[:, 0] != e[:, 1]]
    order = np.lexsort((e[:, 2], e[:, 1], e[:, 0]))
    e = e[order]
    key = e[:, 0].astype(np.int64) * (nv + 1) + e[:, 1]
    starts = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
    counts = np.diff(np.r_[starts, len(e)])
    pairs = np.zeros(nv)
    flat = np.zeros(nv)
    boundary = np.zeros(nv, bool)
    cos_max = np.cos(FLAT_ANGLE)
    boundary[e[starts[counts == 1], 0]] = True
    for s, c in zip(starts[counts >= 2], counts[counts >= 2]):
        r = e[s, 0]
        fs = e[s:s + c, 2]
        for i, j in itertools.combinations(fs, 2):
            pairs[r] += 1
            flat[r] += normal[i] @ normal[j] >= cos_max
    share = np.where(pairs > 0, flat / np.maximum(pairs, 1), np.nan)
    share[rep != np.arange(nv)] = np.nan
    return rep, tri, share, boundary


def spread(share, rep, tri, rounds):
    t = rep[tri]
    for _ in range(rounds):
        corner = share[t]                       # (facets, 3)
        ok = ~np.isnan(corner)
        s = np.where(ok, corner, 0).sum(axis=1)
        n = ok.sum(axis=1)
        total = np.zeros(len(share))
        count = np.zeros(len(share))
        for c in range(3):                      # each facet counts at each of its corners
            np.add.at(total, t[:, c], s)
            np.add.at(count, t[:, c], n)
        share = np.where(count > 0, total / np.maximum(count, 1), share)
    return share


def local_edges(x_in, rep, tri):
    """The mean length of the edges at each welded vertex, from each of its facets' corners."""
    t = rep[tri]
    total = np.zeros(len(x_in))
    count = np.zeros(len(x_in))
    for a in range(3):
        for b in range(3):
            if a != b:
                d = np.linalg.norm(x_in[tri[:, b]] - x_in[t[:, a]], axis=1)
                ok = t[:, b] != t[:, a]
                np.add.at(total, t[ok, a], d[ok])
                np.add.at(count, t[ok, a], 1)
    return np.where(count > 0, total / np.maximum(count, 1), 0)


def shape_correlation(x, faces):
    """lib/core/shape_correlation.c in numpy: the correlation of each welded vertex's umbrella
    offset along its (area-weighted) normal with its neighbours' mean."""
    rep = weld(x)
    t = rep[faces]
    n = np.cross(x[faces[:, 1]] - x[faces[:, 0]], x[faces[:, 2]] - x[faces[:, 0]])
    normal = np.zeros_like(x)
    for c in range(3):
        np.add.at(normal, t[:, c], n)
    e = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    e = np.unique(e[e[:, 0] != e[:, 1]], axis=0)
    total, degree = np.zeros_like(x), np.zeros(len(x))
    np.add.at(total, e[:, 0], x[e[:, 1]])
    np.add.at(total, e[:, 1], x[e[:, 0]])
    np.add.at(degree, e[:, 0], 1)
    np.add.at(degree, e[:, 1], 1)
    length = np.linalg.norm(normal, axis=1)
    valid = (rep == np.arange(len(x))) & (degree > 0) & (length > 0)
    bend = np.zeros(len(x))
    bend[valid] = np.sum((total[valid] / degree[valid, None] - x[valid]) * normal[valid], axis=1) \
        / length[valid]
    both = valid[e[:, 0]] & valid[e[:, 1]]
    around, count = np.zeros(len(x)), np.zeros(len(x))
    np.add.at(around, e[both, 0], bend[e[both, 1]])
    np.add.at(around, e[both, 1], bend[e[both, 0]])
    np.add.at(count, e[both, 0], 1)
    np.add.at(count, e[both, 1], 1)
    valid &= count > 0
    a, b = bend[valid], around[valid] / count[valid]
    if len(a) < 2 or a.var() <= 0 or b.var() <= 0:
        return 1.0
    return float(np.corrcoef(a, b)[0, 1])


def fold_guard(x_in, out, faces, untangles=8, halvings=24):
    """lib/stages/fold_guard.c in numpy. A clean input (here: bends correlated; the library also
    reads clean what its noise estimate finds within 1.4 times the shape's own residual, which
    none of the noisy cases is): a triangle turned by
    more than 90 degrees from the input's is turned over; a noisy one: a triangle facing against
    its neighbourhood in the result (the unit normals of the triangles at its corners, summed)
    that did not in the input. Each round moves the vertices of every turned-over
    triangle: on a noisy input first (`untangles` rounds) to the mean of the other corners of the
    triangles at the welded vertex (a boundary vertex: of its neighbours along the boundary, and
    no farther from the input than the filter put it), then halfway back toward the input (after `halvings` such
    rounds, snaps them and two rings of vertices around them to the input)."""
    out = out.copy()
    rep = weld(x_in)
    e = np.sort(rep[np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])], axis=1)
    e = e[e[:, 0] != e[:, 1]]
    edges, counts = np.unique(e, axis=0, return_counts=True)
    boundary = np.zeros(len(x_in), bool)  # welded vertices on an edge of one triangle
    border = edges[counts == 1]
    boundary[border.ravel()] = True
    reach = np.linalg.norm(out - x_in, axis=1)

    def unit(x):
        n = np.cross(x[faces[:, 1]] - x[faces[:, 0]], x[faces[:, 2]] - x[faces[:, 0]])
        length = np.linalg.norm(n, axis=1)
        ok = length > 0
        return np.where(ok[:, None], n / np.where(ok, length, 1)[:, None], 0), ok

    def facing(n):  # against the unit normals of the triangles at its corners, summed
        at_vertex = np.zeros_like(x_in)
        for c in range(3):
            np.add.at(at_vertex, faces[:, c], n)
        return np.sum(n * at_vertex[faces].sum(axis=1), axis=1)
    n_in, ok_in = unit(x_in)
    folded_in = facing(n_in) <= 0

    def turned(reading):
        n_out, ok_out = unit(out)
        ok = ok_in & ok_out
        clean = ok & (np.sum(n_out * n_in, axis=1) < 0)
        noisy = ok & ~folded_in & (facing(n_out) < 0)
        return {"clean": clean, "noisy": noisy, "either": clean | noisy}[reading]
    if not turned("either").any():
        return out
    reading = "clean" if shape_correlation(x_in, faces) >= 0.3 else "noisy"
    for round_ in itertools.count():
        bad = turned(reading)
        if not bad.any():
            return out
        if reading == "noisy" and round_ < untangles:
            marked = np.zeros(len(x_in), bool)
            marked[rep[faces[bad].ravel()]] = True
            r = rep[faces]
            total, count = np.zeros_like(x_in), np.zeros(len(x_in))
            for c in range(3):
                m = marked[r[:, c]]
                np.add.at(total, r[m, c], out[faces[m, (c + 1) % 3]] + out[faces[m, (c + 2) % 3]])
                np.add.at(count, r[m, c], 2)
            along, n_along = np.zeros_like(x_in), np.zeros(len(x_in))  # the boundary's: along it
            for a, b in ((0, 1), (1, 0)):
                np.add.at(along, border[:, a], out[border[:, b]])
                np.add.at(n_along, border[:, a], 1)
            total[boundary], count[boundary] = along[boundary], n_along[boundary]
            v = np.flatnonzero(marked[rep] & (count[rep] > 0))
            out[v] = total[rep[v]] / count[rep[v], None]
            d = out[v] - x_in[v]  # a boundary vertex no farther than the filter put it
            length = np.linalg.norm(d, axis=1)
            clamp = boundary[rep[v]] & (length > reach[v])
            out[v[clamp]] = x_in[v[clamp]] + d[clamp] * (reach[v[clamp]] / length[clamp])[:, None]
        elif round_ < untangles * (reading == "noisy") + halvings:
            v = np.unique(faces[bad])
            out[v] = x_in[v] + (out[v] - x_in[v]) / 2
        else:
            seed = np.zeros(len(x_in), bool)
            seed[faces[bad].ravel()] = True
            for _ in range(2):  # and two rings of vertices around
                seed[faces[seed[faces].any(axis=1)].ravel()] = True
            out[seed] = x_in[seed]


def blend(x_in, f_xyz, t_xyz, faces, level, low, high, rounds, parts=None):
    rep, tri, share, boundary = parts or vertex_shares(f_xyz, faces)
    s = spread(share, rep, tri, rounds)[rep]
    w = np.where(np.isnan(s), 1.0, np.clip((s - low) / (high - low), 0, 1))
    out = w[:, None] * f_xyz + (1 - w[:, None]) * t_xyz
    b = boundary[rep]
    limit = level * local_edges(x_in, rep, tri)[rep]
    d = out - x_in
    move = np.linalg.norm(d, axis=1)
    clamp = b & (move > limit)
    out[clamp] = x_in[clamp] + d[clamp] * (limit[clamp] / move[clamp])[:, None]
    return fold_guard(x_in, out, faces), float(w.mean())


def run(rsmooth, args):
    p = subprocess.run([rsmooth] + args, capture_output=True, text=True)
    if p.returncode:
        sys.exit("region_study.py: %s: %s" % (" ".join(args), p.stderr))
    return p


def compare(rsmooth, path, truth):
    return json.loads(run(rsmooth, ["compare", path, truth, "--json"]).stdout)


def case_inputs(rsmooth, case, stage, tmp):
    """F, T, the level and the input, each as a vertex array, and the faces."""
    f_path, t_path = os.path.join(tmp, "f.obj"), os.path.join(tmp, "t.obj")
    stage = [o for o in stage if o != "--auto"]  # F: the stage and its pass, no choice
    # (nor the fold guard, which the library runs after the choice, as blend() does)
    run(rsmooth, [case["noisy"], "-o", f_path, "-f", "-q", "--no-guard"] + stage)
    p = run(rsmooth, [case["noisy"], "-o", os.path.join(tmp, "a.obj"), "-f", "--json", "--auto"]
            + stage)
    report = json.loads(p.stdout.strip().splitlines()[-1])
    level = float(re.search(r"noise estimate ([0-9.eE+-]+)", p.stderr).group(1))
    if "impulsive" in p.stderr:
        level = report.get("discrepancy_level", level)
    iterations = report.get("region_choice", {}).get("taubin_iterations", 0)
    run(rsmooth, [case["noisy"], "-o", t_path, "-f", "-q", "--method", "taubin", "--iterations",
                  str(max(iterations, 1))])
    x_in, faces = read_obj(case["noisy"])
    return (x_in, read_obj(f_path)[0], read_obj(t_path)[0] if iterations else read_obj(f_path)[0],
            faces, report.get("discrepancy_level", level), iterations)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cases", required=True)
    ap.add_argument("--stage", default="docs/results/calibration_stage.json")
    ap.add_argument("--rsmooth", default="build/rsmooth")
    ap.add_argument("--out", default="docs/results/region_study.json")
    ap.add_argument("--only", default="")
    ap.add_argument("--check", action="store_true")
    args = ap.parse_args()
    cases = json.load(open(args.cases))["cases"]
    if args.only:
        cases = [c for c in cases if c["name"] in args.only.split(",")]
    fold = {r["case"]: r["setting"].split() for r in json.load(open(args.stage))["rows"]}
    grid = [(lo, lo + w, s) for lo in LOWS for w in WIDTHS for s in SPREADS]
    table = {}
    with tempfile.TemporaryDirectory() as tmp:
        for case in cases:
            x_in, f_xyz, t_xyz, faces, level, iterations = case_inputs(
                args.rsmooth, case, fold[case["name"]], tmp)
            parts = vertex_shares(f_xyz, faces)
            row = {"level": level, "taubin_iterations": iterations,
                   "filter": compare(args.rsmooth, os.path.join(tmp, "f.obj"), case["truth"]),
                   "taubin": compare(args.rsmooth, os.path.join(tmp, "t.obj"), case["truth"])}
            if args.check:
                mine, _ = blend(x_in, f_xyz, t_xyz, faces, level, *LIBRARY, parts=parts)
                lib = read_obj(os.path.join(tmp, "a.obj"))[0]
                unit = np.mean(np.linalg.norm(x_in[faces[:, 0]] - x_in[faces[:, 1]], axis=1))
                row["check_max_gap"] = float(np.abs(mine - lib).max() / unit)
                print("%s: library vs numpy blend: %.3g mean edge lengths" % (
                    case["name"], row["check_max_gap"]), flush=True)
            for lo, hi, s in ([] if args.check else grid):
                out, mean_w = blend(x_in, f_xyz, t_xyz, faces, level, lo, hi, s, parts=parts)
                path = os.path.join(tmp, "b.obj")
                write_obj(path, out, faces)
                m = compare(args.rsmooth, path, case["truth"])
                row["%g %g %d" % (lo, hi, s)] = {"ev": m["ev"], "theta": m["theta"],
                                                 "filter_share": mean_w}
            table[case["name"]] = row
            if not args.check:
                print("%-22s filter %.3f taubin %.3f best blend %.3f" % (
                    case["name"], row["filter"]["ev"], row["taubin"]["ev"],
                    min(row["%g %g %d" % g]["ev"] for g in grid)), flush=True)
    if args.check:
        return
    keys = ["%g %g %d" % g for g in grid]

    def ratio(c, k):
        return table[c][k]["ev"] / min(table[c][q]["ev"] for q in keys)

    groups = sorted({c["group"] for c in cases})
    rows = []
    for g in groups:
        train = [c["name"] for c in cases if c["group"] != g]
        k = min(keys, key=lambda q: statistics.mean(ratio(c, q) for c in train))
        for c in (c["name"] for c in cases if c["group"] == g):
            rows.append({"case": c, "bounds": k, "ev": table[c][k]["ev"],
                         "theta": table[c][k]["theta"], "filter_ev": table[c]["filter"]["ev"],
                         "taubin_ev": table[c]["taubin"]["ev"]})
    chosen_all = min(keys, key=lambda q: statistics.mean(ratio(c["name"], q) for c in cases))
    with open(args.out, "w") as f:
        json.dump({"grid": {"low": LOWS, "width": WIDTHS, "spread": SPREADS},
                   "chosen_all": chosen_all, "rows": rows, "table": table}, f, indent=1)
    for r in rows:
        print("%-22s bounds %-12s E_v %.3f (filter %.3f, taubin %.3f)" % (
            r["case"], r["bounds"], r["ev"], r["filter_ev"], r["taubin_ev"]))
    print("bounds fitted on all groups (low high spread):", chosen_all)


if __name__ == "__main__":
    main()
