"""What rsmooth takes and refuses, and what comes back: every real floating dtype (the result in
the input's), a trimesh Scene named, a mesh without triangles named as such, subclasses of mesh
objects kept (and their copies made before the work), meshio's normals recomputed, PyVista's
triangle strips filtered and kept, and one keyword path for numpy and PyOpenCL arrays. The oracle
is the arrays path on float32/float64 arrays, and numpy's own normals."""

from __future__ import annotations

import numpy as np
import pytest

import rsmooth
import rsmooth._filter
import rsmooth._options
import rsmooth._pyopencl
from conftest import box, noisy


@pytest.fixture(scope="module")
def cube() -> tuple[np.ndarray, np.ndarray]:
    v, f = box(6)
    return noisy(v, f, 0.2, seed=9), f


def reference(v: np.ndarray, f: np.ndarray, **kw) -> np.ndarray:
    return rsmooth.smooth(v, f, device="reference", **kw)


@pytest.mark.parametrize("dtype, work", [(np.float16, np.float32), (np.longdouble, np.float64)])
def test_every_float_dtype(cube, dtype, work):
    v, f = cube
    given = v.astype(dtype)
    out = reference(given, f)
    assert out.dtype == np.dtype(dtype) and out.shape == v.shape
    # the filter on the working dtype, given back in the caller's
    assert np.array_equal(out, reference(given.astype(work), f).astype(dtype))
    assert not np.array_equal(out, given)  # it did filter
    p, n = rsmooth.smooth_points(given, given, return_normals=True)
    assert p.dtype == n.dtype == np.dtype(dtype)


def test_integer_and_complex_dtypes_refused(cube):
    v, f = cube
    with pytest.raises(TypeError, match="not a floating-point dtype"):
        reference(v.astype(np.int32), f)
    with pytest.raises(TypeError, match="real floating-point"):
        reference(v.astype(np.complex128), f)


def test_trimesh_scene_named():
    trimesh = pytest.importorskip("trimesh")
    scene = trimesh.Scene([trimesh.creation.box(), trimesh.creation.icosphere()])
    with pytest.raises(TypeError, match=r"trimesh\.Scene with 2 geometries.*force='mesh'"):
        rsmooth.smooth(scene, device="reference")
    with pytest.raises(TypeError, match=r"trimesh\.Scene"):
        rsmooth.smooth_points(scene)


# (auto=True reads no noise there, so runs nothing and gives the input back)
@pytest.mark.parametrize("kw", [dict(best=True), dict(vertex_updates=3)])
def test_no_triangles_named_not_sigma_f(cube, kw):
    v, _ = cube
    with pytest.raises(ValueError) as e:
        reference(v, np.zeros((0, 3), dtype=np.int64), **kw)
    assert "faces: none given" in str(e.value) and "sigma_f" not in str(e.value)
    # triangles of no area: no edge of non-zero length
    flat = np.zeros((3, 3))
    with pytest.raises(ValueError, match="no edge of non-zero length"):
        reference(flat, np.array([[0, 1, 2]]), **kw)


def test_trimesh_subclass_kept(cube):
    trimesh = pytest.importorskip("trimesh")
    v, f = cube

    class Tagged(trimesh.Trimesh):
        def __init__(self, tag, **kw):
            super().__init__(**kw)
            self.tag = tag

    mesh = Tagged("mine", vertices=v, faces=f, process=False)
    out = rsmooth.smooth(mesh, device="reference")
    assert type(out) is Tagged and out is not mesh and out.tag == "mine"
    assert np.array_equal(out.vertices, reference(v, f))
    assert np.array_equal(mesh.vertices, v)  # the input untouched
    out.tag = "changed"
    assert mesh.tag == "mine"


def test_meshio_subclass_kept_and_checked_before_the_work(cube, monkeypatch):
    meshio = pytest.importorskip("meshio")
    v, f = cube

    class Tagged(meshio.Mesh):
        def __init__(self, tag, points, cells, **kw):
            super().__init__(points, cells, **kw)
            self.tag = tag

    mesh = Tagged("mine", v, [("triangle", f)])
    out = rsmooth.smooth(mesh, device="reference")
    assert type(out) is Tagged and out.tag == "mine"
    assert np.array_equal(out.points, reference(v, f))

    # a copy that fails, fails before the filter runs
    class Uncopyable(meshio.Mesh):
        def __deepcopy__(self, memo):
            raise RuntimeError("no copies")

    ran = []
    real = rsmooth._rsmooth._smooth
    monkeypatch.setattr(rsmooth._rsmooth, "_smooth", lambda *a: ran.append(1) or real(*a))
    with pytest.raises(RuntimeError, match="no copies"):
        rsmooth.smooth(Uncopyable(v, [("triangle", f)]), device="reference")
    assert not ran


