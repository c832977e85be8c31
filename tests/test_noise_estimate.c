/* rsmooth_estimate_noise reads the noise that was added: generated shapes with Gaussian noise of
 * known size along their normals, the benchmark meshes against their originals (when ../shared
 * has them), and the edge cases (no edges, a soup, float32, any thread count, bad arrays). */
#define _DEFAULT_SOURCE /* setenv, clock_gettime */
#include "mesh_noise.h"
#include "mesh_shapes.h"
#include "rsmooth.h"
#include "rsmooth_io.h"
#include "test_benchmark.h"
#include "test_util.h"

#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* Gaussian noise of 0.1 to 0.5 mean edge lengths on the generated shapes reads within this
 * fraction of the truth (the figures printed show how much closer it is). */
#define SHAPE_TOLERANCE 0.10
/* The benchmark meshes (sharp features, uneven sampling, scanned): within this. */
#define BENCHMARK_TOLERANCE 0.15

/* The generated shapes, about 10000 vertices each (about 2500 under the sanitizers: test_small):
 * a plane, a sphere, a cube and a capped cylinder. */
static void make_shape(shape_mesh *m, const char *name) {
    bool small = test_small();
    if (strcmp(name, "plane") == 0)
        CHECK_EQ_INT(shape_plane(m, small ? 50 : 100, small ? 50 : 100, 0.01), 0); /* 10201 */
    else if (strcmp(name, "sphere") == 0)
        CHECK_EQ_INT(shape_sphere(m, small ? 4 : 5, 1.0), 0); /* 10242 */
    else if (strcmp(name, "cube") == 0)
        CHECK_EQ_INT(shape_cube(m, small ? 20 : 40, 1.0), 0); /* 9602 */
    else
        CHECK_EQ_INT(shape_capped_cylinder(m, 1.0, 2.0, small ? 5000 : 20000), 0);
}

static double now_ms(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec * 1e3 + (double)t.tv_nsec * 1e-6;
}

static double estimate(const double *xyz, size_t nv, const uint32_t *tri, size_t nt) {
    double noise = -1;
    rsmooth_error err;
    CHECK_STATUS(rsmooth_estimate_noise(RSMOOTH_FLOAT64, xyz, nv, tri, nt, &noise, &err),
                 RSMOOTH_OK);
    CHECK(noise >= 0 && isfinite(noise));
    return noise;
}

/* rsmooth_params_auto on a mesh: the paper's rule takes its sigmas from the estimate, and the
 * best mode takes its impulsive preset exactly when the noise reads impulsive. */
static void check_auto(const char *name, const double *xyz, size_t nv, const uint32_t *tri,
                       size_t nt, bool expect_impulsive) {
    double noise = estimate(xyz, nv, tri, nt);
    rsmooth_params paper, best;
    rsmooth_params_init(&paper);
    rsmooth_params_init_best(&best);
    rsmooth_noise_report read = {.struct_size = sizeof read};
    CHECK_STATUS(rsmooth_params_auto(RSMOOTH_FLOAT64, xyz, nv, tri, nt, &paper, &read, NULL),
                 RSMOOTH_OK);
    CHECK(read.level == noise);
    CHECK_NEAR(paper.sigma_f, 0.6 + 1.6 * noise, 1e-12); /* lib/auto/params_auto.c's paper rule */
    CHECK_NEAR(paper.sigma_g, 4.0 * noise, 1e-12);
    rsmooth_noise_report r;
    r.struct_size = sizeof r;
    CHECK_STATUS(rsmooth_params_auto(RSMOOTH_FLOAT64, xyz, nv, tri, nt, &best, &r, NULL),
                 RSMOOTH_OK);
    CHECK_EQ_INT(r.kind == RSMOOTH_NOISE_IMPULSIVE, expect_impulsive);
    CHECK_EQ_INT(strcmp(r.preset, "best: impulsive") == 0, expect_impulsive);
    printf("%s: auto: noise %.4f -> paper sigma_f %.3f sigma_g %.3f; best preset '%s', %s\n", name,
           noise, paper.sigma_f, paper.sigma_g, r.preset,
           expect_impulsive ? "impulsive" : "Gaussian");
}

