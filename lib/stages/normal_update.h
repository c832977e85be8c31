/* The normal-driven update stage of the best mode (beyond the paper): facet normals filtered by
 * guided normal filtering (guided_normals.c), then vertices moved to agree with them by Sun et
 * al.'s iterative update (vertex_update.c), before the robust passes. Host code on every core,
 * in double precision; the same bytes for any thread count. Internal, not installed. */
#ifndef RSMOOTH_NORMAL_UPDATE_H
#define RSMOOTH_NORMAL_UPDATE_H

#include "core/stage_plan.h"
#include "learned/learned.h"

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
    uint32_t *rep; /* per vertex: the lowest-numbered vertex at its position */
    size_t *start; /* vertex_count + 1: the facets at welded vertex r are facet[start[r] ..
                    * start[r + 1]), in facet order */
    uint32_t *facet;
} rs_adjacency;

/* false when out of memory (nothing to free then). */
bool rs_adjacency_build(rs_adjacency *adj, const double *xyz, size_t vertex_count,
                        const uint32_t *indices, const rs_facets *facets);
void rs_adjacency_free(rs_adjacency *adj);

/* The guided filter's reach by default, in mean distances between the centroids of facets
 * sharing an edge (the authors' setting). */
#define RS_GUIDED_RADIUS_DEFAULT 2.0

/* Guided normal filtering (Zhang et al. 2015) across cycles (guided_normals.c): made once on the
 * input's facets (patches, their interior edges and each facet's neighbours within `radius` mean
 * adjacent-centroid distances: connectivity and neighbour sets stay), then one step per cycle.
 * sigma_s absolute (mesh units), sigma_n the guidance width. NULL when out of memory. */
typedef struct rs_guided rs_guided;
rs_guided *rs_guided_create(const rs_facets *facets, const rs_adjacency *adj,
                            const uint32_t *indices, double sigma_s, double sigma_n, double radius);
/* The same with the neighbourhood's reach given (mesh units, as the facets' centroids): a piece
 * of a larger mesh takes the whole mesh's, radius times its mean adjacent-centroid distance
 * (rs_guided_reach of the whole mesh's filter), so its lists are the whole mesh's. */
rs_guided *rs_guided_create_reach(const rs_facets *facets, const rs_adjacency *adj,
                                  const uint32_t *indices, double sigma_s, double sigma_n,
                                  double reach);
/* Facet f's share of the mean adjacent-centroid distance: the sum of its distances to the
 * edge-adjacent facets of higher index, *pairs their count. The mean is the shares summed in
 * facet order over the pairs' count: a piece holding a facet's patch whole gives its share. */
double rs_guided_adjacent_share(const rs_guided *g, size_t f, size_t *pairs);
/* The reach the filter's neighbour sets were found with (0: it does not filter). */
double rs_guided_reach(const rs_guided *g);
/* `rounds` rounds from the facets' own normals, the weights from their current areas and
 * centroids (`facets` is the one the filter was made with, updated in place); writes 3 doubles
 * per facet to `normals`. */
void rs_guided_step(rs_guided *g, const rs_facets *facets, int rounds, double *normals);
void rs_guided_destroy(rs_guided *g);
/* Fills the plan's guided fields (lists, widths, whether it filters) from g. */
void rs_guided_describe(const rs_guided *g, rs_stage_plan *plan);

/* Create, one step, destroy, at the default radius. false when out of memory. */
bool rs_guided_normals(const rs_facets *facets, const rs_adjacency *adj, const uint32_t *indices,
                       double sigma_s, double sigma_n, int rounds, double *normals);

/* Sun et al. 2007's vertex update, `iterations` times: each vertex moves by the mean over its
 * facets f of n_f (n_f . (c_f - x)), c_f the facets' current centroids (`facets` is updated), n_f
 * the given normals. Welded vertices move together. Vertices whose move_mask byte is 0 stay. xyz
 * is updated in place. false when out of memory (xyz unchanged). */
bool rs_vertex_update(double *xyz, size_t vertex_count, const uint32_t *indices, rs_facets *facets,
                      const rs_adjacency *adj, const double *normals, int iterations,
                      const uint8_t *move_mask);

/* What the stage runs: `cycles` times (fresh facet geometry from the current positions; `rounds`
 * guided rounds; `updates` vertex updates), the lists built once. sigma_s absolute (mesh units),
 * radius in mean adjacent-centroid distances. */
