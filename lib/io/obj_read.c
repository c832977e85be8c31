/* Wavefront OBJ parser over a memory buffer: v (with colours) and f; everything else kept as text.
 */
#include "io/obj_format.h"

#include <math.h>
#include <string.h>

static const char where[] = "rsmooth_mesh_read (OBJ)";

typedef struct obj_state {
    const char *data;
    size_t size;
    /* When >= 0, positive face indices (v, vt, vn) are checked against them as they are read: used
     * by the second pass that locates the face of an index beyond the final count (forward
     * references make the counts unknown during the first pass). */
    int64_t known_vertex_count, known_vt_count, known_vn_count;
    double *positions;
    size_t vertex_count;
    size_t position_capacity; /* in vertices */
    rs_io_u32vec offsets;
    rs_io_u32vec indices;
    uint64_t max_index;     /* largest 0-based positive index seen */
    int64_t max_vt, max_vn; /* largest 1-based vt, vn index seen (0: none) */
    size_t vt_count;        /* vt lines so far: negative vt indices count back from it */
    size_t vn_count;        /* vn lines so far: the same for vn */
    /* The first statement OBJ does not know: where a file without vertices is blamed. */
    int64_t unknown_line;
    const char *unknown;
    size_t unknown_len;
    int64_t last_line;
    /* vt index of each face corner, kept in step with `indices` once any corner names one. */
    rs_io_u32vec corner_vt;
    bool any_vt;
    uint8_t *colors; /* 3 per vertex, position_capacity long once any vertex has r g b */
    unsigned kinds;  /* RS_OBJ_* seen */
    /* The line structure for the extras; TEXT runs' start is an offset into `data` until kept. */
    rs_obj_run *runs;
    size_t run_count, run_capacity;
    bool crlf;
} obj_state;

