/* Denoising error of a mesh against its ground truth (same vertices and triangles), and exact
 * closest-point queries on a triangle surface. Used by `rsmooth compare` and the tests; not part of
 * the installed library.
 *
 * The metrics follow ../shared/tools/meshmetrics.py (the independent oracle) except where that
 * script approximates: distances to a surface here are exact (the closest point over all
 * triangles), where the script only tries the 24 triangles with the nearest centroids. */
#ifndef RSMOOTH_MESH_METRICS_H
#define RSMOOTH_MESH_METRICS_H

#include <stddef.h>
#include <stdint.h>

/* ---- closest point on a triangle surface ----------------------------------------------------- */

/* Squared distance from p to the triangle (a, b, c), the closest point written to `closest` (may
 * be NULL). Ericson, Real-Time Collision Detection, 5.1.5; degenerate triangles (collinear or
 * coincident corners) are treated as the segments they are, so the result is always finite for
 * finite input. */
double surface_closest_on_triangle(const double p[3], const double a[3], const double b[3],
                                   const double c[3], double closest[3]);

/* A uniform grid over the triangles of a surface, answering "closest point of the surface" exactly
 * (the same answer as testing every triangle). Owns copies of the triangle corners: the caller's
 * arrays are not kept. Queries on one index may run concurrently (it is read-only). */
typedef struct surface_index surface_index;

/* Builds the index of `triangle_count` triangles (3 indices each, < vertex_count) over positions
 * `xyz` (3 doubles per vertex, finite). Zero-area triangles count as the segments or points they
 * are. triangle_count 0 gives an index whose queries find nothing. Returns NULL when out of memory
 * or on bad input (NULL arrays, an index out of range, a non-finite coordinate). */
surface_index *surface_index_build(const double *xyz, size_t vertex_count,
                                   const uint32_t *triangles, size_t triangle_count);

/* Distance from `point` to the surface; the closest point goes to `closest` and its triangle to
 * `triangle` (either may be NULL). INFINITY (closest and triangle untouched) when the index is
 * empty or `point` is not finite. */
double surface_index_query(const surface_index *index, const double point[3], double closest[3],
                           size_t *triangle);

/* Frees the index. Accepts NULL. */
void surface_index_free(surface_index *index);

/* ---- error metrics ------------------------------------------------------------------------- */

typedef struct mesh_metrics {
    size_t vertex_count;
    size_t triangle_count;
    double theta;       /* mean angle between corresponding face normals, degrees, over the
                         * triangles with non-zero area in both meshes (NAN when there is none) */
    size_t theta_count; /* how many triangles theta averages */
    double ev;          /* Sun et al. 2007 E_v: sqrt(sum_v A_v d_v^2 / sum_v A_v), A_v the area of
                         * the result's triangles around v, d_v the distance from result vertex v
                         * to the ground-truth surface (exact), over vertices with A_v > 0; in
                         * thousandths of bbox_diag (NAN when no vertex has A_v > 0) */
    double rms_v;     /* RMS distance between corresponding vertices (all of them), in mean_edge */
    double hausdorff; /* symmetric Hausdorff distance sampled at the vertices: the larger of the
                       * farthest result vertex from the ground-truth surface and the farthest
                       * ground-truth vertex from the result surface (vertices used by some
                       * triangle); in thousandths of bbox_diag */
    double mean_edge; /* mean length of the ground truth's unique undirected edges (an edge
                       * shared by two triangles counts once; a repeated index is no edge) */
    double bbox_diag; /* diagonal of the ground truth's axis-aligned bounding box (all vertices) */
} mesh_metrics;

/* Compares `result_xyz` with `truth_xyz` (3 doubles per vertex each, finite), both meshes made of
 * the same `triangles` (3 indices each, < vertex_count). Returns 0, or -1 on bad input (NULL
 * arrays, no vertex or no triangle, an index out of range, a non-finite coordinate) or when out of
 * memory; `out` is then undefined. A zero mean_edge or bbox_diag gives infinite or NAN figures
 * rather than a failure. Thread-safe. */
int mesh_metrics_compute(const double *result_xyz, const double *truth_xyz, size_t vertex_count,
                         const uint32_t *triangles, size_t triangle_count, mesh_metrics *out);

#endif
