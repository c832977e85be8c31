/* Uniform grid over facet centroids: facets sorted by cell into contiguous ranges, occupied cells
 * found through a hash of their integer coordinates. Both paths and the kernels read it. */
#include "core/spatial.h"

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
    rs_free(grid->column_first);
    rs_free(grid->column_table);
    memset(grid, 0, sizeof *grid);
}

void rs_grid_cell_of(const rs_grid *grid, const double p[3], int32_t cell[3]) {
    int32_t m = grid->split + 1;
    for (int k = 0; k < 3; k++) {
        double c = floor(p[k] * grid->inv_cell_size) - grid->origin_cell[k];
        double lo = -m, hi = (double)grid->dims[k] + m - 1;
        cell[k] = (int32_t)(c < lo ? lo : c > hi ? hi : c);
    }
}

/* The cell the grid filed a point it was built over in (rs_grid_cell_of, within the grid). */
static void rs_grid_facet_cell(const rs_grid *grid, const double p[3], int32_t cell[3]) {
    rs_grid_cell_of(grid, p, cell);
    for (int k = 0; k < 3; k++) /* rounding can put the far edge one cell out */
        cell[k] = cell[k] < 0 ? 0 : cell[k] >= grid->dims[k] ? grid->dims[k] - 1 : cell[k];
}

/* Linear key of a (clamped) cell; the offsets make clamped vertex cells non-negative too. */
static uint64_t cell_key(const rs_grid *grid, const int32_t c[3]) {
    int32_t m = grid->split + 1;
    uint64_t x = (uint64_t)(c[0] + m), y = (uint64_t)(c[1] + m), z = (uint64_t)(c[2] + m);
    uint64_t ny = (uint64_t)(grid->dims[1] + 2 * m), nz = (uint64_t)(grid->dims[2] + 2 * m);
    return (x * ny + y) * nz + z;
}

/* The cell whose cell_key is `key`. */
static void cell_of_key(const rs_grid *grid, uint64_t key, int32_t c[3]) {
    int32_t m = grid->split + 1;
    uint64_t ny = (uint64_t)(grid->dims[1] + 2 * m), nz = (uint64_t)(grid->dims[2] + 2 * m);
    c[2] = (int32_t)(key % nz) - m;
    key /= nz;
    c[1] = (int32_t)(key % ny) - m;
    c[0] = (int32_t)(key / ny) - m;
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

/* Elements per chunk below which a key loop is not worth a thread. */
#define KEY_GRAIN 8192

typedef struct key_job {
    const rs_grid *grid;
    const double *points;
    uint64_t *keys;
    uint32_t *order;
    int32_t *cells;
} key_job;

static void facet_keys(void *ctx, size_t begin, size_t end, size_t chunk) {
    const key_job *job = ctx;
    (void)chunk;
    for (size_t i = begin; i < end; i++) {
        int32_t c[3];
        rs_grid_facet_cell(job->grid, job->points + 3 * i, c);
        job->keys[i] = cell_key(job->grid, c);
        job->order[i] = (uint32_t)i;
    }
}

/* Open-addressing table of at least twice `count` slots, all -1; its mask in *mask. */
static int32_t *new_table(size_t count, uint32_t *mask) {
    uint32_t size = 16;
    while (size < 2 * count)
        size *= 2;
    *mask = size - 1;
    int32_t *table = rs_alloc_array(size, sizeof *table);
    for (uint32_t s = 0; table && s < size; s++)
        table[s] = -1;
    return table;
}

/* The columns of occupied cells (cells are sorted by x, then y, then z). */
bool rs_grid_index_columns(rs_grid *grid) {
    size_t columns = 0;
    const int32_t *c = grid->cell_coord;
    for (size_t i = 0; i < grid->cell_count; i++)
        if (i == 0 || c[4 * i] != c[4 * i - 4] || c[4 * i + 1] != c[4 * i - 3])
            columns++;
    grid->column_count = columns;
    grid->column_first = rs_alloc_array(columns + 1, sizeof(uint32_t));
    grid->column_table = new_table(columns, &grid->column_mask);
    if (!grid->column_first || !grid->column_table)
        return false;
    size_t j = 0;
    for (size_t i = 0; i < grid->cell_count; i++) {
        if (!(i == 0 || c[4 * i] != c[4 * i - 4] || c[4 * i + 1] != c[4 * i - 3]))
            continue;
        grid->column_first[j] = (uint32_t)i;
        uint32_t slot = rs_grid_hash(c[4 * i], c[4 * i + 1], 0) & grid->column_mask;
        while (grid->column_table[slot] >= 0)
            slot = (slot + 1) & grid->column_mask;
        grid->column_table[slot] = (int32_t)j++;
    }
    grid->column_first[columns] = (uint32_t)grid->cell_count;
    return true;
}

/* The hash table of occupied cells (rs_grid_find). */
static bool index_cells(rs_grid *grid) {
    grid->table = new_table(grid->cell_count, &grid->table_mask);
    if (!grid->table)
        return false;
    for (size_t cell = 0; cell < grid->cell_count; cell++) {
        const int32_t *c = grid->cell_coord + 4 * cell;
        uint32_t slot = rs_grid_hash(c[0], c[1], c[2]) & grid->table_mask;
        while (grid->table[slot] >= 0)
            slot = (slot + 1) & grid->table_mask;
        grid->table[slot] = (int32_t)cell;
    }
    return true;
}

static rsmooth_status sort_into_cells(rs_grid *grid, const double *points, size_t count,
                                      double reach, int split, const double lo[3],
                                      const double hi[3], rsmooth_error *error);

/* The occupied cells from the sorted keys, a chunk of facets per thread: each counts the cells
 * that begin in it, then writes them from where the chunks before it end. */
typedef struct cell_job {
    rs_grid *grid;
    const uint64_t *keys;
    size_t first[64]; /* per chunk: the cells beginning in it, then the first one's number */
} cell_job;

static void count_cells(void *ctx, size_t begin, size_t end, size_t chunk) {
    cell_job *job = ctx;
    size_t n = 0;
    for (size_t i = begin; i < end; i++)
        n += i == 0 || job->keys[i] != job->keys[i - 1];
    job->first[chunk] = n;
}

static void store_cells(void *ctx, size_t begin, size_t end, size_t chunk) {
    const cell_job *job = ctx;
    rs_grid *grid = job->grid;
    size_t cell = job->first[chunk];
    for (size_t i = begin; i < end; i++) {
        if (i > 0 && job->keys[i] == job->keys[i - 1])
            continue;
        int32_t c[3];
        cell_of_key(grid, job->keys[i], c); /* the clamped cell the key was made from */
        int32_t *coord = grid->cell_coord + 4 * cell;
        coord[0] = c[0];
        coord[1] = c[1];
        coord[2] = c[2];
        coord[3] = 0;
        grid->cell_start[cell] = (uint32_t)i;
        cell++;
    }
}

static rsmooth_status out_of_memory(rs_grid *grid, size_t count, rsmooth_error *error) {
    rs_grid_free(grid);
    return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, "rs_grid_build",
                   "no memory for the grid (%zu facets)", count);
}