static bool is_space(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

/* Next whitespace-separated token of [*p, end); false at the end of the line or at a comment,
 * leaving *p at the '#' of a comment (so callers can tell one was there). */
static bool next_token(const char **p, const char *end, const char **token, size_t *len) {
    const char *s = *p;
    while (s < end && is_space(*s))
        s++;
    if (s == end || *s == '#') {
        *p = s;
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
    if (st->colors) {
        uint8_t *c = rs_realloc_array(st->colors, capacity, 3);
        if (!c)
            return false;
        st->colors = c;
    }
    st->position_capacity = capacity;
    return true;
}

/* A colour component in [0, 1] as a byte (out of range and NaN clamp). */
static uint8_t color_byte(double c) {
    if (!(c > 0))
        return 0;
    return c >= 1 ? 255 : (uint8_t)(c * 255 + 0.5);
}

/* Stores vertex st->vertex_count's colour, creating the array on the first coloured vertex. */
static bool store_color(obj_state *st, const double rgb[3]) {
    if (!st->colors) {
        st->colors = rs_alloc_array(st->position_capacity, 3);
        if (!st->colors)
            return false;
        /* vertices before the first coloured one show as white, the usual default */
        memset(st->colors, 255, 3 * st->vertex_count);
        st->kinds |= RS_OBJ_COLORS;
    }
    uint8_t *c = st->colors + 3 * st->vertex_count;
    for (int k = 0; k < 3; k++)
        c[k] = color_byte(rgb[k]);
    return true;
}

/* *plain: nothing follows the coordinates (so the writer can make the line from the mesh alone). */
static rsmooth_status parse_vertex(obj_state *st, const char *p, const char *end, int64_t line,
                                   const char *statement, bool *plain, rsmooth_error *error) {
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
    double rgb[3] = {0, 0, 0};
    /* x y z, then optionally w, or r g b (colours); any others must be numbers too. */
    while (next_token(&p, end, &token, &len)) {
        double v;
        if (!rs_io_parse_double(token, len, &v))
            return rs_fail_parse(error, line, token - st->data, where, "malformed number '%.*s'",
                                 (int)(len > 40 ? 40 : len), token);
        if (n < 3) {
            xyz[n] = v;
        } else if (n < 6) {
            rgb[n - 3] = v;
        }
        n++;
    }
    if (p < end)
        st->kinds |= RS_OBJ_COMMENTS;
    *plain = n == 3 && p == end;
    if (n < 3)
        return rs_fail_parse(error, line, statement - st->data, where,
                             "vertex %zu has %d coordinates (3 needed)", st->vertex_count + 1, n);
    /* numbered as f statements refer to it: 1-based */
    rsmooth_status status =
        rs_io_check_vertex(xyz, st->vertex_count + 1, line, statement - st->data, where, error);
    if (status != RSMOOTH_OK)
        return status;
    if (n == 6) {
        if (!isfinite(rgb[0]) || !isfinite(rgb[1]) || !isfinite(rgb[2]))
            return rs_fail_parse(error, line, statement - st->data, where,
                                 "vertex %zu has a non-finite colour", st->vertex_count + 1);
        if (!store_color(st, rgb))
            return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "vertex colours");
    } else {
        if (n > 3)
            st->kinds |= RS_OBJ_VERTEX_W;
        if (st->colors)
            memset(st->colors + 3 * st->vertex_count, 255, 3);
    }
    st->vertex_count++;
    return RSMOOTH_OK;
}

/* Parses "v", "v/vt", "v//vn" or "v/vt/vn": the vertex index into *out, the vt and vn indices (0
 * when there is none) into *vt and *vn, all as in the file (1-based, or negative: relative). */
static bool parse_index(const char *s, size_t len, int64_t *out, int64_t *vt, int64_t *vn) {
    *vt = *vn = 0;
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
        } else if (!empty) {
            int64_t *index = part == 1 ? vt : vn;
            *index = negative ? -v : v;
            if (*index == 0)
                return false; /* "v/0", "v//0": OBJ indices start at 1 */
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

/* Checks a vt or vn index of a face corner against the lines of its kind: negative ones against
 * those so far, positive ones against the final count once known (the second pass). Returns it
 * 0-based, or -1 for none. */
static rsmooth_status check_attribute_index(obj_state *st, int64_t index, const char *kind,
                                            size_t count_so_far, int64_t known_count,
                                            int64_t *max_seen, int64_t line, const char *token,
                                            int64_t *zero_based, rsmooth_error *error) {
    *zero_based = -1;
    if (index == 0)
        return RSMOOTH_OK;
    int64_t absolute = index < 0 ? (int64_t)count_so_far + index : index - 1;
    if (absolute < 0 || absolute > (int64_t)UINT32_MAX - 2 ||
        (index > 0 && known_count >= 0 && absolute >= known_count)) {
        size_t lines = index < 0 || known_count < 0 ? count_so_far : (size_t)known_count;
        bool vt = kind[1] == 't';
        return rs_fail_parse(error, line, token - st->data, where,
                             "%s index %lld out of range (%zu %s)", vt ? "texture" : "normal",
                             (long long)index, lines, vt ? "texture coordinates" : "normals");
    }
    if (index > *max_seen)
        *max_seen = index;
    *zero_based = absolute;
    return RSMOOTH_OK;
}

/* Records the vt index (0-based, or -1: none) of the corner about to be appended to st->indices,
 * made absolute so the writer never depends on how many vt lines came before. */
static rsmooth_status record_vt(obj_state *st, int64_t vt, rsmooth_error *error) {
    uint32_t value = vt < 0 ? RS_OBJ_NO_VT : (uint32_t)vt;
    size_t corner = st->indices.count;
    if (!rs_io_u32vec_reserve(&st->corner_vt, corner + 1 - st->corner_vt.count))
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "%zu texture indices",
                       corner + 1);
    if (!st->any_vt) { /* the corners before the first one that names a vt have none */
        for (size_t i = 0; i < corner; i++)
            st->corner_vt.data[i] = RS_OBJ_NO_VT;
        st->corner_vt.count = corner;
        st->any_vt = true;
        st->kinds |= RS_OBJ_TEXCOORDS;
    }
    st->corner_vt.data[st->corner_vt.count++] = value;
    return RSMOOTH_OK;
}

/* *plain: no trailing comment. */
static rsmooth_status parse_face(obj_state *st, const char *p, const char *end, int64_t line,
                                 const char *statement, bool *plain, rsmooth_error *error) {
    const char *token;
    size_t len;
    size_t first = st->indices.count;
    while (next_token(&p, end, &token, &len)) {
        int64_t index, vt, vn;
        if (!parse_index(token, len, &index, &vt, &vn))
            return rs_fail_parse(error, line, token - st->data, where,
                                 "malformed face index '%.*s'", (int)(len > 40 ? 40 : len), token);
        int64_t vt_index, vn_index;
        rsmooth_status status =
            check_attribute_index(st, vt, "vt", st->vt_count, st->known_vt_count, &st->max_vt, line,
                                  token, &vt_index, error);
        if (status == RSMOOTH_OK)
            status = check_attribute_index(st, vn, "vn", st->vn_count, st->known_vn_count,
                                           &st->max_vn, line, token, &vn_index, error);
        if (status != RSMOOTH_OK)
            return status;
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
        if (vt_index >= 0 || st->any_vt) {
            status = record_vt(st, vt_index, error);
            if (status != RSMOOTH_OK)
                return status;
        }
        /* Out-of-range values are caught after the pass; UINT32_MAX is never a valid index. */
        st->indices.data[st->indices.count++] =
            zero_based >= (int64_t)UINT32_MAX ? UINT32_MAX : (uint32_t)zero_based;
    }
    if (p < end)
        st->kinds |= RS_OBJ_COMMENTS;
    *plain = p == end;
    size_t n = st->indices.count - first;
    if (n < 3)
        return rs_fail_parse(error, line, statement - st->data, where,
                             "face has %zu vertices (at least 3 needed)", n);
    if (!rs_io_u32vec_reserve(&st->offsets, 1))
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "%zu faces", st->offsets.count);
    st->offsets.data[st->offsets.count++] = (uint32_t)st->indices.count;
    return RSMOOTH_OK;
}

