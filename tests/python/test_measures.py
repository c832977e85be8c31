"""estimate_noise, compare and mean_edge_length against known answers and the command."""

from __future__ import annotations

import json
import subprocess

import numpy as np
import pytest

import rsmooth
from conftest import box, noisy, roof, write_obj


def test_compare_analytic():
    truth, f = roof(20)
    zero = rsmooth.compare(truth, truth, f)
    assert zero["theta"] == 0 and zero["ev"] == 0 and zero["rms_v"] == 0 and zero["hausdorff"] == 0
    edge = rsmooth.mean_edge_length(truth, f)
    assert zero["mean_edge"] == pytest.approx(edge)
    shifted = truth + [0.0, 0.0, 0.5 * edge]  # every vertex half an edge up
    m = rsmooth.compare(shifted, truth, f)
    assert m["rms_v"] == pytest.approx(0.5)
    assert m["theta"] == pytest.approx(0, abs=1e-6)
    assert m["bbox_diag"] == pytest.approx(np.linalg.norm(truth.max(0) - truth.min(0)))


def test_compare_equals_the_command(cli, tmp_path):
    truth, f = box(8)
    v = noisy(truth, f, 0.3)
    write_obj(tmp_path / "r.obj", v, f)
    write_obj(tmp_path / "t.obj", truth, f)
    r = subprocess.run([str(cli), "compare", str(tmp_path / "r.obj"), str(tmp_path / "t.obj"),
                        "--json"], check=True, capture_output=True, text=True)
    expected = json.loads(r.stdout)
    got = rsmooth.compare(v, truth, f)
    for key in ("theta", "ev", "rms_v", "hausdorff"):
        assert got[key] == pytest.approx(expected[key], rel=1e-9), key


def test_estimate_noise():
    truth, f = box(40)
    for sigma in (0.2, 0.4):
        rng = np.random.default_rng(1)
        n = np.zeros_like(truth)
        # noise along the face normal of each vertex's side (the estimate's definition)
        axis = np.argmax(np.abs(truth), axis=1)
        n[np.arange(len(truth)), axis] = rng.normal(0, sigma * rsmooth.mean_edge_length(truth, f),
                                                    len(truth))
        est = rsmooth.estimate_noise(truth + n, f)
        assert est == pytest.approx(sigma, rel=0.15), (sigma, est)
    assert rsmooth.estimate_noise(truth, f) < 0.02
