/* Depth-sensor noise (rsmooth noise --depth-sensor) against an oracle computed here from the clean
 * mesh and the camera's definition: displacements along the camera rays, spread sigma
 * (z / z_mean)^2 / max(c, grazing), depths on the quantisation lattice, ridges that are sinusoids
 * along one image axis, the seed's reproducibility, bad options refused. */
#include "mesh_noise_depth.h"
#include "mesh_shapes.h"
#include "test_util.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#define GRAZING 0.15
#define PERIOD 4.0

static mesh_depth_noise_options depth_options(double sigma, double quantum, double ridges,
                                              const double *view, uint64_t seed) {
    mesh_depth_noise_options o;
    memset(&o, 0, sizeof o);
    o.sigma = sigma;
    o.quantum = quantum;
    o.ridge_amplitude = ridges;
    o.ridge_period = PERIOD;
    o.grazing = GRAZING;
    o.seed = seed;
    if (view) {
        o.have_view = true;
        memcpy(o.view, view, sizeof o.view);
    }
    return o;
}

/* The noisy positions (caller frees) and the camera placed. */
static double *noisy(const shape_mesh *m, const mesh_depth_noise_options *o,
                     mesh_depth_noise_camera *cam) {
    double *xyz = malloc(3 * m->vertex_count * sizeof *xyz);
    CHECK(xyz);
    memcpy(xyz, m->xyz, 3 * m->vertex_count * sizeof *xyz);
    CHECK_EQ_INT(mesh_add_depth_noise(xyz, m->vertex_count, m->indices, m->triangle_count, o, cam),
                 0);
    return xyz;
}

/* The oracle's view of the clean mesh from a camera: per vertex the unit ray from the camera, the
 * distance z, (z / z_mean)^2 and the cosine c between the normal and the direction to the camera.
 */
typedef struct sight {
    double *ray, *z, *growth, *c;
    double edge;
} sight;

static sight look(const shape_mesh *m, const double camera[3]) {
    size_t n = m->vertex_count;
    sight s = {malloc(3 * n * sizeof(double)), malloc(n * sizeof(double)),
               malloc(n * sizeof(double)), malloc(n * sizeof(double)), shape_mean_edge_length(m)};
    double *normals = malloc(3 * n * sizeof *normals);
    CHECK(s.ray && s.z && s.growth && s.c && normals);
    CHECK_EQ_INT(shape_vertex_normals(m, normals), 0);
    double mean = 0;
    for (size_t v = 0; v < n; v++) {
        double r[3], len2 = 0;
        for (int k = 0; k < 3; k++)
            r[k] = m->xyz[3 * v + k] - camera[k], len2 += r[k] * r[k];
        s.z[v] = sqrt(len2);
        mean += s.z[v] / (double)n;
        s.c[v] = 0;
        for (int k = 0; k < 3; k++) {
            s.ray[3 * v + k] = r[k] / s.z[v];
            s.c[v] -= normals[3 * v + k] * s.ray[3 * v + k];
        }
    }
    for (size_t v = 0; v < n; v++)
        s.growth[v] = (s.z[v] / mean) * (s.z[v] / mean);
    free(normals);
    return s;
}

static void sight_free(sight *s) {
    free(s->ray), free(s->z), free(s->growth), free(s->c);
}

/* The displacement of vertex v along its ray, in mean edge lengths; *off its part across the ray
 * relative to the displacement's length. */
static double along(const shape_mesh *m, const double *xyz, const sight *s, size_t v, double *off) {
    double d[3], t = 0, across = 0, len = 0;
    for (int k = 0; k < 3; k++) {
        d[k] = xyz[3 * v + k] - m->xyz[3 * v + k];
        t += d[k] * s->ray[3 * v + k];
    }
    for (int k = 0; k < 3; k++) {
        double e = d[k] - t * s->ray[3 * v + k];
        across += e * e, len += d[k] * d[k];
    }
    if (off)
        *off = len > 0 ? sqrt(across / len) : 0;
    return t / s->edge;
}

