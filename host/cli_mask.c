/* --mask FILE: a plain list of vertex indices, the simplest selection every tool can write (a
 * MeshLab or Blender selection exported as indices, a numpy savetxt, a grep of a PLY). The file is
 * read whole, then parsed: a regular file or a pipe, up to a size no honest list of this mesh's
 * vertices reaches, so a device (/dev/zero) or an endless pipe is refused instead of read forever.
 */
#define _POSIX_C_SOURCE 200809L
#include "cli_mask.h"
#include "cli_files.h"

#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* Room for every vertex listed with a comment of its own, and 1 MiB besides. */
static size_t mask_limit(size_t vertex_count) {
    size_t per_vertex = 64, base = (size_t)1 << 20;
    return vertex_count > (SIZE_MAX - base) / per_vertex ? SIZE_MAX
                                                         : base + per_vertex * vertex_count;
}

/* The whole file, NUL-terminated, in *text (its length in *size); prints why and returns a
 * cli_files exit status otherwise. */
static int read_mask_file(const char *path, size_t limit, char **text, size_t *size) {
    *text = NULL;
    /* O_NONBLOCK: a FIFO without a writer must not block the open; cleared for the reads */
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    struct stat st;
    if (fd < 0 || fstat(fd, &st) != 0) {
        fprintf(stderr, "rsmooth: --mask %s: %s\n", path, strerror(errno));
        if (fd >= 0)
            close(fd);
        return EXIT_USAGE;
    }
    if (!S_ISREG(st.st_mode) && !S_ISFIFO(st.st_mode)) {
        fprintf(stderr, "rsmooth: --mask %s: %s: a mask is a text file (or a pipe)\n", path,
                S_ISDIR(st.st_mode) ? "is a folder" : "is a device or special file");
        close(fd);
        return EXIT_USAGE;
    }
    int flags = fcntl(fd, F_GETFL);
    if (flags != -1)
        fcntl(fd, F_SETFL, flags & ~O_NONBLOCK);
    size_t capacity = S_ISREG(st.st_mode) && (uint64_t)st.st_size < limit ? (size_t)st.st_size : 0;
    capacity = capacity < 4096 ? 4096 : capacity + 1;
    char *data = malloc(capacity);
    size_t used = 0;
    int code = data ? EXIT_OK : EXIT_OTHER;
    while (code == EXIT_OK) {
        if (used + 1 == capacity) {
            size_t grown = capacity * 2 > limit + 2 ? limit + 2 : capacity * 2;
            char *bigger = grown > capacity ? realloc(data, grown) : NULL;
            if (!bigger) {
                code = EXIT_OTHER;
                break;
            }
            data = bigger;
            capacity = grown;
        }
        ssize_t got = read(fd, data + used, capacity - 1 - used);
        if (got < 0 && errno == EINTR)
            continue;
        if (got < 0) {
            fprintf(stderr, "rsmooth: --mask %s: %s\n", path, strerror(errno));
            code = EXIT_USAGE;
        } else if (got == 0) {
            break;
        } else if ((used += (size_t)got) > limit) {
            fprintf(stderr,
                    "rsmooth: --mask %s: longer than %zu bytes, more than a list of this mesh's "
                    "vertices takes: not a mask\n",
                    path, limit);
            code = EXIT_USAGE;
        }
    }
    close(fd);
    if (code == EXIT_OTHER)
        fprintf(stderr, "rsmooth: --mask %s: out of memory\n", path);
    if (code != EXIT_OK) {
        free(data);
        return code;
    }
    data[used] = '\0';
    *text = data;
    *size = used;
    return EXIT_OK;
}

/* Marks the indices of one line (`line`, NUL-terminated, comments already cut). */
static int parse_line(char *line, const char *path, long number, size_t vertex_count,
                      const char *mesh_path, uint8_t *m, size_t *selected) {
    for (char *p = line; *p;) {
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
            fprintf(stderr, "rsmooth: %s:%ld: '%.40s' is not a vertex index (0, 1, 2...)\n", path,
                    number, p);
            return EXIT_USAGE;
        }
        if (index >= vertex_count) {
            fprintf(stderr, "rsmooth: %s:%ld: vertex %llu is beyond %s's %zu vertices\n", path,
                    number, index, mesh_path, vertex_count);
            return EXIT_USAGE;
        }
        *selected += !m[index];
        m[index] = 1;
        *end = saved;
        p = end;
    }
    return EXIT_OK;
}

int cli_read_mask(const char *path, size_t vertex_count, const char *mesh_path, uint8_t **mask) {
    *mask = NULL;
    char *text = NULL;
    size_t size = 0;
    int code = read_mask_file(path, mask_limit(vertex_count), &text, &size);
    if (code != EXIT_OK)
        return code;
    uint8_t *m = calloc(vertex_count ? vertex_count : 1, 1);
    if (!m) {
        free(text);
        fprintf(stderr, "rsmooth: --mask %s: out of memory\n", path);
        return EXIT_OTHER;
    }
    size_t selected = 0;
    long number = 1;
    for (char *line = text; code == EXIT_OK && line < text + size; number++) {
        char *end = memchr(line, '\n', (size_t)(text + size - line));
        end = end ? end : text + size;
        *end = '\0';
        size_t length = strlen(line);
        if (line + length < end) { /* a NUL inside the line: text it is not */
            fprintf(stderr,
                    "rsmooth: %s:%ld: a NUL byte at column %zu: a mask is text, vertex indices "
                    "separated by blanks, commas or lines\n",
                    path, number, length + 1);
            code = EXIT_USAGE;
            break;
        }
        char *hash = strchr(line, '#');
        if (hash)
            *hash = '\0';
        code = parse_line(line, path, number, vertex_count, mesh_path, m, &selected);
        line = end + 1;
    }
    free(text);
    if (code != EXIT_OK) {
        free(m);
        return code;
    }
    if (selected == 0)
        fprintf(stderr, "rsmooth: warning: --mask %s selects no vertex: nothing moves\n", path);
    *mask = m;
    return EXIT_OK;
}
