/* Every supported scale gives the same answer. A noisy roof (a 20 x 20 grid folded along a sharp
 * crease, noise in every direction) is smoothed at spacings from 1e-300 to 1e148 in decades (the
 * supported range: coordinates up to 1e150 in magnitude, edges down to normal doubles), float64,
 * and from 1e-36 to 1e36 in float32. Oracles: the result at scale s equals s times the result at
 * scale 1 (the filter is scale-free), the result is closer to the noise-free roof than the input,
 * and the OpenCL path agrees with the reference path within 1e-3 mean edge lengths; the noise
 * estimate and point clouds are scale-free too. Also: no
 * non-finite value is ever returned with RSMOOTH_OK (a tetrahedron with one vertex at 1e39, float32
 * results beyond FLT_MAX, weights beyond float's range). */
#include "mesh_shapes.h"
#include "rsmooth.h"
#include "test_cl_util.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define GRID 20
#define SMALLEST_DECADE (-300)
#define LARGEST_DECADE 148 /* the roof spans 20 spacings: coordinates stay below 1e150 */

typedef struct roof {
    shape_mesh noisy;
} roof;

/* z = |x - 10| / 2 over [0, 20]^2, spacing 1, with Gaussian noise of 0.15 in x, y and z. */
static void make_roof(roof *r) {
    CHECK(shape_plane(&r->noisy, GRID, GRID, 1.0) == 0);
    uint64_t state = 12;
    for (size_t v = 0; v < r->noisy.vertex_count; v++) {
        double *p = r->noisy.xyz + 3 * v;
        p[2] = fabs(p[0] - GRID / 2.0) / 2;
        for (int k = 0; k < 3; k++)
            p[k] += 0.15 * shape_gaussian(&state);
    }
}

/* RMS distance of `xyz` (scale s) from the true roof's surface, in spacings: the nearer of the
 * roof's two planes (z -+ (x - 10) / 2 = 0). */
static double rms_error(const roof *r, const double *xyz, double s) {
    double sum = 0;
    for (size_t v = 0; v < r->noisy.vertex_count; v++) {
        double x = xyz[3 * v] / s - GRID / 2.0, z = xyz[3 * v + 2] / s;
        double d = fmin(fabs(z - x / 2), fabs(z + x / 2)) / sqrt(1.25);
        sum += d * d;
    }
    return sqrt(sum / (double)r->noisy.vertex_count);
}

typedef struct sweep {
    double worst_cl; /* largest OpenCL - reference difference, mean edge lengths */
    int worst_cl_decade;
    double worst_scaled; /* largest |result / s - result at 1|, spacings (reference path) */
    double worst_gain;   /* largest error after / error before */
    int decades;
} sweep;

/* Keeps the worst figures of the sweep so far. */
static void record_decade(sweep *out, int decade, double diff, double gain, double scaled) {
    out->worst_scaled = fmax(out->worst_scaled, scaled);
    out->worst_gain = fmax(out->worst_gain, gain);
    if (diff >= out->worst_cl) {
        out->worst_cl = diff;
        out->worst_cl_decade = decade;
    }
    out->decades++;
}

static void smooth_both(rsmooth_context *ctx, rsmooth_scalar scalar, const void *xyz,
                        const shape_mesh *m, void *out_ref, void *out_cl, double *edge) {
    rsmooth_error err;
    rsmooth_report report;
    rsmooth_status st =
        rsmooth_smooth(NULL, scalar, xyz, m->vertex_count, m->indices, m->triangle_count, NULL,
                       out_ref, OUTPUTS(NULL, NULL, &report), &err);
    if (st != RSMOOTH_OK)
        fprintf(stderr, "reference: %s\n", err.message);
    CHECK_STATUS(st, RSMOOTH_OK);
    *edge = report.mean_edge_length;
    if (!ctx)
        return;
    st = rsmooth_smooth(ctx, scalar, xyz, m->vertex_count, m->indices, m->triangle_count, NULL,
                        out_cl, NULL, &err);
    if (st != RSMOOTH_OK)
        fprintf(stderr, "opencl: %s\n", err.message);
    CHECK_STATUS(st, RSMOOTH_OK);
}

