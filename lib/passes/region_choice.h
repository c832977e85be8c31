/* params.discrepancy_level's choice per region (region_choice.c). Internal, not installed. */
#ifndef RSMOOTH_REGION_CHOICE_H
#define RSMOOTH_REGION_CHOICE_H

#include "core/rsmooth_internal.h"

/* Blends the filter's result in out_positions with Taubin's smoothing of `positions` run to
 * `level` mean edge lengths (and, min_gain > 0, until an iteration adds less than min_gain mean
 * edge lengths to the move), per vertex, and limits boundary vertices' moves to that level. Returns
 * Taubin's iterations (0: nothing to smooth, e.g. a soup), or -1 when out of memory.
 * *out_mean_weight (optional): the filter's mean weight over the vertices. */
int rs_region_choice(rsmooth_scalar scalar, const void *positions, size_t vertex_count,
                     const uint32_t *indices, size_t triangle_count, double level, double min_gain,
                     void *out_positions, double *out_mean_weight);

#endif /* RSMOOTH_REGION_CHOICE_H */