static double mean_edge(const double *xyz, size_t nv, const uint32_t *tri, size_t nt) {
    double length = 0;
    CHECK_STATUS(rsmooth_mean_edge_length(RSMOOTH_FLOAT64, xyz, nv, tri, nt, &length, NULL),
                 RSMOOTH_OK);
    return length;
}

/* The true noise of `noisy` against `clean` (same vertices and triangles): the standard deviation
 * of the displacement along the clean mesh's vertex normals, in mean edge lengths of the clean
 * mesh (the unit the estimate is in: lib/auto/noise_estimate.h). */
static double true_noise(const shape_mesh *clean, const double *noisy) {
    size_t nv = clean->vertex_count;
    double *normal = malloc(3 * nv * sizeof *normal);
    CHECK(normal);
    CHECK_EQ_INT(shape_vertex_normals(clean, normal), 0);
    double sum = 0, sum2 = 0;
    size_t n = 0;
    for (size_t v = 0; v < nv; v++) {
        const double *a = clean->xyz + 3 * v, *b = noisy + 3 * v, *nn = normal + 3 * v;
        if (nn[0] == 0 && nn[1] == 0 && nn[2] == 0)
            continue;
        double along = (b[0] - a[0]) * nn[0] + (b[1] - a[1]) * nn[1] + (b[2] - a[2]) * nn[2];
        sum += along;
        sum2 += along * along;
        n++;
    }
    free(normal);
    CHECK(n > 1);
    double mean = sum / (double)n, var = (sum2 - (double)n * mean * mean) / (double)(n - 1);
    return sqrt(var > 0 ? var : 0) /
           mean_edge(clean->xyz, nv, clean->indices, clean->triangle_count);
}

/* Noise of `sigma` (mean edge lengths of the clean shape) along the normals: the estimate against
 * the truth. Returns est / truth (or the estimate when sigma is 0). */
static double check_level(const char *name, const shape_mesh *clean, double sigma, uint64_t seed,
                          double tolerance) {
    shape_mesh noisy;
    CHECK_EQ_INT(shape_copy(clean, &noisy), 0);
    if (sigma > 0)
        CHECK_EQ_INT(shape_add_normal_noise(&noisy, sigma, seed), 0);
    double t0 = now_ms();
    double est = estimate(noisy.xyz, noisy.vertex_count, noisy.indices, noisy.triangle_count);
    double ms = now_ms() - t0;
    double result = est;
    if (sigma > 0) {
        double truth = true_noise(clean, noisy.xyz);
        result = est / truth;
        printf("%-9s %6zu vertices  noise %.1f: truth %.4f  estimate %.4f  ratio %.3f  (%.0f ms)\n",
               name, clean->vertex_count, sigma, truth, est, result, ms);
        CHECK_NEAR(result, 1, tolerance);
    } else {
        printf("%-9s %6zu vertices  noise 0.0: estimate %.5f  (%.0f ms)\n", name,
               clean->vertex_count, est, ms);
    }
    shape_free(&noisy);
    return result;
}

