"""Why tuned Taubin smoothing wins on coarse organic meshes, and a guard that needs no truth
(issue 15): for every case, `--best --auto`'s result and Taubin's at several iteration counts,
each with its E_v, theta and its RMS displacement from the noisy input (in the input's mean edge
lengths), beside the noise estimate. Where the best mode moves the vertices much farther than the
noise it estimated, it is removing the shape's own detail (the discrepancy principle: a denoiser
should move a vertex about as far as the noise did).

    python3 scripts/discrepancy_study.py --cases /work/cases/manifest.json --rsmooth build/rsmooth \
        --out docs/results/discrepancy.json"""
import argparse
import json
import os
import re
import subprocess
import tempfile

TAUBIN = [1, 2, 3, 5, 7, 10, 14, 20, 30, 40, 60]


def read_vertices(path):
    out = []
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                out.append([float(x) for x in line.split()[1:4]])
    return out


def rms_move(a, b, unit):
    s = sum((p[0] - q[0]) ** 2 + (p[1] - q[1]) ** 2 + (p[2] - q[2]) ** 2 for p, q in zip(a, b))
    return (s / len(a)) ** 0.5 / unit


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cases", required=True)
    ap.add_argument("--rsmooth", default="build/rsmooth")
    ap.add_argument("--out", default="docs/results/discrepancy.json")
    args = ap.parse_args()
    cases = json.load(open(args.cases))["cases"]
    result = json.load(open(args.out)) if os.path.exists(args.out) else {}
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "out.obj")
        for c in cases:
            if c["name"] in result:
                continue
            noisy = read_vertices(c["noisy"])
            unit = json.loads(subprocess.run([args.rsmooth, "compare", c["noisy"], c["noisy"],
                                              "--json"], capture_output=True, text=True,
                                             check=True).stdout)["mean_edge"]

            def measure(opts):
                p = subprocess.run([args.rsmooth, c["noisy"], "-o", out, "-f"] + opts,
                                   capture_output=True, text=True, check=True)
                m = json.loads(subprocess.run([args.rsmooth, "compare", out, c["truth"], "--json"],
                                              capture_output=True, text=True, check=True).stdout)
                return {"ev": m["ev"], "theta": m["theta"],
                        "move": rms_move(read_vertices(out), noisy, unit)}, p.stderr

            best, err = measure(["--best", "--auto"])
            est = float(re.search(r"noise estimate ([0-9.eE+-]+)", err).group(1))
            row = {"estimate": est, "impulsive": "impulsive (" in err, "best_auto": best,
                   "taubin": {str(k): measure(["--method", "taubin", "--iterations", str(k),
                                               "-q"])[0] for k in TAUBIN}}
            result[c["name"]] = row
            with open(args.out, "w") as f:
                json.dump(result, f, indent=1)
            print("%-22s est %.3f best move %.3f (ratio %.2f) ev %.3f | taubin best ev %.3f" % (
                c["name"], est, best["move"], best["move"] / max(est, 1e-9), best["ev"],
                min(t["ev"] for t in row["taubin"].values())), flush=True)


if __name__ == "__main__":
    main()
