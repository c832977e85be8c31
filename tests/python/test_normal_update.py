"""The normal update stage (guided normal filtering, then Sun et al.'s vertex update) through the
keywords, and auto_params: what ``auto=True`` reads from a mesh and chooses."""

from __future__ import annotations

import math
import sys

import numpy as np
import pytest

import rsmooth

from conftest import ROOT, box, noisy, require_opencl, roof


@pytest.fixture(scope="module")
def cube():
    truth, f = box(16)
    return truth, noisy(truth, f, 0.3, seed=7), f


def stage(v, f, **kwargs):
    return rsmooth.smooth(v, f, device="reference", vertex_updates=20, passes=0, **kwargs)


def test_stage_alone_moves_and_helps(cube):
    truth, v, f = cube
    out, conf = stage(v, f, confidence=True)
    assert out.shape == v.shape and out.dtype == v.dtype and np.all(np.isfinite(out))
    assert not np.array_equal(out, v)
    before, after = rsmooth.compare(v, truth, f), rsmooth.compare(out, truth, f)
    # the guided filter keeps the cube's creases: far lower normal error, and closer vertices
    assert after["theta"] < 0.4 * before["theta"], (before, after)
    assert after["ev"] < 0.7 * before["ev"], (before, after)
    assert np.all(conf == 1)  # the stage alone: confidences 1
    # float32 in, float32 out, close to the float64 result
    out32 = stage(v.astype(np.float32), f)
    assert out32.dtype == np.float32
    assert np.allclose(out32, out, atol=1e-4)


def test_stage_then_passes_differs_from_stage_alone(cube):
    _, v, f = cube
    alone = stage(v, f)
    with_pass = rsmooth.smooth(v, f, device="reference", vertex_updates=20, passes=1)
    assert not np.array_equal(alone, with_pass)


def test_guided_keywords_reach_the_library(cube):
    _, v, f = cube
    base = stage(v, f)
    for kwargs in (
        dict(guided_sigma_s=1.0), dict(guided_sigma_n=0.35), dict(guided_rounds=5),
    ):
        assert not np.array_equal(stage(v, f, **kwargs), base), kwargs
    assert not np.array_equal(rsmooth.smooth(v, f, device="reference", vertex_updates=5,
                                             passes=0), base)


def test_cycles_and_radius_reach_the_library(cube):
    _, v, f = cube
    width = dict(absolute=True, guided_sigma_s=0.3, guided_rounds=1)
    once = stage(v, f, **width)
    thrice = stage(v, f, stage_repeats=3, **width)
    assert not np.array_equal(thrice, once)
    # the neighbour sets are the input's in every cycle: not three chained one-cycle calls
    assert not np.array_equal(thrice, stage(stage(once, f, **width), f, **width))
    assert not np.array_equal(stage(v, f, stage_repeats=3, guided_radius=3.0, **width), thrice)


def ball(n: int = 10):
    """The box's vertices pushed onto its circumscribed sphere: curved at the scale of its
    triangles everywhere, where the guard hands over to Taubin smoothing."""
    v, f = box(n)
    c = v.mean(axis=0)
    d = v - c
    return c + d / np.linalg.norm(d, axis=1, keepdims=True), f


def discrepancy_iterations(v, f, level):
    """The discrepancy principle, computed here: the fewest Taubin iterations that move the
    vertices (RMS) as far as `level` mean edge lengths (at most 40)."""
    unit = rsmooth.mean_edge_length(v, f)
    for k in range(1, 41):
        t = rsmooth.smooth(v, f, method="taubin", iterations=k)
        if np.sqrt(np.mean(np.sum((t - v) ** 2, axis=1))) >= level * unit:
            return k, t
    return 40, t


