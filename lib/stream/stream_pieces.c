/* Spatial pieces of a mesh on disk. A grid of cells no smaller than the halo counts the vertices;
 * boxes of cells are halved (at the median count, along their longest side) until each holds at
 * most the vertices a piece may have. A piece's core vertices are those in its box; its facets
 * are every triangle of non-zero area whose centroid lies within the halo of the box, so it holds
 * every facet its vertices' results depend on (piece.c). The facets are counted in the
 * statistics' facets' pass (each triangle's piece noted when it lies in one alone) and written in
 * a second pass. Pieces go to ranks by their facet counts (the longest first, each to the least
 * loaded rank), the same on every rank. */
#include "stream/stream_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define MAX_CELLS (1u << 21)
#define MAX_NEAR 512 /* pieces a facet can be near */
#define CODE_BUFFER (64u << 10)

typedef struct cell_grid {
    double lo[3], size[3];
    int32_t dims[3];
    uint32_t *count; /* vertices per cell */
    int32_t *piece;  /* per cell: its piece, -1 for none */
} cell_grid;

typedef struct box {
    int32_t a[3], b[3]; /* cells [a, b) */
} box;

static size_t cell_index(const cell_grid *g, const int32_t c[3]) {
    return ((size_t)c[2] * (size_t)g->dims[1] + (size_t)c[1]) * (size_t)g->dims[0] + (size_t)c[0];
}

static int32_t cell_coordinate(const cell_grid *g, double x, int k) {
    double c = floor((x - g->lo[k]) / g->size[k]);
    return c < 0 ? 0 : c >= g->dims[k] ? g->dims[k] - 1 : (int32_t)c;
}

static void cell_of(const cell_grid *g, const double p[3], int32_t c[3]) {
    for (int k = 0; k < 3; k++)
        c[k] = cell_coordinate(g, p[k], k);
}

/* The cell index of vertex v (of the loaded run). */
static size_t vertex_cell(const cell_grid *g, const rs_stream_vertices *vertices, uint64_t v) {
    double p[3];
    int32_t c[3];
    rs_stream_vertex(vertices, v, p);
    cell_of(g, p, c);
    return cell_index(g, c);
}

static bool grid_init(cell_grid *g, const rs_stream_stats *stats, double halo, size_t max_cells) {
    memset(g, 0, sizeof *g);
    double dims[3];
    for (int k = 0; k < 3; k++) {
        double extent = stats->hi[k] - stats->lo[k];
        dims[k] = halo > 0 && extent > 0 ? floor(extent / halo) : 1;
        dims[k] = dims[k] < 1 ? 1 : dims[k] > 4096 ? 4096 : dims[k];
    }
    while (dims[0] * dims[1] * dims[2] > (double)max_cells) { /* coarser where longest */
        int k = dims[0] >= dims[1] && dims[0] >= dims[2] ? 0 : dims[1] >= dims[2] ? 1 : 2;
        dims[k] = floor(dims[k] / 2);
    }
    for (int k = 0; k < 3; k++) {
        double extent = stats->hi[k] - stats->lo[k];
        g->dims[k] = (int32_t)dims[k];
        g->lo[k] = stats->lo[k];
        g->size[k] = extent > 0 ? extent / dims[k] : 1;
    }
    size_t cells = (size_t)g->dims[0] * (size_t)g->dims[1] * (size_t)g->dims[2];
    g->count = rs_calloc_array(cells, sizeof *g->count);
    g->piece = rs_alloc_array(cells, sizeof *g->piece);
    if (!g->count || !g->piece)
        return false;
    for (size_t i = 0; i < cells; i++)
        g->piece[i] = -1;
    return true;
}

static uint64_t box_count(const cell_grid *g, const box *bx) {
    uint64_t n = 0;
    int32_t c[3];
    for (c[2] = bx->a[2]; c[2] < bx->b[2]; c[2]++)
        for (c[1] = bx->a[1]; c[1] < bx->b[1]; c[1]++)
            for (c[0] = bx->a[0]; c[0] < bx->b[0]; c[0]++)
                n += g->count[cell_index(g, c)];
    return n;
}

