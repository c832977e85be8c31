/* rsmooth_smooth_cl: the filter on positions held in the caller's OpenCL buffers. The input is
 * read to the host once (the grid and the facet data are built there by design); the result of a
 * run that solves the whole mesh at once is written into the caller's output buffer by a small
 * kernel on the device, from the robust pass's displacements that are already there, in the same
 * double arithmetic the host's store_results (cl_smooth.c) uses, so the bits are those
 * rsmooth_smooth would return. Where the result exists only on the host (tiles, passes, the
 * normal update stage, the choice per region, a move mask, a device without fp64), it is
 * uploaded into the output buffer instead. */
#include "core/parts.h"
#include "opencl/cl_internal.h"
#include "rsmooth_cl.h"

#include <string.h>

/* The store kernels: vertex v's coordinates are its input's, scaled as rs_problem_prepare scales
 * them (a power of two: exact), plus its displacement times the cell size, scaled back, in the
 * output's type; any that is not finite there sets *bad. No contraction into fma: the host's
 * (x86-64's default code) rounds the product and the sum apart. */
static const char store_source[] =
    "#pragma OPENCL EXTENSION cl_khr_fp64 : enable\n"
    "#pragma OPENCL FP_CONTRACT OFF\n"
    "#define STORE(NAME, T)                                                                   \\\n"
    "__kernel void NAME(uint n, uint lanes, double scale, double h, double unscale,           \\\n"
    "                   __global const T *in, __global const float *result,                   \\\n"
    "                   __global const uint *slot, __global T *out, __global int *bad) {      \\\n"
    "    size_t v = get_global_id(0);                                                         \\\n"
    "    if (v >= n)                                                                          \\\n"
    "        return;                                                                          \\\n"
    "    uint s = slot[v];                                                                    \\\n"
    "    __global const float *res = result + 4 * (size_t)lanes * (s / lanes) + s % lanes;    \\\n"
    "    T y[3];                                                                              \\\n"
    "    int finite = 1;                                                                      \\\n"
    "    for (int k = 0; k < 3; k++) {                                                        \\\n"
    "        double p = (double)in[3 * v + k] * scale;                                        \\\n"
    "        double d = (double)res[k * lanes] * h;                                           \\\n"
    "        double x = (p + d) * unscale;                                                    \\\n"
    "        y[k] = (T)x;                                                                     \\\n"
    "        finite &= isfinite(y[k]) ? 1 : 0;                                                \\\n"
    "    }                                                                                    \\\n"
    "    for (int k = 0; k < 3; k++)                                                          \\\n"
    "        out[3 * v + k] = y[k];                                                           \\\n"
    "    if (!finite)                                                                         \\\n"
    "        bad[0] = 1;                                                                      \\\n"
    "}\n"
    "STORE(rs_store_float, float)\n"
    "STORE(rs_store_double, double)\n";

static bool device_has_fp64(const rsmooth_context *ctx) {
    cl_device_fp_config config = 0;
    return clGetDeviceInfo(ctx->device, CL_DEVICE_DOUBLE_FP_CONFIG, sizeof config, &config, NULL) ==
               CL_SUCCESS &&
           config != 0;
}

bool rs_cl_store_ready(rsmooth_context *ctx) {
    if (ctx->store_tried)
        return ctx->store_program != NULL;
    ctx->store_tried = true;
    if (!device_has_fp64(ctx))
        return false;
    const char *source = store_source;
    size_t size = sizeof store_source - 1;
    cl_int err = CL_SUCCESS;
    cl_program program = clCreateProgramWithSource(ctx->context, 1, &source, &size, &err);
    if (err != CL_SUCCESS)
        return false;
    /* no RSMOOTH_BUILD_OPTIONS here: this must stay exact whatever the filter's kernels take */
    err = clBuildProgram(program, 1, &ctx->device, "", NULL, NULL);
    cl_kernel kernels[2] = {NULL, NULL};
    if (err == CL_SUCCESS)
        kernels[RSMOOTH_FLOAT32] = clCreateKernel(program, "rs_store_float", &err);
    if (err == CL_SUCCESS)
        kernels[RSMOOTH_FLOAT64] = clCreateKernel(program, "rs_store_double", &err);
    if (err != CL_SUCCESS) {
        for (int k = 0; k < 2; k++)
            if (kernels[k])
                clReleaseKernel(kernels[k]);
        clReleaseProgram(program);
        return false;
    }
    ctx->store_program = program;
    memcpy(ctx->store_kernels, kernels, sizeof kernels);
    return true;
}

