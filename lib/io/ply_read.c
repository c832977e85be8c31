/* Stanford PLY parser (ascii, binary LE and BE): the mesh, and all else into the PLY extras. */
#include "io/ply_format.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char where[] = "rsmooth_mesh_read (PLY)";

typedef enum ply_encoding { PLY_ASCII, PLY_BINARY_LE, PLY_BINARY_BE } ply_encoding;

typedef struct ply_reader {
    const char *data;
    size_t size;
    size_t pos;   /* read position in data */
    int64_t line; /* ascii: current line, 1-based */
    bool crossed_line; /* ascii: the last token read came after a line end */
    int64_t end_header_line;
    ply_encoding encoding;
    bool swap;        /* binary data in the other byte order than the host's */
    rs_ply_extras *x; /* the header, and the values kept */
    /* results */
    rs_ply_element *vertex_element, *face_element;
    size_t vertex_count;
    double *positions;
    rsmooth_scalar precision;
    uint32_t *face_offsets;
    size_t face_count;
    rs_io_u32vec indices;
    bool normals;
    double *normal_values; /* 3 per vertex when `normals`: nx, ny, nz as read */
    size_t color[3]; /* property index of red, green, blue in the vertex element; SIZE_MAX: none */
    uint8_t *colors;
} ply_reader;

static bool is_space(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f' || c == '\n';
}

static bool token_is(const char *token, size_t len, const char *word) {
    size_t n = strlen(word);
    return len == n && memcmp(token, word, n) == 0;
}

/* The spelling index of a type word, or -1. */
static int parse_type(const char *token, size_t len) {
    for (unsigned s = 0; s < RS_PLY_SPELLING_COUNT; s++)
        if (token_is(token, len, rs_ply_spelling(s)))
            return (int)s;
    return -1;
}

static bool is_signed_int(rs_ply_type t) {
    return t == RS_PLY_INT8 || t == RS_PLY_INT16 || t == RS_PLY_INT32;
}

static char *copy_text(const char *s, size_t len) {
    char *copy = rs_alloc_array(len + 1, 1);
    if (copy) {
        memcpy(copy, s, len);
        copy[len] = '\0';
    }
    return copy;
}

/* ---- header */

#define MAX_HEADER_TOKENS 8

static rsmooth_status header_error(const ply_reader *r, size_t offset, rsmooth_error *error,
                                   const char *message, const char *token, size_t len) {
    return rs_fail_parse(error, r->line, (int64_t)offset, where, "%s '%.*s'", message,
                         (int)(len > 40 ? 40 : len), token);
}

static rsmooth_status header_oom(rsmooth_error *error) {
    return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "PLY header");
}

static rsmooth_status add_comment(ply_reader *r, const char *start, const char *eol,
                                  bool have_format, rsmooth_error *error) {
    rs_ply_extras *x = r->x;
    if (x->comment_count == x->comment_capacity) {
        size_t capacity = x->comment_capacity ? 2 * x->comment_capacity : 8;
        rs_ply_comment *c = rs_realloc_array(x->comments, capacity, sizeof *c);
        if (!c)
            return header_oom(error);
        x->comments = c;
        x->comment_capacity = capacity;
    }
    while (eol > start && eol[-1] == '\r')
        eol--;
    char *text = copy_text(start, (size_t)(eol - start));
    if (!text)
        return header_oom(error);
    x->comments[x->comment_count++] = (rs_ply_comment){
        .text = text, .before_element = x->element_count, .before_format = !have_format};
    return RSMOOTH_OK;
}

static rsmooth_status add_property(ply_reader *r, const char *const *tok, const size_t *len, int n,
                                   size_t offset, rsmooth_error *error) {
    rs_ply_extras *x = r->x;
    if (x->element_count == 0)
        return header_error(r, offset, error, "property before any element:", tok[0], len[0]);
    rs_ply_property prop = {0};
    const char *name;
    size_t name_len;
    if (n >= 2 && token_is(tok[1], len[1], "list")) {
        if (n != 5)
            return header_error(r, offset, error,
                                "expected 'property list COUNTTYPE TYPE NAME':", tok[0], len[0]);
        int count_spelling = parse_type(tok[2], len[2]), spelling = parse_type(tok[3], len[3]);
        if (count_spelling < 0)
            return header_error(r, (size_t)(tok[2] - r->data), error, "unknown type", tok[2],
                                len[2]);
        if (spelling < 0)
            return header_error(r, (size_t)(tok[3] - r->data), error, "unknown type", tok[3],
                                len[3]);
        prop.count_spelling = (uint8_t)count_spelling;
        prop.count_type = rs_ply_spelling_type((unsigned)count_spelling);
        prop.spelling = (uint8_t)spelling;
        prop.type = rs_ply_spelling_type((unsigned)spelling);
        if (rs_ply_type_is_float(prop.count_type))
            return header_error(r, (size_t)(tok[2] - r->data), error,
                                "list count type must be an integer:", tok[2], len[2]);
        name = tok[4];
        name_len = len[4];
    } else {
        if (n != 3)
            return header_error(r, offset, error, "expected 'property TYPE NAME':", tok[0], len[0]);
        int spelling = parse_type(tok[1], len[1]);
        if (spelling < 0)
            return header_error(r, (size_t)(tok[1] - r->data), error, "unknown type", tok[1],
                                len[1]);
        prop.spelling = (uint8_t)spelling;
        prop.type = rs_ply_spelling_type((unsigned)spelling);
        name = tok[2];
        name_len = len[2];
    }
    rs_ply_element *e = &x->elements[x->element_count - 1];
    for (size_t k = 0; k < e->property_count; k++) /* a name must say which value it is */
        if (token_is(name, name_len, e->properties[k].name))
            return header_error(r, (size_t)(name - r->data), error,
                                "a second property of the same name in one element:", name,
                                name_len);
    if (e->property_count == e->property_capacity) {
        size_t capacity = e->property_capacity ? 2 * e->property_capacity : 8;
        rs_ply_property *p = rs_realloc_array(e->properties, capacity, sizeof *p);
        if (!p)
            return header_oom(error);
        e->properties = p;
        e->property_capacity = capacity;
    }
    prop.name = copy_text(name, name_len);
    if (!prop.name)
        return header_oom(error);
    e->properties[e->property_count++] = prop;
    return RSMOOTH_OK;
}

