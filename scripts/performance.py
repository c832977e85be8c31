#!/usr/bin/env python3
"""Speed figures for docs/performance.md, regenerated, never typed.

Runs build/rsmooth-bench and build/rsmooth on this machine and writes
  docs/results/performance/*.json   each benchmark's JSON, as printed
  docs/performance.md                the text and tables between its "performance" markers
                                     (never README.md)

    python3 scripts/performance.py [--build build] [--before OLD_BUILD [--before-label T]] [--quick]
    python3 scripts/performance.py --render [--before-label T] [--machine TEXT]

--quick skips the 4M and 16M runs (minutes, several GiB of memory). --before runs the headline
cases (Bunny, 200k, the command's setup, Fandisk end to end, --best against the paper filter)
on an older build too, alternating with this one, and quotes its figures as "before"; T names it
in the text (e.g. "commit 445f166"; default: its path). --render runs nothing: it rewrites the
section from the JSON already in docs/results/performance/ (the machine and the before label come
from after-headline.json, or from --machine and --before-label where an older run did not record
them; "before" figures are quoted only with a label). Needs only the standard library. Run it on a
quiet machine: every figure is a median, but the ratios that matter (useful pairs/s against the
native roofline, per-triangle time across sizes, tiled against untiled) are each measured within
one run or back to back.
"""
import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED = os.path.join(os.path.dirname(ROOT), "shared", "data", "benchmark")
OUT = os.path.join(ROOT, "docs", "results", "performance")
PAGE = os.path.join(ROOT, "docs", "performance.md")
BEGIN, END = "<!-- BEGIN performance", "<!-- END performance -->"
# The JSON files of one run (docs/results/performance/NAME.json), by the key the text uses.
RUN_FILES = {"cold": "program-build-cold", "s1M": "scaling-1M", "s4M": "scaling-4M",
             "s16M": "scaling-16M", "tiled": "scaling-16M-256M"}
HEADLINE_FILES = {"bunny": "bunny0.2-2-0.5", "g200k": "generated-200k-4-1",
                  "best_bunny": "best-bunny0.2", "best_auto_bunny": "best-auto-bunny0.2",
                  "best_200k": "best-200k", "points_200k": "points-200k"}
# The speed targets set for this machine class (PoCL's CPU device): (key, what, target, at most?)
TARGETS = [("g200k", "paper filter, 200k triangles at σ 4/1", 70, True),
           ("bunny", "paper filter, Bunny0.2 at σ 2/0.5", 18, True),
           ("setup", "command setup, warm caches (Fandisk0.3)", 35, True),
           ("ratio", "useful-pair ratio, robust pass (200k)", 0.5, False),
           ("best", "`--best` on Bunny0.2, × the paper filter", 3, True),
           ("best_auto", "`--best --auto` on Bunny0.2, × the paper filter", 3, True),
           ("best_device", "`--best` on Bunny0.2, stage on the device, × paper", 3, True),
           ("best_200k", "`--best` on 200k triangles, × the paper filter", 3, True),
           ("points", "200k-point cloud on the device, × the mesh filter", 2, True)]


def beside(result):
    """The result with the data's paths written as from the checkout (../shared/data/...), not as
    this machine's absolute paths."""
    parent = os.path.dirname(ROOT) + os.sep
    for key in ("mesh", "command"):
        if isinstance(result.get(key), str):
            result[key] = result[key].replace(parent, ".." + os.sep)
    return result


def bench(build, name, args, env=None):
    cmd = [os.path.join(build, "rsmooth-bench"), "filter"] + args
    print("running:", " ".join(cmd), file=sys.stderr)
    run_env = dict(os.environ, **(env or {}))
    out = subprocess.run(cmd, check=True, capture_output=True, text=True, env=run_env).stdout
    result = json.loads(out)
    result["command"] = "rsmooth-bench filter " + " ".join(args)
    beside(result)
    with open(os.path.join(OUT, name + ".json"), "w") as f:
        json.dump(result, f, indent=1)
    return result


