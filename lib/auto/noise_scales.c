/* Noise at several scales: the spatially correlated part of the noise, which the quadric fit of
 * noise_estimate.c over 1-2 rings absorbs (real range scans: ridges along scan lines, waves of a
 * few edges).
 *
 * 1. Profile: each sampled vertex v is predicted from its neighbours within a cylinder of radius
 *    r = RADII (mean edge lengths) around its PCA normal by a least-squares quadric height field,
 *    v left out; the residual is standardised by sqrt(1 + (M^-1)_00) (noise_estimate.c, 3), so
 *    white noise of standard deviation s reads about s at every radius, while noise correlated
 *    over a few edges reads little at r = 2 (the fit follows it) and more at larger radii.
 * 2. Shape floor: the shape's curvature also grows the residual with r. The same profile of a
 *    Taubin-smoothed copy (TAUBIN_STEPS lambda|mu pairs: the noise of short wavelength out, the
 *    coarse shape kept unshrunk) says how much, and is taken out in quadrature.
 * 3. Inference (rs_noise_correlated): the growth of what is left from r = 2 to r = 3.5, beyond
 *    white noise's, times GAIN, is the correlated variance; claimed only where the shape floor
 *    does not dominate at 3.5 and the growth stands above it (coarse organic meshes such as cow
 *    and teapot otherwise read their curvature as noise). The correlation length is the radius
 *    where the variance left reaches half its value at r = 6, over HALF_TO_LENGTH.
 * Limits (docs/accuracy.md): noise correlated over more than about 1.5 edges (band-limited L >= 2,
 * stripes >= 6 edges wide) is smooth on the scale of these fits and is read as shape, not noise;
 * the figures scatter by tens of per cent from mesh to mesh. */
#include "auto/noise_scales.h"
#include "auto/eigen3.h"
#include "core/rsmooth_internal.h"
#include "core/spatial.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#define MAX_TERMS 6
#define SAMPLES 1500 /* vertices sampled at most, at a fixed stride */
#define SAMPLE_GRAIN 64
#define FRAME_RADIUS 2.5 /* the normal's ball, mean edge lengths */
#define MAD_TO_SIGMA 1.482602218505602
#define SQRT2 1.4142135623730951

static const double RADII[RS_NOISE_SCALE_COUNT] = {2, 3.5, 6};

/* Cholesky of the n x n normal matrix m (lower part) into l; false when not positive definite. */
static bool cholesky(int n, double m[MAX_TERMS][MAX_TERMS], double l[MAX_TERMS][MAX_TERMS]) {
    for (int j = 0; j < n; j++) {
        double d = m[j][j];
        for (int k = 0; k < j; k++)
            d -= l[j][k] * l[j][k];
        if (!(d > 1e-12 * (m[j][j] > 0 ? m[j][j] : 1)))
            return false;
        l[j][j] = sqrt(d);
        for (int i = j + 1; i < n; i++) {
            double s = m[i][j];
            for (int k = 0; k < j; k++)
                s -= l[i][k] * l[j][k];
            l[i][j] = s / l[j][j];
        }
    }
    return true;
}

/* Solves l l^T x = b. */
static void solve(int n, double l[MAX_TERMS][MAX_TERMS], const double *b, double *x) {
    double y[MAX_TERMS];
    for (int i = 0; i < n; i++) {
        double s = b[i];
        for (int k = 0; k < i; k++)
            s -= l[i][k] * y[k];
        y[i] = s / l[i][i];
    }
    for (int i = n - 1; i >= 0; i--) {
        double s = y[i];
        for (int k = i + 1; k < n; k++)
            s -= l[k][i] * x[k];
        x[i] = s / l[i][i];
    }
}

/* The quadric's terms at (x, y) into row; their count. */
static int monomials(double x, double y, double *row) {
    const double t[MAX_TERMS] = {1, x, y, x * x, x * y, y * y};
    memcpy(row, t, sizeof t);
    return MAX_TERMS;
}

typedef struct scales_job {
    const double *xyz, *normal;
    size_t count, sample_count;
    double unit;
    rs_grid grid;
    double *low; /* per sample and radius: signed standardised residual, or NAN */
    bool failed[64];
} scales_job;

/* The prediction residual at the origin of a quadric fit to the points (x, y, z) with
 * x^2 + y^2 < r^2 and |z| < r, standardised; NAN when too few points. */
