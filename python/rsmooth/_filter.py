"""The filter on meshes and point clouds: device choice and fallback, then one call into the C
extension with the GIL released."""

from __future__ import annotations

import functools
import numbers
import os
import warnings
from typing import TYPE_CHECKING, Any, Optional, Tuple, overload

import numpy as np

from . import _rsmooth
from ._arrays import _colors, _faces, _mask, _result, _vertices
from ._context import Context, _check_device
from ._meshes import MeshInput, is_mesh_object, read, scene_error
from ._options import (
    _METHODS,
    Progress,
    _filter_params,
    _numpy_bool,
    _params,
    _progress_callable,
)
from ._rsmooth import DeviceError
from ._typing import PointOptions, SmoothOptions

if TYPE_CHECKING:
    from typing import Literal

    import meshio
    import open3d
    import pyvista
    import trimesh

    from numpy.typing import ArrayLike
    from typing_extensions import Unpack


# The types only: a mesh object alone comes back as its own type, arrays as an array, and
# confidence=True adds the per-vertex confidence after either. One pair per library, not a
# constrained TypeVar: a library without types (meshio) would make every result Any.
@overload
def smooth(
    vertices: trimesh.Trimesh, faces: None = None, *, confidence: Literal[False] = False,
    **options: Unpack[SmoothOptions],
) -> trimesh.Trimesh: ...
@overload
def smooth(
    vertices: trimesh.Trimesh, faces: None = None, *, confidence: Literal[True],
    **options: Unpack[SmoothOptions],
) -> Tuple[trimesh.Trimesh, np.ndarray]: ...
@overload
def smooth(
    vertices: open3d.geometry.TriangleMesh, faces: None = None, *, confidence: Literal[False] = False,
    **options: Unpack[SmoothOptions],
) -> open3d.geometry.TriangleMesh: ...
@overload
def smooth(
    vertices: open3d.geometry.TriangleMesh, faces: None = None, *, confidence: Literal[True],
    **options: Unpack[SmoothOptions],
) -> Tuple[open3d.geometry.TriangleMesh, np.ndarray]: ...
@overload
def smooth(
    vertices: pyvista.PolyData, faces: None = None, *, confidence: Literal[False] = False,
    **options: Unpack[SmoothOptions],
) -> pyvista.PolyData: ...
@overload
def smooth(
    vertices: pyvista.PolyData, faces: None = None, *, confidence: Literal[True],
    **options: Unpack[SmoothOptions],
) -> Tuple[pyvista.PolyData, np.ndarray]: ...
@overload
def smooth(
    vertices: meshio.Mesh, faces: None = None, *, confidence: Literal[False] = False,
    **options: Unpack[SmoothOptions],
) -> meshio.Mesh: ...
@overload
def smooth(
    vertices: meshio.Mesh, faces: None = None, *, confidence: Literal[True],
    **options: Unpack[SmoothOptions],
) -> Tuple[meshio.Mesh, np.ndarray]: ...
@overload
def smooth(
    vertices: ArrayLike, faces: ArrayLike, *, confidence: Literal[False] = False,
    **options: Unpack[SmoothOptions],
) -> np.ndarray: ...
@overload
def smooth(
    vertices: ArrayLike, faces: ArrayLike, *, confidence: Literal[True],
    **options: Unpack[SmoothOptions],
) -> Tuple[np.ndarray, np.ndarray]: ...
def smooth(
    vertices: Any,
    faces: Any = None,
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
    vertex_updates: Optional[int] = None,
    guided_sigma_s: Optional[float] = None,
    guided_sigma_n: Optional[float] = None,
    guided_rounds: Optional[int] = None,
    stage_repeats: Optional[int] = None,
    guided_radius: Optional[float] = None,
    stage: Optional[str] = None,
    model: Any = None,
    discrepancy_level: Optional[float] = None,
    discrepancy_gain: Optional[float] = None,
    guard: Optional[bool] = None,
    predictor: Optional[str] = None,
    mollify_cutoff: Optional[float] = None,
    colors: Any = None,
    sigma_c: Optional[float] = None,
    mask: Any = None,
    method: str = "robust",
    iterations: int = 10,
    lam: float = 0.5,
    mu: float = -0.53,
    progress: Progress = False,
) -> Any:
    """Removes noise from a triangle mesh and keeps its sharp edges (Jones et al. 2003).

    Parameters
    ----------
    vertices : (n, 3) array-like of a real floating dtype, any strides or order (float32 and
        float64 are filtered as they are, float16 in float32 and longdouble in float64; the
        result has the input's dtype; integer dtypes raise TypeError); or a mesh object, with
        no ``faces``: a ``trimesh.Trimesh``, ``open3d.geometry.TriangleMesh``, triangulated
        ``pyvista.PolyData`` or ``meshio.Mesh`` (its triangle cells), for which a new object of
        the same type comes back with every other attribute kept (normals recomputed where the
        type stores them).
    faces : (m, 3) integer array-like (int32, int64, uint32...). A negative or out-of-range index
        raises ValueError naming the face. None with a mesh object.
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
        RuntimeWarning where no OpenCL device exists. The kernels are built once per device
        choice and process, on the first call; a :class:`Context` of your own sets its lifetime
        and gives the run's report.
    confidence : also return the per-vertex confidence k(p) / sum a f in [0, 1] (float32, the
        paper's Fig. 10): low at features and outliers.
    best : rsmooth's most accurate mode (the normal update stage, then one robust pass with
        bilateral normals at sigma_f 0.8, sigma_g 0.3); other keywords still apply on top.
    auto : estimate the noise and pick the sigmas from it (with ``best`` the normal update
        stage's strength); :func:`auto_params` says what it read and chose. Keywords given
        explicitly win over the rule.
    normal_filter : "mollify" (the paper) or "bilateral" (keeps creases the Gaussian rounds).
    normal_sigma_s, normal_sigma_n, normal_iterations : the bilateral normal filter's spatial
        width (units of sigma_f, default 1), width on normal differences ((0, 2], default 0.35)
        and rounds (default 5).
    influence : the robust weight: "gaussian" (the paper), "tukey", "lorentzian" or "huber".
    passes : run the filter this many times, each from the previous result (default 1); 0
        with ``vertex_updates`` runs the normal update stage alone.
    pass_confidence : passes after the first move only vertices whose confidence was below it.
    vertex_updates : the normal update stage, before the passes: guided normal filtering
        (Zhang et al. 2015) of the facet normals, then Sun et al. 2007's vertex update, this
        many iterations ([0, 1000]) moving the vertices to agree with the filtered normals.
        Default 0 (off; ``best``: 10 per cycle, 10 cycles of 1 guided round). Runs on the CPU's
        cores in double precision.
    guided_sigma_s, guided_sigma_n, guided_rounds : the guided filter's spatial width (mean edge
        lengths, default 2), width on guidance-normal differences ((0, 2], default 0.2) and
        rounds per cycle ([1, 100], default 20).
    guided_radius : the guided filter's neighbourhood, in mean distances between the centroids
        of triangles sharing an edge ([1, 8], default 2).
    stage_repeats : the stage's cycles ([1, 1000], default 1): each reads fresh facet normals
        from the current positions, runs the guided rounds, then the vertex updates.
    stage : what the stage's vertex updates follow: "guided" (default) or "learned": after the
        guided cycles, a small network trained on noisy copies of clean meshes predicts each
        triangle's normal from its 32 nearest, and the vertices take ``vertex_updates`` more
        updates toward them (docs/model.md). Needs the stage (``best`` or ``vertex_updates``).
    model : the learned stage's model: a path or the bytes of a file train/ wrote (default: the
        one built into the library); a bad one raises ValueError saying what is wrong.
    discrepancy_level : 0 (default): off. A noise level, in mean edge lengths (``auto`` with
        ``best`` sets the estimate): a choice per region. Each vertex's result blends the
        filter's with Taubin smoothing of the input run until the vertices moved (RMS) that far,
        the filter's weight rising with how flat its neighbourhood came out (flat faces and
        creases: the filter's; curved at the scale of the triangles: Taubin's); boundary
        vertices move at most that level. The report's ``discrepancy_iterations`` and
        ``region_filter_share`` say how many Taubin iterations and the filter's mean weight.
    discrepancy_gain : 0 (default). > 0: Taubin's side goes on until an iteration adds less than
        this (mean edge lengths) to the move (``auto`` sets 0.003 where the noise reads
        spatially correlated, as in range scans).
    guard : True (default): do no harm. The vertices of a triangle the filter would turn over
        are pulled back until none is, and the normal update stage does not run on a mesh that
        reads clean (the report's ``guarded_vertices`` and ``stage_skipped``). False: the filter
        exactly as set. Either way parts of very different size are smoothed apart, each in its
        own unit, and a vertex thrown far off the surface is held (``parts``, ``outliers``).
    predictor : "projection" (the paper) or "centroid".
    mollify_cutoff : mollification reach in units of sigma_f, (0, cutoff]; default: cutoff.
    colors : (n, 3) per-vertex colours (floats in [0, 1], or uint8 0..255) weighing each
        triangle by its colour difference too, so colour edges stay sharp; width ``sigma_c``
        (default 0.1).
    mask : (n,) selection (bool or integers): only the vertices where it is true move; the others
        keep their input position bit for bit, and every triangle still supports the selected
        ones (the robust filter only).
    method : "robust" (the filter), or the isotropic smoothers it is measured against:
        "gaussian" (one Gaussian-weighted pass of centroids, width sigma_f), "laplacian" and
        "taubin" (``iterations`` umbrella steps, [0, 1000000], by ``lam`` in (0, 1], Taubin's
        each followed by one by ``mu`` in [-1, 0); these need connected faces and run on the CPU,
        and Ctrl-C waits for them).
    progress : True shows a tqdm progress bar (when tqdm is installed); a callable is called
        with the fraction done, and may raise to stop the call. The call works on copies of the
        arrays taken when it starts, so a callable (or another thread) changing them changes
        nothing in it. A callable may not start a call on an OpenCL context or make a Context:
        that raises RuntimeError, since the running call holds its context until it returns
        (``device="reference"`` calls work there).

    Returns
    -------
    The smoothed vertices, a new array of the input's dtype and shape (for a mesh object: a new
    object of its type); with ``confidence=True`` the tuple ``(vertices, confidence)``.

    Raises
    ------
    ValueError : bad arrays or parameters, named (the library's message), or a number out of
        its keyword's range.
    TypeError : a bool, float or string where a whole number goes, or something that is not a
        number where a real one does (named).
    RuntimeError : a call on an OpenCL context from inside another one's progress callable.
    DeviceError : the OpenCL device is missing or failed (names the device and the error).
    KeyboardInterrupt : Ctrl-C during the call.
    """
    options = dict(
        sigma_f=sigma_f, sigma_g=sigma_g, absolute=absolute, cutoff=cutoff, mollify=mollify,
        confidence=confidence, best=best, auto=auto, normal_filter=normal_filter,
        normal_sigma_s=normal_sigma_s, normal_sigma_n=normal_sigma_n,
        normal_iterations=normal_iterations, influence=influence, passes=passes,
        pass_confidence=pass_confidence, vertex_updates=vertex_updates,
        guided_sigma_s=guided_sigma_s, guided_sigma_n=guided_sigma_n,
        guided_rounds=guided_rounds, stage_repeats=stage_repeats, guided_radius=guided_radius,
        stage=stage, model=model, discrepancy_level=discrepancy_level,
        discrepancy_gain=discrepancy_gain, guard=guard,
        predictor=predictor, mollify_cutoff=mollify_cutoff, colors=colors, sigma_c=sigma_c,
        mask=mask, method=method, iterations=iterations, lam=lam, mu=mu, progress=progress,
    )
    _check_device(device)
    mesh = _mesh_input(vertices, faces, points=False)
    if mesh is not None:
        return _mesh_output(mesh, smooth(mesh.vertices, mesh.faces, device=device, **options))
    if device == "reference" or method in ("laplacian", "taubin"):
        return _smooth(None, vertices, faces, **options)
    try:
        environment = os.environ.get("RSMOOTH_DEVICE") if device is None else None
        context = _shared_context(device, environment)
    except DeviceError as e:
        # only where no OpenCL device exists at all (no loader, no platform): a device that
        # exists and fails is the caller's to know about
        if device not in ("auto", None) or _rsmooth._devices():
            raise
        warnings.warn(
            f"rsmooth: no OpenCL device ({e}); using the reference path (double precision, "
            "one CPU thread)",
            RuntimeWarning,
            stacklevel=2,
        )
        return _smooth(None, vertices, faces, **options)
    return _smooth(context, vertices, faces, **options)


