/* Automatic parameters: the sigmas (and, for the best mode, its normal filter and passes) picked
 * from the input's estimated noise, by rules measured on noisy meshes with a ground truth
 * (docs/experiments.md: section 3 for the paper's filter, section 6 for the best mode). */
#include "rsmooth_internal.h"

#include <math.h>
#include <string.h>

/* The paper's filter: the least-squares line of the best sigma_f over four clean meshes at noise
 * 0.1 ... 0.7 and the median best sigma_g / noise (scripts/experiments.py, Fig. 5(a)). */
#define PAPER_SIGMA_F_AT_0 0.92
#define PAPER_SIGMA_F_PER_NOISE 0.81
#define PAPER_SIGMA_G_PER_NOISE 3.1

/* The best mode moves between two settings as the noise n grows from LOW to HIGH mean edge
 * lengths: gentle (3 bilateral rounds, normal width 0.6, two passes) where the normals are barely
 * noisy, strong (8 wider rounds, normal width 0.3, six passes, Huber's weight, sigma_g 0.1) where
 * they are very noisy. Impulsive noise (a few vertices thrown far) spoils every normal around
 * them, so it gets the strong end with twice the rounds, each twice as wide. The end points were
 * calibrated on the five benchmark models against their ground truth (docs/experiments.md,
 * section 6), so the rule is measured on the models it was fitted to. */
#define BEST_NOISE_LOW 0.2
#define BEST_NOISE_HIGH 0.4

static double clamp01(double x) {
    return x < 0 ? 0 : x > 1 ? 1 : x;
}

/* Sets the sigmas of `params` (and, when its normal_filter is bilateral, the best mode's rounds,
 * passes and influence) for noise of `noise` mean edge lengths. */
static void params_from_noise(rsmooth_params *params, double noise, bool impulsive) {
    double n = noise > 0 ? noise : 0;
    if (params->normal_filter != RSMOOTH_NORMALS_BILATERAL) {
        params->sigma_f = PAPER_SIGMA_F_AT_0 + PAPER_SIGMA_F_PER_NOISE * n;
        params->sigma_g = n > 0 ? PAPER_SIGMA_G_PER_NOISE * n : params->sigma_g;
        return;
    }
    if (impulsive)
        n = fmax(n, BEST_NOISE_HIGH);
    double t = clamp01((n - BEST_NOISE_LOW) / (BEST_NOISE_HIGH - BEST_NOISE_LOW));
    double strong = clamp01((n - 0.3) / 0.1); /* sigma_g narrows only in the upper half */
    params->sigma_f = 0.8;
    params->sigma_g = 0.3 - 0.2 * strong;
    params->normal_sigma_s = impulsive ? 2.0 : 1.0 + 0.5 * t;
    params->normal_sigma_n = 0.6 - 0.3 * t;
    params->normal_iterations = (int)lround((3 + 5 * t) * (impulsive ? 2 : 1));
    params->passes = (int)lround(2 + 4 * t);
    params->influence = n >= 0.35 ? RSMOOTH_INFLUENCE_HUBER : RSMOOTH_INFLUENCE_GAUSSIAN;
    params->absolute = 0;
}

rsmooth_status rsmooth_params_auto(rsmooth_scalar scalar, const void *positions,
                                   size_t vertex_count, const uint32_t *indices,
                                   size_t triangle_count, rsmooth_params *params,
                                   double *out_noise, rsmooth_error *error) {
    static const char where[] = "rsmooth_params_auto";
    rs_error_clear(error);
    if (!params)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "params is NULL: initialise it with rsmooth_params_init or "
                       "rsmooth_params_init_best first");
    rsmooth_params checked;
    rsmooth_status st = rs_params_resolve(params, &checked, error, where);
    if (st != RSMOOTH_OK)
        return st;
    rs_noise_stats stats;
    st = rs_estimate_noise_stats(scalar, positions, vertex_count, indices, triangle_count, &stats,
                                 error, where);
    if (st != RSMOOTH_OK)
        return st;
    /* only the fields the caller's struct has are written */
    params_from_noise(&checked, stats.noise, stats.impulsive);
    size_t size = params->struct_size;
    memcpy(params, &checked, size < sizeof checked ? size : sizeof checked);
    params->struct_size = size;
    if (out_noise)
        *out_noise = stats.noise;
    return RSMOOTH_OK;
}
