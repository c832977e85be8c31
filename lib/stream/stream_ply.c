/* A binary PLY read in pieces: the header through the in-memory reader's own parser, then the
 * vertex block and the faces front to back, and results written back into a copy at their rows. */
#define _GNU_SOURCE
#include "core/environment.h"
#include "stream/stream_internal.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define READ_BUFFER (1u << 20)
/* The header is read in steps of this many bytes at first (growing fourfold). */
#define HEADER_STEP (64u << 10)

static rsmooth_status io_fail(const char *path, const char *what, rsmooth_error *error) {
    return rs_fail(error, RSMOOTH_ERROR_IO, RS_STREAM_WHERE, "%s: %s: %s", path, what,
                   strerror(errno));
}

static rsmooth_status unsupported(const char *path, const char *why, rsmooth_error *error) {
    return rs_fail(error, RSMOOTH_ERROR_UNSUPPORTED, RS_STREAM_WHERE,
                   "%s: streaming %s; without --max-memory the file is read whole (about 150 to "
                   "190 bytes of memory per triangle)",
                   path, why);
}

/* A value of type t stored in the file's byte order. */
static double value_at(const unsigned char *p, rs_ply_type t, bool swap) {
    if (!swap)
        return rs_ply_host_value(p, t);
    unsigned char b[8] = {0}; /* (a type of no size reads 0) */
    size_t n = rs_ply_type_size(t);
    for (size_t i = 0; i < n; i++)
        b[i] = p[n - 1 - i];
    return rs_ply_host_value(b, t);
}

/* Whether the line [line, end) is the parser's last: its first word is 'end_header' (a word
 * later on a line, a comment's, does not end the header). */
static bool ends_header(const char *line, const char *end) {
    while (line < end && rs_ply_is_space(*line))
        line++;
    static const char word[] = "end_header";
    size_t n = sizeof word - 1;
    return (size_t)(end - line) >= n && memcmp(line, word, n) == 0 &&
           (line + n == end || rs_ply_is_space(line[n]));
}

/* Reads the header after the byte-order mark, up to and with its 'end_header' line (or the whole
 * file, whose missing line the parser then reports), through a buffer that grows as the lines
 * need, to at most `limit` bytes. */
static rsmooth_status read_header(rs_stream_ply *ply, uint64_t limit, rsmooth_error *error) {
    const uint64_t start = ply->bom ? RS_IO_UTF8_BOM_SIZE : 0, available = ply->size - start;
    size_t cap = 0, len = 0, line = 0; /* buf[line, len): not yet seen whole */
    char *buf = NULL;
    for (;;) {
        const char *eol = NULL;
        while (len > line && (eol = memchr(buf + line, '\n', len - line)) != NULL) {
            if (ends_header(buf + line, eol)) {
                len = (size_t)(eol + 1 - buf);
                break;
            }
            line = (size_t)(eol + 1 - buf);
        }
        if (eol || len == available) {
            ply->header.data = buf;
            ply->header.size = len;
            return RSMOOTH_OK;
        }
        if (len == cap) {
            if (cap >= limit) {
                rs_free(buf);
                return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, RS_STREAM_WHERE,
                               "%s: the header runs past %.1f MB without its 'end_header' line: "
                               "more than the memory cap allows it",
                               ply->path, (double)cap / (1 << 20));
            }
            uint64_t grown = cap ? 4 * (uint64_t)cap : HEADER_STEP;
            grown = grown > limit ? limit : grown;
            grown = grown > available ? available : grown;
            char *bigger = rs_realloc_array(buf, (size_t)grown + 1, 1);
            if (!bigger) {
                rs_free(buf);
                return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, RS_STREAM_WHERE,
                               "%s: no memory for a header of %.1f MB", ply->path,
                               (double)grown / (1 << 20));
            }
            buf = bigger;
            cap = (size_t)grown;
        }
        if (!rs_pread_all(ply->fd, buf + len, cap - len, start + len)) {
            rs_free(buf);
            return io_fail(ply->path, "cannot read", error);
        }
        len = cap;
        buf[len] = 0;
    }
}

/* Bytes of one item of an element without lists. */
static size_t row_bytes(const rs_ply_element *e, bool *has_list) {
    size_t n = 0;
    *has_list = false;
    for (size_t k = 0; k < e->property_count; k++) {
        if (e->properties[k].count_type != RS_PLY_NONE)
            *has_list = true;
        else
            n += rs_ply_type_size(e->properties[k].type);
    }
    return n;
}

/* Where element e, starting at `start`, ends: its items' fixed size, or (with lists) its items
 * walked. 0 with *st set when the file is too short for it. */