def test_region_choice_against_numpy():
    """The library's choice per region equals region_blend.py's independent numpy blend
    at the library's bounds, on one mesh of a box (flat faces and creases: the filter's result)
    and a ball (curved at triangle scale: Taubin's), and each part goes its own way."""
    sys.path.insert(0, str(ROOT / "tests" / "python"))
    from region_blend import LIBRARY, blend

    bv, bf = box(10)
    gv, gf = ball(8)
    v = np.concatenate([bv, gv + [4.0, 0, 0]])
    f = np.concatenate([bf, gf + len(bv)])
    v = noisy(v, f, 0.3, seed=9)
    level = 0.15
    # F as blend() takes it: before the choice and the fold guard (which blend() runs after it)
    filtered = rsmooth.smooth(v, f, device="reference", best=True, guard=False)
    chosen = rsmooth.smooth(v, f, device="reference", best=True, discrepancy_level=level)
    _, taubin = discrepancy_iterations(v, f, level)
    expected, share = blend(v, filtered, taubin, f, level, *LIBRARY)
    unit = rsmooth.mean_edge_length(v, f)
    assert np.abs(chosen - expected).max() < 1e-9 * unit
    # the box's vertices lean to the filter's result, the ball's are Taubin's
    to_f = np.linalg.norm(chosen - filtered, axis=1)
    to_t = np.linalg.norm(chosen - taubin, axis=1)
    on_box = np.mean(to_f[: len(bv)] < to_t[: len(bv)])
    on_ball = np.all(chosen[len(bv):] == taubin[len(bv):], axis=1).mean()
    assert on_box > 0.7 and on_ball > 0.9, (on_box, on_ball)  # (a coarse box: 10 x 10)


def test_discrepancy_iterations_in_the_report():
    require_opencl()
    truth, f = ball(8)
    v = noisy(truth, f, 0.3, seed=2)
    with rsmooth.Context() as ctx:
        ctx.smooth(v, f, best=True, discrepancy_level=0.1)
        assert ctx.last_report["discrepancy_iterations"] >= 1
        ctx.smooth(v, f, best=True)
        assert ctx.last_report["discrepancy_iterations"] == 0
        stage = ctx.last_report["stage"]  # where the normal-update stage ran, and its cycles
        assert stage["cycles"] == 10 and stage["float_bits"] in (32, 64), stage
        assert stage["on_device"] == (stage["bytes_to_device"] > 0), stage


def test_none_means_the_modes_default(cube):
    _, v, f = cube
    # the library's defaults: guided_sigma_s 2, guided_sigma_n 0.2, guided_rounds 20
    assert np.array_equal(
        stage(v, f, guided_sigma_s=None, guided_sigma_n=None, guided_rounds=None),
        stage(v, f, guided_sigma_s=2.0, guided_sigma_n=0.2, guided_rounds=20),
    )
    # best: the stage (10 cycles of 1 guided round, radius 3, spatial width 1, and 10 updates),
    # then one pass; None keeps them
    best = rsmooth.smooth(v, f, device="reference", best=True, vertex_updates=None)
    assert np.array_equal(
        best, rsmooth.smooth(v, f, device="reference", best=True, vertex_updates=10,
                             guided_rounds=1, stage_repeats=10, guided_radius=3.0,
                             guided_sigma_s=1.0, passes=1)
    )
    assert not np.array_equal(
        best, rsmooth.smooth(v, f, device="reference", best=True, vertex_updates=0)
    )
    # off by default: vertex_updates=0 is the paper's filter
    assert np.array_equal(
        rsmooth.smooth(v, f, device="reference", vertex_updates=0),
        rsmooth.smooth(v, f, device="reference"),
    )


def test_no_pass_returns_the_input():
    """passes=0 without the stage runs nothing (what auto sets on a mesh that reads clean)."""
    v, f = roof(8)
    assert np.array_equal(rsmooth.smooth(v, f, device="reference", passes=0), v)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(vertex_updates=-1), "vertex_updates"),
        (dict(vertex_updates=1001), "vertex_updates"),
        (dict(passes=-1), "passes"),
        (dict(vertex_updates=5, passes=-1), "passes"),
        (dict(vertex_updates=5, guided_sigma_s=0.0), "guided_sigma_s"),
        (dict(vertex_updates=5, guided_sigma_s=math.inf), "guided_sigma_s"),
        (dict(vertex_updates=5, guided_sigma_n=0.0), "guided_sigma_n"),
        (dict(vertex_updates=5, guided_sigma_n=2.5), "guided_sigma_n"),
        (dict(vertex_updates=5, guided_sigma_n=math.nan), "guided_sigma_n"),
        (dict(vertex_updates=5, guided_rounds=0), "guided_rounds"),
        (dict(vertex_updates=5, guided_rounds=101), "guided_rounds"),
        (dict(vertex_updates=5, stage_repeats=0), "stage_repeats"),
        (dict(vertex_updates=5, stage_repeats=1001), "stage_repeats"),
        (dict(vertex_updates=5, guided_radius=0.5), "guided_radius"),
        (dict(vertex_updates=5, guided_radius=9.0), "guided_radius"),
        (dict(discrepancy_level=-1.0), "discrepancy_level"),
        (dict(discrepancy_level=0.1, discrepancy_gain=-0.01), "discrepancy_gain"),
        (dict(discrepancy_level=0.1, discrepancy_gain=math.nan), "discrepancy_gain"),
        (dict(discrepancy_level=math.inf), "discrepancy_level"),
    ],
)
def test_bad_values(kwargs, match):
    v, f = roof(8)
    with pytest.raises(ValueError, match=match):
        rsmooth.smooth(v, f, device="reference", **kwargs)


