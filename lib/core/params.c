/* Filter parameters: defaults, forward-compatible copying and range checks. */
#include "core/rsmooth_internal.h"

#include <math.h>
#include <string.h>

/* The size of the first published rsmooth_params: callers built against it stay valid. */
#define PARAMS_V0_SIZE (offsetof(rsmooth_params, mollify) + sizeof(int))

rsmooth_status rs_params_init(rsmooth_params *params) {
    if (!params)
        return RSMOOTH_ERROR_INVALID_ARGUMENT;
    memset(params, 0, sizeof *params);
    params->struct_size = sizeof *params;
    params->sigma_f = 2.0;
    params->sigma_g = 0.5;
    params->absolute = 0;
    params->cutoff = 2.0;
    params->mollify_cutoff = 0.0;
    params->mollify = 1;
    params->progress = NULL;
    params->progress_user = NULL;
    params->predictor = RSMOOTH_PREDICT_PROJECTION;
    params->normal_filter = RSMOOTH_NORMALS_MOLLIFY;
    params->normal_sigma_s = 1.0;
    params->normal_sigma_n = 0.35;
    params->normal_iterations = 5;
    params->influence = RSMOOTH_INFLUENCE_GAUSSIAN;
    params->passes = 1;
    params->pass_confidence = 0.0;
    params->colors = NULL;
    params->sigma_c = 0.1;
    params->progress_cancel = NULL;
    params->vertex_updates = 0;
    params->guided_sigma_s = 2.0;
    params->guided_sigma_n = 0.2;
    params->guided_rounds = 20;
    params->discrepancy_level = 0.0;
    params->stage_repeats = 1;
    params->guided_radius = 2.0;
    params->discrepancy_gain = 0.0;
    params->guard = 1;
    params->stage_normals = RSMOOTH_STAGE_NORMALS_GUIDED;
    params->model = NULL;
    params->model_size = 0;
    return RSMOOTH_OK;
}

rsmooth_status rs_params_init_best(rsmooth_params *params) {
    if (rs_params_init(params) != RSMOOTH_OK)
        return RSMOOTH_ERROR_INVALID_ARGUMENT;
    params->sigma_f = 0.8;
    params->sigma_g = 0.3;
    params->normal_filter = RSMOOTH_NORMALS_BILATERAL;
    params->normal_sigma_s = 1.0;
    params->normal_sigma_n = 0.45;
    params->normal_iterations = 5;
    params->passes = 1;
    /* the normal update stage first, as the guided filter's authors run it: 10 cycles of one
     * guided round (radius 3, width 0.2, spatial width 1 mean edge length) and 10 vertex updates
     * (params_auto.c's class "mid", the one --best --auto picks at 0.25-0.45 edge lengths) */
    params->vertex_updates = 10;
    params->guided_rounds = 1;
    params->stage_repeats = 10;
    params->guided_radius = 3.0;
    params->guided_sigma_s = 1.0;
    return RSMOOTH_OK;
}

