"""Experiment 6 of scripts/experiments.py: rsmooth beyond the paper. The best mode
(bilateral normals, several passes, a choice of influence function) tuned per model against the
ground truth, compared with the anchors (tuned Open3D Taubin and MeshLab TwoStep
smoothing), the preset `--best`, `--best --auto` (no tuning: sigmas from the estimated noise), the
influence functions and confidence-driven passes, and the time of the best mode against the
paper's filter on the same device."""
import os
import statistics
import sys

# The anchors, as the request for this work gave them (E_v, theta): best results of Open3D's
# Taubin smoothing and of MeshLab's TwoStep smoothing tuned per model, on the same files. They were measured outside
# this project (neither tool is a Debian package here); the numbers are that request's.
ANCHORS = {
    "Open3D Taubin": {"Fandisk0.3": (1.69, 10.0), "Block0.4": (2.27, 11.7),
                      "Bunny0.2": (0.486, 5.7), "SharpSphere0.3": (1.67, 10.6),
                      "Twelve0.5Impulsive": (2.22, 8.9)},
    "MeshLab TwoStep": {"Fandisk0.3": (1.50, 5.4), "Block0.4": (1.49, 5.4),
                        "Bunny0.2": (0.50, 5.8), "SharpSphere0.3": (2.59, 8.9),
                        "Twelve0.5Impulsive": (1.76, 3.4)},
}

# The preset `--best` (lib/core/params.c rsmooth_params_init_best), two other starting points (gentler
# normals for smooth shapes, stronger for CAD shapes and impulsive noise) and the lattice the
# per-model descent moves on, one option at a time from the best of the three.
PRESET = {"--sigma-f": 0.8, "--sigma-g": 0.3, "--normal-sigma-n": 0.45, "--normal-sigma-s": 1,
          "--normal-iterations": 5, "--passes": 3, "--influence": "gaussian"}
STARTS = [PRESET,
          dict(PRESET, **{"--normal-sigma-n": 0.6, "--normal-iterations": 3, "--passes": 2}),
          dict(PRESET, **{"--sigma-g": 0.15, "--normal-sigma-n": 0.3, "--normal-iterations": 10,
                          "--passes": 6, "--influence": "huber"})]
STEPS = {"--normal-sigma-n": [0.15, 0.2, 0.25, 0.3, 0.35, 0.45, 0.6],
         "--sigma-g": [0.15, 0.2, 0.3, 0.4, 0.5, 0.7, 1.0],
         "--passes": [1, 2, 3, 4, 6, 8],
         "--sigma-f": [0.6, 0.8, 1, 1.3, 1.6, 2, 2.5],
         "--normal-iterations": [2, 3, 5, 8, 12, 20],
         "--normal-sigma-s": [0.5, 0.7, 1, 1.5, 2],
         "--influence": ["gaussian", "tukey", "lorentzian", "huber"]}
DESCENT_ROUNDS = 3
INFLUENCES = ["gaussian", "tukey", "lorentzian", "huber"]
INFLUENCE_SIGMA_G = [0.1, 0.15, 0.2, 0.3, 0.4, 0.5, 0.7, 1.0, 1.5]
PASS_CONFIDENCE = [0.5, 0.7, 0.9]
TIMING_RUNS = 7


def steps_text():
    return "; ".join("%s {%s}" % (k, ", ".join(map(str, v))) for k, v in STEPS.items())


def options_of(cfg):
    out = ["--best"]
    for k, v in cfg.items():
        out += [k, v]
    return out


def anchor_score(model, errors):
    """Largest ratio of an error to the better anchor's: below 1 beats every anchor on both."""
    ev = min(a[model][0] for a in ANCHORS.values())
    theta = min(a[model][1] for a in ANCHORS.values())
    return max(errors["ev"] / ev, errors["theta"] / theta)


def descend(runner, jobs, sweep, noisy, truth, start, score):
    """Coordinate descent over STEPS from `start`: each round tries every value of each option in
    turn and keeps the best by `score`; stops after a round without improvement."""
    cfg = dict(start)
    err = runner.smooth(noisy, truth, options_of(cfg))
    for _ in range(DESCENT_ROUNDS):
        improved = False
        for name, values in STEPS.items():
            trial = [dict(cfg, **{name: v}) for v in values]
            results = sweep(runner, jobs, noisy, truth, [options_of(c) for c in trial])
            k = min(range(len(results)), key=lambda n: score(results[n][1]))
            if score(results[k][1]) < score(err) - 1e-9:
                cfg, err, improved = trial[k], results[k][1], True
        if not improved:
            break
    return cfg, err


def median_ms(runner, noisy, options):
    times = []
    for _ in range(TIMING_RUNS):
        out = runner.tmp_path()
        report = runner.json_run([noisy, "-o", out, "--force", "-q", "--json"] + options)
        times.append(report["ms"]["filter"])
        os.remove(out)
    return statistics.median(times)


