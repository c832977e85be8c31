/* The rsmooth command's --auto: the parameters from the input's estimated noise (see
 * cli_smooth.h). */
#define _POSIX_C_SOURCE 200809L
#include "cli_files.h"
#include "cli_smooth.h"

#include <stdio.h>

int cli_choose_params(options *opt, const rsmooth_mesh *mesh, bool points) {
    if (points) {
        fprintf(stderr,
                "rsmooth: %s is a point cloud: --auto needs faces to estimate the noise; "
                "give --sigma-f and --sigma-g\n",
                opt->input);
        return EXIT_USAGE;
    }
    rsmooth_params chosen = opt->params;
    rsmooth_error err;
    rsmooth_noise_report report;
    report.struct_size = sizeof report;
    if (rsmooth_params_auto(RSMOOTH_FLOAT64, mesh->positions, mesh->vertex_count, mesh->triangles,
                            mesh->triangle_count, &chosen, &report, &err) != RSMOOTH_OK) {
        fprintf(stderr, "rsmooth: %s: --auto: %s\n", opt->input, err.message);
        return EXIT_USAGE;
    }
    /* what the command line set explicitly wins over the rule */
    const rsmooth_params *given = &opt->params;
    if (opt->given & GIVEN_SIGMA_F)
        chosen.sigma_f = given->sigma_f;
    if (opt->given & GIVEN_SIGMA_G)
        chosen.sigma_g = given->sigma_g;
    if (opt->given & GIVEN_NORMAL_SIGMA_S)
        chosen.normal_sigma_s = given->normal_sigma_s;
    if (opt->given & GIVEN_NORMAL_SIGMA_N)
        chosen.normal_sigma_n = given->normal_sigma_n;
    if (opt->given & GIVEN_NORMAL_ITERATIONS)
        chosen.normal_iterations = given->normal_iterations;
    if (opt->given & GIVEN_PASSES)
        chosen.passes = given->passes;
    if (opt->given & GIVEN_INFLUENCE)
        chosen.influence = given->influence;
    if (opt->given & GIVEN_VERTEX_UPDATES)
        chosen.vertex_updates = given->vertex_updates;
    if (opt->given & GIVEN_GUIDED_SIGMA_S)
        chosen.guided_sigma_s = given->guided_sigma_s;
    if (opt->given & GIVEN_GUIDED_SIGMA_N)
        chosen.guided_sigma_n = given->guided_sigma_n;
    if (opt->given & GIVEN_GUIDED_ROUNDS)
        chosen.guided_rounds = given->guided_rounds;
    if (opt->given & GIVEN_STAGE_REPEATS)
        chosen.stage_repeats = given->stage_repeats;
    if (opt->given & GIVEN_GUIDED_RADIUS)
        chosen.guided_radius = given->guided_radius;
    if (opt->given & (GIVEN_SIGMA_F | GIVEN_SIGMA_G))
        chosen.absolute = given->absolute;
    /* what the stage follows is the command line's, whatever strength the rule chose */
    chosen.stage_normals = given->stage_normals;
    chosen.model = given->model;
    chosen.model_size = given->model_size;
    opt->params = chosen;
    opt->noise = report.level;
    opt->noise_correlated = report.correlated_level;
    opt->noise_correlation_length = report.correlation_length;
    opt->noise_shape_correlation = report.shape_correlation;
    snprintf(opt->noise_preset, sizeof opt->noise_preset, "%s", report.preset);
    /* the correlated part, when there is one: what the rules (which read `level`) do not see */
    char correlated[128] = "";
    if (report.correlation_length > 0)
        snprintf(correlated, sizeof correlated,
                 "; with its spatially correlated part %.3g mean edge lengths rms (correlation "
                 "length %.2g edges)",
                 report.correlated_level, report.correlation_length);
    if (!opt->quiet && chosen.passes == 0 && chosen.vertex_updates == 0) /* nothing to run */
        fprintf(stderr, "rsmooth: %s: --auto: %s%s -> %s\n", opt->input, report.reason, correlated,
                report.preset);
    else if (!opt->quiet)
        fprintf(stderr, "rsmooth: %s: --auto: %s%s -> %s (sigma_f %.3g, sigma_g %.3g)\n",
                opt->input, report.reason, correlated, report.preset, chosen.sigma_f,
                chosen.sigma_g);
    return EXIT_OK;
}
