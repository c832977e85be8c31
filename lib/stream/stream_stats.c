/* The whole mesh's figures, from its corner records on disk (no position is looked up by vertex
 * id), summed in the order the in-memory path sums them (lib/core/mesh.c), so that the sigmas and
 * the area scale are the same bits:
 *
 *   - the mean edge length over unique edges: each edge belongs to its lower vertex, vertices in
 *     ascending order, a vertex's edges in the order the triangles first name them (mesh.c's
 *     counting sort), a run of vertices at a time when all of them do not fit in memory;
 *   - the mean area: facets summed per block of 8192 triangles, the blocks' sums in order.
 *
 * Both sum at the in-memory path's own power-of-two scale (scale.c, from the same sampled
 * triangles), so even where squares under- or overflow at other scales the figures agree. The
 * edges are counted and placed by runs of triangles on every core (the counting reads the ids file
 * alone while it is kept), an edge's length measured from the record that places it, or from the
 * held positions when its bucket is ordered; the buckets' order and the blocks' sums are made on
 * every core (rs_parallel_for); only the final sums run in one thread, in that order, so the bits
 * do not depend on the number of threads. The facets' pass (rs_stream_facet_figures) comes after
 * the cut into pieces, whose counts it takes too. */
#include "core/edge_bucket.h"
#include "core/parts.h"
#include "stream/stream_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* mesh.c's block of the area sums */
#define GEOMETRY_BLOCK 8192
/* A facet's corner lies at most 2/3 of its longest edge from its centroid (two thirds of a
 * median, and no median is longer than the longest side); 0.7 leaves room for rounding. */
#define REACH_PER_EDGE 0.7

static rsmooth_status read_fail(rsmooth_error *error) {
    return rs_fail(error, RSMOOTH_ERROR_IO, RS_STREAM_WHERE,
                   "cannot read the temporary corner file");
}

/* An edge as a lower vertex's bucket holds it: its upper end and its length (in arrays: the upper
 * ends' low 32 bits, their high halves only for 64-bit ids, the lengths: 12 bytes an edge, 16 with
 * 64-bit ids; this pair only while a large bucket is sorted). */
typedef struct edge_end {
    uint64_t upper;
    double length;
} edge_end;

static int edge_end_compare(const void *a, const void *b) {
    return rs_edge_compare64(&((const edge_end *)a)->upper, &((const edge_end *)b)->upper);
}

/* The lower vertices whose buckets edge_marks orders. */
typedef struct edge_job {
    const size_t *start; /* bucket i: upper and length [start[i], start[i + 1]) */
    uint32_t *upper;     /* the low 32 bits */
    uint32_t *high;      /* the high 32 bits, or NULL (32-bit ids) */
    double *length;
    /* when the positions are held whole: the lengths are measured here (on every core, each
     * bucket's lower vertex lo + i) rather than while the edges are placed */
    const rs_stream_vertices *held;
    uint64_t lo;
    double scale;
    bool no_memory;
} edge_job;

/* An edge's length from its lower end p to its upper end q, at `scale`, as mesh.c measures it. */
static double edge_length_at(const double p[3], const double q[3], double scale) {
    double d[3];
    for (int k = 0; k < 3; k++)
        d[k] = p[k] * scale - q[k] * scale;
    return sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
}

/* The length of the edge from held vertex a (lower) to b. */
static double held_length(const rs_stream_vertices *v, uint64_t a, uint64_t b, double scale) {
    double p[3], q[3];
    rs_stream_vertex(v, a, p);
    rs_stream_vertex(v, b, q);
    return edge_length_at(p, q, scale);
}

/* A bucket of more than RS_EDGE_SCAN_LIMIT edges sorted by upper end, its lengths along. */
static bool sort_bucket(uint64_t *upper, double *length, size_t n) {
    edge_end *pairs = rs_alloc_array(n, sizeof *pairs);
    if (!pairs)
        return false;
    for (size_t j = 0; j < n; j++)
        pairs[j] = (edge_end){upper[j], length[j]};
    qsort(pairs, n, sizeof *pairs, edge_end_compare);
    for (size_t j = 0; j < n; j++) {
        upper[j] = pairs[j].upper;
        length[j] = pairs[j].length;
    }
    rs_free(pairs);
    return true;
}

