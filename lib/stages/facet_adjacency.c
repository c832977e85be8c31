/* Which facets meet at each vertex, with vertices at exactly the same position taken as one (a
 * triangle soup's or an STL file's corners): the connectivity the normal update stage reads, so a
 * soup is filtered as the mesh it was cut from. */
#include "core/weld.h"
#include "stages/normal_update.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Visits corner c of facet f unless an earlier corner welded to the same vertex. */
static bool first_corner(const uint32_t *rep, const uint32_t *t, int c) {
    uint32_t r = rep[t[c]];
    return !((c > 0 && rep[t[0]] == r) || (c > 1 && rep[t[1]] == r));
}

bool rs_adjacency_build(rs_adjacency *adj, const double *xyz, size_t vertex_count,
                        const uint32_t *indices, const rs_facets *facets) {
    memset(adj, 0, sizeof *adj);
    adj->rep = rs_alloc_array(vertex_count ? vertex_count : 1, sizeof *adj->rep);
    adj->start = rs_calloc_array(vertex_count + 1, sizeof *adj->start);
    adj->facet = rs_alloc_array(facets->count ? 3 * facets->count : 1, sizeof *adj->facet);
    size_t *fill = rs_alloc_array(vertex_count ? vertex_count : 1, sizeof *fill);
    if (!adj->rep || !adj->start || !adj->facet || !fill || !rs_weld(xyz, vertex_count, adj->rep)) {
        rs_free(fill);
        rs_adjacency_free(adj);
        return false;
    }
    for (size_t f = 0; f < facets->count; f++) {
        const uint32_t *t = indices + 3 * (size_t)facets->triangle[f];
        for (int c = 0; c < 3; c++)
            if (first_corner(adj->rep, t, c))
                adj->start[adj->rep[t[c]] + 1]++;
    }
    for (size_t v = 0; v < vertex_count; v++)
        adj->start[v + 1] += adj->start[v];
    memcpy(fill, adj->start, vertex_count * sizeof *fill);
    for (size_t f = 0; f < facets->count; f++) { /* in facet order: deterministic lists */
        const uint32_t *t = indices + 3 * (size_t)facets->triangle[f];
        for (int c = 0; c < 3; c++)
            if (first_corner(adj->rep, t, c))
                adj->facet[fill[adj->rep[t[c]]]++] = (uint32_t)f;
    }
    rs_free(fill);
    return true;
}

void rs_adjacency_free(rs_adjacency *adj) {
    rs_free(adj->rep);
    rs_free(adj->start);
    rs_free(adj->facet);
    memset(adj, 0, sizeof *adj);
}
