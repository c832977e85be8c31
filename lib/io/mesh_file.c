/* Public entry points of the mesh file library: whole-file and stream reads (parsed by
 * mesh_detect.c), stream and file writes (files put in place whole, through output_file.h). */
#define _POSIX_C_SOURCE 200809L
#include "io/io_internal.h"
#include "io/output_file.h"

#include <errno.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* Reads the whole stream; regular files in one allocation of their size, others by doubling. */
static rsmooth_status read_all(FILE *file, const char *path, size_t size_hint, char **out_data,
                               size_t *out_size, rsmooth_error *error) {
    static const char where[] = "rsmooth_mesh_read_file";
    size_t capacity =
        size_hint < SIZE_MAX - 1 ? size_hint + 1 : size_hint; /* +1: EOF in one read */
    if (capacity < 4096)
        capacity = 4096;
    char *data = rs_alloc_array(capacity, 1);
    if (!data)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "%zu bytes for '%s'", capacity,
                       path);
    size_t size = 0;
    for (;;) {
        if (size == capacity) {
            size_t grown = capacity <= SIZE_MAX / 2 ? capacity * 2 : SIZE_MAX;
            char *bigger = grown > capacity ? rs_realloc_array(data, grown, 1) : NULL;
            if (!bigger) {
                rs_free(data);
                return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "reading '%s'", path);
            }
            data = bigger;
            capacity = grown;
        }
        errno = 0;
        size_t got = fread(data + size, 1, capacity - size, file);
        size += got;
        if (got == 0 || size < capacity) {
            if (ferror(file)) {
                int e = errno;
                rs_free(data);
                return rs_fail(error, RSMOOTH_ERROR_IO, where, "cannot read '%s': %s", path,
                               e ? strerror(e) : "read error");
            }
            if (feof(file))
                break;
        }
    }
    *out_data = data;
    *out_size = size;
    return RSMOOTH_OK;
}

rsmooth_status rsmooth_mesh_read_file(const char *path, rsmooth_mesh **mesh, rsmooth_error *error) {
    static const char where[] = "rsmooth_mesh_read_file";
    rs_error_clear(error);
    if (!mesh)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "mesh is NULL");
    *mesh = NULL;
    if (!path)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "path is NULL");
    FILE *file = fopen(path, "rb");
    if (!file)
        return rs_fail(error, RSMOOTH_ERROR_IO, where, "cannot open '%s': %s", path,
                       strerror(errno));
    struct stat st;
    if (fstat(fileno(file), &st) != 0) {
        int e = errno;
        fclose(file);
        return rs_fail(error, RSMOOTH_ERROR_IO, where, "cannot stat '%s': %s", path, strerror(e));
    }
    if (S_ISDIR(st.st_mode)) {
        fclose(file);
        return rs_fail(error, RSMOOTH_ERROR_IO, where, "cannot read '%s': %s", path,
                       strerror(EISDIR));
    }
    size_t hint = 0;
    if (S_ISREG(st.st_mode) && st.st_size > 0)
        hint = (uint64_t)st.st_size < SIZE_MAX ? (size_t)st.st_size : SIZE_MAX - 1;
    char *data = NULL;
    size_t size = 0;
    rsmooth_status status = read_all(file, path, hint, &data, &size, error);
    fclose(file); /* read-only: nothing to lose on close */
    if (status != RSMOOTH_OK)
        return status;
    status = rsmooth_mesh_read_memory(data, size, RSMOOTH_FORMAT_AUTO, mesh, error);
    rs_free(data);
    return status;
}

rsmooth_status rsmooth_mesh_read_stream(FILE *stream, const char *name, rsmooth_mesh **mesh,
                                        rsmooth_error *error) {
    static const char where[] = "rsmooth_mesh_read_stream";
    rs_error_clear(error);
    if (!mesh)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "mesh is NULL");
    *mesh = NULL;
    if (!stream)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "stream is NULL");
    char *data = NULL;
    size_t size = 0;
    rsmooth_status status = read_all(stream, name ? name : "stream", 0, &data, &size, error);
    if (status != RSMOOTH_OK)
        return status;
    status = rsmooth_mesh_read_memory(data, size, RSMOOTH_FORMAT_AUTO, mesh, error);
    rs_free(data);
    return status;
}

