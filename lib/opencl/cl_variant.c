/* Which kernel variant a device runs, and how wide.
 *
 * CPU devices run the block kernels: a work-item filters a block of RS_LANES vertices, one per
 * vector lane, so the width is the device's preferred float vector width (PoCL reports 16 with
 * AVX-512, 8 with AVX2, 4 with SSE): rsmooth-bench measured blocks of 16 about a fifth faster
 * than blocks of 8 on AVX-512, and 4 about half as fast.
 * GPUs run the group variant (RS_LANES 1): one vertex per work-item, RS_GROUP consecutive
 * vertices (grid order) per work-group, which searches the cells near the group's box once and
 * stages their facets through local memory (kernels/common.cl, FOR_EACH_FACET_NEAR).
 * Both compute every vertex's sums in the same order over the same facets: they differ only in
 * how the work is spread. */
#include "opencl/cl_grid.h"
#include "opencl/cl_internal.h"

#include <stdlib.h>
#include <string.h>

/* Work-items per group in the group variant: two NVIDIA warps, one AMD wavefront. */
#define GROUP_SIZE 64

static size_t max_group(cl_device_id device) {
    size_t max_size = 1; /* what every device takes, should the query fail */
    if (clGetDeviceInfo(device, CL_DEVICE_MAX_WORK_GROUP_SIZE, sizeof max_size, &max_size, NULL) !=
        CL_SUCCESS)
        max_size = 1;
    return max_size;
}

/* Largest power of two at most `wanted` that the device takes in one work-group. */
static size_t fit_group(cl_device_id device, size_t wanted) {
    size_t max_size = max_group(device), local = wanted;
    while (local > max_size)
        local /= 2;
    return local ? local : 1;
}

rsmooth_status rs_cl_choose_variant(rsmooth_context *ctx, rsmooth_error *error) {
    static const char where[] = "rsmooth_context_create";
    cl_device_type type = CL_DEVICE_TYPE_CPU;
    if (clGetDeviceInfo(ctx->device, CL_DEVICE_TYPE, sizeof type, &type, NULL) != CL_SUCCESS)
        type = CL_DEVICE_TYPE_CPU;
    bool group_variant = (type & CL_DEVICE_TYPE_GPU) != 0;
    const char *variant = ctx->env.value[RS_ENV_KERNEL_VARIANT];
    if (variant && *variant) {
        if (strcmp(variant, "gpu") != 0 && strcmp(variant, "cpu") != 0)
            return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                           "RSMOOTH_KERNEL_VARIANT is \"%s\": use gpu (one vertex per work-item) "
                           "or cpu (vector blocks)",
                           variant);
        group_variant = variant[0] == 'g';
    }
    if (group_variant) {
        ctx->lanes = 1;
        ctx->local_size = fit_group(ctx->device, GROUP_SIZE);
        return RSMOOTH_OK;
    }
    cl_uint preferred = 8;
    if (clGetDeviceInfo(ctx->device, CL_DEVICE_PREFERRED_VECTOR_WIDTH_FLOAT, sizeof preferred,
                        &preferred, NULL) != CL_SUCCESS)
        preferred = 8;
    ctx->lanes = preferred >= 16 ? 16 : preferred >= 8 ? 8 : 4;
    const char *lanes = ctx->env.value[RS_ENV_LANES];
    if (lanes && *lanes) {
        if (strcmp(lanes, "4") != 0 && strcmp(lanes, "8") != 0 && strcmp(lanes, "16") != 0)
            return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                           "RSMOOTH_LANES is \"%s\": use 4, 8 or 16 (vertices per block on a "
                           "CPU device)",
                           lanes);
        ctx->lanes = (unsigned)atoi(lanes);
    }
    /* an explicit work-group size helps PoCL vectorize across work-items */
    ctx->local_size = fit_group(ctx->device, 64);
    return RSMOOTH_OK;
}

/* Whether the grid is sorted on the device too (cl_grid.c): a choice of what a device runs, as
 * the variant is, and made here so that the program (cl_program.c) and the runs agree. */
static bool has_fp64(const rsmooth_context *ctx) {
    cl_device_fp_config config = 0;
    return clGetDeviceInfo(ctx->device, CL_DEVICE_DOUBLE_FP_CONFIG, sizeof config, &config, NULL) ==
               CL_SUCCESS &&
           config != 0;
}

bool rs_cl_device_grid(const rsmooth_context *ctx) {
    const char *forced = ctx->env.value[RS_ENV_DEVICE_GRID];
    bool want;
    if (forced && (strcmp(forced, "0") == 0 || strcmp(forced, "1") == 0)) {
        want = forced[0] == '1';
    } else {
        cl_device_type type = 0;
        want =
            clGetDeviceInfo(ctx->device, CL_DEVICE_TYPE, sizeof type, &type, NULL) == CL_SUCCESS &&
            (type & CL_DEVICE_TYPE_GPU);
    }
    return want && has_fp64(ctx);
}
