"""The learned stage through the keywords: stage="learned" runs the built-in model after the
guided cycles, model= takes another file (path or bytes), and a bad one is refused by name."""

from __future__ import annotations

import os

import numpy as np
import pytest

import rsmooth

from conftest import ROOT, box, noisy


@pytest.fixture(scope="module")
def cube():
    truth, f = box(16)
    return truth, noisy(truth, f, 0.3, seed=11), f


def learned(v, f, **kwargs):
    return rsmooth.smooth(v, f, device="reference", best=True, stage="learned", **kwargs)


def test_learned_stage_helps_and_differs(cube):
    truth, v, f = cube
    out, guided = learned(v, f), rsmooth.smooth(v, f, device="reference", best=True)
    assert out.shape == v.shape and np.all(np.isfinite(out))
    # the model's normals moved the vertices further than rounding would
    assert np.abs(out - guided).max() > 1e-3 * rsmooth.mean_edge_length(v, f)
    before, after = rsmooth.compare(v, truth, f), rsmooth.compare(out, truth, f)
    assert after["theta"] < 0.5 * before["theta"], (before, after)


def test_model_from_path_and_bytes_match_builtin(cube):
    _, v, f = cube
    path = os.path.join(ROOT, "models", "learned-normals.rsnn")
    if not os.path.exists(path):  # an installed package's tests without the source tree
        pytest.skip("models/learned-normals.rsnn is not beside the tests")
    builtin = learned(v, f)
    assert np.array_equal(learned(v, f, model=path), builtin)
    with open(path, "rb") as fh:
        assert np.array_equal(learned(v, f, model=fh.read()), builtin)


def test_bad_models_are_refused(cube, tmp_path):
    _, v, f = cube
    with pytest.raises(ValueError, match="not an rsmooth model"):
        learned(v, f, model=b"not a model at all")
    with pytest.raises(ValueError, match="cannot read"):
        learned(v, f, model=str(tmp_path / "missing.rsnn"))
    with pytest.raises(TypeError, match="model"):
        learned(v, f, model=3.5)
    with pytest.raises(ValueError, match="stage"):
        rsmooth.smooth(v, f, device="reference", best=True, stage="neural")