static void sweep_float64(rsmooth_context *ctx, const roof *r, sweep *out) {
    const shape_mesh *m = &r->noisy;
    size_t n3 = 3 * m->vertex_count;
    double *xyz = malloc(n3 * sizeof *xyz), *ref = malloc(n3 * sizeof *ref);
    double *cl = malloc(n3 * sizeof *cl), *at_one = malloc(n3 * sizeof *at_one);
    CHECK(xyz && ref && cl && at_one);
    double edge_one = 0;
    smooth_both(NULL, RSMOOTH_FLOAT64, m->xyz, m, at_one, NULL, &edge_one);
    double before = rms_error(r, m->xyz, 1), after_one = rms_error(r, at_one, 1);
    printf("float64 roof at spacing 1: error %.4f -> %.4f spacings\n", before, after_one);
    CHECK(after_one < 0.6 * before); /* the filter works at all */
    for (int d = SMALLEST_DECADE; d <= LARGEST_DECADE; d++) {
        double s = pow(10, d), edge = 0;
        for (size_t i = 0; i < n3; i++)
            xyz[i] = m->xyz[i] * s;
        smooth_both(ctx, RSMOOTH_FLOAT64, xyz, m, ref, cl, &edge);
        CHECK(edge > 0 && isfinite(edge));
        double scaled = 0, diff = 0;
        for (size_t i = 0; i < n3; i++) {
            CHECK(isfinite(ref[i]));
            scaled = fmax(scaled, fabs(ref[i] / s - at_one[i]));
            if (ctx) {
                CHECK(isfinite(cl[i]));
                diff = fmax(diff, fabs(cl[i] - ref[i]) / edge);
            }
        }
        record_decade(out, d, diff, rms_error(r, ref, s) / before, scaled);
    }
    free(xyz);
    free(ref);
    free(cl);
    free(at_one);
}

static void sweep_float32(rsmooth_context *ctx, const roof *r, sweep *out) {
    const shape_mesh *m = &r->noisy;
    size_t n3 = 3 * m->vertex_count;
    float *xyz = malloc(n3 * sizeof *xyz), *ref = malloc(n3 * sizeof *ref);
    float *cl = malloc(n3 * sizeof *cl);
    double *as_double = malloc(n3 * sizeof *as_double);
    CHECK(xyz && ref && cl && as_double);
    double before = rms_error(r, m->xyz, 1);
    for (int d = -36; d <= 36; d++) {
        double s = pow(10, d), edge = 0;
        for (size_t i = 0; i < n3; i++)
            xyz[i] = (float)(m->xyz[i] * s);
        smooth_both(ctx, RSMOOTH_FLOAT32, xyz, m, ref, cl, &edge);
        double diff = 0;
        for (size_t i = 0; i < n3; i++) {
            CHECK(isfinite(ref[i]));
            as_double[i] = ref[i];
            if (ctx) {
                CHECK(isfinite(cl[i]));
                diff = fmax(diff, fabs((double)cl[i] - (double)ref[i]) / edge);
            }
        }
        record_decade(out, d, diff, rms_error(r, as_double, s) / before, 0);
    }
    free(xyz);
    free(ref);
    free(cl);
    free(as_double);
}

/* v 0 0 0 / v 1 0 0 / v 0 1 0 / v 0 0 1e39 and the tetrahedron's four faces: one triangle 1e78
 * times smaller in area than the others. Both paths: finite, and the same. */
