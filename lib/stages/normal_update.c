/* The normal-driven update stage (normal_update.h): facet geometry, then guided normal filtering
 * and the vertex update on positions brought near unit size by a power of two, so that squared
 * distances neither overflow nor underflow whatever the mesh's units (and scaling back is exact). */
#include "stages/normal_update.h"

#include <math.h>
#include <string.h>

rsmooth_status rs_normal_update_stage(double *xyz, size_t vertex_count, const uint32_t *indices,
                                      size_t triangle_count, const rs_stage_setting *setting,
                                      const uint8_t *move_mask, rs_cycle_fn cycle_done,
                                      void *user, rsmooth_error *error, const char *where) {
    if (setting->updates < 1 || setting->cycles < 1 || vertex_count == 0)
        return RSMOOTH_OK;
    double largest = 0;
    for (size_t i = 0; i < 3 * vertex_count; i++)
        largest = fmax(largest, fabs(xyz[i]));
    int exponent;
    frexp(fmax(largest, setting->sigma_s), &exponent);
    double scale = ldexp(1.0, -exponent), unscale = ldexp(1.0, exponent);
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
    for (int c = 0; ok && !cancelled && c < setting->cycles; c++) {
        if (c > 0) /* the cycle reads the geometry the one before left */
            rs_facets_update(&facets, xyz, indices);
        rs_guided_step(guided, &facets, setting->rounds, normals);
        ok = rs_vertex_update(xyz, vertex_count, indices, &facets, &adj, normals,
                              setting->updates, move_mask);
        cancelled = ok && cycle_done && cycle_done(user, c + 1, setting->cycles) != 0;
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
    return ok ? RSMOOTH_OK
              : rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where,
                        "out of memory in the normal update stage");
}
