"""The best mode's stage as cycles (issue 25): every candidate setting of the normal update stage on
every case of scripts/make_cases.py, the rule that picks one per estimated noise class chosen by
cross-validation that leaves whole meshes out, and the bounds of the choice per region fitted the
same way.

    python3 scripts/calibrate_stage.py run   --cases /work/cases/manifest.json
    python3 scripts/calibrate_stage.py fit   --cases /work/cases/manifest.json \
        --out docs/results/calibration_stage.json

A candidate is one cycle schedule (cycles x vertex updates, one guided round per cycle as the
guided filter's authors run it), a neighbourhood radius and a guidance width sigma_n; the spatial
width is 1 mean edge length. Whether one robust pass follows is measured for the settings some
fold would choose, and then chosen the same way. `run` measures each (case,
candidate) with the command (the stage's result, no choice per region: `--best` with the stage
spelled out, no --auto) and caches E_v, theta and the wall time in --cache (JSON; reruns skip what
is there). Two commands run at a time (--jobs).

`fit`, for each group of cases (one underlying model): the rule is chosen on the other groups
only (per class of rsmooth's own noise estimate: low < 0.25 <= mid < 0.45 <= high, impulsive;
the candidate with the lowest mean ratio of E_v to each training case's best candidate) and
applied to the left-out group. The figures it reports for a case come from a rule that never saw
that mesh. It also reports each chosen setting's robustness: E_v with every width (sigma_s,
sigma_n, radius) 5% up and 5% down, on the training cases.

The classes' bounds are fixed in advance, not fitted."""
import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor

# (cycles, vertex updates per cycle): from a few long cycles to the authors' many short ones
SCHEDULES = [(5, 10), (10, 10), (20, 10), (40, 5), (100, 2)]
RADII = [2, 3]
SIGMA_N = [0.2, 0.35]
LONG = [(300, 1, 3, 0.2)]  # the authors' schedule for impulsive noise (cycles, k, radius, sigma_n)
SIGMA_S = 1.0
LEVEL_BOUNDS = [0.25, 0.45]


def stage_opts(cycles, updates, radius, sigma_n, passes=0, sigma_s=SIGMA_S):
    return ["--best", "--passes", str(passes), "--guided-rounds", "1",
            "--stage-repeats", str(cycles), "--vertex-updates", str(updates),
            "--guided-radius", "%g" % radius, "--guided-sigma-n", "%g" % sigma_n,
            "--guided-sigma-s", "%g" % sigma_s]


def candidates():
    out = [stage_opts(c, k, r, n) for (c, k) in SCHEDULES for r in RADII for n in SIGMA_N]
    out += [stage_opts(c, k, r, n) for (c, k, r, n) in LONG]
    return out


def with_pass(opts):
    o = list(opts)
    o[o.index("--passes") + 1] = "1"
    return o


def key(opts):
    return " ".join(opts)


def run_one(rsmooth, case, opts):
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "out.obj")
        t0 = time.perf_counter()
        p = subprocess.run([rsmooth, case["noisy"], "-o", out, "-f", "-q"] + opts,
                           capture_output=True, text=True)
        wall = time.perf_counter() - t0
        if p.returncode != 0:
            return {"error": p.stderr.strip()[-300:]}
        c = subprocess.run([rsmooth, "compare", out, case["truth"], "--json"],
                           capture_output=True, text=True, check=True)
        m = json.loads(c.stdout)
        return {"ev": m["ev"], "theta": m["theta"], "s": round(wall, 3)}


def estimate(rsmooth, case):
    """rsmooth's noise estimate of a case and its kind, as --auto prints them."""
    with tempfile.TemporaryDirectory() as tmp:
        p = subprocess.run([rsmooth, case["noisy"], "-o", os.path.join(tmp, "e.obj"), "-f",
                            "--auto"], capture_output=True, text=True)
    m = re.search(r"noise estimate ([0-9.eE+-]+)", p.stderr)
    if not m:
        sys.exit("calibrate_stage.py: no estimate for %s: %s" % (case["name"], p.stderr))
    return float(m.group(1)), "impulsive" if "impulsive" in p.stderr else "gaussian"


def load(path):
    return json.load(open(path)) if os.path.exists(path) else {}


def measure(args, cases, settings):
    """Fills the cache with every (case, setting) not in it, --jobs at a time."""
    cache = load(args.cache)
    todo = [(c, o) for o in settings for c in cases if key(o) not in cache.get(c["name"], {})]

    def one(job):
        c, o = job
        return c["name"], key(o), run_one(args.rsmooth, c, o)

    done = 0
    with ThreadPoolExecutor(args.jobs) as ex:
        for name, k, r in ex.map(one, todo):
            cache.setdefault(name, {})[k] = r
            done += 1
            if done % 10 == 0 or done == len(todo):
                with open(args.cache + ".tmp", "w") as f:
                    json.dump(cache, f)
                os.replace(args.cache + ".tmp", args.cache)
                print("%d of %d runs" % (done, len(todo)), flush=True)
    return cache


