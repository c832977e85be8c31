/* The learned normals' networks on the OpenCL device (opencl/cl_learned.c, kernels/learned.cl)
 * against the host's in double (learned/network.c): on a noisy cylinder of more facets than one
 * chunk (so a full chunk and a part chunk, whose last tile is part padding), every final unit
 * normal within 1e-5, for a random model of the widths the format is meant for (read from bytes
 * encoded as train/model_file.py writes them, so the test does not lean on the shipped weights)
 * and for the built-in one, in both kernel variants (RSMOOTH_KERNEL_VARIANT: a work-item per
 * facet, and the GPU's work-groups over tiles, which PoCL runs as well). A runner that fails
 * leaves the host to run its chunks: the same bytes as the host alone, whatever the runner wrote
 * into the residuals before failing, and a runner that fails on one chunk only still agrees. */
#define _POSIX_C_SOURCE 200809L
#include "learned/learned.h"
#include "mesh_shapes.h"
#include "opencl/cl_internal.h"
#include "stages/normal_update.h"
#include "test_cl_util.h"
#include "test_model.h"

#include <math.h>
#include <string.h>

/* More facets than learned_normals.c's chunk of 16384 (17250), the rest not a whole number of
 * the GPU variant's tiles nor of work-groups. */
#define TRIANGLES 17250
#define TOLERANCE 1e-5

/* ---- runners ------------------------------------------------------------------------------- */

/* Writes nonsense into the residuals, then refuses: none of it may reach a normal. */
static rsmooth_status failing_runner(void *ctx, const rs_learned_stage *stage,
                                     const float *descriptors, size_t count, float *residuals) {
    (void)ctx;
    (void)stage;
    (void)descriptors;
    for (size_t i = 0; i < 3 * count; i++)
        residuals[i] = 1e6f;
    return RSMOOTH_ERROR_OPENCL;
}

/* The device's runner on every chunk but those of 16384 facets (the first of each stage). */
static rsmooth_status partial_runner(void *ctx, const rs_learned_stage *stage,
                                     const float *descriptors, size_t count, float *residuals) {
    if (count == 16384)
        return failing_runner(ctx, stage, descriptors, count, residuals);
    return rs_cl_learned_run(ctx, stage, descriptors, count, residuals);
}

/* ---- the comparison ------------------------------------------------------------------------ */

typedef struct scene {
    rs_facets facets;
    rs_learned_patches patches;
    rs_learned_input in;
} scene;

static void make_scene(scene *s) {
    shape_mesh mesh;
    CHECK(shape_capped_cylinder(&mesh, 1.0, 2.0, TRIANGLES) == 0);
    double unit = shape_mean_edge_length(&mesh);
    CHECK(shape_add_normal_noise(&mesh, 0.3 * unit, 7) == 0);
    CHECK(rs_facets_build(&s->facets, mesh.xyz, mesh.indices, mesh.triangle_count));
    CHECK(rs_learned_patches_build(&s->patches, s->facets.centroid, s->facets.count));
    s->in = (rs_learned_input){s->facets.count,
                               s->facets.centroid,
                               s->facets.area,
                               s->facets.normal,
                               &s->patches,
                               unit,
                               0.3};
    shape_free(&mesh);
}

/* Every stage of `model` through `place` (NULL: the host); normals, 3 per facet, malloc'd. */
static double *run(const rs_learned_model *model, const scene *s, rs_network_runner runner,
                   void *ctx, double *ms) {
    double *normals = malloc(3 * s->facets.count * sizeof *normals);
    CHECK(normals);
    rs_network_place place = {runner, ctx};
    double t0 = rs_now_ms();
    CHECK(rs_learned_normals(model, (int)model->stage_count, &s->in, runner ? &place : NULL,
                             normals));
    if (ms)
        *ms = rs_now_ms() - t0;
    return normals;
}

