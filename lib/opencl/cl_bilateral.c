/* The bilateral normal filter on the device (RSMOOTH_NORMALS_BILATERAL; kernels/bilateral.cl):
 * K rounds over the facet normals of one run, from neighbour lists built once per run where they
 * fit, else searching the grid in every round. */
#include "opencl/cl_run.h"

#include <stdlib.h>
#include <string.h>

/* The bilateral rounds from lists (bilateral_count, bilateral_fill and bilateral_list_normals in
 * kernels/bilateral.cl): the facets near each group are searched for once per run, with the parts
 * of their weights that do not depend on normals, and every round streams them instead of
 * searching again. They take 36 bytes a row, a row per facet near a group (tiles.c plans with
 * RS_DEVICE_BYTES_PER_BILATERAL_FACET); when they would not fit the device (or the caller's
 * budget), *listed stays false and rs_cl_run_bilateral searches in every round instead.
 * RSMOOTH_BILATERAL_LISTS=0 forces that, for tests and measurements. */
typedef struct bilateral_lists {
    cl_uint4 *info; /* per group: first facet, lanes, cell, 0 */
    cl_uint *start; /* the host's copy of list_start */
    cl_uint *facet; /* the lists, in host memory on a device that shares it */
    cl_float *weight;
    cl_kernel count, fill, round;
    cl_mem group_info, list_start, list_facet, list_weight;
} bilateral_lists;

static void bilateral_lists_free(bilateral_lists *l) {
    cl_mem mems[] = {l->group_info, l->list_start, l->list_facet, l->list_weight};
    for (size_t i = 0; i < sizeof mems / sizeof *mems; i++)
        if (mems[i])
            clReleaseMemObject(mems[i]);
    cl_kernel kernels[] = {l->count, l->fill, l->round};
    for (size_t i = 0; i < sizeof kernels / sizeof *kernels; i++)
        if (kernels[i])
            clReleaseKernel(kernels[i]);
    rs_free(l->info); /* after the buffers that used them */
    rs_free(l->start);
    rs_free(l->facet);
    rs_free(l->weight);
}

/* Whether failing with `err` means that the lists did not fit (the rounds search instead). */
static bool lists_out_of_room(cl_int err) {
    return err == CL_MEM_OBJECT_ALLOCATION_FAILURE || err == CL_OUT_OF_RESOURCES ||
           err == CL_OUT_OF_HOST_MEMORY || err == CL_INVALID_BUFFER_SIZE;
}

