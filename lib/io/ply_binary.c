/* PLY binary data (little- and big-endian): fixed-size items copied a run at a time, lists item by
 * item. */
#include "io/ply_reader.h"

#include <string.h>

static const char where[] = RS_PLY_READ_WHERE;

static bool is_signed_int(rs_ply_type t) {
    return t == RS_PLY_INT8 || t == RS_PLY_INT16 || t == RS_PLY_INT32;
}

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

static rsmooth_status truncated(const rs_ply_reader *r, const rs_ply_element *e, uint64_t item,
                                rsmooth_error *error) {
    return rs_fail_parse(error, -1, (int64_t)r->pos, where,
                         "data ends inside element '%.40s' item %llu (byte %zu)", e->name,
                         (unsigned long long)item, r->pos);
}

/* The common face layout (the list alone, 32-bit indices), decoded without going through double. */
static rsmooth_status read_binary_faces(rs_ply_reader *r, const rs_ply_element *e,
                                        rsmooth_error *error) {
    const bool be = r->encoding == RS_PLY_BINARY_BE;
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
        rsmooth_status status = rs_ply_face_begin(r, n, i, -1, (int64_t)count_offset, error);
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
static rsmooth_status copy_rows(rs_ply_reader *r, rs_ply_element *e, size_t item_size,
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

/* The x y z (and nx ny nz when read) of an all-scalar vertex element's items of `item_size` bytes,
 * each vertex checked as read (its row already copied). */
static rsmooth_status read_scalar_vertices(rs_ply_reader *r, const rs_ply_element *e,
                                           size_t item_size, rsmooth_error *error) {
    const bool be = r->encoding == RS_PLY_BINARY_BE;
    const unsigned char *data = (const unsigned char *)r->data;
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
        rsmooth_status status = rs_ply_check_vertex(r, i, -1, (int64_t)(item - data), error);
        if (status != RSMOOTH_OK)
            return status;
    }
    return RSMOOTH_OK;
}

/* An element without lists: items of `item_size` bytes, copied to the rows a run at a time. */
static rsmooth_status read_scalar_element(rs_ply_reader *r, rs_ply_element *e, size_t item_size,
                                          rsmooth_error *error) {
    if (e->row_size > 0) { /* first: the vertex checks read the colours from the rows */
        rsmooth_status status = copy_rows(r, e, item_size, error);
        if (status != RSMOOTH_OK)
            return status;
    }
    if (e == r->vertex_element) {
        rsmooth_status status = read_scalar_vertices(r, e, item_size, error);
        if (status != RSMOOTH_OK)
            return status;
    }
    r->pos += (size_t)e->count * item_size;
    return RSMOOTH_OK;
}

/* Scalar property p of item i (bounds-checked): kept in the row, or a coordinate or normal. */
static void read_scalar(rs_ply_reader *r, const rs_ply_property *p, uint64_t i,
                        unsigned char *row) {
    const bool be = r->encoding == RS_PLY_BINARY_BE;
    const unsigned char *src = (const unsigned char *)r->data + r->pos;
    size_t size = rs_ply_type_size(p->type);
    if (p->role == RS_PLY_STORED)
        copy_values(row + p->row_offset, src, 1, size, r->swap);
    else if (p->role >= RS_PLY_X && p->role <= RS_PLY_Z)
        r->positions[3 * i + (uint64_t)(p->role - RS_PLY_X)] = load_value(src, p->type, be);
    else if (p->role >= RS_PLY_NX && p->role <= RS_PLY_NZ)
        r->normal_values[3 * i + (uint64_t)(p->role - RS_PLY_NX)] = load_value(src, p->type, be);
    r->pos += size;
}

/* List property p of item i of element e: a face's vertex indices, or its count kept in the row
 * and its values appended to the element's list items. */
static rsmooth_status read_list(rs_ply_reader *r, rs_ply_element *e, const rs_ply_property *p,
                                uint64_t i, unsigned char *row, rsmooth_error *error) {
    const bool be = r->encoding == RS_PLY_BINARY_BE;
    const unsigned char *data = (const unsigned char *)r->data;
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
        rsmooth_status status = rs_ply_face_begin(r, n, i, -1, (int64_t)count_offset, error);
        if (status != RSMOOTH_OK)
            return status;
        for (uint64_t j = 0; j < n; j++, r->pos += size) {
            status = rs_ply_face_index(r, load_value(data + r->pos, p->type, be), -1,
                                       (int64_t)r->pos, error);
            if (status != RSMOOTH_OK)
                return status;
        }
        return RSMOOTH_OK;
    }
    if (p->role == RS_PLY_GRID_LIST) {
        rsmooth_status status = rs_ply_grid_cell(r, n, i, -1, (int64_t)count_offset, error);
        for (uint64_t j = 0; status == RSMOOTH_OK && j < n; j++, r->pos += size)
            status = rs_ply_grid_index(r, load_value(data + r->pos, p->type, be), i, -1,
                                       (int64_t)r->pos, error);
        return status;
    }
    copy_values(row + p->row_offset, data + count_offset, 1, count_size, r->swap);
    size_t bytes = (size_t)n * size; /* n * size <= the bytes left */
    if (bytes == 0)
        return RSMOOTH_OK; /* list_items may still be NULL */
    if (!rs_ply_list_reserve(e, bytes))
        return rs_ply_list_oom(e, error);
    copy_values(e->list_items + e->list_bytes, data + r->pos, (size_t)n, size, r->swap);
    e->list_bytes += bytes;
    r->pos += bytes;
    return RSMOOTH_OK;
}

