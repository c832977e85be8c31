/* Stanford PLY parser over a memory buffer (ascii, binary LE and BE): vertex x/y/z, face lists. */
#include "io/io_internal.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char where[] = "rsmooth_mesh_read (PLY)";

typedef enum ply_type {
    PLY_NONE = 0,
    PLY_INT8,
    PLY_UINT8,
    PLY_INT16,
    PLY_UINT16,
    PLY_INT32,
    PLY_UINT32,
    PLY_FLOAT32,
    PLY_FLOAT64
} ply_type;

static const size_t type_size[] = {0, 1, 1, 2, 2, 4, 4, 4, 8};

typedef struct ply_property {
    const char *name; /* into the buffer, not NUL-terminated */
    size_t name_len;
    ply_type type;       /* scalar type, or the item type of a list */
    ply_type count_type; /* PLY_NONE for scalars */
} ply_property;

typedef struct ply_element {
    const char *name;
    size_t name_len;
    uint64_t count;
    size_t first_property;
    size_t property_count;
    int64_t header_line;
} ply_element;

typedef enum ply_encoding { PLY_ASCII, PLY_BINARY_LE, PLY_BINARY_BE } ply_encoding;

typedef struct ply_reader {
    const char *data;
    size_t size;
    size_t pos;   /* read position in data */
    int64_t line; /* ascii: current line, 1-based */
    ply_encoding encoding;
    ply_property *properties;
    size_t property_count, property_capacity;
    ply_element *elements;
    size_t element_count, element_capacity;
    /* results */
    const ply_element *vertex_element, *face_element;
    size_t vertex_count;
    double *positions;
    rsmooth_scalar precision;
    uint32_t *face_offsets;
    size_t face_count;
    rs_io_u32vec indices;
} ply_reader;

static bool is_space(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f' || c == '\n';
}

static bool token_is(const char *token, size_t len, const char *word) {
    size_t n = strlen(word);
    return len == n && memcmp(token, word, n) == 0;
}

static ply_type parse_type(const char *token, size_t len) {
    static const struct {
        const char *name;
        ply_type type;
    } names[] = {{"char", PLY_INT8},      {"int8", PLY_INT8},       {"uchar", PLY_UINT8},
                 {"uint8", PLY_UINT8},    {"short", PLY_INT16},     {"int16", PLY_INT16},
                 {"ushort", PLY_UINT16},  {"uint16", PLY_UINT16},   {"int", PLY_INT32},
                 {"int32", PLY_INT32},    {"uint", PLY_UINT32},     {"uint32", PLY_UINT32},
                 {"float", PLY_FLOAT32},  {"float32", PLY_FLOAT32}, {"double", PLY_FLOAT64},
                 {"float64", PLY_FLOAT64}};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        if (token_is(token, len, names[i].name))
            return names[i].type;
    return PLY_NONE;
}

/* ---- header */

#define MAX_HEADER_TOKENS 8

static rsmooth_status header_error(const ply_reader *r, size_t offset, rsmooth_error *error,
                                   const char *message, const char *token, size_t len) {
    return rs_fail_parse(error, r->line, (int64_t)offset, where, "%s '%.*s'", message,
                         (int)(len > 40 ? 40 : len), token);
}

