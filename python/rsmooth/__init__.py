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
inputs are untouched and no result is returned).
"""

from __future__ import annotations

import warnings
from typing import Any, Callable, Dict, List, Optional, Tuple, Union

import numpy as np

from . import _rsmooth
from ._rsmooth import DeviceError

__version__: str = _rsmooth.__version__

__all__ = [
    "smooth",
    "smooth_points",
    "estimate_noise",
    "mean_edge_length",
    "point_spacing",
    "compare",
    "devices",
    "Context",
    "DeviceError",
    "__version__",
]

_NORMAL_FILTERS = {"mollify": 0, "bilateral": 1}
_INFLUENCES = {"gaussian": 0, "tukey": 1, "lorentzian": 2, "huber": 3}
_PREDICTORS = {"projection": 0, "centroid": 1}
_METHODS = ("robust", "gaussian", "laplacian", "taubin")

Progress = Union[bool, Callable[[float], Any], None]


# ---- arrays ---------------------------------------------------------------------------------


def _vertices(array: Any, name: str = "vertices") -> np.ndarray:
    """(n, 3) float32 or float64, C-contiguous (a copy only when the input is not)."""
    a = np.asarray(array)
    if a.dtype not in (np.float32, np.float64):
        if a.dtype.kind in "iub" or a.dtype == np.float16:
            raise TypeError(
                f"{name}: dtype {a.dtype} is not float32 or float64 "
                f"(convert first, e.g. {name}.astype(np.float64))"
            )
        raise TypeError(f"{name}: expected a float32 or float64 array, got dtype {a.dtype}")
    if a.ndim != 2 or a.shape[1] != 3:
        raise ValueError(f"{name}: expected shape (n, 3), got {a.shape}")
    if a.shape[0] == 0:
        raise ValueError(f"{name}: no vertices")
    if a.shape[0] >= 2**32:
        raise ValueError(f"{name}: {a.shape[0]} vertices; at most 2**32 - 1")
    return np.ascontiguousarray(a)


def _faces(array: Any, vertex_count: int, name: str = "faces") -> np.ndarray:
    """(m, 3) uint32, every index checked against vertex_count first."""
    f = np.asarray(array)
    if f.size == 0:
        return np.zeros((0, 3), dtype=np.uint32)
    if f.dtype.kind not in "iu":
        raise TypeError(f"{name}: expected an integer array, got dtype {f.dtype}")
    if f.ndim != 2 or f.shape[1] != 3:
        raise ValueError(
            f"{name}: expected shape (m, 3) of triangles, got {f.shape}"
            + (" (triangulate polygons first)" if f.ndim == 2 else "")
        )
    bad = (f < 0) | (f >= vertex_count)
    if bad.any():
        face, corner = (int(i) for i in np.argwhere(bad)[0])
        raise ValueError(
            f"{name}: face {face} has index {int(f[face, corner])} at corner {corner}, "
            f"outside 0..{vertex_count - 1}"
        )
    return np.ascontiguousarray(f, dtype=np.uint32)


def _colors(array: Any, vertex_count: int) -> np.ndarray:
    c = np.asarray(array)
    if c.ndim != 2 or c.shape != (vertex_count, 3):
        raise ValueError(f"colors: expected shape ({vertex_count}, 3), got {c.shape}")
    if c.dtype == np.uint8:  # 0..255 to [0, 1], the units sigma_c is given in
        c = c / 255.0
    return np.ascontiguousarray(c, dtype=np.float32)


# ---- parameters -----------------------------------------------------------------------------


def _choice(value: Union[str, int], table: Dict[str, int], name: str) -> int:
    if isinstance(value, str) and value.lower() in table:
        return table[value.lower()]
    raise ValueError(f"{name}: expected one of {', '.join(table)}, got {value!r}")


def _params(
    vertices: np.ndarray,
    faces: np.ndarray,
    *,
    best: bool,
    auto: bool,
    overrides: Dict[str, Any],
) -> Tuple[Dict[str, Any], Optional[float]]:
    """The library's parameters: the preset (paper or best), the noise rule when `auto`, then
    every keyword given explicitly (explicit ones win over the rule, as on the command line)."""
    params = _rsmooth._default_params(bool(best))
    given = {k: v for k, v in overrides.items() if v is not None}
    for key, table in (
        ("normal_filter", _NORMAL_FILTERS),
        ("influence", _INFLUENCES),
        ("predictor", _PREDICTORS),
    ):
        if key in given:
            given[key] = _choice(given[key], table, key)
    for key in ("absolute", "mollify"):
        if key in given:
            given[key] = int(bool(given[key]))
    noise = None
    if auto:
        rule = dict(params)
        if "normal_filter" in given:
            rule["normal_filter"] = given["normal_filter"]
        params, noise = _rsmooth._params_auto(vertices, faces, rule)
    params.update(given)
    return params, noise


def _progress_callable(progress: Progress) -> Tuple[Optional[Callable[[float], Any]], Any]:
    """(callable for the C layer, bar to close). True: a tqdm bar when tqdm is installed."""
    if progress is None or progress is False:
        return None, None
    if callable(progress):
        return progress, None
    try:
        from tqdm.auto import tqdm
    except ImportError:
        warnings.warn("progress=True needs tqdm (pip install tqdm); no bar shown", stacklevel=3)
        return None, None
    bar = tqdm(total=1000, unit="‰", desc="rsmooth", leave=False)

    def advance(fraction: float) -> None:
        step = int(fraction * 1000) - bar.n
        if step > 0:
            bar.update(step)

    return advance, bar


# ---- devices and contexts -------------------------------------------------------------------


def devices() -> List[Dict[str, Any]]:
    """Every OpenCL device, in the order "P:D" device choices count them.

    Each is a dict: ``id`` ("P:D", what ``device=`` takes), ``platform``, ``device``, ``name``
    ("platform / device", which a name choice matches), ``type`` ("gpu", "cpu", "accel" or
    "other"), ``version``, ``compute_units``, ``global_memory`` (bytes). Empty where no OpenCL
    loader or platform exists.
    """
    return _rsmooth._devices()


class Context:
    """An OpenCL device with rsmooth's kernels built on it, reusable across calls.

    ``device``: "auto" (first GPU, else first CPU device), "gpu", "cpu", "P:D" (see
    :func:`devices`), or part of a device's name; None reads the RSMOOTH_DEVICE environment
    variable. Creating one builds the kernels (PoCL caches the binaries on disk); keep it for
    many meshes. Raises :class:`DeviceError` when no OpenCL device matches.

    Threads may share a context: its calls run one at a time.
    """

    def __init__(self, device: Optional[str] = "auto") -> None:
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

    def smooth(self, vertices: Any, faces: Any, **options: Any) -> Any:
        """:func:`rsmooth.smooth` on this context's device (same arguments but ``device``)."""
        if self._capsule is None:
            raise ValueError("this rsmooth.Context is closed")
        if "device" in options:
            raise TypeError("Context.smooth takes no device: the context is one")
        return _smooth(self, vertices, faces, **options)


