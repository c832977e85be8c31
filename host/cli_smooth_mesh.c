/* The rsmooth command's filtering of one mesh in memory: the filter on the chosen device, the
 * Laplacian and Taubin baselines, and point clouds (see cli_smooth.h). */
#define _POSIX_C_SOURCE 200809L
#include "cli_device.h"
#include "cli_files.h"
#include "cli_smooth.h"

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

/* A filter call's status as the command's exit status, its failure said on stderr. */
static int filter_status(const options *opt, rsmooth_context *ctx, cli_progress *bar,
                         rsmooth_status st, const rsmooth_error *err) {
    if (st == RSMOOTH_OK)
        return EXIT_OK;
    cli_progress_clear(bar);
    if (st == RSMOOTH_ERROR_OPENCL)
        fprintf(stderr, "rsmooth: %s: device '%s': %s\n", opt->input, cli_device_name(ctx),
                err->message);
    else
        fprintf(stderr, "rsmooth: %s: %s\n", opt->input, err->message);
    return st == RSMOOTH_ERROR_OPENCL             ? EXIT_DEVICE
           : st == RSMOOTH_ERROR_INVALID_ARGUMENT ? EXIT_USAGE
                                                  : EXIT_OTHER;
}

int cli_smooth_mesh(const options *opt, const rsmooth_mesh *mesh, double *out, float *confidence,
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
    rsmooth_params params = opt->params;
    if (bar->enabled) { /* progress slices the kernel launches: only when a bar can show */
        params.progress = cli_progress_callback;
        params.progress_user = bar;
    }
    rsmooth_outputs outputs = {
        .struct_size = sizeof outputs, .confidence = confidence, .report = report};
    /* ctx NULL: the reference path */
    st = rsmooth_smooth(ctx, RSMOOTH_FLOAT64, mesh->positions, mesh->vertex_count, mesh->triangles,
                        mesh->triangle_count, &params, out, &outputs, &err);
    code = filter_status(opt, ctx, bar, st, &err);
    report->ms_setup = ms_setup;
    rsmooth_context_destroy(ctx);
    return code;
}

int cli_check_point_cloud(const options *opt, const rsmooth_mesh *mesh) {
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

/* The point-cloud filter on `ctx` (NULL: the reference path). */
static rsmooth_status filter_points(rsmooth_context *ctx, const rsmooth_mesh *mesh,
                                    const rsmooth_params *params, double *out, double *out_normals,
                                    float *confidence, rsmooth_report *report, rsmooth_error *err) {
    rsmooth_outputs outputs = {
        .struct_size = sizeof outputs, .confidence = confidence, .report = report};
    return rsmooth_smooth_points(ctx, RSMOOTH_FLOAT64, mesh->positions, mesh->vertex_normals,
                                 mesh->vertex_count, params, out, out_normals, &outputs, err);
    return rsmooth_smooth_points(ctx, RSMOOTH_FLOAT64, mesh->positions, mesh->vertex_normals,
                                 mesh->vertex_count, params, out, out_normals,
                                 &(rsmooth_outputs){.struct_size = sizeof(rsmooth_outputs),
                                                    .confidence = confidence,
                                                    .report = report},
                                 err);
}

int cli_smooth_points(const options *opt, const rsmooth_mesh *mesh, double *out,
                      double *out_normals, float *confidence, rsmooth_report *report,
                      cli_progress *bar) {
    rsmooth_context *ctx = NULL;
    double ms_setup = 0;
    int code = cli_open_device(opt, bar, &ctx, &ms_setup);
    if (code >= 0)
        return code;
    if (!opt->quiet) {
        cli_progress_clear(bar);
        fprintf(stderr,
                "rsmooth: note: %s is a point cloud (no faces): filtering its points and "
                "normals %s%s%s\n",
                opt->input, ctx ? "on device '" : "on the reference path (CPU)",
                cli_device_name(ctx), ctx ? "'" : "");
    }
    rsmooth_params params = opt->params;
    if (bar->enabled) {
        params.progress = cli_progress_callback;
        params.progress_user = bar;
    }
    rsmooth_error err;
    rsmooth_status st =
        filter_points(ctx, mesh, &params, out, out_normals, confidence, report, &err);
    if (st == RSMOOTH_ERROR_OUT_OF_MEMORY && ctx) {
        /* the device cannot hold the cloud (points are not cut into tiles): the host can */
        if (!opt->quiet) {
            cli_progress_clear(bar);
            fprintf(stderr, "rsmooth: note: %s: %s; filtering on the reference path instead\n",
                    opt->input, err.message);
        }
        rsmooth_context_destroy(ctx);
        ctx = NULL;
        st = filter_points(NULL, mesh, &params, out, out_normals, confidence, report, &err);
    }
    code = filter_status(opt, ctx, bar, st, &err);
    report->ms_setup = ms_setup;
    rsmooth_context_destroy(ctx);
    return code;
}
