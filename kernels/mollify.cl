/* Mollification (Jones et al. 2003, Sec. 3.2): the predictors' normals come from a copy of the mesh
 * whose vertices moved to sum c_q a_q f_m / sum a_q f_m, f_m a Gaussian of width sigma_m = sigma_f/2.
 *
 * mollify_vertex: one work-item per vertex (grid order) writes its displacement, in cell units, to
 *   vertex_shift[v] (float4; 0 where no facet is within reach).
 * mollified_facet_normal: one work-item per facet writes the unit normal of the mollified triangle
 *   (or its input normal when the mollified triangle is degenerate: a corner sine below
 *   RS_DEGENERATE_SINE, or an area below RS_DEGENERATE_AREA_RATIO of the input's) to
 *   mollified_normal[q].
 *   facet_vertices[q] = (v0, v1, v2, 0) in grid order; facet_edge1/2[q] = v1 - v0, v2 - v0 (cell units).
 */

__kernel void mollify_vertex(uint vertex_count, float reach2, float inv_2sigma2,
                             __global const float4 *vertex_local, __global const int4 *vertex_cell,
                             __global const float4 *facet_centroid,
                             __global const int4 *cell_coord, __global const uint *cell_start,
                             __global const int *table, uint table_mask,
                             __global float4 *vertex_shift) {
    uint v = get_global_id(0);
    if (v >= vertex_count)
        return;
    float3 p = vertex_local[v].xyz;
    int4 home = vertex_cell[v];
    float wsum = 0.0f;
    float3 acc = (float3)(0.0f);
    for (int dx = -1; dx <= 1; dx++)
        for (int dy = -1; dy <= 1; dy++)
            for (int dz = -1; dz <= 1; dz++) {
                int cell = grid_find(cell_coord, table, table_mask, home.x + dx, home.y + dy,
                                     home.z + dz);
                if (cell < 0)
                    continue;
                float3 pc = p - (float3)((float)dx, (float)dy, (float)dz);
                uint end = cell_start[cell + 1];
                for (uint q = cell_start[cell]; q < end; q++) {
                    float4 c = facet_centroid[q];
                    float3 d = c.xyz - pc;
                    float d2 = dot(d, d);
                    if (d2 <= reach2) {
                        float w = exp(c.w - d2 * inv_2sigma2);
                        acc += w * d;
                        wsum += w;
                    }
                }
            }
    vertex_shift[v] = wsum > 0.0f ? (float4)(acc / wsum, 0.0f) : (float4)(0.0f);
}

__kernel void mollified_facet_normal(uint facet_count, __global const uint4 *facet_vertices,
                                     __global const float4 *facet_edge1,
                                     __global const float4 *facet_edge2,
                                     __global const float4 *facet_normal,
                                     __global const float4 *vertex_shift,
                                     __global float4 *mollified_normal) {
    uint q = get_global_id(0);
    if (q >= facet_count)
        return;
    uint4 t = facet_vertices[q];
    float3 input_e1 = facet_edge1[q].xyz, input_e2 = facet_edge2[q].xyz;
    float3 input_n = cross(input_e1, input_e2);
    float3 s0 = vertex_shift[t.x].xyz;
    float3 e1 = input_e1 + vertex_shift[t.y].xyz - s0;
    float3 e2 = input_e2 + vertex_shift[t.z].xyz - s0;
    float3 n = cross(e1, e2);
    float len = sqrt(dot(n, n));
    if (len > RS_DEGENERATE_SINE * sqrt(dot(e1, e1) * dot(e2, e2)) &&
        len > RS_DEGENERATE_AREA_RATIO * sqrt(dot(input_n, input_n)))
        mollified_normal[q] = (float4)(n / len, 0.0f);
    else
        mollified_normal[q] = facet_normal[q];
}
