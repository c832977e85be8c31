/* PLY header: the grammar from "ply" to "end_header", and the role of each property (what its
 * values are to the mesh). */
#include "io/ply_reader.h"

#include <limits.h>
#include <stdlib.h>
#include <string.h>

static const char where[] = RS_PLY_READ_WHERE;

static bool token_is(const char *token, size_t len, const char *word) {
    size_t n = strlen(word);
    return len == n && memcmp(token, word, n) == 0;
}

/* The spelling index of a type word, or -1. */
static int parse_type(const char *token, size_t len) {
    for (unsigned s = 0; s < RS_PLY_SPELLING_COUNT; s++)
        if (token_is(token, len, rs_ply_spelling(s)))
            return (int)s;
    return -1;
}

static char *copy_text(const char *s, size_t len) {
    char *copy = rs_alloc_array(len + 1, 1);
    if (copy) {
        memcpy(copy, s, len);
        copy[len] = '\0';
    }
    return copy;
}

/* ---- header */

#define MAX_HEADER_TOKENS 8

static rsmooth_status header_error(const rs_ply_reader *r, size_t offset, rsmooth_error *error,
                                   const char *message, const char *token, size_t len) {
    return rs_fail_parse(error, r->line, (int64_t)offset, where, "%s '%.*s'", message,
                         (int)(len > 40 ? 40 : len), token);
}

static rsmooth_status header_oom(rsmooth_error *error) {
    return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "PLY header");
}

static rsmooth_status add_comment(rs_ply_reader *r, const char *start, const char *eol,
                                  bool have_format, rsmooth_error *error) {
    rs_ply_extras *x = r->x;
    if (x->comment_count == x->comment_capacity) {
        size_t capacity = x->comment_capacity ? 2 * x->comment_capacity : 8;
        rs_ply_comment *c = rs_realloc_array(x->comments, capacity, sizeof *c);
        if (!c)
            return header_oom(error);
        x->comments = c;
        x->comment_capacity = capacity;
    }
    while (eol > start && eol[-1] == '\r')
        eol--;
    char *text = copy_text(start, (size_t)(eol - start));
    if (!text)
        return header_oom(error);
    x->comments[x->comment_count++] = (rs_ply_comment){
        .text = text, .before_element = x->element_count, .before_format = !have_format};
    return RSMOOTH_OK;
}

static rsmooth_status add_property(rs_ply_reader *r, const char *const *tok, const size_t *len,
                                   int n, size_t offset, rsmooth_error *error) {
    rs_ply_extras *x = r->x;
    if (x->element_count == 0)
        return header_error(r, offset, error, "property before any element:", tok[0], len[0]);
    rs_ply_property prop = {0};
    const char *name;
    size_t name_len;
    if (n >= 2 && token_is(tok[1], len[1], "list")) {
        if (n != 5)
            return header_error(r, offset, error,
                                "expected 'property list COUNTTYPE TYPE NAME':", tok[0], len[0]);
        int count_spelling = parse_type(tok[2], len[2]), spelling = parse_type(tok[3], len[3]);
        if (count_spelling < 0)
            return header_error(r, (size_t)(tok[2] - r->data), error, "unknown type", tok[2],
                                len[2]);
        if (spelling < 0)
            return header_error(r, (size_t)(tok[3] - r->data), error, "unknown type", tok[3],
                                len[3]);
        prop.count_spelling = (uint8_t)count_spelling;
        prop.count_type = rs_ply_spelling_type((unsigned)count_spelling);
        prop.spelling = (uint8_t)spelling;
        prop.type = rs_ply_spelling_type((unsigned)spelling);
        if (rs_ply_type_is_float(prop.count_type))
            return header_error(r, (size_t)(tok[2] - r->data), error,
                                "list count type must be an integer:", tok[2], len[2]);
        name = tok[4];
        name_len = len[4];
    } else {
        if (n != 3)
            return header_error(r, offset, error, "expected 'property TYPE NAME':", tok[0], len[0]);
        int spelling = parse_type(tok[1], len[1]);
        if (spelling < 0)
            return header_error(r, (size_t)(tok[1] - r->data), error, "unknown type", tok[1],
                                len[1]);
        prop.spelling = (uint8_t)spelling;
        prop.type = rs_ply_spelling_type((unsigned)spelling);
        name = tok[2];
        name_len = len[2];
    }
    rs_ply_element *e = &x->elements[x->element_count - 1];
    for (size_t k = 0; k < e->property_count; k++) /* a name must say which value it is */
        if (token_is(name, name_len, e->properties[k].name))
            return header_error(r, (size_t)(name - r->data), error,
                                "a second property of the same name in one element:", name,
                                name_len);
    if (e->property_count == e->property_capacity) {
        size_t capacity = e->property_capacity ? 2 * e->property_capacity : 8;
        rs_ply_property *p = rs_realloc_array(e->properties, capacity, sizeof *p);
        if (!p)
            return header_oom(error);
        e->properties = p;
        e->property_capacity = capacity;
    }
    prop.name = copy_text(name, name_len);
    if (!prop.name)
        return header_oom(error);
    e->properties[e->property_count++] = prop;
    return RSMOOTH_OK;
}

