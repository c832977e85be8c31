/* The fold guard (fold_guard.c): a smoothed mesh keeps every triangle facing the way it faced.
 * Internal, not installed. */
#ifndef RSMOOTH_FOLD_GUARD_H
#define RSMOOTH_FOLD_GUARD_H

#include "core/rsmooth_internal.h"

/* Moves back toward `positions` (the input) the vertices of `out_positions` (the result, same
 * scalar type) whose triangles came out reversed (fold_guard.c), until none is. Returns how many
 * vertices it moved, or -1 when out of memory (out_positions unchanged then). */
long rs_fold_guard(rsmooth_scalar scalar, const void *positions, void *out_positions,
                   size_t vertex_count, const uint32_t *indices, size_t triangle_count);

#endif /* RSMOOTH_FOLD_GUARD_H */
