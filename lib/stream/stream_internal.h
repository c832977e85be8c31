/* Streaming a mesh larger than memory (not installed): the parts of rsmooth_stream_smooth.
 *
 *   stream_files.c     temporary files, buffered sequential reads and positioned writes
 *   stream_ply.c       a binary PLY's layout, its vertex block and its faces as triangles
 *   stream_vertices.c  the positions: held whole when they fit, else read a run at a time
 *   stream_corners.c   the triangles joined with their corners' positions (corner records)
 *   stream_stats.c     the whole mesh's figures, summed as the in-memory path sums them
 *   stream_pieces.c    spatial pieces: a grid of counts cut into boxes, and their files
 *   stream_passes.c    the positions (and confidences, the stage's shares) between steps
 *   stream_stage.c     the normal update stage's steps on a piece
 *   stream_smooth.c    the pipeline (rsmooth_stream_smooth)
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

/* Vertex ids on disk: 4 bytes each while the mesh has fewer than 2^32 - 1 vertices, else 8
 * (rs_stream_ply.id_bytes); in memory always 64-bit. */
static inline uint64_t rs_stream_get_id(const unsigned char *at, size_t id_bytes) {
    if (id_bytes == 4) {
        uint32_t id;
        memcpy(&id, at, sizeof id);
        return id;
    }
    uint64_t id;
    memcpy(&id, at, sizeof id);
    return id;
}

static inline void rs_stream_put_id(unsigned char *at, uint64_t id, size_t id_bytes) {
    if (id_bytes == 4) {
        uint32_t id32 = (uint32_t)id;
        memcpy(at, &id32, sizeof id32);
    } else
        memcpy(at, &id, sizeof id);
}

/* The temporary triangle file (3 vertex ids of id_bytes each per triangle), read front to back:
 * triangles [first, end). Readers of one file at different places may run at once (each reads
 * with pread at its own offset). */
bool rs_stream_triangles_open_range(rs_stream_reader *r, int fd, size_t id_bytes, uint64_t first,
                                    uint64_t end);
/* The next triangle's ids into tri; false at the end or on a read error. */
static inline bool rs_stream_next_triangle(rs_stream_reader *r, size_t id_bytes, uint64_t tri[3]) {
    const unsigned char *rec = rs_stream_read(r, 3 * id_bytes);
    for (int c = 0; rec && c < 3; c++)
        tri[c] = rs_stream_get_id(rec + (size_t)c * id_bytes, id_bytes);
    return rec != NULL;
}

/* How many of ids[i, n) (at most `most`) are consecutive numbers from ids[i]: the rows, records
 * or slots one read or write serves. */
static inline size_t rs_stream_id_run(const uint64_t *ids, size_t i, size_t n, size_t most) {
    size_t run = 1;
    while (i + run < n && run < most && ids[i + run] == ids[i] + run)
        run++;
    return run;
}

/* An unnamed temporary file in `dir` (O_TMPFILE, else created and unlinked at once), so that
 * nothing is left behind however the process ends. -1 with errno on failure. */
int rs_stream_temporary(const char *dir);
/* A temporary file in `dir` could not be written: RSMOOTH_ERROR_IO naming the folder, with
 * strerror(errnum) when the failed call's errno is at hand (errnum 0: a write on another thread,
 * whose errno this one does not see). */
rsmooth_status rs_stream_unwritten(const char *dir, int errnum, rsmooth_error *error);

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
    size_t id_bytes;      /* a vertex id on disk: 4, or 8 from 2^32 - 1 vertices on (or forced) */
    uint64_t rows_read;   /* vertex rows read, each time a pass read them (the report's) */
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

/* Reads the faces, fans each into triangles as the in-memory reader does, and writes their
 * vertex indices (3 of id_bytes each) to `triangles_fd`, a temporary file in `dir` (which a
 * failed write names); *triangle_count receives how many. */
rsmooth_status rs_stream_ply_write_triangles(rs_stream_ply *ply, int triangles_fd, const char *dir,
                                             uint64_t *triangle_count, rsmooth_error *error);

