/* A native "roofline" for rsmooth-bench: how many vertex-facet pairs per second this machine's CPU
 * cores evaluate with the kernels' per-pair arithmetic (kernels/mollify.cl, kernels/estimate.cl)
 * in a tight, vectorized C loop over contiguous float32 arrays, every pair fully evaluated. The
 * filter's useful pairs per second divided by this says how far the OpenCL path is from it. */
#ifndef RSMOOTH_BENCH_ROOFLINE_H
#define RSMOOTH_BENCH_ROOFLINE_H

#include "bench_pairs.h"

#include <stddef.h>

/* What the passes are given, in mesh units (as rsmooth_report gives them). */
typedef struct bench_roofline_setup {
    double sigma_f, sigma_g;       /* sigma_g may be +INFINITY (influence off) */
    double sigma_m;                /* mollification width */
    double radius, mollify_radius; /* mollify_radius 0: that pass is not timed */
} bench_roofline_setup;

typedef struct bench_roofline {
    double mollify_pairs_per_s; /* 0 when not timed */
    double robust_pairs_per_s;
    int threads;    /* OpenMP threads the loop ran on (1 without OpenMP) */
    int openmp;     /* 1 when built with OpenMP */
    int lanes;      /* vertices per block */
    size_t window;  /* facets each block is evaluated against */
    double seconds; /* wall time of all the timing, calibration included */
} bench_roofline;

/* Times both passes over the facets of `grid` (its cell order) and the float32 vertices at
 * `positions` (3 per vertex): the median of 5 repetitions of at least 0.3 s each. Returns 0, or
 * -1 when memory runs out or there is no facet. */
int bench_roofline_run(const bench_grid *grid, const float *positions, size_t vertex_count,
                       const bench_roofline_setup *setup, bench_roofline *result);

#endif
