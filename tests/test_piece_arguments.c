/* The piece and stream C API refuse what would return garbage:
 *   - rsmooth_smooth_piece checks every field of rsmooth_piece_info (and reads a record of the
 *     first published size, its newer fields at 0), a scale the whole-mesh path
 *     cannot choose (2^-1030) or one that is not the whole mesh's (2^300, 2^-300 on a mesh of
 *     0.1 edges) among them, and returns INVALID_ARGUMENT naming it with nothing written; the
 *     scales a whole mesh of this piece could have give the in-memory reference path's bits;
 *   - refusals before the piece is prepared (NULL out_positions, passes 2, overlapping buffers)
 *     free nothing they did not allocate, on the device and on the reference path (the stack is
 *     filled with junk first, so an uninitialised record is freed as garbage, as it was);
 *   - a piece's weights and confidences (outputs) are the in-memory run's bits, on the device
 *     and on the reference path; an output overlapping another is refused;
 *   - rsmooth_piece_halo refuses a halo beyond double range (mean edge 1e308);
 *   - rsmooth_stream_smooth refuses ranks without a sync and a rank without ranks, before it
 *     reads or writes anything. */
#define _GNU_SOURCE
#include "mesh_shapes.h"
#include "rsmooth.h"
#include "rsmooth_io.h"
#include "test_cl_util.h"
#include "test_util.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* Fills the stack below this frame with junk, so that a record the next call leaves
 * uninitialised holds junk rather than the zeros of a fresh stack. */
static __attribute__((noinline)) void dirty_stack(void) {
    volatile unsigned char junk[16384];
    for (size_t i = 0; i < sizeof junk; i++)
        junk[i] = 0xA5;
}

typedef struct piece_case {
    shape_mesh mesh;
    rsmooth_piece_info info; /* valid: the whole mesh as one piece */
    double *expected;        /* the in-memory reference path's result */
    double *out;
} piece_case;

static void make_case(piece_case *c) {
    CHECK(shape_capped_cylinder(&c->mesh, 1.0, 1.0, 2000) == 0);
    CHECK(shape_add_normal_noise(&c->mesh, 0.3 * shape_mean_edge_length(&c->mesh), 3) == 0);
    size_t v = c->mesh.vertex_count;
    c->expected = malloc(v * 3 * sizeof *c->expected);
    c->out = malloc(v * 3 * sizeof *c->out);
    CHECK(c->expected && c->out);
    rsmooth_report rep;
    rsmooth_report_init(&rep);
    rsmooth_error err;
    CHECK_STATUS(rsmooth_smooth(NULL, RSMOOTH_FLOAT64, c->mesh.xyz, v, c->mesh.indices,
                                c->mesh.triangle_count, NULL, c->expected,
                                OUTPUTS(NULL, NULL, &rep), &err),
                 RSMOOTH_OK);
    /* the mean area (the reference path's positions do not depend on it): non-zero triangles */
    double sum = 0;
    size_t facets = 0;
    for (size_t t = 0; t < c->mesh.triangle_count; t++) {
        const double *p[3];
        for (int k = 0; k < 3; k++)
            p[k] = c->mesh.xyz + 3 * (size_t)c->mesh.indices[3 * t + (size_t)k];
        double e1[3], e2[3];
        for (int k = 0; k < 3; k++) {
            e1[k] = p[1][k] - p[0][k];
            e2[k] = p[2][k] - p[0][k];
        }
        double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                       e1[0] * e2[1] - e1[1] * e2[0]};
        double area = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) / 2;
        facets += area > 0;
        sum += area;
    }
    CHECK(rsmooth_piece_info_init(&c->info) == RSMOOTH_OK);
    c->info.core_count = v;
    c->info.mean_edge_length = rep.mean_edge_length;
    c->info.mean_area = sum / (double)facets;
    c->info.scale = 0;
    printf("piece: %zu vertices, %zu triangles, mean edge %.6g, mean area %.6g\n", v,
           c->mesh.triangle_count, c->info.mean_edge_length, c->info.mean_area);
}

static rsmooth_status smooth(rsmooth_context *ctx, piece_case *c, const rsmooth_piece_info *info,
                             const rsmooth_params *params, double *out, rsmooth_error *err) {
    return rsmooth_smooth_piece(ctx, c->mesh.xyz, c->mesh.vertex_count, c->mesh.indices,
                                c->mesh.triangle_count, info, params, out, NULL, err);
}

