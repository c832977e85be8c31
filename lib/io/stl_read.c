/* STL reader (ascii and binary): the triangles as an unindexed soup, the header and attributes as
 * extras. */
#include "io/stl_format.h"

#include <math.h>
#include <string.h>

static const char where[] = "rsmooth_mesh_read (STL)";

/* ---- the soup both encodings build */

typedef struct stl_soup {
    double *positions; /* 9 per triangle */
    size_t triangle_count;
    size_t capacity; /* in triangles */
    rs_stl_extras *extras;
    size_t solid_capacity; /* of extras->solids */
} stl_soup;

static void soup_free(stl_soup *soup) {
    rs_free(soup->positions);
    rs_io_stl_extras_free(soup->extras);
    memset(soup, 0, sizeof *soup);
}

static bool soup_reserve(stl_soup *soup, size_t triangles) {
    if (triangles <= soup->capacity)
        return true;
    if (triangles > RS_STL_MAX_TRIANGLES || rs_mul_overflows(triangles, 9 * sizeof(double)))
        return false;
    double *p = rs_realloc_array(soup->positions, triangles, 9 * sizeof(double));
    if (!p)
        return false;
    soup->positions = p;
    soup->capacity = triangles;
    return true;
}

/* Hands the soup to a new mesh: face i is (3i, 3i+1, 3i+2). */
static rsmooth_status soup_finish(stl_soup *soup, rsmooth_scalar precision, rsmooth_format format,
                                  rsmooth_mesh **mesh, rsmooth_error *error) {
    size_t t = soup->triangle_count; /* <= RS_STL_MAX_TRIANGLES: 3 t + 1 fits uint32 */
    uint32_t *offsets = NULL, *indices = NULL;
    if (!rs_mul_overflows(t, 3 * sizeof(uint32_t))) {
        offsets = rs_alloc_array(t + 1, sizeof(uint32_t));
        indices = rs_alloc_array(t, 3 * sizeof(uint32_t));
    }
    if (!offsets || !indices) {
        rs_free(offsets);
        rs_free(indices);
        soup_free(soup);
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "faces of %zu triangles", t);
    }
    for (size_t i = 0; i <= t; i++)
        offsets[i] = (uint32_t)(3 * i);
    for (size_t i = 0; i < 3 * t; i++)
        indices[i] = (uint32_t)i;
    rsmooth_status status = rs_io_mesh_adopt(soup->positions, 3 * t, precision, offsets, t, indices,
                                             format, mesh, error);
    soup->positions = NULL; /* adopted, or freed on failure */
    if (status == RSMOOTH_OK && soup->extras) {
        struct rsmooth_mesh_extras *extras = rs_io_mesh_extras(*mesh);
        if (!extras) {
            rsmooth_mesh_destroy(*mesh);
            *mesh = NULL;
            soup_free(soup);
            return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "extras record");
        }
        extras->stl = soup->extras;
        soup->extras = NULL;
    }
    soup_free(soup);
    return status;
}

/* ---- binary */

