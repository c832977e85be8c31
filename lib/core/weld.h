/* Vertices at exactly the same position taken as one (weld.c). Internal. */
#ifndef RSMOOTH_WELD_H
#define RSMOOTH_WELD_H

#include "core/rsmooth_internal.h"

/* rep[v]: the lowest-numbered vertex at v's position (xyz: 3 doubles per vertex). false when out
 * of memory. */
bool rs_weld(const double *xyz, size_t vertex_count, uint32_t *rep);

#endif /* RSMOOTH_WELD_H */
