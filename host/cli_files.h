/* File handling of the rsmooth command: reading with progress, refusing to clobber, and writing
 * through a temporary file that is renamed only when complete. */
#ifndef RSMOOTH_CLI_FILES_H
#define RSMOOTH_CLI_FILES_H

#include "cli_progress.h"
#include "rsmooth_io.h"

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

/* Exit statuses of the command. */
enum { EXIT_OK = 0, EXIT_OTHER = 1, EXIT_USAGE = 2, EXIT_DEVICE = 3 };

/* Reads and parses `path`, reporting bytes read to `bar` (may be NULL: no progress). On failure
 * prints "rsmooth: PATH:LINE: message" (or the byte offset) and returns EXIT_USAGE (bad or
 * unreadable file) or EXIT_OTHER. */
int cli_read_mesh(const char *path, cli_progress *bar, rsmooth_mesh **mesh);

/* The output format for `path` (by extension), ascii variants when `ascii`; AUTO if unknown. */
rsmooth_format cli_output_format(const char *path, bool ascii);

/* -1 when `path` may be written: not the input (unless `in_place`), not an existing file unless
 * `force`, not a directory, a known extension. Else prints why and returns EXIT_USAGE. */
int cli_check_output(const char *path, const char *input, bool force, bool in_place);

/* Writes into a stream; returns 0, or -1 with what went wrong in `message`. */
typedef int (*cli_writer)(FILE *stream, void *user, char *message, size_t size);

/* Calls `write` on a temporary file beside `path` and renames it into place only when everything
 * succeeded, so an error or an interruption (SIGINT, SIGTERM, SIGHUP remove it) never leaves a
 * partial file. Prints what fails; returns EXIT_OK or EXIT_OTHER. */
int cli_write_atomically(const char *path, cli_writer write, void *user);

/* Writes `mesh` to a temporary file beside `path` and renames it into place, so an error or an
 * interruption never leaves a partial file. Prints what fails; returns EXIT_OK or EXIT_OTHER. */
int cli_write_mesh(const rsmooth_mesh *mesh, const char *path, rsmooth_format format);

#endif
