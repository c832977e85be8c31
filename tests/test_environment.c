/* The environment variables the library reads: docs/environment.md holds one row per entry of the
 * library's table (lib/core/environment.c), with its name, meaning and default as the table says
 * them, and nothing else; and a copy taken with rs_environment_read holds what was set then, not
 * what is set later. */
#define _POSIX_C_SOURCE 200809L /* setenv */
#include "core/environment.h"
#include "test_util.h"

#include <stdlib.h>
#include <string.h>

#ifndef RSMOOTH_DOCS_DIR
#define RSMOOTH_DOCS_DIR "docs"
#endif

static char *read_text(const char *path) {
    FILE *f = fopen(path, "rb");
    CHECK(f != NULL);
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *text = malloc((size_t)n + 1);
    CHECK(text && fread(text, 1, (size_t)n, f) == (size_t)n);
    text[n] = '\0';
    fclose(f);
    return text;
}

/* The docs' row for `name` ("| `NAME` | ..."), as its own string, or NULL. */
static char *row_of(const char *text, const char *name) {
    char start[96];
    snprintf(start, sizeof start, "| `%s` |", name);
    const char *p = strstr(text, start);
    if (!p)
        return NULL;
    size_t n = strcspn(p, "\n");
    char *row = malloc(n + 1);
    CHECK(row);
    memcpy(row, p, n);
    row[n] = '\0';
    return row;
}

int main(void) {
    char *text = read_text(RSMOOTH_DOCS_DIR "/environment.md");
    const rs_environment_entry *table = rs_environment_table();
    for (int i = 0; i < RS_ENV_COUNT; i++) {
        char *row = row_of(text, table[i].name);
        printf("%-26s %s\n", table[i].name, row ? "documented" : "MISSING from the docs");
        CHECK(row != NULL);
        CHECK(strstr(row, table[i].meaning) != NULL);
        CHECK(strstr(row, table[i].fallback) != NULL);
        free(row);
    }
    /* no row for a variable the library does not read */
    int rows = 0;
    for (const char *p = strstr(text, "\n| `"); p; p = strstr(p + 1, "\n| `"))
        rows++;
    printf("%d rows, %d variables\n", rows, (int)RS_ENV_COUNT);
    CHECK_EQ_INT(rows, RS_ENV_COUNT);

    /* a copy is a copy */
    setenv("RSMOOTH_STAGE", "host", 1);
    rs_environment env;
    rs_environment_read(&env);
    setenv("RSMOOTH_STAGE", "device", 1);
    CHECK(rs_environment_is(&env, RS_ENV_STAGE, "host"));
    unsetenv("RSMOOTH_STAGE");
    setenv("RSMOOTH_CELLS_PER_REACH", "3", 1);
    rs_environment_read(&env);
    CHECK_EQ_INT(rs_environment_integer(&env, RS_ENV_CELLS_PER_REACH, 1, 8, 0), 3);
    CHECK_STATUS(rs_environment_check(&env, NULL, "test"), RSMOOTH_OK);
    unsetenv("RSMOOTH_CELLS_PER_REACH");
    free(text);
    printf("ok\n");
    return 0;
}
