/* The facet grid sorted on the device (cl_grid.c, kernels/grid.cl). Internal, not installed. */
#ifndef RSMOOTH_CL_GRID_H
#define RSMOOTH_CL_GRID_H

#include "core/spatial.h"

/* Whether the OpenCL path sorts its grid on ctx's device: on GPUs, not on CPU devices (whose
 * kernels would share the host's cores, with the round trip on top); RSMOOTH_DEVICE_GRID=1 or 0
 * forces it either way. Never without double precision on the device (cl_khr_fp64). What it
 * says when the context is created also decides whether its program holds the grid's kernels
 * (cl_program.c). */
bool rs_cl_device_grid(const rsmooth_context *ctx); /* (cl_variant.c) */

/* rs_grid_build_columns with the facets counted, sorted and their cells listed on ctx's device:
 * the same arrays bit for bit. *done is false (and RSMOOTH_OK returned, *grid laid out but
 * empty) where the device does not take this grid: no facet, no double precision, a box of
 * cells far larger than the facets (the counts are dense), or a program built without the
 * grid's kernels (rs_cl_device_grid said no when the context was created); the caller then builds
 * it on the host. On failure *grid is freed. Holds ctx's queue: the caller holds ctx's lock. */
rsmooth_status rs_cl_grid_build_columns(rsmooth_context *ctx, rs_grid *grid, const double *points,
                                        size_t count, double reach, int split, const double lo[3],
                                        const double hi[3], bool *done, rsmooth_error *error);

#endif /* RSMOOTH_CL_GRID_H */
