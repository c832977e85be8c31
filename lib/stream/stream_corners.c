/* The triangles with their corners' positions. When every position is held, a pass reads the
 * triangle file's ids and finds each corner in the held positions (rs_corner_view). Else the
 * triangle file (vertex ids) is joined with the vertex block into a file, a run of vertices at a
 * time: each run is one pass over the triangles that fills the corners whose vertex the run holds;
 * the first pass makes the records, the others read them back. The triangles are cut into blocks on
 * every core; a block's records are read and written at their own offsets, so the file does not
 * depend on the number of threads. */
#include "stream/stream_internal.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

/* Triangles per block read and written at once. */
#define BLOCK 4096

typedef struct corner_job {
    const rs_stream_vertices *v;
    int ids_fd;
    const rs_stream_corners *out;
    size_t chunks;
    bool fresh;   /* the first run: the records are made, not read back */
    bool *failed; /* per chunk: a read or write failed, or no memory */
} corner_job;

static bool fill_block(const corner_job *job, uint64_t first, size_t n, unsigned char *ids,
                       unsigned char *records) {
    const rs_stream_vertices *v = job->v;
    size_t record = job->out->record, vertex_bytes = 3 * (v->f32 ? sizeof(float) : sizeof(double));
    size_t id_bytes = job->out->id_bytes, triangle_bytes = 3 * id_bytes;
    if (!rs_pread_all(job->ids_fd, ids, triangle_bytes * n, triangle_bytes * first))
        return false;
    if (job->fresh)
        memset(records, 0, n * record);
    else if (!rs_pread_all(job->out->fd, records, n * record, first * record))
        return false;
    const unsigned char *xyz = v->xyz;
    for (size_t t = 0; t < n; t++) {
        unsigned char *rec = records + t * record;
        if (job->fresh)
            memcpy(rec, ids + triangle_bytes * t, triangle_bytes);
        for (int c = 0; c < 3; c++) {
            uint64_t id =
                rs_stream_get_id(ids + triangle_bytes * t + id_bytes * (size_t)c, id_bytes);
            if (id >= v->first && id - v->first < v->loaded)
                memcpy(rec + triangle_bytes + (size_t)c * vertex_bytes,
                       xyz + (id - v->first) * vertex_bytes, vertex_bytes);
        }
    }
    return rs_pwrite_all(job->out->fd, records, n * record, first * record);
}

static void corner_chunks(void *ctx, size_t begin, size_t end, size_t chunk_index) {
    (void)chunk_index;
    const corner_job *job = ctx;
    uint64_t triangles = job->out->count;
    unsigned char *ids = rs_alloc_array(BLOCK, 3 * job->out->id_bytes);
    unsigned char *records = rs_alloc_array(BLOCK, job->out->record);
    for (size_t c = begin; c < end; c++) {
        bool ok = ids && records;
        uint64_t first = triangles * c / job->chunks, last = triangles * (c + 1) / job->chunks;
        for (uint64_t t = first; ok && t < last; t += BLOCK)
            ok = fill_block(job, t, (size_t)(last - t < BLOCK ? last - t : BLOCK), ids, records);
        job->failed[c] = !ok;
    }
    rs_free(ids);
    rs_free(records);
}

/* Corner q's x y z in the held positions, for a triangle's ids as the triangle file holds them. */
static const unsigned char *held_corner(const rs_stream_corners *c, const unsigned char *ids,
                                        int q) {
    const rs_stream_vertices *v = c->held;
    uint64_t id = rs_stream_get_id(ids + c->id_bytes * (size_t)q, c->id_bytes);
    return (const unsigned char *)v->xyz +
           (id - v->first) * 3 * (c->f32 ? sizeof(float) : sizeof(double));
}

/* A record made from a triangle's ids and the held positions. */
static void make_record(const rs_stream_corners *c, const unsigned char *ids, unsigned char *out) {
    size_t triangle_bytes = 3 * c->id_bytes;
    size_t vertex_bytes = 3 * (c->f32 ? sizeof(float) : sizeof(double));
    memcpy(out, ids, triangle_bytes);
    for (int q = 0; q < 3; q++)
        memcpy(out + triangle_bytes + (size_t)q * vertex_bytes, held_corner(c, ids, q),
               vertex_bytes);
}