static uint64_t step_over(rs_stream_ply *ply, const rs_ply_element *e, uint64_t start,
                          rsmooth_error *error, rsmooth_status *st) {
    bool list = false;
    size_t bytes = row_bytes(e, &list);
    if (!list) {
        if (bytes && e->count > (ply->size - start) / bytes) {
            *st = rs_fail_parse(error, e->header_line, -1, RS_STREAM_WHERE,
                                "%s: %llu '%s' items of %zu bytes do not fit in the file",
                                ply->path, (unsigned long long)e->count, e->name, bytes);
            return 0;
        }
        return start + e->count * bytes;
    }
    rs_stream_reader r;
    if (!rs_stream_reader_open(&r, ply->fd, ply->path, start, ply->size, READ_BUFFER)) {
        *st = rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, RS_STREAM_WHERE, "read buffer");
        return 0;
    }
    for (uint64_t i = 0; i < e->count; i++)
        for (size_t k = 0; k < e->property_count; k++) {
            const rs_ply_property *p = &e->properties[k];
            size_t n = 1;
            if (p->count_type != RS_PLY_NONE) {
                uint64_t at = rs_stream_reader_offset(&r);
                const unsigned char *c = rs_stream_read(&r, rs_ply_type_size(p->count_type));
                if (!c)
                    goto short_file;
                double count = value_at(c, p->count_type, ply->swap);
                if (count < 0) { /* the in-memory reader's refusal, where it makes it */
                    rs_stream_reader_close(&r);
                    *st = rs_fail_parse(error, -1, (int64_t)at, RS_STREAM_WHERE,
                                        "%s: byte %llu: negative list count in element '%.40s' "
                                        "item %llu",
                                        ply->path, (unsigned long long)at, e->name,
                                        (unsigned long long)i);
                    return 0;
                }
                n = (size_t)count;
            }
            for (size_t j = 0; j < n; j++)
                if (!rs_stream_read(&r, rs_ply_type_size(p->type)))
                    goto short_file;
        }
    uint64_t end = rs_stream_reader_offset(&r);
    rs_stream_reader_close(&r);
    return end;
short_file:
    rs_stream_reader_close(&r);
    *st = rs_fail_parse(error, -1, (int64_t)rs_stream_reader_offset(&r), RS_STREAM_WHERE,
                        "%s: the file ends inside element '%s'", ply->path, e->name);
    return 0;
}

/* Where the vertex and face blocks start; what streaming cannot do is refused. */
static rsmooth_status find_layout(rs_stream_ply *ply, rsmooth_error *error) {
    rs_ply_reader *h = &ply->header;
    if (h->encoding == RS_PLY_ASCII)
        return unsupported(ply->path, "reads binary PLY only (this one is ascii)", error);
    if (h->normals)
        return unsupported(ply->path,
                           "does not recompute vertex normals (nx ny nz), as the in-memory path "
                           "does",
                           error);
    ply->swap = h->swap;
    const rs_ply_element *v = h->vertex_element;
    ply->vertex_count = v->count;
    ply->face_count = h->face_element ? h->face_element->count : 0;
    bool list = false;
    ply->vertex_stride = row_bytes(v, &list);
    if (list)
        return unsupported(ply->path, "needs vertices of fixed size (this vertex has a list)",
                           error);
    size_t offset = 0;
    for (size_t k = 0; k < v->property_count; k++) {
        const rs_ply_property *p = &v->properties[k];
        if (p->role >= RS_PLY_X && p->role <= RS_PLY_Z) {
            ply->xyz_offset[p->role - RS_PLY_X] = offset;
            if (p->type != RS_PLY_FLOAT32 && p->type != RS_PLY_FLOAT64)
                return unsupported(ply->path, "writes float or double x, y, z only", error);
            if (ply->xyz_type != RS_PLY_NONE && ply->xyz_type != p->type)
                return unsupported(ply->path, "needs x, y and z of one type", error);
            ply->xyz_type = p->type;
        }
        offset += rs_ply_type_size(p->type);
    }
    /* Elements before the later of the two blocks are stepped over (those with lists item by
     * item: the faces too, in a file that puts them before the vertices). */
    uint64_t at = ply->data_start;
    rsmooth_status st = RSMOOTH_OK;
    bool vertex_seen = false, face_seen = h->face_element == NULL;
    for (size_t ei = 0; ei < h->x->element_count && !(vertex_seen && face_seen); ei++) {
        const rs_ply_element *e = &h->x->elements[ei];
        if (e == h->vertex_element) {
            ply->vertex_start = at;
            vertex_seen = true;
        }
        if (e == h->face_element) {
            ply->face_start = at;
            face_seen = true;
        }
        if (vertex_seen && face_seen)
            break;
        at = step_over(ply, e, at, error, &st);
        if (st != RSMOOTH_OK)
            return st;
    }
    return RSMOOTH_OK;
}