/* Every refusal of the writer of `format`, run before its first byte (rsmooth_mesh_check_writable
 * and rsmooth_mesh_write_stream): rs_io_mesh_check, rs_io_mesh_check_values, then the format's
 * own check. AUTO or an unknown value is INVALID_ARGUMENT, big-endian PLY UNSUPPORTED. */
static rsmooth_status rs_io_check_writable(const rsmooth_mesh *mesh, rsmooth_format format,
                                           const char *where, rsmooth_error *error) {
    rsmooth_status status = rs_io_mesh_check(mesh, where, error);
    if (status == RSMOOTH_OK)
        status = rs_io_mesh_check_values(mesh, where, error);
    if (status != RSMOOTH_OK)
        return status;
    switch (format) {
    case RSMOOTH_FORMAT_OBJ:
        return rs_io_obj_check(mesh, error);
    case RSMOOTH_FORMAT_PLY_ASCII:
    case RSMOOTH_FORMAT_PLY_BINARY:
        return rs_io_ply_check(mesh, error);
    case RSMOOTH_FORMAT_PLY_BINARY_BE:
        return rs_fail(error, RSMOOTH_ERROR_UNSUPPORTED, where,
                       "big-endian PLY output is not supported");
    case RSMOOTH_FORMAT_OFF:
        return rs_io_off_check(mesh, error);
    case RSMOOTH_FORMAT_STL_ASCII:
        return rs_io_stl_check(mesh, false, error);
    case RSMOOTH_FORMAT_STL_BINARY:
        return rs_io_stl_check(mesh, true, error);
    case RSMOOTH_FORMAT_AUTO:
        break;
    }
    return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                   "format %d: give OBJ, PLY, OFF or STL", (int)format);
}

rsmooth_status rsmooth_mesh_check_writable(const rsmooth_mesh *mesh, rsmooth_format format,
                                           rsmooth_error *error) {
    rs_error_clear(error);
    return rs_io_check_writable(mesh, format, "rsmooth_mesh_check_writable", error);
}

/* Writes a mesh that passed rs_io_check_writable for `format`. */
static rsmooth_status write_checked(const rsmooth_mesh *mesh, FILE *stream, rsmooth_format format,
                                    rsmooth_error *error) {
    switch (format) {
    case RSMOOTH_FORMAT_OBJ:
        return rs_io_obj_write(mesh, stream, error);
    case RSMOOTH_FORMAT_PLY_ASCII:
        return rs_io_ply_write(mesh, stream, false, error);
    case RSMOOTH_FORMAT_PLY_BINARY:
        return rs_io_ply_write(mesh, stream, true, error);
    case RSMOOTH_FORMAT_OFF:
        return rs_io_off_write(mesh, stream, error);
    case RSMOOTH_FORMAT_STL_ASCII:
        return rs_io_stl_write(mesh, stream, false, error);
    case RSMOOTH_FORMAT_STL_BINARY:
        return rs_io_stl_write(mesh, stream, true, error);
    case RSMOOTH_FORMAT_PLY_BINARY_BE: /* refused by the check */
    case RSMOOTH_FORMAT_AUTO:
        break;
    }
    return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, "rsmooth_mesh_write_stream",
                   "format %d: give OBJ, PLY, OFF or STL", (int)format);
}

rsmooth_status rsmooth_mesh_write_stream(const rsmooth_mesh *mesh, FILE *stream,
                                         rsmooth_format format, rsmooth_error *error) {
    static const char where[] = "rsmooth_mesh_write_stream";
    rs_error_clear(error);
    if (!stream)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "stream is NULL");
    /* Every refusal before the first byte: a refused mesh leaves the stream as it was. */
    rsmooth_status status = rs_io_check_writable(mesh, format, where, error);
    if (status != RSMOOTH_OK)
        return status;
    return write_checked(mesh, stream, format, error);
}

/* What a file written whole gets as content: written into `stream`, a status and `error` as a
 * writer gives them. */
typedef rsmooth_status (*content_writer)(FILE *stream, void *user, rsmooth_error *error);

/* A successful write's notes (output_file.h) in error->message, cut to fit. */
static void put_notes(rsmooth_error *error, const char *notes) {
    if (!error)
        return;
    size_t n = strnlen(notes, sizeof error->message - 1);
    memcpy(error->message, notes, n);
    error->message[n] = '\0';
}

/* Writes `path` whole or not at all (output_file.h): `content` goes into a new file beside it,
 * which takes the name only when written, flushed and closed without error; anything that fails
 * removes it and leaves whatever was at `path` as it was. Without `write` only the checks of
 * `path`. A failure of `write` keeps its status (RSMOOTH_ERROR_IO with the path named); on
 * success error->message holds output_file.h's notes, or nothing. */
