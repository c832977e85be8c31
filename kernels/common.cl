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
 * block per work-item and one vertex per vector lane: the cells within reach of the block are
 * looked up once, and each facet is loaded once and evaluated against every lane at once (explicit
 * vectors, which CPU devices run as SIMD instructions). Cells are a fraction of the reach wide
 * (the host picks how many per reach), so the cells searched hug the ball of reach around the
 * block. A vertex's "slot" is block * RS_LANES + lane. Per-vertex arrays are stored per block,
 * component by component: the x of every lane, then every y, and so on. Unused lanes repeat lane 0
 * and their results are never read.
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

/* The lane types of RS_LANES vertices (the host picks the width per device: the preferred float
 * vector width of a CPU device, 1 for the GPU variant, where each work-item is one vertex and the
 * vector "lanes" are the work-items of a group). Comparisons give -1 per true lane of a vector and
 * 1 for a scalar: code tests them with select(), lane_any() and &&, never with bit tricks. */
#define RS_CAT2(a, b) a##b
#define RS_CAT(a, b) RS_CAT2(a, b)
#if RS_LANES == 1
typedef float lanef;
typedef int lanei;
#define load_lanes(i, p) ((p)[i])
#define store_lanes(v, i, p) ((p)[i] = (v))
#define convert_lanef convert_float
#define convert_lanei convert_int
#define as_lanef as_float
inline int lane_any(lanei m) {
    return m != 0;
}
inline float lane_min(lanef v) {
    return v;
}
inline float lane_max(lanef v) {
    return v;
}
#else
typedef RS_CAT(float, RS_LANES) lanef;
typedef RS_CAT(int, RS_LANES) lanei;
#define load_lanes RS_CAT(vload, RS_LANES)
#define store_lanes RS_CAT(vstore, RS_LANES)
#define convert_lanef RS_CAT(convert_float, RS_LANES)
#define convert_lanei RS_CAT(convert_int, RS_LANES)
#define as_lanef RS_CAT(as_float, RS_LANES)
inline int lane_any(lanei m) {
    return any(m);
}
/* Smallest and largest value over the lanes, halving the vector. */
inline float min4(float4 m) {
    float2 n = fmin(m.lo, m.hi);
    return fmin(n.x, n.y);
}
inline float max4(float4 m) {
    float2 n = fmax(m.lo, m.hi);
    return fmax(n.x, n.y);
}
#if RS_LANES == 4
inline float lane_min(lanef v) {
    return min4(v);
}
inline float lane_max(lanef v) {
    return max4(v);
}
#elif RS_LANES == 8
inline float lane_min(lanef v) {
    return min4(fmin(v.lo, v.hi));
}
inline float lane_max(lanef v) {
    return max4(fmax(v.lo, v.hi));
}
#elif RS_LANES == 16
/* The halves through a private array, not v.lo and v.hi: Oclgrind takes a lane picked from
 * element 11 of a vector for undefined (its error 7 in tests/test_oclgrind.c); compilers keep the
 * array in registers all the same. Once per block, out of the facet loops. */
inline float lane_min(lanef v) {
    float h[16];
    vstore16(v, 0, h);
    float8 m = fmin(vload8(0, h), vload8(1, h));
    return min4(fmin(m.lo, m.hi));
}
inline float lane_max(lanef v) {
    float h[16];
    vstore16(v, 0, h);
    float8 m = fmax(vload8(0, h), vload8(1, h));
    return max4(fmax(m.lo, m.hi));
}
#else
#error "RS_LANES must be 1, 4, 8 or 16"
#endif
#endif

/* 2^x per lane, to about 2e-7 relative: 2^n built in the exponent bits times a degree-5 minimax
 * polynomial for 2^f, |f| <= 1/2. Several times cheaper than the exp() PoCL vectorizes; inputs
 * below -126 give about 2^-126 instead of subnormals or 0 (weights that small add nothing to sums
 * the rescue has not taken over). Exponents reach the kernels already in base 2 (the host scales
 * log areas and 1 / 2 sigma^2 by log2 e), which saves a multiply per pair. */
