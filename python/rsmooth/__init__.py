"""Feature-preserving mesh denoising on any OpenCL device, or on the CPU without one.

rsmooth implements Jones, Durand and Desbrun, *Non-Iterative, Feature-Preserving Mesh Smoothing*
(SIGGRAPH 2003): each vertex moves to a robust, area-weighted average of its projections onto
the tangent planes of nearby triangles, so noise goes and sharp edges stay. One pass, and no
connectivity needed: triangle soups, cracked and non-manifold scans work.

Two lines with trimesh::

    import rsmooth, trimesh
    mesh = trimesh.load("scan.ply")
    mesh.vertices = rsmooth.smooth(mesh.vertices, mesh.faces)

Arrays in, arrays out: ``vertices`` is (n, 3) float32 or float64 (any strides or order), ``faces``
(m, 3) of any integer type; the result is a new array of the input's dtype and shape. Sigmas are
in mean edge lengths unless ``absolute=True``. ``device="auto"`` takes the first GPU, else the
first CPU OpenCL device, and falls back to the double-precision reference path (with a warning)
where no OpenCL exists; ``device="reference"`` always runs that path.

The GIL is released while a filter runs, and Ctrl-C stops a long call (KeyboardInterrupt; the
inputs are untouched and no result is returned). A call reads its own copies of the arrays, so
other threads and progress callables may change the caller's meanwhile.
"""

from __future__ import annotations

from . import _rsmooth
from ._context import Context, devices
from ._filter import smooth, smooth_points
from ._measures import auto_params, compare, estimate_noise, mean_edge_length, point_spacing
from ._rsmooth import DeviceError

__version__: str = _rsmooth.__version__

__all__ = [
    "smooth",
    "smooth_points",
    "estimate_noise",
    "auto_params",
    "mean_edge_length",
    "point_spacing",
    "compare",
    "devices",
    "Context",
    "DeviceError",
    "__version__",
]
