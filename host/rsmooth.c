/* rsmooth: the command. Reads a mesh, smooths it on an OpenCL device (or the reference path), and
 * writes the result atomically: a temporary file beside the output, renamed when complete. This
 * file is the flow: the options are read in cli_options.c (table) and cli_options_check.c
 * (checks, output names), printed reports are in cli_report.c, files in cli_files.c and
 * cli_output.c. One input is one smooth_file; several go through smooth_files. */
#define _POSIX_C_SOURCE 200809L
#include "rsmooth.h"
#include "cli_args.h"
#include "cli_options.h"
#include "cli_commands.h"
#include "cli_files.h"
#include "cli_mask.h"
#include "cli_output.h"
#include "cli_progress.h"
#include "cli_report.h"
#include "cli_device.h"
#include "cli_stream.h"
#include "rsmooth_io.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* Laplacian or Taubin smoothing (always on the CPU); fills the report's counts and time. */
static int smooth_umbrella(const options *opt, const rsmooth_mesh *mesh, double *out,
                           rsmooth_report *report) {
    rsmooth_error err;
    double t = cli_now_ms();
    rsmooth_status st = rsmooth_smooth_taubin(RSMOOTH_FLOAT64, mesh->positions, mesh->vertex_count,
                                              mesh->triangles, mesh->triangle_count, opt->lambda,
                                              opt->mu, opt->iterations, out, &err);
    if (st == RSMOOTH_OK)
        st = rsmooth_mean_edge_length(RSMOOTH_FLOAT64, mesh->positions, mesh->vertex_count,
                                      mesh->triangles, mesh->triangle_count,
                                      &report->mean_edge_length, &err);
    if (st != RSMOOTH_OK) {
        fprintf(stderr, "rsmooth: %s: %s\n", opt->input, err.message);
        return st == RSMOOTH_ERROR_INVALID_ARGUMENT ? EXIT_USAGE : EXIT_OTHER;
    }
    report->ms_total = cli_now_ms() - t;
    report->vertex_count = mesh->vertex_count;
    report->triangle_count = mesh->triangle_count;
    snprintf(report->device, sizeof report->device, "%s, %u iterations (double, 1 thread)",
             cli_method_names[opt->method], opt->iterations);
    return EXIT_OK;
}

/* Runs the filter on the chosen device; prints what fails. */
static int smooth(const options *opt, const rsmooth_mesh *mesh, double *out, float *confidence,
                  rsmooth_report *report, cli_progress *bar) {
    if (cli_method_uses_edges(opt->method))
        return smooth_umbrella(opt, mesh, out, report);
    rsmooth_context *ctx = NULL;
    rsmooth_error err;
    rsmooth_status st;
    double ms_setup = 0;
    int code = cli_open_device(opt, bar, &ctx, &ms_setup);
    if (code >= 0)
        return code;
    bool reference = ctx == NULL;
    rsmooth_params params = opt->params;
    if (bar->enabled) { /* progress slices the kernel launches: only when a bar can show */
        params.progress = cli_progress_callback;
        params.progress_user = bar;
    }
    if (reference)
        st = rsmooth_smooth_reference(RSMOOTH_FLOAT64, mesh->positions, mesh->vertex_count,
                                      mesh->triangles, mesh->triangle_count, &params, out, NULL,
                                      confidence, report, &err);
    else
        st = rsmooth_smooth(ctx, RSMOOTH_FLOAT64, mesh->positions, mesh->vertex_count,
                            mesh->triangles, mesh->triangle_count, &params, out, NULL, confidence,
                            report, &err);
    code = EXIT_OK;
    if (st != RSMOOTH_OK) {
        cli_progress_clear(bar);
        if (st == RSMOOTH_ERROR_OPENCL)
            fprintf(stderr, "rsmooth: %s: device '%s': %s\n", opt->input,
                    rsmooth_context_device_name(ctx), err.message);
        else
            fprintf(stderr, "rsmooth: %s: %s\n", opt->input, err.message);
        code = st == RSMOOTH_ERROR_OPENCL             ? EXIT_DEVICE
               : st == RSMOOTH_ERROR_INVALID_ARGUMENT ? EXIT_USAGE
                                                      : EXIT_OTHER;
    }
    report->ms_setup = ms_setup;
    rsmooth_context_destroy(ctx);
    return code;
}

