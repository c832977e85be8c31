/* The noise estimate's details (internal): what rsmooth_estimate_noise measures, and how it read
 * the noise's kind. See the header comment of noise_estimate.c for how each figure is measured. */
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
     * displaced vertices only. rsmooth_estimate_noise returns this. 0 when nothing is measurable.
     */
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
    /* The rms of the noise along the normals including its spatially correlated part
     * (noise_scales.c), clean mean edge lengths: level when the noise reads uncorrelated. */
    double correlated_level;
    /* The correlated part's correlation length (mean edge lengths; 0: uncorrelated). */
    double correlation_length;
    /* What the two are read from (radii and figures in the noisy mesh's mean edge lengths). */
    rs_noise_profile profile;
    /* core/shape_correlation.h's figure: near 1 where the roughness is shape, at or below 0 where
     * it is noise. */
    double shape_correlation;
    /* The mesh's parts (core/parts.h) and outliers: the figures above are the largest part's. */
    size_t parts, outliers;
} rs_noise_details;

/* Nothing to remove (rs_noise_reads_clean): the correlation of bends at or above
 * RS_CLEAN_SHAPE_CORRELATION (core/shape_correlation.h), or (noise
 * read as Gaussian) the small-scale residual within this factor of what a smoothed copy of the
 * mesh leaves (the shape's own share, noise_scales.c). Chosen on the 28 clean meshes of
 * ../shared/data/clean (clean: correlation 0.37-0.99 but one, decimated-knight at -0.07, whose
 * residual is 1.37 times its floor), the 30 noisy accuracy cases (noisy: correlation at most
 * 0.07, residuals 1.64 to 13 times the floor) and the two raw range scans (0.17, 0.10; 8 and 9
 * times). */
#define RS_CLEAN_FLOOR 1.4
/* Impulsive noise whose tail share reaches this (twice the share that reads impulsive) is noise
 * whatever the bends say: a few vertices thrown off a cube leave the cube's correlated edges in
 * charge of the correlation (a 2402-vertex cube with 5% of its vertices thrown 0.3 edges: 0.30).
 * Thrown vertices read 0.029-0.063 here; the one clean mesh that reads impulsive, truck, 0.008. */
#define RS_CLEAR_IMPULSIVE_TAIL 0.012

/* rsmooth_estimate_noise with the details; errors name `caller`. Deterministic for any thread
 * count. */
rsmooth_status rs_estimate_noise_details(rsmooth_scalar scalar, const void *positions,
                                         size_t vertex_count, const uint32_t *indices,
                                         size_t triangle_count, rs_noise_details *out,
                                         rsmooth_error *error, const char *caller);

/* Whether the estimate finds nothing to remove: no measurable noise, or roughness that reads as
 * the mesh's own shape (a clean mesh, however coarse). */
bool rs_noise_reads_clean(const rs_noise_details *d);

/* The public functions' bodies, for api/'s definitions of them (lib/api/): */
/* rsmooth_params_auto */
rsmooth_status rs_params_auto(rsmooth_scalar scalar, const void *positions, size_t vertex_count,
                              const uint32_t *indices, size_t triangle_count,
                              rsmooth_params *params, rsmooth_noise_report *report,
                              rsmooth_error *error);
/* rsmooth_estimate_noise */
rsmooth_status rs_estimate_noise(rsmooth_scalar scalar, const void *positions, size_t vertex_count,
                                 const uint32_t *indices, size_t triangle_count, double *out_noise,
                                 rsmooth_error *error);

#endif
