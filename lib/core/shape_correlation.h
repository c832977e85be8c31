/* Whether a mesh's roughness reads as shape or as noise (shape_correlation.c). Internal. */
#ifndef RSMOOTH_SHAPE_CORRELATION_H
#define RSMOOTH_SHAPE_CORRELATION_H

#include "core/rsmooth_internal.h"

/* The correlation of each welded vertex's bend (umbrella offset along its normal) with its
 * neighbours' mean bend, in [-1, 1]; 1 when the bends barely vary. xyz in internal units (a
 * typical edge about 1, scale.c). false when out of memory. */
/* At or above this the roughness reads as shape: a clean mesh (the figures above). */
#define RS_CLEAN_SHAPE_CORRELATION 0.3

bool rs_shape_correlation(const double *xyz, size_t vertex_count, const uint32_t *indices,
                          size_t triangle_count, double *out);

/* The same from a weld already made (core/weld.h: rep, and its edges from rs_welded_edges). */
bool rs_shape_correlation_welded(const double *xyz, size_t vertex_count, const uint32_t *indices,
                                 size_t triangle_count, const uint32_t *rep, const uint64_t *edge,
                                 size_t edge_count, double *out);

#endif /* RSMOOTH_SHAPE_CORRELATION_H */
