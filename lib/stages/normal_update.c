/* The normal-driven update stage (normal_update.h): facet geometry, then guided normal filtering
 * and the vertex update on positions brought near unit size by a power of two, so that squared
 * distances neither overflow nor underflow whatever the mesh's units (and scaling back is exact). */
#include "stages/normal_update.h"

#include <math.h>
#include <string.h>

bool rs_facets_build(rs_facets *out, const double *xyz, const uint32_t *indices,
                     size_t triangle_count) {
    memset(out, 0, sizeof *out);
    size_t n = triangle_count ? triangle_count : 1;
    out->triangle = rs_alloc_array(n, sizeof *out->triangle);
    out->centroid = rs_alloc_array(n, 3 * sizeof(double));
    out->normal = rs_alloc_array(n, 3 * sizeof(double));
    out->area = rs_alloc_array(n, sizeof(double));
    if (!out->triangle || !out->centroid || !out->normal || !out->area) {
        rs_facets_free(out);
        return false;
    }
    for (size_t t = 0; t < triangle_count; t++) {
        size_t q = out->count;
        if (rs_triangle_geometry(xyz, indices + 3 * t, out->centroid + 3 * q, out->normal + 3 * q,
                                 out->area + q))
            out->triangle[out->count++] = (uint32_t)t;
    }
    return true;
}

void rs_facets_update(rs_facets *facets, const double *xyz, const uint32_t *indices) {
    for (size_t q = 0; q < facets->count; q++) {
        double c[3], n[3], a;
        if (rs_triangle_geometry(xyz, indices + 3 * (size_t)facets->triangle[q], c, n, &a)) {
            memcpy(facets->centroid + 3 * q, c, sizeof c);
            memcpy(facets->normal + 3 * q, n, sizeof n);
            facets->area[q] = a;
        }
    }
}

void rs_facets_free(rs_facets *facets) {
    rs_free(facets->triangle);
    rs_free(facets->centroid);
    rs_free(facets->normal);
    rs_free(facets->area);
    memset(facets, 0, sizeof *facets);
}

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