static cl_int run_bilateral_lists(rsmooth_context *ctx, const rs_problem *pb, const rs_grid *grid,
                                  const cl_mem *buf, cl_mem *normals, uint64_t *pairs,
                                  bool *listed) {
    *listed = false;
    const char *env = getenv("RSMOOTH_BILATERAL_LISTS");
    /* building them costs about what a searching round does: one round is cheaper without */
    if ((env && !strcmp(env, "0")) || pb->normal_iterations < 2)
        return CL_SUCCESS;
    const double h = grid->cell_size, s = pb->normal_sigma_s, t = pb->normal_sigma_n;
    cl_uint mask = grid->column_mask;
    cl_float reach2 = (cl_float)((pb->normal_radius / h) * (pb->normal_radius / h));
    cl_float inv_2s2 = (cl_float)(LOG2_E * h * h / (2 * s * s));
    cl_float inv_2t2 = (cl_float)(LOG2_E / (2 * t * t)); /* normals are unit: no length scale */
    /* The rounds' cheaper form of the normal term, 2 inv_2t2 (n_q . n_r - 1), loses about
     * 2 inv_2t2 float ulps to cancellation: up to 2e-5 of a weight at this limit (t = 0.12),
     * past which they take |n_q - n_r|^2 inv_2t2 itself. */
    cl_int dot = inv_2t2 <= 50;
    cl_float shift = dot ? 2 * inv_2t2 : 0;
    double share = MOLLIFY_SHARE / (pb->normal_iterations + 2); /* a search costs about a round */

    /* the groups of bilateral_cell_normals: each cell's facets, ctx->lanes at a time */
    const size_t lanes_per_group = ctx->lanes;
    size_t groups = 0;
    for (size_t c = 0; c < grid->cell_count; c++)
        groups += (grid->cell_start[c + 1] - grid->cell_start[c] + lanes_per_group - 1) /
                  lanes_per_group;
    /* what this run holds on the device already, and what the groups add */
    size_t start_bytes = (groups + 1) * sizeof(cl_uint);
    uint64_t held = groups * sizeof(cl_uint4) + start_bytes;
    for (int b = 0; b < BUF_COUNT; b++) {
        size_t size = 0;
        if (buf[b] &&
            clGetMemObjectInfo(buf[b], CL_MEM_SIZE, sizeof size, &size, NULL) == CL_SUCCESS)
            held += size;
    }
    uint64_t usable = rs_cl_usable_memory(ctx);
    if (held > usable || groups >= UINT32_MAX)
        return CL_SUCCESS;
    bilateral_lists l;
    memset(&l, 0, sizeof l);
    if (!(l.info = rs_alloc_array(groups, sizeof *l.info)))
        return CL_SUCCESS; /* no host memory for them: search in each round */
    for (size_t c = 0, g = 0; c < grid->cell_count; c++)
        for (uint32_t f = grid->cell_start[c]; f < grid->cell_start[c + 1]; f += lanes_per_group) {
            uint32_t lanes = grid->cell_start[c + 1] - f;
            l.info[g++] = (cl_uint4){
                {f, lanes < lanes_per_group ? lanes : (cl_uint)lanes_per_group, (cl_uint)c, 0}};
        }

    cl_uint group_count = (cl_uint)groups;
    cl_int err = CL_SUCCESS;
    l.count = clCreateKernel(ctx->program, "bilateral_count", &err);
    if (err == CL_SUCCESS)
        l.fill = clCreateKernel(ctx->program, "bilateral_fill", &err);
    if (err == CL_SUCCESS)
        l.round = clCreateKernel(ctx->program, "bilateral_list_normals", &err);
    if (err == CL_SUCCESS)
        l.group_info = clCreateBuffer(ctx->context, CL_MEM_READ_ONLY | rs_cl_input_flags(ctx),
                                      groups * sizeof(cl_uint4), l.info, &err);
    if (err == CL_SUCCESS)
        l.list_start = clCreateBuffer(ctx->context, CL_MEM_READ_WRITE, start_bytes, NULL, &err);
    if (err != CL_SUCCESS)
        goto done;

    arg_setter a = {l.count, 0, CL_SUCCESS};
    arg(&a, sizeof group_count, &group_count);
    arg(&a, sizeof reach2, &reach2);
    arg(&a, sizeof(cl_mem), &l.group_info);
    arg(&a, sizeof(cl_mem), &buf[BUF_FACET_CENTROID]);
    arg_grid(&a, buf, &mask);
    arg(&a, sizeof(cl_mem), &l.list_start);
    if ((err = a.err) != CL_SUCCESS ||
        (err = rs_cl_run_1d(ctx, pb, l.count, groups, 0, share)) != CL_SUCCESS)
        goto done;

    /* counts to offsets, each group with its spare row: read, then written back whole (a map
     * for reading and writing would do on any device, but Oclgrind's uninitialised-value check
     * does not see the host's writes through one: error 5 in tests/test_oclgrind.c) */
    if (!(l.start = rs_alloc_array(groups + 1, sizeof *l.start)))
        goto done; /* no host memory for them (err CL_SUCCESS): search in each round */
    if ((err = clEnqueueReadBuffer(ctx->queue, l.list_start, CL_TRUE, 0, groups * sizeof(cl_uint),
                                   l.start, 0, NULL, NULL)) != CL_SUCCESS)
        goto done;
    uint64_t rows = 0, near_rows = 0;
    for (size_t g = 0; g < groups; g++) {
        uint64_t n = l.start[g];
        l.start[g] = (cl_uint)rows;
        near_rows += n;
        rows += n + 1;
    }
    l.start[groups] = (cl_uint)rows;
    if ((err = clEnqueueWriteBuffer(ctx->queue, l.list_start, CL_TRUE, 0, start_bytes, l.start, 0,
                                    NULL, NULL)) != CL_SUCCESS)
        goto done;
    uint64_t weight_bytes = rows * lanes_per_group * sizeof(cl_float);
    if (rows > UINT32_MAX / lanes_per_group ||
        held + rows * sizeof(cl_uint) + weight_bytes > usable ||
        weight_bytes > ctx->max_allocation || weight_bytes > SIZE_MAX)
        goto done; /* no room (err CL_SUCCESS): the rounds search instead */
    /* A device that shares the host's memory gets it from rs_alloc_array, which asks for huge
     * pages: faulting in tens of megabytes 4 KiB at a time costs more than filling them. */
    cl_mem_flags flags = CL_MEM_READ_WRITE;
    if (ctx->host_unified) {
        l.facet = rs_alloc_array((size_t)rows, sizeof(cl_uint));
        l.weight = rs_alloc_array((size_t)rows, lanes_per_group * sizeof(cl_float));
        if (!l.facet || !l.weight)
            goto done;
        flags |= CL_MEM_USE_HOST_PTR;
    }
    l.list_facet =
        clCreateBuffer(ctx->context, flags, (size_t)rows * sizeof(cl_uint), l.facet, &err);
    if (err == CL_SUCCESS)
        l.list_weight = clCreateBuffer(ctx->context, flags, (size_t)weight_bytes, l.weight, &err);
    if (err != CL_SUCCESS)
        goto done;

    a = (arg_setter){l.fill, 0, CL_SUCCESS};
    arg(&a, sizeof group_count, &group_count);
    arg(&a, sizeof reach2, &reach2);
    arg(&a, sizeof inv_2s2, &inv_2s2);
    arg(&a, sizeof shift, &shift);
    arg(&a, sizeof(cl_mem), &l.group_info);
    arg(&a, sizeof(cl_mem), &buf[BUF_FACET_CENTROID]);
    arg_grid(&a, buf, &mask);
    arg(&a, sizeof(cl_mem), &l.list_start);
    arg(&a, sizeof(cl_mem), &l.list_facet);
    arg(&a, sizeof(cl_mem), &l.list_weight);
    if ((err = a.err) != CL_SUCCESS ||
        (err = rs_cl_run_1d(ctx, pb, l.fill, groups, share, 2 * share)) != CL_SUCCESS)
        goto done;
    *listed = true;
    /* as bilateral_cell_normals counts: every lane of every facet a round reads (the searches
     * that built the lists are not counted) */
    *pairs = near_rows * lanes_per_group * (uint64_t)pb->normal_iterations;

    cl_mem from = buf[BUF_FACET_NORMAL], to = buf[BUF_FACET_SCRATCH];
    for (int round = 0; round < pb->normal_iterations && err == CL_SUCCESS; round++) {
        a = (arg_setter){l.round, 0, CL_SUCCESS};
        arg(&a, sizeof group_count, &group_count);
        arg(&a, sizeof inv_2t2, &inv_2t2);
        arg(&a, sizeof dot, &dot);
        arg(&a, sizeof(cl_mem), &l.group_info);
        arg(&a, sizeof(cl_mem), &l.list_start);
        arg(&a, sizeof(cl_mem), &l.list_facet);
        arg(&a, sizeof(cl_mem), &l.list_weight);
        arg(&a, sizeof(cl_mem), &from);
        arg(&a, sizeof(cl_mem), &to);
        double from_share = share * (round + 2), to_share = share * (round + 3);
        err = a.err != CL_SUCCESS ? a.err
                                  : rs_cl_run_1d(ctx, pb, l.round, groups, from_share, to_share);
        cl_mem written = to;
        to = from;
        from = written;
    }
    *normals = from;
done:
    if (!*listed && lists_out_of_room(err))
        err = clFinish(ctx->queue); /* they did not fit after all: search in each round */
    bilateral_lists_free(&l);
    return err;
}

