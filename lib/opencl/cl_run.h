/* What the OpenCL path's run (cl_smooth.c) shares with its bilateral stage (cl_bilateral.c): the
 * buffers of one run, kernel arguments and launches. Internal, not installed. */
#ifndef RSMOOTH_CL_RUN_H
#define RSMOOTH_CL_RUN_H

#include "core/spatial.h"
#include "opencl/cl_internal.h"

#define LOG2_E 1.4426950408889634

/* Share of the progress of one filter run the predictors' normals take (the robust pass the
 * rest). */
#define MOLLIFY_SHARE 0.45

/* The device buffers of one run. */
enum {
    BUF_FACET_CENTROID,
    BUF_FACET_NORMAL,
    BUF_FACET_VERTICES,
    BUF_FACET_PLACE,
    BUF_CELL_COORD,
    BUF_CELL_START,
    BUF_COLUMN_FIRST,
    BUF_COLUMN_TABLE,
    BUF_BLOCK_POS,
    BUF_BLOCK_CELL,
    BUF_BLOCK_OFFSET,
    BUF_BLOCK_SHIFT,
    BUF_BLOCK_RESULT,
    BUF_BLOCK_EXTRA,
    BUF_BLOCK_PAIRS,
    BUF_FACET_SCRATCH, /* bilateral: the normals of every other round */
    BUF_CELL_PAIRS,    /* bilateral: facets each cell's groups evaluated in a round */
    BUF_FACET_COLOR,   /* colour factor: per facet, in grid order */
    BUF_BLOCK_COLOR,   /* colour factor: per block, as block_pos */
    BUF_COUNT
};

/* Sets kernel arguments in order; stops at the first failure. */
typedef struct arg_setter {
    cl_kernel kernel;
    cl_uint index;
    cl_int err;
} arg_setter;

static inline void arg(arg_setter *s, size_t size, const void *value) {
    if (s->err == CL_SUCCESS)
        s->err = clSetKernelArg(s->kernel, s->index, size, value);
    s->index++;
}

/* The grid lookup every searching kernel takes, in the order they all declare it: cell_coord,
 * cell_start, column_first, column_table, column_mask. */
static inline void arg_grid(arg_setter *s, const cl_mem *buf, const cl_uint *column_mask) {
    arg(s, sizeof(cl_mem), &buf[BUF_CELL_COORD]);
    arg(s, sizeof(cl_mem), &buf[BUF_CELL_START]);
    arg(s, sizeof(cl_mem), &buf[BUF_COLUMN_FIRST]);
    arg(s, sizeof(cl_mem), &buf[BUF_COLUMN_TABLE]);
    arg(s, sizeof *column_mask, column_mask);
}

/* Runs `kernel` over `count` work-items and waits; with progress requested, in slices enqueued
 * together (the device never idles between them) and reported as each completes, as fractions
 * from `from` to `to` of the whole filter. */
cl_int rs_cl_run_1d(rsmooth_context *ctx, const rs_problem *pb, cl_kernel kernel, size_t count,
                    double from, double to);

/* The bilateral normal filter's rounds on the run's buffers (cl_bilateral.c): *normals is left
 * at the buffer holding the last round's normals, *pairs counts the facet pairs read. */
cl_int rs_cl_run_bilateral(rsmooth_context *ctx, const rs_problem *pb, const rs_grid *grid,
                           const cl_mem *buf, cl_mem *normals, uint64_t *pairs);

#endif /* RSMOOTH_CL_RUN_H */
