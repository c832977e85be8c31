/* rsmooth_smooth, the public entry point of the OpenCL path: one call on a context at a time,
 * the caller's host threads, and the passes (passes/passes.c) each run as one device pass
 * (device_pass.c): facet data, then the tiles (opencl/tiles.c) that each run the kernels
 * (opencl/cl_smooth.c). With ctx NULL, the reference path (reference/reference.c). */
#include "api/path.h"
#include "passes/passes.h"
#include "reference/reference.h"

#include <stdlib.h>
#include <string.h>

/* One pass of the filter on the device (rs_filter_passes repeats it); `context` is the call's
 * rs_device_call. */
static rsmooth_status cl_pass(void *context, rsmooth_scalar scalar, const void *positions,
                              size_t vertex_count, const uint32_t *indices, size_t triangle_count,
                              const rsmooth_params *params, void *out_positions, float *out_weight,
                              float *out_confidence, rsmooth_report *report, rsmooth_error *error) {
    const rs_device_call *call = context;
    double t_start = rs_now_ms();
    rs_error_clear(error);
    rs_problem pb;
    rsmooth_status st = rs_problem_prepare(&pb, scalar, positions, vertex_count, indices,
                                           triangle_count, params, false, error, call->where);
    if (st != RSMOOTH_OK)
        return st;
    rs_result_sink sink = {scalar, out_positions, out_weight,       out_confidence,
                           NULL,   vertex_count,  call->device_sink};
    st = rs_device_pass(call, &pb, &sink, false, NULL, report, t_start, error);
    if (st == RSMOOTH_OK)
        rs_progress(&pb, 1.0);
    rs_problem_free(&pb);
    rs_release_free_memory();
    return st;
}

/* The stage's cycles on the call's device: an rs_stage_runner over the call record. */
static rsmooth_status cl_stage(void *context, const rs_stage_plan *plan, double *xyz,
                               rs_cycle_fn cycle_done, void *user, rs_stage_stats *stats,
                               rsmooth_error *error) {
    const rs_device_call *call = context;
    return rs_cl_stage_run(call->ctx, plan, xyz, cycle_done, user, stats, error);
}

/* A learned stage's network on the call's device: an rs_network_runner over the call record. */
static rsmooth_status cl_network(void *context, const rs_learned_stage *stage,
                                 const float *descriptors, size_t count, float *residuals) {
    const rs_device_call *call = context;
    return rs_cl_learned_run(call->ctx, stage, descriptors, count, residuals);
}

/* Where the normal-update stage's cycles run: on a GPU or other accelerator, the device; on a CPU
 * device, the host's cores (the same cores, in double, and measured faster there: the kernels'
 * gathers do not vectorize, docs/best-mode.md). RSMOOTH_STAGE=device or host chooses. */
static bool stage_on_device(const rsmooth_context *ctx) {
    const char *asked = ctx->env.value[RS_ENV_STAGE];
    if (asked && *asked)
        return strcmp(asked, "device") == 0;
    cl_device_type type = CL_DEVICE_TYPE_CPU;
    if (clGetDeviceInfo(ctx->device, CL_DEVICE_TYPE, sizeof type, &type, NULL) != CL_SUCCESS)
        return false;
    return (type & CL_DEVICE_TYPE_CPU) == 0;
}

rs_path rs_device_path(const rs_device_call *call) {
    rs_path path = {cl_pass, stage_on_device(call->ctx) ? cl_stage : NULL, cl_network,
                    (void *)call};
    return path;
}

rsmooth_status rs_path_smooth(const rs_path *path, rsmooth_scalar scalar, const void *positions,
                              size_t vertex_count, const uint32_t *indices, size_t triangle_count,
                              const rsmooth_params *params, void *out_positions, float *out_weight,
                              float *out_confidence, rsmooth_report *report, rsmooth_error *error,
                              const char *where) {
    return rs_filter_passes(path->pass, path->stage, path->network, path->context, scalar,
                            positions, vertex_count, indices, triangle_count, params, out_positions,
                            out_weight, out_confidence, report, error, where);
}

rsmooth_status rsmooth_smooth(rsmooth_context *ctx, rsmooth_scalar scalar, const void *positions,
                              size_t vertex_count, const uint32_t *indices, size_t triangle_count,
                              const rsmooth_params *params, void *out_positions,
                              const rsmooth_outputs *outputs, rsmooth_error *error) {
    static const char where[] = "rsmooth_smooth";
    rs_error_clear(error);
    rsmooth_outputs o;
    rsmooth_status st = rs_read_outputs(outputs, &o, error, where);
    if (st != RSMOOTH_OK)
        return st;
    if (!ctx) { /* the reference path */
        rs_path reference = {rs_reference_pass, NULL, NULL, NULL};
        return rs_path_smooth(&reference, scalar, positions, vertex_count, indices, triangle_count,
                              params, out_positions, o.weight, o.confidence, o.report, error,
                              where);
    }
    size_t saved = 0;
    st = rs_device_enter(ctx, where, &saved, error);
    if (st != RSMOOTH_OK)
        return st;
    rs_device_call call = {ctx, where, NULL};
    rs_path device = rs_device_path(&call);
    st = rs_path_smooth(&device, scalar, positions, vertex_count, indices, triangle_count, params,
                        out_positions, o.weight, o.confidence, o.report, error, where);
    rs_device_leave(ctx, saved);
    return st;
}
