/* The normal update stage on a piece of a larger mesh, one cycle at a time: what streaming the
 * best mode needs (docs/large-meshes.md), where each cycle is a streamed pass over the whole
 * mesh cut into pieces afresh, the positions between cycles on disk.
 *
 * The whole mesh's stage (normal_update.c) builds its lists once, on its input: which triangles
 * are facets, the welding, each facet's patch and its neighbours within the guided filter's
 * reach; every cycle then re-reads the current geometry. A piece rebuilds those lists from its
 * own vertices' input positions, each cycle: given the whole mesh's scale and reach, and its
 * triangles in the whole mesh's order, the lists around its core are the whole mesh's, in the
 * same order (the grid's cells count from a lattice fixed in space; a cell lists its facets in
 * index order), so every sum over them runs as it does there and the core's results are the same
 * bits. One case cannot be: a facet whose area is exactly 0 at the start of a cycle keeps, in the
 * whole mesh's run, the geometry it last had; a piece has only the input's. */
#include "stages/normal_update.h"

#include <math.h>
#include <string.h>

/* How far a centroid lies from a corner of its facet, at most, per longest edge (a corner is
 * 2/3 of a median from the centroid, a median at most sqrt(3)/2 of the longest edge). */
#define CENTROID_REACH 0.58

double rs_stage_scale_of(double largest, double sigma_s) {
    int exponent;
    frexp(fmax(largest, sigma_s), &exponent);
    return ldexp(1.0, -exponent);
}

double rs_stage_scale(const double *xyz, size_t vertex_count, double sigma_s) {
    double largest = 0;
    for (size_t i = 0; i < 3 * vertex_count; i++)
        largest = fmax(largest, fabs(xyz[i]));
    return rs_stage_scale_of(largest, sigma_s);
}

double rs_stage_cycle_halo(const rs_stage_setting *setting, double longest_edge, double reach,
                           double displacement) {
    /* From a core vertex: `updates` rings of vertices (each update reads the facets at its
     * vertex, and so its neighbours of the update before); the filtered normals of the facets
     * at them; each round of the filter reads its neighbours (the reach on the input, up to two
     * displacements more now) and their guidance, two rings of facets around each (a patch is a
     * facet and those sharing a corner with it); the lists of the facets read must be whole: one
     * more reach and two more rings. A ring of facets moves a centroid by two corner reaches. */
    double ring = 2 * CENTROID_REACH * longest_edge;
    double near = reach + 2 * displacement;
    int rounds = setting->rounds > 0 ? setting->rounds : 0;
    return setting->updates * longest_edge + CENTROID_REACH * longest_edge +
           rounds * (near + 2 * ring) + near + 2 * ring;
}

double rs_stage_shares_halo(double longest_edge) {
    return 4 * CENTROID_REACH * longest_edge; /* a patch: the facets at f's corners, and theirs */
}

/* What the whole mesh's stage builds once on its input, built on a piece's (or the whole mesh's)
 * input positions at the stage's scale: the facets, the welded adjacency and the guided filter's
 * lists, its neighbour sets within `reach` (stage units), or radius times the facets' own mean
 * adjacent-centroid distance when reach < 0. */
typedef struct stage_lists {
    double *at_input; /* the positions at the stage's scale */
    rs_facets facets;
    rs_adjacency adj;
    rs_guided *guided;
    bool built, adjacency;
} stage_lists;

static void lists_free(stage_lists *l) {
    rs_guided_destroy(l->guided);
    if (l->adjacency)
        rs_adjacency_free(&l->adj);
    if (l->built)
        rs_facets_free(&l->facets);
    rs_free(l->at_input);
}

