"""Smooths a mesh file with trimesh and writes it coloured by the filter's confidence, e.g.

    python python/examples/trimesh_confidence.py scan.ply -o smooth.ply --sigma-f 1.5

The confidence k(p) / sum a f is near 1 where the neighbourhood agreed (flat and smooth parts)
and low at features and outliers; the output's vertex colours run from red (0) to white (1), so
a viewer shows where the filter held back. trimesh loads with process=False, which keeps the
vertex order (merging vertices would reorder them)."""

import argparse

import numpy as np
import trimesh

import rsmooth


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("input", help="a mesh file trimesh reads (PLY, OBJ, OFF, STL, ...)")
    ap.add_argument("-o", "--output", required=True,
                    help="the smoothed mesh, coloured; any format trimesh writes with colours (PLY)")
    ap.add_argument("--sigma-f", type=float, help="spatial width, mean edge lengths (default 2)")
    ap.add_argument("--sigma-g", type=float,
                    help="influence width, mean edge lengths (default 0.5)")
    ap.add_argument("--device", default="auto", help="auto, gpu, cpu, reference, P:D or a name")
    args = ap.parse_args()

    mesh = trimesh.load(args.input, process=False, force="mesh")
    smooth, confidence = rsmooth.smooth(mesh.vertices, mesh.faces, sigma_f=args.sigma_f,
                                        sigma_g=args.sigma_g, device=args.device, confidence=True)
    moved = np.linalg.norm(smooth - mesh.vertices, axis=1)
    edge = rsmooth.mean_edge_length(mesh.vertices, mesh.faces)
    print(f"{args.input}: {len(mesh.vertices)} vertices; moved {moved.mean() / edge:.3f} mean edge "
          f"lengths on average, confidence {confidence.min():.2f} to {confidence.max():.2f} "
          f"(median {np.median(confidence):.2f})")
    shade = (255 * np.clip(confidence, 0, 1)).astype(np.uint8)
    colors = np.column_stack([np.full_like(shade, 255), shade, shade, np.full_like(shade, 255)])
    out = trimesh.Trimesh(smooth, mesh.faces, vertex_colors=colors, process=False)
    out.export(args.output)
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
