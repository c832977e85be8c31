"""Issue 15's calibration: every candidate setting of the paper's filter and of the best mode on
every case of scripts/make_cases.py, then the automatic rules chosen by cross-validation that
leaves whole meshes out.

    python3 scripts/calibrate.py run  --cases /work/cases/manifest.json --rsmooth build/rsmooth
    python3 scripts/calibrate.py fit  --cases /work/cases/manifest.json --rsmooth build/rsmooth \
        --out docs/results/calibration.json

`run` fills a cache (--cache, JSON) with E_v, theta and the wall time of each (case, setting):
rerunning skips what is there. `fit` reads it and, for each group of cases (one underlying
model), chooses the rule's settings on the other groups only and applies them to the left-out
group: the figures it reports for a case come from a rule that never saw that mesh.

The rules map the estimated noise level (rsmooth's own estimate, printed by --auto) to settings:
  - paper mode: sigma_f = a + b n, sigma_g = c n, (a, b, c) from a small lattice;
  - best mode: one candidate setting per noise class (low, mid, high, impulsive), the one with
    the lowest mean ratio of E_v to the case's best candidate over the training groups.
The classes' bounds are fixed in advance (LEVEL_BOUNDS), not fitted."""
import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

PAPER_SF = [1.0, 1.5, 2.0, 2.5, 3.0, 4.0]
PAPER_SG = [0.15, 0.25, 0.35, 0.5, 0.75, 1.1, 1.6]
STAGE = [("--guided-sigma-s", [2.0]), ("--guided-sigma-n", [0.15, 0.2, 0.3, 0.45]),
         ("--guided-rounds", [5, 10, 20, 40])]
JONES_AFTER = {"none": ["--passes", "0"], "best1": ["--best", "--passes", "1"]}
LEVEL_BOUNDS = [0.25, 0.45]  # low < 0.25 <= mid < 0.45 <= high (estimated level)


def paper_settings():
    return [["--sigma-f", str(f), "--sigma-g", str(g)] for f in PAPER_SF for g in PAPER_SG]


def best_settings():
    out = [["--best"], ["--best", "--auto"]]
    for s in STAGE[0][1]:
        for n in STAGE[1][1]:
            for r in STAGE[2][1]:
                for after in JONES_AFTER.values():
                    out.append(after + ["--vertex-updates", "25", "--guided-sigma-s", str(s),
                                        "--guided-sigma-n", str(n), "--guided-rounds", str(r)])
    return out


def key(opts):
    return " ".join(opts) if opts else "(defaults)"