/* Pieces smaller than this are not cut to keep a wide halo's pieces within their memory. */
#define MIN_CUT_VERTICES 1024

typedef struct cutter {
    cell_grid *grid;
    uint64_t target;
    rs_piece *pieces;
    box *boxes;
    size_t count, capacity;
} cutter;

/* Halves `bx` until each part holds at most `target` vertices (or is one cell). */
static bool cut(cutter *ct, box bx, uint64_t n) {
    cell_grid *g = ct->grid;
    if (n == 0)
        return true;
    int axis = -1;
    double longest = 0;
    for (int k = 0; k < 3; k++) {
        double side = (double)(bx.b[k] - bx.a[k]) * g->size[k];
        if (bx.b[k] - bx.a[k] >= 2 && side > longest) {
            longest = side;
            axis = k;
        }
    }
    if (n <= ct->target || axis < 0) { /* a piece */
        if (ct->count == ct->capacity) {
            size_t cap = ct->capacity ? 2 * ct->capacity : 64;
            rs_piece *p = rs_realloc_array(ct->pieces, cap, sizeof *p);
            if (!p)
                return false;
            ct->pieces = p;
            box *b = rs_realloc_array(ct->boxes, cap, sizeof *b);
            if (!b)
                return false;
            ct->boxes = b;
            ct->capacity = cap;
        }
        int32_t id = (int32_t)ct->count;
        memset(&ct->pieces[ct->count], 0, sizeof *ct->pieces);
        ct->pieces[ct->count].vertex_count = n;
        ct->boxes[ct->count++] = bx;
        int32_t c[3];
        for (c[2] = bx.a[2]; c[2] < bx.b[2]; c[2]++)
            for (c[1] = bx.a[1]; c[1] < bx.b[1]; c[1]++)
                for (c[0] = bx.a[0]; c[0] < bx.b[0]; c[0]++)
                    g->piece[cell_index(g, c)] = id;
        return true;
    }
    /* the slice where the count passes half */
    uint64_t below = 0;
    int32_t split = bx.a[axis] + 1;
    for (int32_t s = bx.a[axis]; s < bx.b[axis] - 1; s++) {
        box slice = bx;
        slice.a[axis] = s;
        slice.b[axis] = s + 1;
        below += box_count(g, &slice);
        split = s + 1;
        if (2 * below >= n)
            break;
    }
    box left = bx, right = bx;
    left.b[axis] = split;
    right.a[axis] = split;
    uint64_t n_left = box_count(g, &left);
    return cut(ct, left, n_left) && cut(ct, right, n - n_left);
}

/* The pieces whose boxes lie within `halo` of point c (at most `max` of them), in `out`. */
static size_t pieces_near(const cell_grid *g, const box *boxes, const double c[3], double halo,
                          int32_t *out, size_t max) {
    int32_t a[3], b[3], own[3];
    for (int k = 0; k < 3; k++) {
        a[k] = cell_coordinate(g, c[k] - halo, k);
        b[k] = cell_coordinate(g, c[k] + halo, k);
    }
    /* most facets: every cell within the halo in the box of the centroid's own piece, which is
     * then the only one (boxes do not overlap, and c lies in its own) */
    cell_of(g, c, own);
    int32_t first = g->piece[cell_index(g, own)];
    bool alone = first >= 0 && max > 0;
    for (int k = 0; k < 3 && alone; k++)
        alone = a[k] >= boxes[first].a[k] && b[k] < boxes[first].b[k];
    if (alone) {
        out[0] = first;
        return 1;
    }
    size_t n = 0;
    int32_t q[3];
    for (q[2] = a[2]; q[2] <= b[2]; q[2]++)
        for (q[1] = a[1]; q[1] <= b[1]; q[1]++)
            for (q[0] = a[0]; q[0] <= b[0]; q[0]++) {
                int32_t id = g->piece[cell_index(g, q)];
                if (id < 0)
                    continue;
                bool seen = false;
                for (size_t i = 0; i < n && !seen; i++)
                    seen = out[i] == id;
                if (seen)
                    continue;
                const box *bx = &boxes[id];
                bool inside = true; /* the box's own bounds, grown by the halo */
                for (int k = 0; k < 3 && inside; k++) {
                    double lo = bx->a[k] == 0 ? -INFINITY : g->lo[k] + bx->a[k] * g->size[k];
                    double hi =
                        bx->b[k] == g->dims[k] ? INFINITY : g->lo[k] + bx->b[k] * g->size[k];
                    inside = c[k] >= lo - halo && c[k] <= hi + halo;
                }
                if (inside && n < max)
                    out[n++] = id;
            }
    return n;
}