rsmooth_status rs_grid_build(rs_grid *grid, const double *points, size_t count, double reach,
                             rsmooth_error *error) {
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < count; i++)
        for (int k = 0; k < 3; k++) {
            double x = points[3 * i + k];
            lo[k] = x < lo[k] ? x : lo[k];
            hi[k] = x > hi[k] ? x : hi[k];
        }
    if (count == 0)
        lo[0] = lo[1] = lo[2] = hi[0] = hi[1] = hi[2] = 0;
    rsmooth_status st = sort_into_cells(grid, points, count, reach, 1, lo, hi, error);
    if (st == RSMOOTH_OK && !index_cells(grid))
        return out_of_memory(grid, count, error);
    return st;
}

rsmooth_status rs_grid_build_columns(rs_grid *grid, const double *points, size_t count,
                                     double reach, int split, const double lo[3],
                                     const double hi[3], rsmooth_error *error) {
    rsmooth_status st = sort_into_cells(grid, points, count, reach, split, lo, hi, error);
    if (st == RSMOOTH_OK && !rs_grid_index_columns(grid))
        return out_of_memory(grid, count, error);
    return st;
}

/* Facets sorted by cell, and the occupied cells with their first facets: what both lookups
 * (cells, columns) index. */
void rs_grid_layout(rs_grid *grid, double reach, int split, const double lo[3],
                    const double hi[3]) {
    memset(grid, 0, sizeof *grid);
    grid->split = split;
    /* A hair wider than the reach: a point and a centroid exactly `reach` apart must never round
     * into cells two apart. */
    double h = reach > 0 ? reach * (1 + 1e-6) / split : 1;
    for (int k = 0; k < 3; k++)
        if ((hi[k] - lo[k]) / h > MAX_CELLS_PER_AXIS - 2)
            h = (hi[k] - lo[k]) / (MAX_CELLS_PER_AXIS - 2);
    /* Cells on the lattice of h from 0: any subset of the facets (a tile, a piece of a larger
     * mesh) sees the same cells, and its vertices the same float coordinates within them, as the
     * whole mesh (scaled by a power of two, the lattice scales exactly). */
    grid->cell_size = h;
    grid->inv_cell_size = 1 / h;
    for (int k = 0; k < 3; k++) {
        grid->origin_cell[k] = floor(lo[k] * grid->inv_cell_size);
        grid->origin[k] = grid->origin_cell[k] * h;
        grid->dims[k] = (int32_t)(floor(hi[k] * grid->inv_cell_size) - grid->origin_cell[k]) + 1;
    }
}