static void generated_shapes(void) {
    shape_mesh shapes[4];
    const char *names[4] = {"plane", "sphere", "cube", "cylinder"};
    for (int s = 0; s < 4; s++)
        make_shape(&shapes[s], names[s]);
    const double levels[] = {0.1, 0.2, 0.3, 0.5};
    double worst = 0;
    for (int s = 0; s < 4; s++) {
        double zero = check_level(names[s], &shapes[s], 0, 0, 0);
        /* exact shapes: only the sphere's and cylinder's curvature beyond a quadric remains */
        CHECK_LE(zero, 0.01);
        for (size_t l = 0; l < sizeof levels / sizeof *levels; l++) {
            double r = check_level(names[s], &shapes[s], levels[l], 100 + l, SHAPE_TOLERANCE);
            worst = fmax(worst, fabs(r - 1));
        }
    }
    printf("generated shapes: worst |estimate / truth - 1| = %.3f (tolerance %.2f)\n", worst,
           SHAPE_TOLERANCE);

    /* impulsive noise: half the vertices moved (reported, not asserted: it reads low) */
    double *xyz = malloc(3 * shapes[1].vertex_count * sizeof *xyz);
    CHECK(xyz);
    memcpy(xyz, shapes[1].xyz, 3 * shapes[1].vertex_count * sizeof *xyz);
    mesh_noise_options o = {0.5, MESH_NOISE_NORMAL, 0.5, 7, 0, 0};
    CHECK_EQ_INT(mesh_add_noise(xyz, shapes[1].vertex_count, shapes[1].indices,
                                shapes[1].triangle_count, &o),
                 0);
    printf("sphere, impulsive 0.5 of vertices moved by 0.5: truth (all vertices) %.4f, estimate "
           "%.4f\n",
           true_noise(&shapes[1], xyz),
           estimate(xyz, shapes[1].vertex_count, shapes[1].indices, shapes[1].triangle_count));
    check_auto("sphere, impulsive", xyz, shapes[1].vertex_count, shapes[1].indices,
               shapes[1].triangle_count, true);
    for (int s = 0; s < 4; s++)
        for (size_t l = 0; l < sizeof levels / sizeof *levels; l++) {
            double *noisy = malloc(3 * shapes[s].vertex_count * sizeof *noisy);
            CHECK(noisy);
            memcpy(noisy, shapes[s].xyz, 3 * shapes[s].vertex_count * sizeof *noisy);
            mesh_noise_options g = {levels[l], MESH_NOISE_NORMAL, 0, 200 + l, 0, 0};
            CHECK_EQ_INT(mesh_add_noise(noisy, shapes[s].vertex_count, shapes[s].indices,
                                        shapes[s].triangle_count, &g),
                         0);
            check_auto(names[s], noisy, shapes[s].vertex_count, shapes[s].indices,
                       shapes[s].triangle_count, false);
            free(noisy);
        }
    free(xyz);
    for (int s = 0; s < 4; s++)
        shape_free(&shapes[s]);
}

/* Gaussian noise in random directions (rsmooth noise --direction random): the estimate reads its
 * normal component (sigma / sqrt 3 in expectation), in the clean mesh's mean edge lengths, and the
 * noise is not taken for impulsive (its normal component's tail is heavier than a Gaussian's). */
#define RANDOM_TOLERANCE 0.12 /* reads 0.90-1.00 of the truth here */
static void random_directions(void) {
    shape_mesh shapes[3];
    const char *names[3] = {"sphere", "cube", "cylinder"};
    for (int s = 0; s < 3; s++)
        make_shape(&shapes[s], names[s]);
    const double levels[] = {0.2, 0.5, 0.7};
    double worst = 0;
    for (int s = 0; s < 3; s++) {
        size_t nv = shapes[s].vertex_count, nt = shapes[s].triangle_count;
        for (size_t l = 0; l < sizeof levels / sizeof *levels; l++) {
            double *noisy = malloc(3 * nv * sizeof *noisy);
            CHECK(noisy);
            memcpy(noisy, shapes[s].xyz, 3 * nv * sizeof *noisy);
            mesh_noise_options o = {levels[l], MESH_NOISE_RANDOM, 0, 300 + l, 0, 0};
            CHECK_EQ_INT(mesh_add_noise(noisy, nv, shapes[s].indices, nt, &o), 0);
            double truth = true_noise(&shapes[s], noisy),
                   est = estimate(noisy, nv, shapes[s].indices, nt);
            printf("%-9s random directions %.1f: truth (normal part) %.4f  estimate %.4f  ratio "
                   "%.3f\n",
                   names[s], levels[l], truth, est, est / truth);
            CHECK_NEAR(est / truth, 1, RANDOM_TOLERANCE);
            worst = fmax(worst, fabs(est / truth - 1));
            check_auto(names[s], noisy, nv, shapes[s].indices, nt, false);
            free(noisy);
        }
    }
    printf("random directions: worst |estimate / truth - 1| = %.3f (tolerance %.2f)\n", worst,
           RANDOM_TOLERANCE);
    for (int s = 0; s < 3; s++)
        shape_free(&shapes[s]);
}