static rsmooth_status no_memory(rsmooth_error *error) {
    return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, RS_STREAM_WHERE, "no memory for pieces");
}

/* The triangles of the facets' pass, cut into `chunks` runs that run on every core
 * (rs_stream_facet_chunks); the writing pass cuts them the same way, so that it knows from the
 * counts where each run's records of each piece go: after the earlier runs' records, as one pass
 * in order would put them. */
typedef struct facet_pass_job {
    const rs_stream_corners *corners;
    size_t chunks;
    const cell_grid *g;
    const box *boxes;
    const rs_piece *pieces;
    size_t piece_count;
    double scale, halo;
    int rank;
    size_t facet_record;       /* bytes of a record the lists keep: all, or the ids alone */
    bool triangle_ids;         /* and after it the triangle's index (8 bytes) */
    uint64_t *counts;          /* chunks x pieces: each run's facets of each piece */
    rs_region_writer *writers; /* per run: the lists (the writing pass) or the codes (counting) */
    /* Per triangle, the piece it lies in alone (most do), or PIECE_NONE or PIECE_SEVERAL: the
     * counting writes them so the writing pass need not look up a corner but for the few near
     * several pieces. code_bytes: 2 while the piece ids fit, else 4. */
    int code_fd;
    size_t code_bytes;
    bool *unread, *unwritten; /* per run */
} facet_pass_job;

#define PIECE_NONE UINT32_MAX          /* no area, or no piece near */
#define PIECE_SEVERAL (UINT32_MAX - 1) /* near more than one: looked for again */

static void put_code(unsigned char *at, uint32_t code, size_t bytes) {
    if (bytes == 2) {
        uint16_t narrow = code >= PIECE_SEVERAL ? (uint16_t)(code - 0xffff0000u) : (uint16_t)code;
        memcpy(at, &narrow, sizeof narrow);
    } else
        memcpy(at, &code, sizeof code);
}

static uint32_t get_code(const unsigned char *at, size_t bytes) {
    if (bytes == 2) {
        uint16_t narrow;
        memcpy(&narrow, at, sizeof narrow);
        return narrow >= (uint16_t)PIECE_SEVERAL ? 0xffff0000u + narrow : narrow;
    }
    uint32_t code;
    memcpy(&code, at, sizeof code);
    return code;
}

/* The counting: a triangle of the facets' pass (rs_facet_visitor), counted in each piece near
 * it, its code written. */
static void count_facet(void *ctx, size_t c, const double centroid[3]) {
    facet_pass_job *job = ctx;
    int32_t near[MAX_NEAR];
    uint64_t *counts = job->counts + c * job->piece_count;
    size_t n = centroid ? pieces_near(job->g, job->boxes, centroid, job->halo, near, MAX_NEAR) : 0;
    for (size_t i = 0; i < n; i++)
        counts[near[i]]++;
    unsigned char code[4];
    put_code(code,
             n == 0   ? PIECE_NONE
             : n == 1 ? (uint32_t)near[0]
                      : PIECE_SEVERAL,
             job->code_bytes);
    if (!rs_region_append(job->writers + c, 0, code))
        job->unwritten[c] = true;
}

/* The writing: run c of the triangles again, each facet's entry appended to this rank's pieces
 * it lies near (found again only for a facet near several). */
