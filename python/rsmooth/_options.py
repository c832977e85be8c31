"""Keywords to the library's parameters (rsmooth_params), and progress reports to a callable or
a tqdm bar. The defaults come from the library itself (rsmooth_params_init and _init_best)."""

from __future__ import annotations

import os
import warnings
from typing import Any, Callable, Dict, Optional, Tuple, Union

import numpy as np

from . import _rsmooth
from ._arrays import _colors, _mask

_NORMAL_FILTERS = {"mollify": 0, "bilateral": 1}
_INFLUENCES = {"gaussian": 0, "tukey": 1, "lorentzian": 2, "huber": 3}
_PREDICTORS = {"projection": 0, "centroid": 1}
_STAGES = {"guided": 0, "learned": 1}


def _model_bytes(model: Any) -> bytes:
    """model=: a model file's bytes, or its path (read whole here; the library checks it)."""
    if isinstance(model, (bytes, bytearray, memoryview)):
        return bytes(model)
    try:
        with open(os.fspath(model), "rb") as f:
            return f.read()
    except TypeError:
        raise TypeError(f"model: expected a path or bytes, got {model!r}") from None
    except OSError as e:
        raise ValueError(f"model: cannot read {os.fspath(model)}: {e.strerror}") from None
_METHODS = ("robust", "gaussian", "laplacian", "taubin")

Progress = Union[bool, Callable[[float], Any], None]


def _choice(value: Union[str, int], table: Dict[str, int], name: str) -> int:
    if isinstance(value, str) and value.lower() in table:
        return table[value.lower()]
    raise ValueError(f"{name}: expected one of {', '.join(table)}, got {value!r}")


def _numpy_bool(value: Any) -> Any:
    """numpy's bool as Python's: the extension refuses a bool where a number goes by name, but
    cannot tell numpy's (which converts to 0.0 and 1.0) from a number."""
    return bool(value) if isinstance(value, np.bool_) else value


def _params(
    vertices: np.ndarray,
    faces: np.ndarray,
    *,
    best: bool,
    auto: bool,
    overrides: Dict[str, Any],
) -> Tuple[Dict[str, Any], Optional[Dict[str, Any]]]:
    """The library's parameters: the preset (paper or best), the noise rule when `auto`, then
    every keyword given explicitly (explicit ones win over the rule, as on the command line).
    Also the rule's noise report when `auto` (else None)."""
    params = _rsmooth._default_params(bool(best))
    given = {k: _numpy_bool(v) for k, v in overrides.items() if v is not None}
    if "stage" in given:
        given["stage_normals"] = _choice(given.pop("stage"), _STAGES, "stage")
    if "model" in given:
        given["model"] = _model_bytes(given["model"])
    for key, table in (
        ("normal_filter", _NORMAL_FILTERS),
        ("influence", _INFLUENCES),
        ("predictor", _PREDICTORS),
    ):
        if key in given:
            given[key] = _choice(given[key], table, key)
    for key in ("absolute", "mollify", "guard"):
        if key in given:
            given[key] = int(bool(given[key]))
    report = None
    if auto:
        rule = dict(params)
        for key in ("normal_filter", "vertex_updates"):  # these pick the rule (paper or best)
            if key in given:
                rule[key] = given[key]
        params, report = _rsmooth._params_auto(vertices, faces, rule)
    params.update(given)
    return params, report


def _filter_params(
    vertices: np.ndarray,
    faces: np.ndarray,
    vertex_count: int,
    *,
    best: bool,
    auto: bool,
    colors: Any,
    mask: Any,
    method: str,
    overrides: Dict[str, Any],
) -> Dict[str, Any]:
    """The library's parameters of one filter call, the same for rsmooth.smooth and
    Context.smooth on numpy or PyOpenCL arrays: the method's setting ("robust" or "gaussian"),
    the preset, the noise rule, the keywords, the colours and the mask, all checked before any
    work. `vertices`: the positions on the host (only read with `auto`, and for the check that
    the normal update stage has edges: an empty array where they are not on the host)."""
    if method not in ("robust", "gaussian"):
        raise ValueError(f"method: expected one of {', '.join(_METHODS)}, got {method!r}")
    if method == "gaussian":  # the isotropic baseline: centroids, no influence weight
        overrides = dict(overrides, predictor="centroid", sigma_g=float("inf"), mollify=False)
    params, _ = _params(vertices, faces, best=best, auto=auto, overrides=overrides)
    updates: Any = params.get("vertex_updates")  # (any type here: the extension checks it)
    whole = isinstance(updates, (int, np.integer)) and not isinstance(updates, bool)
    if whole and updates > 0 and not params["absolute"] and (
        faces.shape[0] == 0
        or (len(vertices) == vertex_count and _rsmooth._mean_edge_length(vertices, faces) == 0)
    ):
        # the library would go on to the pass with a relative sigma_f of 0 mean edge lengths
        # and blame sigma_f; the reason is the mesh's
        raise ValueError(
            "faces: " + ("none given" if faces.shape[0] == 0 else "no edge of non-zero length")
            + ": the normal update stage (best=True or vertex_updates) needs triangles, and the "
            "mesh's mean edge length, the unit of relative sigmas, is 0 (points with normals: "
            "rsmooth.smooth_points)"
        )
    if colors is not None:
        params["colors"] = _colors(colors, vertex_count)
    if mask is not None:
        params["move_mask"] = _mask(mask, vertex_count)
    return params


def _keywords(params: Dict[str, Any]) -> Dict[str, Any]:
    """The library's parameters as rsmooth.smooth's keywords (choices by name, flags as bools)."""
    out = dict(params)
    if "stage_normals" in out:
        value = out.pop("stage_normals")
        out["stage"] = next(name for name, v in _STAGES.items() if v == value)
    for key, table in (
        ("normal_filter", _NORMAL_FILTERS),
        ("influence", _INFLUENCES),
        ("predictor", _PREDICTORS),
    ):
        out[key] = next(name for name, value in table.items() if value == out[key])
    for key in ("absolute", "mollify", "guard"):
        out[key] = bool(out[key])
    return out


def _progress_callable(progress: Progress) -> Tuple[Optional[Callable[[float], Any]], Any]:
    """(callable for the C layer, bar to close). True: a tqdm bar when tqdm is installed."""
    if isinstance(progress, np.bool_):
        progress = bool(progress)
    if progress is None or progress is False:
        return None, None
    if callable(progress):
        return progress, None
    if progress is not True:
        raise TypeError(f"progress: expected True, False, None or a callable, got {progress!r}")
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
