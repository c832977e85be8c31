/* Noise level of a mesh, for choosing the filter's parameters automatically: the standard
 * deviation of the vertices' displacement along the surface normal, in mean edge lengths (the unit
 * of relative sigmas), from the geometry alone.
 *
 * Each sampled vertex v is predicted from the other vertices near it; the prediction error is v's
 * noise plus the prediction's own error, whose size per unit noise is known exactly:
 *
 *  1. Frame: the plane of the vertices within RADIUS (mean edge lengths) of v, by PCA; then again
 *     with the ball centred on v's projection onto that plane instead of v, so that which
 *     neighbours are used does not depend on v's own noise (a ball around a noisy v holds more of
 *     the surface on v's side; the screening in 4 then kept vertices with large noise, +15% at 0.7).
 *  2. Neighbours: the other vertices within a cylinder of radius RADIUS around v's axis along that
 *     normal, within SLAB of the neighbours' centroid. Vertices whose normal faces away from v's
 *     (cosine <= FACING) are left out: the far wall of a slot, the back of a thin fin.
 *  3. Fit: a quadric height field z = b0 + b1 x + b2 y + b3 x^2 + b4 x y + b5 y^2 by least squares
 *     (a plane reads curvature as noise: several times too high on a fine sphere at low noise).
 *     v is not in its own fit, so its residual r = z_v - b0 has variance sigma^2 (1 + a_0^T M^-1
 *     a_0) = sigma^2 (1 + (M^-1)_00) with M = A^T A: r / sqrt(1 + (M^-1)_00) is exactly N(0,
 *     sigma^2) on a smooth surface, with no empirical factor for the fit's own bias. The residual
 *     is made perpendicular by sqrt(1 + g^2), g the fit's slope at v less its noise.
 *  4. Screening: next to sharp edges and corners no quadric fits and residuals are too large. Those
 *     fits show it in their residual variance s^2 over the neighbours, which for a least-squares
 *     fit is independent of the prediction at v (Cochran's theorem) and of v's noise: keeping only
 *     the vertices with s^2 <= KAPPA sigma^2 (sigma the current estimate) removes them without
 *     biasing the rest. sigma starts from the median s^2 and is refined ROUNDS times as 1.4826 x the
 *     median standardised |residual| of the kept vertices (a normal's median |value| is 0.6745
 *     sigma).
 *
 * Calibration (tests/test_noise_estimate.c; the benchmark models' Original.obj with generated noise,
 * 3 seeds each): Gaussian noise of 0.1 to 0.7 mean edge lengths along the normals reads within 5%
 * of the truth on planes, spheres, cubes and capped cylinders of ~10k vertices and on Fandisk,
 * Block, Bunny, SharpSphere and Twelve; a 602-vertex cube, most of whose vertices are near an edge,
 * within 15%. KAPPA = 1.25 was chosen there (1 and 1.5 do nearly as well but for the coarse cube); no
 * other factor is fitted. Choosing, per vertex, the best of the whole disc and half discs on either
 * side of a crease instead of screening read 5-10% high at low noise: the choice depends on the
 * neighbours' noise.
 *
 * Exact duplicate positions are welded first (a triangle soup's corners), so a vertex's copies are
 * not its neighbours. Up to MAX_SAMPLES vertices are used, at a fixed stride; each sample depends on
 * the positions alone and the medians on the samples alone, so the result is the same on every
 * run and for any thread count. */
#include "spatial.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define RADIUS 2.5        /* fit radius, mean edge lengths */
#define SLAB 2.5          /* half-height of the cylinder around the neighbours' centroid */
#define MARGIN 1.0        /* how far v's frame centre may lie from v, beyond which a neighbour of
                           * the cylinder is missed: > 2 sigma even at noise 0.5 */
#define FACING (-0.5)     /* neighbours whose normal is > 120 degrees from v's are left out */
#define MIN_POINTS 10     /* fewest points a quadric (6 coefficients) is fitted to */
#define KAPPA 1.25        /* vertices whose fit's residual variance exceeds KAPPA sigma^2 are left
                           * out (their neighbourhood is no quadric: an edge, a corner) */