/* A mesh without triangles is a point cloud: it needs its normals, and a method without edges. */
static int check_point_cloud(const options *opt, const rsmooth_mesh *mesh) {
    if (!mesh->vertex_normals) {
        /* what is missing would come after everything the file holds: name its end */
        struct stat st;
        char end[64] = ""; /* (standard input has no size to name) */
        if (stat(opt->input, &st) == 0)
            snprintf(end, sizeof end, " byte %lld (the end):", (long long)st.st_size);
        fprintf(stderr,
                "rsmooth: %s:%s %zu vertices but no faces and no vertex normals: a mesh needs "
                "faces, a point cloud normals (nx, ny, nz)\n",
                opt->input, end, mesh->vertex_count);
        return EXIT_USAGE;
    }
    if (cli_method_uses_edges(opt->method)) {
        fprintf(stderr, "rsmooth: %s is a point cloud (no faces): --method %s needs edges\n",
                opt->input, cli_method_names[opt->method]);
        return EXIT_USAGE;
    }
    return EXIT_OK;
}

/* The point-cloud filter, on the reference path: the OpenCL path does not take points yet. */
static int smooth_points(const options *opt, const rsmooth_mesh *mesh, double *out,
                         double *out_normals, float *confidence, rsmooth_report *report,
                         cli_progress *bar) {
    const char *device = opt->device ? opt->device : getenv("RSMOOTH_DEVICE");
    if (!opt->quiet) {
        cli_progress_clear(bar);
        if (device && strcmp(device, "reference") != 0 && strcmp(device, "auto") != 0)
            fprintf(stderr, "rsmooth: note: %s is a point cloud, which the OpenCL path does not "
                            "take yet: filtering on the reference path, not on device '%s'\n",
                    opt->input, device);
        else if (!device || strcmp(device, "reference") != 0)
            fprintf(stderr, "rsmooth: note: %s is a point cloud (no faces): filtering its points "
                            "and normals on the reference path (CPU)\n", opt->input);
    }
    rsmooth_params params = opt->params;
    if (bar->enabled) {
        params.progress = cli_progress_callback;
        params.progress_user = bar;
    }
    rsmooth_error err;
    rsmooth_status st = rsmooth_smooth_points_reference(
        RSMOOTH_FLOAT64, mesh->positions, mesh->vertex_normals, mesh->vertex_count, &params, out,
        out_normals, confidence, report, &err);
    if (st != RSMOOTH_OK) {
        cli_progress_clear(bar);
        fprintf(stderr, "rsmooth: %s: %s\n", opt->input, err.message);
        return st == RSMOOTH_ERROR_INVALID_ARGUMENT ? EXIT_USAGE : EXIT_OTHER;
    }
    return EXIT_OK;
}

/* The confidence mesh: the result's surface, coloured, written without the input's extras. */
static int write_confidence(rsmooth_mesh *mesh, const options *opt, float *confidence) {
    if (cli_same_file(opt->confidence, opt->output)) { /* e.g. out.ply and ./out.ply */
        fprintf(stderr, "rsmooth: %s: is the output file; the confidence mesh needs its own file\n",
                opt->confidence);
        return EXIT_USAGE;
    }
    size_t nv = mesh->vertex_count;
    uint8_t *colours = malloc(nv * 3);
    if (!colours) {
        fprintf(stderr, "rsmooth: %s: out of memory\n", opt->confidence);
        return EXIT_OTHER;
    }
    /* Normalised: the ramp spans the mesh's own range of confidence among vertices some facet
     * reached (those no facet reached, confidence 0, are red), so the lows show on any mesh;
     * the raw value stays in the quality property. */
    float lo = INFINITY, hi = 0;
    for (size_t v = 0; v < nv; v++)
        if (confidence[v] > 0) {
            lo = fminf(lo, confidence[v]);
            hi = fmaxf(hi, confidence[v]);
        }
    for (size_t v = 0; v < nv; v++) {
        float c = confidence[v];
        float x = !(c > 0) ? 0 : hi - lo > 1e-6f ? (c - lo) / (hi - lo) : 1;
        cli_confidence_colour(x, colours + 3 * v);
    }
    if (!opt->quiet)
        fprintf(stderr, "rsmooth: %s: confidence from %.3g (red) to %.3g (blue)\n",
                opt->confidence, lo < hi ? lo : hi, hi);
    float *quality = mesh->vertex_quality;
    uint8_t *input_colours = mesh->vertex_colors;
    struct rsmooth_mesh_extras *extras = mesh->extras;
    mesh->vertex_quality = confidence;
    mesh->vertex_colors = colours;
    mesh->extras = NULL;
    int code = cli_write_mesh(mesh, opt->confidence, cli_output_format(opt->confidence, opt->ascii),
                              opt->force, opt->quiet);
    mesh->vertex_quality = quality;
    mesh->vertex_colors = input_colours;
    mesh->extras = extras;
    free(colours);
    return code;
}

