/* The device path's one run over a prepared problem: the sequence a mesh's pass (smooth.c), a
 * point cloud's pass (points.c) and a piece of a larger mesh (piece.c) share, and the entry and
 * exit of every call on a context. */
#include "api/path.h"

#include <string.h>

rsmooth_status rs_device_enter(rsmooth_context *ctx, const char *where, size_t *saved,
                               rsmooth_error *error) {
    if (!ctx)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "ctx is NULL");
    /* the kernels' arguments and the queue are the context's: one call at a time */
    rsmooth_status st = rs_context_enter(ctx, where, error);
    if (st == RSMOOTH_OK)
        *saved = rs_set_call_threads(ctx->host_threads);
    return st;
}

void rs_device_leave(rsmooth_context *ctx, size_t saved) {
    rs_set_call_threads(saved);
    rs_context_unlock(ctx);
}

rsmooth_status rs_device_pass(const rs_device_call *call, const rs_problem *pb,
                              const rs_result_sink *sink, bool points, double *out_normals,
                              rsmooth_report *report, double t_start, rsmooth_error *error) {
    rsmooth_context *ctx = call->ctx;
    double t_facets = rs_now_ms();
    rs_run_stats stats;
    memset(&stats, 0, sizeof stats);
    rsmooth_status st = RSMOOTH_OK;
    if (pb->facet_count == 0) { /* nothing carries weight: every vertex stays */
        rs_store_unmoved(pb, sink->core_count, sink->scalar, sink->positions, sink->weight,
                         sink->confidence);
    } else if (points) { /* untiled: a point cloud's facets are not triangles, which tiles cut */
        uint64_t needed = 0;
        st = rs_cl_run_normals(ctx, pb, sink, out_normals, &stats, &needed, error);
        if (st == RSMOOTH_ERROR_OUT_OF_MEMORY && needed > 0)
            return rs_fail(error, st, call->where,
                           "%zu points need %llu bytes on %s, beyond its usable memory or "
                           "the memory budget (point clouds are not cut into tiles; "
                           "the reference path, ctx NULL, takes them)",
                           pb->vertex_count, (unsigned long long)needed, ctx->device_name);
    } else {
        st = rs_cl_filter(ctx, pb, sink, &stats, error);
    }
    if (st == RSMOOTH_OK && report)
        rs_cl_report(report, pb, &stats, ctx->device_name, t_start, t_facets);
    return st;
}
