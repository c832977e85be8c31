/* Error metrics (rsmooth_compare): analytic cases, agreement with the independent oracle
 * ../shared/tools/meshmetrics.py on the benchmark meshes, float32 input, every invalid argument
 * refused with a message, the inputs left as they were, every scale alike, the same figures with
 * any thread count and from concurrent calls. The closest points under the figures are checked
 * against brute force in test_surface_index.c. */
#define _POSIX_C_SOURCE 200809L
#include "mesh_shapes.h"
#include "rsmooth.h"
#include "rsmooth_io.h"
#include "test_util.h"

#include <pthread.h>
#include <stdbool.h>
#include <stdint.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static const double pi = 3.14159265358979323846;

/* rsmooth_compare on float64 arrays, which must succeed. */
static rsmooth_metrics compare64(const double *result, const double *truth, size_t vertex_count,
                                 const uint32_t *indices, size_t triangle_count) {
    rsmooth_metrics m;
    rsmooth_error err;
    rsmooth_status s = rsmooth_compare(RSMOOTH_FLOAT64, result, truth, vertex_count, indices,
                                       triangle_count, &m, &err);
    if (s != RSMOOTH_OK)
        fprintf(stderr, "rsmooth_compare: %s\n", err.message);
    CHECK_STATUS(s, RSMOOTH_OK);
    CHECK_STATUS(err.status, RSMOOTH_OK);
    CHECK_EQ_INT(m.vertex_count, vertex_count);
    CHECK_EQ_INT(m.triangle_count, triangle_count);
    return m;
}

/* Two figures are the same double, NAN equal to NAN. */
static bool same(double a, double b) {
    return (isnan(a) && isnan(b)) || memcmp(&a, &b, sizeof a) == 0;
}

static bool same_metrics(const rsmooth_metrics *a, const rsmooth_metrics *b) {
    return a->vertex_count == b->vertex_count && a->triangle_count == b->triangle_count &&
           a->theta_count == b->theta_count && same(a->theta, b->theta) && same(a->ev, b->ev) &&
           same(a->rms_v, b->rms_v) && same(a->hausdorff, b->hausdorff) &&
           same(a->mean_edge, b->mean_edge) && same(a->bbox_diag, b->bbox_diag);
}

static void print_metrics(const char *label, const rsmooth_metrics *m) {
    printf("%s: theta %.17g (%zu faces) ev %.17g rms_v %.17g hausdorff %.17g mean_edge %.17g "
           "bbox_diag %.17g\n",
           label, m->theta, m->theta_count, m->ev, m->rms_v, m->hausdorff, m->mean_edge,
           m->bbox_diag);
}

/* Rodrigues' rotation of `mesh` by `angle` about the unit `axis` through the origin, into `out`. */
static void rotate(const shape_mesh *mesh, const double axis[3], double angle, double *out) {
    for (size_t v = 0; v < mesh->vertex_count; v++) {
        const double *p = mesh->xyz + 3 * v;
        double kxp[3] = {axis[1] * p[2] - axis[2] * p[1], axis[2] * p[0] - axis[0] * p[2],
                         axis[0] * p[1] - axis[1] * p[0]};
        double kdp = axis[0] * p[0] + axis[1] * p[1] + axis[2] * p[2];
        for (int k = 0; k < 3; k++)
            out[3 * v + k] =
                p[k] * cos(angle) + kxp[k] * sin(angle) + axis[k] * kdp * (1 - cos(angle));
    }
}

/* ---- metrics on analytic cases ------------------------------------------------------------- */