def run_one(rsmooth, case, opts, tmp):
    out = os.path.join(tmp, "out.obj")
    t0 = time.perf_counter()
    p = subprocess.run([rsmooth, case["noisy"], "-o", out, "-f", "-q"] + opts,
                       capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        return {"error": p.stderr.strip()[-300:]}
    c = subprocess.run([rsmooth, "compare", out, case["truth"], "--json"], capture_output=True,
                       text=True, check=True)
    m = json.loads(c.stdout)
    return {"ev": m["ev"], "theta": m["theta"], "s": round(wall, 3)}


def estimate(rsmooth, case, tmp):
    """rsmooth's noise estimate of a case, as --auto prints it."""
    p = subprocess.run([rsmooth, case["noisy"], "-o", os.path.join(tmp, "est.obj"), "-f",
                        "--auto"], capture_output=True, text=True)
    m = re.search(r"noise estimate ([0-9.eE+-]+)", p.stderr)
    if not m:
        sys.exit("calibrate.py: no estimate for %s: %s" % (case["name"], p.stderr))
    kind = "impulsive" if "impulsive" in p.stderr else "gaussian"
    return float(m.group(1)), kind


def load(path):
    return json.load(open(path)) if os.path.exists(path) else {}


def cmd_run(args, cases):
    cache = load(args.cache)
    settings = ([] if args.only == "best" else [[]] + paper_settings()) + \
               ([] if args.only == "paper" else best_settings())
    with tempfile.TemporaryDirectory() as tmp:
        for case in cases:
            done = cache.setdefault(case["name"], {})
            for opts in settings:
                if key(opts) in done:
                    continue
                done[key(opts)] = run_one(args.rsmooth, case, opts, tmp)
                with open(args.cache + ".tmp", "w") as f:
                    json.dump(cache, f)
                os.replace(args.cache + ".tmp", args.cache)
            print("%s: %d settings" % (case["name"], len(done)), flush=True)


def level_class(level, kind):
    if kind == "impulsive":
        return "impulsive"
    return "low" if level < LEVEL_BOUNDS[0] else "mid" if level < LEVEL_BOUNDS[1] else "high"


def cmd_fit(args, cases):
    cache = load(args.cache)
    with tempfile.TemporaryDirectory() as tmp:
        est = {c["name"]: estimate(args.rsmooth, c, tmp) for c in cases}
    groups = sorted({c["group"] for c in cases})
    best_keys = [key(o) for o in best_settings()]

    def ev(case, k):
        r = cache[case["name"]].get(k, {})
        return r.get("ev", float("inf"))

    def best_of(case, keys):
        return min(ev(case, k) for k in keys)

    # paper mode: sigma_f = a + b n, sigma_g = c n, each snapped to the measured lattice
    def snap(x, grid):
        return min(grid, key=lambda g: abs(g - x))

    def paper_key(rule, n):
        a, b, c = rule
        return key(["--sigma-f", str(snap(a + b * n, PAPER_SF)),
                    "--sigma-g", str(snap(c * n, PAPER_SG))])

    paper_keys = [key(o) for o in paper_settings()]
    rules = [(a, b, c) for a in (0.6, 0.9, 1.2, 1.5) for b in (0.4, 0.8, 1.2, 1.6, 2.4)
             for c in (1.5, 2.0, 2.5, 3.0, 3.5)]

    def paper_loss(rule, train):
        return statistics.mean(ev(c, paper_key(rule, est[c["name"]][0])) /
                               best_of(c, paper_keys) for c in train)

    def best_rule(train):
        rule = {}
        for cls in ("low", "mid", "high", "impulsive"):
            members = [c for c in train if level_class(*est[c["name"]]) == cls]
            if not members:  # no training case of this class: the nearest class's choice
                members = [c for c in train if level_class(*est[c["name"]]) ==
                           {"low": "mid", "mid": "high", "high": "mid",
                            "impulsive": "high"}[cls]]
            rule[cls] = min(best_keys, key=lambda k: statistics.mean(
                ev(c, k) / best_of(c, best_keys) for c in members))
        return rule

    rows = []
    for g in groups:
        train = [c for c in cases if c["group"] != g]
        test = [c for c in cases if c["group"] == g]
        prule = min(rules, key=lambda r: paper_loss(r, train))
        brule = best_rule(train)
        for c in test:
            n, kind = est[c["name"]]
            res = cache[c["name"]]
            pk, bk = paper_key(prule, n), brule[level_class(n, kind)]
            oracle_p = min(paper_keys, key=lambda k: ev(c, k))
            oracle_b = min(best_keys, key=lambda k: ev(c, k))
            rows.append({"case": c["name"], "group": g, "kind": c["kind"], "sigma": c["sigma"],
                         "estimate": n, "estimated_kind": kind,
                         "paper_rule": list(prule), "paper_auto": dict(res[pk], setting=pk),
                         "paper_defaults": res["(defaults)"],
                         "paper_oracle": dict(res[oracle_p], setting=oracle_p),
                         "best_auto": dict(res[bk], setting=bk),
                         "best_preset_old": res["--best"],
                         "best_auto_old": res["--best --auto"],
                         "best_oracle": dict(res[oracle_b], setting=oracle_b)})
    full_paper = min(rules, key=lambda r: paper_loss(r, cases))
    full_best = best_rule(cases)
    out = {"level_bounds": LEVEL_BOUNDS, "paper_rule_all": list(full_paper),
           "best_rule_all": full_best, "rows": rows}
    with open(args.out, "w") as f:
        json.dump(out, f, indent=1)
    for r in rows:
        print("%-22s est %.3f %-9s paper auto/oracle %.3f  defaults/oracle %.3f  best auto %.3f "
              "(%s) oracle %.3f old-auto %.3f" % (
                  r["case"], r["estimate"], r["estimated_kind"],
                  r["paper_auto"]["ev"] / r["paper_oracle"]["ev"],
                  r["paper_defaults"]["ev"] / r["paper_oracle"]["ev"], r["best_auto"]["ev"],
                  r["best_auto"]["setting"][-40:], r["best_oracle"]["ev"],
                  r["best_auto_old"]["ev"]))
    print("rule fitted on all groups: paper", full_paper, "best", full_best)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("command", choices=["run", "fit"])
    ap.add_argument("--cases", required=True)
    ap.add_argument("--rsmooth", default="build/rsmooth")
    ap.add_argument("--cache", default="/tmp/rsmooth-calibration-cache.json")
    ap.add_argument("--only", choices=["paper", "best"], default=None)
    ap.add_argument("--out", default="docs/results/calibration.json")
    args = ap.parse_args()
    cases = json.load(open(args.cases))["cases"]
    (cmd_run if args.command == "run" else cmd_fit)(args, cases)


if __name__ == "__main__":
    main()
