/* Vertex-facet pairs within reach, counted independently of the library for rsmooth-bench: the
 * "useful" work of a filter pass, against which the pairs the kernels evaluate are measured. A
 * uniform grid over the facet centroids (triangles of non-zero area), in double. */
#ifndef RSMOOTH_BENCH_PAIRS_H
#define RSMOOTH_BENCH_PAIRS_H

#include <stddef.h>
#include <stdint.h>

/* Facets sorted by grid cell (x, then y, then z): facets of one cell are contiguous, and nearby
 * cells mostly near each other in the arrays. */
typedef struct bench_grid {
    double cell_size; /* mesh units */
    double origin[3]; /* corner of cell (0, 0, 0): the lowest centroid */
    size_t facet_count;
    int32_t *cell;    /* 3 per facet: its cell's (x, y, z) */
    double *centroid; /* 3 per facet */
    double *normal;   /* 3 per facet, unit */
    double *area;     /* 1 per facet */
    double mean_area;
} bench_grid;

/* Builds the grid of the triangles of non-zero area of a float32 mesh (3 floats per vertex, 3
 * indices per triangle, each < vertex_count), with cells of `cell_size` mesh units (> 0).
 * Returns 0, or -1 when memory runs out or the mesh spans more than 2^30 cells (grid empty). */
int bench_grid_build(bench_grid *grid, const float *positions, const uint32_t *indices,
                     size_t triangle_count, double cell_size);

/* The cell holding point p (far points are clamped to cells no facet is near). */
void bench_grid_cell(const bench_grid *grid, const double p[3], int32_t cell[3]);

/* Index of the first facet whose cell is not before `cell` in the grid's order (facet_count when
 * none). */
size_t bench_grid_first_facet(const bench_grid *grid, const int32_t cell[3]);

/* Number of (vertex, facet) pairs with |centroid - vertex| <= radius, for the `vertex_count`
 * float32 vertices at `positions`. radius must not exceed the cell size. */
uint64_t bench_pairs_within(const bench_grid *grid, const float *positions, size_t vertex_count,
                            double radius);

/* Frees the arrays; the grid is then empty. Accepts an empty grid. */
void bench_grid_free(bench_grid *grid);

#endif
