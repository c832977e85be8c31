#!/usr/bin/env python3
"""Speed figures for the README's "Performance" section (issue 5), regenerated, never typed.

Runs build/rsmooth-bench and build/rsmooth on this machine and writes
  docs/results/performance/*.json   each benchmark's JSON, as printed
  README.md                          the table between the "performance" markers

    python3 scripts/performance.py [--build build] [--before OLD_BUILD [--before-label T]] [--quick]

--quick skips the 4M and 16M runs (minutes, several GiB of memory). --before runs the headline
cases (Bunny, 200k, the command's setup, Fandisk end to end, --best against the paper filter)
on an older build too, alternating with this one, for a before/after table. Needs only the standard
library. Run it on a quiet machine: every figure is a median, but the ratios that matter
(useful pairs/s against the native roofline, per-triangle time across sizes, tiled against
untiled) are each measured within one run or back to back.
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
BEGIN, END = "<!-- BEGIN performance", "<!-- END performance -->"


def bench(build, name, args, env=None):
    cmd = [os.path.join(build, "rsmooth-bench"), "filter"] + args
    print("running:", " ".join(cmd), file=sys.stderr)
    run_env = dict(os.environ, **(env or {}))
    out = subprocess.run(cmd, check=True, capture_output=True, text=True, env=run_env).stdout
    result = json.loads(out)
    result["command"] = "rsmooth-bench filter " + " ".join(args)
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


def headline(build, tag):
    """The issue-17 targets' figures for one build (each a median, on this machine)."""
    out = {}
    bunny = os.path.join(SHARED, "Bunny0.2", "Noisy.obj")
    fandisk = os.path.join(SHARED, "Fandisk0.3", "Noisy.obj")
    if os.path.exists(bunny):
        out["bunny"] = bench(build, f"{tag}-bunny0.2-2-0.5", [bunny, "--repeat", "9"])
    out["g200k"] = bench(build, f"{tag}-generated-200k-4-1",
                         ["--triangles", "200000", "--sigma-f", "4", "--sigma-g", "1",
                          "--repeat", "9"])
    if os.path.exists(fandisk):
        out["setup"] = command_json_ms(build, fandisk, [])["setup"]
        out["fandisk_ms"] = command_wall_ms(build, fandisk)[0]
    if os.path.exists(bunny):
        out["paper_filter"] = command_json_ms(build, bunny, [], runs=5)["filter"]
        out["best_filter"] = command_json_ms(build, bunny, ["--best"], runs=3)["filter"]
    with open(os.path.join(OUT, f"{tag}-headline.json"), "w") as f:
        json.dump({k: v for k, v in out.items() if not isinstance(v, dict)}, f, indent=1)
    return out