/* "vn x y z": three finite numbers (a point cloud's normals are its data; a mesh's are
 * recomputed on output, but a file holding others is not what it claims). */
static rsmooth_status parse_normal(obj_state *st, const char *p, const char *end, int64_t line,
                                   const char *statement, rsmooth_error *error) {
    const char *token;
    size_t len;
    int n = 0;
    for (; n < 3 && next_token(&p, end, &token, &len); n++) {
        double v;
        if (!rs_io_parse_double(token, len, &v))
            return rs_fail_parse(error, line, token - st->data, where, "malformed number '%.*s'",
                                 (int)(len > 40 ? 40 : len), token);
        if (!isfinite(v))
            return rs_fail_parse(error, line, token - st->data, where,
                                 "normal %zu has a non-finite component", st->vn_count);
    }
    if (n < 3 || next_token(&p, end, &token, &len))
        return rs_fail_parse(error, line, statement - st->data, where,
                             "normal %zu: 'vn' takes 3 numbers", st->vn_count);
    return RSMOOTH_OK;
}

/* The RS_OBJ_* kind of a statement other than v and f (counting vt lines on the way). */
static unsigned classify(obj_state *st, const char *s, size_t len) {
    if (len == 1) {
        switch (s[0]) {
        case 'g':
        case 'o':
            return RS_OBJ_GROUPS;
        case 's':
            return RS_OBJ_SMOOTHING;
        case 'l':
        case 'p':
            return RS_OBJ_LINES;
        default:
            return RS_OBJ_OTHER;
        }
    }
    if (len == 2 && s[0] == 'v' && s[1] == 't') {
        st->vt_count++;
        return RS_OBJ_TEXCOORDS;
    }
    if (len == 2 && s[0] == 'v' && s[1] == 'n') {
        st->vn_count++;
        return RS_OBJ_NORMALS;
    }
    if (len == 6 && (memcmp(s, "mtllib", 6) == 0 || memcmp(s, "usemtl", 6) == 0))
        return RS_OBJ_MATERIALS;
    return RS_OBJ_OTHER;
}

/* Adds the line [start, start + bytes) to the run structure as a line of `kind`. */
static bool add_line(obj_state *st, int kind, size_t start, size_t bytes) {
    rs_obj_run *last = st->run_count ? st->runs + st->run_count - 1 : NULL;
    if (last && last->kind == kind) {
        last->count += kind == RS_OBJ_RUN_TEXT ? bytes : 1;
        return true;
    }
    if (st->run_count == st->run_capacity) {
        size_t capacity = st->run_capacity ? 2 * st->run_capacity : 16;
        rs_obj_run *runs = rs_realloc_array(st->runs, capacity, sizeof *runs);
        if (!runs)
            return false;
        st->runs = runs;
        st->run_capacity = capacity;
    }
    st->runs[st->run_count++] =
        (rs_obj_run){.start = start, .count = kind == RS_OBJ_RUN_TEXT ? bytes : 1, .kind = kind};
    return true;
}

