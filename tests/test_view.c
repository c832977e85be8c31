/* Meshes as hosts hold them, and a selection that moves alone:
 * - rsmooth_smooth_view on an interleaved float32 vertex buffer (32-byte stride) with int64 and
 *   padded int32 indices equals the packed call bit for bit, on both paths, written back into the
 *   same buffer with the bytes between positions untouched; bad indices are named in their own
 *   type and nothing is written;
 * - params.move_mask: unselected vertices keep their input bit for bit; with one pass the selected
 *   ones equal the unmasked result, with two they equal two single passes composed by hand (each
 *   restoring the unselected), the oracle; point clouds likewise;
 * - rsmooth_version agrees with the header; a context's host-thread setting reads back and does
 *   not change the result. */
#include "mesh_shapes.h"
#include "rsmooth.h"
#include "test_cl_util.h"
#include "test_util.h"

#include <stdint.h>
#include <string.h>

#define FLOATS_PER_VERTEX 8 /* x y z, then a normal and a uv the filter must not touch */

typedef struct interleaved {
    float *buffer;   /* vertex_count * FLOATS_PER_VERTEX */
    float *packed;   /* 3 per vertex */
    int64_t *i64;    /* 3 per triangle */
    int32_t *i32pad; /* 4 per triangle: three indices and a pad */
} interleaved;

static void make(const shape_mesh *m, interleaved *x) {
    x->buffer = malloc(m->vertex_count * FLOATS_PER_VERTEX * sizeof(float));
    x->packed = malloc(m->vertex_count * 3 * sizeof(float));
    x->i64 = malloc(m->triangle_count * 3 * sizeof(int64_t));
    x->i32pad = malloc(m->triangle_count * 4 * sizeof(int32_t));
    CHECK(x->buffer && x->packed && x->i64 && x->i32pad);
    for (size_t v = 0; v < m->vertex_count; v++)
        for (int k = 0; k < FLOATS_PER_VERTEX; k++) {
            float value = k < 3 ? (float)m->xyz[3 * v + (size_t)k] : (float)(1000 * v + (size_t)k);
            x->buffer[v * FLOATS_PER_VERTEX + (size_t)k] = value;
            if (k < 3)
                x->packed[3 * v + (size_t)k] = value;
        }
    for (size_t t = 0; t < m->triangle_count; t++) {
        for (int c = 0; c < 3; c++) {
            x->i64[3 * t + (size_t)c] = m->indices[3 * t + (size_t)c];
            x->i32pad[4 * t + (size_t)c] = (int32_t)m->indices[3 * t + (size_t)c];
        }
        x->i32pad[4 * t + 3] = -7; /* a pad the view must skip */
    }
}

static void release(interleaved *x) {
    free(x->buffer);
    free(x->packed);
    free(x->i64);
    free(x->i32pad);
}

/* The view of `x` with int64 (or padded int32) indices. */
static rsmooth_mesh_view view_of(const shape_mesh *m, interleaved *x, int int32) {
    rsmooth_mesh_view view;
    CHECK_STATUS(rsmooth_mesh_view_init(&view), RSMOOTH_OK);
    view.scalar = RSMOOTH_FLOAT32;
    view.positions = x->buffer;
    view.position_stride = FLOATS_PER_VERTEX * sizeof(float);
    view.vertex_count = m->vertex_count;
    view.indices = int32 ? (const void *)x->i32pad : (const void *)x->i64;
    view.index_type = int32 ? RSMOOTH_INDEX_INT32 : RSMOOTH_INDEX_INT64;
    view.index_stride = int32 ? 4 * sizeof(int32_t) : 0;
    view.triangle_count = m->triangle_count;
    return view;
}

