/* Point clouds on the device (rsmooth_smooth_points) equal the double-precision reference path
 * (rsmooth_smooth_points, ctx NULL): per-point deviation in point spacings (max <= 1e-3), the
 * normals and confidence, on generated clouds and, when ../shared exists, on the vertices of
 * benchmark meshes; two device runs are bit-identical. */
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

#define MAX_DEVIATION 1e-3 /* point spacings */
/* A neighbour whose distance is within this fraction of a reach may fall on either side of it:
 * float32 (device) and double (reference) round it differently. */
#define AT_CUTOFF 1e-6
/* What one such neighbour may move a point by: its weight at the cutoff (e^-2 of the centre's at
 * cutoff 2) over the sum of weights, times its prediction's distance (about 1e-3 spacings on the
 * benchmark meshes' vertices at sigma_f 2; a mesh's facets are half a point's area, so they
 * stay below 1e-3). */
#define CUTOFF_FLIP 1e-2
#define MAX_NORMAL 1e-3 /* per component of the unit normals */
#define MAX_CONFIDENCE 1e-3
/* A normal's change by a flip in the bilateral reach: the neighbour's share of the weights times
 * how far its normal is from the point's. */
#define CUTOFF_FLIP_NORMAL 5e-2

/* Whether point i of the cloud has a neighbour at the cutoff of `reach` (brute force). */
static bool at_cutoff(const double *xyz, size_t n, size_t i, double reach) {
    for (size_t j = 0; j < n; j++) {
        double d2 = 0;
        for (int k = 0; k < 3; k++)
            d2 += (xyz[3 * j + k] - xyz[3 * i + k]) * (xyz[3 * j + k] - xyz[3 * i + k]);
        if (reach > 0 && fabs(sqrt(d2) / reach - 1) < AT_CUTOFF)
            return true;
    }
    return false;
}

/* Per point of a comparison: position deviation (spacings), largest normal component and
 * confidence differences. */
typedef struct differences {
    double *position, *normal, *confidence;
} differences;

/* Points off by more than the tolerances with a neighbour at a cutoff (of one pass: the input's
 * positions are that pass's) are flips: counted, their largest differences in flip_worst, and
 * taken out of `d` (set to 0). Returns how many. */
static size_t take_out_flips(const double *xyz, size_t n, differences *d, const rsmooth_report *rr,
                             int passes, double flip_worst[3]) {
    size_t flips = 0;
    flip_worst[0] = flip_worst[1] = flip_worst[2] = 0;
    for (size_t i = 0; passes == 1 && i < n; i++) {
        bool off = d->position[i] > MAX_DEVIATION || d->normal[i] > MAX_NORMAL ||
                   d->confidence[i] > MAX_CONFIDENCE;
        if (off && (at_cutoff(xyz, n, i, rr->radius) || at_cutoff(xyz, n, i, rr->mollify_radius))) {
            flips++;
            flip_worst[0] = fmax(flip_worst[0], d->position[i]);
            flip_worst[1] = fmax(flip_worst[1], d->normal[i]);
            flip_worst[2] = fmax(flip_worst[2], d->confidence[i]);
            d->position[i] = d->normal[i] = d->confidence[i] = 0;
        }
    }
    return flips;
}

static double largest(const double *x, size_t n) {
    double m = 0;
    for (size_t i = 0; i < n; i++)
        m = fmax(m, x[i]);
    return m;
}

/* Runs both paths (float64 arrays), prints and checks the differences, then the device again
 * for a bit-identical repeat. */
