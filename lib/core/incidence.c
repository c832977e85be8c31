/* Which triangles meet at each vertex: a counting sort of the corners, in triangle order, so a
 * sum over a vertex's triangles runs in the order a pass over all triangles adds them. */
#include "core/incidence.h"

#include <string.h>

bool rs_vertex_triangles(const uint32_t *indices, size_t triangle_count, size_t vertex_count,
                         size_t **first, uint32_t **triangle) {
    *first = rs_calloc_array(vertex_count + 1, sizeof **first);
    *triangle = rs_alloc_array(triangle_count ? 3 * triangle_count : 1, sizeof **triangle);
    size_t *fill = rs_alloc_array(vertex_count ? vertex_count : 1, sizeof *fill);
    if (!*first || !*triangle || !fill) {
        rs_free(*first);
        rs_free(*triangle);
        rs_free(fill);
        *first = NULL;
        *triangle = NULL;
        return false;
    }
    for (int pass = 0; pass < 2; pass++) {
        for (size_t t = 0; t < triangle_count; t++)
            for (int c = 0; c < 3; c++) {
                const uint32_t *tri = indices + 3 * t;
                if ((c > 0 && tri[c] == tri[0]) || (c > 1 && tri[c] == tri[1]))
                    continue; /* a repeated corner: once */
                if (pass == 0)
                    (*first)[tri[c] + 1]++;
                else
                    (*triangle)[fill[tri[c]]++] = (uint32_t)t;
            }
        if (pass == 0) {
            for (size_t v = 0; v < vertex_count; v++)
                (*first)[v + 1] += (*first)[v];
            memcpy(fill, *first, vertex_count * sizeof *fill);
        }
    }
    rs_free(fill);
    return true;
}