def command_wall_ms(build, mesh, runs=7):
    """Median wall time of the whole command, process start to output written."""
    times = []
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(runs):
            t0 = time.perf_counter()
            subprocess.run([os.path.join(build, "rsmooth"), mesh, "-o",
                            os.path.join(tmp, "out.obj"), "-f", "-q"], check=True)
            times.append((time.perf_counter() - t0) * 1e3)
    return statistics.median(times), times


def command_json_ms(build, mesh, extra, runs=7):
    """Medians of the command's own --json stage times (setup, filter, ...) over `runs` runs."""
    stages = {}
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(runs):
            out = subprocess.run([os.path.join(build, "rsmooth"), mesh, "-o",
                                  os.path.join(tmp, "out.obj"), "-f", "--json"] + extra,
                                 check=True, capture_output=True, text=True).stdout
            for k, v in json.loads(out)["ms"].items():
                stages.setdefault(k, []).append(v)
    return {k: statistics.median(v) for k, v in stages.items()}


def has_mode(build, mode):
    """Whether this build's rsmooth-bench has `mode` (older builds lack "best")."""
    r = subprocess.run([os.path.join(build, "rsmooth-bench"), mode, "--help"],
                       capture_output=True, text=True)
    return r.returncode == 0


def best_bench(build, name, args, mode="best"):
    """rsmooth-bench best (the best mode against the paper filter, its stage on the host and on
    the device, in one run) or points (a 200k-point cloud against the mesh filter)."""
    cmd = [os.path.join(build, "rsmooth-bench"), mode] + args
    print("running:", " ".join(cmd), file=sys.stderr)
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    result = json.loads(out)
    result["command"] = f"rsmooth-bench {mode} " + " ".join(args)
    beside(result)
    with open(os.path.join(OUT, name + ".json"), "w") as f:
        json.dump(result, f, indent=1)
    return result


def headline(build, tag):
    """The headline figures for one build (each a median, on this machine)."""
    out = {}
    bunny = os.path.join(SHARED, "Bunny0.2", "Noisy.obj")
    fandisk = os.path.join(SHARED, "Fandisk0.3", "Noisy.obj")
    if os.path.exists(bunny):
        out["bunny"] = bench(build, f"{tag}-{HEADLINE_FILES['bunny']}",
                             [bunny, "--repeat", "9"])
    out["g200k"] = bench(build, f"{tag}-{HEADLINE_FILES['g200k']}",
                         ["--triangles", "200000", "--sigma-f", "4", "--sigma-g", "1",
                          "--repeat", "9"])
    if os.path.exists(fandisk):
        out["setup"] = command_json_ms(build, fandisk, [])["setup"]
        out["fandisk_ms"] = command_wall_ms(build, fandisk)[0]
    if os.path.exists(bunny):
        out["paper_filter"] = command_json_ms(build, bunny, [], runs=5)["filter"]
        out["best_filter"] = command_json_ms(build, bunny, ["--best"], runs=3)["filter"]
        out["best_auto_filter"] = command_json_ms(build, bunny, ["--best", "--auto"],
                                                  runs=3)["filter"]
    if has_mode(build, "best"):
        if os.path.exists(bunny):
            out["best_bunny"] = best_bench(build, f"{tag}-{HEADLINE_FILES['best_bunny']}",
                                           [bunny, "--repeat", "3"])
            out["best_auto_bunny"] = best_bench(
                build, f"{tag}-{HEADLINE_FILES['best_auto_bunny']}",
                [bunny, "--repeat", "3", "--auto"])
        out["best_200k"] = best_bench(build, f"{tag}-{HEADLINE_FILES['best_200k']}",
                                      ["--triangles", "200000", "--repeat", "1"])
    if has_mode(build, "points"):
        out["points_200k"] = best_bench(build, f"{tag}-{HEADLINE_FILES['points_200k']}",
                                        ["--repeat", "5"], mode="points")
    with open(os.path.join(OUT, f"{tag}-headline.json"), "w") as f:
        json.dump({k: v for k, v in out.items() if not isinstance(v, dict)}, f, indent=1)
    return out


