/* The caller's own OpenCL context (rsmooth_cl.h): an application that already runs OpenCL makes
 * its context and queue as usual, hands rsmooth the queue (retained, never owned: the caller
 * releases its own reference when it likes), and rsmooth runs its kernels there. The result is
 * checked against the double-precision reference path (they agree to about 1e-4 edge lengths).
 *
 *     example_own_context
 *
 * Exit status 77 (skipped) when no OpenCL platform or device exists, unless
 * RSMOOTH_REQUIRE_OPENCL=1. Link OpenCL::OpenCL (-lOpenCL): rsmooth then shares that loader. */
#define CL_TARGET_OPENCL_VERSION 120 /* rsmooth_cl.h leaves the OpenCL version to its user */
#include <rsmooth_cl.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int skip(const char *why) {
    const char *require = getenv("RSMOOTH_REQUIRE_OPENCL");
    fprintf(stderr, "example_own_context: %s\n", why);
    return require && strcmp(require, "1") == 0 ? EXIT_FAILURE : 77;
}

int main(void) {
    /* A small mesh: an octahedron whose 6 vertices lie a little off their places. */
    double xyz[] = {1.1, 0, 0, -1, 0.1, 0, 0, 1, 0.05, 0, -0.9, 0, 0, 0, 1.05, 0.1, 0, -1};
    uint32_t indices[] = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};
    double out[18], expected[18];

    cl_platform_id platform;
    cl_device_id device;
    cl_uint count = 0;
    if (clGetPlatformIDs(1, &platform, &count) != CL_SUCCESS || count == 0)
        return skip("no OpenCL platform");
    if (clGetDeviceIDs(platform, CL_DEVICE_TYPE_ALL, 1, &device, &count) != CL_SUCCESS)
        return skip("no OpenCL device on the first platform");
    cl_int cl_err;
    cl_context cl_ctx = clCreateContext(NULL, 1, &device, NULL, NULL, &cl_err);
    if (!cl_ctx)
        return skip("clCreateContext failed");
    cl_command_queue queue = clCreateCommandQueue(cl_ctx, device, 0, &cl_err);
    if (!queue)
        return skip("clCreateCommandQueue failed");

    rsmooth_error err;
    rsmooth_error_init(&err);
    rsmooth_context *ctx = NULL;
    rsmooth_status st = rsmooth_context_create_from_queue(queue, NULL, &ctx, &err);
    clReleaseCommandQueue(queue); /* ours: rsmooth holds its own reference until destroyed */
    clReleaseContext(cl_ctx);
    if (st == RSMOOTH_OK) {
        rsmooth_context_info info = {.struct_size = sizeof info};
        rsmooth_context_get_info(ctx, &info);
        printf("device: %s (program build %.0f ms)\n", info.device_name, info.build_ms);
        st = rsmooth_smooth(ctx, RSMOOTH_FLOAT64, xyz, 6, indices, 8, NULL, out, NULL, &err);
    }
    rsmooth_context_destroy(ctx); /* releases the queue and context it retained */
    if (st == RSMOOTH_OK)
        st = rsmooth_smooth(NULL, RSMOOTH_FLOAT64, xyz, 6, indices, 8, NULL, expected, NULL, &err);
    if (st != RSMOOTH_OK) {
        fprintf(stderr, "example_own_context: %s: %s\n", rsmooth_status_str(st), err.message);
        return EXIT_FAILURE;
    }
    double moved = 0, apart = 0;
    for (int i = 0; i < 18; i++) {
        moved = fmax(moved, fabs(out[i] - xyz[i]));
        apart = fmax(apart, fabs(out[i] - expected[i]));
    }
    printf("largest move %.4f, largest difference from the reference path %.1e\n", moved, apart);
    return apart < 1e-4 ? EXIT_SUCCESS : EXIT_FAILURE;
}