static void test_analytic(void) {
    shape_mesh plane, moved;
    CHECK(shape_plane(&plane, 20, 10, 0.5) == 0);
    CHECK(shape_copy(&plane, &moved) == 0);
    rsmooth_metrics m;

    /* Identical meshes. */
    m = compare64(plane.xyz, plane.xyz, plane.vertex_count, plane.indices, plane.triangle_count);
    printf("identical plane: theta %g ev %g rms_v %g hausdorff %g\n", m.theta, m.ev, m.rms_v,
           m.hausdorff);
    CHECK(m.theta == 0 && m.ev == 0 && m.rms_v == 0 && m.hausdorff == 0);
    double diag = sqrt(10.0 * 10.0 + 5.0 * 5.0), edge = shape_mean_edge_length(&plane);
    CHECK_NEAR(m.bbox_diag, diag, 1e-12);
    CHECK_NEAR(m.mean_edge, edge, 1e-12);
    CHECK_EQ_INT(m.theta_count, plane.triangle_count);

    /* The plane moved by t along its normal: every vertex is t from the other surface. */
    const double t = 0.0375;
    for (size_t v = 0; v < moved.vertex_count; v++)
        moved.xyz[3 * v + 2] += t;
    m = compare64(moved.xyz, plane.xyz, plane.vertex_count, plane.indices, plane.triangle_count);
    printf("plane moved by %g: theta %g ev %.12g (expect %.12g) rms_v %.12g (expect %.12g) "
           "hausdorff %.12g\n",
           t, m.theta, m.ev, t / diag * 1e3, m.rms_v, t / edge, m.hausdorff);
    CHECK(m.theta == 0);
    CHECK_NEAR(m.ev, t / diag * 1e3, 1e-12);
    CHECK_NEAR(m.rms_v, t / edge, 1e-12);
    CHECK_NEAR(m.hausdorff, t / diag * 1e3, 1e-12);

    /* One vertex raised by h: Hausdorff sees it whole; ev weights it by its area share. */
    memcpy(moved.xyz, plane.xyz, 3 * plane.vertex_count * sizeof *plane.xyz);
    size_t lifted = 5 * 21 + 7; /* an interior vertex (rows of 21) */
    const double h = 0.2;
    moved.xyz[3 * lifted + 2] += h;
    m = compare64(moved.xyz, plane.xyz, plane.vertex_count, plane.indices, plane.triangle_count);
    printf("one vertex raised by %g: hausdorff %.12g (expect %.12g), ev %.6g, theta %.6g\n", h,
           m.hausdorff, h / diag * 1e3, m.ev, m.theta);
    CHECK_NEAR(m.hausdorff, h / diag * 1e3, 1e-12);
    CHECK(m.ev > 0 && m.ev < h / diag * 1e3 && m.theta > 0);

    /* A rotation by alpha about an axis turns a normal at angle phi to the axis by
     * 2 asin(sin phi sin(alpha / 2)): by alpha itself for the plane turned about an axis in it, by
     * that per-face amount averaged for a sphere. */
    const double alpha = 0.7 * pi / 180;
    const double x_axis[3] = {1, 0, 0}, diagonal[3] = {1 / sqrt(3.0), 1 / sqrt(3.0), 1 / sqrt(3.0)};
    rotate(&plane, x_axis, alpha, moved.xyz);
    m = compare64(moved.xyz, plane.xyz, plane.vertex_count, plane.indices, plane.triangle_count);
    printf("plane turned by 0.7 deg about an axis in it: theta %.12g deg\n", m.theta);
    CHECK_NEAR(m.theta, 0.7, 1e-9);
    shape_mesh sphere, turned;
    CHECK(shape_sphere(&sphere, 3, 1.0) == 0);
    CHECK(shape_copy(&sphere, &turned) == 0);
    rotate(&sphere, diagonal, alpha, turned.xyz);
    double expect = 0;
    for (size_t f = 0; f < sphere.triangle_count; f++) {
        const uint32_t *i = sphere.indices + 3 * f;
        const double *a = sphere.xyz + 3 * (size_t)i[0], *b = sphere.xyz + 3 * (size_t)i[1],
                     *c = sphere.xyz + 3 * (size_t)i[2];
        double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                       u[0] * v[1] - u[1] * v[0]};
        double cos_phi = (n[0] * diagonal[0] + n[1] * diagonal[1] + n[2] * diagonal[2]) /
                         sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        double sin_phi = sqrt(fmax(0, 1 - cos_phi * cos_phi));
        expect += 2 * asin(sin_phi * sin(alpha / 2));
    }
    expect = expect / (double)sphere.triangle_count * 180 / pi;
    m = compare64(turned.xyz, sphere.xyz, sphere.vertex_count, sphere.indices,
                  sphere.triangle_count);
    printf("sphere turned by 0.7 deg: theta %.12g deg (expect %.12g from the faces' angles to the "
           "axis)\n",
           m.theta, expect);
    CHECK_NEAR(m.theta, expect, 1e-9);

    /* A truth whose edges all have zero length has no unit for rms_v and no extent for ev and
     * hausdorff: infinite or NAN figures, not a failure. */
    double point[9] = {1, 2, 3, 1, 2, 3, 1, 2, 3}, spread[9] = {1, 2, 3, 2, 2, 3, 1, 3, 3};
    uint32_t tri[3] = {0, 1, 2};
    m = compare64(spread, point, 3, tri, 1);
    print_metrics("a triangle against its corners collapsed to one point", &m);
    CHECK(m.mean_edge == 0 && m.bbox_diag == 0 && m.theta_count == 0 && isnan(m.theta));
    CHECK(isinf(m.rms_v) && isinf(m.ev) && isinf(m.hausdorff));
    shape_free(&plane);
    shape_free(&moved);
    shape_free(&sphere);
    shape_free(&turned);
}