static double fit_residual(const double *c, size_t n, double r) {
    double m[MAX_TERMS][MAX_TERMS] = {{0}}, b[MAX_TERMS] = {0}, row[MAX_TERMS];
    size_t used = 0;
    int terms = 0;
    for (size_t j = 0; j < n; j++) {
        const double *p = c + 3 * j;
        if (p[0] * p[0] + p[1] * p[1] >= r * r || fabs(p[2]) >= r)
            continue;
        terms = monomials(p[0] / r, p[1] / r, row);
        for (int i = 0; i < terms; i++) {
            b[i] += row[i] * p[2];
            for (int k = 0; k <= i; k++)
                m[i][k] += row[i] * row[k];
        }
        used++;
    }
    if (terms == 0 || used < (size_t)(2 * terms))
        return NAN;
    double l[MAX_TERMS][MAX_TERMS], beta[MAX_TERMS], e0[MAX_TERMS] = {1}, w[MAX_TERMS];
    if (!cholesky(terms, m, l))
        return NAN;
    solve(terms, l, b, beta);
    solve(terms, l, e0, w); /* w[0] = (M^-1)_00 */
    return -beta[0] / sqrt(1 + w[0]);
}

/* Sample s's residuals at every radius; false when out of memory. */
static bool sample_scales(scales_job *job, size_t s, double **buf, size_t *cap) {
    size_t v = (size_t)((double)s * (double)job->count / (double)job->sample_count);
    const double *p = job->xyz + 3 * v, *nv = job->normal + 3 * v, unit = job->unit;
    double reach = RADII[RS_NOISE_SCALE_COUNT - 1] * SQRT2 * unit;
    int32_t cell[3];
    rs_grid_cell_of(&job->grid, p, cell);
    size_t n = 0;
    double sum[3] = {0}, second[3][3] = {{0}};
    size_t inner = 0;
    for (int dx = -1; dx <= 1; dx++)
        for (int dy = -1; dy <= 1; dy++)
            for (int dz = -1; dz <= 1; dz++) {
                int32_t c = rs_grid_find(&job->grid, cell[0] + dx, cell[1] + dy, cell[2] + dz);
                for (uint32_t i = c < 0 ? 1 : job->grid.cell_start[c];
                     c >= 0 && i < job->grid.cell_start[c + 1]; i++) {
                    size_t j = job->grid.facet_order[i];
                    double d[3];
                    rs_sub3(job->xyz + 3 * j, p, d);
                    if (j == v || rs_dot3(d, d) > reach * reach ||
                        rs_dot3(nv, job->normal + 3 * j) <= 0)
                        continue;
                    if (n == *cap) {
                        size_t grown = *cap ? 2 * *cap : 512;
                        double *b = rs_realloc_array(*buf, grown, 3 * sizeof *b);
                        if (!b)
                            return false;
                        *buf = b;
                        *cap = grown;
                    }
                    for (int k = 0; k < 3; k++)
                        (*buf)[3 * n + k] = d[k] / unit;
                    if (rs_dot3(d, d) < FRAME_RADIUS * FRAME_RADIUS * unit * unit) {
                        for (int r = 0; r < 3; r++) {
                            sum[r] += d[r] / unit;
                            for (int k = 0; k <= r; k++)
                                second[r][k] += d[r] * d[k] / (unit * unit);
                        }
                        inner++;
                    }
                    n++;
                }
            }
    double *low = job->low + RS_NOISE_SCALE_COUNT * s;
    for (int k = 0; k < RS_NOISE_SCALE_COUNT; k++)
        low[k] = NAN;
    if (inner < 6)
        return true;
    double cov[3][3], values[3], axes[3][3];
    for (int r = 0; r < 3; r++)
        for (int k = 0; k <= r; k++)
            cov[r][k] = cov[k][r] = second[r][k] - sum[r] * sum[k] / (double)inner;
    rs_symmetric_eigen3(cov, values, axes); /* axes[0]: the normal (smallest) */
    for (size_t j = 0; j < n; j++) {
        double *d = *buf + 3 * j,
               t[3] = {rs_dot3(d, axes[1]), rs_dot3(d, axes[2]), rs_dot3(d, axes[0])};
        memcpy(d, t, sizeof t);
    }
    for (int k = 0; k < RS_NOISE_SCALE_COUNT; k++)
        low[k] = fit_residual(*buf, n, RADII[k]);
    return true;
}

