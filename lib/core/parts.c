/* Parts of a mesh by scale: the unit every width is measured in belongs to a part, and a vertex
 * is moved by its own part's triangles only (parts.h has the rule). A stray vertex thrown far off
 * the surface makes the triangles around it large: they form a part of their own, whose vertices
 * on the surface belong to the surface's part, so the stray vertex reaches no triangle of its own
 * part whose corners are all its part's, and it is held as an outlier. Parts of very different
 * size in one file (a bolt beside a building) each get their own unit.
 *
 * Everything here is local to a triangle and its corners' triangles, and the parts come from a
 * histogram of integer counts, so the pieces of a streamed mesh can find them with a halo of one
 * ring and a sum of histograms, and get the same answer. */
#include "core/parts.h"
#include "core/incidence.h"

#include <math.h>
#include <string.h>

#define BIN_MIN RS_PART_BIN_MIN
#define BIN_COUNT RS_PART_BIN_COUNT
#define SCALE_GRAIN 4096

typedef struct scale_job {
    rsmooth_scalar scalar;
    const void *positions;
    const uint32_t *indices;
    size_t triangle_count;
    int16_t *bin;    /* per triangle: quarter-octave bin of its scale, RS_NO_BIN when 0 */
    double *longest; /* per chunk: its longest edge */
} scale_job;

static void scale_range(void *ctx, size_t begin, size_t end, size_t chunk) {
    scale_job *job = ctx;
    double worst = 0;
    for (size_t t = begin; t < end; t++) {
        double hi = 0;
        double median = rs_triangle_scale(job->scalar, job->positions, job->indices + 3 * t, &hi);
        job->bin[t] = rs_scale_bin(median);
        if (job->bin[t] != RS_NO_BIN)
            worst = fmax(worst, hi);
    }
    job->longest[chunk] = worst;
}

/* Which part moves each vertex (the part of most of its triangles, the finer of equals), and the
 * outliers among them. */
static bool assign_vertices(rs_parts *parts, size_t vertex_count, const uint32_t *indices,
                            size_t triangle_count) {
    size_t *start = NULL;
    uint32_t *list = NULL;
    uint32_t *tally_part = rs_alloc_array(parts->count, sizeof *tally_part);
    size_t *tally = rs_alloc_array(parts->count, sizeof *tally);
    if (!tally_part || !tally ||
        !rs_vertex_triangles(indices, triangle_count, vertex_count, &start, &list)) {
        rs_free(tally_part);
        rs_free(tally);
        return false;
    }
    for (size_t v = 0; v < vertex_count; v++) {
        size_t kinds = 0;
        for (size_t i = start[v]; i < start[v + 1]; i++) {
            uint32_t p = parts->triangle_part[list[i]];
            if (p == RS_NO_PART)
                continue; /* (its corners coincide: no part's) */
            size_t k = 0;
            while (k < kinds && tally_part[k] != p)
                k++;
            if (k == kinds) {
                tally_part[kinds] = p;
                tally[kinds++] = 0;
            }
            tally[k]++;
        }
        uint32_t best = RS_NO_PART;
        size_t best_count = 0;
        for (size_t k = 0; k < kinds; k++)
            if (tally[k] > best_count || (tally[k] == best_count && tally_part[k] < best)) {
                best = tally_part[k];
                best_count = tally[k];
            }
        parts->vertex_part[v] = best;
    }
    /* An outlier reaches no triangle of its own part whose corners are all that part's. */
    for (size_t v = 0; v < vertex_count; v++) {
        uint32_t p = parts->vertex_part[v];
        if (p == RS_NO_PART)
            continue;
        bool anchored = false;
        for (size_t i = start[v]; i < start[v + 1] && !anchored; i++) {
            const uint32_t *tri = indices + 3 * (size_t)list[i];
            anchored = parts->triangle_part[list[i]] == p && parts->vertex_part[tri[0]] == p &&
                       parts->vertex_part[tri[1]] == p && parts->vertex_part[tri[2]] == p;
        }
        parts->outlier[v] = !anchored;
        if (anchored)
            parts->vertices[p]++;
        else
            parts->outliers++;
    }
    rs_free(start);
    rs_free(list);
    rs_free(tally_part);
    rs_free(tally);
    return true;
}

