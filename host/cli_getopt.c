/* Command-line options the Unix way (see cli_getopt.h for what is accepted, and why this is not
 * getopt_long). */
#include "cli_getopt.h"
#include "cli_args.h"

#include <stdio.h>
#include <string.h>

void cli_getopt_init(cli_getopt_state *s, int argc, char **argv, const char *command,
                     const cli_option *table) {
    memset(s, 0, sizeof *s);
    s->argc = argc;
    s->argv = argv;
    s->command = command;
    s->table = table;
    s->next = 1;
}

/* The value of an option that takes one: `attached` (after '=' or the letter), else the next
 * argument, whatever it looks like. */
static int take_value(cli_getopt_state *s, const cli_option *o, const char *attached,
                      const char **value) {
    if (attached) {
        *value = attached;
    } else if (s->next < s->argc) {
        *value = s->argv[s->next++];
    } else {
        cli_usage_error(s->command, "%s needs a value", s->spelled);
        return CLI_GETOPT_ERROR;
    }
    return o->id;
}

/* The table's long name nearest the `length` characters at `name` (a typo of it: "sigma_f" for
 * "sigma-f"), or NULL when none is close. */
static const char *nearest_name(const cli_option *table, const char *name, size_t length) {
    const char *near = NULL;
    size_t best = (size_t)-1;
    for (const cli_option *o = table; o->name; o++) {
        size_t d = cli_edit_distance(name, length, o->name);
        if (d < best && cli_close_enough(d, length))
            best = d, near = o->name;
    }
    return near;
}

static int short_option(cli_getopt_state *s, const char **value) {
    char letter = *s->cluster++;
    const cli_option *o = s->table;
    while (o->name && o->letter != letter)
        o++;
    snprintf(s->spelled, sizeof s->spelled, "-%c", letter);
    if (!o->name) {
        /* "-sigma-f": a long name with one dash, its first letter no option */
        const char *eq = strchr(s->word, '=');
        size_t length = eq ? (size_t)(eq - s->word) : strlen(s->word);
        const char *near = s->cluster == s->word + 1 && length > 1
                               ? nearest_name(s->table, s->word, length)
                               : NULL;
        s->cluster = NULL;
        if (near)
            cli_usage_error(s->command, "unknown option '-%.*s' (did you mean --%s?)",
                            (int)(length < 60 ? length : 60), s->word, near);
        else
            cli_usage_error(s->command, "unknown option '-%c'", letter);
        return CLI_GETOPT_ERROR;
    }
    if (!o->takes_value) {
        if (!*s->cluster)
            s->cluster = NULL;
        return o->id;
    }
    const char *attached = *s->cluster ? s->cluster : NULL; /* -oFILE */
    s->cluster = NULL;
    return take_value(s, o, attached, value);
}

int cli_getopt(cli_getopt_state *s, const char **value) {
    *value = NULL;
    if (s->cluster)
        return short_option(s, value);
    if (s->next >= s->argc)
        return CLI_GETOPT_END;
    const char *a = s->argv[s->next++];
    if (s->operands_only || a[0] != '-' || a[1] == '\0') { /* a lone "-" is an operand */
        *value = a;
        return CLI_GETOPT_OPERAND;
    }
    if (a[1] != '-') { /* -o FILE, -oFILE, -fq */
        /* a long name after one dash ("-force", "-output x") is that typo, not -f -o rce */
        const char *eq = strchr(a + 1, '=');
        size_t length = eq ? (size_t)(eq - (a + 1)) : strlen(a + 1);
        for (const cli_option *o = s->table; o->name && length > 1; o++)
            if (strlen(o->name) == length && !strncmp(o->name, a + 1, length)) {
                snprintf(s->spelled, sizeof s->spelled, "--%s", o->name);
                cli_usage_error(s->command, "unknown option '-%s' (did you mean --%s?)", o->name,
                                o->name);
                return CLI_GETOPT_ERROR;
            }
        s->word = a + 1;
        s->cluster = a + 1;
        return short_option(s, value);
    }
    if (a[2] == '\0') { /* "--": operands only from here */
        s->operands_only = true;
        return cli_getopt(s, value);
    }
    const char *name = a + 2, *eq = strchr(name, '=');
    size_t length = eq ? (size_t)(eq - name) : strlen(name);
    const cli_option *o = s->table;
    while (o->name && !(strlen(o->name) == length && !strncmp(o->name, name, length)))
        o++;
    snprintf(s->spelled, sizeof s->spelled, "--%.*s", (int)(length < 60 ? length : 60), name);
    if (!o->name) {
        const char *near = nearest_name(s->table, name, length);
        cli_usage_error(s->command, "unknown option '%.*s'%s%s%s", (int)(length + 2), a,
                        near ? " (did you mean --" : "", near ? near : "", near ? "?)" : "");
        return CLI_GETOPT_ERROR;
    }
    if (!o->takes_value) {
        if (eq) {
            cli_usage_error(s->command, "%s takes no value (got '%s')", s->spelled, a);
            return CLI_GETOPT_ERROR;
        }
        return o->id;
    }
    return take_value(s, o, eq ? eq + 1 : NULL, value);
}
