/* Repeated passes (beyond the paper, its Sec. 5 suggestion): the filter run again from its own
 * output, optionally only where the previous pass had low confidence. Each pass recomputes facet
 * data, normals and the grid from the previous positions; the sigmas stay those the input's mean
 * edge length gave, so later passes do not shrink their reach as the mesh smooths. */
#include "passes/passes.h"

#include "auto/noise_estimate.h"
#include "learned/learned.h"
#include "passes/one_part.h"
#include "passes/region_choice.h"
#include "stages/normal_update.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

int rs_report_pass_progress(void *user, double fraction) {
    const rs_pass_progress *pp = user;
    double whole = ((double)pp->pass + fraction) / (double)pp->count;
    if (pp->progress)
        pp->progress(pp->user, whole);
    return pp->cancel ? pp->cancel(pp->user, whole) : 0;
}

void rs_add_pass_report(rsmooth_report *sum, const rsmooth_report *pass) {
    rsmooth_report keep = *sum;
    *sum = *pass;
    rs_add_report_times(sum, &keep);
    if (keep.vertex_count) /* the facets of the input, not of the last pass's positions */
        sum->facet_count = keep.facet_count;
}

/* The vertices params->move_mask holds still get their input position back, byte for byte. */
static void keep_unselected(rsmooth_scalar scalar, const void *positions, size_t vertex_count,
                            const uint8_t *mask, void *out_positions) {
    size_t record = rs_vertex_bytes(scalar);
    for (size_t v = 0; mask && v < vertex_count; v++)
        if (!mask[v])
            memcpy((char *)out_positions + v * record, (const char *)positions + v * record,
                   record);
}

static rsmooth_status filter_passes(rs_filter_fn one_pass, void *ctx, rsmooth_scalar scalar,
                                    const void *positions, size_t vertex_count,
                                    const uint32_t *indices, size_t triangle_count,
                                    const rsmooth_params *params, void *out_positions,
                                    float *out_weight, float *out_confidence,
                                    rsmooth_report *report, rsmooth_error *error, const char *where,
                                    rsmooth_params *resolved, const rs_stage_place *stage,
                                    rs_stage_stats *stage_stats);

/* What no pass of the filter leaves: weights 0, confidences 1, a report of the counts alone. */
static void no_pass(float *out_weight, float *out_confidence, size_t vertex_count,
                    size_t triangle_count, rsmooth_report *report) {
    for (size_t v = 0; v < vertex_count; v++) {
        if (out_weight)
            out_weight[v] = 0;
        if (out_confidence)
            out_confidence[v] = 1;
    }
    if (report) {
        rs_report_init(report);
        report->vertex_count = vertex_count;
        report->triangle_count = triangle_count;
    }
}

/* The stage's progress: the cycles done, as a fraction of the stage's half. */
static int report_cycle(void *user, int done, int cycles) {
    return rs_report_pass_progress(user, (double)done / cycles);
}

/* The normal update stage (normal_update.h) on a double copy of the input, then the passes from
 * its result, in the caller's scalar type (params resolved and outputs checked). */