rsmooth_status rs_cl_store_device(rsmooth_context *ctx, rs_device_sink *sink, cl_mem result,
                                  const uint32_t *slot, size_t vertex_count, size_t lanes,
                                  double scale, double h, rsmooth_error *error) {
    if (vertex_count == 0) {
        sink->written = true;
        return RSMOOTH_OK;
    }
    cl_int err = CL_SUCCESS;
    cl_int bad = 0;
    cl_mem slots = clCreateBuffer(ctx->context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                                  vertex_count * sizeof(cl_uint), (void *)slot, &err);
    cl_mem flag = NULL;
    if (err == CL_SUCCESS)
        flag = clCreateBuffer(ctx->context, CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, sizeof bad,
                              &bad, &err);
    if (err != CL_SUCCESS) {
        if (slots)
            clReleaseMemObject(slots);
        return rs_cl_fail(error, err, "clCreateBuffer (store)", ctx->device_name);
    }
    cl_uint n = (cl_uint)vertex_count, width = (cl_uint)lanes;
    double unscale = 1 / scale;
    cl_kernel k = sink->kernel;
    cl_uint a = 0;
    if (err == CL_SUCCESS)
        err = clSetKernelArg(k, a++, sizeof n, &n);
    if (err == CL_SUCCESS)
        err = clSetKernelArg(k, a++, sizeof width, &width);
    if (err == CL_SUCCESS)
        err = clSetKernelArg(k, a++, sizeof scale, &scale);
    if (err == CL_SUCCESS)
        err = clSetKernelArg(k, a++, sizeof h, &h);
    if (err == CL_SUCCESS)
        err = clSetKernelArg(k, a++, sizeof unscale, &unscale);
    const cl_mem mems[5] = {sink->input, result, slots, sink->output, flag};
    for (int m = 0; m < 5 && err == CL_SUCCESS; m++)
        err = clSetKernelArg(k, a++, sizeof(cl_mem), &mems[m]);
    size_t global = vertex_count;
    if (err == CL_SUCCESS)
        err = clEnqueueNDRangeKernel(ctx->queue, k, 1, NULL, &global, NULL, 0, NULL, NULL);
    if (err == CL_SUCCESS)
        err = clEnqueueReadBuffer(ctx->queue, flag, CL_TRUE, 0, sizeof bad, &bad, 0, NULL, NULL);
    clReleaseMemObject(slots);
    clReleaseMemObject(flag);
    if (err != CL_SUCCESS)
        return rs_cl_fail(error, err, "rs_store (the result into the caller's buffer)",
                          ctx->device_name);
    sink->written = true;
    sink->bad = bad != 0;
    return RSMOOTH_OK;
}

/* The caller's buffer `mem`: on ctx's OpenCL context and at least `bytes` long. */
static rsmooth_status check_buffer(const rsmooth_context *ctx, cl_mem mem, const char *name,
                                   size_t bytes, size_t vertex_count, rsmooth_error *error) {
    static const char where[] = "rsmooth_smooth_cl";
    if (!mem)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "%s is NULL", name);
    cl_context context = NULL;
    size_t size = 0;
    cl_int err = clGetMemObjectInfo(mem, CL_MEM_CONTEXT, sizeof context, &context, NULL);
    if (err == CL_SUCCESS)
        err = clGetMemObjectInfo(mem, CL_MEM_SIZE, sizeof size, &size, NULL);
    if (err != CL_SUCCESS) {
        rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                "%s is not a valid OpenCL buffer (%s)", name, rs_cl_error_name(err));
        if (error)
            error->cl_error = err;
        return RSMOOTH_ERROR_INVALID_ARGUMENT;
    }
    if (context != ctx->context)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "%s belongs to another OpenCL context than the rsmooth context's queue",
                       name);
    if (size < bytes)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "%s holds %zu bytes; %zu vertices need %zu", name, size, vertex_count,
                       bytes);
    return RSMOOTH_OK;
}

/* Whether the call's result can be written on the device: one pass of the filter over the whole
 * mesh (one part, core/parts.h) and nothing after it on the host (see the top; the fold guard
 * reads the result on the host). */
