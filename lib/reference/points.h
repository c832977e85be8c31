/* Point clouds' passes (points.c) with each pass's filter given: the reference path's, or the
 * device's (api/points.c). Internal, not installed. */
#ifndef RSMOOTH_POINTS_H
#define RSMOOTH_POINTS_H

#include "passes/passes.h"
#include "reference/reference.h"

/* One pass's filter on a point cloud's problem (no indices: facet q is point q, its centroid,
 * normal and area kept): the next positions (3 doubles per point, internal units), confidence
 * and, when the pass filters normals, the predictors' unit normals (3 per facet; untouched
 * otherwise), with rs_reference_solve's report, t_start, errors and `where`. */
typedef rsmooth_status (*rs_points_solve_fn)(void *ctx, const rs_problem *pb, double *out_next,
                                             float *out_confidence, double *out_normals,
                                             rsmooth_report *report, double t_start,
                                             rsmooth_error *error, const char *where);

/* The reference path's pass on a point cloud (an rs_points_solve_fn): rs_reference_solve in
 * double on the host (point_parts.c). */
rsmooth_status rs_reference_points_pass(void *ctx, const rs_problem *pb, double *out_next,
                                        float *out_confidence, double *out_normals,
                                        rsmooth_report *report, double t_start,
                                        rsmooth_error *error, const char *where);

/* rsmooth_smooth_points's whole call (checks, spacings, passes, outputs) with `solve`
 * (given `solve_ctx`) filtering each pass; errors name `where`. Part by part (point_parts.c):
 * points whose spacings differ by more than about 8 times, with none between, are filtered apart,
 * and parts of fewer than RS_MIN_PART_POINTS points are held as outliers. */
rsmooth_status rs_smooth_points_with(rs_points_solve_fn solve, void *solve_ctx, const char *where,
                                     rsmooth_scalar scalar, const void *positions,
                                     const void *normals, size_t point_count,
                                     const rsmooth_params *params, void *out_positions,
                                     void *out_normals, float *out_confidence,
                                     rsmooth_report *report, rsmooth_error *error);

/* The call on a cloud of one part (points.c). given_spacing: the input's spacings in internal
 * units (rs_point_spacings over its positions scaled as rs_check_point_positions says), which the
 * first pass then does not measure again; NULL: it measures them. */
rsmooth_status rs_smooth_points_one_part(rs_points_solve_fn solve, void *solve_ctx,
                                         const char *where, rsmooth_scalar scalar,
                                         const void *positions, const void *normals,
                                         size_t point_count, const double *given_spacing,
                                         const rsmooth_params *params, void *out_positions,
                                         void *out_normals, float *out_confidence,
                                         rsmooth_report *report, rsmooth_error *error);

/* Fewer points than this are no surface: a part that small is held (a point's spacing is its mean
 * distance to its 6 nearest others). */
#define RS_MIN_PART_POINTS 7

/* Shared with point_parts.c: the positions' checks and internal scale, a normal made unit (NULL,
 * or what is wrong with it), and each point's spacing over a k-d tree of the positions (their
 * mean returned). */
typedef struct rs_kdtree rs_kdtree;
rsmooth_status rs_check_point_positions(rsmooth_scalar scalar, const void *positions,
                                        size_t point_count, double *scale, rsmooth_error *error,
                                        const char *caller);
const char *rs_point_unit_normal(rsmooth_scalar scalar, const void *normals, size_t i,
                                 double out[3]);
double rs_point_spacings(const rs_kdtree *tree, double *spacing);

/* The public functions' bodies, for api/'s definitions of them (lib/api/): */
/* rsmooth_point_spacing */
rsmooth_status rs_point_spacing(rsmooth_scalar scalar, const void *positions, size_t point_count,
                                double *out_spacing, rsmooth_error *error);

#endif /* RSMOOTH_POINTS_H */
