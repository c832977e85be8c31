/* What a path is, as the api layer runs it. A call enters its context (one call at a time, the
 * context's host threads), prepares a problem from the caller's arrays, runs passes of one path's
 * filter (passes/passes.h: a pass function and a stage runner) and reports. The device path's
 * pieces are here, once: the call record handed to every pass, and the one-pass sequence that a
 * mesh's pass, a point cloud's pass and a streamed piece all run. Internal, not installed. */
#ifndef RSMOOTH_API_PATH_H
#define RSMOOTH_API_PATH_H

#include "opencl/cl_internal.h"
#include "passes/passes.h"

/* One call on the device path, passed down to each of its passes (in place of state set aside in
 * the context while the call runs). */
typedef struct rs_device_call {
    rsmooth_context *ctx;
    const char *where;           /* the public function, for errors */
    rs_device_sink *device_sink; /* rsmooth_smooth_cl's buffers: where one whole run may leave
                                  * the result on the device; NULL: the host's arrays */
} rs_device_call;

/* Takes ctx for a call (rs_context_enter) and sets the calling thread's host threads to the
 * context's; *saved gets the setting to give back to rs_device_leave. */
rsmooth_status rs_device_enter(rsmooth_context *ctx, const char *where, size_t *saved,
                               rsmooth_error *error);
void rs_device_leave(rsmooth_context *ctx, size_t saved);

/* One run of the filter on the device over a prepared problem: its results into `sink` (every
 * vertex unmoved where there is no facet), the report filled. A point cloud's run (`points`) is
 * untiled, and gives the predictors' normals to out_normals (optional). t_start: when the call
 * began. */
rsmooth_status rs_device_pass(const rs_device_call *call, const rs_problem *pb,
                              const rs_result_sink *sink, bool points, double *out_normals,
                              rsmooth_report *report, double t_start, rsmooth_error *error);

/* A path, as a mesh call runs it: one pass of its filter (rs_filter_passes repeats it, part by
 * part), the runner of the normal-update stage's cycles and that of the learned normals'
 * networks (NULL: the host's), all given `context`. The reference path is {rs_reference_pass,
 * NULL, NULL, NULL} (reference/); the device's is rs_device_path's. */
typedef struct rs_path {
    rs_filter_fn pass;
    rs_stage_runner stage;
    rs_network_runner network;
    void *context;
} rs_path;

/* The device path of a call entered on its context: its pass (smooth.c's), the stage on the
 * device where RSMOOTH_STAGE or the device's type puts it there, the networks on the device. */
rs_path rs_device_path(const rs_device_call *call);

/* A mesh call's whole work on `path` (the arrays checked once at its start, rs_filter_passes);
 * errors name `where`. */
rsmooth_status rs_path_smooth(const rs_path *path, rsmooth_scalar scalar, const void *positions,
                              size_t vertex_count, const uint32_t *indices, size_t triangle_count,
                              const rsmooth_params *params, void *out_positions, float *out_weight,
                              float *out_confidence, rsmooth_report *report, rsmooth_error *error,
                              const char *where);

#endif /* RSMOOTH_API_PATH_H */
