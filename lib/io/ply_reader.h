/* The PLY reader's state, shared by its parts (not installed): ply_header.c reads the header and
 * gives each property its role, ply_binary.c and ply_ascii.c read the data (with ply_element.c's
 * helpers), ply_read.c drives them and builds the mesh. */
#ifndef RSMOOTH_PLY_READER_H
#define RSMOOTH_PLY_READER_H

#include "io/ply_format.h"

#define RS_PLY_READ_WHERE "rsmooth_mesh_read (PLY)"

typedef enum rs_ply_encoding { RS_PLY_ASCII, RS_PLY_BINARY_LE, RS_PLY_BINARY_BE } rs_ply_encoding;

typedef struct rs_ply_reader {
    const char *data;
    size_t size;
    size_t pos;        /* read position in data */
    int64_t line;      /* ascii: current line, 1-based */
    bool crossed_line; /* ascii: the last token read came after a line end */
    int64_t end_header_line;
    rs_ply_encoding encoding;
    bool swap;        /* binary data in the other byte order than the host's */
    rs_ply_extras *x; /* the header, and the values kept */
    /* vertices accepted: 0 for fewer than RS_IO_MAX_VERTICES (the in-memory path's 32-bit ids);
     * streaming, with 64-bit ids, takes more */
    uint64_t max_vertices;
    /* results */
    rs_ply_element *vertex_element, *face_element;
    size_t vertex_count;
    double *positions;
    rsmooth_scalar precision;
    uint32_t *face_offsets;
    size_t face_count;
    rs_io_u32vec indices;
    bool normals;
    double *normal_values; /* 3 per vertex when `normals`: nx, ny, nz as read */
    size_t color[3]; /* property index of red, green, blue in the vertex element; SIZE_MAX: none */
    uint8_t *colors;
    /* range grid (ply_range_grid.c): the element, its size, each cell's sample (UINT32_MAX: none)
     * and each vertex's cell + 1 (0: none), to refuse a sample listed twice */
    rs_ply_element *grid_element;
    uint64_t grid_cols, grid_rows;
    uint32_t *grid_cells;
    uint64_t *grid_owner;
} rs_ply_reader;

/* PLY's blanks (header and ascii data), line ends included. */
static inline bool rs_ply_is_space(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f' || c == '\n';
}

/* ---- ply_header.c */

/* Reads the header from "ply" to "end_header": r->pos ends at the first data byte, r->line at the
 * first data line. */
rsmooth_status rs_ply_parse_header(rs_ply_reader *r, rsmooth_error *error);

/* Finds the vertex (required, with fewer than 2^32 items) and face elements. */
rsmooth_status rs_ply_find_elements(rs_ply_reader *r, rsmooth_error *error);

/* Gives each property its role (rs_ply_role) and each element its row layout. */
rsmooth_status rs_ply_assign_roles(rs_ply_reader *r, rsmooth_error *error);

/* The header is the generic writer's layout: nothing for the extras to keep. */
bool rs_ply_is_plain(const rs_ply_reader *r);

/* ---- ply_element.c: what both data readers share */

/* Starts face `item` of `n` vertices (n >= 3, room reserved), or a located error. */
rsmooth_status rs_ply_face_begin(rs_ply_reader *r, uint64_t n, uint64_t item, int64_t line,
                                 int64_t offset, rsmooth_error *error);

/* Appends a face's vertex index v (whole, in range), or a located error. */
rsmooth_status rs_ply_face_index(rs_ply_reader *r, double v, int64_t line, int64_t offset,
                                 rsmooth_error *error);

/* Checks vertex i as read (its row stored): supported coordinates, finite normals and colours. */
rsmooth_status rs_ply_check_vertex(const rs_ply_reader *r, size_t i, int64_t line, int64_t offset,
                                   rsmooth_error *error);

/* Room for `extra` more bytes of an element's list items; false when out of memory. */
bool rs_ply_list_reserve(rs_ply_element *e, size_t extra);
rsmooth_status rs_ply_list_oom(const rs_ply_element *e, rsmooth_error *error);

/* ---- ply_range_grid.c: a scanner's range grid (element range_grid) read as triangles */

/* The header's element named "range_grid", or NULL. */
rs_ply_element *rs_ply_range_grid_element(const rs_ply_extras *x);

/* Finds a range grid and checks its header (num_cols / num_rows obj_info lines whose product is
 * its count, an integer vertex_indices list, no face element), marking the list RS_PLY_GRID_LIST;
 * RSMOOTH_OK with r->grid_element NULL when there is none. Before rs_ply_assign_roles. */
rsmooth_status rs_ply_range_grid_header(rs_ply_reader *r, rsmooth_error *error);

/* Cell `item` of the grid lists `n` vertex indices (0 or 1), or a located error. */
rsmooth_status rs_ply_grid_cell(rs_ply_reader *r, uint64_t n, uint64_t item, int64_t line,
                                int64_t offset, rsmooth_error *error);

/* Cell `item`'s vertex index v (whole, in range, in no other cell), or a located error. */
rsmooth_status rs_ply_grid_index(rs_ply_reader *r, double v, uint64_t item, int64_t line,
                                 int64_t offset, rsmooth_error *error);

/* After the data: the grid's triangles into r->face_offsets / r->indices, and the extras made a
 * mesh's (the range_grid element becomes the face element; the obj_info lines describing the grid
 * are dropped). */
rsmooth_status rs_ply_range_grid_triangulate(rs_ply_reader *r, rsmooth_error *error);

/* ---- ply_binary.c, ply_ascii.c: one element's items from r->pos (its count already bounded by
 * the bytes left; rows, positions, normals and face offsets allocated) */
rsmooth_status rs_ply_read_binary_element(rs_ply_reader *r, rs_ply_element *e,
                                          rsmooth_error *error);
rsmooth_status rs_ply_read_ascii_element(rs_ply_reader *r, rs_ply_element *e, rsmooth_error *error);

#endif /* RSMOOTH_PLY_READER_H */
