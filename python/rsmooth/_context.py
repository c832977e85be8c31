"""OpenCL devices and the reusable Context (the kernels built once)."""

from __future__ import annotations

from typing import Any, Dict, List, Optional

from . import _rsmooth


def devices() -> List[Dict[str, Any]]:
    """Every OpenCL device, in the order "P:D" device choices count them.

    Each is a dict: ``id`` ("P:D", what ``device=`` takes), ``platform``, ``device``, ``name``
    ("platform / device", which a name choice matches), ``type`` ("gpu", "cpu", "accel" or
    "other"), ``version``, ``compute_units``, ``global_memory`` (bytes). Empty where no OpenCL
    loader or platform exists.
    """
    return _rsmooth._devices()


def _check_device(device: Any) -> None:
    if device is not None and not isinstance(device, str):
        raise TypeError(f"device: expected a str or None, got {device!r}")


class Context:
    """An OpenCL device with rsmooth's kernels built on it, reusable across calls.

    ``device``: "auto" (first GPU, else first CPU device), "gpu", "cpu", "P:D" (see
    :func:`devices`), or part of a device's name; None reads the RSMOOTH_DEVICE environment
    variable. Creating one builds the kernels (PoCL caches the binaries on disk); keep it for
    many meshes. Raises :class:`DeviceError` when no OpenCL device matches.

    Threads may share a context: its calls run one at a time.

    ``queue``: a ``pyopencl.CommandQueue`` of your own instead of a device: the context runs on
    that queue (its OpenCL context and device), keeps a reference to it (``.queue``), and
    :meth:`smooth` also takes ``pyopencl.array.Array`` vertices on its OpenCL context and returns
    one (docs/python.md, "Your own PyOpenCL context"). Leave ``device`` out then.
    """

    def __init__(self, device: Optional[str] = "auto", *, queue: Any = None) -> None:
        #: The caller's pyopencl.CommandQueue this context runs on, or None.
        self.queue: Any = None
        if queue is not None:
            if device != "auto":
                raise TypeError(
                    f"Context: give a device or a queue, not both (device={device!r}); the "
                    "queue's device is the context's"
                )
            from ._pyopencl import _queue_pointer

            pointer = _queue_pointer(queue)
            self._capsule = _rsmooth._context_from_queue(pointer)
            self.queue = queue
        else:
            _check_device(device)
            if device == "reference":
                raise ValueError(
                    'Context: "reference" is the CPU path without OpenCL; '
                    'call rsmooth.smooth(..., device="reference") instead'
                )
            self._capsule = _rsmooth._context_create(device)
        self.device, self.build_ms, self.memory_budget = _rsmooth._context_info(self._capsule)
        #: Figures of the last filter run on this context (times in ms, sigmas in mesh units).
        self.last_report: Optional[Dict[str, Any]] = None

    def __repr__(self) -> str:
        state = "closed" if self._capsule is None else repr(self.device)
        on = ", queue=<caller's>" if self.queue is not None else ""
        return f"rsmooth.Context({state}{on})"

    def __enter__(self) -> "Context":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def close(self) -> None:
        """Releases the device's context and buffers now (else when garbage-collected)."""
        self._capsule = None
        self.queue = None

    def smooth(self, vertices: Any, faces: Any = None, **options: Any) -> Any:
        """:func:`rsmooth.smooth` on this context's device (same arguments but ``device``; a mesh
        object in, the same kind out).

        On a context made with ``queue=``, ``vertices`` may also be a ``pyopencl.array.Array``
        of shape (n, 3), float32 or float64, on the queue's OpenCL context: the result is then
        a new ``pyopencl.array.Array`` of the same shape and dtype on that queue (no
        ``confidence``; ``faces`` a host array or a pyopencl array).
        """
        if self._capsule is None:
            raise ValueError("this rsmooth.Context is closed")
        if "device" in options:
            raise TypeError("Context.smooth takes no device: the context is one")
        if type(vertices).__module__.startswith("pyopencl"):
            from ._pyopencl import _is_device_array, smooth_array

            if _is_device_array(vertices):
                return smooth_array(self, vertices, faces, **options)
        from ._filter import _mesh_input, _mesh_output, _smooth

        mesh = _mesh_input(vertices, faces, points=False)
        if mesh is not None:
            return _mesh_output(mesh, _smooth(self, mesh.vertices, mesh.faces, **options))
        return _smooth(self, vertices, faces, **options)
