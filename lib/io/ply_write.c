/* Stanford PLY writer: ascii or binary little-endian (bytes laid out explicitly for any host). */
#include "io/float_print.h"
#include "io/ply_format.h"

#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <string.h>

/* Faithful path: a mesh whose PLY extras (ply_format.h) still match it (same vertex and face
 * counts) is written with the input's header (comments, obj_info, elements, properties and their
 * type words, in order) and every kept value as read; positions come from mesh->positions in the
 * x/y/z types, normals are recomputed from them in the nx/ny/nz types, faces come from mesh->face_*
 * in the list's types (widened when a value does not fit). There the extras win: caller-set
 * vertex_quality and vertex_colors are ignored (set mesh->extras to NULL to write them instead).
 * Otherwise the generic path writes positions, faces, recomputed normals when has_vertex_normals,
 * vertex_quality and vertex_colors. */

static const char where[] = "rsmooth_mesh_write_stream";

typedef struct out_buffer {
    FILE *stream;
    unsigned char bytes[1 << 20];
    size_t used;
    bool ok;
} out_buffer;

static void out_flush(out_buffer *out) {
    if (out->ok && out->used > 0 && fwrite(out->bytes, 1, out->used, out->stream) != out->used)
        out->ok = false;
    out->used = 0;
}

/* Room for `n` more bytes (n is small: one record at most). */
static unsigned char *out_reserve(out_buffer *out, size_t n) {
    if (sizeof out->bytes - out->used < n)
        out_flush(out);
    return out->bytes + out->used;
}

static out_buffer *out_open(FILE *stream) {
    out_buffer *out = rs_alloc_array(1, sizeof *out);
    if (out) {
        out->stream = stream;
        out->used = 0;
        out->ok = true;
    }
    return out;
}

/* Flushes and frees; false when any write failed. */
static bool out_close(out_buffer *out) {
    out_flush(out);
    bool ok = out->ok;
    rs_free(out);
    return ok;
}

static void put_le(unsigned char *p, uint64_t v, size_t size) {
    for (size_t b = 0; b < size; b++)
        p[b] = (unsigned char)(v >> (8 * b));
}

static void put_u32(unsigned char *p, uint32_t v) {
    put_le(p, v, 4);
}

static void put_f32(unsigned char *p, float f) {
    uint32_t bits;
    memcpy(&bits, &f, sizeof bits);
    put_u32(p, bits);
}

static void put_f64(unsigned char *p, double d) {
    uint64_t bits;
    memcpy(&bits, &d, sizeof bits);
    put_le(p, bits, 8);
}

static rsmooth_status io_failure(rsmooth_error *error) {
    return rs_fail(error, RSMOOTH_ERROR_IO, where, "writing PLY: %s",
                   errno ? strerror(errno) : "stream error or out of memory");
}

/* ---- generic path: the mesh's own fields */

/* Positions (and normals) go out as float when the mesh holds float32 data that float32 holds at
 * its scale (rs_io_float32_holds: recomputed normals are unit vectors, which it always holds), else
 * as double: rsmooth picks the type here, so it never refuses for it. A value beyond float range is
 * never written as an infinity, nor a mesh at 1e-150 as zeros. */
static bool use_float(const rsmooth_mesh *mesh) {
    return rs_io_float32_holds(mesh);
}

/* The UTF-8 byte-order mark the input opened with (rs_io_keeps_bom), when `bom`. */
static bool put_bom(FILE *stream, bool bom) {
    return !bom || fwrite(RS_IO_UTF8_BOM, 1, RS_IO_UTF8_BOM_SIZE, stream) == RS_IO_UTF8_BOM_SIZE;
}

/* What the generic path's header says: the mesh's counts and which of its fields follow x y z. */
typedef struct generic_header {
    bool bom, binary, f32, normals, quality, colors, wide_count, unsigned_index;
    size_t vertex_count, face_count;
} generic_header;

