"""Measures of meshes and point sets: noise (and the parameters ``auto`` picks from it), edge
length, spacing, and the error against a ground truth (the library's rsmooth_compare)."""

from __future__ import annotations

from typing import Any, Dict

from . import _rsmooth
from ._arrays import _faces, _vertices
from ._options import _keywords, _params


def estimate_noise(vertices: Any, faces: Any) -> float:
    """The mesh's noise: the standard deviation of its vertices' displacement along the surface
    normal, in mean edge lengths, from the geometry alone (quadric fits, robust to sharp edges).
    Gaussian noise of 0.1 to 0.7 mean edge lengths reads within about 5% on meshes of a few
    thousand vertices or more. 0 for a mesh too small to fit."""
    v = _vertices(vertices)
    return _rsmooth._estimate_noise(v, _faces(faces, v.shape[0]))


def auto_params(vertices: Any, faces: Any, *, best: bool = False) -> Dict[str, Any]:
    """What ``rsmooth.smooth(vertices, faces, auto=True, best=best)`` reads from the mesh and
    chooses (the library's rsmooth_params_auto with its report).

    Returns a dict: ``level`` (the noise's standard deviation along the surface normal, in mean
    edge lengths of the clean mesh; for impulsive noise that of the displaced vertices),
    ``kind`` ("gaussian": every vertex displaced, "impulsive": a share of them thrown and the
    others nearly exact, "none": nothing to remove, either nothing measurable or roughness that
    reads as the mesh's own shape, and then the setting leaves every vertex where it is),
    ``impulsive_fraction`` (the share displaced: 1 unless impulsive), ``tangential_level`` (the
    displacement along one tangent direction, same unit; NaN when not measured),
    ``mean_edge_length`` (the mesh's as given, in its units: :func:`mean_edge_length`'s figure,
    the command's ``--json`` ``mean_edge_length`` and :func:`compare`'s ``mean_edge``),
    ``clean_mean_edge_length`` (the clean mesh's, as estimated: the unit of ``level``; until 0.11
    this figure was ``mean_edge_length``), ``preset`` (the setting chosen, e.g. "paper" or
    "best: mid"), ``reason`` (why, in words), ``correlated_level`` (the rms along the normal
    including the noise's spatially correlated part, as real range scans have: ``level`` when the
    noise reads uncorrelated), ``correlation_length`` (mean edge lengths; 0: uncorrelated),
    ``shape_correlation`` (how alike neighbouring vertices bend: 0.3 or more reads clean),
    ``parts`` and ``outliers`` (the mesh's parts by scale and the vertices held as outliers; the
    figures are the largest part's), and ``params``: the chosen setting as
    keywords, so that ``rsmooth.smooth(vertices, faces, **report["params"])`` runs it."""
    v = _vertices(vertices)
    f = _faces(faces, v.shape[0])
    params, report = _params(v, f, best=best, auto=True, overrides={})
    assert report is not None
    # the library's figure is the clean mesh's, as estimated; under the name every other measure
    # uses for the mesh as given, it read as a third "mean edge length" of the same file
    report["clean_mean_edge_length"] = report["mean_edge_length"]
    report["mean_edge_length"] = _rsmooth._mean_edge_length(v, f)
    report["params"] = _keywords(params)
    return report


def mean_edge_length(vertices: Any, faces: Any) -> float:
    """Mean length of the mesh's unique undirected edges, in its units: the unit of relative
    sigmas. The same figure as the command's ``--json`` ``mean_edge_length`` and ``rsmooth compare
    --json``'s ``mean_edge`` for the same vertices and faces. An STL file holds every triangle's
    own corners: the command reads them as they are (each triangle's edges its own), while
    ``trimesh.load`` merges equal vertices by default, so an open mesh's figure can differ
    between the two (``trimesh.load(path, process=False)`` reads it as the command does)."""
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
    of the diagonal), and ``theta_count``, ``mean_edge``, ``bbox_diag``, ``vertices``,
    ``triangles``: the keys of ``rsmooth compare --json``. Distances to surfaces are exact.
    ``vertex_count`` and ``triangle_count``, the old names of ``vertices`` and ``triangles``, are
    kept until 0.12."""
    r = _vertices(result, "result")
    t = _vertices(truth, "truth")
    if t.shape != r.shape:
        raise ValueError(f"truth: shape {t.shape} for a result of shape {r.shape}")
    figures = _rsmooth._compare(r, t.astype(r.dtype, copy=False), _faces(faces, r.shape[0]))
    figures["vertices"] = figures["vertex_count"]  # the command's keys (compare --json)
    figures["triangles"] = figures["triangle_count"]
    return figures