static void compare(rsmooth_context *ctx, const char *name, const double *xyz,
                    const double *normals, size_t n, const rsmooth_params *params) {
    double *ref = malloc(3 * n * sizeof *ref), *dev = malloc(3 * n * sizeof *dev);
    double *ref_n = malloc(3 * n * sizeof *ref_n), *dev_n = malloc(3 * n * sizeof *dev_n);
    double *again = malloc(3 * n * sizeof *again), *again_n = malloc(3 * n * sizeof *again_n);
    float *ref_c = malloc(n * sizeof *ref_c), *dev_c = malloc(n * sizeof *dev_c);
    float *again_c = malloc(n * sizeof *again_c);
    differences d = {malloc(n * sizeof(double)), malloc(n * sizeof(double)),
                     malloc(n * sizeof(double))};
    CHECK(ref && dev && ref_n && dev_n && again && again_n && ref_c && dev_c && again_c &&
          d.position && d.normal && d.confidence);
    rsmooth_report rr, rd;
    rsmooth_report_init(&rr);
    rsmooth_report_init(&rd);
    rsmooth_error err;
    CHECK_STATUS(rsmooth_smooth_points(NULL, RSMOOTH_FLOAT64, xyz, normals, n, params, ref, ref_n,
                                       OUTPUTS(NULL, ref_c, &rr), &err),
                 RSMOOTH_OK);
    rsmooth_status st = rsmooth_smooth_points(ctx, RSMOOTH_FLOAT64, xyz, normals, n, params, dev,
                                              dev_n, OUTPUTS(NULL, dev_c, &rd), &err);
    if (st != RSMOOTH_OK)
        fprintf(stderr, "%s: %s\n", name, err.message);
    CHECK_STATUS(st, RSMOOTH_OK);
    double spacing = rr.mean_edge_length, moved = 0;
    for (size_t i = 0; i < n; i++) {
        double d2 = 0, m2 = 0;
        d.normal[i] = 0;
        for (int k = 0; k < 3; k++) {
            double e = dev[3 * i + k] - ref[3 * i + k], m = ref[3 * i + k] - xyz[3 * i + k];
            d2 += e * e;
            m2 += m * m;
            d.normal[i] = fmax(d.normal[i], fabs(dev_n[3 * i + k] - ref_n[3 * i + k]));
        }
        d.position[i] = sqrt(d2) / spacing;
        d.confidence[i] = fabs((double)dev_c[i] - ref_c[i]);
        moved += sqrt(m2) / spacing;
    }
    printf("%-44s N=%7zu  mean move %.4f  deviation max %.3g spacings (tol %.0e)  normals max "
           "%.2g  confidence max %.2g  (reference %.0f ms, device %.0f ms)\n",
           name, n, moved / (double)n, largest(d.position, n), MAX_DEVIATION, largest(d.normal, n),
           largest(d.confidence, n), rr.ms_total, rd.ms_total);
    CHECK(isfinite(largest(d.position, n)));
    double flip_worst[3];
    size_t flips = take_out_flips(xyz, n, &d, &rr, params->passes, flip_worst);
    if (flips > 0) {
        printf("    %zu point(s) beyond the tolerances, each with a neighbour within %.0e of a "
               "cutoff: deviation max %.3g (limit %.0e), normals %.2g (limit %.0e), confidence "
               "%.2g; the others' deviation max %.3g, normals %.2g, confidence %.2g\n",
               flips, AT_CUTOFF, flip_worst[0], CUTOFF_FLIP, flip_worst[1], CUTOFF_FLIP_NORMAL,
               flip_worst[2], largest(d.position, n), largest(d.normal, n),
               largest(d.confidence, n));
        CHECK_LE(flip_worst[0], CUTOFF_FLIP);
        CHECK_LE(flip_worst[1], CUTOFF_FLIP_NORMAL);
    }
    CHECK_LE(largest(d.position, n), MAX_DEVIATION);
    CHECK_LE(largest(d.normal, n), MAX_NORMAL);
    CHECK_LE(largest(d.confidence, n), MAX_CONFIDENCE);
    CHECK(moved > 0.01 * (double)n); /* the comparison is not of two no-ops */
    CHECK_EQ_INT(rd.vertex_count, n);
    CHECK_EQ_INT(rd.facet_count, rr.facet_count);
    CHECK_NEAR(rd.mean_edge_length, spacing, 1e-12 * spacing);

    CHECK_STATUS(rsmooth_smooth_points(ctx, RSMOOTH_FLOAT64, xyz, normals, n, params, again,
                                       again_n, OUTPUTS(NULL, again_c, NULL), &err),
                 RSMOOTH_OK);
    CHECK(memcmp(again, dev, 3 * n * sizeof *dev) == 0);
    CHECK(memcmp(again_n, dev_n, 3 * n * sizeof *dev_n) == 0);
    CHECK(memcmp(again_c, dev_c, n * sizeof *dev_c) == 0);
    free(ref), free(dev), free(ref_n), free(dev_n), free(again), free(again_n);
    free(ref_c), free(dev_c), free(again_c), free(d.position), free(d.normal), free(d.confidence);
}

