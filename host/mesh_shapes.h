/* Analytic test shapes and reproducible noise, shared by the demo program and the tests. They are
 * generated, so the demo and core tests need no data files. Not part of the installed library. */
#ifndef RSMOOTH_MESH_SHAPES_H
#define RSMOOTH_MESH_SHAPES_H

#include <stddef.h>
#include <stdint.h>

typedef struct shape_mesh {
    size_t vertex_count;
    double *xyz; /* 3 * vertex_count */
    size_t triangle_count;
    uint32_t *indices; /* 3 * triangle_count, counter-clockwise seen from outside */
} shape_mesh;

/* All return 0 on success, -1 on bad arguments or allocation failure (mesh then empty). */

/* Plane z = 0 over [0, nx*spacing] x [0, ny*spacing], nx*ny quads split into 2 triangles each. */
int shape_plane(shape_mesh *mesh, int nx, int ny, double spacing);

/* Closed axis-aligned cube [-size/2, size/2]^3, each face an n x n grid of quads (2 triangles
 * each), vertices shared along edges and corners (welded: 6n^2 + 2 vertices). */
int shape_cube(shape_mesh *mesh, int n, double size);

/* Closed sphere of `radius` centred at the origin: an icosahedron subdivided `levels` times,
 * vertices projected onto the sphere. */
int shape_sphere(shape_mesh *mesh, int levels, double radius);

/* Closed cylinder (sharp rims, curved side, flat caps) of `radius` and `height` along z, about
 * `target_triangles` triangles of near-uniform size. */
int shape_capped_cylinder(shape_mesh *mesh, double radius, double height, size_t target_triangles);

/* Area-weighted vertex normals (unit; zero for unreferenced vertices), 3 per vertex. */
int shape_vertex_normals(const shape_mesh *mesh, double *normals);

/* Mean length of unique undirected edges. */
double shape_mean_edge_length(const shape_mesh *mesh);

/* Moves each vertex along its normal by Gaussian noise of standard deviation
 * sigma * mean edge length, from a deterministic generator seeded with `seed`. */
int shape_add_normal_noise(shape_mesh *mesh, double sigma, uint64_t seed);

/* Standard normal variate from a splitmix64 state (deterministic on every platform). */
double shape_gaussian(uint64_t *state);

/* Every triangle gets its own three vertices (a fully unindexed soup of the same surface):
 * out->xyz[9t + 3c + k] = in vertex indices[3t + c], coordinate k. */
int shape_unindex(const shape_mesh *in, shape_mesh *out);

/* Deep copy. */
int shape_copy(const shape_mesh *in, shape_mesh *out);

/* Mean angle in degrees between the face normals of two meshes sharing `mesh`'s triangles, one with
 * mesh->xyz, the other with `other_xyz` (3 per vertex). Degenerate faces are skipped. */
double shape_face_normal_error_deg(const shape_mesh *mesh, const double *other_xyz);

void shape_free(shape_mesh *mesh);

#endif
