/* Helpers shared by the mesh file readers and writers (not installed). Prefix rs_io_. */
#ifndef RSMOOTH_IO_INTERNAL_H
#define RSMOOTH_IO_INTERNAL_H

#include "rsmooth_internal.h"
#include "rsmooth_io.h"

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

/* Vertex indices are uint32, so a mesh holds fewer than 2^32 vertices; face_offsets are uint32 too,
 * so the faces hold fewer than 2^32 indices in all. */
#define RS_IO_MAX_VERTICES ((uint64_t)UINT32_MAX)
#define RS_IO_MAX_FACE_INDICES ((uint64_t)UINT32_MAX)

/* Parses the whole token s[0, len) as a decimal floating-point number. Exact (correctly rounded)
 * fast path for plain decimals, strtod on a bounded NUL-terminated copy otherwise. Accepts what
 * strtod accepts (so "nan" and "inf" parse, to be rejected as non-finite by the caller). */
bool rs_io_parse_double(const char *s, size_t len, double *out);

/* A growable uint32 array (geometric growth, no per-item allocation). */
typedef struct rs_io_u32vec {
    uint32_t *data;
    size_t count;
    size_t capacity;
} rs_io_u32vec;

/* Makes room for `extra` more items; false when out of memory. */
bool rs_io_u32vec_reserve(rs_io_u32vec *vec, size_t extra);

/* Builds a mesh from parsed arrays, taking ownership of them (they are freed on failure too):
 * positions (3 * vertex_count), face_offsets (face_count + 1, may be NULL when face_count is 0) and
 * face_indices (already checked against vertex_count by the parser). Fans the faces into triangles.
 */
rsmooth_status rs_io_mesh_adopt(double *positions, size_t vertex_count, rsmooth_scalar precision,
                                uint32_t *face_offsets, size_t face_count, uint32_t *face_indices,
                                rsmooth_format format, rsmooth_mesh **mesh, rsmooth_error *error);

/* Checks a mesh given to a writer (arrays present, offsets increasing, faces of >= 3 in-range
 * indices) so the writers never read out of bounds. RSMOOTH_ERROR_INVALID_ARGUMENT otherwise. */
rsmooth_status rs_io_mesh_check(const rsmooth_mesh *mesh, const char *where, rsmooth_error *error);

/* Format parsers over a buffer that is not NUL-terminated (obj_read.c, ply_read.c). */
rsmooth_status rs_io_obj_read(const char *data, size_t size, rsmooth_mesh **mesh,
                              rsmooth_error *error);
rsmooth_status rs_io_ply_read(const char *data, size_t size, rsmooth_mesh **mesh,
                              rsmooth_error *error);

/* Format writers (obj_write.c, ply_write.c); the mesh is already checked. */
rsmooth_status rs_io_obj_write(const rsmooth_mesh *mesh, FILE *stream, rsmooth_error *error);
rsmooth_status rs_io_ply_write(const rsmooth_mesh *mesh, FILE *stream, bool binary,
                               rsmooth_error *error);

#endif /* RSMOOTH_IO_INTERNAL_H */