/* The output's header: rs_io_ply_write's for what the reader makes of this one. */
static rsmooth_status output_header(rs_stream_ply *ply, rsmooth_error *error) {
    FILE *f = open_memstream(&ply->out_header, &ply->out_header_size);
    bool ok = f && rs_io_ply_write_binary_header(f, ply->header.x, ply->plain, ply->bom,
                                                 ply->xyz_type == RS_PLY_FLOAT32);
    if (f && fclose(f) != 0)
        ok = false;
    return ok ? RSMOOTH_OK
              : rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, RS_STREAM_WHERE,
                        "%s: no memory for the output's header", ply->path);
}

rsmooth_status rs_stream_ply_open(rs_stream_ply *ply, const char *path, uint64_t header_memory,
                                  rsmooth_error *error) {
    memset(ply, 0, sizeof *ply);
    ply->path = path;
    ply->fd = open(path, O_RDONLY | O_CLOEXEC);
    if (ply->fd < 0)
        return io_fail(path, "cannot open", error);
    struct stat sb;
    if (fstat(ply->fd, &sb) != 0)
        return io_fail(path, "cannot stat", error);
    if (!S_ISREG(sb.st_mode))
        return unsupported(path, "needs a regular file (it reads the file more than once)", error);
    ply->size = (uint64_t)sb.st_size;
    char magic[7] = {0}; /* a byte-order mark, as the in-memory reader takes it, then "ply" */
    size_t got = ply->size < sizeof magic ? (size_t)ply->size : sizeof magic;
    if (!rs_pread_all(ply->fd, magic, got, 0))
        return io_fail(path, "cannot read", error);
    ply->bom = got >= RS_IO_UTF8_BOM_SIZE && !memcmp(magic, RS_IO_UTF8_BOM, RS_IO_UTF8_BOM_SIZE);
    const char *m = magic + (ply->bom ? RS_IO_UTF8_BOM_SIZE : 0);
    if (got < (size_t)(m - magic) + 4 || memcmp(m, "ply", 3) != 0 || (m[3] != '\n' && m[3] != '\r'))
        return unsupported(path, "reads binary PLY only, and this is not a PLY file", error);
    rsmooth_status st = read_header(ply, header_memory, error);
    if (st != RSMOOTH_OK)
        return st;
    ply->header.precision = RSMOOTH_FLOAT32;
    ply->header.x = rs_calloc_array(1, sizeof *ply->header.x);
    if (!ply->header.x)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, RS_STREAM_WHERE, "PLY header");
    ply->header.x->vertex_element = ply->header.x->face_element = SIZE_MAX;
    ply->header.max_vertices = 1ull << 48; /* ids are 64-bit here; indices exact in a double */
    rsmooth_error detail;
    st = rs_ply_parse_header(&ply->header, &detail);
    if (st == RSMOOTH_OK)
        st = rs_ply_find_elements(&ply->header, &detail);
    if (st == RSMOOTH_OK)
        st = rs_ply_assign_roles(&ply->header, &detail);
    if (st != RSMOOTH_OK) { /* the reader's message, with the file named */
        int64_t offset = detail.byte_offset;
        if (offset >= 0 && ply->bom) /* offsets count from the file's first byte */
            offset += RS_IO_UTF8_BOM_SIZE;
        rs_fail_parse(error, detail.line, offset, RS_STREAM_WHERE, "%s: %s", path, detail.message);
        return st;
    }
    if (rs_ply_range_grid_element(ply->header.x)) /* not a point cloud: refused, not misread */
        return unsupported(path, "does not triangulate range grids (element 'range_grid')", error);
    ply->data_start = (ply->bom ? RS_IO_UTF8_BOM_SIZE : 0) + (uint64_t)ply->header.pos;
    ply->plain = rs_ply_is_plain(&ply->header);
    ply->out_swap = !rs_ply_host_is_le(); /* rs_io_ply_write writes little-endian */
    st = find_layout(ply, error);
    const char *wide = rs_environment_now(RS_ENV_STREAM_WIDE_IDS);
    ply->id_bytes = ply->vertex_count >= UINT32_MAX || (wide && !strcmp(wide, "1")) ? 8 : 4;
    return st == RSMOOTH_OK ? output_header(ply, error) : st;
}

