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

/* The rule, written once for the in-memory path's 32-bit vertex ids (rs_edge_compare,
 * rs_edge_repeats) and streaming's 64-bit ones (rs_edge_compare64, rs_edge_repeats64): qsort's
 * comparison of two upper ends, and whether entry j of an ordered bucket repeats an edge before
 * it. */
#define RS_EDGE_RULE(suffix, id_type)                                                              \
    static inline int rs_edge_compare##suffix(const void *a, const void *b) {                      \
        id_type x = *(const id_type *)a, y = *(const id_type *)b;                                  \
        return (x > y) - (x < y);                                                                  \
    }                                                                                              \
    static inline bool rs_edge_repeats##suffix(const id_type *bucket, size_t n, size_t j) {        \
        if (n > RS_EDGE_SCAN_LIMIT)                                                                \
            return j > 0 && bucket[j] == bucket[j - 1];                                            \
        for (size_t k = 0; k < j; k++)                                                             \
            if (bucket[k] == bucket[j])                                                            \
                return true;                                                                       \
        return false;                                                                              \
    }

RS_EDGE_RULE(, uint32_t)
RS_EDGE_RULE(64, uint64_t)

/* Puts a bucket of n upper ends in the order its edges are counted in. */
static inline void rs_edge_bucket_order(uint32_t *bucket, size_t n) {
    if (n > RS_EDGE_SCAN_LIMIT)
        qsort(bucket, n, sizeof *bucket, rs_edge_compare);
}

#endif /* RSMOOTH_EDGE_BUCKET_H */
