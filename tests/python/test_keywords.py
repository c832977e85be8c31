"""Every numeric keyword is checked by name before the library runs: whole
numbers in the command's ranges (the command is the oracle: it accepts and refuses the same
values), ValueError naming the keyword and its range outside them, however far (beyond a C
long too: nothing wraps); TypeError naming the keyword for a bool, a float or a string where a
whole number goes; NaN, infinities and negatives ValueError naming the keyword where a real
number goes."""

from __future__ import annotations

import subprocess

import numpy as np
import pytest

import rsmooth
from conftest import box, write_obj


@pytest.fixture(scope="module")
def tiny():
    v, f = box(1)  # 8 vertices: the longest runs below (a million Taubin steps) stay short
    return v + np.random.default_rng(4).normal(0, 0.05, v.shape), f


# keyword, the command's option, its range, keywords (and options) it needs beside it
COUNTS = [
    ("normal_iterations", "--normal-iterations", 1, 100, {}),
    ("passes", "--passes", 0, 100, {"vertex_updates": 1}),  # 0: the normal update stage alone
    ("vertex_updates", "--vertex-updates", 0, 1000, {}),
    ("guided_rounds", "--guided-rounds", 1, 100, {"vertex_updates": 1}),
    ("stage_repeats", "--stage-repeats", 1, 1000, {"vertex_updates": 1}),
    ("iterations", "--iterations", 0, 1_000_000, {"method": "taubin"}),
]


def option(key, value):
    return ["--" + key.replace("_", "-"), str(value)]


@pytest.mark.parametrize("key,flag,low,high,beside", COUNTS, ids=[c[0] for c in COUNTS])
def test_counts_have_the_commands_range(tiny, cli, tmp_path, key, flag, low, high, beside):
    v, f = tiny
    write_obj(tmp_path / "in.obj", v, f)
    for value in (high + 1, high, low, low - 1):  # (before the fix iterations -1 ran for hours)
        extra = [a for k, x in beside.items() for a in option(k, x)]
        command = subprocess.run(
            [str(cli), str(tmp_path / "in.obj"), "-o", str(tmp_path / "out.obj"), "--force",
             "--quiet", "--device", "reference", flag, str(value), *extra],
            capture_output=True, text=True,
        )
        try:
            rsmooth.smooth(v, f, device="reference", **{key: value}, **beside)
            accepted, said = True, ""
        except ValueError as e:
            accepted, said = False, str(e)
        assert accepted == (command.returncode == 0), (key, value, said, command.stderr)
        if not accepted:
            assert f"{key} must be in [{low}, {high}] (got {value})" in said, said


@pytest.mark.parametrize("key,flag,low,high,beside", COUNTS, ids=[c[0] for c in COUNTS])
def test_counts_refuse_what_would_wrap_or_truncate(tiny, key, flag, low, high, beside):
    v, f = tiny
    for value in (2**32, 2**64, 2**31, 2**63, 10**30, -(2**31) - 1, -(2**70)):
        with pytest.raises(ValueError, match=rf"^{key} must be in \[{low}, {high}\] \(got "):
            rsmooth.smooth(v, f, device="reference", **{key: value}, **beside)
    for value in (True, np.True_, float(low + 1), 2.5, "2", None if key == "iterations" else []):
        with pytest.raises(TypeError, match=rf"^{key} must be a whole number in \[{low}, {high}\]"):
            rsmooth.smooth(v, f, device="reference", **{key: value}, **beside)
    # numpy's integers are whole numbers: the same result as the Python int
    same = rsmooth.smooth(v, f, device="reference", **{key: low + 1}, **beside)
    for kind in (np.int64, np.uint8, np.int32):
        got = rsmooth.smooth(v, f, device="reference", **{key: kind(low + 1)}, **beside)
        assert np.array_equal(got, same), kind


