/* Streaming a mesh larger than memory (not installed): the parts of rsmooth_stream_smooth.
 *
 *   stream_files.c   temporary files, buffered sequential reads and positioned writes
 *   stream_ply.c     a binary PLY's layout, its vertex block and its faces as triangles
 *   stream_stats.c   the whole mesh's figures, summed as the in-memory path sums them
 *   stream_pieces.c  spatial pieces: a grid of counts cut into boxes, and their files
 *   stream_smooth.c  the pipeline (rsmooth_stream_smooth)
 */
#ifndef RSMOOTH_STREAM_INTERNAL_H
#define RSMOOTH_STREAM_INTERNAL_H

#include "io/ply_reader.h"
#include "rsmooth_io.h"

#include <stdbool.h>
#include <stdint.h>
#include <string.h>

#define RS_STREAM_WHERE "rsmooth_stream_smooth"
/* How a caller of rsmooth_stream_smooth asks for an existing output to be replaced. */
#define RS_STREAM_REPLACE_HINT "set options->replace"

/* ---- stream_files.c ------------------------------------------------------------------------ */

/* A file read front to back through a buffer, from byte `pos` to `end`. */
typedef struct rs_stream_reader {
    int fd;
    const char *name; /* for messages */
    uint64_t pos, end;
    unsigned char *buf;
    size_t cap, at, len; /* buf[at, len) is unread */
} rs_stream_reader;

bool rs_stream_reader_open(rs_stream_reader *r, int fd, const char *name, uint64_t pos,
                           uint64_t end, size_t cap);
void rs_stream_reader_close(rs_stream_reader *r);
/* The next n (<= cap) bytes, or NULL at the end or on a read error (rs_stream_reader_failed). */
const unsigned char *rs_stream_read(rs_stream_reader *r, size_t n);
/* Where the next unread byte sits in the file. */
static inline uint64_t rs_stream_reader_offset(const rs_stream_reader *r) {
    return r->pos - (r->len - r->at);
}

/* The temporary triangle file (3 uint32 vertex ids per triangle), read front to back. */
bool rs_stream_triangles_open(rs_stream_reader *r, int fd, uint64_t triangle_count);
/* Triangles [first, end) only: readers of one file at different places may run at once (each
 * reads with pread at its own offset). */
bool rs_stream_triangles_open_range(rs_stream_reader *r, int fd, uint64_t first, uint64_t end);
/* The next triangle's ids into tri; false at the end or on a read error. */
static inline bool rs_stream_next_triangle(rs_stream_reader *r, uint32_t tri[3]) {
    const unsigned char *rec = rs_stream_read(r, 3 * sizeof(uint32_t));
    if (rec)
        memcpy(tri, rec, 3 * sizeof(uint32_t));
    return rec != NULL;
}

/* An unnamed temporary file in `dir` (O_TMPFILE, else created and unlinked at once), so that
 * nothing is left behind however the process ends. -1 with errno on failure. */
int rs_stream_temporary(const char *dir);

/* Copies `size` bytes of `from` at `from_offset` to `to` at `to_offset` (copy_file_range where
 * it works). */
bool rs_stream_copy(int from, uint64_t from_offset, int to, uint64_t to_offset, uint64_t size);

/* Appends records to many regions of one file (the pieces' lists): each region has its own
 * small buffer, flushed with a positioned write at the region's running offset. */
typedef struct rs_region_writer {
    int fd;
    size_t regions, record, per_buffer; /* bytes per record; records per buffer */
    uint64_t *next;                     /* per region: where its next record goes */
    uint32_t *filled;                   /* per region: records buffered */
    unsigned char *buffers;             /* regions * per_buffer * record */
} rs_region_writer;

/* Regions start at `starts` (in records: region i's first record is starts[i]); `memory` bounds
 * the buffers. */
bool rs_region_writer_init(rs_region_writer *w, int fd, size_t regions, size_t record,
                           const uint64_t *starts, size_t memory);
bool rs_region_append(rs_region_writer *w, size_t region, const void *record);
bool rs_region_writer_finish(rs_region_writer *w); /* flushes and frees */
void rs_region_writer_free(rs_region_writer *w);

/* ---- stream_ply.c -------------------------------------------------------------------------- */

/* The input, and the output as rs_io_ply_write writes it from memory: the header that writer
 * gives (the generic one, with its comment, for a file it keeps no extras of), then the input's
 * data little-endian, x y z rewritten. Offsets are bytes from the start of the file. */
typedef struct rs_stream_ply {
    int fd;
    const char *path;
    uint64_t size;        /* of the file */
    bool bom;             /* it opens with a UTF-8 byte-order mark (kept in the output) */
    rs_ply_reader header; /* the parsed header (data: a copy of the header bytes after the mark) */
    bool plain;           /* rs_ply_is_plain: written from memory with the generic header */
    bool swap;            /* data in the other byte order than the host's */
    bool out_swap;        /* the output (little-endian) in the other byte order than the host's */
    uint64_t vertex_count, face_count;
    uint64_t data_start, data_end; /* the elements' data (data_end: once the faces are read) */
    uint64_t vertex_start;         /* the vertex block */
    size_t vertex_stride;          /* bytes per vertex row */
    size_t xyz_offset[3];
    rs_ply_type xyz_type; /* FLOAT32 or FLOAT64, the same for x, y and z */
    uint64_t face_start;  /* the face block */
    double magnitude;     /* the largest |coordinate| read: the mesh's scale for float32 */
    char *out_header;     /* the output's header bytes, its mark included */
    size_t out_header_size;
} rs_stream_ply;

/* Opens `path` and reads its header (holding at most `header_memory` bytes of it) and layout;
 * refuses (UNSUPPORTED, naming the file and why) what streaming cannot do. */
