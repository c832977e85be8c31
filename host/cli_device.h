/* The device a command's smoothing runs on: --device, RSMOOTH_DEVICE, or the reference path. */
#ifndef RSMOOTH_CLI_DEVICE_H
#define RSMOOTH_CLI_DEVICE_H

#include "cli_options.h"
#include "cli_progress.h"
#include "rsmooth.h"

/* Opens the device opt->device (else RSMOOTH_DEVICE, else auto) with --memory-budget: -1 on
 * success, *ctx NULL for the reference path (asked for, or auto with no OpenCL: a warning); else
 * prints why and returns the exit status (2 for a device the choice does not name or a bad
 * setting, 3 for a device failure, 1 out of memory). *ms_setup: the time it took. */
int cli_open_device(const options *opt, cli_progress *bar, rsmooth_context **ctx, double *ms_setup);

/* The context's device name ("platform / device"); "" for NULL. */
const char *cli_device_name(const rsmooth_context *ctx);

#endif
