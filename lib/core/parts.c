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

#include <math.h>
#include <string.h>

#define BIN_MIN RS_PART_BIN_MIN
#define BIN_COUNT RS_PART_BIN_COUNT
#define SCALE_GRAIN 4096

/* |a - b| for two vertices, without overflow or underflow of the squares. */
static double edge_length(rsmooth_scalar scalar, const void *positions, uint32_t a, uint32_t b) {
    double d[3], m = 0;
    for (int k = 0; k < 3; k++) {
        d[k] = rs_coordinate(scalar, positions, 3 * (size_t)a + (size_t)k) -
               rs_coordinate(scalar, positions, 3 * (size_t)b + (size_t)k);
        m = fmax(m, fabs(d[k]));
    }
    if (!(m > 0))
        return 0;
    double s = 0;
    for (int k = 0; k < 3; k++)
        s += (d[k] / m) * (d[k] / m);
    return m * sqrt(s);
}

typedef struct scale_job {
    rsmooth_scalar scalar;
    const void *positions;
    const uint32_t *indices;
    size_t triangle_count;
    int16_t *bin;           /* per triangle: quarter-octave bin of its scale, RS_NO_BIN when 0 */
    double *longest;        /* per chunk: its longest edge */
} scale_job;

double rs_triangle_scale(rsmooth_scalar scalar, const void *positions, const uint32_t tri[3],
                         double *longest) {
    double e0 = edge_length(scalar, positions, tri[0], tri[1]);
    double e1 = edge_length(scalar, positions, tri[1], tri[2]);
    double e2 = edge_length(scalar, positions, tri[2], tri[0]);
    double lo = fmin(e0, fmin(e1, e2));
    *longest = fmax(e0, fmax(e1, e2));
    return e0 + e1 + e2 - lo - *longest; /* the median */
}

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

int16_t rs_scale_bin(double scale) {
    if (!(scale > 0) || !isfinite(scale))
        return RS_NO_BIN;
    return (int16_t)floor(RS_PART_BINS_PER_OCTAVE * log2(scale));
}

/* The parts as ranges of bins: part_of_bin[b - BIN_MIN] for every occupied bin, and each part's
 * edge limit. Returns the number of parts. */
static size_t cut_parts(const size_t *histogram, uint32_t *part_of_bin, double *limit,
                        size_t limit_capacity) {
    size_t parts = 0;
    int last = 0, first = 0;
    size_t in_part = 0;
    bool open = false;
    for (int b = 0; b <= BIN_COUNT; b++) {
        bool occupied = b < BIN_COUNT && histogram[b] > 0;
        bool ends = open && (b == BIN_COUNT ||
                             (occupied && b - last > RS_PART_GAP_OCTAVES * RS_PART_BINS_PER_OCTAVE));
        if (ends) { /* the part [first, last]: its median bin bounds its typical scale */
            size_t seen = 0;
            int median = first;
            for (int m = first; m <= last; m++) {
                seen += histogram[m];
                if (2 * seen >= in_part) {
                    median = m;
                    break;
                }
            }
            if (parts < limit_capacity)
                limit[parts] = RS_EDGE_OUT_OF_LINE *
                               exp2((double)(median + BIN_MIN + 1) / RS_PART_BINS_PER_OCTAVE);
            parts++;
            open = false;
            in_part = 0;
        }
        if (occupied) {
            if (!open) {
                open = true;
                first = b;
            }
            part_of_bin[b] = (uint32_t)parts;
            in_part += histogram[b];
            last = b;
        }
    }
    return parts;
}

/* The corners of triangle t that are not repeats of an earlier corner: 1 to 3 of them. */
static int distinct_corners(const uint32_t *tri, uint32_t out[3]) {
    int n = 0;
    for (int c = 0; c < 3; c++)
        if ((c < 1 || tri[c] != tri[0]) && (c < 2 || tri[c] != tri[1]))
            out[n++] = tri[c];
    return n;
}

/* Which part moves each vertex (the part of most of its triangles, the finer of equals), and the
 * outliers among them. */