static void facet_run(facet_pass_job *job, size_t c) {
    const rs_stream_corners *corners = job->corners;
    uint64_t first = rs_stream_facet_chunk_first(corners->count, job->chunks, c);
    uint64_t last = rs_stream_facet_chunk_first(corners->count, job->chunks, c + 1);
    size_t bytes = job->code_bytes;
    rs_corner_reader r;
    rs_stream_reader codes;
    if (!rs_stream_reader_open(&codes, job->code_fd, "codes", first * bytes, last * bytes,
                               CODE_BUFFER / bytes * bytes)) {
        job->unread[c] = true;
        return;
    }
    if (!rs_corner_reader_open(&r, corners, first, last)) {
        rs_stream_reader_close(&codes);
        job->unread[c] = true;
        return;
    }
    int32_t near[MAX_NEAR];
    for (uint64_t t = first; t < last && !job->unwritten[c]; t++) {
        rs_corner_view view;
        const unsigned char *code_at = rs_stream_read(&codes, bytes);
        if (!code_at || !rs_corner_next(&r, &view)) {
            job->unread[c] = true;
            break;
        }
        uint32_t code = get_code(code_at, bytes);
        size_t n = 0;
        if (code == PIECE_SEVERAL) {
            double p[9], centroid[3], area;
            rs_stream_facet(corners, &view, job->scale, p, centroid, &area); /* (not 0: counted) */
            for (int k = 0; k < 3; k++)
                centroid[k] /= job->scale; /* exact: a power of two */
            n = pieces_near(job->g, job->boxes, centroid, job->halo, near, MAX_NEAR);
        } else if (code != PIECE_NONE) {
            near[0] = (int32_t)code;
            n = 1;
        }
        const unsigned char *entry = view.entry;
        unsigned char with_index[RS_STREAM_RECORD_MAX + sizeof t];
        if (job->triangle_ids && n > 0) {
            size_t kept = job->facet_record - sizeof t;
            memcpy(with_index, view.entry, kept);
            memcpy(with_index + kept, &t, sizeof t);
            entry = with_index;
        }
        for (size_t i = 0; i < n; i++)
            if (job->pieces[near[i]].rank == job->rank &&
                !rs_region_append(job->writers + c, (size_t)near[i], entry))
                job->unwritten[c] = true;
    }
    rs_corner_reader_close(&r);
    rs_stream_reader_close(&codes);
}

static void facet_runs(void *ctx, size_t begin, size_t end, size_t chunk) {
    (void)chunk;
    for (size_t c = begin; c < end; c++)
        facet_run(ctx, c);
}

/* The writing pass over the triangles: this rank's pieces' facet records. */
static rsmooth_status facet_pass(facet_pass_job *job, rs_region_writer *writers, const char *dir,
                                 rsmooth_error *error) {
    job->writers = writers;
    memset(job->unread, 0, job->chunks * sizeof *job->unread);
    memset(job->unwritten, 0, job->chunks * sizeof *job->unwritten);
    rs_parallel_for(job->chunks, 1, facet_runs, job);
    for (size_t c = 0; c < job->chunks; c++) {
        if (job->unread[c])
            return rs_fail(error, RSMOOTH_ERROR_IO, RS_STREAM_WHERE,
                           "cannot read the temporary corner file");
        if (job->unwritten[c])
            return rs_stream_unwritten(dir, 0, error);
    }
    return RSMOOTH_OK;
}

/* Longest processing time first: each piece, by facets, to the rank with the least so far. */
static bool share(rs_piece *pieces, size_t count, int ranks) {
    size_t *order = rs_alloc_array(count ? count : 1, sizeof *order);
    uint64_t *load = rs_calloc_array((size_t)ranks, sizeof *load);
    if (!order || !load) {
        rs_free(order);
        rs_free(load);
        return false;
    }
    for (size_t i = 0; i < count; i++)
        order[i] = i;
    for (size_t i = 1; i < count; i++) { /* insertion sort: pieces are few */
        size_t x = order[i], j = i;
        uint64_t cx = pieces[x].facet_count + pieces[x].vertex_count;
        while (j > 0 && pieces[order[j - 1]].facet_count + pieces[order[j - 1]].vertex_count < cx)
            order[j] = order[j - 1], j--;
        order[j] = x;
    }
    for (size_t i = 0; i < count; i++) {
        int best = 0;
        for (int r = 1; r < ranks; r++)
            if (load[r] < load[best])
                best = r;
        rs_piece *p = &pieces[order[i]];
        p->rank = best;
        load[best] += p->facet_count + p->vertex_count;
    }
    rs_free(order);
    rs_free(load);
    return true;
}

