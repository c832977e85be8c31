/* The public parameter and report initialisers and the automatic parameters (rsmooth.h): core/
 * holds the defaults, auto/ the rules. */
#include "auto/noise_estimate.h"
#include "core/rsmooth_internal.h"

rsmooth_status rsmooth_params_init(rsmooth_params *params) {
    return rs_params_init(params);
}

void rsmooth_report_init(rsmooth_report *report) {
    rs_report_init(report);
}

rsmooth_status rsmooth_params_init_best(rsmooth_params *params) {
    return rs_params_init_best(params);
}

rsmooth_status rsmooth_params_auto(rsmooth_scalar scalar, const void *positions,
                                   size_t vertex_count, const uint32_t *indices,
                                   size_t triangle_count, rsmooth_params *params,
                                   rsmooth_noise_report *report, rsmooth_error *error) {
    return rs_params_auto(scalar, positions, vertex_count, indices, triangle_count, params, report,
                          error);
}
