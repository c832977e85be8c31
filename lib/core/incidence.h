/* Which triangles meet at each vertex (incidence.c). Internal. */
#ifndef RSMOOTH_INCIDENCE_H
#define RSMOOTH_INCIDENCE_H

#include "core/rsmooth_internal.h"

/* The triangles at vertex v are triangle[first[v] .. first[v + 1]), in index order, each once (a
 * repeated corner counts once); first has vertex_count + 1 entries. Both are allocated here
 * (rs_free them); false when out of memory (then both are NULL). */
bool rs_vertex_triangles(const uint32_t *indices, size_t triangle_count, size_t vertex_count,
                         size_t **first, uint32_t **triangle);

#endif /* RSMOOTH_INCIDENCE_H */
