/* --mask FILE: a plain list of vertex indices, the simplest selection every tool can write (a
 * MeshLab or Blender selection exported as indices, a numpy savetxt, a grep of a PLY). */
#include "cli_mask.h"
#include "cli_files.h"

#include <ctype.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int cli_read_mask(const char *path, size_t vertex_count, const char *mesh_path, uint8_t **mask) {
    *mask = NULL;
    FILE *f = fopen(path, "r");
    if (!f) {
        fprintf(stderr, "rsmooth: --mask %s: %s\n", path, strerror(errno));
        return EXIT_USAGE;
    }
    uint8_t *m = calloc(vertex_count ? vertex_count : 1, 1);
    if (!m) {
        fclose(f);
        fprintf(stderr, "rsmooth: --mask %s: out of memory\n", path);
        return EXIT_OTHER;
    }
    char line[4096];
    long number = 0;
    size_t selected = 0;
    int code = EXIT_OK;
    while (code == EXIT_OK && fgets(line, sizeof line, f)) {
        number++;
        size_t len = strlen(line);
        if (len == sizeof line - 1 && line[len - 1] != '\n' && !feof(f)) {
            fprintf(stderr, "rsmooth: %s:%ld: line longer than %zu bytes\n", path, number,
                    sizeof line - 2);
            code = EXIT_USAGE;
            break;
        }
        char *hash = strchr(line, '#');
        if (hash)
            *hash = '\0';
        for (char *p = line; code == EXIT_OK && *p;) {
            while (*p && (isspace((unsigned char)*p) || *p == ','))
                p++;
            if (!*p)
                break;
            char *end = p;
            while (*end && !isspace((unsigned char)*end) && *end != ',')
                end++;
            char saved = *end;
            *end = '\0';
            char *stop = NULL;
            errno = 0;
            unsigned long long index = isdigit((unsigned char)*p) ? strtoull(p, &stop, 10) : 0;
            if (!isdigit((unsigned char)*p) || *stop || errno) {
                fprintf(stderr, "rsmooth: %s:%ld: '%s' is not a vertex index (0, 1, 2...)\n",
                        path, number, p);
                code = EXIT_USAGE;
            } else if (index >= vertex_count) {
                fprintf(stderr, "rsmooth: %s:%ld: vertex %llu is beyond %s's %zu vertices\n",
                        path, number, index, mesh_path, vertex_count);
                code = EXIT_USAGE;
            } else {
                selected += !m[index];
                m[index] = 1;
            }
            *end = saved;
            p = end;
        }
    }
    if (code == EXIT_OK && ferror(f)) {
        fprintf(stderr, "rsmooth: --mask %s: read error\n", path);
        code = EXIT_USAGE;
    }
    fclose(f);
    if (code != EXIT_OK) {
        free(m);
        return code;
    }
    if (selected == 0)
        fprintf(stderr, "rsmooth: warning: --mask %s selects no vertex: nothing moves\n", path);
    *mask = m;
    return EXIT_OK;
}
