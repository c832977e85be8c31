/* Every bad argument is refused: RSMOOTH_ERROR_INVALID_ARGUMENT, a message, nothing written. */
#include "mesh_shapes.h"
#include "rsmooth.h"
#include "test_util.h"

#include <stdint.h>
#include <string.h>

/* The paths under test, through one signature: rsmooth_smooth with ctx NULL (the reference
 * path), and with the context main creates, when there is a device. */
typedef rsmooth_status (*smooth_fn)(rsmooth_scalar scalar, const void *positions,
                                    size_t vertex_count, const uint32_t *indices,
                                    size_t triangle_count, const rsmooth_params *params,
                                    void *out_positions, float *out_weight, float *out_confidence,
                                    rsmooth_report *report, rsmooth_error *error);

static rsmooth_context *g_context;

static rsmooth_status smooth_reference(rsmooth_scalar scalar, const void *positions,
                                       size_t vertex_count, const uint32_t *indices,
                                       size_t triangle_count, const rsmooth_params *params,
                                       void *out_positions, float *out_weight,
                                       float *out_confidence, rsmooth_report *report,
                                       rsmooth_error *error) {
    return rsmooth_smooth(NULL, scalar, positions, vertex_count, indices, triangle_count, params,
                          out_positions, OUTPUTS(out_weight, out_confidence, report), error);
}

static rsmooth_status smooth_opencl(rsmooth_scalar scalar, const void *positions,
                                    size_t vertex_count, const uint32_t *indices,
                                    size_t triangle_count, const rsmooth_params *params,
                                    void *out_positions, float *out_weight, float *out_confidence,
                                    rsmooth_report *report, rsmooth_error *error) {
    return rsmooth_smooth(g_context, scalar, positions, vertex_count, indices, triangle_count,
                          params, out_positions, OUTPUTS(out_weight, out_confidence, report),
                          error);
}

static struct {
    const char *name;
    smooth_fn fn;
} entry_points[2] = {
    {"rsmooth_smooth (reference)", smooth_reference},
};
static size_t g_entry_points = 1;

/* One call's arguments. */
typedef struct call {
    rsmooth_scalar scalar;
    const void *positions;
    size_t vertex_count;
    const uint32_t *indices;
    size_t triangle_count;
    const rsmooth_params *params;
    void *out_positions;
    float *out_weight;
    float *out_confidence;
    rsmooth_report *report;
} call;

/* Output buffers, big enough for the base mesh in float64, set to a sentinel before each call. */
#define OUT_DOUBLES 512
static double g_out[OUT_DOUBLES];
static float g_weight[OUT_DOUBLES], g_confidence[OUT_DOUBLES];
static rsmooth_report g_report;
static unsigned char g_sentinel[sizeof g_out];

static void fill_sentinels(void) {
    memset(g_out, 0xA5, sizeof g_out);
    memset(g_weight, 0xA5, sizeof g_weight);
    memset(g_confidence, 0xA5, sizeof g_confidence);
    memset(&g_report, 0xA5, sizeof g_report);
}

static int outputs_untouched(void) {
    return memcmp(g_out, g_sentinel, sizeof g_out) == 0 &&
           memcmp(g_weight, g_sentinel, sizeof g_weight) == 0 &&
           memcmp(g_confidence, g_sentinel, sizeof g_confidence) == 0 &&
           memcmp(&g_report, g_sentinel, sizeof g_report) == 0;
}

static int g_cases;

