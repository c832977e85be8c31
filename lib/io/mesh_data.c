/* The rsmooth_mesh record (create, fan triangulation, destroy) and helpers the parsers share. */
#define _POSIX_C_SOURCE 200809L
#include "io/io_internal.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

rsmooth_status rsmooth_mesh_create(size_t vertex_count, size_t face_count, size_t face_index_count,
                                   rsmooth_mesh **mesh, rsmooth_error *error) {
    static const char where[] = "rsmooth_mesh_create";
    rs_error_clear(error);
    if (!mesh)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "mesh is NULL");
    *mesh = NULL;
    if ((uint64_t)vertex_count >= RS_IO_MAX_VERTICES)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "vertex count %zu not below 2^32", vertex_count);
    if ((uint64_t)face_index_count >= RS_IO_MAX_FACE_INDICES || face_count == SIZE_MAX)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "%zu faces with %zu indices: too many", face_count, face_index_count);
    rsmooth_mesh *m = rs_calloc_array(1, sizeof *m);
    if (!m)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "mesh record");
    m->vertex_count = vertex_count;
    m->face_count = face_count;
    m->precision = RSMOOTH_FLOAT64;
    m->source_format = RSMOOTH_FORMAT_AUTO;
    m->positions = rs_calloc_array(vertex_count, 3 * sizeof(double));
    m->face_offsets = rs_calloc_array(face_count + 1, sizeof(uint32_t));
    m->face_indices = rs_calloc_array(face_index_count, sizeof(uint32_t));
    if (!m->positions || !m->face_offsets || !m->face_indices) {
        rsmooth_mesh_destroy(m);
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where,
                       "%zu vertices, %zu faces, %zu face indices", vertex_count, face_count,
                       face_index_count);
    }
    *mesh = m;
    return RSMOOTH_OK;
}

/* Fans the faces of a checked mesh into `triangles`. */
static rsmooth_status fan_faces(rsmooth_mesh *mesh, const char *where, rsmooth_error *error) {
    /* The check bounds every face by 2^32 indices in all, so the sum cannot overflow size_t / 3. */
    size_t triangle_count = 0;
    for (size_t f = 0; f < mesh->face_count; f++)
        triangle_count += (size_t)(mesh->face_offsets[f + 1] - mesh->face_offsets[f]) - 2;
    uint32_t *triangles = NULL;
    if (triangle_count > 0) {
        if (rs_mul_overflows(triangle_count, 3 * sizeof(uint32_t)))
            return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "%zu triangles",
                           triangle_count);
        triangles = rs_alloc_array(triangle_count, 3 * sizeof(uint32_t));
        if (!triangles)
            return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "%zu triangles",
                           triangle_count);
        uint32_t *t = triangles;
        for (size_t f = 0; f < mesh->face_count; f++) {
            const uint32_t *v = mesh->face_indices + mesh->face_offsets[f];
            uint32_t n = mesh->face_offsets[f + 1] - mesh->face_offsets[f];
            for (uint32_t i = 1; i + 1 < n; i++) {
                t[0] = v[0];
                t[1] = v[i];
                t[2] = v[i + 1];
                t += 3;
            }
        }
    }
    rs_free(mesh->triangles);
    mesh->triangles = triangles;
    mesh->triangle_count = triangle_count;
    return RSMOOTH_OK;
}

rsmooth_status rsmooth_mesh_triangulate(rsmooth_mesh *mesh, rsmooth_error *error) {
    static const char where[] = "rsmooth_mesh_triangulate";
    rs_error_clear(error);
    rsmooth_status status = rs_io_mesh_check(mesh, where, error);
    if (status != RSMOOTH_OK)
        return status;
    return fan_faces(mesh, where, error);
}

