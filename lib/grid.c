/* Uniform grid over facet centroids: facets sorted by cell into contiguous ranges, occupied cells
 * found through a hash of their integer coordinates. Both paths and the kernels read it. */
#include "rsmooth_internal.h"

#include <math.h>
#include <string.h>

/* Cells per axis are capped so a cell key fits 64 bits; a coarser grid is slower, never wrong. */
#define MAX_CELLS_PER_AXIS (1 << 20)

void rs_grid_free(rs_grid *grid) {
    if (!grid)
        return;
    rs_free(grid->cell_coord);
    rs_free(grid->cell_start);
    rs_free(grid->facet_order);
    rs_free(grid->table);
    memset(grid, 0, sizeof *grid);
}

void rs_grid_cell_of(const rs_grid *grid, const double p[3], int32_t cell[3]) {
    for (int k = 0; k < 3; k++) {
        double c = floor((p[k] - grid->origin[k]) / grid->cell_size);
        double hi = (double)grid->dims[k] + 1;
        cell[k] = (int32_t)(c < -2 ? -2 : c > hi ? hi : c);
    }
}

/* Linear key of a (clamped) cell; the +2 offsets make clamped vertex cells non-negative too. */
static uint64_t cell_key(const rs_grid *grid, const int32_t c[3]) {
    uint64_t x = (uint64_t)(c[0] + 2), y = (uint64_t)(c[1] + 2), z = (uint64_t)(c[2] + 2);
    uint64_t ny = (uint64_t)grid->dims[1] + 4, nz = (uint64_t)grid->dims[2] + 4;
    return (x * ny + y) * nz + z;
}

/* The cell whose cell_key is `key`. */
static void cell_of_key(const rs_grid *grid, uint64_t key, int32_t c[3]) {
    uint64_t ny = (uint64_t)grid->dims[1] + 4, nz = (uint64_t)grid->dims[2] + 4;
    c[2] = (int32_t)(key % nz) - 2;
    key /= nz;
    c[1] = (int32_t)(key % ny) - 2;
    c[0] = (int32_t)(key / ny) - 2;
}

int32_t rs_grid_find(const rs_grid *grid, int32_t x, int32_t y, int32_t z) {
    if (grid->cell_count == 0)
        return -1;
    uint32_t slot = rs_grid_hash(x, y, z) & grid->table_mask;
    for (;;) {
        int32_t cell = grid->table[slot];
        if (cell < 0)
            return -1;
        const int32_t *c = grid->cell_coord + 4 * (size_t)cell;
        if (c[0] == x && c[1] == y && c[2] == z)
            return cell;
        slot = (slot + 1) & grid->table_mask;
    }
}

rsmooth_status rs_grid_build(rs_grid *grid, const double *points, size_t count, double reach,
                             rsmooth_error *error) {
    static const char where[] = "rs_grid_build";
    memset(grid, 0, sizeof *grid);
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < count; i++)
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], points[3 * i + k]);
            hi[k] = fmax(hi[k], points[3 * i + k]);
        }
    if (count == 0)
        lo[0] = lo[1] = lo[2] = hi[0] = hi[1] = hi[2] = 0;
    /* A hair wider than the reach: a point and a centroid exactly `reach` apart must never round
     * into cells two apart. */
    double h = reach > 0 ? reach * (1 + 1e-6) : 1;
    for (int k = 0; k < 3; k++)
        if ((hi[k] - lo[k]) / h > MAX_CELLS_PER_AXIS - 2)
            h = (hi[k] - lo[k]) / (MAX_CELLS_PER_AXIS - 2);
    memcpy(grid->origin, lo, sizeof lo);
    grid->cell_size = h;
    for (int k = 0; k < 3; k++)
        grid->dims[k] = (int32_t)floor((hi[k] - lo[k]) / h) + 1;

    uint64_t *keys = rs_alloc_array(count, sizeof *keys);
    grid->facet_order = rs_alloc_array(count, sizeof *grid->facet_order);
    if (!keys || !grid->facet_order)
        goto fail_memory;
    for (size_t i = 0; i < count; i++) {
        int32_t c[3];
        rs_grid_cell_of(grid, points + 3 * i, c);
        for (int k = 0; k < 3; k++) /* rounding can put the far edge one cell out */
            c[k] = c[k] < 0 ? 0 : c[k] >= grid->dims[k] ? grid->dims[k] - 1 : c[k];
        keys[i] = cell_key(grid, c);
        grid->facet_order[i] = (uint32_t)i;
    }
    if (!rs_radix_sort_u64(keys, grid->facet_order, count))
        goto fail_memory;

    size_t cells = 0;
    for (size_t i = 0; i < count; i++)
        if (i == 0 || keys[i] != keys[i - 1])
            cells++;
    grid->cell_count = cells;
    grid->cell_coord = rs_alloc_array(cells, 4 * sizeof(int32_t));
    grid->cell_start = rs_alloc_array(cells + 1, sizeof(uint32_t));
    if (cells > (1u << 30))
        goto fail_memory; /* the hash table's 32-bit slots would overflow */
    uint32_t table_size = 16;
    while (table_size < 2 * cells)
        table_size *= 2;
    grid->table_mask = table_size - 1;
    grid->table = rs_alloc_array(table_size, sizeof(int32_t));
    if (!grid->cell_coord || !grid->cell_start || !grid->table)
        goto fail_memory;
    for (uint32_t s = 0; s < table_size; s++)
        grid->table[s] = -1;

    size_t cell = 0;
    for (size_t i = 0; i < count; i++) {
        if (i > 0 && keys[i] == keys[i - 1])
            continue;
        int32_t c[3];
        cell_of_key(grid, keys[i], c); /* the clamped cell the key was made from */
        int32_t *coord = grid->cell_coord + 4 * cell;
        coord[0] = c[0];
        coord[1] = c[1];
        coord[2] = c[2];
        coord[3] = 0;
        grid->cell_start[cell] = (uint32_t)i;
        uint32_t slot = rs_grid_hash(c[0], c[1], c[2]) & grid->table_mask;
        while (grid->table[slot] >= 0)
            slot = (slot + 1) & grid->table_mask;
        grid->table[slot] = (int32_t)cell;
        cell++;
    }
    grid->cell_start[cells] = (uint32_t)count;
    rs_free(keys);
    return RSMOOTH_OK;

fail_memory:
    rs_free(keys);
    rs_grid_free(grid);
    return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "no memory for the grid (%zu facets)",
                   count);
}

rsmooth_status rs_grid_order_points(const rs_grid *grid, const double *points, size_t count,
                                    uint32_t *order, int32_t *cells, rsmooth_error *error) {
    uint64_t *keys = rs_alloc_array(count, sizeof *keys);
    if (!keys)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, "rs_grid_order_points",
                       "no memory to order %zu vertices", count);
    for (size_t i = 0; i < count; i++) {
        int32_t c[3];
        rs_grid_cell_of(grid, points + 3 * i, c);
        keys[i] = cell_key(grid, c);
        order[i] = (uint32_t)i;
    }
    bool ok = rs_radix_sort_u64(keys, order, count);
    for (size_t i = 0; ok && i < count; i++)
        cell_of_key(grid, keys[i], cells + 3 * i);
    rs_free(keys);
    return ok ? RSMOOTH_OK
              : rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, "rs_grid_order_points",
                        "no memory to order %zu vertices", count);
}
