/* rsmooth_smooth_points, point clouds on the OpenCL path: the passes, spacings and areas of the
 * reference path's point clouds (reference/points.c), each pass's filter one device run
 * (device_pass.c) with the points as its facets: the same grid, bilateral rounds and robust
 * kernels as a mesh's. */
#include "reference/points.h"
#include "api/path.h"
#include "reference/reference.h"

/* One pass on the device. Untiled: a point cloud's facets are not triangles, which tiles cut. */
static rsmooth_status cl_points_pass(void *context, const rs_problem *pb, double *out_next,
                                     float *out_confidence, double *out_normals,
                                     rsmooth_report *report, double t_start, rsmooth_error *error,
                                     const char *where) {
    rs_device_call call = {context, where, NULL};
    rs_result_sink sink = {RSMOOTH_FLOAT64,  out_next, NULL, out_confidence, NULL,
                           pb->vertex_count, NULL};
    return rs_device_pass(&call, pb, &sink, true, out_normals, report, t_start, error);
}

rsmooth_status rsmooth_smooth_points(rsmooth_context *ctx, rsmooth_scalar scalar,
                                     const void *positions, const void *normals, size_t point_count,
                                     const rsmooth_params *params, void *out_positions,
                                     void *out_normals, const rsmooth_outputs *outputs,
                                     rsmooth_error *error) {
    static const char where[] = "rsmooth_smooth_points";
    rs_error_clear(error);
    rsmooth_outputs o;
    rsmooth_status st = rs_read_outputs(outputs, &o, error, where);
    if (st == RSMOOTH_OK && o.weight)
        st = rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                     "outputs->weight: point clouds give no weight (set it to NULL)");
    if (st != RSMOOTH_OK)
        return st;
    if (!ctx) /* the reference path: its pass, on the host */
        return rs_smooth_points_with(rs_reference_points_pass, NULL, where, scalar, positions,
                                     normals, point_count, params, out_positions, out_normals,
                                     o.confidence, o.report, error);
    size_t saved = 0;
    st = rs_device_enter(ctx, where, &saved, error);
    if (st != RSMOOTH_OK)
        return st;
    st = rs_smooth_points_with(cl_points_pass, ctx, where, scalar, positions, normals, point_count,
                               params, out_positions, out_normals, o.confidence, o.report, error);
    rs_device_leave(ctx, saved);
    return st;
}
