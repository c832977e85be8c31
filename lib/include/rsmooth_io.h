/** @file
 * rsmooth_io: reading and writing the mesh files scanners and tools produce (library target
 * rsmooth::io, separate from rsmooth::rsmooth so hosts that pass arrays do not pull it in).
 *
 * Parsing from a memory buffer is the core (testable without a disk); the file functions are thin
 * wrappers. Formats: Wavefront OBJ, Stanford PLY (ascii, binary little- and big-endian on input;
 * ascii and binary little-endian on output), OFF (with COFF/NOFF variants) and STL (ascii and
 * binary; an unindexed soup, read as one and written back as one).
 *
 * Nothing is lost in a round trip through the same format: what a file carries beyond positions and
 * faces (PLY properties, elements and comments; OBJ texture coordinates, groups, objects, materials
 * and smoothing groups; OFF colours; STL header and attributes) is kept in `extras` and written
 * back unchanged, except vertex normals, which writers recompute from the (filtered) positions
 * (point clouds, with no faces to recompute from, write their vertex_normals). Converting to
 * another format keeps what the target can hold (positions, faces, vertex colours, normals);
 * rsmooth_mesh_conversion_losses() says what it drops. A UTF-8 byte-order mark before a text file
 * is accepted and written back by the same format (PLY: either encoding; not binary STL).
 *
 * What rsmooth writes, rsmooth reads back to the same numbers: writers refuse the values readers
 * refuse (non-finite or beyond 1e150, the magnitude the filter supports) and a mesh a float32 file
 * cannot hold at its own scale, and write every coordinate with the fewest digits (text) or the
 * bits (binary) that give it back exactly, as a double or as the float32 the file holds.
 * rsmooth_mesh_check_writable tells beforehand whether a format's writer would refuse a mesh.
 *
 *     rsmooth_mesh *mesh = NULL;
 *     rsmooth_error err;
 *     if (rsmooth_mesh_read_file("scan.ply", &mesh, &err) != RSMOOTH_OK)
 *         fprintf(stderr, "scan.ply: %s (line %lld)\n", err.message, (long long)err.line);
 *     ... rsmooth_smooth(ctx, RSMOOTH_FLOAT64, mesh->positions, mesh->vertex_count,
 *                        mesh->triangles, mesh->triangle_count, ...);
 *     rsmooth_mesh_destroy(mesh);
 */
#ifndef RSMOOTH_IO_H
#define RSMOOTH_IO_H

#include "rsmooth.h"

#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

/** A mesh file format: what rsmooth_mesh_read_memory expects, rsmooth_mesh_write_file writes. */
typedef enum rsmooth_format {
    RSMOOTH_FORMAT_AUTO = 0,          /**< reading: from the content; writing: from the path's
                                       * extension */
    RSMOOTH_FORMAT_OBJ = 1,           /**< Wavefront OBJ (text) */
    RSMOOTH_FORMAT_PLY_ASCII = 2,     /**< Stanford PLY, ascii */
    RSMOOTH_FORMAT_PLY_BINARY = 3,    /**< little-endian on output; either endianness on input */
    RSMOOTH_FORMAT_PLY_BINARY_BE = 4, /**< input only */
    RSMOOTH_FORMAT_OFF = 5,           /**< OFF and its COFF / NOFF / CNOFF variants */
    RSMOOTH_FORMAT_STL_ASCII = 6,     /**< STL, ascii (an unindexed triangle soup) */
    RSMOOTH_FORMAT_STL_BINARY = 7     /**< STL, binary (an unindexed triangle soup) */
} rsmooth_format;

