/* Stanford PLY writer: ascii or binary little-endian (bytes laid out explicitly for any host). */
#include "io/io_internal.h"

#include <errno.h>
#include <string.h>

typedef struct out_buffer {
    FILE *stream;
    unsigned char bytes[1 << 16];
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

static void put_u32(unsigned char *p, uint32_t v) {
    p[0] = (unsigned char)v;
    p[1] = (unsigned char)(v >> 8);
    p[2] = (unsigned char)(v >> 16);
    p[3] = (unsigned char)(v >> 24);
}

static void put_f32(unsigned char *p, float f) {
    uint32_t bits;
    memcpy(&bits, &f, sizeof bits);
    put_u32(p, bits);
}

static void put_f64(unsigned char *p, double d) {
    uint64_t bits;
    memcpy(&bits, &d, sizeof bits);
    put_u32(p, (uint32_t)bits);
    put_u32(p + 4, (uint32_t)(bits >> 32));
}

static bool write_header(const rsmooth_mesh *mesh, FILE *stream, bool binary, bool wide_count,
                         bool unsigned_index) {
    const char *scalar = mesh->precision == RSMOOTH_FLOAT32 ? "float" : "double";
    bool ok = fprintf(stream,
                      "ply\nformat %s 1.0\ncomment written by rsmooth\nelement vertex %zu\n"
                      "property %s x\nproperty %s y\nproperty %s z\n",
                      binary ? "binary_little_endian" : "ascii", mesh->vertex_count, scalar, scalar,
                      scalar) >= 0;
    if (ok && mesh->vertex_quality)
        ok = fputs("property float quality\n", stream) >= 0;
    if (ok && mesh->vertex_colors)
        ok = fputs("property uchar red\nproperty uchar green\nproperty uchar blue\n", stream) >= 0;
    ok = ok && fprintf(stream, "element face %zu\nproperty list %s %s vertex_indices\nend_header\n",
                       mesh->face_count, wide_count ? "uint" : "uchar",
                       unsigned_index ? "uint" : "int") >= 0;
    return ok;
}

static bool write_binary(const rsmooth_mesh *mesh, FILE *stream, bool wide_count) {
    out_buffer *out = rs_alloc_array(1, sizeof *out);
    if (!out)
        return false;
    out->stream = stream;
    out->used = 0;
    out->ok = true;
    const bool f32 = mesh->precision == RSMOOTH_FLOAT32;
    for (size_t i = 0; out->ok && i < mesh->vertex_count; i++) {
        unsigned char *p = out_reserve(out, 3 * 8 + 4 + 3);
        const double *xyz = mesh->positions + 3 * i;
        for (int c = 0; c < 3; c++) {
            if (f32) {
                put_f32(p, (float)xyz[c]);
                p += 4;
            } else {
                put_f64(p, xyz[c]);
                p += 8;
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
    out_flush(out);
    bool ok = out->ok;
    rs_free(out);
    return ok;
}

static bool write_ascii(const rsmooth_mesh *mesh, FILE *stream) {
    const bool f32 = mesh->precision == RSMOOTH_FLOAT32;
    bool ok = true;
    for (size_t i = 0; ok && i < mesh->vertex_count; i++) {
        const double *xyz = mesh->positions + 3 * i;
        if (f32)
            ok = fprintf(stream, "%.9g %.9g %.9g", (double)(float)xyz[0], (double)(float)xyz[1],
                         (double)(float)xyz[2]) >= 0;
        else
            ok = fprintf(stream, "%.17g %.17g %.17g", xyz[0], xyz[1], xyz[2]) >= 0;
        if (ok && mesh->vertex_quality)
            ok = fprintf(stream, " %.9g", (double)mesh->vertex_quality[i]) >= 0;
        if (ok && mesh->vertex_colors) {
            const uint8_t *c = mesh->vertex_colors + 3 * i;
            ok = fprintf(stream, " %u %u %u", c[0], c[1], c[2]) >= 0;
        }
        ok = ok && putc('\n', stream) != EOF;
    }
    for (size_t f = 0; ok && f < mesh->face_count; f++) {
        uint32_t begin = mesh->face_offsets[f], end = mesh->face_offsets[f + 1];
        ok = fprintf(stream, "%lu", (unsigned long)(end - begin)) >= 0;
        for (uint32_t k = begin; ok && k < end; k++)
            ok = fprintf(stream, " %lu", (unsigned long)mesh->face_indices[k]) >= 0;
        ok = ok && putc('\n', stream) != EOF;
    }
    return ok;
}

rsmooth_status rs_io_ply_write(const rsmooth_mesh *mesh, FILE *stream, bool binary,
                               rsmooth_error *error) {
    bool wide_count = false;
    for (size_t f = 0; f < mesh->face_count && !wide_count; f++)
        wide_count = mesh->face_offsets[f + 1] - mesh->face_offsets[f] > 255;
    /* "int" indices, as most tools expect, unless a vertex index would not fit in one. */
    bool unsigned_index = mesh->vertex_count > (size_t)INT32_MAX;
    errno = 0;
    bool ok = write_header(mesh, stream, binary, wide_count, unsigned_index);
    if (ok)
        ok = binary ? write_binary(mesh, stream, wide_count) : write_ascii(mesh, stream);
    ok = ok && fflush(stream) == 0 && !ferror(stream);
    if (!ok)
        return rs_fail(error, RSMOOTH_ERROR_IO, "rsmooth_mesh_write_stream", "writing PLY: %s",
                       errno ? strerror(errno) : "stream error or out of memory");
    return RSMOOTH_OK;
}