static rsmooth_status add_element(ply_reader *r, const char *const *tok, const size_t *len, int n,
                                  size_t offset, rsmooth_error *error) {
    rs_ply_extras *x = r->x;
    if (n != 3)
        return header_error(r, offset, error, "expected 'element NAME COUNT':", tok[0], len[0]);
    char digits[32];
    bool ok = len[2] > 0 && len[2] < sizeof digits;
    for (size_t i = 0; ok && i < len[2]; i++)
        ok = tok[2][i] >= '0' && tok[2][i] <= '9'; /* strtoull alone would take "-1" */
    if (!ok)
        return header_error(r, (size_t)(tok[2] - r->data), error, "bad element count", tok[2],
                            len[2]);
    memcpy(digits, tok[2], len[2]);
    digits[len[2]] = '\0';
    unsigned long long count = strtoull(digits, NULL, 10);
    if (count == ULLONG_MAX || count > UINT64_MAX / 2)
        return header_error(r, (size_t)(tok[2] - r->data), error, "element count out of range",
                            tok[2], len[2]);
    if (x->element_count == x->element_capacity) {
        size_t capacity = x->element_capacity ? 2 * x->element_capacity : 8;
        rs_ply_element *e = rs_realloc_array(x->elements, capacity, sizeof *e);
        if (!e)
            return header_oom(error);
        x->elements = e;
        x->element_capacity = capacity;
    }
    char *name = copy_text(tok[1], len[1]);
    if (!name)
        return header_oom(error);
    x->elements[x->element_count++] =
        (rs_ply_element){.name = name, .count = count, .header_line = r->line};
    return RSMOOTH_OK;
}

static rsmooth_status parse_header(ply_reader *r, rsmooth_error *error) {
    const char *data = r->data;
    /* Magic: "ply" alone on the first line. */
    bool magic = r->size >= 3 && memcmp(data, "ply", 3) == 0;
    if (magic && (r->size == 3 || (r->size == 4 && data[3] == '\r')))
        return rs_fail_parse(error, 1, (int64_t)r->size, where,
                             "the file ends after 'ply' (a header up to 'end_header' expected)");
    if (!magic || !(data[3] == '\n' || (data[3] == '\r' && data[4] == '\n'))) {
        size_t len = 0;
        while (len < r->size && len < 40 && data[len] != '\n' && data[len] != '\r')
            len++;
        return rs_fail_parse(error, 1, 0, where,
                             "not a PLY file: the first line is '%.*s', not 'ply' alone", (int)len,
                             data);
    }
    r->pos = data[3] == '\n' ? 4 : 5;
    r->line = 2;
    bool have_format = false;
    for (;; r->line++) {
        if (r->pos >= r->size)
            return rs_fail_parse(error, r->line, (int64_t)r->pos, where,
                                 "header ends without 'end_header'");
        const char *start = data + r->pos;
        const char *eol = memchr(start, '\n', r->size - r->pos);
        if (!eol)
            return rs_fail_parse(error, r->line, (int64_t)r->pos, where,
                                 "header ends without 'end_header'");
        size_t offset = r->pos;
        r->pos = (size_t)(eol - data) + 1;
        /* A header is text: a NUL could never be written back (names and comments are strings). */
        const char *nul = memchr(start, '\0', (size_t)(eol - start));
        if (nul)
            return rs_fail_parse(error, r->line, (int64_t)(nul - data), where,
                                 "NUL byte in the header");
        const char *tok[MAX_HEADER_TOKENS];
        size_t len[MAX_HEADER_TOKENS];
        int n = 0;
        for (const char *p = start; p < eol;) {
            while (p < eol && is_space(*p))
                p++;
            if (p == eol)
                break;
            const char *t = p;
            while (p < eol && !is_space(*p))
                p++;
            if (n < MAX_HEADER_TOKENS) {
                tok[n] = t;
                len[n] = (size_t)(p - t);
            }
            n++;
        }
        if (n == 0)
            continue; /* tolerate blank header lines */
        rsmooth_status status = RSMOOTH_OK;
        if (token_is(tok[0], len[0], "comment") || token_is(tok[0], len[0], "obj_info")) {
            status = add_comment(r, tok[0], eol, have_format, error);
        } else if (token_is(tok[0], len[0], "end_header")) {
            if (n != 1)
                return header_error(r, offset, error, "bad header line:", tok[0], len[0]);
            if (!have_format)
                return rs_fail_parse(error, r->line, (int64_t)offset, where,
                                     "header has no 'format' line");
            r->end_header_line = r->line;
            r->line++; /* ascii data starts on the next line */
            return RSMOOTH_OK;
        } else if (token_is(tok[0], len[0], "format")) {
            if (n != 3 || have_format)
                return header_error(r, offset, error, "bad header line:", tok[0], len[0]);
            if (token_is(tok[1], len[1], "ascii"))
                r->encoding = PLY_ASCII;
            else if (token_is(tok[1], len[1], "binary_little_endian"))
                r->encoding = PLY_BINARY_LE;
            else if (token_is(tok[1], len[1], "binary_big_endian"))
                r->encoding = PLY_BINARY_BE;
            else
                return header_error(r, (size_t)(tok[1] - data), error, "unknown PLY format", tok[1],
                                    len[1]);
            if (!token_is(tok[2], len[2], "1.0") && !token_is(tok[2], len[2], "1"))
                return header_error(r, (size_t)(tok[2] - data), error, "unsupported PLY version",
                                    tok[2], len[2]);
            r->swap = r->encoding != PLY_ASCII &&
                      (r->encoding == PLY_BINARY_LE) != rs_ply_host_is_le();
            have_format = true;
        } else if (token_is(tok[0], len[0], "element")) {
            status = add_element(r, tok, len, n, offset, error);
        } else if (token_is(tok[0], len[0], "property")) {
            status = add_property(r, tok, len, n, offset, error);
        } else {
            return header_error(r, offset, error, "bad header line:", tok[0], len[0]);
        }
        if (status != RSMOOTH_OK)
            return status;
    }
}

/* ---- roles: what each property's values are to the mesh */

static size_t find_scalar(const rs_ply_element *e, const char *name) {
    for (size_t k = 0; k < e->property_count; k++)
        if (e->properties[k].count_type == RS_PLY_NONE && !strcmp(e->properties[k].name, name))
            return k;
    return SIZE_MAX;
}

