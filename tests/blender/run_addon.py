"""The Blender add-on against the command, inside Blender (headless):

    blender -b --factory-startup --python-exit-code 1 --python tests/blender/run_addon.py -- \
        --zip rsmooth_blender-V.zip --mesh noisy.ply --rsmooth build/rsmooth --work DIR [--device cpu]

Run by tests/blender/run.sh, with BLENDER_USER_SCRIPTS set to a temporary folder (the add-on is
installed there). Steps: the mesh (binary little-endian PLY, as rsmooth-demo-shape writes it) is
written again with float32 coordinates, since Blender holds float32 and both sides must read the
same numbers; the command smooths that file (paper defaults, then --best); the zip is installed
and enabled (bpy.ops.preferences.addon_install, addon_enable); the mesh is built with
Mesh.from_pydata (no importer: the vertex order and faces are checked to be the file's); the
operator runs in each mode on the same device, and its positions are compared with the command's,
in mean edge lengths (mean |difference| <= 1e-6); Edit > Undo must bring the input back;
Blender's default cube keeps its corners within 1% of its diagonal in every mode but Paper
without Auto, with no triangle turned over; a device that does not exist must report an error
naming the object and change nothing.
"""

import argparse
import os
import subprocess
import sys
import time

import bpy
import numpy as np

TOLERANCE = 1e-6  # mean |difference| per coordinate, in mean edge lengths

PLY_TYPES = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2", "int16": "i2",
    "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
    "float": "f4", "float32": "f4", "double": "f8", "float64": "f8",
}


