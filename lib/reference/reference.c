/* The reference path: Jones, Durand & Desbrun 2003 in double precision on one thread, written to be
 * read beside the paper. Mollification (Sec. 3.2), then robust estimation (Eq. 3). It is the oracle
 * the OpenCL path is tested against and the fallback when no OpenCL device exists. */
#include "reference/reference.h"
#include "core/spatial.h"
#include "passes/passes.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

/* Progress: reported every PROGRESS_STEP vertices; mollification is about this share of the work.
 */
#define PROGRESS_STEP 4096
#define MOLLIFY_SHARE 0.45

/* The facets whose centroid lies within `reach` of p (distance <= reach), with squared distances.
 */
typedef struct neighbours {
    size_t count, capacity;
    uint32_t *facet;
    double *dist2;
} neighbours;

static bool gather(const rs_problem *pb, const rs_grid *grid, const double p[3], double reach,
                   neighbours *out) {
    out->count = 0;
    int32_t c[3];
    rs_grid_cell_of(grid, p, c);
    for (int dx = -1; dx <= 1; dx++)
        for (int dy = -1; dy <= 1; dy++)
            for (int dz = -1; dz <= 1; dz++) {
                int32_t cell = rs_grid_find(grid, c[0] + dx, c[1] + dy, c[2] + dz);
                if (cell < 0)
                    continue;
                for (uint32_t i = grid->cell_start[cell]; i < grid->cell_start[cell + 1]; i++) {
                    uint32_t q = grid->facet_order[i];
                    double d[3];
                    rs_sub3(pb->centroid + 3 * (size_t)q, p, d);
                    double d2 = rs_dot3(d, d);
                    if (d2 > reach * reach)
                        continue;
                    if (out->count == out->capacity) {
                        size_t cap = out->capacity ? 2 * out->capacity : 256;
                        uint32_t *f = rs_realloc_array(out->facet, cap, sizeof *f);
                        if (!f)
                            return false;
                        out->facet = f;
                        double *dd = rs_realloc_array(out->dist2, cap, sizeof *dd);
                        if (!dd)
                            return false;
                        out->dist2 = dd;
                        out->capacity = cap;
                    }
                    out->facet[out->count] = q;
                    out->dist2[out->count] = d2;
                    out->count++;
                }
            }
    return true;
}

/* Mollified position of p: sum c_q a_q f_m / sum a_q f_m, f_m of width sigma_m. */
static void mollify_vertex(const rs_problem *pb, const neighbours *nb, const double p[3],
                           double out[3]) {
    double wsum = 0, acc[3] = {0, 0, 0};
    for (size_t i = 0; i < nb->count; i++) {
        uint32_t q = nb->facet[i];
        double w = pb->area[q] * exp(-nb->dist2[i] / (2 * pb->sigma_m * pb->sigma_m));
        for (int k = 0; k < 3; k++)
            acc[k] += w * (pb->centroid[3 * (size_t)q + k] - p[k]);
        wsum += w;
    }
    for (int k = 0; k < 3; k++)
        out[k] = wsum > 0 ? p[k] + acc[k] / wsum : p[k];
}

/* Unit normal of the mollified facet, or the input normal if the mollified facet is degenerate. */
static void mollified_normal(const rs_problem *pb, const double *mollified, size_t q,
                             double out[3]) {
    const uint32_t *tri = pb->indices + 3 * (size_t)pb->facet_triangle[q];
    double e1[3], e2[3], n[3];
    rs_sub3(mollified + 3 * (size_t)tri[1], mollified + 3 * (size_t)tri[0], e1);
    rs_sub3(mollified + 3 * (size_t)tri[2], mollified + 3 * (size_t)tri[0], e2);
    rs_cross3(e1, e2, n);
    double len = sqrt(rs_dot3(n, n));
    if (!(len > RS_DEGENERATE_SINE * sqrt(rs_dot3(e1, e1) * rs_dot3(e2, e2))) ||
        !(len > RS_DEGENERATE_AREA_RATIO * 2 * pb->area[q])) {
        memcpy(out, pb->normal + 3 * q, 3 * sizeof(double));
        return;
    }
    for (int k = 0; k < 3; k++)
        out[k] = n[k] / len;
}

