/* Exact closest points on a triangle surface: the closest point of one triangle, and a uniform grid
 * over a surface's triangles that finds the closest point of the whole surface (the same answer as
 * testing every triangle). What rsmooth_compare's distances rest on. Internal, not installed.
 * Prefix rs_. */
#ifndef RSMOOTH_SURFACE_INDEX_H
#define RSMOOTH_SURFACE_INDEX_H

#include <stddef.h>
#include <stdint.h>

/* Squared distance from p to the triangle (a, b, c), the closest point written to `closest` (may
 * be NULL). Ericson, Real-Time Collision Detection, 5.1.5; degenerate triangles (collinear or
 * coincident corners) are treated as the segments they are, so the result is always finite for
 * finite input. */
double rs_closest_on_triangle(const double p[3], const double a[3], const double b[3],
                              const double c[3], double closest[3]);

/* A uniform grid over the triangles of a surface, answering "closest point of the surface" exactly
 * (the same answer as testing every triangle). Owns copies of the triangle corners: the caller's
 * arrays are not kept. Queries on one index may run concurrently (it is read-only). */
typedef struct rs_surface_index rs_surface_index;

/* Builds the index of `triangle_count` triangles (3 indices each, < vertex_count) over positions
 * `xyz` (3 doubles per vertex, finite). Zero-area triangles count as the segments or points they
 * are. triangle_count 0 gives an index whose queries find nothing. Returns NULL when out of memory
 * or on bad input (NULL arrays, an index out of range, a non-finite coordinate, extents that
 * overflow a double). */
rs_surface_index *rs_surface_index_build(const double *xyz, size_t vertex_count,
                                         const uint32_t *triangles, size_t triangle_count);

/* Distance from `point` to the surface; the closest point goes to `closest` and its triangle to
 * `triangle` (either may be NULL). Of equally near triangles, the lowest numbered. INFINITY
 * (closest and triangle untouched) when the index is empty or `point` is not finite. */
double rs_surface_index_query(const rs_surface_index *index, const double point[3],
                              double closest[3], size_t *triangle);

/* Frees the index. Accepts NULL. */
void rs_surface_index_free(rs_surface_index *index);

#endif /* RSMOOTH_SURFACE_INDEX_H */