/* float32 arrays: both paths on the same rounded input, results within the tolerance. */
static void compare_float32(rsmooth_context *ctx, const char *name, const double *xyz,
                            const double *normals, size_t n) {
    float *x32 = malloc(3 * n * sizeof *x32), *n32 = malloc(3 * n * sizeof *n32);
    float *ref = malloc(3 * n * sizeof *ref), *dev = malloc(3 * n * sizeof *dev);
    CHECK(x32 && n32 && ref && dev);
    for (size_t i = 0; i < 3 * n; i++) {
        x32[i] = (float)xyz[i];
        n32[i] = (float)normals[i];
    }
    double spacing = 0, worst = 0;
    CHECK_STATUS(rsmooth_point_spacing(RSMOOTH_FLOAT32, x32, n, &spacing, NULL), RSMOOTH_OK);
    CHECK_STATUS(
        rsmooth_smooth_points(NULL, RSMOOTH_FLOAT32, x32, n32, n, NULL, ref, NULL, NULL, NULL),
        RSMOOTH_OK);
    CHECK_STATUS(
        rsmooth_smooth_points(ctx, RSMOOTH_FLOAT32, x32, n32, n, NULL, dev, NULL, NULL, NULL),
        RSMOOTH_OK);
    for (size_t i = 0; i < n; i++) {
        double d2 = 0;
        for (int k = 0; k < 3; k++) {
            double d = (double)dev[3 * i + k] - (double)ref[3 * i + k];
            d2 += d * d;
        }
        worst = fmax(worst, sqrt(d2) / spacing);
    }
    printf("%-44s N=%7zu  deviation max %.3g spacings (tol %.0e)\n", name, n, worst, MAX_DEVIATION);
    CHECK_LE(worst, MAX_DEVIATION);
    free(x32), free(n32), free(ref), free(dev);
}

/* A progress_cancel that stops at its `*user`-th report (the first is the pass's start, the
 * others come from the device's launches). */
static int stop_at(void *user, double fraction) {
    (void)fraction;
    int *left = user;
    return --*left <= 0;
}

/* A noisy cloud: the vertices of `mesh` moved along its normals by `noise` mean edge lengths,
 * with the normals of the noisy surface (as a scanner gives them). */
static double *noisy_cloud(shape_mesh *mesh, double noise, uint64_t seed) {
    CHECK(shape_add_normal_noise(mesh, noise, seed) == 0);
    double *normals = malloc(3 * mesh->vertex_count * sizeof *normals);
    CHECK(normals && shape_vertex_normals(mesh, normals) == 0);
    return normals;
}

/* The variants of the parameters each generated cloud runs with. */
static void compare_variants(rsmooth_context *ctx, const char *shape, const shape_mesh *m,
                             const double *normals) {
    float *colors = malloc(3 * m->vertex_count * sizeof *colors);
    CHECK(colors);
    for (size_t i = 0; i < m->vertex_count; i++) { /* red below z = 0, blue above */
        bool low = m->xyz[3 * i + 2] < 0;
        colors[3 * i] = low ? 0.9f : 0.1f;
        colors[3 * i + 1] = 0.2f;
        colors[3 * i + 2] = low ? 0.1f : 0.8f;
    }
    for (int variant = 0; variant < 9; variant++) {
        rsmooth_params p;
        rsmooth_params_init(&p);
        const char *what = "defaults";
        switch (variant) {
        case 1:
            what = "mollify off";
            p.mollify = 0;
            break;
        case 2:
            what = "best";
            rsmooth_params_init_best(&p);
            break;
        case 3:
            what = "3 passes, confidence 0.6, sf 1.5";
            p.passes = 3;
            p.pass_confidence = 0.6;
            p.sigma_f = 1.5;
            break;
        case 4:
            what = "tukey";
            p.influence = RSMOOTH_INFLUENCE_TUKEY;
            break;
        case 5:
            what = "sigma_g inf";
            p.sigma_g = INFINITY;
            break;
        case 6:
            what = "centroid predictor";
            p.predictor = RSMOOTH_PREDICT_CENTROID;
            p.sigma_g = INFINITY;
            break;
        case 7:
            what = "colour, sigma_c 0.3";
            p.colors = colors;
            p.sigma_c = 0.3;
            break;
        case 8:
            what = "sf 4 sg 1, 2 bilateral rounds";
            p.sigma_f = 4;
            p.sigma_g = 1;
            p.normal_iterations = 2;
            break;
        }
        char name[128];
        snprintf(name, sizeof name, "%s, %s", shape, what);
        compare(ctx, name, m->xyz, normals, m->vertex_count, &p);
    }
    free(colors);
}

/* The vertices of benchmark meshes as clouds, with the area-weighted normals of their noisy
 * surfaces. */