static rsmooth_status sort_into_cells(rs_grid *grid, const double *points, size_t count,
                                      double reach, int split, const double lo[3],
                                      const double hi[3], rsmooth_error *error) {
    rs_grid_layout(grid, reach, split, lo, hi);

    uint64_t *keys = rs_alloc_array(count, sizeof *keys);
    grid->facet_order = rs_alloc_array(count, sizeof *grid->facet_order);
    if (!keys || !grid->facet_order)
        goto fail_memory;
    key_job job = {grid, points, keys, grid->facet_order, NULL};
    rs_parallel_for(count, KEY_GRAIN, facet_keys, &job);
    if (!rs_radix_sort_u64(keys, grid->facet_order, count))
        goto fail_memory;

    cell_job cj = {grid, keys, {0}};
    size_t chunks = rs_parallel_chunks(count, KEY_GRAIN), cells = 0;
    rs_parallel_for(count, KEY_GRAIN, count_cells, &cj);
    for (size_t c = 0; c < chunks; c++) {
        size_t n = cj.first[c];
        cj.first[c] = cells;
        cells += n;
    }
    grid->cell_count = cells;
    grid->cell_coord = rs_alloc_array(cells, 4 * sizeof(int32_t));
    grid->cell_start = rs_alloc_array(cells + 1, sizeof(uint32_t));
    if (cells > (1u << 30))
        goto fail_memory; /* the hash tables' 32-bit slots would overflow */
    if (!grid->cell_coord || !grid->cell_start)
        goto fail_memory;

    rs_parallel_for(count, KEY_GRAIN, store_cells, &cj);
    grid->cell_start[cells] = (uint32_t)count;
    rs_free(keys);
    return RSMOOTH_OK;

fail_memory:
    rs_free(keys);
    return out_of_memory(grid, count, error);
}

/* Spreads the low 21 bits of x to every third bit (Morton order). */
static uint64_t spread_bits(uint64_t x) {
    x &= 0x1fffff;
    x = (x | x << 32) & 0x1f00000000ffffull;
    x = (x | x << 16) & 0x1f0000ff0000ffull;
    x = (x | x << 8) & 0x100f00f00f00f00full;
    x = (x | x << 4) & 0x10c30c30c30c30c3ull;
    x = (x | x << 2) & 0x1249249249249249ull;
    return x;
}

static void morton_keys(void *ctx, size_t begin, size_t end, size_t chunk) {
    const key_job *job = ctx;
    int32_t m = job->grid->split + 1; /* clamped cells start at -m */
    (void)chunk;
    for (size_t i = begin; i < end; i++) {
        int32_t *c = job->cells + 3 * i;
        rs_grid_cell_of(job->grid, job->points + 3 * i, c);
        job->keys[i] = spread_bits((uint64_t)(c[0] + m)) << 2 |
                       spread_bits((uint64_t)(c[1] + m)) << 1 | spread_bits((uint64_t)(c[2] + m));
        job->order[i] = (uint32_t)i;
    }
}

/* The inverse of spread_bits: every third bit of x gathered into the low 21. */
static uint64_t compact_bits(uint64_t x) {
    x &= 0x1249249249249249ull;
    x = (x | x >> 2) & 0x10c30c30c30c30c3ull;
    x = (x | x >> 4) & 0x100f00f00f00f00full;
    x = (x | x >> 8) & 0x1f0000ff0000ffull;
    x = (x | x >> 16) & 0x1f00000000ffffull;
    x = (x | x >> 32) & 0x1fffff;
    return x;
}

/* The cells of the points in their new order, read back from the sorted keys (sequential and
 * exact: cells fit the 21 bits per axis a key holds) rather than found again from the points. */
static void ordered_cells(void *ctx, size_t begin, size_t end, size_t chunk) {
    const key_job *job = ctx;
    int32_t m = job->grid->split + 1;
    (void)chunk;
    for (size_t i = begin; i < end; i++) {
        uint64_t key = job->keys[i];
        for (int k = 0; k < 3; k++)
            job->cells[3 * i + k] = (int32_t)compact_bits(key >> (2 - k)) - m;
    }
}

rsmooth_status rs_grid_order_points(const rs_grid *grid, const double *points, size_t count,
                                    uint32_t *order, int32_t *cells, rsmooth_error *error) {
    uint64_t *keys = rs_alloc_array(count, sizeof *keys);
    if (!keys)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, "rs_grid_order_points",
                       "no memory to order %zu vertices", count);
    key_job job = {grid, points, keys, order, cells};
    rs_parallel_for(count, KEY_GRAIN, morton_keys, &job);
    bool ok = rs_radix_sort_u64(keys, order, count);
    if (ok)
        rs_parallel_for(count, KEY_GRAIN, ordered_cells, &job);
    rs_free(keys);
    return ok ? RSMOOTH_OK
              : rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, "rs_grid_order_points",
                        "no memory to order %zu vertices", count);
}
