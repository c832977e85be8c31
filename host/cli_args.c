/* Argument helpers shared by the rsmooth command and its subcommands (see cli_args.h). */
#include "cli_args.h"
#include "cli_files.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int cli_usage_error(const char *command, const char *format, ...) {
    const char *space = command ? " " : "";
    command = command ? command : "";
    va_list args;
    va_start(args, format);
    fprintf(stderr, "rsmooth%s%s: ", space, command);
    vfprintf(stderr, format, args);
    fprintf(stderr, "\nTry 'rsmooth%s%s --help'.\n", space, command);
    va_end(args);
    return EXIT_USAGE;
}

size_t cli_edit_distance(const char *a, size_t a_length, const char *b) {
    enum { LONGEST = 64 }; /* option and command names are shorter; longer words match nothing */
    size_t b_length = strlen(b);
    if (a_length >= LONGEST || b_length >= LONGEST)
        return (size_t)-1;
    /* rows i-2, i-1 and i of the table of distances between prefixes (optimal string alignment) */
    size_t rows[3][LONGEST + 1];
    for (size_t j = 0; j <= b_length; j++)
        rows[0][j] = j;
    size_t *before = NULL, *last = rows[0];
    for (size_t i = 1; i <= a_length; i++) {
        size_t *row = rows[i % 3];
        row[0] = i;
        for (size_t j = 1; j <= b_length; j++) {
            size_t cost = a[i - 1] != b[j - 1];
            size_t best = last[j - 1] + cost;
            if (last[j] + 1 < best)
                best = last[j] + 1;
            if (row[j - 1] + 1 < best)
                best = row[j - 1] + 1;
            if (before && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] &&
                before[j - 2] + 1 < best)
                best = before[j - 2] + 1;
            row[j] = best;
        }
        before = last;
        last = row;
    }
    return last[b_length];
}

bool cli_close_enough(size_t distance, size_t length) {
    return distance <= 2 && 2 * distance < length;
}

bool cli_parse_number(const char *text, double *out) {
    char *end = NULL;
    errno = 0;
    double v = strtod(text, &end);
    if (end == text || *end != '\0' || errno == ERANGE || isnan(v))
        return false;
    *out = v;
    return true;
}

bool cli_parse_bytes(const char *text, uint64_t *out) {
    char *end = NULL;
    double v = strtod(text, &end);
    if (end == text || !(v >= 0))
        return false;
    static const char units[] = "KMGT";
    const char *unit = *end ? strchr(units, toupper((unsigned char)*end)) : NULL;
    if (unit && *unit) {
        for (const char *u = units; u <= unit; u++)
            v *= 1024;
        end++;
        if (*end == 'i') /* "MiB" */
            end++;
        if (*end == 'B' || *end == 'b')
            end++;
    }
    if (*end != '\0' || !(v < 1.8e19))
        return false;
    *out = (uint64_t)v;
    return true;
}

void cli_print_json_string(const char *text) {
    putchar('"');
    for (const unsigned char *c = (const unsigned char *)text; *c; c++) {
        if (*c == '"' || *c == '\\')
            printf("\\%c", *c);
        else if (*c < 0x20)
            printf("\\u%04x", *c);
        else
            putchar(*c);
    }
    putchar('"');
}

int cli_check_environment(void) {
    static const struct {
        const char *name;
        long lo, hi;
    } knobs[] = {{"RSMOOTH_HOST_THREADS", 1, 64}, {"RSMOOTH_CELLS_PER_REACH", 1, 8}};
    for (size_t i = 0; i < sizeof knobs / sizeof *knobs; i++) {
        const char *text = getenv(knobs[i].name);
        if (!text || !*text)
            continue;
        char *end = NULL;
        errno = 0;
        long v = strtol(text, &end, 10);
        if (*end != '\0' || errno == ERANGE || v < knobs[i].lo || v > knobs[i].hi) {
            fprintf(stderr,
                    "rsmooth: %s='%s' is not an integer in [%ld, %ld] (unset it for the "
                    "default)\n",
                    knobs[i].name, text, knobs[i].lo, knobs[i].hi);
            return EXIT_USAGE;
        }
    }
    return -1;
}
