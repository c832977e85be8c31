"""Minimal OBJ writer: `v` and `f` lines only, 1-based triangle indices."""

import numpy as np

DIGITS = 7  # fixed precision so a seed always gives byte-identical files


def quantize(verts):
    """Round as the file will store them, so checks see the written mesh."""
    # Adding 0.0 turns -0.0 into 0.0: one spelling per number in the file.
    return np.round(np.asarray(verts, dtype=np.float64), DIGITS) + 0.0


def canonical_order(verts, faces):
    """Sort vertices by position and faces by index, keeping orientation.

    manifold3d sorts in parallel, so equal meshes can come out in a
    different order from run to run; this makes the order a function of
    the geometry alone.
    """
    order = np.lexsort(verts.T[::-1])
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    faces = rank[faces]
    # Rotate each triangle to start at its smallest index: same winding.
    shift = np.argmin(faces, axis=1)
    rows = np.arange(len(faces))[:, None]
    faces = faces[rows, (shift[:, None] + np.arange(3)) % 3]
    faces = faces[np.lexsort(faces.T[::-1])]
    return verts[order], faces


def obj_text(verts, faces):
    fmt = f"v %.{DIGITS}f %.{DIGITS}f %.{DIGITS}f"
    lines = [fmt % tuple(v) for v in verts.tolist()]
    lines += ["f %d %d %d" % tuple(f) for f in (faces + 1).tolist()]
    return "\n".join(lines) + "\n"