static uint32_t get_u32(const unsigned char *p) {
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static float get_f32(const unsigned char *p) {
    uint32_t bits = get_u32(p);
    float f;
    memcpy(&f, &bits, sizeof f);
    return f;
}

static rsmooth_status read_binary(const unsigned char *data, size_t size, rsmooth_mesh **mesh,
                                  rsmooth_error *error) {
    if (size < RS_STL_HEADER_SIZE + 4)
        return rs_fail_parse(error, -1, (int64_t)size, where,
                             "binary STL: at least 84 bytes expected (an 80-byte header and the "
                             "triangle count), %zu found",
                             size);
    uint32_t declared = get_u32(data + RS_STL_HEADER_SIZE);
    uint64_t need = RS_STL_HEADER_SIZE + 4 + (uint64_t)RS_STL_RECORD_SIZE * declared;
    if (need != (uint64_t)size) /* located where the data ends early, or where the excess starts */
        return rs_fail_parse(error, -1, (int64_t)(size < need ? size : need), where,
                             "binary STL of %lu triangles (the count at byte 80): 84 + 50 × %lu = "
                             "%llu bytes expected, %zu found",
                             (unsigned long)declared, (unsigned long)declared,
                             (unsigned long long)need, size);
    if (declared == 0)
        return rs_fail_parse(error, -1, RS_STL_HEADER_SIZE, where,
                             "no triangles (the count at byte 80 is 0)");
    if ((size_t)declared > RS_STL_MAX_TRIANGLES)
        return rs_fail_parse(error, -1, RS_STL_HEADER_SIZE, where,
                             "binary STL declares %lu triangles: more than %zu (3 vertices each, "
                             "fewer than 2^32 in all)",
                             (unsigned long)declared, RS_STL_MAX_TRIANGLES);
    size_t t = declared;
    stl_soup soup = {0};
    if (!soup_reserve(&soup, t))
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "%zu triangles", t);
    bool any_attribute = false;
    for (size_t i = 0; i < t; i++) {
        const unsigned char *record = data + RS_STL_HEADER_SIZE + 4 + RS_STL_RECORD_SIZE * i;
        double *xyz = soup.positions + 9 * i;
        for (int k = 0; k < 9; k++) {
            /* record + 12 skips the facet normal: it is recomputed from the vertices. */
            float f = get_f32(record + 12 + 4 * k);
            if (!isfinite(f)) {
                soup_free(&soup);
                return rs_fail_parse(error, -1, (int64_t)(record - data) + 12 + 12 * (k / 3), where,
                                     "facet %zu has a non-finite vertex", i);
            }
            xyz[k] = f;
        }
        any_attribute = any_attribute || record[48] != 0 || record[49] != 0;
    }
    soup.triangle_count = t;
    const unsigned char *header = data;
    if (any_attribute || !rs_stl_header_is_blank(header)) {
        soup.extras = rs_calloc_array(1, sizeof *soup.extras);
        if (!soup.extras) {
            soup_free(&soup);
            return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "STL extras");
        }
        soup.extras->binary = true;
        soup.extras->triangle_count = t;
        memcpy(soup.extras->header, header, RS_STL_HEADER_SIZE);
        if (any_attribute) {
            uint16_t *attributes = rs_alloc_array(t, sizeof(uint16_t));
            if (!attributes) {
                soup_free(&soup);
                return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "%zu facet attributes",
                               t);
            }
            for (size_t i = 0; i < t; i++) {
                const unsigned char *a =
                    data + RS_STL_HEADER_SIZE + 4 + RS_STL_RECORD_SIZE * i + 48;
                attributes[i] = (uint16_t)(a[0] | a[1] << 8);
            }
            soup.extras->attributes = attributes;
        }
    }
    return soup_finish(&soup, RSMOOTH_FLOAT32, RSMOOTH_FORMAT_STL_BINARY, mesh, error);
}

/* ---- ascii */

typedef struct stl_lexer {
    const char *data;
    size_t size;
    size_t pos;
    int64_t line; /* of the last token returned */
    const char *token;
    size_t len;
    size_t token_pos;
} stl_lexer;

static bool is_space(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f';
}

/* Next whitespace-separated token; false at the end of the data. */
static bool next_token(stl_lexer *lx) {
    while (lx->pos < lx->size && is_space(lx->data[lx->pos])) {
        if (lx->data[lx->pos] == '\n')
            lx->line++;
        lx->pos++;
    }
    if (lx->pos == lx->size) {
        lx->token = lx->data + lx->size;
        lx->len = 0;
        lx->token_pos = lx->size;
        return false;
    }
    lx->token_pos = lx->pos;
    lx->token = lx->data + lx->pos;
    while (lx->pos < lx->size && !is_space(lx->data[lx->pos]))
        lx->pos++;
    lx->len = lx->pos - lx->token_pos;
    return true;
}

/* The rest of the current line, blanks trimmed (the solid's name); leaves pos at the newline. */
static void rest_of_line(stl_lexer *lx, const char **text, size_t *len) {
    size_t begin = lx->pos;
    while (lx->pos < lx->size && lx->data[lx->pos] != '\n')
        lx->pos++;
    size_t end = lx->pos;
    while (begin < end && is_space(lx->data[begin]))
        begin++;
    while (end > begin && is_space(lx->data[end - 1]))
        end--;
    *text = lx->data + begin;
    *len = end - begin;
}

static bool keyword_is(const stl_lexer *lx, const char *word) {
    size_t n = strlen(word);
    if (lx->len != n)
        return false;
    for (size_t i = 0; i < n; i++) {
        char c = lx->token[i];
        if (c >= 'A' && c <= 'Z')
            c = (char)(c - 'A' + 'a');
        if (c != word[i])
            return false;
    }
    return true;
}

static rsmooth_status expected(const stl_lexer *lx, const char *word, rsmooth_error *error) {
    if (lx->len == 0)
        return rs_fail_parse(error, lx->line, (int64_t)lx->token_pos, where,
                             "data ends where '%s' was expected", word);
    if (lx->token[0] == '#') /* some tools comment STL files: say why it is refused */
        return rs_fail_parse(error, lx->line, (int64_t)lx->token_pos, where,
                             "a '#' comment where '%s' was expected: ascii STL has no comments "
                             "(remove the line to read the file)",
                             word);
    return rs_fail_parse(error, lx->line, (int64_t)lx->token_pos, where,
                         "expected '%s', found '%.*s'", word, (int)(lx->len > 40 ? 40 : lx->len),
                         lx->token);
}

