"""The learned stage against the hand-fitted one on shapes each fold's model never saw.

    python train/evaluate.py BUILD CACHE OUT --models DIR [--folds 0,1,2,3] [--cases A,B]

For each fold F, DIR/model-fold{F}.rsnn (trained without fold F's shapes) runs as
`rsmooth --best --auto --stage learned --model ...` and the hand-fitted stage as
`rsmooth --best --auto` on the fold's cases: the benchmark pairs of its shapes, fresh noisy
copies of its shapes (every noise class, seeds the training never used), GCN-Denoiser's noise
model (Gaussian along vertex normals of 0.1, 0.2, 0.3 and 0.6 mean edges; impulsive with 0.1,
0.2, 0.3 as both the fraction moved and the size) on its shapes, and the raw scans of its
shapes (against the reconstruction, with Taubin smoothing tuned against it as the anchor). Errors
by ../shared/tools/meshmetrics.py (independent of rsmooth): theta (mean face-normal angle,
degrees) and ev (vertex-to-surface, thousandths of the diagonal); a scan's theta is against the
reconstruction triangle nearest each centroid.

Each case also says where the learned step's limit lies, facet by facet: the mean normal error of
what the guided cycles leave (the model's input), of the model's normals of it, and of those
normals capped as the stage caps them (rsmooth-train-features --predict, the library's own path).
Writes OUT/evaluation.json and prints the tables docs/model.md quotes.
"""
import argparse
import functools
import hashlib
import json
import os
import shutil
import subprocess
import sys
from multiprocessing import Pool

import numpy as np
from scipy.spatial import cKDTree

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import dataset  # noqa: E402

METRICS = os.path.join(dataset.SHARED, "..", "tools", "meshmetrics.py")
GCN_LEVELS = (0.1, 0.2, 0.3, 0.6)
# lib/stages/normal_update.c's MAX_TURN_DEGREES: a facet the model turns further keeps its normal
MAX_TURN_DEGREES = 5.0
# a facet counts as at a crease when its true normal and one of its 8 nearest facets' differ by
# more than about 25 degrees (features.c's sharpness, 1 - the least cosine, above 0.1)
SHARP = 0.1
TAUBIN_GRID = (1, 2, 3, 5, 8, 12, 18, 27, 40, 60, 90)

sys.path.insert(0, os.path.dirname(METRICS))
import meshmetrics  # noqa: E402  (the independent measure)
# GCN-Denoiser's noise model on these shapes (the ones its published cases resemble: CAD parts,
# and a few scanned ones), to keep the evaluation within the training's hour
GCN_SHAPES = ("fandisk", "block", "stanford-bunny", "twelve", "trimstar", "sharpsphere",
              "rocker-arm", "armadillo", "lion", "screwdriver")


def eval_cases(cad_dir, folds, cad_per_fold):
    """(case dict with noisy/truth paths to make) for every fold's evaluation."""
    out = []
    for base in ("benchmark", "train"):
        for d in sorted(os.listdir(os.path.join(dataset.SHARED, base))):
            group = "".join(c for c in d if c.isalpha()).lower().replace("impulsive", "")
            group = "stanford-bunny" if group == "bunny" else group
            fold = dataset.PINNED_FOLDS.get(group)
            if fold in folds:
                out.append({"name": d, "fold": fold, "class": "benchmark", "noise": None,
                            "noisy": os.path.join(dataset.SHARED, base, d, "Noisy.obj"),
                            "truth": os.path.join(dataset.SHARED, base, d, "Original.obj")})
    cad_seen = {}
    for case in dataset.cases(cad_dir, dataset.NOISE_CLASSES, seed=1001):
        if case["fold"] not in folds or "Original" in case["clean"]:
            continue
        if case["class"] == "scan":
            out.append(dict(case, truth=None))
            continue
        if case["group"].startswith("cad-"):
            seen = cad_seen.setdefault(case["fold"], [])
            if case["group"] not in seen:
                if len(seen) >= cad_per_fold:
                    continue
                seen.append(case["group"])
        case = dict(case, truth=case["clean"], name=case["name"] + "-eval")
        out.append(case)
        if case["class"] == "gaussian" and case["group"] in GCN_SHAPES:
            for level in GCN_LEVELS:
                kinds = [("gcn-gaussian", ["--sigma", str(level)])]
                if level < 0.5:  # (its impulsive cases move at most 30% of the vertices)
                    kinds.append(("gcn-impulsive", ["--sigma", str(level), "--impulsive",
                                                    str(level)]))
                for kind, args in kinds:
                    seed = int(hashlib.sha256(f"{case['group']}/{kind}/{level}".encode())
                               .hexdigest()[:8], 16)
                    out.append(dict(case, name=f"{case['group']}-{kind}-{level}",
                                    **{"class": f"{kind}-{level}"},
                                    noise=args + ["--seed", str(seed)]))
    return out