static void expect_invalid(const char *what, call c) {
    for (size_t e = 0; e < g_entry_points; e++) {
        rsmooth_error err;
        memset(&err, 0, sizeof err);
        fill_sentinels();
        rsmooth_status s = entry_points[e].fn(c.scalar, c.positions, c.vertex_count, c.indices,
                                              c.triangle_count, c.params, c.out_positions,
                                              c.out_weight, c.out_confidence, c.report, &err);
        printf("%-26s %-44s -> %d \"%s\" (%s)\n", entry_points[e].name, what, (int)s, err.message,
               err.where);
        if (s != RSMOOTH_ERROR_INVALID_ARGUMENT)
            fprintf(stderr, "%s: %s: status %d, expected RSMOOTH_ERROR_INVALID_ARGUMENT\n",
                    entry_points[e].name, what, (int)s);
        CHECK_STATUS(s, RSMOOTH_ERROR_INVALID_ARGUMENT);
        CHECK_EQ_INT(err.status, RSMOOTH_ERROR_INVALID_ARGUMENT);
        CHECK(err.message[0] != '\0');
        CHECK(memchr(err.message, '\0', sizeof err.message) != NULL);
        CHECK(outputs_untouched());
        /* the same without an error record */
        fill_sentinels();
        s = entry_points[e].fn(c.scalar, c.positions, c.vertex_count, c.indices, c.triangle_count,
                               c.params, c.out_positions, c.out_weight, c.out_confidence, c.report,
                               NULL);
        CHECK_STATUS(s, RSMOOTH_ERROR_INVALID_ARGUMENT);
        CHECK(outputs_untouched());
        g_cases++;
    }
}