def level_class(level, kind):
    if kind == "impulsive":
        return "impulsive"
    return "low" if level < LEVEL_BOUNDS[0] else "mid" if level < LEVEL_BOUNDS[1] else "high"


def choose(cache, train, est, keys):
    """Per class, the candidate with the lowest mean E_v ratio to each case's best candidate."""
    def ev(c, k):
        return cache[c["name"]].get(k, {}).get("ev", float("inf"))
    rule = {}
    for cls in ("low", "mid", "high", "impulsive"):
        members = [c for c in train if level_class(*est[c["name"]]) == cls]
        if not members:  # no training case of this class: the nearest class's cases
            near = {"low": "mid", "mid": "high", "high": "mid", "impulsive": "high"}[cls]
            members = [c for c in train if level_class(*est[c["name"]]) == near]
        rule[cls] = min(keys, key=lambda k: statistics.mean(
            ev(c, k) / min(ev(c, q) for q in keys) for c in members))
    return rule


def nudged(opts, factor):
    """The setting with every width (sigma_s, sigma_n, radius) times factor."""
    o = list(opts)
    for flag in ("--guided-sigma-s", "--guided-sigma-n", "--guided-radius"):
        i = o.index(flag) + 1
        o[i] = "%.4g" % (float(o[i]) * factor)
    return o


def cmd_run(args, cases):
    measure(args, cases, candidates())


def cmd_fit(args, cases):
    cache = measure(args, cases, candidates())
    keys = [key(o) for o in candidates()]
    est = {c["name"]: estimate(args.rsmooth, c) for c in cases}
    groups = sorted({c["group"] for c in cases})
    folds = {g: [c for c in cases if c["group"] != g] for g in groups}
    # whether one robust pass follows: measured for every setting a fold (or all) would choose,
    # then part of the choice
    first = {k for train in list(folds.values()) + [cases]
             for k in choose(cache, train, est, keys).values()}
    passes = [with_pass(k.split()) for k in sorted(first)]
    cache = measure(args, cases, passes)
    keys += [key(o) for o in passes]
    rows, chosen = [], set()
    for g in groups:
        train = folds[g]
        rule = choose(cache, train, est, keys)
        for c in (c for c in cases if c["group"] == g):
            n, kind = est[c["name"]]
            k = rule[level_class(n, kind)]
            chosen.add(k)
            oracle = min(keys, key=lambda q: cache[c["name"]][q].get("ev", float("inf")))
            rows.append({"case": c["name"], "group": g, "estimate": n, "estimated_kind": kind,
                         "class": level_class(n, kind), "setting": k,
                         "ev": cache[c["name"]][k]["ev"], "theta": cache[c["name"]][k]["theta"],
                         "s": cache[c["name"]][k]["s"], "oracle": oracle,
                         "oracle_ev": cache[c["name"]][oracle]["ev"]})
    rule_all = choose(cache, cases, est, keys)
    # robustness of each setting any fold chose: every width 5% up and down, on all cases
    nudges = [nudged(k.split(), f) for k in sorted(chosen) for f in (0.95, 1.05)]
    cache = measure(args, cases, nudges)
    robust = {}
    for k in sorted(chosen):
        members = [c for c in cases if any(r["setting"] == k and r["case"] == c["name"]
                                           for r in rows)]
        base = [cache[c["name"]][k]["ev"] for c in members]
        robust[k] = {("%.2f" % f): max(cache[c["name"]][key(nudged(k.split(), f))]["ev"] / b
                                       for c, b in zip(members, base))
                     for f in (0.95, 1.05)}
    out = {"level_bounds": LEVEL_BOUNDS, "rule_all": rule_all, "rows": rows,
           "robustness_worst_ratio": robust}
    with open(args.out, "w") as f:
        json.dump(out, f, indent=1)
    for r in rows:
        print("%-22s %-9s est %.3f  E_v %.3f (oracle %.3f)  %s" % (
            r["case"], r["class"], r["estimate"], r["ev"], r["oracle_ev"], r["setting"][40:]))
    print("rule fitted on all groups:", json.dumps(rule_all, indent=1))
    print("robustness (worst E_v ratio at widths x0.95 / x1.05 over the cases it was chosen for):")
    for k, v in robust.items():
        print("  %s: %s" % (k[40:], v))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("command", choices=["run", "fit"])
    ap.add_argument("--cases", required=True)
    ap.add_argument("--rsmooth", default="build/rsmooth")
    ap.add_argument("--cache", default="/tmp/rsmooth-stage-cache.json")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--only", default="", help="comma-separated case names (default: all)")
    ap.add_argument("--out", default="docs/results/calibration_stage.json")
    args = ap.parse_args()
    cases = json.load(open(args.cases))["cases"]
    if args.only:
        cases = [c for c in cases if c["name"] in args.only.split(",")]
    {"run": cmd_run, "fit": cmd_fit}[args.command](args, cases)


if __name__ == "__main__":
    main()
