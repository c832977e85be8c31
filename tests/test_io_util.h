/* Shared by the mesh-file tests and the seed corpus: a byte buffer, writing to memory, faces. */
#ifndef RSMOOTH_TEST_IO_UTIL_H
#define RSMOOTH_TEST_IO_UTIL_H

#include "rsmooth_io.h"
#include "test_util.h"

#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* ---- a byte buffer the tests build files in */

typedef struct bytes {
    unsigned char *data;
    size_t size, capacity;
    bool big_endian; /* for put_uint and what calls it */
} bytes;

static inline void put(bytes *b, const void *p, size_t n) {
    if (b->size + n > b->capacity) {
        b->capacity = 2 * (b->size + n) + 64;
        b->data = realloc(b->data, b->capacity);
        CHECK(b->data != NULL);
    }
    memcpy(b->data + b->size, p, n);
    b->size += n;
}

static inline void put_text(bytes *b, const char *s) {
    put(b, s, strlen(s));
}

/* The low `n` bytes of `v`, in the buffer's byte order. */
static inline void put_uint(bytes *b, uint64_t v, size_t n) {
    unsigned char tmp[8];
    for (size_t i = 0; i < n; i++)
        tmp[b->big_endian ? n - 1 - i : i] = (unsigned char)(v >> (8 * i));
    put(b, tmp, n);
}

static inline void put_u8(bytes *b, unsigned v) {
    put_uint(b, v, 1);
}
static inline void put_u32(bytes *b, uint32_t v) {
    put_uint(b, v, 4);
}
static inline void put_i32(bytes *b, int32_t v) {
    put_uint(b, (uint32_t)v, 4);
}
static inline void put_f32(bytes *b, float f) {
    uint32_t u;
    memcpy(&u, &f, 4);
    put_uint(b, u, 4);
}
static inline void put_f64(bytes *b, double d) {
    uint64_t u;
    memcpy(&u, &d, 8);
    put_uint(b, u, 8);
}

static inline void bytes_free(bytes *b) {
    free(b->data);
    b->data = NULL;
    b->size = b->capacity = 0;
}

/* ---- meshes */

static inline bool io_test_is_stl(rsmooth_format f) {
    return f == RSMOOTH_FORMAT_STL_ASCII || f == RSMOOTH_FORMAT_STL_BINARY;
}

/* Writes `mesh` in `format` into a malloc'd buffer, NUL-terminated (*size without the NUL). Needs
 * _POSIX_C_SOURCE 200809L for open_memstream. */
static inline void *mesh_to_memory(const rsmooth_mesh *mesh, rsmooth_format format, size_t *size) {
    char *data = NULL;
    size_t n = 0;
    FILE *f = open_memstream(&data, &n);
    CHECK(f != NULL);
    rsmooth_error err;
    rsmooth_status s = rsmooth_mesh_write_stream(mesh, f, format, &err);
    if (s != RSMOOTH_OK)
        fprintf(stderr, "write: %s\n", err.message);
    CHECK_EQ_INT(s, RSMOOTH_OK);
    CHECK(fclose(f) == 0);
    CHECK(data != NULL);
    CHECK(n > 0);
    *size = n;
    return data;
}

/* Face `f` of `m` is the `n` vertices `expected`. */
static inline void check_face(const rsmooth_mesh *m, size_t f, const uint32_t *expected, size_t n) {
    CHECK(f < m->face_count);
    CHECK_EQ_INT(m->face_offsets[f + 1] - m->face_offsets[f], n);
    for (size_t i = 0; i < n; i++)
        CHECK_EQ_INT(m->face_indices[m->face_offsets[f] + i], expected[i]);
}

/* ---- what every reader and writer owes: shared by the format tests */

/* Reads `size` bytes of `data` from an exact-size copy (ASan sees any over-read) as `format`. */
static inline rsmooth_status read_exact_copy(const void *data, size_t size, rsmooth_format format,
                                             rsmooth_mesh **mesh, rsmooth_error *err) {
    void *copy = malloc(size ? size : 1);
    CHECK(copy != NULL);
    memcpy(copy, data, size);
    rsmooth_status s = rsmooth_mesh_read_memory(copy, size, format, mesh, err);
    free(copy);
    return s;
}

/* Every prefix of a file, read through automatic detection as the command reads it, either reads or
 * fails with a parse error that locates itself (a line or a byte offset within the prefix) and
 * says more than the OBJ fallback's bare "no vertices". */