/* Where the camera must be: 3 bounding-box diagonals from the box's centre along the view. */
static void expected_camera(const shape_mesh *m, const double view[3], double out[3]) {
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t v = 0; v < m->vertex_count; v++)
        for (int k = 0; k < 3; k++)
            lo[k] = fmin(lo[k], m->xyz[3 * v + k]), hi[k] = fmax(hi[k], m->xyz[3 * v + k]);
    double d2 = 0, u2 = 0;
    for (int k = 0; k < 3; k++)
        d2 += (hi[k] - lo[k]) * (hi[k] - lo[k]), u2 += view[k] * view[k];
    for (int k = 0; k < 3; k++)
        out[k] = 0.5 * (lo[k] + hi[k]) + 3 * sqrt(d2) * view[k] / sqrt(u2);
}

/* A plane of n x n edges tilted by `degrees` about the x axis. */
static shape_mesh tilted_plane(int n, double degrees) {
    shape_mesh m;
    CHECK_EQ_INT(shape_plane(&m, n, n, 1.0), 0);
    double a = degrees * 3.14159265358979323846 / 180;
    for (size_t v = 0; v < m.vertex_count; v++) {
        double y = m.xyz[3 * v + 1];
        m.xyz[3 * v + 1] = y * cos(a), m.xyz[3 * v + 2] = y * sin(a);
    }
    return m;
}

/* Facing the camera: every move lies on its ray; the camera where the definition puts it. */
static void test_along_rays(void) {
    shape_mesh plane = tilted_plane(80, 0);
    const double up[3] = {0, 0, 2};
    mesh_depth_noise_options o = depth_options(0.3, 0.15, 0.25, up, 5);
    mesh_depth_noise_camera cam;
    double *xyz = noisy(&plane, &o, &cam), want[3];
    expected_camera(&plane, up, want);
    for (int k = 0; k < 3; k++)
        CHECK_NEAR(cam.position[k], want[k], 1e-12 * fabs(want[2]));
    CHECK_NEAR(cam.view[2], 1, 1e-15);
    sight s = look(&plane, cam.position);
    double worst = 0, sum2 = 0;
    size_t moved = 0;
    for (size_t v = 0; v < plane.vertex_count; v++) {
        double off, t = along(&plane, xyz, &s, v, &off);
        worst = fmax(worst, off);
        sum2 += t * t;
        moved += t != 0;
    }
    printf("facing plane, %zu vertices: %zu moved, rms %.4f mean edge lengths, largest part "
           "across the ray %.2e of the move\n",
           plane.vertex_count, moved, sqrt(sum2 / (double)plane.vertex_count), worst);
    CHECK(worst < 1e-9);
    CHECK(moved > plane.vertex_count * 9 / 10);
    free(xyz);
    sight_free(&s);
    shape_free(&plane);
}

/* The spread grows as (z / z_mean)^2 / max(c, grazing): on a plane tilted 60 degrees from the
 * camera, the far half's rms over the near half's is the oracle's, and each vertex's move divided
 * by its own predicted sigma is a standard Gaussian. */