def run(runner, jobs, sweep, data, models):
    rows = {}
    for model in models:
        print("beyond the paper: %s" % model, file=sys.stderr)
        noisy = os.path.join(data, "benchmark", model, "Noisy.obj")
        truth = os.path.join(data, "benchmark", model, "Original.obj")
        row = {"preset": runner.smooth(noisy, truth, ["--best"])}
        row["auto"] = runner.smooth(noisy, truth, ["--best", "--auto"])
        starts = sweep(runner, jobs, noisy, truth, [options_of(c) for c in STARTS])
        k = min(range(len(STARTS)), key=lambda n: anchor_score(model, starts[n][1]))
        cfg2, err2 = descend(runner, jobs, sweep, noisy, truth, STARTS[k],
                             lambda e: anchor_score(model, e))
        row["best_anchor"] = {"options": cfg2, "errors": err2}
        k = min(range(len(STARTS)), key=lambda n: starts[n][1]["ev"])
        start = cfg2 if err2["ev"] < starts[k][1]["ev"] else STARTS[k]
        cfg, err = descend(runner, jobs, sweep, noisy, truth, start, lambda e: e["ev"])
        row["best_ev"] = {"options": cfg, "errors": err}
        row["influence"] = {}
        for fn in INFLUENCES:
            trial = [dict(cfg, **{"--influence": fn, "--sigma-g": g}) for g in INFLUENCE_SIGMA_G]
            results = sweep(runner, jobs, noisy, truth, [options_of(c) for c in trial])
            k = min(range(len(results)), key=lambda n: results[n][1]["ev"])
            row["influence"][fn] = {"sigma_g": INFLUENCE_SIGMA_G[k], "errors": results[k][1]}
        row["pass_confidence"] = {}
        for c in PASS_CONFIDENCE:
            trial = dict(cfg, **{"--passes": int(cfg["--passes"]) + 2, "--pass-confidence": c})
            row["pass_confidence"][c] = runner.smooth(noisy, truth, options_of(trial))
        row["ms_paper"] = median_ms(runner, noisy, [])
        row["ms_best"] = median_ms(runner, noisy, options_of(cfg2))
        row["ms_preset"] = median_ms(runner, noisy, ["--best"])
        rows[model] = row
        runner.save()
    return rows


# Held out from the rule's calibration: clean meshes other than the benchmark models, with the
# Gaussian noise of experiment 3 (the same files), at a low and a high level.
HELD_OUT_MESHES = ["rocker-arm", "spot", "stanford-bunny"]
HELD_OUT_NOISE = [0.2, 0.4]


def held_out(runner, jobs, sweep, data):
    """`--best --auto` against the oracle (best start, then a descent on E_v) on meshes the auto
    rule was not calibrated on. Returns {(mesh, noise): row}."""
    out = {}
    for mesh in HELD_OUT_MESHES:
        clean = os.path.join(data, "clean", mesh + ".obj")
        for level in HELD_OUT_NOISE:
            noisy = os.path.join(runner.work, "noisy", "%s-%.1f.ply" % (mesh, level))
            if not (os.path.exists(clean) and os.path.exists(noisy)):
                continue
            print("beyond the paper, held out: %s %.1f" % (mesh, level), file=sys.stderr)
            auto = runner.smooth(noisy, clean, ["--best", "--auto"])
            starts = sweep(runner, jobs, noisy, clean, [options_of(c) for c in STARTS])
            k = min(range(len(STARTS)), key=lambda n: starts[n][1]["ev"])
            cfg, err = descend(runner, jobs, sweep, noisy, clean, STARTS[k], lambda e: e["ev"])
            best = min([err, auto], key=lambda e: e["ev"])
            out["%s %.1f" % (mesh, level)] = {"auto": auto, "oracle": best,
                                              "oracle_options": cfg,
                                              "noisy": runner.compare(noisy, clean)}
        runner.save()
    return out


def held_out_table(rows, fmt):
    lines = ["| mesh, noise | noisy E_v | oracle E_v (descent on E_v) | `--best --auto` E_v (θ) | "
             "auto / oracle |", "| --- " * 5 + "|"]
    for name, r in rows.items():
        lines.append("| %s | %s | %s | %s (%s°) | %.3f |" % (
            name, fmt(r["noisy"]["ev"]), fmt(r["oracle"]["ev"], 4), fmt(r["auto"]["ev"], 4),
            fmt(r["auto"]["theta"]), r["auto"]["ev"] / r["oracle"]["ev"]))
    return "\n".join(lines)


def cfg_text(cfg):
    return ("σ_f %s, σ_g %s, bilateral σ_s %s σ_n %s × %s, %s passes, %s" % (
        cfg["--sigma-f"], cfg["--sigma-g"], cfg["--normal-sigma-s"], cfg["--normal-sigma-n"],
        cfg["--normal-iterations"], cfg["--passes"], cfg["--influence"]))