static void scales_range(void *ctx, size_t begin, size_t end, size_t chunk) {
    scales_job *job = ctx;
    double *buf = NULL;
    size_t cap = 0;
    bool failed = false;
    for (size_t s = begin; s < end && !failed; s++)
        failed = !sample_scales(job, s, &buf, &cap);
    job->failed[chunk] = failed;
    rs_free(buf);
}

static int compare_doubles(const void *pa, const void *pb) {
    double a = *(const double *)pa, b = *(const double *)pb;
    return (a > b) - (a < b);
}

/* 1.4826 x the median |value| of the non-NAN values among n at `stride`; NAN when none. */
static double robust_sd(const double *values, size_t n, size_t stride, double *scratch) {
    size_t k = 0;
    for (size_t i = 0; i < n; i++)
        if (!isnan(values[i * stride]))
            scratch[k++] = fabs(values[i * stride]);
    if (k == 0)
        return NAN;
    qsort(scratch, k, sizeof *scratch, compare_doubles);
    return MAD_TO_SIGMA * (k % 2 ? scratch[k / 2] : 0.5 * (scratch[k / 2 - 1] + scratch[k / 2]));
}

/* The profile figures of the points xyz into low/high (grid built over xyz). */
static rsmooth_status profile_of(const double *xyz, const double *normal, size_t count, double unit,
                                 double *low, size_t *samples, rsmooth_error *error,
                                 const char *caller) {
    scales_job job;
    memset(&job, 0, sizeof job);
    job.xyz = xyz;
    job.normal = normal;
    job.count = count;
    job.unit = unit;
    job.sample_count = count < SAMPLES ? count : SAMPLES;
    rsmooth_status st =
        rs_grid_build(&job.grid, xyz, count, RADII[RS_NOISE_SCALE_COUNT - 1] * SQRT2 * unit, error);
    if (st != RSMOOTH_OK)
        return st;
    size_t cells = job.sample_count * RS_NOISE_SCALE_COUNT;
    job.low = rs_alloc_array(cells, sizeof *job.low);
    double *scratch = rs_alloc_array(job.sample_count, sizeof *scratch);
    if (!job.low || !scratch) {
        st = rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, caller, "no memory for %zu samples",
                     job.sample_count);
        goto done;
    }
    rs_parallel_for(job.sample_count, SAMPLE_GRAIN, scales_range, &job);
    for (size_t c = 0; c < sizeof job.failed / sizeof *job.failed; c++)
        if (job.failed[c]) {
            st = rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, caller,
                         "no memory for a vertex's neighbours");
            goto done;
        }
    for (int k = 0; k < RS_NOISE_SCALE_COUNT; k++)
        low[k] = robust_sd(job.low + k, job.sample_count, RS_NOISE_SCALE_COUNT, scratch);
    *samples = job.sample_count;
done:
    rs_free(job.low);
    rs_free(scratch);
    rs_grid_free(&job.grid);
    return st;
}

/* Taubin's lambda|mu smoothing (umbrella operator over the mesh neighbours), TAUBIN_STEPS pairs:
 * takes the noise of a few edges' wavelength out and keeps the coarser shape, unshrunk. */
#define TAUBIN_STEPS 20
#define TAUBIN_LAMBDA 0.5
#define TAUBIN_MU (-0.53)
static void taubin(double *xyz, double *tmp, size_t count, const uint32_t *ring_start,
                   const uint32_t *ring) {
    for (int step = 0; step < 2 * TAUBIN_STEPS; step++) {
        double f = step % 2 ? TAUBIN_MU : TAUBIN_LAMBDA;
        for (size_t v = 0; v < count; v++) {
            double c[3] = {0, 0, 0};
            uint32_t k = ring_start[v + 1] - ring_start[v];
            for (uint32_t j = ring_start[v]; j < ring_start[v + 1]; j++)
                for (int d = 0; d < 3; d++)
                    c[d] += xyz[3 * (size_t)ring[j] + d];
            for (int d = 0; d < 3; d++)
                tmp[3 * v + d] =
                    k ? xyz[3 * v + d] + f * (c[d] / k - xyz[3 * v + d]) : xyz[3 * v + d];
        }
        memcpy(xyz, tmp, 3 * count * sizeof *xyz);
    }
}

