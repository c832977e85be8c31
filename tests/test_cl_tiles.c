/* Spatial tiles (lib/opencl/tiles.c): with a memory budget far below what a mesh needs, the OpenCL
 * path cuts it into tiles and must give the untiled run's positions bit for bit (grid cells count
 * from a lattice fixed in space and the kernels' differences do not depend on which vertices share
 * a block) and agree with the double-precision reference path (max deviation <= 1e-3 mean edge
 * lengths, as for untiled runs); a budget too small
 * for any tile fails cleanly with the caller's arrays untouched; RSMOOTH_MEMORY_BUDGET is read. */
#define _POSIX_C_SOURCE 200809L
#include "mesh_shapes.h"
#include "rsmooth.h"
#include "test_cl_util.h"

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_DEVIATION 1e-3 /* mean edge lengths */

typedef struct run {
    double *xyz;
    float *weight, *confidence;
    rsmooth_report report;
} run;

static void run_alloc(run *r, size_t nv) {
    r->xyz = malloc(nv * 3 * sizeof *r->xyz);
    r->weight = malloc(nv * sizeof *r->weight);
    r->confidence = malloc(nv * sizeof *r->confidence);
    CHECK(r->xyz && r->weight && r->confidence);
}

static void run_free(run *r) {
    free(r->xyz);
    free(r->weight);
    free(r->confidence);
}

/* Progress must rise monotonically to 1 across the tiles. */
typedef struct progress_log {
    double last;
    int calls, backwards;
} progress_log;

static void log_progress(void *user, double fraction) {
    progress_log *log = user;
    if (fraction < log->last - 1e-12)
        log->backwards++;
    log->last = fraction;
    log->calls++;
}

/* Largest per-vertex distance between two results, in mean edge lengths. */
static double max_deviation(const run *a, const run *b, size_t nv, double edge) {
    double worst = 0;
    for (size_t v = 0; v < nv; v++) {
        double d2 = 0;
        for (int k = 0; k < 3; k++) {
            double d = a->xyz[3 * v + k] - b->xyz[3 * v + k];
            d2 += d * d;
        }
        worst = fmax(worst, sqrt(d2) / edge);
    }
    return worst;
}

static double max_float_diff(const float *a, const float *b, size_t n, bool relative) {
    double worst = 0;
    for (size_t i = 0; i < n; i++) {
        double d = fabs((double)a[i] - b[i]);
        worst = fmax(worst, relative ? d / fmax(1e-30, fabs((double)b[i])) : d);
    }
    return worst;
}