/* The view's result, written into a copy of the vertex buffer, equals the packed call's. */
static void check_view_equals_packed(rsmooth_context *ctx, const shape_mesh *m, int int32,
                                     const char *name) {
    interleaved x;
    make(m, &x);
    rsmooth_params p;
    rsmooth_params_init(&p);
    size_t n = m->vertex_count;
    float *packed_out = malloc(n * 3 * sizeof(float));
    float *packed_conf = malloc(n * sizeof(float)), *view_conf = malloc(n * sizeof(float));
    float *before = malloc(n * FLOATS_PER_VERTEX * sizeof(float));
    CHECK(packed_out && packed_conf && view_conf && before);
    memcpy(before, x.buffer, n * FLOATS_PER_VERTEX * sizeof(float));
    rsmooth_error err;
    CHECK_STATUS(
        ctx ? rsmooth_smooth(ctx, RSMOOTH_FLOAT32, x.packed, n, m->indices, m->triangle_count, &p,
                             packed_out, OUTPUTS(NULL, packed_conf, NULL), &err)
            : rsmooth_smooth(NULL, RSMOOTH_FLOAT32, x.packed, n, m->indices, m->triangle_count, &p,
                             packed_out, OUTPUTS(NULL, packed_conf, NULL), &err),
        RSMOOTH_OK);
    rsmooth_mesh_view view = view_of(m, &x, int32);
    /* in place: the result goes back into the vertex buffer it came from */
    CHECK_STATUS(rsmooth_smooth_view(ctx, &view, &p, x.buffer, FLOATS_PER_VERTEX * sizeof(float),
                                     OUTPUTS(NULL, view_conf, NULL), &err),
                 RSMOOTH_OK);
    size_t moved = 0;
    for (size_t v = 0; v < n; v++)
        for (int k = 0; k < FLOATS_PER_VERTEX; k++) {
            float got = x.buffer[v * FLOATS_PER_VERTEX + (size_t)k];
            float want =
                k < 3 ? packed_out[3 * v + (size_t)k] : before[v * FLOATS_PER_VERTEX + (size_t)k];
            CHECK(memcmp(&got, &want, sizeof got) == 0);
            moved += k < 3 && got != before[v * FLOATS_PER_VERTEX + (size_t)k];
        }
    CHECK(moved > n); /* the filter did move the vertices */
    CHECK(memcmp(packed_conf, view_conf, n * sizeof(float)) == 0);
    printf("%-44s equal to the packed call, %zu coordinates moved, padding kept\n", name, moved);
    free(packed_out);
    free(packed_conf);
    free(view_conf);
    free(before);
    release(&x);
}