/* Refuses positions (3 doubles each, of the vertices `ids[0, n)`) the output cannot hold, as
 * rs_io_ply_check refuses them in memory (its message, after "OUTPUT: cannot write: "):
 * RSMOOTH_ERROR_NUMERICAL, before any of them is written. */
rsmooth_status rs_stream_ply_check_positions(const rs_stream_ply *ply, const uint64_t *ids,
                                             size_t n, const double *xyz, const char *output,
                                             rsmooth_error *error);

/* Writes vertex positions (3 doubles each) of the vertices `ids[0, n)` (ascending) into the
 * output file `out_fd` (rs_stream_ply_write_copy's), in the file's type. */
bool rs_stream_ply_write_positions(const rs_stream_ply *ply, int out_fd, const uint64_t *ids,
                                   size_t n, const double *xyz);

/* Reads vertex rows [first, first + count) into `xyz` (3 per vertex from xyz[0], floats when
 * xyz_type is FLOAT32, else doubles), checking each, and measures their extent on the way. */
rsmooth_status rs_stream_ply_read_range(rs_stream_ply *ply, uint64_t first, uint64_t count,
                                        void *xyz, rs_stream_extent *extent, rsmooth_error *error);

/* The positions (as doubles) of the vertices ids[0, n), read from their rows (a run of
 * consecutive ids at a time); false on a read error (errno set) or when out of memory. */
bool rs_stream_ply_read_rows(const rs_stream_ply *ply, const uint64_t *ids, size_t n, double *xyz);

/* ---- stream_vertices.c --------------------------------------------------------------------- */

/* The vertex positions, in the file's type: all held when they fit in the memory given, else
 * read from the input a run of vertices at a time, by each pass that needs them. No array of the
 * whole mesh's positions is needed: what holds them afterwards is the corner records. */
typedef struct rs_stream_vertices {
    rs_stream_ply *ply;
    bool f32;
    uint64_t count;
    uint64_t run;           /* vertices per run: count when they are all held */
    void *xyz;              /* vertices [first, first + loaded) */
    uint64_t first, loaded; /* which run xyz holds */
    uint64_t runs_read;     /* runs read from the file, for the report */
} rs_stream_vertices;

/* Reads every vertex once, checking each and measuring their extent, holding `memory` bytes of
 * positions at most (all of them when they fit). */
rsmooth_status rs_stream_vertices_open(rs_stream_vertices *v, rs_stream_ply *ply, uint64_t memory,
                                       rs_stream_extent *extent, rsmooth_error *error);
/* Makes xyz hold the run that starts at vertex `first` (a multiple of run), reading it unless it
 * is held already. */
rsmooth_status rs_stream_vertices_load(rs_stream_vertices *v, uint64_t first, rsmooth_error *error);
/* Frees the run held (a later load allocates it again). */
void rs_stream_vertices_release(rs_stream_vertices *v);

/* Vertex `id`'s position (one of the loaded run's). */
static inline void rs_stream_vertex(const rs_stream_vertices *v, uint64_t id, double out[3]) {
    uint64_t i = 3 * (id - v->first);
    for (int k = 0; k < 3; k++)
        out[k] = v->f32 ? (double)((const float *)v->xyz)[i + (uint64_t)k]
                        : ((const double *)v->xyz)[i + (uint64_t)k];
}

/* ---- stream_corners.c ---------------------------------------------------------------------- */

/* The triangles as corner records: a triangle's three vertex ids (id_bytes each), then its
 * corners' x y z in the file's type. Every later pass reads its positions from them (or from the
 * pieces' lists, made of the same records), so no pass needs the whole mesh's positions. When the
 * positions are held whole anyway, the records are made as they are read, from the triangle file
 * and the positions (the same bytes, a quarter of the reading); else they are written to a file
 * once, one pass over the triangles per run of vertices the cap holds. */
