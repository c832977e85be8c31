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
 *   It searches for the neighbours in every round; the host runs it only where the lists below
 *   (which search once per run) do not fit the device.
 */

/* A group's new normals: the sums (ax, ay, az) normalised, or the previous normal (nx, ny, nz)
 * where a sum has zero length, for its `count` facets from `first` on. */
inline void store_group_normals(lanef ax, lanef ay, lanef az, lanef nx, lanef ny, lanef nz,
                                __global float4 *normal_out, uint first, uint count) {
    float mx[RS_LANES], my[RS_LANES], mz[RS_LANES];
    lanef len = sqrt(ax * ax + ay * ay + az * az);
    lanei some = len > 0.0f;
    store_lanes(select(nx, ax / len, some), 0, mx);
    store_lanes(select(ny, ay / len, some), 0, my);
    store_lanes(select(nz, az / len, some), 0, mz);
    for (uint l = 0; l < count; l++) /* vstore4: see DECLARE_STAGE (common.cl) */
        vstore4((float4)(mx[l], my[l], mz[l], 0.0f), first + l, (__global float *)normal_out);
}

__kernel void
bilateral_cell_normals(uint cell_count, float reach2, float inv_2s2, float inv_2t2,
                       __global const float4 *facet_centroid, __global const float4 *normal_in,
                       __global const int4 *cell_coord, __global const uint *cell_start,
                       __global const uint *column_first, __global const int *column_table,
                       uint column_mask, __global float4 *normal_out, __global ulong *cell_pairs) {
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
        FOR_EACH_CELL_NEAR(
            anchor, lo, hi, reach2, cell_coord, column_first, column_table, column_mask, {
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
        store_group_normals(ax, ay, az, nx, ny, nz, normal_out, group, count);
    }
    cell_pairs[c] = pairs;
}

/* The same rounds from lists, which the device builds once for all the rounds of a run: centroids
 * and areas, hence which facets lie within reach and the part of their weights that does not
 * depend on normals, do not change between rounds. The search above meets every facet of every
 * cell near a group's box, most of them beyond the reach of all its lanes; a group's list keeps
 * those within reach of at least one lane, one row each: list_facet[i] = q and
 * list_weight[RS_LANES i + l] = log2(a_q / mean area) - |c_q - c_r|^2 inv_2s2 - shift for lane l's
 * facet r, or BILATERAL_FAR where q is beyond r's reach. A round then costs one exponential per
 * row and lane, and no search.
 *
 * group_info[g] = (first facet, lanes, cell, 0) for the groups of bilateral_cell_normals (each
 * cell's facets, RS_LANES at a time). bilateral_count counts each group's rows into list_start[g];
 * the host turns the counts, each plus one, into offsets (list_start[group_count] = the total);
 * bilateral_fill writes the rows, without branches: every facet met is written to the next row,
 * which the next facet overwrites unless this one was near (hence the spare row past each
 * group's last); each round runs bilateral_list_normals. Every run sums the same rows in the
 * same order. */

/* A row's weight for a lane beyond reach: bilateral_exp2 gives exactly 0 for it. */
#define BILATERAL_FAR -1e30f

/* fast_exp2 for the rounds: exponents at or below -127 give exactly 0, and there is no upper
 * clamp (a weight's exponent is at most log2(a_q / mean area), far below 128). */
inline lanef bilateral_exp2(lanef x) {
    lanef y = fmax(x, -127.0f);
    lanei t = convert_lanei(y + 128.5f); /* n + 128, n = y rounded to nearest */
    lanef f = y - (convert_lanef(t) - 128.0f);
    lanef p =
        1.00000012f +
        f * (0.693146944f +
             f * (0.240221202f + f * (0.0555071346f + f * (0.00967554096f + f * 0.00132764666f))));
    return p * as_lanef((t - 1) << 23);
}

/* 1 where some lane of m is set, else 0. */
inline uint some_lane(lanei m) {
    return (uint)lane_any(m);
}

/* The search of bilateral_cell_normals for group g: BODY runs for each facet q of each cell near
 * the group's box, with cq = facet_centroid[q], d2 its squared distance to each lane's centroid
 * and near = d2 <= reach2. */
#define BILATERAL_GROUP_SEARCH(BODY)                                                               \
    uint4 info = group_info[g];                                                                    \
    int4 anchor = cell_coord[info.z];                                                              \
    float rx[RS_LANES], ry[RS_LANES], rz[RS_LANES];                                                \
    for (uint l = 0; l < RS_LANES; l++) {                                                          \
        float4 cr = facet_centroid[info.x + (l < info.y ? l : 0)];                                 \
        rx[l] = cr.x;                                                                              \
        ry[l] = cr.y;                                                                              \
        rz[l] = cr.z;                                                                              \
    }                                                                                              \
    lanef px = load_lanes(0, rx), py = load_lanes(0, ry), pz = load_lanes(0, rz);                  \
    float3 lo = (float3)(lane_min(px), lane_min(py), lane_min(pz));                                \
    float3 hi = (float3)(lane_max(px), lane_max(py), lane_max(pz));                                \
    FOR_EACH_CELL_NEAR(anchor, lo, hi, reach2, cell_coord, column_first, column_table,             \
                       column_mask, {                                                              \
                           lanef qx = px - (float)dx, qy = py - (float)dy, qz = pz - (float)dz;    \
                           uint begin = cell_start[cell], end = cell_start[cell + 1];              \
                           for (uint q = begin; q < end; q++) {                                    \
                               float4 cq = facet_centroid[q];                                      \
                               lanef ex = cq.x - qx, ey = cq.y - qy, ez = cq.z - qz;               \
                               lanef d2 = ex * ex + ey * ey + ez * ez;                             \
                               lanei near = d2 <= reach2;                                          \
                               BODY                                                                \
                           }                                                                       \
                       })

__kernel void bilateral_count(uint group_count, float reach2, __global const uint4 *group_info,
                              __global const float4 *facet_centroid,
                              __global const int4 *cell_coord, __global const uint *cell_start,
                              __global const uint *column_first, __global const int *column_table,
                              uint column_mask, __global uint *list_start) {
    uint g = get_global_id(0);
    if (g >= group_count)
        return;
    uint n = 0;
    BILATERAL_GROUP_SEARCH({ n += some_lane(near); })
    list_start[g] = n;
}

__kernel void bilateral_fill(uint group_count, float reach2, float inv_2s2, float shift,
                             __global const uint4 *group_info,
                             __global const float4 *facet_centroid, __global const int4 *cell_coord,
                             __global const uint *cell_start, __global const uint *column_first,
                             __global const int *column_table, uint column_mask,
                             __global const uint *list_start, __global uint *list_facet,
                             __global float *list_weight) {
    uint g = get_global_id(0);
    if (g >= group_count)
        return;
    uint row = list_start[g];
    BILATERAL_GROUP_SEARCH({
        list_facet[row] = q;
        store_lanes(select((lanef)BILATERAL_FAR, cq.w - d2 * inv_2s2 - shift, near), row,
                    list_weight);
        row += some_lane(near);
    })
}

/* One round from the lists: the normals of group g's facets, from normal_in to normal_out. The
 * normals being unit, |n_q - n_r|^2 inv_2t2 = (2 - 2 n_q . n_r) inv_2t2: with `dot` 1 the rows
 * hold the - 2 inv_2t2 already (bilateral_fill's shift), the lanes 2 inv_2t2 n_r, and an exponent
 * is a row's value plus a dot product. That form loses about 2 inv_2t2 float ulps to
 * cancellation, so for narrow normal widths (large inv_2t2) the host asks for the difference
 * itself (`dot` 0, shift 0). */
__kernel void
bilateral_list_normals(uint group_count, float inv_2t2, int dot, __global const uint4 *group_info,
                       __global const uint *list_start, __global const uint *list_facet,
                       __global const float *list_weight, __global const float4 *normal_in,
                       __global float4 *normal_out) {
    uint g = get_global_id(0);
    if (g >= group_count)
        return;
    uint4 info = group_info[g];
    float mx[RS_LANES], my[RS_LANES], mz[RS_LANES];
    for (uint l = 0; l < RS_LANES; l++) {
        float4 nr = normal_in[info.x + (l < info.y ? l : 0)];
        mx[l] = nr.x;
        my[l] = nr.y;
        mz[l] = nr.z;
    }
    lanef nx = load_lanes(0, mx), ny = load_lanes(0, my), nz = load_lanes(0, mz);
    lanef ax = 0.0f, ay = 0.0f, az = 0.0f;
    uint begin = list_start[g], end = list_start[g + 1] - 1; /* less the spare row */
    if (dot) {
        float two_inv_2t2 = 2.0f * inv_2t2;
        lanef sx = nx * two_inv_2t2, sy = ny * two_inv_2t2, sz = nz * two_inv_2t2;
        for (uint row = begin; row < end; row++) {
            float4 nq = normal_in[list_facet[row]];
            lanef w =
                bilateral_exp2(load_lanes(row, list_weight) + nq.x * sx + nq.y * sy + nq.z * sz);
            ax += w * nq.x;
            ay += w * nq.y;
            az += w * nq.z;
        }
    } else {
        for (uint row = begin; row < end; row++) {
            float4 nq = normal_in[list_facet[row]];
            lanef fx = nq.x - nx, fy = nq.y - ny, fz = nq.z - nz;
            lanef w = bilateral_exp2(load_lanes(row, list_weight) -
                                     (fx * fx + fy * fy + fz * fz) * inv_2t2);
            ax += w * nq.x;
            ay += w * nq.y;
            az += w * nq.z;
        }
    }
    store_group_normals(ax, ay, az, nx, ny, nz, normal_out, info.x, info.y);
}