def test_iterations_as_reported(tiny):
    """What the hostile-input campaign found: 2**32 returned the input unchanged (wrapped to 0),
    -1 ran 4.3e9 steps."""
    v, f = tiny
    with pytest.raises(ValueError, match=r"iterations must be in \[0, 1000000\] \(got 4294967296\)"):
        rsmooth.smooth(v, f, method="taubin", iterations=2**32)
    with pytest.raises(ValueError, match=r"iterations must be in \[0, 1000000\] \(got -1\)"):
        rsmooth.smooth(v, f, method="taubin", iterations=-1)
    with pytest.raises(ValueError, match=r"iterations must be in \[0, 1000000\]"):  # the private way in
        rsmooth._rsmooth._taubin(v, f.astype(np.uint32), np.empty_like(v), 0.5, -0.53, -1)
    with pytest.raises(ValueError, match=r"passes must be in \[0, 100\]"):
        rsmooth._rsmooth._smooth(None, v, f.astype(np.uint32), np.empty_like(v), None,
                                 {"passes": 2**40}, None)


# keyword, values the library takes beside the usual (infinity turns a weight off)
REALS = [
    ("sigma_f", ()), ("sigma_g", (float("inf"),)), ("cutoff", ()), ("mollify_cutoff", (0.0,)),
    ("normal_sigma_s", ()), ("normal_sigma_n", ()), ("pass_confidence", (0.0,)),
    ("sigma_c", (float("inf"),)), ("guided_sigma_s", ()), ("guided_sigma_n", ()),
    ("discrepancy_level", (0.0,)), ("lam", ()), ("mu", ()),
]


@pytest.mark.parametrize("key,allowed", REALS, ids=[r[0] for r in REALS])
def test_reals_are_checked_by_name(tiny, key, allowed):
    v, f = tiny
    beside = {"method": "taubin"} if key in ("lam", "mu") else {}
    if key == "sigma_c":
        beside["colors"] = np.full(v.shape, 0.5)
    bad = [float("nan"), float("-inf"), -2.0, 10**400, -(10**400)]
    bad += [] if key == "sigma_g" or key == "sigma_c" else [float("inf")]
    bad += [0.0] if key in ("lam", "mu") else []  # mu 0 is Laplacian's, not Taubin's
    for value in bad:
        with pytest.raises(ValueError, match=rf"^{key}\b") as info:
            rsmooth.smooth(v, f, device="reference", **{key: value}, **beside)
        assert "range" in str(info.value) or " in " in str(info.value) or "positive" in str(
            info.value), str(info.value)
    for value in ("0.5", True, np.False_, [0.5], 1j):
        with pytest.raises(TypeError, match=rf"^{key} must be a number"):
            rsmooth.smooth(v, f, device="reference", **{key: value}, **beside)
    usual = 0.5 if key not in ("mu",) else -0.5
    same = rsmooth.smooth(v, f, device="reference", **{key: usual}, **beside)
    for kind in (np.float64, np.float32):
        got = rsmooth.smooth(v, f, device="reference", **{key: kind(usual)}, **beside)
        assert np.array_equal(got, same), kind
    for value in allowed:
        rsmooth.smooth(v, f, device="reference", **{key: value}, **beside)


def test_smooth_points_counts_and_reals(tiny):
    v, _ = tiny
    n = v / np.linalg.norm(v, axis=1, keepdims=True)
    with pytest.raises(ValueError, match=r"^passes must be in \[0, 100\]"):
        rsmooth.smooth_points(v, n, passes=2**64)
    with pytest.raises(TypeError, match=r"^normal_iterations must be a whole number"):
        rsmooth.smooth_points(v, n, normal_iterations=True)
    with pytest.raises(ValueError, match=r"^sigma_f"):
        rsmooth.smooth_points(v, n, sigma_f=float("nan"))
    with pytest.raises(ValueError, match=r"^sigma_f"):
        rsmooth.smooth_points(v, n, sigma_f=10**400)


def test_device_and_progress_types(tiny):
    v, f = tiny
    with pytest.raises(TypeError, match=r"^device: expected a str or None, got 0"):
        rsmooth.smooth(v, f, device=0)
    with pytest.raises(TypeError, match=r"^device: expected a str or None"):
        rsmooth.Context(["cpu"])
    with pytest.raises(TypeError, match=r"^progress: expected True, False, None or a callable"):
        rsmooth.smooth(v, f, device="reference", progress=5)
