/* The spatial indexes both paths search: the uniform grid over facet centroids and the k-d tree
 * over point clouds. Internal, not installed. */
#ifndef RSMOOTH_SPATIAL_H
#define RSMOOTH_SPATIAL_H

#include "core/rsmooth_internal.h"

/* ---- grid.c: uniform grid over facet centroids, facets sorted by cell -------------------------
 */

/* Occupied cells are found through an open-addressing hash on their integer coordinates, so
 * far-apart components cost no empty cells. Cell edge >= reach / split, so a vertex's neighbours
 * lie within `split` cells of its own (the 27 around it when split is 1). */
typedef struct rs_grid {
    double origin[3];      /* origin_cell * cell_size: at or below the centroids' minimum */
    double origin_cell[3]; /* whole numbers: the cells count from this one of the lattice of
                            * cell_size from 0, so a subset of the points (a tile, a piece of a
                            * larger mesh) sees the same cells and corners as the whole */
    double cell_size;      /* h >= reach / split */
    double inv_cell_size;  /* 1 / h: cells are found by multiplying (the margin in h absorbs
                              the rounding) */
    int32_t split;         /* cells per reach */
    int32_t dims[3];       /* cells per axis covering the centroids */
    size_t cell_count;     /* occupied cells */
    int32_t *cell_coord;   /* 4 per cell: x, y, z, 0 */
    uint32_t
        *cell_start; /* cell_count + 1: facets of cell i are facet_order[start[i]..start[i+1]) */
    uint32_t *facet_order; /* facet ids sorted by cell */
    /* rs_grid_build only: a hash table of the occupied cells */
    uint32_t table_mask; /* hash table size - 1 (a power of two) */
    int32_t *table;      /* table_mask + 1 slots: cell index or -1 */
    /* rs_grid_build_columns only. Columns: the occupied cells of one (x, y), consecutive in cell
     * order (sorted by x, y, z). */
    size_t column_count;
    uint32_t *column_first; /* column_count + 1: cells of column j are column_first[j] .. [j+1]-1 */
    uint32_t column_mask;   /* column hash table size - 1 */
    int32_t *column_table;  /* column_mask + 1 slots: column index or -1, hashed on (x, y, 0) */
} rs_grid;

/* Builds the grid over `count` points (3 doubles each) with cells at least `reach` wide, its
 * occupied cells found through `table` (rs_grid_find): the reference path's grid. */
rsmooth_status rs_grid_build(rs_grid *grid, const double *points, size_t count, double reach,
                             rsmooth_error *error);
/* The OpenCL path's grid: cells at least reach / split wide (split >= 1) over the box [lo, hi],
 * which must hold every point (it may hold more: the OpenCL path makes it hold the vertices too, so
 * none of them is clamped), its occupied cells found by column (no `table`). */
rsmooth_status rs_grid_build_columns(rs_grid *grid, const double *points, size_t count,
                                     double reach, int split, const double lo[3],
                                     const double hi[3], rsmooth_error *error);
void rs_grid_free(rs_grid *grid);

/* The steps of rs_grid_build_columns, for a caller that sorts the facets elsewhere (the device,
 * lib/opencl/cl_grid.c): rs_grid_layout zeroes *grid and sets its cell size, origin and dims;
 * the caller fills cell_count, cell_coord, cell_start and facet_order exactly as the host sort
 * would (cells in x, y, z order, each cell's facets in increasing index, rs_alloc'ed);
 * rs_grid_index_columns then adds the columns (false when out of memory). */
void rs_grid_layout(rs_grid *grid, double reach, int split, const double lo[3], const double hi[3]);
bool rs_grid_index_columns(rs_grid *grid);

/* Cell coordinates of a point, clamped to [-split - 1, dims + split]: a point clamped there is more
 * than `split` cells away from every facet, so clamping never loses a neighbour. */
void rs_grid_cell_of(const rs_grid *grid, const double p[3], int32_t cell[3]);

/* Index of the occupied cell at (x, y, z), or -1 (a grid from rs_grid_build). */
int32_t rs_grid_find(const rs_grid *grid, int32_t x, int32_t y, int32_t z);

/* The hash both host and kernels use to place a cell in the table. */
static inline uint32_t rs_grid_hash(int32_t x, int32_t y, int32_t z) {
    return ((uint32_t)x * 73856093u) ^ ((uint32_t)y * 19349663u) ^ ((uint32_t)z * 83492791u);
}

/* Orders `count` points (3 doubles each) by grid cell in Morton (Z) order, so points that follow
 * each other are close in every direction: order[i] is the index of the i-th point in that order
 * and cells[3 i .. 3 i + 2] its cell (as rs_grid_cell_of gives it). */
rsmooth_status rs_grid_order_points(const rs_grid *grid, const double *points, size_t count,
                                    uint32_t *order, int32_t *cells, rsmooth_error *error);

/* ---- kdtree.c: neighbour queries over a point set (point clouds) ------------------------------
 */

typedef struct rs_kdtree {
    const double *xyz; /* 3 per point, borrowed: must outlive the tree */
    size_t count;
    uint32_t *order; /* point indices, arranged as the tree's ranges */
    uint8_t *axis;   /* split axis of each internal node */
    double *split;   /* and the coordinate it splits at: left <= split <= right */
} rs_kdtree;

/* Builds the tree over `count` points (< 2^32). false when out of memory (tree then empty). */
bool rs_kdtree_build(rs_kdtree *tree, const double *xyz, size_t count);
void rs_kdtree_free(rs_kdtree *tree);

/* The squared distances from p to its k nearest points, point `skip` left out (UINT32_MAX: none),
 * nearest first, into dist2[0 ..); returns how many were found (k, or fewer points). Thread-safe
 * on a built tree. */
size_t rs_kdtree_nearest(const rs_kdtree *tree, const double p[3], uint32_t skip, size_t k,
                         double *dist2);
/* The same with the points' indices into ids[0 ..) (ids may be NULL); points at equal distances
 * come in increasing index, so the list does not depend on the tree's layout. */
size_t rs_kdtree_nearest_ids(const rs_kdtree *tree, const double p[3], uint32_t skip, size_t k,
                             double *dist2, uint32_t *ids);

#endif /* RSMOOTH_SPATIAL_H */