static rsmooth_status assign_roles(ply_reader *r, rsmooth_error *error) {
    r->color[0] = r->color[1] = r->color[2] = SIZE_MAX;
    rs_ply_element *v = r->vertex_element;
    static const char *const axis[3] = {"x", "y", "z"};
    for (int c = 0; c < 3; c++) {
        size_t k = SIZE_MAX;
        for (size_t i = 0; i < v->property_count && k == SIZE_MAX; i++)
            if (!strcmp(v->properties[i].name, axis[c]))
                k = i;
        if (k == SIZE_MAX)
            return rs_fail_parse(error, v->header_line, -1, where,
                                 "vertex element has no '%s' property", axis[c]);
        if (v->properties[k].count_type != RS_PLY_NONE)
            return rs_fail_parse(error, v->header_line, -1, where,
                                 "vertex property '%s' is a list", axis[c]);
        v->properties[k].role = (uint8_t)(RS_PLY_X + c);
        if (v->properties[k].type == RS_PLY_FLOAT64)
            r->precision = RSMOOTH_FLOAT64;
    }
    /* Normals only as floating-point triples: integer ones stay opaque values, kept as read. */
    size_t n[3] = {find_scalar(v, "nx"), find_scalar(v, "ny"), find_scalar(v, "nz")};
    if (n[0] != SIZE_MAX && n[1] != SIZE_MAX && n[2] != SIZE_MAX &&
        rs_ply_type_is_float(v->properties[n[0]].type) &&
        rs_ply_type_is_float(v->properties[n[1]].type) &&
        rs_ply_type_is_float(v->properties[n[2]].type)) {
        for (int c = 0; c < 3; c++)
            v->properties[n[c]].role = (uint8_t)(RS_PLY_NX + c);
        r->normals = true;
    }
    static const char *const channel[2][3] = {{"red", "green", "blue"},
                                             {"diffuse_red", "diffuse_green", "diffuse_blue"}};
    for (int naming = 0; naming < 2 && r->color[0] == SIZE_MAX; naming++) {
        size_t k[3];
        bool all = true;
        for (int c = 0; c < 3; c++) {
            k[c] = find_scalar(v, channel[naming][c]);
            all = all && k[c] != SIZE_MAX && v->properties[k[c]].role == RS_PLY_STORED;
        }
        for (int c = 0; all && c < 3; c++) {
            r->color[c] = k[c];
            v->properties[k[c]].color = true;
        }
    }
    rs_ply_element *f = r->face_element;
    if (f) {
        size_t k = SIZE_MAX;
        for (size_t i = 0; i < f->property_count && k == SIZE_MAX; i++)
            if (f->properties[i].count_type != RS_PLY_NONE &&
                (!strcmp(f->properties[i].name, "vertex_indices") ||
                 !strcmp(f->properties[i].name, "vertex_index")))
                k = i;
        if (k == SIZE_MAX)
            return rs_fail_parse(error, f->header_line, -1, where,
                                 "face element has no 'vertex_indices' list property");
        f->properties[k].role = RS_PLY_FACE_LIST;
    }
    /* Rows: the stored scalars and list counts of each element, in property order. */
    for (size_t ei = 0; ei < r->x->element_count; ei++) {
        rs_ply_element *e = &r->x->elements[ei];
        for (size_t k = 0; k < e->property_count; k++) {
            rs_ply_property *p = &e->properties[k];
            if (p->role != RS_PLY_STORED)
                continue;
            p->row_offset = e->row_size;
            e->row_size += rs_ply_type_size(p->count_type != RS_PLY_NONE ? p->count_type : p->type);
        }
    }
    return RSMOOTH_OK;
}

/* The layout the generic writer produces (x y z of one float type, then "list uchar int
 * vertex_indices" faces, no comment but rsmooth's): nothing for extras to keep. */
static bool is_plain(const ply_reader *r) {
    const rs_ply_extras *x = r->x;
    for (size_t c = 0; c < x->comment_count; c++)
        if (strcmp(x->comments[c].text, "comment written by rsmooth") != 0)
            return false;
    if (x->element_count != 2 || x->vertex_element != 0 || x->face_element != 1 || r->normals)
        return false;
    const rs_ply_element *v = &x->elements[0], *f = &x->elements[1];
    if (v->property_count != 3 || f->property_count != 1)
        return false;
    for (int c = 0; c < 3; c++) {
        const rs_ply_property *p = &v->properties[c];
        if (p->role != RS_PLY_X + c || p->type != v->properties[0].type ||
            (strcmp(rs_ply_spelling(p->spelling), "float") != 0 &&
             strcmp(rs_ply_spelling(p->spelling), "double") != 0))
            return false;
    }
    const rs_ply_property *list = &f->properties[0];
    return !strcmp(list->name, "vertex_indices") &&
           !strcmp(rs_ply_spelling(list->count_spelling), "uchar") &&
           !strcmp(rs_ply_spelling(list->spelling), "int");
}

/* ---- data: shared */

static rsmooth_status face_begin(ply_reader *r, uint64_t n, uint64_t item, int64_t line,
                                 int64_t offset, rsmooth_error *error) {
    if (n < 3)
        return rs_fail_parse(error, line, offset, where,
                             "face %llu has %llu vertices (at least 3 needed)",
                             (unsigned long long)item, (unsigned long long)n);
    if (n >= RS_IO_MAX_FACE_INDICES - r->indices.count)
        return rs_fail_parse(error, line, offset, where, "too many face indices (32-bit offsets)");
    if (!rs_io_u32vec_reserve(&r->indices, (size_t)n))
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "%zu face indices",
                       r->indices.count + (size_t)n);
    return RSMOOTH_OK;
}

static rsmooth_status face_index(ply_reader *r, double v, int64_t line, int64_t offset,
                                 rsmooth_error *error) {
    /* The vertex count comes from the header, so faces before the vertex data check as well. */
    if (!(v >= 0 && v < (double)r->vertex_count && v == floor(v)))
        return rs_fail_parse(error, line, offset, where,
                             "face index %.17g out of range (%zu vertices)", v, r->vertex_count);
    r->indices.data[r->indices.count++] = (uint32_t)v;
    return RSMOOTH_OK;
}

/* A vertex as read (its row stored): coordinates rsmooth supports, finite normals (a point cloud's
 * data; a mesh's are recomputed, but a file holding others is not what it claims) and finite colour
 * channels (they become vertex_colors). */
