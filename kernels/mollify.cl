/* Mollification (Jones et al. 2003, Sec. 3.2): the predictors' normals come from a copy of the mesh
 * whose vertices moved to sum c_q a_q f_m / sum a_q f_m, f_m a Gaussian of width sigma_m =
 * sigma_f/2.
 *
 * mollify_block: one work-item per vertex block writes each lane's displacement, in cell units, to
 *   block_shift (3 components per lane; 0 where no facet is within reach).
 * mollified_facet_normal: one work-item per facet replaces its input normal, in place, by the unit
 *   normal of the mollified triangle (unless that triangle is degenerate: a corner sine below
 *   RS_DEGENERATE_SINE, or an area below RS_DEGENERATE_AREA_RATIO of the input's). The triangle's
 *   corners come from the vertex blocks (positions plus shifts); facet_vertices[q] = the slots of
 *   its three vertices, in the caller's facet order; facet_place[q] = the facet's index in grid
 *   order, where its normal lives.
 */

__kernel void mollify_block(uint block_count, float reach2, float inv_2sigma2,
                            __global const float *block_pos, __global const int4 *block_cell,
                            __global const uchar *block_offset,
                            __global const float4 *facet_centroid, __global const int4 *cell_coord,
                            __global const uint *cell_start, __global const uint *column_first,
                            __global const int *column_table, uint column_mask,
                            __global float *block_shift, __global uint *block_pairs) {
    uint b = get_global_id(0);
    BEGIN_BLOCK(b, block_count, block_pos, block_cell, block_offset);
    lanef wsum = 0.0f, ax = 0.0f, ay = 0.0f, az = 0.0f;
    uint pairs = 0;
    FOR_EACH_FACET_NEAR(reach2, facet_centroid, pairs, {
        lanef ex = c.x - qx, ey = c.y - qy, ez = c.z - qz;
        lanef d2 = ex * ex + ey * ey + ez * ez;
        lanef w = select((lanef)0.0f, fast_exp2(c.w - d2 * inv_2sigma2), d2 <= reach2);
        ax += w * ex;
        ay += w * ey;
        az += w * ez;
        wsum += w;
    })
    if (b >= block_count) /* the group variant's spare work-items */
        return;
    lanei some = wsum > 0.0f;
    __global float *out = block_shift + 3 * RS_LANES * (size_t)b;
    store_lanes(select((lanef)0.0f, ax / wsum, some), 0, out);
    store_lanes(select((lanef)0.0f, ay / wsum, some), 1, out);
    store_lanes(select((lanef)0.0f, az / wsum, some), 2, out);
    block_pairs[2 * (size_t)b] = pairs;
}

/* The displacement of the vertex in `slot` (from mollify_block). */
inline float3 slot_shift(__global const float *block_shift, uint slot) {
    return (float3)(slot_component(block_shift, slot, 3, 0),
                    slot_component(block_shift, slot, 3, 1),
                    slot_component(block_shift, slot, 3, 2));
}

/* The position of the vertex in `slot`, in cells from the corner of cell `origin`: exact in its
 * integer part, so differences between a facet's corners keep float32's full precision. */
inline float3 slot_position(__global const float *block_pos, __global const int4 *block_cell,
                            __global const uchar *block_offset, uint slot, int4 origin) {
    int4 cell = slot_cell(block_cell, block_offset, slot) - origin;
    return convert_float3(cell.xyz) + (float3)(slot_component(block_pos, slot, 3, 0),
                                               slot_component(block_pos, slot, 3, 1),
                                               slot_component(block_pos, slot, 3, 2));
}

__kernel void mollified_facet_normal(uint facet_count, __global const uint *facet_vertices,
                                     __global const uint *facet_place,
                                     __global const float *block_pos,
                                     __global const int4 *block_cell,
                                     __global const uchar *block_offset, __global float4 *normal,
                                     __global const float *block_shift) {
    uint q = get_global_id(0); /* the caller's facet order; j is its place in grid order */
    if (q >= facet_count)
        return;
    uint j = facet_place[q];
    uint3 t = vload3(q, facet_vertices);
    int4 origin = slot_cell(block_cell, block_offset, t.x);
    float3 p0 = slot_position(block_pos, block_cell, block_offset, t.x, origin);
    float3 input_e1 = slot_position(block_pos, block_cell, block_offset, t.y, origin) - p0;
    float3 input_e2 = slot_position(block_pos, block_cell, block_offset, t.z, origin) - p0;
    float3 input_n = cross(input_e1, input_e2);
    float3 s0 = slot_shift(block_shift, t.x);
    float3 e1 = input_e1 + slot_shift(block_shift, t.y) - s0;
    float3 e2 = input_e2 + slot_shift(block_shift, t.z) - s0;
    float3 n = cross(e1, e2);
    float len = sqrt(dot(n, n));
    /* each work-item reads and writes its own facet's normal only: replacing it is safe */
    if (len > RS_DEGENERATE_SINE * sqrt(dot(e1, e1) * dot(e2, e2)) &&
        len > RS_DEGENERATE_AREA_RATIO * sqrt(dot(input_n, input_n)))
        normal[j] = (float4)(n / len, 0.0f);
}
