/* The normal-update stage of the best mode on the device (lib/stages/normal_update.h is the
 * double-precision host version these follow line by line, and what the tests hold them to):
 * cycles of facet geometry, guided normal filtering (Zhang et al. 2015) and Sun et al.'s vertex
 * update, every list built once on the host and kept on the device across cycles.
 *
 * One work-item per facet or per vertex, whatever the variant: each sums over its own lists in
 * the host's order, so the CPU blocks and GPU groups variants give the same bits.
 *
 * Positions live as displacements d_v from the input (which stays in double on the host),
 * and the input's geometry as differences computed in double and rounded once: a facet's two edge
 * vectors, and each (welded vertex, facet) pair's offset from the vertex to the facet's centroid.
 * So every length the update sums is of the order of an edge, and rounding does not grow with the
 * mesh's distance from the origin or with the cycles (the drift table in docs/best-mode.md).
 *
 * The program holds these kernels twice (cl_program.c): in float (names ending _f) and, where the
 * device has cl_khr_fp64, in double (_d), which the host picks by default: float32 does not drift
 * over the cycles, but a patch's score can come out of float on the other side of a near tie and
 * pick another guidance than the double host would (docs/best-mode.md, the drift table). REAL,
 * REAL4 and STAGE_NAME are defined before each copy. Vectors are 4-wide with w = 0 wherever a
 * 3-vector is meant (Oclgrind's uninitialised-value checker crashes on 3-wide ones).
 *
 * Buffers (REAL4 unless said; scaled units, near 1: normal_update.c):
 *   facet_vertex[f]   uint4 (a, b, c, 0): the facet's three vertices
 *   facet_rest[2 f]   REAL4 b - a, [2 f + 1] c - a, of the input
 *   rest_centroid[f]  REAL4 the input centroid
 *   centroid[f]       REAL4 (current centroid, area): the spatial weights'
 *   shift[f]          REAL4 the centroid's displacement: the vertex update's
 *   normal[f]         REAL4 the current unit normal
 *   rep[v], rep_start, rep_facet, rep_offset: the welded vertex of v, and its facets with the
 *                     input offset c_f - x_v of each
 *   patch_start, patch; edge_start, edge; near_start, near: guided_normals.c's lists
 */

/* Facet geometry from the displacements: centroid, area, unit normal; a facet whose cross product
 * vanishes keeps what it had (rs_facets_update). */
__kernel void STAGE_NAME(stage_facets)(uint facet_count, __global const uint4 *facet_vertex,
                                       __global const REAL4 *facet_rest,
                                       __global const REAL4 *rest_centroid, __global const REAL4 *d,
                                       __global REAL4 *centroid, __global REAL4 *shift,
                                       __global REAL4 *normal) {
    uint f = get_global_id(0);
    if (f >= facet_count)
        return;
    uint4 t = facet_vertex[f];
    REAL4 da = d[t.x], db = d[t.y], dc = d[t.z];
    REAL4 n =
        cross(facet_rest[2 * (size_t)f] + (db - da), facet_rest[2 * (size_t)f + 1] + (dc - da));
    REAL len = sqrt(dot(n, n));
    if (!(len > 0))
        return;
    REAL4 s = (da + db + dc) / 3, c = rest_centroid[f] + s;
    c.w = (REAL)0.5 * len;
    normal[f] = n / len;
    shift[f] = s;
    centroid[f] = c;
}

/* Step 1: facet j's patch: its area-weighted mean normal and its score Phi R. */
__kernel void STAGE_NAME(stage_patch)(uint facet_count, __global const uint *patch_start,
                                      __global const uint *patch, __global const uint *edge_start,
                                      __global const uint *edge, __global const REAL4 *centroid,
                                      __global const REAL4 *normal_in, __global REAL4 *patch_mean,
                                      __global REAL *patch_score) {
    uint j = get_global_id(0);
    if (j >= facet_count)
        return;
    uint first = patch_start[j], end = patch_start[j + 1];
    REAL4 mean = (REAL4)(0);
    REAL phi2 = 0, edge_max = 0, edge_sum = 0;
    for (uint a = first; a < end; a++) {
        uint fa = patch[a];
        REAL4 na = normal_in[fa];
        mean += centroid[fa].w * na;
        for (uint b = a + 1; b < end; b++) {
            REAL4 g = na - normal_in[patch[b]];
            phi2 = fmax(phi2, dot(g, g));
        }
    }
    for (uint e = edge_start[j]; e < edge_start[j + 1]; e++) {
        REAL4 g = normal_in[edge[2 * e]] - normal_in[edge[2 * e + 1]];
        REAL gap = sqrt(dot(g, g));
        edge_max = fmax(edge_max, gap);
        edge_sum += gap;
    }
    REAL len = sqrt(dot(mean, mean));
    patch_mean[j] = len > 0 ? mean / len : normal_in[j];
    patch_score[j] = sqrt(phi2) * edge_max / ((REAL)1e-9 + edge_sum);
}