/* Whether the output files' formats can hold the input (the result has its scale): refused before
 * any filtering. The confidence mesh is written without the input's extras, so checked so. */
static int check_outputs_hold(const options *opt, rsmooth_mesh *mesh) {
    int code = cli_check_writable(mesh, strcmp(opt->output, "-") ? opt->output : "<stdout>",
                                  cli_result_format(opt, opt->output, mesh->source_format),
                                  opt->input);
    if (code >= 0 || !opt->confidence)
        return code >= 0 ? code : EXIT_OK;
    struct rsmooth_mesh_extras *extras = mesh->extras;
    mesh->extras = NULL;
    code = cli_check_writable(mesh, opt->confidence,
                              cli_output_format(opt->confidence, opt->ascii), opt->input);
    mesh->extras = extras;
    return code >= 0 ? code : EXIT_OK;
}

/* --sigma-c: the input's vertex colours as floats in [0, 1], for rsmooth_params.colors. */
static int input_colors(const options *opt, const rsmooth_mesh *mesh, float **colors) {
    *colors = NULL;
    if (!mesh->vertex_colors) {
        fprintf(stderr, "rsmooth: %s has no vertex colours: --sigma-c needs them (PLY red, "
                        "green, blue; OBJ v x y z r g b; COFF)\n", opt->input);
        return EXIT_USAGE;
    }
    size_t n = 3 * mesh->vertex_count;
    *colors = malloc(n * sizeof **colors);
    if (!*colors) {
        fprintf(stderr, "rsmooth: %s: out of memory\n", opt->input);
        return EXIT_OTHER;
    }
    for (size_t i = 0; i < n; i++)
        (*colors)[i] = (float)mesh->vertex_colors[i] / 255.0f;
    return EXIT_OK;
}

/* --auto: the sigmas (and with --best its rounds and passes) from the input's estimated noise;
 * options given after --auto still override them. */
