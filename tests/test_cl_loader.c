/* The OpenCL loader, opened at run time: `test_cl_loader` makes it unreachable
 * (RSMOOTH_OPENCL_LIBRARY names no file) and checks that every OpenCL entry point says so while the
 * reference path works; `test_cl_loader real` checks that the loader found by default runs the
 * OpenCL path (skipped without a device, as the other OpenCL tests). One process each: the loader
 * is opened once per process. */
#define _POSIX_C_SOURCE 200809L
#include "mesh_shapes.h"
#include "rsmooth_cl.h"
#include "test_cl_util.h"

#include <pthread.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define MISSING "/nonexistent/libOpenCL.so.1"
#define THREADS 4

/* A context on `device` fails as the missing loader does: NO_DEVICE naming the loader's file. */
static void check_refused(const char *device) {
    rsmooth_context *ctx = (rsmooth_context *)&ctx; /* not NULL: the call must clear it */
    rsmooth_error err;
    rsmooth_context_options options = {.struct_size = sizeof options, .device = device};
    CHECK_STATUS(rsmooth_context_create(&options, &ctx, &err), RSMOOTH_ERROR_NO_DEVICE);
    CHECK(ctx == NULL);
    CHECK_EQ_INT(err.status, RSMOOTH_ERROR_NO_DEVICE);
    CHECK(strstr(err.message, "loader") != NULL);
    CHECK(strstr(err.message, MISSING) != NULL);
    CHECK(strcmp(err.where, "rsmooth_context_create") == 0);
}

static void *refuse_concurrently(void *unused) {
    (void)unused;
    check_refused("auto");
    return NULL;
}

/* The reference path needs no loader. */
static void check_reference(void) {
    shape_mesh cube;
    CHECK(shape_cube(&cube, 6, 1.0) == 0);
    CHECK(shape_add_normal_noise(&cube, 0.2 * shape_mean_edge_length(&cube), 7) == 0);
    double *out = malloc(3 * cube.vertex_count * sizeof *out);
    CHECK(out);
    rsmooth_error err;
    CHECK_STATUS(rsmooth_smooth(NULL, RSMOOTH_FLOAT64, cube.xyz, cube.vertex_count, cube.indices,
                                cube.triangle_count, NULL, out, NULL, &err),
                 RSMOOTH_OK);
    for (size_t i = 0; i < 3 * cube.vertex_count; i++)
        CHECK(isfinite(out[i]));
    free(out);
    shape_free(&cube);
}

static int missing_loader(void) {
    CHECK(setenv("RSMOOTH_OPENCL_LIBRARY", MISSING, 1) == 0);
    /* the first use from several threads at once: one load, the same answer for each */
    pthread_t threads[THREADS];
    for (int t = 0; t < THREADS; t++)
        CHECK(pthread_create(&threads[t], NULL, refuse_concurrently, NULL) == 0);
    for (int t = 0; t < THREADS; t++)
        CHECK(pthread_join(threads[t], NULL) == 0);
    check_refused("cpu");
    check_refused(NULL);
    check_refused("0:0");

    rsmooth_error err;
    rsmooth_context *ctx = NULL;
    /* a caller's queue (never touched: the loader comes first) */
    cl_command_queue queue = (cl_command_queue)(uintptr_t)1;
    CHECK_STATUS(rsmooth_context_create_from_queue(queue, NULL, &ctx, &err),
                 RSMOOTH_ERROR_NO_DEVICE);
    CHECK(ctx == NULL);
    CHECK(strstr(err.message, MISSING) != NULL);
    printf("refused: %s\n", err.message);

    rsmooth_device_info devices[4];
    CHECK_EQ_INT(rsmooth_list_devices(devices, 4), 0);
    CHECK_EQ_INT(rsmooth_list_devices(NULL, 0), 0);
    char version[16] = "x";
    CHECK_EQ_INT(rsmooth_device_version(0, 0, version, sizeof version), 0);
    CHECK(version[0] == '\0');
    check_reference();
    printf("missing loader: OpenCL refused with the reason, reference path works\n");
    return 0;
}

static int real_loader(void) {
    CHECK(unsetenv("RSMOOTH_OPENCL_LIBRARY") == 0);
    rsmooth_context *ctx = open_test_context(); /* exits 77 without a device */
    CHECK(rsmooth_list_devices(NULL, 0) > 0);
    shape_mesh cube;
    CHECK(shape_cube(&cube, 6, 1.0) == 0);
    CHECK(shape_add_normal_noise(&cube, 0.2 * shape_mean_edge_length(&cube), 7) == 0);
    size_t n = 3 * cube.vertex_count;
    double *out = malloc(n * sizeof *out), *ref = malloc(n * sizeof *ref);
    CHECK(out && ref);
    rsmooth_error err;
    CHECK_STATUS(rsmooth_smooth(ctx, RSMOOTH_FLOAT64, cube.xyz, cube.vertex_count, cube.indices,
                                cube.triangle_count, NULL, out, NULL, &err),
                 RSMOOTH_OK);
    CHECK_STATUS(rsmooth_smooth(NULL, RSMOOTH_FLOAT64, cube.xyz, cube.vertex_count, cube.indices,
                                cube.triangle_count, NULL, ref, NULL, &err),
                 RSMOOTH_OK);
    double edge = shape_mean_edge_length(&cube), worst = 0;
    for (size_t i = 0; i < n; i++)
        worst = fmax(worst, fabs(out[i] - ref[i]));
    printf("OpenCL vs reference: max %.3g mean edge lengths\n", worst / edge);
    CHECK_LE(worst, 1e-3 * edge);
    free(out);
    free(ref);
    shape_free(&cube);
    rsmooth_context_destroy(ctx);
    return 0;
}

int main(int argc, char **argv) {
    if (argc == 1)
        return missing_loader();
    if (argc == 2 && strcmp(argv[1], "real") == 0)
        return real_loader();
    fprintf(stderr, "usage: test_cl_loader [real]\n");
    return 2;
}