/* Bucket i put in the order its edges are counted in (core/edge_bucket.h: sorted when large;
 * repeated edges have the same length, so the sort's order among them does not matter), a
 * repeated edge's length set to -1, and, when the positions are held, the others measured. Only
 * the lengths are summed after, in bucket order: the upper ends need not be written back. */
static bool order_bucket(const edge_job *job, size_t i) {
    size_t first = job->start[i], n = job->start[i + 1] - first;
    double *length = job->length + first;
    uint64_t small[RS_EDGE_SCAN_LIMIT];
    uint64_t *upper = n <= RS_EDGE_SCAN_LIMIT ? small : rs_alloc_array(n, sizeof *upper);
    if (!upper)
        return false;
    for (size_t j = 0; j < n; j++)
        upper[j] = job->upper[first + j] | (job->high ? (uint64_t)job->high[first + j] << 32 : 0);
    bool ok = true;
    if (n > RS_EDGE_SCAN_LIMIT && job->held)
        qsort(upper, n, sizeof *upper, rs_edge_compare64);
    else if (n > RS_EDGE_SCAN_LIMIT)
        ok = sort_bucket(upper, length, n);
    for (size_t j = 0; ok && j < n; j++)
        if (rs_edge_repeats64(upper, n, j))
            length[j] = -1;
        else if (job->held)
            length[j] = held_length(job->held, job->lo + i, upper[j], job->scale);
    if (upper != small)
        rs_free(upper);
    return ok;
}

/* Buckets [begin, end), on every core. */
static void edge_marks(void *ctx, size_t begin, size_t end, size_t chunk) {
    (void)chunk;
    edge_job *job = ctx;
    for (size_t i = begin; i < end; i++)
        if (!order_bucket(job, i)) {
            job->no_memory = true; /* (a flag written only to true: no race that matters) */
            return;
        }
}

/* Edge e (0-2) of a record: from corner e to corner e + 1, its length measured lower end minus
 * upper end at `scale`, as mesh.c measures it from the positions. */
static void record_edge(const rs_stream_corners *corners, const rs_corner_view *view,
                        const uint64_t tri[3], int e, double scale, uint64_t *upper_end,
                        double *length) {
    int ca = e, cb = (e + 1) % 3;
    uint64_t a = tri[ca], b = tri[cb];
    int lower = a < b ? ca : cb, upper = a < b ? cb : ca;
    double p[3], q[3];
    rs_stream_view_corner(corners, view, lower, p);
    rs_stream_view_corner(corners, view, upper, q);
    *upper_end = a < b ? b : a;
    *length = edge_length_at(p, q, scale);
}

/* The next triangle's ids, and its record when `rec` is asked for: counting needs only the ids,
 * read from the ids file while it is kept (a quarter of the bytes or less). */
static bool next_ids(rs_corner_reader *r, const rs_stream_corners *corners, bool ids_only,
                     uint64_t tri[3], rs_corner_view *view) {
    if (ids_only)
        return rs_stream_next_triangle(&r->r, corners->id_bytes, tri);
    if (!rs_corner_next(r, view))
        return false;
    rs_stream_record_ids(corners, view->entry, tri);
    return true;
}

/* The edges of lower vertices [lo, hi) counted, then placed, by runs of triangles on every core:
 * run c counts its edges of vertex lo + i in at[c * span + i], which then becomes where its first
 * one goes in the vertex's bucket (after the earlier runs'), so each bucket holds its edges in
 * triangle order, as one pass would put them, for any number of threads. */
typedef struct edge_pass {
    const rs_stream_corners *corners;
    double scale;
    uint64_t lo, hi;
    size_t span, runs;
    uint32_t *at;        /* runs x span */
    const size_t *start; /* the buckets (the placing) */
    uint32_t *upper, *high;
    double *length;
    bool place;
    bool *unread; /* per run */
} edge_pass;

