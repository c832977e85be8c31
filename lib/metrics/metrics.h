/* The error measures against a ground-truth mesh (metrics.c). Internal, not installed. */
#ifndef RSMOOTH_METRICS_H
#define RSMOOTH_METRICS_H

#include "rsmooth.h"

/* The public functions' bodies, for api/'s definitions of them (lib/api/): */
/* rsmooth_compare */
rsmooth_status rs_compare(rsmooth_scalar scalar, const void *result_positions,
                          const void *truth_positions, size_t vertex_count, const uint32_t *indices,
                          size_t triangle_count, rsmooth_metrics *out, rsmooth_error *error);

#endif /* RSMOOTH_METRICS_H */