static void test_tall_tetrahedron(rsmooth_context *ctx) {
    const double xyz[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1e39};
    const uint32_t tri[12] = {0, 2, 1, 0, 1, 3, 1, 2, 3, 2, 0, 3};
    double ref[12], cl[12], edge = 0;
    shape_mesh m = {4, (double *)xyz, 4, (uint32_t *)tri};
    smooth_both(ctx, RSMOOTH_FLOAT64, xyz, &m, ref, cl, &edge);
    double diff = 0;
    for (int i = 0; i < 12; i++) {
        CHECK(isfinite(ref[i]));
        if (ctx) {
            CHECK(isfinite(cl[i]));
            diff = fmax(diff, fabs(cl[i] - ref[i]) / edge);
        }
    }
    printf("tetrahedron to 1e39: apex %.6g -> %.6g (reference), OpenCL - reference %.3g mean "
           "edge lengths\n",
           xyz[11], ref[11], diff);
    CHECK_LE(diff, 1e-3);
}

/* A float32 result beyond FLT_MAX, and weights beyond float's range, are errors, never inf. */
static void test_unrepresentable(rsmooth_context *ctx) {
    /* One tilted triangle near FLT_MAX and a lone vertex below its plane whose projection onto it
     * lands at z = 3.85e38: representable in float64, not in float32. */
    const double d_xyz[12] = {0, 0, 3.3e38, 1e38, 0, 3.3e38, 0, 1e38, 3.0e38, -2e38, -2e38, 3.3e38};
    const uint32_t tri[3] = {0, 1, 2};
    float f_xyz[12], f_out[12];
    double d_out[12];
    for (int i = 0; i < 12; i++)
        f_xyz[i] = (float)d_xyz[i];
    rsmooth_params p;
    rsmooth_params_init(&p);
    p.absolute = 1;
    p.sigma_f = 3e38;
    p.sigma_g = INFINITY;
    p.mollify = 0;
    rsmooth_error err;
    CHECK_STATUS(rsmooth_smooth(NULL, RSMOOTH_FLOAT64, d_xyz, 4, tri, 1, &p, d_out, NULL, &err),
                 RSMOOTH_OK);
    printf("lone vertex projected to z = %.4g (float64)\n", d_out[11]);
    CHECK(d_out[11] > FLT_MAX && isfinite(d_out[11]));
    CHECK_STATUS(rsmooth_smooth(NULL, RSMOOTH_FLOAT32, f_xyz, 4, tri, 1, &p, f_out, NULL, &err),
                 RSMOOTH_ERROR_NUMERICAL);
    printf("float32 reference: %s\n", err.message);
    if (ctx) {
        CHECK_STATUS(rsmooth_smooth(ctx, RSMOOTH_FLOAT32, f_xyz, 4, tri, 1, &p, f_out, NULL, &err),
                     RSMOOTH_ERROR_NUMERICAL);
        printf("float32 OpenCL: %s\n", err.message);
    }

    /* k(p) is in area units: at spacing 1e25 the areas are 1e50, beyond float. */
    roof r;
    make_roof(&r);
    size_t n = r.noisy.vertex_count;
    double *big = malloc(3 * n * sizeof *big), *out = malloc(3 * n * sizeof *out);
    float *weight = malloc(n * sizeof *weight);
    CHECK(big && out && weight);
    for (int decade = 0; decade <= 25; decade += 25) {
        for (size_t i = 0; i < 3 * n; i++)
            big[i] = r.noisy.xyz[i] * pow(10, decade);
        rsmooth_status want = decade == 0 ? RSMOOTH_OK : RSMOOTH_ERROR_NUMERICAL;
        CHECK_STATUS(rsmooth_smooth(NULL, RSMOOTH_FLOAT64, big, n, r.noisy.indices,
                                    r.noisy.triangle_count, NULL, out, OUTPUTS(weight, NULL, NULL),
                                    &err),
                     want);
        if (ctx)
            CHECK_STATUS(rsmooth_smooth(ctx, RSMOOTH_FLOAT64, big, n, r.noisy.indices,
                                        r.noisy.triangle_count, NULL, out,
                                        OUTPUTS(weight, NULL, NULL), &err),
                         want);
        if (want != RSMOOTH_OK)
            printf("weights at spacing 1e%d: %s\n", decade, err.message);
        /* and without weights the same call succeeds */
        CHECK_STATUS(rsmooth_smooth(NULL, RSMOOTH_FLOAT64, big, n, r.noisy.indices,
                                    r.noisy.triangle_count, NULL, out, NULL, &err),
                     RSMOOTH_OK);
    }
    /* Taubin's inflating step pushes a float32 vertex past FLT_MAX. */
    const float spike[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 3e38f};
    const uint32_t faces[12] = {0, 2, 1, 0, 1, 3, 1, 2, 3, 2, 0, 3};
    float spiked[12];
    CHECK_STATUS(
        rsmooth_smooth_taubin(RSMOOTH_FLOAT32, spike, 4, faces, 4, 1e-6, -1, 1, spiked, &err),
        RSMOOTH_ERROR_NUMERICAL);
    printf("taubin: %s\n", err.message);
    free(big);
    free(out);
    free(weight);
    shape_free(&r.noisy);
}