static void test_smooth_arguments(void) {
    memset(g_sentinel, 0xA5, sizeof g_sentinel);
    shape_mesh plane;
    CHECK(shape_plane(&plane, 4, 4, 1.0) == 0); /* 25 vertices, 32 triangles */
    CHECK(3 * plane.vertex_count <= OUT_DOUBLES);
    size_t vc = plane.vertex_count, tc = plane.triangle_count;
    double *pos = plane.xyz;
    const uint32_t *idx = plane.indices;
    float pos32[3 * 25];
    for (size_t i = 0; i < 3 * vc; i++)
        pos32[i] = (float)pos[i];
    rsmooth_params params;
    rsmooth_params_init(&params);

    const call base = {RSMOOTH_FLOAT64, pos,   vc,       idx,          tc,
                       &params,         g_out, g_weight, g_confidence, &g_report};
    /* the base call is valid and writes its outputs */
    for (size_t e = 0; e < g_entry_points; e++) {
        rsmooth_error err;
        fill_sentinels();
        CHECK_STATUS(entry_points[e].fn(base.scalar, base.positions, base.vertex_count,
                                        base.indices, base.triangle_count, base.params,
                                        base.out_positions, base.out_weight, base.out_confidence,
                                        base.report, &err),
                     RSMOOTH_OK);
        CHECK_EQ_INT(err.status, RSMOOTH_OK);
        CHECK(err.message[0] == '\0');
        CHECK(memcmp(g_out, pos, 3 * vc * sizeof(double)) == 0); /* a flat plane stays */
        CHECK(!outputs_untouched());
        CHECK_STATUS(entry_points[e].fn(base.scalar, base.positions, base.vertex_count,
                                        base.indices, base.triangle_count, NULL, g_out, NULL, NULL,
                                        NULL, NULL),
                     RSMOOTH_OK); /* NULL params: defaults */
    }

    call c;
    c = base, c.positions = NULL;
    expect_invalid("NULL positions", c);
    c = base, c.indices = NULL;
    expect_invalid("NULL indices with triangles", c);
    c = base, c.out_positions = NULL;
    expect_invalid("NULL out_positions", c);
    c = base, c.vertex_count = 0;
    expect_invalid("vertex_count 0", c);
    c = base, c.vertex_count = 0, c.triangle_count = 0, c.indices = NULL;
    expect_invalid("vertex_count 0, no triangles", c);

    uint32_t bad_idx[3 * 32];
    memcpy(bad_idx, idx, sizeof bad_idx);
    bad_idx[3 * 31 + 2] = (uint32_t)vc; /* the last index of the last triangle */
    c = base, c.indices = bad_idx;
    expect_invalid("index == vertex count", c);
    bad_idx[3 * 31 + 2] = UINT32_MAX;
    expect_invalid("index UINT32_MAX", c);
    bad_idx[3 * 31 + 2] = idx[3 * 31 + 2];
    bad_idx[0] = (uint32_t)vc + 7;
    expect_invalid("index > vertex count (first)", c);

    static const double bad_sigma_f[] = {0.0, -1.0, NAN, INFINITY, -INFINITY, -0.0};
    for (size_t i = 0; i < sizeof bad_sigma_f / sizeof bad_sigma_f[0]; i++) {
        rsmooth_params p = params;
        p.sigma_f = bad_sigma_f[i];
        char what[64];
        snprintf(what, sizeof what, "sigma_f %g", bad_sigma_f[i]);
        c = base, c.params = &p;
        expect_invalid(what, c);
        p.absolute = 1;
        snprintf(what, sizeof what, "sigma_f %g, absolute", bad_sigma_f[i]);
        expect_invalid(what, c);
    }
    static const double bad_sigma_g[] = {0.0, -0.5, NAN, -INFINITY};
    for (size_t i = 0; i < sizeof bad_sigma_g / sizeof bad_sigma_g[0]; i++) {
        rsmooth_params p = params;
        p.sigma_g = bad_sigma_g[i];
        char what[64];
        snprintf(what, sizeof what, "sigma_g %g", bad_sigma_g[i]);
        c = base, c.params = &p;
        expect_invalid(what, c);
    }
    static const double bad_cutoff[] = {0.0, 6.0, NAN, -1.0, 5.000001, INFINITY};
    for (size_t i = 0; i < sizeof bad_cutoff / sizeof bad_cutoff[0]; i++) {
        rsmooth_params p = params;
        p.cutoff = bad_cutoff[i];
        char what[64];
        snprintf(what, sizeof what, "cutoff %.9g", bad_cutoff[i]);
        c = base, c.params = &p;
        expect_invalid(what, c);
    }
    static const double bad_mollify_cutoff[] = {2.5, -0.5, NAN, INFINITY};
    for (size_t i = 0; i < sizeof bad_mollify_cutoff / sizeof bad_mollify_cutoff[0]; i++) {
        rsmooth_params p = params; /* cutoff 2 */
        p.mollify_cutoff = bad_mollify_cutoff[i];
        char what[64];
        snprintf(what, sizeof what, "mollify_cutoff %g (cutoff 2)", bad_mollify_cutoff[i]);
        c = base, c.params = &p;
        expect_invalid(what, c);
    }
    {
        rsmooth_params p = params;
        p.cutoff = 1.0;
        p.mollify_cutoff = 1.5;
        c = base, c.params = &p;
        expect_invalid("mollify_cutoff 1.5 > cutoff 1", c);
        p = params;
        p.absolute = 2;
        expect_invalid("absolute 2", c);
        p = params;
        p.mollify = -1;
        expect_invalid("mollify -1", c);
        p = params;
        p.predictor = 2;
        expect_invalid("predictor 2", c);
        static const size_t small[] = {0, 1, sizeof(size_t) + sizeof(double),
                                       offsetof(rsmooth_params, mollify)};
        for (size_t i = 0; i < sizeof small / sizeof small[0]; i++) {
            p = params;
            p.struct_size = small[i];
            char what[64];
            snprintf(what, sizeof what, "params.struct_size %zu", small[i]);
            expect_invalid(what, c);
        }
    }

    { /* the colour factor: sigma_c > 0, and every colour finite (one pass and several) */
        float colors[3 * 25];
        for (size_t i = 0; i < 3 * vc; i++)
            colors[i] = 0.5f;
        rsmooth_params p = params;
        p.colors = colors;
        c = base, c.params = &p;
        static const double bad_sigma_c[] = {0.0, -0.1, NAN, -INFINITY};
        for (size_t i = 0; i < sizeof bad_sigma_c / sizeof bad_sigma_c[0]; i++) {
            p.sigma_c = bad_sigma_c[i];
            char what[64];
            snprintf(what, sizeof what, "sigma_c %g", bad_sigma_c[i]);
            expect_invalid(what, c);
        }
        p.sigma_c = 0.1;
        static const float bad_colors[] = {NAN, INFINITY, -INFINITY, 1e16f};
        for (size_t i = 0; i < sizeof bad_colors / sizeof bad_colors[0]; i++) {
            for (int passes = 1; passes <= 3; passes += 2) {
                colors[3 * 7 + 2] = bad_colors[i];
                p.passes = passes;
                char what[64];
                snprintf(what, sizeof what, "colour of vertex 7 = %g, %d pass%s",
                         (double)bad_colors[i], passes, passes > 1 ? "es" : "");
                expect_invalid(what, c);
                rsmooth_error err;
                CHECK_STATUS(
                    rsmooth_smooth(NULL, RSMOOTH_FLOAT64, pos, vc, idx, tc, &p, g_out, NULL, &err),
                    RSMOOTH_ERROR_INVALID_ARGUMENT);
                CHECK(strstr(err.message, "vertex 7 ") != NULL); /* names the vertex */
            }
        }
        colors[3 * 7 + 2] = 0.5f;
        p.passes = 1;
        p.sigma_c = INFINITY; /* off: valid */
        CHECK_STATUS(rsmooth_smooth(NULL, RSMOOTH_FLOAT64, pos, vc, idx, tc, &p, g_out, NULL, NULL),
                     RSMOOTH_OK);
    }

    c = base, c.scalar = (rsmooth_scalar)2;
    expect_invalid("scalar 2", c);
    c = base, c.scalar = (rsmooth_scalar)-1;
    expect_invalid("scalar -1", c);

    double bad_pos[3 * 25];
    static const double bad_values[] = {NAN, INFINITY, -INFINITY};
    for (size_t i = 0; i < 3; i++) {
        for (size_t where = 0; where < 3 * vc; where += 3 * vc - 1) { /* first and last */
            memcpy(bad_pos, pos, sizeof bad_pos);
            bad_pos[where] = bad_values[i];
            char what[64];
            snprintf(what, sizeof what, "coordinate %zu = %g (float64)", where, bad_values[i]);
            c = base, c.positions = bad_pos;
            expect_invalid(what, c);
        }
        float bad32[3 * 25];
        memcpy(bad32, pos32, sizeof bad32);
        bad32[3 * 12 + 1] = (float)bad_values[i];
        char what[64];
        snprintf(what, sizeof what, "coordinate 37 = %g (float32)", bad_values[i]);
        c = base, c.scalar = RSMOOTH_FLOAT32, c.positions = bad32;
        expect_invalid(what, c);
    }
    { /* an unreferenced vertex counts too */
        double extra[3 * 26];
        memcpy(extra, pos, 3 * vc * sizeof(double));
        extra[3 * 25] = 1;
        extra[3 * 25 + 1] = NAN;
        extra[3 * 25 + 2] = 1;
        c = base, c.positions = extra, c.vertex_count = 26;
        expect_invalid("NaN in an unreferenced vertex", c);
    }

    /* Sizes that overflow: refused before the arrays are read (the real arrays are tiny; ASan or a
     * crash would show a read). */
    c = base, c.triangle_count = SIZE_MAX / 4;
    expect_invalid("triangle_count SIZE_MAX / 4", c);
    c = base, c.triangle_count = SIZE_MAX;
    expect_invalid("triangle_count SIZE_MAX", c);
    c = base, c.vertex_count = SIZE_MAX;
    expect_invalid("vertex_count SIZE_MAX", c);
    if (SIZE_MAX > UINT32_MAX) {
        c = base, c.vertex_count = (size_t)UINT32_MAX + 1;
        expect_invalid("vertex_count 2^32", c);
        c = base, c.triangle_count = (size_t)UINT32_MAX + 1;
        expect_invalid("triangle_count 2^32", c);
    }

    /* out_positions overlapping positions: refused, and the shared array left as it was */
    {
        double shared[3 * 25 + 6];
        memcpy(shared, pos, 3 * vc * sizeof(double));
        memset(shared + 3 * vc, 0, 6 * sizeof(double));
        double pristine[3 * 25 + 6];
        memcpy(pristine, shared, sizeof shared);
        static const size_t shifts[] = {0, 3, 6};
        for (size_t i = 0; i < 3; i++) {
            char what[64];
            snprintf(what, sizeof what, "out_positions = positions + %zu", shifts[i]);
            c = base, c.positions = shared, c.out_positions = shared + shifts[i];
            expect_invalid(what, c);
            CHECK(memcmp(shared, pristine, sizeof shared) == 0);
        }
        c = base, c.positions = shared + 3, c.out_positions = shared;
        expect_invalid("positions = out_positions + 3", c);
        CHECK(memcmp(shared, pristine, sizeof shared) == 0);
        float shared32[3 * 25 + 3];
        memcpy(shared32, pos32, sizeof pos32);
        c = base, c.scalar = RSMOOTH_FLOAT32, c.positions = shared32,
        c.out_positions = shared32 + 1;
        expect_invalid("float32 out_positions = positions + 1", c);
        CHECK(memcmp(shared32, pos32, sizeof pos32) == 0);
    }

    /* Every other output against every input, and the outputs against each other: each refused
     * with the inputs left as they were. One buffer holds an input and lends its tail (or head)
     * to an output. */
    {
        enum { WORDS = 2048 };
        static uint32_t arena[WORDS]; /* aligned for doubles too: static storage */
        static uint32_t pristine[WORDS];
        double *arena_d = (double *)(void *)arena;
        float *arena_f = (float *)(void *)arena;
        /* positions in the arena, the weights or confidences starting inside them */
        memcpy(arena_d, pos, 3 * vc * sizeof(double));
        memcpy(pristine, arena, sizeof arena);
        c = base, c.positions = arena_d, c.out_weight = arena_f + 6 * vc - 2;
        expect_invalid("out_weight overlaps positions' last vertex", c);
        c = base, c.positions = arena_d, c.out_confidence = arena_f;
        expect_invalid("out_confidence = positions", c);
        CHECK(memcmp(arena, pristine, sizeof arena) == 0);
        /* indices in the arena, out_positions over their end */
        memset(arena, 0, sizeof arena);
        memcpy(arena, idx, 3 * tc * sizeof(uint32_t));
        memcpy(pristine, arena, sizeof arena);
        c = base, c.indices = arena, c.out_positions = arena_d + (3 * tc - 2) / 2;
        expect_invalid("out_positions overlaps indices", c);
        c = base, c.indices = arena, c.out_weight = arena_f;
        expect_invalid("out_weight = indices", c);
        CHECK(memcmp(arena, pristine, sizeof arena) == 0);
        /* colours in the arena, the confidence inside them */
        rsmooth_params colored;
        rsmooth_params_init(&colored);
        for (size_t i = 0; i < 3 * vc; i++)
            arena_f[i] = 0.5f;
        memcpy(pristine, arena, sizeof arena);
        colored.colors = arena_f;
        c = base, c.params = &colored, c.out_confidence = arena_f + vc;
        expect_invalid("out_confidence overlaps params->colors", c);
        CHECK(memcmp(arena, pristine, sizeof arena) == 0);
        /* two outputs in one place */
        c = base, c.out_weight = g_weight, c.out_confidence = g_weight + 1;
        expect_invalid("out_confidence overlaps out_weight", c);
        c = base, c.out_weight = (float *)(void *)g_out;
        expect_invalid("out_weight overlaps out_positions", c);
        /* and Taubin's one output against its indices */
        memset(arena, 0, sizeof arena);
        memcpy(arena, idx, 3 * tc * sizeof(uint32_t));
        memcpy(pristine, arena, sizeof arena);
        rsmooth_error err;
        CHECK_STATUS(rsmooth_smooth_taubin(RSMOOTH_FLOAT64, pos, vc, arena, tc, 0.5, -0.53, 3,
                                           arena_d + 1, &err),
                     RSMOOTH_ERROR_INVALID_ARGUMENT);
        printf("rsmooth_smooth_taubin out_positions over indices -> \"%s\"\n", err.message);
        CHECK(memcmp(arena, pristine, sizeof arena) == 0);
    }
    shape_free(&plane);
}

