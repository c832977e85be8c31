/* Helpers shared by the mesh file readers and writers (not installed). Prefix rs_io_.
 *
 * Calls run one way, down this list (a file calls only files below it):
 *   mesh_file.c     the public reads and writes: the dispatch to each format's check and writer
 *   mesh_detect.c   reading from memory: which format, then its reader
 *   *_read.c        the readers (ply_read.c over ply_header.c, ply_ascii.c / ply_binary.c, then
 *                   ply_element.c)
 *   *_write.c       the writers and their own checks (over text_out.c, float_print.c and
 *                   mesh_normals.c; OBJ's and OFF's through text_mesh_write.c, which calls those)
 *   mesh_data.c     the mesh record (create, destroy, adopt) and the conversion-loss report
 *   mesh_check.c    the well-formedness and value checks every writer makes
 *   *_extras.c      each format's extras record: its release and what a conversion drops
 *   coordinates.c, float32_check.c, bom.c, losses.c: small helpers that call nothing in io/ */
#ifndef RSMOOTH_IO_INTERNAL_H
#define RSMOOTH_IO_INTERNAL_H

#include "core/rsmooth_internal.h"
#include "rsmooth_io.h"

#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

/* Vertex indices are uint32, so a mesh holds fewer than 2^32 vertices; face_offsets are uint32 too,
 * so the faces hold fewer than 2^32 indices in all. */
#define RS_IO_MAX_VERTICES ((uint64_t)UINT32_MAX)
#define RS_IO_MAX_FACE_INDICES ((uint64_t)UINT32_MAX)

/* The UTF-8 byte-order mark some editors put before text (EF BB BF). */
#define RS_IO_UTF8_BOM "\xEF\xBB\xBF"
#define RS_IO_UTF8_BOM_SIZE 3

/* A coordinate readers accept and writers write: finite and within RS_MAX_COORDINATE, the range the
 * filter supports (so what rsmooth writes, rsmooth reads). */
static inline bool rs_io_coordinate_ok(double x) {
    return x >= -RS_MAX_COORDINATE && x <= RS_MAX_COORDINATE; /* false for NaN */
}

/* The shortest decimal form of v that reads back as v (up to 17 significant digits), for messages
 * that compare a value with a limit: "%g" prints 1.0000001e150 as the limit 1e+150 itself. The
 * text lives as long as the full expression that calls this. */
typedef struct rs_io_digits {
    char text[32];
} rs_io_digits;
rs_io_digits rs_io_shortest(double v);

/* Checks a vertex's x y z as read (rs_io_coordinate_ok), failing with a parse error at `line` /
 * `byte_offset` that names vertex `number` (numbered as the format numbers vertices). */
rsmooth_status rs_io_check_vertex(const double xyz[3], size_t number, int64_t line,
                                  int64_t byte_offset, const char *where, rsmooth_error *error);

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

/* Checks the values a writer would write, before it writes anything: every position
 * (rs_io_coordinate_ok) and vertex_quality value finite, naming the first vertex that is not.
 * RSMOOTH_ERROR_INVALID_ARGUMENT otherwise. */
rsmooth_status rs_io_mesh_check_values(const rsmooth_mesh *mesh, const char *where,
                                       rsmooth_error *error);

/* rs_io_mesh_check_values' check of positions on `count` of them: the i-th at xyz + 3 i, named
 * vertex ids[i] (i when ids is NULL; the streamed writer checks a piece's at a time). */
rsmooth_status rs_io_check_position_values(const double *xyz, size_t count, const uint64_t *ids,
                                           const char *where, rsmooth_error *error);

/* A coordinate float32 cannot hold at the mesh's own scale: beyond FLT_MAX, or rounded by more
 * than float32's precision relative to the largest coordinate magnitude, |x - (float)x| >
 * 2^-24 * largest. No normal float is that far off, so in practice: a value beyond float range,
 * or a whole mesh below FLT_MIN (1.2e-38) whose subnormal floats lose its shape (a mesh at 1 with
 * a stray 1e-40 is held). */
typedef struct rs_io_float32_misfit {
    size_t vertex;
    int axis;       /* 0, 1, 2: x, y, z */
    double value;   /* the coordinate */
    double rounded; /* as a float32 */
    double largest; /* the mesh's largest coordinate magnitude */
} rs_io_float32_misfit;

/* How far float32 may round a coordinate of a mesh whose largest magnitude is `largest`. A normal
 * float rounds within 2^-24 of its own magnitude, so only values beyond FLT_MAX, or subnormal ones
 * in a mesh whose largest coordinate is itself about as small, exceed it. */
static inline double rs_io_float32_tolerance(double largest) {
    return ldexp(largest, -24);
}