# ---- the filter -----------------------------------------------------------------------------


def smooth(
    vertices: Any,
    faces: Any,
    *,
    sigma_f: Optional[float] = None,
    sigma_g: Optional[float] = None,
    absolute: bool = False,
    cutoff: Optional[float] = None,
    mollify: bool = True,
    device: Optional[str] = "auto",
    confidence: bool = False,
    best: bool = False,
    auto: bool = False,
    normal_filter: Optional[str] = None,
    normal_sigma_s: Optional[float] = None,
    normal_sigma_n: Optional[float] = None,
    normal_iterations: Optional[int] = None,
    influence: Optional[str] = None,
    passes: Optional[int] = None,
    pass_confidence: Optional[float] = None,
    predictor: Optional[str] = None,
    mollify_cutoff: Optional[float] = None,
    colors: Any = None,
    sigma_c: Optional[float] = None,
    method: str = "robust",
    iterations: int = 10,
    lam: float = 0.5,
    mu: float = -0.53,
    progress: Progress = False,
) -> Any:
    """Removes noise from a triangle mesh and keeps its sharp edges (Jones et al. 2003).

    Parameters
    ----------
    vertices : (n, 3) float32 or float64 array-like, any strides or order.
    faces : (m, 3) integer array-like (int32, int64, uint32...). A negative or out-of-range index
        raises ValueError naming the face.
    sigma_f : spatial width: how far around a vertex triangles are consulted (ignored beyond
        ``cutoff * sigma_f``). Mean edge lengths unless ``absolute``. Default 2 (``best``: 0.8).
    sigma_g : influence width: how far a triangle's plane may lie from the vertex before it
        counts as the other side of a feature; ``float("inf")`` turns it off. Default 0.5
        (``best``: 0.3). The paper's rule: raise both until smooth enough, then lower sigma_g
        until the edges come back.
    absolute : sigmas in the mesh's own units instead of mean edge lengths.
    cutoff : triangles beyond ``cutoff * sigma_f`` are ignored, (0, 5]. Default 2.
    mollify : predict with mollified normals (the paper); False uses the raw ones.
    device : "auto", "gpu", "cpu", "P:D", part of a device name, or "reference" (double
        precision on one CPU thread, no OpenCL). "auto" falls back to "reference" with a
        RuntimeWarning where no OpenCL device exists. Use :class:`Context` to build the kernels
        once for many calls.
    confidence : also return the per-vertex confidence k(p) / sum a f in [0, 1] (float32, the
        paper's Fig. 10): low at features and outliers.
    best : rsmooth's most accurate mode (bilateral normals, 3 passes at sigma_f 0.8,
        sigma_g 0.3); other keywords still apply on top.
    auto : estimate the noise (:func:`estimate_noise`) and pick the sigmas from it (with
        ``best`` also the rounds and passes). Keywords given explicitly win over the rule.
    normal_filter : "mollify" (the paper) or "bilateral" (keeps creases the Gaussian rounds).
    normal_sigma_s, normal_sigma_n, normal_iterations : the bilateral normal filter's spatial
        width (units of sigma_f, default 1), width on normal differences ((0, 2], default 0.35)
        and rounds (default 5).
    influence : the robust weight: "gaussian" (the paper), "tukey", "lorentzian" or "huber".
    passes : run the filter this many times, each from the previous result (default 1).
    pass_confidence : passes after the first move only vertices whose confidence was below it.
    predictor : "projection" (the paper) or "centroid".
    mollify_cutoff : mollification reach in units of sigma_f, (0, cutoff]; default: cutoff.
    colors : (n, 3) per-vertex colours (floats in [0, 1], or uint8 0..255) weighing each
        triangle by its colour difference too, so colour edges stay sharp; width ``sigma_c``
        (default 0.1).
    method : "robust" (the filter), or the isotropic smoothers it is measured against:
        "gaussian" (one Gaussian-weighted pass of centroids, width sigma_f), "laplacian" and
        "taubin" (``iterations`` umbrella steps by ``lam``, Taubin's each followed by one by
        ``mu``; these need connected faces and run on the CPU).
    progress : True shows a tqdm progress bar (when tqdm is installed); a callable is called
        with the fraction done, and may raise to stop the call.

    Returns
    -------
    The smoothed vertices, a new array of the input's dtype and shape; with ``confidence=True``
    the tuple ``(vertices, confidence)``.

    Raises
    ------
    ValueError : bad arrays or parameters (the library's message).
    DeviceError : the OpenCL device is missing or failed (names the device and the error).
    KeyboardInterrupt : Ctrl-C during the call.
    """
    options = dict(
        sigma_f=sigma_f, sigma_g=sigma_g, absolute=absolute, cutoff=cutoff, mollify=mollify,
        confidence=confidence, best=best, auto=auto, normal_filter=normal_filter,
        normal_sigma_s=normal_sigma_s, normal_sigma_n=normal_sigma_n,
        normal_iterations=normal_iterations, influence=influence, passes=passes,
        pass_confidence=pass_confidence, predictor=predictor, mollify_cutoff=mollify_cutoff,
        colors=colors, sigma_c=sigma_c, method=method, iterations=iterations, lam=lam, mu=mu,
        progress=progress,
    )
    if device == "reference" or method in ("laplacian", "taubin"):
        return _smooth(None, vertices, faces, **options)
    try:
        context = Context(device)
    except DeviceError as e:
        if device not in ("auto", None) or not _no_opencl(e):
            raise
        warnings.warn(
            f"rsmooth: no OpenCL device ({e}); using the reference path (double precision, "
            "one CPU thread)",
            RuntimeWarning,
            stacklevel=2,
        )
        return _smooth(None, vertices, faces, **options)
    with context:
        return _smooth(context, vertices, faces, **options)


