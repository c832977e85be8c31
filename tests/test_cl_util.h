/* Opening the OpenCL device for a test: prints platform and device first. With no OpenCL device the
 * test is skipped (exit 77) unless RSMOOTH_REQUIRE_OPENCL=1, as CI sets, so a missing PoCL cannot
 * pass as green. The device comes from RSMOOTH_DEVICE (default "auto"). */
#ifndef RSMOOTH_TEST_CL_UTIL_H
#define RSMOOTH_TEST_CL_UTIL_H

#include "rsmooth.h"
#include "test_util.h"

#include <stdlib.h>
#include <string.h>

/* ctx's rsmooth_context_info (every field). */
static inline rsmooth_context_info context_info(const rsmooth_context *ctx) {
    rsmooth_context_info info = {.struct_size = sizeof info};
    if (rsmooth_context_get_info(ctx, &info) != RSMOOTH_OK) {
        fprintf(stderr, "rsmooth_context_get_info failed\n");
        exit(1);
    }
    return info;
}

/* A context on the default device whose calls may hold `budget` bytes of device memory (0: the
 * device's own limit), as rsmooth_context_options.memory_budget sets it. */
static inline rsmooth_context *open_test_context_budget(uint64_t budget) {
    rsmooth_context *ctx = NULL;
    rsmooth_error err;
    rsmooth_context_options options = {.struct_size = sizeof options, .memory_budget = budget};
    rsmooth_status st = rsmooth_context_create(&options, &ctx, &err);
    if (st != RSMOOTH_OK) {
        const char *require = getenv("RSMOOTH_REQUIRE_OPENCL");
        fprintf(stderr, "no OpenCL device: %s: %s\n%s\n", rsmooth_status_str(st), err.message,
                err.build_log);
        if (st == RSMOOTH_ERROR_NO_DEVICE && !(require && strcmp(require, "1") == 0)) {
            fprintf(stderr, "skipping (set RSMOOTH_REQUIRE_OPENCL=1 to make this a failure)\n");
            exit(TEST_SKIP);
        }
        exit(1);
    }
    rsmooth_context_info info = context_info(ctx);
    printf("device: %s (program build %.1f ms)\n", info.device_name, info.build_ms);
    return ctx;
}

static inline rsmooth_context *open_test_context(void) {
    return open_test_context_budget(0);
}

/* Path of ../shared/data/benchmark/<model>/<file> beside the source tree, or NULL when absent. */
#ifndef RSMOOTH_SHARED_DIR
#define RSMOOTH_SHARED_DIR ""
#endif

#endif
