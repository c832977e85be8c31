/* Bilateral normal filter (Zheng et al. 2011), in place of mollification: one round replaces each
 * facet normal n_r by
 *
 *     normalise(sum_q a_q exp(-|c_q - c_r|^2 / 2 s^2) exp(-|n_q - n_r|^2 / 2 t^2) n_q)
 *
 * over the facets q (r included) whose centroid lies within the reach of c_r; r keeps its normal
 * when the sum has zero length. Centroids and areas are the input's; the host runs the rounds,
 * each reading the previous round's normals and writing the other buffer.
 *
 * bilateral_cell_normals: one work-item per occupied cell computes its facets' new normals, up to
 *   RS_LANES facets at a time, one per vector lane: the cells within reach are looked up once per
 *   group and each neighbour is loaded once for every lane, as the vertex blocks do. The exponents
 *   are in base 2 (inv_2s2 = log2(e) h^2 / 2 s^2, inv_2t2 = log2(e) / 2 t^2), the area comes from
 *   facet_centroid.w = log2(area / mean area). cell_pairs[c] = facets the cell's groups evaluated.
 */

__kernel void bilateral_cell_normals(uint cell_count, float reach2, float inv_2s2, float inv_2t2,
                                     __global const float4 *facet_centroid,
                                     __global const float4 *normal_in,
                                     __global const int4 *cell_coord,
                                     __global const uint *cell_start,
                                     __global const uint *column_first,
                                     __global const int *column_table, uint column_mask,
                                     __global float4 *normal_out, __global ulong *cell_pairs) {
    uint c = get_global_id(0);
    if (c >= cell_count)
        return;
    int4 anchor = cell_coord[c];
    uint first = cell_start[c], last = cell_start[c + 1];
    ulong pairs = 0; /* a crowded cell's groups may scan more than 2^32 in all */
    for (uint group = first; group < last; group += RS_LANES) {
        uint count = min((uint)RS_LANES, last - group);
        /* Lanes past the group's end repeat its first facet; their results are never stored. */
        float rx[RS_LANES], ry[RS_LANES], rz[RS_LANES], mx[RS_LANES], my[RS_LANES], mz[RS_LANES];
        for (uint l = 0; l < RS_LANES; l++) {
            uint r = group + (l < count ? l : 0);
            float4 cr = facet_centroid[r], nr = normal_in[r];
            rx[l] = cr.x;
            ry[l] = cr.y;
            rz[l] = cr.z;
            mx[l] = nr.x;
            my[l] = nr.y;
            mz[l] = nr.z;
        }
        lanef px = load_lanes(0, rx), py = load_lanes(0, ry), pz = load_lanes(0, rz);
        lanef nx = load_lanes(0, mx), ny = load_lanes(0, my), nz = load_lanes(0, mz);
        float3 lo = (float3)(lane_min(px), lane_min(py), lane_min(pz));
        float3 hi = (float3)(lane_max(px), lane_max(py), lane_max(pz));
        lanef ax = 0.0f, ay = 0.0f, az = 0.0f;
        FOR_EACH_CELL_NEAR(anchor, lo, hi, reach2, cell_coord, column_first, column_table,
                           column_mask, {
            lanef qx = px - (float)dx, qy = py - (float)dy, qz = pz - (float)dz;
            uint begin = cell_start[cell], end = cell_start[cell + 1];
            pairs += end - begin;
            for (uint q = begin; q < end; q++) {
                float4 cq = facet_centroid[q];
                float4 nq = normal_in[q];
                lanef ex = cq.x - qx, ey = cq.y - qy, ez = cq.z - qz;
                lanef d2 = ex * ex + ey * ey + ez * ez;
                lanef fx = nq.x - nx, fy = nq.y - ny, fz = nq.z - nz;
                lanef m2 = fx * fx + fy * fy + fz * fz;
                lanef w = select((lanef)0.0f, fast_exp2(cq.w - d2 * inv_2s2 - m2 * inv_2t2),
                                 d2 <= reach2);
                ax += w * nq.x;
                ay += w * nq.y;
                az += w * nq.z;
            }
        })
        lanef len = sqrt(ax * ax + ay * ay + az * az);
        lanei some = len > 0.0f;
        store_lanes(select(nx, ax / len, some), 0, mx);
        store_lanes(select(ny, ay / len, some), 0, my);
        store_lanes(select(nz, az / len, some), 0, mz);
        for (uint l = 0; l < count; l++)
            normal_out[group + l] = (float4)(mx[l], my[l], mz[l], 0.0f);
    }
    cell_pairs[c] = pairs;
}
