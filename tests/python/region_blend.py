"""An independent numpy copy of the best mode's choice per region (lib/passes/region_choice.c) and
of the fold guard (lib/stages/fold_guard.c), written from their descriptions, for
test_normal_update.py to compare the library against.

blend(x_in, F, T, faces, level, low, high, rounds): per vertex, the share of the pairs of facets
sharing an edge at it whose normals in F (the filter's result) lie within 2 degrees, spread over
`rounds` rings, the weight w = clamp((share - low) / (high - low)), the result w F + (1 - w) T
(T: Taubin's smoothing of the input), boundary vertices limited to the noise level in their edge
lengths from the input, then the fold guard. (The bounds were fitted with cross-validation that
leaves whole meshes out; docs/maintainers/studies.md says where that study is kept.)"""
import itertools

import numpy as np

LIBRARY = (0.2, 0.8, 6)  # region_choice.c's SHARE_LOW, SHARE_HIGH, SHARE_SPREAD
FLAT_ANGLE = np.radians(2.0)

def weld(x):
    """Each vertex's representative: the lowest-numbered vertex at exactly its position."""
    _, first, inverse = np.unique(x, axis=0, return_index=True, return_inverse=True)
    return first[inverse.ravel()]


def facet_geometry(x, faces):
    a, b, c = x[faces[:, 0]], x[faces[:, 1]], x[faces[:, 2]]
    n = np.cross(b - a, c - a)
    area2 = np.linalg.norm(n, axis=1)
    keep = area2 > 0
    return faces[keep], n[keep] / area2[keep, None]


def vertex_shares(f_xyz, faces):
    """share[r] (NaN without pairs) and boundary[r] per welded vertex r, as region_choice.c."""
    rep = weld(f_xyz)
    tri, normal = facet_geometry(f_xyz, faces)
    t = rep[tri]
    nv = len(f_xyz)
    # one row per (vertex r, other corner o, facet): the edges at r and who holds them
    rows = []
    for a in range(3):
        for b in range(3):
            if a != b:
                rows.append(np.stack([t[:, a], t[:, b], np.arange(len(t))], axis=1))
    e = np.concatenate(rows)
    e = e[e[:, 0] != e[:, 1]]
    order = np.lexsort((e[:, 2], e[:, 1], e[:, 0]))
    e = e[order]
    key = e[:, 0].astype(np.int64) * (nv + 1) + e[:, 1]
    starts = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
    counts = np.diff(np.r_[starts, len(e)])
    pairs = np.zeros(nv)
    flat = np.zeros(nv)
    boundary = np.zeros(nv, bool)
    cos_max = np.cos(FLAT_ANGLE)
    boundary[e[starts[counts == 1], 0]] = True
    for s, c in zip(starts[counts >= 2], counts[counts >= 2]):
        r = e[s, 0]
        fs = e[s:s + c, 2]
        for i, j in itertools.combinations(fs, 2):
            pairs[r] += 1
            flat[r] += normal[i] @ normal[j] >= cos_max
    share = np.where(pairs > 0, flat / np.maximum(pairs, 1), np.nan)
    share[rep != np.arange(nv)] = np.nan
    return rep, tri, share, boundary


def spread(share, rep, tri, rounds):
    t = rep[tri]
    for _ in range(rounds):
        corner = share[t]                       # (facets, 3)
        ok = ~np.isnan(corner)
        s = np.where(ok, corner, 0).sum(axis=1)
        n = ok.sum(axis=1)
        total = np.zeros(len(share))
        count = np.zeros(len(share))
        for c in range(3):                      # each facet counts at each of its corners
            np.add.at(total, t[:, c], s)
            np.add.at(count, t[:, c], n)
        share = np.where(count > 0, total / np.maximum(count, 1), share)
    return share


def local_edges(x_in, rep, tri):
    """The mean length of the edges at each welded vertex, from each of its facets' corners."""
    t = rep[tri]
    total = np.zeros(len(x_in))
    count = np.zeros(len(x_in))
    for a in range(3):
        for b in range(3):
            if a != b:
                d = np.linalg.norm(x_in[tri[:, b]] - x_in[t[:, a]], axis=1)
                ok = t[:, b] != t[:, a]
                np.add.at(total, t[ok, a], d[ok])
                np.add.at(count, t[ok, a], 1)
    return np.where(count > 0, total / np.maximum(count, 1), 0)


def shape_correlation(x, faces):
    """lib/core/shape_correlation.c in numpy: the correlation of each welded vertex's umbrella
    offset along its (area-weighted) normal with its neighbours' mean."""
    rep = weld(x)
    t = rep[faces]
    n = np.cross(x[faces[:, 1]] - x[faces[:, 0]], x[faces[:, 2]] - x[faces[:, 0]])
    normal = np.zeros_like(x)
    for c in range(3):
        np.add.at(normal, t[:, c], n)
    e = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    e = np.unique(e[e[:, 0] != e[:, 1]], axis=0)
    total, degree = np.zeros_like(x), np.zeros(len(x))
    np.add.at(total, e[:, 0], x[e[:, 1]])
    np.add.at(total, e[:, 1], x[e[:, 0]])
    np.add.at(degree, e[:, 0], 1)
    np.add.at(degree, e[:, 1], 1)
    length = np.linalg.norm(normal, axis=1)
    valid = (rep == np.arange(len(x))) & (degree > 0) & (length > 0)
    bend = np.zeros(len(x))
    bend[valid] = np.sum((total[valid] / degree[valid, None] - x[valid]) * normal[valid], axis=1) \
        / length[valid]
    both = valid[e[:, 0]] & valid[e[:, 1]]
    around, count = np.zeros(len(x)), np.zeros(len(x))
    np.add.at(around, e[both, 0], bend[e[both, 1]])
    np.add.at(around, e[both, 1], bend[e[both, 0]])
    np.add.at(count, e[both, 0], 1)
    np.add.at(count, e[both, 1], 1)
    valid &= count > 0
    a, b = bend[valid], around[valid] / count[valid]
    if len(a) < 2 or a.var() <= 0 or b.var() <= 0:
        return 1.0
    return float(np.corrcoef(a, b)[0, 1])