inline lanef fast_exp2(lanef x) {
    lanef y = clamp(x, -126.0f, 127.0f);
    lanei n = convert_lanei(y + 128.5f) - 128; /* round to nearest, through truncation of y > 0 */
    lanef f = y - convert_lanef(n);            /* |f| <= 1/2 */
    lanef p =
        1.00000012f +
        f * (0.693146944f +
             f * (0.240221202f + f * (0.0555071346f + f * (0.00967554096f + f * 0.00132764666f))));
    return p * as_lanef((n + 127) << 23);
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
    return convert_lanei(load_lanes(k, offset));
}

/* Declares the lanes of block b: px, py, pz local to their own cells, ox, oy, oz their cells'
 * offsets from the anchor, and lo, hi the box they span in cells from the anchor (for the
 * search; the distances themselves never go through it). */
#define LOAD_BLOCK_LANES(b, block_pos, block_offset)                                               \
    __global const float *pos_ = (block_pos) + 3 * RS_LANES * (size_t)(b);                         \
    lanef px = load_lanes(0, pos_), py = load_lanes(1, pos_), pz = load_lanes(2, pos_);            \
    __global const uchar *off_ = (block_offset) + 3 * RS_LANES * (size_t)(b);                      \
    lanei ox = load_offsets(0, off_), oy = load_offsets(1, off_), oz = load_offsets(2, off_);      \
    lanef ax_ = px + convert_lanef(ox), ay_ = py + convert_lanef(oy),                              \
          az_ = pz + convert_lanef(oz);                                                            \
    float3 lo = (float3)(lane_min(ax_), lane_min(ay_), lane_min(az_));                             \
    float3 hi = (float3)(lane_max(ax_), lane_max(ay_), lane_max(az_))

/* The cell of the vertex in `slot`: its block's anchor plus its offset. */
inline int4 slot_cell(__global const int4 *block_cell, __global const uchar *block_offset,
                      uint slot) {
    __global const uchar *o = block_offset + (slot / RS_LANES) * 3 * RS_LANES + slot % RS_LANES;
    return block_cell[slot / RS_LANES] + (int4)(o[0], o[RS_LANES], o[2 * RS_LANES], 0);
}

/* ---- Where a kernel's vertices come from, and the facets near them ---------------------------
 *
 * BEGIN_BLOCK declares, for work-item b of a block kernel, the names the searches below use:
 * px, py, pz (positions local to each lane's own cell), ox, oy, oz (their cells' offsets from
 * `anchor`, whole numbers) and lo, hi (the box they span, in cells from `anchor`).
 * FOR_EACH_FACET_NEAR(REACH2, NORMALS, PAIRS, body) then runs `body` for every facet q of every
 * cell near that box, in the same order in both variants (cells by x, y, z, facets in cell order),
 * with c = facet_centroid[q], n = NORMALS[q] and qx, qy, qz the lanes' positions seen from q's
 * cell (a lane's whole-cell distance to it built in integers); PAIRS counts the facets.
 *
 * Block variant (RS_LANES > 1, CPU devices): the box is the block's lanes'; facets come straight
 * from global memory, where the CPU's caches hold them.
 * Group variant (RS_LANES 1, GPUs): the box is that of the work-group's RS_GROUP vertices, so every
 * work-item walks the same cells (no divergence). The group loads each candidate facet once,
 * one per work-item, into local memory, with a flag for whether it lies within reach of the
 * group's box at all; then every work-item reads the staged facets, skipping flagged ones (a
 * branch every work-item takes alike). Facets out of a lane's reach give it an exact zero either
 * way, so both variants compute the same sums. */

/* FOR_EACH_FACET_NEAR's walk for the lanes of one work-item alone, straight from global memory:
 * the block variant's, and the group variant's rare rescue. */
