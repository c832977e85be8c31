/* mesh_add_noise gives the noise it promises: its direction, spread, count and reproducibility. */
#include "mesh_noise.h"
#include "mesh_shapes.h"
#include "test_util.h"

#include <stdbool.h>
#include <stdint.h>
#include <string.h>

#define SIGMA 0.3

typedef struct noise_stats {
    size_t moved;
    double max_cross;              /* max |d x n|: 0 when every displacement is along the normal */
    double mean, std;              /* of d . n over moved vertices, in mesh units */
    double rms;                    /* of |d| over moved vertices */
    double dir_mean[3], dir_m2[3]; /* of d / |d|: mean and second moment per axis */
} noise_stats;

static double *copy_xyz(const shape_mesh *m) {
    double *xyz = malloc(3 * m->vertex_count * sizeof *xyz);
    CHECK(xyz);
    memcpy(xyz, m->xyz, 3 * m->vertex_count * sizeof *xyz);
    return xyz;
}

/* Noisy positions of `m` (caller frees). */
static double *noisy(const shape_mesh *m, double sigma, mesh_noise_direction direction,
                     double fraction, uint64_t seed) {
    double *xyz = copy_xyz(m);
    mesh_noise_options o = {sigma, direction, fraction, seed, 0, 0};
    CHECK_EQ_INT(mesh_add_noise(xyz, m->vertex_count, m->indices, m->triangle_count, &o), 0);
    return xyz;
}

static noise_stats measure(const shape_mesh *m, const double *out) {
    noise_stats s;
    memset(&s, 0, sizeof s);
    double *n = malloc(3 * m->vertex_count * sizeof *n);
    CHECK(n);
    CHECK_EQ_INT(shape_vertex_normals(m, n), 0);
    double sum = 0, sum2 = 0, r2 = 0;
    for (size_t v = 0; v < m->vertex_count; v++) {
        const double *a = m->xyz + 3 * v, *b = out + 3 * v, *nv = n + 3 * v;
        if (memcmp(a, b, 3 * sizeof *a) == 0)
            continue;
        s.moved++;
        double d[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        double c[3] = {d[1] * nv[2] - d[2] * nv[1], d[2] * nv[0] - d[0] * nv[2],
                       d[0] * nv[1] - d[1] * nv[0]};
        s.max_cross = fmax(s.max_cross, sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]));
        double along = d[0] * nv[0] + d[1] * nv[1] + d[2] * nv[2];
        sum += along;
        sum2 += along * along;
        r2 += len * len;
        for (int k = 0; k < 3; k++) {
            s.dir_mean[k] += d[k] / len;
            s.dir_m2[k] += d[k] * d[k] / (len * len);
        }
    }
    CHECK(s.moved > 1);
    double k = (double)s.moved;
    s.mean = sum / k;
    s.std = sqrt((sum2 - k * s.mean * s.mean) / (k - 1));
    s.rms = sqrt(r2 / k);
    for (int i = 0; i < 3; i++) {
        s.dir_mean[i] /= k;
        s.dir_m2[i] /= k;
    }
    free(n);
    return s;
}

/* NORMAL: along the normals, standard deviation sigma mean edge lengths, mean 0; and exactly
 * shape_add_normal_noise (the noise the other tests already use). */
static void check_normal(const char *name, const shape_mesh *m) {
    double edge = shape_mean_edge_length(m), scale = SIGMA * edge;
    double *out = noisy(m, SIGMA, MESH_NOISE_NORMAL, 0, 42);
    noise_stats s = measure(m, out);
    double se = s.std / sqrt((double)s.moved);
    printf("%-7s normal:  %zu/%zu moved, max |d x n| / (sigma * edge) %.2e, std %.6g "
           "(sigma * edge %.6g, ratio %.4f), mean %.3g (%.2f standard errors)\n",
           name, s.moved, m->vertex_count, s.max_cross / scale, s.std, scale, s.std / scale, s.mean,
           s.mean / se);
    CHECK_EQ_INT(s.moved, m->vertex_count);
    /* rounding only: d = (x + s n) - x is exact to an ulp of x, whatever |d| */
    CHECK_LE(s.max_cross / scale, 1e-10);
    CHECK_NEAR(s.std / scale, 1, 0.03);
    CHECK_LE(fabs(s.mean), 3 * se);

    shape_mesh same;
    CHECK_EQ_INT(shape_copy(m, &same), 0);
    CHECK_EQ_INT(shape_add_normal_noise(&same, SIGMA, 42), 0);
    CHECK(memcmp(same.xyz, out, 3 * m->vertex_count * sizeof *out) == 0);
    shape_free(&same);
    free(out);
}