/* The largest corner record: three 64-bit ids and nine doubles. */
#define RS_STREAM_RECORD_MAX (3 * sizeof(uint64_t) + 9 * sizeof(double))

typedef struct rs_stream_corners {
    int fd;                         /* the records, or -1 when they are made from `held` */
    int ids_fd;                     /* the triangles' ids alone (the caller's; closed by it) */
    const rs_stream_vertices *held; /* every position, or NULL */
    bool f32;
    size_t id_bytes; /* 4 or 8 */
    size_t record;   /* bytes per triangle */
    uint64_t count;
} rs_stream_corners;

/* The corner records of the `triangles` in `ids_fd` (3 ids of id_bytes each): read through the
 * held positions when `hold` and `v` holds every position, else written to a temporary file in
 * `dir` (positions that fill the cap go to the file too: the pieces need the room). */
rsmooth_status rs_stream_corners_make(rs_stream_vertices *v, bool hold, int ids_fd, size_t id_bytes,
                                      uint64_t triangles, const char *dir, rs_stream_corners *out,
                                      rsmooth_error *error);

/* A triangle as a pass reads it: what the pieces' lists keep of it (its record, or its ids alone
 * when the positions are held), and where each corner's x y z lie (in the record, or in the held
 * positions: nothing is copied to make a record). */
typedef struct rs_corner_view {
    const unsigned char *entry; /* its three vertex ids first */
    const unsigned char *xyz[3];
} rs_corner_view;

/* Triangles [first, end) front to back. Readers of one triangle set at different places may run
 * at once (each reads with pread at its own offset). */
typedef struct rs_corner_reader {
    rs_stream_reader r;
    const rs_stream_corners *c;
} rs_corner_reader;

bool rs_corner_reader_open(rs_corner_reader *cr, const rs_stream_corners *c, uint64_t first,
                           uint64_t end);
/* The next triangle into *view (valid until the next call); false at the end or on a read error. */
bool rs_corner_next(rs_corner_reader *cr, rs_corner_view *view);
void rs_corner_reader_close(rs_corner_reader *cr);
/* Triangle t's whole record into out (c->record bytes). */
bool rs_stream_corner_at(const rs_stream_corners *c, uint64_t t, unsigned char *out);

static inline void rs_stream_record_ids(const rs_stream_corners *c, const unsigned char *rec,
                                        uint64_t tri[3]) {
    for (int k = 0; k < 3; k++)
        tri[k] = rs_stream_get_id(rec + (size_t)k * c->id_bytes, c->id_bytes);
}

/* A record's nine coordinates (three corners' x y z, in the file's type). */
static inline const unsigned char *rs_stream_record_values(const rs_stream_corners *c,
                                                           const unsigned char *rec) {
    return rec + 3 * c->id_bytes;
}

/* Corner q's (0-2) position. */
static inline void rs_stream_view_corner(const rs_stream_corners *c, const rs_corner_view *view,
                                         int q, double out[3]) {
    const unsigned char *at = view->xyz[q];
    for (int k = 0; k < 3; k++) {
        if (c->f32) {
            float x;
            memcpy(&x, at + sizeof x * (size_t)k, sizeof x);
            out[k] = (double)x;
        } else
            memcpy(out + k, at + sizeof(double) * (size_t)k, sizeof(double));
    }
}

/* The corners in the file's type, as an xyz array of three vertices (for the functions of core/
 * that read positions through vertex ids 0, 1, 2). */
static inline const void *rs_stream_view_xyz(const rs_stream_corners *c, const rs_corner_view *view,
                                             double aligned[9]) {
    size_t vertex_bytes = 3 * (c->f32 ? sizeof(float) : sizeof(double));
    for (int q = 0; q < 3; q++)
        memcpy((unsigned char *)aligned + (size_t)q * vertex_bytes, view->xyz[q], vertex_bytes);
    return aligned;
}

/* rs_triangle_geometry of a triangle with its corners times `scale` (internal units): whether it
 * is a facet, and then its corners and centroid (scaled) and area. */
