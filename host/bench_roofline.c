/* The native roofline (see bench_roofline.h). Built with -O3 -ffast-math (and -march=native where
 * the compiler takes it) so GCC vectorizes the lane loops; OpenMP spreads the blocks over the
 * cores. Every pair in a block's window is evaluated: nothing is skipped, so the figure is a
 * ceiling on arithmetic throughput, not on search. */
#define _POSIX_C_SOURCE 200809L
#include "bench_roofline.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#ifdef _OPENMP
#include <omp.h>
#define PARALLEL_BLOCKS _Pragma("omp parallel for schedule(static) reduction(+ : sum)")
#else
#define PARALLEL_BLOCKS
#endif

/* 16 vertices per block: two AVX2 vectors or one AVX-512 vector per quantity, so each facet loaded
 * serves 16 pairs (the kernels' blocks are float8, 8 lanes; 16 measured no slower here). */
#define LANES 16
#define WINDOW 1024
#define REPETITIONS 5
#define MIN_SECONDS 0.3

typedef struct roof {
    size_t block_count, window;
    const size_t *window_start; /* per block */
    const float *px, *py, *pz;  /* per slot (block * LANES + lane), cell units from the origin */
    const float *cx, *cy, *cz, *nx, *ny, *nz, *logarea; /* per facet, grid order */
    float reach2, inv_2sf2, inv_2sg2, mollify_reach2, inv_2sm2;
} roof;

#define LOG2E 1.4426950408889634

/* The sums live on through this, so the compiler cannot drop them. */
static volatile double sink;

/* fast_exp2 of kernels/common.cl on one float: 2^n from the exponent bits times a degree-5
 * minimax polynomial for 2^f, |f| <= 1/2 (exponents arrive in base 2, as in the kernels). */
static inline float fast_exp2(float x) {
    float y = fminf(fmaxf(x, -126.0f), 127.0f);
    int32_t n = (int32_t)(y + 128.5f) - 128;
    float f = y - (float)n;
    float p =
        1.00000012f +
        f * (0.693146944f +
             f * (0.240221202f + f * (0.0555071346f + f * (0.00967554096f + f * 0.00132764666f))));
    int32_t bits = (n + 127) << 23; /* n >= -126 after the clamp: never negative */
    float scale;
    memcpy(&scale, &bits, sizeof scale);
    return p * scale;
}

/* w where `keep`, else 0, as the kernels' select(). Done on the bits: with -ffast-math GCC turns
 * `keep ? w : 0.0f` into a branch around the sums (adding 0 * x is a no-op to it), and a branch in
 * the lane loop stops vectorization. */
static inline float masked(float w, int keep) {
    int32_t bits;
    memcpy(&bits, &w, sizeof bits);
    bits &= -(int32_t)(keep != 0);
    memcpy(&w, &bits, sizeof w);
    return w;
}

/* robust_sums of kernels/estimate.cl for one block: projection predictor, no confidence, no
 * rescue (the kernel decides on a rescue from the sums, after the loop). */
static double robust_block(const roof *r, size_t b) {
    float px[LANES], py[LANES], pz[LANES];
    float ax[LANES] = {0}, ay[LANES] = {0}, az[LANES] = {0}, ak[LANES] = {0};
    memcpy(px, r->px + b * LANES, sizeof px);
    memcpy(py, r->py + b * LANES, sizeof py);
    memcpy(pz, r->pz + b * LANES, sizeof pz);
    const float reach2 = r->reach2, inv_2sf2 = r->inv_2sf2, inv_2sg2 = r->inv_2sg2;
    const size_t end = r->window_start[b] + r->window;
    for (size_t q = r->window_start[b]; q < end; q++) {
        const float cx = r->cx[q], cy = r->cy[q], cz = r->cz[q], la = r->logarea[q];
        const float nx = r->nx[q], ny = r->ny[q], nz = r->nz[q];
        for (int l = 0; l < LANES; l++) {
            float ex = cx - px[l], ey = cy - py[l], ez = cz - pz[l];
            float d2 = ex * ex + ey * ey + ez * ez;
            float t = nx * ex + ny * ey + nz * ez;
            float e = t * t * inv_2sg2;
            int near = d2 <= reach2;
            float w = masked(fast_exp2(la - d2 * inv_2sf2 - e), near);
            float wt = w * t;
            ax[l] += wt * nx;
            ay[l] += wt * ny;
            az[l] += wt * nz;
            ak[l] += w;
        }
    }
    double sum = 0;
    for (int l = 0; l < LANES; l++)
        sum += (double)ax[l] + ay[l] + az[l] + ak[l];
    return sum;
}

