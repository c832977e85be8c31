"""Keywords to the library's parameters (rsmooth_params), and progress reports to a callable or
a tqdm bar. The defaults come from the library itself (rsmooth_params_init and _init_best)."""

from __future__ import annotations

import warnings
from typing import Any, Callable, Dict, Optional, Tuple, Union

import numpy as np

from . import _rsmooth

_NORMAL_FILTERS = {"mollify": 0, "bilateral": 1}
_INFLUENCES = {"gaussian": 0, "tukey": 1, "lorentzian": 2, "huber": 3}
_PREDICTORS = {"projection": 0, "centroid": 1}
_METHODS = ("robust", "gaussian", "laplacian", "taubin")

Progress = Union[bool, Callable[[float], Any], None]


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