static rsmooth_status parse_all(obj_state *st, rsmooth_error *error) {
    const char *p = st->data, *end = st->data + st->size;
    if (!rs_io_u32vec_reserve(&st->offsets, 1))
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "face offsets");
    st->offsets.data[st->offsets.count++] = 0;
    for (int64_t line = 1; p < end; line++) {
        const char *eol = memchr(p, '\n', (size_t)(end - p));
        const char *line_end = eol ? eol : end;
        bool crlf = line_end > p && line_end[-1] == '\r';
        if (line == 1)
            st->crlf = crlf; /* the first line's end is the one plain lines are written with */
        const char *statement;
        size_t len;
        const char *q = p, *start = p;
        p = eol ? eol + 1 : end;
        st->last_line = line;
        int kind = RS_OBJ_RUN_TEXT;
        if (!next_token(&q, line_end, &statement, &len)) {
            if (q < line_end)
                st->kinds |= RS_OBJ_COMMENTS;
        } else {
            rsmooth_status status = RSMOOTH_OK;
            bool plain = false;
            if (len == 1 && statement[0] == 'v') {
                status = parse_vertex(st, q, line_end, line, statement, &plain, error);
                kind = RS_OBJ_RUN_V;
            } else if (len == 1 && statement[0] == 'f') {
                status = parse_face(st, q, line_end, line, statement, &plain, error);
                kind = RS_OBJ_RUN_F;
            } else {
                unsigned kind_bit = classify(st, statement, len);
                st->kinds |= kind_bit;
                if (kind_bit == RS_OBJ_NORMALS)
                    status = parse_normal(st, q, line_end, line, statement, error);
                if (kind_bit == RS_OBJ_OTHER && !st->unknown) {
                    st->unknown = statement;
                    st->unknown_len = len;
                    st->unknown_line = line;
                }
            }
            if (status != RSMOOTH_OK)
                return status;
            if (!plain || !eol || crlf != st->crlf)
                kind = RS_OBJ_RUN_TEXT;
        }
        if (!add_line(st, kind, (size_t)(start - st->data), (size_t)(p - start)))
            return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "line structure");
    }
    return RSMOOTH_OK;
}

static void free_state(obj_state *st) {
    rs_free(st->positions);
    rs_free(st->offsets.data);
    rs_free(st->indices.data);
    rs_free(st->corner_vt.data);
    rs_free(st->colors);
    rs_free(st->runs);
}

/* Hands the colours, the normals flag and (when the file held anything beyond v and f) the extras
 * record to the new mesh; frees what it does not hand over. */
static rsmooth_status attach_extras(obj_state *st, rsmooth_mesh *mesh, rsmooth_error *error) {
    mesh->has_vertex_normals = (st->kinds & RS_OBJ_NORMALS) != 0;
    if (st->colors) {
        uint8_t *colors = rs_realloc_array(st->colors, st->vertex_count, 3);
        mesh->vertex_colors = colors ? colors : st->colors;
        st->colors = NULL;
    }
    if (st->kinds == 0)
        return RSMOOTH_OK;
    size_t text_size = 0;
    for (size_t i = 0; i < st->run_count; i++)
        if (st->runs[i].kind == RS_OBJ_RUN_TEXT)
            text_size += st->runs[i].count;
    rs_obj_extras *x = rs_calloc_array(1, sizeof *x);
    struct rsmooth_mesh_extras *holder = x ? rs_io_mesh_extras(mesh) : NULL;
    if (x)
        x->text = rs_alloc_array(text_size, 1);
    if (!x || !holder || !x->text) {
        rs_io_obj_extras_free(x);
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "%zu bytes of OBJ extras",
                       text_size);
    }
    for (size_t i = 0; i < st->run_count; i++) {
        rs_obj_run *run = st->runs + i;
        if (run->kind == RS_OBJ_RUN_TEXT) {
            memcpy(x->text + x->size, st->data + run->start, run->count);
            run->start = x->size;
            x->size += run->count;
        }
    }
    rs_obj_run *runs = rs_realloc_array(st->runs, st->run_count, sizeof *runs);
    x->runs = runs ? runs : st->runs;
    x->run_count = st->run_count;
    st->runs = NULL;
    x->crlf = st->crlf;
    x->vertex_count = mesh->vertex_count;
    x->face_count = mesh->face_count;
    x->offsets_hash = rs_obj_offsets_hash(mesh->face_offsets, mesh->face_count);
    x->corner_vt = st->corner_vt.data;
    st->corner_vt.data = NULL;
    x->kinds = st->kinds;
    holder->obj = x;
    return RSMOOTH_OK;
}

