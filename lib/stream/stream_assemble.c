/* A piece's arrays from its lists: its core vertices first, in their list's order (ascending ids),
 * then the other vertices its facets name, in ascending id order, and the facets renumbered.
 *
 * The facets' corners are sorted by vertex id (core/sort.c's radix sort, on every core) and walked
 * once beside the core's ids: each vertex is found by a merge instead of a lookup per corner, and
 * the held positions are read in ascending order instead of where the facets point (a hash table
 * per piece cost 14 of 77 s at 10^8 triangles, most of it in cache misses). The numbering of the
 * vertices outside the core does not change a core vertex's result: the filter reads them only
 * through the facets, whose order is kept. */
#include "stream/stream_internal.h"

#include <errno.h>
#include <string.h>

/* Position `at` (3 values of the file's type) into xyz[3 v .. 3 v + 2]. */
static void put_position(double *xyz, size_t v, bool f32, const unsigned char *at) {
    for (int k = 0; k < 3; k++) {
        if (f32) {
            float x;
            memcpy(&x, at + sizeof x * (size_t)k, sizeof x);
            xyz[3 * v + (size_t)k] = (double)x;
        } else
            memcpy(xyz + 3 * v + (size_t)k, at + sizeof(double) * (size_t)k, sizeof(double));
    }
}

/* Vertex `id`'s position as the file's type: in the held positions, or at byte `offset` of its
 * list entry `entry` (an entry of ids alone carries none). */
static const unsigned char *position_of(const rs_piece_source *src, uint64_t id,
                                        const unsigned char *entry, size_t offset) {
    size_t vertex_bytes = 3 * (src->f32 ? sizeof(float) : sizeof(double));
    return src->held ? (const unsigned char *)src->held->xyz + id * vertex_bytes : entry + offset;
}

/* The core's positions in `core` in ascending id order (the lists write them ascending, so this is
 * nearly free; sorted all the same, the merge below holds for any list). NULL when out of
 * memory. */
static uint32_t *core_order(const uint64_t *core, size_t n) {
    uint64_t *keys = rs_alloc_array(n ? n : 1, sizeof *keys);
    uint32_t *order = rs_alloc_array(n ? n : 1, sizeof *order);
    bool ok = keys && order;
    for (size_t v = 0; ok && v < n; v++) {
        keys[v] = core[v];
        order[v] = (uint32_t)v;
    }
    ok = ok && rs_radix_sort_u64(keys, order, n);
    rs_free(keys);
    if (!ok) {
        rs_free(order);
        return NULL;
    }
    return order;
}

bool rs_stream_assemble(const rs_piece_source *src, const unsigned char *core_records, size_t n,
                        const unsigned char *facet_records, size_t m, uint64_t *core, uint32_t *tri,
                        double *xyz, size_t *k, uint64_t *all_ids) {
    size_t id_bytes = src->id_bytes;
    for (size_t v = 0; v < n; v++) {
        const unsigned char *rec = core_records + v * src->vertex_record;
        core[v] = rs_stream_get_id(rec, id_bytes);
        put_position(xyz, v, src->f32, position_of(src, core[v], rec, id_bytes));
    }
    size_t corners = 3 * m;
    uint64_t *ids = rs_alloc_array(corners ? corners : 1, sizeof *ids);
    uint32_t *slot = rs_alloc_array(corners ? corners : 1, sizeof *slot);
    uint32_t *order = ids && slot ? core_order(core, n) : NULL;
    bool ok = order != NULL;
    for (size_t f = 0; ok && f < m; f++) /* (read before tri, which may be the records, is set) */
        for (size_t q = 0; q < 3; q++) {
            const unsigned char *rec = facet_records + f * src->facet_record;
            ids[3 * f + q] = rs_stream_get_id(rec + q * id_bytes, id_bytes);
            slot[3 * f + q] = (uint32_t)(3 * f + q);
        }
    ok = ok && rs_radix_sort_u64(ids, slot, corners);
    size_t value = src->f32 ? sizeof(float) : sizeof(double), next = 0, count = n;
    uint32_t number = 0;
    for (size_t i = 0; ok && i < corners; i++) {
        uint64_t id = ids[i];
        if (i == 0 || id != ids[i - 1]) { /* a vertex first met: in the core, or the next one */
            while (next < n && core[order[next]] < id)
                next++;
            if (next < n && core[order[next]] == id)
                number = order[next];
            else {
                size_t f = slot[i] / 3, q = slot[i] % 3;
                const unsigned char *rec = facet_records + f * src->facet_record;
                put_position(xyz, count, src->f32,
                             position_of(src, id, rec, 3 * id_bytes + 3 * value * q));
                if (all_ids)
                    all_ids[count] = id;
                number = (uint32_t)count++;
            }
        }
        tri[slot[i]] = number;
    }
    rs_free(order);
    rs_free(ids);
    rs_free(slot);
    for (size_t v = 0; all_ids && v < n; v++)
        all_ids[v] = core[v];
    *k = count;
    return ok;
}