#define FOR_EACH_FACET_OWN(REACH2, NORMALS, PAIRS, ...)                                            \
    FOR_EACH_CELL_NEAR(                                                                            \
        anchor, lo, hi, REACH2, cell_coord, column_first, column_table, column_mask, {             \
            lanef qx = px - convert_lanef(dx - ox), qy = py - convert_lanef(dy - oy),              \
                  qz = pz - convert_lanef(dz - oz);                                                \
            uint begin_ = cell_start[cell], end_ = cell_start[cell + 1];                           \
            (PAIRS) += end_ - begin_;                                                              \
            for (uint q = begin_; q < end_; q++) {                                                 \
                float4 c = facet_centroid[q];                                                      \
                float4 n = (NORMALS)[q];                                                           \
                __VA_ARGS__                                                                        \
            }                                                                                      \
        })

#if RS_LANES == 1

/* The local memory of the group variant, declared at kernel scope (OpenCL C requires it there).
 * Vectors made of scalars go in with vstore4: stored whole, LLVM writes them with the scalar lanes
 * undefined and then each lane, which Oclgrind's uninitialised-value check reports. Boxes are
 * float4, not float3, whose fourth lane LLVM leaves undefined: that check crashes on it.
 * (Oclgrind's errors 2 and 3 in tests/test_oclgrind.c; both forms cost nothing.) */
#define DECLARE_STAGE                                                                              \
    __local float4 stage_c[RS_GROUP], stage_n[RS_GROUP];                                           \
    __local int4 stage_d[RS_GROUP];                                                                \
    __local uint stage_q[RS_GROUP];                                                                \
    __local int4 stage_anchor;                                                                     \
    __local float4 stage_box[2]
#define STAGE_PARAMS                                                                               \
    , __local float4 *stage_c, __local float4 *stage_n, __local int4 *stage_d, __local uint *stage_q
#define STAGE_ARGS , stage_c, stage_n, stage_d, stage_q

/* Work-items past the last vertex repeat it (every work-item must reach the barriers), and their
 * results are never stored. The group's anchor is its lowest cell; work-item 0 forms the box. */
#define BEGIN_BLOCK(b, block_count, block_pos, block_cell, block_offset)                           \
    DECLARE_STAGE;                                                                                 \
    uint own_ = min((uint)(b), (block_count)-1), lid_ = get_local_id(0);                           \
    lanef px = (block_pos)[3 * own_], py = (block_pos)[3 * own_ + 1],                              \
          pz = (block_pos)[3 * own_ + 2];                                                          \
    int4 cell_ = (block_cell)[own_];                                                               \
    stage_d[lid_] = cell_;                                                                         \
    vstore4((float4)(px, py, pz, 0.0f), lid_, (__local float *)stage_c);                           \
    barrier(CLK_LOCAL_MEM_FENCE);                                                                  \
    if (lid_ == 0) {                                                                               \
        int4 a_ = stage_d[0];                                                                      \
        for (uint i_ = 1; i_ < RS_GROUP; i_++)                                                     \
            a_ = min(a_, stage_d[i_]);                                                             \
        float4 l_ = MAXFLOAT, h_ = -MAXFLOAT; /* w: 0, unread */                                   \
        for (uint i_ = 0; i_ < RS_GROUP; i_++) {                                                   \
            float4 p_ = convert_float4(stage_d[i_] - a_) + stage_c[i_];                            \
            l_ = fmin(l_, p_);                                                                     \
            h_ = fmax(h_, p_);                                                                     \
        }                                                                                          \
        stage_anchor = a_;                                                                         \
        stage_box[0] = l_;                                                                         \
        stage_box[1] = h_;                                                                         \
    }                                                                                              \
    barrier(CLK_LOCAL_MEM_FENCE);                                                                  \
    int4 anchor = stage_anchor;                                                                    \
    float3 lo = stage_box[0].xyz, hi = stage_box[1].xyz;                                           \
    lanei ox = cell_.x - anchor.x, oy = cell_.y - anchor.y, oz = cell_.z - anchor.z

