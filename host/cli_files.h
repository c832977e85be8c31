/* Mesh files of the rsmooth command: reading with progress, checking an output before the work,
 * and writing atomically (cli_output.h). */
#ifndef RSMOOTH_CLI_FILES_H
#define RSMOOTH_CLI_FILES_H

#include "cli_progress.h"
#include "rsmooth_io.h"

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

/* Exit statuses of the command. */
enum { EXIT_OK = 0, EXIT_OTHER = 1, EXIT_USAGE = 2, EXIT_DEVICE = 3 };

/* Reads and parses `path` ("-": standard input, "<stdin>" in messages), reporting bytes read to
 * `bar` (may be NULL: no progress). On failure prints "rsmooth: PATH:LINE: message" (or the byte
 * offset) and returns EXIT_USAGE (bad or unreadable file) or EXIT_OTHER. */
int cli_read_mesh(const char *path, cli_progress *bar, rsmooth_mesh **mesh);

/* The output format for `path` (by the extension of the file written: a symbolic link's target),
 * ascii variants when `ascii`; AUTO if unknown. */
rsmooth_format cli_output_format(const char *path, bool ascii);

/* -1 when `path` may be written: not the input (unless `in_place`), a known extension (unless
 * `format_given`: --format), and as cli_check_output_path allows with `force || in_place` (not an
 * existing file without them, never a directory or a link to nothing). Else prints why and
 * returns EXIT_USAGE. */
int cli_check_output(const char *path, const char *input, bool force, bool in_place,
                     bool format_given);

/* -1 when `format`'s writer would accept `mesh` (rsmooth_mesh_check_writable), else prints
 * "rsmooth: PATH: cannot hold INPUT: why" and returns EXIT_USAGE: called on the input before any
 * work, so a result its output's number type cannot hold (a binary STL of a mesh at 1e-150 or
 * 1e39) costs no filtering. The result has the input's scale; the writer checks it again. */
int cli_check_writable(const rsmooth_mesh *mesh, const char *path, rsmooth_format format,
                       const char *input);

/* Writes `mesh` to standard output when `path` is "-", else through cli_write_atomically
 * (`replace`: --force or --in-place; `quiet`: no warning about an owner that could not be kept).
 * Returns EXIT_OK, EXIT_USAGE (the file exists and `replace` is off, or appeared meanwhile) or
 * EXIT_OTHER. */
int cli_write_mesh(const rsmooth_mesh *mesh, const char *path, rsmooth_format format, bool replace,
                   bool quiet);

#endif