void rsmooth_mesh_destroy(rsmooth_mesh *mesh) {
    if (!mesh)
        return;
    rs_free(mesh->positions);
    rs_free(mesh->face_offsets);
    rs_free(mesh->face_indices);
    rs_free(mesh->triangles);
    rs_free(mesh->vertex_quality);
    rs_free(mesh->vertex_colors);
    rs_free(mesh->vertex_normals);
    if (mesh->extras) {
        rs_io_ply_extras_free(mesh->extras->ply);
        rs_io_obj_extras_free(mesh->extras->obj);
        rs_io_off_extras_free(mesh->extras->off);
        rs_io_stl_extras_free(mesh->extras->stl);
        rs_free(mesh->extras);
    }
    rs_free(mesh);
}

struct rsmooth_mesh_extras *rs_io_mesh_extras(rsmooth_mesh *mesh) {
    if (!mesh->extras)
        mesh->extras = rs_calloc_array(1, sizeof *mesh->extras);
    return mesh->extras;
}

size_t rsmooth_mesh_conversion_losses(const rsmooth_mesh *mesh, rsmooth_format format, char *buffer,
                                      size_t size) {
    char scratch[1];
    if (!buffer || size == 0) {
        buffer = scratch;
        size = sizeof scratch;
    }
    buffer[0] = '\0';
    if (!mesh)
        return 0;
    size_t lost = 0;
    bool stl = rs_io_is_stl(format);
    if (mesh->vertex_colors && (stl || format == RSMOOTH_FORMAT_AUTO))
        lost += rs_io_loss_add(buffer, size, "vertex colours");
    /* a point cloud whose normals matched no vertex keeps them only as its own format's text */
    if (mesh->has_vertex_normals &&
        (stl || (!rs_io_normals_available(mesh) && format != mesh->source_format)))
        lost += rs_io_loss_add(buffer, size, "vertex normals");
    if (mesh->vertex_quality && !rs_io_is_ply(format))
        lost += rs_io_loss_add(buffer, size, "vertex quality");
    if (mesh->extras) {
        if (mesh->extras->utf8_bom && !rs_io_keeps_bom(mesh, format))
            lost += rs_io_loss_add(buffer, size, "UTF-8 byte-order mark");
        lost += rs_io_ply_losses(mesh->extras->ply, format, buffer, size);
        lost += rs_io_obj_losses(mesh->extras->obj, format, buffer, size);
        lost += rs_io_off_losses(mesh->extras->off, format, buffer, size);
        lost += rs_io_stl_losses(mesh->extras->stl, format, buffer, size);
    }
    return lost;
}

static bool ends_with_ci(const char *s, size_t len, const char *suffix) {
    size_t n = strlen(suffix);
    if (len < n)
        return false;
    for (size_t i = 0; i < n; i++)
        if (tolower((unsigned char)s[len - n + i]) != suffix[i])
            return false;
    return true;
}

rsmooth_format rsmooth_format_from_path(const char *path) {
    if (!path)
        return RSMOOTH_FORMAT_AUTO;
    size_t len = strlen(path);
    if (ends_with_ci(path, len, ".obj"))
        return RSMOOTH_FORMAT_OBJ;
    if (ends_with_ci(path, len, ".ply"))
        return RSMOOTH_FORMAT_PLY_BINARY;
    if (ends_with_ci(path, len, ".off"))
        return RSMOOTH_FORMAT_OFF;
    if (ends_with_ci(path, len, ".stl"))
        return RSMOOTH_FORMAT_STL_BINARY;
    return RSMOOTH_FORMAT_AUTO;
}

rsmooth_status rs_io_mesh_adopt(double *positions, size_t vertex_count, rsmooth_scalar precision,
                                uint32_t *face_offsets, size_t face_count, uint32_t *face_indices,
                                rsmooth_format format, rsmooth_mesh **mesh, rsmooth_error *error) {
    rsmooth_mesh *m = rs_calloc_array(1, sizeof *m);
    if (!m) {
        rs_free(positions);
        rs_free(face_offsets);
        rs_free(face_indices);
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, "rsmooth_mesh_read", "mesh record");
    }
    m->positions = positions;
    m->vertex_count = vertex_count;
    m->precision = precision;
    m->face_offsets = face_offsets;
    m->face_count = face_count;
    m->face_indices = face_indices;
    m->source_format = format;
    if (!m->face_offsets) /* keep the documented face_count + 1 entries even with no face */
        m->face_offsets = rs_calloc_array(1, sizeof(uint32_t));
    if (!m->face_offsets) {
        rsmooth_mesh_destroy(m);
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, "rsmooth_mesh_read", "face offsets");
    }
    /* The parsers checked every face as they read it. */
    rsmooth_status status = fan_faces(m, "rsmooth_mesh_read", error);
    if (status != RSMOOTH_OK) {
        rsmooth_mesh_destroy(m);
        return status;
    }
    *mesh = m;
    return RSMOOTH_OK;
}

