"""The learned stage against the hand-fitted one on shapes each fold's model never saw.

    python train/evaluate.py BUILD CACHE OUT --models DIR [--folds 0,1,2,3] [--quick]

For each fold F, DIR/model-fold{F}.rsnn (trained without fold F's shapes) runs as
`rsmooth --best --auto --stage learned --model ...` and the hand-fitted stage as
`rsmooth --best --auto` on the fold's cases: the benchmark pairs of its shapes, fresh noisy
copies of its shapes (every noise class, seeds the training never used), GCN-Denoiser's noise
model (Gaussian along vertex normals of 0.1, 0.2, 0.3 and 0.6 mean edges; impulsive with 0.1,
0.2, 0.3 as both the fraction moved and the size) on its shapes, and the raw scans (against the
reconstruction). Errors by ../shared/tools/meshmetrics.py (independent of rsmooth): theta (mean
face-normal angle, degrees) and ev (vertex-to-surface, thousandths of the diagonal). Writes
OUT/evaluation.json and prints the tables docs/model.md quotes.
"""
import argparse
import hashlib
import json
import os
import subprocess
import sys
from multiprocessing import Pool

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import dataset  # noqa: E402

METRICS = os.path.join(dataset.SHARED, "..", "tools", "meshmetrics.py")
GCN_LEVELS = (0.1, 0.2, 0.3, 0.6)
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
        if case["fold"] not in folds or case["class"] == "scan" or "Original" in case["clean"]:
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


def run_case(job):
    build, cache, out, case, model = job
    noisy = case.get("noisy") or dataset.noisy_mesh(build, cache, case)
    result = {"name": case["name"], "fold": case["fold"], "class": case["class"]}
    for label, extra in (("hand", []), ("learned", ["--stage", "learned", "--model", model])):
        path = os.path.join(out, "results", f"{case['name']}-{label}.ply")
        os.makedirs(os.path.dirname(path), exist_ok=True)
        subprocess.run([os.path.join(build, "rsmooth"), noisy, "-o", path, "--best", "--auto",
                        "-q", "-f"] + extra, check=True)
        result[label] = measure(path, case["truth"])
        os.remove(path)
    result["input"] = measure(noisy, case["truth"])
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
    return table


def markdown(results, table):
    """The model card's tables: per noise class, then every left-out case."""
    lines = ["| noise class | cases | mean theta, guided -> learned | mean ev, guided -> learned "
             "| median ratio theta / ev (learned / guided) | learned at or below guided, theta "
             "/ ev |", "| --- | --- | --- | --- | --- | --- |"]
    for key, row in table.items():
        lines.append(f"| {key} | {row['cases']} | {row['theta_hand']:.2f} -> "
                     f"{row['theta_learned']:.2f} | {row['ev_hand']:.3f} -> "
                     f"{row['ev_learned']:.3f} | {row['theta_ratio']:.3f} / "
                     f"{row['ev_ratio']:.3f} | {row['theta_wins']} / {row['ev_wins']} |")
    lines += ["", "| case | fold | input theta / ev | guided | learned |",
              "| --- | --- | --- | --- | --- |"]
    for r in sorted(results, key=lambda r: (r["fold"], r["name"])):
        lines.append(f"| {r['name']} | {r['fold']} | {r['input'][0]:.2f} / {r['input'][1]:.3f} "
                     f"| {r['hand'][0]:.2f} / {r['hand'][1]:.3f} "
                     f"| {r['learned'][0]:.2f} / {r['learned'][1]:.3f} |")
    return "\n".join(lines) + "\n"


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
    args = ap.parse_args()
    folds = [int(f) for f in args.folds.split(",")]
    cases = eval_cases(args.cad, folds, args.cad_per_fold)
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
