/* The exact closest points rsmooth_compare rests on (lib/metrics/surface_index.c, internal): the
 * closest point of one triangle in each of its regions, on degenerate triangles and against
 * sampling, and the grid against brute force over every triangle on soups, a sphere and a plane. */
#include "mesh_shapes.h"
#include "metrics/surface_index.h"
#include "test_util.h"

#include <stdbool.h>
#include <stdint.h>
#include <string.h>

/* xorshift64*: uniform numbers that are the same on every platform. */
static double uniform(uint64_t *s) {
    *s ^= *s >> 12;
    *s ^= *s << 25;
    *s ^= *s >> 27;
    return (double)((*s * 2685821657736338717ull) >> 11) * 0x1.0p-53;
}

static double dist2(const double a[3], const double b[3]) {
    double x = a[0] - b[0], y = a[1] - b[1], z = a[2] - b[2];
    return x * x + y * y + z * z;
}

/* ---- the closest point on one triangle ----------------------------------------------------- */

/* The smallest squared distance from p to n*(n+1)/2 points spread over the triangle: an upper
 * bound on the true one, within (triangle size / n)^2 of it. */
static double sampled_dist2(const double p[3], const double a[3], const double b[3],
                            const double c[3], int n) {
    double best = INFINITY;
    for (int i = 0; i <= n; i++)
        for (int j = 0; i + j <= n; j++) {
            double u = (double)i / n, v = (double)j / n, q[3];
            for (int k = 0; k < 3; k++)
                q[k] = a[k] + u * (b[k] - a[k]) + v * (c[k] - a[k]);
            best = fmin(best, dist2(p, q));
        }
    return best;
}

static void test_triangle(void) {
    const double a[3] = {0, 0, 0}, b[3] = {2, 0, 0}, c[3] = {0, 2, 0};
    double q[3];
    /* Each Voronoi region of the triangle once: interior, three edges, three corners. */
    struct {
        double p[3], expect[3];
    } cases[] = {
        {{0.5, 0.5, 3}, {0.5, 0.5, 0}}, {{1, -1, 1}, {1, 0, 0}},  {{-1, 1, -1}, {0, 1, 0}},
        {{2, 2, 0.5}, {1, 1, 0}},       {{-1, -1, 2}, {0, 0, 0}}, {{3, -1, 0}, {2, 0, 0}},
        {{-1, 3, 0}, {0, 2, 0}},
    };
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        double d2 = rs_closest_on_triangle(cases[i].p, a, b, c, q);
        CHECK_NEAR(d2, dist2(cases[i].p, cases[i].expect), 1e-14);
        CHECK_NEAR(dist2(q, cases[i].expect), 0, 1e-28);
    }
    /* Degenerate triangles are the segments they collapse to: a point near the middle of a
     * collapsed edge is at its distance from that segment (Ericson's formulas give 0/0 there). */
    const double p[3] = {1.5, 0.3, 0.1};
    const double s0[3] = {2, 0, 0}, s1[3] = {1, 0, 0}, s2[3] = {3, 0, 0};
    double expect = 0.3 * 0.3 + 0.1 * 0.1;
    CHECK_NEAR(rs_closest_on_triangle(p, s0, s0, s1, q), expect, 1e-15);       /* a == b */
    CHECK_NEAR(rs_closest_on_triangle(p, s0, s1, s1, q), expect, 1e-15);       /* b == c */
    CHECK_NEAR(rs_closest_on_triangle(p, s1, s0, s1, q), expect, 1e-15);       /* c == a */
    CHECK_NEAR(rs_closest_on_triangle(p, s1, s2, s0, q), expect, 1e-15);       /* collinear */
    CHECK_NEAR(rs_closest_on_triangle(p, s0, s0, s0, q), dist2(p, s0), 1e-15); /* a point */

    /* Random triangles and points: the answer lies on the triangle and is no farther than any
     * sample of it. */
    uint64_t s = 0x9e3779b97f4a7c15ull;
    double worst_gap = 0, worst_off = 0;
    for (int trial = 0; trial < 400; trial++) {
        double t[3][3], pt[3];
        for (int v = 0; v < 3; v++)
            for (int k = 0; k < 3; k++)
                t[v][k] = uniform(&s) * 2 - 1;
        if (trial % 10 == 0) /* some needles and slivers */
            for (int k = 0; k < 3; k++)
                t[2][k] = t[0][k] + (t[1][k] - t[0][k]) * 0.7 + 1e-4 * uniform(&s);
        for (int k = 0; k < 3; k++)
            pt[k] = uniform(&s) * 4 - 2;
        double d2 = rs_closest_on_triangle(pt, t[0], t[1], t[2], q);
        CHECK_NEAR(d2, dist2(pt, q), 1e-12);
        /* q on the triangle: its distance from it (by the function itself) is ~0, and it lies in
         * the triangle's plane within the corners' hull. */
        double off = rs_closest_on_triangle(q, t[0], t[1], t[2], NULL);
        CHECK_LE(off, 1e-20); /* rounding, largest on the slivers */
        worst_off = fmax(worst_off, off);
        double sampled = sampled_dist2(pt, t[0], t[1], t[2], 60);
        CHECK_LE(d2, sampled + 1e-12);
        worst_gap = fmax(worst_gap, sampled - d2);
    }
    printf("triangle: 7 regions, 5 degenerate cases, 400 random triangles; largest sampled - exact "
           "squared distance %.3g (>= 0 required); closest points off their triangle by at most "
           "%.2g (squared)\n",
           worst_gap, worst_off);
}

