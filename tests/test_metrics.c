/* Error metrics: exact closest points against brute force, analytic cases, and agreement with the
 * independent oracle ../shared/tools/meshmetrics.py on the benchmark meshes. */
#define _POSIX_C_SOURCE 200809L
#include "mesh_metrics.h"
#include "mesh_shapes.h"
#include "rsmooth.h"
#include "rsmooth_io.h"
#include "test_util.h"

#include <stdbool.h>
#include <stdint.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static const double pi = 3.14159265358979323846;

/* xorshift64*: uniform numbers that are the same on every platform. */
static double uniform(uint64_t *s) {
    *s ^= *s >> 12;
    *s ^= *s << 25;
    *s ^= *s >> 27;
    return (double)((*s * 2685821657736338717ull) >> 11) * 0x1.0p-53;
}

static double dist2(const double a[3], const double b[3]) {
    double x = a[0] - b[0], y = a[1] - b[1], z = a[2] - b[2];
    return x * x + y * y + z * z;
}

/* ---- the closest point on one triangle ----------------------------------------------------- */

/* The smallest squared distance from p to n*(n+1)/2 points spread over the triangle: an upper
 * bound on the true one, within (triangle size / n)^2 of it. */
static double sampled_dist2(const double p[3], const double a[3], const double b[3],
                            const double c[3], int n) {
    double best = INFINITY;
    for (int i = 0; i <= n; i++)
        for (int j = 0; i + j <= n; j++) {
            double u = (double)i / n, v = (double)j / n, q[3];
            for (int k = 0; k < 3; k++)
                q[k] = a[k] + u * (b[k] - a[k]) + v * (c[k] - a[k]);
            best = fmin(best, dist2(p, q));
        }
    return best;
}

static void test_triangle(void) {
    const double a[3] = {0, 0, 0}, b[3] = {2, 0, 0}, c[3] = {0, 2, 0};
    double q[3];
    /* Each Voronoi region of the triangle once: interior, three edges, three corners. */
    struct {
        double p[3], expect[3];
    } cases[] = {
        {{0.5, 0.5, 3}, {0.5, 0.5, 0}}, {{1, -1, 1}, {1, 0, 0}},  {{-1, 1, -1}, {0, 1, 0}},
        {{2, 2, 0.5}, {1, 1, 0}},       {{-1, -1, 2}, {0, 0, 0}}, {{3, -1, 0}, {2, 0, 0}},
        {{-1, 3, 0}, {0, 2, 0}},
    };
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        double d2 = surface_closest_on_triangle(cases[i].p, a, b, c, q);
        CHECK_NEAR(d2, dist2(cases[i].p, cases[i].expect), 1e-14);
        CHECK_NEAR(dist2(q, cases[i].expect), 0, 1e-28);
    }
    /* Degenerate triangles are the segments they collapse to: a point near the middle of a
     * collapsed edge is at its distance from that segment (Ericson's formulas give 0/0 there). */
    const double p[3] = {1.5, 0.3, 0.1};
    const double s0[3] = {2, 0, 0}, s1[3] = {1, 0, 0}, s2[3] = {3, 0, 0};
    double expect = 0.3 * 0.3 + 0.1 * 0.1;
    CHECK_NEAR(surface_closest_on_triangle(p, s0, s0, s1, q), expect, 1e-15);       /* a == b */
    CHECK_NEAR(surface_closest_on_triangle(p, s0, s1, s1, q), expect, 1e-15);       /* b == c */
    CHECK_NEAR(surface_closest_on_triangle(p, s1, s0, s1, q), expect, 1e-15);       /* c == a */
    CHECK_NEAR(surface_closest_on_triangle(p, s1, s2, s0, q), expect, 1e-15);       /* collinear */
    CHECK_NEAR(surface_closest_on_triangle(p, s0, s0, s0, q), dist2(p, s0), 1e-15); /* a point */

    /* Random triangles and points: the answer lies on the triangle and is no farther than any
     * sample of it. */
    uint64_t s = 0x9e3779b97f4a7c15ull;
    double worst_gap = 0, worst_off = 0;
    for (int trial = 0; trial < 400; trial++) {
        double t[3][3], pt[3];
        for (int v = 0; v < 3; v++)
            for (int k = 0; k < 3; k++)
                t[v][k] = uniform(&s) * 2 - 1;
        if (trial % 10 == 0) /* some needles and slivers */
            for (int k = 0; k < 3; k++)
                t[2][k] = t[0][k] + (t[1][k] - t[0][k]) * 0.7 + 1e-4 * uniform(&s);
        for (int k = 0; k < 3; k++)
            pt[k] = uniform(&s) * 4 - 2;
        double d2 = surface_closest_on_triangle(pt, t[0], t[1], t[2], q);
        CHECK_NEAR(d2, dist2(pt, q), 1e-12);
        /* q on the triangle: its distance from it (by the function itself) is ~0, and it lies in
         * the triangle's plane within the corners' hull. */
        double off = surface_closest_on_triangle(q, t[0], t[1], t[2], NULL);
        CHECK_LE(off, 1e-20); /* rounding, largest on the slivers */
        worst_off = fmax(worst_off, off);
        double sampled = sampled_dist2(pt, t[0], t[1], t[2], 60);
        CHECK_LE(d2, sampled + 1e-12);
        worst_gap = fmax(worst_gap, sampled - d2);
    }
    printf("triangle: 7 regions, 5 degenerate cases, 400 random triangles; largest sampled - exact "
           "squared distance %.3g (>= 0 required); closest points off their triangle by at most "
           "%.2g (squared)\n",
           worst_gap, worst_off);
}

