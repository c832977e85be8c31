"""The best mode's stage as cycles (issue 25): every candidate setting of the normal update stage on
every case of scripts/make_cases.py, the rule that picks one per estimated noise class chosen by
cross-validation that leaves whole meshes out, and the bounds of the choice per region fitted the
same way.

    python3 scripts/calibrate_stage.py run   --cases /work/cases/manifest.json
    python3 scripts/calibrate_stage.py fit   --cases /work/cases/manifest.json \
        --out docs/results/calibration_stage.json
    python3 scripts/region_study.py --cases /work/cases/manifest.json   (the bounds per fold)
    python3 scripts/calibrate_stage.py final --cases /work/cases/manifest.json \
        --final docs/results/final_stage.json

A candidate is one cycle schedule (cycles x vertex updates, one guided round per cycle as the
guided filter's authors run it), a neighbourhood radius and a guidance width sigma_n; the spatial
width is 1 mean edge length. Each runs as `--best --auto` with the stage spelled out (options given
win over --auto's), so what is measured includes the choice per region that follows the stage at
the estimated noise, with the library's bounds (region_study.py fits those afterwards). Whether one robust pass follows is measured for the settings some
fold would choose, and then chosen the same way. `run` measures each (case,
candidate) with the command (`--best --auto` with the stage spelled out) and caches E_v, theta and the wall time in --cache (JSON; reruns skip what
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
import statistics
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import calibrate  # noqa: E402  (its run, estimate and load)
from calibrate import load  # noqa: E402

# (cycles, vertex updates per cycle): from a few long cycles to the authors' many short ones
SCHEDULES = [(2, 10), (3, 10), (5, 10), (10, 10), (20, 10), (40, 5), (100, 2)]
RADII = [2, 3]
SIGMA_N = [0.2, 0.35, 0.5]
LONG = [(300, 1, 3, 0.2)]  # the authors' schedule for impulsive noise (cycles, k, radius, sigma_n)
SIGMA_S = 1.0
LEVEL_BOUNDS = [0.25, 0.45]


def stage_opts(cycles, updates, radius, sigma_n, passes=0, sigma_s=SIGMA_S):
    return ["--best", "--passes", str(passes), "--guided-rounds", "1",
            "--stage-repeats", str(cycles), "--vertex-updates", str(updates),
            "--guided-radius", "%g" % radius, "--guided-sigma-n", "%g" % sigma_n,
            "--guided-sigma-s", "%g" % sigma_s]


def candidates(blend=True):
    """Every candidate; with `blend`, run as `--best --auto` runs it (the choice per region at
    the estimated noise after the stage: the rule is chosen on what users get)."""
    out = [stage_opts(c, k, r, n) for (c, k) in SCHEDULES for r in RADII for n in SIGMA_N]
    out += [stage_opts(c, k, r, n) for (c, k, r, n) in LONG]
    return [o + ["--auto"] for o in out] if blend else out


def with_pass(opts):
    o = list(opts)
    o[o.index("--passes") + 1] = "1"
    return o


def key(opts):
    return " ".join(opts)


def run_one(rsmooth, case, opts):
    """calibrate.py's run, in a folder of its own (two run at a time)."""
    with tempfile.TemporaryDirectory() as tmp:
        return calibrate.run_one(rsmooth, case, opts, tmp)


