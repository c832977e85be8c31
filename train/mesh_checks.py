"""Checks that a triangle mesh is a clean closed 2-manifold.

A training mesh must be watertight and consistently oriented, otherwise
the per-vertex normals the regressor learns from are ill-defined.
"""

import numpy as np


def manifold_problems(verts, faces):
    """Return a list of reasons the mesh is not clean; empty when it is."""
    faces = np.asarray(faces, dtype=np.int64)
    verts = np.asarray(verts, dtype=np.float64)
    if len(faces) == 0:
        return ["no faces"]
    problems = []
    problems += _index_problems(verts, faces)
    if problems:
        return problems
    problems += _degenerate_problems(verts, faces)
    problems += _edge_problems(faces)
    if not problems:
        problems += _vertex_fan_problems(faces, len(verts))
        problems += _volume_problems(verts, faces)
    return problems


def _index_problems(verts, faces):
    if faces.min() < 0 or faces.max() >= len(verts):
        return ["face index out of range"]
    if np.unique(faces).size != len(verts):
        return ["unreferenced vertices"]
    return []


def triangle_areas(verts, faces):
    a, b, c = (verts[faces[:, k]] for k in range(3))
    return 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)


def _degenerate_problems(verts, faces):
    # Area threshold is relative so it holds at any part scale.
    diag2 = np.sum((verts.max(0) - verts.min(0)) ** 2)
    bad = int(np.sum(triangle_areas(verts, faces) <= 1e-12 * diag2))
    return ["degenerate triangles"] if bad else []


def _edge_problems(faces):
    """Each undirected edge in exactly 2 faces, traversed once each way."""
    directed = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]],
                               faces[:, [2, 0]]])
    _, counts = np.unique(directed, axis=0, return_counts=True)
    if np.any(counts > 1):
        return ["inconsistent orientation or repeated directed edge"]
    undirected = np.sort(directed, axis=1)
    _, counts = np.unique(undirected, axis=0, return_counts=True)
    if np.any(counts != 2):
        return ["edge not shared by exactly 2 faces"]
    return []


def _vertex_fan_problems(faces, n_verts):
    """Faces around each vertex must form a single disc (one link cycle)."""
    # For corner (v, a, b) the link of v has the directed edge a -> b.
    corners = np.concatenate([faces, faces[:, [1, 2, 0]], faces[:, [2, 0, 1]]])
    order = np.argsort(corners[:, 0], kind="stable")
    corners = corners[order]
    starts = np.searchsorted(corners[:, 0], np.arange(n_verts + 1))
    for v in range(n_verts):
        link = dict(zip(corners[starts[v]:starts[v + 1], 1].tolist(),
                        corners[starts[v]:starts[v + 1], 2].tolist()))
        if _cycle_length(link) != len(link):
            return ["non-manifold vertex (pinched fan)"]
    return []


def _cycle_length(link):
    first = next(iter(link))
    node, steps = link[first], 1
    while node != first and steps <= len(link):
        node = link.get(node, first)
        steps += 1
    return steps


def signed_volume(verts, faces):
    a, b, c = (verts[faces[:, k]] for k in range(3))
    return float(np.sum(np.einsum("ij,ij->i", a, np.cross(b, c))) / 6.0)


def _volume_problems(verts, faces):
    # Outward orientation: a closed mesh with CCW faces has positive volume.
    return [] if signed_volume(verts, faces) > 0 else ["inward orientation"]


def component_count(faces, n_verts):
    """Connected components over shared vertices (union-find)."""
    parent = np.arange(n_verts)

    def find(x):
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    for a, b in np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]]]).tolist():
        ra, rb = find(a), find(b)
        if ra != rb:
            parent[ra] = rb
    return len({find(v) for v in range(n_verts)})
