/* Stanford PLY reader (ascii, binary LE and BE): drives the header and data readers and builds the
 * mesh; all else the file holds goes into the PLY extras. */
#include "io/ply_reader.h"

#include <math.h>
#include <string.h>

static const char where[] = RS_PLY_READ_WHERE;

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

static rsmooth_status fill_colors(rs_ply_reader *r, rsmooth_error *error) {
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
                p[c]->type == RS_PLY_UINT8
                    ? row[p[c]->row_offset]
                    : color_byte(rs_ply_host_value(row + p[c]->row_offset, p[c]->type), p[c]->type);
    }
    return RSMOOTH_OK;
}

static rsmooth_status read_data(rs_ply_reader *r, rsmooth_error *error) {
    for (size_t ei = 0; ei < r->x->element_count; ei++) {
        rs_ply_element *e = &r->x->elements[ei];
        const bool is_vertex = e == r->vertex_element, is_face = e == r->face_element;
        if (e->count == 0 || e->property_count == 0)
            continue; /* nothing stored */
        /* Reject counts the remaining bytes cannot hold before allocating anything for them. */
        size_t min_item = 0;
        for (size_t k = 0; k < e->property_count; k++) {
            const rs_ply_property *p = &e->properties[k];
            if (r->encoding == RS_PLY_ASCII)
                min_item += 2; /* a digit and a separator */
            else
                min_item +=
                    rs_ply_type_size(p->count_type != RS_PLY_NONE ? p->count_type : p->type);
        }
        size_t remaining = r->size - r->pos;
        if (r->encoding == RS_PLY_ASCII)
            remaining += 1; /* the last value needs no separator */
        if (e->count > remaining / min_item)
            return rs_fail_parse(error, r->encoding == RS_PLY_ASCII ? r->line : -1, (int64_t)r->pos,
                                 where,
                                 "element '%.40s' declares %llu items but only %zu bytes remain",
                                 e->name, (unsigned long long)e->count, r->size - r->pos);
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
        if (e == r->grid_element) {
            r->grid_cells = rs_alloc_array((size_t)e->count, sizeof(uint32_t));
            r->grid_owner = rs_calloc_array(r->vertex_count, sizeof(uint64_t));
            if (!r->grid_cells || !r->grid_owner)
                return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where,
                               "range grid of %llu cells", (unsigned long long)e->count);
            memset(r->grid_cells, 0xff, (size_t)e->count * sizeof(uint32_t)); /* no sample */
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
        rsmooth_status status = r->encoding == RS_PLY_ASCII
                                    ? rs_ply_read_ascii_element(r, e, error)
                                    : rs_ply_read_binary_element(r, e, error);
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

/* After the last element only blanks may follow (line ends some writers append): anything else is
 * data the header's counts leave out, which a reader would silently drop. */
static rsmooth_status check_end(rs_ply_reader *r, rsmooth_error *error) {
    size_t p = r->pos;
    int64_t line = r->line;
    for (; p < r->size && rs_ply_is_space(r->data[p]); p++)
        if (r->data[p] == '\n')
            line++;
    if (p == r->size)
        return RSMOOTH_OK;
    if (r->encoding != RS_PLY_ASCII)
        return rs_fail_parse(
            error, -1, (int64_t)p, where,
            "%zu bytes after the data the header declares (from byte %zu, 0x%02x): "
            "the header's counts leave data out",
            r->size - p, p, (unsigned)(unsigned char)r->data[p]);
    size_t end = p;
    while (end < r->size && !rs_ply_is_space(r->data[end]))
        end++;
    return rs_fail_parse(error, line, (int64_t)p, where,
                         "'%.*s' after the data the header declares: the header's counts leave "
                         "data out",
                         (int)(end - p > 40 ? 40 : end - p), r->data + p);
}

rsmooth_status rs_io_ply_read(const char *data, size_t size, rsmooth_mesh **mesh,
                              rsmooth_error *error) {
    rs_ply_reader r = {.data = data, .size = size, .precision = RSMOOTH_FLOAT32};
    r.x = rs_calloc_array(1, sizeof *r.x);
    if (!r.x)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "PLY header");
    r.x->vertex_element = r.x->face_element = SIZE_MAX;
    rsmooth_status status = rs_ply_parse_header(&r, error);
    if (status == RSMOOTH_OK)
        status = rs_ply_find_elements(&r, error);
    if (status == RSMOOTH_OK)
        status = rs_ply_range_grid_header(&r, error);
    if (status == RSMOOTH_OK)
        status = rs_ply_assign_roles(&r, error);
    if (status == RSMOOTH_OK)
        status = read_data(&r, error);
    if (status == RSMOOTH_OK)
        status = check_end(&r, error);
    if (status == RSMOOTH_OK && r.grid_element)
        status = rs_ply_range_grid_triangulate(&r, error);
    rs_free(r.grid_cells);
    rs_free(r.grid_owner);
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
    rsmooth_format format = r.encoding == RS_PLY_ASCII       ? RSMOOTH_FORMAT_PLY_ASCII
                            : r.encoding == RS_PLY_BINARY_LE ? RSMOOTH_FORMAT_PLY_BINARY
                                                             : RSMOOTH_FORMAT_PLY_BINARY_BE;
    bool plain = rs_ply_is_plain(&r);
    r.x->plain = plain;
    if (r.grid_element) /* the extras say it was a grid */
        plain = false;
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
