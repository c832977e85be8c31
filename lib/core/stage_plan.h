/* The normal-update stage as data (beyond the paper): what stages/ builds once on the input (the
 * facets, the welded adjacency, the guided filter's lists) and what a runner needs to run every
 * cycle somewhere else, the device's (opencl/cl_stage.c). Only a description, so that the layer
 * that builds it and the layer that runs it need not know each other. Internal, not installed. */
#ifndef RSMOOTH_STAGE_PLAN_H
#define RSMOOTH_STAGE_PLAN_H

#include "core/rsmooth_internal.h"

/* The plan and the figures (below). */
typedef struct rs_stage_plan rs_stage_plan;
typedef struct rs_stage_stats rs_stage_stats;
/* Called after each cycle with the cycles done; non-zero stops the stage (RSMOOTH_CANCELLED). */
typedef int (*rs_cycle_fn)(void *user, int done, int cycles);
/* Runs every cycle of `plan` elsewhere (the device: opencl/cl_stage.c), writing the final
 * positions (the stage's units) to xyz. A runner that cannot take the plan (too large for its
 * device) returns RSMOOTH_ERROR_OUT_OF_MEMORY having changed nothing: the host runs it then. */
typedef rsmooth_status (*rs_stage_runner)(void *ctx, const rs_stage_plan *plan, double *xyz,
                                          rs_cycle_fn cycle_done, void *user, rs_stage_stats *stats,
                                          rsmooth_error *error);

/* CSR lists: the entries of item i are list[start[i] .. start[i + 1]). Positions in the stage's
 * units (scaled near 1 by a power of two: normal_update.c). */
struct rs_stage_plan {
    size_t vertex_count, facet_count;
    const double *xyz;            /* 3 per vertex: the input, in the stage's units */
    const uint32_t *facet_vertex; /* 3 per facet */
    const double *facet_normal;   /* 3 per facet: the input's unit normals */
    const double *facet_area;
    const double *facet_centroid; /* 3 per facet */
    const uint32_t *rep;          /* per vertex: its welded vertex */
    const size_t *rep_start;      /* vertex_count + 1 */
    const uint32_t *rep_facet;
    const size_t *patch_start; /* facet_count + 1 */
    const uint32_t *patch;
    const size_t *edge_start; /* facet_count + 1: edges, 2 facets each in `edge` */
    const uint32_t *edge;
    const size_t *near_start; /* facet_count + 1 */
    const uint32_t *near;
    bool filter;             /* false: the normals stay the facets' own (no shared edge) */
    double inv_2s2, inv_2t2; /* the guided filter's 1 / 2 sigma^2, natural exponents */
    int rounds, updates, cycles;
    const uint8_t *move_mask; /* NULL: every vertex moves */
};

/* What a run of the stage measured. */
struct rs_stage_stats {
    double ms_lists; /* facets, adjacency and the guided lists, on the host */
    double ms_upload, ms_cycles, ms_download;
    uint64_t bytes_to_device, bytes_from_device;
    int cycles;     /* cycles run */
    int float_bits; /* the precision they ran in: 64 (the host, a device with fp64), 32 */
    bool on_device;
    bool skipped;     /* not run: the mesh reads clean (rsmooth_params.guard) */
    char device[128]; /* where the cycles ran */
};

#endif /* RSMOOTH_STAGE_PLAN_H */