static void test_depth_growth(void) {
    shape_mesh plane = tilted_plane(120, 60);
    const double up[3] = {0, 0, 1};
    mesh_depth_noise_options o = depth_options(0.3, 0, 0, up, 9);
    mesh_depth_noise_camera cam;
    double *xyz = noisy(&plane, &o, &cam);
    sight s = look(&plane, cam.position);
    double z_sorted_mid = 0;
    for (size_t v = 0; v < plane.vertex_count; v++)
        z_sorted_mid += s.z[v] / (double)plane.vertex_count; /* halves by the mean depth */
    double got[2] = {0, 0}, want[2] = {0, 0}, unit2 = 0, count[2] = {0, 0};
    for (size_t v = 0; v < plane.vertex_count; v++) {
        int far = s.z[v] > z_sorted_mid;
        double t = along(&plane, xyz, &s, v, NULL);
        double sigma = 0.3 * s.growth[v] / fmax(s.c[v], GRAZING);
        got[far] += t * t, want[far] += sigma * sigma, count[far]++;
        unit2 += (t / sigma) * (t / sigma);
    }
    for (int h = 0; h < 2; h++)
        got[h] = sqrt(got[h] / count[h]), want[h] = sqrt(want[h] / count[h]);
    double unit = sqrt(unit2 / (double)plane.vertex_count);
    printf("tilted plane: rms near %.4f (oracle %.4f), far %.4f (oracle %.4f); far / near %.3f "
           "(oracle %.3f); move / own sigma rms %.4f\n",
           got[0], want[0], got[1], want[1], got[1] / got[0], want[1] / want[0], unit);
    CHECK(want[1] / want[0] > 1.3); /* the depth range makes a difference worth measuring */
    CHECK_NEAR(got[0] / want[0], 1, 0.04);
    CHECK_NEAR(got[1] / want[1], 1, 0.04);
    CHECK_NEAR((got[1] / got[0]) / (want[1] / want[0]), 1, 0.05);
    CHECK_NEAR(unit, 1, 0.02);
    free(xyz);
    sight_free(&s);
    shape_free(&plane);
}

/* Quantisation: every noisy depth is a whole number of steps q (z / z_mean)^2, and without the
 * Gaussian part within half a step of the clean depth. */
static void test_quantisation(void) {
    shape_mesh plane = tilted_plane(60, 40);
    const double view[3] = {0.3, -0.2, 1};
    const double sigmas[2] = {0, 0.3};
    for (int i = 0; i < 2; i++) {
        mesh_depth_noise_options o = depth_options(sigmas[i], 0.5, 0.25, view, 3);
        mesh_depth_noise_camera cam;
        double *xyz = noisy(&plane, &o, &cam);
        sight s = look(&plane, cam.position);
        double lattice = 0, reach = 0;
        size_t moved = 0;
        for (size_t v = 0; v < plane.vertex_count; v++) {
            double r2 = 0;
            for (int k = 0; k < 3; k++)
                r2 += (xyz[3 * v + k] - cam.position[k]) * (xyz[3 * v + k] - cam.position[k]);
            double step = 0.5 * s.edge * s.growth[v], k = sqrt(r2) / step;
            lattice = fmax(lattice, fabs(k - round(k)));
            reach = fmax(reach, fabs(sqrt(r2) - s.z[v]) / step);
            moved += memcmp(xyz + 3 * v, plane.xyz + 3 * v, 3 * sizeof *xyz) != 0;
        }
        printf("quantum 0.5, sigma %.1f: %zu of %zu moved; depth off the lattice by at most %.2e "
               "steps; largest move %.3f steps\n",
               sigmas[i], moved, plane.vertex_count, lattice, reach);
        CHECK(lattice < 1e-9);
        CHECK(moved > plane.vertex_count / 2);
        if (sigmas[i] == 0)
            CHECK(reach <= 0.5 + 1e-9);
        free(xyz);
        sight_free(&s);
    }
    shape_free(&plane);
}

/* Ridges: the difference the ridge term makes, over A sigma (z / z_mean)^2, is a sinusoid of the
 * image's horizontal coordinate: at most 1 in magnitude, rms 1 / sqrt(2), and (the plane facing
 * the camera) the same along each row of vertices parallel to the other image axis. */
