/* A learned cascade stage's network (lib/learned/network.c is the double-precision host version,
 * and what the tests hold these to) over a chunk of facets' descriptors: dense layers, a
 * rectifier where a layer asks for one, the last layer's 3 numbers the facet's residual.
 *
 * Buffers:
 *   shape[l]        uint4 (in, out, activation, offset): layer l's widths, 1 for the rectifier,
 *                   and where its weights start in `weight`, its out biases right after them
 *   weight          every layer's weights and biases, float; row-major (out rows of in) for the
 *                   CPU variant, transposed (in rows of out) for the GPU's, whose work-items read
 *                   neighbouring outputs' weights together
 *   descriptors[f]  shape[0].x floats per facet, row after row
 *   residuals[f]    3 floats per facet
 * `width` is the widest layer (in or out); `scratch` holds 2 RS_LEARNED_TILE rows of it (the GPU
 * variant's; the CPU's takes a token size and leaves it alone).
 *
 * Both sum in float (the host's double is within float rounding: the tests' 1e-5 on the
 * normals); they differ in how the facets are spread: a work-item per facet, its activations
 * private and each output's sum in 8 vector lanes (CPU), or a work-group per tile of
 * RS_LEARNED_TILE facets whose activations sit in local memory, its work-items over the outputs
 * (GPU: each weight is read once per tile, not once per facet). */

#if RS_LANES == 1

__kernel void learned_stage(uint count, uint layers, __global const uint4 *shape,
                            __global const float *weight, __global const float *descriptors,
                            __global float *residuals, __local float *scratch, uint width) {
    uint lid = get_local_id(0), size = get_local_size(0);
    uint first = get_group_id(0) * RS_LEARNED_TILE;
    uint n = min((uint)RS_LEARNED_TILE, count - first);
    uint inputs = shape[0].x;
    __local float *in = scratch, *out = scratch + RS_LEARNED_TILE * width;
    /* the tile's descriptors; rows past the chunk's end are zeros, computed and never written */
    for (uint t = 0; t < RS_LEARNED_TILE; t++)
        for (uint i = lid; i < inputs; i += size)
            in[t * width + i] = t < n ? descriptors[(size_t)(first + t) * inputs + i] : 0.0f;
    barrier(CLK_LOCAL_MEM_FENCE);
    for (uint l = 0; l < layers; l++) {
        uint4 s = shape[l];
        __global const float *w = weight + s.w, *bias = w + (size_t)s.x * s.y;
        for (uint o = lid; o < s.y; o += size) {
            float acc[RS_LEARNED_TILE], part[RS_LEARNED_TILE];
            for (uint t = 0; t < RS_LEARNED_TILE; t++)
                acc[t] = bias[o];
            /* in blocks of 8 inputs, each block's sum added whole: rounding grows with the
             * blocks' count and size, not with the layer's width (as the CPU variant's lanes) */
            for (uint i0 = 0; i0 < s.x; i0 += 8) {
                for (uint t = 0; t < RS_LEARNED_TILE; t++)
                    part[t] = 0.0f;
                for (uint i = i0; i < min(i0 + 8, s.x); i++) {
                    float wi = w[(size_t)i * s.y + o];
#pragma unroll
                    for (uint t = 0; t < RS_LEARNED_TILE; t++)
                        part[t] = mad(wi, in[t * width + i], part[t]);
                }
                for (uint t = 0; t < RS_LEARNED_TILE; t++)
                    acc[t] += part[t];
            }
            for (uint t = 0; t < RS_LEARNED_TILE; t++)
                out[t * width + o] = s.z == 1 ? fmax(acc[t], 0.0f) : acc[t];
        }
        /* every read of `in` is done before the next layer writes over it */
        barrier(CLK_LOCAL_MEM_FENCE);
        __local float *next = in;
        in = out;
        out = next;
    }
    for (uint t = 0; t < n; t++)
        for (uint k = lid; k < 3; k += size)
            residuals[(size_t)(first + t) * 3 + k] = in[t * width + k];
}

#else

/* One output from its 8 lanes of partial sums over row[0, from) and the row's tail: the bias,
 * the lanes summed pairwise, then the tail in order, and the rectifier where asked. The lanes go
 * through a private array: Oclgrind's uninitialised-value check crashes on the shuffles of .lo
 * and .hi (tests/test_oclgrind.c, its error 3). */
inline float finish(float8 acc8, __global const float *row, const float *in, uint from, uint n,
                    float bias, uint rectify) {
    float lane[8];
    vstore8(acc8, 0, lane);
    float sum = bias + (((lane[0] + lane[1]) + (lane[2] + lane[3])) +
                        ((lane[4] + lane[5]) + (lane[6] + lane[7])));
    for (uint i = from; i < n; i++)
        sum = mad(row[i], in[i], sum);
    return rectify == 1 ? fmax(sum, 0.0f) : sum;
}

/* One layer from `in` to `out`: 4 outputs at a time, each 8 inputs loaded once for the 4 rows
 * (every output sums as it would alone), then the outputs left over one at a time. */
inline void dense(uint4 s, __global const float *w, const float *in, float *out) {
    __global const float *bias = w + (size_t)s.x * s.y;
    uint o = 0;
    for (; o + 4 <= s.y; o += 4) {
        __global const float *r = w + (size_t)o * s.x;
        float8 a0 = (float8)(0.0f), a1 = a0, a2 = a0, a3 = a0;
        uint i = 0;
        for (; i + 8 <= s.x; i += 8) {
            float8 x = vload8(0, in + i);
            a0 = mad(vload8(0, r + i), x, a0);
            a1 = mad(vload8(0, r + s.x + i), x, a1);
            a2 = mad(vload8(0, r + 2 * s.x + i), x, a2);
            a3 = mad(vload8(0, r + 3 * s.x + i), x, a3);
        }
        out[o] = finish(a0, r, in, i, s.x, bias[o], s.z);
        out[o + 1] = finish(a1, r + s.x, in, i, s.x, bias[o + 1], s.z);
        out[o + 2] = finish(a2, r + 2 * s.x, in, i, s.x, bias[o + 2], s.z);
        out[o + 3] = finish(a3, r + 3 * s.x, in, i, s.x, bias[o + 3], s.z);
    }
    for (; o < s.y; o++) {
        __global const float *r = w + (size_t)o * s.x;
        float8 a0 = (float8)(0.0f);
        uint i = 0;
        for (; i + 8 <= s.x; i += 8)
            a0 = mad(vload8(0, r + i), vload8(0, in + i), a0);
        out[o] = finish(a0, r, in, i, s.x, bias[o], s.z);
    }
}

__kernel void learned_stage(uint count, uint layers, __global const uint4 *shape,
                            __global const float *weight, __global const float *descriptors,
                            __global float *residuals, __local float *scratch, uint width) {
    (void)scratch;
    (void)width;
    size_t f = get_global_id(0);
    if (f >= count)
        return;
    float a[RS_LEARNED_MAX_WIDTH], b[RS_LEARNED_MAX_WIDTH];
    float *in = a, *out = b;
    uint inputs = shape[0].x;
    for (uint i = 0; i < inputs; i++)
        a[i] = descriptors[f * inputs + i];
    for (uint l = 0; l < layers; l++) {
        dense(shape[l], weight + shape[l].w, in, out);
        float *next = in;
        in = out;
        out = next;
    }
    for (uint k = 0; k < 3; k++)
        residuals[3 * f + k] = in[k];
}

#endif
