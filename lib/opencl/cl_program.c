/* Assembling and building the OpenCL program: a generated prelude, then common.cl, then one file
 * per phase. Kernels are embedded at build time; RSMOOTH_KERNEL_DIR loads them from a directory
 * instead. */
#define _POSIX_C_SOURCE 200809L
#include "learned/learned.h"
#include "opencl/cl_grid.h"
#include "opencl/cl_internal.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

extern const unsigned char rs_kernel_common[], rs_kernel_mollify[], rs_kernel_bilateral[],
    rs_kernel_estimate[], rs_kernel_learned[], rs_kernel_stage[];
extern const size_t rs_kernel_common_size, rs_kernel_mollify_size, rs_kernel_bilateral_size,
    rs_kernel_estimate_size, rs_kernel_learned_size, rs_kernel_stage_size;
extern const unsigned char rs_kernel_grid[];
extern const size_t rs_kernel_grid_size;

/* The kernel files in the order they are compiled, after the prelude and the device's shape. */
#define KERNEL_FILES 7
/* The most strings compiled: the prelude, the device's shape, the files, and stage.cl's second
 * copy with the definitions before each copy and the end of the double one's #if. */
#define SOURCES (KERNEL_FILES + 6)

/* stage.cl's types and kernel names, per copy (kernels/stage.cl) */
static const char stage_float[] = "#define REAL float\n#define REAL4 float4\n"
                                  "#define STAGE_NAME(name) name##_f\n";
static const char stage_double[] =
    "#undef REAL\n#undef REAL4\n#undef STAGE_NAME\n#ifdef cl_khr_fp64\n"
    "#pragma OPENCL EXTENSION cl_khr_fp64 : enable\n"
    "#define REAL double\n#define REAL4 double4\n"
    "#define STAGE_NAME(name) name##_d\n";
static const char stage_end[] = "\n#endif\n";

/* Constants the host and kernels must agree on. Runtime values (sigmas, counts) are kernel
 * arguments, so changing them never rebuilds the program. */
#define STRINGIFY(x) #x
#define EXPANDED_STRING(x) STRINGIFY(x)
#define FLOAT_DEFINE(name, value) "#define " #name " " STRINGIFY(value) "f\n"
static const char prelude[] = FLOAT_DEFINE(RS_DEGENERATE_SINE, RS_DEGENERATE_SINE) FLOAT_DEFINE(
    RS_DEGENERATE_AREA_RATIO, RS_DEGENERATE_AREA_RATIO) "#define RS_RESCUE_WEIGHT 1e-20f\n"
                                                        "#define RS_INFLUENCE_GAUSSIAN 0\n"
                                                        "#define RS_INFLUENCE_TUKEY 1\n"
                                                        "#define RS_INFLUENCE_LORENTZIAN 2\n"
                                                        "#define RS_INFLUENCE_HUBER 3\n";
/* enum constants do not stringify: the values above are written out, and checked here */
_Static_assert(RSMOOTH_INFLUENCE_GAUSSIAN == 0 && RSMOOTH_INFLUENCE_TUKEY == 1 &&
                   RSMOOTH_INFLUENCE_LORENTZIAN == 2 && RSMOOTH_INFLUENCE_HUBER == 3,
               "the kernels' RS_INFLUENCE_ values");

/* Default options: relaxed math lets PoCL vectorize exp(); precision is checked against the
 * double-precision reference path by the tests. */
static const char default_options[] = "-cl-std=CL1.2 -cl-fast-relaxed-math";

static char *read_text_file(const char *dir, const char *name, size_t *size) {
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    char *text = NULL;
    if (fseek(f, 0, SEEK_END) == 0) {
        long n = ftell(f);
        if (n >= 0 && fseek(f, 0, SEEK_SET) == 0) {
            text = rs_alloc_array((size_t)n + 1, 1);
            if (text && fread(text, 1, (size_t)n, f) == (size_t)n) {
                text[n] = '\0';
                *size = (size_t)n;
            } else {
                rs_free(text);
                text = NULL;
            }
        }
    }
    fclose(f);
    return text;
}