/* mollify_block of kernels/mollify.cl for one block. */
static double mollify_block(const roof *r, size_t b) {
    float px[LANES], py[LANES], pz[LANES];
    float ax[LANES] = {0}, ay[LANES] = {0}, az[LANES] = {0}, ak[LANES] = {0};
    memcpy(px, r->px + b * LANES, sizeof px);
    memcpy(py, r->py + b * LANES, sizeof py);
    memcpy(pz, r->pz + b * LANES, sizeof pz);
    const float reach2 = r->mollify_reach2, inv_2sm2 = r->inv_2sm2;
    const size_t end = r->window_start[b] + r->window;
    for (size_t q = r->window_start[b]; q < end; q++) {
        const float cx = r->cx[q], cy = r->cy[q], cz = r->cz[q], la = r->logarea[q];
        for (int l = 0; l < LANES; l++) {
            float ex = cx - px[l], ey = cy - py[l], ez = cz - pz[l];
            float d2 = ex * ex + ey * ey + ez * ez;
            float w = masked(fast_exp2(la - d2 * inv_2sm2), d2 <= reach2);
            ax[l] += w * ex;
            ay[l] += w * ey;
            az[l] += w * ez;
            ak[l] += w;
        }
    }
    double sum = 0;
    for (int l = 0; l < LANES; l++)
        sum += (double)ax[l] + ay[l] + az[l] + ak[l];
    return sum;
}