/* Reads the next token, which must be `word` (any case). */
static rsmooth_status expect_keyword(stl_lexer *lx, const char *word, rsmooth_error *error) {
    if (!next_token(lx) || !keyword_is(lx, word))
        return expected(lx, word, error);
    return RSMOOTH_OK;
}

static rsmooth_status read_number(stl_lexer *lx, double *out, rsmooth_error *error) {
    if (!next_token(lx))
        return rs_fail_parse(error, lx->line, (int64_t)lx->token_pos, where,
                             "data ends where a number was expected");
    if (!rs_io_parse_double(lx->token, lx->len, out))
        return rs_fail_parse(error, lx->line, (int64_t)lx->token_pos, where,
                             "malformed number '%.*s'", (int)(lx->len > 40 ? 40 : lx->len),
                             lx->token);
    return RSMOOTH_OK;
}

/* After "facet": "normal n n n outer loop (vertex x y z){3} endloop endfacet". */
static rsmooth_status read_facet(stl_lexer *lx, stl_soup *soup, rsmooth_error *error) {
    size_t facet = soup->triangle_count;
    int64_t facet_line = lx->line;
    size_t facet_pos = lx->token_pos;
    rsmooth_status status = expect_keyword(lx, "normal", error);
    double value;
    for (int k = 0; status == RSMOOTH_OK && k < 3; k++)
        status = read_number(lx, &value, error); /* the normal is recomputed: any number will do */
    if (status == RSMOOTH_OK)
        status = expect_keyword(lx, "outer", error);
    if (status == RSMOOTH_OK)
        status = expect_keyword(lx, "loop", error);
    if (status != RSMOOTH_OK)
        return status;
    if (facet >= RS_STL_MAX_TRIANGLES)
        return rs_fail_parse(error, facet_line, (int64_t)facet_pos, where,
                             "more than %zu facets (3 vertices each, fewer than 2^32 in all)",
                             RS_STL_MAX_TRIANGLES);
    if (facet == soup->capacity) {
        size_t capacity = soup->capacity ? 2 * soup->capacity : 1024;
        if (capacity > RS_STL_MAX_TRIANGLES)
            capacity = RS_STL_MAX_TRIANGLES;
        if (!soup_reserve(soup, capacity))
            return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "%zu triangles", capacity);
    }
    double *xyz = soup->positions + 9 * facet;
    size_t vertices = 0;
    bool supported = true; /* every coordinate finite and within the supported magnitude */
    double first_bad = 0;
    int64_t bad_line = 0; /* the first bad value's "vertex" line and keyword */
    size_t bad_pos = 0;
    for (;;) {
        if (!next_token(lx))
            return expected(lx, "endloop", error);
        if (keyword_is(lx, "endloop"))
            break;
        if (!keyword_is(lx, "vertex"))
            return expected(lx, vertices < 3 ? "vertex" : "endloop", error);
        int64_t vertex_line = lx->line;
        size_t vertex_pos = lx->token_pos;
        double v[3];
        for (int k = 0; k < 3; k++) {
            status = read_number(lx, &v[k], error);
            if (status != RSMOOTH_OK)
                return status;
            if (supported && !rs_io_coordinate_ok(v[k])) {
                supported = false;
                first_bad = v[k];
                bad_line = vertex_line;
                bad_pos = vertex_pos;
            }
        }
        if (vertices < 3)
            memcpy(xyz + 3 * vertices, v, sizeof v);
        vertices++;
    }
    if (vertices != 3)
        return rs_fail_parse(error, facet_line, (int64_t)facet_pos, where,
                             "facet %zu has %zu vertices (STL facets are triangles)", facet,
                             vertices);
    /* located at the vertex line that holds the value, once the facet is known to be whole */
    if (!supported && !isfinite(first_bad))
        return rs_fail_parse(error, bad_line, (int64_t)bad_pos, where,
                             "facet %zu has a non-finite vertex", facet);
    if (!supported)
        return rs_fail_parse(error, bad_line, (int64_t)bad_pos, where,
                             "facet %zu has coordinate %s beyond the supported magnitude %s", facet,
                             rs_io_shortest(first_bad).text,
                             rs_io_shortest(RS_MAX_COORDINATE).text);
    status = expect_keyword(lx, "endfacet", error);
    if (status == RSMOOTH_OK)
        soup->triangle_count++;
    return status;
}

static rs_stl_extras *ascii_extras(stl_soup *soup) {
    if (!soup->extras)
        soup->extras = rs_calloc_array(1, sizeof *soup->extras);
    return soup->extras;
}

/* After "solid": [name] facet* "endsolid" [name]. Every solid is recorded, to tell whether there is
 * anything to keep once the file is read. */
