/* Shared by every phase: grid lookup, vertex blocks and the layout conventions below.
 *
 * Coordinates are float32 in units of the grid cell size h, relative to the corner of a nearby cell
 * (a facet's own cell, a vertex block's anchor), so a mesh far from the origin keeps full
 * precision. A point local to cell v seen from cell u is at p - (u - v), exact in float for the
 * small integers involved.
 * Facet weights travel as log2(area / mean area), so one exponential per pair gives area * Gaussian
 * and no area underflows; every exponent is in base 2 (see fast_exp2).
 *
 * Vertices travel in blocks of up to RS_LANES vertices spanning at most two cells per axis, one
 * block per work-item and one vertex per vector lane: the cells within reach of the block are looked
 * up once, and each facet is loaded once and evaluated against every lane at once (explicit
 * vectors, which CPU devices run as SIMD instructions). Cells are a fraction of the reach wide
 * (the host picks how many per reach), so the cells searched hug the ball of reach around the block. A vertex's "slot" is block * RS_LANES + lane. Per-vertex arrays are stored
 * per block, component by component: the x of every lane, then every y, and so on. Unused lanes
 * repeat lane 0 and their results are never read.
 *
 * Buffers (facets sorted by cell):
 *   facet_centroid[q]  float4 (c_q local to its cell, log area)
 *   facet_normal[q]    float4 (unit normal, 0)
 *   cell_coord[c]      int4 (x, y, z, 0) of occupied cell c
 *   cell_start[c]      first facet of cell c; cell_start[cell_count] = facet count
 *   column_first[j]    first cell of column j (the occupied cells of one x, y, by z); [j + 1]
 *                      ends it
 *   column_table[s]    open-addressing hash slot, on (x, y, 0): column index or -1
 *   block_cell[b]      int4 (x, y, z, 0): block b's anchor, the lowest cell its vertices span
 *   block_pos          per block: x, y, z of each lane, local to the corner of its own cell
 *   block_offset       per block, as block_pos: each lane's cell minus the anchor (0 or 1), so
 *                      that a lane's distance to a facet comes from two cell-local positions and
 *                      an exact whole number of cells, the same bits in any block
 *   block_pairs[2 b]   facets block b evaluated (times RS_LANES: pairs) in mollification, [2 b + 1]
 *                      in the robust pass: the work done, within reach or not
 */

typedef float8 lanef;
typedef int8 lanei;
#define load_lanes vload8
#define store_lanes vstore8

/* 2^x per lane, to about 2e-7 relative: 2^n built in the exponent bits times a degree-5 minimax
 * polynomial for 2^f, |f| <= 1/2. Several times cheaper than the exp() PoCL vectorizes; inputs
 * below -126 give about 2^-126 instead of subnormals or 0 (weights that small add nothing to sums
 * the rescue has not taken over). Exponents reach the kernels already in base 2 (the host scales
 * log areas and 1 / 2 sigma^2 by log2 e), which saves a multiply per pair. */
inline lanef fast_exp2(lanef x) {
    lanef y = clamp(x, -126.0f, 127.0f);
    lanei n = convert_int8(y + 128.5f) - 128; /* round to nearest, through truncation of y > 0 */
    lanef f = y - convert_float8(n);          /* |f| <= 1/2 */
    lanef p = 1.00000012f + f * (0.693146944f + f * (0.240221202f + f * (0.0555071346f +
                                 f * (0.00967554096f + f * 0.00132764666f))));
    return p * as_float8((n + 127) << 23);
}

/* The hash the host fills the tables with (rs_grid_hash in lib/rsmooth_internal.h). */
inline uint grid_hash(int x, int y, int z) {
    return ((uint)x * 73856093u) ^ ((uint)y * 19349663u) ^ ((uint)z * 83492791u);
}

/* Index of the column of occupied cells at (x, y), or -1. */
inline int column_find(__global const int4 *cell_coord, __global const uint *column_first,
                       __global const int *column_table, uint column_mask, int x, int y) {
    uint slot = grid_hash(x, y, 0) & column_mask;
    for (;;) {
        int column = column_table[slot];
        if (column < 0)
            return -1;
        int4 c = cell_coord[column_first[column]];
        if (c.x == x && c.y == y)
            return column;
        slot = (slot + 1) & column_mask;
    }
}

/* Smallest and largest value over the lanes. */
inline float lane_min(lanef v) {
    float4 m = fmin(v.lo, v.hi);
    float2 n = fmin(m.lo, m.hi);
    return fmin(n.x, n.y);
}
inline float lane_max(lanef v) {
    float4 m = fmax(v.lo, v.hi);
    float2 n = fmax(m.lo, m.hi);
    return fmax(n.x, n.y);
}

/* Squared distance along one axis from the interval [lo, hi] to the cell [c, c + 1]. */
inline float axis_gap2(float lo, float hi, int c) {
    float g = fmax(0.0f, fmax((float)c - hi, lo - (float)(c + 1)));
    return g * g;
}