/* RANDOM: directions uniform on the sphere (mean 0, each axis' second moment 1/3), and the
 * displacement's RMS sigma mean edge lengths. */
static void check_random(const char *name, const shape_mesh *m) {
    double scale = SIGMA * shape_mean_edge_length(m);
    double *out = noisy(m, SIGMA, MESH_NOISE_RANDOM, 0, 43);
    noise_stats s = measure(m, out);
    double se = sqrt(1.0 / (3.0 * (double)s.moved)); /* of one axis' mean: Var u_k = 1/3 */
    printf("%-7s random:  %zu/%zu moved, rms |d| / (sigma * edge) %.4f, mean direction "
           "(%.4f %.4f %.4f) (standard error %.4f), second moments (%.4f %.4f %.4f)\n",
           name, s.moved, m->vertex_count, s.rms / scale, s.dir_mean[0], s.dir_mean[1],
           s.dir_mean[2], se, s.dir_m2[0], s.dir_m2[1], s.dir_m2[2]);
    CHECK_EQ_INT(s.moved, m->vertex_count);
    CHECK_NEAR(s.rms / scale, 1, 0.03);
    for (int k = 0; k < 3; k++) {
        CHECK_LE(fabs(s.dir_mean[k]), 4 * se);
        CHECK_NEAR(s.dir_m2[k] * 3, 1, 0.05);
    }
    free(out);
}

/* Impulsive 0.1: exactly round(0.1 V) vertices moved, each exactly as under plain noise with the
 * same seed, the rest bit-identical; fraction 1 is plain noise. */
static void check_impulsive(const char *name, const shape_mesh *m, mesh_noise_direction dir) {
    size_t nv = m->vertex_count, want = (size_t)llround(0.1 * (double)nv);
    CHECK_EQ_INT(mesh_noise_moved_count(nv, 0.1), want);
    double *full = noisy(m, SIGMA, dir, 0, 44);
    double *part = noisy(m, SIGMA, dir, 0.1, 44);
    double *other = noisy(m, SIGMA, dir, 0.1, 45);
    double *all = noisy(m, SIGMA, dir, 1, 44);
    size_t moved = 0, same_choice = 0;
    for (size_t v = 0; v < nv; v++) {
        const double *a = m->xyz + 3 * v;
        bool p = memcmp(a, part + 3 * v, 3 * sizeof *a) != 0;
        bool o = memcmp(a, other + 3 * v, 3 * sizeof *a) != 0;
        moved += p;
        same_choice += p && o;
        /* moved: as the plain noise; not moved: bit-identical (memcmp said so) */
        if (p)
            CHECK(memcmp(part + 3 * v, full + 3 * v, 3 * sizeof *a) == 0);
    }
    noise_stats s = measure(m, part);
    double scale = SIGMA * shape_mean_edge_length(m);
    printf("%-7s impulsive 0.1 %s: %zu/%zu moved (round(0.1 V) = %zu), rest bit-identical; "
           "%s %.4f; seed 45 picks %zu of the same vertices (chance: %.0f)\n",
           name, dir == MESH_NOISE_NORMAL ? "normal" : "random", moved, nv, want,
           dir == MESH_NOISE_NORMAL ? "std / (sigma * edge)" : "rms / (sigma * edge)",
           (dir == MESH_NOISE_NORMAL ? s.std : s.rms) / scale, same_choice,
           (double)want * (double)want / (double)nv);
    CHECK_EQ_INT(moved, want);
    CHECK_EQ_INT(s.moved, want);
    /* ~1000 vertices: the standard error of a standard deviation is ~2.2 %; 4.5 of them */
    CHECK_NEAR((dir == MESH_NOISE_NORMAL ? s.std : s.rms) / scale, 1, 0.1);
    CHECK(same_choice < want / 2); /* another seed chooses other vertices (expected ~0.1 want) */
    CHECK(memcmp(all, full, 3 * nv * sizeof *all) == 0);
    free(full);
    free(part);
    free(other);
    free(all);
}

