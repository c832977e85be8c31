"""The learned normals' training data: noisy copies of clean shapes, each facet's descriptor (as
the library computes it: rsmooth-train-features) and its true normal in the descriptor's frame.

    python train/dataset.py BUILD CACHE --stage S [--model FILE] [--cad DIR] [--tiny]

Cases (cases()): every clean mesh of ../shared/data/clean, the benchmark and train Originals and
the generated CAD parts, each under every noise class of NOISE (drawn per case from its seed),
and the raw range scans against their reconstruction. Facets are sampled per case, more of them
near sharp features (rare, and what the normal error on CAD parts is made of). Stage S > 1 reads
the descriptors after the model's first S - 1 stages, so each stage trains on the real outputs of
the one before. Writes CACHE/stage{S}.npz and CACHE/manifest.json (what the data is made of: its
digest goes into the model file).
"""
import argparse
import glob
import hashlib
import json
import os
import subprocess
import sys
import tempfile
from multiprocessing import Pool

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
SHARED = os.path.normpath(os.path.join(HERE, "..", "..", "shared", "data"))
# Noise classes: rsmooth noise's options per case, drawn from the case's own generator.
NOISE_CLASSES = ["clean", "gaussian", "random", "impulsive", "correlated", "stripes", "depth"]
SAMPLES_PER_CASE = 3000
SAMPLES_CLEAN = 800
# Folds by whole shape: the shapes the benchmark pairs share with clean/ go to one fold each, so a
# left-out fold never saw its shape under any noise.
FOLDS = 4
PINNED_FOLDS = {"fandisk": 0, "block": 0, "stanford-bunny": 1, "twelve": 1, "trimstar": 2,
                "sharpsphere": 2}


def noise_args(kind, rng):
    """rsmooth noise's options for one case of a noise class."""
    if kind == "gaussian":
        return ["--sigma", f"{rng.uniform(0.05, 0.8):.3f}"]
    if kind == "random":
        return ["--sigma", f"{rng.uniform(0.1, 0.6):.3f}", "--direction", "random"]
    if kind == "impulsive":
        return ["--sigma", f"{rng.uniform(0.3, 0.8):.3f}", "--impulsive",
                f"{rng.uniform(0.05, 0.3):.3f}"]
    if kind == "correlated":
        return ["--sigma", f"{rng.uniform(0.1, 0.4):.3f}", "--correlation",
                f"{rng.uniform(1.2, 3.0):.2f}"]
    if kind == "stripes":
        return ["--sigma", f"{rng.uniform(0.1, 0.4):.3f}", "--stripes",
                f"{rng.uniform(2.0, 6.0):.2f}"]
    if kind == "depth":
        return ["--sigma", f"{rng.uniform(0.05, 0.3):.3f}", "--depth-sensor", "--grazing",
                f"{rng.uniform(0.3, 0.6):.2f}"]
    raise ValueError(kind)


def shapes(cad_dir):
    """(group, clean mesh path) of every clean shape."""
    out = []
    for path in sorted(glob.glob(os.path.join(SHARED, "clean", "*"))):
        out.append((os.path.splitext(os.path.basename(path))[0], path))
    for base in ("benchmark", "train"):
        for path in sorted(glob.glob(os.path.join(SHARED, base, "*", "Original.obj"))):
            name = os.path.basename(os.path.dirname(path))
            group = "".join(c for c in name if c.isalpha()).lower().replace("impulsive", "")
            out.append((group, path))
    if cad_dir:
        for path in sorted(glob.glob(os.path.join(cad_dir, "*.obj"))):
            out.append((os.path.splitext(os.path.basename(path))[0], path))
    return out


def fold_of(group, order):
    return PINNED_FOLDS.get(group, order % FOLDS)


