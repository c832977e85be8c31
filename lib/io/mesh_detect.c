/* What rsmooth_mesh_read_memory reads: the format told by the content (RSMOOTH_FORMAT_AUTO) or
 * named by the caller, and a UTF-8 byte-order mark before text. */
#define _POSIX_C_SOURCE 200809L
#include "io/io_internal.h"

#include <string.h>

typedef rsmooth_status (*reader_fn)(const char *data, size_t size, rsmooth_mesh **mesh,
                                    rsmooth_error *error);

static size_t bom_size(const char *data, size_t size) {
    return size >= RS_IO_UTF8_BOM_SIZE && memcmp(data, RS_IO_UTF8_BOM, RS_IO_UTF8_BOM_SIZE) == 0
               ? RS_IO_UTF8_BOM_SIZE
               : 0;
}

/* Runs `read` on the text after a UTF-8 byte-order mark, if there is one; the mesh then remembers
 * the mark so writers of its format put it back. Error offsets count from the file's first byte. */
static rsmooth_status read_text(reader_fn read, const char *data, size_t size, rsmooth_mesh **mesh,
                                rsmooth_error *error) {
    size_t skip = bom_size(data, size);
    rsmooth_status status = read(data + skip, size - skip, mesh, error);
    if (skip == 0)
        return status;
    if (status != RSMOOTH_OK) {
        if (error && error->byte_offset >= 0)
            error->byte_offset += (int64_t)skip;
        return status;
    }
    struct rsmooth_mesh_extras *extras = rs_io_mesh_extras(*mesh);
    if (!extras) {
        rsmooth_mesh_destroy(*mesh);
        *mesh = NULL;
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, "rsmooth_mesh_read", "extras record");
    }
    extras->utf8_bom = true;
    return RSMOOTH_OK;
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

/* STL: binary when the size says so (its header may be anything, a byte-order mark included),
 * else text after any byte-order mark. */
static rsmooth_status read_stl(const char *data, size_t size, rsmooth_mesh **mesh,
                               rsmooth_error *error) {
    if (is_binary_stl(data, size) || bom_size(data, size) == 0)
        return rs_io_stl_read(data, size, mesh, error);
    return read_text(rs_io_stl_read, data, size, mesh, error);
}

static bool is_blank(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f';
}

/* The first token of a text past blanks and '#' comment lines (OFF allows both before its
 * keyword), with its 1-based line; len 0 when there is none. */
typedef struct first_token {
    size_t offset, len;
    int64_t line;
} first_token;

static first_token find_first_token(const char *data, size_t size) {
    first_token t = {0, 0, 1};
    size_t i = 0;
    while (i < size && (is_blank(data[i]) || data[i] == '#')) {
        if (data[i] == '#')
            while (i < size && data[i] != '\n')
                i++;
        else if (data[i++] == '\n')
            t.line++;
    }
    t.offset = i;
    while (i < size && !is_blank(data[i]))
        i++;
    t.len = i - t.offset;
    return t;
}

static bool token_is_ci(const char *token, size_t len, const char *word) {
    if (len != strlen(word))
        return false;
    for (size_t i = 0; i < len; i++)
        if ((token[i] | 0x20) != word[i])
            return false;
    return true;
}

/* OFF keywords end in "OFF" (OFF, COFF, NOFF, STCNOFF, 4OFF, nOFF, lowercase "off"...): the OFF
 * reader tells the ones it reads from the ones it does not. */
static bool is_off_keyword(const char *token, size_t len) {
    return len >= 3 && len <= 16 && token_is_ci(token + len - 3, 3, "off");
}

/* The statements an OBJ file opens with (past comments): such a file is read as OBJ even if a stray
 * control byte follows (the OBJ reader then locates it). */
static bool is_obj_statement(const char *token, size_t len) {
    static const char *const statements[] = {"v", "vt", "vn", "vp", "f",      "l",
                                             "p", "g",  "o",  "s",  "mtllib", "usemtl"};
    for (size_t i = 0; i < sizeof statements / sizeof statements[0]; i++)
        if (len == strlen(statements[i]) && memcmp(token, statements[i], len) == 0)
            return true;
    return false;
}

/* Offset of the first byte no text holds (NUL or a control character other than blanks) among
 * the first 4 KiB, or SIZE_MAX. */
