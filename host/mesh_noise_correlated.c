/* Spatially correlated noise fields: band-limited Gaussian noise (i.i.d. Gaussians smoothed by a
 * Gaussian kernel over Euclidean neighbours) and scan-line stripes. */
#include "mesh_noise_correlated.h"

#include "mesh_shapes.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define STRIPE_STREAM 0x8EBC6AF09C88C6E3ull
#define PI 3.14159265358979323846

/* Uniform in [0, 1) from 53 random bits. */
static double uniform01(uint64_t *state) {
    *state += 0x9E3779B97F4A7C15ull;
    return (double)(mesh_noise_mix64(*state) >> 11) * 0x1.0p-53;
}

/* A uniform grid of cubes of side `cell`: the vertices sorted by cell. */
typedef struct cell_grid {
    double cell, lo[3];
    int64_t *key;   /* per sorted entry */
    size_t *vertex; /* per sorted entry */
    size_t count;
} cell_grid;

static int64_t cell_key(const int64_t c[3]) {
    return (c[0] * 2097152 + c[1]) * 2097152 + c[2]; /* cells < 2^21 per axis: see build */
}

static void cell_of(const cell_grid *g, const double *p, int64_t c[3]) {
    for (int k = 0; k < 3; k++)
        c[k] = (int64_t)floor((p[k] - g->lo[k]) / g->cell);
}

static const int64_t *sort_keys;
static int compare_entries(const void *a, const void *b) {
    int64_t ka = sort_keys[*(const size_t *)a], kb = sort_keys[*(const size_t *)b];
    return ka < kb   ? -1
           : ka > kb ? 1
                     : (*(const size_t *)a > *(const size_t *)b) -
                           (*(const size_t *)a < *(const size_t *)b);
}

static int build_grid(cell_grid *g, const double *xyz, size_t n, double cell) {
    memset(g, 0, sizeof *g);
    double hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    g->lo[0] = g->lo[1] = g->lo[2] = INFINITY;
    for (size_t v = 0; v < n; v++)
        for (int k = 0; k < 3; k++) {
            g->lo[k] = fmin(g->lo[k], xyz[3 * v + k]);
            hi[k] = fmax(hi[k], xyz[3 * v + k]);
        }
    g->cell = cell;
    for (int k = 0; k < 3; k++) /* at most 2^20 cells per axis: coarser cells when needed */
        if ((hi[k] - g->lo[k]) / g->cell > 1048576.0)
            g->cell = (hi[k] - g->lo[k]) / 1048576.0;
    int64_t *key = malloc((n ? n : 1) * sizeof *key);
    g->key = malloc((n ? n : 1) * sizeof *g->key);
    g->vertex = malloc((n ? n : 1) * sizeof *g->vertex);
    if (!key || !g->key || !g->vertex) {
        free(key);
        return -1;
    }
    for (size_t v = 0; v < n; v++) {
        int64_t c[3];
        cell_of(g, xyz + 3 * v, c);
        key[v] = cell_key(c);
        g->vertex[v] = v;
    }
    sort_keys = key; /* qsort has no context argument; single-threaded use */
    qsort(g->vertex, n, sizeof *g->vertex, compare_entries);
    for (size_t i = 0; i < n; i++)
        g->key[i] = key[g->vertex[i]];
    free(key);
    g->count = n;
    return 0;
}

/* The first sorted entry whose key is >= k. */
static size_t lower_bound(const cell_grid *g, int64_t k) {
    size_t lo = 0, hi = g->count;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (g->key[mid] < k)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

int mesh_band_limited_field(const double *xyz, size_t vertex_count, double length, uint64_t seed,
                            double *out) {
    double *g = malloc((vertex_count ? vertex_count : 1) * sizeof *g);
    if (!g)
        return -1;
    uint64_t state = seed; /* the same Gaussian stream as plain noise */
    for (size_t v = 0; v < vertex_count; v++)
        g[v] = shape_gaussian(&state);
    double reach = 3 * length;
    cell_grid grid;
    if (build_grid(&grid, xyz, vertex_count, reach) != 0) {
        free(g);
        free(grid.key);
        free(grid.vertex);
        return -1;
    }
    for (size_t v = 0; v < vertex_count; v++) {
        const double *p = xyz + 3 * v;
        int64_t c[3];
        cell_of(&grid, p, c);
        double sum = 0, sum_w2 = 0;
        for (int64_t dx = -1; dx <= 1; dx++)
            for (int64_t dy = -1; dy <= 1; dy++)
                for (int64_t dz = -1; dz <= 1; dz++) {
                    const int64_t cc[3] = {c[0] + dx, c[1] + dy, c[2] + dz};
                    int64_t k = cell_key(cc);
                    for (size_t i = lower_bound(&grid, k); i < grid.count && grid.key[i] == k;
                         i++) {
                        const double *q = xyz + 3 * grid.vertex[i];
                        double d2 = (q[0] - p[0]) * (q[0] - p[0]) + (q[1] - p[1]) * (q[1] - p[1]) +
                                    (q[2] - p[2]) * (q[2] - p[2]);
                        if (d2 > reach * reach)
                            continue;
                        double w = exp(-d2 / (2 * length * length));
                        sum += w * g[grid.vertex[i]];
                        sum_w2 += w * w;
                    }
                }
        out[v] = sum_w2 > 0 ? sum / sqrt(sum_w2) : g[v]; /* v itself has weight 1 */
    }
    free(grid.key);
    free(grid.vertex);
    free(g);
    return 0;
}

int mesh_stripe_field(const double *xyz, size_t vertex_count, double width, uint64_t seed,
                      double *out) {
    uint64_t state = mesh_noise_mix64(seed ^ STRIPE_STREAM);
    double u[3], len;
    do { /* an isotropic direction */
        for (int k = 0; k < 3; k++)
            u[k] = shape_gaussian(&state);
        len = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    } while (!(len > 1e-150));
    for (int k = 0; k < 3; k++)
        u[k] /= len;
    double phase = uniform01(&state);
    uint64_t amplitude_base = mesh_noise_mix64(state);
    double ss = 0;
    for (size_t v = 0; v < vertex_count; v++) {
        const double *p = xyz + 3 * v;
        double t = (p[0] * u[0] + p[1] * u[1] + p[2] * u[2]) / width + phase;
        double slab = floor(t), f = t - slab;
        /* the slab's amplitude from a stream of its own: the same for every vertex in it */
        uint64_t slab_state = mesh_noise_mix64(amplitude_base ^ (uint64_t)(int64_t)slab);
        out[v] = shape_gaussian(&slab_state) * sin(PI * f);
        ss += out[v] * out[v];
    }
    double rms = vertex_count ? sqrt(ss / (double)vertex_count) : 0;
    for (size_t v = 0; rms > 0 && v < vertex_count; v++)
        out[v] /= rms;
    return 0;
}