/* Runs the block (the last argument) for every occupied cell whose box lies within sqrt(REACH2) of
 * the box [LO, HI] (float3, in cells relative to the cell ANCHOR), with `cell` its index and
 * (dx, dy, dz) its offset from ANCHOR. Columns (x, y) out of reach are skipped before they are
 * looked up, and a column's cells follow each other in memory, so one lookup per column finds
 * them: the search covers a ball around the block rather than a cube. */
#define FOR_EACH_CELL_NEAR(ANCHOR, LO, HI, REACH2, cell_coord, column_first, column_table,         \
                           column_mask, ...)                                                       \
    {                                                                                              \
        float reach_ = sqrt(REACH2);                                                               \
        int x0_ = (int)floor((LO).x - reach_), x1_ = (int)floor((HI).x + reach_);                  \
        int y0_ = (int)floor((LO).y - reach_), y1_ = (int)floor((HI).y + reach_);                  \
        int z0_ = (ANCHOR).z + (int)floor((LO).z - reach_);                                        \
        int z1_ = (ANCHOR).z + (int)floor((HI).z + reach_);                                        \
        for (int dx = x0_; dx <= x1_; dx++) {                                                      \
            float gx_ = axis_gap2((LO).x, (HI).x, dx);                                             \
            if (gx_ > (REACH2))                                                                    \
                continue;                                                                          \
            for (int dy = y0_; dy <= y1_; dy++) {                                                  \
                float gxy_ = gx_ + axis_gap2((LO).y, (HI).y, dy);                                  \
                if (gxy_ > (REACH2))                                                               \
                    continue;                                                                      \
                int column_ = column_find(cell_coord, column_first, column_table, column_mask,     \
                                          (ANCHOR).x + dx, (ANCHOR).y + dy);                       \
                if (column_ < 0)                                                                   \
                    continue;                                                                      \
                uint last_ = column_first[column_ + 1];                                            \
                for (uint cell = column_first[column_]; cell < last_; cell++) {                    \
                    int z_ = cell_coord[cell].z;                                                   \
                    if (z_ > z1_)                                                                  \
                        break;                                                                     \
                    int dz = z_ - (ANCHOR).z;                                                      \
                    if (z_ < z0_ || gxy_ + axis_gap2((LO).z, (HI).z, dz) > (REACH2))               \
                        continue;                                                                  \
                    __VA_ARGS__                                                                    \
                }                                                                                  \
            }                                                                                      \
        }                                                                                          \
    }

/* Component k (0 = x) of the vertex in `slot` of a per-block array of `stride` components. */
inline float slot_component(__global const float *blocks, uint slot, uint stride, uint k) {
    return blocks[(slot / RS_LANES) * stride * RS_LANES + k * RS_LANES + slot % RS_LANES];
}

/* Axis k of the lanes' cell offsets from the anchor (block_offset). Whole numbers, and kept
 * integers: the kernels build a lane's whole-cell distance to a facet's cell in integers, which
 * -cl-fast-relaxed-math cannot reassociate with the float positions. */
inline lanei load_offsets(uint k, __global const uchar *offset) {
    return convert_int8(vload8(k, offset));
}

/* Declares the lanes of block b: px, py, pz local to their own cells, ox, oy, oz their cells'
 * offsets from the anchor, and lo, hi the box they span in cells from the anchor (for the
 * search; the distances themselves never go through it). */
#define LOAD_BLOCK_LANES(b, block_pos, block_offset)                                               \
    __global const float *pos_ = (block_pos) + 3 * RS_LANES * (size_t)(b);                         \
    lanef px = load_lanes(0, pos_), py = load_lanes(1, pos_), pz = load_lanes(2, pos_);            \
    __global const uchar *off_ = (block_offset) + 3 * RS_LANES * (size_t)(b);                      \
    lanei ox = load_offsets(0, off_), oy = load_offsets(1, off_), oz = load_offsets(2, off_);      \
    lanef ax_ = px + convert_float8(ox), ay_ = py + convert_float8(oy),                            \
          az_ = pz + convert_float8(oz);                                                           \
    float3 lo = (float3)(lane_min(ax_), lane_min(ay_), lane_min(az_));                             \
    float3 hi = (float3)(lane_max(ax_), lane_max(ay_), lane_max(az_))

/* The cell of the vertex in `slot`: its block's anchor plus its offset. */
inline int4 slot_cell(__global const int4 *block_cell, __global const uchar *block_offset,
                      uint slot) {
    __global const uchar *o = block_offset + (slot / RS_LANES) * 3 * RS_LANES + slot % RS_LANES;
    return block_cell[slot / RS_LANES] + (int4)(o[0], o[RS_LANES], o[2 * RS_LANES], 0);
}
