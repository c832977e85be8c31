"""One noisy cube through each mesh library's own object: rsmooth.smooth(mesh) returns a new object
of the same type, and the script prints each type and the error before and after, e.g.

    python python/examples/mesh_objects.py --device reference

A library that is not installed is named and skipped."""

import argparse
import importlib

import numpy as np

import rsmooth


def noisy_cube(n: int = 10, noise: float = 0.2, seed: int = 3):
    """A closed cube of 6 n x n grids (welded), and the same plus noise in edge lengths."""
    grid = np.linspace(-1, 1, n + 1)
    index, verts, faces = {}, [], []
    for axis in range(3):
        u, w = (axis + 1) % 3, (axis + 2) % 3
        for side in (0, n):
            for i in range(n):
                for j in range(n):
                    quad = []
                    for di, dj in ((0, 0), (1, 0), (1, 1), (0, 1)):
                        key = [0, 0, 0]
                        key[axis], key[u], key[w] = side, i + di, j + dj
                        key = tuple(key)
                        if key not in index:
                            index[key] = len(verts)
                            verts.append([grid[k] for k in key])
                        quad.append(index[key])
                    if side == 0:
                        quad.reverse()
                    faces += [quad[:3], [quad[0], quad[2], quad[3]]]
    truth, faces = np.array(verts), np.array(faces)
    edge = rsmooth.mean_edge_length(truth, faces)
    rng = np.random.default_rng(seed)
    return truth, truth + rng.normal(0, noise * edge, truth.shape), faces


def make(library: str, v: np.ndarray, f: np.ndarray):
    """The library's own mesh object of (v, f)."""
    lib = importlib.import_module(library)
    if library == "trimesh":
        return lib.Trimesh(v, f, process=False)
    if library == "open3d":
        return lib.geometry.TriangleMesh(lib.utility.Vector3dVector(v),
                                         lib.utility.Vector3iVector(f))
    if library == "pyvista":
        return lib.PolyData(v, np.hstack([np.full((len(f), 1), 3), f]).ravel())
    return lib.Mesh(v, [("triangle", f)])  # meshio


def positions(mesh) -> np.ndarray:
    for name in ("vertices", "points"):
        if hasattr(mesh, name):
            return np.asarray(getattr(mesh, name))
    raise TypeError(type(mesh))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--device", default="auto", help="auto, gpu, cpu, reference, P:D or a name")
    ap.add_argument("--best", action="store_true", help="rsmooth's most accurate mode")
    args = ap.parse_args()
    truth, v, f = noisy_cube()
    before = rsmooth.compare(v, truth, f)
    for library in ("trimesh", "open3d", "pyvista", "meshio"):
        try:
            mesh = make(library, v, f)
        except ImportError:
            print(f"{library:8} not installed (pip install {library}): skipped")
            continue
        out = rsmooth.smooth(mesh, device=args.device, best=args.best)
        after = rsmooth.compare(positions(out), truth, f)
        kind = f"{type(out).__module__}.{type(out).__qualname__}"
        print(f"{library:8} in: {type(mesh).__qualname__:13} out: {kind:40} "
              f"theta {before['theta']:.2f} -> {after['theta']:.2f} deg")


if __name__ == "__main__":
    main()