def measure(result, truth):
    text = subprocess.run(["/usr/bin/python3", METRICS, result, truth], check=True,
                          capture_output=True, text=True).stdout
    fields = dict(w.split("=") for w in text.split())
    return float(fields["theta"]), float(fields["ev"])


@functools.lru_cache(maxsize=None)
def scan_surface(surface):
    """A reconstruction read once per process: vertices, triangles, normals, centroid tree, and
    the diagonal of its box in its own frame (a box turned with the scan's frame is another box),
    as docs/accuracy.md measured the scans."""
    tv, tf = meshmetrics.read_mesh(surface)
    tn, _ = meshmetrics.face_normals(tv, tf)
    rv, _ = meshmetrics.read_mesh(os.path.join(dataset.SHARED, "scans", "stanford-bunny",
                                               "bun_zipper.ply"))
    return tv, tf, tn, cKDTree(tv[tf].mean(1)), float(np.linalg.norm(rv.max(0) - rv.min(0)))


def measure_scan(result, surface):
    """theta against the nearest reconstruction triangle, ev of the vertices to its surface."""
    tv, tf, tn, tree, diag = scan_surface(surface)
    v, f = meshmetrics.read_mesh(result)
    n, area = meshmetrics.face_normals(v, f)
    va = np.zeros(len(v))
    for j in range(3):
        np.add.at(va, f[:, j], area)
    used = va > 0
    d = meshmetrics.dist_to_surface(v[used], tv, tf)
    ev = float(np.sqrt((va[used] * d ** 2).sum() / va[used].sum())) / diag * 1e3
    _, nearest = tree.query(v[f].mean(1))
    cos = np.clip((n * tn[nearest]).sum(1), -1, 1)
    return float(np.degrees(np.arccos(cos[np.isfinite(cos)])).mean()), ev


def smooth(build, noisy, path, args):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    subprocess.run([os.path.join(build, "rsmooth"), noisy, "-o", path, "-q", "-f"] + args,
                   check=True)


def facet_normals(build, cache, out, case, noisy, model, surface):
    """Mean normal error (degrees), over all facets and over those at creases, of what the guided
    cycles leave, of the model's normals of it, and of those normals capped."""
    staged = dataset.staged_mesh(build, cache, case, noisy)
    folder = os.path.join(out, "results", case["name"] + "-facets")
    os.makedirs(folder, exist_ok=True)
    truth = ["--truth-surface", surface] if case["class"] == "scan" else ["--truth", case["truth"]]
    subprocess.run([os.path.join(build, "rsmooth-train-features"), staged, folder, "--model",
                    model, "--stages", "0", "--predict", "--noise-from", noisy] + truth,
                   check=True, stdout=subprocess.DEVNULL)
    read = {k: np.load(os.path.join(folder, k + ".npy")).astype(np.float64)
            for k in ("normal", "predicted", "target", "sharp")}
    shutil.rmtree(folder)

    def angle(a, b):
        cos = (a * b).sum(1) / (np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1))
        return np.degrees(np.arccos(np.clip(cos, -1, 1)))
    staged_err = angle(read["normal"], read["target"])
    learned_err = angle(read["predicted"], read["target"])
    turned = angle(read["predicted"], read["normal"])
    capped_err = np.where(turned > MAX_TURN_DEGREES, staged_err, learned_err)
    sharp = read["sharp"].ravel() > SHARP
    row = {"staged": float(staged_err.mean()), "learned": float(learned_err.mean()),
           "capped": float(capped_err.mean()), "crease_share": float(sharp.mean())}
    if sharp.any():
        row["crease"] = [float(staged_err[sharp].mean()), float(learned_err[sharp].mean())]
    return row


