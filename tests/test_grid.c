/* The facet grid: neighbour queries through the 27 cells around a point equal a brute-force scan.
 */
#include "core/spatial.h"
#include "test_util.h"

#include <stdint.h>
#include <string.h>

static uint64_t next_u64(uint64_t *s) {
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

static double uniform(uint64_t *s, double lo, double hi) {
    return lo + (hi - lo) * ((double)(next_u64(s) >> 11) * 0x1.0p-53);
}

static int compare_u32(const void *a, const void *b) {
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return x < y ? -1 : x > y;
}

/* Within reach exactly as the filter decides it: squared distance of c - p against reach^2. */
static int within(const double *c, const double p[3], double reach) {
    double d[3];
    rs_sub3(c, p, d);
    return rs_dot3(d, d) <= reach * reach;
}

/* Facets (sorted) found through the grid's 27 cells around p. */
static size_t grid_query(const rs_grid *grid, const double *points, const double p[3], double reach,
                         uint32_t *out) {
    size_t n = 0;
    int32_t c[3];
    rs_grid_cell_of(grid, p, c);
    for (int dx = -1; dx <= 1; dx++)
        for (int dy = -1; dy <= 1; dy++)
            for (int dz = -1; dz <= 1; dz++) {
                int32_t cell = rs_grid_find(grid, c[0] + dx, c[1] + dy, c[2] + dz);
                if (cell < 0)
                    continue;
                CHECK((size_t)cell < grid->cell_count);
                for (uint32_t i = grid->cell_start[cell]; i < grid->cell_start[cell + 1]; i++) {
                    uint32_t q = grid->facet_order[i];
                    if (within(points + 3 * (size_t)q, p, reach))
                        out[n++] = q;
                }
            }
    qsort(out, n, sizeof *out, compare_u32);
    return n;
}

static size_t brute_query(const double *points, size_t count, const double p[3], double reach,
                          uint32_t *out) {
    size_t n = 0;
    for (size_t q = 0; q < count; q++)
        if (within(points + 3 * q, p, reach))
            out[n++] = (uint32_t)q;
    return n; /* already ascending */
}

/* Structure: facet_order a permutation, cell_start strictly increasing from 0 to count, every facet
 * in the cell its centroid maps to, every cell found by its coordinates. */
static void check_structure(const rs_grid *grid, const double *points, size_t count, double reach) {
    CHECK(grid->cell_size >= reach);
    CHECK(grid->cell_count >= 1 && grid->cell_count <= count);
    CHECK_EQ_INT(grid->cell_start[0], 0);
    CHECK_EQ_INT(grid->cell_start[grid->cell_count], count);
    unsigned char *seen = calloc(count, 1);
    CHECK(seen);
    for (size_t cell = 0; cell < grid->cell_count; cell++) {
        CHECK(grid->cell_start[cell] < grid->cell_start[cell + 1]); /* monotone, no empty cell */
        const int32_t *cc = grid->cell_coord + 4 * cell;
        CHECK_EQ_INT(rs_grid_find(grid, cc[0], cc[1], cc[2]), (int64_t)cell);
        for (uint32_t i = grid->cell_start[cell]; i < grid->cell_start[cell + 1]; i++) {
            uint32_t q = grid->facet_order[i];
            CHECK(q < count);
            CHECK(!seen[q]); /* exactly once */
            seen[q] = 1;
            int32_t c[3];
            rs_grid_cell_of(grid, points + 3 * (size_t)q, c);
            for (int k = 0; k < 3; k++) {
                int32_t clamped = c[k] < 0 ? 0 : c[k] >= grid->dims[k] ? grid->dims[k] - 1 : c[k];
                CHECK_EQ_INT(clamped, cc[k]);
            }
        }
    }
    for (size_t q = 0; q < count; q++)
        CHECK(seen[q]);
    free(seen);
}

/* Builds the grid, checks its structure and `queries` random queries drawn by `draw`. Returns the
 * number of neighbours found in all. */
typedef void (*draw_fn)(uint64_t *s, const double *points, size_t count, double reach, double p[3]);

static size_t run_case(const char *name, const double *points, size_t count, double reach,
                       size_t queries, uint64_t seed, draw_fn draw) {
    rs_grid grid;
    rsmooth_error err;
    CHECK_STATUS(rs_grid_build(&grid, points, count, reach, &err), RSMOOTH_OK);
    check_structure(&grid, points, count, reach);
    uint32_t *a = malloc(count * sizeof *a), *b = malloc(count * sizeof *b);
    CHECK(a && b);
    size_t total = 0, max_found = 0;
    for (size_t i = 0; i < queries; i++) {
        double p[3];
        draw(&seed, points, count, reach, p);
        size_t na = grid_query(&grid, points, p, reach, a);
        size_t nb = brute_query(points, count, p, reach, b);
        if (na != nb || memcmp(a, b, na * sizeof *a) != 0) {
            fprintf(stderr, "%s: query %zu at (%.17g, %.17g, %.17g): grid finds %zu, scan %zu\n",
                    name, i, p[0], p[1], p[2], na, nb);
            exit(1);
        }
        total += nb;
        max_found = nb > max_found ? nb : max_found;
    }
    printf("%-28s points %6zu reach %-8g cells %6zu cell %-10.4g dims %d x %d x %d: %zu queries, "
           "%zu neighbours (max %zu) all equal\n",
           name, count, reach, grid.cell_count, grid.cell_size, grid.dims[0], grid.dims[1],
           grid.dims[2], queries, total, max_found);
    free(a);
    free(b);
    rs_grid_free(&grid);
    return total;
}

/* Query draws: inside and around the box, near a point, and far outside. */
static double g_box_lo, g_box_hi;

static void draw_box(uint64_t *s, const double *points, size_t count, double reach, double p[3]) {
    (void)points;
    (void)count;
    double margin = 2 * reach + 1;
    for (int k = 0; k < 3; k++)
        p[k] = uniform(s, g_box_lo - margin, g_box_hi + margin);
}

static void draw_near_point(uint64_t *s, const double *points, size_t count, double reach,
                            double p[3]) {
    size_t q = (size_t)(next_u64(s) % count);
    for (int k = 0; k < 3; k++)
        p[k] = points[3 * q + k] + uniform(s, -1.2 * reach, 1.2 * reach);
}

static void draw_far(uint64_t *s, const double *points, size_t count, double reach, double p[3]) {
    (void)points;
    (void)count;
    (void)reach;
    static const double far[] = {-1e12, -1e7, 1e7, 1e12};
    for (int k = 0; k < 3; k++)
        p[k] = (next_u64(s) & 1) ? uniform(s, g_box_lo, g_box_hi) : far[next_u64(s) % 4];
}

static void draw_mixed(uint64_t *s, const double *points, size_t count, double reach, double p[3]) {
    uint64_t r = next_u64(s) % 10;
    if (r < 5)
        draw_near_point(s, points, count, reach, p);
    else if (r < 9)
        draw_box(s, points, count, reach, p);
    else
        draw_far(s, points, count, reach, p);
}

int main(void) {
    /* 1. Random soups: several seeds, box shapes and reaches (from much finer than the spacing to
     * wider than the whole box). */
    const size_t soup_count = 2000;
    double *points = malloc(3 * 50000 * sizeof *points);
    CHECK(points);
    static const double reaches[] = {0.05, 0.4, 1.7, 30.0};
    for (uint64_t seed = 1; seed <= 4; seed++) {
        uint64_t s = seed * 1000003u;
        double extent[3] = {10, seed == 2 ? 0.01 : 10, seed == 3 ? 1e3 : 10};
        for (size_t i = 0; i < soup_count; i++)
            for (int k = 0; k < 3; k++)
                points[3 * i + k] = uniform(&s, -extent[k] / 2, extent[k] / 2);
        if (seed == 4) /* many coincident centroids */
            for (size_t i = 0; i < soup_count / 2; i++)
                memcpy(points + 3 * i, points + 3 * (i % 7), 3 * sizeof(double));
        g_box_lo = -extent[2] / 2;
        g_box_hi = extent[2] / 2;
        for (size_t r = 0; r < sizeof reaches / sizeof reaches[0]; r++) {
            char name[64];
            snprintf(name, sizeof name, "soup seed %u", (unsigned)seed);
            run_case(name, points, soup_count, reaches[r], 600, seed * 31 + r, draw_mixed);
        }
    }

    /* One point; and all points equal. */
    points[0] = 1;
    points[1] = 2;
    points[2] = 3;
    g_box_lo = 0;
    g_box_hi = 4;
    run_case("single point", points, 1, 0.5, 200, 5, draw_mixed);
    for (size_t i = 1; i < 100; i++)
        memcpy(points + 3 * i, points, 3 * sizeof(double));
    run_case("100 equal points", points, 100, 0.5, 200, 6, draw_mixed);

    /* 2. Two clusters 1e7 units apart, reach 0.1: a dense grid would need 1e8 cells per axis. */
    {
        uint64_t s = 77;
        size_t n = 4000;
        for (size_t i = 0; i < n; i++) {
            double base = i < n / 2 ? 0.0 : 1e7;
            for (int k = 0; k < 3; k++)
                points[3 * i + k] = base + uniform(&s, 0, 2);
        }
        g_box_lo = -1;
        g_box_hi = 1e7 + 3;
        size_t found = run_case("two clusters 1e7 apart", points, n, 0.1, 1500, 8, draw_mixed);
        CHECK(found > 0);
    }

    /* 3. 1e4 clusters of 5 points spread over 1e6^3, reach 0.5: a dense grid would be (2e6)^3. */
    {
        uint64_t s = 99;
        size_t clusters = 10000, per = 5, n = clusters * per;
        for (size_t c = 0; c < clusters; c++) {
            double centre[3];
            for (int k = 0; k < 3; k++)
                centre[k] = uniform(&s, 0, 1e6);
            for (size_t j = 0; j < per; j++)
                for (int k = 0; k < 3; k++)
                    points[3 * (c * per + j) + k] = centre[k] + uniform(&s, -0.5, 0.5);
        }
        g_box_lo = 0;
        g_box_hi = 1e6;
        size_t found = run_case("1e4 clusters over 1e6", points, n, 0.5, 1500, 10, draw_mixed);
        CHECK(found > 0);
    }

    /* 4. Rounding at a cell boundary. The grid puts c and p (exactly 1 - 2.8e-17 apart, reach 1)
     * two cells apart: floor((c - o) / h) = 0 but floor((p - o) / h) = 2, because p - o rounds up
     * to exactly 2 while c - o stays below 1. A facet the filter counts as within reach
     * (|c - p|^2 <= reach^2, and also exactly) is missed by the 27-cell search: the cell size needs
     * a margin over the reach that covers rounding. */
    {
        const double o = -0.8298014645137356, c = 0.17019853548626432, q = 1.1701985354862643;
        const double pts[6] = {o, 0, 0, c, 0, 0};
        const double p[3] = {q, 0, 0};
        rs_grid grid;
        CHECK_STATUS(rs_grid_build(&grid, pts, 2, 1.0, NULL), RSMOOTH_OK);
        uint32_t a[2], b[2];
        size_t na = grid_query(&grid, pts, p, 1.0, a);
        size_t nb = brute_query(pts, 2, p, 1.0, b);
        int32_t cell_c[3], cell_p[3];
        rs_grid_cell_of(&grid, pts + 3, cell_c);
        rs_grid_cell_of(&grid, p, cell_p);
        printf("cell boundary rounding: |c - p| = %.17g, reach 1, cell size %.17g: c in cell %d, "
               "p in cell %d; grid finds %zu, scan %zu\n",
               fabs(q - c), grid.cell_size, cell_c[0], cell_p[0], na, nb);
        rs_grid_free(&grid);
        CHECK_EQ_INT(nb, 1);
        CHECK_EQ_INT(na, nb);
    }

    free(points);
    printf("grid: all queries equal the brute-force scan\n");
    return 0;
}
