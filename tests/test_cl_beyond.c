/* The filters beyond the paper on the OpenCL path equal the double-precision reference path: the
 * bilateral normal filter (1 and 5 rounds, several widths, untiled and tiled) and each influence
 * function, on generated shapes and, when ../shared exists, on Fandisk0.3 and Bunny0.2. Per-vertex
 * deviation in mean edge lengths (max <= 1e-3, as test_cl_vs_reference), confidence within 1e-3;
 * two runs of the OpenCL path are bit-identical. */
#define _POSIX_C_SOURCE 200809L
#include "mesh_shapes.h"
#include "rsmooth.h"
#include "rsmooth_io.h"
#include "test_cl_util.h"

#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define MAX_DEVIATION 1e-3 /* mean edge lengths */

typedef struct mesh_ref {
    const double *xyz;
    size_t vertex_count;
    const uint32_t *indices;
    size_t triangle_count;
} mesh_ref;

typedef struct result {
    double *xyz;
    float *weight, *confidence;
    rsmooth_report report;
} result;

static void result_alloc(result *r, size_t nv) {
    r->xyz = malloc(nv * 3 * sizeof *r->xyz);
    r->weight = malloc(nv * sizeof *r->weight);
    r->confidence = malloc(nv * sizeof *r->confidence);
    CHECK(r->xyz && r->weight && r->confidence);
}

static void result_free(result *r) {
    free(r->xyz);
    free(r->weight);
    free(r->confidence);
}

/* ctx NULL: the reference path. */
static void smooth(rsmooth_context *ctx, const mesh_ref *m, const rsmooth_params *params,
                   result *out) {
    rsmooth_error err;
    if (ctx)
        CHECK_STATUS(rsmooth_smooth(ctx, RSMOOTH_FLOAT64, m->xyz, m->vertex_count, m->indices,
                                    m->triangle_count, params, out->xyz, out->weight,
                                    out->confidence, &out->report, &err),
                     RSMOOTH_OK);
    else
        CHECK_STATUS(rsmooth_smooth_reference(RSMOOTH_FLOAT64, m->xyz, m->vertex_count,
                                              m->indices, m->triangle_count, params, out->xyz,
                                              out->weight, out->confidence, &out->report, &err),
                     RSMOOTH_OK);
}

/* Largest per-vertex distance between two results' positions, in mean edge lengths. */
static double max_deviation(const double *a, const double *b, size_t nv, double edge) {
    double worst = 0;
    for (size_t v = 0; v < nv; v++) {
        double d2 = 0;
        for (int k = 0; k < 3; k++) {
            double d = a[3 * v + k] - b[3 * v + k];
            d2 += d * d;
        }
        worst = fmax(worst, sqrt(d2) / edge);
    }
    return worst;
}

/* Runs both paths (and the OpenCL path again, with a memory budget of `budget` bytes when it is
 * not 0, so that the mesh is tiled), prints how far they are apart and checks it. Returns the
 * reference's largest move, in mean edge lengths, so callers can tell modes apart. */
static double compare(rsmooth_context *ctx, const char *name, const mesh_ref *m,
                      const rsmooth_params *params, uint64_t budget) {
    size_t nv = m->vertex_count;
    result ref, cl, again;
    result_alloc(&ref, nv);
    result_alloc(&cl, nv);
    result_alloc(&again, nv);
    smooth(NULL, m, params, &ref);
    smooth(ctx, m, params, &cl);
    rsmooth_context_set_memory_budget(ctx, budget);
    smooth(ctx, m, params, &again);
    rsmooth_context_set_memory_budget(ctx, 0);

    double edge = ref.report.mean_edge_length;
    double dev = max_deviation(cl.xyz, ref.xyz, nv, edge);
    double moved = max_deviation(ref.xyz, m->xyz, nv, edge);
    double conf = 0, k = 0;
    size_t stayed = 0; /* vertices no facet gave weight to (Tukey can) */
    for (size_t v = 0; v < nv; v++) {
        conf = fmax(conf, fabs((double)cl.confidence[v] - ref.confidence[v]));
        /* k relative to sum a f (= k / confidence): where k is a sliver of it, its relative
         * error is that of a difference of nearly equal numbers */
        double kf = ref.confidence[v] > 0 ? ref.weight[v] / ref.confidence[v] : 0;
        if (kf > 0)
            k = fmax(k, fabs((double)cl.weight[v] - ref.weight[v]) / kf);
        stayed += ref.weight[v] == 0;
    }
    double dev_again = max_deviation(again.xyz, ref.xyz, nv, edge);
    bool same = budget == 0 && memcmp(cl.xyz, again.xyz, nv * 3 * sizeof *cl.xyz) == 0 &&
                memcmp(cl.confidence, again.confidence, nv * sizeof *cl.confidence) == 0;
    printf("%-52s V=%6zu max move %6.3f  deviation max %.3g (tol %.0e)  confidence %.2g  "
           "k/kf %.2g  unmoved %zu  %s",
           name, nv, moved, dev, MAX_DEVIATION, conf, k, stayed,
           budget ? "" : same ? "rerun bit-identical" : "RERUN DIFFERS");
    if (budget)
        printf("%zu tiles: deviation max %.3g", again.report.tiles, dev_again);
    printf("\n");
    CHECK(isfinite(dev));
    CHECK_LE(dev, MAX_DEVIATION);
    CHECK_LE(conf, 1e-3);
    CHECK_LE(k, 1e-3);
    if (budget) {
        CHECK(again.report.tiles >= 2);
        CHECK_LE(dev_again, MAX_DEVIATION);
    } else {
        CHECK(same);
    }
    result_free(&ref);
    result_free(&cl);
    result_free(&again);
    return moved;
}

