/* The normal-driven update stage (normal_update.h): facet geometry, then guided normal filtering
 * and the vertex update on positions brought near unit size by a power of two, so that squared
 * distances neither overflow nor underflow whatever the mesh's units (and scaling back is exact).
 */
#include "stages/normal_update.h"

#include "learned/learned.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* The plan of the stage (stage_plan.h) from what the host built, for a runner elsewhere;
 * facet_vertex (3 per facet) is the caller's to free. false when out of memory. */
static bool describe(rs_stage_plan *plan, const double *xyz, size_t vertex_count,
                     const uint32_t *indices, const rs_facets *facets, const rs_adjacency *adj,
                     const rs_guided *guided, const rs_stage_setting *setting,
                     const uint8_t *move_mask, uint32_t **facet_vertex) {
    memset(plan, 0, sizeof *plan);
    *facet_vertex = rs_alloc_array(facets->count ? facets->count : 1, 3 * sizeof(uint32_t));
    if (!*facet_vertex)
        return false;
    for (size_t f = 0; f < facets->count; f++)
        memcpy(*facet_vertex + 3 * f, indices + 3 * (size_t)facets->triangle[f],
               3 * sizeof(uint32_t));
    plan->vertex_count = vertex_count;
    plan->facet_count = facets->count;
    plan->xyz = xyz;
    plan->facet_vertex = *facet_vertex;
    plan->facet_normal = facets->normal;
    plan->facet_area = facets->area;
    plan->facet_centroid = facets->centroid;
    plan->rep = adj->rep;
    plan->rep_start = adj->start;
    plan->rep_facet = adj->facet;
    rs_guided_describe(guided, plan);
    plan->rounds = setting->rounds;
    plan->updates = setting->updates;
    plan->cycles = setting->cycles;
    plan->move_mask = move_mask;
    return true;
}

/* The cycles on the runner's device; RSMOOTH_ERROR_OUT_OF_MEMORY from it (a plan too large for
 * the device) leaves xyz unchanged and the host runs them. */
static rsmooth_status run_elsewhere(const rs_stage_place *place, double *xyz, size_t vertex_count,
                                    const uint32_t *indices, const rs_facets *facets,
                                    const rs_adjacency *adj, const rs_guided *guided,
                                    const rs_stage_setting *setting, const uint8_t *move_mask,
                                    rs_cycle_fn cycle_done, void *user, rs_stage_stats *stats,
                                    rsmooth_error *error) {
    rs_stage_plan plan;
    uint32_t *facet_vertex = NULL;
    if (!describe(&plan, xyz, vertex_count, indices, facets, adj, guided, setting, move_mask,
                  &facet_vertex))
        return RSMOOTH_ERROR_OUT_OF_MEMORY;
    rsmooth_status st = place->runner(place->ctx, &plan, xyz, cycle_done, user, stats, error);
    rs_free(facet_vertex);
    return st;
}

/* The model's normals of the input's facets (positions in the stage's units, `scale` from the
 * caller's), 3 per facet; NULL when out of memory. */
static double *learned_normals(const rs_stage_setting *setting, const rs_facets *facets,
                               double scale) {
    double *out = rs_alloc_array(facets->count ? facets->count : 1, 3 * sizeof(double));
    rs_learned_patches patches;
    if (!out || !rs_learned_patches_build(&patches, facets->centroid, facets->count)) {
        rs_free(out);
        return NULL;
    }
    rs_learned_input in = {facets->count,       facets->centroid, facets->area,
                           facets->normal,      &patches,         setting->mean_edge * scale,
                           setting->noise_level};
    bool ok = rs_learned_normals(setting->learned, (int)setting->learned->stage_count, &in,
                                 setting->network, out);
    rs_learned_patches_free(&patches);
    if (!ok) {
        rs_free(out);
        return NULL;
    }
    return out;
}

/* The largest turn of a facet's normal the learned step makes (degrees): chosen among 5, 10, 20
 * and no cap on two benchmark cases (docs/model.md). */
#define MAX_TURN_DEGREES 5.0

