/* The isotropic baselines (rsmooth_smooth_taubin) against an independent dense evaluation (an
 * adjacency matrix built straight from the triangles) and against analytic behaviour: a plane stays
 * flat, Laplacian smoothing shrinks a sphere while Taubin's lambda|mu keeps its size, both reduce
 * noise, and lone vertices stay. */
#include "mesh_shapes.h"
#include "rsmooth.h"
#include "test_util.h"

#include <string.h>

/* Dense oracle: V x V adjacency, then the same iteration written the obvious way. */
static void dense_taubin(const shape_mesh *m, double lambda, double mu, unsigned iterations,
                         double *out) {
    size_t n = m->vertex_count;
    unsigned char *adj = calloc(n * n, 1);
    double *next = malloc(3 * n * sizeof *next);
    CHECK(adj && next);
    for (size_t t = 0; t < m->triangle_count; t++)
        for (int e = 0; e < 3; e++) {
            uint32_t a = m->indices[3 * t + e], b = m->indices[3 * t + (e + 1) % 3];
            if (a != b)
                adj[a * n + b] = adj[b * n + a] = 1;
        }
    memcpy(out, m->xyz, 3 * n * sizeof *out);
    for (unsigned it = 0; it < iterations; it++)
        for (int pass = 0; pass < (mu != 0 ? 2 : 1); pass++) {
            double factor = pass == 0 ? lambda : mu;
            for (size_t v = 0; v < n; v++) {
                double sum[3] = {0, 0, 0};
                int count = 0;
                for (size_t u = 0; u < n; u++)
                    if (adj[v * n + u]) {
                        for (int c = 0; c < 3; c++)
                            sum[c] += out[3 * u + c];
                        count++;
                    }
                for (int c = 0; c < 3; c++)
                    next[3 * v + c] =
                        count ? out[3 * v + c] + factor * (sum[c] / count - out[3 * v + c])
                              : out[3 * v + c];
            }
            memcpy(out, next, 3 * n * sizeof *out);
        }
    free(adj);
    free(next);
}

static double max_abs_diff(const double *a, const double *b, size_t count) {
    double worst = 0;
    for (size_t i = 0; i < count; i++)
        worst = fmax(worst, fabs(a[i] - b[i]));
    return worst;
}

/* Mean and standard deviation of the distance to the origin. */
static void radius_stats(const double *xyz, size_t n, double *mean, double *stddev) {
    double s = 0, s2 = 0;
    for (size_t v = 0; v < n; v++) {
        double r = sqrt(xyz[3 * v] * xyz[3 * v] + xyz[3 * v + 1] * xyz[3 * v + 1] +
                        xyz[3 * v + 2] * xyz[3 * v + 2]);
        s += r;
        s2 += r * r;
    }
    *mean = s / (double)n;
    *stddev = sqrt(fmax(0, s2 / (double)n - *mean * *mean));
}

