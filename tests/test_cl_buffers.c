/* rsmooth_smooth_cl: positions in and out of the caller's OpenCL buffers on its own queue. The
 * result read back equals rsmooth_smooth's on host arrays bit for bit, in float32 and float64,
 * in place too, on the path that writes it on the device (one whole run without the fold guard:
 * the report's pair counts are 0) and on the paths that upload the host's (the guard, a move
 * mask, tiles); bad
 * buffers (NULL, too small, another OpenCL context) are refused by name and leave the output
 * untouched. */
#include "mesh_shapes.h"
#include "rsmooth_cl.h"
#include "test_cl_util.h"

#include <stdlib.h>
#include <string.h>

typedef struct fixture {
    rsmooth_context *ctx; /* on `queue` */
    cl_context context;
    cl_command_queue queue;
} fixture;

static cl_mem buffer_with(const fixture *fx, size_t bytes, const void *host) {
    cl_int err = CL_SUCCESS;
    cl_mem mem = clCreateBuffer(fx->context, CL_MEM_READ_WRITE | (host ? CL_MEM_COPY_HOST_PTR : 0),
                                bytes, (void *)host, &err);
    CHECK(err == CL_SUCCESS && mem);
    return mem;
}

static void read_back(const fixture *fx, cl_mem mem, size_t bytes, void *host) {
    CHECK(clEnqueueReadBuffer(fx->queue, mem, CL_TRUE, 0, bytes, host, 0, NULL, NULL) ==
          CL_SUCCESS);
}

/* The mesh's positions in `scalar`. */
static void *positions_as(const shape_mesh *m, rsmooth_scalar scalar) {
    size_t n = 3 * m->vertex_count;
    void *out = malloc(n * (scalar == RSMOOTH_FLOAT32 ? sizeof(float) : sizeof(double)));
    CHECK(out);
    for (size_t i = 0; i < n; i++) {
        if (scalar == RSMOOTH_FLOAT32)
            ((float *)out)[i] = (float)m->xyz[i];
        else
            ((double *)out)[i] = m->xyz[i];
    }
    return out;
}

/* rsmooth_smooth_cl against rsmooth_smooth with the same params: the same bits. Returns the
 * report's robust pair count (0: the result was written on the device). */
static uint64_t check_same(const fixture *fx, const shape_mesh *m, rsmooth_scalar scalar,
                           const rsmooth_params *p, int in_place, const char *what) {
    size_t record = scalar == RSMOOTH_FLOAT32 ? sizeof(float) : sizeof(double);
    size_t bytes = 3 * m->vertex_count * record;
    void *in = positions_as(m, scalar);
    void *expected = malloc(bytes), *got = malloc(bytes);
    CHECK(expected && got);
    rsmooth_error err;
    rsmooth_status st = rsmooth_smooth(fx->ctx, scalar, in, m->vertex_count, m->indices,
                                       m->triangle_count, p, expected, NULL, &err);
    if (st != RSMOOTH_OK)
        printf("%s: rsmooth_smooth: %s\n", what, err.message);
    CHECK_STATUS(st, RSMOOTH_OK);
    cl_mem din = buffer_with(fx, bytes, in);
    memset(got, 0x5a, bytes); /* garbage the call must overwrite */
    cl_mem dout = in_place ? din : buffer_with(fx, bytes, got);
    rsmooth_report report;
    rsmooth_report_init(&report);
    CHECK_STATUS(rsmooth_smooth_cl(fx->ctx, scalar, din, m->vertex_count, m->indices,
                                   m->triangle_count, p, dout, &report, &err),
                 RSMOOTH_OK);
    read_back(fx, dout, bytes, got);
    int same = memcmp(got, expected, bytes) == 0;
    printf("%-34s %s %s: %s (pairs in report %llu, tiles %zu)\n", what,
           scalar == RSMOOTH_FLOAT32 ? "float32" : "float64", in_place ? "in place" : "",
           same ? "bit-identical" : "DIFFERENT", (unsigned long long)report.pairs_robust,
           report.tiles);
    CHECK(same);
    if (!in_place)
        clReleaseMemObject(dout);
    clReleaseMemObject(din);
    free(in);
    free(expected);
    free(got);
    return report.pairs_robust;
}