static rsmooth_status add_element(rs_ply_reader *r, const char *const *tok, const size_t *len,
                                  int n, size_t offset, rsmooth_error *error) {
    rs_ply_extras *x = r->x;
    if (n != 3)
        return header_error(r, offset, error, "expected 'element NAME COUNT':", tok[0], len[0]);
    char digits[32];
    bool ok = len[2] > 0 && len[2] < sizeof digits;
    for (size_t i = 0; ok && i < len[2]; i++)
        ok = tok[2][i] >= '0' && tok[2][i] <= '9'; /* strtoull alone would take "-1" */
    if (!ok)
        return header_error(r, (size_t)(tok[2] - r->data), error, "bad element count", tok[2],
                            len[2]);
    memcpy(digits, tok[2], len[2]);
    digits[len[2]] = '\0';
    unsigned long long count = strtoull(digits, NULL, 10);
    if (count == ULLONG_MAX || count > UINT64_MAX / 2)
        return header_error(r, (size_t)(tok[2] - r->data), error, "element count out of range",
                            tok[2], len[2]);
    if (x->element_count == x->element_capacity) {
        size_t capacity = x->element_capacity ? 2 * x->element_capacity : 8;
        rs_ply_element *e = rs_realloc_array(x->elements, capacity, sizeof *e);
        if (!e)
            return header_oom(error);
        x->elements = e;
        x->element_capacity = capacity;
    }
    char *name = copy_text(tok[1], len[1]);
    if (!name)
        return header_oom(error);
    x->elements[x->element_count++] =
        (rs_ply_element){.name = name, .count = count, .header_line = r->line};
    return RSMOOTH_OK;
}

rsmooth_status rs_ply_parse_header(rs_ply_reader *r, rsmooth_error *error) {
    const char *data = r->data;
    /* Magic: "ply" alone on the first line. */
    bool magic = r->size >= 3 && memcmp(data, "ply", 3) == 0;
    if (magic && (r->size == 3 || (r->size == 4 && data[3] == '\r')))
        return rs_fail_parse(error, 1, (int64_t)r->size, where,
                             "the file ends after 'ply' (a header up to 'end_header' expected)");
    if (!magic || !(data[3] == '\n' || (data[3] == '\r' && data[4] == '\n'))) {
        size_t len = 0;
        while (len < r->size && len < 40 && data[len] != '\n' && data[len] != '\r')
            len++;
        return rs_fail_parse(error, 1, 0, where,
                             "not a PLY file: the first line is '%.*s', not 'ply' alone", (int)len,
                             data);
    }
    r->pos = data[3] == '\n' ? 4 : 5;
    r->line = 2;
    bool have_format = false;
    for (;; r->line++) {
        if (r->pos >= r->size)
            return rs_fail_parse(error, r->line, (int64_t)r->pos, where,
                                 "header ends without 'end_header'");
        const char *start = data + r->pos;
        const char *eol = memchr(start, '\n', r->size - r->pos);
        if (!eol)
            return rs_fail_parse(error, r->line, (int64_t)r->pos, where,
                                 "header ends without 'end_header'");
        size_t offset = r->pos;
        r->pos = (size_t)(eol - data) + 1;
        /* A header is text: a NUL could never be written back (names and comments are strings). */
        const char *nul = memchr(start, '\0', (size_t)(eol - start));
        if (nul)
            return rs_fail_parse(error, r->line, (int64_t)(nul - data), where,
                                 "NUL byte in the header");
        const char *tok[MAX_HEADER_TOKENS];
        size_t len[MAX_HEADER_TOKENS];
        int n = 0;
        for (const char *p = start; p < eol;) {
            while (p < eol && rs_ply_is_space(*p))
                p++;
            if (p == eol)
                break;
            const char *t = p;
            while (p < eol && !rs_ply_is_space(*p))
                p++;
            if (n < MAX_HEADER_TOKENS) {
                tok[n] = t;
                len[n] = (size_t)(p - t);
            }
            n++;
        }
        if (n == 0)
            continue; /* tolerate blank header lines */
        rsmooth_status status = RSMOOTH_OK;
        if (token_is(tok[0], len[0], "comment") || token_is(tok[0], len[0], "obj_info")) {
            status = add_comment(r, tok[0], eol, have_format, error);
        } else if (token_is(tok[0], len[0], "end_header")) {
            if (n != 1)
                return header_error(r, offset, error, "bad header line:", tok[0], len[0]);
            if (!have_format)
                return rs_fail_parse(error, r->line, (int64_t)offset, where,
                                     "header has no 'format' line");
            r->end_header_line = r->line;
            r->line++; /* ascii data starts on the next line */
            return RSMOOTH_OK;
        } else if (token_is(tok[0], len[0], "format")) {
            if (n != 3 || have_format)
                return header_error(r, offset, error, "bad header line:", tok[0], len[0]);
            if (token_is(tok[1], len[1], "ascii"))
                r->encoding = RS_PLY_ASCII;
            else if (token_is(tok[1], len[1], "binary_little_endian"))
                r->encoding = RS_PLY_BINARY_LE;
            else if (token_is(tok[1], len[1], "binary_big_endian"))
                r->encoding = RS_PLY_BINARY_BE;
            else
                return header_error(r, (size_t)(tok[1] - data), error, "unknown PLY format", tok[1],
                                    len[1]);
            if (!token_is(tok[2], len[2], "1.0") && !token_is(tok[2], len[2], "1"))
                return header_error(r, (size_t)(tok[2] - data), error, "unsupported PLY version",
                                    tok[2], len[2]);
            r->swap = r->encoding != RS_PLY_ASCII &&
                      (r->encoding == RS_PLY_BINARY_LE) != rs_ply_host_is_le();
            have_format = true;
        } else if (token_is(tok[0], len[0], "element")) {
            status = add_element(r, tok, len, n, offset, error);
        } else if (token_is(tok[0], len[0], "property")) {
            status = add_property(r, tok, len, n, offset, error);
        } else {
            return header_error(r, offset, error, "bad header line:", tok[0], len[0]);
        }
        if (status != RSMOOTH_OK)
            return status;
    }
}