/* ---- agreement with meshmetrics.py ----------------------------------------------------------- */

static bool json_number(const char *json, const char *key, double *out) {
    char pattern[64];
    snprintf(pattern, sizeof pattern, "\"%s\":", key);
    const char *at = strstr(json, pattern);
    if (!at)
        return false;
    char *end;
    *out = strtod(at + strlen(pattern), &end);
    return end != at + strlen(pattern);
}

static double relative(double ours, double theirs) {
    return fabs(ours - theirs) / fabs(theirs);
}

typedef struct worst {
    double rms_v, theta, ev, mean_edge, bbox_diag;
} worst;

/* Runs the script on RESULT against TRUTH and compares it with our figures. */
static void agree(const char *label, const char *script, const char *result_path,
                  const double *result_xyz, const rsmooth_mesh *truth, const char *truth_path,
                  worst *w) {
    rsmooth_metrics m = compare64(result_xyz, truth->positions, truth->vertex_count,
                                  truth->triangles, truth->triangle_count);
    char command[8400], json[4096] = "";
    snprintf(command, sizeof command, "/usr/bin/python3 '%s' '%s' '%s' --json", script, result_path,
             truth_path);
    FILE *pipe = popen(command, "r");
    CHECK(pipe != NULL);
    size_t n = fread(json, 1, sizeof json - 1, pipe);
    json[n] = '\0';
    CHECK_EQ_INT(pclose(pipe), 0);
    double rms_v, theta, ev, mean_edge, bbox_diag;
    if (!json_number(json, "rms_v", &rms_v) || !json_number(json, "theta", &theta) ||
        !json_number(json, "ev", &ev) || !json_number(json, "mean_edge", &mean_edge) ||
        !json_number(json, "bbox_diag", &bbox_diag)) {
        fprintf(stderr, "%s: unexpected output of meshmetrics.py: %s\n", label, json);
        exit(1);
    }
    double r_rms = relative(m.rms_v, rms_v), r_theta = relative(m.theta, theta);
    double r_ev = relative(m.ev, ev), r_edge = relative(m.mean_edge, mean_edge);
    double r_diag = relative(m.bbox_diag, bbox_diag);
    printf("%-28s %9.6f %9.6f %8.1e | %8.4f %8.4f %8.1e | %9.6f %9.6f %8.1e | %8.4f\n", label,
           rms_v, m.rms_v, r_rms, theta, m.theta, r_theta, ev, m.ev, (m.ev - ev) / ev, m.hausdorff);
    fflush(stdout);
    CHECK_LE(r_rms, 1e-3);
    CHECK_LE(r_theta, 1e-3);
    CHECK_LE(r_ev, 1e-2);
    CHECK_LE(r_edge, 1e-3);
    CHECK_LE(r_diag, 1e-3);
    /* The script's distance is a minimum over a subset of the triangles: never below the exact. */
    CHECK_LE(m.ev, ev * (1 + 1e-9));
    w->rms_v = fmax(w->rms_v, r_rms);
    w->theta = fmax(w->theta, r_theta);
    w->ev = fmax(w->ev, r_ev);
    w->mean_edge = fmax(w->mean_edge, r_edge);
    w->bbox_diag = fmax(w->bbox_diag, r_diag);
}