/* Step 2: facet i's guidance, the mean normal of the lowest-scored patch holding it (ties to the
 * lowest index). */
__kernel void STAGE_NAME(stage_guidance)(uint facet_count, __global const uint *patch_start,
                                         __global const uint *patch,
                                         __global const REAL *patch_score,
                                         __global const REAL4 *patch_mean,
                                         __global REAL4 *guidance) {
    uint i = get_global_id(0);
    if (i >= facet_count)
        return;
    uint best = i;
    REAL b = patch_score[i];
    for (uint k = patch_start[i] + 1; k < patch_start[i + 1]; k++) {
        uint q = patch[k];
        REAL s = patch_score[q];
        if (s < b || (s == b && q < best)) {
            best = q;
            b = s;
        }
    }
    guidance[i] = patch_mean[best];
}

/* Step 3: the joint bilateral filter over facet i's neighbours, its range from the guidance.
 * Exponents in base 2 (inv_2s2 and inv_2t2 carry log2 e). */
__kernel void STAGE_NAME(stage_filter)(uint facet_count, __global const uint *near_start,
                                       __global const uint *near, __global const REAL4 *centroid,
                                       __global const REAL4 *guidance,
                                       __global const REAL4 *normal_in, REAL inv_2s2, REAL inv_2t2,
                                       __global REAL4 *normal_out) {
    uint i = get_global_id(0);
    if (i >= facet_count)
        return;
    REAL4 ci = centroid[i], gi = guidance[i], acc = (REAL4)(0);
    for (uint k = near_start[i]; k < near_start[i + 1]; k++) {
        uint q = near[k];
        REAL4 dc = centroid[q] - ci, dg = guidance[q] - gi;
        REAL area = dc.w + ci.w; /* centroid[q].w, without a second load */
        dc.w = 0;
        REAL w = area * exp2(-(dot(dc, dc) * inv_2s2 + dot(dg, dg) * inv_2t2));
        acc += w * normal_in[q];
    }
    REAL len = sqrt(dot(acc, acc));
    normal_out[i] = len > 0 ? acc / len : normal_in[i];
}

/* Sun et al.'s vertex update, Jacobi style: x += mean over the welded vertex's facets of
 * n_f (n_f . (c_f - x)), c_f - x = (input offset) + (centroid's shift) - (vertex's); a vertex
 * whose `mask` byte is 0 stays (mask_on 0: every vertex moves). */
__kernel void STAGE_NAME(stage_vertex)(uint vertex_count, __global const uint *rep,
                                       __global const uint *rep_start,
                                       __global const uint *rep_facet,
                                       __global const REAL4 *rep_offset,
                                       __global const REAL4 *shift, __global const REAL4 *normal,
                                       __global const uchar *mask, int mask_on,
                                       __global const REAL4 *d_in, __global REAL4 *d_out) {
    uint v = get_global_id(0);
    if (v >= vertex_count)
        return;
    REAL4 dv = d_in[v], move = (REAL4)(0);
    uint r = rep[v], first = rep_start[r], end = rep_start[r + 1];
    for (uint i = first; i < end; i++) {
        uint f = rep_facet[i];
        REAL4 nf = normal[f];
        move += dot(nf, rep_offset[i] + shift[f] - dv) * nf;
    }
    bool moves = end > first && (!mask_on || mask[v]);
    d_out[v] = moves ? dv + move / (REAL)(end - first) : dv;
}