/* Bilateral filter on the facet normals (RSMOOTH_NORMALS_BILATERAL), normal_iterations rounds:
 * each facet's normal becomes the normalised sum of its neighbours' normals weighted by area, a
 * Gaussian of centroid distance and a Gaussian of normal difference, so normals across a crease
 * (far apart in direction) do not blend. Starts from the input normals; writes `normals`. */
static bool bilateral_normals(const rs_problem *pb, const rs_grid *grid, neighbours *nb,
                              double *normals) {
    size_t nf = pb->facet_count;
    double *prev = rs_alloc_array(nf, 3 * sizeof(double));
    if (!prev)
        return false;
    memcpy(prev, pb->normal, nf * 3 * sizeof(double));
    const double inv_2s2 = 1 / (2 * pb->normal_sigma_s * pb->normal_sigma_s);
    const double inv_2n2 = 1 / (2 * pb->normal_sigma_n * pb->normal_sigma_n);
    for (int round = 0; round < pb->normal_iterations; round++) {
        for (size_t r = 0; r < nf; r++) {
            if (!gather(pb, grid, pb->centroid + 3 * r, pb->normal_radius, nb)) {
                rs_free(prev);
                return false;
            }
            const double *nr = prev + 3 * r;
            double acc[3] = {0, 0, 0};
            for (size_t i = 0; i < nb->count; i++) {
                const double *nq = prev + 3 * (size_t)nb->facet[i];
                double dn[3];
                rs_sub3(nq, nr, dn);
                double w = pb->area[nb->facet[i]] * exp(-nb->dist2[i] * inv_2s2) *
                           exp(-rs_dot3(dn, dn) * inv_2n2);
                for (int k = 0; k < 3; k++)
                    acc[k] += w * nq[k];
            }
            double len = sqrt(rs_dot3(acc, acc));
            for (int k = 0; k < 3; k++)
                normals[3 * r + k] = len > 0 ? acc[k] / len : nr[k];
        }
        memcpy(prev, normals, nf * 3 * sizeof(double));
    }
    rs_free(prev);
    return true;
}

/* The robust weight g of a prediction at squared distance x2 (in units of sigma_g^2) for the
 * influence functions other than the paper's Gaussian (Black et al. 1998). */
static double influence_weight(int influence, double x2) {
    switch (influence) {
    case RSMOOTH_INFLUENCE_TUKEY: /* biweight, zero beyond c = sqrt(5) sigma_g */
        return x2 < 5 ? (1 - x2 / 5) * (1 - x2 / 5) : 0;
    case RSMOOTH_INFLUENCE_LORENTZIAN:
        return 1 / (1 + x2);
    case RSMOOTH_INFLUENCE_HUBER:
        return x2 <= 1 ? 1 : 1 / sqrt(x2);
    default:
        return exp(-x2 / 2);
    }
}

/* What facet q predicts for p, as a step from p: the projection Pi_q(p) - p = (n . d) n, with
 * d = c_q - p, or (centroid predictor) d itself. */
static void prediction_step(const rs_problem *pb, const double n[3], const double d[3],
                            double step[3]) {
    double t = pb->predict_centroid ? 1 : rs_dot3(n, d);
    for (int c = 0; c < 3; c++)
        step[c] = pb->predict_centroid ? d[c] : t * n[c];
}

/* 1 / (2 sigma_c^2) of the colour factor, finite however small sigma_c is (a zero colour
 * difference then still gives a zero exponent, not NaN). */
static double color_inv_2s2(const rs_problem *pb) {
    return fmin(1 / (2 * pb->sigma_c * pb->sigma_c), DBL_MAX);
}

