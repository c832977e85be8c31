/* Do no harm, on both paths (the reference and the OpenCL device), in every mode (the paper's
 * filter, --auto, --best, --best --auto):
 *  - clean shapes (cubes of 8, 98 and 866 vertices, icospheres, an open grid) and, when ../shared
 *    is there, the clean meshes of data/clean: no triangle turned over; --auto and --best --auto
 *    move no vertex more than 0.25 of its own mean edge length and say there is nothing to remove
 *    (no stage runs); the 8-vertex cube keeps its corners within 1% of its diagonal but under the
 *    paper's filter at its fixed widths (whose rounding is the method's own);
 *  - a vertex of the 866-vertex cube thrown 1e2, 1e4 and 1e6 mean edges off its face: counted as
 *    an outlier, left where it is, and every other vertex ends within 0.05 mean edges of where the
 *    same mode puts it on the clean cube (the oracle: the cube without the stray vertex);
 *  - three icospheres of radius 1e-3, 1 and 1e3 in one mesh: three parts, each sphere's result
 *    the one it gets smoothed alone, bit for bit; at 2562 vertices each keeps its centre within
 *    1% of its radius and its radius within 3%;
 *  - a sphere of points with normals and one point 1e6 away: the far point held, the others
 *    exactly as without it;
 *  - the guard: unguarded, the best mode's stage folds the 8-vertex cube; guarded it does not run.
 * tests/test_fold_guard.c tests the fold guard's pulling back itself. */
#define _DEFAULT_SOURCE /* setenv */
#include "mesh_shapes.h"
#include "rsmooth.h"
#include "rsmooth_io.h"
#include "test_cl_util.h"
#include "test_util.h"

#include <dirent.h>
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

enum mode { PAPER, AUTO, BEST, BEST_AUTO, MODES };
static const char *const mode_name[MODES] = {"paper", "--auto", "--best", "--best --auto"};

typedef struct mesh {
    const char *name;
    size_t vertex_count, triangle_count;
    double *xyz;
    uint32_t *indices;
} mesh;

/* One smoothing: the params the mode gives (auto read on the mesh itself), on ctx or the reference
 * path (ctx NULL). Returns the noise report's kind (auto modes) or -1. */
static int smooth(rsmooth_context *ctx, const mesh *m, enum mode mode, double *out,
                  rsmooth_report *report) {
    rsmooth_params p;
    rsmooth_error err;
    if (mode == BEST || mode == BEST_AUTO)
        rsmooth_params_init_best(&p);
    else
        rsmooth_params_init(&p);
    int kind = -1;
    if (mode == AUTO || mode == BEST_AUTO) {
        rsmooth_noise_report noise;
        noise.struct_size = sizeof noise;
        CHECK_STATUS(rsmooth_params_auto(RSMOOTH_FLOAT64, m->xyz, m->vertex_count, m->indices,
                                         m->triangle_count, &p, &noise, &err),
                     RSMOOTH_OK);
        kind = noise.kind;
    }
    rsmooth_report_init(report);
    rsmooth_status st =
        ctx ? rsmooth_smooth(ctx, RSMOOTH_FLOAT64, m->xyz, m->vertex_count, m->indices,
                             m->triangle_count, &p, out, OUTPUTS(NULL, NULL, report), &err)
            : rsmooth_smooth(NULL, RSMOOTH_FLOAT64, m->xyz, m->vertex_count, m->indices,
                             m->triangle_count, &p, out, OUTPUTS(NULL, NULL, report), &err);
    if (st != RSMOOTH_OK)
        fprintf(stderr, "%s, %s: %s\n", m->name, mode_name[mode], err.message);
    CHECK_STATUS(st, RSMOOTH_OK);
    return kind;
}

static void normal_of(const double *xyz, const uint32_t *tri, double n[3]) {
    const double *a = xyz + 3 * (size_t)tri[0], *b = xyz + 3 * (size_t)tri[1];
    const double *c = xyz + 3 * (size_t)tri[2];
    double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
}

/* Triangles whose normal turned by more than 90 degrees from the input's. */
static size_t turned_over(const mesh *m, const double *out) {
    size_t count = 0;
    for (size_t t = 0; t < m->triangle_count; t++) {
        double a[3], b[3];
        normal_of(m->xyz, m->indices + 3 * t, a);
        normal_of(out, m->indices + 3 * t, b);
        count += a[0] * b[0] + a[1] * b[1] + a[2] * b[2] < 0;
    }
    return count;
}

