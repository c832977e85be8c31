/* The triangles with their corners' positions: the join of the triangle file (vertex ids) with the
 * vertex block, a run of vertices at a time. Each run is one pass over the triangles that fills
 * the corners whose vertex the run holds; the first pass makes the records, the others read them
 * back. The triangles are cut into blocks on every core; a block's records are read and written
 * at their own offsets, so the file does not depend on the number of threads. */
#include "stream/stream_internal.h"

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

rsmooth_status rs_stream_corners_write(rs_stream_vertices *v, int ids_fd, size_t id_bytes,
                                       uint64_t triangles, rs_stream_corners *out,
                                       rsmooth_error *error) {
    out->ids_fd = ids_fd;
    out->f32 = v->f32;
    out->id_bytes = id_bytes;
    out->record = 3 * id_bytes + 9 * (v->f32 ? sizeof(float) : sizeof(double));
    out->count = triangles;
    corner_job job = {v, ids_fd, out, rs_parallel_chunks((size_t)triangles, BLOCK), true, NULL};
    job.failed = rs_calloc_array(job.chunks ? job.chunks : 1, sizeof *job.failed);
    if (!job.failed)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, RS_STREAM_WHERE, "corner records");
    rsmooth_status st = RSMOOTH_OK;
    /* the run held last first: when all vertices are held, no read at all */
    uint64_t held = v->loaded ? v->first : 0;
    for (uint64_t i = 0; st == RSMOOTH_OK && i < v->count; i += v->run) {
        uint64_t first = i == 0 ? held : i == held ? 0 : i;
        st = rs_stream_vertices_load(v, first, error);
        if (st != RSMOOTH_OK)
            break;
        rs_parallel_for(job.chunks, 1, corner_chunks, &job);
        for (size_t c = 0; c < job.chunks && st == RSMOOTH_OK; c++)
            if (job.failed[c])
                st = rs_fail(error, RSMOOTH_ERROR_IO, RS_STREAM_WHERE,
                             "cannot write the temporary corner file (disk full?)");
        job.fresh = false;
    }
    rs_free(job.failed);
    return st;
}

bool rs_stream_corners_open_range(rs_stream_reader *r, const rs_stream_corners *c, uint64_t first,
                                  uint64_t end) {
    return rs_stream_reader_open(r, c->fd, "corners", first * c->record, end * c->record,
                                 (1u << 20) / c->record * c->record);
}
