/* OFF reader (OFF, COFF, NOFF, CNOFF, STOFF and their combinations); its extras record is released
 * and reported in off_extras.c. */
#include "io/off_format.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

static const char where[] = "rsmooth_mesh_read (OFF)";

/* Lines hold whitespace-separated tokens; '#' starts a comment. */
typedef struct off_reader {
    const char *data, *p, *end;
    int64_t line; /* of the line last returned by next_line */
} off_reader;

static bool is_space(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

/* The next line holding a token, as [*begin, *stop) with any comment cut off; false at the end. */
static bool next_line(off_reader *r, const char **begin, const char **stop) {
    while (r->p < r->end) {
        const char *eol = memchr(r->p, '\n', (size_t)(r->end - r->p));
        const char *line_end = eol ? eol : r->end;
        const char *s = r->p;
        r->p = eol ? eol + 1 : r->end;
        r->line++;
        const char *hash = memchr(s, '#', (size_t)(line_end - s));
        if (hash)
            line_end = hash;
        while (s < line_end && is_space(*s))
            s++;
        if (s < line_end) {
            *begin = s;
            *stop = line_end;
            return true;
        }
    }
    r->line++; /* the errors for a missing line name the one after the last */
    return false;
}

static bool next_token(const char **p, const char *end, const char **token, size_t *len) {
    const char *s = *p;
    while (s < end && is_space(*s))
        s++;
    if (s == end)
        return false;
    *token = s;
    while (s < end && !is_space(*s))
        s++;
    *len = (size_t)(s - *token);
    *p = s;
    return true;
}

/* A decimal integer (optional sign), saturating far beyond any valid count or index. */
static bool parse_int(const char *s, size_t len, int64_t *out) {
    size_t i = 0;
    bool negative = false;
    if (i < len && (s[i] == '-' || s[i] == '+')) {
        negative = s[i] == '-';
        i++;
    }
    if (i == len)
        return false;
    int64_t v = 0;
    for (; i < len; i++) {
        if (s[i] < '0' || s[i] > '9')
            return false;
        if (v < INT64_MAX / 100)
            v = v * 10 + (s[i] - '0');
    }
    *out = negative ? -v : v;
    return true;
}

#define TOKEN_TEXT(t, len) (int)((len) > 40 ? 40 : (len)), (t)

static bool texts_append(rs_off_texts *texts, size_t index, size_t count, const char *s,
                         size_t len) {
    if (!texts->offsets) {
        if (len == 0)
            return true;
        texts->offsets = rs_calloc_array(count + 1, sizeof(size_t)); /* earlier ones: empty */
        if (!texts->offsets)
            return false;
    }
    if (texts->capacity - texts->size < len) {
        size_t capacity = texts->capacity ? texts->capacity : 256;
        while (capacity - texts->size < len) {
            if (capacity > SIZE_MAX / 2)
                return false;
            capacity *= 2;
        }
        char *text = rs_realloc_array(texts->text, capacity, 1);
        if (!text)
            return false;
        texts->text = text;
        texts->capacity = capacity;
    }
    if (len)
        memcpy(texts->text + texts->size, s, len);
    texts->size += len;
    texts->offsets[index + 1] = texts->size;
    return true;
}

/* What the header says. */
typedef struct off_header {
    char keyword[16];
    bool st, c, n;
    uint64_t vertex_count, face_count, edge_count;
} off_header;

/* Parses "vertices faces [edges]" from [p, stop). */
static rsmooth_status parse_counts(off_reader *r, const char *p, const char *stop, off_header *h,
                                   rsmooth_error *error) {
    const char *token;
    size_t len;
    uint64_t counts[3] = {0, 0, 0};
    int n = 0;
    while (next_token(&p, stop, &token, &len)) {
        int64_t v;
        if (n == 3)
            return rs_fail_parse(error, r->line, token - r->data, where,
                                 "unexpected '%.*s' after the vertex, face and edge counts",
                                 TOKEN_TEXT(token, len));
        if (!parse_int(token, len, &v) || v < 0)
            return rs_fail_parse(error, r->line, token - r->data, where,
                                 "malformed count '%.*s' (a non-negative integer expected)",
                                 TOKEN_TEXT(token, len));
        counts[n++] = (uint64_t)v;
    }
    if (n < 2)
        return rs_fail_parse(error, r->line, p - r->data, where,
                             "expected the vertex and face counts");
    h->vertex_count = counts[0];
    h->face_count = counts[1];
    h->edge_count = counts[2];
    return RSMOOTH_OK;
}

/* A variant this reader does not read: RSMOOTH_ERROR_UNSUPPORTED, located at `token`. */
static rsmooth_status unsupported(const off_reader *r, const char *token, rsmooth_error *error,
                                  const char *format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;
static rsmooth_status unsupported(const off_reader *r, const char *token, rsmooth_error *error,
                                  const char *format, ...) {
    if (!error)
        return RSMOOTH_ERROR_UNSUPPORTED;
    char message[sizeof error->message];
    va_list args;
    va_start(args, format);
    vsnprintf(message, sizeof message, format, args);
    va_end(args);
    rs_fail(error, RSMOOTH_ERROR_UNSUPPORTED, where, "%s", message);
    error->line = r->line; /* rs_fail leaves the location to parse errors */
    error->byte_offset = token - r->data;
    return RSMOOTH_ERROR_UNSUPPORTED;
}

static rsmooth_status parse_header(off_reader *r, off_header *h, rsmooth_error *error) {
    const char *p, *stop, *token;
    size_t len;
    if (!next_line(r, &p, &stop) || !next_token(&p, stop, &token, &len))
        return rs_fail_parse(error, r->line, -1, where, "missing OFF header (empty file)");
    /* [ST][C][N][4][n]OFF */
    size_t i = 0;
    bool four = false, dim = false;
    if (len >= 2 && token[0] == 'S' && token[1] == 'T') {
        h->st = true;
        i = 2;
    }
    if (i < len && token[i] == 'C') {
        h->c = true;
        i++;
    }
    if (i < len && token[i] == 'N') {
        h->n = true;
        i++;
    }
    if (i < len && token[i] == '4') {
        four = true;
        i++;
    }
    if (i < len && token[i] == 'n') {
        dim = true;
        i++;
    }
    /* "off" in any case: some writers use lowercase (the prefix letters keep their case: 'n' is
     * the dimension prefix, 'N' normals) */
    bool off = len - i == 3 && (token[i] | 0x20) == 'o' && (token[i + 1] | 0x20) == 'f' &&
               (token[i + 2] | 0x20) == 'f';
    if (!off)
        return rs_fail_parse(error, r->line, token - r->data, where,
                             "missing OFF header: the file starts with '%.*s', not OFF, COFF, "
                             "NOFF, CNOFF, STOFF or a combination",
                             TOKEN_TEXT(token, len));
    if (four || dim)
        return unsupported(r, token, error, "%.*s: %s vertices are not supported (only 3D OFF)",
                           TOKEN_TEXT(token, len), dim ? "n-dimensional" : "4-dimensional");
    memcpy(h->keyword, token, len);
    h->keyword[len] = '\0';
    const char *rest = p;
    if (next_token(&p, stop, &token, &len)) {
        if (len == 6 && memcmp(token, "BINARY", 6) == 0)
            return unsupported(r, token, error, "binary OFF is not supported");
        return parse_counts(r, rest, stop, h, error); /* the counts on the keyword's line */
    }
    if (!next_line(r, &p, &stop))
        return rs_fail_parse(error, r->line, -1, where,
                             "the file ends before the vertex and face counts");
    return parse_counts(r, p, stop, h, error);
}

/* The parse in progress; freed whole on failure. */
typedef struct off_state {
    double *positions;
    double *normals;   /* NOFF: 3 per vertex as written */
    float *raw_colors; /* 3 per vertex as written; bytes once the file's convention is known */
    bool color_above_one;
    uint32_t *offsets;
    rs_io_u32vec indices;
    rs_off_extras *extras;
} off_state;

static void free_state(off_state *st) {
    rs_free(st->positions);
    rs_free(st->normals);
    rs_free(st->raw_colors);
    rs_free(st->offsets);
    rs_free(st->indices.data);
    rs_io_off_extras_free(st->extras);
}

/* The most values a line may hold: x y z nx ny nz r g b a s t. */
#define MAX_TOKENS 12

/* The tokens of a line from p up to stop, at most MAX_TOKENS; *count is how many there are, and
 * *beyond the first one past MAX_TOKENS (or NULL). */
static void split_line(const char *p, const char *stop, const char **tokens, size_t *lens,
                       int *count, const char **beyond) {
    const char *token;
    size_t len;
    *count = 0;
    *beyond = NULL;
    while (next_token(&p, stop, &token, &len)) {
        if (*count == MAX_TOKENS) {
            *beyond = token;
            return;
        }
        tokens[*count] = token;
        lens[(*count)++] = len;
    }
}

/* A colour component as OFF writes them: integers 0 to 255 or floats 0 to 1 (the file's values
 * tell which), so anything outside [0, 255] is no colour. */
static rsmooth_status check_color(const off_reader *r, const char *token, size_t len, double c,
                                  const char *what, size_t number, rsmooth_error *error) {
    if (!isfinite(c))
        return rs_fail_parse(error, r->line, token - r->data, where,
                             "%s %zu has a non-finite colour", what, number);
    if (c < 0 || c > 255)
        return rs_fail_parse(error, r->line, token - r->data, where,
                             "%s %zu: colour component '%.*s' outside 0 to 255 (integer colours) "
                             "or 0 to 1 (float colours)",
                             what, number, TOKEN_TEXT(token, len));
    return RSMOOTH_OK;
}

/* What a vertex line of this variant holds: "x y z[ nx ny nz][ r g b [a]][ s t]". */
static void vertex_layout(const off_header *h, char *text, size_t size) {
    snprintf(text, size, "x y z%s%s%s", h->n ? " nx ny nz" : "", h->c ? " r g b [a]" : "",
             h->st ? " s t" : "");
}

static rsmooth_status parse_vertex(off_reader *r, const off_header *h, off_state *st, size_t v,
                                   rsmooth_error *error) {
    const char *p, *stop;
    if (!next_line(r, &p, &stop))
        return rs_fail_parse(error, r->line, -1, where,
                             "the file ends after %zu of %llu vertices (fewer than declared)", v,
                             (unsigned long long)h->vertex_count);
    const char *tokens[MAX_TOKENS], *beyond;
    size_t lens[MAX_TOKENS];
    int count;
    split_line(p, stop, tokens, lens, &count, &beyond);
    /* Exactly what the keyword declares: x y z, nx ny nz (N), r g b or r g b a (C), s t (ST).
     * Anything more is no OFF (a stray value, or two lines run together by a lone CR). */
    int base = h->n ? 6 : 3, tail = h->st ? 2 : 0;
    int least = base + (h->c ? 3 : 0) + tail, most = least + (h->c ? 1 : 0);
    if (count < least || count > most || beyond) {
        char layout[64];
        vertex_layout(h, layout, sizeof layout);
        const char *at = beyond ? beyond : count > most ? tokens[most] : tokens[0];
        char declared[32];
        if (least == most)
            snprintf(declared, sizeof declared, "%d", least);
        else
            snprintf(declared, sizeof declared, "%d or %d", least, most);
        return rs_fail_parse(error, r->line, at - r->data, where,
                             "vertex %zu has %s%d values (%s declares %s: %s)", v,
                             beyond ? "more than " : "", count, h->keyword, declared, layout);
    }
    double values[MAX_TOKENS];
    for (int k = 0; k < count; k++)
        if (!rs_io_parse_double(tokens[k], lens[k], &values[k]))
            return rs_fail_parse(error, r->line, tokens[k] - r->data, where,
                                 "vertex %zu: malformed number '%.*s'", v,
                                 TOKEN_TEXT(tokens[k], lens[k]));
    rsmooth_status status =
        rs_io_check_vertex(values, v, r->line, tokens[0] - r->data, where, error);
    if (status != RSMOOTH_OK)
        return status;
    if (h->n && (!isfinite(values[3]) || !isfinite(values[4]) || !isfinite(values[5])))
        return rs_fail_parse(error, r->line, tokens[3] - r->data, where,
                             "vertex %zu has a non-finite normal", v);
    memcpy(st->positions + 3 * v, values, 3 * sizeof(double));
    if (h->n)
        memcpy(st->normals + 3 * v, values + 3, 3 * sizeof(double));
    int components = count - base - tail;
    for (int k = 0; k < components; k++) {
        status =
            check_color(r, tokens[base + k], lens[base + k], values[base + k], "vertex", v, error);
        if (status != RSMOOTH_OK)
            return status;
        if (values[base + k] > 1) /* "r g b 255": integer colours */
            st->color_above_one = true;
        if (k < 3)
            st->raw_colors[3 * v + (size_t)k] = (float)values[base + k];
    }
    if (components == 4)
        st->extras->alpha = true;
    for (int k = count - tail; k < count; k++)
        if (!isfinite(values[k]))
            return rs_fail_parse(error, r->line, tokens[k] - r->data, where,
                                 "vertex %zu has a non-finite texture coordinate", v);
    if (count > base) { /* colour and texture coordinates, kept as written */
        const char *from = tokens[base];
        const char *last_end = tokens[count - 1] + lens[count - 1];
        if (!texts_append(&st->extras->vertex, v, h->vertex_count, from, (size_t)(last_end - from)))
            return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "OFF vertex extras");
    } else if (st->extras->vertex.offsets) {
        texts_append(&st->extras->vertex, v, h->vertex_count, "", 0);
    }
    return RSMOOTH_OK;
}

/* What may follow a face's indices (Geomview's OFF): nothing, a colormap index, or a colour of 3
 * or 4 components (integers 0 to 255 or floats 0 to 1). */
static rsmooth_status check_face_color(const off_reader *r, size_t f, const char *p,
                                       const char *stop, const char **from, const char **last_end,
                                       rsmooth_error *error) {
    const char *tokens[MAX_TOKENS], *beyond;
    size_t lens[MAX_TOKENS];
    int count;
    split_line(p, stop, tokens, lens, &count, &beyond);
    *from = *last_end = NULL;
    if (count == 0)
        return RSMOOTH_OK;
    if (count == 2 || count > 4)
        return rs_fail_parse(error, r->line, (count == 2 ? tokens[0] : tokens[4]) - r->data, where,
                             "face %zu has %s%d values after its indices (a face colour is a "
                             "colormap index, or r g b [a])",
                             f, beyond ? "more than " : "", count);
    for (int k = 0; k < count; k++) {
        double c;
        if (!rs_io_parse_double(tokens[k], lens[k], &c))
            return rs_fail_parse(error, r->line, tokens[k] - r->data, where,
                                 "face %zu: malformed colour '%.*s'", f,
                                 TOKEN_TEXT(tokens[k], lens[k]));
        int64_t index;
        if (count == 1 && !(parse_int(tokens[k], lens[k], &index) && index >= 0))
            return rs_fail_parse(error, r->line, tokens[k] - r->data, where,
                                 "face %zu: colormap index '%.*s' is not a whole number >= 0", f,
                                 TOKEN_TEXT(tokens[k], lens[k]));
        rsmooth_status status =
            count == 1 ? RSMOOTH_OK : check_color(r, tokens[k], lens[k], c, "face", f, error);
        if (status != RSMOOTH_OK)
            return status;
    }
    *from = tokens[0];
    *last_end = tokens[count - 1] + lens[count - 1];
    return RSMOOTH_OK;
}

static rsmooth_status parse_face(off_reader *r, const off_header *h, off_state *st, size_t f,
                                 rsmooth_error *error) {
    const char *p, *stop, *token = NULL;
    size_t len = 0;
    if (!next_line(r, &p, &stop))
        return rs_fail_parse(error, r->line, -1, where,
                             "the file ends after %zu of %llu faces (fewer than declared)", f,
                             (unsigned long long)h->face_count);
    int64_t n;
    if (!next_token(&p, stop, &token, &len) || !parse_int(token, len, &n))
        return rs_fail_parse(error, r->line, token - r->data, where,
                             "face %zu: malformed vertex count '%.*s'", f, TOKEN_TEXT(token, len));
    if (n < 3)
        return rs_fail_parse(error, r->line, token - r->data, where,
                             "face %zu has %lld vertices (at least 3 needed)", f, (long long)n);
    for (int64_t k = 0; k < n; k++) {
        if (!next_token(&p, stop, &token, &len))
            return rs_fail_parse(error, r->line, p - r->data, where,
                                 "face %zu lists %lld of its %lld vertices", f, (long long)k,
                                 (long long)n);
        int64_t index;
        if (!parse_int(token, len, &index))
            return rs_fail_parse(error, r->line, token - r->data, where,
                                 "face %zu: malformed index '%.*s'", f, TOKEN_TEXT(token, len));
        if (index < 0 || (uint64_t)index >= h->vertex_count)
            return rs_fail_parse(error, r->line, token - r->data, where,
                                 "face %zu: index %lld out of range (%llu vertices)", f,
                                 (long long)index, (unsigned long long)h->vertex_count);
        if (st->indices.count + 1 >= RS_IO_MAX_FACE_INDICES)
            return rs_fail_parse(error, r->line, token - r->data, where,
                                 "too many face indices (offsets are 32-bit)");
        if (!rs_io_u32vec_reserve(&st->indices, 1))
            return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "%zu face indices",
                           st->indices.count + 1);
        st->indices.data[st->indices.count++] = (uint32_t)index;
    }
    st->offsets[f + 1] = (uint32_t)st->indices.count;
    /* A face colour (r g b [a] or a colormap index), kept as written. */
    const char *from, *last_end;
    rsmooth_status status = check_face_color(r, f, p, stop, &from, &last_end, error);
    if (status != RSMOOTH_OK)
        return status;
    bool ok =
        from ? texts_append(&st->extras->face, f, h->face_count, from, (size_t)(last_end - from))
             : texts_append(&st->extras->face, f, h->face_count, "", 0);
    if (!ok)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "OFF face colours");
    return RSMOOTH_OK;
}

