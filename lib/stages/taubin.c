/* The isotropic baselines: Laplacian smoothing and Taubin's lambda|mu smoothing (SIGGRAPH 1995),
 * with the uniform "umbrella" operator on the mesh's edge graph. They need connectivity and many
 * iterations, and they round sharp edges: rsmooth offers them only so its filter can be compared
 * with what people already use. */
#include "stages/taubin.h"
#include "core/rsmooth_internal.h"

#include <math.h>
#include <string.h>

/* Edge neighbours of every vertex, compressed: those of v are neighbour[first[v] .. first[v+1]). */
typedef struct adjacency {
    size_t *first; /* vertex_count + 1 */
    uint32_t *neighbour;
} adjacency;

static void adjacency_free(adjacency *adj) {
    rs_free(adj->first);
    rs_free(adj->neighbour);
}

/* Unique undirected edges of the triangles, each stored in both directions, grouped by vertex. */
static bool adjacency_build(adjacency *adj, size_t vertex_count, const uint32_t *indices,
                            size_t triangle_count) {
    size_t slots = 6 * triangle_count;
    uint64_t *keys = rs_alloc_array(slots, sizeof *keys);
    uint32_t *unused = rs_alloc_array(slots, sizeof *unused);
    adj->first = rs_calloc_array(vertex_count + 1, sizeof *adj->first);
    adj->neighbour = NULL;
    bool ok = keys && unused && adj->first;
    size_t n = 0;
    for (size_t t = 0; ok && t < triangle_count; t++) {
        for (int e = 0; e < 3; e++) {
            uint64_t a = indices[3 * t + e], b = indices[3 * t + (e + 1) % 3];
            if (a == b)
                continue; /* a repeated index is no edge */
            keys[n] = a << 32 | b;
            keys[n + 1] = b << 32 | a;
            unused[n] = unused[n + 1] = 0;
            n += 2;
        }
    }
    ok = ok && rs_radix_sort_u64(keys, unused, n);
    size_t unique = 0;
    for (size_t i = 0; ok && i < n; i++)
        if (i == 0 || keys[i] != keys[i - 1])
            keys[unique++] = keys[i];
    if (ok)
        adj->neighbour = rs_alloc_array(unique ? unique : 1, sizeof *adj->neighbour);
    ok = ok && adj->neighbour;
    for (size_t i = 0; ok && i < unique; i++) {
        adj->first[(keys[i] >> 32) + 1]++;
        adj->neighbour[i] = (uint32_t)(keys[i] & 0xffffffffu);
    }
    for (size_t v = 0; ok && v < vertex_count; v++)
        adj->first[v + 1] += adj->first[v];
    rs_free(keys);
    rs_free(unused);
    if (!ok)
        adjacency_free(adj);
    return ok;
}

/* to = from + factor * (mean of the neighbours - from), per vertex; lone vertices stay. */
static void umbrella_step(const adjacency *adj, size_t vertex_count, double factor,
                          const double *from, double *to) {
    for (size_t v = 0; v < vertex_count; v++) {
        size_t begin = adj->first[v], end = adj->first[v + 1];
        double mean[3] = {0, 0, 0};
        for (size_t i = begin; i < end; i++)
            for (int c = 0; c < 3; c++)
                mean[c] += from[3 * (size_t)adj->neighbour[i] + c];
        for (int c = 0; c < 3; c++) {
            double p = from[3 * v + c];
            to[3 * v + c] = end > begin ? p + factor * (mean[c] / (double)(end - begin) - p) : p;
        }
    }
}

rsmooth_status rs_smooth_taubin(rsmooth_scalar scalar, const void *positions, size_t vertex_count,
                                const uint32_t *indices, size_t triangle_count, double lambda,
                                double mu, unsigned iterations, void *out_positions,
                                rsmooth_error *error) {
    static const char where[] = "rsmooth_smooth_taubin";
    rs_error_clear(error);
    rsmooth_status st = rs_check_mesh_arrays(scalar, positions, vertex_count, indices,
                                             triangle_count, NULL, error, where);
    if (st == RSMOOTH_OK)
        st = rs_check_outputs(scalar, positions, vertex_count, indices, triangle_count, NULL,
                              out_positions, NULL, NULL, error, where);
    if (st != RSMOOTH_OK)
        return st;
    if (!(lambda > 0 && lambda <= 1))
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "lambda must be in (0, 1] (got %g)", lambda);
    if (!(mu >= -1 && mu <= 0))
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "mu must be in [-1, 0], 0 for plain Laplacian smoothing (got %g)", mu);

    double *a = rs_alloc_array(vertex_count, 3 * sizeof *a);
    double *b = rs_alloc_array(vertex_count, 3 * sizeof *b);
    adjacency adj = {NULL, NULL};
    if (!a || !b || !adjacency_build(&adj, vertex_count, indices, triangle_count)) {
        rs_free(a);
        rs_free(b);
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "out of memory");
    }
    for (size_t i = 0; i < 3 * vertex_count; i++)
        a[i] = rs_coordinate(scalar, positions, i);
    double *cur = a, *next = b;
    for (unsigned it = 0; it < iterations; it++) {
        for (int pass = 0; pass < (mu != 0 ? 2 : 1); pass++) { /* shrink, then inflate back */
            umbrella_step(&adj, vertex_count, pass == 0 ? lambda : mu, cur, next);
            double *t = cur;
            cur = next;
            next = t;
        }
    }
    for (size_t v = 0; v < vertex_count; v++)
        rs_store_position(scalar, out_positions, v, cur + 3 * v, 1); /* linear: no scale */
    rs_free(a);
    rs_free(b);
    adjacency_free(&adj);
    return rs_check_results(scalar, out_positions, NULL, NULL, vertex_count, "vertex", error,
                            where);
}

int rs_taubin_until(double *xyz, size_t vertex_count, const uint32_t *indices,
                    size_t triangle_count, double lambda, double mu, double target_move,
                    double min_gain, int max_iterations) {
    double *origin = rs_alloc_array(vertex_count, 3 * sizeof *origin);
    double *next = rs_alloc_array(vertex_count, 3 * sizeof *next);
    adjacency adj = {NULL, NULL};
    if (!origin || !next || !adjacency_build(&adj, vertex_count, indices, triangle_count)) {
        rs_free(origin);
        rs_free(next);
        return -1;
    }
    memcpy(origin, xyz, vertex_count * 3 * sizeof *xyz);
    int it = 0;
    double move = 0, gain = INFINITY;
    while (it < max_iterations && (move < target_move || (min_gain > 0 && gain >= min_gain))) {
        umbrella_step(&adj, vertex_count, lambda, xyz, next);
        umbrella_step(&adj, vertex_count, mu, next, xyz);
        it++;
        double sum = 0;
        for (size_t i = 0; i < 3 * vertex_count; i++)
            sum += (xyz[i] - origin[i]) * (xyz[i] - origin[i]);
        double before = move;
        move = vertex_count ? sqrt(sum / (double)vertex_count) : 0;
        gain = move - before;
    }
    rs_free(origin);
    rs_free(next);
    adjacency_free(&adj);
    return it;
}
