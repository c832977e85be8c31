/* Opening the OpenCL device for a test: prints platform and device first. With no OpenCL device the
 * test is skipped (exit 77) unless RSMOOTH_REQUIRE_OPENCL=1, as CI sets, so a missing PoCL cannot
 * pass as green. The device comes from RSMOOTH_DEVICE (default "auto"). */
#ifndef RSMOOTH_TEST_CL_UTIL_H
#define RSMOOTH_TEST_CL_UTIL_H

#include "rsmooth.h"
#include "test_util.h"

#include <stdlib.h>
#include <string.h>

static inline rsmooth_context *open_test_context(void) {
    rsmooth_context *ctx = NULL;
    rsmooth_error err;
    rsmooth_status st = rsmooth_context_create(NULL, &ctx, &err);
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
    printf("device: %s (program build %.1f ms)\n", rsmooth_context_device_name(ctx),
           rsmooth_context_build_ms(ctx));
    return ctx;
}

/* Path of ../shared/data/benchmark/<model>/<file> beside the source tree, or NULL when absent. */
#ifndef RSMOOTH_SHARED_DIR
#define RSMOOTH_SHARED_DIR ""
#endif

#endif
