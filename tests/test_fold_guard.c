/* The fold guard (lib/stages/fold_guard.c) on results made to fold, where the oracle is the
 * construction: which triangles were turned over is known, and so is what must not change.
 *  - clean input (a flat grid): one vertex dragged across its neighbours turns its triangles over;
 *    the guard leaves none turned over, moves only that vertex (pulled back toward the input),
 *    and leaves every other byte as it was;
 *  - noisy input (the grid with noise along its normal) and a flat result with one vertex dragged
 *    across its neighbours: the guard leaves no triangle facing against its neighbourhood that
 *    did not in the input, and moves only vertices near the fold;
 *  - a result turned over nowhere comes back byte for byte, with 0 vertices counted;
 *  - float32 positions give the same decisions as float64. */
#include "core/rsmooth_internal.h"
#include "mesh_shapes.h"
#include "stages/fold_guard.h"
#include "test_util.h"

#include <string.h>

static void normal_of(const double *xyz, const uint32_t *tri, double n[3]) {
    double e1[3], e2[3];
    rs_sub3(xyz + 3 * (size_t)tri[1], xyz + 3 * (size_t)tri[0], e1);
    rs_sub3(xyz + 3 * (size_t)tri[2], xyz + 3 * (size_t)tri[0], e2);
    rs_cross3(e1, e2, n);
}

/* Triangles of `out` turned by more than 90 degrees from `in`'s. */
static size_t turned_over(const shape_mesh *m, const double *in, const double *out) {
    size_t count = 0;
    for (size_t t = 0; t < m->triangle_count; t++) {
        double a[3], b[3];
        normal_of(in, m->indices + 3 * t, a);
        normal_of(out, m->indices + 3 * t, b);
        count += rs_dot3(a, b) < 0;
    }
    return count;
}

/* Triangles of `xyz` facing against the sum of the unit normals at their corners. */
static size_t facing_against(const shape_mesh *m, const double *xyz) {
    double *at = calloc(3 * m->vertex_count, sizeof *at);
    CHECK(at);
    for (size_t t = 0; t < m->triangle_count; t++) {
        double n[3];
        normal_of(xyz, m->indices + 3 * t, n);
        double len = sqrt(rs_dot3(n, n));
        for (int c = 0; c < 3 && len > 0; c++)
            for (int k = 0; k < 3; k++)
                at[3 * (size_t)m->indices[3 * t + c] + k] += n[k] / len;
    }
    size_t count = 0;
    for (size_t t = 0; t < m->triangle_count; t++) {
        const uint32_t *tri = m->indices + 3 * t;
        double n[3], r[3];
        normal_of(xyz, tri, n);
        for (int k = 0; k < 3; k++)
            r[k] = at[3 * (size_t)tri[0] + k] + at[3 * (size_t)tri[1] + k] +
                   at[3 * (size_t)tri[2] + k];
        count += rs_dot3(n, r) < 0;
    }
    free(at);
    return count;
}

/* The grid's vertex nearest its middle. */
static size_t middle(const shape_mesh *m) {
    size_t best = 0;
    for (size_t v = 0; v < m->vertex_count; v++)
        if (hypot(m->xyz[3 * v] - 1, m->xyz[3 * v + 1] - 1) <
            hypot(m->xyz[3 * best] - 1, m->xyz[3 * best + 1] - 1))
            best = v;
    return best;
}

