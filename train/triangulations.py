"""Triangulation kinds: the same solid meshed the ways real inputs are.

cad        manifold3d's own output: long thin fan triangles on flat faces,
           strips on curved ones (anisotropic, like exported CAD).
refined    manifold3d edges split to a target length: denser, still
           CAD-structured.
remeshed   pymeshlab isotropic remeshing: near-equilateral triangles.
irregular  remeshed, decimated, then split inside random blobs, so
           density and valence vary across the surface.
"""

import numpy as np
import pymeshlab

from obj_io import canonical_order

KINDS = ("cad", "refined", "remeshed", "irregular")
KIND_WEIGHTS = (0.3, 0.2, 0.3, 0.2)


def manifold_arrays(solid):
    mesh = solid.to_mesh64()
    verts = np.asarray(mesh.vert_properties, dtype=np.float64)[:, :3]
    # Fixed order in, so pymeshlab's remeshing is repeatable too.
    return canonical_order(verts, np.asarray(mesh.tri_verts, dtype=np.int64))


def edge_length_for(area, triangles):
    """Edge length giving about `triangles` equilateral triangles."""
    return float(np.sqrt(4.0 * area / (np.sqrt(3.0) * triangles)))


def triangulate(solid, kind, rng, target_triangles):
    """Mesh `solid` as `kind`; returns (verts, faces, params for the log)."""
    area = solid.surface_area()
    if kind == "cad":
        return (*manifold_arrays(solid), {})
    if kind == "refined":
        # refine_to_length also splits the long CAD edges, so aim coarser.
        length = 1.5 * edge_length_for(area, target_triangles)
        return (*manifold_arrays(solid.refine_to_length(length)),
                {"edge_length": round(length, 5)})
    if kind == "remeshed":
        length = edge_length_for(area, target_triangles)
        meshset = _remesh(*manifold_arrays(solid), length)
        return (*_arrays(meshset), {"edge_length": round(length, 5)})
    return _irregular(solid, rng, target_triangles)


def _arrays(meshset):
    out = meshset.current_mesh()
    return (np.asarray(out.vertex_matrix(), dtype=np.float64),
            np.asarray(out.face_matrix(), dtype=np.int64))


def _remesh(verts, faces, length):
    meshset = pymeshlab.MeshSet()
    meshset.add_mesh(pymeshlab.Mesh(vertex_matrix=verts, face_matrix=faces))
    # featuredeg keeps the CAD creases sharp instead of rounding them.
    meshset.meshing_isotropic_explicit_remeshing(
        iterations=8, targetlen=pymeshlab.PureValue(length), featuredeg=30.0,
        maxsurfdist=pymeshlab.PureValue(length * 0.2))
    return meshset


def _irregular(solid, rng, target_triangles):
    """Remesh, decimate everywhere (quadric error keeps curved areas dense),
    then split every triangle inside random blobs: density jumps about 4x
    across blob borders and valences become irregular there."""
    keep = rng.uniform(0.4, 0.8)
    # Blobs cover about 40% of faces and quadruple them: 2.2x on the whole.
    start = target_triangles / (keep * 2.2)
    length = edge_length_for(solid.surface_area(), start)
    meshset = _remesh(*manifold_arrays(solid), length)
    meshset.meshing_decimation_quadric_edge_collapse(
        targetfacenum=int(keep * meshset.current_mesh().face_number()),
        preservetopology=True, preservenormal=True, planarquadric=True)
    blobs = _select_blobs(meshset, rng)
    meshset.meshing_surface_subdivision_midpoint(
        iterations=1, threshold=pymeshlab.PureValue(0.0), selected=True)
    return (*_arrays(meshset), {"edge_length": round(length, 5),
                                "decimate_keep": round(keep, 4), **blobs})


def _select_blobs(meshset, rng):
    """Select the faces where a random smooth field is high."""
    freq = rng.uniform(2.0, 8.0, size=3)
    phase = rng.uniform(0, 2 * np.pi, size=3)
    cut = rng.uniform(-0.5, 1.0)
    field = " + ".join(f"sin({f:.4f}*{c} + {p:.4f})" for f, c, p in
                       zip(freq, ("x0", "y0", "z0"), phase))
    meshset.compute_selection_by_condition_per_face(
        condselect=f"({field}) > {cut:.4f}")
    return {"blob_freq": [round(float(f), 4) for f in freq],
            "blob_phase": [round(float(p), 4) for p in phase],
            "blob_cut": round(cut, 4)}
