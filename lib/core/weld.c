/* Welding: a triangle soup's or an STL file's corners are separate vertices at one position; the
 * stages that read connectivity take them as one, so a soup is filtered as the mesh it was cut
 * from. */
#include "core/weld.h"

#include <stdlib.h>
#include <string.h>

typedef struct weld_key {
    double xyz[3];
    uint32_t vertex;
} weld_key;

static int compare_weld(const void *pa, const void *pb) {
    const weld_key *a = pa, *b = pb;
    for (int k = 0; k < 3; k++)
        if (a->xyz[k] != b->xyz[k])
            return a->xyz[k] < b->xyz[k] ? -1 : 1;
    return a->vertex < b->vertex ? -1 : a->vertex > b->vertex;
}

bool rs_weld(const double *xyz, size_t vertex_count, uint32_t *rep) {
    weld_key *keys = rs_alloc_array(vertex_count ? vertex_count : 1, sizeof *keys);
    if (!keys)
        return false;
    for (size_t v = 0; v < vertex_count; v++) {
        memcpy(keys[v].xyz, xyz + 3 * v, sizeof keys[v].xyz);
        keys[v].vertex = (uint32_t)v;
    }
    qsort(keys, vertex_count, sizeof *keys, compare_weld);
    for (size_t i = 0; i < vertex_count; i++) {
        bool same = i > 0 && !memcmp(keys[i].xyz, keys[i - 1].xyz, sizeof keys[i].xyz);
        rep[keys[i].vertex] = same ? rep[keys[i - 1].vertex] : keys[i].vertex;
    }
    rs_free(keys);
    return true;
}