/* ---- the grid against brute force ------------------------------------------------------------ */

static double brute_force(const double *xyz, const uint32_t *tris, size_t tri_count,
                          const double p[3], size_t *best_tri) {
    double best = INFINITY;
    *best_tri = SIZE_MAX;
    for (size_t t = 0; t < tri_count; t++) {
        const uint32_t *f = tris + 3 * t;
        double d = surface_closest_on_triangle(p, xyz + 3 * (size_t)f[0], xyz + 3 * (size_t)f[1],
                                               xyz + 3 * (size_t)f[2], NULL);
        if (d < best) { /* the first of equal ones, as the index breaks ties */
            best = d;
            *best_tri = t;
        }
    }
    return sqrt(best);
}

static void check_against_brute_force(const char *name, const double *xyz, size_t vertex_count,
                                      const uint32_t *tris, size_t tri_count, const double *points,
                                      size_t point_count) {
    surface_index *ix = surface_index_build(xyz, vertex_count, tris, tri_count);
    CHECK(ix != NULL);
    double max_d = 0;
    for (size_t i = 0; i < point_count; i++) {
        size_t t_grid = SIZE_MAX, t_brute;
        double q[3];
        double d_grid = surface_index_query(ix, points + 3 * i, q, &t_grid);
        double d_brute = brute_force(xyz, tris, tri_count, points + 3 * i, &t_brute);
        if (d_grid != d_brute || t_grid != t_brute) {
            fprintf(stderr, "%s: point %zu: grid %.17g (triangle %zu), brute force %.17g (%zu)\n",
                    name, i, d_grid, t_grid, d_brute, t_brute);
            exit(1);
        }
        CHECK_NEAR(sqrt(dist2(points + 3 * i, q)), d_grid, 1e-12 * (1 + d_grid));
        max_d = fmax(max_d, d_grid);
    }
    printf("grid = brute force: %-34s %6zu triangles, %5zu points, all equal (largest distance "
           "%.3g)\n",
           name, tri_count, point_count, max_d);
    surface_index_free(ix);
}

/* A random soup in the unit cube: `count` triangles of about `size`, a few of them huge or
 * degenerate, so cell sizes and multi-cell triangles get exercised. */
static void random_soup(uint64_t *s, size_t count, double size, double **xyz, uint32_t **tris) {
    *xyz = malloc(9 * count * sizeof **xyz);
    *tris = malloc(3 * count * sizeof **tris);
    CHECK(*xyz && *tris);
    for (size_t t = 0; t < count; t++) {
        double *v = *xyz + 9 * t, centre[3], scale = size;
        if (t % 97 == 5)
            scale = 1.0; /* spans much of the cube */
        for (int k = 0; k < 3; k++)
            centre[k] = uniform(s);
        for (int c = 0; c < 3; c++)
            for (int k = 0; k < 3; k++)
                v[3 * c + k] = centre[k] + (uniform(s) - 0.5) * scale;
        if (t % 53 == 7)
            memcpy(v + 3, v, 3 * sizeof *v); /* two corners coincide */
        if (t % 61 == 3)
            for (int k = 0; k < 3; k++)
                v[6 + k] = 0.5 * (v[k] + v[3 + k]); /* collinear */
        for (int c = 0; c < 3; c++)
            (*tris)[3 * t + c] = (uint32_t)(3 * t + (size_t)c);
    }
}

static double *random_points(uint64_t *s, size_t count, double lo, double hi) {
    double *p = malloc(3 * count * sizeof *p);
    CHECK(p);
    for (size_t i = 0; i < 3 * count; i++)
        p[i] = lo + (hi - lo) * uniform(s);
    return p;
}