static inline bool rs_stream_facet(const rs_stream_corners *c, const rs_corner_view *view,
                                   double scale, double corners[9], double centroid[3],
                                   double *area) {
    static const uint32_t local[3] = {0, 1, 2};
    double normal[3];
    for (int q = 0; q < 3; q++) {
        rs_stream_view_corner(c, view, q, corners + 3 * q);
        for (int k = 0; k < 3; k++)
            corners[3 * q + k] *= scale;
    }
    return rs_triangle_geometry(corners, local, centroid, normal, area);
}

/* ---- stream_stats.c ------------------------------------------------------------------------ */

typedef struct rs_stream_stats {
    double scale;            /* power of two the sums run at (exact; see stream_stats.c) */
    double mean_edge_length; /* caller's units */
    double mean_area;
    /* the two at `scale` (internal units), as the in-memory path holds them: in the caller's
     * units a mesh at 1e-300 has no representable area */
    double scaled_mean_edge_length, scaled_mean_area;
    double longest_edge; /* caller's units */
    double magnitude;    /* the largest |coordinate| */
    double reach;        /* largest centroid-to-corner distance of a facet (checked against: */
    double reach_bound;  /* a bound on it from the longest edge, which sets the halo before the
                          * facets' pass measures the reach itself) */
    uint64_t facet_count;
    double lo[3], hi[3]; /* the vertices' bounding box */
    bool whole;          /* one part, no edge out of line (core/parts.h): what streams */
    bool parts_tested;   /* (the caller's) the input was found whole: a later pass's positions
                          * are cut into pieces whatever `whole` says of them, as the in-memory
                          * passes run on the input's parts */
} rs_stream_stats;

/* The figures of the mesh of `vertex_count` vertices whose triangles are `corners` that its edges
 * give (the scale, the mean edge length, the reach's bound), with at most `memory` bytes of
 * working memory for the unique edges. The facets' figures come in a second pass. */
rsmooth_status rs_stream_statistics(const rs_stream_corners *corners, uint64_t vertex_count,
                                    const rs_stream_extent *extent, uint64_t memory,
                                    rs_stream_stats *stats, rsmooth_error *error);

/* What the facets' pass does besides: the cut counts each facet's pieces in it (one read of the
 * triangles' corners instead of two). `triangle` is called with each triangle, its centroid in
 * the caller's units (NULL for a triangle of no area, which is no facet), in triangle order within
 * each chunk of rs_stream_facet_chunks; the chunks run on every core at once. */
typedef struct rs_facet_visitor {
    void (*triangle)(void *ctx, size_t chunk, const double centroid[3]);
    void *ctx;
} rs_facet_visitor;

/* The chunks of the facets' pass over `triangles`: chunk c holds triangles [first(c),
 * first(c + 1)), first(chunks) = triangles. */
size_t rs_stream_facet_chunks(uint64_t triangles);
uint64_t rs_stream_facet_chunk_first(uint64_t triangles, size_t chunks, size_t c);

/* The facet count, mean area, reach and parts test (stats->scale set), with `visitor` (or NULL)
 * called on every facet. */
rsmooth_status rs_stream_facet_figures(const rs_stream_corners *corners,
                                       const rs_facet_visitor *visitor, rs_stream_stats *stats,
                                       rsmooth_error *error);

/* ---- stream_pieces.c ----------------------------------------------------------------------- */

typedef struct rs_piece {
    uint64_t vertex_start, vertex_count; /* in the vertex list file, records */
    uint64_t facet_start, facet_count;   /* in the facet list file, corner records */
    int rank;                            /* who filters it */
} rs_piece;

typedef struct rs_stream_pieces {
    rs_piece *pieces;
    size_t count;
    int vertex_fd, facet_fd; /* the lists (only of this rank's pieces) */
    size_t id_bytes;         /* a vertex id's bytes in the lists: 4 or 8 */
    /* A list's entries: a vertex's id (id_bytes) and a facet's corner record; only the ids when
     * the positions are held whole (the filter looks them up then, as the lists would cost four
     * times the bytes to write and read) */
    size_t vertex_record, facet_record;
    bool triangle_ids; /* a facet's entry ends with its triangle's index (8 bytes) */
    uint64_t temporary_bytes;
} rs_stream_pieces;