static rsmooth_status check_vertex(const ply_reader *r, size_t i, int64_t line, int64_t offset,
                                   rsmooth_error *error) {
    rsmooth_status status = rs_io_check_vertex(r->positions + 3 * i, i, line, offset, where, error);
    if (status != RSMOOTH_OK)
        return status;
    const double *n = r->normal_values ? r->normal_values + 3 * i : NULL;
    if (n && (!isfinite(n[0]) || !isfinite(n[1]) || !isfinite(n[2])))
        return rs_fail_parse(error, line, offset, where, "vertex %zu has a non-finite normal", i);
    const rs_ply_element *v = r->vertex_element;
    for (int c = 0; r->color[0] != SIZE_MAX && c < 3; c++) {
        const rs_ply_property *p = &v->properties[r->color[c]];
        if (rs_ply_type_is_float(p->type) &&
            !isfinite(rs_ply_host_value(v->rows + i * v->row_size + p->row_offset, p->type)))
            return rs_fail_parse(error, line, offset, where,
                                 "vertex %zu has a non-finite colour ('%.40s')", i, p->name);
    }
    return RSMOOTH_OK;
}

/* Room for `extra` more bytes of list items (geometric growth). */
static bool list_reserve(rs_ply_element *e, size_t extra) {
    if (e->list_capacity - e->list_bytes >= extra)
        return true;
    if (extra > SIZE_MAX / 2 - e->list_bytes)
        return false;
    size_t need = e->list_bytes + extra;
    size_t capacity = e->list_capacity ? e->list_capacity : 256;
    while (capacity < need)
        capacity = capacity > SIZE_MAX / 4 ? need : 2 * capacity;
    unsigned char *items = rs_realloc_array(e->list_items, capacity, 1);
    if (!items)
        return false;
    e->list_items = items;
    e->list_capacity = capacity;
    return true;
}

static rsmooth_status list_oom(const rs_ply_element *e, rsmooth_error *error) {
    return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "list values of element '%.40s'",
                   e->name);
}

/* ---- data: binary */

/* Fixed-size loads: compilers turn these into one load (and a byte swap where needed). */
static inline uint16_t load_u16(const unsigned char *p, bool big_endian) {
    return big_endian ? (uint16_t)(p[0] << 8 | p[1]) : (uint16_t)(p[1] << 8 | p[0]);
}

static inline uint32_t load_u32(const unsigned char *p, bool big_endian) {
    return big_endian ? (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3]
                      : (uint32_t)p[3] << 24 | (uint32_t)p[2] << 16 | (uint32_t)p[1] << 8 | p[0];
}

static inline uint64_t load_u64(const unsigned char *p, bool big_endian) {
    uint64_t a = load_u32(p, big_endian), b = load_u32(p + 4, big_endian);
    return big_endian ? a << 32 | b : b << 32 | a;
}

/* An unsigned integer of an integer type's size (list counts). */
static inline uint64_t load_uint(const unsigned char *p, size_t size, bool big_endian) {
    switch (size) {
    case 1:
        return p[0];
    case 2:
        return load_u16(p, big_endian);
    case 4:
        return load_u32(p, big_endian);
    default:
        return load_u64(p, big_endian);
    }
}

static inline double load_value(const unsigned char *p, rs_ply_type type, bool big_endian) {
    switch (type) {
    case RS_PLY_INT8:
        return (double)(int8_t)p[0];
    case RS_PLY_UINT8:
        return (double)p[0];
    case RS_PLY_INT16:
        return (double)(int16_t)load_u16(p, big_endian);
    case RS_PLY_UINT16:
        return (double)load_u16(p, big_endian);
    case RS_PLY_INT32:
        return (double)(int32_t)load_u32(p, big_endian);
    case RS_PLY_UINT32:
        return (double)load_u32(p, big_endian);
    case RS_PLY_FLOAT32: {
        uint32_t bits = load_u32(p, big_endian);
        float f;
        memcpy(&f, &bits, sizeof f);
        return (double)f;
    }
    case RS_PLY_FLOAT64: {
        uint64_t bits = load_u64(p, big_endian);
        double d;
        memcpy(&d, &bits, sizeof d);
        return d;
    }
    case RS_PLY_NONE:
        break;
    }
    return 0;
}

/* Copies `count` values of `size` bytes, reversing each one's bytes when `swap`. */
static void copy_values(unsigned char *dst, const unsigned char *src, size_t count, size_t size,
                        bool swap) {
    if (!swap || size == 1) {
        memcpy(dst, src, count * size);
        return;
    }
    for (size_t i = 0; i < count; i++, dst += size, src += size)
        for (size_t b = 0; b < size; b++)
            dst[b] = src[size - 1 - b];
}

static rsmooth_status truncated(const ply_reader *r, const rs_ply_element *e, uint64_t item,
                                rsmooth_error *error) {
    return rs_fail_parse(error, -1, (int64_t)r->pos, where,
                         "data ends inside element '%.40s' item %llu (byte %zu)", e->name,
                         (unsigned long long)item, r->pos);
}

/* The common face layout (the list alone, 32-bit indices), decoded without going through double. */
static rsmooth_status read_binary_faces(ply_reader *r, const rs_ply_element *e,
                                        rsmooth_error *error) {
    const bool be = r->encoding == PLY_BINARY_BE;
    const unsigned char *data = (const unsigned char *)r->data;
    const rs_ply_type count_type = e->properties[0].count_type;
    const size_t count_size = rs_ply_type_size(count_type);
    const bool count_signed = is_signed_int(count_type);
    const bool index_signed = e->properties[0].type == RS_PLY_INT32;
    for (uint64_t i = 0; i < e->count; i++) {
        r->face_offsets[i] = (uint32_t)r->indices.count;
        if (r->size - r->pos < count_size)
            return truncated(r, e, i, error);
        size_t count_offset = r->pos;
        uint64_t n = load_uint(data + r->pos, count_size, be);
        r->pos += count_size;
        if (count_signed && n >> (8 * count_size - 1))
            return rs_fail_parse(error, -1, (int64_t)count_offset, where,
                                 "negative list count in face %llu", (unsigned long long)i);
        if (n > (r->size - r->pos) / 4)
            return truncated(r, e, i, error);
        rsmooth_status status = face_begin(r, n, i, -1, (int64_t)count_offset, error);
        if (status != RSMOOTH_OK)
            return status;
        uint32_t *out = r->indices.data + r->indices.count;
        for (uint64_t j = 0; j < n; j++, r->pos += 4) {
            uint32_t v = load_u32(data + r->pos, be);
            if (v >= r->vertex_count || (index_signed && v > INT32_MAX))
                return rs_fail_parse(error, -1, (int64_t)r->pos, where,
                                     "face index %lld out of range (%zu vertices)",
                                     index_signed ? (long long)(int32_t)v : (long long)v,
                                     r->vertex_count);
            out[j] = v;
        }
        r->indices.count += (size_t)n;
    }
    return RSMOOTH_OK;
}

