"""Mesh objects in, the same kind out. The oracle is the arrays path on the same arrays (itself
checked against the C command in test_filter.py): an object's result must hold exactly those
positions, in its own type, with everything else it carried kept and its normals recomputed."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import rsmooth
from conftest import box, noisy, run_python


@pytest.fixture(scope="module")
def cube() -> tuple[np.ndarray, np.ndarray]:
    v, f = box(8)
    return noisy(v, f, 0.2, seed=4), f


def arrays_result(v: np.ndarray, f: np.ndarray, **kw) -> np.ndarray:
    return rsmooth.smooth(v, f, device="reference", **kw)


def test_trimesh(cube):
    trimesh = pytest.importorskip("trimesh")
    v, f = cube
    mesh = trimesh.Trimesh(v, f, process=False)
    colours = np.random.default_rng(1).integers(0, 255, (len(v), 4), dtype=np.uint8)
    mesh.visual.vertex_colors = colours
    mesh.metadata["name"] = "cube"
    normals_before = mesh.vertex_normals.copy()
    out = rsmooth.smooth(mesh, device="reference", best=True)
    assert type(out) is trimesh.Trimesh and out is not mesh
    assert np.array_equal(out.vertices, arrays_result(v, f, best=True))
    assert np.array_equal(out.faces, f) and np.array_equal(mesh.vertices, v)  # input untouched
    assert np.array_equal(out.visual.vertex_colors, colours) and out.metadata["name"] == "cube"
    fresh = trimesh.Trimesh(np.array(out.vertices), f, process=False)
    assert np.allclose(out.vertex_normals, fresh.vertex_normals)  # from the new positions
    assert not np.allclose(out.vertex_normals, normals_before)


def test_trimesh_confidence_and_context(cube):
    trimesh = pytest.importorskip("trimesh")
    from conftest import require_opencl

    v, f = cube
    mesh = trimesh.Trimesh(v, f, process=False)
    out, conf = rsmooth.smooth(mesh, device="reference", confidence=True)
    expect, expect_conf = arrays_result(v, f, confidence=True)
    assert np.array_equal(out.vertices, expect) and np.array_equal(conf, expect_conf)
    require_opencl()
    with rsmooth.Context("cpu") as ctx:
        on_device = ctx.smooth(mesh)
        assert type(on_device) is trimesh.Trimesh
        assert np.array_equal(on_device.vertices, ctx.smooth(v, f))


def test_open3d_triangle_mesh(cube):
    o3d = pytest.importorskip("open3d")
    v, f = cube
    mesh = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(v), o3d.utility.Vector3iVector(f))
    colours = np.random.default_rng(2).random((len(v), 3))
    mesh.vertex_colors = o3d.utility.Vector3dVector(colours)
    mesh.compute_vertex_normals()
    out = rsmooth.smooth(mesh, device="reference")
    assert type(out) is o3d.geometry.TriangleMesh and out is not mesh
    assert np.array_equal(np.asarray(out.vertices), arrays_result(v, f))
    assert np.array_equal(np.asarray(mesh.vertices), v)
    assert np.allclose(np.asarray(out.vertex_colors), colours)
    fresh = o3d.geometry.TriangleMesh(out.vertices, out.triangles)
    fresh.compute_vertex_normals()
    assert out.has_vertex_normals()
    assert np.allclose(np.asarray(out.vertex_normals), np.asarray(fresh.vertex_normals))


def test_pyvista_polydata(cube):
    pv = pytest.importorskip("pyvista")
    v, f = cube
    poly = pv.PolyData(v.astype(np.float32), np.hstack([np.full((len(f), 1), 3), f]).ravel())
    poly.point_data["height"] = v[:, 2].copy()
    poly = poly.compute_normals(split_vertices=False, consistent_normals=False,
                                auto_orient_normals=False)
    out = rsmooth.smooth(poly, device="reference")
    assert type(out) is pv.PolyData and out is not poly
    expect = arrays_result(v.astype(np.float32), f)
    assert out.points.dtype == np.float32 and np.array_equal(out.points, expect)
    assert np.array_equal(out.point_data["height"], v[:, 2])
    fresh = pv.PolyData(expect, poly.faces).compute_normals(
        split_vertices=False, consistent_normals=False, auto_orient_normals=False)
    assert np.allclose(out.point_data["Normals"], fresh.point_data["Normals"], atol=1e-6)
    assert np.allclose(out.cell_data["Normals"], fresh.cell_data["Normals"], atol=1e-6)
    with pytest.raises(ValueError, match="triangulate"):
        rsmooth.smooth(pv.Plane(i_resolution=3, j_resolution=3), device="reference")


def test_meshio(cube):
    meshio = pytest.importorskip("meshio")
    v, f = cube
    lines = np.array([[0, 1], [1, 2]])
    mesh = meshio.Mesh(v, [("triangle", f[:10]), ("line", lines), ("triangle", f[10:])],
                       point_data={"t": np.arange(len(v), dtype=np.float64)},
                       cell_data={"id": [np.arange(10), np.arange(2), np.arange(len(f) - 10)]})
    out = rsmooth.smooth(mesh, device="reference")
    assert type(out) is meshio.Mesh and out is not mesh
    assert np.array_equal(out.points, arrays_result(v, f))
    assert [c.type for c in out.cells] == ["triangle", "line", "triangle"]
    assert np.array_equal(out.cells[1].data, lines) and np.array_equal(out.point_data["t"],
                                                                         np.arange(len(v)))
    assert np.array_equal(out.cell_data["id"][2], np.arange(len(f) - 10))
    assert np.array_equal(mesh.points, v)
    with pytest.raises(ValueError, match="no triangle cells"):
        rsmooth.smooth(meshio.Mesh(v, [("line", lines)]), device="reference")


def sphere_cloud(n: int = 800) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(5)
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    return d * (1 + rng.normal(0, 0.01, (n, 1))), d


def test_open3d_point_cloud():
    o3d = pytest.importorskip("open3d")
    p, n = sphere_cloud()
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(p))
    cloud.normals = o3d.utility.Vector3dVector(n)
    cloud.colors = o3d.utility.Vector3dVector(np.full_like(p, 0.5))
    out, conf = rsmooth.smooth_points(cloud, confidence=True)
    expect_p, expect_n, expect_c = rsmooth.smooth_points(p, n, return_normals=True,
                                                         confidence=True)
    assert type(out) is o3d.geometry.PointCloud
    assert np.array_equal(np.asarray(out.points), expect_p)
    assert np.array_equal(np.asarray(out.normals), expect_n) and np.array_equal(conf, expect_c)
    assert np.allclose(np.asarray(out.colors), 0.5)
    with pytest.raises(ValueError, match="no normals"):
        rsmooth.smooth_points(o3d.geometry.PointCloud(o3d.utility.Vector3dVector(p)))
    with pytest.raises(TypeError, match="smooth_points"):
        rsmooth.smooth(cloud)


def test_pyvista_point_cloud():
    pv = pytest.importorskip("pyvista")
    p, n = sphere_cloud()
    cloud = pv.PolyData(p)
    cloud.point_data["Normals"] = n
    out = rsmooth.smooth_points(cloud)
    expect_p, expect_n = rsmooth.smooth_points(p, n, return_normals=True)
    assert type(out) is pv.PolyData and out.n_points == len(p)
    assert np.array_equal(out.points, expect_p)
    assert np.array_equal(out.point_data["Normals"], expect_n)
    with pytest.raises(TypeError, match="smooth_points"):
        rsmooth.smooth(cloud)


def test_misuse_named(cube):
    v, f = cube
    with pytest.raises(TypeError, match="faces: missing"):
        rsmooth.smooth(v)
    with pytest.raises(TypeError, match="normals: missing"):
        rsmooth.smooth_points(v)
    trimesh = pytest.importorskip("trimesh")
    with pytest.raises(TypeError, match="not taken with a mesh object"):
        rsmooth.smooth(trimesh.Trimesh(v, f, process=False), f)
    with pytest.raises(TypeError, match="triangle mesh"):
        rsmooth.smooth_points(trimesh.Trimesh(v, f, process=False))


def test_no_mesh_library_imported_for_arrays():
    r = run_python(
        textwrap.dedent(
            """
            import sys, numpy as np, rsmooth
            v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, .2]])
            rsmooth.smooth(v, [[0, 1, 2], [1, 3, 2]], device="reference")
            print(sorted(m for m in ("trimesh", "open3d", "pyvista", "meshio") if m in sys.modules))
            """
        ),
        {},
    )
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "[]"


STUBS = {  # the four libraries' classes as stubs: the check needs none of them installed
    "trimesh/__init__.pyi": "class Trimesh: ...\n",
    "open3d/__init__.pyi": "from . import geometry as geometry\n",
    "open3d/geometry.pyi": "class TriangleMesh: ...\nclass PointCloud: ...\n",
    "pyvista/__init__.pyi": "class PolyData: ...\n",
    "meshio/__init__.pyi": "class Mesh: ...\n",
}


def test_overloads_seen_by_mypy(tmp_path):
    """The overloads give each object's own type back, arrays an array, and a misspelt keyword
    is an error (reveal_type through mypy)."""
    pytest.importorskip("mypy")
    for name, text in STUBS.items():
        (tmp_path / "stubs" / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / "stubs" / name).write_text(text)
    script = tmp_path / "use.py"
    script.write_text(textwrap.dedent(
        """
        import numpy as np, rsmooth, trimesh, open3d, pyvista, meshio
        reveal_type(rsmooth.smooth(trimesh.Trimesh()))
        reveal_type(rsmooth.smooth(open3d.geometry.TriangleMesh(), confidence=True))
        reveal_type(rsmooth.smooth(pyvista.PolyData(), best=True))
        reveal_type(rsmooth.smooth(meshio.Mesh(), device="reference"))
        reveal_type(rsmooth.smooth(np.zeros((3, 3)), [[0, 1, 2]], sigma_f=2.0))
        reveal_type(rsmooth.smooth(np.zeros((3, 3)), [[0, 1, 2]], confidence=True))
        reveal_type(rsmooth.smooth_points(open3d.geometry.PointCloud()))
        rsmooth.smooth(trimesh.Trimesh(), sigma_q=1.0)
        """
    ))
    r = subprocess.run(
        [sys.executable, "-m", "mypy", "--no-incremental", "--cache-dir", str(tmp_path / "cache"),
         str(script)],
        capture_output=True, text=True, cwd=tmp_path, env={**os.environ, "MYPYPATH": str(tmp_path / "stubs")},
    )
    seen = [line.split('Revealed type is "')[1].rstrip('"') for line in r.stdout.splitlines()
            if "Revealed type is" in line]
    seen = [t.replace("Tuple[", "tuple[") for t in seen]  # (older mypy)
    assert len(seen) == 7, r.stdout
    assert seen[0] == "trimesh.Trimesh" and seen[2] == "pyvista.PolyData", r.stdout
    assert seen[1].startswith("tuple[open3d.geometry.TriangleMesh, numpy.ndarray"), r.stdout
    assert seen[3] == "meshio.Mesh", r.stdout
    assert seen[4].startswith("numpy.ndarray") and seen[5].startswith("tuple[numpy.ndarray")
    assert seen[6] == "open3d.geometry.PointCloud"
    assert 'Unexpected keyword argument "sigma_q"' in r.stdout
    # and the package itself checks clean against its own overloads
    r = subprocess.run(
        [sys.executable, "-m", "mypy", "--no-incremental", "--cache-dir", str(tmp_path / "cache"),
         "--ignore-missing-imports", "-p", "rsmooth"],
        capture_output=True, text=True, cwd=tmp_path, env={**os.environ, "MYPYPATH": str(tmp_path / "stubs")},
    )
    assert r.returncode == 0, r.stdout


def test_typed_keywords_match_the_functions():
    """The TypedDicts the overloads take are exactly the functions' keywords (none forgotten)."""
    import inspect

    from rsmooth._typing import PointOptions, SmoothOptions

    smooth_kw = set(inspect.signature(rsmooth.smooth).parameters) - {"vertices", "faces"}
    assert set(SmoothOptions.__annotations__) == smooth_kw - {"confidence"}
    points_kw = set(inspect.signature(rsmooth.smooth_points).parameters) - {"points", "normals"}
    assert set(PointOptions.__annotations__) == points_kw - {"confidence", "return_normals"}
