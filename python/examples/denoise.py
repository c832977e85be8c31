"""Denoises a mesh file through trimesh and, given its ground truth, prints the error before and
after (rsmooth.compare), e.g.

    python python/examples/denoise.py ../shared/data/benchmark/Fandisk0.3/Noisy.obj \\
        ../shared/data/benchmark/Fandisk0.3/Original.obj --best --auto -o smooth.ply

trimesh loads with process=False: merging vertices would reorder them, and the comparison needs
the result's vertex i to be the truth's vertex i."""

import argparse
import time
import warnings

import trimesh

import rsmooth


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("noisy")
    ap.add_argument("truth", nargs="?")
    ap.add_argument("-o", "--output", help="write the result here (any format trimesh writes)")
    ap.add_argument("--device", default="auto")
    ap.add_argument("--best", action="store_true")
    ap.add_argument("--auto", action="store_true")
    args = ap.parse_args()

    mesh = trimesh.load(args.noisy, process=False, force="mesh")
    print(f"{args.noisy}: {len(mesh.vertices)} vertices, {len(mesh.faces)} faces; "
          f"estimated noise {rsmooth.estimate_noise(mesh.vertices, mesh.faces):.3f} edge lengths")
    start = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        smooth = rsmooth.smooth(mesh.vertices, mesh.faces, device=args.device, best=args.best,
                                auto=args.auto)
    for w in caught:
        print(f"warning: {w.message}")
    print(f"smoothed in {time.perf_counter() - start:.2f} s "
          f"(device {args.device}; devices here: {[d['name'] for d in rsmooth.devices()]})")
    if args.truth:
        truth = trimesh.load(args.truth, process=False, force="mesh")
        for name, vertices in (("noisy", mesh.vertices), ("smoothed", smooth)):
            m = rsmooth.compare(vertices, truth.vertices, truth.faces)
            print(f"{name:9s} E_v {m['ev']:.3f} (1e-3 bbox diagonal)  theta {m['theta']:.2f} deg  "
                  f"rms_v {m['rms_v']:.3f} edges  Hausdorff {m['hausdorff']:.2f}")
    if args.output:
        mesh.vertices = smooth
        mesh.export(args.output)
        print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