#define ROUNDS 3          /* refinements of sigma and of the screening */
#define MAX_SAMPLES 50000 /* vertices used at most */
#define SAMPLE_GRAIN 256  /* samples per chunk below which a thread does not pay */
#define MAD_TO_SIGMA 1.482602218505602 /* 1 / Phi^-1(3/4) */
#define TERMS 6

static const char where[] = "rsmooth_estimate_noise";

/* ---- small linear algebra ------------------------------------------------------------------- */

/* Eigenvectors of a symmetric 3x3 matrix by cyclic Jacobi rotations: vectors[k] (rows) belongs to
 * values[k], ascending. */
static void symmetric_eigen3(double m[3][3], double values[3], double vectors[3][3]) {
    double a[3][3], v[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    memcpy(a, m, sizeof a);
    for (int sweep = 0; sweep < 50; sweep++) {
        double off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
        double diag = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
        if (off <= 1e-30 * diag || off == 0)
            break;
        for (int p = 0; p < 2; p++)
            for (int q = p + 1; q < 3; q++) {
                if (a[p][q] == 0)
                    continue;
                double theta = (a[q][q] - a[p][p]) / (2 * a[p][q]);
                double t = (theta >= 0 ? 1 : -1) / (fabs(theta) + sqrt(theta * theta + 1));
                double c = 1 / sqrt(t * t + 1), s = t * c;
                for (int k = 0; k < 3; k++) { /* A <- A J */
                    double akp = a[k][p], akq = a[k][q];
                    a[k][p] = c * akp - s * akq;
                    a[k][q] = s * akp + c * akq;
                }
                for (int k = 0; k < 3; k++) { /* A <- J^T A */
                    double apk = a[p][k], aqk = a[q][k];
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                }
                for (int k = 0; k < 3; k++) { /* V <- V J (columns are the vectors) */
                    double vkp = v[k][p], vkq = v[k][q];
                    v[k][p] = c * vkp - s * vkq;
                    v[k][q] = s * vkp + c * vkq;
                }
            }
    }
    int order[3] = {0, 1, 2};
    for (int i = 0; i < 2; i++)
        for (int j = i + 1; j < 3; j++)
            if (a[order[j]][order[j]] < a[order[i]][order[i]]) {
                int t = order[i];
                order[i] = order[j];
                order[j] = t;
            }
    for (int k = 0; k < 3; k++) {
        values[k] = a[order[k]][order[k]];
        for (int c = 0; c < 3; c++)
            vectors[k][c] = v[c][order[k]];
    }
}

/* Cholesky factor L (lower) of the symmetric positive definite m, and the reciprocals of its
 * diagonal; false when a pivot falls below 1e-10 of the largest diagonal entry (too few or
 * collinear points for a quadric). */
static bool cholesky6(double m[TERMS][TERMS], double l[TERMS][TERMS], double inv[TERMS]) {
    double scale = 0;
    for (int i = 0; i < TERMS; i++)
        scale = m[i][i] > scale ? m[i][i] : scale;
    if (!(scale > 0))
        return false;
    for (int j = 0; j < TERMS; j++) {
        double d = m[j][j];
        for (int k = 0; k < j; k++)
            d -= l[j][k] * l[j][k];
        if (!(d > 1e-10 * scale))
            return false;
        l[j][j] = sqrt(d);
        inv[j] = 1 / l[j][j];
        for (int i = j + 1; i < TERMS; i++) {
            double s = m[i][j];
            for (int k = 0; k < j; k++)
                s -= l[i][k] * l[j][k];
            l[i][j] = s * inv[j];
        }
    }
    return true;
}

/* y = L^-1 b for b zero before `first` (y is then zero there too). */
static void forward6(double l[TERMS][TERMS], const double inv[TERMS], const double b[TERMS],
                     int first, double y[TERMS]) {
    for (int i = 0; i < first; i++)
        y[i] = 0;
    for (int i = first; i < TERMS; i++) {
        double s = b[i];
        for (int k = first; k < i; k++)
            s -= l[i][k] * y[k];
        y[i] = s * inv[i];
    }
}

/* x = L^-T y. */
static void backward6(double l[TERMS][TERMS], const double inv[TERMS], const double y[TERMS],
                      double x[TERMS]) {
    for (int i = TERMS - 1; i >= 0; i--) {
        double s = y[i];
        for (int k = i + 1; k < TERMS; k++)
            s -= l[k][i] * x[k];
        x[i] = s * inv[i];
    }
}

/* |L^-1 e_k|^2 = (M^-1)_kk. */
static double inverse_diagonal(double l[TERMS][TERMS], const double inv[TERMS], int k) {
    double e[TERMS] = {0}, y[TERMS], sum = 0;
    e[k] = 1;
    forward6(l, inv, e, k, y);
    for (int i = k; i < TERMS; i++)
        sum += y[i] * y[i];
    return sum;
}

/* ---- the points: welded vertices with normals ------------------------------------------------ */

typedef struct point_set {
    size_t count;
    double *xyz;    /* 3 per point */
    double *normal; /* 3 per point, unit */
} point_set;

typedef struct keyed_vertex {
    double p[3];
    uint32_t v;
} keyed_vertex;

/* By position, then by index (so equal positions are merged in a fixed order). */
static int compare_keyed(const void *pa, const void *pb) {
    const keyed_vertex *a = pa, *b = pb;
    for (int k = 0; k < 3; k++)
        if (a->p[k] != b->p[k])
            return a->p[k] < b->p[k] ? -1 : 1;
    return (a->v > b->v) - (a->v < b->v);
}

/* The vertices some non-degenerate triangle uses, exact duplicates merged (their area-weighted
 * normals summed; copies whose normals cancel, both sides of a sheet, are dropped). false when out
 * of memory. */
static bool build_points(const double *xyz, size_t vertex_count, const uint32_t *indices,
                         size_t triangle_count, point_set *out) {
    memset(out, 0, sizeof *out);
    double *normal = rs_calloc_array(vertex_count, 3 * sizeof *normal);
    keyed_vertex *order = rs_alloc_array(vertex_count, sizeof *order);
    out->xyz = rs_alloc_array(vertex_count, 3 * sizeof *out->xyz);
    out->normal = rs_alloc_array(vertex_count, 3 * sizeof *out->normal);
    if (!normal || !order || !out->xyz || !out->normal) {
        rs_free(normal);
        rs_free(order);
        rs_free(out->xyz);
        rs_free(out->normal);
        memset(out, 0, sizeof *out);
        return false;
    }
    for (size_t t = 0; t < triangle_count; t++) {
        const uint32_t *tri = indices + 3 * t;
        double e1[3], e2[3], n[3];
        rs_sub3(xyz + 3 * (size_t)tri[1], xyz + 3 * (size_t)tri[0], e1);
        rs_sub3(xyz + 3 * (size_t)tri[2], xyz + 3 * (size_t)tri[0], e2);
        rs_cross3(e1, e2, n); /* twice the area times the unit normal */
        for (int c = 0; c < 3; c++)
            for (int k = 0; k < 3; k++)
                normal[3 * (size_t)tri[c] + k] += n[k];
    }
    size_t used = 0;
    for (size_t v = 0; v < vertex_count; v++)
        if (rs_dot3(normal + 3 * v, normal + 3 * v) > 0) {
            memcpy(order[used].p, xyz + 3 * v, sizeof order[used].p);
            order[used++].v = (uint32_t)v;
        }
    qsort(order, used, sizeof *order, compare_keyed);
    size_t count = 0;
    for (size_t i = 0; i < used; i++) {
        const double *p = order[i].p, *n = normal + 3 * (size_t)order[i].v;
        const double *last = out->xyz + 3 * (count - 1);
        if (count == 0 || p[0] != last[0] || p[1] != last[1] || p[2] != last[2]) {
            memcpy(out->xyz + 3 * count, p, 3 * sizeof *p);
            memset(out->normal + 3 * count, 0, 3 * sizeof *n);
            count++;
        }
        for (int k = 0; k < 3; k++)
            out->normal[3 * (count - 1) + k] += n[k];
    }
    size_t kept = 0;
    for (size_t i = 0; i < count; i++) {
        const double *n = out->normal + 3 * i;
        double len = sqrt(rs_dot3(n, n));
        if (!(len > 0))
            continue;
        for (int k = 0; k < 3; k++) {
            out->xyz[3 * kept + k] = out->xyz[3 * i + k];
            out->normal[3 * kept + k] = n[k] / len;
        }
        kept++;
    }
    out->count = kept;
    rs_free(normal);
    rs_free(order);
    return true;
}

static void free_points(point_set *points) {
    rs_free(points->xyz);
    rs_free(points->normal);
    memset(points, 0, sizeof *points);
}

/* Reorders the points as the grid's facet_order lists them (by cell), so that a cell's points are
 * contiguous: neighbour searches then read memory in order. */
static bool sort_points(point_set *points, const uint32_t *order) {
    double *xyz = rs_alloc_array(points->count, 3 * sizeof *xyz);
    double *normal = rs_alloc_array(points->count, 3 * sizeof *normal);
    if (!xyz || !normal) {
        rs_free(xyz);
        rs_free(normal);
        return false;
    }
    for (size_t i = 0; i < points->count; i++) {
        memcpy(xyz + 3 * i, points->xyz + 3 * (size_t)order[i], 3 * sizeof *xyz);
        memcpy(normal + 3 * i, points->normal + 3 * (size_t)order[i], 3 * sizeof *normal);
    }
    rs_free(points->xyz);
    rs_free(points->normal);
    points->xyz = xyz;
    points->normal = normal;
    return true;
}

/* ---- per-sample residuals -------------------------------------------------------------------- */

typedef struct sample_job {
    const point_set *points;
    const rs_grid *grid;
    double unit;          /* mean edge length */
    size_t sample_count;
    double *residual;     /* per sample: standardised |residual|, mesh units, or NAN (no fit) */
    double *variance;     /* per sample: the fit's residual variance s^2, mesh units squared */
    bool failed[64];      /* per chunk: out of memory */
} sample_job;

/* A sample's neighbours, offsets from it in mesh units (grown as needed, one per thread). */
typedef struct workspace {
    size_t capacity;
    double *d; /* 3 per neighbour */
} workspace;

static bool reserve(workspace *w, size_t n) {
    if (n <= w->capacity)
        return true;
    size_t cap = w->capacity ? 2 * w->capacity : 256;
    while (cap < n)
        cap *= 2;
    double *d = rs_realloc_array(w->d, cap, 3 * sizeof *d);
    if (!d)
        return false;
    w->d = d;
    w->capacity = cap;
    return true;
}

/* Gathers the neighbours of point v within `reach` whose normals do not face away from v's into
 * w (offsets from v); returns their count, or SIZE_MAX when out of memory. */
static size_t gather(const sample_job *job, size_t v, double reach, workspace *w) {
    const point_set *pts = job->points;
    const double *p = pts->xyz + 3 * v, *nv = pts->normal + 3 * v;
    int32_t cell[3];
    rs_grid_cell_of(job->grid, p, cell);
    size_t n = 0;
    for (int dx = -1; dx <= 1; dx++)
        for (int dy = -1; dy <= 1; dy++)
            for (int dz = -1; dz <= 1; dz++) {
                int32_t c = rs_grid_find(job->grid, cell[0] + dx, cell[1] + dy, cell[2] + dz);
                if (c < 0)
                    continue;
                /* the points are stored in cell order: a cell's are contiguous */
                for (size_t j = job->grid->cell_start[c]; j < job->grid->cell_start[c + 1]; j++) {
                    double d[3];
                    rs_sub3(pts->xyz + 3 * j, p, d);
                    if (j == v || rs_dot3(d, d) > reach * reach ||
                        rs_dot3(nv, pts->normal + 3 * j) <= FACING)
                        continue;
                    if (!reserve(w, n + 1))
                        return SIZE_MAX;
                    memcpy(w->d + 3 * n, d, sizeof d);
                    n++;
                }
            }
    return n;
}

/* PCA of the offsets within `radius` of `centre`: their centroid and axes (axes[0] the normal);
 * false when fewer than MIN_POINTS lie there. One pass: the offsets are from v, within a few edge
 * lengths, so the second moments less the centroid's lose nothing. */
static bool ball_frame(const double *d, size_t n, const double centre[3], double radius,
                       double centroid[3], double axes[3][3]) {
    size_t count = 0;
    double sum[3] = {0, 0, 0}, second[3][3] = {{0}};
    for (size_t j = 0; j < n; j++) {
        const double *p = d + 3 * j;
        double e[3];
        rs_sub3(p, centre, e);
        if (!(rs_dot3(e, e) < radius * radius))
            continue;
        for (int r = 0; r < 3; r++) {
            sum[r] += p[r];
            for (int c = 0; c <= r; c++)
                second[r][c] += p[r] * p[c];
        }
        count++;
    }
    if (count < MIN_POINTS)
        return false;
    double cov[3][3];
    for (int r = 0; r < 3; r++)
        centroid[r] = sum[r] / (double)count;
    for (int r = 0; r < 3; r++)
        for (int c = 0; c <= r; c++)
            cov[r][c] = cov[c][r] = second[r][c] - (double)count * centroid[r] * centroid[c];
    double values[3];
    symmetric_eigen3(cov, values, axes);
    return true;
}

/* The standardised |residual| of point v and its fit's residual variance (mesh units); false when
 * no fit is possible (too few neighbours). *failed when out of memory. */
static bool sample_residual(const sample_job *job, size_t v, workspace *w, bool *failed,
                            double *residual, double *variance) {
    const double unit = job->unit, radius = RADIUS * unit, slab = SLAB * unit;
    size_t n = gather(job, v, hypot(radius, slab) + MARGIN * unit, w);
    if (n == SIZE_MAX) {
        *failed = true;
        return false;
    }
    /* the frame: the ball around v, then around v projected onto the first ball's plane */
    double origin[3] = {0, 0, 0}, centre[3], centroid[3], axes[3][3];
    if (!ball_frame(w->d, n, origin, radius, centroid, axes))
        return false;
    double offset = rs_dot3(centroid, axes[0]); /* v is at the origin */
    for (int k = 0; k < 3; k++)
        centre[k] = offset * axes[0][k];
    if (!ball_frame(w->d, n, centre, radius, centroid, axes))
        return false;
    const double *normal = axes[0], *t1 = axes[1], *t2 = axes[2];
    double centre_z = rs_dot3(centroid, normal);
    /* least-squares moments of the cylinder's points: x, y in mean edge lengths, z in mesh units */
    double m[TERMS][TERMS] = {{0}}, b[TERMS] = {0}, zz = 0;
    size_t count = 0;
    for (size_t j = 0; j < n; j++) {
        const double *d = w->d + 3 * j;
        double x = rs_dot3(d, t1), y = rs_dot3(d, t2), z = rs_dot3(d, normal);
        if (x * x + y * y >= radius * radius || fabs(z - centre_z) >= slab)
            continue;
        x /= unit;
        y /= unit;
        const double row[TERMS] = {1, x, y, x * x, x * y, y * y};
        for (int r = 0; r < TERMS; r++) {
            b[r] += row[r] * z;
            for (int c = 0; c <= r; c++)
                m[r][c] += row[r] * row[c];
        }
        zz += z * z;
        count++;
    }
    if (count < MIN_POINTS)
        return false;
    for (int r = 0; r < TERMS; r++)
        for (int c = r + 1; c < TERMS; c++)
            m[r][c] = m[c][r];
    double l[TERMS][TERMS], inv[TERMS], y[TERMS], beta[TERMS];
    if (!cholesky6(m, l, inv))
        return false;
    forward6(l, inv, b, 0, y);
    backward6(l, inv, y, beta);
    /* the residual sum of squares z^T z - b^T M^-1 b: z is measured from v, so both terms are of
     * the order of the noise and nothing large cancels */
    double rss = zz;
    for (int r = 0; r < TERMS; r++)
        rss -= y[r] * y[r];
    double s2 = (rss > 0 ? rss : 0) / (double)(count - TERMS);
    /* the squared slope at v less its noise, s2 ((M^-1)_11 + (M^-1)_22) (x, y in edge lengths) */
    double slope_noise = s2 * (inverse_diagonal(l, inv, 1) + inverse_diagonal(l, inv, 2));
    double g2 = (beta[1] * beta[1] + beta[2] * beta[2] - slope_noise) / (unit * unit);
    g2 = g2 > 0 ? g2 : 0;
    double factor = 1 + inverse_diagonal(l, inv, 0);
    *residual = fabs(beta[0]) / sqrt((1 + g2) * factor);
    *variance = s2;
    return true;
}

static void sample_range(void *ctx, size_t begin, size_t end, size_t chunk) {
    sample_job *job = ctx;
    workspace w = {0, NULL};
    bool failed = false;
    size_t count = job->points->count;
    for (size_t s = begin; s < end && !failed; s++) {
        /* a fixed stride over the points in cell order (all of them when there are few enough) */
        size_t v = (size_t)((double)s * (double)count / (double)job->sample_count);
        v = v < count ? v : count - 1;
        if (!sample_residual(job, v, &w, &failed, &job->residual[s], &job->variance[s]))
            job->residual[s] = job->variance[s] = NAN;
    }
    job->failed[chunk] = failed;
    rs_free(w.d);
}

/* ---- the robust scale ------------------------------------------------------------------------ */

static int compare_double(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Median of values[0 .. n) (n > 0), reordering them. */
static double median(double *values, size_t n) {
    qsort(values, n, sizeof *values, compare_double);
    return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

/* sigma (mesh units) from the samples' residuals and fit variances (NAN-free, n > 0), by the
 * screening of the header comment; scratch holds n doubles. */
static double robust_sigma(const double *residual, const double *variance, size_t n,
                           double *scratch) {
    memcpy(scratch, variance, n * sizeof *scratch);
    double sigma2 = median(scratch, n), sigma = sqrt(sigma2);
    for (int round = 0; round < ROUNDS; round++) {
        size_t kept = 0;
        for (size_t s = 0; s < n; s++)
            if (variance[s] <= KAPPA * sigma2)
                scratch[kept++] = residual[s];
        if (kept == 0)
            break; /* none this close to a quadric (sigma 0, a rough surface): keep the last */
        sigma = MAD_TO_SIGMA * median(scratch, kept);
        sigma2 = sigma * sigma;
    }
    return sigma;
}

/* ---- the public call ------------------------------------------------------------------------ */

/* The share of screened residuals (away from edges, as robust_sigma keeps them) beyond TAIL_SIGMAS
 * robust sigmas, above which the noise is impulsive: a Gaussian puts 6e-5 of its mass there (the
 * generated shapes and the Gaussian benchmark models read at most 6e-4); a few vertices thrown
 * far while the rest stay put, which is impulsive noise, put a large share there (Twelve0.5
 * Impulsive 0.03, a sphere with half its vertices moved 0.08). */
#define TAIL_SIGMAS 4.0
#define IMPULSIVE_TAIL 0.01

static double tail_share(const double *residual, const double *variance, size_t n,
                         double sigma) {
    size_t far = 0, kept = 0;
    for (size_t s = 0; s < n; s++)
        if (variance[s] <= KAPPA * sigma * sigma) { /* not near an edge: as robust_sigma */
            kept++;
            far += fabs(residual[s]) > TAIL_SIGMAS * sigma;
        }
    return kept ? (double)far / (double)kept : 0;
}

rsmooth_status rsmooth_estimate_noise(rsmooth_scalar scalar, const void *positions,
                                      size_t vertex_count, const uint32_t *indices,
                                      size_t triangle_count, double *out_noise,
                                      rsmooth_error *error) {
    rs_error_clear(error);
    if (!out_noise)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "out_noise is NULL");
    rs_noise_stats stats;
    rsmooth_status st = rs_estimate_noise_stats(scalar, positions, vertex_count, indices,
                                                triangle_count, &stats, error, where);
    if (st == RSMOOTH_OK)
        *out_noise = stats.noise;
    return st;
}

rsmooth_status rs_estimate_noise_stats(rsmooth_scalar scalar, const void *positions,
                                       size_t vertex_count, const uint32_t *indices,
                                       size_t triangle_count, rs_noise_stats *out,
                                       rsmooth_error *error, const char *caller) {
    double magnitude = 0, scale = 1;
    rsmooth_status st = rs_check_mesh_arrays(scalar, positions, vertex_count, indices,
                                             triangle_count, &magnitude, error, caller);
    if (st == RSMOOTH_OK) /* internal units (scale.c): the estimate is a ratio, unchanged */
        st = rs_mesh_scale(scalar, positions, indices, triangle_count, magnitude, &scale, error,
                           caller);
    if (st != RSMOOTH_OK)
        return st;
    memset(out, 0, sizeof *out);
    double *out_noise = &out->noise;
    double *xyz = rs_alloc_array(vertex_count, 3 * sizeof *xyz);
    if (!xyz)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, caller, "no memory for positions");
    rs_scale_positions(scalar, positions, vertex_count, scale, xyz);
    double unit = 0;
    if (!rs_mean_edge_length(xyz, vertex_count, indices, triangle_count, &unit)) {
        rs_free(xyz);
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, caller, "no memory for edges");
    }
    if (!(unit > 0)) { /* no edge: no unit, nothing to measure */
        rs_free(xyz);
        return RSMOOTH_OK;
    }
    point_set pts;
    bool ok = build_points(xyz, vertex_count, indices, triangle_count, &pts);
    rs_free(xyz);
    if (!ok)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, caller,
                       "no memory for %zu vertex normals", vertex_count);
    if (pts.count <= MIN_POINTS) { /* too few vertices for any fit: nothing measurable */
        free_points(&pts);
        return RSMOOTH_OK;
    }
    rs_grid grid;
    st = rs_grid_build(&grid, pts.xyz, pts.count, (hypot(RADIUS, SLAB) + MARGIN) * unit, error);
    if (st != RSMOOTH_OK) {
        free_points(&pts);
        return st;
    }
    if (!sort_points(&pts, grid.facet_order)) {
        rs_grid_free(&grid);
        free_points(&pts);
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, caller, "no memory for %zu points",
                       pts.count);
    }
    sample_job job;
    memset(&job, 0, sizeof job);
    job.points = &pts;
    job.grid = &grid;
    job.unit = unit;
    job.sample_count = pts.count < MAX_SAMPLES ? pts.count : MAX_SAMPLES;
    job.residual = rs_alloc_array(job.sample_count, sizeof *job.residual);
    job.variance = rs_alloc_array(job.sample_count, sizeof *job.variance);
    double *scratch = rs_alloc_array(job.sample_count, sizeof *scratch);
    if (!job.residual || !job.variance || !scratch) {
        st = rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, caller, "no memory for %zu samples",
                     job.sample_count);
    } else {
        rs_parallel_for(job.sample_count, SAMPLE_GRAIN, sample_range, &job);
        for (size_t c = 0; c < sizeof job.failed / sizeof *job.failed; c++)
            if (job.failed[c])
                st = rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, caller,
                             "no memory for a vertex's neighbours");
    }
    if (st == RSMOOTH_OK) {
        size_t valid = 0; /* the samples with a fit, in sample order */
        for (size_t s = 0; s < job.sample_count; s++)
            if (!isnan(job.residual[s])) {
                job.residual[valid] = job.residual[s];
                job.variance[valid++] = job.variance[s];
            }
        if (valid > 0) {
            double sigma = robust_sigma(job.residual, job.variance, valid, scratch);
            *out_noise = sigma / unit;
            out->impulsive =
                sigma > 0 && tail_share(job.residual, job.variance, valid, sigma) > IMPULSIVE_TAIL;
        }
    }
    rs_free(job.residual);
    rs_free(job.variance);
    rs_free(scratch);
    rs_grid_free(&grid);
    free_points(&pts);
    return st;
}
