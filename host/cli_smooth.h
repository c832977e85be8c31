/* The rsmooth command's smoothing of files in memory, in named steps: one file's run
 * (cli_smooth_file.c), the filter or a baseline on its mesh (cli_smooth_mesh.c), --auto's
 * parameters (cli_auto.c) and the confidence mesh (cli_confidence.c). Each prints what fails and
 * returns the exit status (EXIT_OK when it went well). */
#ifndef RSMOOTH_CLI_SMOOTH_H
#define RSMOOTH_CLI_SMOOTH_H

#include "cli_options.h"
#include "cli_progress.h"
#include "rsmooth.h"
#include "rsmooth_io.h"

#include <stdbool.h>

/* Smooths `path` (opt->input names it in messages) into opt->output: one file's whole run, in
 * memory or (--max-memory) streamed. */
int cli_smooth_file(const options *job, const char *path);

/* Runs the filter on the chosen device, or --method laplacian or taubin on the CPU; fills
 * `report` (and `confidence` when not NULL). */
int cli_smooth_mesh(const options *opt, const rsmooth_mesh *mesh, double *out, float *confidence,
                    rsmooth_report *report, cli_progress *bar);

/* A mesh without triangles is a point cloud: it needs its normals, and a method without edges. */
int cli_check_point_cloud(const options *opt, const rsmooth_mesh *mesh);

/* The point-cloud filter on the chosen device (the reference path without one, or where the
 * device cannot hold the cloud); fills `report`. */
int cli_smooth_points(const options *opt, const rsmooth_mesh *mesh, double *out,
                      double *out_normals, float *confidence, rsmooth_report *report,
                      cli_progress *bar);

/* --auto: the sigmas (and with --best its rounds and passes) from the input's estimated noise,
 * into opt->params and opt->noise; options given on the command line still override them. */
int cli_choose_params(options *opt, const rsmooth_mesh *mesh, bool points);

/* Writes --confidence: the result's surface (mesh, its positions the result's), coloured by
 * `confidence`, without the input's extras. */
int cli_write_confidence(rsmooth_mesh *mesh, const options *opt, float *confidence);

#endif