/* ---- roles: what each property's values are to the mesh */

static size_t find_scalar(const rs_ply_element *e, const char *name) {
    for (size_t k = 0; k < e->property_count; k++)
        if (e->properties[k].count_type == RS_PLY_NONE && !strcmp(e->properties[k].name, name))
            return k;
    return SIZE_MAX;
}

rsmooth_status rs_ply_assign_roles(rs_ply_reader *r, rsmooth_error *error) {
    r->color[0] = r->color[1] = r->color[2] = SIZE_MAX;
    rs_ply_element *v = r->vertex_element;
    static const char *const axis[3] = {"x", "y", "z"};
    for (int c = 0; c < 3; c++) {
        size_t k = SIZE_MAX;
        for (size_t i = 0; i < v->property_count && k == SIZE_MAX; i++)
            if (!strcmp(v->properties[i].name, axis[c]))
                k = i;
        if (k == SIZE_MAX)
            return rs_fail_parse(error, v->header_line, -1, where,
                                 "vertex element has no '%s' property", axis[c]);
        if (v->properties[k].count_type != RS_PLY_NONE)
            return rs_fail_parse(error, v->header_line, -1, where, "vertex property '%s' is a list",
                                 axis[c]);
        v->properties[k].role = (uint8_t)(RS_PLY_X + c);
        if (v->properties[k].type == RS_PLY_FLOAT64)
            r->precision = RSMOOTH_FLOAT64;
    }
    /* Normals only as floating-point triples: integer ones stay opaque values, kept as read. */
    size_t n[3] = {find_scalar(v, "nx"), find_scalar(v, "ny"), find_scalar(v, "nz")};
    if (n[0] != SIZE_MAX && n[1] != SIZE_MAX && n[2] != SIZE_MAX &&
        rs_ply_type_is_float(v->properties[n[0]].type) &&
        rs_ply_type_is_float(v->properties[n[1]].type) &&
        rs_ply_type_is_float(v->properties[n[2]].type)) {
        for (int c = 0; c < 3; c++)
            v->properties[n[c]].role = (uint8_t)(RS_PLY_NX + c);
        r->normals = true;
    }
    static const char *const channel[2][3] = {{"red", "green", "blue"},
                                              {"diffuse_red", "diffuse_green", "diffuse_blue"}};
    for (int naming = 0; naming < 2 && r->color[0] == SIZE_MAX; naming++) {
        size_t k[3];
        bool all = true;
        for (int c = 0; c < 3; c++) {
            k[c] = find_scalar(v, channel[naming][c]);
            all = all && k[c] != SIZE_MAX && v->properties[k[c]].role == RS_PLY_STORED;
        }
        for (int c = 0; all && c < 3; c++) {
            r->color[c] = k[c];
            v->properties[k[c]].color = true;
        }
    }
    rs_ply_element *f = r->face_element;
    if (f) {
        size_t k = SIZE_MAX;
        for (size_t i = 0; i < f->property_count && k == SIZE_MAX; i++)
            if (f->properties[i].count_type != RS_PLY_NONE &&
                (!strcmp(f->properties[i].name, "vertex_indices") ||
                 !strcmp(f->properties[i].name, "vertex_index")))
                k = i;
        if (k == SIZE_MAX)
            return rs_fail_parse(error, f->header_line, -1, where,
                                 "face element has no 'vertex_indices' list property");
        f->properties[k].role = RS_PLY_FACE_LIST;
    }
    /* Rows: the stored scalars and list counts of each element, in property order. */
    for (size_t ei = 0; ei < r->x->element_count; ei++) {
        rs_ply_element *e = &r->x->elements[ei];
        for (size_t k = 0; k < e->property_count; k++) {
            rs_ply_property *p = &e->properties[k];
            if (p->role != RS_PLY_STORED)
                continue;
            p->row_offset = e->row_size;
            e->row_size += rs_ply_type_size(p->count_type != RS_PLY_NONE ? p->count_type : p->type);
        }
    }
    return RSMOOTH_OK;
}