/** A mesh read from a file. All arrays are owned by the mesh and freed by rsmooth_mesh_destroy. */
typedef struct rsmooth_mesh {
    size_t vertex_count;      /**< vertices in the file (unreferenced ones included) */
    double *positions;        /**< 3 * vertex_count: x, y, z per vertex, file order */
    rsmooth_scalar precision; /**< precision the file stored positions in: FLOAT32 for PLY float,
                               * FLOAT64 for PLY double and for text (OBJ) coordinates */
    size_t face_count;        /**< polygons as in the file */
    uint32_t *face_offsets;   /**< face_count + 1 entries: face i is
                               * face_indices[face_offsets[i] .. face_offsets[i + 1]) */
    uint32_t *face_indices;   /**< 0-based vertex indices */
    size_t triangle_count;    /**< the faces fanned into triangles (v0, vi, vi+1) */
    uint32_t *triangles;      /**< 3 * triangle_count */
    rsmooth_format source_format; /**< format it was read from */
    int has_vertex_normals;       /**< the file carried vertex normals: writers that can hold them
                                   * write normals recomputed from `positions` (area-weighted face
                                   * normals) */

    /** @name Per-vertex attributes
     * Per-vertex attributes writers of every format that can hold them write when non-NULL.
     * Readers fill vertex_colors when the file has vertex colours (PLY red/green/blue, OBJ
     * "v x y z r g b", COFF); vertex_quality is for callers (the confidence output). @{ */
    float *vertex_quality;  /**< vertex_count values: PLY "quality" property */
    uint8_t *vertex_colors; /**< 3 * vertex_count RGB bytes */
    /** @} */

    /** What the file held beyond the fields above, kept by the reader so writing back to the same
     * format loses nothing (opaque; NULL when there is nothing). Writers to the same format use it
     * in place of vertex_colors / vertex_quality; set it to NULL to write only the fields above. */
    struct rsmooth_mesh_extras *extras;

    /** The vertex normals the file held (added in 0.4): 3 * vertex_count values as read (PLY nx,
     * ny, nz; OFF NOFF; OBJ vn when there are no faces and as many vn as v), NULL when it held
     * none. Point clouds live on them. Writers emit them in place of recomputed normals when the
     * mesh has no triangles (nothing to recompute from); a caller may set or replace them (the
     * mesh frees them: allocate with malloc). */
    double *vertex_normals;
} rsmooth_mesh;

/** Parses a whole file held in memory. Any PLY value reads every PLY encoding (the header decides),
 * either STL value both STL encodings (the size decides). With `format` AUTO, the content decides:
 *   - a binary STL by its exact size (84 + 50 x the count at byte 80), whatever its header says;
 *   - after an optional UTF-8 byte-order mark: PLY when the file starts with "ply";
 *   - then by the first word past blank lines, indentation and '#' comments: an OFF keyword (OFF,
 *     COFF, NOFF, CNOFF, STOFF... in any case of "off"), "solid" (ascii STL; ascii STL has no
 *     comments, so a '#' line before "solid" or between facets is refused at its line);
 *   - binary content (NUL or control bytes) not opening with an OBJ statement: a binary STL whose
 *     size disagrees with its count, which is then the error;
 *   - anything else OBJ.
 * On failure *mesh is NULL and `error` says what was expected and where: its line (text, 1-based)
 * or byte offset (binary; from the file's first byte, a byte-order mark included) is always set.
 * RSMOOTH_ERROR_PARSE for malformed content: an empty file, "ply" after blanks, truncation, bad
 * numbers, indices out of range (OBJ vt and vn too), faces with fewer than 3 vertices, non-finite
 * coordinates or normals, coordinates beyond 1e150 in magnitude, counts larger than the data can
 * hold, and per format:
 *   - PLY: values a property's declared type cannot hold, a property named twice in an element, an
 *     ascii row with a value too many or too few, anything but blanks after the last element
 *     (binary: at its byte offset; the header's counts would leave it out);
 *   - OFF: a vertex line with other than the values its keyword declares (x y z; N: nx ny nz;
 *     C: r g b or r g b a, integers 0 to 255 or floats 0 to 1; ST: s t; in that order), a face
 *     line with anything after its indices but a colormap index (a whole number) or an r g b [a]
 *     colour, anything but comments after the declared faces;
 *   - ascii STL: a '#' comment anywhere (ascii STL has none).
 * RSMOOTH_ERROR_UNSUPPORTED for variants not read (4OFF, nOFF, binary OFF), also located;
 * RSMOOTH_ERROR_OUT_OF_MEMORY. Thread-safe. */