static void test_status_strings(void) {
    for (int s = RSMOOTH_OK; s <= RSMOOTH_ERROR_NUMERICAL; s++) {
        const char *text = rsmooth_status_str((rsmooth_status)s);
        printf("status %d: \"%s\"\n", s, text ? text : "(null)");
        CHECK(text && text[0]);
    }
    const char *text = rsmooth_status_str((rsmooth_status)1234);
    printf("status 1234: \"%s\"\n", text ? text : "(null)");
    CHECK(text && text[0]);
    CHECK_STATUS(rsmooth_params_init(NULL), RSMOOTH_ERROR_INVALID_ARGUMENT);
}

static void test_mean_edge_length(void) {
    const int nx = 4, ny = 3;
    shape_mesh plane;
    CHECK(shape_plane(&plane, nx, ny, 1.0) == 0);
    /* unit edges: nx (ny + 1) along x, (nx + 1) ny along y; sqrt(2) diagonals: one per quad */
    double unit_edges = nx * (ny + 1) + (nx + 1) * ny, diagonals = nx * ny;
    double expected = (unit_edges + diagonals * sqrt(2.0)) / (unit_edges + diagonals);
    double got = -1, got32 = -1;
    rsmooth_error err;
    CHECK_STATUS(rsmooth_mean_edge_length(RSMOOTH_FLOAT64, plane.xyz, plane.vertex_count,
                                          plane.indices, plane.triangle_count, &got, &err),
                 RSMOOTH_OK);
    float xyz32[3 * 20];
    for (size_t i = 0; i < 3 * plane.vertex_count; i++)
        xyz32[i] = (float)plane.xyz[i];
    CHECK_STATUS(rsmooth_mean_edge_length(RSMOOTH_FLOAT32, xyz32, plane.vertex_count, plane.indices,
                                          plane.triangle_count, &got32, &err),
                 RSMOOTH_OK);
    printf("mean edge length of the %dx%d unit plane: %.15f (float32 %.15f), expected (31 + 12 "
           "sqrt 2) / 43 = %.15f\n",
           nx, ny, got, got32, expected);
    CHECK_NEAR(got, expected, 1e-14);
    CHECK_NEAR(got32, expected, 1e-14);
    CHECK_NEAR(shape_mean_edge_length(&plane), expected, 1e-14);

    /* no triangles: no edge, 0; only zero-length edges: 0 */
    CHECK_STATUS(rsmooth_mean_edge_length(RSMOOTH_FLOAT64, plane.xyz, plane.vertex_count, NULL, 0,
                                          &got, &err),
                 RSMOOTH_OK);
    CHECK_NEAR(got, 0, 0);
    double same[9] = {1, 2, 3, 1, 2, 3, 1, 2, 3};
    uint32_t tri[3] = {0, 1, 2};
    CHECK_STATUS(rsmooth_mean_edge_length(RSMOOTH_FLOAT64, same, 3, tri, 1, &got, &err),
                 RSMOOTH_OK);
    CHECK_NEAR(got, 0, 0);

    /* its own argument errors */
    CHECK_STATUS(rsmooth_mean_edge_length(RSMOOTH_FLOAT64, plane.xyz, plane.vertex_count,
                                          plane.indices, plane.triangle_count, NULL, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK(err.message[0]);
    got = 42;
    CHECK_STATUS(rsmooth_mean_edge_length(RSMOOTH_FLOAT64, NULL, plane.vertex_count, plane.indices,
                                          plane.triangle_count, &got, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK(err.message[0] && err.status == RSMOOTH_ERROR_INVALID_ARGUMENT);
    tri[2] = 3;
    CHECK_STATUS(rsmooth_mean_edge_length(RSMOOTH_FLOAT64, same, 3, tri, 1, &got, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK_STATUS(rsmooth_mean_edge_length(RSMOOTH_FLOAT64, same, 3, tri, SIZE_MAX / 4, &got, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    printf("mean edge length argument errors: last \"%s\"\n", err.message);
    shape_free(&plane);
}

int main(void) {
    if (rsmooth_context_create(NULL, &g_context, NULL) == RSMOOTH_OK) {
        entry_points[g_entry_points].name = "rsmooth_smooth (device)";
        entry_points[g_entry_points++].fn = smooth_opencl;
    } else {
        printf("no OpenCL device: the reference path alone\n");
    }
    test_smooth_arguments();
    test_status_strings();
    test_mean_edge_length();
    printf("bad_arguments: %d bad calls refused with nothing written\n", g_cases);
    rsmooth_context_destroy(g_context);
    return 0;
}
