/* Automatic parameters: the widths (and, for the best mode, its whole setting) picked from the
 * input's estimated noise, by rules chosen on noisy meshes with a ground truth with
 * cross-validation that leaves whole meshes out (the calibrate study; the figures of meshes the
 * rules never saw are in docs/experiments.md, section 7). */
#include "auto/noise_estimate.h"
#include "core/rsmooth_internal.h"
#include "core/shape_correlation.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* The paper's filter: sigma_f = A + B n, sigma_g = C n for noise n (the calibrate study's fit,
 * the lattice rule with the lowest mean ratio to each case's best sigmas). */
#define PAPER_SIGMA_F_AT_0 0.6
#define PAPER_SIGMA_F_PER_NOISE 1.6
#define PAPER_SIGMA_G_PER_NOISE 4.0

/* The best mode: the normal update stage as the guided filter's authors run it (cycles of fresh
 * facet normals, one guided round and some vertex updates; spatial width 1 mean edge length),
 * then robust passes with bilateral normals, by noise class; then the choice per region
 * (rsmooth_params.discrepancy_level) at the estimated noise. The classes' bounds were fixed in
 * advance; each class's setting is the one the calibrate_stage study chose on all 30
 * calibration cases (the figures of cases left out of the fit: docs/accuracy.md). */
typedef struct best_preset {
    const char *name;
    double below;   /* for Gaussian levels below this (the last: any) */
    int cycles;     /* stage_repeats */
    int updates;    /* vertex_updates per cycle */
    double radius;  /* guided_radius */
    double sigma_n; /* guided_sigma_n */
    int passes;     /* robust passes after the stage */
} best_preset;

#define STAGE_SIGMA_S 1.0 /* guided_sigma_s, mean edge lengths */
static const best_preset GAUSSIAN_PRESETS[] = {
    {"best: low", 0.25, 5, 10, 3, 0.2, 1},
    {"best: mid", 0.45, 10, 10, 3, 0.2, 1},
    {"best: high", INFINITY, 40, 5, 2, 0.2, 1},
};
static const best_preset IMPULSIVE_PRESET = {"best: impulsive", INFINITY, 10, 10, 3, 0.2, 0};
/* Spatially correlated noise (range scans): where the multi-scale estimate reads a correlated part
 * this many times the small-scale level, Taubin's side of the choice per region runs until an
 * iteration adds less than CORRELATED_GAIN mean edge lengths to the move (rsmooth_params
 * .discrepancy_gain): on the two raw Stanford scans the truth-tuned iteration count (18 of a
 * grid 1..90, both) is where that gain falls to 0.0030 on either scan, so fitting on one and
 * applying to the other gives 19 iterations (the scans study). */
#define CORRELATED_SHARE 1.5
#define CORRELATED_GAIN 0.003

static bool reads_correlated(const rs_noise_details *d) {
    return d->correlation_length > 0 && d->correlated_level > CORRELATED_SHARE * d->level;
}

#define TANGENTIAL_SHARE                                                                           \
    0.5 /* tangential / normal level above which noise reads as random                             \
         * in direction (for the report only) */

/* A report with nothing measured yet. */
static void noise_report_blank(rsmooth_noise_report *report) {
    if (!report)
        return;
    memset(report, 0, sizeof *report);
    report->struct_size = sizeof *report;
    report->tangential_level = NAN;
}

/* "noise estimate 0.31 mean edge lengths, Gaussian along the normals (tangential 0.05)". */
static void describe(const rs_noise_details *d, char *out, size_t size) {
    double n = d->level > 0 ? d->level : 0;
    if (!(n > 0)) {
        snprintf(out, size, "noise estimate 0 (nothing measurable)");
        return;
    }
    if (d->impulsive) {
        snprintf(out, size,
                 "noise estimate %.3g mean edge lengths, impulsive (%.0f%% of the "
                 "vertices thrown)",
                 n, 100 * d->impulsive_fraction);
        return;
    }
    if (!isfinite(d->tangential_level)) {
        snprintf(out, size, "noise estimate %.3g mean edge lengths, Gaussian", n);
        return;
    }
    snprintf(out, size, "noise estimate %.3g mean edge lengths, Gaussian %s (tangential %.2g)", n,
             d->tangential_level > TANGENTIAL_SHARE * n ? "in random directions"
                                                        : "along the normals",
             d->tangential_level);
}

/* Nothing to remove: no pass and no stage, so the input comes back as it is. */
static void choose_clean(rsmooth_params *params, const rs_noise_details *d, const char *what,
                         char *preset, size_t preset_size, char *reason, size_t reason_size) {
    params->vertex_updates = 0;
    params->passes = 0;
    params->discrepancy_level = 0;
    params->discrepancy_gain = 0;
    snprintf(preset, preset_size, "clean");
    if (d->level > 0 && d->shape_correlation >= RS_CLEAN_SHAPE_CORRELATION)
        snprintf(reason, reason_size,
                 "noise estimate %.3g mean edge lengths, but the roughness "
                 "reads as the mesh's shape (bends correlated %.2f across neighbours): nothing "
                 "to remove, every vertex stays",
                 d->level, d->shape_correlation);
    else if (d->level > 0)
        snprintf(reason, reason_size,
                 "noise estimate %.3g mean edge lengths, but the roughness "
                 "is %.2f times what the shape alone leaves (a smoothed copy's): nothing to "
                 "remove, every vertex stays",
                 d->level, d->profile.low[0] / d->profile.low_floor[0]);
    else
        snprintf(reason, reason_size, "%.100s: nothing to remove, every vertex stays", what);
}