static bool write_header(FILE *stream, const generic_header *h) {
    const char *scalar = h->f32 ? "float" : "double";
    bool ok = put_bom(stream, h->bom) &&
              fprintf(stream,
                      "ply\nformat %s 1.0\ncomment written by rsmooth\nelement vertex %zu\n"
                      "property %s x\nproperty %s y\nproperty %s z\n",
                      h->binary ? "binary_little_endian" : "ascii", h->vertex_count, scalar, scalar,
                      scalar) >= 0;
    if (ok && h->normals)
        ok = fprintf(stream, "property %s nx\nproperty %s ny\nproperty %s nz\n", scalar, scalar,
                     scalar) >= 0;
    if (ok && h->quality)
        ok = fputs("property float quality\n", stream) >= 0;
    if (ok && h->colors)
        ok = fputs("property uchar red\nproperty uchar green\nproperty uchar blue\n", stream) >= 0;
    ok = ok && fprintf(stream, "element face %zu\nproperty list %s %s vertex_indices\nend_header\n",
                       h->face_count, h->wide_count ? "uint" : "uchar",
                       h->unsigned_index ? "uint" : "int") >= 0;
    return ok;
}

static bool write_binary(const rsmooth_mesh *mesh, const double *normals, FILE *stream, bool f32,
                         bool wide_count) {
    out_buffer *out = out_open(stream);
    if (!out)
        return false;
    for (size_t i = 0; out->ok && i < mesh->vertex_count; i++) {
        unsigned char *p = out_reserve(out, 6 * 8 + 4 + 3);
        for (int set = 0; set < (normals ? 2 : 1); set++) {
            const double *xyz = (set == 0 ? mesh->positions : normals) + 3 * i;
            for (int c = 0; c < 3; c++) {
                if (f32) {
                    put_f32(p, (float)xyz[c]);
                    p += 4;
                } else {
                    put_f64(p, xyz[c]);
                    p += 8;
                }
            }
        }
        if (mesh->vertex_quality) {
            put_f32(p, mesh->vertex_quality[i]);
            p += 4;
        }
        if (mesh->vertex_colors) {
            memcpy(p, mesh->vertex_colors + 3 * i, 3);
            p += 3;
        }
        out->used = (size_t)(p - out->bytes);
    }
    for (size_t f = 0; out->ok && f < mesh->face_count; f++) {
        uint32_t begin = mesh->face_offsets[f], end = mesh->face_offsets[f + 1];
        unsigned char *p = out_reserve(out, 4);
        if (wide_count) {
            put_u32(p, end - begin);
            out->used += 4;
        } else {
            *p = (unsigned char)(end - begin);
            out->used += 1;
        }
        for (uint32_t k = begin; k < end; k++) {
            p = out_reserve(out, 4);
            put_u32(p, mesh->face_indices[k]);
            out->used += 4;
        }
    }
    return out_close(out);
}

/* A text value and the separator after it ("%.9g"-style shortest digits: float_print.h). */
static unsigned char *text_float(unsigned char *p, float v, char sep) {
    p += rs_io_print_float((char *)p, v);
    *p++ = (unsigned char)sep;
    return p;
}

static unsigned char *text_double(unsigned char *p, double v, char sep) {
    p += rs_io_print_double((char *)p, v);
    *p++ = (unsigned char)sep;
    return p;
}

static unsigned char *text_u64(unsigned char *p, uint64_t v, char sep) {
    p += rs_io_print_u64((char *)p, v);
    *p++ = (unsigned char)sep;
    return p;
}

static bool write_ascii(const rsmooth_mesh *mesh, const double *normals, FILE *stream, bool f32) {
    out_buffer *out = out_open(stream);
    if (!out)
        return false;
    for (size_t i = 0; out->ok && i < mesh->vertex_count; i++) {
        /* 6 values, quality, 3 colours, each with its separator */
        unsigned char *start = out_reserve(out, 7 * (RS_IO_PRINT_MAX + 1) + 3 * 4);
        unsigned char *p = start;
        for (int set = 0; set < (normals ? 2 : 1); set++) {
            const double *xyz = (set == 0 ? mesh->positions : normals) + 3 * i;
            for (int c = 0; c < 3; c++)
                p = f32 ? text_float(p, (float)xyz[c], ' ') : text_double(p, xyz[c], ' ');
        }
        if (mesh->vertex_quality)
            p = text_float(p, mesh->vertex_quality[i], ' ');
        if (mesh->vertex_colors)
            for (int c = 0; c < 3; c++)
                p = text_u64(p, mesh->vertex_colors[3 * i + (size_t)c], ' ');
        p[-1] = '\n';
        out->used += (size_t)(p - start);
    }
    for (size_t f = 0; out->ok && f < mesh->face_count; f++) {
        uint32_t begin = mesh->face_offsets[f], end = mesh->face_offsets[f + 1];
        unsigned char *p = out_reserve(out, 11);
        out->used += (size_t)(text_u64(p, end - begin, ' ') - p);
        for (uint32_t k = begin; k < end; k++) {
            p = out_reserve(out, 11);
            out->used += (size_t)(text_u64(p, mesh->face_indices[k], ' ') - p);
        }
        out->bytes[out->used - 1] = '\n';
    }
    return out_close(out);
}

