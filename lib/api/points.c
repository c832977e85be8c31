/* rsmooth_smooth_points, point clouds on the OpenCL path: the passes, spacings and areas of the
 * reference path's point clouds (reference/points.c), each pass's filter one device run
 * (device_pass.c) with the points as its facets: the same grid, bilateral rounds and robust
 * kernels as a mesh's. */
#include "reference/points.h"
#include "api/path.h"

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
                                     void *out_normals, float *out_confidence,
                                     rsmooth_report *report, rsmooth_error *error) {
    static const char where[] = "rsmooth_smooth_points";
    rs_error_clear(error);
    size_t saved = 0;
    rsmooth_status st = rs_device_enter(ctx, where, &saved, error);
    if (st != RSMOOTH_OK)
        return st;
    st = rs_smooth_points_with(cl_points_pass, ctx, where, scalar, positions, normals, point_count,
                               params, out_positions, out_normals, out_confidence, report, error);
    rs_device_leave(ctx, saved);
    return st;
}