def standing(before, after, label):
    """The paragraph on where the headline figures stand, each with its "before" figure when an
    older build was measured too."""
    b = before or {}

    def was(key, fmt, text):
        """text.format(the before figure), or "" where there is none."""
        v = b.get(key)
        return text.format(fmt.format(v)) if v is not None else ""

    g = after["g200k"]
    text = "What these figures stand at"
    if before:
        text += f", measured one after the other against {label}\n(\"before\")"
    clauses = []
    clauses.append(f" the 200k-triangle case at σ 4/1 filters in **{ms(g, 'total'):.0f} ms**" +
                   (f" ({ms(b['g200k'], 'total'):.0f} ms\nbefore)" if "g200k" in b else ""))
    robust, mollify = g["robust"].get("ratio"), g["mollify"].get("ratio")
    if robust is not None and mollify is not None:
        c = (f" its useful-pair ratio is **{robust:.2f}** for the robust pass and "
             f"**{mollify:.2f}** for mollification")
        if "g200k" in b and b["g200k"]["robust"].get("ratio") is not None:
            c += (f"\n({b['g200k']['robust']['ratio']:.2f} and "
                  f"{b['g200k']['mollify']['ratio']:.2f} before)")
        if g.get("kernel_variant", "block") == "block" and max(robust, mollify) < 0.5:
            c += (f", which whole cells and {g.get('lanes', 8)}-wide blocks bound below 0.5 on a "
                  "CPU (below)")
        clauses.append(c)
    if "bunny" in after:
        clauses.append(f"\nBunny0.2 at σ 2/0.5 filters in **{ms(after['bunny'], 'total'):.0f} ms**"
                       + (f" ({ms(b['bunny'], 'total'):.0f} ms before)" if "bunny" in b else ""))
    if "setup" in after and "fandisk_ms" in after:
        clauses.append(f" the command's setup on Fandisk0.3 with\nwarm caches takes "
                       f"**{after['setup']:.0f} ms**" + was("setup", "{:.0f}", " ({} ms before)") +
                       f" and the whole run **{after['fandisk_ms']:.0f} ms**" +
                       was("fandisk_ms", "{:.0f}", " ({} ms before)"))
    text += ":" + ";".join(clauses) + "."
    ratio = lambda r: (r["best_filter"] / r["paper_filter"]
                       if "best_filter" in r and "paper_filter" in r else None)
    if ratio(after) is not None:
        text += (f" `--best`\ntakes **{ratio(after):.0f}×** the paper filter's filter time on "
                 "Bunny0.2" + (f" ({ratio(b):.0f}× before)" if ratio(b) is not None else "") +
                 ": its normal-update stage does many times the\npaper filter's work, on the "
                 "host's cores on a CPU device ([best-mode.md](best-mode.md)).")
    return text


def target_figures(r):
    """Each target's figure from one build's headline results (None where not measured)."""
    if not r:
        return {}
    f = {}
    if "g200k" in r:
        f["g200k"] = ms(r["g200k"], "total")
        f["ratio"] = r["g200k"]["robust"].get("ratio")
    if "bunny" in r:
        f["bunny"] = ms(r["bunny"], "total")
    f["setup"] = r.get("setup")
    if "best_filter" in r and "paper_filter" in r:
        f["best"] = r["best_filter"] / r["paper_filter"]
    if "best_auto_filter" in r and "paper_filter" in r:
        f["best_auto"] = r["best_auto_filter"] / r["paper_filter"]
    if "best_bunny" in r:
        f["best_device"] = r["best_bunny"]["best_stage_device"]["ratio_to_paper"]
    if "best_200k" in r:
        f["best_200k"] = min(r["best_200k"][m]["ratio_to_paper"]
                             for m in ("best_stage_host", "best_stage_device"))
    if "points_200k" in r:
        f["points"] = r["points_200k"]["points_over_mesh"]
    return f