/* Cuts the mesh into pieces of at most about `piece_vertices` core vertices (smaller, when some
 * piece holds more than `facets_max` facets with its halo; 0: no bound), counts each piece's
 * facets within `halo` in the facets' pass (which fills the rest of `stats`; nothing more is done
 * when it finds the mesh is not whole), shares the pieces among `ranks` by their facet counts,
 * and writes (for this `rank`'s pieces) each piece's core vertices and its facets (corner
 * records, in triangle order; each followed by the triangle's index with `triangle_ids`) to
 * temporary files in `dir`. */
rsmooth_status rs_stream_pieces_build(rs_stream_vertices *vertices,
                                      const rs_stream_corners *corners, rs_stream_stats *stats,
                                      double halo, uint64_t piece_vertices, uint64_t facets_max,
                                      size_t buffer_memory, int rank, int ranks, bool triangle_ids,
                                      const char *dir, rs_stream_pieces *out, rsmooth_error *error);
void rs_stream_pieces_free(rs_stream_pieces *pieces);

/* ---- stream_assemble.c --------------------------------------------------------------------- */

/* Where a piece's lists' entries and positions come from. */
typedef struct rs_piece_source {
    const rs_stream_vertices *held; /* the positions held whole, or NULL: the entries carry them */
    bool f32;                       /* positions in the file's float32 (else float64) */
    size_t id_bytes, vertex_record, facet_record; /* rs_stream_pieces' */
} rs_piece_source;

/* A piece's arrays from its n core vertices' and m facets' list entries: the core's ids into
 * `core`, every vertex's position into xyz (the core first; at most n + 3 m of them, *k
 * receives how many) and, when all_ids is not NULL, its id there, the facets renumbered into
 * `tri` (which may be `facet_records` itself when those are three 32-bit ids each). false when
 * out of memory. */
bool rs_stream_assemble(const rs_piece_source *src, const unsigned char *core_records, size_t n,
                        const unsigned char *facet_records, size_t m, uint64_t *core, uint32_t *tri,
                        double *xyz, size_t *k, uint64_t *all_ids);

/* ---- stream_passes.c ----------------------------------------------------------------------- */

/* The positions between passes (two double blocks, each read as a PLY's vertex block of x y z
 * doubles) and the vertices' confidences (two float blocks), in a temporary file of their own or
 * in a file the ranks share, from byte `base` on. */
typedef struct rs_pass_store {
    int fd;
    bool own; /* a temporary of its own (closed), else a shared file's tail (cut off) */
    uint64_t base, vertex_count, triangle_count;
    rs_stream_ply block[2];
} rs_pass_store;

/* In `shared_fd` from `base` on, or (shared_fd -1) in a new temporary file in `dir`. */
rsmooth_status rs_pass_store_open(rs_pass_store *s, int shared_fd, uint64_t base,
                                  uint64_t vertex_count, uint64_t triangle_count, const char *dir,
                                  rsmooth_error *error);
/* The disk the store takes at most: the two position blocks, the confidences' when they are
 * kept, the stage's shares when it runs. */
uint64_t rs_pass_store_bytes(uint64_t vertex_count, uint64_t triangle_count, bool confidences,
                             bool shares);
/* The stage's reach shares of the triangles `triangles[0, n)` (ascending), and their sum and
 * pairs' count over every triangle, in triangle order (those no piece gave count 0). */
bool rs_pass_store_write_shares(const rs_pass_store *s, const uint64_t *triangles, size_t n,
                                const double *share, const uint32_t *pairs);
