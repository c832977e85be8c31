/* The reference path equals an independent O(V * F) evaluation of the filter's equations. */
#include "mesh_shapes.h"
#include "rsmooth.h"
#include "test_util.h"

#include <stdbool.h>
#include <stdint.h>
#include <string.h>

/* ---- the brute force: plain loops over every triangle, double precision ---------------------- */

typedef struct bf_stats {
    size_t facets;    /* triangles of non-zero area */
    size_t fallback;  /* mollified facets that fell back to the input normal */
    size_t unreached; /* vertices with no facet within reach */
    double mean_edge;
} bf_stats;

static int compare_u64(const void *a, const void *b) {
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

static double dot(const double *a, const double *b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross(const double *a, const double *b, double *out) {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static double dist2(const double *a, const double *b) {
    double d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
    return dot(d, d);
}

/* Mean length of unique undirected edges (pairs of distinct indices). */
static double bf_mean_edge(const double *xyz, const uint32_t *idx, size_t tc) {
    uint64_t *keys = malloc((3 * tc + 1) * sizeof *keys);
    CHECK(keys);
    size_t n = 0;
    for (size_t t = 0; t < tc; t++)
        for (int e = 0; e < 3; e++) {
            uint64_t a = idx[3 * t + e], b = idx[3 * t + (e + 1) % 3];
            if (a != b)
                keys[n++] = a < b ? a << 32 | b : b << 32 | a;
        }
    qsort(keys, n, sizeof *keys, compare_u64);
    double sum = 0;
    size_t unique = 0;
    for (size_t i = 0; i < n; i++)
        if (i == 0 || keys[i] != keys[i - 1]) {
            sum += sqrt(dist2(xyz + 3 * (keys[i] >> 32), xyz + 3 * (keys[i] & 0xffffffffu)));
            unique++;
        }
    free(keys);
    return unique ? sum / (double)unique : 0;
}

/* Bilateral normal filter, every facet against every other: `rounds` times n_r <- normalise(sum
 * a_q exp(-|c_q - c_r|^2 / 2 s^2) exp(-|n_q - n_r|^2 / 2 t^2) n_q) over |c_q - c_r| <= reach. */
static void bf_bilateral(const double *cen, const double *nrm, const double *area, size_t fc,
                         double reach, double s, double t, int rounds, double *out) {
    double *prev = malloc((3 * fc + 1) * sizeof *prev);
    CHECK(prev);
    memcpy(prev, nrm, 3 * fc * sizeof *prev);
    for (int round = 0; round < rounds; round++) {
        for (size_t r = 0; r < fc; r++) {
            double acc[3] = {0, 0, 0};
            for (size_t q = 0; q < fc; q++) {
                double d2 = dist2(cen + 3 * q, cen + 3 * r);
                if (!(d2 <= reach * reach))
                    continue;
                double dn2 = dist2(prev + 3 * q, prev + 3 * r);
                double w = area[q] * exp(-d2 / (2 * s * s)) * exp(-dn2 / (2 * t * t));
                for (int k = 0; k < 3; k++)
                    acc[k] += w * prev[3 * q + k];
            }
            double len = sqrt(dot(acc, acc));
            for (int k = 0; k < 3; k++)
                out[3 * r + k] = len > 0 ? acc[k] / len : prev[3 * r + k];
        }
        memcpy(prev, out, 3 * fc * sizeof *prev);
    }
    free(prev);
}

/* Black et al. 1998's weights at squared distance x2 in units of sigma_g^2, as rsmooth.h
 * defines them. */
static double bf_influence(int influence, double x2) {
    double x = sqrt(x2);
    switch (influence) {
    case RSMOOTH_INFLUENCE_TUKEY: {
        double c = sqrt(5.0);
        return x < c ? pow(1 - (x / c) * (x / c), 2) : 0;
    }
    case RSMOOTH_INFLUENCE_LORENTZIAN:
        return 1 / (1 + x * x);
    case RSMOOTH_INFLUENCE_HUBER:
        return x <= 1 ? 1 : 1 / x;
    }
    return exp(-x * x / 2);
}

/* |C_q - C_p|^2: C_q the mean colour of the triangle with corners tri[0..2], C_p = cp. */
static double bf_color_dist2(const float *colors, const uint32_t *tri, const float *cp) {
    double s = 0;
    for (int k = 0; k < 3; k++) {
        double mean =
            ((double)colors[3 * (size_t)tri[0] + k] + (double)colors[3 * (size_t)tri[1] + k] +
             (double)colors[3 * (size_t)tri[2] + k]) /
            3;
        s += (mean - cp[k]) * (mean - cp[k]);
    }
    return s;
}

static void brute_force(const double *xyz, size_t vc, const uint32_t *idx, size_t tc,
                        const rsmooth_params *prm, double *out, double *k_out, double *conf_out,
                        unsigned char *unreached, bf_stats *st) {
    memset(st, 0, sizeof *st);
    /* facet data */
    uint32_t *tri = malloc((tc + 1) * sizeof *tri);
    double *cen = malloc((3 * tc + 1) * sizeof *cen), *nrm = malloc((3 * tc + 1) * sizeof *nrm);
    double *area = malloc((tc + 1) * sizeof *area), *mnrm = malloc((3 * tc + 1) * sizeof *mnrm);
    double *moll = malloc(3 * vc * sizeof *moll);
    CHECK(tri && cen && nrm && area && mnrm && moll);
    size_t fc = 0;
    for (size_t t = 0; t < tc; t++) {
        const double *a = xyz + 3 * (size_t)idx[3 * t], *b = xyz + 3 * (size_t)idx[3 * t + 1],
                     *c = xyz + 3 * (size_t)idx[3 * t + 2];
        double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        double e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        double n[3];
        cross(e1, e2, n);
        double len = sqrt(dot(n, n));
        if (!(len > 0))
            continue;
        tri[fc] = (uint32_t)t;
        for (int k = 0; k < 3; k++) {
            cen[3 * fc + k] = (a[k] + b[k] + c[k]) / 3;
            nrm[3 * fc + k] = n[k] / len;
        }
        area[fc] = len / 2;
        fc++;
    }
    st->facets = fc;
    st->mean_edge = bf_mean_edge(xyz, idx, tc);

    double unit = prm->absolute ? 1 : st->mean_edge;
    double sf = prm->sigma_f * unit;
    double sg = isinf(prm->sigma_g) ? INFINITY : prm->sigma_g * unit;
    double sm = sf / 2;
    double reach = prm->cutoff * sf;
    double mreach = (prm->mollify_cutoff > 0 ? prm->mollify_cutoff : prm->cutoff) * sf;

    /* mollification: sum c a f_m / sum a f_m over facets within mreach */
    for (size_t v = 0; v < vc; v++) {
        const double *p = xyz + 3 * v;
        double acc[3] = {0, 0, 0}, ws = 0;
        size_t count = 0, last = 0;
        for (size_t q = 0; q < fc; q++) {
            double d2 = dist2(cen + 3 * q, p);
            if (!(d2 <= mreach * mreach))
                continue;
            double w = area[q] * exp(-d2 / (2 * sm * sm));
            for (int k = 0; k < 3; k++)
                acc[k] += w * cen[3 * q + k];
            ws += w;
            count++;
            last = q;
        }
        for (int k = 0; k < 3; k++)
            moll[3 * v + k] = ws > 0 ? acc[k] / ws : p[k];
        /* One facet within reach: the average is that centroid exactly (c w / w may round). So an
         * isolated triangle's mollified copy collapses to exactly one point and falls back to the
         * input normal, as the equations say. */
        if (count == 1)
            memcpy(moll + 3 * v, cen + 3 * last, 3 * sizeof(double));
    }
    /* normals of the mollified facets, or the input ones */
    for (size_t q = 0; q < fc; q++) {
        const uint32_t *t = idx + 3 * (size_t)tri[q];
        const double *m0 = moll + 3 * (size_t)t[0], *m1 = moll + 3 * (size_t)t[1],
                     *m2 = moll + 3 * (size_t)t[2];
        double e1[3] = {m1[0] - m0[0], m1[1] - m0[1], m1[2] - m0[2]};
        double e2[3] = {m2[0] - m0[0], m2[1] - m0[1], m2[2] - m0[2]};
        double n[3];
        cross(e1, e2, n);
        double len = sqrt(dot(n, n));
        int degenerate = !(len > 1e-6 * sqrt(dot(e1, e1)) * sqrt(dot(e2, e2)));
        if (!prm->mollify || degenerate) {
            memcpy(mnrm + 3 * q, nrm + 3 * q, 3 * sizeof(double));
            st->fallback += prm->mollify != 0;
        } else {
            for (int k = 0; k < 3; k++)
                mnrm[3 * q + k] = n[k] / len;
        }
    }
    const int centroid = prm->predictor == RSMOOTH_PREDICT_CENTROID; /* predict c_q, not Pi_q(p) */
    if (prm->mollify && !centroid && prm->normal_filter == RSMOOTH_NORMALS_BILATERAL)
        bf_bilateral(cen, nrm, area, fc, prm->cutoff * prm->normal_sigma_s * unit,
                     prm->normal_sigma_s * unit, prm->normal_sigma_n, prm->normal_iterations, mnrm);
    const int influence = isinf(sg) ? RSMOOTH_INFLUENCE_GAUSSIAN : prm->influence;
    /* colour factor exp(-|C_q - C_p|^2 / 2 sigma_c^2), C_q the mean of q's corners' colours:
     * with the Gaussian its exponent joins the influence's (and its shift) */
    const float *col = prm->colors && !isinf(prm->sigma_c) ? prm->colors : NULL;
    const double sc = prm->sigma_c;
    /* robust estimate, with the influence exponents shifted by their smallest (log-sum-exp) so no
     * weight underflows: p' = p + sum w t n / sum w is unchanged by the shift. */
    for (size_t v = 0; v < vc; v++) {
        const double *p = xyz + 3 * v;
        double e_min = INFINITY;
        size_t count = 0;
        for (size_t q = 0; q < fc; q++) {
            double d2 = dist2(cen + 3 * q, p);
            if (!(d2 <= reach * reach))
                continue;
            double d[3] = {cen[3 * q] - p[0], cen[3 * q + 1] - p[1], cen[3 * q + 2] - p[2]};
            double t = dot(mnrm + 3 * q, d);
            double r2 = centroid ? d2 : t * t; /* |prediction - p|^2 */
            double e = isinf(sg) ? 0 : r2 / (2 * sg * sg);
            double ec =
                col ? bf_color_dist2(col, idx + 3 * (size_t)tri[q], col + 3 * v) / (2 * sc * sc)
                    : 0;
            /* the Gaussian's exponent is shifted with the colour's, the other functions' colour
             * exponent alone (nothing without colour), over the facets they give weight */
            if (influence == RSMOOTH_INFLUENCE_GAUSSIAN)
                e_min = fmin(e_min, e + ec);
            else if (bf_influence(influence, r2 / (sg * sg)) > 0)
                e_min = fmin(e_min, ec);
            count++;
        }
        if (!(e_min < INFINITY)) /* no facet with weight (Tukey): nothing to shift */
            e_min = 0;
        double acc[3] = {0, 0, 0}, ws = 0, kf = 0;
        for (size_t q = 0; count && q < fc; q++) {
            double d2 = dist2(cen + 3 * q, p);
            if (!(d2 <= reach * reach))
                continue;
            double d[3] = {cen[3 * q] - p[0], cen[3 * q + 1] - p[1], cen[3 * q + 2] - p[2]};
            const double *n = mnrm + 3 * q;
            double t = dot(n, d);
            double r2 = centroid ? d2 : t * t;
            double e = isinf(sg) ? 0 : r2 / (2 * sg * sg);
            double ec =
                col ? bf_color_dist2(col, idx + 3 * (size_t)tri[q], col + 3 * v) / (2 * sc * sc)
                    : 0;
            double af = area[q] * exp(-d2 / (2 * sf * sf));
            double w = af * (influence == RSMOOTH_INFLUENCE_GAUSSIAN
                                 ? exp(-(e + ec - e_min))
                                 : bf_influence(influence, r2 / (sg * sg)) * exp(-(ec - e_min)));
            for (int k = 0; k < 3; k++)
                acc[k] += w * (centroid ? d[k] : t * n[k]);
            ws += w;
            kf += af;
        }
        if (count == 0 || !(ws > 0)) {
            memcpy(out + 3 * v, p, 3 * sizeof(double));
            k_out[v] = 0;
            conf_out[v] = 0;
            unreached[v] = 1;
            st->unreached++;
            continue;
        }
        unreached[v] = 0;
        for (int k = 0; k < 3; k++)
            out[3 * v + k] = p[k] + acc[k] / ws;
        k_out[v] = ws * exp(-e_min);
        conf_out[v] = fmin(1.0, k_out[v] / kf);
    }
    free(tri);
    free(cen);
    free(nrm);
    free(area);
    free(mnrm);
    free(moll);
}

/* The filter run prm->passes times, each pass by brute_force from the previous positions with the
 * input's sigmas; with pass_confidence, vertices that were confident keep their previous result.
 * `st` describes the input. */
static void brute_force_passes(const double *xyz, size_t vc, const uint32_t *idx, size_t tc,
                               const rsmooth_params *prm, double *out, double *k_out,
                               double *conf_out, unsigned char *unreached, bf_stats *st) {
    if (prm->passes <= 1) {
        brute_force(xyz, vc, idx, tc, prm, out, k_out, conf_out, unreached, st);
        return;
    }
    double unit = prm->absolute ? 1 : bf_mean_edge(xyz, idx, tc);
    rsmooth_params p = *prm;
    p.sigma_f *= unit;
    p.sigma_g *= unit;
    p.normal_sigma_s *= unit;
    p.absolute = 1;
    p.passes = 1;
    double *cur = malloc(3 * vc * sizeof *cur), *pk = malloc(vc * sizeof *pk);
    double *pc = malloc(vc * sizeof *pc);
    CHECK(cur && pk && pc);
    memcpy(cur, xyz, 3 * vc * sizeof *cur);
    bf_stats first;
    for (int pass = 0; pass < prm->passes; pass++) {
        brute_force(cur, vc, idx, tc, &p, out, k_out, conf_out, unreached, st);
        if (pass == 0)
            first = *st;
        for (size_t v = 0; pass > 0 && p.pass_confidence > 0 && v < vc; v++)
            if (pc[v] >= p.pass_confidence) {
                memcpy(out + 3 * v, cur + 3 * v, 3 * sizeof *out);
                k_out[v] = pk[v];
                conf_out[v] = pc[v];
            }
        memcpy(cur, out, 3 * vc * sizeof *cur);
        memcpy(pk, k_out, vc * sizeof *pk);
        memcpy(pc, conf_out, vc * sizeof *pc);
    }
    first.unreached = st->unreached;
    *st = first;
    free(cur);
    free(pk);
    free(pc);
}

/* ---- comparison ------------------------------------------------------------------------------ */

static double rel_float_dev(float got, double want) {
    double diff = fabs((double)got - want);
    if (diff <= 1e-37) /* below float's normal range: both underflowed */
        return 0;
    return diff / fmax(fabs(want), 1e-300);
}

/* Soft check: prints and counts a failure, so every case reports before the program fails. */
static int g_failures;

#define EXPECT_LE(name, a, b)                                                                      \
    do {                                                                                           \
        if (!((a) <= (b))) {                                                                       \
            fprintf(stderr, "%s:%d: %s: FAILED %s = %.9g > %s = %.9g\n", __FILE__, __LINE__, name, \
                    #a, (double)(a), #b, (double)(b));                                             \
            g_failures++;                                                                          \
        }                                                                                          \
    } while (0)

static void run_case(const char *name, const double *xyz, size_t vc, const uint32_t *idx, size_t tc,
                     const rsmooth_params *prm, size_t expect_unreached_min) {
    double *ref = malloc(3 * vc * sizeof *ref), *bf = malloc(3 * vc * sizeof *bf);
    double *bk = malloc(vc * sizeof *bk), *bc = malloc(vc * sizeof *bc);
    float *rk = malloc(vc * sizeof *rk), *rc = malloc(vc * sizeof *rc);
    unsigned char *unreached = malloc(vc);
    CHECK(ref && bf && bk && bc && rk && rc && unreached);
    rsmooth_report report;
    rsmooth_report_init(&report);
    rsmooth_error err;
    /* the paper's equation exactly, as the brute force computes it: the fold guard, which pulls
     * back triangles the filter turns over, is tested in test_do_no_harm */
    rsmooth_params unguarded = *prm;
    unguarded.guard = 0;
    rsmooth_status s = rsmooth_smooth(NULL, RSMOOTH_FLOAT64, xyz, vc, idx, tc, &unguarded, ref,
                                      OUTPUTS(rk, rc, &report), &err);
    if (s != RSMOOTH_OK)
        fprintf(stderr, "%s: %s\n", name, err.message);
    CHECK_STATUS(s, RSMOOTH_OK);
    bf_stats st;
    brute_force_passes(xyz, vc, idx, tc, prm, bf, bk, bc, unreached, &st);

    double max_dev = 0, max_move = 0, max_k = 0, max_c = 0;
    size_t worst = 0, kept_exactly = 0;
    for (size_t v = 0; v < vc; v++) {
        double dev = sqrt(dist2(ref + 3 * v, bf + 3 * v));
        if (dev > max_dev) {
            max_dev = dev;
            worst = v;
        }
        max_move = fmax(max_move, sqrt(dist2(bf + 3 * v, xyz + 3 * v)));
        max_k = fmax(max_k, rel_float_dev(rk[v], bk[v]));
        max_c = fmax(max_c, rel_float_dev(rc[v], bc[v]));
        if (unreached[v]) /* no facet within reach: kept bit for bit, weight and confidence 0 */
            kept_exactly += memcmp(ref + 3 * v, xyz + 3 * v, 3 * sizeof(double)) == 0 &&
                            rc[v] == 0.0f && rk[v] == 0.0f;
    }
    double mel = st.mean_edge;
    printf("%-38s V %5zu T %5zu facets %5zu fallback normals %2zu unreached %zu (kept %zu) | max "
           "move %.3g edges, max |ref - brute| %.3g edges, k rel %.3g, confidence rel %.3g\n",
           name, vc, tc, st.facets, st.fallback, st.unreached, kept_exactly, max_move / mel,
           max_dev / mel, max_k, max_c);
    if (max_dev / mel > 1e-9)
        printf("    worst vertex %zu at (%.9g, %.9g, %.9g): reference (%.9g, %.9g, %.9g), brute "
               "force (%.9g, %.9g, %.9g), confidence %.6g vs %.6g\n",
               worst, xyz[3 * worst], xyz[3 * worst + 1], xyz[3 * worst + 2], ref[3 * worst],
               ref[3 * worst + 1], ref[3 * worst + 2], bf[3 * worst], bf[3 * worst + 1],
               bf[3 * worst + 2], rc[worst], bc[worst]);
    CHECK_EQ_INT(report.facet_count, st.facets);
    CHECK_NEAR(report.mean_edge_length, mel, 1e-12 * mel);
    CHECK(max_move > 0); /* the case does something */
    CHECK(st.unreached >= expect_unreached_min);
    EXPECT_LE(name, max_dev / mel, 1e-9);
    EXPECT_LE(name, max_k, 1e-6);
    EXPECT_LE(name, max_c, 1e-6);
    EXPECT_LE(name, st.unreached, kept_exactly);
    free(ref);
    free(bf);
    free(bk);
    free(bc);
    free(rk);
    free(rc);
    free(unreached);
}

/* ---- the meshes ------------------------------------------------------------------------------ */

static uint64_t next_u64(uint64_t *s) {
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

static double uniform(uint64_t *s, double lo, double hi) {
    return lo + (hi - lo) * ((double)(next_u64(s) >> 11) * 0x1.0p-53);
}

/* A soup: clustered random triangles sharing some vertices, duplicated vertices, zero-area
 * triangles (repeated index, coincident duplicates, exactly collinear), isolated small triangles
 * (whose mollified copies collapse to a point: the fallback normal), unreferenced vertices near the
 * soup and far from everything. */
static void make_soup(shape_mesh *m, uint64_t seed, size_t isolated) {
    const size_t base_tris = 500, dups = 30, extra_near = 25, extra_far = 4;
    size_t vmax = 3 * base_tris + 3 * isolated + dups + 3 + extra_near + extra_far;
    size_t tmax = base_tris + isolated + 2 * dups + 3 + 5;
    m->xyz = malloc(3 * vmax * sizeof(double));
    m->indices = malloc(3 * tmax * sizeof(uint32_t));
    CHECK(m->xyz && m->indices);
    uint64_t s = seed;
    size_t v = 0, t = 0;
#define ADD_V(x, y, z)                                                                             \
    (m->xyz[3 * v] = (x), m->xyz[3 * v + 1] = (y), m->xyz[3 * v + 2] = (z), (uint32_t)v++)
#define ADD_T(a, b, c)                                                                             \
    (m->indices[3 * t] = (a), m->indices[3 * t + 1] = (b), m->indices[3 * t + 2] = (c), t++)
    for (size_t i = 0; i < base_tris; i++) {
        double c[3];
        for (int k = 0; k < 3; k++)
            c[k] = uniform(&s, 0, 3);
        uint32_t corner[3];
        for (int j = 0; j < 3; j++) {
            if (v > 10 && next_u64(&s) % 4 == 0) { /* share an existing vertex */
                corner[j] = (uint32_t)(next_u64(&s) % v);
            } else {
                corner[j] = ADD_V(c[0] + uniform(&s, -0.3, 0.3), c[1] + uniform(&s, -0.3, 0.3),
                                  c[2] + uniform(&s, -0.3, 0.3));
            }
        }
        if (corner[0] == corner[1] || corner[1] == corner[2] || corner[0] == corner[2])
            corner[2] = ADD_V(c[0], c[1], c[2] + 0.2);
        ADD_T(corner[0], corner[1], corner[2]);
    }
    for (size_t i = 0; i < isolated; i++) {
        double x = 40 + 15 * (double)i;
        uint32_t a = ADD_V(x, 0, 0), b = ADD_V(x + 0.3, 0.05, 0), c = ADD_V(x, 0.3, 0.1);
        ADD_T(a, b, c);
    }
    for (size_t i = 0; i < dups; i++) { /* duplicates used by real and by zero-area triangles */
        uint32_t src = (uint32_t)(next_u64(&s) % 300);
        uint32_t d = ADD_V(m->xyz[3 * src], m->xyz[3 * src + 1], m->xyz[3 * src + 2]);
        uint32_t w = (uint32_t)(next_u64(&s) % 300);
        if (i % 2)
            ADD_T(src, d, w); /* src and d coincide: zero area */
        if (w != src)
            ADD_T(d, w, (uint32_t)((w + 1) % 300)); /* a real triangle through the duplicate */
    }
    {
        uint32_t a = ADD_V(1, 1, 1), b = ADD_V(1.25, 1.25, 1.25), c = ADD_V(1.5, 1.5, 1.5);
        ADD_T(a, b, c); /* exactly collinear */
        ADD_T(a, a, b); /* repeated index */
        ADD_T(c, c, c);
    }
    for (size_t i = 0; i < extra_near; i++)
        ADD_V(uniform(&s, 0, 3), uniform(&s, 0, 3), uniform(&s, 0, 3));
    for (size_t i = 0; i < extra_far; i++)
        ADD_V(1000 + 100 * (double)i, -500, 7);
#undef ADD_V
#undef ADD_T
    m->vertex_count = v;
    m->triangle_count = t;
}

/* Colours for the colour factor: the cube's six faces each their own (by the axis and sign of a
 * vertex's largest coordinate), the sphere's two halves (z < 0, z >= 0) and the soups' vertices
 * random. RGB in [0, 1]. */
static float *make_colors(const shape_mesh *m, int kind, uint64_t seed) {
    static const float face[6][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1},
                                     {1, 1, 0}, {0, 1, 1}, {1, 0, 1}};
    float *c = malloc(3 * m->vertex_count * sizeof *c);
    CHECK(c);
    uint64_t s = seed;
    for (size_t v = 0; v < m->vertex_count; v++) {
        const double *p = m->xyz + 3 * v;
        const float *rgb = NULL;
        float random[3];
        if (kind == 0) {
            int axis = 0;
            for (int k = 1; k < 3; k++)
                if (fabs(p[k]) > fabs(p[axis]))
                    axis = k;
            rgb = face[axis + (p[axis] < 0 ? 3 : 0)];
        } else if (kind == 1) {
            rgb = face[p[2] < 0 ? 0 : 2];
        } else {
            for (int k = 0; k < 3; k++)
                random[k] = (float)uniform(&s, 0, 1);
            rgb = random;
        }
        memcpy(c + 3 * v, rgb, 3 * sizeof *c);
    }
    return c;
}

/* A flat noisy plane coloured in two halves with a sharp colour edge: vertices with x <= the
 * middle red, the others blue. With a narrow sigma_c, the vertices along the edge (x = the middle)
 * are pulled by their own side only: with the centroid predictor and no influence weight (a plain
 * Gaussian average of centroids), they move away from the edge, towards -x, where without colours
 * they stay on it to the noise's asymmetry. With sigma_c huge the result equals the colourless
 * one (to 1e-12). Both against the brute force too. */
static void colour_edge_plane(void) {
    const int n = 24;
    shape_mesh m;
    CHECK(shape_plane(&m, n, n, 1.0) == 0);
    CHECK(shape_add_normal_noise(&m, 0.2, 99) == 0);
    const double middle = n / 2;
    float *col = malloc(3 * m.vertex_count * sizeof *col);
    CHECK(col);
    for (size_t v = 0; v < m.vertex_count; v++) {
        bool red = m.xyz[3 * v] <= middle;
        col[3 * v] = red ? 1.0f : 0.0f;
        col[3 * v + 1] = 0.0f;
        col[3 * v + 2] = red ? 0.0f : 1.0f;
    }
    rsmooth_params p;
    rsmooth_params_init(&p);
    p.sigma_f = 1.0;
    p.predictor = RSMOOTH_PREDICT_CENTROID;
    p.sigma_g = INFINITY;
    size_t nv = m.vertex_count;
    double *plain = malloc(3 * nv * sizeof *plain), *narrow = malloc(3 * nv * sizeof *narrow);
    double *wide = malloc(3 * nv * sizeof *wide);
    CHECK(plain && narrow && wide);
    rsmooth_error err;
    CHECK_STATUS(rsmooth_smooth(NULL, RSMOOTH_FLOAT64, m.xyz, nv, m.indices, m.triangle_count, &p,
                                plain, NULL, &err),
                 RSMOOTH_OK);
    p.colors = col;
    p.sigma_c = 0.05;
    run_case("colour-edge plane, centroid, sigma_c 0.05", m.xyz, nv, m.indices, m.triangle_count,
             &p, 0);
    CHECK_STATUS(rsmooth_smooth(NULL, RSMOOTH_FLOAT64, m.xyz, nv, m.indices, m.triangle_count, &p,
                                narrow, NULL, &err),
                 RSMOOTH_OK);
    p.sigma_c = 1e8;
    CHECK_STATUS(rsmooth_smooth(NULL, RSMOOTH_FLOAT64, m.xyz, nv, m.indices, m.triangle_count, &p,
                                wide, NULL, &err),
                 RSMOOTH_OK);
    /* the edge's vertices away from the plane's border (2 sigma_f = reach of 2.3 units) */
    double plain_dx = 0, narrow_dx = -INFINITY, wide_dev = 0;
    size_t edge = 0;
    for (size_t v = 0; v < nv; v++) {
        for (int k = 0; k < 3; k++)
            wide_dev = fmax(wide_dev, fabs(wide[3 * v + k] - plain[3 * v + k]));
        double y = m.xyz[3 * v + 1];
        if (m.xyz[3 * v] != middle || y < 3 || y > n - 3)
            continue;
        edge++;
        plain_dx = fmax(plain_dx, fabs(plain[3 * v] - middle));
        narrow_dx = fmax(narrow_dx, narrow[3 * v] - middle); /* the least pull towards -x */
    }
    printf("colour-edge plane: %zu edge vertices: |dx| <= %.3g without colour, dx <= %.3g with "
           "sigma_c 0.05 (pulled to their side); sigma_c 1e8 vs no colour: %.3g\n",
           edge, plain_dx, narrow_dx, wide_dev);
    CHECK(edge == (size_t)(n - 5));
    CHECK_LE(plain_dx, 0.05);
    CHECK_LE(narrow_dx, -0.2);
    CHECK_LE(wide_dev, 1e-12);
    /* the projection predictor with the Gaussian influence too, each against the brute force */
    rsmooth_params_init(&p);
    p.colors = col;
    p.sigma_c = 0.05;
    run_case("colour-edge plane, defaults, sigma_c 0.05", m.xyz, nv, m.indices, m.triangle_count,
             &p, 0);
    p.sigma_c = 1e8;
    run_case("colour-edge plane, defaults, sigma_c 1e8", m.xyz, nv, m.indices, m.triangle_count, &p,
             0);
    free(plain);
    free(narrow);
    free(wide);
    free(col);
    shape_free(&m);
}

int main(void) {
    rsmooth_params def;
    rsmooth_params_init(&def);

    enum { MESHES = 4 };
    shape_mesh meshes[MESHES];
    memset(meshes, 0, sizeof meshes);
    CHECK(shape_cube(&meshes[0], 12, 2.0) == 0);
    CHECK(shape_add_normal_noise(&meshes[0], 0.3, 12345) == 0);
    CHECK(shape_sphere(&meshes[1], 3, 1.0) == 0);
    CHECK(shape_add_normal_noise(&meshes[1], 0.25, 777) == 0);
    make_soup(&meshes[2], 4242, 0);
    make_soup(&meshes[3], 4242, 6);
    const char *names[MESHES] = {"noisy cube", "noisy sphere", "soup", "soup + isolated triangles"};
    const size_t unreached[MESHES] = {0, 0, 4, 4};
    const double absolute_sigma_f[MESHES] = {0.25, 0.25, 0.4, 0.4};

    for (int i = 0; i < MESHES; i++) {
        const shape_mesh *m = &meshes[i];
        float *colors = make_colors(m, i < 2 ? i : 2, 5150 + (uint64_t)i);
        char name[96];
        for (int variant = 0; variant < 26; variant++) {
            rsmooth_params p = def;
            const char *what = "";
            switch (variant) {
            case 0:
                what = "defaults";
                break;
            case 1:
                what = "mollify off";
                p.mollify = 0;
                break;
            case 2:
                what = "sigma_g inf";
                p.sigma_g = INFINITY;
                break;
            case 3:
                what = "sigma_g inf, mollify off";
                p.sigma_g = INFINITY;
                p.mollify = 0;
                break;
            case 4:
                what = "absolute";
                p.absolute = 1;
                p.sigma_f = absolute_sigma_f[i];
                p.sigma_g = 0.06;
                break;
            case 5:
                what = "cutoff 3.5, mollify 1.2";
                p.sigma_f = 1.5;
                p.sigma_g = 0.7;
                p.cutoff = 3.5;
                p.mollify_cutoff = 1.2;
                break;
            case 6:
                what = "cutoff 1, mollify 0.5";
                p.cutoff = 1.0;
                p.mollify_cutoff = 0.5;
                break;
            case 7: /* so narrow that every influence weight underflows: the rescue path */
                what = "sigma_g 0.004 (underflow)";
                p.sigma_g = 0.004;
                break;
            case 8: /* the paper's isotropic Gaussian baseline */
                what = "centroid predictor, sigma_g inf";
                p.predictor = RSMOOTH_PREDICT_CENTROID;
                p.sigma_g = INFINITY;
                break;
            case 9:
                what = "centroid predictor, sigma_g 0.7";
                p.predictor = RSMOOTH_PREDICT_CENTROID;
                p.sigma_g = 0.7;
                break;
            /* beyond the paper */
            case 10:
                what = "bilateral normals, 1 round";
                p.normal_filter = RSMOOTH_NORMALS_BILATERAL;
                p.normal_iterations = 1;
                break;
            case 11:
                what = "bilateral normals, 4 rounds, wide";
                p.normal_filter = RSMOOTH_NORMALS_BILATERAL;
                p.normal_iterations = 4;
                p.normal_sigma_s = 1.6; /* reach beyond the robust pass's */
                p.normal_sigma_n = 0.5;
                p.sigma_f = 1.2;
                break;
            case 12:
                what = "Tukey";
                p.influence = RSMOOTH_INFLUENCE_TUKEY;
                p.sigma_g = 0.3;
                break;
            case 13:
                what = "Lorentzian";
                p.influence = RSMOOTH_INFLUENCE_LORENTZIAN;
                break;
            case 14:
                what = "Huber, centroid predictor";
                p.influence = RSMOOTH_INFLUENCE_HUBER;
                p.predictor = RSMOOTH_PREDICT_CENTROID;
                break;
            case 15:
                what = "Tukey, sigma_g 0.004 (all rejected)";
                p.influence = RSMOOTH_INFLUENCE_TUKEY;
                p.sigma_g = 0.004;
                break;
            case 16:
                what = "3 passes";
                p.passes = 3;
                break;
            case 17:
                what = "0.5's best preset (bilateral, 3 passes)";
                rsmooth_params_init_best(&p);
                p.vertex_updates = 0; /* the stage has its own oracle (test_normal_update) */
                p.passes = 3;
                break;
            case 18:
                what = "4 passes where confidence < 0.6, Huber";
                p.passes = 4;
                p.pass_confidence = 0.6;
                p.influence = RSMOOTH_INFLUENCE_HUBER;
                p.normal_filter = RSMOOTH_NORMALS_BILATERAL;
                break;
            /* the colour factor */
            case 19:
                what = "colour, sigma_c 0.1";
                p.colors = colors;
                p.sigma_c = 0.1;
                break;
            case 20:
                what = "colour, sigma_c 1 (wide)";
                p.colors = colors;
                p.sigma_c = 1;
                break;
            case 21: /* every weight underflows: the rescue with colour exponents */
                what = "colour 0.03, sigma_g 0.004 (underflow)";
                p.colors = colors;
                p.sigma_c = 0.03;
                p.sigma_g = 0.004;
                break;
            case 22:
                what = "colour 0.2, Tukey";
                p.colors = colors;
                p.sigma_c = 0.2;
                p.influence = RSMOOTH_INFLUENCE_TUKEY;
                p.sigma_g = 0.3;
                break;
            case 23:
                what = "colour 0.05, Lorentzian, centroid, sg inf";
                p.colors = colors;
                p.sigma_c = 0.05;
                p.influence = RSMOOTH_INFLUENCE_LORENTZIAN;
                p.predictor = RSMOOTH_PREDICT_CENTROID;
                p.sigma_g = INFINITY; /* the Gaussian then, with the colour exponent alone */
                break;
            case 24:
                what = "colour 0.1, 0.5's best preset";
                rsmooth_params_init_best(&p);
                p.vertex_updates = 0;
                p.passes = 3;
                p.colors = colors;
                p.sigma_c = 0.1;
                break;
            case 25: /* colour factors below double's range: the colour rescue */
                what = "colour 0.002, Huber (underflow)";
                p.colors = colors;
                p.sigma_c = 0.002;
                p.influence = RSMOOTH_INFLUENCE_HUBER;
                break;
            }
            snprintf(name, sizeof name, "%s, %s", names[i], what);
            run_case(name, m->xyz, m->vertex_count, m->indices, m->triangle_count, &p,
                     unreached[i]);
        }
        free(colors);
    }
    colour_edge_plane();
    for (int i = 0; i < MESHES; i++)
        shape_free(&meshes[i]);
    if (g_failures) {
        fprintf(stderr, "reference_bruteforce: %d comparisons FAILED\n", g_failures);
        return 1;
    }
    printf("reference_bruteforce: the reference path equals the brute force\n");
    return 0;
}