RSMOOTH_API rsmooth_status rsmooth_mesh_read_memory(const void *data, size_t size,
                                                    rsmooth_format format, rsmooth_mesh **mesh,
                                                    rsmooth_error *error);

/** Reads a file, its format told by the content (rsmooth_mesh_read_memory with AUTO).
 * RSMOOTH_ERROR_IO when the path cannot be opened or read (a directory, missing, unreadable), else
 * as rsmooth_mesh_read_memory. */
RSMOOTH_API rsmooth_status rsmooth_mesh_read_file(const char *path, rsmooth_mesh **mesh,
                                                  rsmooth_error *error);

/** Reads a whole stream (to its end), then parses it as rsmooth_mesh_read_memory with AUTO.
 * RSMOOTH_ERROR_IO when the stream fails. `name` (may be NULL) is used in messages. */
RSMOOTH_API rsmooth_status rsmooth_mesh_read_stream(FILE *stream, const char *name,
                                                    rsmooth_mesh **mesh, rsmooth_error *error);

/** Writes `mesh` (its faces as polygons, not the fanned triangles; STL: the triangles) to an open
 * stream. `format` must not be AUTO; big-endian PLY output is RSMOOTH_ERROR_UNSUPPORTED. Returns
 * RSMOOTH_ERROR_INVALID_ARGUMENT, naming the vertex and having written nothing, for what no reader
 * would read back as it is (rsmooth_mesh_check_writable lists it); RSMOOTH_ERROR_IO when the
 * stream fails.
 *
 * Float32 and the mesh's scale: a file that stores float32 must hold the mesh at its own scale, so
 * binary STL, and PLY written with the input's header (its extras) whose x y z are 'float', refuse
 * a coordinate beyond FLT_MAX or one float32 rounds by more than its precision at the mesh's
 * largest coordinate M (|x - (float)x| > 2^-24 M): in practice a whole mesh below FLT_MIN
 * (1.2e-38), whose subnormal floats would lose its shape (at 1e-150 every vertex is 0 0 0); a mesh
 * at 1 with a stray 1e-40 is written. Where rsmooth picks the type it never refuses for it: PLY
 * written without the input's header uses float for float32 data only while float32 holds it at
 * its scale, else double; text formats write a float32 mesh's values with float digits on the same
 * condition, else as the doubles they are. */
RSMOOTH_API rsmooth_status rsmooth_mesh_write_stream(const rsmooth_mesh *mesh, FILE *stream,
                                                     rsmooth_format format, rsmooth_error *error);

/** Runs exactly the refusals of rsmooth_mesh_write_stream for `format` without writing anything
 * (for a caller that wants to know before it filters whether the output format can hold the mesh):
 * RSMOOTH_OK when the writer would write it; else the status and message the writer would give:
 * RSMOOTH_ERROR_INVALID_ARGUMENT, naming the vertex (or face, triangle), for a mesh that is not
 * well-formed (NULL arrays, faces of fewer than 3 vertices, indices out of range), a coordinate
 * that is NaN, infinite or beyond 1e150 in magnitude, a non-finite vertex_quality or point-cloud
 * normal, what the format cannot hold (STL: no triangles, more than 2^32 - 1 for binary; binary
 * STL's float32, and the 'float' or integer types of a PLY file written with its input's header, at
 * the mesh's scale: see above), and for AUTO or an unknown format; RSMOOTH_ERROR_UNSUPPORTED for
 * big-endian PLY. A mesh that passes may still fail to write for want of memory or a stream error
 * (RSMOOTH_ERROR_OUT_OF_MEMORY, RSMOOTH_ERROR_IO). O(vertices + face indices), allocates nothing
 * and computes no normals. Thread-safe; `error` may be NULL. */