/* The program's kernels; the double ones may be missing (a device without fp64: NULL). */
static rsmooth_status create_kernels(rsmooth_context *ctx, rsmooth_error *error) {
    static const char *const kernel_names[RS_KERNEL_COUNT] = {
        [RS_KERNEL_MOLLIFY] = "mollify_block",
        [RS_KERNEL_NORMALS] = "mollified_facet_normal",
        [RS_KERNEL_BILATERAL] = "bilateral_cell_normals",
        [RS_KERNEL_ROBUST] = "robust_block",
        [RS_KERNEL_LEARNED] = "learned_stage",
        [RS_KERNEL_STAGE_FLOAT + RS_STAGE_FACETS] = "stage_facets_f",
        [RS_KERNEL_STAGE_FLOAT + RS_STAGE_PATCH] = "stage_patch_f",
        [RS_KERNEL_STAGE_FLOAT + RS_STAGE_GUIDANCE] = "stage_guidance_f",
        [RS_KERNEL_STAGE_FLOAT + RS_STAGE_FILTER] = "stage_filter_f",
        [RS_KERNEL_STAGE_FLOAT + RS_STAGE_VERTEX] = "stage_vertex_f",
        [RS_KERNEL_STAGE_DOUBLE + RS_STAGE_FACETS] = "stage_facets_d",
        [RS_KERNEL_STAGE_DOUBLE + RS_STAGE_PATCH] = "stage_patch_d",
        [RS_KERNEL_STAGE_DOUBLE + RS_STAGE_GUIDANCE] = "stage_guidance_d",
        [RS_KERNEL_STAGE_DOUBLE + RS_STAGE_FILTER] = "stage_filter_d",
        [RS_KERNEL_STAGE_DOUBLE + RS_STAGE_VERTEX] = "stage_vertex_d"};
    for (int k = 0; k < RS_KERNEL_COUNT; k++) {
        cl_int err = CL_SUCCESS;
        ctx->kernels[k] = clCreateKernel(ctx->program, kernel_names[k], &err);
        if (err != CL_SUCCESS && k >= RS_KERNEL_STAGE_DOUBLE) /* a device without fp64 */
            ctx->kernels[k] = NULL;
        else if (err != CL_SUCCESS)
            return rs_cl_fail(error, err, "clCreateKernel", kernel_names[k]);
    }
    return RSMOOTH_OK;
}

static rsmooth_status build_program_once(rsmooth_context *ctx, rsmooth_error *error) {
    static const char *const names[KERNEL_FILES] = {"common.cl",   "mollify.cl", "bilateral.cl",
                                                    "estimate.cl", "grid.cl",    "learned.cl",
                                                    "stage.cl"};
    /* the variant this device runs (cl_variant.c): its vector width and work-group size; the
     * learned networks' tile (cl_learned.c launches by it) and widest layer */
    char shape[192];
    snprintf(shape, sizeof shape,
             "#define RS_LANES %u\n#define RS_GROUP %zu\n#define RS_LEARNED_TILE %d\n"
             "#define RS_LEARNED_MAX_WIDTH %d\n",
             ctx->lanes, ctx->local_size, RS_LEARNED_TILE, RS_LEARNED_MAX_WIDTH);
    const char *sources[SOURCES] = {prelude,
                                    shape,
                                    (const char *)rs_kernel_common,
                                    (const char *)rs_kernel_mollify,
                                    (const char *)rs_kernel_bilateral,
                                    (const char *)rs_kernel_estimate,
                                    (const char *)rs_kernel_grid,
                                    (const char *)rs_kernel_learned,
                                    (const char *)rs_kernel_stage};
    size_t sizes[SOURCES] = {sizeof prelude - 1,       strlen(shape),
                             rs_kernel_common_size,    rs_kernel_mollify_size,
                             rs_kernel_bilateral_size, rs_kernel_estimate_size,
                             rs_kernel_grid_size,      rs_kernel_learned_size,
                             rs_kernel_stage_size};
    char *loaded[KERNEL_FILES] = {NULL};
    /* grid.cl only where the grid is sorted on the device (rs_cl_device_grid): a CPU device's
     * program stays without its kernels, whose loading would lengthen every setup */
    const bool grid = rs_cl_device_grid(ctx);
    rsmooth_status st = RSMOOTH_OK;
    const char *dir = ctx->env.value[RS_ENV_KERNEL_DIR];
    if (dir && *dir) {
        for (int i = 0; i < KERNEL_FILES; i++) {
            if (!grid && strcmp(names[i], "grid.cl") == 0)
                continue;
            loaded[i] = read_text_file(dir, names[i], &sizes[i + 2]);
            if (!loaded[i]) {
                st = rs_fail(error, RSMOOTH_ERROR_IO, "RSMOOTH_KERNEL_DIR", "cannot read %s/%s",
                             dir, names[i]);
                goto done;
            }
            sources[i + 2] = loaded[i];
        }
    }
    int files = KERNEL_FILES;
    for (int i = 0; !grid && i < files; i++)
        if (strcmp(names[i], "grid.cl") == 0) { /* left out: the sources after it move up */
            memmove(&sources[i + 2], &sources[i + 3], (size_t)(files - 1 - i) * sizeof *sources);
            memmove(&sizes[i + 2], &sizes[i + 3], (size_t)(files - 1 - i) * sizeof *sizes);
            files--;
        }
    /* stage.cl, the last file, twice: in float, and in double where the device has it */
    const char *stage = sources[files + 1];
    size_t stage_size = sizes[files + 1];
    const char *const tail[5] = {stage_float, stage, stage_double, stage, stage_end};
    const size_t tail_sizes[5] = {sizeof stage_float - 1, stage_size, sizeof stage_double - 1,
                                  stage_size, sizeof stage_end - 1};
    for (int i = 0; i < 5; i++) {
        sources[files + 1 + i] = tail[i];
        sizes[files + 1 + i] = tail_sizes[i];
    }
    const cl_uint count = (cl_uint)files + 6; /* the prelude, the shape, the files, 4 more */

    double t0 = rs_now_ms();
    cl_int err = CL_SUCCESS;
    char options[1024];
    const char *extra = ctx->env.value[RS_ENV_BUILD_OPTIONS];
    snprintf(options, sizeof options, "%s %s", default_options, extra ? extra : "");
    /* rsmooth's binary cache (cl_program_cache.c), keyed by exactly the sources and options the
     * build from source below takes */
    rs_program_cache cache;
    ctx->program_cache = rs_program_cache_open(&cache, ctx, count, sources, sizes, options)
                             ? RS_PROGRAM_CACHE_MISS
                             : RS_PROGRAM_CACHE_OFF;
    if ((ctx->program = rs_program_cache_load(&cache, ctx, options))) {
        ctx->program_cache = RS_PROGRAM_CACHE_HIT;
        goto kernels;
    }
    if (cache.refused) {
        ctx->program_cache = RS_PROGRAM_CACHE_REFUSED;
        snprintf(ctx->program_cache_note, sizeof ctx->program_cache_note, "%s", cache.note);
    }
    ctx->program = clCreateProgramWithSource(ctx->context, count, sources, sizes, &err);
    if (err != CL_SUCCESS) {
        st = rs_cl_fail(error, err, "clCreateProgramWithSource", ctx->device_name);
        goto done;
    }
    err = clBuildProgram(ctx->program, 1, &ctx->device, options, NULL, NULL);
    if (err != CL_SUCCESS) {
        st = rs_cl_fail(error, err, "clBuildProgram", ctx->device_name);
        if (error) {
            error->status = st = RSMOOTH_ERROR_KERNEL_BUILD;
            /* The log may exceed our buffer, and OpenCL refuses short buffers: fetch it whole. */
            size_t log_size = 0;
            clGetProgramBuildInfo(ctx->program, ctx->device, CL_PROGRAM_BUILD_LOG, 0, NULL,
                                  &log_size);
            char *log = rs_alloc_array(log_size + 1, 1);
            if (log && clGetProgramBuildInfo(ctx->program, ctx->device, CL_PROGRAM_BUILD_LOG,
                                             log_size, log, NULL) == CL_SUCCESS) {
                log[log_size] = '\0';
                snprintf(error->build_log, sizeof error->build_log, "%s", log);
            }
            rs_free(log);
        } else {
            st = RSMOOTH_ERROR_KERNEL_BUILD;
        }
        goto done;
    }
    rs_program_cache_store(&cache, ctx, ctx->program);
kernels:;
    if ((st = create_kernels(ctx, error)) != RSMOOTH_OK)
        goto done;
    ctx->build_ms = rs_now_ms() - t0;
done:
    for (int i = 0; i < KERNEL_FILES; i++)
        rs_free(loaded[i]);
    return st;
}