/* An element with lists, item by item and property by property. */
static rsmooth_status read_items(rs_ply_reader *r, rs_ply_element *e, rsmooth_error *error) {
    const bool is_vertex = e == r->vertex_element, is_face = e == r->face_element;
    for (uint64_t i = 0; i < e->count; i++) {
        const size_t item_start = r->pos;
        unsigned char *row = e->rows ? e->rows + (size_t)i * e->row_size : NULL;
        if (is_face)
            r->face_offsets[i] = (uint32_t)r->indices.count;
        for (size_t k = 0; k < e->property_count; k++) {
            const rs_ply_property *p = &e->properties[k];
            if (p->count_type == RS_PLY_NONE) {
                if (r->size - r->pos < rs_ply_type_size(p->type))
                    return truncated(r, e, i, error);
                read_scalar(r, p, i, row);
                continue;
            }
            rsmooth_status status = read_list(r, e, p, i, row, error);
            if (status != RSMOOTH_OK)
                return status;
        }
        if (is_vertex) {
            rsmooth_status status =
                rs_ply_check_vertex(r, (size_t)i, -1, (int64_t)item_start, error);
            if (status != RSMOOTH_OK)
                return status;
        }
    }
    return RSMOOTH_OK;
}

rsmooth_status rs_ply_read_binary_element(rs_ply_reader *r, rs_ply_element *e,
                                          rsmooth_error *error) {
    bool all_scalar = true;
    size_t item_size = 0;
    for (size_t k = 0; k < e->property_count; k++) {
        const rs_ply_property *p = &e->properties[k];
        all_scalar = all_scalar && p->count_type == RS_PLY_NONE;
        item_size += rs_ply_type_size(p->count_type != RS_PLY_NONE ? p->count_type : p->type);
    }
    /* item_size is the minimum size of an item, checked for every element in read_data. */
    if (all_scalar)
        return read_scalar_element(r, e, item_size, error);
    if (e == r->face_element && e->property_count == 1 &&
        (e->properties[0].type == RS_PLY_INT32 || e->properties[0].type == RS_PLY_UINT32))
        return read_binary_faces(r, e, error);
    return read_items(r, e, error);
}