bool rs_pass_store_sum_shares(const rs_pass_store *s, double *sum, uint64_t *pairs);
/* A value per rank (its slot), and the largest of `ranks` slots once every rank has put its. */
bool rs_pass_store_put_slot(const rs_pass_store *s, int rank, double value);
bool rs_pass_store_largest_slot(const rs_pass_store *s, int ranks, double *largest);
/* Confidences of the vertices ids[0, n) (ascending) in float block k (0 or 1). */
bool rs_pass_store_read_confidence(const rs_pass_store *s, int k, const uint64_t *ids, size_t n,
                                   float *out);
bool rs_pass_store_write_confidence(const rs_pass_store *s, int k, const uint64_t *ids, size_t n,
                                    const float *values);
/* What the in-memory loop does after each pass (passes/passes.c), for a piece's n core vertices
 * (ids `core`, ascending; positions xyz[0, 3n) as this pass read them, results in `out` and
 * `confidence`): from the second pass on, a vertex whose confidence in the pass before (float
 * block (pass - 1) % 2) was at least keep_confidence (> 0) keeps that pass's position and
 * confidence; a vertex the mask holds still keeps its input position, where every pass found it.
 * false when the confidences cannot be read (errno set) or no memory. */
typedef struct rs_pass_rule {
    int pass;               /* from 0 */
    double keep_confidence; /* params.pass_confidence; 0: none */
    const uint8_t *mask;    /* params.move_mask (0: held still), or NULL */
} rs_pass_rule;

bool rs_pass_rules(const rs_pass_store *s, const rs_pass_rule *rule, const uint64_t *core, size_t n,
                   const double *xyz, double *out, float *confidence);
/* Closes its own file, or (`cut`) cuts the shared one back to `base`; false if that fails. */
bool rs_pass_store_close(rs_pass_store *s, bool cut);

/* A piece's arrays, as rs_stream_piece_load makes them. */
typedef struct rs_stream_piece_arrays {
    size_t n, k, m;     /* core vertices (the first n), all vertices, facets */
    uint64_t *core;     /* the core's ids */
    uint64_t *ids;      /* every vertex's id (the core's first), when asked for */
    double *xyz;        /* 3 per vertex, the source's positions as doubles */
    uint32_t *tri;      /* 3 per facet, the piece's numbers, in triangle order */
    uint64_t *triangle; /* per facet: its triangle's index (lists with triangle_ids), or NULL */
} rs_stream_piece_arrays;

/* Piece p's lists read and assembled (rs_stream_assemble), every vertex's id with want_ids. */
rsmooth_status rs_stream_piece_load(const rs_stream_pieces *pieces, const rs_piece_source *src,
                                    const rs_piece *p, bool want_ids, rs_stream_piece_arrays *a,
                                    rsmooth_error *error);
void rs_stream_piece_arrays_free(rs_stream_piece_arrays *a);

/* ---- stream_stage.c ------------------------------------------------------------------------ */

struct rs_stage_setting;
struct rs_stage_whole;

/* The guided reach's shares of the triangles whose first corner is the piece's own (its arrays
 * from the lists with triangle ids, positions the input's), written into `store` at their
 * triangles' places; `scale` the stage's. */
rsmooth_status rs_stream_stage_shares(const rs_pass_store *store, const rs_stream_piece_arrays *p,
                                      const struct rs_stage_setting *setting, double scale,
                                      rsmooth_error *error);
/* One cycle of the stage on the piece (its arrays with every vertex's id, positions the cycle's
 * start), its lists from the positions `input`'s rows hold; the core's results in p->xyz,
 * *displacement raised to their largest distance from the input. `mask` the caller's move mask
 * (by vertex id) or NULL. The results stay doubles between steps whatever the file's type, as
 * the file read whole is (its positions are doubles in memory). */
rsmooth_status rs_stream_stage_cycle(const rs_stream_ply *input, rs_stream_piece_arrays *p,
                                     const struct rs_stage_setting *setting,
                                     const struct rs_stage_whole *whole, const uint8_t *mask,
                                     double *displacement, rsmooth_error *error);

#endif /* RSMOOTH_STREAM_INTERNAL_H */