static bool device_result_possible(const rsmooth_params *params, rsmooth_scalar scalar,
                                   const void *positions, size_t vertex_count,
                                   const uint32_t *indices, size_t triangle_count) {
    rsmooth_params p;
    if (rs_params_resolve(params, &p, NULL, "rsmooth_smooth_cl") != RSMOOTH_OK)
        return false; /* the call fails on them, as rsmooth_smooth would */
    if (p.passes != 1 || p.vertex_updates != 0 || p.discrepancy_level != 0 || p.move_mask ||
        p.guard)
        return false;
    if (rs_check_mesh_arrays(scalar, positions, vertex_count, indices, triangle_count, NULL, NULL,
                             "rsmooth_smooth_cl") != RSMOOTH_OK)
        return false; /* refused by the call itself */
    rs_parts parts;
    bool whole = rs_parts_find(&parts, scalar, positions, vertex_count, indices, triangle_count,
                               NULL, "rsmooth_smooth_cl") == RSMOOTH_OK &&
                 parts.whole;
    rs_parts_free(&parts);
    return whole;
}

rsmooth_status rsmooth_smooth_cl(rsmooth_context *ctx, rsmooth_scalar scalar, cl_mem positions,
                                 size_t vertex_count, const uint32_t *indices,
                                 size_t triangle_count, const rsmooth_params *params,
                                 cl_mem out_positions, rsmooth_report *report,
                                 rsmooth_error *error) {
    static const char where[] = "rsmooth_smooth_cl";
    rs_error_clear(error);
    if (!ctx)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "ctx is NULL");
    if (scalar != RSMOOTH_FLOAT32 && scalar != RSMOOTH_FLOAT64)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "scalar %d is no rsmooth_scalar", (int)scalar);
    size_t record = rs_vertex_bytes(scalar);
    if (vertex_count > SIZE_MAX / record)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "%zu vertices overflow size_t",
                       vertex_count);
    size_t bytes = vertex_count * record;
    rsmooth_status st = rs_context_enter(ctx, where, error);
    if (st != RSMOOTH_OK)
        return st;
    st = check_buffer(ctx, positions, "positions", bytes, vertex_count, error);
    if (st == RSMOOTH_OK)
        st = check_buffer(ctx, out_positions, "out_positions", bytes, vertex_count, error);
    if (st == RSMOOTH_OK) /* buffers, readable, writable, the same or apart */
        st = rs_cl_check_buffer_pair(positions, out_positions, bytes, error);
    void *host_in = NULL, *host_out = NULL;
    if (st == RSMOOTH_OK) {
        /* the host's output stays zero where the device takes the result: the final check of
         * finite outputs then reads zeros, and the store kernel's flag speaks for the device */
        host_in = rs_alloc_array(vertex_count ? vertex_count : 1, record);
        host_out = rs_calloc_array(vertex_count ? vertex_count : 1, record);
        if (!host_in || !host_out)
            st = rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where,
                         "no memory for %zu vertices on the host", vertex_count);
    }
    cl_int err = CL_SUCCESS;
    if (st == RSMOOTH_OK && bytes > 0) {
        /* in order after what the caller enqueued on the queue before this call */
        err = clEnqueueReadBuffer(ctx->queue, positions, CL_TRUE, 0, bytes, host_in, 0, NULL, NULL);
        if (err != CL_SUCCESS)
            st = rs_cl_fail(error, err, "clEnqueueReadBuffer (positions)", ctx->device_name);
    }
    rs_device_sink sink = {positions, out_positions, NULL, false, false};
    if (st == RSMOOTH_OK) {
        if (device_result_possible(params, scalar, host_in, vertex_count, indices,
                                   triangle_count) &&
            rs_cl_store_ready(ctx)) {
            sink.kernel = ctx->store_kernels[scalar];
            ctx->device_sink = &sink;
        }
        st = rs_smooth_entered(ctx, scalar, host_in, vertex_count, indices, triangle_count, params,
                               host_out, NULL, NULL, report, error);
        ctx->device_sink = NULL;
    }
    if (st == RSMOOTH_OK && sink.written && sink.bad)
        st = rs_fail(error, RSMOOTH_ERROR_NUMERICAL, where,
                     "a smoothed position is not finite in the output's type");
    if (st == RSMOOTH_OK && !sink.written && bytes > 0) {
        /* tiles, passes, the stage, a move mask or the choice per region: the host has it */
        err = clEnqueueWriteBuffer(ctx->queue, out_positions, CL_TRUE, 0, bytes, host_out, 0, NULL,
                                   NULL);
        if (err != CL_SUCCESS)
            st = rs_cl_fail(error, err, "clEnqueueWriteBuffer (out_positions)", ctx->device_name);
    }
    if (st == RSMOOTH_OK) {
        err = clFinish(ctx->queue);
        if (err != CL_SUCCESS)
            st = rs_cl_fail(error, err, "clFinish", ctx->device_name);
    }
    rs_context_unlock(ctx);
    rs_free(host_in);
    rs_free(host_out);
    return st;
}