/* Runs the body over the `filled_` staged facets, between barriers: the first makes the group's
 * loads visible, the second keeps the next loads from overwriting facets still being read. */
#define CONSUME_STAGE(PAIRS, ...)                                                                  \
    barrier(CLK_LOCAL_MEM_FENCE);                                                                  \
    for (uint i_ = 0; i_ < filled_; i_++) {                                                        \
        uint q = stage_q[i_];                                                                      \
        if (q != UINT_MAX) { /* within reach of the group's box: the same for every work-item */   \
            int4 d_ = stage_d[i_];                                                                 \
            lanef qx = px - convert_lanef(d_.x - ox), qy = py - convert_lanef(d_.y - oy),          \
                  qz = pz - convert_lanef(d_.z - oz);                                              \
            float4 c = stage_c[i_], n = stage_n[i_];                                               \
            (PAIRS)++;                                                                             \
            __VA_ARGS__                                                                            \
        }                                                                                          \
    }                                                                                              \
    barrier(CLK_LOCAL_MEM_FENCE);

/* A facet is skipped when its centroid lies farther than the reach from the group's box; the
 * margin keeps float rounding of that box test from skipping a facet some lane counts. */
#define FOR_EACH_FACET_NEAR(REACH2, NORMALS, PAIRS, ...)                                           \
    {                                                                                              \
        uint filled_ = 0, slot_ = get_local_id(0);                                                 \
        float cull2_ = (REACH2)*1.001f + 1e-3f;                                                    \
        FOR_EACH_CELL_NEAR(                                                                        \
            anchor, lo, hi, REACH2, cell_coord, column_first, column_table, column_mask, {         \
                uint next_ = cell_start[cell], end_ = cell_start[cell + 1];                        \
                while (next_ < end_) {                                                             \
                    uint take_ = min(end_ - next_, (uint)RS_GROUP - filled_);                      \
                    if (slot_ < take_) {                                                           \
                        uint q_ = next_ + slot_;                                                   \
                        float4 c_ = facet_centroid[q_];                                            \
                        float3 g_ = convert_float3((int3)(dx, dy, dz)) + c_.xyz;                   \
                        float3 gap_ = fmax((float3)0.0f, fmax(lo - g_, g_ - hi));                  \
                        float gap2_ = gap_.x * gap_.x + gap_.y * gap_.y + gap_.z * gap_.z;         \
                        stage_q[filled_ + slot_] = gap2_ <= cull2_ ? q_ : UINT_MAX;                \
                        stage_c[filled_ + slot_] = c_;                                             \
                        stage_n[filled_ + slot_] = (NORMALS)[q_];                                  \
                        vstore4((int4)(dx, dy, dz, 0), filled_ + slot_, (__local int *)stage_d);   \
                    }                                                                              \
                    filled_ += take_;                                                              \
                    next_ += take_;                                                                \
                    if (filled_ == RS_GROUP) {                                                     \
                        CONSUME_STAGE(PAIRS, __VA_ARGS__)                                          \
                        filled_ = 0;                                                               \
                    }                                                                              \
                }                                                                                  \
            })                                                                                     \
        if (filled_ > 0) {                                                                         \
            CONSUME_STAGE(PAIRS, __VA_ARGS__)                                                      \
        }                                                                                          \
    }

#else /* the block variant */

#define STAGE_PARAMS
#define STAGE_ARGS

#define BEGIN_BLOCK(b, block_count, block_pos, block_cell, block_offset)                           \
    if ((b) >= (block_count))                                                                      \
        return;                                                                                    \
    LOAD_BLOCK_LANES(b, block_pos, block_offset);                                                  \
    int4 anchor = (block_cell)[b]

#define FOR_EACH_FACET_NEAR FOR_EACH_FACET_OWN

#endif
