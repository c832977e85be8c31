/* rsmooth_smooth, the public entry point of the OpenCL path: one call on a context at a time,
 * the caller's host threads, and the passes (passes/passes.c) each run as one device pass:
 * facet data, then the tiles (opencl/tiles.c) that each run the kernels (opencl/cl_smooth.c).
 * The reference path's entry point is rsmooth_smooth_reference (reference/reference.c). */
#include "opencl/cl_run.h"
#include "passes/passes.h"

#include <stdlib.h>
#include <string.h>

/* One pass of the filter on the device (rs_filter_passes repeats it). */
static rsmooth_status cl_pass(void *context, rsmooth_scalar scalar, const void *positions,
                              size_t vertex_count, const uint32_t *indices, size_t triangle_count,
                              const rsmooth_params *params, void *out_positions, float *out_weight,
                              float *out_confidence, rsmooth_report *report, rsmooth_error *error) {
    static const char where[] = "rsmooth_smooth";
    rsmooth_context *ctx = context;
    double t_start = rs_now_ms();
    rs_error_clear(error);
    rs_problem pb;
    rsmooth_status st =
        rs_problem_prepare(&pb, scalar, positions, vertex_count, indices, triangle_count, params,
                           out_positions, false, error, where);
    if (st != RSMOOTH_OK)
        return st;
    double t_facets = rs_now_ms();
    rs_run_stats stats;
    memset(&stats, 0, sizeof stats);
    if (pb.facet_count == 0) {
        rs_store_unmoved(&pb, scalar, out_positions, out_weight, out_confidence);
    } else {
        rs_result_sink sink = {scalar, out_positions, out_weight,      out_confidence,
                               NULL,   vertex_count,  ctx->device_sink};
        st = rs_cl_filter(ctx, &pb, &sink, &stats, error);
    }
    if (st == RSMOOTH_OK) {
        rs_progress(&pb, 1.0);
        if (report)
            rs_cl_report(report, &pb, &stats, ctx->device_name, t_start, t_facets);
    }
    rs_problem_free(&pb);
    rs_release_free_memory();
    return st;
}

/* Where the normal-update stage's cycles run: on a GPU or other accelerator, the device; on a CPU
 * device, the host's cores (the same cores, in double, and measured faster there: the kernels'
 * gathers do not vectorize, docs/best-mode.md). RSMOOTH_STAGE=device or host chooses. */
static bool stage_on_device(const rsmooth_context *ctx, const char *asked) {
    if (asked && *asked)
        return strcmp(asked, "device") == 0;
    cl_device_type type = CL_DEVICE_TYPE_CPU;
    if (clGetDeviceInfo(ctx->device, CL_DEVICE_TYPE, sizeof type, &type, NULL) != CL_SUCCESS)
        return false;
    return (type & CL_DEVICE_TYPE_CPU) == 0;
}

rsmooth_status rsmooth_smooth(rsmooth_context *ctx, rsmooth_scalar scalar, const void *positions,
                              size_t vertex_count, const uint32_t *indices, size_t triangle_count,
                              const rsmooth_params *params, void *out_positions, float *out_weight,
                              float *out_confidence, rsmooth_report *report, rsmooth_error *error) {
    rs_error_clear(error);
    if (!ctx)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, "rsmooth_smooth", "ctx is NULL");
    /* the kernels' arguments and the queue are the context's: one call at a time */
    rsmooth_status entered = rs_context_enter(ctx, "rsmooth_smooth", error);
    if (entered != RSMOOTH_OK)
        return entered;
    rsmooth_status st =
        rs_smooth_entered(ctx, scalar, positions, vertex_count, indices, triangle_count, params,
                          out_positions, out_weight, out_confidence, report, error);
    rs_context_unlock(ctx);
    return st;
}

rsmooth_status rs_smooth_entered(rsmooth_context *ctx, rsmooth_scalar scalar, const void *positions,
                                 size_t vertex_count, const uint32_t *indices,
                                 size_t triangle_count, const rsmooth_params *params,
                                 void *out_positions, float *out_weight, float *out_confidence,
                                 rsmooth_report *report, rsmooth_error *error) {
    const char *stage_env = getenv("RSMOOTH_STAGE");
    if (stage_env && *stage_env && strcmp(stage_env, "host") != 0 &&
        strcmp(stage_env, "device") != 0) {
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, "rsmooth_smooth",
                       "RSMOOTH_STAGE is \"%s\": use device (the normal-update stage on the "
                       "OpenCL device: the default on GPUs) or host (on the host's cores, in "
                       "double: the default on CPU devices)",
                       stage_env);
    }
    rs_stage_runner stage = stage_on_device(ctx, stage_env) ? rs_cl_stage_run : NULL;
    size_t threads_before = rs_set_call_threads(ctx->host_threads);
    rsmooth_status st = rs_filter_passes(cl_pass, stage, ctx, scalar, positions, vertex_count,
                                         indices, triangle_count, params, out_positions, out_weight,
                                         out_confidence, report, error, "rsmooth_smooth");
    rs_set_call_threads(threads_before);
    return st;
}