/* The colour exponent |C_q - C_p|^2 / (2 sigma_c^2) of facet q for a vertex of colour `color`. */
static double color_exponent(const rs_problem *pb, uint32_t q, const float *color,
                             double inv_2sc2) {
    const double *cq = pb->facet_color + 3 * (size_t)q;
    double d[3] = {cq[0] - color[0], cq[1] - color[1], cq[2] - color[2]};
    return rs_dot3(d, d) * inv_2sc2;
}

/* Eq. 3 with an influence function other than the Gaussian: these never underflow (Lorentzian,
 * Huber) or are meant to reach zero (Tukey), so there is no rescue of their own; k(p) = 0 leaves
 * p in place. With colour, though, the colour factors can all underflow: then the sums are redone
 * with the colour exponents shifted by their smallest, as the Gaussian's rescue does. */
static void estimate_vertex_robust_norm(const rs_problem *pb, const neighbours *nb,
                                        const double *normals, const double p[3],
                                        const float *color, double disp[3], double *k_out,
                                        double *kf_out) {
    const double inv_2sf2 = 1 / (2 * pb->sigma_f * pb->sigma_f);
    const double inv_sg2 = 1 / (pb->sigma_g * pb->sigma_g);
    const double inv_2sc2 = color ? color_inv_2s2(pb) : 0;
    double k = 0, kf = 0, acc[3] = {0, 0, 0};
    double ec_min = INFINITY, shift = 0; /* the smallest colour exponent; the rescue's shift */
    for (int round = 0; round < 2; round++) {
        k = kf = 0;
        acc[0] = acc[1] = acc[2] = 0;
        for (size_t i = 0; i < nb->count; i++) {
            uint32_t q = nb->facet[i];
            double d[3], step[3];
            rs_sub3(pb->centroid + 3 * (size_t)q, p, d);
            prediction_step(pb, normals + 3 * (size_t)q, d, step);
            double af = pb->area[q] * exp(-nb->dist2[i] * inv_2sf2);
            double g = influence_weight(pb->influence, rs_dot3(step, step) * inv_sg2);
            double w = af * g;
            if (color) {
                double ec = color_exponent(pb, q, color, inv_2sc2);
                if (g > 0) /* the shift of the facets that have weight (Tukey rejects some) */
                    ec_min = fmin(ec_min, ec);
                w *= exp(shift - ec);
            }
            for (int c = 0; c < 3; c++)
                acc[c] += w * step[c];
            k += w;
            kf += af;
        }
        if (!color || round > 0 || !(kf > 0) || k > kf * RS_UNDERFLOW_RATIO || !(ec_min < INFINITY))
            break;
        shift = ec_min;
    }
    for (int c = 0; c < 3; c++)
        disp[c] = k > 0 ? acc[c] / k : 0;
    *k_out = k * exp(-shift);
    *kf_out = kf;
}

/* Robust estimate for p (Eq. 3). Writes the displacement p' - p, k(p) and sum a f. `color` is p's
 * colour when the colour factor is on (else NULL): its exponent adds to the influence's, so the
 * underflow rescue covers both. */
