/* rsmooth_smooth_cl: the filter on positions held in the caller's OpenCL buffers. The input is
 * read to the host once (the grid and the facet data are built there by design); the result of a
 * run that solves the whole mesh at once is written into the caller's output buffer on the device
 * (opencl/cl_store.c), so the bits are those rsmooth_smooth would return. Where the result exists
 * only on the host (tiles, passes, the normal update stage, the choice per region, a move mask, a
 * device without fp64), it is uploaded into the output buffer instead. */
#include "api/path.h"
#include "core/parts.h"
#include "rsmooth_cl.h"

#include <string.h>

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
    size_t saved = 0;
    rsmooth_status st = rs_device_enter(ctx, where, &saved, error);
    if (st != RSMOOTH_OK)
        return st;
    st = rs_cl_check_buffer(ctx, positions, "positions", bytes, vertex_count, error);
    if (st == RSMOOTH_OK)
        st = rs_cl_check_buffer(ctx, out_positions, "out_positions", bytes, vertex_count, error);
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
    rs_device_call call = {ctx, where, NULL};
    if (st == RSMOOTH_OK) {
        if (device_result_possible(params, scalar, host_in, vertex_count, indices,
                                   triangle_count) &&
            rs_cl_store_ready(ctx)) {
            sink.kernel = ctx->store_kernels[scalar];
            call.device_sink = &sink;
        }
        rs_path device = rs_device_path(&call);
        st = rs_path_smooth(&device, scalar, host_in, vertex_count, indices, triangle_count, params,
                            host_out, NULL, NULL, report, error, where);
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
    rs_device_leave(ctx, saved);
    rs_free(host_in);
    rs_free(host_out);
    return st;
}