/* Whether coordinate x is a misfit at that tolerance: the one test every float32 writer makes. */
static inline bool rs_io_float32_misfits(double x, double tolerance) {
    float f = (float)x;
    return !isfinite(f) || fabs(x - (double)f) > tolerance;
}

/* Finds the first misfit among the vertices `indices` names (index_count entries; every one of
 * vertex_count when indices is NULL), in the components whose bit is set in `axes` (1 x, 2 y,
 * 4 z), the scale taken from all three of those vertices'. false when there is none. */
bool rs_io_float32_misfit_find(const double *xyz, size_t vertex_count, const uint32_t *indices,
                               size_t index_count, unsigned axes, rs_io_float32_misfit *misfit);

/* A float32 mesh whose positions (and a point cloud's own normals) float32 holds at their scale:
 * text writers then write them at float precision (shortest digits of the float), else every value
 * as the double it is. */
bool rs_io_float32_holds(const rsmooth_mesh *mesh);

/* Each format's own refusals (before its writer runs; the mesh already passed rs_io_mesh_check and
 * rs_io_mesh_check_values): what its file cannot hold (STL: no triangles, binary STL's float32;
 * PLY: the input's declared types), and the normals it would write. */
rsmooth_status rs_io_obj_check(const rsmooth_mesh *mesh, rsmooth_error *error);
rsmooth_status rs_io_ply_check(const rsmooth_mesh *mesh, rsmooth_error *error);
rsmooth_status rs_io_off_check(const rsmooth_mesh *mesh, rsmooth_error *error);
rsmooth_status rs_io_stl_check(const rsmooth_mesh *mesh, bool binary, rsmooth_error *error);

/* Format parsers over a buffer that is not NUL-terminated (obj_read.c, ply_read.c). */
rsmooth_status rs_io_obj_read(const char *data, size_t size, rsmooth_mesh **mesh,
                              rsmooth_error *error);
rsmooth_status rs_io_ply_read(const char *data, size_t size, rsmooth_mesh **mesh,
                              rsmooth_error *error);

/* Format writers; the mesh already passed rs_io_check_writable. Each writes faithfully from its own
 * format's extras when the mesh has them, else the generic fields (positions, faces, vertex_colors,
 * vertex_quality, has_vertex_normals) it can hold. */
rsmooth_status rs_io_obj_write(const rsmooth_mesh *mesh, FILE *stream, rsmooth_error *error);
rsmooth_status rs_io_ply_write(const rsmooth_mesh *mesh, FILE *stream, bool binary,
                               rsmooth_error *error);
rsmooth_status rs_io_off_read(const char *data, size_t size, rsmooth_mesh **mesh,
                              rsmooth_error *error);
rsmooth_status rs_io_off_write(const rsmooth_mesh *mesh, FILE *stream, rsmooth_error *error);
rsmooth_status rs_io_stl_read(const char *data, size_t size, rsmooth_mesh **mesh,
                              rsmooth_error *error);
rsmooth_status rs_io_stl_write(const rsmooth_mesh *mesh, FILE *stream, bool binary,
                               rsmooth_error *error);

/* Whether there are normals to write: recomputed from triangles, or a point cloud's own (a point
 * cloud whose file held normals that matched no vertex has none). */
static inline bool rs_io_normals_available(const rsmooth_mesh *mesh) {
    return mesh->triangle_count > 0 || mesh->vertex_normals;
}

/* The mesh's own normals are what writers emit (a point cloud: no triangle to recompute from). */
static inline bool rs_io_normals_are_data(const rsmooth_mesh *mesh) {
    return mesh->triangle_count == 0 && mesh->vertex_normals;
}

/* What rs_io_vertex_normals refuses, checked without computing: a point cloud's own normals must be
 * finite; recomputing needs the triangles (present, indices in range). */
rsmooth_status rs_io_check_normals(const rsmooth_mesh *mesh, const char *where,
                                   rsmooth_error *error);

/* The normals writers emit, recomputed from the positions (a mesh without triangles, a point cloud:
 * its vertex_normals): 3 * vertex_count doubles in a new *normals (the caller frees it), or an
 * error naming `where`. */
rsmooth_status rs_io_vertex_normals(const rsmooth_mesh *mesh, double **normals, const char *where,
                                    rsmooth_error *error);

/* ---- extras: what a format keeps beyond positions and faces ---------------------------------- */

/* Each format defines its own record (its *_format.h), released and reported in its own *_extras.c;
 * a mesh holds at most one of them, the one its reader made. */
typedef struct rs_ply_extras rs_ply_extras;
typedef struct rs_obj_extras rs_obj_extras;
typedef struct rs_off_extras rs_off_extras;
typedef struct rs_stl_extras rs_stl_extras;

