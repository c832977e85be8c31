/* The normal update stage streamed (params.vertex_updates: the best mode's first half), a cycle
 * at a time, on the pieces the pipeline cuts afresh for each (stream_smooth.c runs the steps):
 *
 *   1. the guided filter's one figure of the whole mesh, its reach (radius times the mean
 *      distance between edge-adjacent facets' centroids): each piece gives the shares of the
 *      triangles whose first corner is its own (stages/stage_piece.c), into a file indexed by
 *      triangle, then summed in triangle order as the whole mesh's stage sums them;
 *   2. each cycle: a piece holding every triangle within rs_stage_cycle_halo of its core runs the
 *      cycle (its lists rebuilt from its vertices' input positions, read from the input's rows),
 *      and its core's positions go to the positions between steps.
 * With the whole mesh's scale and reach, each core comes out as the whole mesh's stage leaves
 * it, bit for bit (the stage on the host, in double: where the in-memory run has it on CPU
 * devices, and with RSMOOTH_STAGE=host on others). */
#include "stages/normal_update.h"
#include "stream/stream_internal.h"

#include <errno.h>
#include <math.h>
#include <string.h>

rsmooth_status rs_stream_stage_shares(const rs_pass_store *store, const rs_stream_piece_arrays *p,
                                      const rs_stage_setting *setting, double scale,
                                      rsmooth_error *error) {
    double *share = rs_alloc_array(p->m ? p->m : 1, sizeof *share);
    uint32_t *pairs = rs_alloc_array(p->m ? p->m : 1, sizeof *pairs);
    uint64_t *owned = rs_alloc_array(p->m ? p->m : 1, sizeof *owned);
    rsmooth_status st = share && pairs && owned ? RSMOOTH_OK : RSMOOTH_ERROR_OUT_OF_MEMORY;
    if (st == RSMOOTH_OK)
        st = rs_stage_piece_shares(p->xyz, p->k, p->tri, p->m, setting, scale, share, pairs);
    size_t count = 0; /* the triangles whose first corner is the core's: this piece's to give */
    for (size_t f = 0; st == RSMOOTH_OK && f < p->m; f++)
        if (p->tri[3 * f] < p->n) {
            owned[count] = p->triangle[f];
            share[count] = share[f];
            pairs[count++] = pairs[f];
        }
    if (st == RSMOOTH_OK && !rs_pass_store_write_shares(store, owned, count, share, pairs))
        st = rs_fail(error, RSMOOTH_ERROR_IO, RS_STREAM_WHERE,
                     "cannot write the guided filter's shares: %s", strerror(errno));
    else if (st == RSMOOTH_ERROR_OUT_OF_MEMORY)
        st = rs_fail(error, st, RS_STREAM_WHERE, "no memory for a piece of %zu facets", p->m);
    rs_free(share);
    rs_free(pairs);
    rs_free(owned);
    return st;
}

rsmooth_status rs_stream_stage_cycle(const rs_stream_ply *input, rs_stream_piece_arrays *p,
                                     const rs_stage_setting *setting, const rs_stage_whole *whole,
                                     const uint8_t *mask, double *displacement,
                                     rsmooth_error *error) {
    double *at_input = rs_alloc_array(p->k ? p->k : 1, 3 * sizeof *at_input);
    uint8_t *held = mask ? rs_alloc_array(p->k ? p->k : 1, 1) : NULL;
    if (!at_input || (mask && !held)) {
        rs_free(at_input);
        rs_free(held);
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, RS_STREAM_WHERE,
                       "no memory for a piece of %zu facets", p->m);
    }
    rsmooth_status st = RSMOOTH_OK;
    if (!rs_stream_ply_read_rows(input, p->ids, p->k, at_input))
        st = rs_fail(error, RSMOOTH_ERROR_IO, RS_STREAM_WHERE, "%s: cannot read the vertices: %s",
                     input->path, strerror(errno));
    for (size_t v = 0; held && v < p->k; v++)
        held[v] = mask[p->ids[v]];
    if (st == RSMOOTH_OK && rs_stage_cycle_piece(at_input, p->xyz, p->k, p->tri, p->m, setting,
                                                 whole, held) != RSMOOTH_OK)
        st = rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, RS_STREAM_WHERE,
                     "no memory for the normal update stage on a piece of %zu facets", p->m);
    for (size_t v = 0; st == RSMOOTH_OK && v < p->n; v++) {
        double d2 = 0;
        for (int k = 0; k < 3; k++) {
            double d = p->xyz[3 * v + (size_t)k] - at_input[3 * v + (size_t)k];
            d2 += d * d;
        }
        *displacement = fmax(*displacement, sqrt(d2));
    }
    rs_free(at_input);
    rs_free(held);
    return st;
}
