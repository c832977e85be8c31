/* Output files of the rsmooth command: which paths may be written, and writing them so that no
 * reader ever sees a partial file, nothing is replaced without permission (not even by another
 * run racing for the same name), and a file that is replaced keeps its mode, owner and group. */
#ifndef RSMOOTH_CLI_OUTPUT_H
#define RSMOOTH_CLI_OUTPUT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

/* -1 when `path` may be written, else prints why ("rsmooth: PATH: ...") and returns the usage
 * exit status (2). Without `replace` (--force, --in-place) only a name that does not exist may
 * be written. With it also an existing regular file, or a symbolic link to one: the link is
 * written through (it stays a link; the file it names is replaced). Never a directory or another
 * kind of file, nor a symbolic link whose target does not exist (not even with `replace`). */
int cli_check_output_path(const char *path, bool replace);

/* Writes into a stream; returns 0, or -1 with what went wrong in `message`. */
typedef int (*cli_writer)(FILE *stream, void *user, char *message, size_t size);

/* Calls `write` on a temporary file in the directory of `path` (of its target, for a symbolic
 * link) and puts it in place only when everything succeeded: an unnamed file (O_TMPFILE) linked
 * in when complete where the system allows, else ".rsmooth-XXXXXX" renamed (SIGINT, SIGTERM and
 * SIGHUP remove it). Without `replace` the file appears only if no file of that name exists at
 * that moment; a run that loses that race prints "already exists" and returns 2. With `replace`
 * an existing file is replaced atomically, keeping its permission bits, owner and group (a
 * warning says so, unless `quiet`, when the owner or group cannot be kept). Checks `path` as
 * cli_check_output_path does. Prints what fails; returns 0, 2 (usage) or 1 (the write failed).
 *
 * RSMOOTH_NAMED_TEMPORARY=1 in the environment skips O_TMPFILE (tests of the fallback). */
int cli_write_atomically(const char *path, bool replace, bool quiet, cli_writer write, void *user);

/* Creates the folders of `path` that are missing (mode 0777 less the umask), as mkdir -p does:
 * those above its last '/', or with `whole` all of it (-o DIR/). Says which it created on stderr
 * unless `quiet`. -1 when the folders are there, else prints why ("rsmooth: PATH: 'a/b' is not a
 * folder", or the system's reason) and returns the usage exit status (2). */
int cli_make_folders(const char *path, bool whole, bool quiet);

/* True when both paths name the same existing file (links followed). */
bool cli_same_file(const char *a, const char *b);

#endif