def cases(cad_dir, classes, seed=1):
    """Every training case: its name, shape group, fold, noise class, clean mesh and options."""
    out, order = [], {}
    for group, path in shapes(cad_dir):
        if group == "bunny":  # the benchmark's Bunny is stanford-bunny
            group = "stanford-bunny"
        order.setdefault(group, len([g for g in order if g not in PINNED_FOLDS]))
        fold = fold_of(group, order[group])
        for kind in classes:
            digest = hashlib.sha256(f"{seed}/{path}/{kind}".encode()).digest()
            rng = np.random.default_rng(int.from_bytes(digest[:8], "little"))
            args = [] if kind == "clean" else noise_args(kind, rng) + [
                "--seed", str(int.from_bytes(digest[8:12], "little"))]
            name = f"{os.path.basename(os.path.dirname(path)) if 'Original' in path else group}-{kind}"
            out.append({"name": name, "group": group, "fold": fold, "class": kind,
                        "clean": path, "noise": args})
    for scan in ("bun000", "bun045"):
        path = os.path.join(SHARED, "scans", "stanford-bunny", f"{scan}.ply")
        if os.path.exists(path):
            out.append({"name": scan, "group": "stanford-bunny", "fold": PINNED_FOLDS["stanford-bunny"],
                        "class": "scan", "clean": path, "noise": None})
    return out