static void test_against_script(void) {
    char dir[4096], script[4200];
    struct stat st;
    snprintf(dir, sizeof dir, "%s/data/benchmark", RSMOOTH_SHARED_DIR);
    snprintf(script, sizeof script, "%s/tools/meshmetrics.py", RSMOOTH_SHARED_DIR);
    if (RSMOOTH_SHARED_DIR[0] == '\0' || stat(dir, &st) != 0 || stat(script, &st) != 0) {
        printf("meshmetrics.py agreement: %s or %s absent, skipped\n", dir, script);
        return;
    }
    if (system("/usr/bin/python3 -c 'import numpy, scipy' >/dev/null 2>&1") != 0) {
        printf("meshmetrics.py agreement: /usr/bin/python3 with numpy and scipy absent, skipped\n");
        return;
    }
    char tmpdir[] = "/tmp/rsmooth_test_metrics_XXXXXX";
    CHECK(mkdtemp(tmpdir) != NULL);
    char result_path[64];
    snprintf(result_path, sizeof result_path, "%s/result.obj", tmpdir);

    static const char *const models[] = {"Fandisk0.3", "Block0.4", "Bunny0.2", "SharpSphere0.3",
                                         "Twelve0.5Impulsive"};
    printf("meshmetrics.py (script) against rsmooth_compare (ours; ev exact), reference filter "
           "sigma_f 2, sigma_g 0.5:\n");
    printf("%-28s %9s %9s %8s | %8s %8s %8s | %9s %9s %8s | %8s\n", "model", "rms_v py", "ours",
           "rel", "theta py", "ours", "rel", "ev py", "ours", "ours-py", "hausdrff");
    worst w = {0, 0, 0, 0, 0};
    for (size_t i = 0; i < sizeof models / sizeof *models; i++) {
        char noisy_path[4300], truth_path[4300];
        snprintf(noisy_path, sizeof noisy_path, "%s/%s/Noisy.obj", dir, models[i]);
        snprintf(truth_path, sizeof truth_path, "%s/%s/Original.obj", dir, models[i]);
        rsmooth_mesh *noisy = NULL, *truth = NULL;
        rsmooth_error err;
        CHECK_STATUS(rsmooth_mesh_read_file(noisy_path, &noisy, &err), RSMOOTH_OK);
        CHECK_STATUS(rsmooth_mesh_read_file(truth_path, &truth, &err), RSMOOTH_OK);
        CHECK_EQ_INT(noisy->vertex_count, truth->vertex_count);
        CHECK_EQ_INT(noisy->triangle_count, truth->triangle_count);

        char label[96];
        snprintf(label, sizeof label, "%s noisy", models[i]);
        agree(label, script, noisy_path, noisy->positions, truth, truth_path, &w);

        rsmooth_params p;
        rsmooth_params_init(&p);
        p.sigma_f = 2;
        p.sigma_g = 0.5;
        double *smoothed = malloc(3 * noisy->vertex_count * sizeof *smoothed);
        CHECK(smoothed != NULL);
        CHECK_STATUS(rsmooth_smooth(NULL, RSMOOTH_FLOAT64, noisy->positions, noisy->vertex_count,
                                    noisy->triangles, noisy->triangle_count, &p, smoothed, NULL,
                                    &err),
                     RSMOOTH_OK);
        /* The OBJ writer prints coordinates in full precision, so the script reads what we
         * measure. */
        memcpy(noisy->positions, smoothed, 3 * noisy->vertex_count * sizeof *smoothed);
        CHECK_STATUS(rsmooth_mesh_write_file(noisy, result_path, RSMOOTH_FORMAT_OBJ, &err),
                     RSMOOTH_OK);
        snprintf(label, sizeof label, "%s smoothed", models[i]);
        agree(label, script, result_path, smoothed, truth, truth_path, &w);
        free(smoothed);
        rsmooth_mesh_destroy(noisy);
        rsmooth_mesh_destroy(truth);
    }
    unlink(result_path);
    rmdir(tmpdir);
    printf("largest relative differences: rms_v %.2e theta %.2e (limits 1e-3), ev %.2e (limit "
           "1e-2), mean_edge %.2e bbox_diag %.2e (limits 1e-3)\n",
           w.rms_v, w.theta, w.ev, w.mean_edge, w.bbox_diag);
}

/* ---- float32 input ------------------------------------------------------------------------- */

/* A noisy sphere against the clean one: every figure non-trivial. */
static void noisy_sphere(int levels, shape_mesh *truth, shape_mesh *noisy) {
    CHECK(shape_sphere(truth, levels, 1.0) == 0);
    CHECK(shape_copy(truth, noisy) == 0);
    CHECK(shape_add_normal_noise(noisy, 0.3, 7) == 0);
}