def _mesh_input(first: Any, second: Any, points: bool) -> Optional[MeshInput]:
    """The arrays of a mesh object passed alone; None for arrays (which need their second)."""
    scene = scene_error(first, points)
    if scene is not None:
        raise TypeError(scene)
    if is_mesh_object(first):
        if second is not None:
            what = "normals" if points else "faces"
            raise TypeError(f"{what}: not taken with a mesh object (its own are used)")
        return read(first, points)
    if second is None:
        what = "normals" if points else "faces"
        raise TypeError(
            f"{what}: missing (arrays need it; the objects taken alone are trimesh, Open3D, "
            f"PyVista and meshio meshes), got {type(first).__name__} alone"
        )
    return None


def _mesh_output(mesh: MeshInput, result: Any) -> Any:
    """The object of the input's type around the filtered positions (confidence kept beside)."""
    if isinstance(result, tuple):
        return (mesh.rebuild(result[0]), result[1])
    return mesh.rebuild(result)


@functools.lru_cache(maxsize=8)
def _shared_context(device: Optional[str], environment: Optional[str]) -> Context:
    """The context rsmooth.smooth uses for `device` (with device None: for RSMOOTH_DEVICE's value,
    `environment`), built once per process: building the kernels costs more than filtering a small
    mesh, and a loop of smooth() calls should not pay it each time. A failure is not cached."""
    return Context(device)