/* ---- the grid against brute force ------------------------------------------------------------ */

static double brute_force(const double *xyz, const uint32_t *tris, size_t tri_count,
                          const double p[3], size_t *best_tri) {
    double best = INFINITY;
    *best_tri = SIZE_MAX;
    for (size_t t = 0; t < tri_count; t++) {
        const uint32_t *f = tris + 3 * t;
        double d = rs_closest_on_triangle(p, xyz + 3 * (size_t)f[0], xyz + 3 * (size_t)f[1],
                                          xyz + 3 * (size_t)f[2], NULL);
        if (d < best) { /* the first of equal ones, as the index breaks ties */
            best = d;
            *best_tri = t;
        }
    }
    return sqrt(best);
}

static void check_against_brute_force(const char *name, const double *xyz, size_t vertex_count,
                                      const uint32_t *tris, size_t tri_count, const double *points,
                                      size_t point_count) {
    rs_surface_index *ix = rs_surface_index_build(xyz, vertex_count, tris, tri_count);
    CHECK(ix != NULL);
    double max_d = 0;
    for (size_t i = 0; i < point_count; i++) {
        size_t t_grid = SIZE_MAX, t_brute;
        double q[3];
        double d_grid = rs_surface_index_query(ix, points + 3 * i, q, &t_grid);
        double d_brute = brute_force(xyz, tris, tri_count, points + 3 * i, &t_brute);
        if (d_grid != d_brute || t_grid != t_brute) {
            fprintf(stderr, "%s: point %zu: grid %.17g (triangle %zu), brute force %.17g (%zu)\n",
                    name, i, d_grid, t_grid, d_brute, t_brute);
            exit(1);
        }
        CHECK_NEAR(sqrt(dist2(points + 3 * i, q)), d_grid, 1e-12 * (1 + d_grid));
        max_d = fmax(max_d, d_grid);
    }
    printf("grid = brute force: %-34s %6zu triangles, %5zu points, all equal (largest distance "
           "%.3g)\n",
           name, tri_count, point_count, max_d);
    rs_surface_index_free(ix);
}

/* A random soup in the unit cube: `count` triangles of about `size`, a few of them huge or
 * degenerate, so cell sizes and multi-cell triangles get exercised. */