static rsmooth_status write_generic(const rsmooth_mesh *mesh, FILE *stream, bool binary,
                                    rsmooth_error *error) {
    bool wide_count = false;
    for (size_t f = 0; f < mesh->face_count && !wide_count; f++)
        wide_count = mesh->face_offsets[f + 1] - mesh->face_offsets[f] > 255;
    /* "int" indices, as most tools expect, unless a vertex index would not fit in one. */
    bool unsigned_index = mesh->vertex_count > (size_t)INT32_MAX;
    double *normals = NULL;
    if (mesh->has_vertex_normals && rs_io_normals_available(mesh)) {
        rsmooth_status status = rs_io_vertex_normals(mesh, &normals, where, error);
        if (status != RSMOOTH_OK)
            return status;
    }
    const bool f32 = use_float(mesh);
    const generic_header h = {
        rs_io_keeps_bom(mesh, binary ? RSMOOTH_FORMAT_PLY_BINARY : RSMOOTH_FORMAT_PLY_ASCII),
        binary,
        f32,
        normals != NULL,
        mesh->vertex_quality != NULL,
        mesh->vertex_colors != NULL,
        wide_count,
        unsigned_index,
        mesh->vertex_count,
        mesh->face_count};
    errno = 0;
    bool ok = write_header(stream, &h);
    if (ok)
        ok = binary ? write_binary(mesh, normals, stream, f32, wide_count)
                    : write_ascii(mesh, normals, stream, f32);
    rs_free(normals);
    ok = ok && fflush(stream) == 0 && !ferror(stream);
    return ok ? RSMOOTH_OK : io_failure(error);
}

/* ---- faithful path: the input's header and kept values */

/* true when the integer or floating-point type t holds v exactly (v integral for integers). */
static bool type_holds(rs_ply_type t, double v) {
    switch (t) {
    case RS_PLY_INT8:
        return v >= INT8_MIN && v <= INT8_MAX;
    case RS_PLY_UINT8:
        return v >= 0 && v <= UINT8_MAX;
    case RS_PLY_INT16:
        return v >= INT16_MIN && v <= INT16_MAX;
    case RS_PLY_UINT16:
        return v >= 0 && v <= UINT16_MAX;
    case RS_PLY_INT32:
        return v >= INT32_MIN && v <= INT32_MAX;
    case RS_PLY_UINT32:
        return v >= 0 && v <= UINT32_MAX;
    case RS_PLY_FLOAT32:
        return fabs(v) <= 16777216.0; /* integers up to 2^24 are exact in a float */
    case RS_PLY_FLOAT64:
        return true;
    case RS_PLY_NONE:
        break;
    }
    return false;
}

/* Writes v (integral and in range for integer types) as a value of type t. */
static void emit_double(out_buffer *out, bool binary, rs_ply_type t, double v) {
    unsigned char *p = out_reserve(out, 40);
    if (binary) {
        size_t size = rs_ply_type_size(t);
        if (t == RS_PLY_FLOAT32)
            put_f32(p, (float)v);
        else if (t == RS_PLY_FLOAT64)
            put_f64(p, v);
        else
            put_le(p, (uint64_t)(int64_t)v, size);
        out->used += size;
        return;
    }
    unsigned char *end = p;
    if (t == RS_PLY_FLOAT32) {
        end = text_float(end, (float)v, ' ');
    } else if (t == RS_PLY_FLOAT64) {
        end = text_double(end, v, ' ');
    } else {
        int64_t i = (int64_t)v;
        if (i < 0)
            *end++ = '-';
        end = text_u64(end, i < 0 ? 0 - (uint64_t)i : (uint64_t)i, ' ');
    }
    out->used += (size_t)(end - p);
}

