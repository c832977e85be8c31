"""The keywords of smooth() and smooth_points() as TypedDicts, so that each of their overloads
(one per mesh object type, in _filter.py) names only what differs between them."""

from __future__ import annotations

from typing import Any, Optional, TypedDict

from ._options import Progress


class PointOptions(TypedDict, total=False):
    """smooth_points()'s keywords but ``confidence`` and ``return_normals``: the ones both
    functions take."""

    sigma_f: Optional[float]
    sigma_g: Optional[float]
    absolute: bool
    cutoff: Optional[float]
    mollify: bool
    best: bool
    normal_sigma_s: Optional[float]
    normal_sigma_n: Optional[float]
    normal_iterations: Optional[int]
    influence: Optional[str]
    passes: Optional[int]
    pass_confidence: Optional[float]
    predictor: Optional[str]
    colors: Any
    sigma_c: Optional[float]
    mask: Any
    progress: Progress


class SmoothOptions(PointOptions, total=False):
    """smooth()'s keywords but ``confidence`` (which changes what comes back): the point cloud's
    and those of meshes alone."""

    device: Optional[str]
    auto: bool
    normal_filter: Optional[str]
    vertex_updates: Optional[int]
    guided_sigma_s: Optional[float]
    guided_sigma_n: Optional[float]
    guided_rounds: Optional[int]
    stage_repeats: Optional[int]
    guided_radius: Optional[float]
    stage: Optional[str]
    model: Any
    discrepancy_level: Optional[float]
    discrepancy_gain: Optional[float]
    guard: Optional[bool]
    mollify_cutoff: Optional[float]
    method: str
    iterations: int
    lam: float
    mu: float