def estimate(rsmooth, case):
    """rsmooth's noise estimate of a case and its kind, as --auto prints them."""
    with tempfile.TemporaryDirectory() as tmp:
        return calibrate.estimate(rsmooth, case, tmp)


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
                         "oracle_ev": cache[c["name"]][oracle]["ev"],
                         "oracle_theta": min(cache[c["name"]][q].get("theta", float("inf"))
                                             for q in keys)})
    rule_all = choose(cache, cases, est, keys)
    robust = {}
    if args.robustness:  # the shipped settings' widths 5% up and down, on their classes' cases
        shipped = sorted(set(rule_all.values()))
        nudges = [nudged(k.split(), f) for k in shipped for f in (0.95, 1.05)]
        cache = measure(args, cases, nudges)
        for k in shipped:
            members = [c for c in cases if rule_all[level_class(*est[c["name"]])] == k]
            ratios = {("%.2f" % f): [cache[c["name"]][key(nudged(k.split(), f))]["ev"] /
                                     cache[c["name"]][k]["ev"] for c in members]
                      for f in (0.95, 1.05)}
            robust[k] = {f: {"worst": max(v), "median": statistics.median(v)}
                         for f, v in ratios.items()}
    out = {"level_bounds": LEVEL_BOUNDS, "rule_all": rule_all, "rows": rows,
           "robustness": robust}
    with open(args.out, "w") as f:
        json.dump(out, f, indent=1)
    for r in rows:
        print("%-22s %-9s est %.3f  E_v %.3f (oracle %.3f)  %s" % (
            r["case"], r["class"], r["estimate"], r["ev"], r["oracle_ev"], r["setting"][40:]))
    print("rule fitted on all groups:", json.dumps(rule_all, indent=1))
    print("robustness (E_v ratio at widths x0.95 / x1.05 over the cases it was chosen for):")
    for k, v in robust.items():
        print("  %s: %s" % (k[40:], v))


def adjacent_ratio(path):
    """The mean distance between the centroids of triangles sharing an edge over the mean edge
    length (each unique edge once): the guided filter's authors give sigma_s in the former."""
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import numpy as np
    from obj_mesh import read_obj
    v, f = read_obj(path)
    c = v[f].mean(axis=1)
    e = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    owner = np.tile(np.arange(len(f)), 3)
    order = np.lexsort((e[:, 1], e[:, 0]))
    e, owner = e[order], owner[order]
    same = np.all(e[1:] == e[:-1], axis=1)
    pairs = np.flatnonzero(same)
    adjacent = np.linalg.norm(c[owner[pairs]] - c[owner[pairs + 1]], axis=1).mean()
    unique = e[np.r_[True, ~same]]
    return adjacent / np.linalg.norm(v[unique[:, 0]] - v[unique[:, 1]], axis=1).mean()


def gmnf_defaults(case):
    """The guided filter's authors' program at its defaults (GuidedDenoising, local scheme: 20
    cycles of one guided step and 10 vertex updates, radius 2 and sigma_s 1 in mean
    adjacent-centroid distances, sigma_r 0.35), as rsmooth's stage spells it. Their program
    re-measures sigma_s on the current mesh each cycle; rsmooth keeps the input's."""
    return stage_opts(20, 10, 2, 0.35, sigma_s=float("%.4g" % adjacent_ratio(case["noisy"]))) + [
        "--no-guard"]  # their program has no fold guard


def run_report(rsmooth, case, opts, out):
    """E_v, theta, the filter's ms (--json) and the choice per region's figures."""
    p = subprocess.run([rsmooth, case["noisy"], "-o", out, "-f", "--json"] + opts,
                       capture_output=True, text=True, check=True)
    report = json.loads(p.stdout.strip().splitlines()[-1])
    m = json.loads(subprocess.run([rsmooth, "compare", out, case["truth"], "--json"],
                                  capture_output=True, text=True, check=True).stdout)
    region = report.get("region_choice", {})
    return {"ev": m["ev"], "theta": m["theta"], "ms_filter": report["ms"]["filter"],
            "taubin_iterations": region.get("taubin_iterations", 0),
            "filter_share": region.get("filter_share", 1.0)}


def geometry_checks(case, out_path, level):
    """Triangles facing away from the truth's (normals more than 90 degrees apart) in the result
    and in the input, and the largest move of a boundary vertex over the noise level in its own
    edge lengths (region_study.py's measure; at most 1 means within the level)."""
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import numpy as np
    import region_study
    from obj_mesh import read_obj
    x_in, faces = read_obj(case["noisy"])
    x_out, x_truth = read_obj(out_path)[0], read_obj(case["truth"])[0]

    def normals(x):
        return np.cross(x[faces[:, 1]] - x[faces[:, 0]], x[faces[:, 2]] - x[faces[:, 0]])

    truth_n = normals(x_truth)
    flipped = int(np.sum(np.sum(normals(x_out) * truth_n, axis=1) < 0))
    flipped_in = int(np.sum(np.sum(normals(x_in) * truth_n, axis=1) < 0))
    rep, tri, _, boundary = region_study.vertex_shares(x_in, faces)
    edge = region_study.local_edges(x_in, rep, tri)[rep]
    move = np.linalg.norm(x_out - x_in, axis=1)
    b = boundary[rep] & (edge > 0)
    worst = float(np.max(move[b] / (level * edge[b]))) if b.any() and level > 0 else 0.0
    return {"flipped": flipped, "flipped_input": flipped_in, "boundary_vertices": int(b.sum()),
            "boundary_move_over_level": worst}


