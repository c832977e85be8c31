"""Do no harm from Python: a clean mesh comes back unchanged under auto, a stray vertex is an
outlier that moves nothing else, parts and the fold guard are reported, and guard= is a keyword
(the C tests, tests/test_do_no_harm.c, check the figures on both paths)."""
import numpy as np
import pytest

import rsmooth


def cube(n=4, size=2.0):
    """The surface lattice of an n x n x n cube, outward triangles (as host/mesh_shapes.c's)."""
    verts, index, faces = [], {}, []
    for axis in range(3):
        for side in (0, 1):
            u, w = (axis + 1) % 3, (axis + 2) % 3
            first, second = (u, w) if side else (w, u)
            ids = np.zeros((n + 1, n + 1), dtype=np.int64)
            for j in range(n + 1):
                for i in range(n + 1):
                    lat = [0, 0, 0]
                    lat[axis] = n if side else 0
                    lat[first], lat[second] = i, j
                    key = tuple(lat)
                    if key not in index:
                        index[key] = len(verts)
                        verts.append([-size / 2 + size * k / n for k in lat])
                    ids[j, i] = index[key]
            for j in range(n):
                for i in range(n):
                    a, b, c, d = ids[j, i], ids[j, i + 1], ids[j + 1, i + 1], ids[j + 1, i]
                    faces += [(a, b, c), (a, c, d)]
    return np.array(verts), np.array(faces)


@pytest.mark.parametrize("best", [False, True])
def test_clean_cube_unchanged_under_auto(best):
    v, f = cube(1)  # Blender's default cube: 8 vertices
    report = rsmooth.auto_params(v, f, best=best)
    assert report["kind"] == "none" and report["preset"] == "clean", report
    out = rsmooth.smooth(v, f, auto=True, best=best, device="reference")
    assert np.array_equal(out, v)


def test_stray_vertex_is_held_and_moves_nothing_else():
    v, f = cube(12)
    clean = rsmooth.smooth(v, f, device="reference")
    stray = int(np.argmin(np.linalg.norm(v - [1, 0, 0], axis=1)))
    w = v.copy()
    w[stray, 0] += 1e4
    with rsmooth.Context() as ctx:
        out = ctx.smooth(w, f)
        assert ctx.last_report["outliers"] == 1
        assert ctx.last_report["parts"] >= 1
    assert np.array_equal(out[stray], w[stray])
    others = np.arange(len(v)) != stray
    assert np.abs(out[others] - clean[others]).max() < 0.05 * (2 / 12)


def test_guard_keyword_and_report():
    v, f = cube(1)
    with rsmooth.Context() as ctx:
        ctx.smooth(v, f, best=True, guard=False)
        assert ctx.last_report["stage_skipped"] is False
        ctx.smooth(v, f, best=True)
        assert ctx.last_report["stage_skipped"] is True
        assert "guarded_vertices" in ctx.last_report
    with pytest.raises((TypeError, ValueError)):
        rsmooth.smooth(v, f, guard=2, device="reference")
