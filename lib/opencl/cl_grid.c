/* The facet grid sorted on the device (kernels/grid.cl): a counting sort by cell, for GPUs, to take
 * the host's radix sort and its passes over the keys off the host (not yet timed on a GPU: none
 * has run rsmooth). It gives rs_grid_build_columns' arrays bit for bit (tests/test_cl_grid.c):
 * the same layout (rs_grid_layout), cells in the same order, each cell's facets in increasing
 * index, as the host's stable sort leaves them. */
#include "opencl/cl_grid.h"
#include "opencl/cl_run.h"

#include <string.h>

/* Dense cells (every cell of the grid's box, occupied or not) per facet beyond which the counts
 * would outweigh the facets themselves: such grids (a few facets spread far apart) stay on the
 * host, whose sort only sees occupied cells. */
#define DENSE_PER_FACET 8
#define DENSE_SLACK 65536
/* Dense cells one work-item of the scan walks; more where that would make too many chunks for
 * the one work-item that scans the chunks' sums. */
#define SCAN_CHUNK 256
#define MAX_CHUNKS 65536

/* The kernels, created for each call (as cl_bilateral.c's lists do): a CPU device, which never
 * sorts its grid, creates none, and its context's setup pays for none. */
enum { K_ZERO, K_COUNT, K_CHUNK_SUMS, K_CHUNK_SCAN, K_CELLS, K_SCATTER, K_SORT_CELLS, K_N };
static const char *const kernel_names[K_N] = {"grid_zero",       "grid_count", "grid_chunk_sums",
                                              "grid_chunk_scan", "grid_cells", "grid_scatter",
                                              "grid_sort_cells"};

enum { G_POINTS, G_KEY, G_FACETS, G_CURSOR, G_CHUNKS, G_OCCUPIED, G_COORD, G_START, G_ORDER, G_N };

/* Launches `kernel` over `count` work-items (rounded up to whole groups; the kernels check). */
static cl_int launch(rsmooth_context *ctx, cl_kernel kernel, size_t count) {
    size_t local = ctx->local_size, global = (count + local - 1) / local * local;
    if (global == 0)
        return CL_SUCCESS;
    return clEnqueueNDRangeKernel(ctx->queue, kernel, 1, NULL, &global, &local, 0, NULL, NULL);
}

typedef struct device_sort {
    rsmooth_context *ctx;
    rs_grid *grid;
    const double *points;
    cl_uint count, dense, chunk, chunks;
    cl_mem buf[G_N];
    cl_kernel kernel[K_N];
} device_sort;

/* The call's kernels and buffers. */
static cl_int create_objects(device_sort *ds) {
    rsmooth_context *ctx = ds->ctx;
    size_t n = ds->count, cells = ds->count < ds->dense ? ds->count : ds->dense;
    const size_t size[G_N] = {[G_POINTS] = 3 * n * sizeof(cl_double),
                              [G_KEY] = n * sizeof(cl_uint),
                              [G_FACETS] = ds->dense * sizeof(cl_uint),
                              [G_CURSOR] = ds->dense * sizeof(cl_uint),
                              [G_CHUNKS] = ds->chunks * sizeof(cl_uint2),
                              [G_OCCUPIED] = sizeof(cl_uint),
                              [G_COORD] = cells * sizeof(cl_int4),
                              [G_START] = (cells + 1) * sizeof(cl_uint),
                              [G_ORDER] = n * sizeof(cl_uint)};
    cl_int err = CL_SUCCESS;
    for (int k = 0; k < K_N && err == CL_SUCCESS; k++)
        ds->kernel[k] = clCreateKernel(ctx->program, kernel_names[k], &err);
    if (err == CL_INVALID_KERNEL_NAME)
        return err; /* a program built without grid.cl (cl_program.c): the host sorts */
    for (int b = 0; b < G_N && err == CL_SUCCESS; b++) {
        bool input = b == G_POINTS;
        cl_mem_flags flags = input ? CL_MEM_READ_ONLY | rs_cl_input_flags(ctx) : CL_MEM_READ_WRITE;
        ds->buf[b] =
            clCreateBuffer(ctx->context, flags, size[b], input ? (void *)ds->points : NULL, &err);
    }
    return err;
}