static rsmooth_status staged_passes(rs_filter_fn one_pass, void *ctx, rsmooth_scalar scalar,
                                    const void *positions, size_t vertex_count,
                                    const uint32_t *indices, size_t triangle_count,
                                    const rsmooth_params *resolved, void *out_positions,
                                    float *out_weight, float *out_confidence,
                                    rsmooth_report *report, rsmooth_error *error, const char *where,
                                    const rs_stage_place *stage, rs_stage_stats *stage_stats) {
    double t_start = rs_now_ms();
    double unit = 0; /* (the arrays were checked at the call's entry: rs_filter_passes) */
    rsmooth_status st = rs_mesh_mean_edge(scalar, positions, vertex_count, indices, triangle_count,
                                          &unit, error, where);
    if (st != RSMOOTH_OK)
        return st;
    rsmooth_params p = *resolved;
    if (!p.absolute) { /* the input's unit for the stage and every pass after it */
        p.sigma_f *= unit;
        p.sigma_g *= unit;
        p.normal_sigma_s *= unit;
        p.guided_sigma_s *= unit;
        p.absolute = 1;
    }
    double *staged = rs_alloc_array(vertex_count ? vertex_count : 1, 3 * sizeof(double));
    if (!staged)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where,
                       "no memory for the normal update stage");
    for (size_t i = 0; i < 3 * vertex_count; i++)
        staged[i] = rs_coordinate(scalar, positions, i);
    /* Progress: the stage is the first half, reported after each cycle (and the caller may stop
     * it there); the passes the second half, through the same rescaling as repeated passes. */
    int halves = p.passes > 0 ? 2 : 1;
    rs_pass_progress pp = {p.progress, p.progress_cancel, p.progress_user, 0, halves};
    bool reports = pp.progress || pp.cancel;
    rs_stage_setting setting = {.sigma_s = p.guided_sigma_s,
                                .sigma_n = p.guided_sigma_n,
                                .radius = p.guided_radius,
                                .rounds = p.guided_rounds,
                                .updates = p.vertex_updates,
                                .cycles = p.stage_repeats};
    /* do no harm: no stage where the noise estimate finds nothing to remove (a caller that gives
     * the noise level, as rsmooth_params_auto does where it found noise, has measured it) */
    bool clean = false, learned = p.stage_normals == RSMOOTH_STAGE_NORMALS_LEARNED;
    rs_noise_details noise = {0};
    rs_learned_model model = {0}; /* read first: a bad model is an error on any mesh */
    if (learned)
        st = p.model ? rs_learned_model_read(p.model, p.model_size, &model, error, "params.model")
                     : rs_learned_model_builtin(&model, error);
    if (st == RSMOOTH_OK && unit > 0 && ((p.guard && !(p.discrepancy_level > 0)) || learned)) {
        st = rs_estimate_noise_details(scalar, positions, vertex_count, indices, triangle_count,
                                       &noise, error, where);
        clean = st == RSMOOTH_OK && p.guard && !(p.discrepancy_level > 0) &&
                rs_noise_reads_clean(&noise);
        if (stage_stats)
            stage_stats->skipped = clean;
    }
    if (st == RSMOOTH_OK && learned && unit > 0 && !clean) {
        setting.learned = &model;
        setting.noise_level = noise.level; /* the descriptor's: as train/ measures it */
        setting.mean_edge = unit;
        setting.network = stage ? &stage->network : NULL;
    }
    if (st == RSMOOTH_OK && unit > 0 && !clean) /* no edge: nothing to filter */
        st = rs_normal_update_stage(staged, vertex_count, indices, triangle_count, &setting,
                                    p.move_mask, stage, reports ? report_cycle : NULL, &pp,
                                    stage_stats, error, where);
    rs_learned_model_free(&model);
    double t_stage = rs_now_ms();
    if (st == RSMOOTH_OK && p.passes == 0) { /* the stage alone */
        for (size_t v = 0; v < vertex_count; v++)
            rs_store_position(scalar, out_positions, v, staged + 3 * v, 1);
        no_pass(out_weight, out_confidence, vertex_count, triangle_count, report);
        if (report) {
            report->mean_edge_length = unit;
            if (stage_stats && stage_stats->device[0])
                snprintf(report->device, sizeof report->device, "%.127s", stage_stats->device);
            else
                snprintf(report->device, sizeof report->device, "host (double, %zu threads)",
                         rs_host_threads());
        }
    } else if (st == RSMOOTH_OK) {
        /* the passes read the stage's result in the caller's type (a float32 caller's outputs
         * are float32 anyway) */
        void *from = staged;
        if (scalar == RSMOOTH_FLOAT32) {
            float *f = (float *)staged; /* narrowing in place: element i never overtakes 3v+k */
            for (size_t i = 0; i < 3 * vertex_count; i++)
                f[i] = (float)staged[i];
            from = f;
        }
        p.vertex_updates = 0;
        if (reports) {
            pp.pass = 1;
            p.progress = NULL;
            p.progress_cancel = rs_report_pass_progress;
            p.progress_user = &pp;
        }
        rsmooth_params unused;
        st = filter_passes(one_pass, ctx, scalar, from, vertex_count, indices, triangle_count, &p,
                           out_positions, out_weight, out_confidence, report, error, where, &unused,
                           NULL, NULL);
    }
    if (st == RSMOOTH_OK && report) {
        report->ms_normals += t_stage - t_start; /* the stage counts as normal filtering */
        report->ms_total = rs_now_ms() - t_start;
        report->mean_edge_length = unit; /* the input's, the unit of its sigmas */
    }
    rs_free(staged);
    return st;
}

/* Passes after the first: confident vertices keep what the pass before gave them. */
static void keep_confident(const double *cur, double *next, float *weight, float *confidence,
                           const float *prev_weight, const float *prev_confidence,
                           size_t vertex_count, double threshold) {
    for (size_t v = 0; v < vertex_count; v++)
        if (prev_confidence[v] >= threshold) {
            memcpy(next + 3 * v, cur + 3 * v, 3 * sizeof(double));
            weight[v] = prev_weight[v];
            confidence[v] = prev_confidence[v];
        }
}

