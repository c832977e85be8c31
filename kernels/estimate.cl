/* Robust estimation (Jones et al. 2003, Eq. 3): p' = sum Pi_q(p) a_q f g / k(p), Pi_q(p) = p + t n_q
 * with t = n_q . (c_q - p), f = exp(-|c_q - p|^2 / (2 sigma_f^2)), g = exp(-t^2 / (2 sigma_g^2)).
 *
 * robust_block: one work-item per vertex block writes, per lane,
 *   block_result: the displacement p' - p in cell units (x, y, z) and k' = the sum of the weights
 *                 used (4 components per lane)
 *   block_extra:  sum a f and the exponent shift e_s (2 components per lane), so that
 *                 k(p) = k' exp(-e_s) in mean-area units.
 * When every influence exponent of a vertex exceeds RS_RESCUE_EXPONENT, float32 weights would
 * underflow; its sums are then redone with its smallest exponent subtracted (e_s), as the reference
 * path does. `want_confidence` = 0 skips sum a f (one exp per pair instead of two).
 * `predict_centroid` = 1 predicts c_q instead of Pi_q(p) (isotropic Gaussian smoothing when
 * inv_2sg2 = 0).
 */

typedef struct robust_acc {
    lanef x, y, z, k, kf, e_min;
} robust_acc;

/* Sums of Eq. 3 for the lanes at (px, py, pz) over the facets within reach in `cells` (the 27
 * around the block's cell, -1 where empty), with influence exponents shifted down by `shift`. */
inline robust_acc robust_sums(lanef px, lanef py, lanef pz, const int *cells, float reach2,
                              float inv_2sf2, float inv_2sg2, lanef shift, int want_confidence,
                              int predict_centroid, __global const float4 *facet_centroid,
                              __global const float4 *normal, __global const uint *cell_start) {
    robust_acc a;
    a.x = a.y = a.z = a.k = a.kf = 0.0f;
    a.e_min = MAXFLOAT;
    int i = 0;
    for (int dx = -1; dx <= 1; dx++)
        for (int dy = -1; dy <= 1; dy++)
            for (int dz = -1; dz <= 1; dz++) {
                int cell = cells[i++];
                if (cell < 0)
                    continue;
                lanef qx = px - (float)dx, qy = py - (float)dy, qz = pz - (float)dz;
                uint end = cell_start[cell + 1];
                for (uint q = cell_start[cell]; q < end; q++) {
                    float4 c = facet_centroid[q];
                    float4 n = normal[q];
                    lanef ex = c.x - qx, ey = c.y - qy, ez = c.z - qz;
                    lanef d2 = ex * ex + ey * ey + ez * ez;
                    lanei near = d2 <= reach2;
                    lanef t = n.x * ex + n.y * ey + n.z * ez;
                    /* |prediction - p|^2: t^2 for the projection, d2 for the centroid */
                    lanef e = (predict_centroid ? d2 : t * t) * inv_2sg2;
                    lanef w = select((lanef)0.0f, fast_exp(c.w - d2 * inv_2sf2 - (e - shift)), near);
                    if (predict_centroid) {
                        a.x += w * ex;
                        a.y += w * ey;
                        a.z += w * ez;
                    } else {
                        lanef wt = w * t;
                        a.x += wt * n.x;
                        a.y += wt * n.y;
                        a.z += wt * n.z;
                    }
                    a.k += w;
                    a.e_min = select(a.e_min, fmin(a.e_min, e), near);
                    if (want_confidence)
                        a.kf += select((lanef)0.0f, fast_exp(c.w - d2 * inv_2sf2), near);
                }
            }
    return a;
}

__kernel void robust_block(uint block_count, float reach2, float inv_2sf2, float inv_2sg2,
                           int want_confidence, int predict_centroid,
                           __global const float *block_pos, __global const int4 *block_cell,
                           __global const float4 *facet_centroid, __global const float4 *normal,
                           __global const int4 *cell_coord, __global const uint *cell_start,
                           __global const int *table, uint table_mask,
                           __global float *block_result, __global float *block_extra) {
    uint b = get_global_id(0);
    if (b >= block_count)
        return;
    __global const float *pos = block_pos + 3 * RS_LANES * (size_t)b;
    lanef px = load_lanes(0, pos), py = load_lanes(1, pos), pz = load_lanes(2, pos);
    int cells[27];
    neighbour_cells(block_cell[b], cell_coord, table, table_mask, cells);
    robust_acc a = robust_sums(px, py, pz, cells, reach2, inv_2sf2, inv_2sg2, (lanef)0.0f,
                               want_confidence, predict_centroid, facet_centroid, normal,
                               cell_start);
    lanef kf = a.kf;
    lanef shift = select((lanef)0.0f, a.e_min,
                         a.e_min > RS_RESCUE_EXPONENT && a.e_min < MAXFLOAT);
    if (any(shift != 0.0f)) /* some lane's weights all underflowed: redo it shifted */
        a = robust_sums(px, py, pz, cells, reach2, inv_2sf2, inv_2sg2, shift, 0, predict_centroid,
                        facet_centroid, normal, cell_start);
    lanei some = a.k > 0.0f;
    __global float *out = block_result + 4 * RS_LANES * (size_t)b;
    store_lanes(select((lanef)0.0f, a.x / a.k, some), 0, out);
    store_lanes(select((lanef)0.0f, a.y / a.k, some), 1, out);
    store_lanes(select((lanef)0.0f, a.z / a.k, some), 2, out);
    store_lanes(a.k, 3, out);
    __global float *extra = block_extra + 2 * RS_LANES * (size_t)b;
    store_lanes(kf, 0, extra);
    store_lanes(shift, 1, extra);
}