bool rs_io_u32vec_reserve(rs_io_u32vec *vec, size_t extra) {
    if (vec->capacity - vec->count >= extra)
        return true;
    if (extra > SIZE_MAX / 2 - vec->count)
        return false;
    size_t need = vec->count + extra;
    size_t capacity = vec->capacity ? vec->capacity : 1024;
    while (capacity < need)
        capacity = capacity > SIZE_MAX / 4 ? need : capacity * 2;
    uint32_t *data = rs_realloc_array(vec->data, capacity, sizeof(uint32_t));
    if (!data)
        return false;
    vec->data = data;
    vec->capacity = capacity;
    return true;
}

/* Powers of ten exactly representable in a double: m * 10^e with m < 2^53 and |e| <= 22 is then one
 * correctly rounded IEEE operation (Clinger's fast path). */
static const double exact_pow10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                       1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                       1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

static bool parse_double_slow(const char *s, size_t len, double *out) {
    char buf[128];
    if (len == 0 || len >= sizeof buf)
        return false;
    memcpy(buf, s, len);
    buf[len] = '\0';
    char *end = NULL;
    double v = strtod(buf, &end);
    if (end != buf + len)
        return false;
    *out = v;
    return true;
}

bool rs_io_parse_double(const char *s, size_t len, double *out) {
    size_t i = 0;
    bool negative = false;
    if (i < len && (s[i] == '-' || s[i] == '+')) {
        negative = s[i] == '-';
        i++;
    }
    uint64_t mantissa = 0;
    int significant = 0, exponent = 0, digits = 0;
    for (; i < len && s[i] >= '0' && s[i] <= '9'; i++, digits++) {
        if (mantissa == 0 && s[i] == '0')
            continue;
        if (++significant > 19)
            return parse_double_slow(s, len, out);
        mantissa = mantissa * 10 + (uint64_t)(s[i] - '0');
    }
    if (i < len && s[i] == '.') {
        for (i++; i < len && s[i] >= '0' && s[i] <= '9'; i++, digits++) {
            exponent--;
            if (mantissa == 0 && s[i] == '0')
                continue;
            if (++significant > 19)
                return parse_double_slow(s, len, out);
            mantissa = mantissa * 10 + (uint64_t)(s[i] - '0');
        }
    }
    if (digits == 0)
        return parse_double_slow(s, len, out); /* "nan", "inf", or malformed */
    if (i < len && (s[i] == 'e' || s[i] == 'E')) {
        i++;
        bool exp_negative = false;
        if (i < len && (s[i] == '-' || s[i] == '+')) {
            exp_negative = s[i] == '-';
            i++;
        }
        int e = 0, exp_digits = 0;
        for (; i < len && s[i] >= '0' && s[i] <= '9'; i++, exp_digits++) {
            if (e > 9999)
                return parse_double_slow(s, len, out);
            e = e * 10 + (s[i] - '0');
        }
        if (exp_digits == 0)
            return false;
        exponent += exp_negative ? -e : e;
    }
    if (i != len)
        return parse_double_slow(s, len, out); /* hex floats and anything else strtod may take */
    if (mantissa > ((uint64_t)1 << 53) || exponent < -22 || exponent > 22) {
        if (mantissa == 0) {
            *out = negative ? -0.0 : 0.0;
            return true;
        }
        return parse_double_slow(s, len, out);
    }
    double v = (double)mantissa;
    v = exponent < 0 ? v / exact_pow10[-exponent] : v * exact_pow10[exponent];
    *out = negative ? -v : v;
    return true;
}
