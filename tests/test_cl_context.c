/* The OpenCL context: device choice by spec, a caller's own queue (retained, never owned),
 * bit-identical repeated runs, threads sharing one context, calls from a call's own progress
 * callback refused at once instead of deadlocking, and argument errors that leave the output
 * untouched. */
#define _POSIX_C_SOURCE 200809L
#include "mesh_shapes.h"
#include "rsmooth_cl.h"
#include "test_cl_util.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

static void smooth_cube(rsmooth_context *ctx, const shape_mesh *m, double *out) {
    rsmooth_error err;
    rsmooth_params p;
    rsmooth_params_init(&p);
    float *conf = malloc(m->vertex_count * sizeof *conf);
    CHECK(conf);
    CHECK_STATUS(rsmooth_smooth(ctx, RSMOOTH_FLOAT64, m->xyz, m->vertex_count, m->indices,
                                m->triangle_count, &p, out, OUTPUTS(NULL, conf, NULL), &err),
                 RSMOOTH_OK);
    free(conf);
}

/* Records progress reports: count, last fraction, and whether they ever went backwards. */
typedef struct progress_log {
    int calls;
    double last;
    int backwards;
} progress_log;

static void record_progress(void *user, double fraction) {
    progress_log *log = user;
    if (fraction < log->last || fraction < 0 || fraction > 1)
        log->backwards = 1;
    log->last = fraction;
    log->calls++;
}

/* Progress reports arrive in order, end at 1, and slicing the kernels changes nothing. */
static void check_progress(rsmooth_context *ctx, const shape_mesh *m, const double *expected) {
    size_t n = 3 * m->vertex_count;
    double *out = malloc(n * sizeof *out);
    CHECK(out);
    rsmooth_params p;
    rsmooth_params_init(&p);
    progress_log log = {0, 0, 0};
    p.progress = record_progress;
    p.progress_user = &log;
    rsmooth_error err;
    CHECK_STATUS(rsmooth_smooth(ctx, RSMOOTH_FLOAT64, m->xyz, m->vertex_count, m->indices,
                                m->triangle_count, &p, out, NULL, &err),
                 RSMOOTH_OK);
    printf("progress (OpenCL): %d reports, last %.3f\n", log.calls, log.last);
    CHECK(log.calls >= 10 && !log.backwards && log.last == 1.0);
    CHECK(memcmp(out, expected, n * sizeof *out) == 0);
    log = (progress_log){0, 0, 0};
    CHECK_STATUS(rsmooth_smooth(NULL, RSMOOTH_FLOAT64, m->xyz, m->vertex_count, m->indices,
                                m->triangle_count, &p, out, NULL, &err),
                 RSMOOTH_OK);
    printf("progress (reference): %d reports, last %.3f\n", log.calls, log.last);
    CHECK(log.calls >= 3 && !log.backwards && log.last == 1.0);
    free(out);
}

/* Threads sharing one context: each thread filters its own noisy cube again and again; every
 * result must equal the same call made alone (the context serialises its calls). */
#define SHARING_THREADS 8
#define CALLS_PER_THREAD 10

typedef struct sharer {
    rsmooth_context *ctx;
    const shape_mesh *mesh;
    const double *alone; /* the result of the same call with no other thread running */
    double *out;
    int wrong, failed;
} sharer;

static void *share_context(void *arg) {
    sharer *s = arg;
    size_t n = 3 * s->mesh->vertex_count;
    for (int call = 0; call < CALLS_PER_THREAD; call++) {
        rsmooth_error err;
        if (rsmooth_smooth(s->ctx, RSMOOTH_FLOAT64, s->mesh->xyz, s->mesh->vertex_count,
                           s->mesh->indices, s->mesh->triangle_count, NULL, s->out, NULL,
                           &err) != RSMOOTH_OK)
            s->failed++;
        else if (memcmp(s->out, s->alone, n * sizeof *s->out) != 0)
            s->wrong++;
    }
    return NULL;
}