static rsmooth_status add_property(ply_reader *r, const char *const *tok, const size_t *len, int n,
                                   size_t offset, rsmooth_error *error) {
    if (r->element_count == 0)
        return header_error(r, offset, error, "property before any element:", tok[0], len[0]);
    ply_property prop = {0};
    if (n >= 2 && token_is(tok[1], len[1], "list")) {
        if (n != 5)
            return header_error(r, offset, error,
                                "expected 'property list COUNTTYPE TYPE NAME':", tok[0], len[0]);
        prop.count_type = parse_type(tok[2], len[2]);
        prop.type = parse_type(tok[3], len[3]);
        if (prop.count_type == PLY_NONE)
            return header_error(r, (size_t)(tok[2] - r->data), error, "unknown type", tok[2],
                                len[2]);
        if (prop.type == PLY_NONE)
            return header_error(r, (size_t)(tok[3] - r->data), error, "unknown type", tok[3],
                                len[3]);
        if (prop.count_type == PLY_FLOAT32 || prop.count_type == PLY_FLOAT64)
            return header_error(r, (size_t)(tok[2] - r->data), error,
                                "list count type must be an integer:", tok[2], len[2]);
        prop.name = tok[4];
        prop.name_len = len[4];
    } else {
        if (n != 3)
            return header_error(r, offset, error, "expected 'property TYPE NAME':", tok[0], len[0]);
        prop.type = parse_type(tok[1], len[1]);
        if (prop.type == PLY_NONE)
            return header_error(r, (size_t)(tok[1] - r->data), error, "unknown type", tok[1],
                                len[1]);
        prop.name = tok[2];
        prop.name_len = len[2];
    }
    if (r->property_count == r->property_capacity) {
        size_t capacity = r->property_capacity ? 2 * r->property_capacity : 16;
        ply_property *p = rs_realloc_array(r->properties, capacity, sizeof *p);
        if (!p)
            return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "header properties");
        r->properties = p;
        r->property_capacity = capacity;
    }
    r->properties[r->property_count++] = prop;
    r->elements[r->element_count - 1].property_count++;
    return RSMOOTH_OK;
}

static rsmooth_status add_element(ply_reader *r, const char *const *tok, const size_t *len, int n,
                                  size_t offset, rsmooth_error *error) {
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
    if (r->element_count == r->element_capacity) {
        size_t capacity = r->element_capacity ? 2 * r->element_capacity : 8;
        ply_element *e = rs_realloc_array(r->elements, capacity, sizeof *e);
        if (!e)
            return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "header elements");
        r->elements = e;
        r->element_capacity = capacity;
    }
    ply_element e = {.name = tok[1],
                     .name_len = len[1],
                     .count = count,
                     .first_property = r->property_count,
                     .header_line = r->line};
    r->elements[r->element_count++] = e;
    return RSMOOTH_OK;
}

