/* rsmooth_smooth_points, point clouds on the OpenCL path: the passes, spacings and areas of the
 * reference path's point clouds (reference/points.c), each pass's filter one device run
 * (opencl/cl_smooth.c) with the points as its facets: the same grid, bilateral rounds and
 * robust kernels as a mesh's. */
#include "reference/points.h"
#include "opencl/cl_internal.h"

#include <string.h>

/* One pass on the device. Untiled: a point cloud's facets are not triangles, which tiles cut. */
static rsmooth_status cl_points_pass(void *context, const rs_problem *pb, double *out_next,
                                     float *out_confidence, double *out_normals,
                                     rsmooth_report *report, double t_start, rsmooth_error *error,
                                     const char *where) {
    rsmooth_context *ctx = context;
    double t_facets = rs_now_ms();
    rs_run_stats stats;
    memset(&stats, 0, sizeof stats);
    rsmooth_status st = RSMOOTH_OK;
    if (pb->facet_count == 0) { /* nothing carries weight: every point stays */
        rs_store_unmoved(pb, RSMOOTH_FLOAT64, out_next, NULL, out_confidence);
    } else {
        rs_result_sink sink = {RSMOOTH_FLOAT64,  out_next, NULL, out_confidence, NULL,
                               pb->vertex_count, NULL};
        uint64_t needed = 0;
        st = rs_cl_run_normals(ctx, pb, &sink, out_normals, &stats, &needed, error);
        if (st == RSMOOTH_ERROR_OUT_OF_MEMORY && needed > 0)
            return rs_fail(error, st, where,
                           "%zu points need %llu bytes on %s, beyond its usable memory or "
                           "the memory budget (point clouds are not cut into tiles; "
                           "rsmooth_smooth_points_reference takes them)",
                           pb->vertex_count, (unsigned long long)needed, ctx->device_name);
    }
    if (st == RSMOOTH_OK && report)
        rs_cl_report(report, pb, &stats, ctx->device_name, t_start, t_facets);
    return st;
}

rsmooth_status rsmooth_smooth_points(rsmooth_context *ctx, rsmooth_scalar scalar,
                                     const void *positions, const void *normals, size_t point_count,
                                     const rsmooth_params *params, void *out_positions,
                                     void *out_normals, float *out_confidence,
                                     rsmooth_report *report, rsmooth_error *error) {
    static const char where[] = "rsmooth_smooth_points";
    rs_error_clear(error);
    if (!ctx)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "ctx is NULL");
    /* the kernels' arguments and the queue are the context's: one call at a time */
    rsmooth_status entered = rs_context_enter(ctx, where, error);
    if (entered != RSMOOTH_OK)
        return entered;
    size_t threads_before = rs_set_call_threads(ctx->host_threads);
    rsmooth_status st =
        rs_smooth_points_with(cl_points_pass, ctx, where, scalar, positions, normals, point_count,
                              params, out_positions, out_normals, out_confidence, report, error);
    rs_set_call_threads(threads_before);
    rs_context_unlock(ctx);
    return st;
}