/* false when out of memory (*l freed then). */
static bool lists_build(stage_lists *l, const double *input, size_t vertex_count,
                        const uint32_t *indices, size_t triangle_count,
                        const rs_stage_setting *setting, double scale, double reach) {
    memset(l, 0, sizeof *l);
    l->at_input = rs_alloc_array(vertex_count ? vertex_count : 1, 3 * sizeof *l->at_input);
    for (size_t i = 0; l->at_input && i < 3 * vertex_count; i++)
        l->at_input[i] = input[i] * scale;
    l->built = l->at_input && rs_facets_build(&l->facets, l->at_input, indices, triangle_count);
    l->adjacency =
        l->built && rs_adjacency_build(&l->adj, l->at_input, vertex_count, indices, &l->facets);
    if (l->adjacency)
        l->guided = reach < 0
                        ? rs_guided_create(&l->facets, &l->adj, indices, setting->sigma_s * scale,
                                           setting->sigma_n, setting->radius)
                        : rs_guided_create_reach(&l->facets, &l->adj, indices,
                                                 setting->sigma_s * scale, setting->sigma_n, reach);
    if (!l->guided)
        lists_free(l);
    return l->guided != NULL;
}

rsmooth_status rs_stage_piece_shares(const double *input, size_t vertex_count,
                                     const uint32_t *indices, size_t triangle_count,
                                     const rs_stage_setting *setting, double scale, double *share,
                                     uint32_t *pairs) {
    for (size_t t = 0; t < triangle_count; t++) {
        share[t] = 0;
        pairs[t] = 0;
    }
    stage_lists l; /* the patches alone (no neighbour sets: a reach of 0) */
    if (!lists_build(&l, input, vertex_count, indices, triangle_count, setting, scale, 0))
        return RSMOOTH_ERROR_OUT_OF_MEMORY;
    for (size_t f = 0; f < l.facets.count; f++) {
        size_t n;
        share[l.facets.triangle[f]] = rs_guided_adjacent_share(l.guided, f, &n);
        pairs[l.facets.triangle[f]] = (uint32_t)n;
    }
    lists_free(&l);
    return RSMOOTH_OK;
}

double rs_stage_reach(const rs_stage_setting *setting, double share_sum, uint64_t pairs,
                      double scale) {
    /* as guided_normals.c: radius times the mean, in the stage's units, then the caller's */
    return pairs ? setting->radius * (share_sum / (double)pairs) / scale : 0;
}

rsmooth_status rs_stage_whole_figures(const double *input, size_t vertex_count,
                                      const uint32_t *indices, size_t triangle_count,
                                      const rs_stage_setting *setting, rs_stage_whole *whole) {
    whole->scale = rs_stage_scale(input, vertex_count, setting->sigma_s);
    whole->reach = 0;
    stage_lists l;
    if (!lists_build(&l, input, vertex_count, indices, triangle_count, setting, whole->scale, -1))
        return RSMOOTH_ERROR_OUT_OF_MEMORY;
    whole->reach = rs_guided_reach(l.guided) / whole->scale;
    lists_free(&l);
    return RSMOOTH_OK;
}

rsmooth_status rs_stage_cycle_piece(const double *input, double *xyz, size_t vertex_count,
                                    const uint32_t *indices, size_t triangle_count,
                                    const rs_stage_setting *setting, const rs_stage_whole *whole,
                                    const uint8_t *move_mask) {
    if (setting->updates < 1 || vertex_count == 0)
        return RSMOOTH_OK;
    const double scale = whole->scale, unscale = 1 / scale;
    stage_lists l;
    if (!lists_build(&l, input, vertex_count, indices, triangle_count, setting, scale,
                     whole->reach * scale))
        return RSMOOTH_ERROR_OUT_OF_MEMORY;
    double *normals = rs_alloc_array(l.facets.count ? l.facets.count : 1, 3 * sizeof(double));
    bool ok = normals != NULL;
    for (size_t i = 0; ok && i < 3 * vertex_count; i++)
        xyz[i] *= scale;
    if (ok && l.facets.count > 0) { /* the cycle, as normal_update.c runs each */
        rs_facets_update(&l.facets, xyz, indices);
        rs_guided_step(l.guided, &l.facets, setting->rounds, normals);
        ok = rs_vertex_update(xyz, vertex_count, indices, &l.facets, &l.adj, normals,
                              setting->updates, move_mask);
    }
    for (size_t i = 0; normals && i < 3 * vertex_count; i++)
        xyz[i] *= unscale;
    rs_free(normals);
    lists_free(&l);
    return ok ? RSMOOTH_OK : RSMOOTH_ERROR_OUT_OF_MEMORY;
}
