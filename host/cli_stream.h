/* The rsmooth command under --max-memory: the file streamed through rsmooth_stream_smooth. */
#ifndef RSMOOTH_CLI_STREAM_H
#define RSMOOTH_CLI_STREAM_H

#include "cli_options.h"
#include "rsmooth_io.h"

#include <stdint.h>

/* Refuses (printed; the usage exit status) the options streaming cannot honour, and --tmpdir
 * without --max-memory; -1 when all is well. */
int cli_stream_check(const options *opt);

/* Smooths `path` into opt->output under opt->max_memory (the output already checked); prints the
 * status line (and --json); returns the exit status. */
int cli_stream_file(const options *opt, const char *path);

/* --mask FILE for the streamed `path` (its vertex count from its header): *mask a new array
 * of one byte a vertex (NULL without --mask); -1 when all is well, else the exit status (the
 * reason printed). */
int cli_stream_mask(const options *opt, const char *path, uint8_t **mask);

/* The exit status for a streaming failure. */
int cli_stream_exit_code(rsmooth_status st);

/* Prints a streaming failure as "PROGRAM: message", in the command's words: the library's
 * "set options->replace" is the command's "use --force". */
void cli_stream_print_error(const char *program, const char *message);

/* --json for a streaming run: one object on stdout. */
void cli_stream_print_json(const rsmooth_stream_report *r, const options *opt, int ranks);

#endif