static void edge_run(edge_pass *pass, size_t c) {
    const rs_stream_corners *corners = pass->corners;
    uint64_t first = corners->count * c / pass->runs, last = corners->count * (c + 1) / pass->runs;
    uint32_t *at = pass->at + c * pass->span;
    rs_corner_reader r;
    bool ids_only = !pass->place || corners->held; /* held: measured after, on every core */
    if (ids_only
            ? !rs_stream_triangles_open_range(&r.r, corners->ids_fd, corners->id_bytes, first, last)
            : !rs_corner_reader_open(&r, corners, first, last)) {
        pass->unread[c] = true;
        return;
    }
    for (uint64_t t = first; t < last; t++) {
        rs_corner_view view;
        uint64_t tri[3];
        if (!next_ids(&r, corners, ids_only, tri, &view)) {
            pass->unread[c] = true;
            break;
        }
        for (int e = 0; e < 3; e++) {
            uint64_t a = tri[e], b = tri[(e + 1) % 3];
            uint64_t low = a < b ? a : b;
            if (a == b || low < pass->lo || low >= pass->hi)
                continue;
            size_t i = (size_t)(low - pass->lo);
            if (!pass->place) {
                at[i]++;
                continue;
            }
            size_t slot = pass->start[i] + at[i]++;
            uint64_t up = a < b ? b : a;
            if (!corners->held)
                record_edge(corners, &view, tri, e, pass->scale, &up, pass->length + slot);
            pass->upper[slot] = (uint32_t)up;
            if (pass->high)
                pass->high[slot] = (uint32_t)(up >> 32);
        }
    }
    rs_corner_reader_close(&r);
}

static void edge_runs(void *ctx, size_t begin, size_t end, size_t chunk) {
    (void)chunk;
    for (size_t c = begin; c < end; c++)
        edge_run(ctx, c);
}

/* The runs' counts into bucket starts and each run's first place in them; false when a bucket
 * holds 2^32 edges or more (no memory cap gets near). */
static bool edge_starts(edge_pass *pass, size_t *start) {
    start[0] = 0;
    for (size_t i = 0; i < pass->span; i++) {
        uint64_t sum = 0;
        for (size_t c = 0; c < pass->runs; c++) {
            uint32_t n = pass->at[c * pass->span + i];
            pass->at[c * pass->span + i] = (uint32_t)sum;
            sum += n;
        }
        if (sum > UINT32_MAX)
            return false;
        start[i + 1] = start[i] + (size_t)sum;
    }
    return true;
}

/* Sum, longest and count of the unique edges whose lower vertex lies in [lo, hi); `capacity` edges
 * fit in `upper` and `length`. *fits is false (nothing summed) when the range has more edges than
 * that. The edges are counted and placed by runs of triangles and the buckets ordered on every
 * core; the sum runs here in the in-memory path's order. */
static rsmooth_status edge_range(edge_pass *pass, size_t *start, size_t capacity, double *sum,
                                 double *longest, uint64_t *unique, bool *fits,
                                 rsmooth_error *error) {
    size_t span = pass->span;
    memset(pass->at, 0, pass->runs * span * sizeof *pass->at);
    memset(pass->unread, 0, pass->runs * sizeof *pass->unread);
    for (int place = 0; place < 2; place++) { /* count, then place */
        pass->place = place;
        pass->start = start;
        rs_parallel_for(pass->runs, 1, edge_runs, pass);
        for (size_t c = 0; c < pass->runs; c++)
            if (pass->unread[c])
                return read_fail(error);
        if (!place && !edge_starts(pass, start))
            return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, RS_STREAM_WHERE,
                           "a vertex has 2^32 edges or more");
        if (!place && start[span] > capacity) {
            *fits = false;
            return RSMOOTH_OK;
        }
    }
    edge_job job = {start,    pass->upper, pass->high, pass->length, pass->corners->held,
                    pass->lo, pass->scale, false};
    rs_parallel_for(span, 4096, edge_marks, &job);
    if (job.no_memory)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, RS_STREAM_WHERE,
                       "no memory to sort a vertex's edges");
    const double *length = pass->length;
    for (size_t e = 0; e < start[span]; e++) /* in order: the in-memory path's bits */
        if (!(length[e] < 0)) {
            *sum += length[e];
            *longest = fmax(*longest, length[e]);
            (*unique)++;
        }
    *fits = true;
    return RSMOOTH_OK;
}

/* Runs of triangles the edges are counted and placed in: a few (each costs 4 bytes per vertex of
 * a run of vertices), on every core. */
#define EDGE_RUNS_MAX 8