def test_auto_params_reads_gaussian_noise():
    truth, f = box(30)
    v = noisy(truth, f, 0.3, seed=3)
    paper = rsmooth.auto_params(v, f)
    assert paper["kind"] == "gaussian", paper
    assert paper["impulsive_fraction"] == 1.0
    assert 0.2 < paper["level"] < 0.4, paper
    # noise in every direction: the tangential part about the normal one
    assert 0.15 < paper["tangential_level"] < 0.45, paper
    edge = rsmooth.mean_edge_length(truth, f)
    assert paper["clean_mean_edge_length"] == pytest.approx(edge, rel=0.1)
    assert paper["mean_edge_length"] == rsmooth.mean_edge_length(v, f)  # the mesh's as given
    assert paper["preset"] == "paper"
    assert "Gaussian" in paper["reason"] and "sigma_f" in paper["reason"]
    assert paper["params"]["sigma_f"] == pytest.approx(0.6 + 1.6 * paper["level"])
    assert paper["params"]["sigma_g"] == pytest.approx(4.0 * paper["level"])
    assert paper["params"]["vertex_updates"] == 0

    best = rsmooth.auto_params(v.astype(np.float32), f, best=True)
    assert best["kind"] == "gaussian"
    assert best["preset"].startswith("best"), best
    assert best["params"]["vertex_updates"] > 0
    assert best["params"]["normal_filter"] == "bilateral"

    # the chosen keywords are exactly what auto=True runs
    for report, mode in ((paper, dict()), (best, dict(best=True))):
        assert np.array_equal(
            rsmooth.smooth(v, f, device="reference", **report["params"]),
            rsmooth.smooth(v, f, device="reference", auto=True, **mode),
        ), report["preset"]
    # vertex_updates given with auto picks the best mode's rule (as --vertex-updates does), and
    # wins over it
    assert np.array_equal(
        rsmooth.smooth(v, f, device="reference", auto=True, vertex_updates=10),
        rsmooth.smooth(v, f, device="reference", **dict(best["params"], vertex_updates=10)),
    )


def test_auto_params_reads_impulsive_noise():
    # half the vertices thrown along their side's normal by 0.5 mean edge lengths, the others
    # exact (as rsmooth noise --impulsive 0.5 does; the setting the C suite asserts)
    truth, f = box(40)
    rng = np.random.default_rng(11)
    edge = rsmooth.mean_edge_length(truth, f)
    axis = np.argmax(np.abs(truth), axis=1)
    thrown = np.nonzero(rng.random(len(truth)) < 0.5)[0]
    v = truth.copy()
    v[thrown, axis[thrown]] += rng.normal(0.0, 0.5 * edge, len(thrown))
    report = rsmooth.auto_params(v, f, best=True)
    assert report["kind"] == "impulsive", report
    assert 0.3 < report["impulsive_fraction"] < 0.8, report
    assert report["preset"] == "best: impulsive"
    assert "impulsive" in report["reason"]


def test_auto_params_errors():
    v, f = roof(8)
    with pytest.raises(ValueError, match="vertex 2"):
        bad = v.copy()
        bad[2, 0] = np.inf
        rsmooth.auto_params(bad, f)
    with pytest.raises(TypeError):
        rsmooth.auto_params(v, f, True)  # best is keyword-only
