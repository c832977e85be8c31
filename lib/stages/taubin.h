/* Taubin's lambda|mu smoothing (taubin.c), the choice per region's alternative. Internal, not
 * installed. */
#ifndef RSMOOTH_TAUBIN_H
#define RSMOOTH_TAUBIN_H

#include "rsmooth.h"

#include <stddef.h>
#include <stdint.h>

/* Taubin's lambda|mu smoothing of xyz (double, in place) until the RMS distance of the vertices
 * from where they started reaches target_move (mesh units) and, when min_gain > 0, an iteration
 * adds less than min_gain to it; or max_iterations. Returns the iterations run, -1 when out of
 * memory (xyz unchanged). */
int rs_taubin_until(double *xyz, size_t vertex_count, const uint32_t *indices,
                    size_t triangle_count, double lambda, double mu, double target_move,
                    double min_gain, int max_iterations);

/* The public functions' bodies, for api/'s definitions of them (lib/api/): */
/* rsmooth_smooth_taubin */
rsmooth_status rs_smooth_taubin(rsmooth_scalar scalar, const void *positions, size_t vertex_count,
                                const uint32_t *indices, size_t triangle_count, double lambda,
                                double mu, unsigned iterations, void *out_positions,
                                rsmooth_error *error);

#endif /* RSMOOTH_TAUBIN_H */