static void check_errors(const fixture *fx, const shape_mesh *m) {
    size_t n = m->vertex_count, bytes = 3 * n * sizeof(float);
    float *in = positions_as(m, RSMOOTH_FLOAT32);
    float *marker = malloc(bytes), *got = malloc(bytes);
    CHECK(marker && got);
    memset(marker, 0x5a, bytes);
    cl_mem din = buffer_with(fx, bytes, in), dout = buffer_with(fx, bytes, marker);
    cl_mem small = buffer_with(fx, bytes - 4, NULL);
    rsmooth_error err;

    CHECK_STATUS(rsmooth_smooth_cl(fx->ctx, RSMOOTH_FLOAT32, din, n, m->indices, m->triangle_count,
                                   NULL, small, NULL, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    printf("output too small: %s\n", err.message);
    CHECK(strstr(err.message, "out_positions holds") != NULL);
    CHECK_STATUS(rsmooth_smooth_cl(fx->ctx, RSMOOTH_FLOAT32, small, n, m->indices,
                                   m->triangle_count, NULL, dout, NULL, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    printf("input too small: %s\n", err.message);
    CHECK(strstr(err.message, "positions holds") != NULL);
    /* float64 needs twice the bytes the float32 buffers hold */
    CHECK_STATUS(rsmooth_smooth_cl(fx->ctx, RSMOOTH_FLOAT64, din, n, m->indices, m->triangle_count,
                                   NULL, dout, NULL, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    printf("float64 on float32's bytes: %s\n", err.message);
    CHECK_STATUS(rsmooth_smooth_cl(fx->ctx, RSMOOTH_FLOAT32, NULL, n, m->indices, m->triangle_count,
                                   NULL, dout, NULL, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(err.message, "positions is NULL") != NULL);
    CHECK_STATUS(rsmooth_smooth_cl(NULL, RSMOOTH_FLOAT32, din, n, m->indices, m->triangle_count,
                                   NULL, dout, NULL, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK_STATUS(rsmooth_smooth_cl(fx->ctx, (rsmooth_scalar)7, din, n, m->indices,
                                   m->triangle_count, NULL, dout, NULL, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);

    /* a buffer of another OpenCL context on the same device */
    cl_device_id device = NULL;
    CHECK(clGetCommandQueueInfo(fx->queue, CL_QUEUE_DEVICE, sizeof device, &device, NULL) ==
          CL_SUCCESS);
    cl_int cl_err = CL_SUCCESS;
    cl_context foreign = clCreateContext(NULL, 1, &device, NULL, NULL, &cl_err);
    CHECK(cl_err == CL_SUCCESS);
    cl_mem elsewhere =
        clCreateBuffer(foreign, CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, bytes, in, &cl_err);
    CHECK(cl_err == CL_SUCCESS);
    CHECK_STATUS(rsmooth_smooth_cl(fx->ctx, RSMOOTH_FLOAT32, elsewhere, n, m->indices,
                                   m->triangle_count, NULL, dout, NULL, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    printf("another context's buffer: %s\n", err.message);
    CHECK(strstr(err.message, "another OpenCL context") != NULL);
    CHECK_STATUS(rsmooth_smooth_cl(fx->ctx, RSMOOTH_FLOAT32, din, n, m->indices, m->triangle_count,
                                   NULL, elsewhere, NULL, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(err.message, "out_positions belongs to another") != NULL);

    /* a bad index: the library's own message, the output untouched */
    uint32_t keep = m->indices[4];
    m->indices[4] = (uint32_t)n;
    CHECK_STATUS(rsmooth_smooth_cl(fx->ctx, RSMOOTH_FLOAT32, din, n, m->indices, m->triangle_count,
                                   NULL, dout, NULL, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    printf("index out of range: %s\n", err.message);
    m->indices[4] = keep;
    read_back(fx, dout, bytes, got);
    CHECK(memcmp(got, marker, bytes) == 0);
    printf("errors: output untouched\n");

    clReleaseMemObject(elsewhere);
    clReleaseContext(foreign);
    clReleaseMemObject(small);
    clReleaseMemObject(din);
    clReleaseMemObject(dout);
    free(in);
    free(marker);
    free(got);
}

int main(void) {
    rsmooth_context *base = open_test_context();
    fixture fx;
    cl_device_id device = NULL;
    CHECK(clGetCommandQueueInfo(rsmooth_context_queue(base), CL_QUEUE_CONTEXT, sizeof fx.context,
                                &fx.context, NULL) == CL_SUCCESS);
    CHECK(clGetCommandQueueInfo(rsmooth_context_queue(base), CL_QUEUE_DEVICE, sizeof device,
                                &device, NULL) == CL_SUCCESS);
    cl_int cl_err = CL_SUCCESS;
    fx.queue = clCreateCommandQueue(fx.context, device, 0, &cl_err);
    CHECK(cl_err == CL_SUCCESS);
    rsmooth_error err;
    CHECK_STATUS(rsmooth_context_create_from_queue(fx.queue, NULL, &fx.ctx, &err), RSMOOTH_OK);
    cl_device_fp_config fp64 = 0;
    clGetDeviceInfo(device, CL_DEVICE_DOUBLE_FP_CONFIG, sizeof fp64, &fp64, NULL);

    shape_mesh cube;
    CHECK(shape_cube(&cube, 20, 20.0) == 0);
    CHECK(shape_add_normal_noise(&cube, 0.3, 11) == 0);
    rsmooth_params p;
    rsmooth_params_init(&p);
    p.guard = 0; /* the fold guard reads the result on the host: the device keeps it only without */
    for (int s = 0; s < 2; s++) {
        rsmooth_scalar scalar = s ? RSMOOTH_FLOAT64 : RSMOOTH_FLOAT32;
        uint64_t pairs = check_same(&fx, &cube, scalar, &p, 0, "the paper's filter");
        if (fp64) /* written on the device: no pair counts came back */
            CHECK(pairs == 0);
        check_same(&fx, &cube, scalar, &p, 1, "the paper's filter");
    }
    rsmooth_params guarded; /* the defaults: the host's guarded result uploaded */
    rsmooth_params_init(&guarded);
    CHECK(check_same(&fx, &cube, RSMOOTH_FLOAT32, &guarded, 0, "the paper's filter, guarded") > 0);
    /* single-pass variants: still one whole run */
    rsmooth_params v = p;
    v.normal_filter = RSMOOTH_NORMALS_BILATERAL;
    v.influence = RSMOOTH_INFLUENCE_TUKEY;
    uint64_t pairs = check_same(&fx, &cube, RSMOOTH_FLOAT32, &v, 0, "bilateral, Tukey");
    CHECK(!fp64 || pairs == 0);
    /* the paths that upload the host's result */
    v = p;
    v.passes = 2; /* (float32: the case test_passes_scalar guards) */
    CHECK(check_same(&fx, &cube, RSMOOTH_FLOAT32, &v, 0, "2 passes (uploaded)") > 0);
    uint8_t *mask = malloc(cube.vertex_count);
    CHECK(mask);
    for (size_t i = 0; i < cube.vertex_count; i++)
        mask[i] = (uint8_t)(i % 3 != 0);
    v = p;
    v.move_mask = mask;
    CHECK(check_same(&fx, &cube, RSMOOTH_FLOAT64, &v, 0, "a move mask (uploaded)") > 0);
    free(mask);
    shape_mesh big; /* tiles, as test_cl_tiles makes them */
    CHECK(shape_cube(&big, 40, 40.0) == 0);
    CHECK(shape_add_normal_noise(&big, 0.3, 12) == 0);
    fixture tiled = fx; /* the same queue, a context with a budget */
    rsmooth_context_options budget = {.struct_size = sizeof budget,
                                      .memory_budget = (uint64_t)big.triangle_count * 96 / 6};
    CHECK_STATUS(rsmooth_context_create_from_queue(fx.queue, &budget, &tiled.ctx, &err),
                 RSMOOTH_OK);
    CHECK(check_same(&tiled, &big, RSMOOTH_FLOAT32, &p, 0, "tiles (uploaded)") > 0);
    rsmooth_context_destroy(tiled.ctx);
    shape_free(&big);

    check_errors(&fx, &cube);

    shape_free(&cube);
    rsmooth_context_destroy(fx.ctx);
    clReleaseCommandQueue(fx.queue);
    rsmooth_context_destroy(base);
    printf("ok\n");
    return 0;
}
