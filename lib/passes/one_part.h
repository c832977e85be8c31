/* The passes on one part of a mesh (passes.c), which by_part.c runs for each part. Internal. */
#ifndef RSMOOTH_ONE_PART_H
#define RSMOOTH_ONE_PART_H

#include "passes/passes.h"

/* rs_filter_passes's work on a mesh of one part: the stage, the passes, the choice per region,
 * the caller's mask, then the last check of what they wrote (results.c): never a non-finite OK. */
rsmooth_status rs_filter_one_part(rs_filter_fn one_pass, rs_stage_runner stage,
                                  rs_network_runner network, void *ctx, rsmooth_scalar scalar,
                                  const void *positions, size_t vertex_count,
                                  const uint32_t *indices, size_t triangle_count,
                                  const rsmooth_params *params, void *out_positions,
                                  float *out_weight, float *out_confidence, rsmooth_report *report,
                                  rsmooth_error *error, const char *where);

#endif /* RSMOOTH_ONE_PART_H */
