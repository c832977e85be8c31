/* Facet geometry for the normal-update stage (normal_update.h): each triangle's centroid, unit
 * normal and area, built once and updated in place as the vertices move. The adjacency, the
 * guided filter and the vertex update read it; it reads nothing of theirs. */
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

#define GRAIN 4096 /* facets per chunk below which a thread does not pay */

typedef struct update_job {
    rs_facets *facets;
    const double *xyz;
    const uint32_t *indices;
} update_job;

static void update_range(void *ctx, size_t begin, size_t end, size_t chunk) {
    const update_job *job = ctx;
    rs_facets *facets = job->facets;
    (void)chunk;
    for (size_t q = begin; q < end; q++) {
        double c[3], n[3], a;
        if (rs_triangle_geometry(job->xyz, job->indices + 3 * (size_t)facets->triangle[q], c, n,
                                 &a)) {
            memcpy(facets->centroid + 3 * q, c, sizeof c);
            memcpy(facets->normal + 3 * q, n, sizeof n);
            facets->area[q] = a;
        }
    }
}

/* Each facet on its own: any thread count gives the same bytes. */
void rs_facets_update(rs_facets *facets, const double *xyz, const uint32_t *indices) {
    update_job job = {facets, xyz, indices};
    rs_parallel_for(facets->count, GRAIN, update_range, &job);
}

void rs_facets_free(rs_facets *facets) {
    rs_free(facets->triangle);
    rs_free(facets->centroid);
    rs_free(facets->normal);
    rs_free(facets->area);
    memset(facets, 0, sizeof *facets);
}
