/* Robust estimation (Jones et al. 2003, Eq. 3): p' = sum Pi_q(p) a_q f g / k(p), Pi_q(p) = p + t n_q
 * with t = n_q . (c_q - p), f = exp(-|c_q - p|^2 / (2 sigma_f^2)), g = exp(-t^2 / (2 sigma_g^2)).
 *
 * robust_vertex: one work-item per vertex (grid order) writes
 *   vertex_result[v] = (displacement p' - p in cell units, k' = sum of the weights used)
 *   vertex_extra[v]  = (sum a f, the exponent shift e_s, 0, 0): k(p) = k' exp(-e_s) in mean-area units.
 * When every influence exponent exceeds RS_RESCUE_EXPONENT, float32 weights would underflow; the
 * sums are then redone with the smallest exponent subtracted (e_s), as the reference path does.
 * `want_confidence` = 0 skips sum a f (one exp per pair instead of two). `predict_centroid` = 1
 * predicts c_q instead of Pi_q(p) (isotropic Gaussian smoothing when inv_2sg2 = 0).
 */

/* Sums of Eq. 3 over the facets within reach of p, in the cells listed in `cells` (the 27 around
 * the vertex's own, -1 where empty), with influence exponents shifted down by `shift`. */
inline void robust_sums(float3 p, const int *cells, float reach2, float inv_2sf2, float inv_2sg2,
                        float shift, int want_confidence, int predict_centroid, __global const float4 *facet_centroid,
                        __global const float4 *normal, __global const uint *cell_start,
                        float3 *acc_out, float *k_out, float *kf_out, float *e_min_out) {
    float k = 0.0f, kf = 0.0f, e_min = MAXFLOAT;
    float3 acc = (float3)(0.0f);
    int i = 0;
    for (int dx = -1; dx <= 1; dx++)
        for (int dy = -1; dy <= 1; dy++)
            for (int dz = -1; dz <= 1; dz++) {
                int cell = cells[i++];
                if (cell < 0)
                    continue;
                float3 pc = p - (float3)((float)dx, (float)dy, (float)dz);
                uint end = cell_start[cell + 1];
                for (uint q = cell_start[cell]; q < end; q++) {
                    float4 c = facet_centroid[q];
                    float3 d = c.xyz - pc;
                    float d2 = dot(d, d);
                    if (d2 <= reach2) {
                        float3 n = normal[q].xyz;
                        float t = dot(n, d);
                        /* prediction - p: Pi_q(p) - p = t n, or c_q - p = d (centroid) */
                        float3 step = predict_centroid ? d : t * n;
                        float e = (predict_centroid ? d2 : t * t) * inv_2sg2;
                        float w = exp(c.w - d2 * inv_2sf2 - (e - shift));
                        acc += w * step;
                        k += w;
                        e_min = fmin(e_min, e);
                        if (want_confidence)
                            kf += exp(c.w - d2 * inv_2sf2);
                    }
                }
            }
    *acc_out = acc;
    *k_out = k;
    *kf_out = kf;
    *e_min_out = e_min;
}

__kernel void robust_vertex(uint vertex_count, float reach2, float inv_2sf2, float inv_2sg2,
                            int want_confidence, int predict_centroid,
                            __global const float4 *vertex_local, __global const int4 *vertex_cell,
                            __global const float4 *facet_centroid, __global const float4 *normal,
                            __global const int4 *cell_coord, __global const uint *cell_start,
                            __global const int *table, uint table_mask,
                            __global float4 *vertex_result, __global float4 *vertex_extra) {
    uint v = get_global_id(0);
    if (v >= vertex_count)
        return;
    float3 p = vertex_local[v].xyz;
    int4 home = vertex_cell[v];
    int cells[27];
    int i = 0;
    for (int dx = -1; dx <= 1; dx++)
        for (int dy = -1; dy <= 1; dy++)
            for (int dz = -1; dz <= 1; dz++)
                cells[i++] = grid_find(cell_coord, table, table_mask, home.x + dx, home.y + dy,
                                       home.z + dz);
    float3 acc;
    float k, kf, e_min, unused;
    robust_sums(p, cells, reach2, inv_2sf2, inv_2sg2, 0.0f, want_confidence, predict_centroid,
                facet_centroid, normal, cell_start, &acc, &k, &kf, &e_min);
    float shift = 0.0f;
    if (e_min > RS_RESCUE_EXPONENT && e_min < MAXFLOAT) {
        shift = e_min;
        robust_sums(p, cells, reach2, inv_2sf2, inv_2sg2, shift, 0, predict_centroid,
                    facet_centroid, normal, cell_start, &acc, &k, &unused, &e_min);
    }
    vertex_result[v] = k > 0.0f ? (float4)(acc / k, k) : (float4)(0.0f);
    vertex_extra[v] = (float4)(kf, shift, 0.0f, 0.0f);
}