def read_ply(path):
    """(vertices (n, 3) as stored, faces (m, 3) int64) of a binary little-endian triangle PLY
    whose elements are vertex (scalar properties, x y z among them) then face (one list)."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii").splitlines()
    assert "format binary_little_endian 1.0" in header, f"{path}: not binary little-endian"
    elements = []
    for line in header:
        words = line.split()
        if words[0] == "element":
            elements.append((words[1], int(words[2]), []))
        elif words[0] == "property":
            elements[-1][2].append(words[1:])
    assert [e[0] for e in elements] == ["vertex", "face"], f"{path}: elements {elements}"
    _, n, vertex_properties = elements[0]
    dtype = np.dtype([(p[1], "<" + PLY_TYPES[p[0]]) for p in vertex_properties])
    vertex = np.frombuffer(data, dtype=dtype, count=n, offset=end)
    vertices = np.stack([vertex["x"], vertex["y"], vertex["z"]], axis=1)
    _, m, face_properties = elements[1]
    kind, count_type, index_type = face_properties[0][:3]
    assert kind == "list" and len(face_properties) == 1, f"{path}: face {face_properties}"
    row = np.dtype([("k", "<" + PLY_TYPES[count_type]), ("i", "<" + PLY_TYPES[index_type], 3)])
    faces = np.frombuffer(data, dtype=row, count=m, offset=end + n * dtype.itemsize)
    assert (faces["k"] == 3).all(), f"{path}: not all triangles"
    return vertices, faces["i"].astype(np.int64)


def write_ply(path, vertices, faces):
    """Binary little-endian PLY, float32 x y z and uchar/int faces."""
    header = (f"ply\nformat binary_little_endian 1.0\nelement vertex {len(vertices)}\n"
              "property float x\nproperty float y\nproperty float z\n"
              f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n")
    row = np.dtype([("k", "u1"), ("i", "<i4", 3)])
    face_rows = np.empty(len(faces), dtype=row)
    face_rows["k"] = 3
    face_rows["i"] = faces
    with open(path, "wb") as f:
        f.write(header.encode("ascii"))
        f.write(np.ascontiguousarray(vertices, dtype="<f4").tobytes())
        f.write(face_rows.tobytes())


def mean_edge_length(vertices, faces):
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    edges = np.unique(np.sort(edges, axis=1), axis=0)
    v = vertices.astype(np.float64)
    return float(np.linalg.norm(v[edges[:, 0]] - v[edges[:, 1]], axis=1).mean())


def positions(mesh):
    out = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", out)
    return out.reshape(-1, 3)


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(prog="run_addon.py")
    parser.add_argument("--zip", required=True)
    parser.add_argument("--mesh", required=True)
    parser.add_argument("--rsmooth", required=True, help="the command")
    parser.add_argument("--work", required=True)
    parser.add_argument("--device", default="cpu", choices=["cpu", "reference", "gpu", "auto"])
    args = parser.parse_args(argv)
    started = time.perf_counter()
    print(f"Blender {bpy.app.version_string}, Python {sys.version.split()[0]}, "
          f"numpy {np.__version__}")

    # the same float32 numbers on both sides
    vertices, faces = read_ply(args.mesh)
    vertices = vertices.astype(np.float32)
    noisy = os.path.join(args.work, "noisy32.ply")
    write_ply(noisy, vertices, faces)
    edge = mean_edge_length(vertices, faces)
    modes = [("PAPER", []), ("BEST", ["--best"])]
    expected = {}
    for mode, flags in modes:
        out = os.path.join(args.work, f"command-{mode.lower()}.ply")
        t = time.perf_counter()
        subprocess.run([args.rsmooth, noisy, "-o", out, "--device", args.device, "-q", "--force"]
                       + flags, check=True)
        expected[mode] = read_ply(out)
        assert (expected[mode][1] == faces).all(), f"{out}: the command changed the faces"
        print(f"command {mode.lower()}: {time.perf_counter() - t:.2f} s")

    # the add-on, from the zip
    t = time.perf_counter()
    result = bpy.ops.preferences.addon_install(filepath=os.path.abspath(args.zip), overwrite=True)
    assert result == {"FINISHED"}, f"addon_install: {result}"
    result = bpy.ops.preferences.addon_enable(module="rsmooth_blender")
    assert result == {"FINISHED"}, f"addon_enable: {result}"
    import rsmooth  # the vendored copy, which register() put first on sys.path

    user_scripts = os.environ.get("BLENDER_USER_SCRIPTS")
    print(f"add-on installed and enabled in {time.perf_counter() - t:.2f} s; rsmooth "
          f"{rsmooth.__version__} from {os.path.dirname(rsmooth.__file__)} "
          f"(extension {os.path.basename(rsmooth._rsmooth.__file__)})")
    if user_scripts:
        assert os.path.realpath(rsmooth.__file__).startswith(os.path.realpath(user_scripts)), \
            "rsmooth was not imported from the installed add-on"

    # the mesh, from the file's arrays, in its order
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    mesh = bpy.data.meshes.new("noisy")
    mesh.from_pydata(vertices.tolist(), [], faces.tolist())
    mesh.update()
    obj = bpy.data.objects.new("Noisy", mesh)
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    assert (positions(mesh) == vertices).all(), "the mesh's vertices are not the file's"
    corners = np.empty(len(mesh.polygons) * 3, dtype=np.int32)
    assert all(p.loop_total == 3 for p in mesh.polygons)
    mesh.polygons.foreach_get("vertices", corners)
    assert (corners.reshape(-1, 3) == faces).all(), "the mesh's faces are not the file's"
    print(f"mesh: {len(vertices)} vertices, {len(faces)} triangles, order and faces as the "
          f"file's; mean edge length {edge:.6g}")
    bpy.ops.ed.undo_push(message="input")

    failures = []
    for mode, _ in modes:
        t = time.perf_counter()
        # 'EXEC_DEFAULT', True: pushes an undo step as a call from the UI does (a plain call
        # from Python pushes none)
        result = bpy.ops.object.rsmooth_denoise("EXEC_DEFAULT", True, mode=mode,
                                                device=args.device.upper())
        seconds = time.perf_counter() - t
        assert result == {"FINISHED"}, f"operator {mode}: {result}"
        got = positions(mesh).astype(np.float64)
        want = expected[mode][0].astype(np.float64)
        difference = np.abs(got - want) / edge
        moved = np.linalg.norm(got - vertices, axis=1).mean() / edge
        print(f"{mode.lower()}: operator {seconds:.2f} s; mean |add-on - command| "
              f"{difference.mean():.3g} edge lengths (max {difference.max():.3g}); "
              f"vertices moved {moved:.3f} edge lengths on average")
        if not difference.mean() <= TOLERANCE:
            failures.append(f"{mode}: mean |difference| {difference.mean():.3g} > {TOLERANCE}")
        # Edit > Undo brings the input back: the operator's step (bl_options UNDO) is undone to
        # the "input" step pushed above
        try:
            bpy.ops.ed.undo()
        except RuntimeError as e:  # no step to undo: the operator pushed none
            raise SystemExit(f"FAILED: {mode}: ed.undo(): {e} (is UNDO in bl_options?)")
        mesh = bpy.data.meshes["noisy"]  # undo rebuilds the data: take it again
        back = positions(mesh)
        print(f"{mode.lower()}: after ed.undo(): max |vertex - input| "
              f"{np.abs(back - vertices).max():.3g}")
        if not (back == vertices).all():
            failures.append(f"{mode}: undo did not restore the input")
            mesh.vertices.foreach_set("co", vertices.ravel())
            mesh.update()

    # Blender's default cube: every mode but Paper at its fixed widths keeps its corners within
    # 1% of its diagonal, and no mode turns a triangle over (docs/do-no-harm.md)
    for obj in list(bpy.data.objects):
        obj.select_set(False)
    bpy.ops.mesh.primitive_cube_add()
    cube = bpy.context.active_object
    corners = positions(cube.data).astype(np.float64)
    diagonal = np.linalg.norm(corners.max(axis=0) - corners.min(axis=0))
    cube.data.calc_loop_triangles()
    tris = np.empty(len(cube.data.loop_triangles) * 3, dtype=np.int32)
    cube.data.loop_triangles.foreach_get("vertices", tris)
    tris = tris.reshape(-1, 3)

    def normals(x):
        return np.cross(x[tris[:, 1]] - x[tris[:, 0]], x[tris[:, 2]] - x[tris[:, 0]])
    for mode in ("PAPER", "BEST"):
        for auto in (False, True):
            cube.data.vertices.foreach_set("co", corners.astype(np.float32).ravel())
            cube.data.update()
            result = bpy.ops.object.rsmooth_denoise(mode=mode, auto=auto,
                                                    device=args.device.upper())
            assert result == {"FINISHED"}, f"operator {mode} on the cube: {result}"
            got = positions(cube.data).astype(np.float64)
            moved = np.linalg.norm(got - corners, axis=1).max() / diagonal
            turned = int(np.sum(np.sum(normals(got) * normals(corners), axis=1) < 0))
            name = mode.lower() + (" auto" if auto else "")
            print(f"default cube, {name}: corners moved at most {100 * moved:.2f}% of the "
                  f"diagonal, {turned} triangles turned over")
            if turned:
                failures.append(f"default cube, {name}: {turned} triangles turned over")
            if (mode != "PAPER" or auto) and not moved <= 0.01:
                failures.append(f"default cube, {name}: corners moved {100 * moved:.2f}% > 1%")
    bpy.data.objects.remove(cube)
    bpy.data.objects["Noisy"].select_set(True)
    bpy.context.view_layer.objects.active = bpy.data.objects["Noisy"]

    # an error: named, and nothing changed
    try:
        bpy.ops.object.rsmooth_denoise(device="NAME", device_name="no such device")
        failures.append("a device that does not exist: no error")
    except RuntimeError as e:
        message = str(e).strip()
        print(f"error reported: {message}")
        if "Noisy" not in message:
            failures.append(f"the error does not name the object: {message}")
    if not (positions(bpy.data.meshes["noisy"]) == vertices).all():
        failures.append("a failed call changed the mesh")

    print(f"run_addon.py: {time.perf_counter() - started:.1f} s")
    if failures:
        for failure in failures:
            print(f"FAILED: {failure}")
        raise SystemExit(1)
    print("run_addon.py: all checks passed")


main()