static void check_shared_context(rsmooth_context *ctx) {
    shape_mesh meshes[SHARING_THREADS];
    sharer sharers[SHARING_THREADS];
    pthread_t threads[SHARING_THREADS];
    for (int t = 0; t < SHARING_THREADS; t++) {
        /* different sizes and noise, so a mixed-up call shows */
        CHECK(shape_cube(&meshes[t], 24 + 2 * t, 1.0) == 0);
        CHECK(shape_add_normal_noise(&meshes[t], 0.3, 100 + (uint64_t)t) == 0);
        size_t n = 3 * meshes[t].vertex_count;
        double *alone = malloc(n * sizeof *alone), *out = malloc(n * sizeof *out);
        CHECK(alone && out);
        CHECK_STATUS(rsmooth_smooth(ctx, RSMOOTH_FLOAT64, meshes[t].xyz, meshes[t].vertex_count,
                                    meshes[t].indices, meshes[t].triangle_count, NULL, alone, NULL,
                                    NULL),
                     RSMOOTH_OK);
        sharers[t] = (sharer){ctx, &meshes[t], alone, out, 0, 0};
    }
    for (int t = 0; t < SHARING_THREADS; t++)
        CHECK(pthread_create(&threads[t], NULL, share_context, &sharers[t]) == 0);
    int wrong = 0, failed = 0;
    for (int t = 0; t < SHARING_THREADS; t++) {
        CHECK(pthread_join(threads[t], NULL) == 0);
        wrong += sharers[t].wrong;
        failed += sharers[t].failed;
        free((double *)sharers[t].alone);
        free(sharers[t].out);
        shape_free(&meshes[t]);
    }
    printf("%d threads sharing one context, %d calls: %d failed, %d differ from the call made "
           "alone\n",
           SHARING_THREADS, SHARING_THREADS * CALLS_PER_THREAD, failed, wrong);
    CHECK_EQ_INT(failed, 0);
    CHECK_EQ_INT(wrong, 0);
}

/* A progress callback that calls back into the context its call runs on: every entry
 * point must answer at once instead of waiting for the lock its own call holds. */
typedef struct reentry {
    rsmooth_context *ctx, *other;
    const shape_mesh *m;
    double *scratch;
    int calls;
    rsmooth_status nested, piece, nested_other;
    char message[256];
    uint64_t budget;
    unsigned threads;
} reentry;

static void call_back_in(void *user, double fraction) {
    (void)fraction;
    reentry *r = user;
    if (r->calls++)
        return;
    rsmooth_error err;
    r->nested = rsmooth_smooth(r->ctx, RSMOOTH_FLOAT64, r->m->xyz, r->m->vertex_count,
                               r->m->indices, r->m->triangle_count, NULL, r->scratch, NULL, &err);
    snprintf(r->message, sizeof r->message, "%s", err.message);
    rsmooth_piece_info info;
    rsmooth_piece_info_init(&info);
    info.core_count = r->m->vertex_count;
    r->piece = rsmooth_smooth_piece(r->ctx, r->m->xyz, r->m->vertex_count, r->m->indices,
                                    r->m->triangle_count, &info, NULL, r->scratch, NULL, &err);
    /* another context is free: its call runs */
    r->nested_other =
        rsmooth_smooth(r->other, RSMOOTH_FLOAT64, r->m->xyz, r->m->vertex_count, r->m->indices,
                       r->m->triangle_count, NULL, r->scratch, NULL, &err);
    /* the info answers from inside the call, and destroy leaves it alone */
    rsmooth_context_info about = {.struct_size = sizeof about};
    if (rsmooth_context_get_info(r->ctx, &about) == RSMOOTH_OK) {
        r->budget = about.memory_budget;
        r->threads = about.host_threads + 1; /* +1: answered */
    }
    rsmooth_context_destroy(r->ctx);
}

