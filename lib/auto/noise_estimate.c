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
 *     the surface on v's side; the screening in 4 then kept vertices with large noise, +15% at
 * 0.7).
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
 *     biasing the rest. sigma starts from the median s^2 and is refined ROUNDS times as 1.4826 x
 * the median standardised |residual| of the kept vertices (a normal's median |value| is 0.6745
 *     sigma).
 *
 * Calibration (tests/test_noise_estimate.c; the benchmark models' Original.obj with generated
 * noise, 3 seeds each): Gaussian noise of 0.1 to 0.7 mean edge lengths along the normals reads
 * within 5% of the truth on planes, spheres, cubes and capped cylinders of ~10k vertices and on
 * Fandisk, Block, Bunny, SharpSphere and Twelve; a 602-vertex cube, most of whose vertices are near
 * an edge, within 15%. KAPPA = 1.25 was chosen there (1 and 1.5 do nearly as well but for the
 * coarse cube); no other factor is fitted. Choosing, per vertex, the best of the whole disc and
 * half discs on either side of a crease instead of screening read 5-10% high at low noise: the
 * choice depends on the neighbours' noise.
 *
 * 5. Unit (lib/auto/noise_estimate.h): the level is in mean edge lengths of the CLEAN mesh, which
 * noise lengthens (E|e'|^2 = |e|^2 + 2 tr Cov per edge). Each sampled vertex's mesh edges are
 *    measured in its frame: the tangential part as it is, the normal part from the quadric (less
 *    its own noise, s^2 (a_u - a_0)^T M^-1 (a_u - a_0)): the normal noise drops out. The
 *    tangential noise (6) is then taken out of the mean square (4 t^2 per edge, t per axis), the
 *    mean scaled as the root mean square, and the ratio to the same edges' raw mean scales the
 *    whole mesh's mean edge.
 * 6. Tangential noise: the umbrella offset of a vertex from its ring's centroid, in the tangent
 *    plane, over (1 + 1/k): t^2 = median / (2 ln 2) (a chi-square of 2 degrees). A clean mesh's own
 *    irregularity reads 0.03-0.15 edges here (a floor, not subtracted).
 * 7. Level: the rms of the screened standardised residuals within TRIM robust sigmas (the median
 *    alone reads random-direction noise's normal part 33% low: g cos(theta) is heavy-tailed).
 * 8. Impulsive (outlier_share): each sample's quadric is refitted without the neighbours beyond 2.5
 *    robust sigmas of the fit (twice); in impulsive noise the refit follows the exact neighbours,
 *    so a displaced sample stands far beyond the refit's inliers' scatter. The noise reads
 *    impulsive when over IMPULSIVE_SHARE of the samples lie beyond OUTLIER_Z (6) such scatters
 *    (the threshold fitted with leave-one-mesh-out cross-validation on the accuracy table) and the
 *    tangential level is below half the displaced vertices' level (random-direction noise on a very
 *    regular mesh passes the first test). The level and the share displaced then come from a
 *    two-normal mixture fitted by EM to the least-squares residuals (impulsive_mixture).
 * Apart from IMPULSIVE_SHARE no constant was fitted in 5-8 (TRIM 5, MIX_SCREEN 2, ROBUST_CUT 2.5,
 * OUTLIER_Z 6, IMPULSIVE_TANGENTIAL 0.5 chosen, not fitted); the noise_accuracy study measured the
 * table (docs/accuracy.md; the study: docs/maintainers/studies.md).
 *
 * Exact duplicate positions are welded first (a triangle soup's corners), so a vertex's copies are
 * not its neighbours. Up to MAX_SAMPLES vertices are used, at a fixed stride; each sample depends
 * on the positions alone and the medians on the samples alone, so the result is the same on every
 * run and for any thread count. */
#include "auto/noise_estimate.h"
#include "auto/eigen3.h"
#include "core/parts.h"
#include "core/shape_correlation.h"
#include "core/spatial.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define RADIUS 2.5 /* fit radius, mean edge lengths */
#define SLAB 2.5   /* half-height of the cylinder around the neighbours' centroid */
#define MARGIN                                                                                     \
    1.0               /* how far v's frame centre may lie from v, beyond which a neighbour of      \
                       * the cylinder is missed: > 2 sigma even at noise 0.5 */
#define FACING (-0.5) /* neighbours whose normal is > 120 degrees from v's are left out */
#define MIN_POINTS 10 /* fewest points a quadric (6 coefficients) is fitted to */
#define KAPPA                                                                                      \
    1.25         /* vertices whose fit's residual variance exceeds KAPPA sigma^2 are left          \
                  * out (their neighbourhood is no quadric: an edge, a corner) */
#define ROUNDS 3 /* refinements of sigma and of the screening */
#define MAX_SAMPLES                                                                                \
    6000                 /* vertices used at most (50000 before: 4x the time on a 36k-vertex mesh  \
                          * for the same table) */
#define SAMPLE_GRAIN 256 /* samples per chunk below which a thread does not pay */
#define MAD_TO_SIGMA 1.482602218505602 /* 1 / Phi^-1(3/4) */
#define TERMS 6

static const char where[] = "rsmooth_estimate_noise";

/* ---- small linear algebra ------------------------------------------------------------------- */

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

static void free_points(point_set *points) {
    rs_free(points->xyz);
    rs_free(points->normal);
    memset(points, 0, sizeof *points);
}

/* The vertices some non-degenerate triangle uses, exact duplicates merged (their area-weighted
 * normals summed; copies whose normals cancel, both sides of a sheet, are dropped). false when out
 * of memory. */
static bool build_points(const double *xyz, size_t vertex_count, const uint32_t *indices,
                         size_t triangle_count, point_set *out, uint32_t *point_of) {
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
    rs_add_area_normals(xyz, indices, triangle_count, NULL, normal);
    size_t used = 0;
    for (size_t v = 0; v < vertex_count; v++)
        point_of[v] = UINT32_MAX;
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
        point_of[order[i].v] = (uint32_t)(count - 1);
    }
    size_t kept = 0;
    rs_free(order);
    uint32_t *renumber = rs_alloc_array(count ? count : 1, sizeof *renumber);
    if (!renumber) {
        rs_free(normal);
        free_points(out);
        return false;
    }
    for (size_t i = 0; i < count; i++) {
        const double *n = out->normal + 3 * i;
        double len = sqrt(rs_dot3(n, n));
        renumber[i] = UINT32_MAX;
        if (!(len > 0))
            continue;
        renumber[i] = (uint32_t)kept;
        for (int k = 0; k < 3; k++) {
            out->xyz[3 * kept + k] = out->xyz[3 * i + k];
            out->normal[3 * kept + k] = n[k] / len;
        }
        kept++;
    }
    out->count = kept;
    for (size_t v = 0; v < vertex_count; v++)
        if (point_of[v] != UINT32_MAX)
            point_of[v] = renumber[point_of[v]];
    rs_free(normal);
    rs_free(renumber);
    return true;
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

/* The mesh's edges between points, both ways, as lists per point (start has count + 1 entries),
 * duplicates removed; false when out of memory. point_of maps vertices to points (UINT32_MAX:
 * none). */
static bool build_rings(const uint32_t *indices, size_t triangle_count, const uint32_t *point_of,
                        size_t count, uint32_t **start_out, uint32_t **ring_out) {
    uint32_t *start = rs_calloc_array(count + 1, sizeof *start);
    uint32_t *ring = rs_alloc_array(triangle_count ? 6 * triangle_count : 1, sizeof *ring);
    if (!start || !ring) {
        rs_free(start);
        rs_free(ring);
        return false;
    }
    for (int pass = 0; pass < 2; pass++) {
        for (size_t t = 0; t < triangle_count; t++)
            for (int e = 0; e < 3; e++) {
                uint32_t a = point_of[indices[3 * t + e]],
                         b = point_of[indices[3 * t + (e + 1) % 3]];
                if (a == UINT32_MAX || b == UINT32_MAX || a == b)
                    continue;
                if (pass == 0) {
                    start[a + 1]++;
                    start[b + 1]++;
                } else {
                    ring[start[a]++] = b;
                    ring[start[b]++] = a;
                }
            }
        if (pass == 0)
            for (size_t i = 0; i < count; i++)
                start[i + 1] += start[i];
        else {
            for (size_t i = count; i > 0; i--)
                start[i] = start[i - 1];
            start[0] = 0;
        }
    }
    /* duplicates out (each edge comes once per triangle that has it), compacting in place */
    uint32_t kept = 0;
    for (size_t i = 0; i < count; i++) {
        uint32_t begin = start[i], end = start[i + 1];
        start[i] = kept;
        for (uint32_t j = begin; j < end; j++) {
            bool seen = false;
            for (uint32_t k = start[i]; k < kept && !seen; k++)
                seen = ring[k] == ring[j];
            if (!seen)
                ring[kept++] = ring[j];
        }
    }
    start[count] = kept;
    *start_out = start;
    *ring_out = ring;
    return true;
}

/* ---- per-sample residuals -------------------------------------------------------------------- */

/* What a sample's mesh edges say about the clean mesh's edge lengths and the tangential noise
 * (header comment, 5 and 6). */
typedef struct edge_sums {
    double raw;      /* sum of the edges' lengths as they are */
    double raw2;     /* ... of their squares */
    double clean;    /* sum of the lengths with the normal noise taken out */
    double clean2;   /* ... of their squares */
    double umbrella; /* |tangential offset from the ring's centroid|^2 / (1 + 1/k); NAN: none */
    uint32_t edges;
} edge_sums;

typedef struct sample_job {
    const point_set *points;
    const rs_grid *grid;
    const uint32_t *ring_start, *ring; /* the mesh's edges, per point */
    edge_sums *edges;                  /* per sample */
    double unit;                       /* mean edge length */
    size_t sample_count;
    double *residual; /* per sample: standardised |residual|, mesh units, or NAN (no fit) */
    double *variance; /* per sample: the fit's residual variance s^2, mesh units squared */
    double *robust;   /* per sample: |residual| of the robust refit (robust_residual) */
    double *rscale;   /* per sample: the refit's inliers' rms residual (NAN: no refit) */
    double *rshare;   /* per sample: the share of the points the refit kept */
    bool failed[64];  /* per chunk: out of memory */
} sample_job;

/* A sample's neighbours, offsets from it in mesh units (grown as needed, one per thread). */
typedef struct workspace {
    size_t capacity;
    double *d; /* 3 per neighbour */
    double *c; /* 3 per cylinder point: x, y (mean edge lengths), z (mesh units) */
    double *e; /* per cylinder point: |residual| (scratch) */
} workspace;

static bool reserve(workspace *w, size_t n) {
    if (n <= w->capacity)
        return true;
    size_t cap = w->capacity ? 2 * w->capacity : 256;
    while (cap < n)
        cap *= 2;
    double *d = rs_realloc_array(w->d, cap, 3 * sizeof *d);
    if (d)
        w->d = d;
    double *c = d ? rs_realloc_array(w->c, cap, 3 * sizeof *c) : NULL;
    if (c)
        w->c = c;
    double *e = c ? rs_realloc_array(w->e, cap, sizeof *e) : NULL;
    if (!e)
        return false;
    w->e = e;
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
    rs_symmetric_eigen3(cov, values, axes);
    return true;
}

/* The k-th smallest of a[0 .. n) (k < n), reordering them (Hoare's selection). */
static double select_kth(double *a, size_t n, size_t k) {
    size_t lo = 0, hi = n - 1;
    while (lo < hi) {
        double pivot = a[lo + (hi - lo) / 2];
        size_t i = lo, j = hi;
        while (i <= j) {
            while (a[i] < pivot)
                i++;
            while (a[j] > pivot)
                j--;
            if (i <= j) {
                double t = a[i];
                a[i] = a[j];
                a[j] = t;
                i++;
                if (j == 0)
                    break;
                j--;
            }
        }
        if (k <= j)
            hi = j;
        else if (k >= i)
            lo = i;
        else
            break;
    }
    return a[k];
}

/* The quadric's terms at (x, y) into row, and its height there for coefficients beta (NULL: 0). */
static double quadric_at(double x, double y, const double *beta, double row[TERMS]) {
    row[0] = 1;
    row[1] = x;
    row[2] = y;
    row[3] = x * x;
    row[4] = x * y;
    row[5] = y * y;
    double f = 0;
    for (int r = 0; beta && r < TERMS; r++)
        f += row[r] * beta[r];
    return f;
}

/* The prediction error at v of a robust refit: the cylinder's points (w->c, count of them) whose
 * residual from the fit beta exceeds ROBUST_CUT robust sigmas (1.4826 x their median |residual|)
 * are left out and the quadric refitted, ROBUST_ROUNDS times; |b0| / sqrt(1 + (M^-1)_00), mesh
 * units, or NAN when too few points are left. In impulsive noise most points sit exactly on the
 * clean surface: the refit follows them and leaves the exact vertices a residual near zero, where
 * a least-squares fit is pulled by the displaced neighbours. */
#define ROBUST_CUT 2.5
#define ROBUST_ROUNDS 2
static double robust_residual(workspace *w, size_t count, const double beta_ls[TERMS], double unit,
                              double *scale_out, double *share_out) {
    double beta[TERMS], result = NAN;
    *scale_out = NAN;
    *share_out = NAN;
    memcpy(beta, beta_ls, sizeof beta);
    for (int round = 0; round < ROBUST_ROUNDS; round++) {
        for (size_t j = 0; j < count; j++) {
            const double *c = w->c + 3 * j;
            double row[TERMS];
            w->e[j] = fabs(c[2] - quadric_at(c[0], c[1], beta, row));
        }
        double cut = ROBUST_CUT * MAD_TO_SIGMA * select_kth(w->e, count, count / 2);
        cut = cut > 1e-9 * unit ? cut : 1e-9 * unit;
        double m[TERMS][TERMS] = {{0}}, b[TERMS] = {0};
        size_t kept = 0;
        for (size_t j = 0; j < count; j++) {
            const double *c = w->c + 3 * j;
            double row[TERMS];
            if (!(fabs(c[2] - quadric_at(c[0], c[1], beta, row)) <= cut))
                continue;
            for (int r = 0; r < TERMS; r++) {
                b[r] += row[r] * c[2];
                for (int q = 0; q <= r; q++)
                    m[r][q] += row[r] * row[q];
            }
            kept++;
        }
        if (kept < MIN_POINTS)
            break;
        for (int r = 0; r < TERMS; r++)
            for (int q = r + 1; q < TERMS; q++)
                m[r][q] = m[q][r];
        double l[TERMS][TERMS], inv[TERMS], y[TERMS];
        if (!cholesky6(m, l, inv))
            break;
        forward6(l, inv, b, 0, y);
        backward6(l, inv, y, beta);
        result = fabs(beta[0]) / sqrt(1 + inverse_diagonal(l, inv, 0));
        *share_out = (double)kept / (double)count;
        if (round == ROBUST_ROUNDS - 1) { /* the inliers' scatter about the refit */
            double ss = 0;
            for (size_t j = 0; j < count; j++) {
                const double *c = w->c + 3 * j;
                double row[TERMS];
                double e = c[2] - quadric_at(c[0], c[1], beta, row);
                if (fabs(e) <= cut)
                    ss += e * e;
            }
            *scale_out = sqrt(ss / (double)(kept - TERMS));
        }
    }
    return result;
}

/* The standardised |residual| of point v and its fit's residual variance (mesh units); false when
 * no fit is possible (too few neighbours). *failed when out of memory. */
static bool sample_residual(const sample_job *job, size_t v, workspace *w, bool *failed,
                            double *residual, double *variance, double *robust, double *rscale,
                            double *rshare, edge_sums *es) {
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
        w->c[3 * count] = x;
        w->c[3 * count + 1] = y;
        w->c[3 * count + 2] = z;
        double row[TERMS];
        quadric_at(x, y, NULL, row);
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
    *robust = robust_residual(w, count, beta, unit, rscale, rshare);
    if (isnan(*robust))
        *robust = *residual;
    else
        *robust /= sqrt(1 + g2);
    /* the mesh edges at v: in the frame, their tangential part as it is and their normal part from
     * the fit (less the fit's own noise, s2 (a_u - a_0)^T M^-1 (a_u - a_0)) */
    const double *p = job->points->xyz + 3 * v;
    double cx = 0, cy = 0;
    for (uint32_t j = job->ring_start[v]; j < job->ring_start[v + 1]; j++) {
        double d[3];
        rs_sub3(job->points->xyz + 3 * (size_t)job->ring[j], p, d);
        double x = rs_dot3(d, t1), yt = rs_dot3(d, t2), len2 = rs_dot3(d, d);
        double xe = x / unit, ye = yt / unit;
        const double a[TERMS] = {0, xe, ye, xe * xe, xe * ye, ye * ye};
        double dz = 0, ya[TERMS], q = 0;
        for (int r = 1; r < TERMS; r++)
            dz += beta[r] * a[r];
        forward6(l, inv, a, 1, ya);
        for (int r = 1; r < TERMS; r++)
            q += ya[r] * ya[r];
        double clean2 = x * x + yt * yt + dz * dz - s2 * q;
        es->raw += sqrt(len2);
        es->raw2 += len2;
        es->clean += sqrt(clean2 > 0 ? clean2 : 0);
        es->clean2 += clean2;
        es->edges++;
        cx += x;
        cy += yt;
    }
    uint32_t k = es->edges;
    es->umbrella =
        k >= 3 ? (cx * cx + cy * cy) / ((double)k * (double)k) / (1 + 1 / (double)k) : NAN;
    return true;
}

static void sample_range(void *ctx, size_t begin, size_t end, size_t chunk) {
    sample_job *job = ctx;
    workspace w = {0, NULL, NULL, NULL};
    bool failed = false;
    size_t count = job->points->count;
    for (size_t s = begin; s < end && !failed; s++) {
        /* a fixed stride over the points in cell order (all of them when there are few enough) */
        size_t v = (size_t)((double)s * (double)count / (double)job->sample_count);
        v = v < count ? v : count - 1;
        memset(&job->edges[s], 0, sizeof job->edges[s]);
        if (!sample_residual(job, v, &w, &failed, &job->residual[s], &job->variance[s],
                             &job->robust[s], &job->rscale[s], &job->rshare[s], &job->edges[s]))
            job->residual[s] = job->variance[s] = job->robust[s] = NAN;
    }
    job->failed[chunk] = failed;
    rs_free(w.d);
    rs_free(w.c);
    rs_free(w.e);
}

/* ---- the robust scale ------------------------------------------------------------------------ */

/* Median of values[0 .. n) (n > 0), reordering them (by selection: linear time). */
static double median(double *values, size_t n) {
    double upper = select_kth(values, n, n / 2);
    if (n % 2)
        return upper;
    double lower = values[0]; /* the largest below the n/2-th */
    for (size_t i = 1; i < n / 2; i++)
        lower = values[i] > lower ? values[i] : lower;
    return 0.5 * (lower + upper);
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

/* Impulsive or Gaussian: the share of the samples whose robust residual (robust_residual) exceeds
 * OUTLIER_Z times the rms residual of the points its refit kept (the sample's neighbours that fit
 * the surface). In impulsive noise most vertices sit exactly on the clean surface: around an exact
 * vertex the refit follows the exact neighbours, whose scatter is then the clean surface's own
 * departure from a quadric, far below the displaced vertices' offsets, so about the displaced
 * share of the samples lies beyond it (a few percent and more at a share of 0.05). Gaussian noise,
 * along the normals or in random directions, moves the neighbours as much as the sample: its
 * studentised residual exceeds OUTLIER_Z for at most 0.5% of the samples (creases and corners
 * included: their refit keeps one side and the sample sits on it). IMPULSIVE_SHARE was fitted on
 * the noise_accuracy study's rows with cross-validation leaving each of its 13 meshes out (the
 * geometric mean of the largest Gaussian share and the smallest impulsive one above it, fitted on
 * the other 12: 0.0055-0.0063; no Gaussian case of the left-out mesh read impulsive), and rounded.
 */
#define OUTLIER_Z 6.0
#define IMPULSIVE_SHARE 0.006
#define IMPULSIVE_TANGENTIAL 0.5 /* chosen, not fitted (as before, commit 19d703f) */

static double outlier_share(const double *robust, const double *rscale, size_t n) {
    size_t far = 0, counted = 0;
    for (size_t s = 0; s < n; s++)
        if (rscale[s] > 0) {
            counted++;
            far += robust[s] > OUTLIER_Z * rscale[s];
        }
    return counted ? (double)far / (double)counted : 0;
}

/* The rms of the screened residuals within TRIM robust sigmas: the standard deviation itself, not
 * a Gaussian's from its median (noise whose normal component is not Gaussian, as a random
 * direction's, reads right). */
#define TRIM 5.0
static double trimmed_rms(const double *residual, const double *variance, size_t n, double sigma) {
    double sum = 0;
    size_t kept = 0;
    for (size_t s = 0; s < n; s++)
        if (variance[s] <= KAPPA * sigma * sigma && fabs(residual[s]) <= TRIM * sigma) {
            sum += residual[s] * residual[s];
            kept++;
        }
    return kept ? sqrt(sum / (double)kept) : sigma;
}

/* Impulsive noise: the screened residuals (fits whose residual variance is at most MIX_SCREEN
 * times the median: away from edges, with no regard to the sample's own noise) as a mixture of
 * two zero-mean normals, (1 - w) N(0, a^2) + w N(0, b^2), by EM: the exact vertices, whose residual
 * is the prediction's error, and the displaced ones. scratch holds n doubles. */
#define MIX_SCREEN 2.0
#define MIX_ROUNDS 60
static void impulsive_mixture(const double *residual, const double *variance, size_t n,
                              double *scratch, double *w_out, double *a_out, double *b_out) {
    memcpy(scratch, variance, n * sizeof *scratch);
    double cut = MIX_SCREEN * median(scratch, n);
    size_t m = 0;
    for (size_t s = 0; s < n; s++)
        if (variance[s] <= cut)
            scratch[m++] = residual[s] * residual[s];
    *w_out = 1;
    *a_out = *b_out = 0;
    if (m < 20)
        return;
    /* start: a from the median, b and w from what lies beyond 3 a */
    double sum = 0;
    size_t far = 0;
    double *sq = scratch + 0; /* squared residuals, m of them */
    double a2 = 0, b2 = 0, w = 0;
    {
        double *tmp = rs_alloc_array(m, sizeof *tmp);
        if (!tmp)
            return;
        memcpy(tmp, sq, m * sizeof *tmp);
        a2 = median(tmp, m) / 0.45493642311957283; /* chi-square 1: median 0.4549 */
        rs_free(tmp);
    }
    for (size_t s = 0; s < m; s++)
        if (sq[s] > 9 * a2) {
            sum += sq[s];
            far++;
        }
    w = far ? (double)far / (double)m : 0.01;
    b2 = far ? sum / (double)far : 9 * a2;
    if (!(a2 > 0)) {
        *w_out = 1;
        return;
    }
    for (int round = 0; round < MIX_ROUNDS; round++) {
        double sw = 0, sw2 = 0, sa2 = 0;
        for (size_t s = 0; s < m; s++) {
            /* responsibilities, with the exponent's difference only (no overflow) */
            double la = -0.5 * sq[s] / a2 - 0.5 * log(a2) + log(1 - w);
            double lb = -0.5 * sq[s] / b2 - 0.5 * log(b2) + log(w);
            double rb = 1 / (1 + exp(la - lb));
            sw += rb;
            sw2 += rb * sq[s];
            sa2 += (1 - rb) * sq[s];
        }
        double wn = sw / (double)m;
        if (!(wn > 1e-6) || !(wn < 1 - 1e-6))
            break;
        w = wn;
        b2 = sw2 / sw;
        a2 = sa2 / ((double)m - sw);
        if (!(a2 > 0) || !(b2 > 0))
            break;
    }
    if (b2 < a2) { /* the components are named by size */
        double t = a2;
        a2 = b2;
        b2 = t;
        w = 1 - w;
    }
    *w_out = w;
    *a_out = sqrt(a2);
    *b_out = sqrt(b2);
}

/* The figures from the samples (valid of them, compacted), into out. */
static void summarise(const sample_job *job, size_t valid, double unit, double scale,
                      double *scratch, rs_noise_details *out) {
    double sigma_mad = robust_sigma(job->residual, job->variance, valid, scratch);
    double sigma = trimmed_rms(job->residual, job->variance, valid, sigma_mad);
    /* tangential noise: the umbrella offsets' median, a chi-square of 2 degrees (median 2 ln 2) */
    size_t k = 0;
    for (size_t s = 0; s < valid; s++)
        if (!isnan(job->edges[s].umbrella))
            scratch[k++] = job->edges[s].umbrella;
    double tangential2 = k ? median(scratch, k) / (2 * 0.6931471805599453) : NAN;
    /* the clean mesh's mean edge */
    double raw = 0, clean = 0, clean2 = 0, edges = 0;
    for (size_t s = 0; s < valid; s++) {
        raw += job->edges[s].raw;
        clean += job->edges[s].clean;
        clean2 += job->edges[s].clean2;
        edges += job->edges[s].edges;
    }
    double ratio = 1;
    if (edges > 0 && raw > 0) {
        double m1n = clean / edges, m2n = clean2 / edges;
        double t2 = isnan(tangential2) ? 0 : tangential2;
        double m2 = m2n - 4 * t2;
        /* the tangential noise out of the mean square; the mean from it as the noisy edges'
         * mean is from their mean square */
        double m1 = m2n > 0 && m2 > 0 ? m1n * sqrt(m2 / m2n) : m1n;
        ratio = m1 / (raw / edges);
        if (!(ratio > 0.05) || !(ratio <= 1.5))
            ratio = ratio > 1.5 ? 1.5 : 0.05; /* not a mesh of edges with noise: bounded */
    }
    double clean_unit = unit * ratio;
    out->mean_edge_clean = clean_unit / scale;
    out->level = sigma / clean_unit;
    out->overall_level = sigma / clean_unit;
    out->tangential_level = isnan(tangential2) ? NAN : sqrt(tangential2) / clean_unit;
    out->tail_share = outlier_share(job->robust, job->rscale, valid);
    out->samples = valid;
    out->mean_edge_noisy = unit / scale;
    out->impulsive = out->tail_share > IMPULSIVE_SHARE;
    if (out->impulsive) { /* the level and share displaced from the mixture, when it separates */
        double w, a, b;
        impulsive_mixture(job->residual, job->variance, valid, scratch, &w, &a, &b);
        double displaced = b > a && w < 1 ? sqrt(b * b - a * a) / clean_unit : out->level;
        /* random-direction noise on a very regular mesh (no surface roughness to hide it) also
         * puts samples beyond OUTLIER_Z: its tangential noise is of the normal noise's size,
         * impulsive noise along the normals has none */
        out->impulsive = !(out->tangential_level >= IMPULSIVE_TANGENTIAL * displaced);
        if (out->impulsive && b > a && w < 1) {
            out->level = displaced;
            out->impulsive_fraction = w;
        }
    }
}

rsmooth_status rs_estimate_noise(rsmooth_scalar scalar, const void *positions, size_t vertex_count,
                                 const uint32_t *indices, size_t triangle_count, double *out_noise,
                                 rsmooth_error *error) {
    rs_error_clear(error);
    if (!out_noise)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "out_noise is NULL");
    rs_noise_details details;
    rsmooth_status st = rs_estimate_noise_details(scalar, positions, vertex_count, indices,
                                                  triangle_count, &details, error, where);
    if (st == RSMOOTH_OK)
        *out_noise = details.level;
    return st;
}

/* One estimate's state, shared by its steps. */
typedef struct estimate_run {
    const uint32_t *indices;
    size_t vertex_count, triangle_count;
    double scale;             /* internal units per caller unit (scale.c) */
    double unit;              /* the noisy mesh's mean edge length, internal units */
    double shape_correlation; /* core/shape_correlation.h */
    uint32_t *point_of; /* per vertex: its point (UINT32_MAX: none), until the rings are built */
    point_set pts;
    rs_grid grid;
    bool grid_built;
    uint32_t *ring_start, *ring; /* the mesh's edges, per point */
    sample_job job;
    double *scratch; /* per sample */
    rsmooth_error *error;
    const char *caller;
} estimate_run;

static void free_estimate(estimate_run *e) {
    rs_free(e->point_of);
    rs_free(e->job.residual);
    rs_free(e->job.variance);
    rs_free(e->job.robust);
    rs_free(e->job.rscale);
    rs_free(e->job.rshare);
    rs_free(e->job.edges);
    rs_free(e->ring_start);
    rs_free(e->ring);
    rs_free(e->scratch);
    if (e->grid_built)
        rs_grid_free(&e->grid);
    free_points(&e->pts);
}

/* The mean edge length (e->unit; not above 0 when the mesh has no edge, and then nothing else)
 * and the points, from the positions in internal units. */
static rsmooth_status read_points(estimate_run *e, rsmooth_scalar scalar, const void *positions) {
    size_t vertex_count = e->vertex_count;
    double *xyz = rs_alloc_array(vertex_count, 3 * sizeof *xyz);
    if (!xyz)
        return rs_fail(e->error, RSMOOTH_ERROR_OUT_OF_MEMORY, e->caller, "no memory for positions");
    rs_scale_positions(scalar, positions, vertex_count, e->scale, xyz);
    if (!rs_mean_edge_length(xyz, vertex_count, e->indices, e->triangle_count, &e->unit)) {
        rs_free(xyz);
        return rs_fail(e->error, RSMOOTH_ERROR_OUT_OF_MEMORY, e->caller, "no memory for edges");
    }
    if (!(e->unit > 0)) { /* no edge: no unit, nothing to measure */
        rs_free(xyz);
        return RSMOOTH_OK;
    }
    e->point_of = rs_alloc_array(vertex_count, sizeof *e->point_of);
    bool ok =
        e->point_of &&
        build_points(xyz, vertex_count, e->indices, e->triangle_count, &e->pts, e->point_of) &&
        rs_shape_correlation(xyz, vertex_count, e->indices, e->triangle_count,
                             &e->shape_correlation);
    rs_free(xyz);
    if (!ok)
        return rs_fail(e->error, RSMOOTH_ERROR_OUT_OF_MEMORY, e->caller,
                       "no memory for %zu vertex normals", vertex_count);
    return RSMOOTH_OK;
}

/* The points' grid, the points sorted into its order, and each point's ring of edges. */
static rsmooth_status order_points(estimate_run *e) {
    point_set *pts = &e->pts;
    rsmooth_status st = rs_grid_build(&e->grid, pts->xyz, pts->count,
                                      (hypot(RADIUS, SLAB) + MARGIN) * e->unit, e->error);
    if (st != RSMOOTH_OK)
        return st;
    e->grid_built = true;
    uint32_t *sorted_of = rs_alloc_array(pts->count, sizeof *sorted_of);
    bool ok = sorted_of && sort_points(pts, e->grid.facet_order);
    if (ok) { /* the vertices' points in the sorted order, then the rings */
        for (size_t i = 0; i < pts->count; i++)
            sorted_of[e->grid.facet_order[i]] = (uint32_t)i;
        for (size_t v = 0; v < e->vertex_count; v++)
            if (e->point_of[v] != UINT32_MAX)
                e->point_of[v] = sorted_of[e->point_of[v]];
        ok = build_rings(e->indices, e->triangle_count, e->point_of, pts->count, &e->ring_start,
                         &e->ring);
    }
    rs_free(sorted_of);
    rs_free(e->point_of);
    e->point_of = NULL;
    if (!ok)
        return rs_fail(e->error, RSMOOTH_ERROR_OUT_OF_MEMORY, e->caller, "no memory for %zu points",
                       pts->count);
    return RSMOOTH_OK;
}

/* Each sample's fit (sample_range), on all threads. */
static rsmooth_status take_samples(estimate_run *e) {
    sample_job *job = &e->job;
    memset(job, 0, sizeof *job);
    job->points = &e->pts;
    job->grid = &e->grid;
    job->ring_start = e->ring_start;
    job->ring = e->ring;
    job->unit = e->unit;
    job->sample_count = e->pts.count < MAX_SAMPLES ? e->pts.count : MAX_SAMPLES;
    job->residual = rs_alloc_array(job->sample_count, sizeof *job->residual);
    job->variance = rs_alloc_array(job->sample_count, sizeof *job->variance);
    job->robust = rs_alloc_array(job->sample_count, sizeof *job->robust);
    job->rscale = rs_alloc_array(job->sample_count, sizeof *job->rscale);
    job->rshare = rs_alloc_array(job->sample_count, sizeof *job->rshare);
    job->edges = rs_alloc_array(job->sample_count, sizeof *job->edges);
    e->scratch = rs_alloc_array(job->sample_count, sizeof *e->scratch);
    if (!job->residual || !job->variance || !job->robust || !job->rscale || !job->rshare ||
        !job->edges || !e->scratch)
        return rs_fail(e->error, RSMOOTH_ERROR_OUT_OF_MEMORY, e->caller,
                       "no memory for %zu samples", job->sample_count);
    rs_parallel_for(job->sample_count, SAMPLE_GRAIN, sample_range, job);
    rsmooth_status st = RSMOOTH_OK;
    for (size_t c = 0; c < sizeof job->failed / sizeof *job->failed; c++)
        if (job->failed[c])
            st = rs_fail(e->error, RSMOOTH_ERROR_OUT_OF_MEMORY, e->caller,
                         "no memory for a vertex's neighbours");
    return st;
}

/* The samples with a fit moved to the front, in sample order; their count. */
static size_t keep_fitted(sample_job *job) {
    size_t valid = 0;
    for (size_t s = 0; s < job->sample_count; s++)
        if (!isnan(job->residual[s])) {
            job->residual[valid] = job->residual[s];
            job->variance[valid] = job->variance[s];
            job->robust[valid] = job->robust[s];
            job->rscale[valid] = job->rscale[s];
            job->rshare[valid] = job->rshare[s];
            job->edges[valid++] = job->edges[s];
        }
    return valid;
}

/* The correlated noise (noise_scales.c) into out, in the clean mesh's mean edge lengths. */
static rsmooth_status correlated_part(estimate_run *e, rs_noise_details *out) {
    rsmooth_status st = rs_noise_scales(e->pts.xyz, e->pts.normal, e->pts.count, e->unit,
                                        e->ring_start, e->ring, &out->profile, e->error, e->caller);
    if (st != RSMOOTH_OK)
        return st;
    double noisy_per_clean = out->mean_edge_noisy / out->mean_edge_clean; /* level's unit */
    /* the rms over all vertices: for impulsive noise that of the displaced ones times the root
     * of their share */
    double white = out->impulsive ? out->level * sqrt(out->impulsive_fraction) : out->overall_level;
    double level_noisy = white / noisy_per_clean, length = 0, correlated = 0;
    rs_noise_correlated(&out->profile, level_noisy, &correlated, &length);
    out->correlated_level = correlated * noisy_per_clean;
    out->correlation_length = length * noisy_per_clean;
    return RSMOOTH_OK;
}

/* The estimate on a whole mesh (one part). */
static rsmooth_status estimate_mesh(rsmooth_scalar scalar, const void *positions,
                                    size_t vertex_count, const uint32_t *indices,
                                    size_t triangle_count, rs_noise_details *out,
                                    rsmooth_error *error, const char *caller) {
    double magnitude = 0;
    estimate_run e;
    memset(&e, 0, sizeof e);
    e.indices = indices;
    e.vertex_count = vertex_count;
    e.triangle_count = triangle_count;
    e.scale = 1;
    e.error = error;
    e.caller = caller;
    rsmooth_status st = rs_check_mesh_arrays(scalar, positions, vertex_count, indices,
                                             triangle_count, &magnitude, error, caller);
    if (st == RSMOOTH_OK) /* internal units (scale.c): the estimate is a ratio, unchanged */
        st = rs_mesh_scale(scalar, positions, indices, triangle_count, magnitude, &e.scale, error,
                           caller);
    if (st != RSMOOTH_OK)
        return st;
    memset(out, 0, sizeof *out);
    out->impulsive_fraction = 1;
    out->tangential_level = NAN;
    e.shape_correlation = 1;
    st = read_points(&e, scalar, positions);
    out->shape_correlation = e.shape_correlation;
    if (st == RSMOOTH_OK && e.unit > 0 && e.pts.count <= MIN_POINTS) {
        /* too few vertices for any fit: nothing measurable */
        out->mean_edge_noisy = out->mean_edge_clean = e.unit / e.scale;
    } else if (st == RSMOOTH_OK && e.unit > 0) {
        if ((st = order_points(&e)) == RSMOOTH_OK)
            st = take_samples(&e);
        if (st == RSMOOTH_OK) {
            size_t valid = keep_fitted(&e.job);
            out->mean_edge_noisy = out->mean_edge_clean = e.unit / e.scale;
            if (valid > 0)
                summarise(&e.job, valid, e.unit, e.scale, e.scratch, out);
            if (valid > 0)
                st = correlated_part(&e, out);
        }
    }
    free_estimate(&e);
    return st;
}

rsmooth_status rs_estimate_noise_details(rsmooth_scalar scalar, const void *positions,
                                         size_t vertex_count, const uint32_t *indices,
                                         size_t triangle_count, rs_noise_details *out,
                                         rsmooth_error *error, const char *caller) {
    rsmooth_status st = rs_check_mesh_arrays(scalar, positions, vertex_count, indices,
                                             triangle_count, NULL, error, caller);
    rs_parts parts;
    if (st == RSMOOTH_OK)
        st = rs_parts_find(&parts, scalar, positions, vertex_count, indices, triangle_count, error,
                           caller);
    if (st != RSMOOTH_OK)
        return st;
    if (parts.whole) {
        st = estimate_mesh(scalar, positions, vertex_count, indices, triangle_count, out, error,
                           caller);
    } else { /* the part that moves the most vertices, without outliers or other parts */
        rs_submesh sub;
        if (!rs_submesh_make(&sub, &parts, rs_parts_largest(&parts), scalar, positions,
                             vertex_count, indices, triangle_count, NULL)) {
            rs_parts_free(&parts);
            return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, caller, "no memory for a part");
        }
        st = estimate_mesh(scalar, sub.positions, sub.vertex_count, sub.indices, sub.triangle_count,
                           out, error, caller);
        rs_submesh_free(&sub);
    }
    if (st == RSMOOTH_OK) {
        out->parts = parts.count;
        out->outliers = parts.outliers;
    }
    rs_parts_free(&parts);
    return st;
}

bool rs_noise_reads_clean(const rs_noise_details *d) {
    if (!(d->level > 0))
        return true;
    if (d->impulsive && d->tail_share >= RS_CLEAR_IMPULSIVE_TAIL)
        return false; /* vertices thrown unmistakably: the rest's shape does not hide them */
    if (d->shape_correlation >= RS_CLEAN_SHAPE_CORRELATION)
        return true;
    double low = d->profile.low[0], floor = d->profile.low_floor[0];
    return !d->impulsive && isfinite(low) && isfinite(floor) && low <= RS_CLEAN_FLOOR * floor;
}