def numpy_vertex_normals(v: np.ndarray, f: np.ndarray) -> np.ndarray:
    n = np.zeros_like(v)
    cross = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    for k in range(3):
        np.add.at(n, f[:, k], cross)
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def test_meshio_normals_recomputed(cube):
    meshio = pytest.importorskip("meshio")
    v, f = cube
    stale = numpy_vertex_normals(v, f).astype(np.float32)
    cell = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    mesh = meshio.Mesh(v, [("triangle", f)], point_data={"Normals": stale},
                       cell_data={"Normals": [cell / np.linalg.norm(cell, axis=1, keepdims=True)]})
    out = rsmooth.smooth(mesh, device="reference")
    p = np.asarray(out.points)
    got = out.point_data["Normals"]
    assert got.dtype == np.float32 and got.shape == v.shape
    assert np.allclose(got, numpy_vertex_normals(p, f), atol=1e-6)
    assert not np.allclose(got, stale, atol=1e-3)
    assert np.array_equal(mesh.point_data["Normals"], stale)  # the input's untouched
    c = np.cross(p[f[:, 1]] - p[f[:, 0]], p[f[:, 2]] - p[f[:, 0]])
    assert np.allclose(out.cell_data["Normals"][0], c / np.linalg.norm(c, axis=1, keepdims=True))


def test_pyvista_strips_filtered_and_kept(cube):
    pv = pytest.importorskip("pyvista")
    v, f = cube
    triangles = pv.PolyData(v, np.hstack([np.full((len(f), 1), 3), f]).ravel())
    strips = triangles.strip()
    assert strips.strips.size and not strips.faces.size
    out = rsmooth.smooth(strips, device="reference")
    assert type(out) is type(strips)
    assert np.array_equal(out.strips, strips.strips) and not out.faces.size  # still strips
    # the strips' triangles are the mesh's: the filter on them is the filter on the mesh
    whole = strips.triangulate()
    expected = reference(np.asarray(strips.points), np.asarray(whole.faces).reshape(-1, 4)[:, 1:])
    assert np.array_equal(out.points, expected)
    assert not np.array_equal(out.points, strips.points)


def test_pyvista_lines_and_vertex_cells_refused(cube):
    pv = pytest.importorskip("pyvista")
    v, f = cube
    cells = np.hstack([np.full((len(f), 1), 3), f]).ravel()
    with pytest.raises(ValueError, match="has lines; only triangles and triangle strips"):
        rsmooth.smooth(pv.PolyData(v, cells, lines=np.array([2, 0, 1])), device="reference")
    with pytest.raises(ValueError, match="has vertex cells"):
        rsmooth.smooth(pv.PolyData(v, cells, verts=np.array([1, 0])), device="reference")
    quads = pv.PolyData(v[:4], np.array([4, 0, 1, 2, 3]))
    with pytest.raises(ValueError, match="polygons that are not triangles.*triangulate"):
        rsmooth.smooth(quads, device="reference")


def test_one_keyword_path_for_numpy_and_pyopencl(cube, monkeypatch):
    """rsmooth.smooth and Context.smooth on pyopencl arrays go through one function for the
    keywords: a change there is a change for both."""
    seen = []
    real = rsmooth._options._filter_params
    monkeypatch.setattr(rsmooth._options, "_filter_params",
                        lambda *a, **kw: seen.append(kw["method"]) or real(*a, **kw))
    monkeypatch.setattr(rsmooth._filter, "_filter_params", rsmooth._options._filter_params)
    monkeypatch.setattr(rsmooth._pyopencl, "_filter_params", rsmooth._options._filter_params)
    v, f = cube
    reference(v, f, method="gaussian")
    assert seen == ["gaussian"]
    cl = pytest.importorskip("pyopencl")
    cl_array = pytest.importorskip("pyopencl.array")
    try:
        devices = [d for p in cl.get_platforms() for d in p.get_devices(cl.device_type.CPU)]
    except cl.Error as e:
        pytest.skip(f"pyopencl finds no OpenCL platform ({e})")
    if not devices:
        pytest.skip("no CPU OpenCL device for pyopencl")
    queue = cl.CommandQueue(cl.Context(devices[:1]))
    with rsmooth.Context(queue=queue) as ctx:
        array = cl_array.to_device(queue, v.astype(np.float32))
        with pytest.raises(ValueError, match="faces: none given"):
            ctx.smooth(array, np.zeros((0, 3), dtype=np.int64), best=True)
        out = ctx.smooth(array, f, method="gaussian").get()
    assert seen[1:] == ["robust", "gaussian"]
    expected = rsmooth.smooth(v.astype(np.float32), f, device="cpu", method="gaussian")
    assert np.allclose(out, expected, atol=1e-5)
