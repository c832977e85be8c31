/* Point clouds' passes (points.c) with each pass's filter given: the reference path's, or the
 * device's (api/points.c). Internal, not installed. */
#ifndef RSMOOTH_POINTS_H
#define RSMOOTH_POINTS_H

#include "core/rsmooth_internal.h"

/* One pass's filter on a point cloud's problem (no indices: facet q is point q, its centroid,
 * normal and area kept): the next positions (3 doubles per point, internal units), confidence
 * and, when the pass filters normals, the predictors' unit normals (3 per facet; untouched
 * otherwise), with rs_reference_solve's report, t_start, errors and `where`. */
typedef rsmooth_status (*rs_points_solve_fn)(void *ctx, const rs_problem *pb, double *out_next,
                                             float *out_confidence, double *out_normals,
                                             rsmooth_report *report, double t_start,
                                             rsmooth_error *error, const char *where);

/* rsmooth_smooth_points_reference's whole call (checks, spacings, passes, outputs) with `solve`
 * (given `solve_ctx`) filtering each pass; errors name `where`. */
rsmooth_status rs_smooth_points_with(rs_points_solve_fn solve, void *solve_ctx, const char *where,
                                     rsmooth_scalar scalar, const void *positions,
                                     const void *normals, size_t point_count,
                                     const rsmooth_params *params, void *out_positions,
                                     void *out_normals, float *out_confidence,
                                     rsmooth_report *report, rsmooth_error *error);

#endif /* RSMOOTH_POINTS_H */