def run_case(job):
    build, cache, out, case, model = job
    noisy = case.get("noisy") or dataset.noisy_mesh(build, cache, case)
    scan = case["class"] == "scan"
    surface = dataset.scan_truth(cache, case["name"]) if scan else None
    score = (lambda p: measure_scan(p, surface)) if scan else (lambda p: measure(p, case["truth"]))
    result = {"name": case["name"], "fold": case["fold"], "class": case["class"]}
    for label, extra in (("hand", []), ("learned", ["--stage", "learned", "--model", model])):
        path = os.path.join(out, "results", f"{case['name']}-{label}.ply")
        smooth(build, noisy, path, ["--best", "--auto"] + extra)
        result[label] = score(path)
        os.remove(path)
    if scan:  # (the raw range grid as triangles: a filter that moves nothing writes them)
        path = os.path.join(out, "results", f"{case['name']}-raw.ply")
        smooth(build, noisy, path, ["--method", "laplacian", "--iterations", "0"])
        result["input"] = score(path)
        os.remove(path)
    else:
        result["input"] = score(noisy)
    if scan:  # the standing anchor: Taubin smoothing tuned against the reconstruction
        grid = {}
        for n in TAUBIN_GRID:
            path = os.path.join(out, "results", f"{case['name']}-taubin.ply")
            smooth(build, noisy, path, ["--method", "taubin", "--iterations", str(n)])
            grid[n] = score(path)
            os.remove(path)
        best = min(grid, key=lambda n: grid[n][1])
        result["taubin"] = {"iterations": best, "theta": grid[best][0], "ev": grid[best][1],
                            "at_grid_edge": best in (TAUBIN_GRID[0], TAUBIN_GRID[-1])}
    result["normals"] = facet_normals(build, cache, out, case, noisy, model, surface)
    return result


def summary(results):
    """Per class: cases, median ratio learned / hand in theta and ev, wins."""
    rows = {}
    for r in results:
        key = r["class"].split("-0")[0] if r["class"].startswith("gcn") else r["class"]
        rows.setdefault(key, []).append(r)
    table = {}
    for key, rs in sorted(rows.items()):
        t = [r["learned"][0] / r["hand"][0] for r in rs if r["hand"][0] > 0]
        e = [r["learned"][1] / r["hand"][1] for r in rs if r["hand"][1] > 0]
        table[key] = {"cases": len(rs), "theta_ratio": float(np.median(t)) if t else None,
                      "ev_ratio": float(np.median(e)) if e else None,
                      "theta_wins": sum(x <= 1.0 for x in t), "ev_wins": sum(x <= 1.0 for x in e),
                      "theta_learned": float(np.mean([r["learned"][0] for r in rs])),
                      "theta_hand": float(np.mean([r["hand"][0] for r in rs])),
                      "ev_learned": float(np.mean([r["learned"][1] for r in rs])),
                      "ev_hand": float(np.mean([r["hand"][1] for r in rs]))}
        facets = [r["normals"] for r in rs if "normals" in r]
        if facets:
            table[key]["normals"] = {k: float(np.mean([x[k] for x in facets]))
                                     for k in ("staged", "learned", "capped")}
    return table