/* The kind the estimate reads (rsmooth_params_auto): Gaussian noise, along the normals or
 * in random directions, at any level from 0.05 to 1 mean edge lengths, is never taken for
 * impulsive; impulsive noise (a share F of the vertices displaced, the rest exact) is, at F 0.05
 * and 0.1 and levels 0.3 to 1. */
static bool reads_impulsive(const shape_mesh *m, const double *xyz) {
    rsmooth_params p;
    rsmooth_params_init(&p);
    rsmooth_noise_report r;
    r.struct_size = sizeof r;
    rsmooth_error err;
    CHECK_STATUS(rsmooth_params_auto(RSMOOTH_FLOAT64, xyz, m->vertex_count, m->indices,
                                     m->triangle_count, &p, &r, &err),
                 RSMOOTH_OK);
    return r.kind == RSMOOTH_NOISE_IMPULSIVE;
}

static void check_kind(void) {
    shape_mesh shapes[3];
    const char *names[3] = {"sphere", "cube", "cylinder"};
    for (int s = 0; s < 3; s++)
        make_shape(&shapes[s], names[s]);
    const double gaussian[] = {0.05, 0.2, 0.5, 1.0}, impulsive[] = {0.3, 0.5, 1.0};
    const double fractions[] = {0.05, 0.1};
    /* under the sanitizers every other level (0.05 and 0.5; 0.3 and 1.0): the same checks */
    const size_t stride = test_small() ? 2 : 1;
    for (int s = 0; s < 3; s++) {
        size_t nv = shapes[s].vertex_count, nt = shapes[s].triangle_count;
        double *noisy = malloc(3 * nv * sizeof *noisy);
        CHECK(noisy);
        for (int d = 0; d < 2; d++)
            for (size_t l = 0; l < sizeof gaussian / sizeof *gaussian; l += stride) {
                memcpy(noisy, shapes[s].xyz, 3 * nv * sizeof *noisy);
                mesh_noise_options o = {gaussian[l], d ? MESH_NOISE_RANDOM : MESH_NOISE_NORMAL,
                                        0,           400 + 10 * (uint64_t)d + l,
                                        0,           0};
                CHECK_EQ_INT(mesh_add_noise(noisy, nv, shapes[s].indices, nt, &o), 0);
                bool imp = reads_impulsive(&shapes[s], noisy);
                printf("%-9s Gaussian %s %.2f: %s\n", names[s], d ? "random" : "normal",
                       gaussian[l], imp ? "IMPULSIVE (wrong)" : "Gaussian");
                CHECK(!imp);
            }
        for (size_t f = 0; f < sizeof fractions / sizeof *fractions; f++)
            for (size_t l = 0; l < sizeof impulsive / sizeof *impulsive; l += stride) {
                memcpy(noisy, shapes[s].xyz, 3 * nv * sizeof *noisy);
                mesh_noise_options o = {impulsive[l],
                                        MESH_NOISE_NORMAL,
                                        fractions[f],
                                        500 + 10 * (uint64_t)f + l,
                                        0,
                                        0};
                CHECK_EQ_INT(mesh_add_noise(noisy, nv, shapes[s].indices, nt, &o), 0);
                bool imp = reads_impulsive(&shapes[s], noisy);
                printf("%-9s impulsive F %.2f %.1f: %s\n", names[s], fractions[f], impulsive[l],
                       imp ? "impulsive" : "GAUSSIAN (wrong)");
                CHECK(imp);
            }
        free(noisy);
        shape_free(&shapes[s]);
    }
}