static void test_ridges(void) {
    shape_mesh plane = tilted_plane(100, 0);
    const double up[3] = {0, 0, 1};
    mesh_depth_noise_options with = depth_options(0.3, 0, 0.5, up, 4),
                             without = depth_options(0.3, 0, 0, up, 4);
    mesh_depth_noise_camera cam;
    double *a = noisy(&plane, &with, &cam), *b = noisy(&plane, &without, NULL);
    sight s = look(&plane, cam.position);
    double largest = 0, sum2 = 0, row_spread = 0;
    size_t w = 101; /* vertices per row of the plane */
    double *wave = malloc(plane.vertex_count * sizeof *wave);
    CHECK(wave);
    for (size_t v = 0; v < plane.vertex_count; v++) {
        wave[v] = (along(&plane, a, &s, v, NULL) - along(&plane, b, &s, v, NULL)) /
                  (0.5 * 0.3 * s.growth[v]);
        largest = fmax(largest, fabs(wave[v]));
        sum2 += wave[v] * wave[v];
        row_spread =
            fmax(row_spread, fabs(wave[v] - wave[v - v % w])); /* against the row's first */
    }
    double rms = sqrt(sum2 / (double)plane.vertex_count);
    printf("ridges 0.5 x sigma every %.0f edges: largest %.6f, rms %.4f (sinusoid 0.7071), "
           "spread along a row %.2e\n",
           PERIOD, largest, rms, row_spread);
    CHECK(largest <= 1 + 1e-9);
    CHECK_NEAR(rms, sqrt(0.5), 0.03);
    CHECK(row_spread < 1e-9);
    free(wave), free(a), free(b);
    sight_free(&s);
    shape_free(&plane);
}

/* A sphere seen from +z: the half facing away and the vertices seen edge-on get 1 / grazing times
 * the noise of those facing the camera (over their own (z / z_mean)^2). */
static void test_grazing(void) {
    shape_mesh sphere;
    CHECK_EQ_INT(shape_sphere(&sphere, 5, 50.0), 0);
    const double up[3] = {0, 0, 1};
    mesh_depth_noise_options o = depth_options(0.3, 0, 0, up, 17);
    mesh_depth_noise_camera cam;
    double *xyz = noisy(&sphere, &o, &cam);
    sight s = look(&sphere, cam.position);
    double sum2[3] = {0, 0, 0}, count[3] = {0, 0, 0}; /* facing (c > 0.9), edge-on, behind */
    for (size_t v = 0; v < sphere.vertex_count; v++) {
        double t = along(&sphere, xyz, &s, v, NULL) / (0.3 * s.growth[v]);
        int group = s.c[v] > 0.9 ? 0 : s.c[v] < 0 ? 2 : s.c[v] < GRAZING ? 1 : -1;
        if (group >= 0)
            sum2[group] += t * t, count[group]++;
    }
    double rms[3];
    for (int g = 0; g < 3; g++)
        rms[g] = sqrt(sum2[g] / count[g]);
    printf("sphere %zu vertices, noise over sigma (z / z_mean)^2: facing %.3f (%.0f vertices), "
           "edge-on %.3f (%.0f), behind %.3f (%.0f); 1 / grazing %.3f\n",
           sphere.vertex_count, rms[0], count[0], rms[1], count[1], rms[2], count[2], 1 / GRAZING);
    CHECK_NEAR(rms[0], 1, 0.1); /* 1 / c in [1, 1.11] */
    CHECK_NEAR(rms[2] * GRAZING, 1, 0.05);
    CHECK_NEAR(rms[1] * GRAZING, 1, 0.12); /* fewer vertices */
    CHECK(rms[1] > 5 * rms[0]);
    free(xyz);
    sight_free(&s);
    shape_free(&sphere);
}

/* The seed: the same bytes again, other bytes and another camera with another seed; a view given
 * keeps the camera whatever the seed. A mesh at 1e-300 moves as the same mesh at 1 (scaled). */
