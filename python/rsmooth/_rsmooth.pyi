# Type stub of the C extension rsmooth._rsmooth (python/ext/). These are internal: the package's
# public functions (rsmooth.smooth, ...) convert and check their arguments, then call these with
# C-contiguous float32/float64 (n, 3) arrays, uint32 (m, 3) faces and preallocated outputs.
# They check again what reaches the library (numbers by name and range) and hand it copies of
# the arrays, so that Python code running during a call cannot change what the call reads.
from typing import Any, Callable, Dict, List, Optional, Tuple

import numpy as np

__version__: str

class DeviceError(RuntimeError): ...

def _smooth(
    context: Optional[object],
    vertices: np.ndarray,
    faces: np.ndarray,
    out: np.ndarray,
    confidence: Optional[np.ndarray],
    params: Optional[Dict[str, Any]],
    progress: Optional[Callable[[float], Any]],
) -> Dict[str, Any]: ...
def _smooth_points(
    points: np.ndarray,
    normals: np.ndarray,
    out: np.ndarray,
    out_normals: Optional[np.ndarray],
    confidence: Optional[np.ndarray],
    params: Optional[Dict[str, Any]],
    progress: Optional[Callable[[float], Any]],
) -> Dict[str, Any]: ...
def _taubin(
    vertices: np.ndarray, faces: np.ndarray, out: np.ndarray, lam: float, mu: float,
    iterations: int,
) -> None: ...
def _default_params(best: bool) -> Dict[str, Any]: ...
def _params_auto(
    vertices: np.ndarray, faces: np.ndarray, params: Dict[str, Any]
) -> Tuple[Dict[str, Any], Dict[str, Any]]: ...
def _estimate_noise(vertices: np.ndarray, faces: np.ndarray) -> float: ...
def _mean_edge_length(vertices: np.ndarray, faces: np.ndarray) -> float: ...
def _point_spacing(points: np.ndarray) -> float: ...
def _compare(result: np.ndarray, truth: np.ndarray, faces: np.ndarray) -> Dict[str, float]: ...
def _devices() -> List[Dict[str, Any]]: ...
def _context_create(device: Optional[str]) -> object: ...
def _context_info(context: object) -> Tuple[str, float, int]: ...
def _context_from_queue(queue: int) -> object: ...
def _smooth_cl(
    context: object,
    double: bool,
    positions: int,
    vertex_count: int,
    faces: np.ndarray,
    out: int,
    params: Optional[Dict[str, Any]],
    progress: Optional[Callable[[float], Any]],
) -> Dict[str, Any]: ...
