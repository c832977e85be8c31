/* Wavefront OBJ parser over a memory buffer: v and f statements; all else accepted and skipped. */
#include "io/io_internal.h"

#include <math.h>
#include <string.h>

static const char where[] = "rsmooth_mesh_read (OBJ)";

typedef struct obj_state {
    const char *data;
    size_t size;
    /* When >= 0, positive face indices are checked against it as they are read: used by the second
     * pass that locates the face of an index beyond the final vertex count (forward references make
     * that count unknown during the first pass). */
    int64_t known_vertex_count;
    double *positions;
    size_t vertex_count;
    size_t position_capacity; /* in vertices */
    rs_io_u32vec offsets;
    rs_io_u32vec indices;
    uint64_t max_index; /* largest 0-based positive index seen */
} obj_state;

static bool is_space(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

/* Next whitespace-separated token of [*p, end); false at the end of the line or at a comment. */
static bool next_token(const char **p, const char *end, const char **token, size_t *len) {
    const char *s = *p;
    while (s < end && is_space(*s))
        s++;
    if (s == end || *s == '#') {
        *p = end;
        return false;
    }
    const char *t = s;
    while (s < end && !is_space(*s))
        s++;
    *token = t;
    *len = (size_t)(s - t);
    *p = s;
    return true;
}

static bool grow_positions(obj_state *st) {
    if (st->vertex_count < st->position_capacity)
        return true;
    size_t capacity = st->position_capacity ? st->position_capacity * 2 : 4096;
    if (capacity > RS_IO_MAX_VERTICES)
        capacity = (size_t)RS_IO_MAX_VERTICES;
    double *p = rs_realloc_array(st->positions, capacity, 3 * sizeof(double));
    if (!p)
        return false;
    st->positions = p;
    st->position_capacity = capacity;
    return true;
}

static rsmooth_status parse_vertex(obj_state *st, const char *p, const char *end, int64_t line,
                                   const char *statement, rsmooth_error *error) {
    if ((uint64_t)st->vertex_count + 1 >= RS_IO_MAX_VERTICES)
        return rs_fail_parse(error, line, statement - st->data, where,
                             "too many vertices (indices are 32-bit)");
    if (!grow_positions(st))
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "%zu vertices",
                       st->vertex_count + 1);
    double *xyz = st->positions + 3 * st->vertex_count;
    const char *token;
    size_t len;
    int n = 0;
    bool finite = true;
    /* x y z, then optionally w or r g b (accepted, ignored, but they must be numbers). */
    while (next_token(&p, end, &token, &len)) {
        double v;
        if (!rs_io_parse_double(token, len, &v))
            return rs_fail_parse(error, line, token - st->data, where, "malformed number '%.*s'",
                                 (int)(len > 40 ? 40 : len), token);
        if (n < 3) {
            xyz[n] = v;
            finite = finite && isfinite(v);
        }
        n++;
    }
    if (n < 3)
        return rs_fail_parse(error, line, statement - st->data, where,
                             "vertex %zu has %d coordinates (3 needed)", st->vertex_count + 1, n);
    if (!finite) /* numbered as f statements refer to it: 1-based */
        return rs_fail_parse(error, line, statement - st->data, where,
                             "vertex %zu has a non-finite coordinate", st->vertex_count + 1);
    st->vertex_count++;
    return RSMOOTH_OK;
}

/* Parses the vertex part of "v", "v/vt", "v//vn" or "v/vt/vn" (the others must be integers too). */
static bool parse_index(const char *s, size_t len, int64_t *out) {
    size_t i = 0;
    int part = 0;
    while (part < 3) {
        bool negative = false;
        if (i < len && (s[i] == '-' || s[i] == '+')) {
            negative = s[i] == '-';
            i++;
        }
        size_t first = i;
        int64_t v = 0;
        for (; i < len && s[i] >= '0' && s[i] <= '9'; i++)
            v = v < INT64_MAX / 100 ? v * 10 + (s[i] - '0')
                                    : v; /* saturates: out of range anyway */
        bool empty = i == first;
        if (part == 0) {
            if (empty)
                return false;
            *out = negative ? -v : v;
        } else if (empty && (negative || part == 2)) {
            return false; /* "v/-" or "v/vt/" */
        }
        if (i == len)
            return true;
        if (s[i] != '/')
            return false;
        i++;
        part++;
    }
    return false; /* a third slash */
}