static bool assign_vertices(rs_parts *parts, size_t vertex_count, const uint32_t *indices,
                            size_t triangle_count) {
    size_t *start = rs_calloc_array(vertex_count + 1, sizeof *start);
    uint32_t *list = rs_alloc_array(triangle_count ? 3 * triangle_count : 1, sizeof *list);
    uint32_t *tally_part = rs_alloc_array(parts->count, sizeof *tally_part);
    size_t *tally = rs_alloc_array(parts->count, sizeof *tally);
    if (!start || !list || !tally_part || !tally) {
        rs_free(start);
        rs_free(list);
        rs_free(tally_part);
        rs_free(tally);
        return false;
    }
    uint32_t corner[3];
    for (size_t t = 0; t < triangle_count; t++)
        if (parts->triangle_part[t] != RS_NO_PART)
            for (int c = 0, n = distinct_corners(indices + 3 * t, corner); c < n; c++)
                start[corner[c] + 1]++;
    for (size_t v = 0; v < vertex_count; v++)
        start[v + 1] += start[v];
    for (size_t t = 0; t < triangle_count; t++)
        if (parts->triangle_part[t] != RS_NO_PART)
            for (int c = 0, n = distinct_corners(indices + 3 * t, corner); c < n; c++)
                list[start[corner[c]]++] = (uint32_t)t;
    for (size_t v = vertex_count; v > 0; v--) /* the fill moved each start to the next's */
        start[v] = start[v - 1];
    start[0] = 0;
    for (size_t v = 0; v < vertex_count; v++) {
        size_t kinds = 0;
        for (size_t i = start[v]; i < start[v + 1]; i++) {
            uint32_t p = parts->triangle_part[list[i]];
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
    parts->count = cut_parts(histogram, part_of_bin, &limit_one, 1);
    if (parts->count <= 1 && worst <= limit_one) { /* no edge out of line either */
        parts->count = 1;
        goto done;
    }
    parts->whole = false;
    parts->triangle_part = rs_alloc_array(triangle_count, sizeof *parts->triangle_part);
    parts->vertex_part = rs_alloc_array(vertex_count ? vertex_count : 1, sizeof *parts->vertex_part);
    parts->outlier = rs_calloc_array(vertex_count ? vertex_count : 1, 1);
    parts->edge_limit = rs_alloc_array(parts->count ? parts->count : 1, sizeof *parts->edge_limit);
    parts->vertices = rs_calloc_array(parts->count ? parts->count : 1, sizeof *parts->vertices);
    if (!parts->triangle_part || !parts->vertex_part || !parts->outlier || !parts->edge_limit ||
        !parts->vertices) {
        st = rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "no memory for the parts");
        goto done;
    }
    cut_parts(histogram, part_of_bin, parts->edge_limit, parts->count);
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
            sub->move[s] = parts->vertex_part[v] == part && !parts->outlier[v] &&
                           (!move_mask || move_mask[v]);
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

size_t rs_scale_parts(const int16_t *bin, size_t count, uint32_t *part, double **limit) {
    size_t *histogram = rs_calloc_array(BIN_COUNT, sizeof *histogram);
    uint32_t *part_of_bin = rs_alloc_array(BIN_COUNT, sizeof *part_of_bin);
    size_t parts = SIZE_MAX;
    *limit = NULL;
    if (histogram && part_of_bin) {
        for (size_t i = 0; i < count; i++)
            if (bin[i] != RS_NO_BIN)
                histogram[bin[i] - BIN_MIN]++;
        parts = cut_parts(histogram, part_of_bin, NULL, 0);
        *limit = rs_alloc_array(parts ? parts : 1, sizeof **limit);
        if (*limit) {
            cut_parts(histogram, part_of_bin, *limit, parts);
            for (size_t i = 0; i < count; i++)
                part[i] = bin[i] == RS_NO_BIN ? RS_NO_PART : part_of_bin[bin[i] - BIN_MIN];
        } else {
            parts = SIZE_MAX;
        }
    }
    rs_free(histogram);
    rs_free(part_of_bin);
    return parts;
}

bool rs_scales_whole(const size_t *histogram, double longest) {
    uint32_t *part_of_bin = rs_alloc_array(BIN_COUNT, sizeof *part_of_bin);
    if (!part_of_bin)
        return false;
    double limit = 0;
    size_t parts = cut_parts(histogram, part_of_bin, &limit, 1);
    rs_free(part_of_bin);
    return parts <= 1 && longest <= limit;
}