/* Writes a kept value (host order) of type t. */
static void emit_stored(out_buffer *out, bool binary, rs_ply_type t, const unsigned char *value) {
    if (!binary) {
        emit_double(out, false, t, rs_ply_host_value(value, t));
        return;
    }
    size_t size = rs_ply_type_size(t);
    unsigned char *p = out_reserve(out, size);
    if (rs_ply_host_is_le() || size == 1)
        memcpy(p, value, size);
    else
        for (size_t b = 0; b < size; b++)
            p[b] = value[size - 1 - b];
    out->used += size;
}

/* ascii: each value is followed by a space; the item's last one becomes the line end. */
static void end_item(out_buffer *out, bool binary) {
    if (!binary && out->used > 0)
        out->bytes[out->used - 1] = '\n';
}

/* The face list's types as written: the input's, widened where the mesh's faces do not fit. */
typedef struct face_types {
    rs_ply_type count_type, index_type;
    uint8_t count_spelling, spelling;
} face_types;

static face_types choose_face_types(const rsmooth_mesh *mesh, const rs_ply_property *list) {
    face_types ft = {list->count_type, list->type, list->count_spelling, list->spelling};
    uint32_t max_count = 0, max_index = 0;
    for (size_t f = 0; f < mesh->face_count; f++) {
        uint32_t n = mesh->face_offsets[f + 1] - mesh->face_offsets[f];
        if (n > max_count)
            max_count = n;
    }
    size_t index_count = mesh->face_count ? mesh->face_offsets[mesh->face_count] : 0;
    for (size_t k = 0; k < index_count; k++)
        if (mesh->face_indices[k] > max_index)
            max_index = mesh->face_indices[k];
    if (!type_holds(ft.count_type, max_count)) {
        ft.count_type = RS_PLY_UINT32;
        ft.count_spelling = rs_ply_canonical_spelling(RS_PLY_UINT32);
    }
    if (!type_holds(ft.index_type, max_index)) {
        ft.index_type = max_index <= INT32_MAX ? RS_PLY_INT32 : RS_PLY_UINT32;
        ft.spelling = rs_ply_canonical_spelling(ft.index_type);
    }
    return ft;
}

/* Whether property p's type holds `value` as written: float32 a finite one (a double any, an
 * integer type the value rounded). */
static bool holds_written(const rs_ply_property *p, double value) {
    return p->type == RS_PLY_FLOAT32       ? isfinite((float)value)
           : rs_ply_type_is_float(p->type) ? true
                                           : type_holds(p->type, round(value));
}

/* Component c of `count` triples (the i-th at values + 3 i, vertex ids[i], or i when ids is NULL)
 * against property p's type, naming the first that does not fit. */
static rsmooth_status check_component(const rs_ply_property *p, const double *values, int c,
                                      size_t count, const uint64_t *ids, rsmooth_error *error) {
    for (size_t i = 0; i < count; i++) {
        double value = values[3 * i + (size_t)c];
        if (!holds_written(p, value))
            return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                           "vertex %zu: %s = %.17g does not fit the file's '%s' type",
                           ids ? (size_t)ids[i] : i, p->name, value, rs_ply_spelling(p->spelling));
    }
    return RSMOOTH_OK;
}

/* The float32 x y z (`axis[c]` of type float for the bits of `float_axes`: 1 x, 2 y, 4 z) must
 * hold the positions (addressed as check_component's) at the scale of `largest`, the mesh's
 * largest coordinate magnitude (rs_io_float32_misfit), vertex by vertex. */
static rsmooth_status check_float32_scale(const double *xyz, size_t count, const uint64_t *ids,
                                          unsigned float_axes, const rs_ply_property *const axis[3],
                                          double largest, rsmooth_error *error) {
    const double tolerance = rs_io_float32_tolerance(largest);
    for (size_t i = 0; float_axes && i < count; i++)
        for (int c = 0; c < 3; c++) {
            double x = xyz[3 * i + (size_t)c];
            if (!((float_axes >> c) & 1) || !rs_io_float32_misfits(x, tolerance))
                continue;
            const rs_ply_property *p = axis[c];
            return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, /* 256 bytes: briefly */
                           "vertex %zu: %s = %s is %s in the file's '%s' type, beyond float32's "
                           "precision at the mesh's scale (largest %s); a PLY with double x y z "
                           "(extras NULL), OBJ or ascii STL holds it",
                           ids ? (size_t)ids[i] : i, p->name, rs_io_shortest(x).text,
                           rs_io_shortest((float)x).text, rs_ply_spelling(p->spelling),
                           rs_io_shortest(largest).text);
        }
    return RSMOOTH_OK;
}

