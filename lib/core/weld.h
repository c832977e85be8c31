/* Vertices at exactly the same position taken as one (weld.c). Internal. */
#ifndef RSMOOTH_WELD_H
#define RSMOOTH_WELD_H

#include "core/rsmooth_internal.h"

/* rep[v]: the lowest-numbered vertex at v's position (xyz: 3 doubles per vertex). false when out
 * of memory. */
bool rs_weld(const double *xyz, size_t vertex_count, uint32_t *rep);

/* The welded mesh's edges (between two different welded vertices), each once, sorted, as keys
 * low << 32 | high; *count of them. With `single` not NULL, *single (allocated, rs_free it) says
 * per edge whether one triangle alone has it: the boundary's. NULL when out of memory. */
uint64_t *rs_welded_edges(const uint32_t *rep, const uint32_t *indices, size_t triangle_count,
                          size_t *count, uint8_t **single);

#endif /* RSMOOTH_WELD_H */