def scan_truth(cache, scan):
    """The reconstruction moved into the scan's own frame (bun.conf: aligned = R^T p + t, so
    p = R (aligned - t)), written once as an OBJ for --truth-surface."""
    folder = os.path.join(SHARED, "scans", "stanford-bunny")
    out = os.path.join(cache, "meshes", f"{scan}-reconstruction.obj")
    if os.path.exists(out):
        return out
    conf = {}
    for line in open(os.path.join(folder, "bun.conf")):
        w = line.split()
        if w and w[0] == "bmesh":
            conf[os.path.splitext(w[1])[0]] = [float(v) for v in w[2:9]]
    t, (x, y, z, w) = np.array(conf[scan][:3]), conf[scan][3:]
    r = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                  [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                  [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    with open(os.path.join(folder, "bun_zipper.ply")) as f:
        header = []
        while not header or header[-1] != "end_header":
            header.append(f.readline().strip())
        nv = int(next(h.split()[2] for h in header if h.startswith("element vertex")))
        nf = int(next(h.split()[2] for h in header if h.startswith("element face")))
        rows = [f.readline().split() for _ in range(nv + nf)]
    xyz = np.array([[float(v) for v in row[:3]] for row in rows[:nv]])
    xyz = (xyz - t) @ r.T
    os.makedirs(os.path.dirname(out), exist_ok=True)
    with open(out + ".tmp", "w") as f:
        f.writelines(f"v {float(p[0])!r} {float(p[1])!r} {float(p[2])!r}\n" for p in xyz)
        f.writelines("f %d %d %d\n" % tuple(int(v) + 1 for v in row[1:4]) for row in rows[nv:])
    os.replace(out + ".tmp", out)
    return out


def file_digest(path):
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def portable(path):
    """A source's name without the machine's folders: data/... for ../shared/data, cad/NAME for
    a generated part (its recipe is in the shape generator's manifest, by seed)."""
    if path.startswith(SHARED + os.sep):
        return "data/" + os.path.relpath(path, SHARED)
    return "cad/" + os.path.basename(path)


def write_manifest(path, all_cases):
    """What the training data is made of (every case's source, class, fold and noise options,
    every source's SHA-256, the sampling), one line of JSON: its digest goes into the model."""
    cases = [dict(c, clean=portable(c["clean"])) for c in all_cases]
    sources = sorted({c["clean"] for c in all_cases})
    manifest = {"cases": cases, "sources": {portable(p): file_digest(p) for p in sources},
                "samples_per_case": SAMPLES_PER_CASE, "samples_clean": SAMPLES_CLEAN,
                "descriptor_layout": 1}
    with open(path + ".tmp", "w") as f:
        json.dump(manifest, f, sort_keys=True, separators=(",", ":"))
        f.write("\n")
    os.replace(path + ".tmp", path)


def noisy_mesh(build, cache, case):
    """The case's noisy mesh, made once (rsmooth noise) and kept in CACHE/meshes."""
    if not case["noise"]:
        return case["clean"]
    out = os.path.join(cache, "meshes", case["name"] + ".ply")
    if not os.path.exists(out):
        os.makedirs(os.path.dirname(out), exist_ok=True)
        tmp = out + ".tmp.ply"
        subprocess.run([os.path.join(build, "rsmooth"), "noise", case["clean"], tmp, "-q", "-f"]
                       + case["noise"], check=True)
        os.replace(tmp, out)
    return out


def staged_mesh(build, cache, case, noisy):
    """The hand-fitted stage's result on the noisy mesh (rsmooth --best --auto --passes 0): the
    learned normals refine what it leaves."""
    out = os.path.join(cache, "staged", case["name"] + ".ply")
    if not os.path.exists(out):
        os.makedirs(os.path.dirname(out), exist_ok=True)
        tmp = out + ".tmp.ply"
        subprocess.run([os.path.join(build, "rsmooth"), noisy, "-o", tmp, "--best", "--auto",
                        "--passes", "0", "--device", "reference", "-q", "-f"], check=True)
        os.replace(tmp, out)
    return out


def features(build, mesh, truth, surface=False, model=None, stages=0, predict=False,
             noise_from=None):
    """The tool's arrays for one mesh, as a dict."""
    with tempfile.TemporaryDirectory() as tmp:
        cmd = [os.path.join(build, "rsmooth-train-features"), mesh, tmp]
        if noise_from:
            cmd += ["--noise-from", noise_from]
        if truth:
            cmd += ["--truth-surface" if surface else "--truth", truth]
        if model and stages:
            cmd += ["--model", model, "--stages", str(stages)]
        if predict:
            cmd += ["--predict"] + (["--model", model] if model else [])
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
        return {os.path.splitext(f)[0]: np.load(os.path.join(tmp, f))
                for f in os.listdir(tmp)}


def to_frame(frames, vectors):
    return np.einsum("fij,fj->fi", frames.reshape(-1, 3, 3), vectors)


def sample(case, arrays, rng):
    """The case's sampled facets: more near sharp features."""
    n = len(arrays["descriptor"])
    want = SAMPLES_CLEAN if case["class"] == "clean" else SAMPLES_PER_CASE
    if n <= want:
        return np.arange(n)
    weight = 1.0 + 4.0 * np.minimum(arrays["sharp"][:, 0] / 0.3, 1.0)
    return np.sort(rng.choice(n, size=want, replace=False, p=weight / weight.sum()))


def one_case(job):
    build, cache, case, model, stage = job
    noisy = noisy_mesh(build, cache, case)
    mesh = staged_mesh(build, cache, case, noisy)
    truth = scan_truth(cache, case["name"]) if case["class"] == "scan" else case["clean"]
    arrays = features(build, mesh, truth, surface=case["class"] == "scan",
                      model=model, stages=stage - 1, noise_from=noisy)
    rng = np.random.default_rng(int(hashlib.sha256(case["name"].encode()).hexdigest()[:8], 16))
    keep = sample(case, arrays, rng)
    x = arrays["descriptor"][keep]
    y = to_frame(arrays["frame"][keep], arrays["target"][keep].astype(np.float64))
    return x, y.astype(np.float32), arrays["sharp"][keep, 0], len(keep)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("build")
    ap.add_argument("cache")
    ap.add_argument("--stage", type=int, default=1)
    ap.add_argument("--model")
    ap.add_argument("--cad")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--classes", default=",".join(NOISE_CLASSES))
    ap.add_argument("--name", help="the output's name (default stage{S}): a stage after the "
                    "first is made per fold, from that fold's model")
    args = ap.parse_args()
    if not os.path.isdir(SHARED):
        sys.exit(f"dataset.py: the training data folder {SHARED} is missing: the training reads "
                 "the clean meshes, pairs and scans of ../shared/data beside the checkout")
    os.makedirs(args.cache, exist_ok=True)
    all_cases = cases(args.cad, args.classes.split(","))
    if args.stage == 1:
        write_manifest(os.path.join(args.cache, "manifest.json"), all_cases)
    jobs = [(args.build, args.cache, c, args.model, args.stage) for c in all_cases]
    xs, ys, sharp, case_of = [], [], [], []
    with Pool(args.jobs) as pool:
        for i, (x, y, s, n) in enumerate(pool.imap(one_case, jobs)):
            xs.append(x), ys.append(y), sharp.append(s), case_of.append(np.full(n, i, np.int32))
            if (i + 1) % 25 == 0 or i + 1 == len(jobs):
                print(f"[{i + 1}/{len(jobs)}] cases", flush=True)
    out = os.path.join(args.cache, f"{args.name or f'stage{args.stage}'}.npz")
    np.savez(out + ".tmp.npz", x=np.concatenate(xs), y=np.concatenate(ys),
             sharp=np.concatenate(sharp), case=np.concatenate(case_of))
    os.replace(out + ".tmp.npz", out)
    print(f"{out}: {sum(len(x) for x in xs)} facets from {len(jobs)} cases")


if __name__ == "__main__":
    main()
