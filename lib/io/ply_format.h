/* PLY types and the extras record shared by the PLY reader, writer and loss report (not installed).
 */
#ifndef RSMOOTH_PLY_FORMAT_H
#define RSMOOTH_PLY_FORMAT_H

#include "io/io_internal.h"

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

typedef enum rs_ply_type {
    RS_PLY_NONE = 0,
    RS_PLY_INT8,
    RS_PLY_UINT8,
    RS_PLY_INT16,
    RS_PLY_UINT16,
    RS_PLY_INT32,
    RS_PLY_UINT32,
    RS_PLY_FLOAT32,
    RS_PLY_FLOAT64
} rs_ply_type;

static inline size_t rs_ply_type_size(rs_ply_type t) {
    switch (t) {
    case RS_PLY_INT8:
    case RS_PLY_UINT8:
        return 1;
    case RS_PLY_INT16:
    case RS_PLY_UINT16:
        return 2;
    case RS_PLY_INT32:
    case RS_PLY_UINT32:
    case RS_PLY_FLOAT32:
        return 4;
    case RS_PLY_FLOAT64:
        return 8;
    case RS_PLY_NONE:
        break;
    }
    return 0;
}

static inline bool rs_ply_type_is_float(rs_ply_type t) {
    return t == RS_PLY_FLOAT32 || t == RS_PLY_FLOAT64;
}

/* The header's words for the types, in pairs (classic name, sized name) per type: spelling s names
 * type 1 + s / 2. Kept per property so a written header spells its types as the input did. */
#define RS_PLY_SPELLING_COUNT 16u

static inline const char *rs_ply_spelling(unsigned spelling) {
    static const char *const names[RS_PLY_SPELLING_COUNT] = {
        "char", "int8",  "uchar", "uint8",  "short", "int16",   "ushort", "uint16",
        "int",  "int32", "uint",  "uint32", "float", "float32", "double", "float64"};
    return spelling < RS_PLY_SPELLING_COUNT ? names[spelling] : "?";
}

static inline rs_ply_type rs_ply_spelling_type(unsigned spelling) {
    return spelling < RS_PLY_SPELLING_COUNT ? (rs_ply_type)(1 + spelling / 2) : RS_PLY_NONE;
}

/* The classic spelling of a type. */
static inline uint8_t rs_ply_canonical_spelling(rs_ply_type t) {
    return (uint8_t)(2 * ((unsigned)t - 1));
}

/* true on a little-endian host (folded to a constant by compilers). */
static inline bool rs_ply_host_is_le(void) {
    const uint16_t one = 1;
    unsigned char first;
    memcpy(&first, &one, 1);
    return first == 1;
}

/* A value stored in host byte order, as a double (exact: every PLY type fits). */
static inline double rs_ply_host_value(const unsigned char *p, rs_ply_type t) {
    switch (t) {
    case RS_PLY_INT8:
        return (double)(int8_t)p[0];
    case RS_PLY_UINT8:
        return (double)p[0];
    case RS_PLY_INT16: {
        int16_t x;
        memcpy(&x, p, sizeof x);
        return x;
    }
    case RS_PLY_UINT16: {
        uint16_t x;
        memcpy(&x, p, sizeof x);
        return x;
    }
    case RS_PLY_INT32: {
        int32_t x;
        memcpy(&x, p, sizeof x);
        return x;
    }
    case RS_PLY_UINT32: {
        uint32_t x;
        memcpy(&x, p, sizeof x);
        return x;
    }
    case RS_PLY_FLOAT32: {
        float x;
        memcpy(&x, p, sizeof x);
        return x;
    }
    case RS_PLY_FLOAT64: {
        double x;
        memcpy(&x, p, sizeof x);
        return x;
    }
    case RS_PLY_NONE:
        break;
    }
    return 0;
}

/* What a property's values are to the reader and writers. */
typedef enum rs_ply_role {
    RS_PLY_STORED = 0, /* kept in the element's rows (a list: its count) and list items */
    RS_PLY_X,          /* vertex positions: mesh->positions, not kept here */
    RS_PLY_Y,
    RS_PLY_Z,
    RS_PLY_NX, /* vertex normals (float or double): recomputed by writers, not kept */
    RS_PLY_NY,
    RS_PLY_NZ,
    RS_PLY_FACE_LIST, /* the face element's vertex indices: mesh->face_*, not kept here */
    RS_PLY_GRID_LIST  /* a range_grid element's vertex indices: triangulated (ply_range_grid.c) */
} rs_ply_role;

