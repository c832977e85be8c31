/* One vertex's edges as the mean edge length counts them: core/mesh.c in memory and
 * stream/stream_stats.c streamed must give the same bits, so they share this rule. A vertex's
 * bucket holds the upper ends of the edges whose lower end it is, in the order the triangles name
 * them; a bucket of more than RS_EDGE_SCAN_LIMIT is sorted (then scanned for neighbours), a
 * smaller one scanned as it is, and an edge counts at its first place only. Header-only, since
 * both libraries carry it (not installed). */
#ifndef RSMOOTH_EDGE_BUCKET_H
#define RSMOOTH_EDGE_BUCKET_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

/* Buckets of more edges than this are sorted to find duplicates; smaller ones are scanned. */
#define RS_EDGE_SCAN_LIMIT 32

static inline int rs_edge_compare(const void *a, const void *b) {
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

/* Puts a bucket of n upper ends in the order its edges are counted in. */
static inline void rs_edge_bucket_order(uint32_t *bucket, size_t n) {
    if (n > RS_EDGE_SCAN_LIMIT)
        qsort(bucket, n, sizeof *bucket, rs_edge_compare);
}

/* Whether entry j of an ordered bucket repeats an edge before it. */
static inline bool rs_edge_repeats(const uint32_t *bucket, size_t n, size_t j) {
    if (n > RS_EDGE_SCAN_LIMIT)
        return j > 0 && bucket[j] == bucket[j - 1];
    for (size_t k = 0; k < j; k++)
        if (bucket[k] == bucket[j])
            return true;
    return false;
}

/* The same rule on 64-bit vertex ids (streaming: meshes of 2^32 - 1 vertices and more). */
static inline int rs_edge_compare64(const void *a, const void *b) {
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

static inline bool rs_edge_repeats64(const uint64_t *bucket, size_t n, size_t j) {
    if (n > RS_EDGE_SCAN_LIMIT)
        return j > 0 && bucket[j] == bucket[j - 1];
    for (size_t k = 0; k < j; k++)
        if (bucket[k] == bucket[j])
            return true;
    return false;
}

#endif /* RSMOOTH_EDGE_BUCKET_H */