rsmooth_status rs_parts_find(rs_parts *parts, rsmooth_scalar scalar, const void *positions,
                             size_t vertex_count, const uint32_t *indices, size_t triangle_count,
                             rsmooth_error *error, const char *where) {
    memset(parts, 0, sizeof *parts);
    parts->whole = true;
    parts->count = triangle_count > 0;
    if (triangle_count == 0)
        return RSMOOTH_OK;
    size_t chunks = rs_parallel_chunks(triangle_count, SCALE_GRAIN);
    int16_t *bin = rs_alloc_array(triangle_count, sizeof *bin);
    double *longest = rs_calloc_array(chunks, sizeof *longest);
    size_t *histogram = rs_calloc_array(BIN_COUNT, sizeof *histogram);
    uint32_t *part_of_bin = rs_alloc_array(BIN_COUNT, sizeof *part_of_bin);
    rsmooth_status st = RSMOOTH_OK;
    if (!bin || !longest || !histogram || !part_of_bin) {
        st = rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "no memory for the parts");
        goto done;
    }
    scale_job job = {scalar, positions, indices, triangle_count, bin, longest};
    rs_parallel_for(triangle_count, SCALE_GRAIN, scale_range, &job);
    double worst = 0;
    for (size_t c = 0; c < chunks; c++)
        worst = fmax(worst, longest[c]);
    for (size_t t = 0; t < triangle_count; t++)
        if (bin[t] != RS_NO_BIN)
            histogram[bin[t] - BIN_MIN]++;
    double limit_one = 0;
    parts->count = rs_cut_parts(histogram, part_of_bin, &limit_one, 1);
    if (parts->count <= 1 && worst <= limit_one) { /* no edge out of line either */
        parts->count = 1;
        goto done;
    }
    parts->whole = false;
    parts->triangle_part = rs_alloc_array(triangle_count, sizeof *parts->triangle_part);
    parts->vertex_part =
        rs_alloc_array(vertex_count ? vertex_count : 1, sizeof *parts->vertex_part);
    parts->outlier = rs_calloc_array(vertex_count ? vertex_count : 1, 1);
    parts->edge_limit = rs_alloc_array(parts->count ? parts->count : 1, sizeof *parts->edge_limit);
    parts->vertices = rs_calloc_array(parts->count ? parts->count : 1, sizeof *parts->vertices);
    if (!parts->triangle_part || !parts->vertex_part || !parts->outlier || !parts->edge_limit ||
        !parts->vertices) {
        st = rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "no memory for the parts");
        goto done;
    }
    rs_cut_parts(histogram, part_of_bin, parts->edge_limit, parts->count);
    for (size_t t = 0; t < triangle_count; t++)
        parts->triangle_part[t] = bin[t] == RS_NO_BIN ? RS_NO_PART : part_of_bin[bin[t] - BIN_MIN];
    if (!assign_vertices(parts, vertex_count, indices, triangle_count)) {
        st = rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "no memory for the parts");
        goto done;
    }
done:
    rs_free(bin);
    rs_free(longest);
    rs_free(histogram);
    rs_free(part_of_bin);
    return st;
}

void rs_parts_free(rs_parts *parts) {
    if (!parts)
        return;
    rs_free(parts->triangle_part);
    rs_free(parts->vertex_part);
    rs_free(parts->outlier);
    rs_free(parts->edge_limit);
    rs_free(parts->vertices);
    size_t count = parts->count;
    bool whole = parts->whole;
    memset(parts, 0, sizeof *parts);
    parts->count = count;
    parts->whole = whole;
}

uint32_t rs_parts_largest(const rs_parts *parts) {
    uint32_t best = 0;
    for (size_t p = 1; !parts->whole && p < parts->count; p++)
        if (parts->vertices[p] > parts->vertices[best])
            best = (uint32_t)p;
    return best;
}

bool rs_submesh_make(rs_submesh *sub, const rs_parts *parts, uint32_t part, rsmooth_scalar scalar,
                     const void *positions, size_t vertex_count, const uint32_t *indices,
                     size_t triangle_count, const uint8_t *move_mask) {
    memset(sub, 0, sizeof *sub);
    uint32_t *local = rs_alloc_array(vertex_count ? vertex_count : 1, sizeof *local);
    if (!local)
        return false;
    for (size_t v = 0; v < vertex_count; v++)
        local[v] = RS_NO_PART;
    size_t triangles = 0, vertices = 0;
    for (size_t t = 0; t < triangle_count; t++)
        if (parts->triangle_part[t] == part) {
            triangles++;
            for (int c = 0; c < 3; c++)
                local[indices[3 * t + c]] = 0; /* used */
        }
    for (size_t v = 0; v < vertex_count; v++) /* numbered in the mesh's order */
        if (local[v] == 0)
            local[v] = (uint32_t)vertices++;
    size_t record = rs_vertex_bytes(scalar);
    sub->positions = rs_alloc_array(vertices ? vertices : 1, record);
    sub->indices = rs_alloc_array(triangles ? 3 * triangles : 1, sizeof *sub->indices);
    sub->vertex = rs_alloc_array(vertices ? vertices : 1, sizeof *sub->vertex);
    sub->move = rs_alloc_array(vertices ? vertices : 1, 1);
    if (!sub->positions || !sub->indices || !sub->vertex || !sub->move) {
        rs_free(local);
        rs_submesh_free(sub);
        return false;
    }
    for (size_t v = 0; v < vertex_count; v++)
        if (local[v] != RS_NO_PART) {
            uint32_t s = local[v];
            sub->vertex[s] = (uint32_t)v;
            memcpy((char *)sub->positions + s * record, (const char *)positions + v * record,
                   record);
            sub->move[s] =
                parts->vertex_part[v] == part && !parts->outlier[v] && (!move_mask || move_mask[v]);
            sub->moving += sub->move[s];
        }
    size_t out = 0;
    for (size_t t = 0; t < triangle_count; t++)
        if (parts->triangle_part[t] == part)
            for (int c = 0; c < 3; c++)
                sub->indices[out++] = local[indices[3 * t + c]];
    sub->vertex_count = vertices;
    sub->triangle_count = triangles;
    rs_free(local);
    return true;
}

void rs_submesh_free(rs_submesh *sub) {
    if (!sub)
        return;
    rs_free(sub->positions);
    rs_free(sub->indices);
    rs_free(sub->vertex);
    rs_free(sub->move);
    memset(sub, 0, sizeof *sub);
}
