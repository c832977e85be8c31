/* Vertex update from filtered facet normals (Sun, Rosin, Martin & Langbein, "Fast and Effective
 * Feature-Preserving Mesh Denoising", TVCG 2007, Sec. 4): with the normals n_f fixed, each vertex
 * x moves, iteration after iteration, by
 *     dx = 1/|F(x)| sum_{f in F(x)} n_f (n_f . (c_f - x)),
 * the mean of its projections onto the planes through the current centroids c_f with the filtered
 * normals: a gradient step towards the mesh whose facets have those normals. Jacobi style (every
 * move from the same positions), so the result does not depend on the order or the threads.
 *
 * Vertices at exactly the same position are one vertex here (facet_adjacency.c): their facets are
 * pooled and they move together, so a soup is updated as the mesh it was cut from. */
#include "stages/normal_update.h"

#include <math.h>
#include <string.h>

#define GRAIN 1024 /* vertices per chunk below which a thread does not pay */

typedef struct update_job {
    const double *from; /* positions before this iteration */
    double *to;
    const uint32_t *rep;
    const size_t *start; /* CSR of the welded vertices' facets */
    const uint32_t *facet;
    const rs_facets *facets;
    const double *normal;
} update_job;

static void update_range(void *ctx, size_t begin, size_t end, size_t chunk) {
    const update_job *job = ctx;
    (void)chunk;
    for (size_t v = begin; v < end; v++) {
        const double *x = job->from + 3 * v;
        size_t r = job->rep[v], n = job->start[r + 1] - job->start[r];
        double move[3] = {0, 0, 0};
        for (size_t i = job->start[r]; i < job->start[r + 1]; i++) {
            size_t f = job->facet[i];
            const double *nf = job->normal + 3 * f;
            double d[3];
            rs_sub3(job->facets->centroid + 3 * f, x, d);
            double h = rs_dot3(nf, d);
            for (int k = 0; k < 3; k++)
                move[k] += h * nf[k];
        }
        for (int k = 0; k < 3; k++)
            job->to[3 * v + k] = n ? x[k] + move[k] / (double)n : x[k];
    }
}

bool rs_vertex_update(double *xyz, size_t vertex_count, const uint32_t *indices, rs_facets *facets,
                      const rs_adjacency *adj, const double *normals, int iterations,
                      const uint8_t *move_mask) {
    if (iterations < 1 || facets->count == 0)
        return true;
    double *next = rs_alloc_array(vertex_count, 3 * sizeof(double));
    if (!next)
        return false;
    for (int it = 0; it < iterations; it++) {
        if (it > 0)
            rs_facets_update(facets, xyz, indices);
        update_job job = {xyz, next, adj->rep, adj->start, adj->facet, facets, normals};
        rs_parallel_for(vertex_count, GRAIN, update_range, &job);
        for (size_t v = 0; v < vertex_count; v++)
            if (!move_mask || move_mask[v])
                memcpy(xyz + 3 * v, next + 3 * v, 3 * sizeof(double));
    }
    rs_free(next);
    return true;
}
