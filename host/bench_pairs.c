/* Vertex-facet pairs within reach on a uniform grid of facet centroids (see bench_pairs.h). Written
 * apart from lib/core/grid.c on purpose: a second, plain implementation whose counts check the
 * library's. */
#include "bench_pairs.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Cells beyond this from the origin are refused (facets) or clamped to it (far vertices), so cell
 * coordinates and their neighbours fit int32. */
#define CELL_LIMIT (1 << 30)

typedef struct keyed_facet {
    int32_t cell[3];
    uint32_t facet; /* in triangle order */
} keyed_facet;

static int compare_cells(const int32_t *a, const int32_t *b) {
    for (int k = 0; k < 3; k++)
        if (a[k] != b[k])
            return a[k] < b[k] ? -1 : 1;
    return 0;
}

static int compare_keyed(const void *a, const void *b) {
    const keyed_facet *x = a, *y = b;
    int c = compare_cells(x->cell, y->cell);
    return c ? c : (x->facet > y->facet) - (x->facet < y->facet);
}

static void load_vertex(const float *positions, uint32_t v, double out[3]) {
    for (int k = 0; k < 3; k++)
        out[k] = (double)positions[3 * (size_t)v + k];
}

void bench_grid_cell(const bench_grid *grid, const double p[3], int32_t cell[3]) {
    for (int k = 0; k < 3; k++) {
        double c = floor((p[k] - grid->origin[k]) / grid->cell_size);
        cell[k] = (int32_t)fmax(-CELL_LIMIT, fmin(CELL_LIMIT, c));
    }
}

int bench_grid_build(bench_grid *grid, const float *positions, const uint32_t *indices,
                     size_t triangle_count, double cell_size) {
    memset(grid, 0, sizeof *grid);
    grid->cell_size = cell_size;
    size_t n = triangle_count ? triangle_count : 1;
    keyed_facet *keys = malloc(n * sizeof *keys);
    double *facet = malloc(n * 7 * sizeof *facet); /* centroid, normal, area, triangle order */
    grid->cell = malloc(n * 3 * sizeof *grid->cell);
    grid->centroid = malloc(n * 3 * sizeof *grid->centroid);
    grid->normal = malloc(n * 3 * sizeof *grid->normal);
    grid->area = malloc(n * sizeof *grid->area);
    if (!keys || !facet || !grid->cell || !grid->centroid || !grid->normal || !grid->area)
        goto fail;

    /* The facets as the library finds them: triangles with a non-zero, finite cross product. */
    size_t nf = 0;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    double area_sum = 0;
    for (size_t t = 0; t < triangle_count; t++) {
        double a[3], b[3], c[3], e1[3], e2[3];
        load_vertex(positions, indices[3 * t], a);
        load_vertex(positions, indices[3 * t + 1], b);
        load_vertex(positions, indices[3 * t + 2], c);
        for (int k = 0; k < 3; k++)
            e1[k] = b[k] - a[k], e2[k] = c[k] - a[k];
        double cross[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                           e1[0] * e2[1] - e1[1] * e2[0]};
        double len = sqrt(cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]);
        if (!(len > 0) || !isfinite(len))
            continue;
        double *f = facet + 7 * nf;
        for (int k = 0; k < 3; k++) {
            f[k] = (a[k] + b[k] + c[k]) / 3.0;
            f[3 + k] = cross[k] / len;
            lo[k] = fmin(lo[k], f[k]);
            hi[k] = fmax(hi[k], f[k]);
        }
        f[6] = 0.5 * len;
        area_sum += f[6];
        nf++;
    }
    for (int k = 0; k < 3; k++) {
        grid->origin[k] = nf ? lo[k] : 0;
        if (nf && !((hi[k] - lo[k]) / cell_size < CELL_LIMIT - 2))
            goto fail;
    }
    for (size_t f = 0; f < nf; f++) {
        bench_grid_cell(grid, facet + 7 * f, keys[f].cell);
        keys[f].facet = (uint32_t)f;
    }
    qsort(keys, nf, sizeof *keys, compare_keyed);
    for (size_t s = 0; s < nf; s++) {
        const double *f = facet + 7 * (size_t)keys[s].facet;
        memcpy(grid->cell + 3 * s, keys[s].cell, sizeof keys[s].cell);
        memcpy(grid->centroid + 3 * s, f, 3 * sizeof *f);
        memcpy(grid->normal + 3 * s, f + 3, 3 * sizeof *f);
        grid->area[s] = f[6];
    }
    grid->facet_count = nf;
    grid->mean_area = nf ? area_sum / (double)nf : 0;
    free(keys);
    free(facet);
    return 0;

fail:
    free(keys);
    free(facet);
    bench_grid_free(grid);
    return -1;
}

size_t bench_grid_first_facet(const bench_grid *grid, const int32_t cell[3]) {
    size_t lo = 0, hi = grid->facet_count;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (compare_cells(grid->cell + 3 * mid, cell) < 0)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

uint64_t bench_pairs_within(const bench_grid *grid, const float *positions, size_t vertex_count,
                            double radius) {
    if (!(radius > 0) || radius > grid->cell_size)
        return 0;
    const double r2 = radius * radius;
    uint64_t count = 0;
    for (size_t v = 0; v < vertex_count; v++) {
        double p[3];
        int32_t home[3];
        load_vertex(positions, (uint32_t)v, p);
        bench_grid_cell(grid, p, home);
        /* The 3 cells along z of one (x, y) column are contiguous in the grid's order. */
        for (int dx = -1; dx <= 1; dx++)
            for (int dy = -1; dy <= 1; dy++) {
                int32_t first[3] = {home[0] + dx, home[1] + dy, home[2] - 1};
                int32_t last[3] = {home[0] + dx, home[1] + dy, home[2] + 1};
                for (size_t f = bench_grid_first_facet(grid, first);
                     f < grid->facet_count && compare_cells(grid->cell + 3 * f, last) <= 0; f++) {
                    const double *c = grid->centroid + 3 * f;
                    double ex = c[0] - p[0], ey = c[1] - p[1], ez = c[2] - p[2];
                    count += ex * ex + ey * ey + ez * ez <= r2;
                }
            }
    }
    return count;
}

void bench_grid_free(bench_grid *grid) {
    free(grid->cell);
    free(grid->centroid);
    free(grid->normal);
    free(grid->area);
    memset(grid, 0, sizeof *grid);
}
