/* The fold guard (fold_guard.c): a smoothed mesh keeps every triangle facing the way it faced.
 * Internal, not installed. */
#ifndef RSMOOTH_FOLD_GUARD_H
#define RSMOOTH_FOLD_GUARD_H

#include "core/rsmooth_internal.h"

/* Moves the vertices of `out_positions` (the result, `positions`' scalar type) whose triangles
 * came out turned over (fold_guard.c) until none is; a vertex whose `movable` byte is 0 (NULL:
 * every vertex may move) is left where it is (held by the caller's mask, or an outlier). Returns
 * how many vertices it moved, or -1 when out of memory (out_positions unchanged then). */
long rs_fold_guard(rsmooth_scalar scalar, const void *positions, void *out_positions,
                   size_t vertex_count, const uint32_t *indices, size_t triangle_count,
                   const uint8_t *movable);

#endif /* RSMOOTH_FOLD_GUARD_H */
