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
    /* the run */
    rsmooth_context *ctx;
    const rs_problem *pb;
    const rs_grid *grid;
    const cl_mem *buf;
    /* the kernels' arguments (as rs_cl_run_bilateral's) and the share of progress a search takes */
    cl_uint mask, group_count;
    cl_float reach2, inv_2s2, inv_2t2, shift;
    cl_int dot;
    double share;
    /* the groups, what the run holds and may hold, and the lists' rows (each group's spare one
     * included) and near rows (the facets found) */
    size_t lanes_per_group, groups, start_bytes;
    uint64_t held, usable, rows, near_rows;
    bool no_room;   /* the lists do not fit (host or device memory): the rounds search instead */
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

/* The kernels' arguments from the run's widths and grid. */
static void lists_arguments(bilateral_lists *l) {
    const rs_problem *pb = l->pb;
    const double h = l->grid->cell_size, s = pb->normal_sigma_s, t = pb->normal_sigma_n;
    l->mask = l->grid->column_mask;
    l->reach2 = (cl_float)((pb->normal_radius / h) * (pb->normal_radius / h));
    l->inv_2s2 = (cl_float)(LOG2_E * h * h / (2 * s * s));
    l->inv_2t2 = (cl_float)(LOG2_E / (2 * t * t)); /* normals are unit: no length scale */
    /* The rounds' cheaper form of the normal term, 2 inv_2t2 (n_q . n_r - 1), loses about
     * 2 inv_2t2 float ulps to cancellation: up to 2e-5 of a weight at this limit (t = 0.12),
     * past which they take |n_q - n_r|^2 inv_2t2 itself. */
    l->dot = l->inv_2t2 <= 50;
    l->shift = l->dot ? 2 * l->inv_2t2 : 0;
    l->share = MOLLIFY_SHARE / (pb->normal_iterations + 2); /* a search costs about a round */
}

/* The groups of bilateral_cell_normals (each cell's facets, ctx->lanes at a time) and their
 * info; false when they would not fit (the rounds search instead). */
static bool plan_groups(bilateral_lists *l) {
    const rs_grid *grid = l->grid;
    l->lanes_per_group = l->ctx->lanes;
    size_t groups = 0;
    for (size_t c = 0; c < grid->cell_count; c++)
        groups += (grid->cell_start[c + 1] - grid->cell_start[c] + l->lanes_per_group - 1) /
                  l->lanes_per_group;
    /* what this run holds on the device already, and what the groups add */
    l->start_bytes = (groups + 1) * sizeof(cl_uint);
    l->held = groups * sizeof(cl_uint4) + l->start_bytes;
    for (int b = 0; b < BUF_COUNT; b++) {
        size_t size = 0;
        if (l->buf[b] &&
            clGetMemObjectInfo(l->buf[b], CL_MEM_SIZE, sizeof size, &size, NULL) == CL_SUCCESS)
            l->held += size;
    }
    l->usable = rs_cl_usable_memory(l->ctx);
    if (l->held > l->usable || groups >= UINT32_MAX)
        return false;
    if (!(l->info = rs_alloc_array(groups, sizeof *l->info)))
        return false; /* no host memory for them: search in each round */
    for (size_t c = 0, g = 0; c < grid->cell_count; c++)
        for (uint32_t f = grid->cell_start[c]; f < grid->cell_start[c + 1];
             f += l->lanes_per_group) {
            uint32_t lanes = grid->cell_start[c + 1] - f;
            l->info[g++] =
                (cl_uint4){{f, lanes < l->lanes_per_group ? lanes : (cl_uint)l->lanes_per_group,
                            (cl_uint)c, 0}};
        }
    l->groups = groups;
    l->group_count = (cl_uint)groups;
    return true;
}

/* The three kernels, the groups' info on the device and the list starts' buffer. */
static cl_int create_lists(bilateral_lists *l) {
    rsmooth_context *ctx = l->ctx;
    cl_int err = CL_SUCCESS;
    l->count = clCreateKernel(ctx->program, "bilateral_count", &err);
    if (err == CL_SUCCESS)
        l->fill = clCreateKernel(ctx->program, "bilateral_fill", &err);
    if (err == CL_SUCCESS)
        l->round = clCreateKernel(ctx->program, "bilateral_list_normals", &err);
    if (err == CL_SUCCESS)
        l->group_info = clCreateBuffer(ctx->context, CL_MEM_READ_ONLY | rs_cl_input_flags(ctx),
                                       l->groups * sizeof(cl_uint4), l->info, &err);
    if (err == CL_SUCCESS)
        l->list_start = clCreateBuffer(ctx->context, CL_MEM_READ_WRITE, l->start_bytes, NULL, &err);
    return err;
}