def oracle(row):
    """The lowest E_v of the best mode on a model over every run of this experiment (the descents'
    trials included, through the cache), with its settings' text."""
    runs = [(row["best_ev"]["errors"], cfg_text(row["best_ev"]["options"])),
            (row["best_anchor"]["errors"], cfg_text(row["best_anchor"]["options"])),
            (row["preset"], "`--best`"), (row["auto"], "`--best --auto`")]
    runs += [(v["errors"], "%s at σ_g %s" % (fn, v["sigma_g"])) for fn, v in
             row["influence"].items()]
    runs += [(e, "2 more passes where confidence < %s" % c) for c, e in
             row["pass_confidence"].items()]
    return min(runs, key=lambda r: r[0]["ev"])


def tables(rows, models, fmt):
    """Markdown tables: (anchors, details, influence, passes, time)."""
    names = list(ANCHORS)
    head = ("| model | rsmooth best mode E_v | θ | beats both anchors? | " +
            " | ".join("%s E_v (θ)" % n for n in names) + " | paper mode best E_v (θ) |")
    anchors = [head, "| --- " * (5 + len(names)) + "|"]
    for m in models:
        r = rows[m]
        e = r["best_anchor"]["errors"]
        beats = all(e["ev"] < a[m][0] and e["theta"] < a[m][1] for a in ANCHORS.values())
        anchors.append("| %s | **%s** | **%s°** | %s | %s | %s |" % (
            m, fmt(e["ev"], 4), fmt(e["theta"]), "yes" if beats else "**no**",
            " | ".join("%s (%s°)" % (a[m][0], a[m][1]) for a in ANCHORS.values()),
            r.get("paper", "-")))
    detail = ["| model | settings beating the anchors (descent on the worse ratio to them) | "
              "lowest E_v of the mode (oracle): settings | E_v | θ | `--best` E_v (θ) | "
              "`--best --auto` E_v (θ) | auto / oracle E_v |", "| --- " * 8 + "|"]
    for m in models:
        r = rows[m]
        best, how = oracle(r)
        detail.append("| %s | %s | %s | %s | %s° | %s (%s°) | %s (%s°) | %.3f |" % (
            m, cfg_text(r["best_anchor"]["options"]), how, fmt(best["ev"], 4),
            fmt(best["theta"]), fmt(r["preset"]["ev"], 4), fmt(r["preset"]["theta"]),
            fmt(r["auto"]["ev"], 4), fmt(r["auto"]["theta"]), r["auto"]["ev"] / best["ev"]))
    influence = ["| influence | " + " | ".join(models) + " |", "| --- " * (1 + len(models)) + "|"]
    for fn in INFLUENCES:
        influence.append("| %s | %s |" % (fn, " | ".join(
            "%s (%s°) at σ_g %s" % (fmt(rows[m]["influence"][fn]["errors"]["ev"], 4),
                                    fmt(rows[m]["influence"][fn]["errors"]["theta"]),
                                    rows[m]["influence"][fn]["sigma_g"]) for m in models)))
    passes = ["| passes | " + " | ".join(models) + " |", "| --- " * (1 + len(models)) + "|"]
    passes.append("| lowest-E_v settings | %s |" % " | ".join(
        "%s (%s°)" % (fmt(rows[m]["best_ev"]["errors"]["ev"], 4),
                      fmt(rows[m]["best_ev"]["errors"]["theta"])) for m in models))
    for c in PASS_CONFIDENCE:
        passes.append("| 2 more passes where confidence < %s | %s |" % (c, " | ".join(
            "%s (%s°)" % (fmt(rows[m]["pass_confidence"][c]["ev"], 4),
                          fmt(rows[m]["pass_confidence"][c]["theta"])) for m in models)))
    time = ["| model | paper mode, defaults (ms) | `--best` (ms) | best mode, tuned (ms) | "
            "tuned / paper |", "| --- " * 5 + "|"]
    for m in models:
        r = rows[m]
        time.append("| %s | %.0f | %.0f | %.0f | %.2f |" % (
            m, r["ms_paper"], r["ms_preset"], r["ms_best"], r["ms_best"] / r["ms_paper"]))
    preset = [rows[m]["ms_preset"] / rows[m]["ms_paper"] for m in models]
    tuned = [rows[m]["ms_best"] / rows[m]["ms_paper"] for m in models]
    time_summary = ("The accuracy is not free: version 0.5's `--best` took %.1f to %.1f times "
                    "the paper filter's time at its defaults here (the present `--best` costs "
                    "far more: [best-mode.md](best-mode.md)), and the tuned settings %.1f to %.1f "
                    "times (their bilateral rounds and passes; every pass also redoes the host "
                    "work, which dominates on meshes this small)." % (
                        min(preset), max(preset), min(tuned), max(tuned)))
    return {"anchors": "\n".join(anchors), "detail": "\n".join(detail),
            "time_summary": time_summary,
            "influence": "\n".join(influence), "passes": "\n".join(passes),
            "time": "\n".join(time)}