def cmd_final(args, cases):
    """Per case: the best mode as its fold chose it (the fold's stage setting, then the choice
    per region at the fold's bounds, by region_study.py's blend, which equals the library's),
    `--best --auto` as users run it (the rule fitted on all groups, compiled in), the guided
    filter's authors' defaults and the paper's defaults (for the time ratio)."""
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import region_study
    from obj_mesh import write_obj
    stage = {r["case"]: r for r in json.load(open(args.out))["rows"]}
    region = {r["case"]: r for r in json.load(open(args.region))["rows"]}
    out = load(args.final)
    with tempfile.TemporaryDirectory() as tmp:
        for c in cases:
            if c["name"] in out:
                continue
            setting = stage[c["name"]]["setting"].split()
            x_in, f_xyz, t_xyz, faces, level, iterations = region_study.case_inputs(
                args.rsmooth, c, setting, tmp)
            lo, hi, spread = region[c["name"]]["bounds"].split()
            mine, share = region_study.blend(x_in, f_xyz, t_xyz, faces, level, float(lo),
                                             float(hi), int(spread))
            path = os.path.join(tmp, "fold.obj")
            write_obj(path, mine, faces)
            m = region_study.compare(args.rsmooth, path, c["truth"])
            path = os.path.join(tmp, "run.obj")
            res = {"fold": {"ev": m["ev"], "theta": m["theta"], "filter_share": share,
                            "setting": " ".join(setting), "bounds": region[c["name"]]["bounds"]},
                   "best_auto": run_report(args.rsmooth, c, ["--best", "--auto"], path),
                   "checks": geometry_checks(c, path, level),
                   "gmnf_defaults": run_report(args.rsmooth, c, gmnf_defaults(c), path),
                   "paper_defaults": run_report(args.rsmooth, c, [], path),
                   "estimate": stage[c["name"]]["estimate"],
                   "estimated_kind": stage[c["name"]]["estimated_kind"],
                   "lattice_oracle": {"ev": stage[c["name"]]["oracle_ev"],
                                      "theta": stage[c["name"]]["oracle_theta"],
                                      "setting": stage[c["name"]]["oracle"]}}
            out[c["name"]] = res
            with open(args.final, "w") as f:
                json.dump(out, f, indent=1)
            print("%-22s fold %.3f/%.2f  --best --auto %.3f/%.2f (%.0f ms)  GMNF defaults "
                  "%.3f/%.2f  paper defaults %.3f (%.0f ms)" % (
                      c["name"], res["fold"]["ev"], res["fold"]["theta"],
                      res["best_auto"]["ev"], res["best_auto"]["theta"],
                      res["best_auto"]["ms_filter"], res["gmnf_defaults"]["ev"],
                      res["gmnf_defaults"]["theta"], res["paper_defaults"]["ev"],
                      res["paper_defaults"]["ms_filter"]), flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("command", choices=["run", "fit", "final"])
    ap.add_argument("--cases", required=True)
    ap.add_argument("--rsmooth", default="build/rsmooth")
    ap.add_argument("--cache", default="/tmp/rsmooth-stage-cache.json")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--robustness", action="store_true",
                    help="fit: also every chosen setting with its widths 5%% up and down")
    ap.add_argument("--only", default="", help="comma-separated case names (default: all)")
    ap.add_argument("--out", default="docs/results/calibration_stage.json")
    ap.add_argument("--region", default="docs/results/region_study.json")
    ap.add_argument("--final", default="docs/results/final_stage.json")
    args = ap.parse_args()
    cases = json.load(open(args.cases))["cases"]
    if args.only:
        cases = [c for c in cases if c["name"] in args.only.split(",")]
    {"run": cmd_run, "fit": cmd_fit, "final": cmd_final}[args.command](args, cases)


if __name__ == "__main__":
    main()
