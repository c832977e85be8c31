/* LSD radix sort of 64-bit keys with 32-bit payloads: grid cells and vertex orders sort in linear
 * time. Each pass counts digits per chunk and scatters the chunks at once (rs_parallel_for); chunk
 * c's elements of a digit go after those of chunks before it, so the sort stays stable and its
 * result does not depend on the thread count. */
#include "core/rsmooth_internal.h"

#include <string.h>

#define RADIX_BITS 11
#define RADIX_SIZE (1u << RADIX_BITS)
#define SORT_GRAIN 16384 /* elements per chunk below which a pass is not worth a thread */

typedef struct radix_pass {
    const uint64_t *src_k;
    const uint32_t *src_v;
    uint64_t *dst_k;
    uint32_t *dst_v;
    size_t count;
    int shift;
    size_t *offsets; /* per chunk: RADIX_SIZE counts, then the first slot of each digit */
} radix_pass;

typedef struct key_bits {
    const uint64_t *keys;
    uint64_t any[64]; /* per chunk: its keys or'ed */
} key_bits;

static void or_keys(void *ctx, size_t begin, size_t end, size_t chunk) {
    key_bits *job = ctx;
    uint64_t any = 0;
    for (size_t i = begin; i < end; i++)
        any |= job->keys[i];
    job->any[chunk] = any;
}

static void count_digits(void *ctx, size_t begin, size_t end, size_t chunk) {
    const radix_pass *p = ctx;
    size_t *histogram = p->offsets + chunk * RADIX_SIZE;
    memset(histogram, 0, RADIX_SIZE * sizeof *histogram);
    for (size_t i = begin; i < end; i++)
        histogram[(p->src_k[i] >> p->shift) & (RADIX_SIZE - 1)]++;
}

static void scatter(void *ctx, size_t begin, size_t end, size_t chunk) {
    const radix_pass *p = ctx;
    size_t *next = p->offsets + chunk * RADIX_SIZE;
    for (size_t i = begin; i < end; i++) {
        size_t slot = next[(p->src_k[i] >> p->shift) & (RADIX_SIZE - 1)]++;
        p->dst_k[slot] = p->src_k[i];
        p->dst_v[slot] = p->src_v[i];
    }
}

bool rs_radix_sort_u64(uint64_t *keys, uint32_t *values, size_t count) {
    if (count < 2)
        return true;
    size_t chunks = rs_parallel_chunks(count, SORT_GRAIN);
    key_bits kb = {keys, {0}};
    rs_parallel_for(count, SORT_GRAIN, or_keys, &kb);
    uint64_t max_key = 0;
    for (size_t c = 0; c < chunks; c++)
        max_key |= kb.any[c];
    int bits = 0;
    while (bits < 64 && (max_key >> bits) != 0)
        bits++;
    uint64_t *key_tmp = rs_alloc_array(count, sizeof *key_tmp);
    uint32_t *val_tmp = rs_alloc_array(count, sizeof *val_tmp);
    size_t *offsets = rs_alloc_array(chunks * RADIX_SIZE, sizeof *offsets);
    if (!key_tmp || !val_tmp || !offsets) {
        rs_free(key_tmp);
        rs_free(val_tmp);
        rs_free(offsets);
        return false;
    }
    radix_pass p = {keys, values, key_tmp, val_tmp, count, 0, offsets};
    for (p.shift = 0; p.shift < bits; p.shift += RADIX_BITS) {
        rs_parallel_for(count, SORT_GRAIN, count_digits, &p);
        size_t sum = 0; /* digit-major, chunk-minor: stable */
        for (size_t d = 0; d < RADIX_SIZE; d++)
            for (size_t c = 0; c < chunks; c++) {
                size_t n = offsets[c * RADIX_SIZE + d];
                offsets[c * RADIX_SIZE + d] = sum;
                sum += n;
            }
        rs_parallel_for(count, SORT_GRAIN, scatter, &p);
        const uint64_t *k = p.src_k;
        p.src_k = p.dst_k;
        p.dst_k = (uint64_t *)k;
        const uint32_t *v = p.src_v;
        p.src_v = p.dst_v;
        p.dst_v = (uint32_t *)v;
    }
    if (p.src_k != keys) {
        memcpy(keys, p.src_k, count * sizeof *keys);
        memcpy(values, p.src_v, count * sizeof *values);
    }
    rs_free(key_tmp);
    rs_free(val_tmp);
    rs_free(offsets);
    return true;
}
