/* The vertex positions of a streamed mesh: held whole when they fit in the memory the plan gives
 * them, else a run of vertices at a time, read again from the input by each pass that needs them
 * (the corner records, the grid's counts, the pieces' vertex lists). Reading the vertex block is
 * sequential and on every core, so a run costs about what its bytes take to read; what it saves
 * is the whole mesh's positions in memory (12-24 bytes a vertex: 6 GB at 10^9 triangles). */
#include "stream/stream_internal.h"

#include <math.h>
#include <string.h>

/* Fewer vertices per run than this make the passes' overheads count. */
#define MIN_RUN 4096

static uint64_t run_end(const rs_stream_vertices *v, uint64_t first) {
    return v->count - first < v->run ? v->count : first + v->run;
}

static size_t vertex_bytes(const rs_stream_vertices *v) {
    return 3 * (v->f32 ? sizeof(float) : sizeof(double));
}

/* Reads the run that starts at `first` into xyz (made when it is not there), its extent into
 * *extent. */
static rsmooth_status read_run(rs_stream_vertices *v, uint64_t first, rs_stream_extent *extent,
                               rsmooth_error *error) {
    if (!v->xyz)
        v->xyz = rs_alloc_array((size_t)(v->run ? v->run : 1), vertex_bytes(v));
    if (!v->xyz)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, RS_STREAM_WHERE,
                       "no memory for %llu vertex positions", (unsigned long long)v->run);
    v->loaded = 0;
    rsmooth_status st =
        rs_stream_ply_read_range(v->ply, first, run_end(v, first) - first, v->xyz, extent, error);
    if (st != RSMOOTH_OK)
        return st;
    v->first = first;
    v->loaded = run_end(v, first) - first;
    v->runs_read++;
    v->ply->rows_read += v->loaded;
    return RSMOOTH_OK;
}

rsmooth_status rs_stream_vertices_load(rs_stream_vertices *v, uint64_t first,
                                       rsmooth_error *error) {
    if (v->xyz && first == v->first && v->loaded == run_end(v, first) - first)
        return RSMOOTH_OK;
    rs_stream_extent unused;
    return read_run(v, first, &unused, error);
}

rsmooth_status rs_stream_vertices_open(rs_stream_vertices *v, rs_stream_ply *ply, uint64_t memory,
                                       rs_stream_extent *extent, rsmooth_error *error) {
    memset(v, 0, sizeof *v);
    v->ply = ply;
    v->f32 = ply->xyz_type == RS_PLY_FLOAT32;
    v->count = ply->vertex_count;
    v->run = memory / vertex_bytes(v);
    if (v->run < MIN_RUN)
        v->run = MIN_RUN;
    if (v->run > v->count)
        v->run = v->count;
    for (int k = 0; k < 3; k++) {
        extent->lo[k] = INFINITY;
        extent->hi[k] = -INFINITY;
    }
    extent->magnitude = 0;
    /* every run once, in file order: the extent, and the first bad vertex found first */
    for (uint64_t first = 0; first < v->count; first += v->run) {
        rs_stream_extent part;
        rsmooth_status st = read_run(v, first, &part, error);
        if (st != RSMOOTH_OK)
            return st;
        for (int k = 0; k < 3; k++) {
            extent->lo[k] = fmin(extent->lo[k], part.lo[k]);
            extent->hi[k] = fmax(extent->hi[k], part.hi[k]);
        }
        extent->magnitude = fmax(extent->magnitude, part.magnitude);
    }
    ply->magnitude = extent->magnitude;
    return RSMOOTH_OK;
}

void rs_stream_vertices_release(rs_stream_vertices *v) {
    rs_free(v->xyz);
    v->xyz = NULL;
    v->loaded = 0;
}