static rsmooth_status mean_edge_length(const rs_stream_corners *corners, uint64_t v_count,
                                       double scale, uint64_t memory, double *out, double *longest,
                                       rsmooth_error *error) {
    uint64_t triangles = corners->count;
    edge_pass pass = {.corners = corners, .scale = scale};
    pass.runs = rs_parallel_chunks((size_t)triangles, 65536);
    pass.runs = pass.runs > EDGE_RUNS_MAX ? EDGE_RUNS_MAX : pass.runs;
    /* a first guess at the run of vertices that fits: each holds about 3 T / V edges */
    bool wide = corners->id_bytes == 8;
    size_t edge_bytes = wide ? 16 : 12;      /* upper end (and its high half) and length */
    size_t vertex_bytes = 8 + 4 * pass.runs; /* its bucket's start, each run's place in it */
    double per_vertex =
        (double)vertex_bytes +
        (double)edge_bytes * (v_count ? 3.0 * (double)triangles / (double)v_count : 0) * 1.25;
    uint64_t span = (uint64_t)((double)memory / per_vertex);
    if (span < 1024)
        span = 1024;
    if (span > v_count)
        span = v_count;
    /* one set of arrays for every run (runs only shrink): freed and made again per run, the
     * allocator's heap crept up by about a run's arrays each time */
    size_t *start = rs_alloc_array((size_t)span + 1, sizeof *start);
    pass.at = rs_alloc_array((size_t)span ? (size_t)span : 1, pass.runs * sizeof *pass.at);
    pass.unread = rs_alloc_array(pass.runs, sizeof *pass.unread);
    uint64_t used = vertex_bytes * (span + 1);
    size_t capacity = memory > used ? (size_t)((memory - used) / edge_bytes) : 0;
    if (capacity > 3 * triangles)
        capacity = (size_t)(3 * triangles);
    pass.upper = rs_alloc_array(capacity ? capacity : 1, sizeof *pass.upper);
    pass.high = wide ? rs_alloc_array(capacity ? capacity : 1, sizeof *pass.high) : NULL;
    pass.length = rs_alloc_array(capacity ? capacity : 1, sizeof *pass.length);
    rsmooth_status st = RSMOOTH_OK;
    if (!start || !pass.at || !pass.unread || !pass.upper || !pass.length || (wide && !pass.high))
        st = rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, RS_STREAM_WHERE,
                     "no memory for the edges of %llu vertices", (unsigned long long)span);
    double sum = 0;
    uint64_t unique = 0;
    for (uint64_t lo = 0; st == RSMOOTH_OK && lo < v_count;) {
        uint64_t hi = lo + span < v_count ? lo + span : v_count;
        bool fits = false;
        pass.lo = lo;
        pass.hi = hi;
        pass.span = (size_t)(hi - lo);
        st = edge_range(&pass, start, capacity, &sum, longest, &unique, &fits, error);
        if (st == RSMOOTH_OK && !fits && hi - lo <= 1)
            st = rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, RS_STREAM_WHERE,
                         "vertex %llu has more edges than the memory cap holds",
                         (unsigned long long)lo);
        else if (!fits)
            span = (hi - lo) / 2; /* denser than guessed: retry this run halved */
        else
            lo = hi;
    }
    rs_free(start);
    rs_free(pass.at);
    rs_free(pass.unread);
    rs_free(pass.upper);
    rs_free(pass.high);
    rs_free(pass.length);
    if (st != RSMOOTH_OK)
        return st;
    *out = unique ? sum / (double)unique : 0;
    return RSMOOTH_OK;
}

/* What one chunk of blocks (facet_figures, on every core) finds besides its blocks' sums. */
typedef struct facet_chunk {
    uint64_t facets;
    double reach, longest;
    size_t *histogram; /* RS_PART_BIN_COUNT: the parts test's scales (core/parts.h) */
    bool unread;       /* a read error */
    bool no_memory;
} facet_chunk;

typedef struct facet_job {
    const rs_stream_corners *corners;
    double scale;
    double *block_sum; /* per block of GEOMETRY_BLOCK triangles: its facets' areas, in order */
    facet_chunk *chunk;
    const rs_facet_visitor *visitor; /* or NULL */
} facet_job;

size_t rs_stream_facet_chunks(uint64_t triangles) {
    return rs_parallel_chunks((size_t)((triangles + GEOMETRY_BLOCK - 1) / GEOMETRY_BLOCK), 4);
}