/* float32 arrays give exactly the figures of float64 arrays holding the same values. */
static void check_float32(const char *label, const double *result, const double *truth,
                          size_t vertex_count, const uint32_t *indices, size_t triangle_count) {
    size_t n = 3 * vertex_count;
    float *r32 = malloc(n * sizeof *r32), *t32 = malloc(n * sizeof *t32);
    double *r64 = malloc(n * sizeof *r64), *t64 = malloc(n * sizeof *t64);
    CHECK(r32 && t32 && r64 && t64);
    for (size_t i = 0; i < n; i++) {
        r32[i] = (float)result[i];
        t32[i] = (float)truth[i];
        r64[i] = r32[i];
        t64[i] = t32[i];
    }
    rsmooth_metrics m32, m64 = compare64(r64, t64, vertex_count, indices, triangle_count);
    rsmooth_error err;
    CHECK_STATUS(rsmooth_compare(RSMOOTH_FLOAT32, r32, t32, vertex_count, indices, triangle_count,
                                 &m32, &err),
                 RSMOOTH_OK);
    print_metrics(label, &m32);
    if (!same_metrics(&m32, &m64)) {
        print_metrics("  float64 of the same values", &m64);
        CHECK(!"float32 and float64 figures differ");
    }
    free(r32);
    free(t32);
    free(r64);
    free(t64);
}

static void test_float32(void) {
    shape_mesh sphere, noisy, plane, moved;
    noisy_sphere(3, &sphere, &noisy);
    check_float32("float32 = float64: noisy sphere", noisy.xyz, sphere.xyz, sphere.vertex_count,
                  sphere.indices, sphere.triangle_count);
    CHECK(shape_plane(&plane, 20, 10, 0.5) == 0);
    CHECK(shape_copy(&plane, &moved) == 0);
    for (size_t v = 0; v < moved.vertex_count; v++)
        moved.xyz[3 * v + 2] += 0.01 * (double)(v % 7); /* 0.01 is no float: rounding shows */
    check_float32("float32 = float64: rippled plane", moved.xyz, plane.xyz, plane.vertex_count,
                  plane.indices, plane.triangle_count);
    shape_free(&sphere);
    shape_free(&noisy);
    shape_free(&plane);
    shape_free(&moved);
}

/* ---- invalid arguments ---------------------------------------------------------------------- */

static int g_refused;

/* The call is refused as invalid with a message containing `expect`, `out` untouched; the same
 * without an error record. */