/* The largest work-group every kernel of the program takes (CL_KERNEL_WORK_GROUP_SIZE: a GPU
 * lowers it for kernels that use many registers), 0 when the query fails. */
static size_t kernels_group_limit(const rsmooth_context *ctx) {
    size_t limit = SIZE_MAX;
    for (int k = 0; k < RS_KERNEL_COUNT; k++) {
        size_t size = 0;
        if (!ctx->kernels[k]) /* a precision the device does not have */
            continue;
        if (clGetKernelWorkGroupInfo(ctx->kernels[k], ctx->device, CL_KERNEL_WORK_GROUP_SIZE,
                                     sizeof size, &size, NULL) != CL_SUCCESS)
            return 0;
        limit = size < limit ? size : limit;
    }
    return limit;
}

rsmooth_status rs_cl_build_program(rsmooth_context *ctx, rsmooth_error *error) {
    rsmooth_status st = build_program_once(ctx, error);
    /* The group variant compiles its work-group size in (local arrays of RS_GROUP facets): where
     * a kernel takes fewer work-items than that, build again with the largest power of two it
     * takes, rather than fail at the first launch. */
    size_t limit = st == RSMOOTH_OK && ctx->lanes == 1 ? kernels_group_limit(ctx) : 0;
    if (limit > 0 && limit < ctx->local_size) {
        for (int k = 0; k < RS_KERNEL_COUNT; k++) {
            if (ctx->kernels[k])
                clReleaseKernel(ctx->kernels[k]);
            ctx->kernels[k] = NULL;
        }
        clReleaseProgram(ctx->program);
        ctx->program = NULL;
        while (ctx->local_size > 1 && ctx->local_size > limit)
            ctx->local_size /= 2;
        st = build_program_once(ctx, error);
    }
    return st;
}
