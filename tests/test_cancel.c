/* progress_cancel: a callback that never asks to stop changes nothing (bit for bit against a run
 * without it) and sees fractions that rise to 1; one that asks to stop after its k-th report ends
 * the call with RSMOOTH_ERROR_CANCELLED at once (no report after it), on every path: reference
 * and OpenCL, one pass and several, the bilateral normal filter, the best mode's normal update
 * stage (reported, and stoppable, after each of its repeats), spatial tiles, point clouds. */
#include "mesh_shapes.h"
#include "rsmooth.h"
#include "test_cl_util.h"
#include "test_util.h"

#include <string.h>

typedef struct cancel_log {
    int calls;       /* progress_cancel reports */
    int plain_calls; /* plain progress reports */
    int stop_at;     /* ask to stop at this report (0: never) */
    double last;
    int backwards;
    int after_stop; /* reports after the one that asked to stop */
} cancel_log;

static int on_report(void *user, double fraction) {
    cancel_log *log = user;
    if (log->stop_at && log->calls >= log->stop_at)
        log->after_stop++;
    log->calls++;
    if (fraction < log->last || fraction < 0 || fraction > 1) {
        fprintf(stderr, "report %d: %.17g after %.17g\n", log->calls, fraction, log->last);
        log->backwards++;
    }
    log->last = fraction;
    return log->stop_at && log->calls >= log->stop_at;
}

static void on_plain_report(void *user, double fraction) {
    (void)fraction;
    ((cancel_log *)user)->plain_calls++;
}

typedef rsmooth_status (*run_fn)(rsmooth_context *ctx, const shape_mesh *m, const rsmooth_params *p,
                                 double *out, rsmooth_error *err);

static rsmooth_status run_reference(rsmooth_context *ctx, const shape_mesh *m,
                                    const rsmooth_params *p, double *out, rsmooth_error *err) {
    (void)ctx;
    return rsmooth_smooth(NULL, RSMOOTH_FLOAT64, m->xyz, m->vertex_count, m->indices,
                          m->triangle_count, p, out, NULL, err);
}

static rsmooth_status run_opencl(rsmooth_context *ctx, const shape_mesh *m, const rsmooth_params *p,
                                 double *out, rsmooth_error *err) {
    return rsmooth_smooth(ctx, RSMOOTH_FLOAT64, m->xyz, m->vertex_count, m->indices,
                          m->triangle_count, p, out, NULL, err);
}

/* Points: the mesh's vertices with its vertex normals. */
static const double *point_normals;
static rsmooth_status run_points(rsmooth_context *ctx, const shape_mesh *m, const rsmooth_params *p,
                                 double *out, rsmooth_error *err) {
    (void)ctx;
    return rsmooth_smooth_points(NULL, RSMOOTH_FLOAT64, m->xyz, point_normals, m->vertex_count, p,
                                 out, NULL, NULL, err);
}