static int choose_params(options *opt, const rsmooth_mesh *mesh, bool points) {
    if (points) {
        fprintf(stderr, "rsmooth: %s is a point cloud: --auto needs faces to estimate the noise; "
                        "give --sigma-f and --sigma-g\n", opt->input);
        return EXIT_USAGE;
    }
    rsmooth_params chosen = opt->params;
    rsmooth_error err;
    rsmooth_noise_report report;
    rsmooth_noise_report_init(&report);
    if (rsmooth_params_auto_report(RSMOOTH_FLOAT64, mesh->positions, mesh->vertex_count,
                                   mesh->triangles, mesh->triangle_count, &chosen, &report,
                                   &err) != RSMOOTH_OK) {
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
    if (opt->given & (GIVEN_SIGMA_F | GIVEN_SIGMA_G))
        chosen.absolute = given->absolute;
    opt->params = chosen;
    opt->noise = report.level;
    if (!opt->quiet)
        fprintf(stderr, "rsmooth: %s: --auto: %s -> %s (sigma_f %.3g, sigma_g %.3g)\n",
                opt->input, report.reason, report.preset, chosen.sigma_f, chosen.sigma_g);
    return EXIT_OK;
}

/* Smooths `path` (opt->input names it in messages) into opt->output: one file's whole run. */
static int smooth_file(const options *job, const char *path) {
    options opt = *job; /* --auto changes the parameters for this file only */
    int code;
    bool to_stdout = !strcmp(opt.output, "-");
    if (!to_stdout && ((code = cli_make_folders(opt.output, false, opt.quiet)) >= 0 ||
                       (code = cli_check_output(opt.output, path, opt.force, opt.in_place,
                                                opt.format != RSMOOTH_FORMAT_AUTO)) >= 0))
        return code;
    if (opt.confidence) {
        if (!strcmp(opt.confidence, opt.output) || cli_same_file(opt.confidence, opt.output)) {
            fprintf(stderr, "rsmooth: %s: the confidence mesh needs its own file\n",
                    opt.confidence);
            return EXIT_USAGE;
        }
        if ((code = cli_make_folders(opt.confidence, false, opt.quiet)) >= 0 ||
            (code = cli_check_output(opt.confidence, path, opt.force, false, false)) >= 0)
            return code;
    }

    if (opt.max_memory)
        return cli_stream_file(&opt, path);
    cli_progress bar;
    cli_progress_init(&bar, opt.quiet, opt.progress);
    cli_progress_stage(&bar, "reading", 0, 0.1);
    rsmooth_mesh *mesh = NULL;
    double t0 = cli_now_ms();
    if ((code = cli_read_mesh(path, &bar, &mesh)) != EXIT_OK)
        return code;
    double ms_read = cli_now_ms() - t0;
    bool points = mesh->triangle_count == 0; /* a point cloud: its points and normals filtered */
    if (points && (code = check_point_cloud(&opt, mesh)) != EXIT_OK) {
        rsmooth_mesh_destroy(mesh);
        return code;
    }
    if ((code = check_outputs_hold(&opt, mesh)) != EXIT_OK) {
        rsmooth_mesh_destroy(mesh);
        return code;
    }
    float *colors = NULL; /* --sigma-c */
    if (opt.colors && (code = input_colors(&opt, mesh, &colors)) != EXIT_OK) {
        rsmooth_mesh_destroy(mesh);
        return code;
    }
    opt.params.colors = colors;
    uint8_t *mask = NULL; /* --mask */
    if (opt.mask && (code = cli_read_mask(opt.mask, mesh->vertex_count, path, &mask)) != EXIT_OK) {
        rsmooth_mesh_destroy(mesh);
        free(colors);
        return code;
    }
    opt.params.move_mask = mask;
    if (opt.auto_params && (code = choose_params(&opt, mesh, points)) != EXIT_OK) {
        rsmooth_mesh_destroy(mesh);
        free(colors);
        free(mask);
        return code;
    }

    size_t nv = mesh->vertex_count;
    double *out = malloc(nv * 3 * sizeof *out);
    double *out_normals = points ? malloc(nv * 3 * sizeof *out_normals) : NULL;
    bool umbrella = cli_method_uses_edges(opt.method);
    bool want_confidence = opt.confidence || (opt.stats && !umbrella);
    float *confidence = want_confidence ? malloc(nv * sizeof *confidence) : NULL;
    rsmooth_report report;
    rsmooth_report_init(&report);
    code = EXIT_OTHER;
    if (!out || (points && !out_normals) || (want_confidence && !confidence)) {
        fprintf(stderr, "rsmooth: %s: out of memory\n", opt.input);
        goto cleanup;
    }
    cli_progress_stage(&bar, "smoothing", 0.1, 0.95);
    code = points ? smooth_points(&opt, mesh, out, out_normals, confidence, &report, &bar)
                  : smooth(&opt, mesh, out, confidence, &report, &bar);
    if (code != EXIT_OK)
        goto cleanup;

    cli_progress_stage(&bar, "writing", 0.95, 1);
    double t1 = cli_now_ms();
    double *input_positions = mesh->positions, *input_normals = mesh->vertex_normals;
    mesh->positions = out;
    if (points)
        mesh->vertex_normals = out_normals; /* written in place of recomputed ones */
    rsmooth_format format = cli_result_format(&opt, opt.output, mesh->source_format);
    cli_progress_clear(&bar);
    const char *wrote = to_stdout ? "<stdout>" : opt.output;
    cli_warn_losses(mesh, wrote, format, opt.quiet);
    code = cli_write_mesh(mesh, opt.output, format, opt.force || opt.in_place, opt.quiet);
    if (code == EXIT_OK && opt.confidence)
        code = write_confidence(mesh, &opt, confidence);
    mesh->positions = input_positions;
    mesh->vertex_normals = input_normals;
    double ms_write = cli_now_ms() - t1;
    cli_progress_clear(&bar);
    if (code != EXIT_OK)
        goto cleanup;

    if (!opt.quiet && report.discrepancy_iterations > 0)
        fprintf(stderr, "rsmooth: %s: --auto: the result is curved at the scale of its "
                        "triangles (an organic mesh coarse for its curvature, where low-pass "
                        "smoothing restores the surface better): Taubin smoothing instead, %d "
                        "iterations, until the vertices moved as far as the noise\n",
                opt.input, report.discrepancy_iterations);
    if (opt.json)
        cli_print_json(&report, &opt, ms_read, ms_write);
    if (opt.stats)
        cli_print_stats(mesh, out, confidence, &report);
    if (!opt.quiet && umbrella)
        fprintf(stderr, "rsmooth: %s: %zu vertices, %zu triangles; %s: %.1f ms; wrote %s\n",
                opt.input, report.vertex_count, report.triangle_count, report.device,
                report.ms_total, wrote);
    else if (!opt.quiet && report.discrepancy_iterations > 0)
        fprintf(stderr,
                "rsmooth: %s: %zu vertices, %zu triangles, mean edge %.6g; Taubin smoothing, %d "
                "iterations (--auto's choice, in place of the filter's result on %s): %.1f ms; "
                "wrote %s%s%s\n",
                opt.input, report.vertex_count, report.triangle_count, report.mean_edge_length,
                report.discrepancy_iterations, report.device, report.ms_total, wrote,
                opt.confidence ? " and " : "", opt.confidence ? opt.confidence : "");
    else if (!opt.quiet && points)
        fprintf(stderr,
                "rsmooth: %s: %zu points with normals, spacing %.6g; sigma_f %.6g, sigma_g "
                "%.6g (cloud units) on %s: filter %.1f ms; wrote %s%s%s\n",
                opt.input, report.vertex_count, report.mean_edge_length, report.sigma_f,
                report.sigma_g, report.device, report.ms_total, wrote,
                opt.confidence ? " and " : "", opt.confidence ? opt.confidence : "");
    else if (!opt.quiet)
        fprintf(stderr,
                "rsmooth: %s: %zu vertices, %zu triangles, mean edge %.6g; sigma_f %.6g, "
                "sigma_g %.6g (mesh units) on %s: filter %.1f ms; wrote %s%s%s\n",
                opt.input, report.vertex_count, report.triangle_count, report.mean_edge_length,
                report.sigma_f, report.sigma_g, report.device, report.ms_total, wrote,
                opt.confidence ? " and " : "", opt.confidence ? opt.confidence : "");

cleanup:
    cli_progress_clear(&bar);
    rsmooth_mesh_destroy(mesh);
    free(out);
    free(out_normals);
    free(confidence);
    free(colors);
    free(mask);
    return code;
}

/* Several inputs: each smoothed in turn, going on past one that fails; a summary at the end. */
static int smooth_files(options *opt) {
    size_t failed = 0;
    char *failures = NULL; /* "a.ply, b.obj" */
    for (size_t i = 0; i < opt->input_count; i++) {
        char output[4096];
        options job = *opt;
        job.input = opt->inputs[i];
        job.output = output;
        cli_output_for(opt, job.input, output, sizeof output); /* checked to fit */
        if (smooth_file(&job, job.input) == EXIT_OK)
            continue;
        failed++;
        size_t length = strlen(job.input), used = failures ? strlen(failures) : 0;
        char *grown = realloc(failures, used + length + 3);
        if (grown) {
            failures = grown;
            snprintf(failures + used, length + 3, "%s%s", used ? ", " : "", job.input);
        }
    }
    size_t n = opt->input_count;
    if (failed)
        fprintf(stderr, "rsmooth: %zu files: %zu smoothed, %zu failed (%s)\n", n, n - failed,
                failed, failures ? failures : "out of memory for their names");
    else if (!opt->quiet)
        fprintf(stderr, "rsmooth: %zu files: %zu smoothed\n", n, n);
    free(failures);
    return failed ? EXIT_USAGE : EXIT_OK;
}

/* A first word that is no file but nearly a subcommand ("compre"): the subcommand was meant, and
 * saying so beats "no output file". -1, or the usage exit status (printed). */
static int check_subcommand_typo(int argc, char **argv) {
    static const char *const commands[] = {"compare", "noise", "render"};
    struct stat st;
    if (argc < 2 || argv[1][0] == '-' || stat(argv[1], &st) == 0)
        return -1;
    size_t length = strlen(argv[1]);
    for (size_t k = 0; k < sizeof commands / sizeof *commands; k++)
        if (cli_close_enough(cli_edit_distance(argv[1], length, commands[k]), length))
            return cli_usage_error(NULL, "%s: no such file or command: did you mean \"%s\"?",
                                   argv[1], commands[k]);
    return -1;
}

int main(int argc, char **argv) {
    if (argc >= 2 && !strcmp(argv[1], "compare"))
        return cli_compare_main(argc - 1, argv + 1);
    if (argc >= 2 && !strcmp(argv[1], "noise"))
        return cli_noise_main(argc - 1, argv + 1);
    if (argc >= 2 && !strcmp(argv[1], "render"))
        return cli_render_main(argc - 1, argv + 1);
    int code;
    if ((code = check_subcommand_typo(argc, argv)) >= 0)
        return code;
    options opt;
    code = cli_options_parse(argc, argv, &opt);
    if (code >= 0)
        return code;
    if ((code = cli_check_environment()) >= 0) {
        cli_options_free(&opt);
        return code;
    }
    if (opt.list_devices) {
        cli_options_free(&opt);
        return cli_list_devices();
    }
    if (opt.input_count == 1) {
        char output[4096];
        const char *path = opt.inputs[0];
        opt.input = strcmp(path, "-") ? path : "<stdin>";
        opt.output = output;
        cli_output_for(&opt, path, output, sizeof output); /* checked to fit */
        code = smooth_file(&opt, path);
    } else {
        code = smooth_files(&opt);
    }
    cli_options_free(&opt);
    return code;
}