/* A coordinate beyond 1e225 typical edges from the origin is refused, not silently unmoved; a far
 * stray vertex within that is harmless. */
static void test_dynamic_range(void) {
    roof r;
    make_roof(&r);
    shape_mesh *m = &r.noisy;
    size_t n = m->vertex_count + 1;
    double *xyz = malloc(3 * n * sizeof *xyz), *out = malloc(3 * n * sizeof *out);
    double *alone = malloc(3 * n * sizeof *alone);
    CHECK(xyz && out && alone);
    rsmooth_error err;
    for (size_t i = 0; i < 3 * m->vertex_count; i++)
        xyz[i] = m->xyz[i] * 1e-100;
    xyz[3 * n - 3] = xyz[3 * n - 2] = 0;
    xyz[3 * n - 1] = 1e130; /* 1e230 spacings away */
    CHECK_STATUS(rsmooth_smooth(NULL, RSMOOTH_FLOAT64, xyz, n, m->indices, m->triangle_count, NULL,
                                out, NULL, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    printf("stray vertex 1e230 spacings away: %s\n", err.message);
    /* 1e160 spacings away: filtered, and the grid moves exactly as without the stray vertex */
    for (size_t i = 0; i < 3 * m->vertex_count; i++)
        xyz[i] = m->xyz[i] * 1e-10;
    xyz[3 * n - 1] = 1e150;
    CHECK_STATUS(rsmooth_smooth(NULL, RSMOOTH_FLOAT64, xyz, n, m->indices, m->triangle_count, NULL,
                                out, NULL, &err),
                 RSMOOTH_OK);
    CHECK_STATUS(rsmooth_smooth(NULL, RSMOOTH_FLOAT64, xyz, n - 1, m->indices, m->triangle_count,
                                NULL, alone, NULL, &err),
                 RSMOOTH_OK);
    double diff = 0;
    for (size_t i = 0; i < 3 * (n - 1); i++)
        diff = fmax(diff, fabs(out[i] - alone[i]) / 1e-10);
    printf("stray vertex 1e160 spacings away: grid differs by %.3g spacings\n", diff);
    CHECK_LE(diff, 1e-12);
    CHECK(out[3 * n - 1] == 1e150);
    free(xyz);
    free(out);
    free(alone);
    shape_free(&r.noisy);
}

/* The other scale-free results at the ends of the range: the noise estimate, and a point cloud
 * (the roof's vertices with their normals) filtered on the reference path. */
static void test_points_and_noise(const roof *r) {
    const shape_mesh *m = &r->noisy;
    size_t n = m->vertex_count;
    double *normals = malloc(3 * n * sizeof *normals), *xyz = malloc(3 * n * sizeof *xyz);
    double *out = malloc(3 * n * sizeof *out), *at_one = malloc(3 * n * sizeof *at_one);
    CHECK(normals && xyz && out && at_one);
    CHECK(shape_vertex_normals(m, normals) == 0);
    rsmooth_error err;
    double noise_one = 0, spacing_one = 0;
    CHECK_STATUS(rsmooth_estimate_noise(RSMOOTH_FLOAT64, m->xyz, n, m->indices, m->triangle_count,
                                        &noise_one, &err),
                 RSMOOTH_OK);
    CHECK_STATUS(rsmooth_smooth_points(NULL, RSMOOTH_FLOAT64, m->xyz, normals, n, NULL, at_one,
                                       NULL, NULL, &err),
                 RSMOOTH_OK);
    CHECK_STATUS(rsmooth_point_spacing(RSMOOTH_FLOAT64, m->xyz, n, &spacing_one, &err), RSMOOTH_OK);
    static const int decades[] = {SMALLEST_DECADE, -150, -20, 20, 150 - 2};
    for (size_t i = 0; i < sizeof decades / sizeof *decades; i++) {
        double s = pow(10, decades[i]), noise = 0, spacing = 0, moved = 0;
        for (size_t k = 0; k < 3 * n; k++)
            xyz[k] = m->xyz[k] * s;
        CHECK_STATUS(rsmooth_estimate_noise(RSMOOTH_FLOAT64, xyz, n, m->indices, m->triangle_count,
                                            &noise, &err),
                     RSMOOTH_OK);
        CHECK_STATUS(rsmooth_smooth_points(NULL, RSMOOTH_FLOAT64, xyz, normals, n, NULL, out, NULL,
                                           NULL, &err),
                     RSMOOTH_OK);
        CHECK_STATUS(rsmooth_point_spacing(RSMOOTH_FLOAT64, xyz, n, &spacing, &err), RSMOOTH_OK);
        for (size_t k = 0; k < 3 * n; k++)
            moved = fmax(moved, fabs(out[k] / s - at_one[k]));
        printf("at 1e%d: noise %.6f (at 1: %.6f), point spacing / s %.6f (%.6f), points / s - "
               "points at 1: %.3g\n",
               decades[i], noise, noise_one, spacing / s, spacing_one, moved);
        CHECK_NEAR(noise, noise_one, 1e-9);
        CHECK_NEAR(spacing / s, spacing_one, 1e-9);
        CHECK_LE(moved, 1e-9);
    }
    CHECK(noise_one > 0.05); /* there is noise to find */
    free(normals);
    free(xyz);
    free(out);
    free(at_one);
}

int main(void) {
    rsmooth_context *ctx = open_test_context();
    roof r;
    make_roof(&r);
    sweep s64 = {0}, s32 = {0};
    sweep_float64(ctx, &r, &s64);
    printf("float64, spacing 1e%d to 1e%d (%d decades): OpenCL - reference at most %.3g mean "
           "edge lengths (at 1e%d); result / s - result at 1 at most %.3g spacings; error after / "
           "before at most %.3f\n",
           SMALLEST_DECADE, LARGEST_DECADE, s64.decades, s64.worst_cl, s64.worst_cl_decade,
           s64.worst_scaled, s64.worst_gain);
    CHECK_LE(s64.worst_cl, 1e-3);
    CHECK_LE(s64.worst_scaled, 1e-9);
    CHECK_LE(s64.worst_gain, 0.6);
    sweep_float32(ctx, &r, &s32);
    printf("float32, spacing 1e-36 to 1e36 (%d decades): OpenCL - reference at most %.3g mean "
           "edge lengths (at 1e%d); error after / before at most %.3f\n",
           s32.decades, s32.worst_cl, s32.worst_cl_decade, s32.worst_gain);
    CHECK_LE(s32.worst_cl, 1e-3);
    CHECK_LE(s32.worst_gain, 0.6);
    test_tall_tetrahedron(ctx);
    test_points_and_noise(&r);
    test_unrepresentable(ctx);
    test_dynamic_range();
    shape_free(&r.noisy);
    rsmooth_context_destroy(ctx);
    printf("scale: ok\n");
    return 0;
}
