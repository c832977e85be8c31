"""Smooths a mesh file with Open3D: its vectors seen as numpy arrays, the result put back and its
normals recomputed, e.g.

    python python/examples/open3d_smooth.py scan.ply -o smooth.ply --best

Open3D is optional: without it this prints how to install it and exits (status 0)."""

import argparse
import sys

import numpy as np

import rsmooth


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("input", help="a mesh file Open3D reads (PLY, OBJ, OFF, STL, GLTF)")
    ap.add_argument("-o", "--output", required=True, help="the smoothed mesh")
    ap.add_argument("--best", action="store_true", help="rsmooth's most accurate mode (slower)")
    ap.add_argument("--device", default="auto", help="auto, gpu, cpu, reference, P:D or a name")
    args = ap.parse_args()
    try:
        import open3d as o3d
    except ImportError:
        print("open3d is not installed (pip install open3d): skipping")
        return

    mesh = o3d.io.read_triangle_mesh(args.input)
    if not mesh.has_triangles():
        sys.exit(f"{args.input}: no triangles read")
    vertices = np.asarray(mesh.vertices)  # float64 (n, 3), a view of Open3D's vector
    triangles = np.asarray(mesh.triangles)  # int32 (m, 3)
    print(f"{args.input}: {len(vertices)} vertices, {len(triangles)} triangles, estimated noise "
          f"{rsmooth.estimate_noise(vertices, triangles):.3f} mean edge lengths")
    smooth = rsmooth.smooth(vertices, triangles, best=args.best, device=args.device)
    mesh.vertices = o3d.utility.Vector3dVector(smooth)
    mesh.compute_vertex_normals()
    if not o3d.io.write_triangle_mesh(args.output, mesh):
        sys.exit(f"{args.output}: Open3D could not write it")
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