/* A run of stored values copied from each fixed-size item to its row. */
typedef struct copy_run {
    size_t src, dst, len; /* byte offsets in the item and in the row; bytes */
    size_t unit;          /* size of the values to byte-swap, or 0 to copy as they are */
} copy_run;

/* Copies the stored values of an all-scalar element's `count` items of `item_size` bytes (already
 * bounds-checked) into its rows: a memcpy per run of adjacent values. */
static rsmooth_status copy_rows(ply_reader *r, rs_ply_element *e, size_t item_size,
                                rsmooth_error *error) {
    copy_run *runs = rs_alloc_array(e->property_count, sizeof *runs);
    if (!runs)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "element '%.40s'", e->name);
    size_t run_count = 0, src = 0;
    for (size_t k = 0; k < e->property_count; k++) {
        const rs_ply_property *p = &e->properties[k];
        size_t size = rs_ply_type_size(p->type);
        if (p->role == RS_PLY_STORED) {
            size_t unit = r->swap && size > 1 ? size : 0;
            copy_run *last = run_count ? &runs[run_count - 1] : NULL;
            if (last && last->unit == unit && last->src + last->len == src &&
                last->dst + last->len == p->row_offset)
                last->len += size;
            else
                runs[run_count++] = (copy_run){src, p->row_offset, size, unit};
        }
        src += size;
    }
    const unsigned char *data = (const unsigned char *)r->data + r->pos;
    for (size_t i = 0; i < (size_t)e->count; i++) {
        const unsigned char *item = data + i * item_size;
        unsigned char *row = e->rows + i * e->row_size;
        for (size_t k = 0; k < run_count; k++) {
            const copy_run *run = &runs[k];
            if (run->unit == 0)
                memcpy(row + run->dst, item + run->src, run->len);
            else
                copy_values(row + run->dst, item + run->src, run->len / run->unit, run->unit, true);
        }
    }
    rs_free(runs);
    return RSMOOTH_OK;
}

static rsmooth_status read_binary_element(ply_reader *r, rs_ply_element *e, rsmooth_error *error) {
    const bool be = r->encoding == PLY_BINARY_BE;
    const bool is_vertex = e == r->vertex_element, is_face = e == r->face_element;
    const unsigned char *data = (const unsigned char *)r->data;
    bool all_scalar = true;
    size_t item_size = 0;
    for (size_t k = 0; k < e->property_count; k++) {
        const rs_ply_property *p = &e->properties[k];
        all_scalar = all_scalar && p->count_type == RS_PLY_NONE;
        item_size += rs_ply_type_size(p->count_type != RS_PLY_NONE ? p->count_type : p->type);
    }
    /* item_size is the minimum size of an item, checked for every element in read_data. */
    if (all_scalar) {
        if (e->row_size > 0) { /* first: the vertex checks read the colours from the rows */
            rsmooth_status status = copy_rows(r, e, item_size, error);
            if (status != RSMOOTH_OK)
                return status;
        }
        if (is_vertex) {
            /* x, y, z, then nx, ny, nz (when read) */
            size_t offsets[6] = {0, 0, 0, 0, 0, 0};
            rs_ply_type types[6] = {RS_PLY_NONE, RS_PLY_NONE, RS_PLY_NONE,
                                    RS_PLY_NONE, RS_PLY_NONE, RS_PLY_NONE};
            size_t at = 0;
            for (size_t k = 0; k < e->property_count; k++) {
                const rs_ply_property *p = &e->properties[k];
                if (p->role >= RS_PLY_X && p->role <= RS_PLY_NZ) {
                    offsets[p->role - RS_PLY_X] = at;
                    types[p->role - RS_PLY_X] = p->type;
                }
                at += rs_ply_type_size(p->type);
            }
            for (size_t i = 0; i < e->count; i++) {
                const unsigned char *item = data + r->pos + i * item_size;
                double *xyz = r->positions + 3 * i;
                for (int c = 0; c < 3; c++)
                    xyz[c] = load_value(item + offsets[c], types[c], be);
                for (int c = 0; r->normal_values && c < 3; c++)
                    r->normal_values[3 * i + (size_t)c] =
                        load_value(item + offsets[3 + c], types[3 + c], be);
                rsmooth_status status = check_vertex(r, i, -1, (int64_t)(item - data), error);
                if (status != RSMOOTH_OK)
                    return status;
            }
        }
        r->pos += (size_t)e->count * item_size;
        return RSMOOTH_OK;
    }
    if (is_face && e->property_count == 1 &&
        (e->properties[0].type == RS_PLY_INT32 || e->properties[0].type == RS_PLY_UINT32))
        return read_binary_faces(r, e, error);
    for (uint64_t i = 0; i < e->count; i++) {
        const size_t item_start = r->pos;
        unsigned char *row = e->rows ? e->rows + (size_t)i * e->row_size : NULL;
        if (is_face)
            r->face_offsets[i] = (uint32_t)r->indices.count;
        for (size_t k = 0; k < e->property_count; k++) {
            const rs_ply_property *p = &e->properties[k];
            if (p->count_type == RS_PLY_NONE) {
                size_t size = rs_ply_type_size(p->type);
                if (r->size - r->pos < size)
                    return truncated(r, e, i, error);
                const unsigned char *src = data + r->pos;
                if (p->role == RS_PLY_STORED)
                    copy_values(row + p->row_offset, src, 1, size, r->swap);
                else if (p->role >= RS_PLY_X && p->role <= RS_PLY_Z)
                    r->positions[3 * i + (uint64_t)(p->role - RS_PLY_X)] =
                        load_value(src, p->type, be);
                else if (p->role >= RS_PLY_NX && p->role <= RS_PLY_NZ)
                    r->normal_values[3 * i + (uint64_t)(p->role - RS_PLY_NX)] =
                        load_value(src, p->type, be);
                r->pos += size;
                continue;
            }
            size_t count_size = rs_ply_type_size(p->count_type);
            if (r->size - r->pos < count_size)
                return truncated(r, e, i, error);
            size_t count_offset = r->pos;
            uint64_t n = load_uint(data + r->pos, count_size, be);
            if (is_signed_int(p->count_type) && n >> (8 * count_size - 1))
                return rs_fail_parse(error, -1, (int64_t)count_offset, where,
                                     "negative list count in element '%.40s' item %llu", e->name,
                                     (unsigned long long)i);
            r->pos += count_size;
            size_t size = rs_ply_type_size(p->type);
            if (n > (r->size - r->pos) / size)
                return truncated(r, e, i, error);
            if (p->role == RS_PLY_FACE_LIST) {
                rsmooth_status status = face_begin(r, n, i, -1, (int64_t)count_offset, error);
                if (status != RSMOOTH_OK)
                    return status;
                for (uint64_t j = 0; j < n; j++, r->pos += size) {
                    status = face_index(r, load_value(data + r->pos, p->type, be), -1,
                                        (int64_t)r->pos, error);
                    if (status != RSMOOTH_OK)
                        return status;
                }
                continue;
            }
            copy_values(row + p->row_offset, data + count_offset, 1, count_size, r->swap);
            size_t bytes = (size_t)n * size; /* n * size <= the bytes left */
            if (bytes == 0)
                continue; /* list_items may still be NULL */
            if (!list_reserve(e, bytes))
                return list_oom(e, error);
            copy_values(e->list_items + e->list_bytes, data + r->pos, (size_t)n, size, r->swap);
            e->list_bytes += bytes;
            r->pos += bytes;
        }
        if (is_vertex) {
            rsmooth_status status = check_vertex(r, (size_t)i, -1, (int64_t)item_start, error);
            if (status != RSMOOTH_OK)
                return status;
        }
    }
    return RSMOOTH_OK;
}