/* The file's types must hold the filtered positions (rounded, for integer types) and a point
 * cloud's own normals (`normals`, NULL for recomputed ones: unit vectors every float type holds),
 * and its float x y z must hold the positions at the mesh's scale (check_float32_scale): checked
 * before anything is written, property by property in the element's order. */
static rsmooth_status check_vertex_values(const rsmooth_mesh *mesh, const rs_ply_element *v,
                                          const double *normals, rsmooth_error *error) {
    unsigned float_axes = 0;
    const rs_ply_property *axis[3] = {NULL, NULL, NULL};
    for (size_t k = 0; k < v->property_count; k++) {
        const rs_ply_property *p = &v->properties[k];
        rsmooth_status status = RSMOOTH_OK;
        if (p->role >= RS_PLY_X && p->role <= RS_PLY_Z) {
            int c = p->role - RS_PLY_X;
            axis[c] = p;
            if (p->type == RS_PLY_FLOAT32)
                float_axes |= 1u << c;
            status = check_component(p, mesh->positions, c, mesh->vertex_count, NULL, error);
        } else if (p->role >= RS_PLY_NX && p->role <= RS_PLY_NZ && normals) {
            status =
                check_component(p, normals, p->role - RS_PLY_NX, mesh->vertex_count, NULL, error);
        }
        if (status != RSMOOTH_OK)
            return status;
    }
    double largest = 0;
    for (size_t i = 0; float_axes && i < 3 * mesh->vertex_count; i++)
        largest = fmax(largest, fabs(mesh->positions[i]));
    return check_float32_scale(mesh->positions, mesh->vertex_count, NULL, float_axes, axis, largest,
                               error);
}

rsmooth_status rs_io_ply_check_positions(const double *xyz, size_t count, const uint64_t *ids,
                                         const rs_ply_element *v, double largest,
                                         rsmooth_error *error) {
    rsmooth_status status = rs_io_check_position_values(xyz, count, ids, where, error);
    unsigned float_axes = 0;
    const rs_ply_property *axis[3] = {NULL, NULL, NULL};
    for (size_t k = 0; status == RSMOOTH_OK && k < v->property_count; k++) {
        const rs_ply_property *p = &v->properties[k];
        if (p->role < RS_PLY_X || p->role > RS_PLY_Z)
            continue;
        int c = p->role - RS_PLY_X;
        axis[c] = p;
        if (p->type == RS_PLY_FLOAT32)
            float_axes |= 1u << c;
        status = check_component(p, xyz, c, count, ids, error);
    }
    return status != RSMOOTH_OK
               ? status
               : check_float32_scale(xyz, count, ids, float_axes, axis, largest, error);
}

static bool write_faithful_header(const rs_ply_extras *x, FILE *stream, bool bom, bool binary,
                                  const face_types *ft) {
    bool ok = put_bom(stream, bom) && fputs("ply\n", stream) >= 0;
    for (size_t c = 0; ok && c < x->comment_count; c++)
        if (x->comments[c].before_format)
            ok = fprintf(stream, "%s\n", x->comments[c].text) >= 0;
    ok = ok && fprintf(stream, "format %s 1.0\n", binary ? "binary_little_endian" : "ascii") >= 0;
    size_t next_comment = 0;
    for (size_t ei = 0; ok && ei <= x->element_count; ei++) {
        for (; ok && next_comment < x->comment_count &&
               x->comments[next_comment].before_element <= ei;
             next_comment++)
            if (!x->comments[next_comment].before_format)
                ok = fprintf(stream, "%s\n", x->comments[next_comment].text) >= 0;
        if (ei == x->element_count)
            break;
        const rs_ply_element *e = &x->elements[ei];
        ok = ok && fprintf(stream, "element %s %" PRIu64 "\n", e->name, e->count) >= 0;
        for (size_t k = 0; ok && k < e->property_count; k++) {
            const rs_ply_property *p = &e->properties[k];
            if (p->count_type == RS_PLY_NONE)
                ok =
                    fprintf(stream, "property %s %s\n", rs_ply_spelling(p->spelling), p->name) >= 0;
            else if (p->role == RS_PLY_FACE_LIST)
                ok =
                    fprintf(stream, "property list %s %s %s\n", rs_ply_spelling(ft->count_spelling),
                            rs_ply_spelling(ft->spelling), p->name) >= 0;
            else
                ok = fprintf(stream, "property list %s %s %s\n", rs_ply_spelling(p->count_spelling),
                             rs_ply_spelling(p->spelling), p->name) >= 0;
        }
    }
    return ok && fputs("end_header\n", stream) >= 0;
}

