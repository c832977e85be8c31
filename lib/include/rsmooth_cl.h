/** @file
 * rsmooth_cl: interoperation with a caller's own OpenCL objects. Include this instead of rsmooth.h
 * when the host application already has an OpenCL context and queue.
 *
 *     rsmooth_context *ctx;
 *     rsmooth_context_create_from_queue(my_queue, &ctx, &err);  // retains my_queue
 *     rsmooth_smooth(ctx, ...);                                  // runs on my_queue, then finishes it
 *     rsmooth_context_destroy(ctx);                              // releases what it retained
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
 * The program is built for the queue's device. Fails like rsmooth_context_create
 * (RSMOOTH_ERROR_INVALID_ARGUMENT for a NULL or invalid queue). The context's calls are serialised
 * among themselves; work the caller enqueues on the same queue from other threads meanwhile is the
 * caller's to order. */
RSMOOTH_API rsmooth_status rsmooth_context_create_from_queue(cl_command_queue queue,
                                                             rsmooth_context **ctx,
                                                             rsmooth_error *error);

/** The queue the context runs on (owned by the context; retain it to keep it beyond the
 * context). */
RSMOOTH_API cl_command_queue rsmooth_context_queue(const rsmooth_context *ctx);

#ifdef __cplusplus
}
#endif

#endif /* RSMOOTH_CL_H */