def _smooth(
    context: Optional[Context],
    vertices: Any,
    faces: Any,
    *,
    confidence: bool = False,
    best: bool = False,
    auto: bool = False,
    colors: Any = None,
    mask: Any = None,
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
        if confidence or mask is not None:
            raise ValueError(f"method {method!r} takes no confidence and no mask")
        lam, mu, iterations = (_numpy_bool(x) for x in (lam, mu, iterations))
        if method == "taubin" and isinstance(mu, numbers.Real) and not isinstance(mu, bool):
            try:
                m: Optional[float] = float(mu)
            except OverflowError:  # the extension refuses it by name
                m = None
            if m is not None and not -1 <= m < 0:  # 0 is Laplacian's; NaN fails too
                raise ValueError(f"mu must be in [-1, 0) for method 'taubin' (got {m!r})")
        # lam, mu and iterations go as given: the extension checks their types and ranges
        _rsmooth._taubin(v, f, out, lam, mu if method == "taubin" else 0.0, iterations)
        return _result(out, vertices).reshape(shape_in)
    params = _filter_params(v, f, v.shape[0], best=best, auto=auto, colors=colors, mask=mask,
                            method=method, overrides=overrides)
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
    out = _result(out, vertices).reshape(shape_in)
    return (out, conf) if confidence else out


@overload
def smooth_points(
    points: open3d.geometry.PointCloud, normals: None = None, *, confidence: Literal[False] = False,
    **options: Unpack[PointOptions],
) -> open3d.geometry.PointCloud: ...
@overload
def smooth_points(
    points: open3d.geometry.PointCloud, normals: None = None, *, confidence: Literal[True],
    **options: Unpack[PointOptions],
) -> Tuple[open3d.geometry.PointCloud, np.ndarray]: ...
@overload
def smooth_points(
    points: pyvista.PolyData, normals: None = None, *, confidence: Literal[False] = False,
    **options: Unpack[PointOptions],
) -> pyvista.PolyData: ...
@overload
def smooth_points(
    points: pyvista.PolyData, normals: None = None, *, confidence: Literal[True],
    **options: Unpack[PointOptions],
) -> Tuple[pyvista.PolyData, np.ndarray]: ...
@overload
def smooth_points(
    points: ArrayLike, normals: ArrayLike, *, confidence: bool = False,
    return_normals: bool = False, **options: Unpack[PointOptions],
) -> Any: ...
def smooth_points(
    points: Any,
    normals: Any = None,
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
    mask: Any = None,
    progress: Progress = False,
) -> Any:
    """The filter on a point cloud with normals: each point is its own facet, its plane the
    tangent plane through it, its area from the spacing of its 6 nearest neighbours.

    ``points`` and ``normals``: (n, 3), of a real floating dtype as :func:`smooth`'s vertices
    (normals of any non-zero length, consistently oriented). Sigmas are in point spacings
    (:func:`point_spacing`) unless ``absolute``. With ``mollify`` (default) the normals are
    smoothed by the bilateral normal filter first. Runs on the CPU reference path (double
    precision).

    ``points`` may instead be a point cloud object with normals, and no ``normals`` given: an
    ``open3d.geometry.PointCloud`` or a ``pyvista.PolyData`` of vertices with
    ``point_data["Normals"]``; a new object of its type comes back, its points and normals the
    filtered ones, everything else kept.

    Returns the filtered points (the input's dtype), or a tuple adding the filtered unit normals
    (``return_normals``) and the confidence (``confidence``), in that order; for an object, the
    object (with the confidence after it when asked for).
    """
    cloud = _mesh_input(points, normals, points=True)
    if cloud is not None:
        if return_normals:
            raise TypeError("smooth_points: return_normals is for arrays; the object returned "
                            "carries the filtered normals")
        arrays: Any = smooth_points  # (the arrays overload: the checker need not try them all)
        result = arrays(
            cloud.vertices, cloud.normals, sigma_f=sigma_f, sigma_g=sigma_g, absolute=absolute,
            cutoff=cutoff, mollify=mollify, confidence=confidence, return_normals=True,
            best=best, normal_sigma_s=normal_sigma_s, normal_sigma_n=normal_sigma_n,
            normal_iterations=normal_iterations, influence=influence, passes=passes,
            pass_confidence=pass_confidence, predictor=predictor, colors=colors,
            sigma_c=sigma_c, mask=mask, progress=progress,
        )
        out = cloud.rebuild(result[0], result[1])
        return (out, result[2]) if confidence else out
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
    if mask is not None:
        params["move_mask"] = _mask(mask, p.shape[0])
    out = np.empty_like(p)
    out_n = np.empty_like(p) if return_normals else None
    conf = np.empty(p.shape[0], dtype=np.float32) if confidence else None
    call, bar = _progress_callable(progress)
    try:
        _rsmooth._smooth_points(p, np.ascontiguousarray(n), out, out_n, conf, params, call)
    finally:
        if bar is not None:
            bar.close()
    out = _result(out, points)
    if out_n is not None:
        out_n = _result(out_n, points)
    result = (out,) + ((out_n,) if return_normals else ()) + ((conf,) if confidence else ())
    return result if len(result) > 1 else out