RSMOOTH_API rsmooth_status rsmooth_mesh_check_writable(const rsmooth_mesh *mesh,
                                                       rsmooth_format format, rsmooth_error *error);

/** Writes `mesh` to `path`, whole or not at all. AUTO picks the format from the extension: .obj,
 * .ply (binary little-endian), .off, .stl (binary). A mesh refused as by rsmooth_mesh_write_stream
 * creates no file. The file is written beside `path` (beside the file a symbolic link leads to)
 * and takes the name only when complete, replacing an existing regular file atomically and
 * keeping its permission bits, owner and group: a write that fails (RSMOOTH_ERROR_IO, the path
 * named; or the writer's own status) leaves whatever was at `path` untouched and no temporary
 * behind. Never replaces a directory, device, FIFO or socket, nor writes through a link to
 * nothing (RSMOOTH_ERROR_IO). On success error->message is empty, or a warning to pass on (the
 * file had other hard links, which keep the old content; its owner could not be kept). While a
 * named temporary exists (where the file system has no unnamed ones), a SIGINT, SIGTERM or SIGHUP
 * removes it first, then takes its previous action. */
RSMOOTH_API rsmooth_status rsmooth_mesh_write_file(const rsmooth_mesh *mesh, const char *path,
                                                   rsmooth_format format, rsmooth_error *error);

/** Writes a file's content for rsmooth_file_write into `stream`: returns 0, or -1 with what went
 * wrong in `message` (a buffer of `size` bytes). (Added in 0.11) */
typedef int (*rsmooth_file_writer)(FILE *stream, void *user, char *message, size_t size);

/** Writes `path` whole or not at all, as rsmooth_mesh_write_file writes a mesh, with content of
 * the caller's (the rsmooth command's meshes and pictures): `write(stream, user, ...)` fills a new
 * file beside `path` (beside the file a symbolic link leads to), which takes the name only when
 * `write` returned 0 and the stream was flushed and closed without error; anything that fails
 * removes it and leaves whatever was at `path` untouched. Without `replace` an existing name is
 * refused, and so is a file another program creates at the name meanwhile; with it an existing
 * regular file (or the one a link leads to) is replaced atomically and keeps its permission
 * bits, owner and group. Directories, devices, FIFOs, sockets and links to nothing are never
 * written. `hint` says how a caller's user asks for replacing, in the refusal of an existing
 * name ("PATH: already exists (HINT to replace it)"; NULL: "set replace"). With `write` NULL
 * only checks that `path` may be written, and writes nothing. RSMOOTH_ERROR_IO with a message
 * that starts with the path when `path` may not be written or the writing fails ("PATH: cannot
 * write: " and `write`'s message); RSMOOTH_ERROR_INVALID_ARGUMENT for a NULL path. On success
 * error->message is empty, or a warning to pass on (the file had other hard links, which keep
 * the old content; its owner could not be kept). (Added in 0.11) */
RSMOOTH_API rsmooth_status rsmooth_file_write(const char *path, int replace, const char *hint,
                                              rsmooth_file_writer write, void *user,
                                              rsmooth_error *error);

/** The format a path's extension names (case-insensitive .obj, .ply (binary), .off, .stl (binary)),
 * or AUTO if none. */
RSMOOTH_API rsmooth_format rsmooth_format_from_path(const char *path);

/** Allocates an empty mesh with room for the given counts (arrays zeroed; face_offsets[0] = 0).
 * Used by generators and tests. */
RSMOOTH_API rsmooth_status rsmooth_mesh_create(size_t vertex_count, size_t face_count,
                                               size_t face_index_count, rsmooth_mesh **mesh,
                                               rsmooth_error *error);