/* Same result every run, with any thread count, for float32 and for the same surface as a soup. */
static void check_invariance(void) {
    shape_mesh m, soup;
    CHECK_EQ_INT(shape_sphere(&m, 4, 1.0), 0);
    CHECK_EQ_INT(shape_add_normal_noise(&m, 0.3, 5), 0);
    size_t nv = m.vertex_count, nt = m.triangle_count;
    setenv("RSMOOTH_HOST_THREADS", "1", 1);
    double one = estimate(m.xyz, nv, m.indices, nt);
    setenv("RSMOOTH_HOST_THREADS", "7", 1);
    double seven = estimate(m.xyz, nv, m.indices, nt);
    unsetenv("RSMOOTH_HOST_THREADS");
    double again = estimate(m.xyz, nv, m.indices, nt);
    CHECK(memcmp(&one, &seven, sizeof one) == 0);
    CHECK(memcmp(&one, &again, sizeof one) == 0);

    float *f = malloc(3 * nv * sizeof *f);
    CHECK(f);
    for (size_t i = 0; i < 3 * nv; i++)
        f[i] = (float)m.xyz[i];
    double single = -1;
    CHECK_STATUS(rsmooth_estimate_noise(RSMOOTH_FLOAT32, f, nv, m.indices, nt, &single, NULL),
                 RSMOOTH_OK);
    CHECK_NEAR(single / one, 1, 1e-3);
    free(f);

    CHECK_EQ_INT(shape_unindex(&m, &soup), 0);
    double as_soup = estimate(soup.xyz, soup.vertex_count, soup.indices, soup.triangle_count);
    CHECK_NEAR(as_soup / one, 1, 1e-6); /* copies are welded: the same points and normals */
    printf("sphere 0.3: %.6f on 1 and 7 threads and again, float32 %.6f, as a soup %.6f\n", one,
           single, as_soup);
    shape_free(&m);
    shape_free(&soup);
}

/* More vertices than the estimate samples (lib/auto/noise_estimate.c's MAX_SAMPLES, 6000): the
 * stride's subset reads the same noise. */
static void check_sampled(void) {
    shape_mesh clean, noisy;
    int side = test_small() ? 120 : 250; /* 14641 or 63001 vertices */
    CHECK_EQ_INT(shape_plane(&clean, side, side, 0.01), 0);
    CHECK_EQ_INT(shape_copy(&clean, &noisy), 0);
    CHECK_EQ_INT(shape_add_normal_noise(&noisy, 0.3, 11), 0);
    double t0 = now_ms();
    double est = estimate(noisy.xyz, noisy.vertex_count, noisy.indices, noisy.triangle_count);
    double truth = true_noise(&clean, noisy.xyz);
    printf(
        "plane %zu vertices (at most 6000 sampled), noise 0.3: truth %.4f estimate %.4f ratio %.3f "
        "(%.0f ms)\n",
        clean.vertex_count, truth, est, est / truth, now_ms() - t0);
    CHECK_NEAR(est / truth, 1, SHAPE_TOLERANCE);
    shape_free(&clean);
    shape_free(&noisy);
}