static size_t first_binary_byte(const char *data, size_t size) {
    for (size_t i = 0; i < size && i < 4096; i++) {
        unsigned char c = (unsigned char)data[i];
        if ((c < 0x20 && !is_blank((char)c)) || c == 0x7f)
            return i;
    }
    return SIZE_MAX;
}

/* Binary content without the PLY magic can only be a binary STL, whose size is then wrong: the
 * STL reader says how, and this says why the file was taken for one. */
static rsmooth_status read_binary_content(const char *data, size_t size, size_t binary_byte,
                                          rsmooth_mesh **mesh, rsmooth_error *error) {
    rsmooth_status status = rs_io_stl_read(data, size, mesh, error);
    if (status == RSMOOTH_ERROR_PARSE && error) {
        char detail[sizeof error->message];
        snprintf(detail, sizeof detail, "%s", error->message);
        int n = snprintf(error->message, sizeof error->message,
                         "binary content (byte %zu is 0x%02x) without the 'ply' magic, so not PLY, "
                         "OBJ or OFF; read as STL: ",
                         binary_byte, (unsigned)(unsigned char)data[binary_byte]);
        if (n > 0 && (size_t)n < sizeof error->message) { /* as much of the detail as fits */
            size_t room = sizeof error->message - (size_t)n - 1;
            size_t len = strnlen(detail, room);
            memcpy(error->message + n, detail, len);
            error->message[(size_t)n + len] = '\0';
        }
    }
    return status;
}

/* What RSMOOTH_FORMAT_AUTO reads: a binary STL by its exact size; after any byte-order mark, PLY
 * by its first bytes "ply"; then by the first token past blanks and comments: an OFF keyword, or
 * "solid" (ascii STL); binary content not opening with an OBJ statement (a binary STL of the wrong
 * size); else OBJ. Content none of them can hold gets a located error that says what was
 * expected. */
static rsmooth_status read_auto(const char *data, size_t size, rsmooth_mesh **mesh,
                                rsmooth_error *error) {
    static const char where[] = "rsmooth_mesh_read";
    if (size == 0)
        return rs_fail_parse(error, 1, 0, where,
                             "the file is empty (expected an OBJ, PLY, OFF or STL mesh)");
    if (is_binary_stl(data, size))
        return rs_io_stl_read(data, size, mesh, error);
    size_t skip = bom_size(data, size);
    const char *text = data + skip;
    if (size - skip >= 3 && memcmp(text, "ply", 3) == 0)
        return read_text(rs_io_ply_read, data, size, mesh, error);
    first_token t = find_first_token(text, size - skip);
    const char *token = text + t.offset;
    if (is_off_keyword(token, t.len))
        return read_text(rs_io_off_read, data, size, mesh, error);
    if (token_is_ci(token, t.len, "solid"))
        return read_stl(data, size, mesh, error);
    if (token_is_ci(token, t.len, "ply"))
        return rs_fail_parse(error, t.line, (int64_t)(skip + t.offset), where,
                             "'%.3s' after %zu bytes of blanks or comments: a PLY file must start "
                             "with the line 'ply' (lowercase) at its first byte",
                             token, t.offset);
    size_t binary_byte = first_binary_byte(data, size);
    if (binary_byte != SIZE_MAX && !is_obj_statement(token, t.len))
        return read_binary_content(data, size, binary_byte, mesh, error);
    if (t.len == 0)
        return rs_fail_parse(error, t.line, (int64_t)size, where,
                             "the file holds only blanks and comments (expected an OBJ, PLY, OFF "
                             "or STL mesh)");
    return read_text(rs_io_obj_read, data, size, mesh, error);
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
        return read_auto(bytes, size, mesh, error);
    case RSMOOTH_FORMAT_OFF:
        return read_text(rs_io_off_read, bytes, size, mesh, error);
    case RSMOOTH_FORMAT_STL_ASCII:
    case RSMOOTH_FORMAT_STL_BINARY: /* the content decides */
        return read_stl(bytes, size, mesh, error);
    case RSMOOTH_FORMAT_OBJ:
        return read_text(rs_io_obj_read, bytes, size, mesh, error);
    case RSMOOTH_FORMAT_PLY_ASCII:
    case RSMOOTH_FORMAT_PLY_BINARY:
    case RSMOOTH_FORMAT_PLY_BINARY_BE: /* the header names the encoding */
        return read_text(rs_io_ply_read, bytes, size, mesh, error);
    }
    return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "unknown format %d", (int)format);
}
