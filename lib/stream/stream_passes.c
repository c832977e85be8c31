/* Between the streamed steps (the stage's cycles, the filter's passes: params.vertex_updates,
 * params.passes): each step reads the positions the step before wrote, as the in-memory loops
 * read their double arrays (passes/passes.c). They lie in a double block of the vertex count (24
 * bytes a vertex), two of them, one read while the other is written; where passes after the
 * first keep their confident vertices (pass_confidence), each vertex's confidence (4 bytes) in
 * two blocks likewise; the stage's reach its shares per triangle (12 bytes), and the ranks'
 * largest displacements a slot each. A block of positions is read and written as the vertex
 * block of a PLY of x y z doubles and nothing else, so the input's readers serve it unchanged.
 *
 * Alone the blocks are a temporary file of their own; ranks share the partial output's bytes
 * past its end instead (every rank has it open already, it is removed however the run ends, and
 * it is cut back to the output's size before it is named). */
#define _GNU_SOURCE /* ftruncate */
#include "stream/stream_internal.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#define POSITION_BYTES (3 * sizeof(double))
#define SHARE_BYTES (sizeof(double) + sizeof(uint32_t))
/* Consecutive ids read or written in one call, at most. */
#define RUN_IDS 4096

static uint64_t confidence_at(const rs_pass_store *s, int k) {
    return s->base + 2 * s->vertex_count * POSITION_BYTES +
           (uint64_t)k * s->vertex_count * sizeof(float);
}

static uint64_t shares_at(const rs_pass_store *s) {
    return confidence_at(s, 2);
}

static uint64_t slot_at(const rs_pass_store *s, int rank) {
    return shares_at(s) + s->triangle_count * SHARE_BYTES + (uint64_t)rank * sizeof(double);
}

uint64_t rs_pass_store_bytes(uint64_t vertex_count, uint64_t triangle_count, bool confidences,
                             bool shares) {
    return vertex_count * (2 * POSITION_BYTES + (confidences ? 2 * sizeof(float) : 0)) +
           (shares ? triangle_count * SHARE_BYTES : 0);
}

rsmooth_status rs_pass_store_open(rs_pass_store *s, int shared_fd, uint64_t base,
                                  uint64_t vertex_count, uint64_t triangle_count, const char *dir,
                                  rsmooth_error *error) {
    memset(s, 0, sizeof *s);
    s->fd = shared_fd;
    s->base = base;
    s->vertex_count = vertex_count;
    s->triangle_count = triangle_count;
    if (shared_fd < 0) {
        s->fd = rs_stream_temporary(dir);
        s->own = true;
        if (s->fd < 0)
            return rs_fail(error, RSMOOTH_ERROR_IO, RS_STREAM_WHERE,
                           "cannot create a temporary file in %s: %s", dir, strerror(errno));
    }
    for (int k = 0; k < 2; k++) {
        rs_stream_ply *b = &s->block[k];
        b->fd = s->fd;
        b->path = "the positions between passes (a temporary file)";
        b->vertex_count = vertex_count;
        b->vertex_start = base + (uint64_t)k * vertex_count * POSITION_BYTES;
        b->vertex_stride = POSITION_BYTES;
        b->size = b->vertex_start + vertex_count * POSITION_BYTES; /* every row written by then */
        for (int c = 0; c < 3; c++)
            b->xyz_offset[c] = (size_t)c * sizeof(double);
        b->xyz_type = RS_PLY_FLOAT64;
        /* host byte order both ways; data from offset 0, no header: rows where they are read */
    }
    return RSMOOTH_OK;
}

/* Runs of consecutive ids among ids[0, n) (ascending): one call each. */
static bool confidence_runs(const rs_pass_store *s, int k, const uint64_t *ids, size_t n,
                            float *values, bool write) {
    for (size_t i = 0; i < n;) {
        size_t run = rs_stream_id_run(ids, i, n, RUN_IDS);
        uint64_t at = confidence_at(s, k) + ids[i] * sizeof(float);
        bool ok = write ? rs_pwrite_all(s->fd, values + i, run * sizeof(float), at)
                        : rs_pread_all(s->fd, values + i, run * sizeof(float), at);
        if (!ok)
            return false;
        i += run;
    }
    return true;
}