static void test_grid(void) {
    uint64_t s = 12345;
    const struct {
        const char *name;
        size_t count;
        double size;
    } soups[] = {{"soup of small triangles", 3000, 0.05},
                 {"soup of mid-size triangles", 800, 0.3},
                 {"sparse soup", 40, 0.1},
                 {"one triangle", 1, 0.5}};
    for (size_t i = 0; i < sizeof soups / sizeof *soups; i++) {
        double *xyz;
        uint32_t *tris;
        random_soup(&s, soups[i].count, soups[i].size, &xyz, &tris);
        double *inside = random_points(&s, 1500, -0.1, 1.1);
        double *outside = random_points(&s, 300, -5, 6); /* mostly outside the grid */
        char name[96];
        snprintf(name, sizeof name, "%s, near", soups[i].name);
        check_against_brute_force(name, xyz, 3 * soups[i].count, tris, soups[i].count, inside,
                                  1500);
        snprintf(name, sizeof name, "%s, far", soups[i].name);
        check_against_brute_force(name, xyz, 3 * soups[i].count, tris, soups[i].count, outside,
                                  300);
        free(xyz);
        free(tris);
        free(inside);
        free(outside);
    }

    /* A closed surface with points on both sides of it and at its centre (the farthest the shells
     * ever have to grow from inside), and a flat one (a grid one cell thick). */
    shape_mesh sphere, plane;
    CHECK(shape_sphere(&sphere, 4, 1.0) == 0);
    CHECK(shape_plane(&plane, 30, 20, 0.1) == 0);
    double *pts = random_points(&s, 2000, -1.3, 1.3);
    memset(pts, 0, 3 * sizeof *pts);
    check_against_brute_force("sphere", sphere.xyz, sphere.vertex_count, sphere.indices,
                              sphere.triangle_count, pts, 2000);
    for (size_t i = 0; i < 2000; i++) {
        pts[3 * i] = 3.4 * uniform(&s) - 0.2;
        pts[3 * i + 1] = 2.4 * uniform(&s) - 0.2;
        pts[3 * i + 2] = (uniform(&s) - 0.5) * (i % 2 ? 0.02 : 2.0);
    }
    check_against_brute_force("plane", plane.xyz, plane.vertex_count, plane.indices,
                              plane.triangle_count, pts, 2000);
    free(pts);

    /* Empty index, bad input. */
    surface_index *empty = surface_index_build(NULL, 0, NULL, 0);
    CHECK(empty != NULL);
    const double origin[3] = {0, 0, 0};
    CHECK(isinf(surface_index_query(empty, origin, NULL, NULL)));
    surface_index_free(empty);
    uint32_t bad[3] = {0, 1, (uint32_t)sphere.vertex_count};
    CHECK(surface_index_build(sphere.xyz, sphere.vertex_count, bad, 1) == NULL);
    surface_index_free(NULL);
    shape_free(&sphere);
    shape_free(&plane);
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
    mesh_metrics m;

    /* Identical meshes. */
    CHECK(mesh_metrics_compute(plane.xyz, plane.xyz, plane.vertex_count, plane.indices,
                               plane.triangle_count, &m) == 0);
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
    CHECK(mesh_metrics_compute(moved.xyz, plane.xyz, plane.vertex_count, plane.indices,
                               plane.triangle_count, &m) == 0);
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
    CHECK(mesh_metrics_compute(moved.xyz, plane.xyz, plane.vertex_count, plane.indices,
                               plane.triangle_count, &m) == 0);
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
    CHECK(mesh_metrics_compute(moved.xyz, plane.xyz, plane.vertex_count, plane.indices,
                               plane.triangle_count, &m) == 0);
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
    CHECK(mesh_metrics_compute(turned.xyz, sphere.xyz, sphere.vertex_count, sphere.indices,
                               sphere.triangle_count, &m) == 0);
    printf("sphere turned by 0.7 deg: theta %.12g deg (expect %.12g from the faces' angles to the "
           "axis)\n",
           m.theta, expect);
    CHECK_NEAR(m.theta, expect, 1e-9);
    memcpy(moved.xyz, plane.xyz, 3 * plane.vertex_count * sizeof *plane.xyz);

    /* Bad input. */
    CHECK(mesh_metrics_compute(NULL, plane.xyz, plane.vertex_count, plane.indices,
                               plane.triangle_count, &m) == -1);
    CHECK(mesh_metrics_compute(plane.xyz, plane.xyz, plane.vertex_count, plane.indices, 0, &m) ==
          -1);
    uint32_t bad[3] = {0, 1, (uint32_t)plane.vertex_count};
    CHECK(mesh_metrics_compute(plane.xyz, plane.xyz, plane.vertex_count, bad, 1, &m) == -1);
    moved.xyz[4] = NAN;
    CHECK(mesh_metrics_compute(moved.xyz, plane.xyz, plane.vertex_count, plane.indices,
                               plane.triangle_count, &m) == -1);
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
    mesh_metrics m;
    CHECK(mesh_metrics_compute(result_xyz, truth->positions, truth->vertex_count, truth->triangles,
                               truth->triangle_count, &m) == 0);
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
    printf("meshmetrics.py (script) against mesh_metrics (ours; ev exact), reference filter "
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
        CHECK_STATUS(rsmooth_smooth_reference(
                         RSMOOTH_FLOAT64, noisy->positions, noisy->vertex_count, noisy->triangles,
                         noisy->triangle_count, &p, smoothed, NULL, NULL, NULL, &err),
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

int main(void) {
    test_triangle();
    test_grid();
    test_analytic();
    test_against_script();
    return 0;
}
