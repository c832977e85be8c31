"""Shared fixtures of the Python suite: meshes the suite makes itself (a roof with a sharp ridge,
a closed box), the C command-line program built from the same library (the oracle the module is
checked against), and a way to run Python in a child process with OpenCL out of reach."""

from __future__ import annotations

import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest

import rsmooth

ROOT = pathlib.Path(__file__).resolve().parents[2]


def roof(n: int = 40) -> tuple[np.ndarray, np.ndarray]:
    """An n x n grid over [-1, 1]^2 folded along x = 0 (z = -0.5 |x|): two planes meeting at a
    sharp ridge, triangulated in alternating diagonals."""
    xs = np.linspace(-1.0, 1.0, n + 1)
    x, y = np.meshgrid(xs, xs, indexing="ij")
    v = np.stack([x.ravel(), y.ravel(), -0.5 * np.abs(x.ravel())], axis=1)
    faces = []
    for i in range(n):
        for j in range(n):
            a, b, c, d = i * (n + 1) + j, (i + 1) * (n + 1) + j, (i + 1) * (n + 1) + j + 1, i * (n + 1) + j + 1
            faces += [(a, b, c), (a, c, d)] if (i + j) % 2 else [(a, b, d), (b, c, d)]
    return v, np.array(faces, dtype=np.int64)


def box(n: int = 12) -> tuple[np.ndarray, np.ndarray]:
    """A closed, welded cube [-1, 1]^3, each side an n x n grid (sharp edges and corners)."""
    index: dict[tuple[int, int, int], int] = {}
    verts: list[tuple[float, float, float]] = []
    faces: list[tuple[int, int, int]] = []

    def vid(p: tuple[int, int, int]) -> int:
        if p not in index:
            index[p] = len(verts)
            verts.append(tuple(2.0 * c / n - 1.0 for c in p))
        return index[p]

    for axis in range(3):
        for side in (0, n):
            u, w = (axis + 1) % 3, (axis + 2) % 3
            for i in range(n):
                for j in range(n):
                    quad = []
                    for di, dj in ((0, 0), (1, 0), (1, 1), (0, 1)):
                        p = [0, 0, 0]
                        p[axis], p[u], p[w] = side, i + di, j + dj
                        quad.append(vid(tuple(p)))
                    if side == 0:
                        quad.reverse()
                    faces += [(quad[0], quad[1], quad[2]), (quad[0], quad[2], quad[3])]
    return np.array(verts), np.array(faces, dtype=np.int64)


def noisy(v: np.ndarray, faces: np.ndarray, sigma: float, seed: int = 1) -> np.ndarray:
    """v plus Gaussian noise of `sigma` mean edge lengths in every direction."""
    rng = np.random.default_rng(seed)
    edge = rsmooth.mean_edge_length(v, faces)
    return v + rng.normal(0.0, sigma * edge, v.shape)


def has_opencl() -> bool:
    return bool(rsmooth.devices())


def require_opencl() -> None:
    """Skips an OpenCL test where no device exists, unless RSMOOTH_REQUIRE_OPENCL=1 (CI)."""
    if not has_opencl():
        if os.environ.get("RSMOOTH_REQUIRE_OPENCL") == "1":
            pytest.fail("no OpenCL device, and RSMOOTH_REQUIRE_OPENCL=1")
        pytest.skip("no OpenCL device")


@pytest.fixture(scope="session")
def cli() -> pathlib.Path:
    """The rsmooth command built from this checkout (RSMOOTH_CLI, else build/rsmooth)."""
    path = pathlib.Path(os.environ.get("RSMOOTH_CLI", ROOT / "build" / "rsmooth"))
    if not path.is_file():
        if os.environ.get("RSMOOTH_REQUIRE_CLI") == "1":
            pytest.fail(f"the rsmooth command is not at {path}")
        pytest.skip(f"the rsmooth command is not built ({path})")
    return path


def write_obj(path: pathlib.Path, v: np.ndarray, faces: np.ndarray) -> None:
    with open(path, "w") as f:
        for p in v:
            f.write("v %r %r %r\n" % tuple(float(c) for c in p))
        for t in faces:
            f.write("f %d %d %d\n" % tuple(int(i) + 1 for i in t))


def read_obj_vertices(path: pathlib.Path) -> np.ndarray:
    rows = [line.split()[1:4] for line in open(path) if line.startswith("v ")]
    return np.array(rows, dtype=np.float64)


def run_python(code: str, env: dict[str, str]) -> subprocess.CompletedProcess:
    """Runs `code` in a fresh interpreter (from outside the source tree) with `env` added."""
    full = dict(os.environ)
    full.update(env)
    return subprocess.run(
        [sys.executable, "-c", code], env=full, cwd="/", capture_output=True, text=True,
        timeout=300,
    )
