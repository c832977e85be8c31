"""A caller's own PyOpenCL queue and arrays: rsmooth.Context(queue=...) and Context.smooth on a
``pyopencl.array.Array``. PyOpenCL is never imported here: its objects are recognised by their
attributes (``int_ptr``, ``context``, ``device``; an array's ``base_data``, ``queue``...), so
rsmooth works without it and only a caller who passes its objects needs it."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Optional

import numpy as np

from . import _rsmooth
from ._arrays import _faces
from ._options import _filter_params, _progress_callable

if TYPE_CHECKING:  # pragma: no cover
    from ._context import Context


def _queue_pointer(queue: Any) -> int:
    """The cl_command_queue of a pyopencl.CommandQueue, or TypeError naming what is missing."""
    missing = [a for a in ("int_ptr", "context", "device") if not hasattr(queue, a)]
    if missing:
        raise TypeError(
            f"queue: expected a pyopencl.CommandQueue (with int_ptr, context and device), got "
            f"{type(queue).__module__}.{type(queue).__qualname__} without {', '.join(missing)}"
        )
    pointer = queue.int_ptr
    if not isinstance(pointer, int) or isinstance(pointer, bool):
        raise TypeError(f"queue: its int_ptr is {pointer!r}, not an int")
    return pointer


def _is_device_array(obj: Any) -> bool:
    """Whether `obj` is a pyopencl.array.Array (or a subclass), without importing pyopencl."""
    return any(
        c.__module__.startswith("pyopencl") and c.__name__ == "Array" for c in type(obj).__mro__
    ) and hasattr(obj, "base_data")


def _same_context(a: Any, b: Any) -> bool:
    return getattr(a, "int_ptr", None) == getattr(b, "int_ptr", None)


def _check_array(context: "Context", v: Any, name: str = "vertices") -> np.dtype:
    queue = context.queue
    if queue is None:
        raise ValueError(
            f"{name}: a pyopencl array needs a Context made on its queue "
            "(rsmooth.Context(queue=...)); this one has its own OpenCL context"
        )
    dtype = np.dtype(v.dtype)
    if dtype not in (np.dtype(np.float32), np.dtype(np.float64)):
        raise TypeError(f"{name}: a pyopencl array of float32 or float64, got {dtype}")
    if len(v.shape) != 2 or v.shape[1] != 3:
        raise ValueError(f"{name}: a pyopencl array of shape (n, 3), got {tuple(v.shape)}")
    if not v.flags.c_contiguous:
        raise ValueError(
            f"{name}: the pyopencl array is not C-contiguous (strides {v.strides}); pass a "
            "contiguous copy (e.g. pyopencl.array.empty + a copy kernel, or .copy() of a "
            "contiguous array)"
        )
    if getattr(v, "offset", 0):
        raise ValueError(
            f"{name}: the pyopencl array starts {v.offset} bytes into its buffer (a slice); "
            "pass one that starts at its buffer's beginning (e.g. its .copy())"
        )
    if v.base_data is None and v.size:
        raise ValueError(f"{name}: the pyopencl array has no buffer")
    if not _same_context(v.context, queue.context):
        raise ValueError(
            f"{name}: the pyopencl array belongs to another OpenCL context than the queue this "
            "rsmooth.Context runs on"
        )
    return dtype


def smooth_array(
    context: "Context",
    vertices: Any,
    faces: Any,
    *,
    confidence: bool = False,
    best: bool = False,
    auto: bool = False,
    colors: Any = None,
    mask: Any = None,
    method: str = "robust",
    progress: Any = False,
    **overrides: Any,
) -> Any:
    """Context.smooth on a pyopencl.array.Array: the result is a new array of the same shape and
    dtype on the context's queue (see docs/python.md, "Your own PyOpenCL context")."""
    dtype = _check_array(context, vertices)
    if confidence:
        raise ValueError(
            "confidence: not returned for a pyopencl array; smooth a numpy array for it"
        )
    if method not in ("robust", "gaussian"):
        raise ValueError(
            f"method {method!r}: only 'robust' and 'gaussian' run on a pyopencl array "
            "(the others run on the CPU: pass a numpy array)"
        )
    for key in ("iterations", "lam", "mu"):  # the CPU smoothers' keywords: meaningless here
        overrides.pop(key, None)
    queue = context.queue
    n = int(vertices.shape[0])
    if _is_device_array(faces):
        faces = faces.get()
    f = _faces(faces, n)
    # what the caller enqueued for the array (on its own queue too) comes first
    vertices.finish()
    if vertices.queue is not None and vertices.queue is not queue:
        vertices.queue.finish()
    # `auto` reads the noise from the positions: one more read to the host, for it alone
    host = vertices.get(queue) if auto else np.empty((0, 3), dtype=dtype)
    params = _filter_params(
        host, f, n, best=best, auto=auto, method=method, overrides=overrides,
        colors=colors.get() if _is_device_array(colors) else colors,
        mask=mask.get() if _is_device_array(mask) else mask,
    )
    import pyopencl.array as cl_array  # the caller passed an array: pyopencl is there

    out: Any = cl_array.empty(queue, (n, 3), dtype)  # (its base_data a buffer: made here)
    in_ptr = vertices.base_data.int_ptr if n else 0
    out_ptr = out.base_data.int_ptr if n else 0
    call, bar = _progress_callable(progress)
    try:
        if n:
            report: Optional[Any] = _rsmooth._smooth_cl(
                context._capsule, dtype == np.float64, in_ptr, n, f, out_ptr, params, call
            )
        else:
            report = None
    finally:
        if bar is not None:
            bar.close()
    context.last_report = report
    return out