int main(void) {
    shape_mesh sphere, plane;
    CHECK(shape_sphere(&sphere, 3, 1.0) == 0);
    CHECK(shape_add_normal_noise(&sphere, 0.3, 7) == 0);
    CHECK(shape_plane(&plane, 12, 9, 0.5) == 0);
    size_t n = sphere.vertex_count;
    double *got = malloc(3 * n * sizeof *got), *want = malloc(3 * n * sizeof *want);
    CHECK(got && want);

    /* Library vs dense oracle, Laplacian and Taubin. */
    static const double settings[][2] = {{0.5, 0}, {0.5, -0.53}, {0.33, -0.34}, {1, -1}};
    for (size_t s = 0; s < sizeof settings / sizeof settings[0]; s++) {
        CHECK_STATUS(rsmooth_smooth_taubin(RSMOOTH_FLOAT64, sphere.xyz, n, sphere.indices,
                                           sphere.triangle_count, settings[s][0], settings[s][1], 7,
                                           got, NULL),
                     RSMOOTH_OK);
        dense_taubin(&sphere, settings[s][0], settings[s][1], 7, want);
        double diff = max_abs_diff(got, want, 3 * n);
        printf("sphere lambda %g mu %g, 7 iterations: max |library - dense| %.3g\n", settings[s][0],
               settings[s][1], diff);
        CHECK_LE(diff, 1e-12);
    }

    /* Float input gives the double result rounded. */
    {
        float *in = malloc(3 * n * sizeof *in), *out = malloc(3 * n * sizeof *out);
        CHECK(in && out);
        for (size_t i = 0; i < 3 * n; i++)
            in[i] = (float)sphere.xyz[i];
        CHECK_STATUS(rsmooth_smooth_taubin(RSMOOTH_FLOAT32, in, n, sphere.indices,
                                           sphere.triangle_count, 0.5, -0.53, 5, out, NULL),
                     RSMOOTH_OK);
        shape_mesh rounded = sphere;
        rounded.xyz = want;
        for (size_t i = 0; i < 3 * n; i++)
            want[i] = in[i];
        double *exact = malloc(3 * n * sizeof *exact);
        CHECK(exact);
        dense_taubin(&rounded, 0.5, -0.53, 5, exact);
        double worst = 0;
        for (size_t i = 0; i < 3 * n; i++)
            worst = fmax(worst, fabs((double)out[i] - exact[i]));
        CHECK_LE(worst, 1e-6);
        free(exact);
        free(in);
        free(out);
    }

    /* Laplacian shrinks the noisy sphere; Taubin keeps its size; both remove noise. */
    double r0, sd0, r_lap, sd_lap, r_tau, sd_tau;
    radius_stats(sphere.xyz, n, &r0, &sd0);
    CHECK_STATUS(rsmooth_smooth_taubin(RSMOOTH_FLOAT64, sphere.xyz, n, sphere.indices,
                                       sphere.triangle_count, 0.5, 0, 30, got, NULL),
                 RSMOOTH_OK);
    radius_stats(got, n, &r_lap, &sd_lap);
    CHECK_STATUS(rsmooth_smooth_taubin(RSMOOTH_FLOAT64, sphere.xyz, n, sphere.indices,
                                       sphere.triangle_count, 0.5, -0.53, 30, got, NULL),
                 RSMOOTH_OK);
    radius_stats(got, n, &r_tau, &sd_tau);
    printf("noisy unit sphere: radius %.4f (sd %.4f); Laplacian x30 %.4f (sd %.4f); "
           "Taubin x30 %.4f (sd %.4f)\n",
           r0, sd0, r_lap, sd_lap, r_tau, sd_tau);
    CHECK_LE(r_lap, 0.9 * r0);             /* shrinks */
    CHECK_LE(fabs(r_tau - r0), 0.03 * r0); /* keeps its size */
    CHECK_LE(sd_lap, 0.5 * sd0);
    CHECK_LE(sd_tau, 0.5 * sd0);

    /* A plane stays in its plane (z stays exactly 0), whatever the boundary does. */
    {
        size_t pn = plane.vertex_count;
        double *out = malloc(3 * pn * sizeof *out);
        CHECK(out);
        CHECK_STATUS(rsmooth_smooth_taubin(RSMOOTH_FLOAT64, plane.xyz, pn, plane.indices,
                                           plane.triangle_count, 0.5, -0.53, 10, out, NULL),
                     RSMOOTH_OK);
        for (size_t v = 0; v < pn; v++)
            CHECK(out[3 * v + 2] == 0);
        free(out);
    }

    /* Lone and degenerate: a vertex in no triangle and a triangle with a repeated index. */
    {
        double xyz[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 5, 5, 5};
        uint32_t idx[] = {0, 1, 2, 2, 2, 1};
        double out[12];
        CHECK_STATUS(rsmooth_smooth_taubin(RSMOOTH_FLOAT64, xyz, 4, idx, 2, 0.5, 0, 1, out, NULL),
                     RSMOOTH_OK);
        CHECK(out[9] == 5 && out[10] == 5 && out[11] == 5);
        /* vertex 0: neighbours 1 and 2 -> halfway to their mean (0.5, 0.5, 0) */
        CHECK_NEAR(out[0], 0.25, 1e-15);
        CHECK_NEAR(out[1], 0.25, 1e-15);
        /* zero iterations copy */
        CHECK_STATUS(rsmooth_smooth_taubin(RSMOOTH_FLOAT64, xyz, 4, idx, 2, 0.5, 0, 0, out, NULL),
                     RSMOOTH_OK);
        CHECK(memcmp(out, xyz, sizeof xyz) == 0);

        /* Bad arguments: refused with a message and nothing written. */
        rsmooth_error err;
        double untouched[12];
        memset(untouched, 0x5a, sizeof untouched);
        memcpy(out, untouched, sizeof out);
        CHECK_STATUS(rsmooth_smooth_taubin(RSMOOTH_FLOAT64, xyz, 4, idx, 2, 0, 0, 1, out, &err),
                     RSMOOTH_ERROR_INVALID_ARGUMENT);
        CHECK(strstr(err.message, "lambda") != NULL);
        CHECK_STATUS(rsmooth_smooth_taubin(RSMOOTH_FLOAT64, xyz, 4, idx, 2, 0.5, 0.2, 1, out, &err),
                     RSMOOTH_ERROR_INVALID_ARGUMENT);
        CHECK(strstr(err.message, "mu") != NULL);
        CHECK_STATUS(rsmooth_smooth_taubin(RSMOOTH_FLOAT64, xyz, 4, idx, 2, NAN, 0, 1, out, &err),
                     RSMOOTH_ERROR_INVALID_ARGUMENT);
        uint32_t bad[] = {0, 1, 4};
        CHECK_STATUS(rsmooth_smooth_taubin(RSMOOTH_FLOAT64, xyz, 4, bad, 1, 0.5, 0, 1, out, &err),
                     RSMOOTH_ERROR_INVALID_ARGUMENT);
        CHECK(strstr(err.message, "index 4") != NULL);
        CHECK_STATUS(
            rsmooth_smooth_taubin(RSMOOTH_FLOAT64, xyz, 4, idx, 2, 0.5, 0, 1, xyz + 3, &err),
            RSMOOTH_ERROR_INVALID_ARGUMENT);
        CHECK(strstr(err.message, "overlaps") != NULL);
        CHECK_STATUS(rsmooth_smooth_taubin(RSMOOTH_FLOAT64, xyz, 4, idx, 2, 0.5, 0, 1, NULL, &err),
                     RSMOOTH_ERROR_INVALID_ARGUMENT);
        CHECK(memcmp(out, untouched, sizeof out) == 0);
    }

    free(got);
    free(want);
    shape_free(&sphere);
    shape_free(&plane);
    printf("taubin: library equals the dense oracle; shrinkage and flatness as expected\n");
    return 0;
}