/* No pass and no stage: the input comes back, weights 0 and confidences 1 (what
 * rsmooth_params_auto sets on a mesh with nothing to remove). */
static rsmooth_status give_input(rsmooth_scalar scalar, const void *positions, size_t vertex_count,
                                 size_t triangle_count, void *out_positions, float *out_weight,
                                 float *out_confidence, rsmooth_report *report, double t_start) {
    memcpy(out_positions, positions, vertex_count * rs_vertex_bytes(scalar));
    no_pass(out_weight, out_confidence, vertex_count, triangle_count, report);
    if (report) {
        snprintf(report->device, sizeof report->device, "none (no pass)");
        report->ms_total = rs_now_ms() - t_start;
    }
    return RSMOOTH_OK;
}

static rsmooth_status filter_passes(rs_filter_fn one_pass, void *ctx, rsmooth_scalar scalar,
                                    const void *positions, size_t vertex_count,
                                    const uint32_t *indices, size_t triangle_count,
                                    const rsmooth_params *params, void *out_positions,
                                    float *out_weight, float *out_confidence,
                                    rsmooth_report *report, rsmooth_error *error, const char *where,
                                    rsmooth_params *resolved, const rs_stage_place *stage,
                                    rs_stage_stats *stage_stats) {
    double t_start = rs_now_ms();
    rs_error_clear(error);
    rsmooth_params p;
    rsmooth_status st = rs_params_resolve(params, &p, error, where);
    *resolved = p;        /* the caller's mask and guard act at the end */
    if (st != RSMOOTH_OK) /* (arrays and outputs checked at the call's entry: rs_filter_passes) */
        return st;
    if (p.vertex_updates > 0)
        return staged_passes(one_pass, ctx, scalar, positions, vertex_count, indices,
                             triangle_count, &p, out_positions, out_weight, out_confidence, report,
                             error, where, stage, stage_stats);
    if (p.passes == 0) /* nothing to run */
        return give_input(scalar, positions, vertex_count, triangle_count, out_positions,
                          out_weight, out_confidence, report, t_start);
    if (p.passes == 1) /* the paper's single pass, exactly as it was */
        return one_pass(ctx, scalar, positions, vertex_count, indices, triangle_count, params,
                        out_positions, out_weight, out_confidence, report, error);
    /* Fix the sigmas in mesh units once, from the input (checked at the call's entry). */
    double unit = 0;
    if ((st = rs_mesh_mean_edge(scalar, positions, vertex_count, indices, triangle_count, &unit,
                                error, where)) != RSMOOTH_OK)
        return st;
    if (!p.absolute) {
        if (!(unit > 0)) /* no edge: nothing moves, one pass says so */
            p.passes = 1;
        p.sigma_f *= unit;
        p.sigma_g *= unit; /* +INFINITY stays */
        p.normal_sigma_s *= unit;
        p.absolute = 1;
    }
    int passes = p.passes;
    p.passes = 1;
    rs_pass_progress pp = {p.progress, p.progress_cancel, p.progress_user, 0, passes};
    if (pp.progress || pp.cancel) {
        p.progress = NULL;
        p.progress_cancel = rs_report_pass_progress;
        p.progress_user = &pp;
    }
    if (passes == 1)
        return one_pass(ctx, scalar, positions, vertex_count, indices, triangle_count, &p,
                        out_positions, out_weight, out_confidence, report, error);

    double *cur = rs_alloc_array(vertex_count, 3 * sizeof(double));
    double *next = rs_alloc_array(vertex_count, 3 * sizeof(double));
    float *weight = rs_alloc_array(vertex_count, sizeof(float));
    float *confidence = rs_alloc_array(vertex_count, sizeof(float));
    float *prev_weight = rs_alloc_array(vertex_count, sizeof(float));
    float *prev_confidence = rs_alloc_array(vertex_count, sizeof(float));
    if (!cur || !next || !weight || !confidence || !prev_weight || !prev_confidence) {
        st = rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "no memory for %d passes", passes);
        goto done;
    }
    /* Every pass reads and writes double: a pass writes in the scalar type it reads, so a
     * float32 caller's first pass would otherwise leave floats where the next reads doubles. */
    for (size_t i = 0; i < 3 * vertex_count; i++)
        cur[i] = rs_coordinate(scalar, positions, i);
    rsmooth_report sum, one;
    memset(&sum, 0, sizeof sum);
    for (int pass = 0; pass < passes; pass++) {
        pp.pass = pass;
        st = one_pass(ctx, RSMOOTH_FLOAT64, cur, vertex_count, indices, triangle_count, &p, next,
                      weight, confidence, report ? &one : NULL, error);
        if (st != RSMOOTH_OK)
            goto done;
        if (report)
            rs_add_pass_report(&sum, &one);
        if (pass > 0 && p.pass_confidence > 0)
            keep_confident(cur, next, weight, confidence, prev_weight, prev_confidence,
                           vertex_count, p.pass_confidence);
        for (size_t v = 0; p.move_mask && v < vertex_count; v++)
            if (!p.move_mask[v]) /* held still: each pass sees it where the input has it */
                for (int k = 0; k < 3; k++)
                    next[3 * v + (size_t)k] = rs_coordinate(scalar, positions, 3 * v + (size_t)k);
        double *t = cur;
        cur = next;
        next = t;
        float *tw = prev_weight, *tc = prev_confidence;
        prev_weight = weight;
        prev_confidence = confidence;
        weight = tw;
        confidence = tc;
    }
    for (size_t v = 0; v < vertex_count; v++) {
        rs_store_position(scalar, out_positions, v, cur + 3 * v, 1); /* caller's units */
        if (out_weight)
            out_weight[v] = prev_weight[v];
        if (out_confidence)
            out_confidence[v] = prev_confidence[v];
    }
    if (report) {
        *report = sum;
        report->mean_edge_length = unit; /* the input's, the unit of its sigmas */
        report->ms_total = rs_now_ms() - t_start;
    }