def fold_guard(x_in, out, faces, untangles=8, halvings=24):
    """lib/stages/fold_guard.c in numpy. A clean input (here: bends correlated; the library also
    reads clean what its noise estimate finds within 1.4 times the shape's own residual, which
    none of the noisy cases is): a triangle turned by
    more than 90 degrees from the input's is turned over; a noisy one: a triangle facing against
    its neighbourhood in the result (the unit normals of the triangles at its corners, summed)
    that did not in the input. Each round moves the vertices of every turned-over
    triangle: on a noisy input first (`untangles` rounds) to the mean of the other corners of the
    triangles at the welded vertex (a boundary vertex: of its neighbours along the boundary, and
    no farther from the input than the filter put it), then halfway back toward the input (after `halvings` such
    rounds, snaps them and two rings of vertices around them to the input)."""
    out = out.copy()
    rep = weld(x_in)
    e = np.sort(rep[np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])], axis=1)
    e = e[e[:, 0] != e[:, 1]]
    edges, counts = np.unique(e, axis=0, return_counts=True)
    boundary = np.zeros(len(x_in), bool)  # welded vertices on an edge of one triangle
    border = edges[counts == 1]
    boundary[border.ravel()] = True
    reach = np.linalg.norm(out - x_in, axis=1)

    def unit(x):
        n = np.cross(x[faces[:, 1]] - x[faces[:, 0]], x[faces[:, 2]] - x[faces[:, 0]])
        length = np.linalg.norm(n, axis=1)
        ok = length > 0
        return np.where(ok[:, None], n / np.where(ok, length, 1)[:, None], 0), ok

    def facing(n):  # against the unit normals of the triangles at its corners, summed
        at_vertex = np.zeros_like(x_in)
        for c in range(3):
            np.add.at(at_vertex, faces[:, c], n)
        return np.sum(n * at_vertex[faces].sum(axis=1), axis=1)
    n_in, ok_in = unit(x_in)
    folded_in = facing(n_in) <= 0

    def turned(reading):
        n_out, ok_out = unit(out)
        ok = ok_in & ok_out
        clean = ok & (np.sum(n_out * n_in, axis=1) < 0)
        noisy = ok & ~folded_in & (facing(n_out) < 0)
        return {"clean": clean, "noisy": noisy, "either": clean | noisy}[reading]
    if not turned("either").any():
        return out
    reading = "clean" if shape_correlation(x_in, faces) >= 0.3 else "noisy"
    for round_ in itertools.count():
        bad = turned(reading)
        if not bad.any():
            return out
        if reading == "noisy" and round_ < untangles:
            marked = np.zeros(len(x_in), bool)
            marked[rep[faces[bad].ravel()]] = True
            r = rep[faces]
            total, count = np.zeros_like(x_in), np.zeros(len(x_in))
            for c in range(3):
                m = marked[r[:, c]]
                np.add.at(total, r[m, c], out[faces[m, (c + 1) % 3]] + out[faces[m, (c + 2) % 3]])
                np.add.at(count, r[m, c], 2)
            along, n_along = np.zeros_like(x_in), np.zeros(len(x_in))  # the boundary's: along it
            for a, b in ((0, 1), (1, 0)):
                np.add.at(along, border[:, a], out[border[:, b]])
                np.add.at(n_along, border[:, a], 1)
            total[boundary], count[boundary] = along[boundary], n_along[boundary]
            v = np.flatnonzero(marked[rep] & (count[rep] > 0))
            out[v] = total[rep[v]] / count[rep[v], None]
            d = out[v] - x_in[v]  # a boundary vertex no farther than the filter put it
            length = np.linalg.norm(d, axis=1)
            clamp = boundary[rep[v]] & (length > reach[v])
            out[v[clamp]] = x_in[v[clamp]] + d[clamp] * (reach[v[clamp]] / length[clamp])[:, None]
        elif round_ < untangles * (reading == "noisy") + halvings:
            v = np.unique(faces[bad])
            out[v] = x_in[v] + (out[v] - x_in[v]) / 2
        else:
            seed = np.zeros(len(x_in), bool)
            seed[faces[bad].ravel()] = True
            for _ in range(2):  # and two rings of vertices around
                seed[faces[seed[faces].any(axis=1)].ravel()] = True
            out[seed] = x_in[seed]


def blend(x_in, f_xyz, t_xyz, faces, level, low, high, rounds, parts=None):
    rep, tri, share, boundary = parts or vertex_shares(f_xyz, faces)
    s = spread(share, rep, tri, rounds)[rep]
    w = np.where(np.isnan(s), 1.0, np.clip((s - low) / (high - low), 0, 1))
    out = w[:, None] * f_xyz + (1 - w[:, None]) * t_xyz
    b = boundary[rep]
    limit = level * local_edges(x_in, rep, tri)[rep]
    d = out - x_in
    move = np.linalg.norm(d, axis=1)
    clamp = b & (move > limit)
    out[clamp] = x_in[clamp] + d[clamp] * (limit[clamp] / move[clamp])[:, None]
    return fold_guard(x_in, out, faces), float(w.mean())