/* Past the declared faces only blanks and comments may follow: anything else (another face, a
 * count too low) would be silently dropped. */
static rsmooth_status check_end(off_reader *r, const off_header *h, rsmooth_error *error) {
    const char *p, *stop, *token;
    size_t len;
    if (!next_line(r, &p, &stop) || !next_token(&p, stop, &token, &len))
        return RSMOOTH_OK;
    return rs_fail_parse(error, r->line, token - r->data, where,
                         "'%.*s' after the %llu vertices and %llu faces the header declares (only "
                         "comments may follow)",
                         TOKEN_TEXT(token, len), (unsigned long long)h->vertex_count,
                         (unsigned long long)h->face_count);
}

/* Colours as bytes: integers 0..255 when any value exceeds 1 (whether written "255" or "255.0"),
 * else floats in [0, 1]; a file of only 0 and 1 reads as floats, as Geomview defines colours. */
static uint8_t *color_bytes(const off_state *st, size_t vertex_count) {
    uint8_t *bytes = rs_alloc_array(vertex_count, 3);
    if (!bytes)
        return NULL;
    bool integers = st->color_above_one;
    for (size_t i = 0; i < 3 * vertex_count; i++) {
        double c = st->raw_colors[i];
        if (!integers)
            c *= 255;
        bytes[i] = !(c > 0) ? 0 : c >= 255 ? 255 : (uint8_t)(c + 0.5);
    }
    return bytes;
}