void rs_stream_ply_close(rs_stream_ply *ply) {
    if (ply->fd >= 0)
        close(ply->fd);
    rs_free((char *)ply->header.data);
    rs_io_ply_extras_free(ply->header.x);
    free(ply->out_header); /* open_memstream's */
    memset(ply, 0, sizeof *ply);
}

/* One chunk of rows of rs_stream_ply_read_vertices, on every core. */
typedef struct vertex_chunk {
    rs_stream_extent extent;
    uint64_t bad; /* the first vertex with a coordinate out of range, or UINT64_MAX */
    double bad_value;
    bool unread, no_memory;
} vertex_chunk;

typedef struct vertex_job {
    const rs_stream_ply *ply;
    uint64_t first; /* the vertex xyz[0] is */
    void *xyz;
    vertex_chunk *chunk;
} vertex_job;

static void read_rows(void *ctx, size_t begin, size_t end, size_t chunk_index) {
    const vertex_job *job = ctx;
    const rs_stream_ply *ply = job->ply;
    vertex_chunk *chunk = job->chunk + chunk_index;
    chunk->bad = UINT64_MAX;
    for (int k = 0; k < 3; k++) {
        chunk->extent.lo[k] = INFINITY;
        chunk->extent.hi[k] = -INFINITY;
    }
    rs_stream_reader r;
    uint64_t first = job->first + begin, last = job->first + end;
    if (!rs_stream_reader_open(&r, ply->fd, ply->path,
                               ply->vertex_start + first * ply->vertex_stride,
                               ply->vertex_start + last * ply->vertex_stride, READ_BUFFER)) {
        chunk->no_memory = true;
        return;
    }
    bool f32 = ply->xyz_type == RS_PLY_FLOAT32;
    rs_stream_extent *extent = &chunk->extent;
    for (uint64_t i = first; i < last && chunk->bad == UINT64_MAX; i++) {
        uint64_t at = 3 * (i - job->first);
        const unsigned char *row = rs_stream_read(&r, ply->vertex_stride);
        if (!row) {
            chunk->unread = true;
            break;
        }
        for (int k = 0; k < 3; k++) {
            double c = value_at(row + ply->xyz_offset[k], ply->xyz_type, ply->swap);
            if (!rs_io_coordinate_ok(c)) {
                chunk->bad = i;
                chunk->bad_value = c;
                break;
            }
            extent->magnitude = fmax(extent->magnitude, fabs(c));
            extent->lo[k] = fmin(extent->lo[k], c);
            extent->hi[k] = fmax(extent->hi[k], c);
            if (f32)
                ((float *)job->xyz)[at + (uint64_t)k] = (float)c;
            else
                ((double *)job->xyz)[at + (uint64_t)k] = c;
        }
    }
    rs_stream_reader_close(&r);
}

rsmooth_status rs_stream_ply_read_range(rs_stream_ply *ply, uint64_t first, uint64_t count,
                                        void *xyz, rs_stream_extent *extent, rsmooth_error *error) {
    uint64_t end = ply->vertex_start + ply->vertex_count * ply->vertex_stride;
    if (end > ply->size)
        return rs_fail_parse(error, -1, (int64_t)ply->size, RS_STREAM_WHERE,
                             "%s: the file ends inside the vertex block", ply->path);
    /* rows on every core, each chunk from its own place in the file; the extent's minima and
     * maxima and the first bad vertex do not depend on how the rows were cut */
    size_t rows = (size_t)count, chunks = rs_parallel_chunks(rows, 65536);
    vertex_chunk *chunk = rs_calloc_array(chunks ? chunks : 1, sizeof *chunk);
    if (!chunk)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, RS_STREAM_WHERE, "read buffer");
    vertex_job job = {ply, first, xyz, chunk};
    rs_parallel_for(rows, 65536, read_rows, &job);
    for (int k = 0; k < 3; k++) {
        extent->lo[k] = INFINITY;
        extent->hi[k] = -INFINITY;
    }
    extent->magnitude = 0;
    rsmooth_status st = RSMOOTH_OK;
    for (size_t c = 0; c < chunks && st == RSMOOTH_OK; c++) { /* in file order: the first error */
        if (chunk[c].no_memory)
            st = rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, RS_STREAM_WHERE, "read buffer");
        else if (chunk[c].bad != UINT64_MAX)
            st = rs_fail_parse(error, -1,
                               (int64_t)(ply->vertex_start + chunk[c].bad * ply->vertex_stride),
                               RS_STREAM_WHERE,
                               "%s: vertex %llu has coordinate %g (finite values up to 1e150 "
                               "are supported)",
                               ply->path, (unsigned long long)chunk[c].bad, chunk[c].bad_value);
        else if (chunk[c].unread)
            st = io_fail(ply->path, "cannot read the vertices", error);
        for (int k = 0; k < 3; k++) {
            extent->lo[k] = fmin(extent->lo[k], chunk[c].extent.lo[k]);
            extent->hi[k] = fmax(extent->hi[k], chunk[c].extent.hi[k]);
        }
        extent->magnitude = fmax(extent->magnitude, chunk[c].extent.magnitude);
    }
    rs_free(chunk);
    return st;
}