/* The bilateral normal filter's rounds (kernels/bilateral.cl), each reading the normals the
 * previous one wrote: they alternate between the input normals' buffer and the scratch one.
 * *normals is left at the buffer holding the last round's; *pairs counts the facet pairs
 * evaluated (as vertex-facet pairs are: every lane of every facet looked at). From lists where
 * they fit (run_bilateral_lists), else searching in every round (bilateral_cell_normals). */
cl_int rs_cl_run_bilateral(rsmooth_context *ctx, const rs_problem *pb, const rs_grid *grid,
                           const cl_mem *buf, cl_mem *normals, uint64_t *pairs) {
    const double h = grid->cell_size, s = pb->normal_sigma_s, t = pb->normal_sigma_n;
    cl_uint cell_count = (cl_uint)grid->cell_count, mask = grid->column_mask;
    cl_float reach2 = (cl_float)((pb->normal_radius / h) * (pb->normal_radius / h));
    cl_float inv_2s2 = (cl_float)(LOG2_E * h * h / (2 * s * s));
    cl_float inv_2t2 = (cl_float)(LOG2_E / (2 * t * t)); /* normals are unit: no length scale */
    cl_mem from = buf[BUF_FACET_NORMAL], to = buf[BUF_FACET_SCRATCH];
    double share = MOLLIFY_SHARE / pb->normal_iterations;
    bool listed = false;
    cl_int err = run_bilateral_lists(ctx, pb, grid, buf, normals, pairs, &listed);
    if (err != CL_SUCCESS || listed)
        return err;
    for (int round = 0; round < pb->normal_iterations && err == CL_SUCCESS; round++) {
        arg_setter a = {ctx->kernels[RS_KERNEL_BILATERAL], 0, CL_SUCCESS};
        arg(&a, sizeof cell_count, &cell_count);
        arg(&a, sizeof reach2, &reach2);
        arg(&a, sizeof inv_2s2, &inv_2s2);
        arg(&a, sizeof inv_2t2, &inv_2t2);
        arg(&a, sizeof(cl_mem), &buf[BUF_FACET_CENTROID]);
        arg(&a, sizeof(cl_mem), &from);
        arg_grid(&a, buf, &mask);
        arg(&a, sizeof(cl_mem), &to);
        arg(&a, sizeof(cl_mem), &buf[BUF_CELL_PAIRS]);
        err = a.err != CL_SUCCESS ? a.err
                                  : rs_cl_run_1d(ctx, pb, a.kernel, cell_count, share * round,
                                           share * (round + 1));
        cl_mem written = to;
        to = from;
        from = written;
    }
    *normals = from;
    if (err != CL_SUCCESS)
        return err;
    /* every round evaluates the same pairs: the last round's count stands for each */
    cl_ulong *cell_pairs = clEnqueueMapBuffer(ctx->queue, buf[BUF_CELL_PAIRS], CL_TRUE,
                                              CL_MAP_READ, 0, cell_count * sizeof(cl_ulong), 0,
                                              NULL, NULL, &err);
    if (err != CL_SUCCESS)
        return err;
    uint64_t sum = 0;
    for (size_t c = 0; c < cell_count; c++)
        sum += cell_pairs[c];
    *pairs = sum * ctx->lanes * (uint64_t)pb->normal_iterations;
    return clEnqueueUnmapMemObject(ctx->queue, buf[BUF_CELL_PAIRS], cell_pairs, 0, NULL, NULL);
}
