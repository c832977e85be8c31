"""Generate watertight CAD-like training parts as OBJ files.

    python train/shapes.py OUTDIR --count N --seed S

Writes OUTDIR/cad-NNNN-KIND.obj and OUTDIR/shapes.json (per file: seed,
recipe, triangulation, counts, sha256). The same seed gives identical
files. A part that fails the mesh checks is redrawn from the next seed of
its own sequence, so one bad part never shifts the others.
"""

import argparse
import hashlib
import json
import sys
import time
from collections import Counter
from pathlib import Path

import numpy as np

from cad_parts import DENSE_SEGMENT_CHOICES, SEGMENT_CHOICES, build_part
from mesh_checks import component_count, manifold_problems, signed_volume
from obj_io import canonical_order, obj_text, quantize
from triangulations import KIND_WEIGHTS, KINDS, triangulate

MIN_TRIANGLES, MAX_TRIANGLES = 2000, 60000
MAX_ATTEMPTS = 50


def main():
    args = parse_args()
    out = Path(args.outdir)
    out.mkdir(parents=True, exist_ok=True)
    master = np.random.default_rng(args.seed)
    # One seed per part, drawn up front: part i does not depend on --count.
    part_seeds = [int(s) for s in master.integers(0, 2**32, size=args.count)]
    start, entries, redraws = time.perf_counter(), [], Counter()
    for index, part_seed in enumerate(part_seeds):
        entry, reasons = make_part(index, part_seed, out)
        redraws.update(reasons)
        entries.append(entry)
        print(f"{entry['file']}: {entry['triangles']} triangles"
              + (f" ({len(reasons)} redrawn)" if reasons else ""))
    write_manifest(out, args, entries, redraws)
    print(summary(entries, redraws, time.perf_counter() - start))


def parse_args():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("outdir")
    parser.add_argument("--count", type=int, default=40)
    parser.add_argument("--seed", type=int, default=1)
    return parser.parse_args()


def make_part(index, part_seed, out):
    """Draw until a part passes the checks; returns (entry, redraw reasons)."""
    reasons = []
    for attempt in range(MAX_ATTEMPTS):
        rng = np.random.default_rng([part_seed, attempt])
        entry, verts, faces, problem = draw_part(rng)
        if problem is None:
            entry = {"file": f"cad-{index:04d}-{entry['kind']}.obj",
                     "seed": [part_seed, attempt], **entry}
            return save(out, entry, verts, faces), reasons
        reasons.append(problem)
    sys.exit(f"part {index}: no valid part in {MAX_ATTEMPTS} attempts")


def draw_part(rng):
    kind = str(rng.choice(KINDS, p=KIND_WEIGHTS))
    dense = kind == "cad"
    solid, recipe, segments = build_part(
        rng, DENSE_SEGMENT_CHOICES if dense else SEGMENT_CHOICES)
    solid, placement = place(solid, rng)
    # manifold3d's own meshing has no size knob but `segments`.
    target = None if dense else target_triangles(rng)
    verts, faces, params = triangulate(solid, kind, rng, target)
    verts, faces = canonical_order(quantize(verts), faces)
    entry = {"kind": kind, "recipe": recipe, "segments": segments,
             **placement, "target_triangles": target, "triangulation": params}
    return entry, verts, faces, first_problem(solid, verts, faces)


def place(solid, rng):
    """Centre, maybe turn, and scale to a bbox diagonal in [0.5, 2]."""
    rotation = [0.0, 0.0, 0.0]
    if rng.random() < 0.5:
        rotation = [round(float(a), 3) for a in rng.uniform(0, 360, size=3)]
        solid = solid.rotate(tuple(rotation))
    lo, hi = np.reshape(solid.bounding_box(), (2, 3))
    diagonal = float(np.exp(rng.uniform(np.log(0.5), np.log(2.0))))
    solid = solid.translate(tuple(-(lo + hi) / 2)) \
        .scale((diagonal / float(np.linalg.norm(hi - lo)),) * 3)
    return solid, {"rotation_deg": rotation, "diagonal": round(diagonal, 4)}


def target_triangles(rng):
    """Mostly 2.5k-25k triangles, one part in ten up to 55k."""
    lo, hi = (25000, 55000) if rng.random() < 0.1 else (2500, 25000)
    return int(np.exp(rng.uniform(np.log(lo), np.log(hi))))


def first_problem(solid, verts, faces):
    n = len(faces)
    if not MIN_TRIANGLES <= n <= MAX_TRIANGLES:
        return "triangle count out of range"
    problems = manifold_problems(verts, faces)
    if problems:
        return problems[0]
    if component_count(faces, len(verts)) != 1:
        return "more than one piece"
    # Remeshing must not change the solid: compare enclosed volumes.
    if abs(signed_volume(verts, faces) / solid.volume() - 1.0) > 0.02:
        return "volume drift after remeshing"
    return None


def save(out, entry, verts, faces):
    data = obj_text(verts, faces).encode()
    (out / entry["file"]).write_bytes(data)
    entry.update(vertices=len(verts), triangles=len(faces),
                 sha256=hashlib.sha256(data).hexdigest())
    return entry


def write_manifest(out, args, entries, redraws):
    manifest = {"seed": args.seed, "count": args.count,
                "redrawn": sum(redraws.values()),
                "redraw_reasons": dict(sorted(redraws.items())),
                "parts": entries}
    (out / "shapes.json").write_text(json.dumps(manifest, indent=1) + "\n")


def summary(entries, redraws, seconds):
    tris = [e["triangles"] for e in entries]
    kinds = Counter(e["kind"] for e in entries)
    return (f"{len(entries)} parts in {seconds:.1f} s; triangles "
            f"{min(tris)}-{max(tris)} (median {int(np.median(tris))}); "
            f"kinds {dict(sorted(kinds.items()))}; "
            f"redrawn {sum(redraws.values())} {dict(redraws)}")


if __name__ == "__main__":
    main()