static rsmooth_status parse_face(obj_state *st, const char *p, const char *end, int64_t line,
                                 const char *statement, rsmooth_error *error) {
    const char *token;
    size_t len;
    size_t first = st->indices.count;
    while (next_token(&p, end, &token, &len)) {
        int64_t index;
        if (!parse_index(token, len, &index))
            return rs_fail_parse(error, line, token - st->data, where,
                                 "malformed face index '%.*s'", (int)(len > 40 ? 40 : len), token);
        int64_t zero_based;
        if (index == 0)
            return rs_fail_parse(error, line, token - st->data, where,
                                 "face index 0 (OBJ indices start at 1)");
        if (index < 0) { /* relative to the vertices defined so far */
            zero_based = (int64_t)st->vertex_count + index;
            if (zero_based < 0)
                return rs_fail_parse(error, line, token - st->data, where,
                                     "face index %lld out of range (%zu vertices)",
                                     (long long)index, st->vertex_count);
        } else {
            zero_based = index - 1;
            if (st->known_vertex_count >= 0 && zero_based >= st->known_vertex_count)
                return rs_fail_parse(error, line, token - st->data, where,
                                     "face index %lld out of range (%lld vertices)",
                                     (long long)index, (long long)st->known_vertex_count);
        }
        if ((uint64_t)zero_based > st->max_index)
            st->max_index = (uint64_t)zero_based;
        if (st->indices.count + 1 >= RS_IO_MAX_FACE_INDICES)
            return rs_fail_parse(error, line, token - st->data, where,
                                 "too many face indices (offsets are 32-bit)");
        if (!rs_io_u32vec_reserve(&st->indices, 1))
            return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "%zu face indices",
                           st->indices.count + 1);
        /* Out-of-range values are caught after the pass; UINT32_MAX is never a valid index. */
        st->indices.data[st->indices.count++] =
            zero_based >= (int64_t)UINT32_MAX ? UINT32_MAX : (uint32_t)zero_based;
    }
    size_t n = st->indices.count - first;
    if (n < 3)
        return rs_fail_parse(error, line, statement - st->data, where,
                             "face has %zu vertices (at least 3 needed)", n);
    if (!rs_io_u32vec_reserve(&st->offsets, 1))
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "%zu faces", st->offsets.count);
    st->offsets.data[st->offsets.count++] = (uint32_t)st->indices.count;
    return RSMOOTH_OK;
}

static rsmooth_status parse_all(obj_state *st, rsmooth_error *error) {
    const char *p = st->data, *end = st->data + st->size;
    if (!rs_io_u32vec_reserve(&st->offsets, 1))
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "face offsets");
    st->offsets.data[st->offsets.count++] = 0;
    for (int64_t line = 1; p < end; line++) {
        const char *eol = memchr(p, '\n', (size_t)(end - p));
        const char *line_end = eol ? eol : end;
        const char *statement;
        size_t len;
        const char *q = p;
        p = eol ? eol + 1 : end;
        if (!next_token(&q, line_end, &statement, &len) || len != 1)
            continue; /* blank, comment, or a statement we skip (vt, vn, g, o, usemtl, ...) */
        rsmooth_status status = RSMOOTH_OK;
        if (statement[0] == 'v')
            status = parse_vertex(st, q, line_end, line, statement, error);
        else if (statement[0] == 'f')
            status = parse_face(st, q, line_end, line, statement, error);
        if (status != RSMOOTH_OK)
            return status;
    }
    return RSMOOTH_OK;
}

static void free_state(obj_state *st) {
    rs_free(st->positions);
    rs_free(st->offsets.data);
    rs_free(st->indices.data);
}

rsmooth_status rs_io_obj_read(const char *data, size_t size, rsmooth_mesh **mesh,
                              rsmooth_error *error) {
    obj_state st = {.data = data, .size = size, .known_vertex_count = -1};
    rsmooth_status status = parse_all(&st, error);
    if (status == RSMOOTH_OK && st.vertex_count == 0)
        status = rs_fail_parse(error, -1, -1, where, "no vertices");
    if (status == RSMOOTH_OK && st.indices.count > 0 && st.max_index >= st.vertex_count) {
        /* Rare error path: parse again, checking each index against the final count, so the error
         * names the line of the first offending face. */
        obj_state again = {
            .data = data, .size = size, .known_vertex_count = (int64_t)st.vertex_count};
        status = parse_all(&again, error);
        free_state(&again);
        if (status == RSMOOTH_OK) /* unreachable unless the two passes disagree */
            status = rs_fail_parse(error, -1, -1, where, "face index out of range (%zu vertices)",
                                   st.vertex_count);
    }
    if (status != RSMOOTH_OK) {
        free_state(&st);
        return status;
    }
    size_t face_count = st.offsets.count - 1;
    uint32_t *indices = st.indices.data;
    if (!indices) /* no face: keep a valid (empty) array */
        indices = rs_alloc_array(1, sizeof(uint32_t));
    if (!indices) {
        free_state(&st);
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "face indices");
    }
    /* Give back the slack of geometric growth. */
    double *positions = rs_realloc_array(st.positions, st.vertex_count, 3 * sizeof(double));
    if (!positions)
        positions = st.positions;
    return rs_io_mesh_adopt(positions, st.vertex_count, RSMOOTH_FLOAT64, st.offsets.data,
                            face_count, indices, RSMOOTH_FORMAT_OBJ, mesh, error);
}