def _no_opencl(error: DeviceError) -> bool:
    """Whether `auto` found no OpenCL at all (no loader, no platform, no device), rather than a
    device that failed."""
    text = str(error).lower()
    return any(s in text for s in ("loader", "no opencl", "platform", "no device", "no gpu"))


def _smooth(
    context: Optional[Context],
    vertices: Any,
    faces: Any,
    *,
    confidence: bool = False,
    best: bool = False,
    auto: bool = False,
    colors: Any = None,
    method: str = "robust",
    iterations: int = 10,
    lam: float = 0.5,
    mu: float = -0.53,
    progress: Progress = False,
    **overrides: Any,
) -> Any:
    shape_in = np.shape(vertices)
    v = _vertices(vertices)
    f = _faces(faces, v.shape[0])
    if method not in _METHODS:
        raise ValueError(f"method: expected one of {', '.join(_METHODS)}, got {method!r}")
    out = np.empty_like(v)
    if method in ("laplacian", "taubin"):
        if confidence:
            raise ValueError(f"method {method!r} gives no confidence")
        _rsmooth._taubin(v, f, out, float(lam), float(mu) if method == "taubin" else 0.0,
                         int(iterations))
        return out.reshape(shape_in)
    if method == "gaussian":  # the isotropic baseline: centroids, no influence weight
        overrides.update(predictor="centroid", sigma_g=float("inf"), mollify=False)
    params, _ = _params(v, f, best=best, auto=auto, overrides=overrides)
    if colors is not None:
        params["colors"] = _colors(colors, v.shape[0])
    conf = np.empty(v.shape[0], dtype=np.float32) if confidence else None
    call, bar = _progress_callable(progress)
    try:
        report = _rsmooth._smooth(
            context._capsule if context is not None else None, v, f, out, conf, params, call
        )
    finally:
        if bar is not None:
            bar.close()
    if context is not None:
        context.last_report = report
    out = out.reshape(shape_in)
    return (out, conf) if confidence else out


