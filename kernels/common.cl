/* Shared by every phase: grid lookup, vertex blocks and the layout conventions below.
 *
 * Coordinates are float32 in units of the grid cell size h, relative to the origin of the cell that
 * holds the point (so a mesh far from the origin keeps full precision). A vertex in cell v seen from
 * a neighbouring cell u is at p - (u - v), exact in float for the small integers involved.
 * Facet weights travel as log(area / mean area), so one exp() per pair gives area * Gaussian and no
 * area underflows.
 *
 * Vertices travel in blocks of up to RS_LANES vertices of one cell, one block per work-item and one
 * vertex per vector lane: the 27 cells around the block are looked up once, and each facet is
 * loaded once and evaluated against every lane at once (explicit vectors, which CPU devices run as
 * SIMD instructions). A vertex's "slot" is block * RS_LANES + lane. Per-vertex arrays are stored
 * per block, component by component: the x of every lane, then every y, and so on. Unused lanes
 * repeat lane 0 and their results are never read.
 *
 * Buffers (facets sorted by cell):
 *   facet_centroid[q]  float4 (c_q local to its cell, log area)
 *   facet_normal[q]    float4 (unit normal, 0)
 *   cell_coord[c]      int4 (x, y, z, 0) of occupied cell c
 *   cell_start[c]      first facet of cell c; cell_start[cell_count] = facet count
 *   table[s]           open-addressing hash slot: occupied cell index or -1
 *   block_cell[b]      int4 (x, y, z, 0): the cell of block b's vertices
 *   block_pos          per block: x, y, z of each lane, local to the block's cell
 */

typedef float8 lanef;
typedef int8 lanei;
#define load_lanes vload8
#define store_lanes vstore8

/* e^x per lane, to about 2e-7 relative: 2^(x log2 e) split into 2^n (built in the exponent bits)
 * times a degree-6 polynomial for 2^f, |f| <= 1/2. Several times cheaper than the exp() PoCL
 * vectorizes; inputs below -87 give about e^-87 instead of subnormals or 0 (weights that small
 * add nothing to sums of order one; the rescue path handles sums that are all that small). */
inline lanef fast_exp(lanef x) {
    lanef y = clamp(x, -87.0f, 88.0f) * 1.44269504089f;
    lanei n = convert_int8(y + 128.5f) - 128; /* round to nearest, through truncation of y > 0 */
    lanef f = (y - convert_float8(n)) * 0.69314718056f; /* e^f = 2^(y - n), |f| <= ln 2 / 2 */
    lanef p = 1.0f + f * (1.0f + f * (0.5f + f * (0.166666667f + f * (0.0416666667f +
                                     f * (0.00833333333f + f * 0.00138888889f)))));
    return p * as_float8((n + 127) << 23);
}

/* The hash the host uses to fill `table` (rs_grid_hash in lib/rsmooth_internal.h). */
inline uint grid_hash(int x, int y, int z) {
    return ((uint)x * 73856093u) ^ ((uint)y * 19349663u) ^ ((uint)z * 83492791u);
}

/* Index of the occupied cell at (x, y, z), or -1 (rs_grid_find). */
inline int grid_find(__global const int4 *cell_coord, __global const int *table, uint table_mask,
                     int x, int y, int z) {
    uint slot = grid_hash(x, y, z) & table_mask;
    for (;;) {
        int cell = table[slot];
        if (cell < 0)
            return -1;
        int4 c = cell_coord[cell];
        if (c.x == x && c.y == y && c.z == z)
            return cell;
        slot = (slot + 1) & table_mask;
    }
}

/* The occupied cells around `home` (27 entries, -1 where empty), dx outermost, dz innermost. */
inline void neighbour_cells(int4 home, __global const int4 *cell_coord,
                            __global const int *table, uint table_mask, int *cells) {
    int i = 0;
    for (int dx = -1; dx <= 1; dx++)
        for (int dy = -1; dy <= 1; dy++)
            for (int dz = -1; dz <= 1; dz++)
                cells[i++] = grid_find(cell_coord, table, table_mask, home.x + dx, home.y + dy,
                                       home.z + dz);
}

/* Component k (0 = x) of the vertex in `slot` of a per-block array of `stride` components. */
inline float slot_component(__global const float *blocks, uint slot, uint stride, uint k) {
    return blocks[(slot / RS_LANES) * stride * RS_LANES + k * RS_LANES + slot % RS_LANES];
}
