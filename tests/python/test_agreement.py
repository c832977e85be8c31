"""One figure per file, one key per figure: the command's --json, `rsmooth compare --json` and
Python's measures agree on a mesh the suite makes (the oracle: numpy's mean over the unique
undirected edges, computed here)."""

from __future__ import annotations

import json
import subprocess
import warnings

import numpy as np
import pytest

import rsmooth
from conftest import box, noisy, roof, write_obj


def unique_edge_mean(v: np.ndarray, f: np.ndarray) -> float:
    """numpy's mean length of the unique undirected edges (one shared by two triangles: once)."""
    edges = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    edges = np.unique(np.sort(edges, axis=1), axis=0)
    return float(np.linalg.norm(v[edges[:, 0]] - v[edges[:, 1]], axis=1).mean())


@pytest.mark.parametrize("shape", ["box", "roof"])  # closed, and open with a boundary
def test_mean_edge_length_is_one_figure(cli, tmp_path, shape):
    clean, f = box(10) if shape == "box" else roof(20)
    v = noisy(clean, f, 0.3, seed=7)
    path = tmp_path / "noisy.obj"
    write_obj(path, v, f)
    oracle = unique_edge_mean(v, f)
    run = subprocess.run(
        [str(cli), str(path), "-o", str(tmp_path / "out.obj"), "--json", "--device", "reference"],
        capture_output=True, text=True, check=True,
    )
    command = json.loads(run.stdout)["mean_edge_length"]
    run = subprocess.run([str(cli), "compare", str(path), str(path), "--json"],
                         capture_output=True, text=True, check=True)
    compared = json.loads(run.stdout)["mean_edge"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        report = rsmooth.auto_params(v, f)
    figures = {
        "command --json": command,
        "compare --json": compared,
        "rsmooth.mean_edge_length": rsmooth.mean_edge_length(v, f),
        "rsmooth.compare": rsmooth.compare(v, v, f)["mean_edge"],
        "rsmooth.auto_params": report["mean_edge_length"],
    }
    assert oracle == pytest.approx(figures["rsmooth.mean_edge_length"], rel=1e-12)
    # the same file, the same bits: the OBJ holds v to the last bit (repr), and the command prints
    # 17 digits
    assert len(set(figures.values())) == 1, figures
    # the clean mesh's estimate has a name of its own, near the clean mesh's edge
    assert report["clean_mean_edge_length"] != report["mean_edge_length"]
    assert report["clean_mean_edge_length"] == pytest.approx(unique_edge_mean(clean, f), rel=0.1)


def test_compare_keys_are_the_commands(cli, tmp_path):
    truth, f = box(8)
    v = noisy(truth, f, 0.2, seed=2)
    write_obj(tmp_path / "result.obj", v, f)
    write_obj(tmp_path / "truth.obj", truth, f)
    run = subprocess.run(
        [str(cli), "compare", str(tmp_path / "result.obj"), str(tmp_path / "truth.obj"), "--json"],
        capture_output=True, text=True, check=True,
    )
    command = json.loads(run.stdout)
    python = rsmooth.compare(v, truth, f)
    old = {"faces"}  # the command's old key, kept until 0.12
    old_python = {"vertex_count", "triangle_count"}  # Python's, kept until 0.12
    assert set(command) - old == set(python) - old_python, (command, python)
    assert python["vertices"] == command["vertices"] == len(v)
    assert python["triangles"] == command["triangles"] == len(f)
    assert python["vertex_count"] == len(v) and python["triangle_count"] == len(f)
    assert command["faces"] == len(f)
    for key in ("theta", "ev", "rms_v", "hausdorff", "mean_edge", "bbox_diag"):
        assert python[key] == pytest.approx(command[key], rel=1e-9, abs=1e-12), key