static void clean_grid(void) {
    shape_mesh m;
    CHECK_EQ_INT(shape_plane(&m, 20, 20, 0.1), 0);
    size_t n = m.vertex_count, v = middle(&m);
    double *out = malloc(3 * n * sizeof *out), *before = malloc(3 * n * sizeof *before);
    CHECK(out && before);
    memcpy(out, m.xyz, 3 * n * sizeof *out);
    out[3 * v] += 0.25; /* across its right-hand neighbour */
    size_t turned = turned_over(&m, m.xyz, out);
    memcpy(before, out, 3 * n * sizeof *out);
    long pulled = rs_fold_guard(RSMOOTH_FLOAT64, m.xyz, out, n, m.indices, m.triangle_count, NULL);
    size_t changed = 0;
    for (size_t u = 0; u < n; u++)
        changed += memcmp(out + 3 * u, before + 3 * u, 3 * sizeof *out) != 0;
    printf("clean grid, a vertex dragged 2.5 cells: %zu triangles turned over, after the guard "
           "%zu; %ld vertex pulled back to %.3g cells from its place; %zu vertices changed\n",
           turned, turned_over(&m, m.xyz, out), pulled, (out[3 * v] - m.xyz[3 * v]) / 0.1, changed);
    CHECK(turned > 0);
    CHECK_EQ_INT(turned_over(&m, m.xyz, out), 0);
    CHECK_EQ_INT(pulled, 1);
    CHECK_EQ_INT(changed, 1);
    CHECK(out[3 * v] > m.xyz[3 * v] && out[3 * v] < m.xyz[3 * v] + 0.1); /* toward the input */

    /* float32: the same decisions */
    float *in32 = malloc(3 * n * sizeof *in32), *out32 = malloc(3 * n * sizeof *out32);
    CHECK(in32 && out32);
    for (size_t i = 0; i < 3 * n; i++) {
        in32[i] = (float)m.xyz[i];
        out32[i] = (float)before[i];
    }
    CHECK_EQ_INT(rs_fold_guard(RSMOOTH_FLOAT32, in32, out32, n, m.indices, m.triangle_count, NULL),
                 1);
    CHECK_NEAR(out32[3 * v], out[3 * v], 1e-6);

    /* nothing turned over: nothing changes */
    memcpy(out, m.xyz, 3 * n * sizeof *out);
    out[3 * v] += 0.04;
    memcpy(before, out, 3 * n * sizeof *out);
    CHECK_EQ_INT(rs_fold_guard(RSMOOTH_FLOAT64, m.xyz, out, n, m.indices, m.triangle_count, NULL),
                 0);
    CHECK(memcmp(out, before, 3 * n * sizeof *out) == 0);
    printf("clean grid, a vertex moved 0.4 cells: nothing turned over, nothing changed\n");
    free(in32);
    free(out32);
    free(out);
    free(before);
    shape_free(&m);
}

static void noisy_grid(void) {
    shape_mesh m;
    CHECK_EQ_INT(shape_plane(&m, 20, 20, 0.1), 0);
    size_t n = m.vertex_count, v = middle(&m);
    double *out = malloc(3 * n * sizeof *out), *flat = malloc(3 * n * sizeof *flat);
    CHECK(out && flat);
    memcpy(flat, m.xyz, 3 * n * sizeof *flat);
    CHECK_EQ_INT(shape_add_normal_noise(&m, 0.3, 7), 0); /* the input: noisy along z */
    memcpy(out, flat, 3 * n * sizeof *out);              /* the result: flat again */
    out[3 * v] += 0.25;
    size_t before = facing_against(&m, out), input = facing_against(&m, m.xyz);
    long pulled = rs_fold_guard(RSMOOTH_FLOAT64, m.xyz, out, n, m.indices, m.triangle_count, NULL);
    size_t after = facing_against(&m, out);
    double far = 0; /* the largest change more than 3 cells from the fold */
    for (size_t u = 0; u < n; u++)
        if (hypot(flat[3 * u] - flat[3 * v], flat[3 * u + 1] - flat[3 * v + 1]) > 0.3)
            for (int k = 0; k < 3; k++)
                far = fmax(far, fabs(out[3 * u + k] - flat[3 * u + k] - (u == v) * 0.25 * !k));
    printf("noisy grid (0.3 edges), flat result with a vertex dragged 2.5 cells: facing against "
           "its neighbourhood %zu (input %zu), after the guard %zu; %ld vertices moved, none "
           "beyond 3 cells (largest change there %.3g)\n",
           before, input, after, pulled, far);
    CHECK(before > 0);
    CHECK(after <= input);
    CHECK(pulled > 0);
    CHECK_EQ_INT(far, 0);

    /* held vertices (a caller's mask, outliers) stay where they are: hold every vertex but the
     * dragged one; the guard must fix the fold with that one alone */
    uint8_t *movable = calloc(n, 1);
    CHECK(movable);
    movable[v] = 1;
    double *held = malloc(3 * n * sizeof *held);
    CHECK(held);
    memcpy(out, flat, 3 * n * sizeof *out);
    out[3 * v] += 0.25;
    memcpy(held, out, 3 * n * sizeof *out);
    CHECK_EQ_INT(
        rs_fold_guard(RSMOOTH_FLOAT64, m.xyz, out, n, m.indices, m.triangle_count, movable), 1);
    for (size_t u = 0; u < n; u++)
        if (u != v)
            CHECK(memcmp(out + 3 * u, held + 3 * u, 3 * sizeof *out) == 0);
    CHECK(facing_against(&m, out) <= input);
    printf("the same with every other vertex held: only the dragged vertex moved, no fold left\n");
    free(movable);
    free(held);
    free(out);
    free(flat);
    shape_free(&m);
}

int main(void) {
    clean_grid();
    noisy_grid();
    return 0;
}