rsmooth_status rs_stream_ply_open(rs_stream_ply *ply, const char *path, uint64_t header_memory,
                                  rsmooth_error *error);
void rs_stream_ply_close(rs_stream_ply *ply);

/* Writes the output's header and the input's data into `out_fd` (from offset 0): the copy the
 * results are written into. Needs data_end (rs_stream_ply_write_triangles). */
bool rs_stream_ply_write_copy(const rs_stream_ply *ply, int out_fd);

/* The vertices' extent: their bounding box and largest |coordinate|. */
typedef struct rs_stream_extent {
    double lo[3], hi[3];
    double magnitude;
} rs_stream_extent;

/* Reads every vertex's x, y, z into `xyz` (3 per vertex, floats when xyz_type is FLOAT32, else
 * doubles), checking each, and measures their extent on the way. */
rsmooth_status rs_stream_ply_read_vertices(rs_stream_ply *ply, void *xyz, rs_stream_extent *extent,
                                           rsmooth_error *error);

/* Reads the faces, fans each into triangles as the in-memory reader does, and writes their
 * vertex indices (3 uint32 each) to `triangles_fd`; *triangle_count receives how many. */
rsmooth_status rs_stream_ply_write_triangles(rs_stream_ply *ply, int triangles_fd,
                                             uint64_t *triangle_count, rsmooth_error *error);

/* Refuses positions (3 doubles each, of the vertices `ids[0, n)`) the output cannot hold, as
 * rs_io_ply_check refuses them in memory (its message, after "OUTPUT: cannot write: "):
 * RSMOOTH_ERROR_NUMERICAL, before any of them is written. */
rsmooth_status rs_stream_ply_check_positions(const rs_stream_ply *ply, const uint32_t *ids,
                                             size_t n, const double *xyz, const char *output,
                                             rsmooth_error *error);

/* Writes vertex positions (3 doubles each) of the vertices `ids[0, n)` (ascending) into the
 * output file `out_fd` (rs_stream_ply_write_copy's), in the file's type. */
bool rs_stream_ply_write_positions(const rs_stream_ply *ply, int out_fd, const uint32_t *ids,
                                   size_t n, const double *xyz);

/* ---- stream_stats.c ------------------------------------------------------------------------ */

/* The vertex positions held in memory, in the file's type. */
typedef struct rs_stream_positions {
    const void *xyz;
    bool f32;
    uint64_t count;
} rs_stream_positions;

static inline void rs_stream_position(const rs_stream_positions *p, uint64_t v, double out[3]) {
    for (int k = 0; k < 3; k++)
        out[k] = p->f32 ? (double)((const float *)p->xyz)[3 * v + (uint64_t)k]
                        : ((const double *)p->xyz)[3 * v + (uint64_t)k];
}

/* rs_triangle_geometry of triangle `tri` with its corners times `scale` (internal units):
 * whether it is a facet, and then its centroid (scaled) and area. */
static inline bool rs_stream_facet(const rs_stream_positions *p, const uint32_t tri[3],
                                   double scale, double corners[9], double centroid[3],
                                   double *area) {
    static const uint32_t local[3] = {0, 1, 2};
    double normal[3];
    for (int c = 0; c < 3; c++) {
        rs_stream_position(p, tri[c], corners + 3 * c);
        for (int k = 0; k < 3; k++)
            corners[3 * c + k] *= scale;
    }
    return rs_triangle_geometry(corners, local, centroid, normal, area);
}

typedef struct rs_stream_stats {
    double scale;            /* power of two the sums run at (exact; see stream_stats.c) */
    double mean_edge_length; /* caller's units */
    double mean_area;
    /* the two at `scale` (internal units), as the in-memory path holds them: in the caller's
     * units a mesh at 1e-300 has no representable area */
    double scaled_mean_edge_length, scaled_mean_area;
    double reach; /* largest centroid-to-corner distance of a facet */
    uint64_t facet_count;
    double lo[3], hi[3]; /* the vertices' bounding box */
    bool whole;          /* one part, no edge out of line (core/parts.h): what streams */
} rs_stream_stats;

/* The figures of the mesh whose triangles are in `triangles_fd`, with at most `memory` bytes of
 * working memory for the unique edges. */
rsmooth_status rs_stream_statistics(const rs_stream_positions *positions, int triangles_fd,
                                    uint64_t triangle_count, const rs_stream_extent *extent,
                                    uint64_t memory, rs_stream_stats *stats, rsmooth_error *error);

/* ---- stream_pieces.c ----------------------------------------------------------------------- */

typedef struct rs_piece {
    uint64_t vertex_start, vertex_count; /* in the vertex list file, records */
    uint64_t facet_start, facet_count;   /* in the facet list file, records (3 uint32) */
    int rank;                            /* who filters it */
} rs_piece;

typedef struct rs_stream_pieces {
    rs_piece *pieces;
    size_t count;
    int vertex_fd, facet_fd; /* the lists (facets only of this rank's pieces) */
    uint64_t temporary_bytes;
} rs_stream_pieces;

/* Cuts the mesh into pieces of at most about `piece_vertices` core vertices, shares them among
 * `ranks` by their facet counts, and writes each piece's core vertex ids and (for this `rank`'s
 * pieces) its facets within `halo` to temporary files in `dir`. */
rsmooth_status rs_stream_pieces_build(const rs_stream_positions *positions, int triangles_fd,
                                      uint64_t triangle_count, const rs_stream_stats *stats,
                                      double halo, uint64_t piece_vertices, size_t buffer_memory,
                                      int rank, int ranks, const char *dir, rs_stream_pieces *out,
                                      rsmooth_error *error);
void rs_stream_pieces_free(rs_stream_pieces *pieces);

#endif /* RSMOOTH_STREAM_INTERNAL_H */