/* ---- data: ascii */

/* Next whitespace-separated token; counts lines, and sets r->crossed_line when it passed a line
 * end. False at the end of the data. */
static bool next_token(ply_reader *r, const char **token, size_t *len) {
    const char *p = r->data + r->pos, *end = r->data + r->size;
    r->crossed_line = false;
    for (; p < end && is_space(*p); p++)
        if (*p == '\n') {
            r->line++;
            r->crossed_line = true;
        }
    if (p == end) {
        r->pos = r->size;
        return false;
    }
    const char *t = p;
    while (p < end && !is_space(*p))
        p++;
    *token = t;
    *len = (size_t)(p - t);
    r->pos = (size_t)(p - r->data);
    return true;
}

/* Where an ascii item stands: each item is one line, so a value missing from it or one too many
 * is blamed on that line rather than on a later item. */
typedef struct ascii_item {
    const rs_ply_element *element;
    uint64_t index;
    int64_t line;
    size_t start; /* offset of its first value */
    bool started;
} ascii_item;

static rsmooth_status read_ascii_value(ply_reader *r, ascii_item *item, double *value,
                                       size_t *offset, rsmooth_error *error) {
    const char *token;
    size_t len;
    bool found = next_token(r, &token, &len);
    if (found && item->started && r->crossed_line)
        return rs_fail_parse(error, item->line, (int64_t)item->start, where,
                             "element '%.40s' item %llu ends with its line before all the values "
                             "the header declares",
                             item->element->name, (unsigned long long)item->index);
    if (!found)
        return rs_fail_parse(error, r->line, (int64_t)r->size, where,
                             "data ends inside element '%.40s' item %llu", item->element->name,
                             (unsigned long long)item->index);
    *offset = (size_t)(token - r->data);
    if (!item->started) {
        item->started = true;
        item->line = r->line;
        item->start = *offset;
    }
    if (!rs_io_parse_double(token, len, value))
        return rs_fail_parse(error, r->line, (int64_t)*offset, where, "malformed number '%.*s'",
                             (int)(len > 40 ? 40 : len), token);
    return RSMOOTH_OK;
}

/* After an item's values, only blanks may remain on its line. */
static rsmooth_status end_ascii_item(ply_reader *r, const ascii_item *item, rsmooth_error *error) {
    size_t p = r->pos;
    while (p < r->size && r->data[p] != '\n' && is_space(r->data[p]))
        p++;
    if (p == r->size || r->data[p] == '\n')
        return RSMOOTH_OK;
    size_t end = p;
    while (end < r->size && !is_space(r->data[end]))
        end++;
    return rs_fail_parse(error, item->line, (int64_t)p, where,
                         "extra value '%.*s' on the line of element '%.40s' item %llu (more values "
                         "than the header declares)",
                         (int)(end - p > 40 ? 40 : end - p), r->data + p, item->element->name,
                         (unsigned long long)item->index);
}

/* true when a value of type t holds v as written: integers within the type's range and whole
 * (NaN and infinities are not), floats within float range unless written as an infinity or NaN
 * (which the checks of what they are, coordinates or normals, refuse; other properties keep them).
 */
static bool value_fits(rs_ply_type t, double v) {
    switch (t) {
    case RS_PLY_INT8:
        return v == floor(v) && v >= INT8_MIN && v <= INT8_MAX;
    case RS_PLY_UINT8:
        return v == floor(v) && v >= 0 && v <= UINT8_MAX;
    case RS_PLY_INT16:
        return v == floor(v) && v >= INT16_MIN && v <= INT16_MAX;
    case RS_PLY_UINT16:
        return v == floor(v) && v >= 0 && v <= UINT16_MAX;
    case RS_PLY_INT32:
        return v == floor(v) && v >= INT32_MIN && v <= INT32_MAX;
    case RS_PLY_UINT32:
        return v == floor(v) && v >= 0 && v <= UINT32_MAX;
    case RS_PLY_FLOAT32:
        return !isfinite(v) || isfinite((float)v);
    case RS_PLY_FLOAT64:
        return true;
    case RS_PLY_NONE:
        break;
    }
    return false;
}

/* Stores v, which fits type t, as a value of type t (host order). */
static void store_value(unsigned char *dst, rs_ply_type t, double v) {
    switch (t) {
    case RS_PLY_INT8: {
        int8_t x = (int8_t)v;
        memcpy(dst, &x, sizeof x);
        return;
    }
    case RS_PLY_UINT8:
        *dst = (uint8_t)v;
        return;
    case RS_PLY_INT16: {
        int16_t x = (int16_t)v;
        memcpy(dst, &x, sizeof x);
        return;
    }
    case RS_PLY_UINT16: {
        uint16_t x = (uint16_t)v;
        memcpy(dst, &x, sizeof x);
        return;
    }
    case RS_PLY_INT32: {
        int32_t x = (int32_t)v;
        memcpy(dst, &x, sizeof x);
        return;
    }
    case RS_PLY_UINT32: {
        uint32_t x = (uint32_t)v;
        memcpy(dst, &x, sizeof x);
        return;
    }
    case RS_PLY_FLOAT32: {
        float x = (float)v;
        memcpy(dst, &x, sizeof x);
        return;
    }
    case RS_PLY_FLOAT64:
        memcpy(dst, &v, sizeof v);
        return;
    case RS_PLY_NONE:
        break;
    }
}

