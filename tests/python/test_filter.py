"""rsmooth.smooth against the C library: the reference path to 1e-12 against the command built
from the same sources, the OpenCL path within 1e-3 mean edge lengths of it and bit-identical
between calls; every dtype and stride; the keywords reach the library."""

from __future__ import annotations

import numpy as np
import pytest

import rsmooth
from conftest import box, noisy, read_obj_vertices, require_opencl, roof, write_obj


@pytest.fixture(scope="module")
def mesh():
    v, f = box(10)
    return noisy(v, f, 0.3, seed=3), f


def edge(v, f):
    return rsmooth.mean_edge_length(v, f)


def test_reference_equals_the_command(mesh, cli, tmp_path):
    import subprocess

    v, f = mesh
    write_obj(tmp_path / "noisy.obj", v, f)
    for extra, kwargs in (
        ([], {}),
        (["--sigma-f", "1.5", "--sigma-g", "0.7"], dict(sigma_f=1.5, sigma_g=0.7)),
        (["--best"], dict(best=True)),
        (["--best", "--auto"], dict(best=True, auto=True)),
        (["--influence", "tukey", "--passes", "2"], dict(influence="tukey", passes=2)),
        (["--method", "taubin", "--iterations", "5"], dict(method="taubin", iterations=5)),
    ):
        out = tmp_path / "out.obj"
        subprocess.run(
            [str(cli), str(tmp_path / "noisy.obj"), "-o", str(out), "--device", "reference",
             "--force", "--quiet", *extra],
            check=True,
        )
        expected = read_obj_vertices(out)
        got = rsmooth.smooth(v, f, device="reference", **kwargs)
        assert np.max(np.abs(got - expected)) <= 1e-12 * edge(v, f), extra


def test_opencl_agrees_with_reference_and_repeats(mesh):
    require_opencl()
    v, f = mesh
    ref = rsmooth.smooth(v, f, device="reference")
    with rsmooth.Context("auto") as ctx:
        a = ctx.smooth(v, f)
        b = ctx.smooth(v, f)
        assert ctx.last_report["device"] == ctx.device
    assert np.array_equal(a, b)  # bit-identical between calls
    assert np.max(np.linalg.norm(a - ref, axis=1)) <= 1e-3 * edge(v, f)
    best_ref = rsmooth.smooth(v, f, device="reference", best=True)
    best_cl = rsmooth.smooth(v, f, best=True)
    assert np.max(np.linalg.norm(best_cl - best_ref, axis=1)) <= 1e-3 * edge(v, f)


def test_kernels_built_once(mesh):
    """rsmooth.smooth keeps one context per device choice: the second call builds nothing."""
    require_opencl()
    from rsmooth import _filter

    v, f = mesh
    first = rsmooth.smooth(v, f, device="auto")
    before = _filter._shared_context.cache_info()
    assert np.array_equal(rsmooth.smooth(v, f, device="auto"), first)
    after = _filter._shared_context.cache_info()
    assert after.hits == before.hits + 1 and after.misses == before.misses


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_dtype_shape_and_strides(mesh, dtype):
    v64, f = mesh
    v = v64.astype(dtype)
    base = rsmooth.smooth(v, f, device="reference")
    assert base.dtype == dtype and base.shape == v.shape
    assert base is not v and not np.shares_memory(base, v)
    # Fortran order, a strided view into a wider array, reversed strides: the same result.
    wide = np.zeros((v.shape[0], 7), dtype=dtype)
    wide[:, 2:5] = v
    for variant in (np.asfortranarray(v), wide[:, 2:5], v[::-1][::-1]):
        assert np.array_equal(rsmooth.smooth(variant, f, device="reference"), base)
    # Every integer index type, and faces that are a strided view.
    for itype in (np.int32, np.int64, np.uint32, np.uint16, np.uint64, np.int16):
        assert np.array_equal(rsmooth.smooth(v, f.astype(itype), device="reference"), base)
    wide_f = np.zeros((f.shape[0], 5), dtype=np.int64)
    wide_f[:, 1:4] = f
    assert np.array_equal(rsmooth.smooth(v, wide_f[:, 1:4], device="reference"), base)
    # Lists work too (as the float64 arrays they become).
    assert np.array_equal(rsmooth.smooth(v.tolist(), f.tolist(), device="reference"),
                          rsmooth.smooth(np.array(v.tolist()), f, device="reference"))


def test_float32_close_to_float64(mesh):
    v, f = mesh
    a = rsmooth.smooth(v, f, device="reference")
    b = rsmooth.smooth(v.astype(np.float32), f, device="reference")
    assert np.max(np.abs(a - b)) < 1e-5 * np.max(np.abs(v))


def test_inputs_untouched(mesh):
    v, f = mesh
    v0, f0 = v.copy(), f.copy()
    rsmooth.smooth(v, f, device="reference", confidence=True)
    assert np.array_equal(v, v0) and np.array_equal(f, f0)


def test_confidence(mesh):
    v, f = mesh
    out, conf = rsmooth.smooth(v, f, device="reference", confidence=True)
    assert conf.dtype == np.float32 and conf.shape == (v.shape[0],)
    assert np.all((conf >= 0) & (conf <= 1))
    assert np.array_equal(out, rsmooth.smooth(v, f, device="reference"))