static rsmooth_status read_solid(stl_lexer *lx, stl_soup *soup, rsmooth_error *error) {
    const char *name;
    size_t name_len;
    rest_of_line(lx, &name, &name_len);
    rs_stl_extras *extras = ascii_extras(soup);
    if (!extras)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "STL extras");
    if (extras->solid_count == soup->solid_capacity) {
        size_t capacity = soup->solid_capacity ? 2 * soup->solid_capacity : 4;
        rs_stl_solid *solids = rs_realloc_array(extras->solids, capacity, sizeof *solids);
        if (!solids) /* rs_realloc_array refuses a capacity whose size overflows */
            return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "%zu STL solids", capacity);
        extras->solids = solids;
        soup->solid_capacity = capacity;
    }
    rs_stl_solid *solid = &extras->solids[extras->solid_count];
    solid->name = rs_alloc_array(name_len + 1, 1);
    if (!solid->name)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "STL solid name");
    memcpy(solid->name, name, name_len);
    solid->name[name_len] = '\0';
    solid->name_len = name_len;
    solid->facet_count = 0;
    extras->solid_count++;
    size_t first = soup->triangle_count;
    for (;;) {
        if (!next_token(lx))
            return expected(lx, "endsolid", error);
        if (keyword_is(lx, "endsolid"))
            break;
        if (!keyword_is(lx, "facet"))
            return expected(lx, "facet", error);
        rsmooth_status status = read_facet(lx, soup, error);
        if (status != RSMOOTH_OK)
            return status;
    }
    solid->facet_count = soup->triangle_count - first;
    rest_of_line(lx, &name, &name_len); /* the name repeated, or nothing: not checked */
    return RSMOOTH_OK;
}

static rsmooth_status read_ascii(const char *data, size_t size, rsmooth_mesh **mesh,
                                 rsmooth_error *error) {
    stl_lexer lx = {.data = data, .size = size, .line = 1};
    stl_soup soup = {0};
    rsmooth_status status = RSMOOTH_OK;
    if (!next_token(&lx) || !keyword_is(&lx, "solid"))
        status = expected(&lx, "solid", error);
    while (status == RSMOOTH_OK) {
        status = read_solid(&lx, &soup, error);
        if (status == RSMOOTH_OK && next_token(&lx) && !keyword_is(&lx, "solid"))
            status = expected(&lx, "solid", error); /* another solid, or the end */
        if (lx.len == 0)
            break;
    }
    if (status == RSMOOTH_OK && soup.triangle_count == 0)
        status = rs_fail_parse(error, lx.line, (int64_t)size, where, "no triangles");
    if (status != RSMOOTH_OK) {
        soup_free(&soup);
        return status;
    }
    /* Keep the names only when there is something to keep. */
    rs_stl_extras *extras = soup.extras;
    bool keep = extras->solid_count > 1;
    for (size_t i = 0; !keep && i < extras->solid_count; i++)
        keep = extras->solids[i].name_len > 0;
    if (keep) {
        extras->binary = false;
        extras->triangle_count = soup.triangle_count;
    } else {
        rs_io_stl_extras_free(extras);
        soup.extras = NULL;
    }
    return soup_finish(&soup, RSMOOTH_FLOAT64, RSMOOTH_FORMAT_STL_ASCII, mesh, error);
}

/* ---- entry points */

/* The first word past blanks and '#' comment lines is "solid", as format detection sees it; the
 * ascii reader then refuses the comments with their line. */
static bool starts_with_solid(const char *data, size_t size) {
    stl_lexer lx = {.data = data, .size = size};
    while (next_token(&lx) && lx.token[0] == '#')
        while (lx.pos < lx.size && lx.data[lx.pos] != '\n')
            lx.pos++;
    return keyword_is(&lx, "solid");
}

rsmooth_status rs_io_stl_read(const char *data, size_t size, rsmooth_mesh **mesh,
                              rsmooth_error *error) {
    const unsigned char *bytes = (const unsigned char *)data;
    /* The size test comes first: many binary headers start with "solid" too. */
    if (size >= RS_STL_HEADER_SIZE + 4) {
        uint64_t count = get_u32(bytes + RS_STL_HEADER_SIZE);
        if (RS_STL_HEADER_SIZE + 4 + RS_STL_RECORD_SIZE * count == (uint64_t)size)
            return read_binary(bytes, size, mesh, error);
    }
    /* Text never holds NUL bytes: such a file is a binary one whose header starts with "solid",
     * and its size is what is wrong. */
    if (starts_with_solid(data, size) &&
        !(size >= RS_STL_HEADER_SIZE + 4 && memchr(data, '\0', size)))
        return read_ascii(data, size, mesh, error);
    return read_binary(bytes, size, mesh, error);
}