def smooth_points(
    points: Any,
    normals: Any,
    *,
    sigma_f: Optional[float] = None,
    sigma_g: Optional[float] = None,
    absolute: bool = False,
    cutoff: Optional[float] = None,
    mollify: bool = True,
    confidence: bool = False,
    return_normals: bool = False,
    best: bool = False,
    normal_sigma_s: Optional[float] = None,
    normal_sigma_n: Optional[float] = None,
    normal_iterations: Optional[int] = None,
    influence: Optional[str] = None,
    passes: Optional[int] = None,
    pass_confidence: Optional[float] = None,
    predictor: Optional[str] = None,
    colors: Any = None,
    sigma_c: Optional[float] = None,
    progress: Progress = False,
) -> Any:
    """The filter on a point cloud with normals: each point is its own facet, its plane the
    tangent plane through it, its area from the spacing of its 6 nearest neighbours.

    ``points`` and ``normals``: (n, 3), float32 or float64 (normals of any non-zero length,
    consistently oriented). Sigmas are in point spacings (:func:`point_spacing`) unless
    ``absolute``. With ``mollify`` (default) the normals are smoothed by the bilateral normal
    filter first. Runs on the CPU reference path (double precision).

    Returns the filtered points (the input's dtype), or a tuple adding the filtered unit normals
    (``return_normals``) and the confidence (``confidence``), in that order.
    """
    p = _vertices(points, "points")
    n = _vertices(normals, "normals").astype(p.dtype, copy=False)
    if n.shape != p.shape:
        raise ValueError(f"normals: shape {n.shape} for points of shape {p.shape}")
    overrides = dict(
        sigma_f=sigma_f, sigma_g=sigma_g, absolute=absolute, cutoff=cutoff, mollify=mollify,
        normal_sigma_s=normal_sigma_s, normal_sigma_n=normal_sigma_n,
        normal_iterations=normal_iterations, influence=influence, passes=passes,
        pass_confidence=pass_confidence, predictor=predictor, sigma_c=sigma_c,
    )
    no_faces = np.zeros((0, 3), dtype=np.uint32)
    params, _ = _params(p, no_faces, best=best, auto=False, overrides=overrides)
    if colors is not None:
        params["colors"] = _colors(colors, p.shape[0])
    out = np.empty_like(p)
    out_n = np.empty_like(p) if return_normals else None
    conf = np.empty(p.shape[0], dtype=np.float32) if confidence else None
    call, bar = _progress_callable(progress)
    try:
        _rsmooth._smooth_points(p, np.ascontiguousarray(n), out, out_n, conf, params, call)
    finally:
        if bar is not None:
            bar.close()
    result = (out,) + ((out_n,) if return_normals else ()) + ((conf,) if confidence else ())
    return result if len(result) > 1 else out