bool rs_stream_ply_read_rows(const rs_stream_ply *ply, const uint64_t *ids, size_t n, double *xyz) {
    enum { RUN_ROWS = 4096 };
    size_t stride = ply->vertex_stride;
    unsigned char *rows = rs_alloc_array(RUN_ROWS, stride);
    bool ok = rows != NULL;
    for (size_t i = 0; ok && i < n;) {
        size_t run = rs_stream_id_run(ids, i, n, RUN_ROWS); /* consecutive ids: one read */
        ok = rs_pread_all(ply->fd, rows, run * stride, ply->vertex_start + ids[i] * stride);
        for (size_t j = 0; ok && j < run; j++)
            for (int k = 0; k < 3; k++)
                xyz[3 * (i + j) + (size_t)k] =
                    value_at(rows + j * stride + ply->xyz_offset[k], ply->xyz_type, ply->swap);
        i += run;
    }
    rs_free(rows);
    return ok;
}

/* The in-memory reader's last check: after the elements the header declares, blanks only (a
 * file whose counts leave data out is not what it claims). `at` is where element `next` starts. */
static rsmooth_status check_end(rs_stream_ply *ply, size_t next, uint64_t at,
                                rsmooth_error *error) {
    const rs_ply_reader *h = &ply->header;
    rsmooth_status st = RSMOOTH_OK;
    for (size_t ei = next; ei < h->x->element_count; ei++) {
        at = step_over(ply, h->x->elements + ei, at, error, &st);
        if (st != RSMOOTH_OK)
            return st;
    }
    ply->data_end = at;
    rs_stream_reader r;
    if (!rs_stream_reader_open(&r, ply->fd, ply->path, at, ply->size, READ_BUFFER))
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, RS_STREAM_WHERE, "read buffer");
    for (uint64_t p = at; p < ply->size; p++) {
        const unsigned char *c = rs_stream_read(&r, 1);
        if (!c) {
            st = io_fail(ply->path, "cannot read", error);
            break;
        }
        if (!rs_ply_is_space((char)*c)) {
            st = rs_fail_parse(error, -1, (int64_t)p, RS_STREAM_WHERE,
                               "%s: %llu bytes after the data the header declares (from byte "
                               "%llu, 0x%02x): the header's counts leave data out",
                               ply->path, (unsigned long long)(ply->size - p),
                               (unsigned long long)p, (unsigned)*c);
            break;
        }
    }
    rs_stream_reader_close(&r);
    return st;
}

/* The index of element e in the header. */
static size_t element_index(const rs_stream_ply *ply, const rs_ply_element *e) {
    return (size_t)(e - ply->header.x->elements);
}

/* Nearly every file's faces: one list property alone, a one-byte count and 32-bit indices, three
 * each; rows of FACE_ROW bytes then, read on every core. */
#define FACE_ROW 13
typedef struct triangle_rows {
    const rs_stream_ply *ply;
    int fd;
    bool is_signed;
    bool *odd; /* per chunk: a row that is not three indices in range (the general reader then) */
} triangle_rows;

static void triangle_chunk(void *ctx, size_t begin, size_t end, size_t chunk) {
    triangle_rows *job = ctx;
    const rs_stream_ply *ply = job->ply;
    enum { ROWS = 1 << 15 };
    size_t id_bytes = ply->id_bytes, row = FACE_ROW;
    unsigned char *in = rs_alloc_array(ROWS, row);
    unsigned char *out = rs_alloc_array(ROWS, 3 * id_bytes);
    bool odd = !in || !out;
    for (uint64_t first = begin; !odd && first < end; first += ROWS) {
        size_t n = end - first < ROWS ? (size_t)(end - first) : ROWS;
        odd = !rs_pread_all(ply->fd, in, n * row, ply->face_start + first * row);
        for (size_t i = 0; !odd && i < n; i++) {
            const unsigned char *r = in + i * row;
            odd = r[0] != 3;
            for (int c = 0; c < 3 && !odd; c++) {
                unsigned char b[4];
                for (int k = 0; k < 4; k++)
                    b[k] = r[1 + 4 * c + (ply->swap ? 3 - k : k)];
                uint32_t u;
                memcpy(&u, b, sizeof u);
                odd = (job->is_signed && (int32_t)u < 0) || u >= ply->vertex_count;
                rs_stream_put_id(out + (3 * i + (size_t)c) * id_bytes, u, id_bytes);
            }
        }
        odd = odd || !rs_pwrite_all(job->fd, out, n * 3 * id_bytes, first * 3 * id_bytes);
    }
    rs_free(in);
    rs_free(out);
    job->odd[chunk] = odd;
}