/* Reads the next value of the item, which must fit `type` (the property's, or its list's count or
 * item type). */
static rsmooth_status read_typed_value(ply_reader *r, ascii_item *item, const rs_ply_property *p,
                                       rs_ply_type type, double *value, size_t *offset,
                                       rsmooth_error *error) {
    rsmooth_status status = read_ascii_value(r, item, value, offset, error);
    if (status == RSMOOTH_OK && !value_fits(type, *value))
        return rs_fail_parse(error, r->line, (int64_t)*offset, where,
                             "value %.17g does not fit the type '%s' of property '%.40s' (element "
                             "'%.40s')",
                             *value, rs_ply_spelling(rs_ply_canonical_spelling(type)), p->name,
                             item->element->name);
    return status;
}

static rsmooth_status read_ascii_element(ply_reader *r, rs_ply_element *e, rsmooth_error *error) {
    const bool is_vertex = e == r->vertex_element, is_face = e == r->face_element;
    rsmooth_status status;
    for (uint64_t i = 0; i < e->count; i++) {
        ascii_item item = {.element = e, .index = i};
        unsigned char *row = e->rows ? e->rows + (size_t)i * e->row_size : NULL;
        if (is_face)
            r->face_offsets[i] = (uint32_t)r->indices.count;
        for (size_t k = 0; k < e->property_count; k++) {
            const rs_ply_property *p = &e->properties[k];
            double v;
            size_t offset;
            if (p->count_type == RS_PLY_NONE) {
                status = read_typed_value(r, &item, p, p->type, &v, &offset, error);
                if (status != RSMOOTH_OK)
                    return status;
                /* as stored in binary: a float property holds a float */
                double stored = p->type == RS_PLY_FLOAT32 ? (double)(float)v : v;
                if (p->role >= RS_PLY_X && p->role <= RS_PLY_Z)
                    r->positions[3 * i + (uint64_t)(p->role - RS_PLY_X)] = stored;
                else if (p->role >= RS_PLY_NX && p->role <= RS_PLY_NZ)
                    r->normal_values[3 * i + (uint64_t)(p->role - RS_PLY_NX)] = stored;
                else if (p->role == RS_PLY_STORED)
                    store_value(row + p->row_offset, p->type, v);
                continue;
            }
            status = read_typed_value(r, &item, p, p->count_type, &v, &offset, error);
            if (status != RSMOOTH_OK)
                return status;
            /* A list: every item takes at least 2 bytes ("1 "), which bounds the count. */
            if (!(v >= 0 && v <= (double)(r->size - r->pos)))
                return rs_fail_parse(error, r->line, (int64_t)offset, where,
                                     "bad list count %.17g in element '%.40s' item %llu", v,
                                     e->name, (unsigned long long)i);
            uint64_t n = (uint64_t)v;
            if (p->role == RS_PLY_FACE_LIST) {
                status = face_begin(r, n, i, r->line, (int64_t)offset, error);
                for (uint64_t j = 0; status == RSMOOTH_OK && j < n; j++) {
                    status = read_typed_value(r, &item, p, p->type, &v, &offset, error);
                    if (status == RSMOOTH_OK)
                        status = face_index(r, v, r->line, (int64_t)offset, error);
                }
                if (status != RSMOOTH_OK)
                    return status;
                continue;
            }
            store_value(row + p->row_offset, p->count_type, v);
            const size_t size = rs_ply_type_size(p->type);
            for (uint64_t j = 0; j < n; j++) {
                status = read_typed_value(r, &item, p, p->type, &v, &offset, error);
                if (status != RSMOOTH_OK)
                    return status;
                if (!list_reserve(e, size))
                    return list_oom(e, error);
                store_value(e->list_items + e->list_bytes, p->type, v);
                e->list_bytes += size;
            }
        }
        status = end_ascii_item(r, &item, error);
        if (status == RSMOOTH_OK && is_vertex)
            status = check_vertex(r, (size_t)i, item.line, (int64_t)item.start, error);
        if (status != RSMOOTH_OK)
            return status;
    }
    return RSMOOTH_OK;
}

/* ---- data: driver */

/* A colour channel as a byte: floats span [0, 1], 16-bit integers their range, other integers
 * are taken as bytes (clamped). */
static uint8_t color_byte(double v, rs_ply_type t) {
    if (rs_ply_type_is_float(t))
        v *= 255;
    else if (t == RS_PLY_UINT16 || t == RS_PLY_INT16)
        v /= 257;
    if (!(v > 0))
        return 0; /* NaN too */
    return v >= 255 ? 255 : (uint8_t)(v + 0.5);
}

static rsmooth_status fill_colors(ply_reader *r, rsmooth_error *error) {
    const rs_ply_element *v = r->vertex_element;
    if (rs_mul_overflows(r->vertex_count, 3))
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "%zu vertex colours",
                       r->vertex_count);
    r->colors = rs_alloc_array(r->vertex_count, 3);
    if (!r->colors)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "%zu vertex colours",
                       r->vertex_count);
    const rs_ply_property *p[3];
    for (int c = 0; c < 3; c++)
        p[c] = &v->properties[r->color[c]];
    for (size_t i = 0; i < r->vertex_count; i++) {
        const unsigned char *row = v->rows + i * v->row_size;
        for (int c = 0; c < 3; c++)
            r->colors[3 * i + (size_t)c] =
                p[c]->type == RS_PLY_UINT8 ? row[p[c]->row_offset]
                                           : color_byte(rs_ply_host_value(row + p[c]->row_offset, p[c]->type),
                                                        p[c]->type);
    }
    return RSMOOTH_OK;
}

