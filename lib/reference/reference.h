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

#endif /* RSMOOTH_REFERENCE_H */