/* The largest distance between two sets of unit normals. */
static double largest_difference(const double *a, const double *b, size_t count) {
    double worst = 0;
    for (size_t f = 0; f < count; f++) {
        double d[3] = {a[3 * f] - b[3 * f], a[3 * f + 1] - b[3 * f + 1],
                       a[3 * f + 2] - b[3 * f + 2]};
        worst = fmax(worst, sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
    }
    return worst;
}

/* Runners that fail: the host's bytes where every chunk fails, and where only the full chunks do
 * (the part chunks on the device), the host's within the tolerance. */
static void check_fallbacks(const rs_learned_model *model, const scene *s, rsmooth_context *ctx,
                            const double *host) {
    size_t n = s->facets.count;
    double *failed = run(model, s, failing_runner, NULL, NULL);
    CHECK(memcmp(failed, host, 3 * n * sizeof *host) == 0);
    double *partial = run(model, s, partial_runner, ctx, NULL);
    double mixed = largest_difference(host, partial, n);
    printf("  a failing runner: the host's bytes; failing on full chunks only: %.3g\n", mixed);
    CHECK_LE(mixed, TOLERANCE);
    free(failed);
    free(partial);
}

/* The device's variant in `ctx` against the host for `model`; with `random_weights`, that the
 * device's float shows (the built-in model's weights may all be 0), and the failing runners. */
static void compare(const char *name, const rs_learned_model *model, const scene *s,
                    rsmooth_context *ctx, bool random_weights) {
    size_t n = s->facets.count;
    double host_ms, device_ms;
    double *host = run(model, s, NULL, NULL, &host_ms);
    double *device = run(model, s, rs_cl_learned_run, ctx, &device_ms);
    double worst = largest_difference(host, device, n);
    printf("%s (%zu parameters): %zu facets, largest normal difference %.3g (host %.0f ms, "
           "device %.0f ms)\n",
           name, model->parameters, n, worst, host_ms, device_ms);
    CHECK_LE(worst, TOLERANCE);
    if (random_weights) {
        CHECK(worst > 0); /* float on the device: the device did run */
        check_fallbacks(model, s, ctx, host);
    }
    free(host);
    free(device);
}

_Static_assert(MODEL_INPUTS == RS_LEARNED_INPUTS && MODEL_NEIGHBOURS == RS_LEARNED_NEIGHBOURS &&
                   MODEL_LAYOUT == RS_LEARNED_LAYOUT,
               "test_model.h's descriptor layout");

int main(void) {
    scene s;
    make_scene(&s);
    CHECK(s.facets.count > 16384 && s.facets.count < 2 * 16384);
    CHECK(s.facets.count % RS_LEARNED_TILE != 0 && s.facets.count % 64 != 0);
    /* the shipped widths; under the sanitizers (RSMOOTH_TEST_SMALL) narrower layers, the same
     * chunks, tiles and checks: the host's double network is what takes the time there */
    static const uint32_t hidden[] = {176, 176, 96}, narrow[] = {24, 16, 8};
    model_bytes encoded = random_model(2, test_small() ? narrow : hidden, 3, 42);
    rs_learned_model random_weights, builtin;
    rsmooth_error err;
    CHECK_STATUS(rs_learned_model_read(encoded.at, encoded.size, &random_weights, &err, "test"),
                 RSMOOTH_OK);
    CHECK_STATUS(rs_learned_model_builtin(&builtin, &err), RSMOOTH_OK);
    for (int variant = 0; variant < 2; variant++) {
        /* the context reads its variant when it is made */
        setenv("RSMOOTH_KERNEL_VARIANT", variant ? "gpu" : "cpu", 1);
        rsmooth_context *ctx = open_test_context();
        printf("variant %s (%u lanes, work-groups of %zu)\n", variant ? "gpu" : "cpu", ctx->lanes,
               ctx->local_size);
        compare(test_small() ? "random model 240-24-16-8-3, 2 stages"
                             : "random model 240-176-176-96-3, 2 stages",
                &random_weights, &s, ctx, true);
        compare("built-in model", &builtin, &s, ctx, false);
        rsmooth_context_destroy(ctx);
    }
    printf("FLOPs per facet per stage (2 x parameters): random model %zu, built-in %zu\n",
           2 * random_weights.parameters / random_weights.stage_count,
           2 * builtin.parameters / builtin.stage_count);
    rs_learned_model_free(&random_weights);
    rs_learned_model_free(&builtin);
    free(encoded.at);
    rs_learned_patches_free(&s.patches);
    rs_facets_free(&s.facets);
    printf("ok\n");
    return 0;
}