/** Recomputes `triangles` by fanning the faces. */
RSMOOTH_API rsmooth_status rsmooth_mesh_triangulate(rsmooth_mesh *mesh, rsmooth_error *error);

/** Describes what writing `mesh` in `format` would drop (e.g. "texture coordinates, groups"), as
 * one comma-separated line in `buffer` (always NUL-terminated when size > 0). Returns the number of
 * kinds of data dropped (0: nothing is lost). */
RSMOOTH_API size_t rsmooth_mesh_conversion_losses(const rsmooth_mesh *mesh, rsmooth_format format,
                                                  char *buffer, size_t size);

/** Whether `mesh` was read from a scanner's PLY range grid (an "element range_grid" with
 * "obj_info num_cols" / "num_rows" lines, each cell listing 0 or 1 vertex index, no faces; added in
 * 0.11). Such a file is read as a triangle mesh: each 2x2 block of cells gives two triangles when
 * all four samples exist (split along the shorter diagonal) and one when three do, all wound the
 * same way, and no triangle whose longest edge exceeds 10 times the scan's median distance between
 * adjacent samples (a depth jump; docs/file-formats.md). Its faces replace the range_grid element
 * in the extras, so a PLY written back is a triangle mesh, not a range grid. Returns 1 and sets
 * *cols, *rows (the grid's size in cells) and *samples (cells holding a sample), each when not
 * NULL; 0 when the mesh was not (or its extras were set to NULL). Thread-safe. A malformed grid
 * fails rsmooth_mesh_read_* with RSMOOTH_ERROR_PARSE: a cell listing 2 or more indices, an index
 * out of range or listed by two cells, num_cols x num_rows other than the element's count, a
 * missing or malformed num_cols / num_rows, or a face element as well. */
RSMOOTH_API int rsmooth_mesh_range_grid(const rsmooth_mesh *mesh, size_t *cols, size_t *rows,
                                        size_t *samples);

/** Area-weighted vertex normals of the mesh's triangles (unit length; 0 for vertices no triangle
 * uses), 3 * vertex_count doubles. What writers emit for files that carried normals. */
RSMOOTH_API rsmooth_status rsmooth_mesh_vertex_normals(const rsmooth_mesh *mesh, double *normals,
                                                       rsmooth_error *error);

/** Frees the mesh and everything it owns (extras included). Accepts NULL. */
RSMOOTH_API void rsmooth_mesh_destroy(rsmooth_mesh *mesh);

/* ---------------------------------------------------------------------------------------------- */
/* Streaming: meshes larger than memory (added in 0.7) */
/* ---------------------------------------------------------------------------------------------- */

/** How rsmooth_stream_smooth may use memory, disk and other processes. */
typedef struct rsmooth_stream_options {
    size_t struct_size;  /**< sizeof(rsmooth_stream_options): set by
                          * rsmooth_stream_options_init */
    uint64_t max_memory; /**< bytes the call may hold at its peak, besides the OpenCL runtime's
                          * own (docs: README "Large meshes"); 0: 1 GiB */
    const char *tmpdir;  /**< folder of the temporary files (all unnamed: nothing is left behind,
                          * however the process ends); an existing folder, or NULL: the
                          * output's folder. "" is refused */
    int replace;         /**< non-zero: an existing output (a regular file, or a symbolic link to
                          * one: written through) is replaced atomically, keeping its mode,
                          * owner and group; nothing else is ever replaced */
    /** @{ */
    /** Several processes sharing the pieces (the MPI driver): each calls with the same arguments,
     * its own rank in [0, ranks), and `sync`, which every rank calls at the same points and which
     * returns the worst (largest) status any rank passed (an all-reduce). ranks 0 or 1: alone,
     * rank 0. Ranks without a sync, a rank outside [0, ranks) and negative ranks are
     * RSMOOTH_ERROR_INVALID_ARGUMENT naming the field. */
    int rank, ranks;
    int (*sync)(void *user, int status);
    void *sync_user;
    /** @} */
} rsmooth_stream_options;

