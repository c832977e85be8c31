"""Bad arguments raise ValueError or TypeError with the library's message; devices that do not
exist raise DeviceError; nothing is written on failure."""

from __future__ import annotations

import numpy as np
import pytest

import rsmooth
from conftest import box, noisy


@pytest.fixture(scope="module")
def mesh():
    v, f = box(4)
    return noisy(v, f, 0.2), f


def test_face_indices_are_checked(mesh):
    v, f = mesh
    bad = f.copy()
    bad[7, 1] = -1
    with pytest.raises(ValueError, match=r"face 7 has index -1 at corner 1"):
        rsmooth.smooth(v, bad, device="reference")
    bad[7, 1] = v.shape[0]
    with pytest.raises(ValueError, match=rf"face 7 has index {v.shape[0]}.*outside 0\.\.{v.shape[0] - 1}"):
        rsmooth.smooth(v, bad, device="reference")
    big = f.astype(np.uint64)
    big[3, 0] = 2**40  # would wrap to a small index as uint32
    with pytest.raises(ValueError, match="face 3"):
        rsmooth.smooth(v, big, device="reference")


def test_shapes_and_types(mesh):
    v, f = mesh
    with pytest.raises(ValueError, match=r"vertices: expected shape \(n, 3\)"):
        rsmooth.smooth(v[:, :2], f, device="reference")
    with pytest.raises(ValueError, match=r"faces: expected shape \(m, 3\)"):
        rsmooth.smooth(v, f.reshape(-1, 6), device="reference")
    with pytest.raises(TypeError, match="not a floating-point dtype"):
        rsmooth.smooth(v.astype(np.int64), f, device="reference")
    with pytest.raises(TypeError, match="integer"):
        rsmooth.smooth(v, f.astype(np.float64), device="reference")
    with pytest.raises(ValueError, match="no vertices"):
        rsmooth.smooth(np.zeros((0, 3)), f[:0], device="reference")


def test_library_messages(mesh):
    v, f = mesh
    nan = v.copy()
    nan[5, 2] = np.nan
    with pytest.raises(ValueError, match="vertex 5"):
        rsmooth.smooth(nan, f, device="reference")
    with pytest.raises(ValueError, match="sigma_f must be positive"):
        rsmooth.smooth(v, f, device="reference", sigma_f=-1)
    with pytest.raises(ValueError, match="cutoff"):
        rsmooth.smooth(v, f, device="reference", cutoff=9)
    with pytest.raises(ValueError, match="influence: expected one of"):
        rsmooth.smooth(v, f, device="reference", influence="cauchy")
    with pytest.raises(ValueError, match="method"):
        rsmooth.smooth(v, f, device="reference", method="magic")
    with pytest.raises(ValueError, match="colors"):
        rsmooth.smooth(v, f, device="reference", colors=np.zeros((3, 3)))
    with pytest.raises(ValueError, match="truth"):
        rsmooth.compare(v, v[:-1], f)


def test_unknown_device(mesh):
    v, f = mesh
    with pytest.raises(rsmooth.DeviceError) as info:
        rsmooth.smooth(v, f, device="no-such-device-anywhere")
    assert "no-such-device-anywhere" in str(info.value)
    assert issubclass(rsmooth.DeviceError, RuntimeError)
    with pytest.raises(ValueError, match="reference"):
        rsmooth.Context("reference")


def test_closed_context(mesh):
    from conftest import require_opencl

    require_opencl()
    v, f = mesh
    ctx = rsmooth.Context()
    ctx.close()
    with pytest.raises(ValueError, match="closed"):
        ctx.smooth(v, f)
    assert "closed" in repr(ctx)


def test_devices_listing():
    for d in rsmooth.devices():
        assert d["id"] == f"{d['platform']}:{d['device']}"
        assert d["type"] in ("gpu", "cpu", "accel", "other")
        assert d["name"] and d["global_memory"] > 0
