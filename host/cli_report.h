/* What the rsmooth command prints besides its status lines (cli_report.c). */
#ifndef RSMOOTH_CLI_REPORT_H
#define RSMOOTH_CLI_REPORT_H

#include "cli_options.h"
#include "rsmooth.h"
#include "rsmooth_io.h"

#include <stdbool.h>
#include <stdint.h>

/* --list-devices: the OpenCL devices and how --device names them, on stdout. Returns 0. */
int cli_list_devices(void);

/* Red (low confidence) through yellow to blue (high), for c in [0, 1]. */
void cli_confidence_colour(float c, uint8_t rgb[3]);

/* What the call left alone (parts, outliers, triangles kept from turning over, a skipped
 * stage), one line on stderr when there is any. */
void cli_print_harm(const char *input, const rsmooth_report *r);

/* --json: one object of counts, sigmas, device and stage times on stdout. */
void cli_print_json(const rsmooth_report *r, const options *opt, double ms_read, double ms_write);

/* --stats: what the mesh is and what the filter did to it (`out`: the result), on stderr. */
void cli_print_stats(const rsmooth_mesh *mesh, const double *out, const float *confidence,
                     const rsmooth_report *r);

/* Says on stderr what writing `mesh` as `format` to `path` drops (unless `quiet`). */
void cli_warn_losses(const rsmooth_mesh *mesh, const char *path, rsmooth_format format, bool quiet);

#endif