static void expect_invalid(const char *what, const char *expect, rsmooth_scalar scalar,
                           const void *result, const void *truth, size_t vertex_count,
                           const uint32_t *indices, size_t triangle_count, bool with_out) {
    rsmooth_metrics out, sentinel;
    memset(&sentinel, 0xA5, sizeof sentinel);
    memcpy(&out, &sentinel, sizeof out);
    rsmooth_error err;
    memset(&err, 0, sizeof err);
    rsmooth_status s = rsmooth_compare(scalar, result, truth, vertex_count, indices, triangle_count,
                                       with_out ? &out : NULL, &err);
    printf("refused: %-40s -> %d \"%s\" (%s)\n", what, (int)s, err.message, err.where);
    CHECK_STATUS(s, RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK_EQ_INT(err.status, RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK(memchr(err.message, '\0', sizeof err.message) != NULL);
    if (!strstr(err.message, expect)) {
        fprintf(stderr, "%s: the message does not say \"%s\"\n", what, expect);
        exit(1);
    }
    CHECK(strcmp(err.where, "rsmooth_compare") == 0);
    CHECK(memcmp(&out, &sentinel, sizeof out) == 0);
    s = rsmooth_compare(scalar, result, truth, vertex_count, indices, triangle_count,
                        with_out ? &out : NULL, NULL);
    CHECK_STATUS(s, RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK(memcmp(&out, &sentinel, sizeof out) == 0);
    g_refused++;
}

static void test_invalid_arguments(void) {
    shape_mesh plane, moved;
    CHECK(shape_plane(&plane, 4, 4, 1.0) == 0); /* 25 vertices, 32 triangles */
    CHECK(shape_copy(&plane, &moved) == 0);
    moved.xyz[3 * 12 + 2] = 0.25;
    const size_t vc = plane.vertex_count, tc = plane.triangle_count;
    const double *r = moved.xyz, *t = plane.xyz;
    const uint32_t *idx = plane.indices;
    compare64(r, t, vc, idx, tc); /* the base call is valid */

    expect_invalid("out NULL", "out is NULL", RSMOOTH_FLOAT64, r, t, vc, idx, tc, false);
    expect_invalid("result NULL", "result_positions is NULL", RSMOOTH_FLOAT64, NULL, t, vc, idx, tc,
                   true);
    expect_invalid("truth NULL", "truth_positions is NULL", RSMOOTH_FLOAT64, r, NULL, vc, idx, tc,
                   true);
    expect_invalid("indices NULL", "indices is NULL", RSMOOTH_FLOAT64, r, t, vc, NULL, tc, true);
    expect_invalid("no vertex", "no vertices", RSMOOTH_FLOAT64, r, t, 0, idx, tc, true);
    expect_invalid("no triangle", "no triangles", RSMOOTH_FLOAT64, r, t, vc, idx, 0, true);
    expect_invalid("no triangle, indices NULL", "no triangles", RSMOOTH_FLOAT64, r, t, vc, NULL, 0,
                   true);
    expect_invalid("scalar 7", "scalar must be", (rsmooth_scalar)7, r, t, vc, idx, tc, true);
    expect_invalid("vertex count beyond 32 bits", "32-bit", RSMOOTH_FLOAT64, r, t,
                   (size_t)UINT32_MAX + 2, idx, tc, true);
    expect_invalid("triangle count overflowing", "too large", RSMOOTH_FLOAT64, r, t, vc, idx,
                   SIZE_MAX / 4, true);

    uint32_t bad[3 * 32];
    memcpy(bad, idx, sizeof bad);
    bad[3 * 17 + 1] = 25;
    expect_invalid("index out of range", "triangle 17: index 25 >= vertex count 25",
                   RSMOOTH_FLOAT64, r, t, vc, bad, tc, true);
    bad[3 * 17 + 1] = UINT32_MAX;
    expect_invalid("index UINT32_MAX", "triangle 17: index 4294967295", RSMOOTH_FLOAT64, r, t, vc,
                   bad, tc, true);

    double broken[3 * 25];
    memcpy(broken, r, sizeof broken);
    broken[3 * 7 + 1] = NAN;
    expect_invalid("NaN in the result", "result vertex 7 has a non-finite coordinate",
                   RSMOOTH_FLOAT64, broken, t, vc, idx, tc, true);
    expect_invalid("NaN in the truth", "truth vertex 7 has a non-finite coordinate",
                   RSMOOTH_FLOAT64, t, broken, vc, idx, tc, true);
    memcpy(broken, r, sizeof broken);
    broken[3 * 11] = -INFINITY;
    expect_invalid("infinity in the truth", "truth vertex 11 has a non-finite coordinate",
                   RSMOOTH_FLOAT64, r, broken, vc, idx, tc, true);
    memcpy(broken, r, sizeof broken);
    broken[3 * 3 + 2] = 1e151;
    expect_invalid("coordinate beyond 1e150", "result vertex 3 has coordinate", RSMOOTH_FLOAT64,
                   broken, t, vc, idx, tc, true);
    float broken32[3 * 25], plane32[3 * 25];
    for (size_t i = 0; i < 3 * vc; i++)
        broken32[i] = plane32[i] = (float)t[i];
    broken32[3 * 24] = NAN;
    expect_invalid("float32 NaN in the truth", "truth vertex 24 has a non-finite coordinate",
                   RSMOOTH_FLOAT32, plane32, broken32, vc, idx, tc, true);

    /* A truth with edges of 1e-100 and a result vertex at 1e140: no power of two holds both
     * scales. */
    double tiny[3 * 25];
    for (size_t i = 0; i < 3 * vc; i++)
        tiny[i] = t[i] * 1e-100;
    memcpy(broken, tiny, sizeof broken);
    broken[3 * 5] = 1e140;
    expect_invalid("scales too far apart", "more than 1e225", RSMOOTH_FLOAT64, broken, tiny, vc,
                   idx, tc, true);
    printf("invalid arguments: %d calls refused, each naming its problem, out untouched\n",
           g_refused);
    shape_free(&plane);
    shape_free(&moved);
}

/* ---- the inputs are only read ---------------------------------------------------------------- */

static void test_inputs_unchanged(void) {
    shape_mesh sphere, noisy;
    noisy_sphere(2, &sphere, &noisy);
    size_t n = 3 * sphere.vertex_count, ni = 3 * sphere.triangle_count;
    double *r = malloc(n * sizeof *r), *t = malloc(n * sizeof *t);
    float *r32 = malloc(n * sizeof *r32), *t32 = malloc(n * sizeof *t32);
    uint32_t *idx = malloc(ni * sizeof *idx);
    CHECK(r && t && r32 && t32 && idx);
    memcpy(r, noisy.xyz, n * sizeof *r);
    memcpy(t, sphere.xyz, n * sizeof *t);
    memcpy(idx, sphere.indices, ni * sizeof *idx);
    for (size_t i = 0; i < n; i++) {
        r32[i] = (float)r[i];
        t32[i] = (float)t[i];
    }
    rsmooth_metrics m;
    CHECK_STATUS(rsmooth_compare(RSMOOTH_FLOAT64, r, t, sphere.vertex_count, idx,
                                 sphere.triangle_count, &m, NULL),
                 RSMOOTH_OK);
    CHECK(memcmp(r, noisy.xyz, n * sizeof *r) == 0);
    CHECK(memcmp(t, sphere.xyz, n * sizeof *t) == 0);
    CHECK(memcmp(idx, sphere.indices, ni * sizeof *idx) == 0);
    float *r32_copy = malloc(n * sizeof *r32), *t32_copy = malloc(n * sizeof *t32);
    CHECK(r32_copy && t32_copy);
    memcpy(r32_copy, r32, n * sizeof *r32);
    memcpy(t32_copy, t32, n * sizeof *t32);
    CHECK_STATUS(rsmooth_compare(RSMOOTH_FLOAT32, r32, t32, sphere.vertex_count, idx,
                                 sphere.triangle_count, &m, NULL),
                 RSMOOTH_OK);
    CHECK(memcmp(r32, r32_copy, n * sizeof *r32) == 0);
    CHECK(memcmp(t32, t32_copy, n * sizeof *t32) == 0);
    CHECK(memcmp(idx, sphere.indices, ni * sizeof *idx) == 0);
    /* The same array as result and truth is fine: nothing is written. */
    CHECK_STATUS(rsmooth_compare(RSMOOTH_FLOAT64, t, t, sphere.vertex_count, idx,
                                 sphere.triangle_count, &m, NULL),
                 RSMOOTH_OK);
    CHECK(m.ev == 0 && m.hausdorff == 0 && m.rms_v == 0 && m.theta == 0);
    CHECK(memcmp(t, sphere.xyz, n * sizeof *t) == 0);
    printf("inputs unchanged: result, truth and indices, float64 and float32\n");
    free(r);
    free(t);
    free(r32);
    free(t32);
    free(r32_copy);
    free(t32_copy);
    free(idx);
    shape_free(&sphere);
    shape_free(&noisy);
}

/* ---- every scale alike ------------------------------------------------------------------------
 */

static void scaled(const double *xyz, size_t n, double factor, double *out) {
    for (size_t i = 0; i < n; i++)
        out[i] = xyz[i] * factor;
}

static void test_scales(void) {
    shape_mesh sphere, noisy;
    noisy_sphere(3, &sphere, &noisy);
    size_t n = 3 * sphere.vertex_count;
    rsmooth_metrics base = compare64(noisy.xyz, sphere.xyz, sphere.vertex_count, sphere.indices,
                                     sphere.triangle_count);
    print_metrics("noisy sphere", &base);
    double *r = malloc(n * sizeof *r), *t = malloc(n * sizeof *t);
    CHECK(r && t);
    /* Powers of two: the same figures bit for bit, lengths times the factor exactly (edges of
     * 1e-290 and coordinates of 1e148 at the ends, where squared distances would underflow or
     * overflow without the library's scaling). */
    const int exponents[] = {-960, -300, -7, 5, 300, 490};
    for (size_t i = 0; i < sizeof exponents / sizeof *exponents; i++) {
        double f = ldexp(1.0, exponents[i]);
        scaled(noisy.xyz, n, f, r);
        scaled(sphere.xyz, n, f, t);
        rsmooth_metrics m =
            compare64(r, t, sphere.vertex_count, sphere.indices, sphere.triangle_count);
        rsmooth_metrics expect = base;
        expect.mean_edge *= f;
        expect.bbox_diag *= f;
        if (!same_metrics(&m, &expect)) {
            fprintf(stderr, "scale 2^%d:\n", exponents[i]);
            print_metrics("  got", &m);
            print_metrics("  expected", &expect);
            CHECK(!"figures differ at a power-of-two scale");
        }
    }
    /* Other factors round the coordinates: the figures agree to rounding. */
    const double factors[] = {1e-200, 3e-7, 1e120};
    for (size_t i = 0; i < sizeof factors / sizeof *factors; i++) {
        scaled(noisy.xyz, n, factors[i], r);
        scaled(sphere.xyz, n, factors[i], t);
        rsmooth_metrics m =
            compare64(r, t, sphere.vertex_count, sphere.indices, sphere.triangle_count);
        CHECK_NEAR(m.theta, base.theta, 1e-9 * base.theta);
        CHECK_NEAR(m.ev, base.ev, 1e-9 * base.ev);
        CHECK_NEAR(m.rms_v, base.rms_v, 1e-9 * base.rms_v);
        CHECK_NEAR(m.hausdorff, base.hausdorff, 1e-9 * base.hausdorff);
        CHECK_NEAR(m.mean_edge / factors[i], base.mean_edge, 1e-9 * base.mean_edge);
        CHECK_NEAR(m.bbox_diag / factors[i], base.bbox_diag, 1e-9 * base.bbox_diag);
    }
    printf("scales: the same figures at 2^-960 .. 2^490 (bit for bit) and at 1e-200 .. 1e120\n");
    free(r);
    free(t);
    shape_free(&sphere);
    shape_free(&noisy);
}

/* ---- threads -----------------------------------------------------------------------------------
 */

typedef struct compare_call {
    const shape_mesh *truth, *result;
    rsmooth_metrics m;
    rsmooth_status status;
} compare_call;

static void *run_compare(void *arg) {
    compare_call *c = arg;
    c->status =
        rsmooth_compare(RSMOOTH_FLOAT64, c->result->xyz, c->truth->xyz, c->truth->vertex_count,
                        c->truth->indices, c->truth->triangle_count, &c->m, NULL);
    return NULL;
}

static void test_threads(void) {
    shape_mesh sphere, noisy;
    noisy_sphere(5, &sphere, &noisy); /* 10242 vertices: several chunks of queries */
    const char *saved = getenv("RSMOOTH_HOST_THREADS");
    char *saved_copy = saved ? strdup(saved) : NULL;
    rsmooth_metrics first;
    const char *counts[] = {"1", "2", "3", "8"};
    for (size_t i = 0; i < sizeof counts / sizeof *counts; i++) {
        CHECK(setenv("RSMOOTH_HOST_THREADS", counts[i], 1) == 0);
        rsmooth_metrics m = compare64(noisy.xyz, sphere.xyz, sphere.vertex_count, sphere.indices,
                                      sphere.triangle_count);
        if (i == 0)
            first = m;
        CHECK(same_metrics(&m, &first));
    }
    if (saved_copy) {
        CHECK(setenv("RSMOOTH_HOST_THREADS", saved_copy, 1) == 0);
        free(saved_copy);
    } else {
        CHECK(unsetenv("RSMOOTH_HOST_THREADS") == 0);
    }
    /* Concurrent calls on the same arrays. */
    enum { CALLS = 4 };
    compare_call calls[CALLS];
    pthread_t threads[CALLS];
    for (int i = 0; i < CALLS; i++) {
        calls[i] = (compare_call){&sphere, &noisy, {0}, RSMOOTH_ERROR_OPENCL};
        CHECK(pthread_create(&threads[i], NULL, run_compare, &calls[i]) == 0);
    }
    for (int i = 0; i < CALLS; i++) {
        CHECK(pthread_join(threads[i], NULL) == 0);
        CHECK_STATUS(calls[i].status, RSMOOTH_OK);
        CHECK(same_metrics(&calls[i].m, &first));
    }
    print_metrics("threads: the same figures with 1, 2, 3 and 8 host threads and from 4 "
                  "concurrent calls",
                  &first);
    shape_free(&sphere);
    shape_free(&noisy);
}

int main(void) {
    test_analytic();
    test_float32();
    test_invalid_arguments();
    test_inputs_unchanged();
    test_scales();
    test_threads();
    test_against_script();
    return 0;
}