/* The largest move of a vertex over the mean length of its own edges in the input (vertices on
 * no edge left out). */
static double largest_local_move(const mesh *m, const double *out) {
    double *sum = calloc(m->vertex_count, sizeof *sum);
    double *count = calloc(m->vertex_count, sizeof *count);
    CHECK(sum && count);
    for (size_t t = 0; t < m->triangle_count; t++)
        for (int e = 0; e < 3; e++) {
            uint32_t a = m->indices[3 * t + e], b = m->indices[3 * t + (e + 1) % 3];
            double d = 0;
            for (int k = 0; k < 3; k++)
                d += pow(m->xyz[3 * (size_t)a + k] - m->xyz[3 * (size_t)b + k], 2);
            sum[a] += sqrt(d), sum[b] += sqrt(d);
            count[a]++, count[b]++;
        }
    double worst = 0;
    for (size_t v = 0; v < m->vertex_count; v++) {
        double d = 0;
        for (int k = 0; k < 3; k++)
            d += pow(out[3 * v + k] - m->xyz[3 * v + k], 2);
        if (sum[v] > 0)
            worst = fmax(worst, sqrt(d) / (sum[v] / count[v]));
    }
    free(sum);
    free(count);
    return worst;
}

static double distance(const double *a, const double *b) {
    return sqrt(pow(a[0] - b[0], 2) + pow(a[1] - b[1], 2) + pow(a[2] - b[2], 2));
}

static double diagonal(const mesh *m) {
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t v = 0; v < m->vertex_count; v++)
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], m->xyz[3 * v + k]);
            hi[k] = fmax(hi[k], m->xyz[3 * v + k]);
        }
    return distance(lo, hi);
}

/* A clean mesh in every mode on one path: nothing turned over; the automatic modes move nothing
 * beyond 0.25 local edges and find nothing to remove; --best runs no stage. */
static void check_clean(rsmooth_context *ctx, const mesh *m) {
    double *out = malloc(3 * m->vertex_count * sizeof *out);
    CHECK(out);
    for (int mode = 0; mode < MODES; mode++) {
        rsmooth_report report;
        int kind = smooth(ctx, m, (enum mode)mode, out, &report);
        size_t turned = turned_over(m, out);
        double move = largest_local_move(m, out);
        printf("  %-18s %-14s %-10s turned over %zu of %zu, largest move %.3g local edges%s\n",
               m->name, mode_name[mode], ctx ? "device" : "reference", turned, m->triangle_count,
               move, kind == RSMOOTH_NOISE_NONE ? ", nothing to remove" : "");
        CHECK_EQ_INT(turned, 0);
        if (mode == AUTO || mode == BEST_AUTO) {
            CHECK_EQ_INT(kind, RSMOOTH_NOISE_NONE);
            CHECK_LE(move, 0.25);
            CHECK_EQ_INT(report.stage_cycles, 0);
        }
        if (mode == BEST)
            CHECK_EQ_INT(report.stage_skipped, 1);
    }
    free(out);
}

static mesh from_shape(const char *name, shape_mesh *s) {
    mesh m = {name, s->vertex_count, s->triangle_count, s->xyz, s->indices};
    return m;
}

/* The 8-vertex cube's corners stay within 1% of its diagonal (but under the paper's filter). */
static void check_cube8(rsmooth_context *ctx) {
    shape_mesh s;
    CHECK_EQ_INT(shape_cube(&s, 1, 2.0), 0);
    mesh m = from_shape("cube-8", &s);
    double out[24], diag = diagonal(&m);
    for (int mode = AUTO; mode < MODES; mode++) {
        rsmooth_report report;
        smooth(ctx, &m, (enum mode)mode, out, &report);
        double worst = 0;
        for (size_t v = 0; v < 8; v++)
            worst = fmax(worst, distance(out + 3 * v, m.xyz + 3 * v));
        printf("  cube-8 %-14s %-10s corners moved at most %.3g%% of the diagonal\n",
               mode_name[mode], ctx ? "device" : "reference", 100 * worst / diag);
        CHECK_LE(worst, 0.01 * diag);
    }
    shape_free(&s);
}