/* A point cloud's normals: with no faces to say which vn goes with which v, the i-th vn line is
 * taken as the i-th vertex's normal when there are as many vn as v (what point-cloud exporters
 * write). NULL otherwise, or when out of memory (the normals are optional). */
static double *point_cloud_normals(const char *data, size_t size, size_t vertex_count) {
    double *normals = rs_alloc_array(vertex_count, 3 * sizeof(double));
    size_t found = 0;
    const char *p = data, *end = data + size;
    while (normals && p < end) {
        const char *eol = memchr(p, '\n', (size_t)(end - p));
        const char *line_end = eol ? eol : end, *token;
        size_t len;
        if (next_token(&p, line_end, &token, &len) && len == 2 && token[0] == 'v' &&
            token[1] == 'n') {
            double n[3];
            int k = 0;
            while (k < 3 && next_token(&p, line_end, &token, &len) &&
                   rs_io_parse_double(token, len, &n[k]))
                k++;
            if (k < 3 || found == vertex_count) { /* malformed, or more vn than v */
                rs_free(normals);
                return NULL;
            }
            memcpy(normals + 3 * found++, n, sizeof n);
        }
        p = eol ? eol + 1 : end;
    }
    if (found != vertex_count) {
        rs_free(normals);
        return NULL;
    }
    return normals;
}

/* A file without a vertex: blamed on its first statement OBJ does not know (the likeliest sign
 * that it is something else), else on its end. */
static rsmooth_status no_vertices(const obj_state *st, rsmooth_error *error) {
    if (st->unknown)
        return rs_fail_parse(error, st->unknown_line, st->unknown - st->data, where,
                             "no vertices (no 'v x y z' line), and '%.*s' is not an OBJ statement",
                             (int)(st->unknown_len > 40 ? 40 : st->unknown_len), st->unknown);
    return rs_fail_parse(error, st->last_line > 0 ? st->last_line : 1, (int64_t)st->size, where,
                         "no vertices: the file ends (line %lld) without a 'v x y z' line",
                         (long long)(st->last_line > 0 ? st->last_line : 1));
}

rsmooth_status rs_io_obj_read(const char *data, size_t size, rsmooth_mesh **mesh,
                              rsmooth_error *error) {
    obj_state st = {.data = data,
                    .size = size,
                    .known_vertex_count = -1,
                    .known_vt_count = -1,
                    .known_vn_count = -1};
    rsmooth_status status = parse_all(&st, error);
    if (status == RSMOOTH_OK && st.vertex_count == 0)
        status = no_vertices(&st, error);
    if (status == RSMOOTH_OK &&
        ((st.indices.count > 0 && st.max_index >= st.vertex_count) ||
         st.max_vt > (int64_t)st.vt_count || st.max_vn > (int64_t)st.vn_count)) {
        /* Rare error path: parse again, checking each index against the final counts, so the
         * error names the line of the first offending face. */
        obj_state again = {.data = data,
                           .size = size,
                           .known_vertex_count = (int64_t)st.vertex_count,
                           .known_vt_count = (int64_t)st.vt_count,
                           .known_vn_count = (int64_t)st.vn_count};
        status = parse_all(&again, error);
        free_state(&again);
        if (status == RSMOOTH_OK) /* unreachable unless the two passes disagree */
            status = rs_fail_parse(error, st.last_line, (int64_t)size, where,
                                   "face index out of range (%zu vertices)", st.vertex_count);
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
    st.positions = NULL; /* adopted (or freed) below */
    uint32_t *offsets = st.offsets.data;
    st.offsets.data = NULL;
    st.indices.data = NULL;
    status = rs_io_mesh_adopt(positions, st.vertex_count, RSMOOTH_FLOAT64, offsets, face_count,
                              indices, RSMOOTH_FORMAT_OBJ, mesh, error);
    if (status == RSMOOTH_OK) {
        status = attach_extras(&st, *mesh, error);
        if (status != RSMOOTH_OK) {
            rsmooth_mesh_destroy(*mesh);
            *mesh = NULL;
        }
    }
    if (status == RSMOOTH_OK && face_count == 0 && (*mesh)->has_vertex_normals)
        (*mesh)->vertex_normals = point_cloud_normals(data, size, st.vertex_count);
    free_state(&st);
    return status;
}