static void check_path(const char *name, run_fn run, rsmooth_context *ctx, const shape_mesh *m,
                       const rsmooth_params *base) {
    size_t n = 3 * m->vertex_count;
    double *plain = malloc(n * sizeof *plain), *watched = malloc(n * sizeof *watched);
    CHECK(plain && watched);
    rsmooth_error err;
    CHECK_STATUS(run(ctx, m, base, plain, &err), RSMOOTH_OK);

    /* Watched, never stopped: the same result, reports rising to 1, both callbacks called. */
    rsmooth_params p = *base;
    cancel_log log = {0, 0, 0, 0, 0, 0};
    p.progress = on_plain_report;
    p.progress_cancel = on_report;
    p.progress_user = &log;
    CHECK_STATUS(run(ctx, m, &p, watched, &err), RSMOOTH_OK);
    CHECK(memcmp(plain, watched, n * sizeof *plain) == 0);
    CHECK(log.calls >= 3);
    CHECK_EQ_INT(log.plain_calls, log.calls);
    CHECK_EQ_INT(log.backwards, 0);
    CHECK_NEAR(log.last, 1.0, 0);
    int reports = log.calls;

    /* Stopped at the first, a middle and the next-to-last report. */
    int stops[3] = {1, reports / 2, reports - 1};
    for (int s = 0; s < 3; s++) {
        cancel_log stop = {0, 0, stops[s], 0, 0, 0};
        p.progress = NULL;
        p.progress_user = &stop;
        rsmooth_status st = run(ctx, m, &p, watched, &err);
        CHECK_STATUS(st, RSMOOTH_ERROR_CANCELLED);
        CHECK_EQ_INT(err.status, RSMOOTH_ERROR_CANCELLED);
        CHECK(strstr(err.message, "cancelled") != NULL);
        CHECK_EQ_INT(stop.calls, stops[s]);
        CHECK_EQ_INT(stop.after_stop, 0);
    }
    /* The call after a cancelled one is whole again. */
    CHECK_STATUS(run(ctx, m, base, watched, &err), RSMOOTH_OK);
    CHECK(memcmp(plain, watched, n * sizeof *plain) == 0);
    printf("%-40s %3d reports; stopped at 1, %d and %d\n", name, reports, stops[1], stops[2]);
    free(plain);
    free(watched);
}

int main(void) {
    shape_mesh m, small;
    CHECK(shape_sphere(&m, 5, 1.0) == 0); /* 10242 vertices: several reference reports */
    CHECK(shape_add_normal_noise(&m, 0.2 * shape_mean_edge_length(&m), 7) == 0);
    /* the best mode's runs, nine tenths of the time under the sanitizers (test_small), there on
     * 2562 vertices: still 7 reference and 14 OpenCL reports */
    CHECK(shape_sphere(&small, 4, 1.0) == 0);
    CHECK(shape_add_normal_noise(&small, 0.2 * shape_mean_edge_length(&small), 7) == 0);
    const shape_mesh *best_mesh = test_small() ? &small : &m;
    double *normals = malloc(3 * m.vertex_count * sizeof *normals);
    CHECK(normals && shape_vertex_normals(&m, normals) == 0);
    point_normals = normals;

    rsmooth_params paper, best;
    rsmooth_params_init(&paper);
    rsmooth_params_init_best(&best);
    CHECK_EQ_INT(paper.progress_cancel == NULL, 1);
    check_path("reference, paper", run_reference, NULL, &m, &paper);
    check_path("reference, best (stage, 1 pass)", run_reference, NULL, best_mesh, &best);
    check_path("points, best", run_points, NULL, &m, &best);

    /* A status of its own, with text. */
    CHECK(strcmp(rsmooth_status_str(RSMOOTH_ERROR_CANCELLED), "cancelled") == 0);

    rsmooth_context *ctx = open_test_context();
    check_path("OpenCL, paper", run_opencl, ctx, &m, &paper);
    check_path("OpenCL, best (stage, 1 pass)", run_opencl, ctx, best_mesh, &best);
    rsmooth_context_destroy(ctx);
    ctx = open_test_context_budget(1u << 20); /* tiles */
    rsmooth_report report;
    rsmooth_error err;
    double *out = malloc(3 * m.vertex_count * sizeof *out);
    CHECK(out);
    CHECK_STATUS(rsmooth_smooth(ctx, RSMOOTH_FLOAT64, m.xyz, m.vertex_count, m.indices,
                                m.triangle_count, &paper, out, OUTPUTS(NULL, NULL, &report), &err),
                 RSMOOTH_OK);
    CHECK(report.tiles > 1);
    check_path("OpenCL, paper, tiled", run_opencl, ctx, &m, &paper);
    free(out);
    rsmooth_context_destroy(ctx);
    free(normals);
    shape_free(&m);
    shape_free(&small);
    printf("cancel: all checks passed\n");
    return 0;
}
