/* The OpenCL path equals the double-precision reference path: per-vertex deviation in mean edge
 * lengths (max <= 1e-3), on generated shapes and, when ../shared exists, on every benchmark mesh.
 */
#include "mesh_shapes.h"
#include "rsmooth.h"
#include "rsmooth_io.h"
#include "test_benchmark.h"
#include "test_cl_util.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_DEVIATION 1e-3 /* mean edge lengths */

static int compare_double(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Runs both paths, prints max and median deviation, checks them and the confidence. */
static void compare(rsmooth_context *ctx, const char *name, const double *xyz, size_t nv,
                    const uint32_t *idx, size_t nt, const rsmooth_params *params) {
    double *ref = malloc(nv * 3 * sizeof *ref), *cl = malloc(nv * 3 * sizeof *cl);
    float *ref_conf = malloc(nv * sizeof(float)), *cl_conf = malloc(nv * sizeof(float));
    float *ref_k = malloc(nv * sizeof(float)), *cl_k = malloc(nv * sizeof(float));
    double *dev = malloc(nv * sizeof *dev);
    CHECK(ref && cl && ref_conf && cl_conf && ref_k && cl_k && dev);
    rsmooth_report rr, rc;
    rsmooth_error err;
    CHECK_STATUS(rsmooth_smooth(NULL, RSMOOTH_FLOAT64, xyz, nv, idx, nt, params, ref,
                                OUTPUTS(ref_k, ref_conf, &rr), &err),
                 RSMOOTH_OK);
    CHECK_STATUS(rsmooth_smooth(ctx, RSMOOTH_FLOAT64, xyz, nv, idx, nt, params, cl,
                                OUTPUTS(cl_k, cl_conf, &rc), &err),
                 RSMOOTH_OK);
    double edge = rr.mean_edge_length, max_conf = 0, max_k = 0, moved = 0;
    for (size_t v = 0; v < nv; v++) {
        double d2 = 0, m2 = 0;
        for (int k = 0; k < 3; k++) {
            double d = cl[3 * v + k] - ref[3 * v + k], m = ref[3 * v + k] - xyz[3 * v + k];
            d2 += d * d;
            m2 += m * m;
        }
        dev[v] = sqrt(d2) / edge;
        moved += sqrt(m2) / edge;
        max_conf = fmax(max_conf, fabs((double)cl_conf[v] - ref_conf[v]));
        max_k = fmax(max_k, fabs((double)cl_k[v] - ref_k[v]) / fmax(1e-30, fabs(ref_k[v])));
    }
    qsort(dev, nv, sizeof *dev, compare_double);
    printf("%-40s V=%7zu F=%7zu  mean move %.4f  deviation max %.3g median %.3g (tol %.0e)  "
           "confidence max diff %.2g  k max rel diff %.2g\n",
           name, nv, nt, moved / (double)nv, dev[nv - 1], dev[nv / 2], MAX_DEVIATION, max_conf,
           max_k);
    CHECK(isfinite(dev[nv - 1]));
    CHECK_LE(dev[nv - 1], MAX_DEVIATION);
    CHECK_LE(max_conf, 1e-3);
    /* k is a sum of weights: a facet exactly at the cutoff may fall on either side of it in
     * float32 and add up to e^-cutoff^2/2 of its area to k, a relative change that can reach a
     * few 1e-3 where k is small (the positions still agree to 1e-4) */
    CHECK_LE(max_k, 1e-2);
    free(ref);
    free(cl);
    free(ref_conf);
    free(cl_conf);
    free(ref_k);
    free(cl_k);
    free(dev);
}

static void compare_shape(rsmooth_context *ctx, const char *name, const shape_mesh *m,
                          const rsmooth_params *params) {
    compare(ctx, name, m->xyz, m->vertex_count, m->indices, m->triangle_count, params);
}

static void benchmark_meshes(rsmooth_context *ctx) {
    static const char *const models[] = {"Fandisk0.3", "Block0.4", "Bunny0.2", "SharpSphere0.3",
                                         "Twelve0.5Impulsive"};
    char dir[4096];
    if (!benchmark_dir(dir, sizeof dir))
        return;
    for (size_t i = 0; i < sizeof models / sizeof *models; i++) {
        if (test_small() && strcmp(models[i], "Bunny0.2") == 0)
            continue; /* under the sanitizers: 35k vertices, the others' paths again */
        rsmooth_mesh *mesh = benchmark_read(dir, models[i], "Noisy.obj");
        if (!mesh)
            continue;
        const double settings[][2] = {{2, 0.5}, {1.5, 0.7}, {4, 1}};
        for (size_t s = 0; s < sizeof settings / sizeof *settings; s++) {
            rsmooth_params p;
            rsmooth_params_init(&p);
            p.sigma_f = settings[s][0];
            p.sigma_g = settings[s][1];
            char name[128];
            snprintf(name, sizeof name, "%s sf=%g sg=%g", models[i], p.sigma_f, p.sigma_g);
            compare(ctx, name, mesh->positions, mesh->vertex_count, mesh->triangles,
                    mesh->triangle_count, &p);
        }
        rsmooth_mesh_destroy(mesh);
    }
}

int main(void) {
    rsmooth_context *ctx = open_test_context();
    rsmooth_params p;
    rsmooth_params_init(&p);

    shape_mesh cube, sphere, cyl;
    CHECK(shape_cube(&cube, 16, 1.0) == 0);
    CHECK(shape_add_normal_noise(&cube, 0.3, 1) == 0);
    CHECK(shape_sphere(&sphere, 4, 2.0) == 0);
    CHECK(shape_add_normal_noise(&sphere, 0.2, 2) == 0);
    /* a quarter of the triangles under the sanitizers (test_small) */
    CHECK(shape_capped_cylinder(&cyl, 1.0, 2.0, test_small() ? 5000 : 20000) == 0);
    CHECK(shape_add_normal_noise(&cyl, 0.3, 3) == 0);

    compare_shape(ctx, "noisy cube (defaults)", &cube, &p);
    compare_shape(ctx, "noisy sphere (defaults)", &sphere, &p);
    compare_shape(ctx, "noisy capped cylinder (defaults)", &cyl, &p);
    p.sigma_f = 1.5;
    p.sigma_g = 0.7;
    compare_shape(ctx, "noisy cylinder sf=1.5 sg=0.7", &cyl, &p);
    p.mollify = 0;
    compare_shape(ctx, "noisy cube, no mollification", &cube, &p);
    p.mollify = 1;
    p.sigma_g = INFINITY;
    compare_shape(ctx, "noisy cube, influence off", &cube, &p);
    p.sigma_g = 0.05; /* tiny influence width: exercises the underflow rescue */
    compare_shape(ctx, "noisy cube, sg=0.05", &cube, &p);
    p.predictor = RSMOOTH_PREDICT_CENTROID;
    compare_shape(ctx, "noisy cube, centroid predictor, sg=0.05", &cube, &p);
    p.sigma_g = INFINITY;
    compare_shape(ctx, "noisy sphere, isotropic Gaussian (centroid, influence off)", &sphere, &p);
    rsmooth_params_init(&p);
    p.cutoff = 3;
    p.mollify_cutoff = 1;
    compare_shape(ctx, "noisy sphere, cutoff 3, mollify 1", &sphere, &p);
    rsmooth_params_init(&p);
    p.absolute = 1;
    p.sigma_f = 0.1;
    p.sigma_g = 0.02;
    compare_shape(ctx, "noisy sphere, absolute sigmas", &sphere, &p);

    /* A soup: random triangles, some degenerate, duplicated and unreferenced vertices. */
    {
        uint64_t state = 42;
        size_t nv = 3000, nt = 2500;
        double *xyz = malloc(nv * 3 * sizeof *xyz);
        uint32_t *idx = malloc(nt * 3 * sizeof *idx);
        CHECK(xyz && idx);
        for (size_t i = 0; i < 3 * nv; i++)
            xyz[i] = 5 * shape_gaussian(&state);
        for (size_t i = 0; i < 3 * nt; i++)
            idx[i] = (uint32_t)((size_t)(fabs(shape_gaussian(&state)) * 1e6) % (nv - 100));
        for (size_t t = 0; t < 50; t++) /* zero area: repeated index */
            idx[3 * t + 1] = idx[3 * t];
        memcpy(xyz + 3 * 10, xyz + 3 * 20, 3 * sizeof *xyz); /* duplicated vertex */
        rsmooth_params_init(&p);
        compare(ctx, "random soup", xyz, nv, idx, nt, &p);
        free(xyz);
        free(idx);
    }

    benchmark_meshes(ctx);
    shape_free(&cube);
    shape_free(&sphere);
    shape_free(&cyl);
    rsmooth_context_destroy(ctx);
    printf("ok\n");
    return 0;
}
