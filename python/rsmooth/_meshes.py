"""Mesh objects in, the same kind out: trimesh, Open3D, PyVista and meshio objects are read as
arrays and copied (a subclass stays that subclass) before the filter runs, so that whatever can
fail fails before the work; the filtered positions then go into the copy, everything else kept.

The libraries are recognised by the names of the object's classes, never imported here: a caller
who passes a trimesh mesh has trimesh loaded already, and one who passes arrays loads none of them.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass
from typing import Any, Callable, Optional

import numpy as np


@dataclass
class MeshInput:
    """What the filter reads from an object, and how to make the result of the same type."""

    vertices: Any
    faces: Optional[Any]  # None for a point cloud
    normals: Optional[Any]  # a point cloud's normals
    rebuild: Callable[..., Any]  # (positions[, normals]) -> the copy made when read, filled


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


def scene_error(obj: Any, points: bool) -> Optional[str]:
    """What to say of a trimesh Scene (trimesh.load's result for files of several meshes, and for
    some formats of one): None for anything else."""
    if not any(c.__module__.split(".")[0] == "trimesh" and c.__name__ == "Scene"
               for c in type(obj).__mro__):
        return None
    count = len(getattr(obj, "geometry", {}))
    call = "smooth_points" if points else "smooth"
    return (
        f"{call}: got a trimesh.Scene with {count} geometr{'y' if count == 1 else 'ies'}, not a "
        "mesh: pass scene.dump(concatenate=True) (one mesh in the scene's frame), one of "
        "scene.geometry's meshes, or load the file with trimesh.load(path, force='mesh')"
    )


def read(obj: Any, points: bool) -> MeshInput:
    """The arrays of a known mesh object; `points` says the caller wants a point cloud."""
    kind = _kind(obj)
    if kind is None:
        raise TypeError(f"expected arrays or a mesh object, got {type(obj).__name__}")
    return _READERS[kind](obj, points)


def _same_class(made: Any, original: Any) -> Any:
    """`made`, a library's copy of `original` (its base class where `original` is a subclass),
    as `original`'s own class, with the attributes the subclass added copied too."""
    cls = type(original)
    if type(made) is cls:
        return made
    out = object.__new__(cls)
    state = {k: copy.deepcopy(v) for k, v in vars(original).items() if k not in vars(made)}
    vars(out).update(vars(made))
    vars(out).update(state)
    return out


def _vertex_normals(positions: np.ndarray, faces: np.ndarray, old: np.ndarray) -> np.ndarray:
    """Unit vertex normals, the area-weighted mean of the triangles' around each vertex; a vertex
    in no triangle (or in triangles of no area) keeps its `old` normal. `old`'s dtype."""
    p = np.asarray(positions, dtype=np.float64)
    t = np.asarray(faces, dtype=np.int64)
    cross = np.cross(p[t[:, 1]] - p[t[:, 0]], p[t[:, 2]] - p[t[:, 0]])  # 2 x area, outward
    n = np.zeros_like(p)
    for corner in range(3):
        np.add.at(n, t[:, corner], cross)
    length = np.linalg.norm(n, axis=1)
    out = np.array(old, dtype=np.float64, copy=True).reshape(p.shape)
    has = length > 0
    out[has] = n[has] / length[has, None]
    return out.astype(np.asarray(old).dtype, copy=False)


def _mesh_only(kind: str, points: bool) -> None:
    if points:
        raise TypeError(f"smooth_points: a {kind} is a triangle mesh; call rsmooth.smooth(mesh)")


def _trimesh(mesh: Any, points: bool) -> MeshInput:
    _mesh_only("trimesh.Trimesh", points)

    out = _same_class(mesh.copy(), mesh)  # colours, UVs, metadata, vertex attributes

    def rebuild(positions: np.ndarray) -> Any:
        out.vertices = positions  # and the cached normals are dropped, to be recomputed
        return out

    return MeshInput(np.asarray(mesh.vertices), np.asarray(mesh.faces), None, rebuild)


def _open3d_mesh(mesh: Any, points: bool) -> MeshInput:
    _mesh_only("open3d TriangleMesh", points)
    vector = type(mesh.vertices)  # open3d.utility.Vector3dVector, without importing open3d

    out = type(mesh)(mesh)  # the copy constructor: colours, UVs, materials kept

    def rebuild(positions: np.ndarray) -> Any:
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

    out = type(cloud)(cloud)

    def rebuild(positions: np.ndarray, normals: np.ndarray) -> Any:
        out.points = vector(np.asarray(positions, dtype=np.float64))
        out.normals = vector(np.asarray(normals, dtype=np.float64))
        return out

    return MeshInput(np.asarray(cloud.points), None, np.asarray(cloud.normals), rebuild)


