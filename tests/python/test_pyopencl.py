"""rsmooth on a caller's own PyOpenCL queue: rsmooth.Context(queue=q) gives the same bits as
rsmooth's own context on the same device, smooths pyopencl arrays into a pyopencl array on that
queue (usable there by the caller's kernels), and refuses wrong queues and arrays by name.

PyOpenCL's wheel carries its own ICD loader (ocl-icd), which reads /etc/OpenCL/vendors as the
system's does, so Debian's pocl-opencl-icd serves both; rsmooth opens the system's
libOpenCL.so.1 meanwhile, and the handles pass between the two loaders (ICD dispatch)."""

from __future__ import annotations

import numpy as np
import pytest

import rsmooth
from conftest import box, noisy

cl = pytest.importorskip("pyopencl")
cl_array = pytest.importorskip("pyopencl.array")


def _cpu_queue():
    """A queue of PyOpenCL's own on a CPU device (PoCL), or a skip saying why there is none."""
    try:
        platforms = cl.get_platforms()
    except cl.Error as e:  # no ICD at all
        pytest.skip(f"pyopencl finds no OpenCL platform ({e})")
    for platform in platforms:
        try:
            devices = platform.get_devices(device_type=cl.device_type.CPU)
        except cl.Error:
            continue
        if devices:
            context = cl.Context([devices[0]])
            return cl.CommandQueue(context)
    pytest.skip("pyopencl finds no CPU OpenCL device (PoCL) to compare with device='cpu'")


@pytest.fixture(scope="module")
def queue():
    return _cpu_queue()


@pytest.fixture(scope="module")
def ctx(queue):
    with rsmooth.Context(queue=queue) as c:
        yield c


@pytest.fixture(scope="module")
def mesh():
    v, f = box(14)
    return noisy(v, f, 0.3, seed=5).astype(np.float32), f


def test_context_on_the_queue(ctx, queue):
    assert ctx.queue is queue
    assert "queue=" in repr(ctx)
    assert ctx.device  # "platform / device", from the queue's device


def test_numpy_same_bits_as_own_context(ctx, mesh):
    v, f = mesh
    got = ctx.smooth(v, f)
    expected = rsmooth.smooth(v, f, device="cpu")
    assert got.dtype == np.float32
    np.testing.assert_array_equal(got, expected)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_pyopencl_array_in_and_out(ctx, queue, mesh, dtype):
    v, f = mesh
    v = v.astype(dtype)
    d_in = cl_array.to_device(queue, v)
    d_out = ctx.smooth(d_in, f)
    assert isinstance(d_out, cl_array.Array)
    assert d_out.shape == v.shape and d_out.dtype == np.dtype(dtype)
    assert d_out.queue is queue
    np.testing.assert_array_equal(d_out.get(), ctx.smooth(v, f))
    np.testing.assert_array_equal(d_in.get(), v)  # the input is left as it was
    assert ctx.last_report["vertex_count"] == len(v)


def test_result_usable_on_the_queue(ctx, queue, mesh):
    v, f = mesh
    d_in = cl_array.to_device(queue, v)
    d_out = ctx.smooth(d_in, cl_array.to_device(queue, f.astype(np.int32)))  # faces on device
    expected = ctx.smooth(v, f)
    # an elementwise op of pyopencl.array, and a kernel of the caller's own, on the same queue
    moved = (d_out - d_in).get()
    np.testing.assert_array_equal(moved, expected - v)
    program = cl.Program(
        queue.context,
        "__kernel void norm2(__global const float *p, __global float *out) {"
        " int i = get_global_id(0);"
        " out[i] = p[3*i] * p[3*i] + p[3*i+1] * p[3*i+1] + p[3*i+2] * p[3*i+2]; }",
    ).build()
    norms = cl_array.empty(queue, len(v), np.float32)
    program.norm2(queue, (len(v),), None, d_out.data, norms.data)
    np.testing.assert_allclose(norms.get(), (expected.astype(np.float64) ** 2).sum(1), rtol=1e-5)


def test_options_on_device_arrays(ctx, queue, mesh):
    v, f = mesh
    d_in = cl_array.to_device(queue, v)
    for options in (
        dict(sigma_f=1.5, sigma_g=0.4),
        dict(normal_filter="bilateral", influence="tukey"),
        dict(passes=2),  # uploaded from the host's result
        dict(mask=np.arange(len(v)) % 2 == 0),
        dict(method="gaussian"),
    ):
        np.testing.assert_array_equal(  # the same bits, whichever way the result went
            ctx.smooth(d_in, f, **options).get(), ctx.smooth(v, f, **options),
            err_msg=str(options),
        )


def test_bad_queues():
    with pytest.raises(TypeError, match="pyopencl.CommandQueue"):
        rsmooth.Context(queue=object())
    q = _cpu_queue()
    with pytest.raises(TypeError, match="not both"):
        rsmooth.Context("cpu", queue=q)


def test_bad_arrays(ctx, queue, mesh):
    v, f = mesh
    with pytest.raises(TypeError, match="float32 or float64"):
        ctx.smooth(cl_array.to_device(queue, v.astype(np.int32)), f)
    with pytest.raises(ValueError, match=r"shape \(n, 3\)"):
        ctx.smooth(cl_array.to_device(queue, v.reshape(-1)), f)
    wide = cl_array.to_device(queue, np.zeros((len(v), 6), np.float32))
    with pytest.raises(ValueError, match="C-contiguous"):
        ctx.smooth(wide[:, :3], f)
    with pytest.raises(ValueError, match="starts"):
        ctx.smooth(cl_array.to_device(queue, np.vstack([v, v]))[len(v):], f)
    with pytest.raises(ValueError, match="confidence"):
        ctx.smooth(cl_array.to_device(queue, v), f, confidence=True)
    # an array of another OpenCL context (same device)
    other = cl.CommandQueue(cl.Context([queue.device]))
    with pytest.raises(ValueError, match="another OpenCL context"):
        ctx.smooth(cl_array.to_device(other, v), f)
    # bad faces: the library's message
    bad = f.copy()
    bad[3, 1] = len(v)
    with pytest.raises(ValueError, match="face"):
        ctx.smooth(cl_array.to_device(queue, v), bad)


def test_array_needs_a_queue_context(queue, mesh):
    v, f = mesh
    with rsmooth.Context("cpu") as own:
        with pytest.raises(ValueError, match="queue="):
            own.smooth(cl_array.to_device(queue, v), f)
