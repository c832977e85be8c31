/* Command-line options the Unix way, for the rsmooth command and its subcommands: a small
 * table-driven parser in the manner of getopt_long.
 *
 * Accepted: "--name value" and "--name=value" for every option that takes a value; "-o FILE" and
 * "-oFILE"; short flags grouped ("-fq"); options before, between and after the operands; "--"
 * ends the options (everything after it is an operand, even "-x"); a lone "-" is an operand
 * (standard input or output). A value may begin with '-' ("--mu -0.45"). A long name after one
 * dash ("-force", "-sigma-f") is refused with the two-dash spelling suggested, not read as a group
 * of letters ("-f -o rce").
 *
 * Why not getopt_long: it accepts abbreviations ("--forc"), so an option added later can make a
 * user's script ambiguous; it prints its own messages (not naming the command the way the rest of
 * rsmooth does, and not exiting 2 by itself); it keeps global state whose reset differs between
 * C libraries (optind = 0 on glibc, optreset on the BSDs); and whether it permutes depends on
 * POSIXLY_CORRECT. What rsmooth needs is this file's hundred lines, the same everywhere. */
#ifndef RSMOOTH_CLI_GETOPT_H
#define RSMOOTH_CLI_GETOPT_H

#include <stdbool.h>

/* One option: `name` the long name without "--" (NULL ends a table), `letter` its short form
 * or 0, `takes_value` whether it needs a value, `id` what cli_getopt returns for it (> 0). */
typedef struct cli_option {
    const char *name;
    char letter;
    bool takes_value;
    int id;
} cli_option;

typedef struct cli_getopt_state {
    int argc;
    char **argv;
    const char *command; /* NULL for the main command, else "render" etc. (in messages) */
    const cli_option *table;
    int next;            /* the next argv index to look at */
    const char *cluster; /* the rest of a group of short flags ("-fq"), or NULL */
    const char *word;    /* the whole group, after its '-' ("fq"): a long name with one dash? */
    bool operands_only;  /* after "--" */
    char spelled[64];    /* the option as to name it in messages: "--sigma-f", "-o" */
} cli_getopt_state;

enum {
    CLI_GETOPT_END = 0,      /* no more arguments */
    CLI_GETOPT_OPERAND = -1, /* *value is an operand */
    CLI_GETOPT_ERROR = -2    /* a usage error, already printed (cli_usage_error) */
};

/* Starts parsing argv[1..argc) against `table`. */
void cli_getopt_init(cli_getopt_state *s, int argc, char **argv, const char *command,
                     const cli_option *table);

/* The next option's id (with *value its value, or NULL for a flag), an operand, the end, or an
 * error: an unknown option, a missing value or a value given to a flag. s->spelled names the
 * option returned (for messages about its value). */
int cli_getopt(cli_getopt_state *s, const char **value);

#endif