/* bilateral_count: the facets near each group, into list_start. */
static cl_int count_rows(bilateral_lists *l) {
    arg_setter a = {l->count, 0, CL_SUCCESS};
    arg(&a, sizeof l->group_count, &l->group_count);
    arg(&a, sizeof l->reach2, &l->reach2);
    arg(&a, sizeof(cl_mem), &l->group_info);
    arg(&a, sizeof(cl_mem), &l->buf[BUF_FACET_CENTROID]);
    arg_grid(&a, l->buf, &l->mask);
    arg(&a, sizeof(cl_mem), &l->list_start);
    if (a.err != CL_SUCCESS)
        return a.err;
    return rs_cl_run_1d(l->ctx, l->pb, l->count, l->groups, 0, l->share);
}

/* Counts to offsets, each group with its spare row: read, then written back whole (a map for
 * reading and writing would do on any device, but Oclgrind's uninitialised-value check does not
 * see the host's writes through one: error 5 in tests/test_oclgrind.c). */
static cl_int list_offsets(bilateral_lists *l) {
    rsmooth_context *ctx = l->ctx;
    size_t groups = l->groups;
    if (!(l->start = rs_alloc_array(groups + 1, sizeof *l->start))) {
        l->no_room = true; /* no host memory for them: search in each round */
        return CL_SUCCESS;
    }
    cl_int err = clEnqueueReadBuffer(ctx->queue, l->list_start, CL_TRUE, 0,
                                     groups * sizeof(cl_uint), l->start, 0, NULL, NULL);
    if (err != CL_SUCCESS)
        return err;
    uint64_t rows = 0, near_rows = 0;
    for (size_t g = 0; g < groups; g++) {
        uint64_t n = l->start[g];
        l->start[g] = (cl_uint)rows;
        near_rows += n;
        rows += n + 1;
    }
    l->start[groups] = (cl_uint)rows;
    l->rows = rows;
    l->near_rows = near_rows;
    return clEnqueueWriteBuffer(ctx->queue, l->list_start, CL_TRUE, 0, l->start_bytes, l->start, 0,
                                NULL, NULL);
}

/* The lists' buffers, when they fit the device and the budget (else no_room). */
static cl_int allocate_rows(bilateral_lists *l) {
    rsmooth_context *ctx = l->ctx;
    uint64_t rows = l->rows, weight_bytes = rows * l->lanes_per_group * sizeof(cl_float);
    if (rows > UINT32_MAX / l->lanes_per_group ||
        l->held + rows * sizeof(cl_uint) + weight_bytes > l->usable ||
        weight_bytes > ctx->max_allocation || weight_bytes > SIZE_MAX) {
        l->no_room = true; /* the rounds search instead */
        return CL_SUCCESS;
    }
    /* A device that shares the host's memory gets it from rs_alloc_array, which asks for huge
     * pages: faulting in tens of megabytes 4 KiB at a time costs more than filling them. */
    cl_mem_flags flags = CL_MEM_READ_WRITE;
    if (ctx->host_unified) {
        l->facet = rs_alloc_array((size_t)rows, sizeof(cl_uint));
        l->weight = rs_alloc_array((size_t)rows, l->lanes_per_group * sizeof(cl_float));
        if (!l->facet || !l->weight) {
            l->no_room = true;
            return CL_SUCCESS;
        }
        flags |= CL_MEM_USE_HOST_PTR;
    }
    cl_int err = CL_SUCCESS;
    l->list_facet =
        clCreateBuffer(ctx->context, flags, (size_t)rows * sizeof(cl_uint), l->facet, &err);
    if (err == CL_SUCCESS)
        l->list_weight = clCreateBuffer(ctx->context, flags, (size_t)weight_bytes, l->weight, &err);
    return err;
}

/* bilateral_fill: each group's near facets and the parts of their weights that do not depend
 * on normals. */
static cl_int fill_lists(bilateral_lists *l) {
    arg_setter a = {l->fill, 0, CL_SUCCESS};
    arg(&a, sizeof l->group_count, &l->group_count);
    arg(&a, sizeof l->reach2, &l->reach2);
    arg(&a, sizeof l->inv_2s2, &l->inv_2s2);
    arg(&a, sizeof l->shift, &l->shift);
    arg(&a, sizeof(cl_mem), &l->group_info);
    arg(&a, sizeof(cl_mem), &l->buf[BUF_FACET_CENTROID]);
    arg_grid(&a, l->buf, &l->mask);
    arg(&a, sizeof(cl_mem), &l->list_start);
    arg(&a, sizeof(cl_mem), &l->list_facet);
    arg(&a, sizeof(cl_mem), &l->list_weight);
    if (a.err != CL_SUCCESS)
        return a.err;
    return rs_cl_run_1d(l->ctx, l->pb, l->fill, l->groups, l->share, 2 * l->share);
}

