/* Repeated passes of one path's filter (passes.c), the mesh part by part (by_part.c), and the
 * normal-update stage between them: what a path gives (one pass, a stage runner) and what the
 * passes give back. Internal, not installed. */
#ifndef RSMOOTH_PASSES_H
#define RSMOOTH_PASSES_H

#include "core/stage_plan.h"
#include "learned/learned.h"

/* The caller's progress callback seen through pass `pass` of `count` (rs_report_pass_progress
 * is the callback to give the pass, with this as its user pointer). */
typedef struct rs_pass_progress {
    rsmooth_progress_fn progress;
    rsmooth_progress_cancel_fn cancel;
    void *user;
    int pass, count;
} rs_pass_progress;
/* A progress_cancel callback: forwards to both of the caller's, the fraction rescaled. */
int rs_report_pass_progress(void *user, double fraction);

/* Adds one pass's stage times and work to `sum`, the passes' so far (all zero before the first):
 * counts, sigmas and device from the last pass, the facet count from the first. */
void rs_add_pass_report(rsmooth_report *sum, const rsmooth_report *pass);

/* One pass of a path's filter (rs_reference_pass, api/smooth.c's device pass); `ctx` is the path's
 * own. */
typedef rsmooth_status (*rs_filter_fn)(void *ctx, rsmooth_scalar scalar, const void *positions,
                                       size_t vertex_count, const uint32_t *indices,
                                       size_t triangle_count, const rsmooth_params *params,
                                       void *out_positions, float *out_weight,
                                       float *out_confidence, rsmooth_report *report,
                                       rsmooth_error *error);

/* Runs `one_pass` params->passes times (once, unchanged, when passes is 1), each pass from the
 * previous pass's positions with the sigmas of the input, honouring pass_confidence; the
 * normal-update stage before them, if params ask for it, through `stage` (NULL: on the host),
 * its learned networks through `network` (NULL: on the host), all with `ctx`. The caller's
 * outputs are written only when every pass succeeded. */
rsmooth_status rs_filter_passes(rs_filter_fn one_pass, rs_stage_runner stage,
                                rs_network_runner network, void *ctx, rsmooth_scalar scalar,
                                const void *positions, size_t vertex_count, const uint32_t *indices,
                                size_t triangle_count, const rsmooth_params *params,
                                void *out_positions, float *out_weight, float *out_confidence,
                                rsmooth_report *report, rsmooth_error *error, const char *where);

#endif /* RSMOOTH_PASSES_H */
