/* Float32 kernels lose nothing to position: a float64 mesh translated by 1e6 gets the same
 * displacements as at the origin, an unindexed soup the same result as its indexed twin, and
 * float32 input gives the float64 result rounded. All on the OpenCL path. */
#include "mesh_shapes.h"
#include "rsmooth.h"
#include "test_cl_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static double *smooth(rsmooth_context *ctx, const shape_mesh *m, double *edge) {
    double *out = malloc(m->vertex_count * 3 * sizeof *out);
    CHECK(out);
    rsmooth_report report;
    rsmooth_error err;
    rsmooth_params p;
    rsmooth_params_init(&p);
    p.sigma_f = 1.5;
    p.sigma_g = 0.7;
    CHECK_STATUS(rsmooth_smooth(ctx, RSMOOTH_FLOAT64, m->xyz, m->vertex_count, m->indices,
                                m->triangle_count, &p, out, OUTPUTS(NULL, NULL, &report), &err),
                 RSMOOTH_OK);
    *edge = report.mean_edge_length;
    return out;
}

int main(void) {
    rsmooth_context *ctx = open_test_context();
    shape_mesh cube, far, soup;
    CHECK(shape_cube(&cube, 20, 1.0) == 0);
    CHECK(shape_add_normal_noise(&cube, 0.3, 7) == 0);

    /* Translated far from the origin, as georeferenced scans are. */
    CHECK(shape_copy(&cube, &far) == 0);
    for (size_t i = 0; i < 3 * far.vertex_count; i++)
        far.xyz[i] += 1e6;
    double edge, edge_far;
    double *near_out = smooth(ctx, &cube, &edge), *far_out = smooth(ctx, &far, &edge_far);
    double max_dev = 0, max_move = 0;
    for (size_t i = 0; i < 3 * cube.vertex_count; i++) {
        double d_near = near_out[i] - cube.xyz[i], d_far = far_out[i] - far.xyz[i];
        max_dev = fmax(max_dev, fabs(d_near - d_far) / edge);
        max_move = fmax(max_move, fabs(d_near) / edge);
    }
    printf("translated by 1e6: max displacement difference %.3g mean edge lengths (tol 1e-3), "
           "largest displacement %.3g\n",
           max_dev, max_move);
    CHECK_LE(max_dev, 1e-3);
    CHECK(max_move > 0.05); /* the filter did move vertices */

    /* A fully unindexed soup: the same surface, every triangle its own three vertices. */
    CHECK(shape_unindex(&cube, &soup) == 0);
    double edge_soup;
    double *soup_out = smooth(ctx, &soup, &edge_soup);
    CHECK_NEAR(edge_soup, edge, 1e-12 * edge); /* closed mesh: each edge twice in the soup */
    double max_soup = 0;
    for (size_t t = 0; t < cube.triangle_count; t++)
        for (int c = 0; c < 3; c++)
            for (int k = 0; k < 3; k++) {
                double a = soup_out[9 * t + 3 * c + k];
                double b = near_out[3 * (size_t)cube.indices[3 * t + c] + k];
                max_soup = fmax(max_soup, fabs(a - b) / edge);
            }
    printf("unindexed soup vs indexed twin: max difference %.3g mean edge lengths (tol 1e-5)\n",
           max_soup);
    CHECK_LE(max_soup, 1e-5);

    /* float32 in and out. */
    size_t n = 3 * cube.vertex_count;
    float *in32 = malloc(n * sizeof *in32), *out32 = malloc(n * sizeof *out32);
    CHECK(in32 && out32);
    for (size_t i = 0; i < n; i++)
        in32[i] = (float)cube.xyz[i];
    rsmooth_params p;
    rsmooth_params_init(&p);
    p.sigma_f = 1.5;
    p.sigma_g = 0.7;
    rsmooth_error err;
    CHECK_STATUS(rsmooth_smooth(ctx, RSMOOTH_FLOAT32, in32, cube.vertex_count, cube.indices,
                                cube.triangle_count, &p, out32, NULL, &err),
                 RSMOOTH_OK);
    double max32 = 0;
    for (size_t i = 0; i < n; i++)
        max32 = fmax(max32, fabs((double)out32[i] - near_out[i]) / edge);
    printf("float32 vs float64 input: max difference %.3g mean edge lengths (tol 1e-3)\n", max32);
    CHECK_LE(max32, 1e-3);

    free(near_out);
    free(far_out);
    free(soup_out);
    free(in32);
    free(out32);
    shape_free(&cube);
    shape_free(&far);
    shape_free(&soup);
    rsmooth_context_destroy(ctx);
    return 0;
}
