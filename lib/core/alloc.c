/* The library's one allocation pair, with overflow-checked array sizes. Large arrays ask for
 * transparent huge pages: a 10M-triangle mesh otherwise spends most of its read time in the kernel
 * faulting in and zeroing 4 KiB pages. */
#define _DEFAULT_SOURCE /* madvise, MADV_HUGEPAGE */
#include "core/rsmooth_internal.h"

#include <stdlib.h>
#if defined(__GLIBC__)
#include <malloc.h>
#endif
#include <string.h>
#include <sys/mman.h>
#include <time.h>

#define HUGE_PAGE (2u << 20)
#define LARGE_ARRAY (16u << 20) /* bytes from which huge pages pay */
/* Arrays from this size are aligned to DEVICE_ALIGNMENT, so OpenCL CPU devices can use them in
 * place as buffers (CL_MEM_USE_HOST_PTR; PoCL copies unaligned ones). */
#define DEVICE_ARRAY (64u << 10)
#define DEVICE_ALIGNMENT 128

static void *allocate(size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    if (bytes >= LARGE_ARRAY) {
        void *p = NULL;
        if (posix_memalign(&p, HUGE_PAGE, bytes) != 0)
            return NULL;
        madvise(p, bytes, MADV_HUGEPAGE); /* advice only: failure changes nothing */
        return p;
    }
#endif
    if (bytes >= DEVICE_ARRAY) {
        void *p = NULL;
        return posix_memalign(&p, DEVICE_ALIGNMENT, bytes) == 0 ? p : NULL;
    }
    return malloc(bytes ? bytes : 1);
}

void *rs_alloc_array(size_t count, size_t size) {
    if (rs_mul_overflows(count, size))
        return NULL;
    return allocate(count * size);
}

void *rs_calloc_array(size_t count, size_t size) {
    if (rs_mul_overflows(count, size))
        return NULL;
    size_t bytes = count * size;
    if (bytes < LARGE_ARRAY)
        return calloc(count ? count : 1, size ? size : 1);
    void *p = allocate(bytes);
    if (p)
        memset(p, 0, bytes);
    return p;
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

void rs_release_free_memory(void) {
#if defined(__GLIBC__)
    malloc_trim(0);
#endif
}

double rs_now_ms(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}
