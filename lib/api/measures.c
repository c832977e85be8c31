/* The public measures of a mesh or point set and the baselines (rsmooth.h): the mean edge length
 * (core/), the noise estimate (auto/), the point spacing (reference/), the error against a truth
 * (metrics/), Laplacian and Taubin smoothing (stages/). */
#include "auto/noise_estimate.h"
#include "core/rsmooth_internal.h"
#include "metrics/metrics.h"
#include "reference/points.h"
#include "stages/taubin.h"

rsmooth_status rsmooth_mean_edge_length(rsmooth_scalar scalar, const void *positions,
                                        size_t vertex_count, const uint32_t *indices,
                                        size_t triangle_count, double *out_length,
                                        rsmooth_error *error) {
    return rs_mesh_mean_edge_length(scalar, positions, vertex_count, indices, triangle_count,
                                    out_length, error);
}

rsmooth_status rsmooth_estimate_noise(rsmooth_scalar scalar, const void *positions,
                                      size_t vertex_count, const uint32_t *indices,
                                      size_t triangle_count, double *out_noise,
                                      rsmooth_error *error) {
    return rs_estimate_noise(scalar, positions, vertex_count, indices, triangle_count, out_noise,
                             error);
}

rsmooth_status rsmooth_point_spacing(rsmooth_scalar scalar, const void *positions,
                                     size_t point_count, double *out_spacing,
                                     rsmooth_error *error) {
    return rs_point_spacing(scalar, positions, point_count, out_spacing, error);
}

rsmooth_status rsmooth_compare(rsmooth_scalar scalar, const void *result_positions,
                               const void *truth_positions, size_t vertex_count,
                               const uint32_t *indices, size_t triangle_count, rsmooth_metrics *out,
                               rsmooth_error *error) {
    return rs_compare(scalar, result_positions, truth_positions, vertex_count, indices,
                      triangle_count, out, error);
}

rsmooth_status rsmooth_smooth_taubin(rsmooth_scalar scalar, const void *positions,
                                     size_t vertex_count, const uint32_t *indices,
                                     size_t triangle_count, double lambda, double mu,
                                     unsigned iterations, void *out_positions,
                                     rsmooth_error *error) {
    return rs_smooth_taubin(scalar, positions, vertex_count, indices, triangle_count, lambda, mu,
                            iterations, out_positions, error);
}
