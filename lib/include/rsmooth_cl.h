/** @file
 * rsmooth_cl: interoperation with a caller's own OpenCL objects. Include this instead of rsmooth.h
 * when the host application already has an OpenCL context and queue.
 *
 *     rsmooth_context *ctx;
 *     rsmooth_context_create_from_queue(my_queue, NULL, &ctx, &err);  // retains my_queue
 *     rsmooth_smooth(ctx, ...);                                  // runs on my_queue, then finishes
 * it rsmooth_context_destroy(ctx);                              // releases what it retained
 *
 * The OpenCL version is the includer's choice: define CL_TARGET_OPENCL_VERSION (e.g. 120, 200, 300)
 * before this header as before <CL/cl.h>; this header defines none. rsmooth needs only OpenCL 1.2's
 * types.
 */
#ifndef RSMOOTH_CL_H
#define RSMOOTH_CL_H

#include "rsmooth.h"

#ifdef __APPLE__
#include <OpenCL/cl.h>
#else
#include <CL/cl.h>
#endif

#ifdef __cplusplus
extern "C" {
#endif

/** Creates a context that runs on the caller's queue; its OpenCL context and device are derived
 * from the queue. The queue (and its context) are retained here and released by
 * rsmooth_context_destroy; the caller keeps its own reference and must not release the queue early.
 * The program is built for the queue's device. `options` as rsmooth_context_create's (its device
 * is ignored: the queue's is used; NULL: the defaults). Fails like rsmooth_context_create
 * (RSMOOTH_ERROR_INVALID_ARGUMENT for a NULL or invalid queue). (`options` in 0.11) The context's
 * calls are serialised among themselves; work the caller enqueues on the same queue from other
 * threads meanwhile is the caller's to order. */
RSMOOTH_API rsmooth_status rsmooth_context_create_from_queue(cl_command_queue queue,
                                                             const rsmooth_context_options *options,
                                                             rsmooth_context **ctx,
                                                             rsmooth_error *error);

/** rsmooth_smooth on positions held in OpenCL buffers of the context's OpenCL context: `positions`
 * holds vertex_count x 3 `scalar`s, packed (x, y, z per vertex, from offset 0), and the result
 * goes to `out_positions` in the same layout. `out_positions` may be `positions` itself (the
 * same cl_mem: smoothed in place), while two different objects must not share the bytes the
 * call uses: overlapping sub-buffers of one buffer, a sub-buffer and its buffer, or buffers over
 * the same host memory (CL_MEM_USE_HOST_PTR) are refused, since a kernel would read inputs it
 * had overwritten (OpenCL leaves such use undefined). Indices stay on the
 * host. The call enqueues its work on the context's queue after what the caller enqueued there
 * (an in-order queue; on another queue of the same context, finish that first), and finishes
 * the queue before it returns: the output is then ready. The input is read to the host once (the
 * grid and facet data are built there by design). Where the filter solves the whole mesh in one
 * run on a device with fp64 (one pass, no tiles, no normal update stage, no choice per region,
 * no move mask, one part, and params.guard 0: the fold guard reads the result on the host; the
 * paper's filter and its single-pass variants) the result is written into
 * out_positions by a kernel on the device, from displacements already there, in the double
 * arithmetic the host uses, so the bits equal rsmooth_smooth's; nothing of the output travels
 * through the host, and the report's pair counts are 0. Otherwise the result is computed on the
 * host as rsmooth_smooth computes it and written into out_positions. Fails like rsmooth_smooth,
 * and with RSMOOTH_ERROR_INVALID_ARGUMENT when a buffer is NULL, not a buffer (an image), of
 * another OpenCL context, or smaller than vertex_count x 3 scalars, when `positions` is
 * CL_MEM_WRITE_ONLY or `out_positions` CL_MEM_READ_ONLY (a sub-buffer's own or its buffer's),
 * or when the two share memory as above (the message names it); out_positions is then
 * untouched. No weight or confidence output: call rsmooth_smooth for those. (Added in 0.11) */
RSMOOTH_API rsmooth_status rsmooth_smooth_cl(rsmooth_context *ctx, rsmooth_scalar scalar,
                                             cl_mem positions, size_t vertex_count,
                                             const uint32_t *indices, size_t triangle_count,
                                             const rsmooth_params *params, cl_mem out_positions,
                                             rsmooth_report *report, rsmooth_error *error);

/** The queue the context runs on (owned by the context; retain it to keep it beyond the
 * context). */
RSMOOTH_API cl_command_queue rsmooth_context_queue(const rsmooth_context *ctx);

#ifdef __cplusplus
}
#endif

#endif /* RSMOOTH_CL_H */