/** Sets struct_size and the defaults (zeroes). Returns RSMOOTH_ERROR_INVALID_ARGUMENT on NULL. */
RSMOOTH_API rsmooth_status rsmooth_stream_options_init(rsmooth_stream_options *options);

/** What a streaming call did. */
typedef struct rsmooth_stream_report {
    size_t struct_size; /**< sizeof(rsmooth_stream_report): rsmooth_stream_report_init */
    /** @{ */
    /** The input's vertices, faces, triangles (faces fanned) and triangles of non-zero area */
    uint64_t vertex_count, face_count, triangle_count, facet_count;
    /** @} */
    double mean_edge_length;   /**< of the input, its units: the unit of the relative sigmas */
    double halo;               /**< how far around a piece its facets reach, mesh units */
    size_t pieces;             /**< pieces the mesh was cut into (all ranks; each pass is cut
                                * afresh, and this sums the passes) */
    size_t pieces_here;        /**< of them, those this rank filtered */
    uint64_t piece_facets_max; /**< facets of the largest piece, its halo's included */
    uint64_t facets_filtered;  /**< facets this rank's pieces held, halos included */
    uint64_t memory_planned;   /**< the peak this call planned for, bytes (<= max_memory) */
    uint64_t temporary_bytes;  /**< disk the temporary files took at their largest */
    /** @{ */
    /** Milliseconds of each step. read: the vertex block and the faces; statistics: mean edge
     * length, area, reach; buckets: the pieces cut and their lists written; copy: the output's
     * copy of the input; assemble: the pieces' arrays from their lists; filter:
     * rsmooth_smooth_piece; write: results into the copy; total: the whole call */
    double ms_read, ms_statistics, ms_buckets, ms_copy, ms_assemble, ms_filter, ms_write, ms_total;
    /** @} */
    char device[128]; /**< "reference ..." or the OpenCL device's name, as
                       * rsmooth_report */
    /** What the caller should tell its user about the output it replaced: other hard links that
     * keep the old content, an owner or group that could not be kept (only root can give a file
     * away). "" when nothing. (Added in 0.9) */
    char notes[400];
    /** How many times runs of vertex positions were read from the input: 1 when they were held
     * whole, more when the cap holds only a run of them at a time (each pass that needs them
     * reads every run again). (Added in 0.11) */
    uint64_t position_runs;
    /** The vertex ids' width in the temporary files: 32, or 64 for meshes of 2^32 - 1 vertices
     * and more (up to 2^48). (Added in 0.11) */
    unsigned vertex_id_bits;
    /** Passes of the filter run, each streamed (params.passes). (Added in 0.11) */
    int passes;
    /** Cycles of the normal update stage run, each streamed (params.vertex_updates above 0:
     * params.stage_repeats of them). (Added in 0.11) */
    int stage_cycles;
    /** Bytes of the input this rank read: its header, the vertex rows each time a pass read
     * them, the faces and what follows them, and (rank 0) the data copied into the output.
     * (Added in 0.11) */
    uint64_t input_bytes_read;
} rsmooth_stream_report;

/** Zeroes `report` and sets its struct_size. Accepts NULL. */
RSMOOTH_API void rsmooth_stream_report_init(rsmooth_stream_report *report);