static rsmooth_status parse_header(ply_reader *r, rsmooth_error *error) {
    const char *data = r->data;
    /* Magic: "ply" alone on the first line. */
    if (r->size < 4 || memcmp(data, "ply", 3) != 0 ||
        !(data[3] == '\n' || (data[3] == '\r' && r->size > 4 && data[4] == '\n')))
        return rs_fail_parse(error, 1, 0, where, "not a PLY file (the first line is not 'ply')");
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
            continue;
        } else if (token_is(tok[0], len[0], "end_header")) {
            if (n != 1)
                return header_error(r, offset, error, "bad header line:", tok[0], len[0]);
            if (!have_format)
                return rs_fail_parse(error, r->line, (int64_t)offset, where,
                                     "header has no 'format' line");
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

/* ---- data: shared */

/* Roles of the properties the reader keeps. */
typedef struct element_plan {
    const ply_element *element;
    const ply_property *props;
    int xyz[3];     /* property index of x, y, z in a vertex element, else -1 */
    int face_list;  /* property index of vertex_indices in the face element, else -1 */
    bool is_vertex; /* the element whose coordinates are kept */
    bool is_face;
} element_plan;

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

static inline double load_value(const unsigned char *p, ply_type type, bool big_endian) {
    switch (type) {
    case PLY_INT8:
        return (double)(int8_t)p[0];
    case PLY_UINT8:
        return (double)p[0];
    case PLY_INT16:
        return (double)(int16_t)load_u16(p, big_endian);
    case PLY_UINT16:
        return (double)load_u16(p, big_endian);
    case PLY_INT32:
        return (double)(int32_t)load_u32(p, big_endian);
    case PLY_UINT32:
        return (double)load_u32(p, big_endian);
    case PLY_FLOAT32: {
        uint32_t bits = load_u32(p, big_endian);
        float f;
        memcpy(&f, &bits, sizeof f);
        return (double)f;
    }
    case PLY_FLOAT64: {
        uint64_t bits = load_u64(p, big_endian);
        double d;
        memcpy(&d, &bits, sizeof d);
        return d;
    }
    case PLY_NONE:
        break;
    }
    return 0;
}

static rsmooth_status truncated(const ply_reader *r, const element_plan *plan, uint64_t item,
                                rsmooth_error *error) {
    return rs_fail_parse(
        error, -1, (int64_t)r->pos, where, "data ends inside element '%.*s' item %llu (byte %zu)",
        (int)plan->element->name_len, plan->element->name, (unsigned long long)item, r->pos);
}

/* The common face layout (the list alone, 32-bit indices), decoded without going through double. */
static rsmooth_status read_binary_faces(ply_reader *r, const element_plan *plan,
                                        rsmooth_error *error) {
    const bool be = r->encoding == PLY_BINARY_BE;
    const unsigned char *data = (const unsigned char *)r->data;
    const ply_type count_type = plan->props[0].count_type;
    const size_t count_size = type_size[count_type];
    const bool count_signed =
        count_type == PLY_INT8 || count_type == PLY_INT16 || count_type == PLY_INT32;
    const bool index_signed = plan->props[0].type == PLY_INT32;
    for (uint64_t i = 0; i < plan->element->count; i++) {
        r->face_offsets[i] = (uint32_t)r->indices.count;
        if (r->size - r->pos < count_size)
            return truncated(r, plan, i, error);
        size_t count_offset = r->pos;
        uint64_t n = load_uint(data + r->pos, count_size, be);
        r->pos += count_size;
        if (count_signed && n >> (8 * count_size - 1))
            return rs_fail_parse(error, -1, (int64_t)count_offset, where,
                                 "negative list count in face %llu", (unsigned long long)i);
        if (n > (r->size - r->pos) / 4)
            return truncated(r, plan, i, error);
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

static rsmooth_status read_binary_element(ply_reader *r, const element_plan *plan,
                                          rsmooth_error *error) {
    const bool be = r->encoding == PLY_BINARY_BE;
    const ply_element *e = plan->element;
    const unsigned char *data = (const unsigned char *)r->data;
    bool all_scalar = true;
    size_t item_size = 0;
    for (size_t k = 0; k < e->property_count; k++) {
        all_scalar = all_scalar && plan->props[k].count_type == PLY_NONE;
        item_size += plan->props[k].count_type == PLY_NONE ? type_size[plan->props[k].type]
                                                           : type_size[plan->props[k].count_type];
    }
    /* item_size is the minimum size of an item, checked for every element in read_data. */
    if (all_scalar) {
        size_t offsets[3] = {0, 0, 0};
        ply_type types[3] = {PLY_NONE, PLY_NONE, PLY_NONE};
        if (plan->is_vertex) {
            for (int c = 0; c < 3; c++) {
                for (int k = 0; k < plan->xyz[c]; k++)
                    offsets[c] += type_size[plan->props[k].type];
                types[c] = plan->props[plan->xyz[c]].type;
            }
            for (size_t i = 0; i < e->count; i++) {
                const unsigned char *item = data + r->pos + i * item_size;
                double *xyz = r->positions + 3 * i;
                for (int c = 0; c < 3; c++)
                    xyz[c] = load_value(item + offsets[c], types[c], be);
                if (!isfinite(xyz[0]) || !isfinite(xyz[1]) || !isfinite(xyz[2]))
                    return rs_fail_parse(error, -1, (int64_t)(item - data), where,
                                         "vertex %zu has a non-finite coordinate", i);
            }
        }
        r->pos += (size_t)e->count * item_size;
        return RSMOOTH_OK;
    }
    if (plan->is_face && e->property_count == 1 &&
        (plan->props[0].type == PLY_INT32 || plan->props[0].type == PLY_UINT32))
        return read_binary_faces(r, plan, error);
    for (uint64_t i = 0; i < e->count; i++) {
        const size_t item_start = r->pos;
        if (plan->is_face)
            r->face_offsets[i] = (uint32_t)r->indices.count;
        for (size_t k = 0; k < e->property_count; k++) {
            const ply_property *prop = &plan->props[k];
            if (prop->count_type == PLY_NONE) {
                size_t size = type_size[prop->type];
                if (r->size - r->pos < size)
                    return truncated(r, plan, i, error);
                if (plan->is_vertex &&
                    ((int)k == plan->xyz[0] || (int)k == plan->xyz[1] || (int)k == plan->xyz[2])) {
                    int c = (int)k == plan->xyz[0] ? 0 : (int)k == plan->xyz[1] ? 1 : 2;
                    r->positions[3 * i + (uint64_t)c] = load_value(data + r->pos, prop->type, be);
                }
                r->pos += size;
                continue;
            }
            size_t count_size = type_size[prop->count_type];
            if (r->size - r->pos < count_size)
                return truncated(r, plan, i, error);
            double count = load_value(data + r->pos, prop->count_type, be);
            size_t count_offset = r->pos;
            r->pos += count_size;
            size_t size = type_size[prop->type];
            if (count < 0 || count > (double)((r->size - r->pos) / size)) {
                if (count < 0)
                    return rs_fail_parse(error, -1, (int64_t)count_offset, where,
                                         "negative list count %.0f", count);
                return truncated(r, plan, i, error);
            }
            uint64_t n = (uint64_t)count;
            if (plan->is_face && (int)k == plan->face_list) {
                rsmooth_status status = face_begin(r, n, i, -1, (int64_t)count_offset, error);
                if (status != RSMOOTH_OK)
                    return status;
                for (uint64_t j = 0; j < n; j++, r->pos += size) {
                    status = face_index(r, load_value(data + r->pos, prop->type, be), -1,
                                        (int64_t)r->pos, error);
                    if (status != RSMOOTH_OK)
                        return status;
                }
            } else {
                r->pos += (size_t)n * size;
            }
        }
        if (plan->is_vertex) {
            const double *xyz = r->positions + 3 * i;
            if (!isfinite(xyz[0]) || !isfinite(xyz[1]) || !isfinite(xyz[2]))
                return rs_fail_parse(error, -1, (int64_t)item_start, where,
                                     "vertex %llu has a non-finite coordinate",
                                     (unsigned long long)i);
        }
    }
    return RSMOOTH_OK;
}

/* ---- data: ascii */

/* Next whitespace-separated token; counts lines. False at the end of the data. */
static bool next_token(ply_reader *r, const char **token, size_t *len) {
    const char *p = r->data + r->pos, *end = r->data + r->size;
    for (; p < end && is_space(*p); p++)
        if (*p == '\n')
            r->line++;
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

static rsmooth_status read_ascii_value(ply_reader *r, const element_plan *plan, uint64_t item,
                                       double *value, size_t *offset, rsmooth_error *error) {
    const char *token;
    size_t len;
    if (!next_token(r, &token, &len))
        return rs_fail_parse(
            error, r->line, (int64_t)r->size, where, "data ends inside element '%.*s' item %llu",
            (int)plan->element->name_len, plan->element->name, (unsigned long long)item);
    *offset = (size_t)(token - r->data);
    if (!rs_io_parse_double(token, len, value))
        return rs_fail_parse(error, r->line, (int64_t)*offset, where, "malformed number '%.*s'",
                             (int)(len > 40 ? 40 : len), token);
    return RSMOOTH_OK;
}

static rsmooth_status read_ascii_element(ply_reader *r, const element_plan *plan,
                                         rsmooth_error *error) {
    const ply_element *e = plan->element;
    rsmooth_status status;
    for (uint64_t i = 0; i < e->count; i++) {
        size_t item_start = 0;
        int64_t item_line = 0;
        if (plan->is_face)
            r->face_offsets[i] = (uint32_t)r->indices.count;
        for (size_t k = 0; k < e->property_count; k++) {
            const ply_property *prop = &plan->props[k];
            double v;
            size_t offset;
            status = read_ascii_value(r, plan, i, &v, &offset, error);
            if (status != RSMOOTH_OK)
                return status;
            if (k == 0) {
                item_start = offset;
                item_line = r->line;
            }
            if (prop->count_type == PLY_NONE) {
                if (plan->is_vertex) {
                    for (int c = 0; c < 3; c++)
                        if ((int)k == plan->xyz[c])
                            /* as stored in binary: a float property holds a float */
                            r->positions[3 * i + (uint64_t)c] =
                                prop->type == PLY_FLOAT32 ? (double)(float)v : v;
                }
                continue;
            }
            /* A list: every item takes at least 2 bytes ("1 "), which bounds the count. */
            if (!(v >= 0 && v == floor(v) && v <= (double)(r->size - r->pos)))
                return rs_fail_parse(error, r->line, (int64_t)offset, where,
                                     "bad list count %.17g in element '%.*s' item %llu", v,
                                     (int)e->name_len, e->name, (unsigned long long)i);
            uint64_t n = (uint64_t)v;
            bool is_face_list = plan->is_face && (int)k == plan->face_list;
            if (is_face_list) {
                status = face_begin(r, n, i, r->line, (int64_t)offset, error);
                if (status != RSMOOTH_OK)
                    return status;
            }
            for (uint64_t j = 0; j < n; j++) {
                status = read_ascii_value(r, plan, i, &v, &offset, error);
                if (status != RSMOOTH_OK)
                    return status;
                if (is_face_list) {
                    status = face_index(r, v, r->line, (int64_t)offset, error);
                    if (status != RSMOOTH_OK)
                        return status;
                }
            }
        }
        if (plan->is_vertex) {
            const double *xyz = r->positions + 3 * i;
            if (!isfinite(xyz[0]) || !isfinite(xyz[1]) || !isfinite(xyz[2]))
                return rs_fail_parse(error, item_line, (int64_t)item_start, where,
                                     "vertex %llu has a non-finite coordinate",
                                     (unsigned long long)i);
        }
    }
    return RSMOOTH_OK;
}

/* ---- data: driver */

static rsmooth_status plan_element(ply_reader *r, const ply_element *e, element_plan *plan,
                                   rsmooth_error *error) {
    memset(plan, 0, sizeof *plan);
    plan->element = e;
    plan->props = r->properties ? r->properties + e->first_property : NULL;
    plan->xyz[0] = plan->xyz[1] = plan->xyz[2] = -1;
    plan->face_list = -1;
    plan->is_vertex = e == r->vertex_element;
    plan->is_face = e == r->face_element;
    static const char *const axis[3] = {"x", "y", "z"};
    for (size_t k = 0; k < e->property_count; k++) {
        const ply_property *prop = &plan->props[k];
        if (plan->is_vertex) {
            for (int c = 0; c < 3; c++) {
                if (plan->xyz[c] < 0 && token_is(prop->name, prop->name_len, axis[c])) {
                    if (prop->count_type != PLY_NONE)
                        return rs_fail_parse(error, e->header_line, -1, where,
                                             "vertex property '%s' is a list", axis[c]);
                    plan->xyz[c] = (int)k;
                }
            }
        }
        if (plan->is_face && plan->face_list < 0 && prop->count_type != PLY_NONE &&
            (token_is(prop->name, prop->name_len, "vertex_indices") ||
             token_is(prop->name, prop->name_len, "vertex_index")))
            plan->face_list = (int)k;
    }
    if (plan->is_vertex) {
        for (int c = 0; c < 3; c++)
            if (plan->xyz[c] < 0)
                return rs_fail_parse(error, e->header_line, -1, where,
                                     "vertex element has no '%s' property", axis[c]);
        for (int c = 0; c < 3; c++)
            if (plan->props[plan->xyz[c]].type == PLY_FLOAT64)
                r->precision = RSMOOTH_FLOAT64;
    }
    if (plan->is_face && plan->face_list < 0)
        return rs_fail_parse(error, e->header_line, -1, where,
                             "face element has no 'vertex_indices' list property");
    return RSMOOTH_OK;
}

static rsmooth_status read_data(ply_reader *r, rsmooth_error *error) {
    for (size_t ei = 0; ei < r->element_count; ei++) {
        const ply_element *e = &r->elements[ei];
        element_plan plan;
        rsmooth_status status = plan_element(r, e, &plan, error);
        if (status != RSMOOTH_OK)
            return status;
        if (e->count == 0 || e->property_count == 0)
            continue; /* nothing stored */
        /* Reject counts the remaining bytes cannot hold before allocating anything for them. */
        size_t min_item = 0;
        for (size_t k = 0; k < e->property_count; k++) {
            const ply_property *prop = &plan.props[k];
            if (r->encoding == PLY_ASCII)
                min_item += 2; /* a digit and a separator */
            else
                min_item += type_size[prop->count_type != PLY_NONE ? prop->count_type : prop->type];
        }
        size_t remaining = r->size - r->pos;
        if (r->encoding == PLY_ASCII)
            remaining += 1; /* the last value needs no separator */
        if (e->count > remaining / min_item)
            return rs_fail_parse(
                error, r->encoding == PLY_ASCII ? r->line : -1, (int64_t)r->pos, where,
                "element '%.*s' declares %llu items but only %zu bytes remain", (int)e->name_len,
                e->name, (unsigned long long)e->count, r->size - r->pos);
        if (plan.is_vertex) {
            r->positions = rs_alloc_array(r->vertex_count, 3 * sizeof(double));
            if (!r->positions)
                return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "%zu vertices",
                               r->vertex_count);
        }
        if (plan.is_face) {
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
        status = r->encoding == PLY_ASCII ? read_ascii_element(r, &plan, error)
                                          : read_binary_element(r, &plan, error);
        if (status != RSMOOTH_OK)
            return status;
        if (plan.is_face)
            r->face_offsets[r->face_count] = (uint32_t)r->indices.count;
    }
    return RSMOOTH_OK;
}

static rsmooth_status find_elements(ply_reader *r, rsmooth_error *error) {
    for (size_t ei = 0; ei < r->element_count; ei++) {
        const ply_element *e = &r->elements[ei];
        bool vertex = token_is(e->name, e->name_len, "vertex");
        bool face = token_is(e->name, e->name_len, "face");
        if ((vertex && r->vertex_element) || (face && r->face_element))
            return rs_fail_parse(error, e->header_line, -1, where, "a second '%s' element",
                                 vertex ? "vertex" : "face");
        if (vertex)
            r->vertex_element = e;
        if (face)
            r->face_element = e;
    }
    if (!r->vertex_element || r->vertex_element->count == 0)
        return rs_fail_parse(error, -1, -1, where, "no vertices");
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
    rsmooth_status status = parse_header(&r, error);
    if (status == RSMOOTH_OK)
        status = find_elements(&r, error);
    if (status == RSMOOTH_OK)
        status = read_data(&r, error);
    rs_free(r.properties);
    rs_free(r.elements);
    if (status != RSMOOTH_OK) {
        rs_free(r.positions);
        rs_free(r.face_offsets);
        rs_free(r.indices.data);
        return status;
    }
    uint32_t *indices = r.indices.data;
    if (!indices)
        indices = rs_alloc_array(1, sizeof(uint32_t));
    if (!indices) {
        rs_free(r.positions);
        rs_free(r.face_offsets);
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "face indices");
    }
    rsmooth_format format = r.encoding == PLY_ASCII       ? RSMOOTH_FORMAT_PLY_ASCII
                            : r.encoding == PLY_BINARY_LE ? RSMOOTH_FORMAT_PLY_BINARY
                                                          : RSMOOTH_FORMAT_PLY_BINARY_BE;
    return rs_io_mesh_adopt(r.positions, r.vertex_count, r.precision, r.face_offsets, r.face_count,
                            indices, format, mesh, error);
}
