"""Smooths every mesh file in a folder into another folder, under the same names, e.g.

    python python/examples/batch.py scans/ smoothed/ --best --device gpu

Outputs that already exist are skipped unless --force, so an interrupted run picks up where it
stopped. rsmooth.smooth builds the kernels once per device and process, so the whole folder pays
for one build. Reading and writing go through trimesh (process=False keeps the vertex order)."""

import argparse
import pathlib
import sys
import time

import trimesh

import rsmooth

SUFFIXES = {".ply", ".obj", ".off", ".stl"}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("input_dir", type=pathlib.Path)
    ap.add_argument("output_dir", type=pathlib.Path, help="created when missing")
    ap.add_argument("--force", action="store_true", help="replace outputs that exist")
    ap.add_argument("--best", action="store_true", help="rsmooth's most accurate mode (slower)")
    ap.add_argument("--device", default="auto", help="auto, gpu, cpu, reference, P:D or a name")
    args = ap.parse_args()

    inputs = sorted(p for p in args.input_dir.iterdir()
                    if p.suffix.lower() in SUFFIXES and p.is_file())
    args.output_dir.mkdir(parents=True, exist_ok=True)
    failed = 0
    print(f"{len(inputs)} meshes in {args.input_dir}, device {args.device}")
    for path in inputs:
        out = args.output_dir / path.name
        if out.exists() and not args.force:
            print(f"{path.name}: {out} exists, skipped (--force replaces it)")
            continue
        start = time.perf_counter()
        try:
            mesh = trimesh.load(path, process=False, force="mesh")
            mesh.vertices = rsmooth.smooth(mesh.vertices, mesh.faces, best=args.best,
                                           device=args.device)
            mesh.export(out)
        except (ValueError, OSError) as e:  # a file trimesh cannot read, a bad mesh, a full disk
            print(f"{path.name}: {e}", file=sys.stderr)
            failed += 1
            continue
        print(f"{path.name}: {len(mesh.vertices)} vertices in {time.perf_counter() - start:.2f} s")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
