/* The rsmooth command's run of one file in memory, in named steps: the outputs checked, the input
 * read (with --sigma-c, --mask and --auto), the filter run, the results written, and what was done
 * reported (see cli_smooth.h). Under --max-memory the file goes to cli_stream.c instead. */
#define _POSIX_C_SOURCE 200809L
#include "cli_files.h"
#include "cli_mask.h"
#include "cli_output.h"
#include "cli_report.h"
#include "cli_smooth.h"
#include "cli_stream.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Whether the output files' formats can hold the input (the result has its scale): refused before
 * any filtering. The confidence mesh is written without the input's extras, so checked so. */
static int check_outputs_hold(const options *opt, rsmooth_mesh *mesh) {
    int code =
        cli_check_writable(mesh, strcmp(opt->output, "-") ? opt->output : "<stdout>",
                           cli_result_format(opt, opt->output, mesh->source_format), opt->input);
    if (code >= 0 || !opt->confidence)
        return code >= 0 ? code : EXIT_OK;
    struct rsmooth_mesh_extras *extras = mesh->extras;
    mesh->extras = NULL;
    code = cli_check_writable(mesh, opt->confidence, cli_output_format(opt->confidence, opt->ascii),
                              opt->input);
    mesh->extras = extras;
    return code >= 0 ? code : EXIT_OK;
}