def _pyvista(poly: Any, points: bool) -> MeshInput:
    """A surface of triangles, given as triangles (``faces``) or triangle strips (``strips``):
    both are filtered, and the copy keeps the caller's cells as they were. Lines, vertex cells
    and other polygons are refused by name: they are not triangles to filter by."""
    surface = poly.faces.size > 0 or poly.strips.size > 0
    vertex_only = poly.n_points > 0 and not surface and poly.lines.size == 0
    if points or vertex_only:
        return _pyvista_points(poly, points)
    cells = np.asarray(poly.faces)
    # a VTK cell array [3, a, b, c, 3, ...] holds triangles only when every 4th entry is 3 (the
    # first other cell would start at a multiple of 4)
    polygons = cells.size % 4 != 0 or bool((cells[::4] != 3).any())
    others = [name for name, there in (
        ("lines", poly.lines.size > 0), ("vertex cells", poly.verts.size > 0),
        ("polygons that are not triangles", polygons)) if there]
    if others:
        raise ValueError(
            f"smooth: the pyvista PolyData has {' and '.join(others)}; only triangles and "
            "triangle strips are filtered (triangulate polygons first: mesh.triangulate(); "
            "remove lines and vertex cells)"
        )
    faces = cells.reshape(-1, 4)[:, 1:]
    if poly.strips.size:  # the strips' triangles too (VTK's triangle filter: the same points)
        whole = poly.triangulate()
        if whole.n_points != poly.n_points:
            raise ValueError("smooth: the pyvista PolyData's strips could not be triangulated "
                             "in place (mesh.triangulate() changed its points)")
        faces = np.asarray(whole.faces).reshape(-1, 4)[:, 1:]
    had_point_normals = "Normals" in poly.point_data
    had_cell_normals = "Normals" in poly.cell_data
    out = poly.copy(deep=True)  # point, cell and field data kept

    def rebuild(positions: np.ndarray) -> Any:
        out.points = positions
        if poly.strips.size and (had_point_normals or had_cell_normals):
            # VTK's normals filter would turn the strips into triangles: the point normals from
            # the triangles (the points are the same), the strips' cells kept; a cell normal per
            # strip has no one value, so cell normals are dropped
            out.point_data.pop("Normals", None)
            out.cell_data.pop("Normals", None)
            if had_point_normals:
                out.point_data["Normals"] = _vertex_normals(
                    positions, faces, poly.point_data["Normals"])
        elif had_point_normals or had_cell_normals:  # stale now: recomputed, same order
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

    out = poly.copy(deep=True)

    def rebuild(positions: np.ndarray, normals: np.ndarray) -> Any:
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

    # every cell block, point and cell data set kept (a subclass's own attributes too)
    out = copy.deepcopy(mesh)
    normals = [k for k, v in mesh.point_data.items()
               if k.lower() == "normals" and np.shape(v) == p.shape]
    cell_normals = [k for k in mesh.cell_data if k.lower() == "normals"]

    def rebuild(positions: np.ndarray) -> Any:
        out.points = positions.astype(p.dtype, copy=False)  # the filter's
        for key in normals:  # stale now: recomputed from the triangles
            out.point_data[key] = _vertex_normals(positions, faces, mesh.point_data[key])
        for key in cell_normals:  # the triangle blocks' face normals too
            for block, (cells, old) in enumerate(zip(mesh.cells, mesh.cell_data[key])):
                if cells.type == "triangle" and np.shape(old) == (len(cells.data), 3):
                    t = np.asarray(cells.data, dtype=np.int64)
                    q = np.asarray(positions, dtype=np.float64)
                    n = np.cross(q[t[:, 1]] - q[t[:, 0]], q[t[:, 2]] - q[t[:, 0]])
                    length = np.linalg.norm(n, axis=1)
                    new = np.array(old, dtype=np.float64, copy=True)
                    new[length > 0] = n[length > 0] / length[length > 0, None]
                    out.cell_data[key][block] = new.astype(np.asarray(old).dtype, copy=False)
        return out

    return MeshInput(p, faces, None, rebuild)


_READERS = {
    "trimesh.Trimesh": _trimesh,
    "open3d.TriangleMesh": _open3d_mesh,
    "open3d.PointCloud": _open3d_points,
    "pyvista.PolyData": _pyvista,
    "meshio.Mesh": _meshio,
}