typedef struct rs_stage_setting {
    double sigma_s, sigma_n, radius;
    int rounds, updates, cycles;
    /* NULL, or the learned normals' model (learned/learned.h): after the cycles, the model's
     * normals of their result are the targets of `updates` more vertex updates (the model is
     * trained on what the guided cycles leave: docs/model.md). noise_level (the input's, in
     * mean edge lengths) and mean_edge (mesh units) feed its descriptors. */
    const rs_learned_model *learned;
    double noise_level, mean_edge;
    const rs_network_place *network; /* where its networks run (NULL: the host) */
} rs_stage_setting;

/* Where the stage's cycles run: `runner` with `ctx` (the device), or the host when runner is
 * NULL or cannot take the plan. */
typedef struct rs_stage_place {
    rs_stage_runner runner;
    void *ctx;
    rs_network_place network; /* where the learned model's networks run ({NULL}: the host) */
} rs_stage_place;

/* The power of two the stage scales positions by (exact both ways): its largest coordinate, or
 * sigma_s when that is larger, brought just below 1, so squared distances neither overflow nor
 * underflow whatever the mesh's units. */
double rs_stage_scale(const double *xyz, size_t vertex_count, double sigma_s);
/* The same from the largest |coordinate| (stage_piece.c: a stream has it from its extent). */
double rs_stage_scale_of(double largest, double sigma_s);

/* The whole stage on `xyz` (double, in place). Vertices whose move_mask byte is 0 stay. `place`
 * may be NULL (the host); `stats` (may be NULL) gets what it measured. */
rsmooth_status rs_normal_update_stage(double *xyz, size_t vertex_count, const uint32_t *indices,
                                      size_t triangle_count, const rs_stage_setting *setting,
                                      const uint8_t *move_mask, const rs_stage_place *place,
                                      rs_cycle_fn cycle_done, void *user, rs_stage_stats *stats,
                                      rsmooth_error *error, const char *where);

/* ---- the stage on a piece of a larger mesh, a cycle at a time (stage_piece.c) ---------------- */

/* The whole mesh's figures a piece's cycle needs: the stage's scale and the guided filter's
 * reach (radius times the mean adjacent-centroid distance), both of the stage's input, the reach
 * in the caller's units. */
typedef struct rs_stage_whole {
    double scale;
    double reach;
} rs_stage_whole;

/* The figures of a whole mesh held in memory (its input positions); RSMOOTH_ERROR_OUT_OF_MEMORY
 * when out of memory. */
rsmooth_status rs_stage_whole_figures(const double *input, size_t vertex_count,
                                      const uint32_t *indices, size_t triangle_count,
                                      const rs_stage_setting *setting, rs_stage_whole *whole);

/* The reach from the pieces: each facet's share of the mean adjacent-centroid distance (and its
 * pairs) for the triangles of a piece (0 for those of no area), in the stage's units at `scale`
 * (the whole's); right for the triangles whose centroid lies rs_stage_shares_halo inside the
 * piece's edge. The shares summed in the whole mesh's triangle order, and the pairs, give
 * rs_stage_reach: rs_stage_whole_figures' reach bit for bit. */
double rs_stage_shares_halo(double longest_edge);
rsmooth_status rs_stage_piece_shares(const double *input, size_t vertex_count,
                                     const uint32_t *indices, size_t triangle_count,
                                     const rs_stage_setting *setting, double scale, double *share,
                                     uint32_t *pairs);
double rs_stage_reach(const rs_stage_setting *setting, double share_sum, uint64_t pairs,
                      double scale);

/* How far from its core vertices a piece must hold every triangle (their centroids, at the
 * cycle's start) for one cycle to move the core as on the whole mesh: `longest_edge` the whole
 * mesh's longest edge (at the input and at the cycle's start, the larger), `reach` the whole's
 * (rs_stage_whole), `displacement` how far any vertex lies from its input position at most. */
double rs_stage_cycle_halo(const rs_stage_setting *setting, double longest_edge, double reach,
                           double displacement);

/* One cycle of the stage (setting's rounds and updates; its cycles and learned model unused) on
 * a piece: `input` its vertices' positions at the stage's input, `xyz` those at the cycle's
 * start (updated in place: the vertices farther than the halo from the piece's edge come out as
 * the whole mesh's cycle leaves them), its triangles in the whole mesh's order. Caller's units,
 * double. RSMOOTH_ERROR_OUT_OF_MEMORY when out of memory (xyz then as it came). */
rsmooth_status rs_stage_cycle_piece(const double *input, double *xyz, size_t vertex_count,
                                    const uint32_t *indices, size_t triangle_count,
                                    const rs_stage_setting *setting, const rs_stage_whole *whole,
                                    const uint8_t *move_mask);

#endif /* RSMOOTH_NORMAL_UPDATE_H */