/* The faces as rows of FACE_ROW bytes, when the header says so and every row is a triangle in
 * range; false (nothing to be relied on written) otherwise, and on any read or write error: the
 * general reader then says what is wrong. */
static bool fixed_triangles(rs_stream_ply *ply, const rs_ply_element *f, int triangles_fd) {
    const rs_ply_property *p = f->property_count == 1 ? &f->properties[0] : NULL;
    if (!p || p->role != RS_PLY_FACE_LIST || rs_ply_type_size(p->count_type) != 1 ||
        (p->type != RS_PLY_INT32 && p->type != RS_PLY_UINT32) || f->count > UINT64_MAX / FACE_ROW ||
        ply->face_start + f->count * FACE_ROW > ply->size)
        return false;
    size_t chunks = rs_parallel_chunks((size_t)f->count, 1 << 16);
    triangle_rows job = {ply, triangles_fd, p->type == RS_PLY_INT32,
                         rs_calloc_array(chunks, sizeof(bool))};
    if (!job.odd)
        return false;
    rs_parallel_for((size_t)f->count, 1 << 16, triangle_chunk, &job);
    bool ok = true;
    for (size_t c = 0; c < chunks; c++)
        ok = ok && !job.odd[c];
    rs_free(job.odd);
    if (!ok && ftruncate(triangles_fd, 0) != 0) /* (the general reader writes it from the start) */
        return false;
    return ok;
}