/* A stray vertex K mean edges off the 866-vertex cube's +x face. */
static void check_stray(rsmooth_context *ctx) {
    shape_mesh s, clean;
    CHECK_EQ_INT(shape_cube(&s, 12, 2.0), 0);
    CHECK_EQ_INT(shape_copy(&s, &clean), 0);
    double unit = shape_mean_edge_length(&clean);
    size_t stray = 0;
    for (size_t v = 1; v < s.vertex_count; v++) /* the vertex nearest (1, 0, 0) */
        if (distance(s.xyz + 3 * v, (double[]){1, 0, 0}) <
            distance(s.xyz + 3 * stray, (double[]){1, 0, 0}))
            stray = v;
    mesh m = from_shape("stray", &s), c = from_shape("cube-866", &clean);
    size_t n = s.vertex_count;
    double *out = malloc(3 * n * sizeof *out), *oracle = malloc(3 * n * sizeof *oracle);
    CHECK(out && oracle);
    const double k_values[] = {1e2, 1e4, 1e6};
    for (int mode = 0; mode < MODES; mode++) {
        rsmooth_report report;
        smooth(ctx, &c, (enum mode)mode, oracle, &report);
        for (int i = 0; i < 3; i++) {
            memcpy(s.xyz, clean.xyz, 3 * n * sizeof *s.xyz);
            s.xyz[3 * stray] += k_values[i] * unit;
            smooth(ctx, &m, (enum mode)mode, out, &report);
            double worst = 0;
            for (size_t v = 0; v < n; v++)
                if (v != stray)
                    worst = fmax(worst, distance(out + 3 * v, oracle + 3 * v) / unit);
            printf("  stray %.0e edges off, %-14s %-10s outliers %zu, stray moved %.3g, others "
                   "within %.3g edges of the clean cube's result\n",
                   k_values[i], mode_name[mode], ctx ? "device" : "reference", report.outliers,
                   distance(out + 3 * stray, s.xyz + 3 * stray), worst);
            CHECK_EQ_INT(report.outliers, 1);
            CHECK(memcmp(out + 3 * stray, s.xyz + 3 * stray, 3 * sizeof *out) == 0);
            CHECK_LE(worst, 0.05);
        }
    }
    free(out);
    free(oracle);
    shape_free(&s);
    shape_free(&clean);
}

/* Three icospheres of radius 1e-3, 1 and 1e3, side by side in one mesh. */
static void check_parts(rsmooth_context *ctx, int levels) {
    const double radius[3] = {1e-3, 1, 1e3}, centre[3] = {0, 3, 3e3};
    shape_mesh sphere[3];
    size_t nv = 0, nt = 0;
    for (int i = 0; i < 3; i++) {
        CHECK_EQ_INT(shape_sphere(&sphere[i], levels, radius[i]), 0);
        for (size_t v = 0; v < sphere[i].vertex_count; v++)
            sphere[i].xyz[3 * v] += centre[i];
        nv += sphere[i].vertex_count;
        nt += sphere[i].triangle_count;
    }
    mesh all = {"three spheres", nv, nt, malloc(3 * nv * sizeof(double)),
                malloc(3 * nt * sizeof(uint32_t))};
    double *out = malloc(3 * nv * sizeof *out), *alone = malloc(3 * nv * sizeof *alone);
    CHECK(all.xyz && all.indices && out && alone);
    size_t v0 = 0, t0 = 0;
    for (int i = 0; i < 3; i++) {
        memcpy(all.xyz + 3 * v0, sphere[i].xyz, 3 * sphere[i].vertex_count * sizeof(double));
        for (size_t t = 0; t < 3 * sphere[i].triangle_count; t++)
            all.indices[3 * t0 + t] = sphere[i].indices[t] + (uint32_t)v0;
        v0 += sphere[i].vertex_count;
        t0 += sphere[i].triangle_count;
    }
    for (int mode = 0; mode < MODES; mode++) {
        rsmooth_report report;
        smooth(ctx, &all, (enum mode)mode, out, &report);
        CHECK_EQ_INT(report.parts, 3);
        v0 = 0;
        for (int i = 0; i < 3; i++) {
            size_t n = sphere[i].vertex_count;
            mesh one = from_shape("sphere alone", &sphere[i]);
            smooth(ctx, &one, (enum mode)mode, alone, &report);
            double c[3] = {0, 0, 0}, r = 0;
            for (size_t v = 0; v < n; v++)
                for (int k = 0; k < 3; k++)
                    c[k] += out[3 * (v0 + v) + k] / (double)n;
            for (size_t v = 0; v < n; v++)
                r += distance(out + 3 * (v0 + v), c) / (double)n;
            double off = distance(c, (double[]){centre[i], 0, 0}) / radius[i];
            bool same = memcmp(out + 3 * v0, alone, 3 * n * sizeof *out) == 0;
            printf("  %zu-vertex spheres, %-14s %-10s radius %g: centre off %.2g radii, radius "
                   "x %.4f, %s\n",
                   n, mode_name[mode], ctx ? "device" : "reference", radius[i], off, r / radius[i],
                   same ? "as smoothed alone" : "NOT AS ALONE");
            CHECK(same);
            if (levels >= 4) {
                CHECK_LE(off, 0.01);
                CHECK_LE(fabs(r / radius[i] - 1), 0.03);
            }
            v0 += n;
        }
    }
    for (int i = 0; i < 3; i++)
        shape_free(&sphere[i]);
    free(all.xyz);
    free(all.indices);
    free(out);
    free(alone);
}

