"""The libraries people hold their meshes in: trimesh (installed with the test extra), meshio and
Open3D where present. Their arrays go in as they are (trimesh's TrackedArray, Open3D's float64
vectors seen through np.asarray) and the result goes back."""

from __future__ import annotations

import numpy as np
import pytest

import rsmooth
from conftest import noisy


def test_trimesh():
    trimesh = pytest.importorskip("trimesh")
    truth = trimesh.creation.icosphere(subdivisions=4)
    mesh = truth.copy()
    mesh.vertices = noisy(np.asarray(truth.vertices), np.asarray(truth.faces), 0.3, seed=9)
    before = rsmooth.compare(mesh.vertices, truth.vertices, mesh.faces)
    mesh.vertices = rsmooth.smooth(mesh.vertices, mesh.faces, device="reference")
    after = rsmooth.compare(mesh.vertices, truth.vertices, mesh.faces)
    assert after["ev"] < 0.8 * before["ev"] and after["theta"] < 0.5 * before["theta"]
    # the faces (int64) and vertices (TrackedArray) went in untouched
    assert mesh.faces.dtype == np.int64 and np.array_equal(mesh.faces, truth.faces)


def test_meshio(tmp_path):
    meshio = pytest.importorskip("meshio")
    trimesh = pytest.importorskip("trimesh")
    sphere = trimesh.creation.icosphere(subdivisions=3)
    v = noisy(np.asarray(sphere.vertices), np.asarray(sphere.faces), 0.2)
    meshio.write_points_cells(tmp_path / "n.ply", v, [("triangle", sphere.faces)])
    m = meshio.read(tmp_path / "n.ply")
    out = rsmooth.smooth(m.points, m.cells_dict["triangle"], device="reference")
    assert out.shape == m.points.shape


def test_open3d():
    o3d = pytest.importorskip("open3d")
    mesh = o3d.geometry.TriangleMesh.create_sphere(radius=1.0, resolution=30)
    v = noisy(np.asarray(mesh.vertices), np.asarray(mesh.triangles), 0.2)
    mesh.vertices = o3d.utility.Vector3dVector(v)
    out = rsmooth.smooth(np.asarray(mesh.vertices), np.asarray(mesh.triangles), device="reference")
    mesh.vertices = o3d.utility.Vector3dVector(out)
    assert np.asarray(mesh.vertices).shape == v.shape
