"""Mesh objects in, the same kind out: trimesh, Open3D, PyVista and meshio objects are read as
arrays, filtered, and copied into a new object of the caller's type with everything else kept.

The libraries are recognised by the names of the object's classes, never imported here: a caller
who passes a trimesh mesh has trimesh loaded already, and one who passes arrays loads none of them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Optional

import numpy as np


@dataclass
class MeshInput:
    """What the filter reads from an object, and how to make the result of the same type."""

    vertices: Any
    faces: Optional[Any]  # None for a point cloud
    normals: Optional[Any]  # a point cloud's normals
    rebuild: Callable[..., Any]  # (positions[, normals]) -> a new object


def _kind(obj: Any) -> Optional[str]:
    """"library.Class" of the first class in obj's hierarchy that rsmooth knows, else None."""
    for cls in type(obj).__mro__:
        top = cls.__module__.split(".")[0]
        tensor = top == "open3d" and ".t." in cls.__module__  # open3d.t.geometry: not (yet)
        name = f"{top}.{'t.' if tensor else ''}{cls.__name__}"
        if name in _READERS:
            return name
    return None


def is_mesh_object(obj: Any) -> bool:
    return _kind(obj) is not None


def read(obj: Any, points: bool) -> MeshInput:
    """The arrays of a known mesh object; `points` says the caller wants a point cloud."""
    kind = _kind(obj)
    if kind is None:
        raise TypeError(f"expected arrays or a mesh object, got {type(obj).__name__}")
    return _READERS[kind](obj, points)


def _mesh_only(kind: str, points: bool) -> None:
    if points:
        raise TypeError(f"smooth_points: a {kind} is a triangle mesh; call rsmooth.smooth(mesh)")


def _trimesh(mesh: Any, points: bool) -> MeshInput:
    _mesh_only("trimesh.Trimesh", points)

    def rebuild(positions: np.ndarray) -> Any:
        out = mesh.copy()  # colours, UVs, metadata and vertex attributes come along
        out.vertices = positions  # and the cached normals are dropped, to be recomputed
        return out

    return MeshInput(np.asarray(mesh.vertices), np.asarray(mesh.faces), None, rebuild)


def _open3d_mesh(mesh: Any, points: bool) -> MeshInput:
    _mesh_only("open3d TriangleMesh", points)
    vector = type(mesh.vertices)  # open3d.utility.Vector3dVector, without importing open3d

    def rebuild(positions: np.ndarray) -> Any:
        out = type(mesh)(mesh)  # the copy constructor: colours, UVs, materials kept
        out.vertices = vector(np.asarray(positions, dtype=np.float64))
        if mesh.has_vertex_normals():
            out.compute_vertex_normals()
        if mesh.has_triangle_normals():
            out.compute_triangle_normals()
        return out

    return MeshInput(np.asarray(mesh.vertices), np.asarray(mesh.triangles), None, rebuild)


def _open3d_points(cloud: Any, points: bool) -> MeshInput:
    if not points:
        raise TypeError("smooth: an open3d PointCloud has no triangles; call rsmooth.smooth_points")
    if not cloud.has_normals():
        raise ValueError(
            "smooth_points: the open3d PointCloud has no normals "
            "(estimate them first: cloud.estimate_normals(), then orient them consistently)"
        )
    vector = type(cloud.points)

    def rebuild(positions: np.ndarray, normals: np.ndarray) -> Any:
        out = type(cloud)(cloud)
        out.points = vector(np.asarray(positions, dtype=np.float64))
        out.normals = vector(np.asarray(normals, dtype=np.float64))
        return out

    return MeshInput(np.asarray(cloud.points), None, np.asarray(cloud.normals), rebuild)


def _pyvista(poly: Any, points: bool) -> MeshInput:
    vertex_only = poly.n_points > 0 and poly.faces.size == 0 and poly.lines.size == 0
    if points or vertex_only:
        return _pyvista_points(poly, points)
    if not poly.is_all_triangles:
        raise ValueError(
            "smooth: the pyvista PolyData has cells that are not triangles "
            "(triangulate it first: mesh.triangulate())"
        )
    faces = poly.faces.reshape(-1, 4)[:, 1:]
    had_point_normals = "Normals" in poly.point_data
    had_cell_normals = "Normals" in poly.cell_data

    def rebuild(positions: np.ndarray) -> Any:
        out = poly.copy(deep=True)  # point, cell and field data kept
        out.points = positions
        if had_point_normals or had_cell_normals:  # stale now: recomputed, same order
            for data in (out.point_data, out.cell_data):  # (VTK would pass the old ones on)
                if "Normals" in data:
                    del data["Normals"]
            out.compute_normals(
                point_normals=had_point_normals, cell_normals=had_cell_normals,
                split_vertices=False, consistent_normals=False, auto_orient_normals=False,
                inplace=True,
            )
        return out

    return MeshInput(np.asarray(poly.points), faces, None, rebuild)


def _pyvista_points(poly: Any, points: bool) -> MeshInput:
    if not points:
        raise TypeError(
            "smooth: the pyvista PolyData has only vertices (a point cloud); "
            "call rsmooth.smooth_points"
        )
    if poly.faces.size or poly.lines.size:
        raise TypeError("smooth_points: the pyvista PolyData has faces; call rsmooth.smooth")
    if "Normals" not in poly.point_data:
        raise ValueError(
            'smooth_points: the pyvista PolyData has no point_data["Normals"] '
            "(consistently oriented normals are needed)"
        )

    def rebuild(positions: np.ndarray, normals: np.ndarray) -> Any:
        out = poly.copy(deep=True)
        out.points = positions
        out.point_data["Normals"] = normals.astype(np.asarray(poly.point_data["Normals"]).dtype)
        return out

    return MeshInput(np.asarray(poly.points), None, np.asarray(poly.point_data["Normals"]), rebuild)


def _meshio(mesh: Any, points: bool) -> MeshInput:
    _mesh_only("meshio.Mesh", points)
    p = np.asarray(mesh.points)
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"smooth: the meshio.Mesh's points have shape {p.shape}; (n, 3) needed")
    blocks = [c.data for c in mesh.cells if c.type == "triangle"]
    if not blocks:
        kinds = ", ".join(sorted({c.type for c in mesh.cells})) or "none"
        raise ValueError(f"smooth: the meshio.Mesh has no triangle cells (it has: {kinds})")
    faces = np.concatenate(blocks) if len(blocks) > 1 else blocks[0]

    def rebuild(positions: np.ndarray) -> Any:
        # every cell block, point and cell data set kept; the points are the filter's
        out = type(mesh)(
            positions.astype(p.dtype, copy=False),
            [type(c)(c.type, np.array(c.data)) for c in mesh.cells],
            point_data={k: np.array(v) for k, v in mesh.point_data.items()},
            cell_data={k: [np.array(b) for b in v] for k, v in mesh.cell_data.items()},
            field_data=dict(mesh.field_data),
            point_sets={k: np.array(v) for k, v in mesh.point_sets.items()},
            cell_sets={k: [np.array(b) for b in v] for k, v in mesh.cell_sets.items()},
        )
        return out

    return MeshInput(p, faces, None, rebuild)


_READERS = {
    "trimesh.Trimesh": _trimesh,
    "open3d.TriangleMesh": _open3d_mesh,
    "open3d.PointCloud": _open3d_points,
    "pyvista.PolyData": _pyvista,
    "meshio.Mesh": _meshio,
}