static inline void check_prefixes_located(const char *what, const void *data, size_t size) {
    for (size_t len = 0; len <= size; len++) {
        rsmooth_mesh *m = NULL;
        rsmooth_error err;
        rsmooth_status s = read_exact_copy(data, len, RSMOOTH_FORMAT_AUTO, &m, &err);
        CHECK((s == RSMOOTH_OK) == (m != NULL));
        rsmooth_mesh_destroy(m);
        if (s == RSMOOTH_OK)
            continue;
        bool located = (err.line >= 1) || (err.byte_offset >= 0 && (size_t)err.byte_offset <= len);
        if ((s != RSMOOTH_ERROR_PARSE && s != RSMOOTH_ERROR_UNSUPPORTED) || !located ||
            strcmp(err.message, "no vertices") == 0 || strlen(err.message) < 20) {
            fprintf(stderr, "%s, prefix of %zu bytes: status %d, line %lld, byte %lld: '%s'\n",
                    what, len, (int)s, (long long)err.line, (long long)err.byte_offset,
                    err.message);
            exit(1);
        }
    }
}

/* The tetrahedron (0 0 0) (1 0 0) (0 1 0) (0 0 1), its four faces outward. */
static inline rsmooth_mesh *tetrahedron(rsmooth_scalar precision) {
    static const double xyz[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    static const uint32_t faces[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
    rsmooth_mesh *m = NULL;
    rsmooth_error err;
    CHECK_EQ_INT(rsmooth_mesh_create(4, 4, 12, &m, &err), RSMOOTH_OK);
    memcpy(m->positions, xyz, sizeof xyz);
    memcpy(m->face_indices, faces, sizeof faces);
    for (uint32_t f = 1; f <= 4; f++)
        m->face_offsets[f] = 3 * f;
    m->precision = precision;
    CHECK_EQ_INT(rsmooth_mesh_triangulate(m, &err), RSMOOTH_OK);
    return m;
}

/* Writes `mesh` as `format` to memory; the status, with *size the bytes the stream received. */
static inline rsmooth_status write_to_memory(const rsmooth_mesh *mesh, rsmooth_format format,
                                             char **data, size_t *size, rsmooth_error *err) {
    *data = NULL;
    *size = 0;
    FILE *f = open_memstream(data, size);
    CHECK(f != NULL);
    rsmooth_status s = rsmooth_mesh_write_stream(mesh, f, format, err);
    CHECK(fclose(f) == 0);
    return s;
}

/* The shortest "%.Ng" text that reads back as v: how messages print a value compared with a limit
 * (1.0000000000000002e150 is not "1e+150"). */
static inline void shortest_digits(double v, char *text, size_t size) {
    for (int digits = 1; digits <= 17; digits++) {
        snprintf(text, size, "%.*g", digits, v);
        if (strtod(text, NULL) == v)
            return;
    }
}

/* The writer of `format` refuses, with INVALID_ARGUMENT, a message naming the vertex and nothing
 * written to the stream (nor a file created), every coordinate rsmooth could not read back: NaN,
 * infinities and magnitudes beyond the supported 1e150. */
static inline void check_writer_refuses_unreadable(rsmooth_format format) {
    const double bad[] = {NAN, INFINITY, -INFINITY, 1.0000000000000002e150, -1e151, 1e300};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        for (int coordinate = 0; coordinate < 3; coordinate++) {
            rsmooth_mesh *m = tetrahedron(RSMOOTH_FLOAT64);
            m->positions[3 * 2 + (size_t)coordinate] = bad[i];
            char *data;
            size_t size;
            rsmooth_error err;
            rsmooth_status s = write_to_memory(m, format, &data, &size, &err);
            /* a finite value is printed with the digits that tell it from the limit */
            char digits[40];
            shortest_digits(bad[i], digits, sizeof digits);
            if (s != RSMOOTH_ERROR_INVALID_ARGUMENT || size != 0 ||
                !strstr(err.message, "vertex 2 ") ||
                (isfinite(bad[i]) && !strstr(err.message, digits))) {
                fprintf(stderr, "format %d, coordinate %g: status %d, %zu bytes written, '%s'\n",
                        (int)format, bad[i], (int)s, size, err.message);
                exit(1);
            }
            free(data);
            /* the query runs the same checks without writing: the same status and message */
            rsmooth_error query;
            CHECK_EQ_INT(rsmooth_mesh_check_writable(m, format, &query),
                         RSMOOTH_ERROR_INVALID_ARGUMENT);
            CHECK(strcmp(query.message, err.message) == 0);
            char path[] = "/tmp/rsmooth_test_refused_XXXXXX";
            int fd = mkstemp(path);
            CHECK(fd >= 0);
            close(fd);
            remove(path);
            CHECK_EQ_INT(rsmooth_mesh_write_file(m, path, format, &err),
                         RSMOOTH_ERROR_INVALID_ARGUMENT);
            CHECK(access(path, F_OK) != 0); /* refused before the file was created */
            rsmooth_mesh_destroy(m);
        }
    }
}

/* Extreme values a writer must give back bit for bit: the supported magnitude, the smallest
 * subnormals, -0, and decimals no short form holds. */
static const double extreme_doubles[] = {1e150,
                                         -1e150,
                                         4.9406564584124654e-324,
                                         -9.8813129168249309e-324,
                                         2.2250738585072014e-308,
                                         -0.0,
                                         1e-300,
                                         0.1,
                                         -0.30000000000000004,
                                         123456789.12345679,
                                         9007199254740993.0,
                                         1.0 / 3.0};
static const float extreme_floats[] = {
    3.40282347e38f, -3.40282347e38f, 1.40129846e-45f, -2.80259693e-45f, 1.17549435e-38f, -0.0f,
    0.1f,           -0.3f,           16777217.0f,     1.0f / 3.0f,      1e-40f,          7.0f};

/* A triangle soup holding `count` values (padded with 1s) as its coordinates. */
static inline rsmooth_mesh *mesh_of_values(const double *values, size_t count,
                                           rsmooth_scalar precision) {
    size_t triangles = (count + 8) / 9;
    rsmooth_mesh *m = NULL;
    rsmooth_error err;
    CHECK_EQ_INT(rsmooth_mesh_create(3 * triangles, triangles, 3 * triangles, &m, &err),
                 RSMOOTH_OK);
    for (size_t i = 0; i < 9 * triangles; i++)
        m->positions[i] = i < count ? values[i] : (double)(i % 3 == 0);
    for (size_t i = 0; i < 3 * triangles; i++)
        m->face_indices[i] = (uint32_t)i;
    for (size_t f = 1; f <= triangles; f++)
        m->face_offsets[f] = (uint32_t)(3 * f);
    m->precision = precision;
    CHECK_EQ_INT(rsmooth_mesh_triangulate(m, &err), RSMOOTH_OK);
    return m;
}

/* Writes the extreme values as `format` and reads them back: every coordinate bit for bit (float32
 * formats get the float extremes). rsmooth reads what it writes. */
static inline void check_extremes_round_trip(rsmooth_format format, rsmooth_scalar precision) {
    double values[sizeof extreme_doubles / sizeof extreme_doubles[0]];
    size_t count = sizeof values / sizeof values[0];
    for (size_t i = 0; i < count; i++)
        values[i] = precision == RSMOOTH_FLOAT32 ? (double)extreme_floats[i] : extreme_doubles[i];
    rsmooth_mesh *m = mesh_of_values(values, count, precision);
    char *data;
    size_t size;
    rsmooth_error err;
    rsmooth_status s = write_to_memory(m, format, &data, &size, &err);
    if (s != RSMOOTH_OK)
        fprintf(stderr, "format %d: %s\n", (int)format, err.message);
    CHECK_EQ_INT(s, RSMOOTH_OK);
    rsmooth_mesh *back = NULL;
    s = read_exact_copy(data, size, RSMOOTH_FORMAT_AUTO, &back, &err);
    if (s != RSMOOTH_OK)
        fprintf(stderr, "format %d: written, then '%s' (line %lld, byte %lld)\n", (int)format,
                err.message, (long long)err.line, (long long)err.byte_offset);
    CHECK_EQ_INT(s, RSMOOTH_OK);
    CHECK_EQ_INT(back->vertex_count, m->vertex_count); /* a soup: STL keeps the order */
    for (size_t i = 0; i < 3 * m->vertex_count; i++) {
        if (memcmp(&back->positions[i], &m->positions[i], sizeof(double)) != 0) {
            fprintf(stderr, "format %d: coordinate %zu written as %.17g, read as %.17g\n",
                    (int)format, i, m->positions[i], back->positions[i]);
            exit(1);
        }
    }
    rsmooth_mesh_destroy(back);
    rsmooth_mesh_destroy(m);
    free(data);
}

/* Writes `m` as `format`: the status rsmooth_mesh_check_writable gave first (the writer must agree
 * with it, message included), and when OK the mesh read back (else NULL, nothing written). */
static inline rsmooth_mesh *write_checked(const rsmooth_mesh *m, rsmooth_format format,
                                          rsmooth_status *status, rsmooth_error *err) {
    rsmooth_error query;
    *status = rsmooth_mesh_check_writable(m, format, &query);
    char *data;
    size_t size;
    rsmooth_status s = write_to_memory(m, format, &data, &size, err);
    if (s != *status || (s != RSMOOTH_OK && strcmp(query.message, err->message) != 0)) {
        fprintf(stderr, "format %d: rsmooth_mesh_check_writable %d '%s', writer %d '%s'\n",
                (int)format, (int)*status, query.message, (int)s, err->message);
        exit(1);
    }
    rsmooth_mesh *back = NULL;
    if (s == RSMOOTH_OK) {
        CHECK_EQ_INT(read_exact_copy(data, size, RSMOOTH_FORMAT_AUTO, &back, err), RSMOOTH_OK);
    } else {
        CHECK(size == 0);
    }
    free(data);
    return back;
}

/* Float32 at the mesh's own scale (the hostile-input campaign: a tetrahedron at 1e-150 written as
 * binary STL came out as four vertices at 0 0 0 with exit 0; at 1e-45..1e-43 the float32 subnormals
 * moved vertices by up to 0.8 edge lengths). A writer whose file stores float32 (binary STL)
 * refuses such a mesh, naming the vertex and what holds it; the others write it exactly, float32
 * meshes too (their float mode falls back to the doubles). A normal-sized mesh with a stray
 * subnormal coordinate is no such mesh: float32's error there is far below its precision at the
 * mesh's scale. */
static inline void check_float32_scale(rsmooth_format format) {
    const bool float_file = format == RSMOOTH_FORMAT_STL_BINARY;
    const double scales[] = {1e-150, 1e-300, 1e-45, 1e-44, 1e-43, 1e-40};
    for (size_t i = 0; i < sizeof scales / sizeof scales[0]; i++) {
        for (int precision = 0; precision < 2; precision++) {
            rsmooth_mesh *m = tetrahedron(precision ? RSMOOTH_FLOAT32 : RSMOOTH_FLOAT64);
            for (size_t k = 0; k < 12; k++)
                m->positions[k] *= scales[i];
            m->positions[4] *= 1.25; /* vertex 1's y: no power of two, never a float */
            rsmooth_status status;
            rsmooth_error err;
            rsmooth_mesh *back = write_checked(m, format, &status, &err);
            if (float_file) {
                if (status != RSMOOTH_ERROR_INVALID_ARGUMENT || !strstr(err.message, "vertex ") ||
                    !strstr(err.message, "float32") ||
                    !strstr(err.message, "ascii STL, OBJ or a PLY with double")) {
                    fprintf(stderr, "format %d, scale %g: status %d '%s'\n", (int)format, scales[i],
                            (int)status, err.message);
                    exit(1);
                }
            } else {
                CHECK_EQ_INT(status, RSMOOTH_OK);
                CHECK_EQ_INT(back->vertex_count, io_test_is_stl(format) ? 12 : 4);
                for (size_t v = 0; v < back->vertex_count; v++) {
                    size_t source = io_test_is_stl(format) ? m->triangles[v] : v;
                    for (int c = 0; c < 3; c++) {
                        double a = m->positions[3 * source + (size_t)c];
                        double b = back->positions[3 * v + (size_t)c];
                        if (memcmp(&a, &b, sizeof a) != 0) {
                            fprintf(stderr, "format %d, scale %g: %.17g written, %.17g read\n",
                                    (int)format, scales[i], a, b);
                            exit(1);
                        }
                    }
                }
            }
            rsmooth_mesh_destroy(back);
            /* a mesh at 1, with one coordinate at that size: written by every format, float32
             * rounding within float32's precision at the mesh's scale */
            rsmooth_mesh_destroy(m);
            m = tetrahedron(precision ? RSMOOTH_FLOAT32 : RSMOOTH_FLOAT64);
            m->positions[5] = 1.25 * scales[i];
            back = write_checked(m, format, &status, &err);
            CHECK_EQ_INT(status, RSMOOTH_OK);
            for (size_t v = 0; v < back->vertex_count; v++) {
                size_t source = io_test_is_stl(format) ? m->triangles[v] : v;
                for (int c = 0; c < 3; c++) {
                    double a = m->positions[3 * source + (size_t)c];
                    CHECK(fabs(back->positions[3 * v + (size_t)c] - a) <= 0x1p-24);
                }
            }
            rsmooth_mesh_destroy(back);
            rsmooth_mesh_destroy(m);
        }
    }
    /* Float32 values at that scale that are exactly floats lose nothing: written as the floats
     * they are (text: digits that read back as that float). */
    rsmooth_mesh *m = tetrahedron(RSMOOTH_FLOAT32);
    for (size_t k = 0; k < 12; k++)
        m->positions[k] *= 0x1p-146; /* 8 times the smallest subnormal float */
    rsmooth_status status;
    rsmooth_error err;
    rsmooth_mesh *back = write_checked(m, format, &status, &err);
    CHECK_EQ_INT(status, RSMOOTH_OK);
    CHECK((float)back->positions[io_test_is_stl(format) ? 6 : 3] == 0x1p-146f);
    rsmooth_mesh_destroy(back);
    rsmooth_mesh_destroy(m);
}

#endif