static void check_edge_cases(void) {
    const double xyz[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 5, 5, 5};
    const uint32_t tri[] = {0, 1, 2};
    const uint32_t degenerate[] = {0, 0, 0, 1, 1, 1};
    const uint32_t bad[] = {0, 1, 4};
    double noise = -1;
    rsmooth_error err;
    /* no edge of non-zero length, no triangle, a single triangle: 0 */
    CHECK_STATUS(rsmooth_estimate_noise(RSMOOTH_FLOAT64, xyz, 4, degenerate, 2, &noise, &err),
                 RSMOOTH_OK);
    CHECK(noise == 0);
    noise = -1;
    CHECK_STATUS(rsmooth_estimate_noise(RSMOOTH_FLOAT64, xyz, 4, NULL, 0, &noise, &err),
                 RSMOOTH_OK);
    CHECK(noise == 0);
    noise = -1;
    CHECK_STATUS(rsmooth_estimate_noise(RSMOOTH_FLOAT64, xyz, 4, tri, 1, &noise, &err), RSMOOTH_OK);
    CHECK(noise == 0);
    /* bad arrays */
    CHECK_STATUS(rsmooth_estimate_noise(RSMOOTH_FLOAT64, xyz, 4, tri, 1, NULL, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(err.message, "out_noise") != NULL);
    CHECK_STATUS(rsmooth_estimate_noise(RSMOOTH_FLOAT64, NULL, 4, tri, 1, &noise, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK_STATUS(rsmooth_estimate_noise(RSMOOTH_FLOAT64, xyz, 4, bad, 1, &noise, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK(strcmp(err.where, "rsmooth_estimate_noise") == 0);
    CHECK_STATUS(rsmooth_estimate_noise(RSMOOTH_FLOAT64, xyz, 4, NULL, 1, &noise, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK_STATUS(rsmooth_estimate_noise((rsmooth_scalar)9, xyz, 4, tri, 1, &noise, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    double nan_xyz[] = {0, 0, 0, 1, 0, 0, 0, NAN, 0};
    CHECK_STATUS(rsmooth_estimate_noise(RSMOOTH_FLOAT64, nan_xyz, 3, tri, 1, &noise, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    printf("no edges, no triangles, one triangle: 0; NULL output or positions, index out of range, "
           "bad scalar, NaN: invalid argument\n");
}

/* The benchmark meshes: the estimate on Noisy.obj against the true noise, Noisy - Original along
 * the original's normals (the files share vertex order and triangles). */
static void benchmark_meshes(void) {
    static const char *const models[] = {"Fandisk0.3", "Block0.4", "Bunny0.2", "SharpSphere0.3",
                                         "Twelve0.5Impulsive"};
    static const double nominal[] = {0.3, 0.4, 0.2, 0.3, 0.5};
    char dir[4096];
    if (!benchmark_dir(dir, sizeof dir))
        return;
    for (size_t i = 0; i < sizeof models / sizeof *models; i++) {
        if (test_small() && i > 0 && i < 4) /* the sanitizers: Fandisk and the impulsive one */
            continue;
        rsmooth_mesh *noisy = benchmark_read(dir, models[i], "Noisy.obj");
        if (!noisy)
            continue;
        double t0 = now_ms();
        double est = estimate(noisy->positions, noisy->vertex_count, noisy->triangles,
                              noisy->triangle_count);
        double ms = now_ms() - t0;
        double unit = mean_edge(noisy->positions, noisy->vertex_count, noisy->triangles,
                                noisy->triangle_count);
        rsmooth_mesh *original = benchmark_read(dir, models[i], "Original.obj");
        double truth = NAN, original_unit = NAN;
        if (original && original->vertex_count == noisy->vertex_count &&
            original->triangle_count == noisy->triangle_count &&
            memcmp(original->triangles, noisy->triangles,
                   3 * noisy->triangle_count * sizeof *noisy->triangles) == 0) {
            shape_mesh clean = {original->vertex_count, original->positions,
                                original->triangle_count, original->triangles};
            truth = true_noise(&clean, noisy->positions);
            original_unit = mean_edge(original->positions, original->vertex_count,
                                      original->triangles, original->triangle_count);
        }
        printf("%-18s %6zu vertices: estimate %.4f, truth %.4f (noisy mean edge lengths; nominal "
               "%.1f original edges = %.4f noisy edges), ratio %.3f  (%.0f ms)\n",
               models[i], noisy->vertex_count, est, truth, nominal[i],
               nominal[i] * original_unit / unit, est / truth, ms);
        if (strstr(models[i], "Impulsive") == NULL && !isnan(truth))
            CHECK_NEAR(est / truth, 1, BENCHMARK_TOLERANCE);
        /* the models' names say which noise is impulsive */
        check_auto(models[i], noisy->positions, noisy->vertex_count, noisy->triangles,
                   noisy->triangle_count, strstr(models[i], "Impulsive") != NULL);
        rsmooth_mesh_destroy(noisy);
        rsmooth_mesh_destroy(original);
    }
}

int main(void) {
    check_edge_cases();
    check_invariance();
    check_kind();
    generated_shapes();
    random_directions();
    check_sampled();
    benchmark_meshes();
    return 0;
}