/* Untiled, tiled with a budget far below the need, and the reference: all agree. */
static void check_shape(rsmooth_context *ctx, const char *name, const shape_mesh *m,
                        const rsmooth_params *base) {
    size_t nv = m->vertex_count, nt = m->triangle_count;
    run whole, tiled, ref;
    run_alloc(&whole, nv);
    run_alloc(&tiled, nv);
    run_alloc(&ref, nv);
    rsmooth_error err;
    rsmooth_params params = *base;
    CHECK_STATUS(rsmooth_smooth(ctx, RSMOOTH_FLOAT64, m->xyz, nv, m->indices, nt, &params,
                                whole.xyz, OUTPUTS(whole.weight, whole.confidence, &whole.report),
                                &err),
                 RSMOOTH_OK);
    CHECK(whole.report.tiles == 1);

    uint64_t budget = (uint64_t)nt * 96 / 6;
    rsmooth_context *budgeted = open_test_context_budget(budget);
    CHECK(context_info(budgeted).memory_budget == budget);
    progress_log log = {0, 0, 0};
    params.progress = log_progress;
    params.progress_user = &log;
    CHECK_STATUS(rsmooth_smooth(budgeted, RSMOOTH_FLOAT64, m->xyz, nv, m->indices, nt, &params,
                                tiled.xyz, OUTPUTS(tiled.weight, tiled.confidence, &tiled.report),
                                &err),
                 RSMOOTH_OK);
    rsmooth_context_destroy(budgeted);
    CHECK_STATUS(rsmooth_smooth(NULL, RSMOOTH_FLOAT64, m->xyz, nv, m->indices, nt, base, ref.xyz,
                                OUTPUTS(ref.weight, ref.confidence, &ref.report), &err),
                 RSMOOTH_OK);
    double edge = ref.report.mean_edge_length;
    double vs_whole = max_deviation(&tiled, &whole, nv, edge);
    double vs_ref = max_deviation(&tiled, &ref, nv, edge);
    double conf = max_float_diff(tiled.confidence, ref.confidence, nv, false);
    double k = max_float_diff(tiled.weight, ref.weight, nv, true);
    printf("%-34s V=%6zu F=%6zu budget %7llu B: %3zu tiles, %5.2fx the pairs; deviation from "
           "untiled %.2g, from reference %.2g (tol %.0e); confidence %.2g, k rel %.2g; "
           "progress %d calls, last %.3f\n",
           name, nv, nt, (unsigned long long)budget, tiled.report.tiles,
           (double)tiled.report.pairs_robust / (double)whole.report.pairs_robust, vs_whole, vs_ref,
           MAX_DEVIATION, conf, k, log.calls, log.last);
    CHECK(tiled.report.tiles >= 4);
    CHECK(tiled.report.pairs_robust > whole.report.pairs_robust); /* halos overlap */
    CHECK(vs_whole == 0);
    CHECK_LE(vs_ref, MAX_DEVIATION);
    CHECK_LE(conf, 1e-3);
    CHECK_LE(k, 1e-3);
    CHECK(log.calls > 0 && log.backwards == 0 && log.last == 1.0);
    run_free(&whole);
    run_free(&tiled);
    run_free(&ref);
}

/* A budget below one vertex's halo: a clear failure, and nothing written. */
static void check_too_small(rsmooth_context *ctx, const shape_mesh *m) {
    size_t nv = m->vertex_count;
    float *out = malloc(nv * 3 * sizeof *out), *xyz = malloc(nv * 3 * sizeof *xyz);
    CHECK(out && xyz);
    for (size_t i = 0; i < 3 * nv; i++) {
        xyz[i] = (float)m->xyz[i];
        out[i] = -12345.0f;
    }
    (void)ctx;
    rsmooth_context *tiny = open_test_context_budget(1024);
    rsmooth_error err;
    CHECK_STATUS(rsmooth_smooth(tiny, RSMOOTH_FLOAT32, xyz, nv, m->indices, m->triangle_count, NULL,
                                out, NULL, &err),
                 RSMOOTH_ERROR_OUT_OF_MEMORY);
    printf("budget 1024 B: %s\n", err.message);
    CHECK(strstr(err.message, "budget") != NULL);
    for (size_t i = 0; i < 3 * nv; i++)
        CHECK(out[i] == -12345.0f);
    rsmooth_context_destroy(tiny);
    free(out);
    free(xyz);
}

