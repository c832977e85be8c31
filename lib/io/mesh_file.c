/* Public entry points of the mesh file library: format dispatch, whole-file reads, file writes. */
#define _POSIX_C_SOURCE 200809L
#include "io/io_internal.h"

#include <errno.h>
#include <string.h>
#include <sys/stat.h>

static bool has_ply_magic(const char *data, size_t size) {
    return size >= 4 && memcmp(data, "ply", 3) == 0 && (data[3] == '\n' || data[3] == '\r');
}

/* OFF files open with a keyword ending in "OFF" (OFF, COFF, NOFF, CNOFF, STOFF...). */
static bool has_off_magic(const char *data, size_t size) {
    size_t n = 0;
    while (n < size && n < 16 && data[n] >= 'A' && data[n] <= 'Z')
        n++;
    return n >= 3 && memcmp(data + n - 3, "OFF", 3) == 0 &&
           (n == size || data[n] == ' ' || data[n] == '\t' || data[n] == '\r' || data[n] == '\n');
}

/* Binary STL: an 80-byte header, a little-endian triangle count, then exactly 50 bytes a triangle.
 * The size test comes first because many binary headers also start with "solid". */
static bool is_binary_stl(const char *data, size_t size) {
    if (size < 84)
        return false;
    const unsigned char *c = (const unsigned char *)data + 80;
    uint64_t count =
        (uint64_t)c[0] | (uint64_t)c[1] << 8 | (uint64_t)c[2] << 16 | (uint64_t)c[3] << 24;
    return 84 + 50 * count == (uint64_t)size;
}

static bool has_ascii_stl_magic(const char *data, size_t size) {
    size_t i = 0;
    while (i < size && (data[i] == ' ' || data[i] == '\t' || data[i] == '\r' || data[i] == '\n'))
        i++;
    static const char solid[] = "solid"; /* keywords are case-insensitive */
    if (size - i < 6)
        return false;
    for (size_t k = 0; k < 5; k++)
        if ((data[i + k] | 0x20) != solid[k])
            return false;
    return (data[i + 5] == ' ' || data[i + 5] == '\t' || data[i + 5] == '\r' ||
            data[i + 5] == '\n');
}

rsmooth_status rsmooth_mesh_read_memory(const void *data, size_t size, rsmooth_format format,
                                        rsmooth_mesh **mesh, rsmooth_error *error) {
    static const char where[] = "rsmooth_mesh_read_memory";
    rs_error_clear(error);
    if (!mesh)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "mesh is NULL");
    *mesh = NULL;
    if (!data && size > 0)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "data is NULL");
    const char *bytes = data ? (const char *)data : "";
    switch (format) {
    case RSMOOTH_FORMAT_AUTO:
        if (has_ply_magic(bytes, size))
            return rs_io_ply_read(bytes, size, mesh, error);
        if (has_off_magic(bytes, size))
            return rs_io_off_read(bytes, size, mesh, error);
        if (is_binary_stl(bytes, size) || has_ascii_stl_magic(bytes, size))
            return rs_io_stl_read(bytes, size, mesh, error);
        return rs_io_obj_read(bytes, size, mesh, error);
    case RSMOOTH_FORMAT_OFF:
        return rs_io_off_read(bytes, size, mesh, error);
    case RSMOOTH_FORMAT_STL_ASCII:
    case RSMOOTH_FORMAT_STL_BINARY: /* the content decides */
        return rs_io_stl_read(bytes, size, mesh, error);
    case RSMOOTH_FORMAT_OBJ:
        return rs_io_obj_read(bytes, size, mesh, error);
    case RSMOOTH_FORMAT_PLY_ASCII:
    case RSMOOTH_FORMAT_PLY_BINARY:
    case RSMOOTH_FORMAT_PLY_BINARY_BE: /* the header names the encoding */
        return rs_io_ply_read(bytes, size, mesh, error);
    }
    return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "unknown format %d", (int)format);
}

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

rsmooth_status rsmooth_mesh_write_stream(const rsmooth_mesh *mesh, FILE *stream,
                                         rsmooth_format format, rsmooth_error *error) {
    static const char where[] = "rsmooth_mesh_write_stream";
    rs_error_clear(error);
    if (!stream)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "stream is NULL");
    rsmooth_status status = rs_io_mesh_check(mesh, where, error);
    if (status != RSMOOTH_OK)
        return status;
    switch (format) {
    case RSMOOTH_FORMAT_OBJ:
        return rs_io_obj_write(mesh, stream, error);
    case RSMOOTH_FORMAT_PLY_ASCII:
        return rs_io_ply_write(mesh, stream, false, error);
    case RSMOOTH_FORMAT_PLY_BINARY:
        return rs_io_ply_write(mesh, stream, true, error);
    case RSMOOTH_FORMAT_PLY_BINARY_BE:
        return rs_fail(error, RSMOOTH_ERROR_UNSUPPORTED, where,
                       "big-endian PLY output is not supported");
    case RSMOOTH_FORMAT_OFF:
        return rs_io_off_write(mesh, stream, error);
    case RSMOOTH_FORMAT_STL_ASCII:
        return rs_io_stl_write(mesh, stream, false, error);
    case RSMOOTH_FORMAT_STL_BINARY:
        return rs_io_stl_write(mesh, stream, true, error);
    case RSMOOTH_FORMAT_AUTO:
        break;
    }
    return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                   "format %d: give OBJ, PLY, OFF or STL", (int)format);
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
    /* Check before creating the file, so a bad mesh leaves no file behind. */
    rsmooth_status status = rs_io_mesh_check(mesh, where, error);
    if (status != RSMOOTH_OK)
        return status;
    if (format == RSMOOTH_FORMAT_PLY_BINARY_BE)
        return rs_fail(error, RSMOOTH_ERROR_UNSUPPORTED, where,
                       "big-endian PLY output is not supported");
    FILE *file = fopen(path, "wb");
    if (!file)
        return rs_fail(error, RSMOOTH_ERROR_IO, where, "cannot create '%s': %s", path,
                       strerror(errno));
    status = rsmooth_mesh_write_stream(mesh, file, format, error);
    errno = 0;
    bool closed = fclose(file) == 0;
    if (status == RSMOOTH_ERROR_IO) {
        char detail[sizeof error->message]; /* rs_fail clears `error` before formatting */
        snprintf(detail, sizeof detail, "%s", error ? error->message : "write failed");
        return rs_fail(error, RSMOOTH_ERROR_IO, where, "writing '%s': %s", path, detail);
    }
    if (status != RSMOOTH_OK)
        return status;
    if (!closed)
        return rs_fail(error, RSMOOTH_ERROR_IO, where, "writing '%s': %s", path,
                       errno ? strerror(errno) : "close failed");
    return RSMOOTH_OK;
}