uint64_t rs_stream_facet_chunk_first(uint64_t triangles, size_t chunks, size_t c) {
    uint64_t blocks = (triangles + GEOMETRY_BLOCK - 1) / GEOMETRY_BLOCK;
    uint64_t first = blocks * c / chunks * GEOMETRY_BLOCK; /* rs_parallel_for's split of blocks */
    return first < triangles ? first : triangles;
}

/* Blocks [begin, end): each block's area summed in triangle order, as mesh.c sums it. */
static void facet_blocks(void *ctx, size_t begin, size_t end, size_t chunk_index) {
    facet_job *job = ctx;
    facet_chunk *chunk = job->chunk + chunk_index;
    const rs_stream_corners *corners = job->corners;
    uint64_t first = (uint64_t)begin * GEOMETRY_BLOCK, last = (uint64_t)end * GEOMETRY_BLOCK;
    if (last > corners->count)
        last = corners->count;
    rs_corner_reader r;
    chunk->histogram = rs_calloc_array(RS_PART_BIN_COUNT, sizeof *chunk->histogram);
    if (!chunk->histogram || !rs_corner_reader_open(&r, corners, first, last)) {
        chunk->no_memory = true;
        return;
    }
    static const uint32_t local[3] = {0, 1, 2};
    rsmooth_scalar scalar = corners->f32 ? RSMOOTH_FLOAT32 : RSMOOTH_FLOAT64;
    for (size_t b = begin; b < end && !chunk->unread; b++) {
        double block_sum = 0;
        uint64_t block_end = (uint64_t)(b + 1) * GEOMETRY_BLOCK;
        for (uint64_t t = (uint64_t)b * GEOMETRY_BLOCK; t < block_end && t < last; t++) {
            rs_corner_view view;
            if (!rs_corner_next(&r, &view)) {
                chunk->unread = true;
                break;
            }
            double hi = 0, xyz[9]; /* the parts test, in the caller's units as in memory */
            int16_t bin = rs_scale_bin(
                rs_triangle_scale(scalar, rs_stream_view_xyz(corners, &view, xyz), local, &hi));
            if (bin != RS_NO_BIN) {
                chunk->histogram[bin - RS_PART_BIN_MIN]++;
                chunk->longest = fmax(chunk->longest, hi);
            }
            double p[9], centroid[3], area = 0;
            bool facet = rs_stream_facet(corners, &view, job->scale, p, centroid, &area);
            if (!facet && job->visitor)
                job->visitor->triangle(job->visitor->ctx, chunk_index, NULL);
            if (facet) {
                chunk->facets++;
                block_sum += area;
                double far = 0; /* sqrt is monotone: the root of the largest square is the same */
                for (int c = 0; c < 3; c++) {
                    double d[3];
                    rs_sub3(p + 3 * c, centroid, d);
                    far = fmax(far, rs_dot3(d, d));
                }
                chunk->reach = fmax(chunk->reach, sqrt(far));
                if (job->visitor) {
                    for (int k = 0; k < 3; k++)
                        centroid[k] /= job->scale; /* exact: a power of two */
                    job->visitor->triangle(job->visitor->ctx, chunk_index, centroid);
                }
            }
        }
        job->block_sum[b] = block_sum;
    }
    rs_corner_reader_close(&r);
}

/* Facet count, mean area and reach, in blocks as mesh.c sums them: the blocks on every core,
 * then their sums in block order, so the bits do not depend on the number of threads. */