/* A sphere of points with normals and one point far away. */
static void check_points(rsmooth_context *ctx) {
    shape_mesh s;
    CHECK_EQ_INT(shape_sphere(&s, 4, 1.0), 0);
    size_t n = s.vertex_count + 1;
    double *xyz = malloc(3 * n * sizeof *xyz), *normal = malloc(3 * n * sizeof *normal);
    double *out = malloc(3 * n * sizeof *out), *alone = malloc(3 * n * sizeof *alone);
    CHECK(xyz && normal && out && alone);
    memcpy(xyz, s.xyz, 3 * s.vertex_count * sizeof *xyz);
    memcpy(normal, s.xyz, 3 * s.vertex_count * sizeof *normal); /* a unit sphere's own */
    double far[3] = {1e6, 0, 0};
    memcpy(xyz + 3 * s.vertex_count, far, sizeof far);
    memcpy(normal + 3 * s.vertex_count, (double[]){1, 0, 0}, 3 * sizeof(double));
    rsmooth_error err;
    rsmooth_report report;
    rsmooth_report_init(&report);
    CHECK_STATUS(ctx ? rsmooth_smooth_points(ctx, RSMOOTH_FLOAT64, xyz, normal, n, NULL, out, NULL,
                                             OUTPUTS(NULL, NULL, &report), &err)
                     : rsmooth_smooth_points(NULL, RSMOOTH_FLOAT64, xyz, normal, n, NULL, out, NULL,
                                             OUTPUTS(NULL, NULL, &report), &err),
                 RSMOOTH_OK);
    CHECK_STATUS(ctx ? rsmooth_smooth_points(ctx, RSMOOTH_FLOAT64, xyz, normal, n - 1, NULL, alone,
                                             NULL, NULL, &err)
                     : rsmooth_smooth_points(NULL, RSMOOTH_FLOAT64, xyz, normal, n - 1, NULL, alone,
                                             NULL, NULL, &err),
                 RSMOOTH_OK);
    bool same = memcmp(out, alone, 3 * (n - 1) * sizeof *out) == 0;
    printf("  point sphere and a point 1e6 away, %-10s outliers %zu, the far point %s, the "
           "others %s\n",
           ctx ? "device" : "reference", report.outliers,
           memcmp(out + 3 * (n - 1), far, sizeof far) == 0 ? "held" : "MOVED",
           same ? "as without it" : "NOT AS WITHOUT IT");
    CHECK_EQ_INT(report.outliers, 1);
    CHECK(memcmp(out + 3 * (n - 1), far, sizeof far) == 0);
    CHECK(same);
    free(xyz);
    free(normal);
    free(out);
    free(alone);
    shape_free(&s);
}

/* The best mode unguarded on the 8-vertex cube: its stage, with nothing to remove, folds the
 * cube; guarded, the stage does not run and nothing turns over. (tests/test_fold_guard.c tests
 * the guard's pulling back itself.) */