/* The learned normals of what the cycles left, then the vertex update toward them. */
static bool refine_after(const rs_stage_setting *setting, double *xyz, size_t vertex_count,
                         const uint32_t *indices, rs_facets *facets, const rs_adjacency *adj,
                         double scale, const uint8_t *move_mask) {
    rs_facets_update(facets, xyz, indices);
    double *learned = learned_normals(setting, facets, scale);
    /* a facet the model would turn further than MAX_TURN keeps its normal: big corrections are
     * the model's least reliable (a facet near a crease put on the wrong side), small ones its
     * most (docs/model.md, "The cap") */
    double least = cos(MAX_TURN_DEGREES * (3.14159265358979324 / 180));
    for (size_t f = 0; learned && f < facets->count; f++)
        if (rs_dot3(learned + 3 * f, facets->normal + 3 * f) < least)
            memcpy(learned + 3 * f, facets->normal + 3 * f, 3 * sizeof(double));
    bool ok = learned && rs_vertex_update(xyz, vertex_count, indices, facets, adj, learned,
                                          setting->updates, move_mask);
    rs_free(learned);
    return ok;
}

rsmooth_status rs_normal_update_stage(double *xyz, size_t vertex_count, const uint32_t *indices,
                                      size_t triangle_count, const rs_stage_setting *setting,
                                      const uint8_t *move_mask, const rs_stage_place *place,
                                      rs_cycle_fn cycle_done, void *user, rs_stage_stats *stats,
                                      rsmooth_error *error, const char *where) {
    rs_stage_stats unused;
    if (!stats)
        stats = &unused;
    memset(stats, 0, sizeof *stats);
    if (setting->updates < 1 || setting->cycles < 1 || vertex_count == 0)
        return RSMOOTH_OK;
    double t_start = rs_now_ms();
    double scale = rs_stage_scale(xyz, vertex_count, setting->sigma_s), unscale = 1 / scale;
    for (size_t i = 0; i < 3 * vertex_count; i++)
        xyz[i] *= scale;
    rs_facets facets;
    rs_adjacency adj;
    rs_guided *guided = NULL;
    double *normals = NULL;
    bool ok = rs_facets_build(&facets, xyz, indices, triangle_count), cancelled = false;
    bool adjacency = ok && rs_adjacency_build(&adj, xyz, vertex_count, indices, &facets);
    ok = adjacency;
    if (ok) {
        normals = rs_alloc_array(facets.count ? facets.count : 1, 3 * sizeof(double));
        guided = rs_guided_create(&facets, &adj, indices, setting->sigma_s * scale,
                                  setting->sigma_n, setting->radius);
        ok = normals && guided;
    }
    stats->ms_lists = rs_now_ms() - t_start;
    rsmooth_status st = RSMOOTH_OK;
    bool done = false;
    if (ok && place && place->runner && facets.count > 0) {
        st = run_elsewhere(place, xyz, vertex_count, indices, &facets, &adj, guided, setting,
                           move_mask, cycle_done, user, stats, error);
        done = st != RSMOOTH_ERROR_OUT_OF_MEMORY;
        cancelled = st == RSMOOTH_ERROR_CANCELLED;
        if (!done) /* the host runs it: the runner's refusal is no error */
            rs_error_clear(error);
        if (!done || cancelled)
            st = RSMOOTH_OK;
    }
    double t_cycles = rs_now_ms();
    for (int c = 0; ok && !done && !cancelled && c < setting->cycles; c++) {
        if (c > 0) /* the cycle reads the geometry the one before left */
            rs_facets_update(&facets, xyz, indices);
        rs_guided_step(guided, &facets, setting->rounds, normals);
        ok = rs_vertex_update(xyz, vertex_count, indices, &facets, &adj, normals, setting->updates,
                              move_mask);
        stats->cycles = c + 1;
        cancelled = ok && cycle_done && cycle_done(user, c + 1, setting->cycles) != 0;
    }
    if (ok && !cancelled && setting->learned && facets.count > 0) /* (after any runner too) */
        ok = refine_after(setting, xyz, vertex_count, indices, &facets, &adj, scale, move_mask);
    if (!done) {
        stats->ms_cycles = rs_now_ms() - t_cycles;
        stats->float_bits = 64;
        snprintf(stats->device, sizeof stats->device, "host (double, %zu threads)",
                 rs_host_threads());
    }
    rs_guided_destroy(guided);
    rs_free(normals);
    if (adjacency)
        rs_adjacency_free(&adj);
    rs_facets_free(&facets);
    for (size_t i = 0; i < 3 * vertex_count; i++)
        xyz[i] *= unscale;
    if (cancelled)
        return rs_cancelled(error, where);
    if (st != RSMOOTH_OK)
        return st;
    return ok ? RSMOOTH_OK
              : rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where,
                        "out of memory in the normal update stage");
}