static void estimate_vertex(const rs_problem *pb, const neighbours *nb, const double *normals,
                            const double p[3], const float *color, double disp[3], double *k_out,
                            double *kf_out) {
    if (pb->influence != RSMOOTH_INFLUENCE_GAUSSIAN) {
        estimate_vertex_robust_norm(pb, nb, normals, p, color, disp, k_out, kf_out);
        return;
    }
    const double inv_2sf2 = 1 / (2 * pb->sigma_f * pb->sigma_f);
    const double inv_2sg2 = isinf(pb->sigma_g) ? 0 : 1 / (2 * pb->sigma_g * pb->sigma_g);
    const double inv_2sc2 = color ? color_inv_2s2(pb) : 0;
    double k = 0, kf = 0, acc[3] = {0, 0, 0};
    double e_min = INFINITY; /* smallest influence exponent, for the underflow rescue */
    for (size_t i = 0; i < nb->count; i++) {
        uint32_t q = nb->facet[i];
        const double *n = normals + 3 * (size_t)q;
        double d[3];
        rs_sub3(pb->centroid + 3 * (size_t)q, p, d);
        double step[3]; /* prediction - p: Pi_q(p) - p = t n, or c_q - p */
        prediction_step(pb, n, d, step);
        double af = pb->area[q] * exp(-nb->dist2[i] * inv_2sf2);
        double e = rs_dot3(step, step) * inv_2sg2;
        if (color)
            e += color_exponent(pb, q, color, inv_2sc2);
        double w = af * exp(-e);
        for (int c = 0; c < 3; c++)
            acc[c] += w * step[c];
        k += w;
        kf += af;
        e_min = fmin(e_min, e);
    }
    if (kf > 0 && !(k > kf * RS_UNDERFLOW_RATIO) && e_min < INFINITY) {
        /* Every influence weight is tiny: weigh by exp(e_min - e) instead, whose largest is 1.
         * (Exponents that overflowed, from an extreme sigma_c, leave k = 0: p stays.) */
        double ks = 0;
        acc[0] = acc[1] = acc[2] = 0;
        for (size_t i = 0; i < nb->count; i++) {
            uint32_t q = nb->facet[i];
            const double *n = normals + 3 * (size_t)q;
            double d[3];
            rs_sub3(pb->centroid + 3 * (size_t)q, p, d);
            double step[3];
            prediction_step(pb, n, d, step);
            /* (without colour, the very expression of the paper mode, unchanged) */
            double w = pb->area[q] * exp(-nb->dist2[i] * inv_2sf2) *
                       (color ? exp(e_min - (rs_dot3(step, step) * inv_2sg2 +
                                             color_exponent(pb, q, color, inv_2sc2)))
                              : exp(e_min - rs_dot3(step, step) * inv_2sg2));
            for (int c = 0; c < 3; c++)
                acc[c] += w * step[c];
            ks += w;
        }
        k = ks * exp(-e_min);
        for (int c = 0; c < 3; c++)
            disp[c] = ks > 0 ? acc[c] / ks : 0;
    } else {
        for (int c = 0; c < 3; c++)
            disp[c] = k > 0 ? acc[c] / k : 0;
    }
    *k_out = k;
    *kf_out = kf;
}