rsmooth_status rs_stream_corners_make(rs_stream_vertices *v, bool hold, int ids_fd, size_t id_bytes,
                                      uint64_t triangles, const char *dir, rs_stream_corners *out,
                                      rsmooth_error *error) {
    out->fd = -1;
    out->ids_fd = ids_fd;
    out->held = NULL;
    out->f32 = v->f32;
    out->id_bytes = id_bytes;
    out->record = 3 * id_bytes + 9 * (v->f32 ? sizeof(float) : sizeof(double));
    out->count = triangles;
    if (hold && v->xyz && v->first == 0 && v->loaded == v->count) {
        out->held = v; /* made as read: no file */
        return RSMOOTH_OK;
    }
    out->fd = rs_stream_temporary(dir);
    if (out->fd < 0)
        return rs_fail(error, RSMOOTH_ERROR_IO, RS_STREAM_WHERE,
                       "cannot create a temporary file in %s: %s", dir, strerror(errno));
    corner_job job = {v, ids_fd, out, rs_parallel_chunks((size_t)triangles, BLOCK), true, NULL};
    job.failed = rs_calloc_array(job.chunks ? job.chunks : 1, sizeof *job.failed);
    if (!job.failed)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, RS_STREAM_WHERE, "corner records");
    rsmooth_status st = RSMOOTH_OK;
    /* the run held last first (read while measuring the extent) */
    uint64_t loaded = v->loaded ? v->first : 0;
    for (uint64_t i = 0; st == RSMOOTH_OK && i < v->count; i += v->run) {
        uint64_t first = i == 0 ? loaded : i == loaded ? 0 : i;
        st = rs_stream_vertices_load(v, first, error);
        if (st != RSMOOTH_OK)
            break;
        rs_parallel_for(job.chunks, 1, corner_chunks, &job);
        for (size_t c = 0; c < job.chunks && st == RSMOOTH_OK; c++)
            if (job.failed[c])
                st = rs_stream_unwritten(dir, 0, error);
        job.fresh = false;
    }
    rs_free(job.failed);
    return st;
}

bool rs_corner_reader_open(rs_corner_reader *cr, const rs_stream_corners *c, uint64_t first,
                           uint64_t end) {
    cr->c = c;
    if (c->held)
        return rs_stream_triangles_open_range(&cr->r, c->ids_fd, c->id_bytes, first, end);
    return rs_stream_reader_open(&cr->r, c->fd, "corners", first * c->record, end * c->record,
                                 (1u << 20) / c->record * c->record);
}

bool rs_corner_next(rs_corner_reader *cr, rs_corner_view *view) {
    const rs_stream_corners *c = cr->c;
    size_t triangle_bytes = 3 * c->id_bytes;
    size_t vertex_bytes = 3 * (c->f32 ? sizeof(float) : sizeof(double));
    const unsigned char *entry = rs_stream_read(&cr->r, c->held ? triangle_bytes : c->record);
    if (!entry)
        return false;
    view->entry = entry;
    for (int q = 0; q < 3; q++)
        view->xyz[q] =
            c->held ? held_corner(c, entry, q) : entry + triangle_bytes + (size_t)q * vertex_bytes;
    return true;
}

void rs_corner_reader_close(rs_corner_reader *cr) {
    rs_stream_reader_close(&cr->r);
}

bool rs_stream_corner_at(const rs_stream_corners *c, uint64_t t, unsigned char *out) {
    if (!c->held)
        return rs_pread_all(c->fd, out, c->record, t * c->record);
    unsigned char ids[3 * sizeof(uint64_t)];
    size_t triangle_bytes = 3 * c->id_bytes;
    if (!rs_pread_all(c->ids_fd, ids, triangle_bytes, t * triangle_bytes))
        return false;
    make_record(c, ids, out);
    return true;
}