/* Bilateral normals with 1 and 5 rounds and a few widths, and each influence function. */
static void compare_modes(rsmooth_context *ctx, const char *mesh_name, const mesh_ref *m,
                          bool quick) {
    static const struct {
        double sigma_s, sigma_n;
        int rounds;
    } bilateral[] = {{1, 0.35, 1}, {1, 0.35, 5}, {0.5, 0.2, 5}, {1.5, 0.6, 1}};
    static const struct {
        int influence;
        const char *name;
    } influences[] = {{RSMOOTH_INFLUENCE_GAUSSIAN, "Gaussian"},
                      {RSMOOTH_INFLUENCE_TUKEY, "Tukey"},
                      {RSMOOTH_INFLUENCE_LORENTZIAN, "Lorentzian"},
                      {RSMOOTH_INFLUENCE_HUBER, "Huber"}};
    char name[160];
    rsmooth_params p;
    for (size_t i = 0; i < sizeof bilateral / sizeof *bilateral; i++) {
        if (quick && i != 1)
            continue;
        rsmooth_params_init(&p);
        p.normal_filter = RSMOOTH_NORMALS_BILATERAL;
        p.normal_sigma_s = bilateral[i].sigma_s;
        p.normal_sigma_n = bilateral[i].sigma_n;
        p.normal_iterations = bilateral[i].rounds;
        snprintf(name, sizeof name, "%s, bilateral s=%g t=%g K=%d", mesh_name, p.normal_sigma_s,
                 p.normal_sigma_n, p.normal_iterations);
        compare(ctx, name, m, &p, 0);
    }
    for (size_t i = 0; i < sizeof influences / sizeof *influences; i++) {
        rsmooth_params_init(&p);
        p.influence = influences[i].influence;
        snprintf(name, sizeof name, "%s, %s", mesh_name, influences[i].name);
        compare(ctx, name, m, &p, 0);
        if (quick)
            continue;
        p.predictor = RSMOOTH_PREDICT_CENTROID;
        snprintf(name, sizeof name, "%s, %s, centroid predictor", mesh_name, influences[i].name);
        compare(ctx, name, m, &p, 0);
        rsmooth_params_init(&p);
        p.influence = influences[i].influence;
        p.normal_filter = RSMOOTH_NORMALS_BILATERAL;
        p.sigma_g = 0.2;
        snprintf(name, sizeof name, "%s, %s sg=0.2, bilateral", mesh_name, influences[i].name);
        compare(ctx, name, m, &p, 0);
        /* tiny sigma_g: Tukey gives some vertices no weight at all (they stay), the Gaussian
         * needs its underflow rescue */
        p.sigma_g = 0.03;
        snprintf(name, sizeof name, "%s, %s sg=0.03, bilateral", mesh_name, influences[i].name);
        compare(ctx, name, m, &p, 0);
    }
}

static mesh_ref shape_ref(const shape_mesh *s) {
    return (mesh_ref){s->xyz, s->vertex_count, s->indices, s->triangle_count};
}

