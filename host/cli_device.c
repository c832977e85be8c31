/* The device a command's smoothing runs on (see cli_device.h). */
#define _POSIX_C_SOURCE 200809L
#include "cli_device.h"
#include "cli_args.h"
#include "cli_files.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int cli_open_device(const options *opt, cli_progress *bar, rsmooth_context **ctx,
                    double *ms_setup) {
    const char *device = opt->device ? opt->device : getenv("RSMOOTH_DEVICE");
    bool reference = device && strcmp(device, "reference") == 0;
    rsmooth_error err;
    rsmooth_status st;
    *ctx = NULL;
    *ms_setup = 0;
    if (!reference) {
        /* the options win over the environment, as --device over RSMOOTH_DEVICE */
        rsmooth_context_options o = {
            .struct_size = sizeof o, .device = device, .memory_budget = opt->memory_budget};
        double t = cli_now_ms();
        st = rsmooth_context_create(&o, ctx, &err);
        *ms_setup = cli_now_ms() - t;
        rsmooth_context_info info = {.struct_size = sizeof info};
        if (st == RSMOOTH_OK && rsmooth_context_get_info(*ctx, &info) == RSMOOTH_OK &&
            *info.program_cache_note && !opt->quiet) { /* the library prints nothing */
            cli_progress_clear(bar);
            fprintf(stderr, "rsmooth: warning: %s\n", info.program_cache_note);
        }
        bool automatic = !device || strcmp(device, "auto") == 0;
        if (st == RSMOOTH_ERROR_NO_DEVICE && automatic) {
            if (!opt->quiet)
                fprintf(stderr, "rsmooth: warning: %s; using the reference path (slower)\n",
                        err.message);
            *ctx = NULL;
        } else if (st == RSMOOTH_ERROR_INVALID_ARGUMENT) { /* a setting: RSMOOTH_MEMORY_BUDGET */
            cli_progress_clear(bar);
            fprintf(stderr, "rsmooth: %s\n", err.message);
            return EXIT_USAGE;
        } else if (st != RSMOOTH_OK) {
            cli_progress_clear(bar);
            fprintf(stderr, "rsmooth: device '%s'%s: %s: %s\n", device ? device : "auto",
                    opt->device || !device ? "" : " (from RSMOOTH_DEVICE)", rsmooth_status_str(st),
                    err.message);
            if (err.build_log[0])
                fprintf(stderr, "%s\n", err.build_log);
            if (st == RSMOOTH_ERROR_NO_DEVICE) { /* the choice names nothing here: a usage error */
                fprintf(stderr, "rsmooth: --list-devices shows what --device can name\n");
                return EXIT_USAGE;
            }
            return st == RSMOOTH_ERROR_OUT_OF_MEMORY ? EXIT_OTHER : EXIT_DEVICE;
        }
    }
    return -1;
}

const char *cli_device_name(const rsmooth_context *ctx) {
    rsmooth_context_info info = {.struct_size = sizeof info};
    return ctx && rsmooth_context_get_info(ctx, &info) == RSMOOTH_OK ? info.device_name : "";
}