def headline_rows(before, after):
    """Rows of the before/after table: figure, before, after, target, met."""
    rows = []

    def add(name, key_fn, target, limit, unit="ms", fmt="{:.0f}"):
        b = key_fn(before) if before else None
        a = key_fn(after)
        if a is None:
            return
        cell = lambda v: "–" if v is None else fmt.format(v) + (f" {unit}" if unit else "")
        met = "yes" if (a <= limit if unit else a >= limit) else "**no**"
        rows.append(f"| {name} | {cell(b)} | **{cell(a)}** | {target} | {met} |")

    get = lambda case, f: (lambda r: f(r[case]) if case in r else None)
    add("200k at σ 4/1, filter total", get("g200k", lambda r: ms(r, "total")), "≤ 70 ms", 70)
    add("200k, useful-pair ratio (robust)", get("g200k", lambda r: r["robust"]["ratio"]),
        "≥ 0.5", 0.5, unit="", fmt="{:.2f}")
    add("200k, useful-pair ratio (mollify)", get("g200k", lambda r: r["mollify"]["ratio"]),
        "≥ 0.5", 0.5, unit="", fmt="{:.2f}")
    add("Bunny0.2 at σ 2/0.5, filter total", get("bunny", lambda r: ms(r, "total")), "≤ 18 ms",
        18)
    add("command setup (`--json` setup, warm caches), Fandisk0.3",
        lambda r: r.get("setup"), "≤ 35 ms", 35)
    add("Fandisk0.3 end to end", lambda r: r.get("fandisk_ms"), "≤ 100 ms", 100)
    ratio = lambda r: (r["best_filter"] / r["paper_filter"]) if "best_filter" in r else None
    add("`--best` / paper filter, Bunny0.2 (filter times)", ratio, "≤ 3×", 3, unit="×",
        fmt="{:.1f}")
    return rows


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


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--before", help="an older build to compare the headline figures with")
    ap.add_argument("--before-label", default=None,
                    help="what the older build is, for the table (default: its path)")
    ap.add_argument("--quick", action="store_true")
    a = ap.parse_args()
    os.makedirs(OUT, exist_ok=True)

    before = headline(a.before, "before") if a.before else None
    after = headline(a.build, "after")
    runs = {}
    # empty PoCL and rsmooth program caches: the cold build
    with tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as programs:
        runs["cold"] = bench(a.build, "program-build-cold",
                             ["--triangles", "2000", "--repeat", "1", "--no-pairs"],
                             env={"POCL_CACHE_DIR": cache, "RSMOOTH_CACHE_DIR": programs})
    if "bunny" in after:
        runs["bunny"] = after["bunny"]
    runs["g200k"] = after["g200k"]
    sizes = [("1M", 1000000, 5)] + ([] if a.quick else [("4M", 4000000, 3), ("16M", 16000000, 3)])
    for label, n, rep in sizes:
        runs["s" + label] = bench(a.build, f"scaling-{label}",
                                  ["--triangles", str(n), "--repeat", str(rep), "--no-pairs"])
    if not a.quick:
        runs["tiled"] = bench(a.build, "scaling-16M-256M",
                              ["--triangles", "16000000", "--repeat", "3", "--no-pairs",
                               "--memory-budget", "256M"])
    fandisk_ms = (after["fandisk_ms"],) if "fandisk_ms" in after else None

    device = runs["g200k"]["device"]
    lines = [f"{BEGIN} (generated by scripts/performance.py; do not edit) -->", "",
             f"Measured on {machine()}, through {device} (PoCL's CPU device), with "
             "`python3 scripts/performance.py` (JSON in `docs/results/performance/`). Filter "
             "time excludes file I/O and the program build; every time is the median of the "
             "runs after a first one.", ""]
    g = runs["g200k"]
    lines += [f"Kernels: the {g.get('kernel_variant', 'block')} variant, "
              f"{g.get('lanes', 8)} vertices per work-item, work-groups of "
              f"{g.get('work_group', 64)} (chosen per device; see How it works).", ""]
    label = a.before_label or (a.before and os.path.relpath(a.before, ROOT))
    lines += ["Issue 17's targets" + (f", before ({label}) and after, run one after the other:"
                                      if before else ":"), "",
              "| figure | before | after | target | met |", "| --- | --- | --- | --- | --- |"]
    lines += headline_rows(before, after) + [""]
    lines += ["| case | filter total | facets + grid | mollify | robust | useful pairs/s, "
              "robust (of the native roofline: **ratio**) | mollify | target |",
              "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    cases = []
    if "bunny" in runs:
        cases.append(("Bunny0.2, σ 2 / 0.5", runs["bunny"], "≤ 18 ms"))
    cases.append(("generated 200k triangles, σ 4 / 1", runs["g200k"], "≤ 70 ms, ratio ≥ 0.5"))
    for name, r, target in cases:
        lines.append(f"| {name} | **{ms(r, 'total'):.0f} ms** | "
                     f"{ms(r, 'facets') + ms(r, 'grid'):.0f} ms | {ms(r, 'mollify'):.0f} ms | "
                     f"{ms(r, 'robust'):.0f} ms | {fmt_pass(r, 'robust')} | "
                     f"{fmt_pass(r, 'mollify')} | {target} |")
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
        label = f"{r['triangles'] / 1e6:.0f}M" + (" (256 MB budget)" if key == "tiled" else "")
        lines.append(f"| {label} | {ms(r, 'total') / 1e3:.2f} s | {per * 1e6:.0f} ns | "
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
    if fandisk_ms:
        lines.append(f"`rsmooth Fandisk0.3/Noisy.obj -o out.obj` end to end (process start to "
                     f"file written, warm cache): **{fandisk_ms[0]:.0f} ms** median of 7 "
                     "(target ≤ 100 ms).")
    lines += ["", END]
    section = "\n".join(lines)

    readme = os.path.join(ROOT, "README.md")
    text = open(readme).read()
    if BEGIN in text:
        head, rest = text.split(BEGIN, 1)
        text = head + section + rest.split(END, 1)[1]
    else:
        text = text.rstrip("\n") + "\n\n" + section + "\n"
    open(readme, "w").write(text)
    print(section)


if __name__ == "__main__":
    main()