static void check_view_refusals(const shape_mesh *m) {
    interleaved x;
    make(m, &x);
    rsmooth_error err;
    size_t n = m->vertex_count;
    float *out = malloc(n * 3 * sizeof(float));
    CHECK(out);
    memset(out, 0x5a, n * 3 * sizeof(float));
    unsigned char untouched = ((unsigned char *)out)[0];

    rsmooth_mesh_view view = view_of(m, &x, 1);
    x.i32pad[4 * 5 + 1] = -1;
    CHECK_STATUS(rsmooth_smooth_view(NULL, &view, NULL, out, 0, NULL, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(err.message, "triangle 5 corner 1: index -1 is negative") != NULL);
    x.i32pad[4 * 5 + 1] = (int32_t)m->indices[3 * 5 + 1];

    view = view_of(m, &x, 0);
    x.i64[3 * 9 + 2] = (int64_t)1 << 40; /* would wrap to 0 as uint32 */
    CHECK_STATUS(rsmooth_smooth_view(NULL, &view, NULL, out, 0, NULL, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(err.message, "triangle 9 corner 2: index 1099511627776 is beyond") != NULL);
    x.i64[3 * 9 + 2] = m->indices[3 * 9 + 2];

    view.position_stride = 8; /* smaller than x, y, z */
    CHECK_STATUS(rsmooth_smooth_view(NULL, &view, NULL, out, 0, NULL, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(err.message, "stride") != NULL);
    view = view_of(m, &x, 0);
    view.struct_size = 0;
    CHECK_STATUS(rsmooth_smooth_view(NULL, &view, NULL, out, 0, NULL, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    view = view_of(m, &x, 0);
    view.index_type = 7;
    CHECK_STATUS(rsmooth_smooth_view(NULL, &view, NULL, out, 0, NULL, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    view = view_of(m, &x, 0);
    CHECK_STATUS(
        rsmooth_smooth_view(NULL, &view, NULL, out, 0, OUTPUTS((float *)out + 5, NULL, NULL), &err),
        RSMOOTH_ERROR_INVALID_ARGUMENT); /* out_weight inside out_positions */
    CHECK(strstr(err.message, "overlap") != NULL);
    CHECK_STATUS(rsmooth_smooth_view(NULL, NULL, NULL, out, 0, NULL, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    rsmooth_params p; /* a mask in the output's memory (the packed call's check) */
    rsmooth_params_init(&p);
    p.move_mask = (const uint8_t *)out;
    CHECK_STATUS(rsmooth_smooth(NULL, RSMOOTH_FLOAT32, x.packed, n, m->indices, m->triangle_count,
                                &p, out, NULL, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(err.message, "out_positions overlaps params->move_mask") != NULL);
    for (size_t i = 0; i < n * 3 * sizeof(float); i++)
        CHECK(((unsigned char *)out)[i] == untouched); /* nothing written by any refusal */
    printf("view refusals: negative int32, int64 beyond, short stride, struct_size, index type, "
           "overlapping outputs, NULL, a mask in the output; nothing written\n");
    free(out);
    release(&x);
}

/* One pass: unselected keep the input bit for bit, selected equal the unmasked run. Two passes:
 * equal to two single passes composed by hand, restoring the unselected after each. */
static void check_mask(rsmooth_context *ctx, const shape_mesh *m, const char *name) {
    size_t n = m->vertex_count, bytes = n * 3 * sizeof(double);
    uint8_t *mask = malloc(n);
    double *full = malloc(bytes), *masked = malloc(bytes), *step = malloc(bytes),
           *oracle = malloc(bytes);
    CHECK(mask && full && masked && step && oracle);
    for (size_t v = 0; v < n; v++)
        mask[v] = m->xyz[3 * v] > 0; /* half the shape */
    rsmooth_params p;
    rsmooth_params_init(&p);
    rsmooth_error err;
#define RUN(params, in, out)                                                                       \
    CHECK_STATUS(ctx ? rsmooth_smooth(ctx, RSMOOTH_FLOAT64, in, n, m->indices, m->triangle_count,  \
                                      params, out, NULL, &err)                                     \
                     : rsmooth_smooth(NULL, RSMOOTH_FLOAT64, in, n, m->indices, m->triangle_count, \
                                      params, out, NULL, &err),                                    \
                 RSMOOTH_OK)
    RUN(&p, m->xyz, full);
    p.move_mask = mask;
    RUN(&p, m->xyz, masked);
    size_t selected = 0;
    for (size_t v = 0; v < n; v++) {
        const double *want = mask[v] ? full + 3 * v : m->xyz + 3 * v;
        CHECK(memcmp(masked + 3 * v, want, 3 * sizeof(double)) == 0);
        selected += mask[v];
    }
    CHECK(selected > 0 && selected < n);

    /* Two passes, sigmas fixed in mesh units as the passes fix them. */
    double unit;
    CHECK_STATUS(rsmooth_mean_edge_length(RSMOOTH_FLOAT64, m->xyz, n, m->indices, m->triangle_count,
                                          &unit, &err),
                 RSMOOTH_OK);
    rsmooth_params one;
    rsmooth_params_init(&one);
    one.absolute = 1;
    one.sigma_f *= unit;
    one.sigma_g *= unit;
    RUN(&one, m->xyz, step);
    for (size_t v = 0; v < n; v++)
        if (!mask[v])
            memcpy(step + 3 * v, m->xyz + 3 * v, 3 * sizeof(double));
    RUN(&one, step, oracle);
    for (size_t v = 0; v < n; v++)
        if (!mask[v])
            memcpy(oracle + 3 * v, m->xyz + 3 * v, 3 * sizeof(double));
    p.passes = 2;
    RUN(&p, m->xyz, masked);
    double worst = 0;
    for (size_t i = 0; i < 3 * n; i++) {
        if (!mask[i / 3])
            CHECK(memcmp(masked + i, m->xyz + i, sizeof(double)) == 0);
        worst = fmax(worst, fabs(masked[i] - oracle[i]));
    }
    /* the same arithmetic but for the unit's rounding (sigma * unit once here, in the library
     * per pass from its own): equal to far below an edge */
    CHECK_LE(worst, 1e-9 * unit);
#undef RUN
    printf("%-44s %zu of %zu selected: unselected bit for bit; 2 passes within %.1e edges of "
           "the hand-composed passes\n",
           name, selected, n, worst / unit);
    free(mask);
    free(full);
    free(masked);
    free(step);
    free(oracle);
}

static void check_points_mask(const shape_mesh *m) {
    size_t n = m->vertex_count;
    double *normals = malloc(n * 3 * sizeof(double)), *out = malloc(n * 3 * sizeof(double));
    uint8_t *mask = malloc(n);
    CHECK(normals && out && mask && shape_vertex_normals(m, normals) == 0);
    for (size_t v = 0; v < n; v++)
        mask[v] = v % 3 != 0;
    rsmooth_params p;
    rsmooth_params_init_best(&p);
    p.move_mask = mask;
    rsmooth_error err;
    CHECK_STATUS(
        rsmooth_smooth_points(NULL, RSMOOTH_FLOAT64, m->xyz, normals, n, &p, out, NULL, NULL, &err),
        RSMOOTH_OK);
    size_t moved = 0;
    for (size_t v = 0; v < n; v++) {
        if (!mask[v])
            CHECK(memcmp(out + 3 * v, m->xyz + 3 * v, 3 * sizeof(double)) == 0);
        else
            moved += memcmp(out + 3 * v, m->xyz + 3 * v, 3 * sizeof(double)) != 0;
    }
    CHECK(moved > n / 2);
    printf("points (best, 3 passes) with a mask: unselected bit for bit, %zu selected moved\n",
           moved);
    free(normals);
    free(out);
    free(mask);
}

/* The context's host threads: the setting reads back, and 1, 3 or every core give the same bits. */
static void check_host_threads(rsmooth_context *ctx, const shape_mesh *m) {
    size_t bytes = m->vertex_count * 3 * sizeof(double);
    double *base = malloc(bytes), *other = malloc(bytes);
    CHECK(base && other);
    rsmooth_params p;
    rsmooth_params_init_best(&p);
    rsmooth_error err;
    CHECK_EQ_INT(context_info(ctx).host_threads, 0);
    CHECK_STATUS(rsmooth_smooth(ctx, RSMOOTH_FLOAT64, m->xyz, m->vertex_count, m->indices,
                                m->triangle_count, &p, base, NULL, &err),
                 RSMOOTH_OK);
    unsigned counts[] = {1, 3};
    for (int i = 0; i < 2; i++) {
        rsmooth_context_options o = {.struct_size = sizeof o, .host_threads = counts[i]};
        rsmooth_context *threaded = NULL;
        CHECK_STATUS(rsmooth_context_create(&o, &threaded, &err), RSMOOTH_OK);
        CHECK_EQ_INT(context_info(threaded).host_threads, counts[i]);
        CHECK_STATUS(rsmooth_smooth(threaded, RSMOOTH_FLOAT64, m->xyz, m->vertex_count, m->indices,
                                    m->triangle_count, &p, other, NULL, &err),
                     RSMOOTH_OK);
        CHECK(memcmp(base, other, bytes) == 0);
        rsmooth_context_destroy(threaded);
    }
    printf("host threads 1 and 3: the same bits as every core\n");
    free(base);
    free(other);
}

int main(void) {
    int major = -1, minor = -1, patch = -1;
    const char *version = rsmooth_version(&major, &minor, &patch);
    char expected[32];
    snprintf(expected, sizeof expected, "%d.%d.%d", RSMOOTH_VERSION_MAJOR, RSMOOTH_VERSION_MINOR,
             RSMOOTH_VERSION_PATCH);
    CHECK(strcmp(version, expected) == 0);
    CHECK(major == RSMOOTH_VERSION_MAJOR && minor == RSMOOTH_VERSION_MINOR &&
          patch == RSMOOTH_VERSION_PATCH);
    CHECK(rsmooth_version(NULL, NULL, NULL) == version ||
          strcmp(rsmooth_version(NULL, NULL, NULL), version) == 0);

    shape_mesh m;
    CHECK(shape_cube(&m, 12, 2.0) == 0);
    CHECK(shape_add_normal_noise(&m, 0.3 * shape_mean_edge_length(&m), 11) == 0);
    check_view_equals_packed(NULL, &m, 0, "reference, stride 32, int64 indices:");
    check_view_equals_packed(NULL, &m, 1, "reference, stride 32, int32 indices padded:");
    check_view_refusals(&m);
    check_mask(NULL, &m, "reference mask:");
    check_points_mask(&m);

    rsmooth_context *ctx = open_test_context();
    check_view_equals_packed(ctx, &m, 0, "OpenCL, stride 32, int64 indices:");
    check_mask(ctx, &m, "OpenCL mask:");
    check_host_threads(ctx, &m);
    rsmooth_context_destroy(ctx);
    shape_free(&m);
    printf("view: all checks passed\n");
    return 0;
}
