/* The normal-driven update stage (normal_update.h): facet geometry, then guided normal filtering
 * and the vertex update on positions brought near unit size by a power of two, so that squared
 * distances neither overflow nor underflow whatever the mesh's units (and scaling back is exact). */
#include "stages/normal_update.h"

#include <math.h>
#include <string.h>

rsmooth_status rs_normal_update_stage(double *xyz, size_t vertex_count, const uint32_t *indices,
                                      size_t triangle_count, double sigma_s,
                                      double sigma_n, int rounds, int updates,
                                      const uint8_t *move_mask, rsmooth_error *error,
                                      const char *where) {
    if (updates < 1 || vertex_count == 0)
        return RSMOOTH_OK;
    double largest = 0;
    for (size_t i = 0; i < 3 * vertex_count; i++)
        largest = fmax(largest, fabs(xyz[i]));
    int exponent;
    frexp(fmax(largest, sigma_s), &exponent);
    double scale = ldexp(1.0, -exponent), unscale = ldexp(1.0, exponent);
    for (size_t i = 0; i < 3 * vertex_count; i++)
        xyz[i] *= scale;
    rs_facets facets;
    rs_adjacency adj;
    double *normals = NULL;
    bool ok = rs_facets_build(&facets, xyz, indices, triangle_count);
    if (ok) {
        normals = rs_alloc_array(facets.count ? facets.count : 1, 3 * sizeof(double));
        ok = normals && rs_adjacency_build(&adj, xyz, vertex_count, indices, &facets);
        if (ok) {
            ok = rs_guided_normals(&facets, &adj, indices, sigma_s * scale, sigma_n, rounds,
                                   normals) &&
                 rs_vertex_update(xyz, vertex_count, indices, &facets, &adj, normals, updates,
                                  move_mask);
            rs_adjacency_free(&adj);
        }
        rs_facets_free(&facets);
    }
    rs_free(normals);
    for (size_t i = 0; i < 3 * vertex_count; i++)
        xyz[i] *= unscale;
    return ok ? RSMOOTH_OK
              : rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where,
                        "out of memory in the normal update stage");
}
