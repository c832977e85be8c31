/* rsmooth_smooth_cl: positions in and out of the caller's OpenCL buffers on its own queue. The
 * result read back equals rsmooth_smooth's on host arrays bit for bit, in float32 and float64,
 * in place too, on the path that writes it on the device (one whole run without the fold guard:
 * the report's pair counts are 0) and on the paths that upload the host's (the guard, a move
 * mask, tiles); bad
 * buffers (NULL, too small, another OpenCL context, an image, a read-only output, a write-only
 * input, two objects over shared memory) are refused by name and leave the output untouched. */
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

/* A sub-buffer of `parent`: `bytes` from `origin`, with `flags` (0: the parent's). */
static cl_mem sub_buffer(cl_mem parent, cl_mem_flags flags, size_t origin, size_t bytes) {
    cl_buffer_region region = {origin, bytes};
    cl_int err = CL_SUCCESS;
    cl_mem mem = clCreateSubBuffer(parent, flags, CL_BUFFER_CREATE_TYPE_REGION, &region, &err);
    CHECK(err == CL_SUCCESS && mem);
    return mem;
}

/* rsmooth_smooth_cl(in, out) on the cube's float32 positions is refused with a message that
 * holds `wanted`; `out_marker` (out's `bytes` when they can be read back, else NULL) unchanged. */
static void check_refused(const fixture *fx, const shape_mesh *m, cl_mem in, cl_mem out,
                          const void *out_marker, const char *wanted, const char *what) {
    size_t bytes = 3 * m->vertex_count * sizeof(float);
    rsmooth_params p;
    rsmooth_params_init(&p);
    p.guard = 0; /* the result written on the device, where overlap changes it */
    rsmooth_error err;
    rsmooth_status st = rsmooth_smooth_cl(fx->ctx, RSMOOTH_FLOAT32, in, m->vertex_count, m->indices,
                                          m->triangle_count, &p, out, NULL, &err);
    printf("%s: %s: %s\n", what, rsmooth_status_str(st), st ? err.message : "accepted");
    CHECK_STATUS(st, RSMOOTH_ERROR_INVALID_ARGUMENT);
    if (!strstr(err.message, wanted)) {
        printf("%s: the message lacks '%s'\n", what, wanted);
        CHECK(0);
    }
    if (out_marker) {
        void *got = malloc(bytes);
        CHECK(got);
        read_back(fx, out, bytes, got);
        CHECK(memcmp(got, out_marker, bytes) == 0);
        free(got);
    }
}

/* The memory objects rsmooth_smooth_cl must refuse besides NULL, small and foreign ones: images,
 * an input kernels may not read, an output they may not write, and two objects over shared
 * memory (sub-buffers of one buffer, a sub-buffer and its buffer, buffers over one host memory),
 * where the device would read inputs other work-items had already overwritten. Sub-buffers of one
 * buffer that do not meet are taken, and give rsmooth_smooth's bits. */