/* RSMOOTH_MEMORY_BUDGET sets the budget at creation; junk or zero there is refused by name. */
static void check_environment(void) {
    rsmooth_context *ctx = NULL;
    rsmooth_error err;
    setenv("RSMOOTH_MEMORY_BUDGET", "3M", 1);
    CHECK_STATUS(rsmooth_context_create(NULL, &ctx, &err), RSMOOTH_OK);
    CHECK(context_info(ctx).memory_budget == 3u << 20);
    rsmooth_context_destroy(ctx);
    /* junk, and a budget of nothing (as the command refuses --memory-budget 0) */
    static const char *const refused[] = {"lots", "0", "0M", "-5M", "12Q"};
    for (size_t i = 0; i < sizeof refused / sizeof *refused; i++) {
        setenv("RSMOOTH_MEMORY_BUDGET", refused[i], 1);
        CHECK_STATUS(rsmooth_context_create(NULL, &ctx, &err), RSMOOTH_ERROR_INVALID_ARGUMENT);
        CHECK(ctx == NULL && strstr(err.message, "RSMOOTH_MEMORY_BUDGET") != NULL);
        printf("RSMOOTH_MEMORY_BUDGET=%s: %s\n", refused[i], err.message);
    }
    /* the caller's option wins over the environment */
    setenv("RSMOOTH_MEMORY_BUDGET", "3M", 1);
    rsmooth_context_options options = {.struct_size = sizeof options, .memory_budget = 5u << 20};
    CHECK_STATUS(rsmooth_context_create(&options, &ctx, &err), RSMOOTH_OK);
    CHECK(context_info(ctx).memory_budget == 5u << 20);
    rsmooth_context_destroy(ctx);
    unsetenv("RSMOOTH_MEMORY_BUDGET");
    /* every variable with a fixed form is checked when a context is made, and named; before,
     * RSMOOTH_STAGE_PRECISION=half ran in double without a word */
    static const char *const wrong[][2] = {{"RSMOOTH_STAGE_PRECISION", "half"},
                                           {"RSMOOTH_STAGE", "gpu"},
                                           {"RSMOOTH_LANES", "5"},
                                           {"RSMOOTH_CELLS_PER_REACH", "9"},
                                           {"RSMOOTH_DEVICE_GRID", "yes"},
                                           {"RSMOOTH_HOST_THREADS", "many"}};
    for (size_t i = 0; i < sizeof wrong / sizeof *wrong; i++) {
        setenv(wrong[i][0], wrong[i][1], 1);
        CHECK_STATUS(rsmooth_context_create(NULL, &ctx, &err), RSMOOTH_ERROR_INVALID_ARGUMENT);
        CHECK(ctx == NULL && strstr(err.message, wrong[i][0]) != NULL);
        printf("%s=%s: %s\n", wrong[i][0], wrong[i][1], err.message);
        unsetenv(wrong[i][0]);
    }
}

int main(void) {
    unsetenv("RSMOOTH_MEMORY_BUDGET");
    rsmooth_context *ctx = open_test_context();
    shape_mesh cylinder, soup;
    CHECK(shape_capped_cylinder(&cylinder, 1.0, 1.5, 30000) == 0);
    CHECK(shape_add_normal_noise(&cylinder, 0.3, 7) == 0);
    CHECK(shape_unindex(&cylinder, &soup) == 0);

    rsmooth_params params;
    rsmooth_params_init(&params);
    check_shape(ctx, "cylinder (2, 0.5)", &cylinder, &params);
    params.sigma_f = 3;
    params.sigma_g = INFINITY;
    params.mollify = 0;
    check_shape(ctx, "cylinder (3, inf), no mollification", &cylinder, &params);
    rsmooth_params_init(&params);
    check_shape(ctx, "unindexed soup (2, 0.5)", &soup, &params);
    /* stray vertices far from every facet make tiles with no facet at all: they stay put */
    shape_mesh stray;
    CHECK(shape_copy(&cylinder, &stray) == 0);
    size_t first = stray.vertex_count;
    stray.vertex_count += 8;
    stray.xyz = realloc(stray.xyz, stray.vertex_count * 3 * sizeof *stray.xyz);
    CHECK(stray.xyz);
    for (size_t v = first; v < stray.vertex_count; v++) {
        stray.xyz[3 * v] = 100.0 * (double)(v - first + 1);
        stray.xyz[3 * v + 1] = -50.0;
        stray.xyz[3 * v + 2] = 3.0;
    }
    check_shape(ctx, "cylinder and 8 far stray vertices", &stray, &params);
    shape_free(&stray);
    check_too_small(ctx, &cylinder);
    rsmooth_context_destroy(ctx);
    check_environment();
    shape_free(&cylinder);
    shape_free(&soup);
    printf("ok\n");
    return 0;
}
