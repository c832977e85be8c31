"""Do no harm from Python: a clean mesh comes back unchanged under auto, a stray vertex is an
outlier that moves nothing else, parts and the fold guard are reported, and guard= is a keyword
(the C tests, tests/test_do_no_harm.c, check the figures on both paths)."""
import numpy as np
import pytest

import rsmooth
from conftest import box


@pytest.mark.parametrize("best", [False, True])
def test_clean_cube_unchanged_under_auto(best):
    v, f = box(1)  # Blender's default cube: 8 vertices
    report = rsmooth.auto_params(v, f, best=best)
    assert report["kind"] == "none" and report["preset"] == "clean", report
    out = rsmooth.smooth(v, f, auto=True, best=best, device="reference")
    assert np.array_equal(out, v)


def test_stray_vertex_is_held_and_moves_nothing_else():
    v, f = box(12)
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
    v, f = box(1)
    with rsmooth.Context() as ctx:
        ctx.smooth(v, f, best=True, guard=False)
        assert ctx.last_report["stage_skipped"] is False
        ctx.smooth(v, f, best=True)
        assert ctx.last_report["stage_skipped"] is True
        assert "guarded_vertices" in ctx.last_report
    # unguarded, the best mode's stage runs on the clean cube and folds it; guarded it keeps it
    folded = rsmooth.smooth(v, f, best=True, guard=False, device="reference")
    kept = rsmooth.smooth(v, f, best=True, device="reference")
    assert np.abs(folded - v).max() > 0.5
    assert np.abs(kept - v).max() < 0.01 * np.linalg.norm(v.max(0) - v.min(0))
