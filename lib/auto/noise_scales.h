/* The noise's residual at several scales (internal): how much of it polynomial fits over growing
 * neighbourhoods leave, from which its correlated part and correlation length are read. */
#ifndef RSMOOTH_NOISE_SCALES_H
#define RSMOOTH_NOISE_SCALES_H

#include "rsmooth.h"

#include <stddef.h>
#include <stdint.h>

#define RS_NOISE_SCALE_COUNT 3

typedef struct rs_noise_profile {
    /* Fit radii, mean edge lengths (noisy mesh's). */
    double radius[RS_NOISE_SCALE_COUNT];
    /* Per radius: the robust standard deviation (1.4826 x median |r|) of the standardised
     * prediction residuals r of a quadric height field fitted to the neighbours within that
     * radius, mean edge lengths; NAN when no sample had a fit. */
    double low[RS_NOISE_SCALE_COUNT];
    /* The same of a Taubin-smoothed copy (noise_scales.c, the shape floor): what the shape alone
     * leaves at each radius, about. */
    double low_floor[RS_NOISE_SCALE_COUNT];
    size_t samples;
} rs_noise_profile;

/* The profile of `count` points (xyz, unit normals: 3 doubles each, internal units), `unit` their
 * mean edge length (> 0), ring_start/ring their mesh neighbours (count + 1 starts; for the shape
 * floor). Deterministic for any thread count. Errors name `caller`. */
rsmooth_status rs_noise_scales(const double *xyz, const double *normal, size_t count, double unit,
                               const uint32_t *ring_start, const uint32_t *ring,
                               rs_noise_profile *out, rsmooth_error *error, const char *caller);

/* The correlated noise read from a profile (noise_scales.c's header comment): its rms along the
 * normals and its correlation length, both in mean edge lengths of the profile; length 0 and the
 * level `level` (the small-scale estimate) when the noise reads uncorrelated. */
void rs_noise_correlated(const rs_noise_profile *profile, double level, double *correlated_level,
                         double *correlation_length);

#endif