static void test_seed_and_scale(void) {
    shape_mesh sphere;
    CHECK_EQ_INT(shape_sphere(&sphere, 3, 1.0), 0);
    size_t n = 3 * sphere.vertex_count;
    mesh_depth_noise_options o1 = depth_options(0.3, 0.15, 0.25, NULL, 1),
                             o2 = depth_options(0.3, 0.15, 0.25, NULL, 2);
    mesh_depth_noise_camera c1, c1b, c2;
    double *a = noisy(&sphere, &o1, &c1), *b = noisy(&sphere, &o1, &c1b),
           *c = noisy(&sphere, &o2, &c2);
    CHECK(memcmp(a, b, n * sizeof *a) == 0);
    CHECK(memcmp(a, c, n * sizeof *a) != 0);
    CHECK(memcmp(c1.view, c2.view, sizeof c1.view) != 0);
    printf("seed 1 view (%.3f, %.3f, %.3f), seed 2 view (%.3f, %.3f, %.3f)\n", c1.view[0],
           c1.view[1], c1.view[2], c2.view[0], c2.view[1], c2.view[2]);
    const double view[3] = {1, 2, 3};
    mesh_depth_noise_options g1 = depth_options(0.3, 0.15, 0.25, view, 1),
                             g2 = depth_options(0.3, 0.15, 0.25, view, 2);
    double *d = noisy(&sphere, &g1, &c1), *e = noisy(&sphere, &g2, &c2);
    CHECK(memcmp(c1.position, c2.position, sizeof c1.position) == 0);
    CHECK(memcmp(d, e, n * sizeof *d) != 0);

    shape_mesh tiny;
    CHECK_EQ_INT(shape_copy(&sphere, &tiny), 0);
    for (size_t i = 0; i < n; i++)
        tiny.xyz[i] *= 1e-300;
    double *t = noisy(&tiny, &g1, NULL), worst = 0;
    for (size_t i = 0; i < n; i++)
        worst = fmax(worst, fabs((t[i] - tiny.xyz[i]) * 1e300 - (d[i] - sphere.xyz[i])));
    printf("at 1e-300: moves differ from those at 1 by %.2e (times 1e300)\n", worst);
    CHECK(worst < 1e-9);
    free(a), free(b), free(c), free(d), free(e), free(t);
    shape_free(&tiny);
    shape_free(&sphere);
}

/* Bad options and arrays: -1, and the positions untouched. */
static void test_refused(void) {
    shape_mesh plane;
    CHECK_EQ_INT(shape_plane(&plane, 4, 4, 1.0), 0);
    size_t n = plane.vertex_count;
    double *xyz = malloc(3 * n * sizeof *xyz);
    CHECK(xyz);
    memcpy(xyz, plane.xyz, 3 * n * sizeof *xyz);
    const double zero[3] = {0, 0, 0};
    mesh_depth_noise_options bad[7];
    for (int i = 0; i < 7; i++)
        bad[i] = depth_options(0.3, 0.15, 0.25, NULL, 1);
    bad[0].sigma = -1;
    bad[1].grazing = 0;
    bad[2].grazing = 1.5;
    bad[3].ridge_period = 0;
    bad[4].quantum = NAN;
    bad[5] = depth_options(0.3, 0.15, 0.25, zero, 1);
    bad[6].ridge_amplitude = INFINITY;
    for (int i = 0; i < 7; i++)
        CHECK_EQ_INT(
            mesh_add_depth_noise(xyz, n, plane.indices, plane.triangle_count, &bad[i], NULL), -1);
    mesh_depth_noise_options good = depth_options(0.3, 0.15, 0.25, NULL, 1);
    plane.indices[4] = (uint32_t)n; /* out of range */
    CHECK_EQ_INT(mesh_add_depth_noise(xyz, n, plane.indices, plane.triangle_count, &good, NULL),
                 -1);
    CHECK_EQ_INT(mesh_add_depth_noise(xyz, n, plane.indices, plane.triangle_count, NULL, NULL), -1);
    CHECK(memcmp(xyz, plane.xyz, 3 * n * sizeof *xyz) == 0);
    free(xyz);
    shape_free(&plane);
}

int main(void) {
    test_along_rays();
    test_depth_growth();
    test_quantisation();
    test_ridges();
    test_grazing();
    test_seed_and_scale();
    test_refused();
    printf("noise_depth: all checks passed\n");
    return 0;
}
