"""Arrays in: numpy converts dtypes, strides and index types and checks faces here, so the C
extension only ever sees C-contiguous float32/float64 (n, 3) and uint32 (m, 3) arrays."""

from __future__ import annotations

from typing import Any

import numpy as np


def _vertices(array: Any, name: str = "vertices") -> np.ndarray:
    """(n, 3) float32 or float64, C-contiguous (a copy only when the input is not). Any real
    floating dtype is taken: float16 is worked on as float32, one wider than float64 (numpy's
    longdouble) as float64; _result gives the result back in the caller's dtype."""
    a = np.asarray(array)
    if a.dtype not in (np.float32, np.float64):
        if a.dtype.kind in "iub":
            raise TypeError(
                f"{name}: dtype {a.dtype} is not a floating-point dtype "
                f"(convert first, e.g. {name}.astype(np.float64))"
            )
        if a.dtype.kind != "f":
            raise TypeError(f"{name}: expected a real floating-point array, got dtype {a.dtype}")
        a = a.astype(np.float32 if a.dtype.itemsize < 4 else np.float64)
    if a.ndim != 2 or a.shape[1] != 3:
        raise ValueError(f"{name}: expected shape (n, 3), got {a.shape}")
    if a.shape[0] == 0:
        raise ValueError(f"{name}: no vertices")
    if a.shape[0] >= 2**32:
        raise ValueError(f"{name}: {a.shape[0]} vertices; at most 2**32 - 1")
    return np.ascontiguousarray(a)


def _result(out: np.ndarray, given: Any) -> np.ndarray:
    """`out` in the dtype of the caller's `given` array where that is another floating dtype
    (float16, longdouble): the dtype in is the dtype out."""
    dtype = getattr(given, "dtype", None)
    if dtype is not None and np.dtype(dtype).kind == "f" and np.dtype(dtype) != out.dtype:
        return out.astype(dtype)
    return out


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


def _mask(array: Any, vertex_count: int) -> np.ndarray:
    """(n,) selection, any dtype (non-zero or True: the vertex moves), as uint8."""
    m = np.asarray(array)
    if m.shape != (vertex_count,):
        raise ValueError(f"mask: expected shape ({vertex_count},), got {m.shape}")
    return np.ascontiguousarray(m != 0, dtype=np.uint8)


def _colors(array: Any, vertex_count: int) -> np.ndarray:
    c = np.asarray(array)
    if c.ndim != 2 or c.shape != (vertex_count, 3):
        raise ValueError(f"colors: expected shape ({vertex_count}, 3), got {c.shape}")
    if c.dtype == np.uint8:  # 0..255 to [0, 1], the units sigma_c is given in
        c = c / 255.0
    return np.ascontiguousarray(c, dtype=np.float32)