bool rs_io_ply_write_binary_header(FILE *stream, const rs_ply_extras *x, bool plain, bool bom,
                                   bool f32) {
    const rs_ply_element *v = &x->elements[x->vertex_element];
    bool faces = x->face_element < x->element_count;
    if (plain) { /* as write_generic: no normals, quality or colours; counts of uchar */
        const generic_header h = {bom,
                                  true,
                                  f32,
                                  false,
                                  false,
                                  false,
                                  false,
                                  v->count > (uint64_t)INT32_MAX,
                                  (size_t)v->count,
                                  faces ? (size_t)x->elements[1].count : 0};
        return write_header(stream, &h);
    }
    /* the list's own types: the values read from them fit them (choose_face_types keeps them) */
    face_types ft = {RS_PLY_NONE, RS_PLY_NONE, 0, 0};
    const rs_ply_element *f = faces ? &x->elements[x->face_element] : NULL;
    for (size_t k = 0; f && k < f->property_count; k++)
        if (f->properties[k].role == RS_PLY_FACE_LIST)
            ft = (face_types){f->properties[k].count_type, f->properties[k].type,
                              f->properties[k].count_spelling, f->properties[k].spelling};
    return write_faithful_header(x, stream, bom, true, &ft);
}

static rsmooth_status inconsistent(const rs_ply_element *e, rsmooth_error *error) {
    return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                   "PLY extras of element '%.40s' are inconsistent", e->name);
}

static rsmooth_status write_element(const rsmooth_mesh *mesh, const rs_ply_extras *x, size_t ei,
                                    const double *normals, const face_types *ft, out_buffer *out,
                                    bool binary, rsmooth_error *error) {
    const rs_ply_element *e = &x->elements[ei];
    const bool is_face = ei == x->face_element;
    size_t list_at = 0;
    for (size_t i = 0; out->ok && i < (size_t)e->count; i++) {
        const unsigned char *row = e->rows ? e->rows + i * e->row_size : NULL;
        for (size_t k = 0; k < e->property_count; k++) {
            const rs_ply_property *p = &e->properties[k];
            switch ((rs_ply_role)p->role) {
            case RS_PLY_X:
            case RS_PLY_Y:
            case RS_PLY_Z: {
                double v = mesh->positions[3 * i + (size_t)(p->role - RS_PLY_X)];
                emit_double(out, binary, p->type, rs_ply_type_is_float(p->type) ? v : round(v));
                break;
            }
            case RS_PLY_NX:
            case RS_PLY_NY:
            case RS_PLY_NZ:
                emit_double(out, binary, p->type, normals[3 * i + (size_t)(p->role - RS_PLY_NX)]);
                break;
            case RS_PLY_FACE_LIST: {
                if (!is_face)
                    return inconsistent(e, error);
                uint32_t begin = mesh->face_offsets[i], end = mesh->face_offsets[i + 1];
                emit_double(out, binary, ft->count_type, end - begin);
                for (uint32_t j = begin; j < end; j++)
                    emit_double(out, binary, ft->index_type, mesh->face_indices[j]);
                break;
            }
            case RS_PLY_GRID_LIST: /* the reader made the grid a face element */
                return inconsistent(e, error);
            case RS_PLY_STORED:
                if (!row || p->row_offset >= e->row_size)
                    return inconsistent(e, error);
                if (p->count_type == RS_PLY_NONE) {
                    emit_stored(out, binary, p->type, row + p->row_offset);
                    break;
                }
                double n = rs_ply_host_value(row + p->row_offset, p->count_type);
                size_t size = rs_ply_type_size(p->type);
                if (!(n >= 0 && n <= (double)((e->list_bytes - list_at) / size)))
                    return inconsistent(e, error);
                emit_stored(out, binary, p->count_type, row + p->row_offset);
                for (size_t j = 0; j < (size_t)n; j++, list_at += size)
                    emit_stored(out, binary, p->type, e->list_items + list_at);
                break;
            }
        }
        end_item(out, binary);
    }
    return RSMOOTH_OK;
}