/* The layout the generic writer produces (x y z of one float type, then "list uchar int
 * vertex_indices" faces, no comment but rsmooth's): nothing for extras to keep. */
bool rs_ply_is_plain(const rs_ply_reader *r) {
    const rs_ply_extras *x = r->x;
    for (size_t c = 0; c < x->comment_count; c++)
        if (strcmp(x->comments[c].text, "comment written by rsmooth") != 0)
            return false;
    if (x->element_count != 2 || x->vertex_element != 0 || x->face_element != 1 || r->normals)
        return false;
    const rs_ply_element *v = &x->elements[0], *f = &x->elements[1];
    if (v->property_count != 3 || f->property_count != 1)
        return false;
    for (int c = 0; c < 3; c++) {
        const rs_ply_property *p = &v->properties[c];
        if (p->role != RS_PLY_X + c || p->type != v->properties[0].type ||
            (strcmp(rs_ply_spelling(p->spelling), "float") != 0 &&
             strcmp(rs_ply_spelling(p->spelling), "double") != 0))
            return false;
    }
    const rs_ply_property *list = &f->properties[0];
    return !strcmp(list->name, "vertex_indices") &&
           !strcmp(rs_ply_spelling(list->count_spelling), "uchar") &&
           !strcmp(rs_ply_spelling(list->spelling), "int");
}

rsmooth_status rs_ply_find_elements(rs_ply_reader *r, rsmooth_error *error) {
    rs_ply_extras *x = r->x;
    const rs_ply_element *grid = NULL;
    for (size_t ei = 0; ei < x->element_count; ei++) {
        rs_ply_element *e = &x->elements[ei];
        bool vertex = !strcmp(e->name, "vertex");
        bool face = !strcmp(e->name, "face");
        if ((vertex && r->vertex_element) || (face && r->face_element))
            return rs_fail_parse(error, e->header_line, -1, where, "a second '%s' element",
                                 vertex ? "vertex" : "face");
        /* one range grid is the surface (ply_range_grid.c); a second would be kept as data and
         * written beside the faces made from the first, a file no reader takes back */
        if (!strcmp(e->name, "range_grid")) {
            if (grid)
                return rs_fail_parse(error, e->header_line, -1, where,
                                     "a second 'range_grid' element (the first is on line %lld): "
                                     "a scan is one grid",
                                     (long long)grid->header_line);
            grid = e;
        }
        if (vertex) {
            r->vertex_element = e;
            x->vertex_element = ei;
        }
        if (face) {
            r->face_element = e;
            x->face_element = ei;
        }
    }
    if (!r->vertex_element)
        return rs_fail_parse(error, r->end_header_line, -1, where,
                             "no vertices: the header declares no 'element vertex'");
    if (r->vertex_element->count == 0)
        return rs_fail_parse(error, r->vertex_element->header_line, -1, where,
                             "no vertices: 'element vertex 0'");
    if (r->vertex_element->count >= (r->max_vertices ? r->max_vertices : RS_IO_MAX_VERTICES))
        return rs_fail_parse(error, r->vertex_element->header_line, -1, where,
                             r->max_vertices ? "%llu vertices: too many (at most 2^48)"
                                             : "%llu vertices: too many (indices are 32-bit)",
                             (unsigned long long)r->vertex_element->count);
    r->vertex_count = (size_t)r->vertex_element->count;
    return RSMOOTH_OK;
}
