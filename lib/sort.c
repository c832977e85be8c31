/* LSD radix sort of 64-bit keys with 32-bit payloads: grid cells and edge keys sort in linear time. */
#include "rsmooth_internal.h"

#include <string.h>

#define RADIX_BITS 11
#define RADIX_SIZE (1u << RADIX_BITS)

bool rs_radix_sort_u64(uint64_t *keys, uint32_t *values, size_t count) {
    if (count < 2)
        return true;
    uint64_t max_key = 0;
    for (size_t i = 0; i < count; i++)
        max_key |= keys[i];
    int bits = 0;
    while (bits < 64 && (max_key >> bits) != 0)
        bits++;
    uint64_t *key_tmp = rs_alloc_array(count, sizeof *key_tmp);
    uint32_t *val_tmp = rs_alloc_array(count, sizeof *val_tmp);
    size_t *histogram = rs_alloc_array(RADIX_SIZE, sizeof *histogram);
    if (!key_tmp || !val_tmp || !histogram) {
        rs_free(key_tmp);
        rs_free(val_tmp);
        rs_free(histogram);
        return false;
    }
    uint64_t *src_k = keys, *dst_k = key_tmp;
    uint32_t *src_v = values, *dst_v = val_tmp;
    for (int shift = 0; shift < bits; shift += RADIX_BITS) {
        memset(histogram, 0, RADIX_SIZE * sizeof *histogram);
        for (size_t i = 0; i < count; i++)
            histogram[(src_k[i] >> shift) & (RADIX_SIZE - 1)]++;
        size_t sum = 0;
        for (size_t d = 0; d < RADIX_SIZE; d++) {
            size_t c = histogram[d];
            histogram[d] = sum;
            sum += c;
        }
        for (size_t i = 0; i < count; i++) {
            size_t slot = histogram[(src_k[i] >> shift) & (RADIX_SIZE - 1)]++;
            dst_k[slot] = src_k[i];
            dst_v[slot] = src_v[i];
        }
        uint64_t *tk = src_k;
        src_k = dst_k;
        dst_k = tk;
        uint32_t *tv = src_v;
        src_v = dst_v;
        dst_v = tv;
    }
    if (src_k != keys) {
        memcpy(keys, src_k, count * sizeof *keys);
        memcpy(values, src_v, count * sizeof *values);
    }
    rs_free(key_tmp);
    rs_free(val_tmp);
    rs_free(histogram);
    return true;
}