static void check_memory_objects(const fixture *fx, const shape_mesh *m) {
    size_t n = m->vertex_count, bytes = 3 * n * sizeof(float);
    float *in = positions_as(m, RSMOOTH_FLOAT32);
    float *marker = malloc(bytes);
    CHECK(marker);
    memset(marker, 0x5a, bytes);
    cl_mem din = buffer_with(fx, bytes, in), dout = buffer_with(fx, bytes, marker);
    cl_device_id device = NULL;
    CHECK(clGetCommandQueueInfo(fx->queue, CL_QUEUE_DEVICE, sizeof device, &device, NULL) ==
          CL_SUCCESS);
    cl_int err = CL_SUCCESS;

    /* an image holding enough bytes, as either argument */
    cl_bool images = CL_FALSE;
    size_t max_width = 0, texels = (3 * n + 3) / 4; /* RGBA float: 4 coordinates a texel */
    clGetDeviceInfo(device, CL_DEVICE_IMAGE_SUPPORT, sizeof images, &images, NULL);
    clGetDeviceInfo(device, CL_DEVICE_IMAGE2D_MAX_WIDTH, sizeof max_width, &max_width, NULL);
    if (images && texels <= max_width) {
        cl_image_format format = {CL_RGBA, CL_FLOAT};
        cl_image_desc desc = {
            .image_type = CL_MEM_OBJECT_IMAGE2D, .image_width = texels, .image_height = 1};
        cl_mem image = clCreateImage(fx->context, CL_MEM_READ_WRITE, &format, &desc, NULL, &err);
        CHECK(err == CL_SUCCESS && image);
        check_refused(fx, m, image, dout, marker, "positions is not a buffer", "image in");
        check_refused(fx, m, din, image, NULL, "out_positions is not a buffer", "image out");
        clReleaseMemObject(image);
    } else
        printf("no images on this device: the image checks skipped\n");

    /* access flags: the input's and the output's own, and a sub-buffer's inherited ones */
    cl_mem read_only =
        clCreateBuffer(fx->context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, bytes, marker, &err);
    CHECK(err == CL_SUCCESS);
    check_refused(fx, m, din, read_only, marker, "out_positions is read-only", "read-only out");
    cl_mem inherits = sub_buffer(read_only, 0, 0, bytes);
    check_refused(fx, m, din, inherits, marker, "out_positions is read-only",
                  "a sub-buffer of a read-only buffer out");
    cl_mem write_only =
        clCreateBuffer(fx->context, CL_MEM_WRITE_ONLY | CL_MEM_COPY_HOST_PTR, bytes, in, &err);
    CHECK(err == CL_SUCCESS);
    check_refused(fx, m, write_only, dout, marker, "positions is write-only", "write-only in");

    /* sub-buffers of one buffer: the output `align` bytes (the least a sub-buffer may start at)
     * after the input, so that they share all but `align` bytes; then apart */
    cl_uint align_bits = 0;
    CHECK(clGetDeviceInfo(device, CL_DEVICE_MEM_BASE_ADDR_ALIGN, sizeof align_bits, &align_bits,
                          NULL) == CL_SUCCESS);
    size_t align = align_bits / 8, apart = (bytes + align - 1) / align * align;
    CHECK(align > 0 && align < bytes);
    cl_mem parent = buffer_with(fx, apart + bytes, NULL);
    CHECK(clEnqueueWriteBuffer(fx->queue, parent, CL_TRUE, 0, bytes, in, 0, NULL, NULL) ==
          CL_SUCCESS);
    CHECK(clEnqueueWriteBuffer(fx->queue, parent, CL_TRUE, align, bytes, marker, 0, NULL, NULL) ==
          CL_SUCCESS); /* the input's bytes from `align` on are now the marker's */
    float *shifted = malloc(bytes);
    CHECK(shifted);
    read_back(fx, parent, bytes, shifted); /* the input as the parent now holds it */
    cl_mem first = sub_buffer(parent, 0, 0, bytes), later = sub_buffer(parent, 0, align, bytes);
    check_refused(fx, m, first, later, marker, "positions and out_positions overlap",
                  "sub-buffers sharing memory");
    check_refused(fx, m, later, first, shifted, "positions and out_positions overlap",
                  "sub-buffers sharing memory, the other way");
    check_refused(fx, m, later, parent, shifted, "positions and out_positions overlap",
                  "a sub-buffer into its buffer");
    cl_mem same = sub_buffer(parent, 0, 0, bytes);
    check_refused(fx, m, first, same, shifted, "positions and out_positions overlap",
                  "two sub-buffers over the same bytes");

    /* apart in one buffer: taken, rsmooth_smooth's bits */
    CHECK(clEnqueueWriteBuffer(fx->queue, parent, CL_TRUE, 0, bytes, in, 0, NULL, NULL) ==
          CL_SUCCESS);
    cl_mem beyond = sub_buffer(parent, 0, apart, bytes);
    rsmooth_params p;
    rsmooth_params_init(&p);
    p.guard = 0;
    rsmooth_error e;
    float *expected = malloc(bytes), *got = malloc(bytes);
    CHECK(expected && got);
    CHECK_STATUS(rsmooth_smooth(fx->ctx, RSMOOTH_FLOAT32, in, n, m->indices, m->triangle_count, &p,
                                expected, NULL, &e),
                 RSMOOTH_OK);
    CHECK_STATUS(rsmooth_smooth_cl(fx->ctx, RSMOOTH_FLOAT32, first, n, m->indices,
                                   m->triangle_count, &p, beyond, NULL, &e),
                 RSMOOTH_OK);
    read_back(fx, beyond, bytes, got);
    CHECK(memcmp(got, expected, bytes) == 0);
    printf("sub-buffers of one buffer, apart: taken, bit-identical\n");

    /* two buffers over one host memory, `align` bytes apart */
    char *host = malloc(apart + bytes);
    CHECK(host);
    memcpy(host, in, bytes);
    cl_mem over_host =
        clCreateBuffer(fx->context, CL_MEM_READ_WRITE | CL_MEM_USE_HOST_PTR, bytes, host, &err);
    CHECK(err == CL_SUCCESS);
    cl_mem over_host_later = clCreateBuffer(fx->context, CL_MEM_READ_WRITE | CL_MEM_USE_HOST_PTR,
                                            bytes, host + align, &err);
    CHECK(err == CL_SUCCESS);
    check_refused(fx, m, over_host, over_host_later, NULL, "positions and out_positions overlap",
                  "buffers over one host memory");

    cl_mem all[] = {over_host_later, over_host,  beyond,   same,      first, later,
                    parent,          write_only, inherits, read_only, din,   dout};
    for (size_t k = 0; k < sizeof all / sizeof all[0]; k++)
        clReleaseMemObject(all[k]);
    free(host);
    free(expected);
    free(got);
    free(shifted);
    free(marker);
    free(in);
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
    check_memory_objects(&fx, &cube);

    shape_free(&cube);
    rsmooth_context_destroy(fx.ctx);
    clReleaseCommandQueue(fx.queue);
    rsmooth_context_destroy(base);
    printf("ok\n");
    return 0;
}