/* The field refused, named in the message, and nothing written. */
static void check_refused(rsmooth_context *ctx, piece_case *c, const rsmooth_piece_info *info,
                          const char *needle) {
    size_t n = c->mesh.vertex_count * 3;
    for (size_t i = 0; i < n; i++)
        c->out[i] = -12345.0;
    rsmooth_error err;
    rsmooth_error_init(&err);
    dirty_stack();
    rsmooth_status st = smooth(ctx, c, info, NULL, c->out, &err);
    printf("  %-9s %-26s %s: %s\n", ctx ? "device" : "reference", needle, rsmooth_status_str(st),
           err.message);
    CHECK_EQ_INT(st, RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(err.message, needle) != NULL);
    for (size_t i = 0; i < n; i++)
        CHECK(c->out[i] == -12345.0);
}

static void check_info_fields(rsmooth_context *ctx, piece_case *c) {
    const rsmooth_piece_info good = c->info;
    rsmooth_piece_info bad;
    const struct {
        const char *field;
        double value;
    } scales[] = {{"info->scale", ldexp(1, -1030)},
                  {"info->scale", ldexp(1, -501)},
                  {"info->scale", ldexp(1, 1001)},
                  {"info->scale", 3.0},
                  {"info->scale", -1.0},
                  {"info->scale", NAN},
                  {"info->scale", INFINITY},
                  {"typical edge", ldexp(1, 300)},
                  {"typical edge", ldexp(1, -300)}};
    for (size_t i = 0; i < sizeof scales / sizeof *scales; i++) {
        bad = good;
        bad.scale = scales[i].value;
        check_refused(ctx, c, &bad, scales[i].field);
    }
    const double figures[] = {0, -1, NAN, INFINITY};
    for (size_t i = 0; i < sizeof figures / sizeof *figures; i++) {
        bad = good;
        bad.mean_edge_length = figures[i];
        check_refused(ctx, c, &bad, "info->mean_edge_length");
        bad = good;
        bad.mean_area = figures[i];
        check_refused(ctx, c, &bad, "info->mean_area");
    }
    const struct {
        double mean_edge_length;
        const char *why;
    } far[] = {{1e308, "range of numbers"}, /* a reach of inf: every vertex stayed, exit 0 */
               {DBL_MAX, "range of numbers"}};
    for (size_t i = 0; i < sizeof far / sizeof *far; i++) {
        bad = good;
        bad.mean_edge_length = far[i].mean_edge_length;
        check_refused(ctx, c, &bad, far[i].why);
    }
    bad = good; /* more than any mesh of this mean edge can have: results 0.08 edges off */
    bad.mean_area = 1.5e300;
    check_refused(ctx, c, &bad, "more than any mesh");
    bad = good; /* figures whose internal units fall out of the normal doubles */
    bad.mean_area = 1e-300;
    bad.scale = ldexp(1, -40);
    check_refused(ctx, c, &bad, "internal units");
    bad = good;
    bad.core_count = c->mesh.vertex_count + 1;
    check_refused(ctx, c, &bad, "info->core_count");
    bad = good;
    bad.keep_memory = 2;
    check_refused(ctx, c, &bad, "info->keep_memory");
    bad = good;
    bad.struct_size = 0;
    check_refused(ctx, c, &bad, "info->struct_size");
    check_refused(ctx, c, NULL, "info is NULL");
}

/* The reference path on the piece with `info`: how many coordinates differ from the in-memory
 * reference path's. */
static size_t differ_with(piece_case *c, const rsmooth_piece_info *info) {
    rsmooth_error err;
    CHECK_STATUS(smooth(NULL, c, info, NULL, c->out, &err), RSMOOTH_OK);
    size_t differ = 0;
    for (size_t k = 0; k < 3 * c->mesh.vertex_count; k++)
        differ += c->out[k] != c->expected[k];
    return differ;
}

/* Scales a whole mesh of this piece could have: the reference path's bits (a power of two
 * changes no bit while nothing over- or underflows). */