static void check_reentry(rsmooth_context *ctx, const shape_mesh *m, const double *expected) {
    size_t n = 3 * m->vertex_count;
    double *out = malloc(n * sizeof *out), *scratch = malloc(n * sizeof *scratch);
    CHECK(out && scratch);
    reentry r;
    memset(&r, 0, sizeof r);
    r.ctx = ctx;
    r.m = m;
    r.scratch = scratch;
    rsmooth_error err;
    CHECK_STATUS(rsmooth_context_create(NULL, &r.other, &err), RSMOOTH_OK);
    rsmooth_params p;
    rsmooth_params_init(&p);
    p.progress = call_back_in;
    p.progress_user = &r;
    alarm(120); /* a deadlock fails the test instead of hanging it */
    CHECK_STATUS(rsmooth_smooth(ctx, RSMOOTH_FLOAT64, m->xyz, m->vertex_count, m->indices,
                                m->triangle_count, &p, out, NULL, &err),
                 RSMOOTH_OK);
    alarm(0);
    printf("a call from its own progress callback: %s (%s); a piece: %s; another context: %s\n",
           rsmooth_status_str(r.nested), r.message, rsmooth_status_str(r.piece),
           rsmooth_status_str(r.nested_other));
    CHECK(r.calls > 0);
    CHECK_STATUS(r.nested, RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(r.message, "callback") != NULL);
    CHECK_STATUS(r.piece, RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK_STATUS(r.nested_other, RSMOOTH_OK);
    CHECK(memcmp(scratch, expected, n * sizeof *out) == 0);
    CHECK(r.budget > 0);
    CHECK(memcmp(out, expected, n * sizeof *out) == 0); /* the outer call as if alone */
    /* the context still works afterwards */
    CHECK_STATUS(rsmooth_smooth(ctx, RSMOOTH_FLOAT64, m->xyz, m->vertex_count, m->indices,
                                m->triangle_count, NULL, out, NULL, &err),
                 RSMOOTH_OK);
    CHECK(memcmp(out, expected, n * sizeof *out) == 0);
    rsmooth_context_destroy(r.other);
    free(out);
    free(scratch);
}

int main(void) {
    rsmooth_context *ctx = open_test_context();
    shape_mesh cube;
    CHECK(shape_cube(&cube, 16, 1.0) == 0);
    CHECK(shape_add_normal_noise(&cube, 0.3, 3) == 0);
    size_t n = 3 * cube.vertex_count;
    double *a = malloc(n * sizeof *a), *b = malloc(n * sizeof *b), *c = malloc(n * sizeof *c);
    CHECK(a && b && c);

    /* Two runs on one device: bit-identical. */
    smooth_cube(ctx, &cube, a);
    smooth_cube(ctx, &cube, b);
    CHECK(memcmp(a, b, n * sizeof *a) == 0);
    printf("two runs: bit-identical\n");
    check_shared_context(ctx);
    {
        double *plain = malloc(n * sizeof *plain);
        CHECK(plain);
        CHECK_STATUS(rsmooth_smooth(ctx, RSMOOTH_FLOAT64, cube.xyz, cube.vertex_count, cube.indices,
                                    cube.triangle_count, NULL, plain, NULL, NULL),
                     RSMOOTH_OK);
        check_reentry(ctx, &cube, plain);
        free(plain);
    }

    /* One host thread or several: the same bits (static chunks, fixed-size partial sums). */
    {
        shape_mesh big;
        CHECK(shape_capped_cylinder(&big, 1.0, 1.5, 60000) == 0);
        CHECK(shape_add_normal_noise(&big, 0.3, 5) == 0);
        size_t nb = 3 * big.vertex_count;
        double *one = malloc(nb * sizeof *one), *many = malloc(nb * sizeof *many);
        CHECK(one && many);
        rsmooth_error err;
        setenv("RSMOOTH_HOST_THREADS", "1", 1); /* read when a context is made */
        rsmooth_context *single = open_test_context();
        CHECK(context_info(single).host_threads == 1);
        CHECK_STATUS(rsmooth_smooth(single, RSMOOTH_FLOAT64, big.xyz, big.vertex_count, big.indices,
                                    big.triangle_count, NULL, one, NULL, &err),
                     RSMOOTH_OK);
        rsmooth_context_destroy(single);
        unsetenv("RSMOOTH_HOST_THREADS");
        rsmooth_context_options five = {.struct_size = sizeof five, .host_threads = 5};
        rsmooth_context *several = NULL;
        CHECK_STATUS(rsmooth_context_create(&five, &several, &err), RSMOOTH_OK);
        CHECK(context_info(several).host_threads == 5);
        CHECK_STATUS(rsmooth_smooth(several, RSMOOTH_FLOAT64, big.xyz, big.vertex_count,
                                    big.indices, big.triangle_count, NULL, many, NULL, &err),
                     RSMOOTH_OK);
        rsmooth_context_destroy(several);
        CHECK(memcmp(one, many, nb * sizeof *one) == 0);
        printf("1 and 5 host threads (%zu triangles): bit-identical\n", big.triangle_count);
        free(one);
        free(many);
        shape_free(&big);
    }
    {
        shape_mesh big;
        CHECK(shape_sphere(&big, 6, 1.0) == 0); /* 40962 vertices: enough to slice */
        CHECK(shape_add_normal_noise(&big, 0.2, 5) == 0);
        double *plain = malloc(3 * big.vertex_count * sizeof *plain);
        CHECK(plain);
        rsmooth_params p;
        rsmooth_params_init(&p);
        CHECK_STATUS(rsmooth_smooth(ctx, RSMOOTH_FLOAT64, big.xyz, big.vertex_count, big.indices,
                                    big.triangle_count, &p, plain, NULL, NULL),
                     RSMOOTH_OK);
        check_progress(ctx, &big, plain);
        free(plain);
        shape_free(&big);
    }

    /* Device specs: "cpu" and "0:0" name PoCL's device here; a name that matches nothing fails. */
    rsmooth_error err;
    rsmooth_context *other = NULL;
    rsmooth_context_options first = {.struct_size = sizeof first, .device = "0:0"};
    CHECK_STATUS(rsmooth_context_create(&first, &other, &err), RSMOOTH_OK);
    printf("device 0:0 is %s\n", context_info(other).device_name);
    rsmooth_device_info devices[8];
    size_t device_count = rsmooth_list_devices(devices, 8);
    CHECK(device_count >= 1);
    CHECK(devices[0].platform_index == 0 && devices[0].device_index == 0);
    CHECK(strcmp(devices[0].name, context_info(other).device_name) == 0);
    CHECK(devices[0].compute_units >= 1 && devices[0].global_memory > 0);
    /* every device has its version (PoCL's is 65 characters: read whole, then cut to the field;
     * a 63-byte query came back empty) */
    for (size_t i = 0; i < device_count && i < 8; i++)
        CHECK(strncmp(devices[i].version, "OpenCL ", 7) == 0 &&
              strlen(devices[i].version) < sizeof devices[i].version);
    printf("devices: %zu, first %s (%s, %u compute units, %s)\n", device_count, devices[0].name,
           devices[0].type, devices[0].compute_units, devices[0].version);
    /* rsmooth_device_version: the whole CL_DEVICE_VERSION as the driver gives it (asked here
     * straight from OpenCL), snprintf's contract on short buffers, "" and 0 for no device */
    {
        cl_device_id device = NULL;
        clGetCommandQueueInfo(rsmooth_context_queue(other), CL_QUEUE_DEVICE, sizeof device, &device,
                              NULL);
        char truth[1024] = "", whole[1024], cut[8] = "xxxxxxx";
        CHECK(clGetDeviceInfo(device, CL_DEVICE_VERSION, sizeof truth, truth, NULL) == CL_SUCCESS);
        size_t length = rsmooth_device_version(0, 0, whole, sizeof whole);
        CHECK(length == strlen(truth) && strcmp(whole, truth) == 0);
        CHECK(strncmp(whole, devices[0].version, sizeof devices[0].version - 1) == 0);
        CHECK(rsmooth_device_version(0, 0, NULL, 0) == length);
        CHECK(rsmooth_device_version(0, 0, cut, sizeof cut) == length);
        CHECK(strlen(cut) == sizeof cut - 1 && strncmp(cut, truth, sizeof cut - 1) == 0);
        CHECK(rsmooth_device_version(99, 0, cut, sizeof cut) == 0 && cut[0] == '\0');
        CHECK(rsmooth_device_version(0, -1, whole, sizeof whole) == 0 && whole[0] == '\0');
        printf("device 0:0 version, whole: %s (%zu bytes)\n", truth, length);
    }
    smooth_cube(other, &cube, c);
    rsmooth_context_destroy(other);
    other = NULL;
    rsmooth_context_options nowhere = {.struct_size = sizeof nowhere,
                                       .device = "no such device anywhere"};
    CHECK_STATUS(rsmooth_context_create(&nowhere, &other, &err), RSMOOTH_ERROR_NO_DEVICE);
    CHECK(other == NULL && strstr(err.message, "no such device anywhere"));
    nowhere.device = "99:0";
    CHECK_STATUS(rsmooth_context_create(&nowhere, &other, &err), RSMOOTH_ERROR_NO_DEVICE);
    printf("unknown device: %s\n", err.message);

    /* A caller's queue: the context derives context and device from it and retains it. The
     * caller may drop its own reference while the rsmooth context lives. PoCL releases its own
     * internal references to a queue lazily, so the count is polled back to where it started. */
    {
        cl_command_queue base = rsmooth_context_queue(ctx);
        cl_context cl_ctx = NULL;
        cl_device_id device = NULL;
        clGetCommandQueueInfo(base, CL_QUEUE_CONTEXT, sizeof cl_ctx, &cl_ctx, NULL);
        clGetCommandQueueInfo(base, CL_QUEUE_DEVICE, sizeof device, &device, NULL);
        cl_int cl_err = CL_SUCCESS;
        cl_command_queue queue = clCreateCommandQueue(cl_ctx, device, 0, &cl_err);
        CHECK(cl_err == CL_SUCCESS);
        cl_uint refs_before = 0, refs_during = 0, refs_after = 0;
        clGetCommandQueueInfo(queue, CL_QUEUE_REFERENCE_COUNT, sizeof refs_before, &refs_before,
                              NULL);
        CHECK_STATUS(rsmooth_context_create_from_queue(queue, NULL, &other, &err), RSMOOTH_OK);
        clGetCommandQueueInfo(queue, CL_QUEUE_REFERENCE_COUNT, sizeof refs_during, &refs_during,
                              NULL);
        CHECK_EQ_INT(refs_during, refs_before + 1);
        CHECK(rsmooth_context_queue(other) == queue);
        smooth_cube(other, &cube, c);
        CHECK(memcmp(a, c, n * sizeof *a) == 0); /* same device, same program: same bits */
        rsmooth_context_destroy(other);
        clFinish(queue);
        for (int i = 0; i < 200; i++) {
            clGetCommandQueueInfo(queue, CL_QUEUE_REFERENCE_COUNT, sizeof refs_after, &refs_after,
                                  NULL);
            if (refs_after == refs_before)
                break;
            nanosleep(&(struct timespec){0, 10000000}, NULL);
        }
        CHECK_EQ_INT(refs_after, refs_before);
        clReleaseCommandQueue(queue);
        CHECK_STATUS(rsmooth_context_create_from_queue(NULL, NULL, &other, &err),
                     RSMOOTH_ERROR_INVALID_ARGUMENT);
        printf("caller's queue: retained (%u -> %u) and released (%u), same result\n", refs_before,
               refs_during, refs_after);
    }

    /* Argument errors: status, message, and the output left as it was. */
    rsmooth_params p;
    rsmooth_params_init(&p);
    memset(c, 0x5a, n * sizeof *c);
    memcpy(b, c, n * sizeof *c);
    uint32_t bad = cube.indices[5];
    cube.indices[5] = (uint32_t)cube.vertex_count;
    CHECK_STATUS(rsmooth_smooth(ctx, RSMOOTH_FLOAT64, cube.xyz, cube.vertex_count, cube.indices,
                                cube.triangle_count, &p, c, NULL, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    printf("index out of range: %s\n", err.message);
    cube.indices[5] = bad;
    p.sigma_f = NAN;
    CHECK_STATUS(rsmooth_smooth(ctx, RSMOOTH_FLOAT64, cube.xyz, cube.vertex_count, cube.indices,
                                cube.triangle_count, &p, c, NULL, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    printf("sigma_f NaN: %s\n", err.message);
    rsmooth_params_init(&p);
    double saved = cube.xyz[7];
    cube.xyz[7] = INFINITY;
    CHECK_STATUS(rsmooth_smooth(ctx, RSMOOTH_FLOAT64, cube.xyz, cube.vertex_count, cube.indices,
                                cube.triangle_count, &p, c, NULL, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    printf("infinite coordinate: %s\n", err.message);
    cube.xyz[7] = saved;
    CHECK_STATUS(rsmooth_smooth(ctx, RSMOOTH_FLOAT64, cube.xyz, cube.vertex_count, cube.indices,
                                cube.triangle_count, &p, cube.xyz, NULL, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK(memcmp(b, c, n * sizeof *c) == 0);
    printf("bad arguments: output untouched\n");

    /* Developer override: kernels from a directory. The source tree's copies give the same bits;
     * a broken kernel gives a build error with the compiler's log; a missing directory an I/O
     * error. */
    setenv("RSMOOTH_KERNEL_DIR", RSMOOTH_KERNEL_SOURCE_DIR, 1);
    CHECK_STATUS(rsmooth_context_create(NULL, &other, &err), RSMOOTH_OK);
    smooth_cube(other, &cube, c);
    CHECK(memcmp(a, c, n * sizeof *a) == 0);
    rsmooth_context_destroy(other);
    char broken_dir[] = "/tmp/rsmooth-broken-kernels-XXXXXX";
    CHECK(mkdtemp(broken_dir) != NULL);
    static const char *const names[] = {"common.cl", "mollify.cl", "bilateral.cl", "estimate.cl",
                                        "stage.cl",  "grid.cl",    "learned.cl"};
    const int files = (int)(sizeof names / sizeof *names);
    for (int i = 0; i < files; i++) {
        char path[256];
        snprintf(path, sizeof path, "%s/%s", broken_dir, names[i]);
        FILE *f = fopen(path, "w");
        CHECK(f);
        /* estimate.cl: in every device's program (grid.cl only in some) */
        fputs(strcmp(names[i], "estimate.cl") == 0
                  ? "__kernel void robust_vertex(void) { this is not C; }\n"
                  : "\n",
              f);
        fclose(f);
    }
    setenv("RSMOOTH_KERNEL_DIR", broken_dir, 1);
    CHECK_STATUS(rsmooth_context_create(NULL, &other, &err), RSMOOTH_ERROR_KERNEL_BUILD);
    CHECK(other == NULL && err.build_log[0] != '\0');
    printf("broken kernel: %s; log starts: %.60s\n", err.message, err.build_log);
    for (int i = 0; i < files; i++) {
        char path[256];
        snprintf(path, sizeof path, "%s/%s", broken_dir, names[i]);
        remove(path);
    }
    CHECK_STATUS(rsmooth_context_create(NULL, &other, &err), RSMOOTH_ERROR_IO);
    printf("missing kernel directory: %s\n", err.message);
    rmdir(broken_dir);
    unsetenv("RSMOOTH_KERNEL_DIR");

    free(a);
    free(b);
    free(c);
    shape_free(&cube);
    rsmooth_context_destroy(ctx);
    return 0;
}
