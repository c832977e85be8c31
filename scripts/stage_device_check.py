#!/usr/bin/env python3
"""The best mode's normal-update stage on the device against the host's, on every case of a
manifest (scripts/make_cases.py's: benchmark, train and generated noisy meshes), at the schedule
--best --auto picks for each: `rsmooth CASE --best --auto --passes 0` with RSMOOTH_STAGE=host,
then =device (double where the device has it) and with RSMOOTH_STAGE_PRECISION=float. Prints and
writes (docs/results/stage_device.json) each case's largest per-vertex deviation from the host's
result, in mean edge lengths of the input, and each run's stage time from --json.

    python3 scripts/stage_device_check.py --rsmooth build/rsmooth --cases /work/cases/manifest.json

Needs numpy. The check itself is test cl_stage's; this runs it on meshes the tests do not carry.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from obj_mesh import read_obj  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RUNS = {"host": {"RSMOOTH_STAGE": "host"},
        "device": {"RSMOOTH_STAGE": "device"},
        "device_float32": {"RSMOOTH_STAGE": "device", "RSMOOTH_STAGE_PRECISION": "float"}}


def mean_edge(v, f):
    e = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    e = np.unique(np.sort(e, axis=1), axis=0)
    e = e[e[:, 0] != e[:, 1]]
    return float(np.linalg.norm(v[e[:, 0]] - v[e[:, 1]], axis=1).mean())


def run(rsmooth, noisy, out, env):
    cmd = [rsmooth, noisy, "-o", out, "-f", "--best", "--auto", "--passes", "0", "--json"]
    p = subprocess.run(cmd, capture_output=True, text=True, env=dict(os.environ, **env))
    if p.returncode != 0:
        sys.exit("stage_device_check: %s failed: %s" % (" ".join(cmd), p.stderr.strip()))
    report = json.loads(p.stdout.splitlines()[-1])
    return read_obj(out)[0], report.get("stage", {})


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rsmooth", default=os.path.join(ROOT, "build", "rsmooth"))
    ap.add_argument("--cases", required=True, help="make_cases.py's manifest.json")
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "results", "stage_device.json"))
    a = ap.parse_args()
    cases = json.load(open(a.cases))["cases"]
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for c in cases:
            v0, f = read_obj(c["noisy"])
            unit = mean_edge(v0, f)
            result, stage = {}, {}
            for name, env in RUNS.items():
                result[name], stage[name] = run(a.rsmooth, c["noisy"],
                                                os.path.join(tmp, name + ".obj"), env)
            gap = {name: float(np.linalg.norm(result[name] - result["host"], axis=1).max() / unit)
                   for name in ("device", "device_float32")}
            row = {"case": c["name"], "vertices": len(v0), "cycles": stage["host"].get("cycles"),
                   "max_deviation": gap,
                   "stage_ms": {k: s.get("ms", {}).get("total") for k, s in stage.items()},
                   "float_bits": {k: s.get("float_bits") for k, s in stage.items()}}
            rows.append(row)
            print("%-22s V=%6d cycles %4s  device double %.2e  float32 %.2e  stage ms host %.0f "
                  "device %.0f float32 %.0f" % (c["name"], len(v0), row["cycles"], gap["device"],
                                                gap["device_float32"], row["stage_ms"]["host"],
                                                row["stage_ms"]["device"],
                                                row["stage_ms"]["device_float32"]), flush=True)
    worst = {k: max(r["max_deviation"][k] for r in rows) for k in ("device", "device_float32")}
    over = {k: sum(r["max_deviation"][k] > 1e-3 for r in rows) for k in worst}
    summary = {"cases": len(rows), "worst": worst, "cases_over_1e-3": over}
    print("worst: double %.2e, float32 %.2e; cases over 1e-3: double %d, float32 %d of %d"
          % (worst["device"], worst["device_float32"], over["device"], over["device_float32"],
             len(rows)))
    with open(a.out, "w") as fh:
        json.dump({"command": "python3 scripts/stage_device_check.py --cases " + a.cases,
                   "summary": summary, "cases": rows}, fh, indent=1)


if __name__ == "__main__":
    main()
