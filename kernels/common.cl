/* Shared by every phase: grid lookup and the layout conventions below.
 *
 * Coordinates are float32 in units of the grid cell size h, relative to the origin of the cell that
 * holds the point (so a mesh far from the origin keeps full precision). A vertex in cell v seen from
 * a neighbouring cell u is at p - (u - v), exact in float for the small integers involved.
 * Facet weights travel as log(area / mean area), so one exp() per pair gives area * Gaussian and no
 * area underflows.
 *
 * Buffers (facets sorted by cell, vertices in grid order):
 *   facet_centroid[q]  float4 (c_q local to its cell, log area)
 *   facet_normal[q]    float4 (unit normal, 0)
 *   cell_coord[c]      int4 (x, y, z, 0) of occupied cell c
 *   cell_start[c]      first facet of cell c; cell_start[cell_count] = facet count
 *   table[s]           open-addressing hash slot: occupied cell index or -1
 *   vertex_local[v]    float4 (p local to its cell, 0);  vertex_cell[v] int4 (its cell, 0)
 */

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
