/* The reference path's filter on a prepared problem (reference.c), for the paths that reuse it:
 * point clouds and the pieces of a streamed mesh. Internal, not installed. */
#ifndef RSMOOTH_REFERENCE_H
#define RSMOOTH_REFERENCE_H

#include "core/rsmooth_internal.h"

/* The reference filter on a prepared problem (with its facet data kept), written to the caller's
 * arrays; out_normals (optional) receives the predictors' unit normals, 3 per facet, when there
 * are facets. t_start is when the call began, for the report. The caller frees the problem. */
rsmooth_status rs_reference_solve(const rs_problem *problem, rsmooth_scalar scalar,
                                  void *out_positions, float *out_weight, float *out_confidence,
                                  double *out_normals, rsmooth_report *report, double t_start,
                                  rsmooth_error *error, const char *where);

/* The reference path's pass of the filter (an rs_filter_fn, passes/passes.h): the problem
 * prepared, then rs_reference_solve in double on the host. `unused` is the path's context (it has
 * none). */
rsmooth_status rs_reference_pass(void *unused, rsmooth_scalar scalar, const void *positions,
                                 size_t vertex_count, const uint32_t *indices,
                                 size_t triangle_count, const rsmooth_params *params,
                                 void *out_positions, float *out_weight, float *out_confidence,
                                 rsmooth_report *report, rsmooth_error *error);

#endif /* RSMOOTH_REFERENCE_H */