typedef struct rs_ply_property {
    char *name;                       /* NUL-terminated, owned */
    rs_ply_type type;                 /* a scalar's type, or the type of a list's items */
    rs_ply_type count_type;           /* a list's count type; RS_PLY_NONE for a scalar */
    uint8_t spelling, count_spelling; /* the header's words for them (rs_ply_spelling) */
    uint8_t role;                     /* rs_ply_role */
    bool color;                       /* a stored vertex colour channel (also in vertex_colors) */
    size_t row_offset; /* STORED: where its value (a list: its count) sits in a row */
} rs_ply_property;

/* One element of the header with its stored values. Values are in host byte order, each in the
 * property's own type: a row of row_size bytes per item holds the STORED scalars and the counts of
 * the STORED lists (in their count types), in property order; the lists' items follow one another
 * in list_items in file order (item by item, list by list), so a reader of the rows walks
 * list_items in step. Memory is about the size of the kept data in a binary file. */
typedef struct rs_ply_element {
    char *name; /* NUL-terminated, owned */
    uint64_t count;
    int64_t header_line; /* for the reader's messages */
    rs_ply_property *properties;
    size_t property_count, property_capacity;
    size_t row_size;
    unsigned char *rows;       /* count * row_size bytes; NULL when that is 0 */
    unsigned char *list_items; /* list_bytes bytes */
    size_t list_bytes, list_capacity;
} rs_ply_element;

/* A "comment ..." or "obj_info ..." header line, with where it stood. */
typedef struct rs_ply_comment {
    char *text;            /* the whole line from its keyword, without the line end; owned */
    size_t before_element; /* elements declared before it */
    bool before_format;    /* it came before the 'format' line */
} rs_ply_comment;

struct rs_ply_extras {
    rs_ply_comment *comments;
    size_t comment_count, comment_capacity;
    rs_ply_element *elements; /* header order */
    size_t element_count, element_capacity;
    size_t vertex_element, face_element; /* indices into elements; SIZE_MAX when absent */
    /* The faces were triangulated from a range grid of grid_cols x grid_rows cells holding
     * grid_samples samples (ply_range_grid.c); all 0 otherwise. */
    uint64_t grid_cols, grid_rows, grid_samples;
    /* Kept only for the grid's size above: the layout is the generic writer's (rs_ply_is_plain,
     * once the grid is faces and its obj_info lines are gone), so the mesh is written as a plain
     * file is, and what is written reads back as a plain file and is written the same again. */
    bool plain;
};

/* ---- ply_write.c: what the streamed writer (lib/stream) shares with rs_io_ply_write, so that a
 * file streamed and one written from memory are the same bytes */

/* Writes the header rs_io_ply_write gives a binary PLY read with header `x` (roles assigned),
 * counts unchanged and no normals: `plain` (rs_ply_is_plain: the reader keeps no extras), the
 * generic header, "comment written by rsmooth" and x y z as float when `f32`, else double;
 * otherwise the file's own header (its comments, elements and type words), little-endian. After
 * a UTF-8 byte-order mark when `bom`. false when the stream fails. */
bool rs_io_ply_write_binary_header(FILE *stream, const rs_ply_extras *x, bool plain, bool bom,
                                   bool f32);

/* The checks rs_io_ply_check makes of x y z before writing (the positions' values, each held by
 * its property's type, float32 ones within float32's precision at `largest`, the mesh's largest
 * coordinate magnitude), on `count` positions: the i-th at xyz + 3 i, vertex ids[i] (i when ids
 * is NULL), of vertex element `v`. RSMOOTH_ERROR_INVALID_ARGUMENT naming the first that fails,
 * in rs_io_ply_check's words. */
rsmooth_status rs_io_ply_check_positions(const double *xyz, size_t count, const uint64_t *ids,
                                         const rs_ply_element *v, double largest,
                                         rsmooth_error *error);

#endif /* RSMOOTH_PLY_FORMAT_H */