def test_smoothing_helps_and_keeps_the_edges():
    truth, f = box(20)
    v = noisy(truth, f, 0.3, seed=5)
    before = rsmooth.compare(v, truth, f)
    after = rsmooth.compare(rsmooth.smooth(v, f, device="reference"), truth, f)
    assert after["theta"] < 0.6 * before["theta"] and after["ev"] < 0.5 * before["ev"]
    # The isotropic baseline of the same width rounds the cube's edges: far larger E_v.
    gauss = rsmooth.compare(rsmooth.smooth(v, f, device="reference", method="gaussian"), truth, f)
    assert after["ev"] < 0.5 * gauss["ev"]


def test_keywords_reach_the_library(mesh):
    v, f = mesh
    base = rsmooth.smooth(v, f, device="reference")
    for kwargs in (
        dict(sigma_f=1.0), dict(sigma_g=float("inf")), dict(absolute=True, sigma_f=0.1),
        dict(cutoff=1.0), dict(mollify=False), dict(normal_filter="bilateral"),
        dict(normal_filter="bilateral", normal_sigma_n=0.2), dict(influence="huber"),
        dict(passes=2), dict(predictor="centroid"), dict(mollify_cutoff=1.0),
        dict(best=True), dict(auto=True), dict(method="laplacian"),
    ):
        assert not np.array_equal(rsmooth.smooth(v, f, device="reference", **kwargs), base), kwargs


def test_colors(mesh):
    v, f = mesh
    colors = np.where(v[:, :1] > 0, [[1.0, 0.0, 0.0]], [[0.0, 0.0, 1.0]])
    a = rsmooth.smooth(v, f, device="reference", colors=colors, sigma_c=0.1)
    b = rsmooth.smooth(v, f, device="reference", colors=(colors * 255).astype(np.uint8))
    assert np.allclose(a, b, atol=1e-6)
    off = rsmooth.smooth(v, f, device="reference", colors=colors, sigma_c=float("inf"))
    assert np.array_equal(off, rsmooth.smooth(v, f, device="reference"))
    assert not np.array_equal(a, off)


def test_progress_callable(mesh):
    v, f = mesh
    seen = []
    rsmooth.smooth(v, f, device="reference", progress=seen.append, best=True)
    assert seen and seen[-1] == 1.0 and seen == sorted(seen)


def test_progress_raising_at_the_end(mesh):
    """The last report (1.0) comes after the work; an exception raised there still propagates."""
    v, f = mesh

    def progress(fraction):
        if fraction == 1.0:
            raise RuntimeError("at the end")

    with pytest.raises(RuntimeError, match="at the end"):
        rsmooth.smooth(v, f, device="reference", progress=progress)
    with pytest.raises(RuntimeError, match="at the end"):
        rsmooth.smooth_points(v, v, progress=progress)


def test_progress_bar(mesh):
    pytest.importorskip("tqdm")
    v, f = mesh
    assert np.array_equal(rsmooth.smooth(v, f, device="reference", progress=True),
                          rsmooth.smooth(v, f, device="reference"))


def test_points():
    truth, f = roof(30)
    rng = np.random.default_rng(2)
    normals = np.tile([0.0, 0.0, 1.0], (truth.shape[0], 1))
    pts = truth + rng.normal(0, 0.01, truth.shape) * [0, 0, 1]
    out, out_n, conf = rsmooth.smooth_points(pts, normals, return_normals=True, confidence=True)
    assert out.shape == pts.shape and out_n.shape == pts.shape and conf.shape == (pts.shape[0],)
    assert np.allclose(np.linalg.norm(out_n, axis=1), 1.0)
    flat = np.abs(truth[:, 0]) > 0.3  # away from the ridge the truth is two planes
    assert np.sqrt(np.mean((out - truth)[flat, 2] ** 2)) < np.sqrt(np.mean((pts - truth)[flat, 2] ** 2))
    o32 = rsmooth.smooth_points(pts.astype(np.float32), normals.astype(np.float32))
    assert o32.dtype == np.float32 and np.max(np.abs(o32 - out)) < 1e-5
    assert rsmooth.point_spacing(truth) > 0


def test_mask(mesh):
    """Only the selected vertices move; with one pass they move exactly as without a mask (the
    filter's: the fold guard may pull back a triangle the selection's border folds)."""
    v, f = mesh
    selected = v[:, 0] > 0
    full = rsmooth.smooth(v, f, device="reference", guard=False)
    out = rsmooth.smooth(v, f, device="reference", mask=selected, guard=False)
    assert np.array_equal(out[~selected], v[~selected])
    assert np.array_equal(out[selected], full[selected])
    out32 = rsmooth.smooth(v.astype(np.float32), f, device="reference", mask=selected.astype(int),
                           best=True)
    assert np.array_equal(out32[~selected], v.astype(np.float32)[~selected])
    pts = rsmooth.smooth_points(v, v / np.linalg.norm(v, axis=1, keepdims=True), mask=selected)
    assert np.array_equal(pts[~selected], v[~selected])
    with pytest.raises(ValueError, match="mask"):
        rsmooth.smooth(v, f, device="reference", mask=selected[:-1])