/** The filter of rsmooth_smooth on the mesh in file `input`, written to `output`, holding at most
 * options->max_memory bytes at a time (the OpenCL runtime's own memory aside): one pass over the
 * input gathers the mesh's figures (mean edge length and area in the order the in-memory path
 * sums them, so the sigmas are the same bits) and writes its triangles, cut into spatial pieces
 * with their halos (rsmooth_piece_halo), to temporary files; each piece is filtered
 * (rsmooth_smooth_piece, on `ctx`'s device, or the reference path when ctx is NULL); results go
 * into a copy of the input's data at their vertices' places, after the header rsmooth_mesh_write
 * gives the file read whole, so the output is the in-memory path's byte for byte: the input's
 * header, comments, other properties and elements and faces (the generic header with its
 * "comment written by rsmooth" where the reader keeps no extras), little-endian, a byte-order
 * mark kept, and the positions an in-memory run's bit for bit, on a device and on the reference
 * path (see rsmooth_smooth_piece). Positions the file's x y z type cannot hold (float32 beyond
 * FLT_MAX, or below its precision at the mesh's scale) are RSMOOTH_ERROR_NUMERICAL with
 * rsmooth_mesh_write's message, nothing written; where the reader keeps no extras, a write from
 * memory would switch to double x y z instead, which a copy cannot. The output appears whole and at
 * once, or not at all: written beside its final name and put in place only when complete, as the
 * rsmooth command writes its files. Without options->replace an existing output, or one another
 * program creates while the call works, is never replaced (RSMOOTH_ERROR_IO, "already exists");
 * folders, devices, FIFOs and links to nothing never are. Several ranks share a partial file
 * ".rsmooth-partial-<hash>" beside the output, made by rank 0 and named as the output when every
 * rank is done. While a named temporary exists, a SIGINT, SIGTERM or SIGHUP (unless ignored)
 * removes it first, then takes its previous action (the default, or the program's own handler).
 *
 * What streams: binary PLY (either byte order) with float or double x, y, z, faces of any size
 * (fanned into triangles as the reader does), up to 2^48 vertices (64-bit ids on disk from 2^32 - 1
 * on) and any number of faces.
 * Memory: nothing grows with the mesh. The vertex positions are held whole when they fit in half
 * of the cap, else read a run at a time (report->position_runs), the triangles then carrying their
 * corners' positions on disk (corner records: about 110 bytes a triangle at their largest for
 * float files, with the pieces' lists, against 26 when the positions are held). Refused with
 * RSMOOTH_ERROR_UNSUPPORTED and a message: other formats, vertex normals in the file (the in-memory
 * path recomputes them), params that need the whole mesh (the normal update stage, colours, the
 * region choice: see rsmooth_piece_halo).
 * Passes (params.passes, with pass_confidence) and a move mask stream too, their results the
 * in-memory ones bit for bit: each pass after the first reads the positions the one before wrote
 * to disk (24 bytes a vertex, twice, and 4 twice more for pass_confidence: alone in a temporary
 * file, ranks past the end of the partial output), its figures and pieces made afresh; passes 0
 * gives the input back. params.move_mask is the caller's memory, one byte for each of the input's
 * vertices (rsmooth_stream_vertex_count).
 * RSMOOTH_ERROR_OUT_OF_MEMORY names the cap needed when max_memory cannot hold the buffers and one
 * piece (about 10 MB). Progress and cancellation through params' callbacks (the passes share
 * the range). */
RSMOOTH_API rsmooth_status rsmooth_stream_smooth(rsmooth_context *ctx, const char *input,
                                                 const char *output, const rsmooth_params *params,
                                                 const rsmooth_stream_options *options,
                                                 rsmooth_stream_report *report,
                                                 rsmooth_error *error);

/** The vertex count of the binary PLY `path` from its header alone, read as rsmooth_stream_smooth
 * reads it: the length of a params.move_mask for it. Errors as that call's for the header
 * (RSMOOTH_ERROR_IO, _PARSE, _UNSUPPORTED, naming the file). (Added in 0.11) */
RSMOOTH_API rsmooth_status rsmooth_stream_vertex_count(const char *path, uint64_t *vertex_count,
                                                       rsmooth_error *error);

#ifdef __cplusplus
}
#endif

#endif /* RSMOOTH_IO_H */
