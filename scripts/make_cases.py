"""The calibration and evaluation cases of the accuracy study (docs/accuracy.md), generated from
../shared/data into a folder outside the project (the data is never copied into it), with a
manifest every experiment reads.

Cases:
  - the six noisy/truth pairs of ../shared/data/benchmark and ../shared/data/train;
  - each clean mesh of ../shared/data/clean with generated noise: Gaussian along the normals at
    0.2 and 0.5 mean edge lengths, Gaussian in random directions at 0.3, and impulsive noise
    (0.5 mean edge lengths on 10% of the vertices) on three of them.

Every case names its `group`: the underlying model. Fandisk0.3 and clean/fandisk are one group,
Bunny0.2 and clean/stanford-bunny another, so cross-validation that leaves a group out leaves the
whole mesh out, never a noisier copy of a mesh the rule was fitted on.

    python3 scripts/make_cases.py --rsmooth build/rsmooth --out ../cases
writes ../cases/manifest.json and the noisy files. Seeds are fixed: the same files every run."""
import argparse
import json
import os
import subprocess
import sys

SHARED = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "shared", "data")

# benchmark / train pair -> group
PAIR_GROUPS = {"Fandisk0.3": "fandisk", "Block0.4": "block", "Bunny0.2": "bunny",
               "SharpSphere0.3": "sharpsphere", "Twelve0.5Impulsive": "twelve",
               "TrimStar0.5": "trimstar"}
# clean mesh -> group
CLEAN_GROUPS = {"fandisk": "fandisk", "stanford-bunny": "bunny", "rocker-arm": "rocker-arm",
                "spot": "spot", "beetle-alt": "beetle", "cow": "cow", "teapot": "teapot"}
# (label, noise options, kind, sigma, clean meshes it is applied to or None for all)
NOISES = [("n0.2", ["--sigma", "0.2"], "normal", 0.2, None),
          ("n0.5", ["--sigma", "0.5"], "normal", 0.5, None),
          ("r0.3", ["--sigma", "0.3", "--direction", "random"], "random", 0.3, None),
          ("i0.5", ["--sigma", "0.5", "--impulsive", "0.1"], "impulsive", 0.5,
           ["fandisk", "rocker-arm", "cow"])]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rsmooth", default="build/rsmooth")
    ap.add_argument("--out", required=True)
    ap.add_argument("--shared", default=SHARED)
    args = ap.parse_args()
    shared = os.path.abspath(args.shared)
    if not os.path.isdir(shared):
        sys.exit("make_cases.py: %s: no such folder (../shared/data beside the project)" % shared)
    os.makedirs(args.out, exist_ok=True)
    cases = []
    for sub in ("benchmark", "train"):
        for name in sorted(os.listdir(os.path.join(shared, sub))):
            d = os.path.join(shared, sub, name)
            kind = "impulsive" if "Impulsive" in name else "normal"
            sigma = float("".join(c for c in name if c.isdigit() or c == ".").strip("."))
            cases.append({"name": name, "group": PAIR_GROUPS.get(name, name.lower()),
                          "source": sub, "kind": kind, "sigma": sigma,
                          "noisy": os.path.join(d, "Noisy.obj"),
                          "truth": os.path.join(d, "Original.obj")})
    for mesh, group in sorted(CLEAN_GROUPS.items()):
        truth = os.path.join(shared, "clean", mesh + ".obj")
        for seed, (label, opts, kind, sigma, only) in enumerate(NOISES, start=11):
            if only is not None and mesh not in only:
                continue
            noisy = os.path.join(args.out, "%s-%s.obj" % (mesh, label))
            if not os.path.exists(noisy):
                subprocess.run([args.rsmooth, "noise", truth, noisy, "--seed", str(seed), "-q"]
                               + opts, check=True)
            cases.append({"name": "%s-%s" % (mesh, label), "group": group, "source": "clean",
                          "kind": kind, "sigma": sigma, "noisy": noisy, "truth": truth})
    with open(os.path.join(args.out, "manifest.json"), "w") as f:
        json.dump({"cases": cases}, f, indent=1)
    print("%d cases in %d groups: %s" % (len(cases), len({c["group"] for c in cases}),
                                         os.path.join(args.out, "manifest.json")))


if __name__ == "__main__":
    main()