static void benchmark_meshes(rsmooth_context *ctx) {
    static const char *const models[] = {"Fandisk0.3", "Bunny0.2"};
    struct stat st;
    char dir[4096];
    snprintf(dir, sizeof dir, "%s/data/benchmark", RSMOOTH_SHARED_DIR);
    if (RSMOOTH_SHARED_DIR[0] == '\0' || stat(dir, &st) != 0) {
        printf("benchmark meshes: %s absent, skipped\n", dir);
        return;
    }
    for (size_t i = 0; i < sizeof models / sizeof *models; i++) {
        char path[4200];
        snprintf(path, sizeof path, "%s/%s/Noisy.obj", dir, models[i]);
        rsmooth_mesh *mesh = NULL;
        rsmooth_error err;
        if (rsmooth_mesh_read_file(path, &mesh, &err) != RSMOOTH_OK) {
            printf("%s: %s, skipped\n", path, err.message);
            continue;
        }
        mesh_ref m = {mesh->positions, mesh->vertex_count, mesh->triangles, mesh->triangle_count};
        compare_modes(ctx, models[i], &m, true);
        rsmooth_mesh_destroy(mesh);
    }
}

int main(void) {
    unsetenv("RSMOOTH_MEMORY_BUDGET");
    rsmooth_context *ctx = open_test_context();
    shape_mesh cube, cyl;
    CHECK(shape_cube(&cube, 16, 1.0) == 0);
    CHECK(shape_add_normal_noise(&cube, 0.3, 1) == 0);
    CHECK(shape_capped_cylinder(&cyl, 1.0, 2.0, 20000) == 0);
    CHECK(shape_add_normal_noise(&cyl, 0.3, 3) == 0);
    mesh_ref cube_ref = shape_ref(&cube), cyl_ref = shape_ref(&cyl);

    compare_modes(ctx, "noisy cube", &cube_ref, false);
    compare_modes(ctx, "noisy cylinder", &cyl_ref, true);

    /* The new modes do change the result (the parameters reach both paths)... */
    rsmooth_params p;
    rsmooth_params_init(&p);
    double edge = shape_mean_edge_length(&cube);
    result paper, other;
    result_alloc(&paper, cube.vertex_count);
    result_alloc(&other, cube.vertex_count);
    smooth(ctx, &cube_ref, &p, &paper);
    p.normal_filter = RSMOOTH_NORMALS_BILATERAL;
    smooth(ctx, &cube_ref, &p, &other);
    double bilateral_change = max_deviation(paper.xyz, other.xyz, cube.vertex_count, edge);
    rsmooth_params_init(&p);
    p.influence = RSMOOTH_INFLUENCE_TUKEY;
    smooth(ctx, &cube_ref, &p, &other);
    double tukey_change = max_deviation(paper.xyz, other.xyz, cube.vertex_count, edge);
    printf("change from the paper's filter: bilateral %.3g, Tukey %.3g mean edge lengths\n",
           bilateral_change, tukey_change);
    CHECK(bilateral_change > 1e-2 && tukey_change > 1e-2);
    result_free(&paper);
    result_free(&other);

    /* ...and tiles reach as far as the bilateral rounds do: 5 rounds spread a facet's
     * dependence 5 bilateral reaches away (here 14 mean edges with the robust reach, beyond the
     * paper's 8.6). A long cylinder, so that tiles with such halos are still a part of it; the
     * budget is about a third of what it needs whole. */
    shape_mesh rod;
    CHECK(shape_capped_cylinder(&rod, 1.0, 6.0, 40000) == 0);
    CHECK(shape_add_normal_noise(&rod, 0.3, 5) == 0);
    mesh_ref rod_ref = shape_ref(&rod);
    rsmooth_params_init(&p);
    p.normal_filter = RSMOOTH_NORMALS_BILATERAL;
    p.normal_sigma_s = 0.5;
    uint64_t budget = (uint64_t)rod.triangle_count * 40;
    compare(ctx, "noisy rod, bilateral s=0.5 K=5, tiled", &rod_ref, &p, budget);
    p.influence = RSMOOTH_INFLUENCE_TUKEY;
    compare(ctx, "noisy rod, bilateral + Tukey, tiled", &rod_ref, &p, budget);
    shape_free(&rod);

    benchmark_meshes(ctx);
    shape_free(&cube);
    shape_free(&cyl);
    rsmooth_context_destroy(ctx);
    printf("ok\n");
    return 0;
}