static void facet_job_free(facet_pass_job *job) {
    if (job->code_fd >= 0)
        close(job->code_fd);
    rs_free(job->counts);
    rs_free(job->unread);
    rs_free(job->unwritten);
}

/* Each piece's facet count, in the facets' pass that fills the rest of `stats`, with the runs'
 * counts kept in job and each triangle's code written to job->code_fd. */
static rsmooth_status count_facets(facet_pass_job *job, rs_piece *pieces, size_t count,
                                   rs_stream_stats *stats, const char *dir, rsmooth_error *error) {
    uint64_t triangles = job->corners->count;
    job->chunks = rs_stream_facet_chunks(triangles);
    job->counts = rs_calloc_array(job->chunks * (count ? count : 1), sizeof(uint64_t));
    job->unread = rs_calloc_array(job->chunks, sizeof(bool));
    job->unwritten = rs_calloc_array(job->chunks, sizeof(bool));
    job->writers = rs_calloc_array(job->chunks, sizeof *job->writers);
    if (!job->counts || !job->unread || !job->unwritten || !job->writers)
        return no_memory(error);
    job->code_bytes = count < 0xfffe ? 2 : 4;
    job->code_fd = rs_stream_temporary(dir);
    if (job->code_fd < 0)
        return rs_fail(error, RSMOOTH_ERROR_IO, RS_STREAM_WHERE,
                       "cannot create a temporary file in %s", dir);
    rsmooth_status st = RSMOOTH_OK;
    for (size_t c = 0; st == RSMOOTH_OK && c < job->chunks; c++) {
        uint64_t first = rs_stream_facet_chunk_first(triangles, job->chunks, c);
        if (!rs_region_writer_init(job->writers + c, job->code_fd, 1, job->code_bytes, &first,
                                   CODE_BUFFER))
            st = no_memory(error);
    }
    rs_facet_visitor counting = {count_facet, job};
    if (st == RSMOOTH_OK)
        st = rs_stream_facet_figures(job->corners, &counting, stats, error);
    bool written = true;
    for (size_t c = 0; c < job->chunks; c++) {
        written = !job->unwritten[c] && written;
        if (st == RSMOOTH_OK)
            written = rs_region_writer_finish(job->writers + c) && written;
        rs_region_writer_free(job->writers + c);
    }
    rs_free(job->writers);
    job->writers = NULL;
    if (st == RSMOOTH_OK && !written)
        st = rs_stream_unwritten(dir, 0, error);
    for (size_t c = 0; st == RSMOOTH_OK && c < job->chunks; c++)
        for (size_t i = 0; i < count; i++)
            pieces[i].facet_count += job->counts[c * count + i];
    return st;
}

/* The grid's vertex counts, a run of vertices at a time. */
static rsmooth_status count_vertices(rs_stream_vertices *vertices, cell_grid *g,
                                     rsmooth_error *error) {
    for (uint64_t first = 0; first < vertices->count; first += vertices->run) {
        rsmooth_status st = rs_stream_vertices_load(vertices, first, error);
        if (st != RSMOOTH_OK)
            return st;
        for (uint64_t v = first; v < first + vertices->loaded; v++)
            g->count[vertex_cell(g, vertices, v)]++;
    }
    return RSMOOTH_OK;
}