static void check_guard(rsmooth_context *ctx) {
    shape_mesh s;
    CHECK_EQ_INT(shape_cube(&s, 1, 2.0), 0);
    mesh m = from_shape("cube-8", &s);
    double out[24];
    rsmooth_params p;
    rsmooth_params_init_best(&p);
    size_t turned[2];
    int skipped[2];
    rsmooth_error err;
    for (int guard = 0; guard <= 1; guard++) {
        p.guard = guard;
        rsmooth_report report;
        rsmooth_report_init(&report);
        CHECK_STATUS(
            ctx ? rsmooth_smooth(ctx, RSMOOTH_FLOAT64, m.xyz, m.vertex_count, m.indices,
                                 m.triangle_count, &p, out, OUTPUTS(NULL, NULL, &report), &err)
                : rsmooth_smooth(NULL, RSMOOTH_FLOAT64, m.xyz, m.vertex_count, m.indices,
                                 m.triangle_count, &p, out, OUTPUTS(NULL, NULL, &report), &err),
            RSMOOTH_OK);
        turned[guard] = turned_over(&m, out);
        skipped[guard] = report.stage_skipped;
    }
    printf("  cube-8, --best %-10s turned over: %zu unguarded (stage run), %zu guarded (stage "
           "%s)\n",
           ctx ? "device" : "reference", turned[0], turned[1], skipped[1] ? "skipped" : "RUN");
    CHECK(turned[0] > 0);
    CHECK_EQ_INT(skipped[0], 0);
    CHECK_EQ_INT(turned[1], 0);
    CHECK_EQ_INT(skipped[1], 1);
    shape_free(&s);
}

/* The clean meshes of ../shared/data/clean, when there: every `stride`-th by name. */
static void check_shared_clean(rsmooth_context *ctx, int stride) {
    char dir[4200];
    snprintf(dir, sizeof dir, "%s/data/clean", RSMOOTH_SHARED_DIR);
    DIR *d = RSMOOTH_SHARED_DIR[0] ? opendir(dir) : NULL;
    if (!d) {
        printf("clean meshes: %s absent, skipped\n", dir);
        return;
    }
    char names[64][256];
    int count = 0;
    struct dirent *e;
    while ((e = readdir(d)) && count < 64)
        if (e->d_name[0] != '.' && strlen(e->d_name) < sizeof names[0])
            memcpy(names[count++], e->d_name, strlen(e->d_name) + 1);
    closedir(d);
    qsort(names, (size_t)count, sizeof names[0], (int (*)(const void *, const void *))strcmp);
    for (int i = 0; i < count; i += stride) {
        char path[4500];
        snprintf(path, sizeof path, "%.4200s/%.255s", dir, names[i]);
        rsmooth_mesh *file = NULL;
        rsmooth_error err;
        CHECK_STATUS(rsmooth_mesh_read_file(path, &file, &err), RSMOOTH_OK);
        mesh m = {names[i], file->vertex_count, file->triangle_count, file->positions,
                  file->triangles};
        check_clean(ctx, &m);
        rsmooth_mesh_destroy(file);
    }
}

static void all_checks(rsmooth_context *ctx) {
    bool small = test_small();
    printf("%s path\n", ctx ? "the device's" : "the reference");
    shape_mesh shapes[6];
    const char *names[6] = {"cube-8",        "cube-98",        "cube-866",
                            "icosphere-642", "icosphere-2562", "open grid 30x30"};
    CHECK_EQ_INT(shape_cube(&shapes[0], 1, 2.0), 0);
    CHECK_EQ_INT(shape_cube(&shapes[1], 4, 2.0), 0);
    CHECK_EQ_INT(shape_cube(&shapes[2], 12, 2.0), 0);
    CHECK_EQ_INT(shape_sphere(&shapes[3], 3, 1.0), 0);
    CHECK_EQ_INT(shape_sphere(&shapes[4], 4, 1.0), 0);
    CHECK_EQ_INT(shape_plane(&shapes[5], 30, 30, 0.1), 0);
    for (int i = 0; i < 6; i++) {
        mesh m = from_shape(names[i], &shapes[i]);
        check_clean(ctx, &m);
        shape_free(&shapes[i]);
    }
    check_cube8(ctx);
    check_stray(ctx);
    check_parts(ctx, 3);
    check_parts(ctx, 4);
    check_points(ctx);
    check_guard(ctx);
    check_shared_clean(ctx, small ? 7 : 1);
}

int main(void) {
    all_checks(NULL);
    rsmooth_context *ctx = open_test_context();
    all_checks(ctx);
    rsmooth_context_destroy(ctx);
    printf("do no harm: all checks passed\n");
    return 0;
}
