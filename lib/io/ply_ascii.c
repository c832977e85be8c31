/* PLY ascii data: one item a line, each value checked against its property's type. */
#include "io/ply_reader.h"

#include <math.h>
#include <string.h>

static const char where[] = RS_PLY_READ_WHERE;

/* Next whitespace-separated token; counts lines, and sets r->crossed_line when it passed a line
 * end. False at the end of the data. */
static bool next_token(rs_ply_reader *r, const char **token, size_t *len) {
    const char *p = r->data + r->pos, *end = r->data + r->size;
    r->crossed_line = false;
    for (; p < end && rs_ply_is_space(*p); p++)
        if (*p == '\n') {
            r->line++;
            r->crossed_line = true;
        }
    if (p == end) {
        r->pos = r->size;
        return false;
    }
    const char *t = p;
    while (p < end && !rs_ply_is_space(*p))
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

static rsmooth_status read_ascii_value(rs_ply_reader *r, ascii_item *item, double *value,
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
static rsmooth_status end_ascii_item(rs_ply_reader *r, const ascii_item *item,
                                     rsmooth_error *error) {
    size_t p = r->pos;
    while (p < r->size && r->data[p] != '\n' && rs_ply_is_space(r->data[p]))
        p++;
    if (p == r->size || r->data[p] == '\n')
        return RSMOOTH_OK;
    size_t end = p;
    while (end < r->size && !rs_ply_is_space(r->data[end]))
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
static rsmooth_status read_typed_value(rs_ply_reader *r, ascii_item *item, const rs_ply_property *p,
                                       rs_ply_type type, double *value, size_t *offset,
                                       rsmooth_error *error) {
    rsmooth_status status = read_ascii_value(r, item, value, offset, error);
    if (status == RSMOOTH_OK && !value_fits(type, *value))
        return rs_fail_parse(error, r->line, (int64_t)*offset, where,
                             "value %.17g does not fit the type '%s' of property '%.40s' (element "
                             "'%.40s')",
                             *value, rs_ply_spelling(rs_ply_canonical_spelling(type)), p->name,
                             item->element->name);
    if (type != RS_PLY_FLOAT32 && type != RS_PLY_FLOAT64)
        *value += 0.0; /* an integer has no sign of zero: "-0" is 0, as binary stores it */
    return status;
}

rsmooth_status rs_ply_read_ascii_element(rs_ply_reader *r, rs_ply_element *e,
                                         rsmooth_error *error) {
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
                status = rs_ply_face_begin(r, n, i, r->line, (int64_t)offset, error);
                for (uint64_t j = 0; status == RSMOOTH_OK && j < n; j++) {
                    status = read_typed_value(r, &item, p, p->type, &v, &offset, error);
                    if (status == RSMOOTH_OK)
                        status = rs_ply_face_index(r, v, r->line, (int64_t)offset, error);
                }
                if (status != RSMOOTH_OK)
                    return status;
                continue;
            }
            if (p->role == RS_PLY_GRID_LIST) {
                status = rs_ply_grid_cell(r, n, i, r->line, (int64_t)offset, error);
                for (uint64_t j = 0; status == RSMOOTH_OK && j < n; j++) {
                    status = read_typed_value(r, &item, p, p->type, &v, &offset, error);
                    if (status == RSMOOTH_OK)
                        status = rs_ply_grid_index(r, v, i, r->line, (int64_t)offset, error);
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
                if (!rs_ply_list_reserve(e, size))
                    return rs_ply_list_oom(e, error);
                store_value(e->list_items + e->list_bytes, p->type, v);
                e->list_bytes += size;
            }
        }
        status = end_ascii_item(r, &item, error);
        if (status == RSMOOTH_OK && is_vertex)
            status = rs_ply_check_vertex(r, (size_t)i, item.line, (int64_t)item.start, error);
        if (status != RSMOOTH_OK)
            return status;
    }
    return RSMOOTH_OK;
}
