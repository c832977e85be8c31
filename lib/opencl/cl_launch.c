/* Launching one kernel over a range of work-items (cl_run.h): in slices when the caller wants
 * progress, so reports and cancels come while the device works. */
#include "opencl/cl_run.h"

/* Slices a kernel launch takes when the caller wants progress reports. Every work-item computes
 * its own vertex alone, so slicing never changes the result. */
#define PROGRESS_SLICES 32

cl_int rs_cl_run_1d(rsmooth_context *ctx, const rs_problem *pb, cl_kernel kernel, size_t count,
                    double from, double to) {
    size_t local = ctx->local_size;
    bool reports = pb->progress || pb->progress_cancel;
    size_t slices = reports && count > PROGRESS_SLICES * local ? PROGRESS_SLICES : 1;
    size_t slice = (count + slices - 1) / slices;
    slice = (slice + local - 1) / local * local;
    cl_event done[PROGRESS_SLICES];
    size_t ends[PROGRESS_SLICES];
    size_t enqueued = 0;
    cl_int err = CL_SUCCESS;
    for (size_t start = 0; start < count && err == CL_SUCCESS; start += slice) {
        size_t n = count - start < slice ? count - start : slice;
        size_t global = (n + local - 1) / local * local;
        err = clEnqueueNDRangeKernel(ctx->queue, kernel, 1, &start, &global, &local, 0, NULL,
                                     &done[enqueued]);
        if (err == CL_SUCCESS)
            ends[enqueued++] = start + n;
    }
    if (err == CL_SUCCESS)
        err = clFlush(ctx->queue);
    for (size_t i = 0; i < enqueued; i++) {
        if (err == CL_SUCCESS)
            err = clWaitForEvents(1, &done[i]);
        /* the last slice reports `to` itself, so the next launch's first report never lies
         * below it by a rounding */
        double at = ends[i] == count ? to : from + (to - from) * ((double)ends[i] / (double)count);
        if (err == CL_SUCCESS && !rs_progress(pb, at))
            err = RS_CL_CANCELLED;
        clReleaseEvent(done[i]);
    }
    /* the slices still queued after a cancel finish before their buffers are released */
    cl_int finished = clFinish(ctx->queue);
    return err == CL_SUCCESS ? finished : err;
}
