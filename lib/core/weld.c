/* Welding: a triangle soup's or an STL file's corners are separate vertices at one position; the
 * stages that read connectivity take them as one, so a soup is filtered as the mesh it was cut
 * from. */
#include "core/weld.h"

#include <string.h>

/* A 64-bit mix of a position's bytes (splitmix64's finaliser over the three words): equal
 * positions hash alike, and different ones almost never do. */
static uint64_t position_hash(const double *p) {
    uint64_t h = 0x9e3779b97f4a7c15u;
    for (int k = 0; k < 3; k++) {
        uint64_t w;
        memcpy(&w, p + k, sizeof w);
        h ^= w + 0x9e3779b97f4a7c15u + (h << 6) + (h >> 2);
        h = (h ^ (h >> 30)) * 0xbf58476d1ce4e5b9u;
        h = (h ^ (h >> 27)) * 0x94d049bb133111ebu;
        h ^= h >> 31;
    }
    return h;
}

bool rs_weld(const double *xyz, size_t vertex_count, uint32_t *rep) {
    /* by hash (a radix sort: linear), then within a run of one hash, each vertex with the first
     * earlier one at exactly its position; the sort is stable, so that one is the lowest-numbered
     */
    uint64_t *key = rs_alloc_array(vertex_count ? vertex_count : 1, sizeof *key);
    uint32_t *vertex = rs_alloc_array(vertex_count ? vertex_count : 1, sizeof *vertex);
    bool ok = key && vertex;
    for (size_t v = 0; ok && v < vertex_count; v++) {
        key[v] = position_hash(xyz + 3 * v);
        vertex[v] = (uint32_t)v;
    }
    ok = ok && rs_radix_sort_u64(key, vertex, vertex_count);
    for (size_t start = 0; ok && start < vertex_count;) {
        size_t end = start + 1;
        while (end < vertex_count && key[end] == key[start])
            end++;
        for (size_t i = start; i < end; i++) {
            uint32_t v = vertex[i];
            rep[v] = v;
            for (size_t j = start; j < i; j++) /* the heads of the run before it */
                if (rep[vertex[j]] == vertex[j] &&
                    memcmp(xyz + 3 * (size_t)vertex[j], xyz + 3 * (size_t)v, 3 * sizeof *xyz) ==
                        0) {
                    rep[v] = vertex[j];
                    break;
                }
        }
        start = end;
    }
    rs_free(key);
    rs_free(vertex);
    return ok;
}

uint64_t *rs_welded_edges(const uint32_t *rep, const uint32_t *indices, size_t triangle_count,
                          size_t *count, uint8_t **single) {
    size_t n = 0, capacity = triangle_count ? 3 * triangle_count : 1;
    uint64_t *key = rs_alloc_array(capacity, sizeof *key);
    uint32_t *unused = rs_calloc_array(capacity, sizeof *unused);
    uint8_t *once = single ? rs_alloc_array(capacity, 1) : NULL;
    bool ok = key && unused && (!single || once);
    for (size_t t = 0; ok && t < triangle_count; t++)
        for (int e = 0; e < 3; e++) {
            uint32_t a = rep[indices[3 * t + e]], b = rep[indices[3 * t + (e + 1) % 3]];
            if (a != b)
                key[n++] = a < b ? (uint64_t)a << 32 | b : (uint64_t)b << 32 | a;
        }
    ok = ok && rs_radix_sort_u64(key, unused, n);
    rs_free(unused);
    if (!ok) {
        rs_free(key);
        rs_free(once);
        return NULL;
    }
    size_t unique = 0;
    for (size_t i = 0; i < n; i++)
        if (i == 0 || key[i] != key[i - 1]) {
            if (once) /* one triangle alone has it: no copy before or after */
                once[unique] = i + 1 == n || key[i + 1] != key[i];
            key[unique++] = key[i];
        }
    *count = unique;
    if (single)
        *single = once;
    return key;
}
