/* The normal-driven update stage of the best mode (beyond the paper): facet normals filtered by
 * guided normal filtering (guided_normals.c), then vertices moved to agree with them by Sun et
 * al.'s iterative update (vertex_update.c), before the robust passes. Host code on every core,
 * in double precision; the same bytes for any thread count. Internal, not installed. */
#ifndef RSMOOTH_NORMAL_UPDATE_H
#define RSMOOTH_NORMAL_UPDATE_H

#include "core/rsmooth_internal.h"

/* The triangles of non-zero area of a mesh, with their geometry. */
typedef struct rs_facets {
    size_t count;
    uint32_t *triangle; /* triangle index of each facet */
    double *centroid;   /* 3 per facet */
    double *normal;     /* 3 per facet, unit */
    double *area;       /* per facet, > 0 */
} rs_facets;

/* The facets of (xyz, indices) into `out`; false when out of memory (nothing to free then). */
bool rs_facets_build(rs_facets *out, const double *xyz, const uint32_t *indices,
                     size_t triangle_count);
/* Recomputes centroids, normals and areas from xyz, keeping the facet list (a facet that became
 * degenerate keeps its last geometry). */
void rs_facets_update(rs_facets *facets, const double *xyz, const uint32_t *indices);
void rs_facets_free(rs_facets *facets);

/* Which facets meet at each vertex, vertices at the same position welded (facet_adjacency.c). */
typedef struct rs_adjacency {
    uint32_t *rep;   /* per vertex: the lowest-numbered vertex at its position */
    size_t *start;   /* vertex_count + 1: the facets at welded vertex r are facet[start[r] ..
                      * start[r + 1]), in facet order */
    uint32_t *facet;
} rs_adjacency;

/* false when out of memory (nothing to free then). */
bool rs_adjacency_build(rs_adjacency *adj, const double *xyz, size_t vertex_count,
                        const uint32_t *indices, const rs_facets *facets);
void rs_adjacency_free(rs_adjacency *adj);

/* The share of the pairs of facets sharing an edge (welded) whose normals are within max_angle
 * (radians) of each other: near 1 on a mesh of flat parts and creases (a machined part), low on
 * one curved at the scale of its triangles. 1 when no facets share an edge; -1 when out of
 * memory. */
double rs_flat_share(const double *xyz, size_t vertex_count, const uint32_t *indices,
                     size_t triangle_count, double max_angle);

/* Guided normal filtering (Zhang et al. 2015), `rounds` rounds, spatial width sigma_s (absolute)
 * and guidance width sigma_n; writes 3 doubles per facet to `normals`. false when out of memory. */
bool rs_guided_normals(const rs_facets *facets, const rs_adjacency *adj, const uint32_t *indices,
                       double sigma_s, double sigma_n, int rounds, double *normals);

/* Sun et al. 2007's vertex update, `iterations` times: each vertex moves by the mean over its
 * facets f of n_f (n_f . (c_f - x)), c_f the facets' current centroids (`facets` is updated), n_f
 * the given normals. Welded vertices move together. Vertices whose move_mask byte is 0 stay. xyz
 * is updated in place. false when out of memory (xyz unchanged). */
bool rs_vertex_update(double *xyz, size_t vertex_count, const uint32_t *indices,
                      rs_facets *facets, const rs_adjacency *adj, const double *normals,
                      int iterations, const uint8_t *move_mask);

/* The whole stage on `xyz` (double, in place): normals from the facets of the current positions
 * by guided filtering, then the vertex update. sigma_s absolute (mesh units). */
rsmooth_status rs_normal_update_stage(double *xyz, size_t vertex_count, const uint32_t *indices,
                                      size_t triangle_count, double sigma_s,
                                      double sigma_n, int rounds, int updates,
                                      const uint8_t *move_mask, rsmooth_error *error,
                                      const char *where);

#endif /* RSMOOTH_NORMAL_UPDATE_H */
