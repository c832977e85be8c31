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
    """

    def __init__(self, device: Optional[str] = "auto") -> None:
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
        return f"rsmooth.Context({state})"

    def __enter__(self) -> "Context":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def close(self) -> None:
        """Releases the device's context and buffers now (else when garbage-collected)."""
        self._capsule = None

    def smooth(self, vertices: Any, faces: Any = None, **options: Any) -> Any:
        """:func:`rsmooth.smooth` on this context's device (same arguments but ``device``; a mesh
        object in, the same kind out)."""
        if self._capsule is None:
            raise ValueError("this rsmooth.Context is closed")
        if "device" in options:
            raise TypeError("Context.smooth takes no device: the context is one")
        from ._filter import _mesh_input, _mesh_output, _smooth

        mesh = _mesh_input(vertices, faces, points=False)
        if mesh is not None:
            return _mesh_output(mesh, _smooth(self, mesh.vertices, mesh.faces, **options))
        return _smooth(self, vertices, faces, **options)