/* This rank's pieces' vertex lists, in vertex order: each vertex's id, then its position. */
static rsmooth_status write_vertex_lists(rs_stream_vertices *vertices, const cell_grid *g,
                                         const rs_piece *pieces, size_t count, int rank,
                                         rs_stream_pieces *out, size_t buffer_memory,
                                         const char *dir, rsmooth_error *error) {
    uint64_t *starts = rs_alloc_array(count ? count : 1, sizeof *starts);
    if (!starts)
        return no_memory(error);
    for (size_t i = 0; i < count; i++)
        starts[i] = pieces[i].vertex_start;
    rs_region_writer w;
    size_t id_bytes = out->id_bytes, vertex_bytes = out->vertex_record - id_bytes;
    bool ok =
        rs_region_writer_init(&w, out->vertex_fd, count, out->vertex_record, starts, buffer_memory);
    rs_free(starts);
    if (!ok)
        return no_memory(error);
    unsigned char record[sizeof(uint64_t) + 3 * sizeof(double)];
    rsmooth_status st = RSMOOTH_OK;
    for (uint64_t first = 0; ok && first < vertices->count; first += vertices->run) {
        st = rs_stream_vertices_load(vertices, first, error);
        if (st != RSMOOTH_OK)
            break;
        const unsigned char *xyz = vertices->xyz;
        for (uint64_t v = first; ok && v < first + vertices->loaded; v++) {
            int32_t id = g->piece[vertex_cell(g, vertices, v)];
            if (pieces[id].rank != rank)
                continue;
            rs_stream_put_id(record, v, id_bytes);
            memcpy(record + id_bytes, xyz + (v - first) * vertex_bytes, vertex_bytes);
            ok = rs_region_append(&w, (size_t)id, record);
        }
    }
    ok = rs_region_writer_finish(&w) && ok; /* (finish frees the writer) */
    if (st != RSMOOTH_OK)
        return st;
    return ok ? RSMOOTH_OK : rs_stream_unwritten(dir, 0, error);
}

/* This rank's pieces' facet lists: each run of triangles through its own writer, its records
 * after the earlier runs' (count_facets' counts), so the lists are in triangle order. */
static rsmooth_status write_facet_lists(facet_pass_job *job, int fd, size_t buffer_memory,
                                        const char *dir, rsmooth_error *error) {
    size_t count = job->piece_count;
    uint64_t *starts = rs_alloc_array(count ? count : 1, sizeof *starts);
    rs_region_writer *writers = rs_calloc_array(job->chunks, sizeof *writers);
    rsmooth_status st = starts && writers ? RSMOOTH_OK : no_memory(error);
    for (size_t i = 0; st == RSMOOTH_OK && i < count; i++)
        starts[i] = job->pieces[i].facet_start;
    for (size_t c = 0; st == RSMOOTH_OK && c < job->chunks; c++) {
        if (!rs_region_writer_init(writers + c, fd, count, job->facet_record, starts,
                                   buffer_memory / job->chunks))
            st = no_memory(error);
        for (size_t i = 0; st == RSMOOTH_OK && i < count; i++)
            starts[i] += job->counts[c * count + i];
    }
    if (st == RSMOOTH_OK)
        st = facet_pass(job, writers, dir, error);
    for (size_t c = 0; st == RSMOOTH_OK && c < job->chunks; c++)
        if (!rs_region_writer_finish(writers + c))
            st = rs_stream_unwritten(dir, 0, error);
    for (size_t c = 0; writers && c < job->chunks; c++)
        rs_region_writer_free(writers + c);
    rs_free(writers);
    rs_free(starts);
    return st;
}