rsmooth_status rs_stream_ply_write_triangles(rs_stream_ply *ply, int triangles_fd, const char *dir,
                                             uint64_t *triangle_count, rsmooth_error *error) {
    *triangle_count = 0;
    const rs_ply_element *f = ply->header.face_element;
    if (!f) {
        const rs_ply_element *v = ply->header.vertex_element;
        return check_end(ply, element_index(ply, v) + 1,
                         ply->vertex_start + v->count * ply->vertex_stride, error);
    }
    if (fixed_triangles(ply, f, triangles_fd)) {
        *triangle_count = f->count;
        return check_end(ply, element_index(ply, f) + 1, ply->face_start + f->count * FACE_ROW,
                         error);
    }
    rs_stream_reader r;
    if (!rs_stream_reader_open(&r, ply->fd, ply->path, ply->face_start, ply->size, READ_BUFFER))
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, RS_STREAM_WHERE, "read buffer");
    enum { OUT_TRIANGLES = 1 << 16 };
    size_t id_bytes = ply->id_bytes, triangle_bytes = 3 * id_bytes;
    unsigned char *out = rs_alloc_array(OUT_TRIANGLES, triangle_bytes);
    if (!out) {
        rs_stream_reader_close(&r);
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, RS_STREAM_WHERE, "face buffer");
    }
    size_t buffered = 0;
    uint64_t written = 0;
    rsmooth_status st = RSMOOTH_OK;
    for (uint64_t i = 0; i < f->count && st == RSMOOTH_OK; i++) {
        for (size_t k = 0; k < f->property_count && st == RSMOOTH_OK; k++) {
            const rs_ply_property *p = &f->properties[k];
            uint64_t at = rs_stream_reader_offset(&r);
            uint64_t n = 1;
            if (p->count_type != RS_PLY_NONE) {
                const unsigned char *c = rs_stream_read(&r, rs_ply_type_size(p->count_type));
                double count = c ? value_at(c, p->count_type, ply->swap) : 0;
                if (!c || !(count >= 0)) {
                    st = c ? rs_fail_parse(error, -1, (int64_t)at, RS_STREAM_WHERE,
                                           "%s: face %llu: negative list count", ply->path,
                                           (unsigned long long)i)
                           : rs_fail_parse(error, -1, (int64_t)at, RS_STREAM_WHERE,
                                           "%s: the file ends inside face %llu", ply->path,
                                           (unsigned long long)i);
                    break;
                }
                n = (uint64_t)count;
            }
            size_t item = rs_ply_type_size(p->type);
            if (p->role != RS_PLY_FACE_LIST) {
                for (uint64_t j = 0; j < n && st == RSMOOTH_OK; j++)
                    if (!rs_stream_read(&r, item))
                        st = rs_fail_parse(error, -1, (int64_t)at, RS_STREAM_WHERE,
                                           "%s: the file ends inside face %llu", ply->path,
                                           (unsigned long long)i);
                continue;
            }
            if (n < 3) {
                st = rs_fail_parse(error, -1, (int64_t)at, RS_STREAM_WHERE,
                                   "%s: face %llu has %llu vertices (at least 3 needed)", ply->path,
                                   (unsigned long long)i, (unsigned long long)n);
                break;
            }
            uint64_t first = 0, previous = 0;
            for (uint64_t j = 0; j < n; j++) {
                uint64_t item_at = rs_stream_reader_offset(&r);
                const unsigned char *c = rs_stream_read(&r, item);
                double v = c ? value_at(c, p->type, ply->swap) : -1;
                if (!c || !(v >= 0 && v < (double)ply->vertex_count && v == floor(v))) {
                    st = !c ? rs_fail_parse(error, -1, (int64_t)item_at, RS_STREAM_WHERE,
                                            "%s: the file ends inside face %llu", ply->path,
                                            (unsigned long long)i)
                            : rs_fail_parse(error, -1, (int64_t)item_at, RS_STREAM_WHERE,
                                            "%s: face %llu: index %.17g out of range (%llu "
                                            "vertices)",
                                            ply->path, (unsigned long long)i, v,
                                            (unsigned long long)ply->vertex_count);
                    break;
                }
                uint64_t index = (uint64_t)v;
                if (j == 0)
                    first = index;
                if (j >= 2) { /* the fan the in-memory reader makes: (v0, v[j-1], v[j]) */
                    unsigned char *t = out + triangle_bytes * buffered++;
                    rs_stream_put_id(t, first, id_bytes);
                    rs_stream_put_id(t + id_bytes, previous, id_bytes);
                    rs_stream_put_id(t + 2 * id_bytes, index, id_bytes);
                    if (buffered == OUT_TRIANGLES) {
                        if (!rs_pwrite_all(triangles_fd, out, buffered * triangle_bytes,
                                           written * triangle_bytes))
                            st = rs_stream_unwritten(dir, errno, error);
                        written += buffered;
                        buffered = 0;
                    }
                }
                previous = index;
            }
        }
    }
    if (st == RSMOOTH_OK && buffered > 0 &&
        !rs_pwrite_all(triangles_fd, out, buffered * triangle_bytes, written * triangle_bytes))
        st = rs_stream_unwritten(dir, errno, error);
    written += buffered;
    uint64_t face_end = rs_stream_reader_offset(&r);
    rs_free(out);
    rs_stream_reader_close(&r);
    *triangle_count = written;
    if (st == RSMOOTH_OK)
        st = check_end(ply, element_index(ply, f) + 1, face_end, error);
    return st;
}

/* A double as the file stores it: its type, its byte order. */
static void put_value(unsigned char *p, double x, rs_ply_type t, bool swap) {
    unsigned char b[8];
    size_t n = rs_ply_type_size(t);
    if (t == RS_PLY_FLOAT32) {
        float f = (float)x;
        memcpy(b, &f, 4);
    } else {
        memcpy(b, &x, 8);
    }
    for (size_t i = 0; i < n; i++)
        p[i] = swap ? b[n - 1 - i] : b[i];
}

/* Where input byte `at` of the data goes in the output: after the output's own header. */
static uint64_t output_offset(const rs_stream_ply *ply, uint64_t at) {
    return ply->out_header_size + (at - ply->data_start);
}

/* The output's data written front to back through a buffer, each value's bytes reversed. */
typedef struct swapped_writer {
    int fd;
    uint64_t at; /* where buf goes */
    unsigned char *buf;
    size_t used;
    bool ok;
} swapped_writer;

/* Copies the next value, of type t, from the input to the output in the other byte order; its
 * value (a list's count: checked when its element was read), or -1 when the input ends. */
static double copy_value(rs_stream_reader *r, swapped_writer *w, rs_ply_type t, bool swap) {
    size_t size = rs_ply_type_size(t);
    const unsigned char *v = rs_stream_read(r, size);
    if (!v)
        return w->ok = false, -1;
    if (w->used + size > READ_BUFFER) {
        w->ok = w->ok && rs_pwrite_all(w->fd, w->buf, w->used, w->at);
        w->at += w->used;
        w->used = 0;
    }
    for (size_t b = 0; b < size; b++)
        w->buf[w->used + b] = v[size - 1 - b];
    w->used += size;
    return value_at(v, t, swap);
}

