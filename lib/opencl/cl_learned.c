/* A learned cascade stage's network on the device (kernels/learned.cl), a chunk of descriptors
 * per call: the stage's weights packed into one buffer (in the layout of the context's kernel
 * variant), the descriptors uploaded, one launch, the residuals read back. Every failure returns
 * a status before any residual is used, and the host (learned/learned_normals.c) runs the chunk in
 * double instead: a runner has no error to fill, its refusal is no error of the call. */
#include "learned/learned.h"
#include "opencl/cl_internal.h"

#include <string.h>

/* The network's buffers, in kernel argument order after count and layers. */
enum { LB_SHAPE, LB_WEIGHT, LB_DESCRIPTORS, LB_RESIDUALS, LB_COUNT };

/* The layers' shapes (in, out, activation, offset) and every weight and bias in one array:
 * row-major as the model holds them, or transposed for the GPU variant. NULL when out of memory.
 * *width gets the widest layer. */
static float *pack_weights(const rs_learned_stage *stage, bool transposed, cl_uint4 *shape,
                           size_t *floats, uint32_t *width) {
    size_t total = 0;
    *width = 0;
    for (uint32_t l = 0; l < stage->layer_count; l++) {
        const rs_learned_layer *layer = &stage->layer[l];
        shape[l] = (cl_uint4){{layer->in, layer->out, layer->activation, (cl_uint)total}};
        total += (size_t)layer->in * layer->out + layer->out;
        *width = layer->in > *width ? layer->in : *width;
        *width = layer->out > *width ? layer->out : *width;
    }
    float *packed = rs_alloc_array(total ? total : 1, sizeof(float));
    for (uint32_t l = 0; packed && l < stage->layer_count; l++) {
        const rs_learned_layer *layer = &stage->layer[l];
        float *w = packed + shape[l].s[3];
        size_t in = layer->in, out = layer->out;
        for (size_t o = 0; o < out; o++)
            for (size_t i = 0; i < in; i++)
                w[transposed ? i * out + o : o * in + i] = layer->weight[o * in + i];
        memcpy(w + in * out, layer->bias, out * sizeof(float));
    }
    *floats = total;
    return packed;
}

/* Whether the device holds the chunk: its buffers within the run's budget and the largest
 * allocation, the GPU variant's tile rows within local memory, the widths within the kernel's. */
static bool fits(const rsmooth_context *ctx, const size_t *bytes, size_t local_bytes,
                 uint32_t width) {
    uint64_t total = 0;
    for (int b = 0; b < LB_COUNT; b++) {
        total += bytes[b];
        if (bytes[b] > ctx->max_allocation)
            return false;
    }
    cl_ulong local_memory = 0;
    if (clGetDeviceInfo(ctx->device, CL_DEVICE_LOCAL_MEM_SIZE, sizeof local_memory, &local_memory,
                        NULL) != CL_SUCCESS)
        return false;
    return total <= rs_cl_usable_memory(ctx) && local_bytes <= local_memory &&
           width <= RS_LEARNED_MAX_WIDTH;
}

/* The launch over `count` facets and the residuals back (blocking). */
static cl_int launch(rsmooth_context *ctx, const cl_mem *buf, cl_uint layers, cl_uint count,
                     size_t local_bytes, cl_uint width, float *residuals) {
    cl_kernel kernel = ctx->kernels[RS_KERNEL_LEARNED];
    cl_int err = CL_SUCCESS;
    cl_uint index = 0;
    const void *values[] = {
        &count, &layers, &buf[LB_SHAPE], &buf[LB_WEIGHT], &buf[LB_DESCRIPTORS], &buf[LB_RESIDUALS],
        NULL,   &width};
    const size_t sizes[] = {sizeof count,   sizeof layers,  sizeof(cl_mem), sizeof(cl_mem),
                            sizeof(cl_mem), sizeof(cl_mem), local_bytes,    sizeof width};
    for (; index < sizeof sizes / sizeof *sizes && err == CL_SUCCESS; index++)
        err = clSetKernelArg(kernel, index, sizes[index], values[index]);
    size_t local = ctx->local_size;
    /* GPU variant: a work-group per tile of facets; CPU: a work-item per facet */
    size_t groups = ctx->lanes == 1 ? (count + RS_LEARNED_TILE - 1) / RS_LEARNED_TILE
                                    : (count + local - 1) / local;
    size_t global = groups * local;
    if (err == CL_SUCCESS)
        err = clEnqueueNDRangeKernel(ctx->queue, kernel, 1, NULL, &global, &local, 0, NULL, NULL);
    if (err == CL_SUCCESS)
        err = clEnqueueReadBuffer(ctx->queue, buf[LB_RESIDUALS], CL_TRUE, 0,
                                  (size_t)count * 3 * sizeof(float), residuals, 0, NULL, NULL);
    return err;
}

rsmooth_status rs_cl_learned_run(void *context, const struct rs_learned_stage *stage,
                                 const float *descriptors, size_t count, float *residuals) {
    rsmooth_context *ctx = context;
    cl_uint4 shape[16]; /* the format's most layers a stage has (model_file.c) */
    if (!ctx->kernels[RS_KERNEL_LEARNED] || count == 0 || count > UINT32_MAX / 3 ||
        stage->layer_count < 1 || stage->layer_count > sizeof shape / sizeof *shape ||
        stage->layer[0].in != RS_LEARNED_INPUTS)
        return RSMOOTH_ERROR_INVALID_ARGUMENT;
    bool group = ctx->lanes == 1;
    size_t floats = 0;
    uint32_t width = 0;
    float *packed = pack_weights(stage, group, shape, &floats, &width);
    if (!packed)
        return RSMOOTH_ERROR_OUT_OF_MEMORY;
    size_t bytes[LB_COUNT] = {stage->layer_count * sizeof(cl_uint4), floats * sizeof(float),
                              count * RS_LEARNED_INPUTS * sizeof(float), count * 3 * sizeof(float)};
    /* the CPU variant leaves its local argument alone: a token size */
    size_t local_bytes = group ? 2 * RS_LEARNED_TILE * (size_t)width * sizeof(float) : 16;
    if (!fits(ctx, bytes, local_bytes, width)) {
        rs_free(packed);
        return RSMOOTH_ERROR_OUT_OF_MEMORY;
    }
    const void *from[LB_COUNT] = {shape, packed, descriptors, NULL};
    cl_mem buf[LB_COUNT] = {NULL};
    cl_int err = CL_SUCCESS;
    for (int b = 0; b < LB_COUNT && err == CL_SUCCESS; b++)
        buf[b] = clCreateBuffer(
            ctx->context, from[b] ? CL_MEM_READ_ONLY | rs_cl_input_flags(ctx) : CL_MEM_WRITE_ONLY,
            bytes[b], (void *)from[b], &err);
    if (err == CL_SUCCESS)
        err = launch(ctx, buf, stage->layer_count, (cl_uint)count, local_bytes, width, residuals);
    if (err != CL_SUCCESS) /* nothing left running on the arrays freed below */
        clFinish(ctx->queue);
    /* the packed weights may be the device's view of them (CL_MEM_USE_HOST_PTR): after the
     * buffers */
    for (int b = 0; b < LB_COUNT; b++)
        if (buf[b])
            clReleaseMemObject(buf[b]);
    rs_free(packed);
    return err == CL_SUCCESS ? RSMOOTH_OK : RSMOOTH_ERROR_OPENCL;
}