static void check_valid_scales(piece_case *c) {
    const int exponents[] = {0, 3, 4, -100, 100, 200};
    for (int i = -1; i < (int)(sizeof exponents / sizeof *exponents); i++) {
        rsmooth_piece_info info = c->info;
        info.scale = i < 0 ? 0 : ldexp(1, exponents[i]);
        size_t differ = differ_with(c, &info);
        printf("  scale %-8g: %zu coordinates differ from the in-memory reference path\n",
               info.scale, differ);
        CHECK(differ == 0);
    }
    /* a record of the first published size (0.7: keep_memory beyond it, read as 0, whatever the
     * bytes there), and one keeping its memory: the same bits */
    for (int variant = 0; variant < 2; variant++) {
        rsmooth_piece_info info = c->info;
        info.keep_memory = variant == 0 ? 99 : 1;
        if (variant == 0)
            info.struct_size = offsetof(rsmooth_piece_info, keep_memory);
        size_t differ = differ_with(c, &info);
        printf("  %s: %zu coordinates differ\n",
               variant == 0 ? "a 0.7-size record" : "keep_memory 1", differ);
        CHECK(differ == 0);
    }
}

/* Refusals before the piece is prepared: the clean-up frees only what was allocated. */
static void check_early_refusals(rsmooth_context *ctx, piece_case *c) {
    rsmooth_params two;
    rsmooth_params_init(&two);
    two.passes = 2;
    rsmooth_error err;
    dirty_stack();
    CHECK_STATUS(smooth(ctx, c, &c->info, NULL, NULL, &err), RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(err.message, "out_positions") != NULL);
    dirty_stack();
    CHECK_STATUS(smooth(ctx, c, &c->info, &two, c->out, &err), RSMOOTH_ERROR_UNSUPPORTED);
    CHECK(strstr(err.message, "passes") != NULL);
    dirty_stack();
    CHECK_STATUS(smooth(ctx, c, &c->info, NULL, c->mesh.xyz, &err), RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(err.message, "overlaps") != NULL);
    printf("  %s: NULL out_positions, passes 2, overlapping buffers refused\n",
           ctx ? "device" : "reference");
}

/* The whole mesh as one piece, its first half the core: the core's weights and confidences are
 * the in-memory run's on the same path, bit for bit. */
