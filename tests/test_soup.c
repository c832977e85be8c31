/* Connectivity, placement and precision do not change the result: an unindexed soup equals its
 * indexed twin, a mesh far from the origin moves as it does at the origin, float32 matches float64,
 * and coordinates near the largest double still work. */
#include "mesh_shapes.h"
#include "rsmooth.h"
#include "test_util.h"

#include <stdint.h>
#include <string.h>

static double dist3(const double *a, const double *b) {
    double d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
    return sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
}

static void smooth64(const shape_mesh *m, const rsmooth_params *p, double *out, float *k,
                     float *conf, rsmooth_report *report) {
    rsmooth_error err;
    rsmooth_status s = rsmooth_smooth(NULL, RSMOOTH_FLOAT64, m->xyz, m->vertex_count, m->indices,
                                      m->triangle_count, p, out, OUTPUTS(k, conf, report), &err);
    if (s != RSMOOTH_OK)
        fprintf(stderr, "rsmooth_smooth: %s\n", err.message);
    CHECK_STATUS(s, RSMOOTH_OK);
}

static void test_soup_equals_indexed(const shape_mesh *mesh, const rsmooth_params *p) {
    shape_mesh soup;
    CHECK(shape_unindex(mesh, &soup) == 0);
    double mel_indexed, mel_soup;
    CHECK_STATUS(rsmooth_mean_edge_length(RSMOOTH_FLOAT64, mesh->xyz, mesh->vertex_count,
                                          mesh->indices, mesh->triangle_count, &mel_indexed, NULL),
                 RSMOOTH_OK);
    CHECK_STATUS(rsmooth_mean_edge_length(RSMOOTH_FLOAT64, soup.xyz, soup.vertex_count,
                                          soup.indices, soup.triangle_count, &mel_soup, NULL),
                 RSMOOTH_OK);
    printf("mean edge length: indexed %.17g, soup %.17g (each edge twice in the soup)\n",
           mel_indexed, mel_soup);
    CHECK_NEAR(mel_soup, mel_indexed, 1e-12 * mel_indexed);

    double *out = malloc(3 * mesh->vertex_count * sizeof *out);
    double *out_soup = malloc(3 * soup.vertex_count * sizeof *out_soup);
    float *conf = malloc(mesh->vertex_count * sizeof *conf);
    float *conf_soup = malloc(soup.vertex_count * sizeof *conf_soup);
    CHECK(out && out_soup && conf && conf_soup);
    rsmooth_report r1, r2;
    smooth64(mesh, p, out, NULL, conf, &r1);
    smooth64(&soup, p, out_soup, NULL, conf_soup, &r2);
    double worst = 0, worst_conf = 0, moved = 0;
    for (size_t i = 0; i < soup.vertex_count; i++) {
        uint32_t v = mesh->indices[i];
        worst = fmax(worst, dist3(out_soup + 3 * i, out + 3 * (size_t)v));
        worst_conf = fmax(worst_conf, fabs((double)conf_soup[i] - (double)conf[v]));
        moved = fmax(moved, dist3(out + 3 * (size_t)v, mesh->xyz + 3 * (size_t)v));
    }
    printf("soup (V %zu) vs indexed (V %zu), T %zu: facets %zu / %zu, max displacement %.3g mean "
           "edges, max |soup - indexed| %.3g mean edges, max confidence difference %.3g\n",
           soup.vertex_count, mesh->vertex_count, mesh->triangle_count, r2.facet_count,
           r1.facet_count, moved / mel_indexed, worst / mel_indexed, worst_conf);
    CHECK_EQ_INT(r1.facet_count, r2.facet_count);
    CHECK(moved > 0.05 * mel_indexed);
    CHECK_LE(worst / mel_indexed, 1e-9);
    CHECK_LE(worst_conf, 1e-6);
    free(out);
    free(out_soup);
    free(conf);
    free(conf_soup);
    shape_free(&soup);
}

