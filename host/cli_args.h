/* Argument helpers shared by the rsmooth command and its subcommands. */
#ifndef RSMOOTH_CLI_ARGS_H
#define RSMOOTH_CLI_ARGS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* Prints "rsmooth[ COMMAND]: message" and the --help hint to stderr; returns the usage exit status
 * (2). `command` is NULL for the main command. */
#if defined(__GNUC__)
__attribute__((format(printf, 2, 3)))
#endif
int cli_usage_error(const char *command, const char *format, ...);

/* The edit distance (insertions, deletions, substitutions and swaps of neighbours, each 1) between
 * the first `a_length` characters of `a` and the string `b`: how "did you mean" finds the name a
 * typo was meant to be. */
size_t cli_edit_distance(const char *a, size_t a_length, const char *b);

/* Whether a word at edit distance `distance` from a name is close enough to suggest the name: at
 * most 2 edits, and fewer than half the word's `length`. */
bool cli_close_enough(size_t distance, size_t length);

/* Parses the whole of `text` as a number; false for junk, NaN or out of range. Accepts "inf". */
bool cli_parse_number(const char *text, double *out);

/* Prints `text` on stdout as a JSON string literal (quotes, backslashes and control characters
 * escaped). */
void cli_print_json_string(const char *text);

/* Parses a byte count: "268435456", "256M", "1.5G", "512KiB" (K, M, G, T are powers of 1024). */
bool cli_parse_bytes(const char *text, uint64_t *out);

/* Checks the environment variables that tune rsmooth (RSMOOTH_HOST_THREADS, an integer in [1, 64];
 * RSMOOTH_CELLS_PER_REACH, in [1, 8]): the library reads them where they apply and falls back to
 * its default on junk, so the command refuses junk first. Returns -1 when all are fine or unset,
 * else prints which is wrong and returns the usage exit status. */
int cli_check_environment(void);

#endif