# ---- measures -------------------------------------------------------------------------------


def estimate_noise(vertices: Any, faces: Any) -> float:
    """The mesh's noise: the standard deviation of its vertices' displacement along the surface
    normal, in mean edge lengths, from the geometry alone (quadric fits, robust to sharp edges).
    Gaussian noise of 0.1 to 0.7 mean edge lengths reads within about 5% on meshes of a few
    thousand vertices or more. 0 for a mesh too small to fit."""
    v = _vertices(vertices)
    return _rsmooth._estimate_noise(v, _faces(faces, v.shape[0]))


def mean_edge_length(vertices: Any, faces: Any) -> float:
    """Mean length of the mesh's unique undirected edges, in its units: the unit of relative
    sigmas."""
    v = _vertices(vertices)
    return _rsmooth._mean_edge_length(v, _faces(faces, v.shape[0]))


def point_spacing(points: Any) -> float:
    """Mean over the points of each one's mean distance to its 6 nearest others: the unit of
    :func:`smooth_points`' relative sigmas."""
    return _rsmooth._point_spacing(_vertices(points, "points"))


def compare(result: Any, truth: Any, faces: Any) -> Dict[str, float]:
    """Error of a denoised mesh against its ground truth (same vertices and faces).

    Returns a dict: ``theta`` (mean angle between corresponding face normals, degrees), ``ev``
    (Sun et al.'s area-weighted vertex-to-surface distance E_v, in thousandths of the truth's
    bounding-box diagonal), ``rms_v`` (RMS distance between corresponding vertices, in the
    truth's mean edge lengths), ``hausdorff`` (symmetric, sampled at the vertices, thousandths
    of the diagonal), and ``theta_count``, ``mean_edge``, ``bbox_diag``, ``vertex_count``,
    ``triangle_count``. Distances to surfaces are exact."""
    r = _vertices(result, "result")
    t = _vertices(truth, "truth")
    if t.shape != r.shape:
        raise ValueError(f"truth: shape {t.shape} for a result of shape {r.shape}")
    return _rsmooth._compare(r, t.astype(r.dtype, copy=False), _faces(faces, r.shape[0]))