static void test_far_from_origin(const shape_mesh *mesh, const rsmooth_params *p) {
    static const double offset = 1e6;
    shape_mesh far;
    CHECK(shape_copy(mesh, &far) == 0);
    for (size_t i = 0; i < 3 * far.vertex_count; i++)
        far.xyz[i] += offset;
    double *out = malloc(3 * mesh->vertex_count * sizeof *out);
    double *out_far = malloc(3 * mesh->vertex_count * sizeof *out_far);
    CHECK(out && out_far);
    rsmooth_report r1, r2;
    smooth64(mesh, p, out, NULL, NULL, &r1);
    smooth64(&far, p, out_far, NULL, NULL, &r2);
    double mel = r1.mean_edge_length, worst = 0, moved = 0;
    for (size_t v = 0; v < mesh->vertex_count; v++) {
        double d0[3], d1[3];
        for (int k = 0; k < 3; k++) {
            d0[k] = out[3 * v + k] - mesh->xyz[3 * v + k];
            d1[k] = out_far[3 * v + k] - far.xyz[3 * v + k];
        }
        worst = fmax(worst, dist3(d0, d1));
        moved = fmax(moved, sqrt(d0[0] * d0[0] + d0[1] * d0[1] + d0[2] * d0[2]));
    }
    printf("translated by %g in x, y, z (float64): mean edge %.12g vs %.12g, max displacement "
           "%.3g mean edges, max displacement difference %.3g mean edges\n",
           offset, r1.mean_edge_length, r2.mean_edge_length, moved / mel, worst / mel);
    CHECK(moved > 0.05 * mel);
    CHECK_LE(worst / mel, 1e-3);
    free(out);
    free(out_far);
    shape_free(&far);
}

static void test_float32(const shape_mesh *mesh, const rsmooth_params *p) {
    size_t n = 3 * mesh->vertex_count;
    float *in32 = malloc(n * sizeof *in32), *out32 = malloc(n * sizeof *out32);
    double *in_rounded = malloc(n * sizeof *in_rounded), *out64 = malloc(n * sizeof *out64);
    double *out_rounded = malloc(n * sizeof *out_rounded);
    float *conf32 = malloc(mesh->vertex_count * sizeof *conf32);
    float *conf64 = malloc(mesh->vertex_count * sizeof *conf64);
    float *k32 = malloc(mesh->vertex_count * sizeof *k32);
    float *k64 = malloc(mesh->vertex_count * sizeof *k64);
    CHECK(in32 && out32 && in_rounded && out64 && out_rounded && conf32 && conf64 && k32 && k64);
    for (size_t i = 0; i < n; i++) {
        in32[i] = (float)mesh->xyz[i];
        in_rounded[i] = (double)in32[i];
    }
    rsmooth_error err;
    rsmooth_report report;
    CHECK_STATUS(rsmooth_smooth(NULL, RSMOOTH_FLOAT32, in32, mesh->vertex_count, mesh->indices,
                                mesh->triangle_count, p, out32, OUTPUTS(k32, conf32, &report),
                                &err),
                 RSMOOTH_OK);
    smooth64(mesh, p, out64, NULL, NULL, NULL);
    /* the same float inputs, widened: the float32 call is this, rounded once at the end */
    shape_mesh rounded = *mesh;
    rounded.xyz = in_rounded;
    smooth64(&rounded, p, out_rounded, k64, conf64, NULL);
    double mel = report.mean_edge_length, worst = 0;
    size_t differ = 0;
    for (size_t v = 0; v < mesh->vertex_count; v++) {
        double o[3] = {out32[3 * v], out32[3 * v + 1], out32[3 * v + 2]};
        worst = fmax(worst, dist3(o, out64 + 3 * v));
        for (int k = 0; k < 3; k++)
            differ += out32[3 * v + k] != (float)out_rounded[3 * v + k];
        differ += k32[v] != k64[v] || conf32[v] != conf64[v];
    }
    printf("float32 in/out: max |float32 - float64| %.3g mean edges; %zu values differ from the "
           "float64 run on the same (float) inputs rounded to float\n",
           worst / mel, differ);
    CHECK_LE(worst / mel, 1e-5);
    CHECK_EQ_INT(differ, 0);
    free(in32);
    free(out32);
    free(in_rounded);
    free(out64);
    free(out_rounded);
    free(conf32);
    free(conf64);
    free(k32);
    free(k64);
}