static rsmooth_status read_data(ply_reader *r, rsmooth_error *error) {
    for (size_t ei = 0; ei < r->x->element_count; ei++) {
        rs_ply_element *e = &r->x->elements[ei];
        const bool is_vertex = e == r->vertex_element, is_face = e == r->face_element;
        if (e->count == 0 || e->property_count == 0)
            continue; /* nothing stored */
        /* Reject counts the remaining bytes cannot hold before allocating anything for them. */
        size_t min_item = 0;
        for (size_t k = 0; k < e->property_count; k++) {
            const rs_ply_property *p = &e->properties[k];
            if (r->encoding == PLY_ASCII)
                min_item += 2; /* a digit and a separator */
            else
                min_item += rs_ply_type_size(p->count_type != RS_PLY_NONE ? p->count_type : p->type);
        }
        size_t remaining = r->size - r->pos;
        if (r->encoding == PLY_ASCII)
            remaining += 1; /* the last value needs no separator */
        if (e->count > remaining / min_item)
            return rs_fail_parse(
                error, r->encoding == PLY_ASCII ? r->line : -1, (int64_t)r->pos, where,
                "element '%.40s' declares %llu items but only %zu bytes remain", e->name,
                (unsigned long long)e->count, r->size - r->pos);
        /* Now count <= the bytes left, and a row is at most 8 bytes per property. */
        if (e->row_size > 0) {
            if (rs_mul_overflows((size_t)e->count, e->row_size))
                return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "element '%.40s'",
                               e->name);
            e->rows = rs_alloc_array((size_t)e->count, e->row_size);
            if (!e->rows)
                return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where,
                               "%llu items of element '%.40s'", (unsigned long long)e->count,
                               e->name);
        }
        if (is_vertex) {
            r->positions = rs_alloc_array(r->vertex_count, 3 * sizeof(double));
            if (r->normals)
                r->normal_values = rs_alloc_array(r->vertex_count, 3 * sizeof(double));
            if (!r->positions || (r->normals && !r->normal_values))
                return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "%zu vertices",
                               r->vertex_count);
        }
        if (is_face) {
            r->face_count = (size_t)e->count;
            r->face_offsets = rs_alloc_array(r->face_count + 1, sizeof(uint32_t));
            if (!r->face_offsets)
                return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "%zu faces",
                               r->face_count);
            /* Most files are triangle meshes: reserve for that, capped by what the data can hold.
             */
            size_t guess = r->face_count <= SIZE_MAX / 3 ? 3 * r->face_count : r->face_count;
            if (!rs_io_u32vec_reserve(&r->indices, guess))
                return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "%zu face indices",
                               guess);
        }
        rsmooth_status status = r->encoding == PLY_ASCII ? read_ascii_element(r, e, error)
                                                         : read_binary_element(r, e, error);
        if (status != RSMOOTH_OK)
            return status;
        if (is_face)
            r->face_offsets[r->face_count] = (uint32_t)r->indices.count;
        if (e->list_items && e->list_capacity > e->list_bytes) {
            unsigned char *fit = rs_realloc_array(e->list_items, e->list_bytes, 1);
            if (fit) { /* else keep the larger block */
                e->list_items = fit;
                e->list_capacity = e->list_bytes;
            }
        }
        if (is_vertex && r->color[0] != SIZE_MAX) {
            status = fill_colors(r, error);
            if (status != RSMOOTH_OK)
                return status;
        }
    }
    return RSMOOTH_OK;
}

static rsmooth_status find_elements(ply_reader *r, rsmooth_error *error) {
    rs_ply_extras *x = r->x;
    for (size_t ei = 0; ei < x->element_count; ei++) {
        rs_ply_element *e = &x->elements[ei];
        bool vertex = !strcmp(e->name, "vertex");
        bool face = !strcmp(e->name, "face");
        if ((vertex && r->vertex_element) || (face && r->face_element))
            return rs_fail_parse(error, e->header_line, -1, where, "a second '%s' element",
                                 vertex ? "vertex" : "face");
        if (vertex) {
            r->vertex_element = e;
            x->vertex_element = ei;
        }
        if (face) {
            r->face_element = e;
            x->face_element = ei;
        }
    }
    if (!r->vertex_element)
        return rs_fail_parse(error, r->end_header_line, -1, where,
                             "no vertices: the header declares no 'element vertex'");
    if (r->vertex_element->count == 0)
        return rs_fail_parse(error, r->vertex_element->header_line, -1, where,
                             "no vertices: 'element vertex 0'");
    if (r->vertex_element->count >= RS_IO_MAX_VERTICES)
        return rs_fail_parse(error, r->vertex_element->header_line, -1, where,
                             "%llu vertices: too many (indices are 32-bit)",
                             (unsigned long long)r->vertex_element->count);
    r->vertex_count = (size_t)r->vertex_element->count;
    return RSMOOTH_OK;
}

rsmooth_status rs_io_ply_read(const char *data, size_t size, rsmooth_mesh **mesh,
                              rsmooth_error *error) {
    ply_reader r = {.data = data, .size = size, .precision = RSMOOTH_FLOAT32};
    r.x = rs_calloc_array(1, sizeof *r.x);
    if (!r.x)
        return header_oom(error);
    r.x->vertex_element = r.x->face_element = SIZE_MAX;
    rsmooth_status status = parse_header(&r, error);
    if (status == RSMOOTH_OK)
        status = find_elements(&r, error);
    if (status == RSMOOTH_OK)
        status = assign_roles(&r, error);
    if (status == RSMOOTH_OK)
        status = read_data(&r, error);
    uint32_t *indices = r.indices.data;
    if (status == RSMOOTH_OK && !indices) {
        indices = rs_alloc_array(1, sizeof(uint32_t));
        if (!indices)
            status = rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "face indices");
    }
    if (status != RSMOOTH_OK) {
        rs_free(r.positions);
        rs_free(r.normal_values);
        rs_free(r.face_offsets);
        rs_free(r.indices.data);
        rs_free(r.colors);
        rs_io_ply_extras_free(r.x);
        return status;
    }
    rsmooth_format format = r.encoding == PLY_ASCII       ? RSMOOTH_FORMAT_PLY_ASCII
                            : r.encoding == PLY_BINARY_LE ? RSMOOTH_FORMAT_PLY_BINARY
                                                          : RSMOOTH_FORMAT_PLY_BINARY_BE;
    bool plain = is_plain(&r);
    rsmooth_mesh *m = NULL;
    status = rs_io_mesh_adopt(r.positions, r.vertex_count, r.precision, r.face_offsets,
                              r.face_count, indices, format, &m, error);
    if (status != RSMOOTH_OK) {
        rs_free(r.colors);
        rs_free(r.normal_values);
        rs_io_ply_extras_free(r.x);
        return status;
    }
    m->has_vertex_normals = r.normals;
    m->vertex_normals = r.normal_values;
    m->vertex_colors = r.colors;
    if (plain) {
        rs_io_ply_extras_free(r.x);
    } else {
        struct rsmooth_mesh_extras *extras = rs_io_mesh_extras(m);
        if (!extras) {
            rsmooth_mesh_destroy(m);
            rs_io_ply_extras_free(r.x);
            return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "extras record");
        }
        extras->ply = r.x;
    }
    *mesh = m;
    return RSMOOTH_OK;
}