rsmooth_status rs_stream_pieces_build(rs_stream_vertices *vertices,
                                      const rs_stream_corners *corners, rs_stream_stats *stats,
                                      double halo, uint64_t piece_vertices, uint64_t facets_max,
                                      size_t buffer_memory, int rank, int ranks, bool triangle_ids,
                                      const char *dir, rs_stream_pieces *out,
                                      rsmooth_error *error) {
    memset(out, 0, sizeof *out);
    out->vertex_fd = out->facet_fd = -1;
    cell_grid g;
    cutter ct = {&g, piece_vertices ? piece_vertices : 1, NULL, NULL, 0, 0};
    facet_pass_job job;
    memset(&job, 0, sizeof job);
    job.code_fd = -1;
    rsmooth_status st = RSMOOTH_OK;
    size_t max_cells = buffer_memory / 8 < MAX_CELLS ? buffer_memory / 8 : MAX_CELLS;
    if (!grid_init(&g, stats, halo, max_cells < 1 ? 1 : max_cells)) {
        st = no_memory(error);
        goto done;
    }
    st = count_vertices(vertices, &g, error);
    if (st != RSMOOTH_OK)
        goto done;
    box all = {{0, 0, 0}, {g.dims[0], g.dims[1], g.dims[2]}};
    /* cut, and the facets each piece's halo brings counted: a piece over facets_max (its halo
     * far wider than the core expected) has the pieces cut smaller, a few times at most */
    for (int attempt = 0;; attempt++) {
        if (!cut(&ct, all, vertices->count)) {
            st = no_memory(error);
            goto done;
        }
        job = (facet_pass_job){.corners = corners,
                               .g = &g,
                               .boxes = ct.boxes,
                               .pieces = ct.pieces,
                               .piece_count = ct.count,
                               .scale = stats->scale,
                               /* a little beyond the halo: a facet exactly at it must not round
                                * out (as tiles.c) */
                               .halo = halo * (1 + 1e-6),
                               .rank = rank,
                               .code_fd = -1};
        st = count_facets(&job, ct.pieces, ct.count, stats, dir, error);
        uint64_t largest = 0;
        for (size_t i = 0; i < ct.count; i++)
            largest = ct.pieces[i].facet_count > largest ? ct.pieces[i].facet_count : largest;
        if (st != RSMOOTH_OK || !facets_max || largest <= facets_max || attempt == 3 ||
            ct.target <= MIN_CUT_VERTICES)
            break;
        double shrink = 0.9 * (double)facets_max / (double)largest;
        ct.target = (uint64_t)((double)ct.target * shrink);
        if (ct.target < MIN_CUT_VERTICES)
            ct.target = MIN_CUT_VERTICES;
        facet_job_free(&job);
        rs_free(ct.boxes);
        rs_free(ct.pieces);
        ct.boxes = NULL;
        ct.pieces = NULL;
        ct.count = ct.capacity = 0;
    }
    /* (the caller says why a mesh not whole stops) */
    if (st != RSMOOTH_OK || (!stats->whole && !stats->parts_tested))
        goto done;
    if (!share(ct.pieces, ct.count, ranks < 1 ? 1 : ranks)) {
        st = no_memory(error);
        goto done;
    }
    out->vertex_fd = rs_stream_temporary(dir);
    out->facet_fd = rs_stream_temporary(dir);
    if (out->vertex_fd < 0 || out->facet_fd < 0) {
        st = rs_fail(error, RSMOOTH_ERROR_IO, RS_STREAM_WHERE,
                     "cannot create a temporary file in %s", dir);
        goto done;
    }
    uint64_t listed = 0, facets = 0; /* this rank's pieces' lists, one after another */
    for (size_t i = 0; i < ct.count; i++) {
        rs_piece *p = &ct.pieces[i];
        p->vertex_start = listed;
        p->facet_start = facets;
        if (p->rank == rank) {
            listed += p->vertex_count;
            facets += p->facet_count;
        }
    }
    out->id_bytes = corners->id_bytes;
    /* ids alone when the positions are held whole (a record's ids come first) */
    size_t xyz = corners->held ? 0 : 3 * (corners->f32 ? sizeof(float) : sizeof(double));
    out->vertex_record = out->id_bytes + xyz;
    out->facet_record = corners->held ? 3 * out->id_bytes : corners->record;
    out->triangle_ids = triangle_ids;
    if (triangle_ids)
        out->facet_record += sizeof(uint64_t);
    job.facet_record = out->facet_record;
    job.triangle_ids = triangle_ids;
    out->temporary_bytes =
        out->vertex_record * listed + out->facet_record * facets + job.code_bytes * corners->count;
    st =
        write_vertex_lists(vertices, &g, ct.pieces, ct.count, rank, out, buffer_memory, dir, error);
    if (st == RSMOOTH_OK)
        st = write_facet_lists(&job, out->facet_fd, buffer_memory, dir, error);

done:
    facet_job_free(&job);
    rs_free(g.count);
    rs_free(g.piece);
    rs_free(ct.boxes);
    out->pieces = ct.pieces;
    out->count = ct.count;
    if (st != RSMOOTH_OK)
        rs_stream_pieces_free(out);
    return st;
}

void rs_stream_pieces_free(rs_stream_pieces *pieces) {
    rs_free(pieces->pieces);
    if (pieces->vertex_fd >= 0)
        close(pieces->vertex_fd);
    if (pieces->facet_fd >= 0)
        close(pieces->facet_fd);
    memset(pieces, 0, sizeof *pieces);
    pieces->vertex_fd = pieces->facet_fd = -1;
}