/* The rounds (bilateral_list_normals), alternating between the normals' buffer and the scratch
 * one; *normals is left at the one the last round wrote. */
static cl_int list_rounds(bilateral_lists *l, cl_mem *normals) {
    cl_int err = CL_SUCCESS;
    cl_mem from = l->buf[BUF_FACET_NORMAL], to = l->buf[BUF_FACET_SCRATCH];
    for (int round = 0; round < l->pb->normal_iterations && err == CL_SUCCESS; round++) {
        arg_setter a = {l->round, 0, CL_SUCCESS};
        arg(&a, sizeof l->group_count, &l->group_count);
        arg(&a, sizeof l->inv_2t2, &l->inv_2t2);
        arg(&a, sizeof l->dot, &l->dot);
        arg(&a, sizeof(cl_mem), &l->group_info);
        arg(&a, sizeof(cl_mem), &l->list_start);
        arg(&a, sizeof(cl_mem), &l->list_facet);
        arg(&a, sizeof(cl_mem), &l->list_weight);
        arg(&a, sizeof(cl_mem), &from);
        arg(&a, sizeof(cl_mem), &to);
        double from_share = l->share * (round + 2), to_share = l->share * (round + 3);
        err = a.err != CL_SUCCESS
                  ? a.err
                  : rs_cl_run_1d(l->ctx, l->pb, l->round, l->groups, from_share, to_share);
        cl_mem written = to;
        to = from;
        from = written;
    }
    *normals = from;
    return err;
}

static cl_int run_bilateral_lists(rsmooth_context *ctx, const rs_problem *pb, const rs_grid *grid,
                                  const cl_mem *buf, cl_mem *normals, uint64_t *pairs,
                                  bool *listed) {
    *listed = false;
    /* building them costs about what a searching round does: one round is cheaper without */
    if (rs_environment_is(&ctx->env, RS_ENV_BILATERAL_LISTS, "0") || pb->normal_iterations < 2)
        return CL_SUCCESS;
    bilateral_lists l;
    memset(&l, 0, sizeof l);
    l.ctx = ctx;
    l.pb = pb;
    l.grid = grid;
    l.buf = buf;
    lists_arguments(&l);
    if (!plan_groups(&l))
        return CL_SUCCESS; /* nothing allocated */
    cl_int err = create_lists(&l);
    if (err == CL_SUCCESS)
        err = count_rows(&l);
    if (err == CL_SUCCESS)
        err = list_offsets(&l);
    if (err == CL_SUCCESS && !l.no_room)
        err = allocate_rows(&l);
    if (err == CL_SUCCESS && !l.no_room)
        err = fill_lists(&l);
    if (err == CL_SUCCESS && !l.no_room) {
        *listed = true;
        /* as bilateral_cell_normals counts: every lane of every facet a round reads (the
         * searches that built the lists are not counted) */
        *pairs = l.near_rows * l.lanes_per_group * (uint64_t)pb->normal_iterations;
        err = list_rounds(&l, normals);
    }
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
        err = a.err != CL_SUCCESS
                  ? a.err
                  : rs_cl_run_1d(ctx, pb, a.kernel, cell_count, share * round, share * (round + 1));
        cl_mem written = to;
        to = from;
        from = written;
    }
    *normals = from;
    if (err != CL_SUCCESS)
        return err;
    /* every round evaluates the same pairs: the last round's count stands for each */
    cl_ulong *cell_pairs =
        clEnqueueMapBuffer(ctx->queue, buf[BUF_CELL_PAIRS], CL_TRUE, CL_MAP_READ, 0,
                           cell_count * sizeof(cl_ulong), 0, NULL, NULL, &err);
    if (err != CL_SUCCESS)
        return err;
    uint64_t sum = 0;
    for (size_t c = 0; c < cell_count; c++)
        sum += cell_pairs[c];
    *pairs = sum * ctx->lanes * (uint64_t)pb->normal_iterations;
    return clEnqueueUnmapMemObject(ctx->queue, buf[BUF_CELL_PAIRS], cell_pairs, 0, NULL, NULL);
}