/* The data into the output little-endian from a big-endian input: value by value, lists walked. */
static bool copy_swapped(const rs_stream_ply *ply, int out_fd) {
    swapped_writer w = {out_fd, output_offset(ply, ply->data_start), rs_alloc_array(READ_BUFFER, 1),
                        0, true};
    rs_stream_reader r;
    if (!w.buf || !rs_stream_reader_open(&r, ply->fd, ply->path, ply->data_start, ply->data_end,
                                         READ_BUFFER)) {
        rs_free(w.buf);
        return false;
    }
    const rs_ply_extras *x = ply->header.x;
    for (size_t ei = 0; w.ok && ei < x->element_count; ei++) {
        const rs_ply_element *e = &x->elements[ei];
        for (uint64_t i = 0; w.ok && i < e->count && e->property_count > 0; i++)
            for (size_t k = 0; w.ok && k < e->property_count; k++) {
                const rs_ply_property *p = &e->properties[k];
                double n =
                    p->count_type == RS_PLY_NONE ? 1 : copy_value(&r, &w, p->count_type, ply->swap);
                for (double j = 0; w.ok && j < n; j++)
                    copy_value(&r, &w, p->type, ply->swap);
            }
    }
    bool ok = w.ok && rs_pwrite_all(out_fd, w.buf, w.used, w.at);
    rs_stream_reader_close(&r);
    rs_free(w.buf);
    return ok;
}

bool rs_stream_ply_write_copy(const rs_stream_ply *ply, int out_fd) {
    if (!rs_pwrite_all(out_fd, ply->out_header, ply->out_header_size, 0))
        return false;
    if (ply->swap != ply->out_swap) /* big-endian in: rs_io_ply_write writes little-endian */
        return copy_swapped(ply, out_fd);
    return rs_stream_copy(ply->fd, ply->data_start, out_fd, output_offset(ply, ply->data_start),
                          ply->data_end - ply->data_start);
}

rsmooth_status rs_stream_ply_check_positions(const rs_stream_ply *ply, const uint64_t *ids,
                                             size_t n, const double *xyz, const char *output,
                                             rsmooth_error *error) {
    rsmooth_error detail;
    rsmooth_error_init(&detail);
    if (rs_io_ply_check_positions(xyz, n, ids, ply->header.vertex_element, ply->magnitude,
                                  &detail) == RSMOOTH_OK)
        return RSMOOTH_OK;
    if (ply->plain && ply->xyz_type == RS_PLY_FLOAT32) /* from memory: written as double */
        return rs_fail(error, RSMOOTH_ERROR_NUMERICAL, RS_STREAM_WHERE,
                       "%s: cannot write: streaming keeps the input's float x y z (without "
                       "--max-memory they are written as double): %s",
                       output, detail.message);
    return rs_fail(error, RSMOOTH_ERROR_NUMERICAL, RS_STREAM_WHERE, "%s: cannot write: %s", output,
                   detail.message);
}

bool rs_stream_ply_write_positions(const rs_stream_ply *ply, int out_fd, const uint64_t *ids,
                                   size_t n, const double *xyz) {
    enum { RUN_ROWS = 4096 };
    size_t stride = ply->vertex_stride;
    /* rows holding only x, y, z need not be read first: every byte of them is written */
    bool whole_rows = stride == 3 * rs_ply_type_size(ply->xyz_type);
    unsigned char *rows = rs_alloc_array(RUN_ROWS, stride);
    if (!rows)
        return false;
    bool ok = true;
    for (size_t i = 0; ok && i < n;) {
        /* consecutive ids: one read and one write */
        size_t run = rs_stream_id_run(ids, i, n, RUN_ROWS);
        uint64_t at = output_offset(ply, ply->vertex_start + ids[i] * stride);
        ok = whole_rows || rs_pread_all(out_fd, rows, run * stride, at);
        for (size_t j = 0; ok && j < run; j++)
            for (int k = 0; k < 3; k++)
                put_value(rows + j * stride + ply->xyz_offset[k], xyz[3 * (i + j) + (size_t)k],
                          ply->xyz_type, ply->out_swap);
        ok = ok && rs_pwrite_all(out_fd, rows, run * stride, at);
        i += run;
    }
    rs_free(rows);
    return ok;
}