void rs_stream_piece_arrays_free(rs_stream_piece_arrays *a) {
    rs_free(a->core);
    rs_free(a->ids);
    rs_free(a->xyz);
    rs_free(a->tri);
    rs_free(a->triangle);
    memset(a, 0, sizeof *a);
}

rsmooth_status rs_stream_piece_load(const rs_stream_pieces *pieces, const rs_piece_source *src,
                                    const rs_piece *p, bool want_ids, rs_stream_piece_arrays *a,
                                    rsmooth_error *error) {
    memset(a, 0, sizeof *a);
    size_t n = a->n = (size_t)p->vertex_count, m = a->m = (size_t)p->facet_count;
    size_t vertex_record = pieces->vertex_record, facet_record = pieces->facet_record;
    unsigned char *core_records = rs_alloc_array(n ? n : 1, vertex_record);
    a->core = rs_alloc_array(n ? n : 1, sizeof *a->core);
    a->tri = rs_alloc_array(m ? m : 1, 3 * sizeof *a->tri);
    /* entries of three 32-bit ids are read into tri itself and renumbered in place (each
     * facet's ids are read before its numbers are written): fewer fresh pages per piece */
    bool in_place = facet_record == 3 * sizeof *a->tri;
    unsigned char *facet_records =
        in_place ? (unsigned char *)a->tri : rs_alloc_array(m ? m : 1, facet_record);
    /* at most n + 3m vertices; a piece's facets share their corners about 6 ways */
    size_t most = n + 3 * m;
    a->xyz = rs_alloc_array(most ? most : 1, 3 * sizeof *a->xyz);
    a->ids = want_ids ? rs_alloc_array(most ? most : 1, sizeof *a->ids) : NULL;
    a->triangle = pieces->triangle_ids ? rs_alloc_array(m ? m : 1, sizeof *a->triangle) : NULL;
    rsmooth_status st = RSMOOTH_OK;
    if (!core_records || !facet_records || !a->core || !a->tri || !a->xyz ||
        (want_ids && !a->ids) || (pieces->triangle_ids && !a->triangle))
        st = rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, RS_STREAM_WHERE,
                     "no memory for a piece of %zu facets", m);
    else if (!rs_pread_all(pieces->vertex_fd, core_records, n * vertex_record,
                           p->vertex_start * vertex_record) ||
             !rs_pread_all(pieces->facet_fd, facet_records, m * facet_record,
                           p->facet_start * facet_record))
        st = rs_fail(error, RSMOOTH_ERROR_IO, RS_STREAM_WHERE, "cannot read a temporary file: %s",
                     strerror(errno));
    for (size_t f = 0; st == RSMOOTH_OK && a->triangle && f < m; f++)
        memcpy(a->triangle + f, facet_records + (f + 1) * facet_record - sizeof *a->triangle,
               sizeof *a->triangle);
    if (st == RSMOOTH_OK && !rs_stream_assemble(src, core_records, n, facet_records, m, a->core,
                                                a->tri, a->xyz, &a->k, a->ids))
        st = rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, RS_STREAM_WHERE,
                     "no memory for a piece of %zu facets", m);
    rs_free(core_records);
    if (!in_place)
        rs_free(facet_records);
    if (st != RSMOOTH_OK)
        rs_stream_piece_arrays_free(a);
    return st;
}