/* Same seed: the same bits; another seed: other bits; sigma 0: nothing changes, not even -0.0. */
static void check_reproducible(const shape_mesh *m) {
    size_t bytes = 3 * m->vertex_count * sizeof(double);
    for (int dir = 0; dir < 2; dir++)
        for (int imp = 0; imp < 2; imp++) {
            double f = imp ? 0.1 : 0;
            double *a = noisy(m, SIGMA, (mesh_noise_direction)dir, f, 7);
            double *b = noisy(m, SIGMA, (mesh_noise_direction)dir, f, 7);
            double *c = noisy(m, SIGMA, (mesh_noise_direction)dir, f, 8);
            CHECK(memcmp(a, b, bytes) == 0);
            CHECK(memcmp(a, c, bytes) != 0);
            free(a);
            free(b);
            free(c);
        }
    double *z = copy_xyz(m);
    z[2] = -0.0;
    double *before = malloc(bytes);
    CHECK(before);
    memcpy(before, z, bytes);
    for (int dir = 0; dir < 2; dir++) {
        mesh_noise_options o = {0, (mesh_noise_direction)dir, 0, 7, 0, 0};
        CHECK_EQ_INT(mesh_add_noise(z, m->vertex_count, m->indices, m->triangle_count, &o), 0);
        o.impulsive_fraction = 0.5;
        CHECK_EQ_INT(mesh_add_noise(z, m->vertex_count, m->indices, m->triangle_count, &o), 0);
    }
    CHECK(memcmp(z, before, bytes) == 0);
    printf("same seed: bit-identical; other seed: different; sigma 0: unchanged (-0.0 kept)\n");
    free(z);
    free(before);
}

/* A vertex no triangle uses has no normal: NORMAL mode moves it in a random direction, and the
 * other vertices move exactly as without it. */
static void check_unreferenced(const shape_mesh *m) {
    shape_mesh extra;
    memset(&extra, 0, sizeof extra);
    extra.vertex_count = m->vertex_count + 1;
    extra.triangle_count = m->triangle_count;
    extra.xyz = malloc(3 * extra.vertex_count * sizeof *extra.xyz);
    CHECK(extra.xyz);
    memcpy(extra.xyz, m->xyz, 3 * m->vertex_count * sizeof *m->xyz);
    for (int k = 0; k < 3; k++)
        extra.xyz[3 * m->vertex_count + (size_t)k] = 5;
    extra.indices = m->indices; /* shared, read-only */
    double *a = noisy(m, SIGMA, MESH_NOISE_NORMAL, 0, 9);
    double *b = noisy(&extra, SIGMA, MESH_NOISE_NORMAL, 0, 9);
    CHECK(memcmp(a, b, 3 * m->vertex_count * sizeof *a) == 0);
    const double *p = b + 3 * m->vertex_count;
    double moved =
        sqrt((p[0] - 5) * (p[0] - 5) + (p[1] - 5) * (p[1] - 5) + (p[2] - 5) * (p[2] - 5));
    printf("unreferenced vertex: moved %.4g (others as without it)\n", moved);
    CHECK(moved > 0 && isfinite(moved));
    free(a);
    free(b);
    free(extra.xyz);
}