/* Sets kernel arguments in order: (size, pointer) pairs, a cl_mem as &buf[...]. */
#define ARG(value) arg(&s, sizeof(value), &(value))

static cl_int enqueue_sort(device_sort *ds) {
    rsmooth_context *ctx = ds->ctx;
    const rs_grid *g = ds->grid;
    cl_mem *buf = ds->buf;
    cl_double inv_h = g->inv_cell_size, ox = g->origin_cell[0], oy = g->origin_cell[1],
              oz = g->origin_cell[2];
    cl_int dx = g->dims[0], dy = g->dims[1], dz = g->dims[2];
    arg_setter s = {ds->kernel[K_ZERO], 0, CL_SUCCESS};
    ARG(ds->dense), ARG(buf[G_FACETS]);
    cl_int err = s.err != CL_SUCCESS ? s.err : launch(ctx, s.kernel, ds->dense);
    s = (arg_setter){ds->kernel[K_COUNT], 0, err};
    ARG(ds->count), ARG(inv_h), ARG(ox), ARG(oy), ARG(oz), ARG(dx), ARG(dy), ARG(dz);
    ARG(buf[G_POINTS]), ARG(buf[G_KEY]), ARG(buf[G_FACETS]);
    err = s.err != CL_SUCCESS ? s.err : launch(ctx, s.kernel, ds->count);
    s = (arg_setter){ds->kernel[K_CHUNK_SUMS], 0, err};
    ARG(ds->dense), ARG(ds->chunk), ARG(buf[G_FACETS]), ARG(buf[G_CHUNKS]);
    err = s.err != CL_SUCCESS ? s.err : launch(ctx, s.kernel, ds->chunks);
    s = (arg_setter){ds->kernel[K_CHUNK_SCAN], 0, err};
    ARG(ds->chunks), ARG(buf[G_CHUNKS]), ARG(buf[G_OCCUPIED]), ARG(buf[G_START]);
    err = s.err != CL_SUCCESS ? s.err : launch(ctx, s.kernel, 1);
    s = (arg_setter){ds->kernel[K_CELLS], 0, err};
    ARG(ds->dense), ARG(ds->chunk), ARG(dy), ARG(dz), ARG(buf[G_FACETS]), ARG(buf[G_CHUNKS]);
    ARG(buf[G_CURSOR]), ARG(buf[G_COORD]), ARG(buf[G_START]);
    err = s.err != CL_SUCCESS ? s.err : launch(ctx, s.kernel, ds->chunks);
    s = (arg_setter){ds->kernel[K_SCATTER], 0, err};
    ARG(ds->count), ARG(buf[G_KEY]), ARG(buf[G_CURSOR]), ARG(buf[G_ORDER]);
    err = s.err != CL_SUCCESS ? s.err : launch(ctx, s.kernel, ds->count);
    return err;
}

