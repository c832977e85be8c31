/* Repeated passes with float32 positions: every pass reads and writes double inside, so a float32
 * caller gets the float64 caller's result on the same values (rounded once to float32), on the
 * reference path and the OpenCL path, and reruns give the same bits. Before this was fixed the
 * first pass of a float32 call wrote floats where the second read doubles: garbage positions,
 * vertices thrown ~1e6 edge lengths away and results that changed from run to run. The oracle is
 * the float64 call, which never took that route. */
#include "mesh_shapes.h"
#include "rsmooth.h"
#include "test_cl_util.h"

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Largest per-vertex distance between a float32 and a float64 result, in edge lengths. */
static double deviation(const float *a, const double *b, size_t nv, double edge) {
    double worst = 0;
    for (size_t v = 0; v < nv; v++) {
        double d2 = 0;
        for (int k = 0; k < 3; k++) {
            double d = (double)a[3 * v + k] - b[3 * v + k];
            d2 += d * d;
        }
        worst = fmax(worst, sqrt(d2) / edge);
    }
    return worst;
}

static void run(rsmooth_context *ctx, rsmooth_scalar scalar, const void *in, const shape_mesh *m,
                const rsmooth_params *p, void *out) {
    rsmooth_error err;
    if (ctx)
        CHECK_STATUS(rsmooth_smooth(ctx, scalar, in, m->vertex_count, m->indices, m->triangle_count,
                                    p, out, NULL, &err),
                     RSMOOTH_OK);
    else
        CHECK_STATUS(rsmooth_smooth(NULL, scalar, in, m->vertex_count, m->indices,
                                    m->triangle_count, p, out, NULL, &err),
                     RSMOOTH_OK);
}

static void check_passes(rsmooth_context *ctx, const char *path, const shape_mesh *m,
                         const char *name, const rsmooth_params *p) {
    size_t nv = m->vertex_count;
    float *in32 = calloc(nv * 3, sizeof *in32), *out32 = malloc(nv * 3 * sizeof *out32);
    float *again = malloc(nv * 3 * sizeof *again);
    double *in64 = calloc(nv * 3, sizeof *in64), *out64 = malloc(nv * 3 * sizeof *out64);
    if (!in32 || !out32 || !again || !in64 || !out64) {
        fprintf(stderr, "passes_scalar: out of memory\n");
        exit(1);
    }
    for (size_t i = 0; i < 3 * nv; i++) {
        in32[i] = (float)m->xyz[i];
        in64[i] = in32[i]; /* the same values, so only the scalar type differs */
    }
    run(ctx, RSMOOTH_FLOAT64, in64, m, p, out64);
    run(ctx, RSMOOTH_FLOAT32, in32, m, p, out32);
    run(ctx, RSMOOTH_FLOAT32, in32, m, p, again);
    double edge = shape_mean_edge_length(m);
    double dev = deviation(out32, out64, nv, edge);
    bool same = memcmp(out32, again, nv * 3 * sizeof *out32) == 0;
    printf("%-10s %-32s float32 vs float64: %.3g edge lengths (tol 1e-5), rerun %s\n", path, name,
           dev, same ? "bit-identical" : "DIFFERS");
    CHECK_LE(dev, 1e-5);
    CHECK(same);
    free(in32);
    free(out32);
    free(again);
    free(in64);
    free(out64);
}

int main(void) {
    rsmooth_context *ctx = open_test_context();
    shape_mesh cube, unit;
    CHECK(shape_cube(&cube, 20, 20.0) == 0); /* a cube of side 20: the sizes the bug hid in */
    CHECK(shape_add_normal_noise(&cube, 0.3, 11) == 0);
    CHECK(shape_cube(&unit, 12, 1.0) == 0); /* and of side 1 */
    CHECK(shape_add_normal_noise(&unit, 0.3, 5) == 0);
    rsmooth_params p;
    for (int path = 0; path < 2; path++) {
        rsmooth_context *on = path ? ctx : NULL;
        const char *where = path ? "opencl" : "reference";
        rsmooth_params_init(&p);
        p.passes = 2;
        check_passes(on, where, &cube, "cube 20, 2 passes", &p);
        check_passes(on, where, &unit, "cube 1, 2 passes", &p);
        p.passes = 3;
        p.pass_confidence = 0.9;
        check_passes(on, where, &unit, "cube 1, 3 passes, confidence 0.9", &p);
        rsmooth_params_init_best(&p);
        p.passes = 2;
        check_passes(on, where, &unit, "cube 1, best with 2 passes", &p);
    }
    rsmooth_context_destroy(ctx);
    shape_free(&cube);
    shape_free(&unit);
    printf("passes_scalar: ok\n");
    return 0;
}