rsmooth_status rs_io_off_read(const char *data, size_t size, rsmooth_mesh **mesh,
                              rsmooth_error *error) {
    off_reader r = {.data = data, .p = data, .end = data + size, .line = 0};
    off_header h = {.keyword = {0}};
    rsmooth_status status = parse_header(&r, &h, error);
    if (status != RSMOOTH_OK)
        return status;
    if (h.vertex_count == 0)
        return rs_fail_parse(error, r.line, -1, where, "no vertices (an empty mesh)");
    /* Every vertex takes at least "0 0 0\n" and every face "3 0 1 2\n": refuse counts the rest of
     * the file cannot hold before allocating for them (the last line may lack its newline). */
    uint64_t remaining = (uint64_t)(r.end - r.p) + 1;
    if (h.vertex_count >= RS_IO_MAX_VERTICES || h.vertex_count > remaining / 6 ||
        h.face_count > (remaining - 6 * h.vertex_count) / 8)
        return rs_fail_parse(error, r.line, -1, where,
                             "%llu vertices and %llu faces declared, more than the remaining "
                             "%llu bytes can hold",
                             (unsigned long long)h.vertex_count, (unsigned long long)h.face_count,
                             (unsigned long long)(remaining - 1));
    size_t nv = (size_t)h.vertex_count, nf = (size_t)h.face_count;
    off_state st = {0};
    st.positions = rs_alloc_array(nv, 3 * sizeof(double));
    st.offsets = rs_calloc_array(nf + 1, sizeof(uint32_t));
    st.extras = rs_calloc_array(1, sizeof *st.extras);
    if (h.c)
        st.raw_colors = rs_alloc_array(nv, 3 * sizeof(float));
    if (h.n)
        st.normals = rs_alloc_array(nv, 3 * sizeof(double));
    if (!st.positions || !st.offsets || !st.extras || (h.c && !st.raw_colors) ||
        (h.n && !st.normals) ||
        !rs_io_u32vec_reserve(&st.indices, nf < SIZE_MAX / 3 ? 3 * nf : nf)) {
        free_state(&st);
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "%zu vertices, %zu faces", nv,
                       nf);
    }
    for (size_t v = 0; status == RSMOOTH_OK && v < nv; v++)
        status = parse_vertex(&r, &h, &st, v, error);
    for (size_t f = 0; status == RSMOOTH_OK && f < nf; f++)
        status = parse_face(&r, &h, &st, f, error);
    if (status == RSMOOTH_OK)
        status = check_end(&r, &h, error);
    uint8_t *colors = NULL;
    if (status == RSMOOTH_OK && h.c && !(colors = color_bytes(&st, nv)))
        status = rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "vertex colours");
    if (status != RSMOOTH_OK) {
        free_state(&st);
        return status;
    }
    rs_off_extras *x = st.extras;
    st.extras = NULL;
    memcpy(x->keyword, h.keyword, sizeof x->keyword);
    x->normals = h.n;
    x->texcoords = h.st;
    x->vertex_count = nv;
    x->face_count = nf;
    x->edge_count = h.edge_count;
    uint32_t *indices = st.indices.data ? st.indices.data : rs_alloc_array(1, sizeof(uint32_t));
    rs_free(st.raw_colors);
    status = rs_io_mesh_adopt(st.positions, nv, RSMOOTH_FLOAT64, st.offsets, nf, indices,
                              RSMOOTH_FORMAT_OFF, mesh, error);
    if (status != RSMOOTH_OK) {
        rs_free(colors);
        rs_free(st.normals);
        rs_io_off_extras_free(x);
        return status;
    }
    (*mesh)->vertex_colors = colors;
    (*mesh)->has_vertex_normals = h.n;
    (*mesh)->vertex_normals = st.normals;
    st.normals = NULL;
    /* Kept only when there is something the generic writer would not reproduce. */
    if (x->vertex.offsets || x->face.offsets) {
        struct rsmooth_mesh_extras *holder = rs_io_mesh_extras(*mesh);
        if (!holder) {
            rs_io_off_extras_free(x);
            rsmooth_mesh_destroy(*mesh);
            *mesh = NULL;
            return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "OFF extras");
        }
        holder->off = x;
    } else {
        rs_io_off_extras_free(x);
    }
    return RSMOOTH_OK;
}