static double now_s(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* Seconds for `sweeps` passes of every block over its window. */
static double time_sweeps(const roof *r, int robust, long sweeps) {
    double t0 = now_s();
    for (long s = 0; s < sweeps; s++) {
        double sum = 0;
        const long blocks = (long)r->block_count;
        PARALLEL_BLOCKS
        for (long b = 0; b < blocks; b++)
            sum += robust ? robust_block(r, (size_t)b) : mollify_block(r, (size_t)b);
        sink = sink + sum;
    }
    return now_s() - t0;
}

static int compare_double(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Pairs per second of one pass: enough sweeps for MIN_SECONDS, median of REPETITIONS. */
static double pairs_per_s(const roof *r, int robust) {
    double one = time_sweeps(r, robust, 1); /* also wakes the threads */
    long sweeps = one > 0 ? (long)ceil(MIN_SECONDS / one) : 1;
    if (sweeps < 1)
        sweeps = 1;
    double t[REPETITIONS];
    for (int i = 0; i < REPETITIONS; i++)
        t[i] = time_sweeps(r, robust, sweeps);
    qsort(t, REPETITIONS, sizeof *t, compare_double);
    double pairs = (double)sweeps * (double)r->block_count * LANES * (double)r->window;
    return pairs / t[REPETITIONS / 2];
}

typedef struct keyed_vertex {
    int32_t cell[3];
    uint32_t vertex;
} keyed_vertex;

static int compare_keyed(const void *a, const void *b) {
    const keyed_vertex *x = a, *y = b;
    for (int k = 0; k < 3; k++)
        if (x->cell[k] != y->cell[k])
            return x->cell[k] < y->cell[k] ? -1 : 1;
    return (x->vertex > y->vertex) - (x->vertex < y->vertex);
}

int bench_roofline_run(const bench_grid *grid, const float *positions, size_t vertex_count,
                       const bench_roofline_setup *setup, bench_roofline *result) {
    memset(result, 0, sizeof *result);
    const size_t nf = grid->facet_count;
    if (nf == 0 || vertex_count == 0)
        return -1;
    double t_start = now_s();
    const size_t blocks = (vertex_count + LANES - 1) / LANES, slots = blocks * LANES;
    const size_t window = nf < WINDOW ? nf : WINDOW;
    keyed_vertex *order = malloc(vertex_count * sizeof *order);
    size_t *window_start = malloc(blocks * sizeof *window_start);
    float *vertex_soa = malloc(slots * 3 * sizeof *vertex_soa);
    float *facet_soa = malloc(nf * 7 * sizeof *facet_soa);
    int status = -1;
    if (!order || !window_start || !vertex_soa || !facet_soa)
        goto done;

    /* As the kernels have them: coordinates in cell units (from the grid's corner rather than each
     * cell's, as a window spans many cells), weights as log2(area / mean area), exponents in base 2
     * like the kernels'. */
    const double h = grid->cell_size;
    for (size_t q = 0; q < nf; q++) {
        for (int k = 0; k < 3; k++) {
            facet_soa[k * nf + q] = (float)((grid->centroid[3 * q + k] - grid->origin[k]) / h);
            facet_soa[(3 + k) * nf + q] = (float)grid->normal[3 * q + k];
        }
        facet_soa[6 * nf + q] = (float)log2(grid->area[q] / grid->mean_area);
    }
    /* Vertices in the grid's cell order, so a block's window holds the facets around it. */
    for (size_t v = 0; v < vertex_count; v++) {
        double p[3];
        for (int k = 0; k < 3; k++)
            p[k] = positions[3 * v + k];
        bench_grid_cell(grid, p, order[v].cell);
        order[v].vertex = (uint32_t)v;
    }
    qsort(order, vertex_count, sizeof *order, compare_keyed);
    for (size_t s = 0; s < slots; s++) {
        /* unused lanes of the last block repeat its lane 0, as in the kernels */
        size_t v = order[s < vertex_count ? s : (blocks - 1) * LANES].vertex;
        for (int k = 0; k < 3; k++)
            vertex_soa[k * slots + s] = (float)((positions[3 * v + k] - grid->origin[k]) / h);
    }
    for (size_t b = 0; b < blocks; b++) {
        size_t first = bench_grid_first_facet(grid, order[b * LANES].cell);
        size_t start = first > window / 2 ? first - window / 2 : 0;
        window_start[b] = start + window > nf ? nf - window : start;
    }

    roof r = {
        .block_count = blocks,
        .window = window,
        .window_start = window_start,
        .px = vertex_soa,
        .py = vertex_soa + slots,
        .pz = vertex_soa + 2 * slots,
        .cx = facet_soa,
        .cy = facet_soa + nf,
        .cz = facet_soa + 2 * nf,
        .nx = facet_soa + 3 * nf,
        .ny = facet_soa + 4 * nf,
        .nz = facet_soa + 5 * nf,
        .logarea = facet_soa + 6 * nf,
        .reach2 = (float)((setup->radius / h) * (setup->radius / h)),
        .inv_2sf2 = (float)(LOG2E * h * h / (2 * setup->sigma_f * setup->sigma_f)),
        .inv_2sg2 = isinf(setup->sigma_g)
                        ? 0.0f
                        : (float)(LOG2E * h * h / (2 * setup->sigma_g * setup->sigma_g)),
        .mollify_reach2 = (float)((setup->mollify_radius / h) * (setup->mollify_radius / h)),
        .inv_2sm2 = (float)(LOG2E * h * h / (2 * setup->sigma_m * setup->sigma_m)),
    };
    if (setup->mollify_radius > 0)
        result->mollify_pairs_per_s = pairs_per_s(&r, 0);
    result->robust_pairs_per_s = pairs_per_s(&r, 1);
#ifdef _OPENMP
    result->threads = omp_get_max_threads();
    result->openmp = 1;
#else
    result->threads = 1;
#endif
    result->lanes = LANES;
    result->window = window;
    result->seconds = now_s() - t_start;
    status = 0;

done:
    free(order);
    free(window_start);
    free(vertex_soa);
    free(facet_soa);
    return status;
}