def markdown(results, table):
    """The model card's tables: per noise class, then every left-out case."""
    lines = ["| noise class | cases | mean theta, guided -> learned | mean ev, guided -> learned "
             "| median ratio theta / ev (learned / guided) | learned at or below guided, theta "
             "/ ev |", "| --- | --- | --- | --- | --- | --- |"]
    for key, row in table.items():
        ratio = " / ".join("-" if row[k] is None else f"{row[k]:.3f}"  # (all zero: clean)
                           for k in ("theta_ratio", "ev_ratio"))
        lines.append(f"| {key} | {row['cases']} | {row['theta_hand']:.2f} -> "
                     f"{row['theta_learned']:.2f} | {row['ev_hand']:.3f} -> "
                     f"{row['ev_learned']:.3f} | {ratio} | {row['theta_wins']} / {row['ev_wins']} |")
    lines += ["", "Facet by facet (the model's input, its normals, capped), mean normal error in "
              "degrees:", "", "| noise class | after the guided cycles | the model's normals | "
              "capped as the stage caps them |", "| --- | --- | --- | --- |"]
    for key, row in table.items():
        if "normals" in row:
            n = row["normals"]
            lines.append(f"| {key} | {n['staged']:.2f} | {n['learned']:.2f} | {n['capped']:.2f} |")
    scans = [r for r in results if "taubin" in r]
    if scans:
        lines += ["", "| scan | raw theta / ev | guided | learned | Taubin tuned on the truth |",
                  "| --- | --- | --- | --- | --- |"]
        for r in scans:
            t = r["taubin"]
            lines.append(f"| {r['name']} | {r['input'][0]:.2f} / {r['input'][1]:.3f} "
                         f"| {r['hand'][0]:.2f} / {r['hand'][1]:.3f} "
                         f"| {r['learned'][0]:.2f} / {r['learned'][1]:.3f} "
                         f"| {t['theta']:.2f} / {t['ev']:.3f} (N = {t['iterations']}) |")
    lines += ["", "| case | fold | input theta / ev | guided | learned | facets: guided cycles"
              " -> model -> capped |", "| --- | --- | --- | --- | --- | --- |"]
    for r in sorted(results, key=lambda r: (r["fold"], r["name"])):
        lines.append(f"| {r['name']} | {r['fold']} | {r['input'][0]:.2f} / {r['input'][1]:.3f} "
                     f"| {r['hand'][0]:.2f} / {r['hand'][1]:.3f} "
                     f"| {r['learned'][0]:.2f} / {r['learned'][1]:.3f} "
                     f"| {facets_cell(r)} |")
    return "\n".join(lines) + "\n"


def facets_cell(r):
    n = r.get("normals")
    return f"{n['staged']:.2f} -> {n['learned']:.2f} -> {n['capped']:.2f}" if n else ""


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("build")
    ap.add_argument("cache")
    ap.add_argument("out")
    ap.add_argument("--models", required=True)
    ap.add_argument("--cad")
    ap.add_argument("--folds", default="0,1,2,3")
    ap.add_argument("--cad-per-fold", type=int, default=3)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--cases", help="only these cases (names, comma-separated)")
    args = ap.parse_args()
    folds = [int(f) for f in args.folds.split(",")]
    cases = eval_cases(args.cad, folds, args.cad_per_fold)
    if args.cases:
        cases = [c for c in cases if c["name"] in args.cases.split(",")]
    jobs = [(args.build, args.cache, args.out, c,
             os.path.join(args.models, f"model-fold{c['fold']}.rsnn")) for c in cases]
    results = []
    with Pool(args.jobs) as pool:
        for i, r in enumerate(pool.imap(run_case, jobs)):
            results.append(r)
            print(f"[{i + 1}/{len(jobs)}] {r['name']:40s} input {r['input'][0]:6.2f} {r['input'][1]:6.3f}"
                  f"  hand {r['hand'][0]:6.2f} {r['hand'][1]:6.3f}"
                  f"  learned {r['learned'][0]:6.2f} {r['learned'][1]:6.3f}", flush=True)
    table = summary(results)
    with open(os.path.join(args.out, "evaluation.json"), "w") as f:
        json.dump({"cases": results, "by_class": table}, f, indent=1)
    with open(os.path.join(args.out, "evaluation.md"), "w") as f:
        f.write(markdown(results, table))
    print(json.dumps(table, indent=1))


if __name__ == "__main__":
    main()