static rsmooth_status write_whole(const char *path, bool replace, const char *hint,
                                  content_writer write, void *user, const char *where,
                                  rsmooth_error *error) {
    rs_output o;
    rsmooth_status status = rs_output_resolve(&o, path, replace, hint, where, error);
    if (status == RSMOOTH_OK && write)
        status = rs_output_create(&o, where, error);
    if (status != RSMOOTH_OK || !write) {
        rs_output_discard(&o);
        if (status == RSMOOTH_OK)
            put_notes(error, o.notes);
        return status;
    }
    /* a stream of its own over a copy of the descriptor, closed (flushed and checked) before
     * the content is put in place */
    int copy = dup(o.fd);
    FILE *stream = copy >= 0 ? fdopen(copy, "wb") : NULL;
    if (!stream) {
        status =
            rs_fail(error, RSMOOTH_ERROR_IO, where, "%s: cannot write: %s", path, strerror(errno));
        if (copy >= 0)
            close(copy);
    }
    if (stream)
        status = write(stream, user, error);
    if (status == RSMOOTH_ERROR_IO) {
        char detail[sizeof error->message]; /* rs_fail clears `error` before formatting */
        snprintf(detail, sizeof detail, "%s", error ? error->message : "write failed");
        status = rs_fail(error, RSMOOTH_ERROR_IO, where, "%s: cannot write: %s", path, detail);
    }
    errno = 0;
    if (stream && fclose(stream) != 0 && status == RSMOOTH_OK)
        status = rs_fail(error, RSMOOTH_ERROR_IO, where, "%s: cannot write: %s", path,
                         errno ? strerror(errno) : "close failed");
    if (status != RSMOOTH_OK) {
        rs_output_discard(&o);
        return status;
    }
    char notes[sizeof o.notes];
    memcpy(notes, o.notes, sizeof notes);
    status = rs_output_publish(&o, replace, where, error);
    if (status == RSMOOTH_OK)
        put_notes(error, notes);
    return status;
}

typedef struct mesh_content {
    const rsmooth_mesh *mesh;
    rsmooth_format format;
} mesh_content;

static rsmooth_status write_mesh_content(FILE *stream, void *user, rsmooth_error *error) {
    const mesh_content *c = user;
    return write_checked(c->mesh, stream, c->format, error);
}

rsmooth_status rsmooth_mesh_write_file(const rsmooth_mesh *mesh, const char *path,
                                       rsmooth_format format, rsmooth_error *error) {
    static const char where[] = "rsmooth_mesh_write_file";
    rs_error_clear(error);
    if (!path)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "path is NULL");
    if (format == RSMOOTH_FORMAT_AUTO) {
        format = rsmooth_format_from_path(path);
        if (format == RSMOOTH_FORMAT_AUTO)
            return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                           "cannot tell the format of '%s' (use .obj, .ply, .off or .stl)", path);
    }
    /* Every refusal before anything is created, so a refused mesh leaves no file behind. */
    rsmooth_status status = rs_io_check_writable(mesh, format, where, error);
    if (status != RSMOOTH_OK)
        return status;
    mesh_content c = {mesh, format};
    return write_whole(path, true, "", write_mesh_content, &c, where, error);
}

typedef struct caller_content {
    rsmooth_file_writer write;
    void *user;
} caller_content;

static rsmooth_status write_caller_content(FILE *stream, void *user, rsmooth_error *error) {
    const caller_content *c = user;
    char message[sizeof error->message] = "";
    if (c->write(stream, c->user, message, sizeof message) == 0)
        return RSMOOTH_OK;
    message[sizeof message - 1] = '\0';
    return rs_fail(error, RSMOOTH_ERROR_IO, "rsmooth_file_write", "%s",
                   message[0] ? message : "the content's writer failed");
}

rsmooth_status rsmooth_file_write(const char *path, int replace, const char *hint,
                                  rsmooth_file_writer write, void *user, rsmooth_error *error) {
    static const char where[] = "rsmooth_file_write";
    rs_error_clear(error);
    if (!path)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "path is NULL");
    caller_content c = {write, user};
    return write_whole(path, replace != 0, hint ? hint : "set replace",
                       write ? write_caller_content : NULL, &c, where, error);
}
