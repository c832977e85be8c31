/* Shared by the mesh-file tests and the seed corpus: a byte buffer, writing to memory, faces. */
#ifndef RSMOOTH_TEST_IO_UTIL_H
#define RSMOOTH_TEST_IO_UTIL_H

#include "rsmooth_io.h"
#include "test_util.h"

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

#endif