rsmooth_status rs_noise_scales(const double *xyz, const double *normal, size_t count, double unit,
                               const uint32_t *ring_start, const uint32_t *ring,
                               rs_noise_profile *out, rsmooth_error *error, const char *caller) {
    memset(out, 0, sizeof *out);
    for (int k = 0; k < RS_NOISE_SCALE_COUNT; k++) {
        out->radius[k] = RADII[k];
        out->low[k] = out->low_floor[k] = NAN;
    }
    if (count == 0 || !(unit > 0))
        return RSMOOTH_OK;
    rsmooth_status st =
        profile_of(xyz, normal, count, unit, out->low, &out->samples, error, caller);
    if (st != RSMOOTH_OK)
        return st;
    double *smooth = rs_alloc_array(count, 3 * sizeof *smooth);
    double *tmp = rs_alloc_array(count, 3 * sizeof *tmp);
    if (!smooth || !tmp) {
        rs_free(smooth);
        rs_free(tmp);
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, caller, "no memory for %zu points",
                       count);
    }
    memcpy(smooth, xyz, 3 * count * sizeof *smooth);
    taubin(smooth, tmp, count, ring_start, ring);
    size_t ignored;
    st = profile_of(smooth, normal, count, unit, out->low_floor, &ignored, error, caller);
    rs_free(smooth);
    rs_free(tmp);
    return st;
}

/* The inference's constants. GAIN, GROWTH, FLOOR_SHARE and EXCESS_SHARE were fitted by
 * the noise_scales_fit study (a grid search, log error) on beetle-alt and rocker-arm (clean
 * meshes of ../shared/data/clean: clean, and with generated noise along normals, in random
 * directions, band-limited L = 1, stripes W = 3; sigma 0.3 to 1) and the raw scan bun000 (truth:
 * its rms distance to the Stanford reconstruction), and checked on the other meshes of
 * the noise_accuracy study, bun045 among them (docs/accuracy.md, "Correlated noise").
 * WHITE_SHARE was chosen; HALF_TO_LENGTH is beetle-alt's L = 1. */
#define GAIN 10.5 /* correlated variance per unit of excess growth at RADII[1] */
#define GROWTH                                                                                     \
    1.1 /* what the profile grows from RADII[0] to RADII[1] for white noise and                    \
         * a sampled surface: more is correlated noise */
#define FLOOR_SHARE                                                                                \
    0.8                    /* the smoothed copy reads at most this share of the mesh at RADII[1]:  \
                            * beyond, the shape dominates there and nothing is claimed */
#define EXCESS_SHARE 0.7   /* the growth must exceed this share of the floor's variance */
#define WHITE_SHARE 1.0    /* and the correlated variance the white variance, times this squared */
#define HALF_TO_LENGTH 4.2 /* half-growth radius per unit of correlation length */

void rs_noise_correlated(const rs_noise_profile *profile, double level, double *correlated_level,
                         double *correlation_length) {
    *correlated_level = level;
    *correlation_length = 0;
    const double *l = profile->low, *f = profile->low_floor;
    double v[3]; /* the variance beyond the shape's, per radius */
    for (int k = 0; k < 3; k++) {
        if (isnan(l[k]) || isnan(f[k]))
            return;
        v[k] = l[k] * l[k] - f[k] * f[k];
        v[k] = v[k] > 0 ? v[k] : 0;
    }
    double growth = v[1] - GROWTH * v[0];
    if (!(f[1] <= FLOOR_SHARE * l[1]) || !(growth > EXCESS_SHARE * f[1] * f[1]) ||
        !(GAIN * growth >= WHITE_SHARE * WHITE_SHARE * level * level))
        return;
    *correlated_level = sqrt(level * level + GAIN * growth);
    /* the radius where v reaches half its value at RADII[2], linear between radii */
    double half = 0.5 * v[2], r = RADII[0];
    if (v[0] < half) {
        int k = v[1] >= half ? 0 : 1;
        r = RADII[k] + (RADII[k + 1] - RADII[k]) * (half - v[k]) / (v[k + 1] - v[k]);
    }
    *correlation_length = r / HALF_TO_LENGTH;
}