static void check_bad_options(const shape_mesh *m) {
    size_t bytes = 3 * m->vertex_count * sizeof(double);
    double *xyz = copy_xyz(m);
    const mesh_noise_options bad[] = {
        {-1, MESH_NOISE_NORMAL, 0, 1, 0, 0},        {NAN, MESH_NOISE_NORMAL, 0, 1, 0, 0},
        {INFINITY, MESH_NOISE_NORMAL, 0, 1, 0, 0},  {0.3, MESH_NOISE_NORMAL, -0.1, 1, 0, 0},
        {0.3, MESH_NOISE_NORMAL, 1.1, 1, 0, 0},     {0.3, MESH_NOISE_RANDOM, NAN, 1, 0, 0},
        {0.3, (mesh_noise_direction)7, 0, 1, 0, 0}, {0.3, MESH_NOISE_NORMAL, 0, 1, -1, 0},
        {0.3, MESH_NOISE_NORMAL, 0, 1, NAN, 0},     {0.3, MESH_NOISE_NORMAL, 0, 1, 0, -2},
        {0.3, MESH_NOISE_NORMAL, 0, 1, 2, 3},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
        CHECK_EQ_INT(mesh_add_noise(xyz, m->vertex_count, m->indices, m->triangle_count, &bad[i]),
                     -1);
    mesh_noise_options good = {0.3, MESH_NOISE_NORMAL, 0, 1, 0, 0};
    CHECK_EQ_INT(mesh_add_noise(xyz, m->vertex_count, m->indices, m->triangle_count, NULL), -1);
    CHECK_EQ_INT(mesh_add_noise(NULL, m->vertex_count, m->indices, m->triangle_count, &good), -1);
    CHECK_EQ_INT(mesh_add_noise(xyz, m->vertex_count, NULL, m->triangle_count, &good), -1);
    /* an index out of range: the last vertex dropped */
    CHECK_EQ_INT(mesh_add_noise(xyz, m->vertex_count - 1, m->indices, m->triangle_count, &good),
                 -1);
    CHECK(memcmp(xyz, m->xyz, bytes) == 0);
    /* no triangles: no unit, nothing moves */
    CHECK_EQ_INT(mesh_add_noise(xyz, m->vertex_count, NULL, 0, &good), 0);
    CHECK(memcmp(xyz, m->xyz, bytes) == 0);
    CHECK_EQ_INT(mesh_add_noise(NULL, 0, NULL, 0, &good), 0);
    free(xyz);

    CHECK_EQ_INT(mesh_noise_moved_count(10, 0), 10);
    CHECK_EQ_INT(mesh_noise_moved_count(10, 1), 10);
    CHECK_EQ_INT(mesh_noise_moved_count(10, 0.05), 1); /* 0.5 rounds away from zero */
    CHECK_EQ_INT(mesh_noise_moved_count(3, 0.1), 0);
    CHECK_EQ_INT(mesh_noise_moved_count(10201, 0.1), 1020);
    printf("bad options (sigma -1, NaN, inf; fraction -0.1, 1.1, NaN; direction 7; NULL arrays; "
           "index out of range): -1, positions unchanged\n");
}

int main(void) {
    shape_mesh sphere, plane;
    CHECK_EQ_INT(shape_sphere(&sphere, 5, 1.0), 0);       /* 10242 vertices */
    CHECK_EQ_INT(shape_plane(&plane, 100, 100, 0.01), 0); /* 10201 vertices */
    const shape_mesh *meshes[2] = {&sphere, &plane};
    const char *names[2] = {"sphere", "plane"};
    for (int i = 0; i < 2; i++) {
        check_normal(names[i], meshes[i]);
        check_random(names[i], meshes[i]);
        check_impulsive(names[i], meshes[i], MESH_NOISE_NORMAL);
        check_impulsive(names[i], meshes[i], MESH_NOISE_RANDOM);
    }
    check_reproducible(&plane);
    check_unreferenced(&sphere);
    check_bad_options(&sphere);
    shape_free(&sphere);
    shape_free(&plane);
    return 0;
}