struct rsmooth_mesh_extras {
    rs_ply_extras *ply;
    rs_obj_extras *obj;
    rs_off_extras *off;
    rs_stl_extras *stl;
    bool utf8_bom; /* the text began with a UTF-8 byte-order mark (mesh->source_format's family) */
};

/* Whether writing `mesh` as `format` writes the byte-order mark it was read with: in the source's
 * own format family, where the file opens with text (all but binary STL, whose header is bytes). */
bool rs_io_keeps_bom(const rsmooth_mesh *mesh, rsmooth_format format);

/* Writes the byte-order mark when rs_io_keeps_bom; false when the stream fails. Writers call it
 * after their checks, before their first byte. */
bool rs_io_put_bom(const rsmooth_mesh *mesh, rsmooth_format format, FILE *stream);

/* ---- text_mesh_write.c: what the text mesh writers (OBJ, OFF) share */

/* The body of a text mesh file (OBJ, OFF): writes `mesh` through `out`, with `extras` the format's
 * record of what the file was read with (NULL: rsmooth's own layout) and `normals` per-vertex
 * normals (or NULL). */
struct rs_io_text_out;
typedef void (*rs_io_text_body)(const rsmooth_mesh *mesh, const void *extras, const double *normals,
                                bool as_float, struct rs_io_text_out *out);

/* Writes a text mesh file to `stream`: the vertex normals computed first when `want_normals`
 * (rs_io_vertex_normals: its errors), its byte-order mark (rs_io_put_bom), then `faithful` with
 * `extras` where they describe the mesh (not NULL), else `generic`, through a buffered text
 * writer; then flushes the stream. `as_float` for the bodies: rs_io_float32_holds(mesh).
 * RSMOOTH_ERROR_IO ("writing NAME: reason") when any write fails. */
rsmooth_status rs_io_text_write_mesh(const rsmooth_mesh *mesh, FILE *stream, rsmooth_format format,
                                     const char *name, rs_io_text_body faithful,
                                     rs_io_text_body generic, const void *extras, bool want_normals,
                                     const char *where, rsmooth_error *error);

/* v so that it reads back as the same value (the same float when `as_float`), in its shortest
 * decimal (float_print.h: "%.15g"'s text when that is shortest, so unchanged coordinates keep
 * their short form). A value beyond float range is written as the double it is. */
void rs_io_text_coordinate(struct rs_io_text_out *out, double v, bool as_float);

/* " n", a vertex normal's component: a point cloud's own normals (`exact`: its data) as
 * rs_io_text_coordinate writes them, so that they read back exactly; recomputed ones to 9 digits
 * (ample for a unit vector; "%.9g"). */
void rs_io_text_normal(struct rs_io_text_out *out, double n, bool exact, bool as_float);

/* Each frees its record (accepts NULL). */
void rs_io_ply_extras_free(rs_ply_extras *extras);
void rs_io_obj_extras_free(rs_obj_extras *extras);
void rs_io_off_extras_free(rs_off_extras *extras);
void rs_io_stl_extras_free(rs_stl_extras *extras);

/* Appends to `list` (a comma-separated line, capacity `size`) each kind of data in `extras` that
 * `target` cannot hold, returning how many it appended. Helper for the list: rs_io_loss_add. */
size_t rs_io_ply_losses(const rs_ply_extras *extras, rsmooth_format target, char *list,
                        size_t size);
size_t rs_io_obj_losses(const rs_obj_extras *extras, rsmooth_format target, char *list,
                        size_t size);
size_t rs_io_off_losses(const rs_off_extras *extras, rsmooth_format target, char *list,
                        size_t size);
size_t rs_io_stl_losses(const rs_stl_extras *extras, rsmooth_format target, char *list,
                        size_t size);

/* Appends ", what" (or "what" to an empty list) to `list`; returns 1 for counting. */
size_t rs_io_loss_add(char *list, size_t size, const char *what);

/* A mesh's extras record, created empty on first use (NULL when out of memory). */
struct rsmooth_mesh_extras *rs_io_mesh_extras(rsmooth_mesh *mesh);

/* true when `format` is one of the PLY / STL encodings. */
static inline bool rs_io_is_ply(rsmooth_format f) {
    return f == RSMOOTH_FORMAT_PLY_ASCII || f == RSMOOTH_FORMAT_PLY_BINARY ||
           f == RSMOOTH_FORMAT_PLY_BINARY_BE;
}
static inline bool rs_io_is_stl(rsmooth_format f) {
    return f == RSMOOTH_FORMAT_STL_ASCII || f == RSMOOTH_FORMAT_STL_BINARY;
}

#endif /* RSMOOTH_IO_INTERNAL_H */