def targets_table(before, after):
    """Each figure beside its target, before and after."""
    b, a = target_figures(before), target_figures(after)
    fmt = lambda key, v: "–" if v is None else (f"{v:.2f}" if key == "ratio" else
                                                f"{v:.1f}×" if key.startswith("best") or
                                                key == "points" else f"{v:.0f} ms")
    lines = ["| figure | target | before | after | met |", "| --- | --- | --- | --- | --- |"]
    for key, what, target, at_most in TARGETS:
        v = a.get(key)
        met = "–" if v is None else ("yes" if (v <= target if at_most else v >= target) else
                                     "**no**")
        goal = ("≤ " if at_most else "≥ ") + fmt(key, target)
        lines.append(f"| {what} | {goal} | {fmt(key, b.get(key))} | **{fmt(key, v)}** | {met} |")
    return lines


def machine():
    model = "unknown CPU"
    with open("/proc/cpuinfo") as f:
        for line in f:
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    with open("/proc/meminfo") as f:
        mem_gib = int(f.readline().split()[1]) / 2**20
    flags = open("/proc/cpuinfo").read()
    simd = "AVX-512" if "avx512f" in flags else "AVX2" if "avx2" in flags else "SSE"
    return f"{model}, {os.cpu_count()} cores ({simd}), {mem_gib:.0f} GiB, {platform.system()}"


def ms(result, stage):
    return result["ms"][stage]["median"]


def fmt_pass(result, name):
    p = result[name]
    if p.get("useful") is None or p.get("ratio") is None:
        return "–"
    return (f"{p['useful_pairs_per_s'] / 1e9:.2f} G/s of {p['roofline_pairs_per_s'] / 1e9:.2f} "
            f"(**{p['ratio']:.2f}**), waste {p['waste']:.0%}")


