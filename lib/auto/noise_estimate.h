/* The noise estimate's details (internal): what rsmooth_estimate_noise measures, and how it read the
 * noise's kind. See the header comment of noise_estimate.c for how each figure is measured. */
#ifndef RSMOOTH_NOISE_ESTIMATE_H
#define RSMOOTH_NOISE_ESTIMATE_H

#include "auto/noise_scales.h"
#include "rsmooth.h"

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

typedef struct rs_noise_details {
    /* The standard deviation of the vertices' displacement along the surface normal, in mean edge
     * lengths of the CLEAN mesh (estimated: the noisy mesh's edges are longer). Random-direction
     * noise of total standard deviation s reads s / sqrt(3). For impulsive noise, that of the
     * displaced vertices only. rsmooth_estimate_noise returns this. 0 when nothing is measurable. */
    double level;
    /* A share of the vertices displaced and the rest (nearly) exact. */
    bool impulsive;
    /* The share of vertices displaced: 1 unless impulsive. */
    double impulsive_fraction;
    /* The standard deviation of the displacement along one tangent direction, clean mean edge
     * lengths (about level for random-direction noise, about 0 for noise along the normals); NAN
     * when not measurable. */
    double tangential_level;
    /* The clean mesh's mean edge length as estimated, and the noisy mesh's as measured, in the
     * caller's units (0 when the mesh has no edge). */
    double mean_edge_clean;
    double mean_edge_noisy;
    /* The standard deviation of all vertices' normal displacement (clean mean edge lengths): equal
     * to level for Gaussian noise, about sqrt(fraction) x level for impulsive noise. */
    double overall_level;
    /* Share of the samples whose robust residual exceeds 6 times their refit's inlier scatter
     * (noise_estimate.c, outlier_share): above 0.006 the noise reads impulsive. */
    double tail_share;
    /* Vertices whose residual was measured. */
    size_t samples;
    /* The rms of the noise along the normals including its spatially correlated part (noise_scales.c),
     * clean mean edge lengths: level when the noise reads uncorrelated. */
    double correlated_level;
    /* The correlated part's correlation length (mean edge lengths; 0: uncorrelated). */
    double correlation_length;
    /* What the two are read from (radii and figures in the noisy mesh's mean edge lengths). */
    rs_noise_profile profile;
} rs_noise_details;

/* rsmooth_estimate_noise with the details; errors name `caller`. Deterministic for any thread
 * count. */
rsmooth_status rs_estimate_noise_details(rsmooth_scalar scalar, const void *positions,
                                         size_t vertex_count, const uint32_t *indices,
                                         size_t triangle_count, rs_noise_details *out,
                                         rsmooth_error *error, const char *caller);

#endif
