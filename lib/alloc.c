/* The library's one allocation pair, with overflow-checked array sizes. */
#define _POSIX_C_SOURCE 200809L
#include "rsmooth_internal.h"

#include <stdlib.h>
#include <time.h>

void *rs_alloc_array(size_t count, size_t size) {
    if (rs_mul_overflows(count, size))
        return NULL;
    size_t bytes = count * size;
    return malloc(bytes ? bytes : 1);
}

void *rs_calloc_array(size_t count, size_t size) {
    if (rs_mul_overflows(count, size))
        return NULL;
    return calloc(count ? count : 1, size ? size : 1);
}

void *rs_realloc_array(void *ptr, size_t count, size_t size) {
    if (rs_mul_overflows(count, size))
        return NULL;
    size_t bytes = count * size;
    return realloc(ptr, bytes ? bytes : 1);
}

void rs_free(void *ptr) {
    free(ptr);
}

double rs_now_ms(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}