static void random_soup(uint64_t *s, size_t count, double size, double **xyz, uint32_t **tris) {
    *xyz = malloc(9 * count * sizeof **xyz);
    *tris = malloc(3 * count * sizeof **tris);
    CHECK(*xyz && *tris);
    for (size_t t = 0; t < count; t++) {
        double *v = *xyz + 9 * t, centre[3], scale = size;
        if (t % 97 == 5)
            scale = 1.0; /* spans much of the cube */
        for (int k = 0; k < 3; k++)
            centre[k] = uniform(s);
        for (int c = 0; c < 3; c++)
            for (int k = 0; k < 3; k++)
                v[3 * c + k] = centre[k] + (uniform(s) - 0.5) * scale;
        if (t % 53 == 7)
            memcpy(v + 3, v, 3 * sizeof *v); /* two corners coincide */
        if (t % 61 == 3)
            for (int k = 0; k < 3; k++)
                v[6 + k] = 0.5 * (v[k] + v[3 + k]); /* collinear */
        for (int c = 0; c < 3; c++)
            (*tris)[3 * t + c] = (uint32_t)(3 * t + (size_t)c);
    }
}

static double *random_points(uint64_t *s, size_t count, double lo, double hi) {
    double *p = malloc(3 * count * sizeof *p);
    CHECK(p);
    for (size_t i = 0; i < 3 * count; i++)
        p[i] = lo + (hi - lo) * uniform(s);
    return p;
}

static void test_grid(void) {
    uint64_t s = 12345;
    const struct {
        const char *name;
        size_t count;
        double size;
    } soups[] = {{"soup of small triangles", 3000, 0.05},
                 {"soup of mid-size triangles", 800, 0.3},
                 {"sparse soup", 40, 0.1},
                 {"one triangle", 1, 0.5}};
    for (size_t i = 0; i < sizeof soups / sizeof *soups; i++) {
        double *xyz;
        uint32_t *tris;
        random_soup(&s, soups[i].count, soups[i].size, &xyz, &tris);
        double *inside = random_points(&s, 1500, -0.1, 1.1);
        double *outside = random_points(&s, 300, -5, 6); /* mostly outside the grid */
        char name[96];
        snprintf(name, sizeof name, "%s, near", soups[i].name);
        check_against_brute_force(name, xyz, 3 * soups[i].count, tris, soups[i].count, inside,
                                  1500);
        snprintf(name, sizeof name, "%s, far", soups[i].name);
        check_against_brute_force(name, xyz, 3 * soups[i].count, tris, soups[i].count, outside,
                                  300);
        free(xyz);
        free(tris);
        free(inside);
        free(outside);
    }

    /* A closed surface with points on both sides of it and at its centre (the farthest the shells
     * ever have to grow from inside), and a flat one (a grid one cell thick). */
    shape_mesh sphere, plane;
    CHECK(shape_sphere(&sphere, 4, 1.0) == 0);
    CHECK(shape_plane(&plane, 30, 20, 0.1) == 0);
    double *pts = random_points(&s, 2000, -1.3, 1.3);
    memset(pts, 0, 3 * sizeof *pts);
    check_against_brute_force("sphere", sphere.xyz, sphere.vertex_count, sphere.indices,
                              sphere.triangle_count, pts, 2000);
    for (size_t i = 0; i < 2000; i++) {
        pts[3 * i] = 3.4 * uniform(&s) - 0.2;
        pts[3 * i + 1] = 2.4 * uniform(&s) - 0.2;
        pts[3 * i + 2] = (uniform(&s) - 0.5) * (i % 2 ? 0.02 : 2.0);
    }
    check_against_brute_force("plane", plane.xyz, plane.vertex_count, plane.indices,
                              plane.triangle_count, pts, 2000);
    free(pts);

    /* Empty index, bad input. */
    rs_surface_index *empty = rs_surface_index_build(NULL, 0, NULL, 0);
    CHECK(empty != NULL);
    const double origin[3] = {0, 0, 0};
    CHECK(isinf(rs_surface_index_query(empty, origin, NULL, NULL)));
    rs_surface_index_free(empty);
    uint32_t bad[3] = {0, 1, (uint32_t)sphere.vertex_count};
    CHECK(rs_surface_index_build(sphere.xyz, sphere.vertex_count, bad, 1) == NULL);
    rs_surface_index_free(NULL);
    shape_free(&sphere);
    shape_free(&plane);
}

int main(void) {
    test_triangle();
    test_grid();
    return 0;
}