/* --sigma-c: the input's vertex colours as floats in [0, 1], for rsmooth_params.colors. */
static int input_colors(const options *opt, const rsmooth_mesh *mesh, float **colors) {
    *colors = NULL;
    if (!mesh->vertex_colors) {
        fprintf(stderr,
                "rsmooth: %s has no vertex colours: --sigma-c needs them (PLY red, "
                "green, blue; OBJ v x y z r g b; COFF)\n",
                opt->input);
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

/* One file's work in memory and what it holds, released by job_free. */
typedef struct file_job {
    options opt;       /* a copy: --auto changes the parameters for this file only */
    const char *path;  /* what is read ("-": standard input) */
    const char *wrote; /* the output as the messages name it */
    cli_progress bar;
    rsmooth_mesh *mesh;
    bool points;   /* a point cloud: its points and normals filtered */
    float *colors; /* --sigma-c */
    uint8_t *mask; /* --mask */
    double *out, *out_normals;
    float *confidence;
    rsmooth_report report;
    double ms_read, ms_write;
} file_job;

static void job_free(file_job *job) {
    cli_progress_clear(&job->bar);
    rsmooth_mesh_destroy(job->mesh);
    free(job->out);
    free(job->out_normals);
    free(job->confidence);
    free(job->colors);
    free(job->mask);
}

/* The output and the confidence mesh may be written (their folders made): -1, or the status. */
static int check_outputs(const options *opt, const char *path) {
    int code;
    if (strcmp(opt->output, "-") != 0 &&
        ((code = cli_make_folders(opt->output, false, opt->quiet)) >= 0 ||
         (code = cli_check_output(opt->output, path, opt->force, opt->in_place,
                                  opt->format != RSMOOTH_FORMAT_AUTO)) >= 0))
        return code;
    if (opt->confidence) {
        if (!strcmp(opt->confidence, opt->output) || cli_same_file(opt->confidence, opt->output)) {
            fprintf(stderr, "rsmooth: %s: the confidence mesh needs its own file\n",
                    opt->confidence);
            return EXIT_USAGE;
        }
        if ((code = cli_make_folders(opt->confidence, false, opt->quiet)) >= 0 ||
            (code = cli_check_output(opt->confidence, path, opt->force, false, false)) >= 0)
            return code;
    }
    return -1;
}

/* Reads the input and what goes with it (--sigma-c's colours, --mask, --auto's parameters),
 * checking that the outputs can hold it. */
static int read_input(file_job *job) {
    options *opt = &job->opt;
    cli_progress_stage(&job->bar, "reading", 0, 0.1);
    double t0 = cli_now_ms();
    int code = cli_read_mesh(job->path, &job->bar, &job->mesh);
    if (code != EXIT_OK)
        return code;
    job->ms_read = cli_now_ms() - t0;
    rsmooth_mesh *mesh = job->mesh;
    size_t cols, rows, samples;
    if (!opt->quiet && rsmooth_mesh_range_grid(mesh, &cols, &rows, &samples))
        fprintf(stderr,
                "rsmooth: note: %s is a range grid (%zu x %zu cells, %zu samples): read as "
                "%zu triangles; the output is a triangle mesh, not a range grid\n",
                opt->input, cols, rows, samples, mesh->triangle_count);
    job->points = mesh->triangle_count == 0;
    if (job->points && (code = cli_check_point_cloud(opt, mesh)) != EXIT_OK)
        return code;
    if ((code = check_outputs_hold(opt, mesh)) != EXIT_OK)
        return code;
    if (opt->colors && (code = input_colors(opt, mesh, &job->colors)) != EXIT_OK)
        return code;
    opt->params.colors = job->colors;
    if (opt->mask &&
        (code = cli_read_mask(opt->mask, mesh->vertex_count, job->path, &job->mask)) != EXIT_OK)
        return code;
    opt->params.move_mask = job->mask;
    if (opt->auto_params && (code = cli_choose_params(opt, mesh, job->points)) != EXIT_OK)
        return code;
    return EXIT_OK;
}

/* The result's arrays, then the filter (or a baseline) on them. */
static int run_filter(file_job *job) {
    const options *opt = &job->opt;
    size_t nv = job->mesh->vertex_count;
    job->out = malloc(nv * 3 * sizeof *job->out);
    job->out_normals = job->points ? malloc(nv * 3 * sizeof *job->out_normals) : NULL;
    bool want_confidence = opt->confidence || (opt->stats && !cli_method_uses_edges(opt->method));
    job->confidence = want_confidence ? malloc(nv * sizeof *job->confidence) : NULL;
    rsmooth_report_init(&job->report);
    if (!job->out || (job->points && !job->out_normals) || (want_confidence && !job->confidence)) {
        fprintf(stderr, "rsmooth: %s: out of memory\n", opt->input);
        return EXIT_OTHER;
    }
    cli_progress_stage(&job->bar, "smoothing", 0.1, 0.95);
    return job->points ? cli_smooth_points(opt, job->mesh, job->out, job->out_normals,
                                           job->confidence, &job->report, &job->bar)
                       : cli_smooth_mesh(opt, job->mesh, job->out, job->confidence, &job->report,
                                         &job->bar);
}

/* The result in the input's mesh (its extras kept), written; then the confidence mesh. */
static int write_results(file_job *job) {
    const options *opt = &job->opt;
    rsmooth_mesh *mesh = job->mesh;
    cli_progress_stage(&job->bar, "writing", 0.95, 1);
    double t1 = cli_now_ms();
    double *input_positions = mesh->positions, *input_normals = mesh->vertex_normals;
    mesh->positions = job->out;
    if (job->points)
        mesh->vertex_normals = job->out_normals; /* written in place of recomputed ones */
    rsmooth_format format = cli_result_format(opt, opt->output, mesh->source_format);
    cli_progress_clear(&job->bar);
    cli_warn_losses(mesh, job->wrote, format, opt->quiet);
    int code = cli_write_mesh(mesh, opt->output, format, opt->force || opt->in_place, opt->quiet);
    if (code == EXIT_OK && opt->confidence)
        code = cli_write_confidence(mesh, opt, job->confidence);
    mesh->positions = input_positions;
    mesh->vertex_normals = input_normals;
    job->ms_write = cli_now_ms() - t1;
    if (code == EXIT_OK)
        cli_progress_done(&job->bar);
    cli_progress_clear(&job->bar);
    return code;
}

/* What was done: --auto's switch to Taubin, --json, --stats and the status line. */
static void report_file(const file_job *job) {
    const options *opt = &job->opt;
    const rsmooth_report *r = &job->report;
    const char *and = opt->confidence ? " and " : "";
    const char *confidence = opt->confidence ? opt->confidence : "";
    if (!opt->quiet && r->discrepancy_iterations > 0)
        fprintf(stderr,
                "rsmooth: %s: --auto: a choice per region: the filter's result where it "
                "came out flat faces and creases, Taubin smoothing (%d iterations, until "
                "the vertices moved as far as the noise) where it came out curved at the "
                "scale of its triangles (organic parts coarse for their curvature), "
                "blended between: the filter's weight %.0f%% on average\n",
                opt->input, r->discrepancy_iterations, 100 * r->region_filter_share);
    if (!opt->quiet)
        cli_print_harm(opt->input, r);
    if (opt->json)
        cli_print_json(r, opt, job->ms_read, job->ms_write);
    if (opt->stats)
        cli_print_stats(job->mesh, job->out, job->confidence, r);
    if (opt->quiet)
        return;
    if (!cli_method_uses_edges(opt->method) && opt->params.passes == 0 &&
        opt->params.vertex_updates == 0) /* --auto found nothing to remove */
        fprintf(stderr,
                "rsmooth: %s: %zu vertices, %zu triangles; nothing to remove: every "
                "vertex as it was; wrote %s%s%s\n",
                opt->input, r->vertex_count, r->triangle_count, job->wrote, and, confidence);
    else if (cli_method_uses_edges(opt->method))
        fprintf(stderr, "rsmooth: %s: %zu vertices, %zu triangles; %s: %.1f ms; wrote %s\n",
                opt->input, r->vertex_count, r->triangle_count, r->device, r->ms_total, job->wrote);
    else if (r->discrepancy_iterations > 0)
        fprintf(stderr,
                "rsmooth: %s: %zu vertices, %zu triangles, mean edge %.6g; the filter (%.0f%%) "
                "blended per region with Taubin smoothing, %d iterations (--auto's choice) on "
                "%s: %.1f ms; wrote %s%s%s\n",
                opt->input, r->vertex_count, r->triangle_count, r->mean_edge_length,
                100 * r->region_filter_share, r->discrepancy_iterations, r->device, r->ms_total,
                job->wrote, and, confidence);
    else if (job->points)
        fprintf(stderr,
                "rsmooth: %s: %zu points with normals, spacing %.6g; sigma_f %.6g, sigma_g "
                "%.6g (cloud units) on %s: filter %.1f ms; wrote %s%s%s\n",
                opt->input, r->vertex_count, r->mean_edge_length, r->sigma_f, r->sigma_g, r->device,
                r->ms_total, job->wrote, and, confidence);
    else
        fprintf(stderr,
                "rsmooth: %s: %zu vertices, %zu triangles, mean edge %.6g; sigma_f %.6g, "
                "sigma_g %.6g (mesh units) on %s: filter %.1f ms; wrote %s%s%s\n",
                opt->input, r->vertex_count, r->triangle_count, r->mean_edge_length, r->sigma_f,
                r->sigma_g, r->device, r->ms_total, job->wrote, and, confidence);
}

int cli_smooth_file(const options *opt, const char *path) {
    int code = check_outputs(opt, path);
    if (code >= 0)
        return code;
    if (opt->max_memory)
        return cli_stream_file(opt, path);
    file_job job;
    memset(&job, 0, sizeof job);
    job.opt = *opt;
    job.path = path;
    job.wrote = strcmp(opt->output, "-") ? opt->output : "<stdout>";
    cli_progress_init(&job.bar, opt->quiet, opt->progress);
    if ((code = read_input(&job)) == EXIT_OK && (code = run_filter(&job)) == EXIT_OK &&
        (code = write_results(&job)) == EXIT_OK)
        report_file(&job);
    job_free(&job);
    return code;
}