/* Sets the fields of `params` the rule chooses for what `d` read, and says which and why. */
static void choose(rsmooth_params *params, const rs_noise_details *d, char *preset,
                   size_t preset_size, char *reason, size_t reason_size) {
    double n = d->level > 0 ? d->level : 0;
    char what[128];
    describe(d, what, sizeof what);
    params->absolute = 0;
    if (rs_noise_reads_clean(d)) {
        choose_clean(params, d, what, preset, preset_size, reason, reason_size);
        return;
    }
    if (params->normal_filter == RSMOOTH_NORMALS_MOLLIFY && params->vertex_updates == 0) {
        params->sigma_f = PAPER_SIGMA_F_AT_0 + PAPER_SIGMA_F_PER_NOISE * n;
        if (n > 0)
            params->sigma_g = PAPER_SIGMA_G_PER_NOISE * n;
        snprintf(preset, preset_size, "paper");
        snprintf(reason, reason_size, "%s: sigma_f = %.2g + %.2g x noise, sigma_g = %.2g x noise",
                 what, PAPER_SIGMA_F_AT_0, PAPER_SIGMA_F_PER_NOISE, PAPER_SIGMA_G_PER_NOISE);
        return;
    }
    const best_preset *b = &IMPULSIVE_PRESET;
    if (!d->impulsive)
        for (b = GAUSSIAN_PRESETS; !(n < b->below); b++)
            ;
    rsmooth_params best;
    rs_params_init_best(&best);
    params->sigma_f = best.sigma_f;
    params->sigma_g = best.sigma_g;
    params->normal_filter = best.normal_filter;
    params->normal_sigma_s = best.normal_sigma_s;
    params->normal_sigma_n = best.normal_sigma_n;
    params->normal_iterations = best.normal_iterations;
    params->influence = best.influence;
    params->guided_sigma_s = STAGE_SIGMA_S;
    params->guided_sigma_n = b->sigma_n;
    params->guided_rounds = 1;
    params->guided_radius = b->radius;
    params->vertex_updates = b->updates;
    params->stage_repeats = b->cycles;
    params->passes = b->passes;
    /* the level Taubin's side of the choice per region runs to: all vertices' rms for impulsive
     * noise, the correlated part too where the noise reads correlated (scans) */
    params->discrepancy_level = d->impulsive ? d->overall_level : fmax(n, d->correlated_level);
    params->discrepancy_gain = reads_correlated(d) ? CORRELATED_GAIN : 0;
    snprintf(preset, preset_size, "%s", b->name);
    char stage[96];
    snprintf(stage, sizeof stage, "%d cycles (guided radius %.3g, width %.2g; %d updates)%s",
             b->cycles, b->radius, b->sigma_n, b->updates, b->passes ? ", robust pass" : "");
    if (d->impulsive) /* (the precisions keep the whole within the report's 192 bytes) */
        snprintf(reason, reason_size, "%.110s: %.75s", what, stage);
    else
        snprintf(reason, reason_size, "%.100s, %s %.2g: %.70s", what,
                 isfinite(b->below) ? "below" : "at least",
                 isfinite(b->below) ? b->below : (b - 1)->below, stage);
}

rsmooth_status rs_params_auto(rsmooth_scalar scalar, const void *positions, size_t vertex_count,
                              const uint32_t *indices, size_t triangle_count,
                              rsmooth_params *params, rsmooth_noise_report *report,
                              rsmooth_error *error) {
    static const char where[] = "rsmooth_params_auto";
    rs_error_clear(error);
    if (!params)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "params is NULL: initialise it with rsmooth_params_init or "
                       "rsmooth_params_init_best first");
    if (report && report->struct_size < sizeof *report)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "report.struct_size %zu is not sizeof(rsmooth_noise_report): set it "
                       "first",
                       report->struct_size);
    rsmooth_params checked;
    rsmooth_status st = rs_params_resolve(params, &checked, error, where);
    if (st != RSMOOTH_OK)
        return st;
    rs_noise_details d;
    st = rs_estimate_noise_details(scalar, positions, vertex_count, indices, triangle_count, &d,
                                   error, where);
    if (st != RSMOOTH_OK)
        return st;
    rsmooth_noise_report r;
    noise_report_blank(&r);
    choose(&checked, &d, r.preset, sizeof r.preset, r.reason, sizeof r.reason);
    /* only the fields the caller's struct has are written */
    size_t size = params->struct_size;
    memcpy(params, &checked, size < sizeof checked ? size : sizeof checked);
    params->struct_size = size;
    if (report) {
        r.level = d.level;
        r.kind = rs_noise_reads_clean(&d) ? RSMOOTH_NOISE_NONE
                 : d.impulsive            ? RSMOOTH_NOISE_IMPULSIVE
                                          : RSMOOTH_NOISE_GAUSSIAN;
        r.impulsive_fraction = d.impulsive_fraction;
        r.tangential_level = d.tangential_level;
        r.mean_edge_length = d.mean_edge_clean;
        r.correlated_level = d.correlated_level;
        r.correlation_length = d.correlation_length;
        r.shape_correlation = d.shape_correlation;
        r.outliers = d.outliers;
        r.parts = d.parts;
        *report = r;
    }
    return RSMOOTH_OK;
}