done:
    rs_free(cur);
    rs_free(next);
    rs_free(weight);
    rs_free(confidence);
    rs_free(prev_weight);
    rs_free(prev_confidence);
    return st;
}

/* The stage's figures into the report (a caller's report new enough to have them). */
static void report_stage(rsmooth_report *report, const rs_stage_stats *stats) {
    report->ms_stage_lists = stats->ms_lists;
    report->ms_stage_upload = stats->ms_upload;
    report->ms_stage_cycles = stats->ms_cycles;
    report->ms_stage_download = stats->ms_download;
    report->ms_stage = stats->ms_lists + stats->ms_upload + stats->ms_cycles + stats->ms_download;
    report->stage_cycles = stats->cycles;
    report->stage_on_device = stats->on_device;
    report->stage_float_bits = stats->float_bits;
    report->stage_bytes_to_device = stats->bytes_to_device;
    report->stage_bytes_from_device = stats->bytes_from_device;
    report->stage_skipped = stats->skipped;
}

rsmooth_status rs_filter_one_part(rs_filter_fn one_pass, rs_stage_runner stage,
                                  rs_network_runner network, void *ctx, rsmooth_scalar scalar,
                                  const void *positions, size_t vertex_count,
                                  const uint32_t *indices, size_t triangle_count,
                                  const rsmooth_params *params, void *out_positions,
                                  float *out_weight, float *out_confidence, rsmooth_report *report,
                                  rsmooth_error *error, const char *where) {
    size_t caller_size = report ? report->struct_size : 0; /* the report's fillers reset it */
    rsmooth_params p;
    rs_stage_place place = {stage, ctx, {network, network ? ctx : NULL}};
    rs_stage_stats stage_stats;
    memset(&stage_stats, 0, sizeof stage_stats);
    rsmooth_status st = filter_passes(
        one_pass, ctx, scalar, positions, vertex_count, indices, triangle_count, params,
        out_positions, out_weight, out_confidence, report, error, where, &p, &place, &stage_stats);
    if (report)
        report->struct_size = caller_size;
    if (st != RSMOOTH_OK)
        return st;
    if (report && caller_size >= offsetof(rsmooth_report, stage_bytes_from_device) +
                                     sizeof report->stage_bytes_from_device)
        report_stage(report, &stage_stats);
    if (p.discrepancy_level > 0 && vertex_count > 0) {
        double share = 0;
        int iterations =
            rs_region_choice(scalar, positions, vertex_count, indices, triangle_count,
                             p.discrepancy_level, p.discrepancy_gain, out_positions, &share);
        if (iterations < 0)
            return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "no memory for the guard");
        if (report && caller_size >= offsetof(rsmooth_report, discrepancy_iterations) +
                                         sizeof report->discrepancy_iterations)
            report->discrepancy_iterations = iterations;
        if (report && caller_size >= offsetof(rsmooth_report, region_filter_share) +
                                         sizeof report->region_filter_share)
            report->region_filter_share = iterations > 0 ? share : 0;
    }
    /* every pass held them still; their final bytes are the input's own */
    keep_unselected(scalar, positions, vertex_count, p.move_mask, out_positions);
    return rs_check_results(scalar, out_positions, out_weight, out_confidence, vertex_count,
                            "vertex", error, where);
}