/* Any finite coordinates are valid input. Two unit triangles in the planes x = -B and x = +B, and a
 * vertex lying in the second: everything is flat, so nothing moves and every confidence is 1.
 * Beyond 1e150 the library refuses the input (RSMOOTH_ERROR_INVALID_ARGUMENT, documented), which is
 * fine; a wrong answer is not: (a + b + c) / 3 and the grid's extent hi - lo must not overflow. */
static void test_extreme_coordinates(void) {
    static const double extremes[] = {1e100, 1e150, 1e300, 1.7e308};
    for (size_t i = 0; i < sizeof extremes / sizeof extremes[0]; i++) {
        double b = extremes[i];
        double xyz[21] = {-b, 0, 0, -b, 1, 0, -b, 0, 1, b, 0, 0, b, 1, 0, b, 0, 1, b, 0.2, 0.3};
        uint32_t tri[6] = {0, 1, 2, 3, 4, 5};
        double out[21];
        float conf[7];
        rsmooth_error err;
        rsmooth_status s = rsmooth_smooth(NULL, RSMOOTH_FLOAT64, xyz, 7, tri, 2, NULL, out,
                                          OUTPUTS(NULL, conf, NULL), &err);
        if (s == RSMOOTH_ERROR_INVALID_ARGUMENT && b > 1e150) { /* documented limit */
            printf("triangles at x = +-%g: refused (\"%s\")\n", b, err.message);
            continue;
        }
        CHECK_STATUS(s, RSMOOTH_OK);
        float min_conf = 1;
        for (int v = 0; v < 7; v++)
            min_conf = conf[v] < min_conf ? conf[v] : min_conf;
        int kept = memcmp(out, xyz, sizeof xyz) == 0;
        printf("triangles at x = +-%g: positions kept %s, smallest confidence %g (expected 1)\n", b,
               kept ? "yes" : "no", min_conf);
        CHECK(kept);
        CHECK_NEAR(min_conf, 1, 1e-6);
    }
}

int main(void) {
    shape_mesh cube;
    CHECK(shape_cube(&cube, 14, 2.0) == 0);
    CHECK(shape_add_normal_noise(&cube, 0.3, 2024) == 0);
    rsmooth_params p;
    rsmooth_params_init(&p);
    printf("noisy cube n=14 (V %zu, T %zu), noise 0.3 mean edges, default parameters\n",
           cube.vertex_count, cube.triangle_count);
    test_soup_equals_indexed(&cube, &p);
    test_far_from_origin(&cube, &p);
    test_float32(&cube, &p);

    /* the same on a closed curved shape with other parameters */
    shape_mesh cylinder;
    CHECK(shape_capped_cylinder(&cylinder, 1.0, 1.5, 3000) == 0);
    CHECK(shape_add_normal_noise(&cylinder, 0.25, 7) == 0);
    rsmooth_params q = p;
    q.sigma_f = 1.5;
    q.sigma_g = 0.7;
    q.mollify_cutoff = 1.0;
    printf("noisy capped cylinder (V %zu, T %zu), noise 0.25, sigma_f 1.5, sigma_g 0.7, mollify "
           "cutoff 1\n",
           cylinder.vertex_count, cylinder.triangle_count);
    test_soup_equals_indexed(&cylinder, &q);
    test_far_from_origin(&cylinder, &q);
    test_float32(&cylinder, &q);

    shape_free(&cube);
    shape_free(&cylinder);
    test_extreme_coordinates();
    printf("soup: all checks passed\n");
    return 0;
}