bool rs_pass_store_read_confidence(const rs_pass_store *s, int k, const uint64_t *ids, size_t n,
                                   float *out) {
    return confidence_runs(s, k, ids, n, out, false);
}

bool rs_pass_store_write_confidence(const rs_pass_store *s, int k, const uint64_t *ids, size_t n,
                                    const float *values) {
    return confidence_runs(s, k, ids, n, (float *)values, true);
}

bool rs_pass_store_close(rs_pass_store *s, bool cut) {
    bool ok = true;
    if (s->own && s->fd >= 0)
        close(s->fd);
    else if (s->fd >= 0 && cut) /* the shared output's tail: back to the output alone */
        ok = ftruncate(s->fd, (off_t)s->base) == 0;
    s->fd = -1;
    return ok;
}

bool rs_pass_store_write_shares(const rs_pass_store *s, const uint64_t *triangles, size_t n,
                                const double *share, const uint32_t *pairs) {
    enum { RUN = 4096 };
    unsigned char buf[RUN * SHARE_BYTES];
    for (size_t i = 0; i < n;) {
        size_t run = rs_stream_id_run(triangles, i, n, RUN); /* consecutive: one write */
        for (size_t j = 0; j < run; j++) {
            memcpy(buf + j * SHARE_BYTES, share + i + j, sizeof(double));
            memcpy(buf + j * SHARE_BYTES + sizeof(double), pairs + i + j, sizeof(uint32_t));
        }
        if (!rs_pwrite_all(s->fd, buf, run * SHARE_BYTES,
                           shares_at(s) + triangles[i] * SHARE_BYTES))
            return false;
        i += run;
    }
    return true;
}

bool rs_pass_store_sum_shares(const rs_pass_store *s, double *sum, uint64_t *pairs) {
    rs_stream_reader r;
    uint64_t at = shares_at(s);
    if (!rs_stream_reader_open(&r, s->fd, "shares", at, at + s->triangle_count * SHARE_BYTES,
                               (1u << 20) / SHARE_BYTES * SHARE_BYTES))
        return false;
    *sum = 0;
    *pairs = 0;
    bool ok = true;
    for (uint64_t t = 0; ok && t < s->triangle_count; t++) { /* triangle order, as in memory */
        const unsigned char *e = rs_stream_read(&r, SHARE_BYTES);
        ok = e != NULL;
        if (ok) {
            double share;
            uint32_t n;
            memcpy(&share, e, sizeof share);
            memcpy(&n, e + sizeof share, sizeof n);
            *sum += share;
            *pairs += n;
        }
    }
    rs_stream_reader_close(&r);
    return ok;
}

bool rs_pass_store_put_slot(const rs_pass_store *s, int rank, double value) {
    return rs_pwrite_all(s->fd, &value, sizeof value, slot_at(s, rank));
}

bool rs_pass_store_largest_slot(const rs_pass_store *s, int ranks, double *largest) {
    *largest = 0;
    for (int r = 0; r < ranks; r++) {
        double value;
        if (!rs_pread_all(s->fd, &value, sizeof value, slot_at(s, r)))
            return false;
        *largest = fmax(*largest, value);
    }
    return true;
}

bool rs_pass_rules(const rs_pass_store *s, const rs_pass_rule *rule, const uint64_t *core, size_t n,
                   const double *xyz, double *out, float *confidence) {
    if (rule->pass > 0 && rule->keep_confidence > 0) {
        float *before = rs_alloc_array(n ? n : 1, sizeof *before);
        bool ok = before && rs_pass_store_read_confidence(s, (rule->pass - 1) % 2, core, n, before);
        for (size_t v = 0; ok && v < n; v++)
            if (before[v] >= rule->keep_confidence) {
                memcpy(out + 3 * v, xyz + 3 * v, POSITION_BYTES);
                confidence[v] = before[v];
            }
        rs_free(before);
        if (!ok)
            return false;
    }
    for (size_t v = 0; rule->mask && v < n; v++)
        if (!rule->mask[core[v]]) /* held still: each pass sees it where the input has it */
            memcpy(out + 3 * v, xyz + 3 * v, POSITION_BYTES);
    return true;
}