static void check_outputs(rsmooth_context *ctx, piece_case *c) {
    size_t v = c->mesh.vertex_count, core = v / 2;
    float *weight = malloc(v * sizeof *weight), *confidence = malloc(v * sizeof *confidence);
    float *piece_weight = malloc(v * sizeof *weight);
    float *piece_confidence = malloc(v * sizeof *confidence);
    CHECK(weight && confidence && piece_weight && piece_confidence);
    rsmooth_error err;
    double *whole = malloc(v * 3 * sizeof *whole);
    CHECK(whole != NULL);
    if (ctx)
        CHECK_STATUS(rsmooth_smooth(ctx, RSMOOTH_FLOAT64, c->mesh.xyz, v, c->mesh.indices,
                                    c->mesh.triangle_count, NULL, whole,
                                    OUTPUTS(weight, confidence, NULL), &err),
                     RSMOOTH_OK);
    else
        CHECK_STATUS(rsmooth_smooth(NULL, RSMOOTH_FLOAT64, c->mesh.xyz, v, c->mesh.indices,
                                    c->mesh.triangle_count, NULL, whole,
                                    OUTPUTS(weight, confidence, NULL), &err),
                     RSMOOTH_OK);
    rsmooth_piece_info info = c->info;
    info.core_count = core;
    for (size_t i = 0; i < v; i++)
        piece_weight[i] = piece_confidence[i] = -1;
    CHECK_STATUS(rsmooth_smooth_piece(ctx, c->mesh.xyz, v, c->mesh.indices, c->mesh.triangle_count,
                                      &info, NULL, c->out,
                                      OUTPUTS(piece_weight, piece_confidence, NULL), &err),
                 RSMOOTH_OK);
    size_t differ = 0, past = 0;
    for (size_t i = 0; i < core; i++)
        differ += piece_weight[i] != weight[i] || piece_confidence[i] != confidence[i] ||
                  memcmp(c->out + 3 * i, whole + 3 * i, 3 * sizeof *whole) != 0;
    for (size_t i = core; i < v; i++) /* nothing beyond the core */
        past += piece_weight[i] != -1 || piece_confidence[i] != -1;
    printf("  %s: %zu of %zu core vertices differ in position, weight or confidence from the "
           "in-memory run; %zu written past the core\n",
           ctx ? "device" : "reference", differ, core, past);
    CHECK(differ == 0 && past == 0);
    CHECK_STATUS(rsmooth_smooth_piece(ctx, c->mesh.xyz, v, c->mesh.indices, c->mesh.triangle_count,
                                      &info, NULL, c->out,
                                      OUTPUTS(piece_weight, piece_weight + 1, NULL), &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    printf("  overlapping outputs: %s\n", err.message);
    CHECK(strstr(err.message, "outputs->weight overlaps") != NULL);
    free(whole);
    free(weight);
    free(confidence);
    free(piece_weight);
    free(piece_confidence);
}

static void check_halo(void) {
    double halo = -1;
    rsmooth_error err;
    CHECK_STATUS(rsmooth_piece_halo(NULL, 0.1, 0.05, &halo, &err), RSMOOTH_OK);
    CHECK(halo > 0 && isfinite(halo));
    halo = -1;
    CHECK_STATUS(rsmooth_piece_halo(NULL, 1e308, 0, &halo, &err), RSMOOTH_ERROR_INVALID_ARGUMENT);
    printf("halo of mean edge 1e308: %s\n", err.message);
    CHECK(strstr(err.message, "halo") != NULL || strstr(err.message, "range of numbers") != NULL);
    CHECK(halo == -1);
}

/* A mesh file of the shape, for the stream's refusals. */
static void write_mesh(const shape_mesh *m, const char *path) {
    rsmooth_mesh *mesh = NULL;
    rsmooth_error err;
    CHECK_STATUS(
        rsmooth_mesh_create(m->vertex_count, m->triangle_count, 3 * m->triangle_count, &mesh, &err),
        RSMOOTH_OK);
    memcpy(mesh->positions, m->xyz, m->vertex_count * 3 * sizeof *m->xyz);
    for (size_t f = 0; f <= m->triangle_count; f++)
        mesh->face_offsets[f] = (uint32_t)(3 * f);
    memcpy(mesh->face_indices, m->indices, 3 * m->triangle_count * sizeof *m->indices);
    CHECK_STATUS(rsmooth_mesh_write_file(mesh, path, RSMOOTH_FORMAT_PLY_BINARY, &err), RSMOOTH_OK);
    rsmooth_mesh_destroy(mesh);
}

static void check_stream_ranks(const shape_mesh *m) {
    char dir[] = "/tmp/rsmooth-piece-args-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char in[64], out[64];
    snprintf(in, sizeof in, "%s/in.ply", dir);
    snprintf(out, sizeof out, "%s/out.ply", dir);
    write_mesh(m, in);
    const struct {
        int rank, ranks;
        const char *needle;
    } cases[] = {{0, 2, "options->sync"}, {1, 2, "options->sync"}, {1, 0, "options->rank"},
                 {3, 1, "options->rank"}, {2, 2, "options->rank"}, {0, -1, "options->ranks"}};
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        rsmooth_stream_options so;
        rsmooth_stream_options_init(&so);
        so.max_memory = 64u << 20;
        so.rank = cases[i].rank;
        so.ranks = cases[i].ranks;
        rsmooth_error err;
        rsmooth_status st = rsmooth_stream_smooth(NULL, in, out, NULL, &so, NULL, &err);
        printf("stream rank %d of %d, no sync: %s: %s\n", so.rank, so.ranks, rsmooth_status_str(st),
               err.message);
        CHECK_EQ_INT(st, RSMOOTH_ERROR_INVALID_ARGUMENT);
        CHECK(strstr(err.message, cases[i].needle) != NULL);
        CHECK(access(out, F_OK) != 0);
    }
    CHECK(unlink(in) == 0 && rmdir(dir) == 0);
}

int main(void) {
    piece_case c;
    make_case(&c);
    rsmooth_context *ctx = open_test_context();
    printf("early refusals:\n");
    check_early_refusals(NULL, &c);
    check_early_refusals(ctx, &c);
    check_halo();
    printf("weights and confidences of a piece's core:\n");
    check_outputs(NULL, &c);
    check_outputs(ctx, &c);
    printf("the scales a whole mesh of this piece could have:\n");
    check_valid_scales(&c);
    printf("refused fields:\n");
    check_info_fields(NULL, &c);
    check_info_fields(ctx, &c);
    check_stream_ranks(&c.mesh);
    rsmooth_context_destroy(ctx);
    free(c.expected);
    free(c.out);
    shape_free(&c.mesh);
    printf("ok\n");
    return 0;
}