static rsmooth_status write_faithful(const rsmooth_mesh *mesh, const rs_ply_extras *x, FILE *stream,
                                     bool binary, rsmooth_error *error) {
    const rs_ply_element *v = &x->elements[x->vertex_element];
    rsmooth_status status = RSMOOTH_OK;
    face_types ft = {RS_PLY_NONE, RS_PLY_NONE, 0, 0};
    if (x->face_element != SIZE_MAX) {
        const rs_ply_element *f = &x->elements[x->face_element];
        for (size_t k = 0; k < f->property_count; k++)
            if (f->properties[k].role == RS_PLY_FACE_LIST)
                ft = choose_face_types(mesh, &f->properties[k]);
    }
    double *normals = NULL;
    for (size_t k = 0; k < v->property_count && !normals; k++) {
        if (v->properties[k].role >= RS_PLY_NX && v->properties[k].role <= RS_PLY_NZ) {
            status = rs_io_vertex_normals(mesh, &normals, where, error);
            if (status != RSMOOTH_OK)
                return status;
        }
    }
    errno = 0;
    out_buffer *out = NULL;
    bool ok = write_faithful_header(
        x, stream,
        rs_io_keeps_bom(mesh, binary ? RSMOOTH_FORMAT_PLY_BINARY : RSMOOTH_FORMAT_PLY_ASCII),
        binary, &ft);
    if (ok)
        ok = (out = out_open(stream)) != NULL;
    for (size_t ei = 0; ok && status == RSMOOTH_OK && ei < x->element_count; ei++)
        if (x->elements[ei].property_count > 0) /* else no data, whatever the count */
            status = write_element(mesh, x, ei, normals, &ft, out, binary, error);
    if (out)
        ok = out_close(out) && ok;
    rs_free(normals);
    if (status != RSMOOTH_OK)
        return status;
    ok = ok && fflush(stream) == 0 && !ferror(stream);
    return ok ? RSMOOTH_OK : io_failure(error);
}

/* The PLY record of the mesh, while it describes it (the same vertex and face counts) with a
 * layout of its own (not plain: a plain one is written as the generic path writes it). */
static const rs_ply_extras *faithful_extras(const rsmooth_mesh *mesh) {
    const rs_ply_extras *x = mesh->extras ? mesh->extras->ply : NULL;
    if (x && !x->plain && x->vertex_element < x->element_count &&
        x->elements[x->vertex_element].count == mesh->vertex_count &&
        (x->face_element < x->element_count ? x->elements[x->face_element].count == mesh->face_count
                                            : mesh->face_count == 0))
        return x;
    return NULL;
}

/* Whether the faithful path writes normals: the vertex element has nx, ny, nz roles. */
static bool faithful_normals(const rs_ply_extras *x) {
    const rs_ply_element *v = &x->elements[x->vertex_element];
    for (size_t k = 0; k < v->property_count; k++)
        if (v->properties[k].role >= RS_PLY_NX && v->properties[k].role <= RS_PLY_NZ)
            return true;
    return false;
}

rsmooth_status rs_io_ply_check(const rsmooth_mesh *mesh, rsmooth_error *error) {
    const rs_ply_extras *x = faithful_extras(mesh);
    bool normals =
        x ? faithful_normals(x) : mesh->has_vertex_normals && rs_io_normals_available(mesh);
    rsmooth_status status = normals ? rs_io_check_normals(mesh, where, error) : RSMOOTH_OK;
    if (status == RSMOOTH_OK && x)
        status =
            check_vertex_values(mesh, &x->elements[x->vertex_element],
                                rs_io_normals_are_data(mesh) ? mesh->vertex_normals : NULL, error);
    return status;
}

rsmooth_status rs_io_ply_write(const rsmooth_mesh *mesh, FILE *stream, bool binary,
                               rsmooth_error *error) {
    const rs_ply_extras *x = faithful_extras(mesh);
    return x ? write_faithful(mesh, x, stream, binary, error)
             : write_generic(mesh, stream, binary, error);
}