static void benchmark_clouds(rsmooth_context *ctx) {
    static const char *const models[] = {"Fandisk0.3", "Bunny0.2", "Block0.4"};
    char dir[4096];
    if (!benchmark_dir(dir, sizeof dir))
        return;
    for (size_t i = 0; i < sizeof models / sizeof *models; i++) {
        if (test_small() && strcmp(models[i], "Bunny0.2") == 0)
            continue; /* under the sanitizers: the others' paths again */
        rsmooth_mesh *mesh = benchmark_read(dir, models[i], "Noisy.obj");
        if (!mesh)
            continue;
        shape_mesh view = {mesh->vertex_count, mesh->positions, mesh->triangle_count,
                           mesh->triangles};
        double *normals = malloc(3 * mesh->vertex_count * sizeof *normals);
        CHECK(normals && shape_vertex_normals(&view, normals) == 0);
        const double settings[][2] = {{2, 0.5}, {4, 1}};
        for (size_t s = 0; s < sizeof settings / sizeof *settings; s++) {
            rsmooth_params p;
            rsmooth_params_init(&p);
            p.sigma_f = settings[s][0];
            p.sigma_g = settings[s][1];
            char name[128];
            snprintf(name, sizeof name, "%s vertices sf=%g sg=%g", models[i], p.sigma_f, p.sigma_g);
            compare(ctx, name, mesh->positions, normals, mesh->vertex_count, &p);
        }
        free(normals);
        rsmooth_mesh_destroy(mesh);
    }
}

int main(void) {
    rsmooth_context *ctx = open_test_context();
    shape_mesh sphere, cube;
    CHECK(shape_sphere(&sphere, test_small() ? 4 : 5, 2.0) == 0);
    double *sphere_n = noisy_cloud(&sphere, 0.2, 21);
    CHECK(shape_cube(&cube, 16, 1.0) == 0);
    double *cube_n = noisy_cloud(&cube, 0.3, 22);

    compare_variants(ctx, "noisy sphere", &sphere, sphere_n);
    compare_variants(ctx, "noisy cube", &cube, cube_n);
    compare_float32(ctx, "noisy sphere, float32 arrays", sphere.xyz, sphere_n, sphere.vertex_count);

    /* Duplicated points: a cluster of 8 in one place has spacing and area 0 (no weight). */
    for (size_t i = 1; i < 8; i++)
        memcpy(cube.xyz + 3 * (100 + i), cube.xyz + 3 * 100, 3 * sizeof *cube.xyz);
    rsmooth_params p;
    rsmooth_params_init(&p);
    compare(ctx, "noisy cube, 8 points in one place", cube.xyz, cube_n, cube.vertex_count, &p);

    /* NULL context: the reference path (one point stays) */
    double one[3] = {0, 0, 0}, up[3] = {0, 0, 1}, out[3];
    rsmooth_error err;
    CHECK_STATUS(
        rsmooth_smooth_points(NULL, RSMOOTH_FLOAT64, one, up, 1, NULL, out, NULL, NULL, &err),
        RSMOOTH_OK);
    CHECK(out[0] == 0 && out[1] == 0 && out[2] == 0);
    /* one point: nothing to weigh it against, it stays */
    CHECK_STATUS(
        rsmooth_smooth_points(ctx, RSMOOTH_FLOAT64, one, up, 1, NULL, out, NULL, NULL, &err),
        RSMOOTH_OK);
    CHECK(out[0] == 0 && out[1] == 0 && out[2] == 0);

    /* cancelled inside the device run: its status, and the context usable after it */
    for (int at = 1; at <= 3; at++) {
        int left = at;
        p.progress_cancel = stop_at;
        p.progress_user = &left;
        double *sink = malloc(3 * cube.vertex_count * sizeof *sink);
        CHECK(sink);
        CHECK_STATUS(rsmooth_smooth_points(ctx, RSMOOTH_FLOAT64, cube.xyz, cube_n,
                                           cube.vertex_count, &p, sink, NULL, NULL, &err),
                     RSMOOTH_ERROR_CANCELLED);
        free(sink);
    }
    rsmooth_params_init(&p);
    compare(ctx, "noisy cube, 8 points in one place, again", cube.xyz, cube_n, cube.vertex_count,
            &p);

    benchmark_clouds(ctx);
    free(sphere_n);
    free(cube_n);
    shape_free(&sphere);
    shape_free(&cube);
    rsmooth_context_destroy(ctx);
    printf("ok\n");
    return 0;
}