/* The sorted cells back on the host, into the grid's arrays. */
static cl_int read_back(device_sort *ds, bool *no_memory) {
    rsmooth_context *ctx = ds->ctx;
    rs_grid *g = ds->grid;
    cl_uint cells = 0;
    cl_int err = clEnqueueReadBuffer(ctx->queue, ds->buf[G_OCCUPIED], CL_TRUE, 0, sizeof cells,
                                     &cells, 0, NULL, NULL);
    if (err != CL_SUCCESS)
        return err;
    /* each cell's facets in increasing index (the scatter's atomics took any order) */
    arg_setter s = {ds->kernel[K_SORT_CELLS], 0, CL_SUCCESS};
    ARG(cells), ARG(ds->buf[G_START]), ARG(ds->buf[G_ORDER]);
    err = s.err != CL_SUCCESS ? s.err : launch(ctx, s.kernel, cells);
    if (err != CL_SUCCESS)
        return err;
    g->cell_count = cells;
    g->cell_coord = rs_alloc_array(cells, 4 * sizeof(int32_t));
    g->cell_start = rs_alloc_array((size_t)cells + 1, sizeof(uint32_t));
    g->facet_order = rs_alloc_array(ds->count, sizeof(uint32_t));
    if (!g->cell_coord || !g->cell_start || !g->facet_order || cells > (1u << 30)) {
        *no_memory = true; /* (the hash tables' 32-bit slots, as the host's sort refuses) */
        return CL_SUCCESS;
    }
    err = clEnqueueReadBuffer(ctx->queue, ds->buf[G_COORD], CL_FALSE, 0,
                              (size_t)cells * sizeof(cl_int4), g->cell_coord, 0, NULL, NULL);
    if (err == CL_SUCCESS)
        err = clEnqueueReadBuffer(ctx->queue, ds->buf[G_START], CL_FALSE, 0,
                                  ((size_t)cells + 1) * sizeof(cl_uint), g->cell_start, 0, NULL,
                                  NULL);
    if (err == CL_SUCCESS)
        err = clEnqueueReadBuffer(ctx->queue, ds->buf[G_ORDER], CL_FALSE, 0,
                                  ds->count * sizeof(cl_uint), g->facet_order, 0, NULL, NULL);
    cl_int finished = clFinish(ctx->queue);
    return err == CL_SUCCESS ? finished : err;
}

rsmooth_status rs_cl_grid_build_columns(rsmooth_context *ctx, rs_grid *grid, const double *points,
                                        size_t count, double reach, int split, const double lo[3],
                                        const double hi[3], bool *done, rsmooth_error *error) {
    *done = false;
    rs_grid_layout(grid, reach, split, lo, hi);
    uint64_t dense = (uint64_t)grid->dims[0] * (uint64_t)grid->dims[1] * (uint64_t)grid->dims[2];
    uint64_t bytes = 8 * dense + 36 * (uint64_t)count;
    if (count == 0 || count > UINT32_MAX / 2 ||
        dense > DENSE_PER_FACET * (uint64_t)count + DENSE_SLACK || dense > (1u << 31) ||
        4 * dense > ctx->max_allocation || bytes > rs_cl_usable_memory(ctx))
        return RSMOOTH_OK; /* the host's sort, then */
    device_sort ds = {.ctx = ctx,
                      .grid = grid,
                      .points = points,
                      .count = (cl_uint)count,
                      .dense = (cl_uint)dense,
                      .chunk = SCAN_CHUNK};
    if (dense / SCAN_CHUNK >= MAX_CHUNKS)
        ds.chunk = (cl_uint)((dense + MAX_CHUNKS - 1) / MAX_CHUNKS);
    ds.chunks = (cl_uint)((dense + ds.chunk - 1) / ds.chunk);
    bool no_memory = false;
    cl_int err = create_objects(&ds);
    bool without = err == CL_INVALID_KERNEL_NAME;
    if (without)
        err = CL_SUCCESS;
    else if (err == CL_SUCCESS)
        err = enqueue_sort(&ds);
    if (err == CL_SUCCESS && !without)
        err = read_back(&ds, &no_memory);
    for (int b = 0; b < G_N; b++)
        if (ds.buf[b])
            clReleaseMemObject(ds.buf[b]);
    for (int k = 0; k < K_N; k++)
        if (ds.kernel[k])
            clReleaseKernel(ds.kernel[k]);
    if (without)
        return RSMOOTH_OK; /* *done stays false */
    if (err == CL_SUCCESS && !no_memory) {
        grid->cell_start[grid->cell_count] = (uint32_t)count;
        no_memory = !rs_grid_index_columns(grid);
    }
    if (err != CL_SUCCESS || no_memory) {
        rs_grid_free(grid);
        return err != CL_SUCCESS ? rs_cl_fail(error, err, "grid on the device", ctx->device_name)
                                 : rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, "rs_grid_build",
                                           "no memory for the grid (%zu facets)", count);
    }
    *done = true;
    return RSMOOTH_OK;
}