def section(before, after, runs, label, machine_text):
    """The text between the markers, from the runs' JSON."""
    device = runs["g200k"]["device"]
    pocl_cpu = (" (PoCL's CPU device)" if device.startswith("Portable Computing Language") and
                runs["g200k"].get("kernel_variant", "block") == "block" else "")
    lines = [f"{BEGIN} (generated by scripts/performance.py; do not edit) -->", "",
             f"Measured on {machine_text}, through {device}{pocl_cpu}, with "
             "`python3 scripts/performance.py` (JSON in `docs/results/performance/`). Filter "
             "time excludes file I/O and the program build; every time is the median of the "
             "runs after a first one.", ""]
    g = runs["g200k"]
    lines += [f"Kernels: the {g.get('kernel_variant', 'block')} variant, "
              f"{g.get('lanes', 8)} vertices per work-item, work-groups of "
              f"{g.get('work_group', 64)} (chosen per device; see [method.md](method.md)).", ""]
    lines += [standing(before, after, label), ""]
    lines += ["Against the project's speed targets (PoCL's CPU device; `--best` ratios are filter times, "
              "the device-stage and 200k ones `rsmooth-bench best`'s whole calls):", ""]
    lines += targets_table(before, after) + [""]
    if "best_bunny" in after:
        bb = after["best_bunny"]
        lines += ["The best mode's normal-update stage on Bunny0.2, by part (`rsmooth-bench "
                  "best`, medians; the host's stage is what a CPU device runs by default):", "",
                  "| stage on | precision | lists | upload | cycles | download | stage total "
                  "| whole call | × paper | bytes to / from the device |",
                  "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
        for mode, where in (("best_stage_host", "host"), ("best_stage_device", "device"),
                            ("best_stage_device_float32", "device")):
            m = bb[mode]
            st = m["stage"]
            lines.append(f"| {where} | {st['float_bits']}-bit | {st['ms']['lists']:.0f} ms | "
                         f"{st['ms']['upload']:.0f} ms | {st['ms']['cycles']:.0f} ms | "
                         f"{st['ms']['download']:.0f} ms | {st['ms']['total']:.0f} ms | "
                         f"{m['ms_total']:.0f} ms | {m['ratio_to_paper']:.1f}× | "
                         f"{st['bytes_to_device'] / 2**20:.1f} / "
                         f"{st['bytes_from_device'] / 2**20:.1f} MiB |")
        gap = bb["device_from_host_max"]
        lines += ["", f"The device's result is within {gap['double']:.1g} (double) and "
                  f"{gap['float32']:.1g} (float32) mean edge lengths of the host's on every "
                  "vertex.", ""]
    lines += ["| case | filter total | facets + grid | mollify | robust | useful pairs/s, "
              "robust (of the native roofline: **ratio**) | mollify |",
              "| --- | --- | --- | --- | --- | --- | --- |"]
    cases = []
    if "bunny" in runs:
        cases.append(("Bunny0.2, σ 2 / 0.5", runs["bunny"]))
    cases.append(("generated 200k triangles, σ 4 / 1", runs["g200k"]))
    for name, r in cases:
        lines.append(f"| {name} | **{ms(r, 'total'):.0f} ms** | "
                     f"{ms(r, 'facets') + ms(r, 'grid'):.0f} ms | {ms(r, 'mollify'):.0f} ms | "
                     f"{ms(r, 'robust'):.0f} ms | {fmt_pass(r, 'robust')} | "
                     f"{fmt_pass(r, 'mollify')} |")
    lines += ["", "Scaling (generated closed cylinders, σ 2 / 0.5; memory is the peak resident "
              "size the filter added to the process, per triangle):", "",
              "| triangles | filter total | per triangle | vs 1M | filter memory | tiles |",
              "| --- | --- | --- | --- | --- | --- |"]
    base = ms(runs["s1M"], "total") / runs["s1M"]["triangles"]
    for key in ["s1M", "s4M", "s16M", "tiled"]:
        if key not in runs:
            continue
        r = runs[key]
        per = ms(r, "total") / r["triangles"]
        size = f"{r['triangles'] / 1e6:.0f}M" + (" (256 MB budget)" if key == "tiled" else "")
        lines.append(f"| {size} | {ms(r, 'total') / 1e3:.2f} s | {per * 1e6:.0f} ns | "
                     f"{per / base:.2f}× | {r['filter_bytes_per_triangle']:.0f} B | "
                     f"{r['tiles']} |")
    if "tiled" in runs and "s16M" in runs:
        loss = ms(runs["tiled"], "total") / ms(runs["s16M"], "total") - 1
        lines += ["", f"Tiling 16M triangles into {runs['tiled']['tiles']} tiles with a 256 MB "
                  f"budget costs **{loss:+.0%}** time against one run, and the peak memory "
                  f"falls from {runs['s16M']['peak_rss_MiB'] / 1024:.1f} to "
                  f"{runs['tiled']['peak_rss_MiB'] / 1024:.1f} GiB."]
    cold = runs["cold"]
    lines += ["", f"Program build: {cold['program_build_first_ms']:.0f} ms from source (empty "
              f"PoCL and rsmooth caches), {cold['program_build_cached_ms']:.0f} ms from rsmooth's "
              "program cache; the first launch "
              f"of the kernels adds PoCL's code generation ({cold['kernel_codegen_ms']:.0f} ms, "
              "cold cache)."]
    if "fandisk_ms" in after:
        lines.append(f"`rsmooth Fandisk0.3/Noisy.obj -o out.obj` end to end (process start to "
                     f"file written, warm cache): **{after['fandisk_ms']:.0f} ms** median of 7.")
    lines += ["", END]
    return "\n".join(lines)


def write_section(text):
    """Replaces what lies between docs/performance.md's markers."""
    page = open(PAGE).read()
    if BEGIN not in page or END not in page:
        sys.exit("performance.py: %s has no performance markers (%s ... %s)" % (PAGE, BEGIN, END))
    head, rest = page.split(BEGIN, 1)
    page = head + text + rest.split(END, 1)[1]
    with open(PAGE + ".tmp", "w") as f:
        f.write(page)
    os.replace(PAGE + ".tmp", PAGE)


def load(name):
    with open(os.path.join(OUT, name + ".json")) as f:
        return json.load(f)


def saved_headline(tag):
    """One build's headline figures as a run left them in docs/results/performance/."""
    if not os.path.exists(os.path.join(OUT, f"{tag}-headline.json")):
        return None
    out = dict(load(f"{tag}-headline"))
    for key, name in HEADLINE_FILES.items():
        if os.path.exists(os.path.join(OUT, f"{tag}-{name}.json")):
            out[key] = load(f"{tag}-{name}")
    return out


def render_saved(a):
    """--render: the section from the JSON of the last run; nothing is run."""
    after = saved_headline("after")
    if after is None:
        sys.exit("performance.py: no after-headline.json in %s; run the benchmarks first" % OUT)
    label = a.before_label or after.get("before_label")
    before = saved_headline("before") if label else None
    machine_text = a.machine or after.get("machine")
    if not machine_text:
        sys.exit("performance.py: after-headline.json does not say which machine ran it; "
                 "pass --machine")
    names = after.get("runs", list(RUN_FILES.values()))
    runs = {k: load(RUN_FILES[k]) for k in RUN_FILES
            if RUN_FILES[k] in names and os.path.exists(os.path.join(OUT, RUN_FILES[k] + ".json"))}
    for key in HEADLINE_FILES:
        if key in after:
            runs[key] = after[key]
    return section(before, after, runs, label, machine_text)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--before", help="an older build to compare the headline figures with")
    ap.add_argument("--before-label", default=None,
                    help="what the older build is, for the text (default: its path)")
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--render", action="store_true",
                    help="rewrite the section from the saved JSON; run nothing")
    ap.add_argument("--machine", help="with --render: the machine the JSON was measured on, "
                    "where after-headline.json does not record it")
    a = ap.parse_args()
    if a.render:
        text = render_saved(a)
        write_section(text)
        print(text)
        return
    os.makedirs(OUT, exist_ok=True)

    before = headline(a.before, "before") if a.before else None
    after = headline(a.build, "after")
    runs = {}
    # empty PoCL and rsmooth program caches: the cold build
    with tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as programs:
        runs["cold"] = bench(a.build, RUN_FILES["cold"],
                             ["--triangles", "2000", "--repeat", "1", "--no-pairs"],
                             env={"POCL_CACHE_DIR": cache, "RSMOOTH_CACHE_DIR": programs})
    if "bunny" in after:
        runs["bunny"] = after["bunny"]
    runs["g200k"] = after["g200k"]
    sizes = [("1M", 1000000, 5)] + ([] if a.quick else [("4M", 4000000, 3), ("16M", 16000000, 3)])
    for size, n, rep in sizes:
        runs["s" + size] = bench(a.build, RUN_FILES["s" + size],
                                 ["--triangles", str(n), "--repeat", str(rep), "--no-pairs"])
    if not a.quick:
        runs["tiled"] = bench(a.build, RUN_FILES["tiled"],
                              ["--triangles", "16000000", "--repeat", "3", "--no-pairs",
                               "--memory-budget", "256M"])
    label = (a.before_label or os.path.relpath(a.before, ROOT)) if a.before else None
    machine_text = machine()
    # what --render needs to write the same text again
    record = {k: v for k, v in after.items() if not isinstance(v, dict)}
    record.update(machine=machine_text, before_label=label,
                  runs=[RUN_FILES[k] for k in RUN_FILES if k in runs])
    with open(os.path.join(OUT, "after-headline.json"), "w") as f:
        json.dump(record, f, indent=1)
    text = section(before, after, runs, label, machine_text)
    write_section(text)
    print(text)


if __name__ == "__main__":
    main()
