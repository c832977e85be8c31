/* The rsmooth command's file handling (see cli_files.h). */
#define _XOPEN_SOURCE 700 /* realpath */
#include "cli_files.h"
#include "cli_output.h"

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define READ_CHUNK (8u << 20)

int cli_read_mesh(const char *path, cli_progress *bar, rsmooth_mesh **mesh) {
    *mesh = NULL;
    bool standard_input = !strcmp(path, "-");
    FILE *f = standard_input ? stdin : fopen(path, "rb");
    if (standard_input)
        path = "<stdin>"; /* in messages */
    struct stat st;
    if (!f || fstat(fileno(f), &st) != 0) {
        fprintf(stderr, "rsmooth: %s: cannot open: %s\n", path, strerror(errno));
        if (f && !standard_input)
            fclose(f);
        return EXIT_USAGE;
    }
    if (S_ISDIR(st.st_mode)) {
        fprintf(stderr, "rsmooth: %s: is a directory, not a mesh file\n", path);
        if (!standard_input)
            fclose(f);
        return EXIT_USAGE;
    }
    size_t expected = S_ISREG(st.st_mode) ? (size_t)st.st_size : 0;
    size_t capacity = expected + 1 > READ_CHUNK ? expected + 1 : READ_CHUNK;
    size_t size = 0;
    char *data = malloc(capacity);
    int code = EXIT_OK;
    while (data) {
        if (size == capacity) {
            char *bigger = realloc(data, capacity * 2);
            if (!bigger) {
                free(data);
                data = NULL;
                break;
            }
            data = bigger;
            capacity *= 2;
        }
        size_t want = capacity - size < READ_CHUNK ? capacity - size : READ_CHUNK;
        size_t got = fread(data + size, 1, want, f);
        size += got;
        if (expected && bar)
            cli_progress_update(bar, (double)size / (double)expected);
        if (got < want) {
            if (ferror(f)) {
                fprintf(stderr, "rsmooth: %s: read error: %s\n", path, strerror(errno));
                code = EXIT_USAGE;
            }
            break;
        }
    }
    if (!standard_input)
        fclose(f);
    if (!data) {
        fprintf(stderr, "rsmooth: %s: out of memory reading it\n", path);
        return EXIT_OTHER;
    }
    if (code != EXIT_OK) {
        free(data);
        return code;
    }
    rsmooth_error err;
    rsmooth_status status = rsmooth_mesh_read_memory(data, size, RSMOOTH_FORMAT_AUTO, mesh, &err);
    free(data);
    if (status == RSMOOTH_OK)
        return EXIT_OK;
    if (bar)
        cli_progress_clear(bar);
    if (err.line >= 0)
        fprintf(stderr, "rsmooth: %s:%lld: %s\n", path, (long long)err.line, err.message);
    else if (err.byte_offset >= 0)
        fprintf(stderr, "rsmooth: %s: byte %lld: %s\n", path, (long long)err.byte_offset,
                err.message);
    else
        fprintf(stderr, "rsmooth: %s: %s\n", path, err.message);
    return status == RSMOOTH_ERROR_OUT_OF_MEMORY ? EXIT_OTHER : EXIT_USAGE;
}

rsmooth_format cli_output_format(const char *path, bool ascii) {
    /* by the name of the file written: a symbolic link's target (see cli_output.h) */
    char target[PATH_MAX];
    struct stat st;
    if (lstat(path, &st) == 0 && S_ISLNK(st.st_mode) && realpath(path, target))
        path = target;
    rsmooth_format format = rsmooth_format_from_path(path);
    if (ascii && format == RSMOOTH_FORMAT_PLY_BINARY)
        return RSMOOTH_FORMAT_PLY_ASCII;
    if (ascii && format == RSMOOTH_FORMAT_STL_BINARY)
        return RSMOOTH_FORMAT_STL_ASCII;
    return format;
}

int cli_check_output(const char *path, const char *input, bool force, bool in_place,
                     bool format_given) {
    if (!in_place && cli_same_file(path, input)) {
        fprintf(stderr, "rsmooth: %s: refusing to overwrite the input file (use --in-place)\n",
                path);
        return EXIT_USAGE;
    }
    int code = cli_check_output_path(path, force || in_place);
    if (code >= 0)
        return code;
    if (!format_given && cli_output_format(path, false) == RSMOOTH_FORMAT_AUTO) {
        fprintf(stderr, "rsmooth: %s: unknown output format (use .obj, .ply, .off or .stl)\n",
                path);
        return EXIT_USAGE;
    }
    return -1;
}

typedef struct mesh_write {
    const rsmooth_mesh *mesh;
    rsmooth_format format;
} mesh_write;

static int write_mesh_stream(FILE *f, void *user, char *message, size_t size) {
    const mesh_write *w = user;
    rsmooth_error err;
    if (rsmooth_mesh_write_stream(w->mesh, f, w->format, &err) == RSMOOTH_OK)
        return 0;
    snprintf(message, size, "%s", err.message);
    return -1;
}

int cli_check_writable(const rsmooth_mesh *mesh, const char *path, rsmooth_format format,
                       const char *input) {
    rsmooth_error err;
    if (rsmooth_mesh_check_writable(mesh, format, &err) == RSMOOTH_OK)
        return -1;
    fprintf(stderr, "rsmooth: %s: cannot hold %s: %s\n", path, input, err.message);
    return EXIT_USAGE;
}

int cli_write_mesh(const rsmooth_mesh *mesh, const char *path, rsmooth_format format, bool replace,
                   bool quiet) {
    mesh_write w = {mesh, format};
    if (strcmp(path, "-") != 0)
        return cli_write_atomically(path, replace, quiet, write_mesh_stream, &w);
    char message[256] = "";
    if (write_mesh_stream(stdout, &w, message, sizeof message) != 0 ||
        (fflush(stdout) != 0 && snprintf(message, sizeof message, "%s", strerror(errno)) > 0)) {
        fprintf(stderr, "rsmooth: <stdout>: cannot write: %s\n", message);
        return EXIT_OTHER;
    }
    return EXIT_OK;
}