rsmooth_status rs_params_resolve(const rsmooth_params *params, rsmooth_params *out,
                                 rsmooth_error *error, const char *where) {
    rs_params_init(out);
    if (params) {
        if (params->struct_size < PARAMS_V0_SIZE)
            return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                           "params.struct_size %zu is too small: call rsmooth_params_init first",
                           params->struct_size);
        size_t n = params->struct_size < sizeof *out ? params->struct_size : sizeof *out;
        memcpy(out, params, n);
        out->struct_size = sizeof *out;
    }
    if (!(out->sigma_f > 0) || !isfinite(out->sigma_f))
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "sigma_f must be positive and finite (got %g)", out->sigma_f);
    if (!(out->sigma_g > 0)) /* NaN fails too; +INFINITY turns the influence weight off */
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "sigma_g must be positive, or +infinity to turn the influence off (got %g)",
                       out->sigma_g);
    if (!(out->cutoff > 0) || !(out->cutoff <= 5))
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "cutoff must be in (0, 5] sigma_f (got %g)", out->cutoff);
    if (!(out->mollify_cutoff >= 0) || !(out->mollify_cutoff <= out->cutoff))
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "mollify_cutoff must be in [0, cutoff = %g] (got %g)", out->cutoff,
                       out->mollify_cutoff);
    if (out->absolute != 0 && out->absolute != 1)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "absolute must be 0 or 1 (got %d)", out->absolute);
    if (out->guard != 0 && out->guard != 1)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "guard must be 0 or 1 (got %d)", out->guard);
    if (out->stage_normals != RSMOOTH_STAGE_NORMALS_GUIDED &&
        out->stage_normals != RSMOOTH_STAGE_NORMALS_LEARNED)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "stage_normals must be RSMOOTH_STAGE_NORMALS_GUIDED (0) or _LEARNED (1) "
                       "(got %d)",
                       out->stage_normals);
    if (out->model && out->model_size == 0)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "model is set but model_size is 0");
    if (out->mollify != 0 && out->mollify != 1)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "mollify must be 0 or 1 (got %d)", out->mollify);
    if (out->predictor != RSMOOTH_PREDICT_PROJECTION && out->predictor != RSMOOTH_PREDICT_CENTROID)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "predictor must be RSMOOTH_PREDICT_PROJECTION or RSMOOTH_PREDICT_CENTROID "
                       "(got %d)",
                       out->predictor);
    if (out->normal_filter != RSMOOTH_NORMALS_MOLLIFY &&
        out->normal_filter != RSMOOTH_NORMALS_BILATERAL)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "normal_filter must be RSMOOTH_NORMALS_MOLLIFY or RSMOOTH_NORMALS_BILATERAL "
                       "(got %d)",
                       out->normal_filter);
    if (!(out->normal_sigma_s > 0) || !isfinite(out->normal_sigma_s))
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "normal_sigma_s must be positive and finite (got %g)", out->normal_sigma_s);
    if (!(out->normal_sigma_n > 0) || !(out->normal_sigma_n <= 2))
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "normal_sigma_n must be in (0, 2] (got %g)", out->normal_sigma_n);
    if (out->normal_iterations < 1 || out->normal_iterations > RS_MAX_ROUNDS)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "normal_iterations must be in [1, %d] (got %d)", RS_MAX_ROUNDS,
                       out->normal_iterations);
    if (out->influence < RSMOOTH_INFLUENCE_GAUSSIAN || out->influence > RSMOOTH_INFLUENCE_HUBER)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "influence must be an rsmooth_influence, 0 to 3 (got %d)", out->influence);
    if (out->vertex_updates < 0 || out->vertex_updates > RS_MAX_UPDATES)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "vertex_updates must be in [0, %d] (got %d)", RS_MAX_UPDATES,
                       out->vertex_updates);
    if (out->passes < 0 || out->passes > RS_MAX_ROUNDS)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "passes must be in [0, %d] (got %d)", RS_MAX_ROUNDS, out->passes);
    if (!(out->guided_sigma_s > 0) || !isfinite(out->guided_sigma_s))
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "guided_sigma_s must be positive and finite (got %g)", out->guided_sigma_s);
    if (!(out->guided_sigma_n > 0) || !(out->guided_sigma_n <= 2))
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "guided_sigma_n must be in (0, 2] (got %g)", out->guided_sigma_n);
    if (out->stage_repeats < 1 || out->stage_repeats > RS_MAX_CYCLES)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "stage_repeats must be in [1, %d] (got %d)", RS_MAX_CYCLES,
                       out->stage_repeats);
    if (!(out->discrepancy_gain >= 0 && out->discrepancy_gain <= 1)) /* NaN fails too */
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "discrepancy_gain must be in [0, 1] (got %g)", out->discrepancy_gain);
    if (!(out->guided_radius >= 1 && out->guided_radius <= 8)) /* NaN fails too */
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "guided_radius must be in [1, 8] (got %g)", out->guided_radius);
    if (!(out->discrepancy_level >= 0) || !isfinite(out->discrepancy_level))
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "discrepancy_level must be 0 (off) or positive and finite (got %g)",
                       out->discrepancy_level);
    if (out->guided_rounds < 1 || out->guided_rounds > RS_MAX_ROUNDS)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "guided_rounds must be in [1, %d] (got %d)", RS_MAX_ROUNDS,
                       out->guided_rounds);
    if (!(out->pass_confidence >= 0) || !(out->pass_confidence <= 1))
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "pass_confidence must be in [0, 1] (got %g)", out->pass_confidence);
    if (!(out->sigma_c > 0)) /* NaN fails too; +INFINITY turns the colour factor off */
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "sigma_c must be positive, or +infinity to turn the colour factor off "
                       "(got %g)",
                       out->sigma_c);
    return RSMOOTH_OK;
}