rsmooth_status rs_reference_solve(const rs_problem *problem, rsmooth_scalar scalar,
                                  void *out_positions, float *out_weight, float *out_confidence,
                                  double *out_normals, rsmooth_report *report, double t_start,
                                  rsmooth_error *error, const char *where) {
    const rs_problem pb = *problem; /* read-only view; the caller frees the problem */
    size_t vertex_count = pb.vertex_count;
    rsmooth_status st = RSMOOTH_OK;
    double t_facets = rs_now_ms();

    rs_grid grid;
    memset(&grid, 0, sizeof grid);
    neighbours nb = {0, 0, NULL, NULL};
    double *mollified = NULL, *normals = NULL;
    double t_grid = t_facets, t_mollify = t_facets, t_normals = t_facets;

    if (pb.facet_count == 0) { /* nothing carries weight: every vertex stays */
        rs_store_unmoved(&pb, pb.vertex_count, scalar, out_positions, out_weight, out_confidence);
        goto done;
    }

    /* one grid serves every reach: the robust pass's and the bilateral filter's */
    st =
        rs_grid_build(&grid, pb.centroid, pb.facet_count, fmax(pb.radius, pb.normal_radius), error);
    if (st != RSMOOTH_OK)
        goto fail;
    t_grid = rs_now_ms();

    normals = rs_alloc_array(pb.facet_count, 3 * sizeof(double));
    if (!normals)
        goto fail_memory;
    if (pb.bilateral) {
        if (!bilateral_normals(&pb, &grid, &nb, normals))
            goto fail_memory;
        t_mollify = rs_now_ms();
    } else if (pb.mollify) {
        mollified = rs_alloc_array(vertex_count, 3 * sizeof(double));
        if (!mollified)
            goto fail_memory;
        for (size_t v = 0; v < vertex_count; v++) {
            if (!gather(&pb, &grid, pb.xyz + 3 * v, pb.mollify_radius, &nb))
                goto fail_memory;
            mollify_vertex(&pb, &nb, pb.xyz + 3 * v, mollified + 3 * v);
            if (v % PROGRESS_STEP == 0 &&
                !rs_progress(&pb, MOLLIFY_SHARE * (double)v / (double)vertex_count))
                goto cancelled;
        }
        t_mollify = rs_now_ms();
        for (size_t q = 0; q < pb.facet_count; q++)
            mollified_normal(&pb, mollified, q, normals + 3 * q);
    } else {
        t_mollify = rs_now_ms();
        memcpy(normals, pb.normal, pb.facet_count * 3 * sizeof(double));
    }
    t_normals = rs_now_ms();
    if (out_normals)
        memcpy(out_normals, normals, pb.facet_count * 3 * sizeof(double));

    double robust_start = pb.mollify ? MOLLIFY_SHARE : 0;
    for (size_t v = 0; v < vertex_count; v++) {
        const double *p = pb.xyz + 3 * v;
        if (!gather(&pb, &grid, p, pb.radius, &nb))
            goto fail_memory;
        if (v % PROGRESS_STEP == 0 &&
            !rs_progress(&pb, robust_start + (1 - robust_start) * (double)v / (double)vertex_count))
            goto cancelled;
        double disp[3], k, kf;
        const float *color = pb.facet_color ? pb.colors + 3 * v : NULL;
        estimate_vertex(&pb, &nb, normals, p, color, disp, &k, &kf);
        double out[3] = {p[0] + disp[0], p[1] + disp[1], p[2] + disp[2]};
        rs_store_position(scalar, out_positions, v, out, 1 / pb.scale);
        if (out_weight)
            out_weight[v] = rs_weight_value(k, 1 / pb.scale);
        if (out_confidence)
            out_confidence[v] = kf > 0 ? (float)fmin(1.0, k / kf) : 0.0f;
    }

done:
    rs_progress(&pb, 1.0);
    if (report) {
        double now = rs_now_ms();
        rs_report_problem(report, &pb, grid.cell_count, "reference (double, 1 thread)");
        report->tiles = 1;
        report->ms_facets = t_facets - t_start;
        report->ms_grid = t_grid - t_facets;
        report->ms_mollify = t_mollify - t_grid;
        report->ms_normals = t_normals - t_mollify;
        report->ms_robust = now - t_normals;
        report->ms_total = now - t_start;
    }
    st = RSMOOTH_OK;
    goto cleanup;

cancelled:
    st = rs_cancelled(error, where);
    goto cleanup;
fail_memory:
    st = rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "out of memory");
fail:
cleanup:
    rs_free(nb.facet);
    rs_free(nb.dist2);
    rs_free(mollified);
    rs_free(normals);
    rs_grid_free(&grid);
    return st;
}

rsmooth_status rs_reference_pass(void *unused, rsmooth_scalar scalar, const void *positions,
                                 size_t vertex_count, const uint32_t *indices,
                                 size_t triangle_count, const rsmooth_params *params,
                                 void *out_positions, float *out_weight, float *out_confidence,
                                 rsmooth_report *report, rsmooth_error *error) {
    static const char where[] = "rsmooth_smooth";
    (void)unused;
    double t_start = rs_now_ms();
    rs_error_clear(error);
    rs_problem pb;
    rsmooth_status st = rs_problem_prepare(&pb, scalar, positions, vertex_count, indices,
                                           triangle_count, params, true, error, where);
    if (st != RSMOOTH_OK)
        return st;
    st = rs_reference_solve(&pb, scalar, out_positions, out_weight, out_confidence, NULL, report,
                            t_start, error, where);
    rs_problem_free(&pb);
    return st;
}