rsmooth_status rs_stream_facet_figures(const rs_stream_corners *corners,
                                       const rs_facet_visitor *visitor, rs_stream_stats *stats,
                                       rsmooth_error *error) {
    double scale = stats->scale;
    size_t blocks = (size_t)((corners->count + GEOMETRY_BLOCK - 1) / GEOMETRY_BLOCK);
    size_t chunks = rs_parallel_chunks(blocks, 4);
    facet_job job = {corners, scale, rs_alloc_array(blocks ? blocks : 1, sizeof(double)),
                     rs_calloc_array(chunks ? chunks : 1, sizeof(facet_chunk)), visitor};
    size_t *histogram = rs_calloc_array(RS_PART_BIN_COUNT, sizeof *histogram);
    bool ok = job.block_sum && job.chunk && histogram;
    if (ok)
        rs_parallel_for(blocks, 4, facet_blocks, &job);
    double area_sum = 0, reach = 0, longest = 0;
    uint64_t facets = 0;
    bool failed = false;
    for (size_t c = 0; ok && c < chunks; c++) {
        facet_chunk *chunk = job.chunk + c;
        failed |= chunk->unread;
        ok &= !chunk->no_memory;
        facets += chunk->facets;
        reach = fmax(reach, chunk->reach);
        longest = fmax(longest, chunk->longest);
        for (size_t b = 0; chunk->histogram && b < RS_PART_BIN_COUNT; b++)
            histogram[b] += chunk->histogram[b];
    }
    for (size_t b = 0; ok && !failed && b < blocks; b++)
        area_sum += job.block_sum[b];
    if (ok && !failed)
        stats->whole = rs_scales_whole(histogram, longest);
    for (size_t c = 0; job.chunk && c < chunks; c++)
        rs_free(job.chunk[c].histogram);
    rs_free(job.chunk);
    rs_free(job.block_sum);
    rs_free(histogram);
    if (!ok)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, RS_STREAM_WHERE,
                       "no memory for the facets' figures");
    if (failed)
        return read_fail(error);
    stats->facet_count = facets;
    stats->scaled_mean_area = facets ? area_sum / (double)facets : 0;
    stats->mean_area = stats->scaled_mean_area / scale / scale;
    stats->reach = reach / scale;
    return RSMOOTH_OK;
}

/* The in-memory path's scale (scale.c): from the same sampled triangles (one in every
 * T / 4096, as rs_mesh_scale strides), their corners read from the records. */
static rsmooth_status whole_scale(const rs_stream_corners *corners, double magnitude, double *scale,
                                  rsmooth_error *error) {
    enum { SAMPLES = 4096 }; /* scale.c's SCALE_SAMPLES */
    uint64_t triangles = corners->count;
    uint64_t stride = triangles > SAMPLES ? triangles / SAMPLES : 1;
    size_t count = (size_t)((triangles + stride - 1) / stride);
    size_t vertex_bytes = 3 * (corners->f32 ? sizeof(float) : sizeof(double));
    uint32_t *local = rs_alloc_array(count ? count : 1, 3 * sizeof *local);
    unsigned char *xyz = rs_alloc_array(count ? count : 1, 3 * vertex_bytes);
    unsigned char *rec = rs_alloc_array(1, corners->record);
    rsmooth_status st = RSMOOTH_OK;
    if (!local || !xyz || !rec)
        st = rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, RS_STREAM_WHERE, "scale samples");
    for (size_t i = 0; st == RSMOOTH_OK && i < count; i++) {
        if (!rs_stream_corner_at(corners, (uint64_t)i * stride, rec))
            st = read_fail(error);
        /* the sample's corners as vertices 3i, 3i + 1, 3i + 2 */
        memcpy(xyz + 3 * i * vertex_bytes, rs_stream_record_values(corners, rec), 3 * vertex_bytes);
        for (int c = 0; c < 3; c++)
            local[3 * i + (size_t)c] = (uint32_t)(3 * i + (size_t)c);
    }
    if (st == RSMOOTH_OK)
        st = rs_mesh_scale(corners->f32 ? RSMOOTH_FLOAT32 : RSMOOTH_FLOAT64, xyz, local, count,
                           magnitude, scale, error, RS_STREAM_WHERE);
    rs_free(local);
    rs_free(xyz);
    rs_free(rec);
    return st;
}

rsmooth_status rs_stream_statistics(const rs_stream_corners *corners, uint64_t vertex_count,
                                    const rs_stream_extent *extent, uint64_t memory,
                                    rs_stream_stats *stats, rsmooth_error *error) {
    memset(stats, 0, sizeof *stats);
    memcpy(stats->lo, extent->lo, sizeof stats->lo);
    memcpy(stats->hi, extent->hi, sizeof stats->hi);
    rsmooth_status st = whole_scale(corners, extent->magnitude, &stats->scale, error);
    if (st != RSMOOTH_OK)
        return st;
    double longest = 0;
    st = mean_edge_length(corners, vertex_count, stats->scale, memory,
                          &stats->scaled_mean_edge_length, &longest, error);
    if (st != RSMOOTH_OK)
        return st;
    stats->mean_edge_length = stats->scaled_mean_edge_length / stats->scale;
    stats->longest_edge = longest / stats->scale;
    stats->reach_bound = REACH_PER_EDGE * stats->longest_edge;
    stats->magnitude = extent->magnitude;
    return RSMOOTH_OK;
}
