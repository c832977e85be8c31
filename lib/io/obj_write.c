/* Wavefront OBJ writer: faithful to the file the mesh was read from, else v (r g b), vn and f. */
#include "io/obj_format.h"
#include "io/text_out.h"

#include <string.h>

static const char where[] = "rsmooth_mesh_write_stream";

/* " v", read back as the same value (rs_io_text_coordinate). */
static void put_coord(rs_io_text_out *out, double v, bool as_float) {
    rs_io_text_char(out, ' ');
    rs_io_text_coordinate(out, v, as_float);
}

/* `as_float`: a float32 mesh that float32 holds at its scale (rs_io_float32_holds). */
static void put_position(rs_io_text_out *out, const rsmooth_mesh *mesh, size_t v, bool as_float) {
    const double *p = mesh->positions + 3 * v;
    rs_io_text_char(out, 'v');
    put_coord(out, p[0], as_float);
    put_coord(out, p[1], as_float);
    put_coord(out, p[2], as_float);
}

/* vertex_count vn lines, each ended by `eol` (rs_io_text_normal: recomputed normals to 9 digits,
 * a point cloud's own exactly). */
static void put_normals(rs_io_text_out *out, const rsmooth_mesh *mesh, const double *normals,
                        const char *eol, size_t eol_len, bool as_float) {
    bool exact = rs_io_normals_are_data(mesh);
    for (size_t i = 0; out->ok && i < mesh->vertex_count; i++) {
        const double *n = normals + 3 * i;
        rs_io_text_bytes(out, "vn", 2);
        for (int c = 0; c < 3; c++)
            rs_io_text_normal(out, n[c], exact, as_float);
        rs_io_text_bytes(out, eol, eol_len);
    }
}

/* The corners of face f: "v", "v/vt", "v//vn" or "v/vt/vn", absolute and 1-based; a vertex's
 * normal has the vertex's index. */
static void put_face(rs_io_text_out *out, const rsmooth_mesh *mesh, size_t f,
                     const uint32_t *corner_vt, bool normals) {
    rs_io_text_char(out, 'f');
    for (uint32_t k = mesh->face_offsets[f]; k < mesh->face_offsets[f + 1]; k++) {
        char *start = rs_io_text_reserve(out, 70); /* one corner: 3 numbers, 4 marks */
        char *p = start;
        uint64_t v = (uint64_t)mesh->face_indices[k] + 1;
        *p++ = ' ';
        p += rs_io_print_u64(p, v);
        bool vt = corner_vt && corner_vt[k] != RS_OBJ_NO_VT;
        if (vt) {
            *p++ = '/';
            p += rs_io_print_u64(p, (uint64_t)corner_vt[k] + 1);
        }
        if (normals) {
            *p++ = '/';
            if (!vt)
                *p++ = '/';
            p += rs_io_print_u64(p, v);
        }
        out->used += (size_t)(p - start);
    }
}

static bool is_space(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

/* As the reader's tokenizer: false at the line's end or at a '#', leaving *p there. */
static bool next_token(const char **p, const char *end, const char **token, size_t *len) {
    const char *s = *p;
    while (s < end && is_space(*s))
        s++;
    *p = s;
    if (s == end || *s == '#')
        return false;
    *token = s;
    while (s < end && !is_space(*s))
        s++;
    *len = (size_t)(s - *token);
    *p = s;
    return true;
}

/* Where the faithful writer stands in the mesh while it walks the runs. */
typedef struct faithful_cursor {
    size_t v, f;
    bool normals_written;
    bool as_float; /* rs_io_float32_holds */
} faithful_cursor;

/* Writes the text lines [p, end): v gets the new position (what follows its coordinates kept), the
 * vn lines give way to the recomputed normals, f gets absolute indices (a trailing comment kept);
 * every other line is copied. */
static void write_text(const rsmooth_mesh *mesh, const rs_obj_extras *x, const double *normals,
                       const char *p, const char *end, faithful_cursor *at, rs_io_text_out *out) {
    while (out->ok && p < end) {
        const char *eol = memchr(p, '\n', (size_t)(end - p));
        const char *next = eol ? eol + 1 : end;
        const char *content_end = eol ? eol : end;
        if (content_end > p && content_end[-1] == '\r')
            content_end--;
        const char *ending = content_end; /* "\r\n", "\n" or nothing, as the line had */
        size_t ending_len = (size_t)(next - content_end);
        const char *q = p, *token;
        size_t len;
        bool keyword = next_token(&q, content_end, &token, &len);
        if (keyword && len == 1 && token[0] == 'v' && at->v < mesh->vertex_count) {
            for (int k = 0; k < 3; k++) /* the reader accepted the line: three numbers follow */
                next_token(&q, content_end, &token, &len);
            put_position(out, mesh, at->v++, at->as_float);
            rs_io_text_bytes(out, q, (size_t)(content_end - q));
        } else if (keyword && len == 2 && token[0] == 'v' && token[1] == 'n' && normals) {
            /* Every vn line ends as the file's first line does: the line replaced may be the
             * last, without a newline or with a lone '\r', and what follows it must still be a
             * line of its own when the file is read and written again. */
            if (!at->normals_written)
                put_normals(out, mesh, normals, x->crlf ? "\r\n" : "\n", x->crlf ? 2 : 1,
                            at->as_float);
            at->normals_written = true;
            p = next;
            continue;
        } else if (keyword && len == 1 && token[0] == 'f' && at->f < mesh->face_count) {
            put_face(out, mesh, at->f++, x->corner_vt, normals != NULL);
            while (next_token(&q, content_end, &token, &len)) {
            }
            if (q < content_end) { /* a trailing comment */
                rs_io_text_char(out, ' ');
                rs_io_text_bytes(out, q, (size_t)(content_end - q));
            }
        } else {
            rs_io_text_bytes(out, p, (size_t)(content_end - p));
        }
        rs_io_text_bytes(out, ending, ending_len);
        p = next;
    }
}

/* Writes the file the mesh was read from, run by run. */
static void write_faithful(const rsmooth_mesh *mesh, const void *extras, const double *normals,
                           bool as_float, rs_io_text_out *out) {
    const rs_obj_extras *x = extras;
    faithful_cursor at = {0, 0, false, as_float};
    const char *eol = x->crlf ? "\r\n" : "\n";
    size_t eol_len = x->crlf ? 2 : 1;
    for (size_t r = 0; out->ok && r < x->run_count; r++) {
        const rs_obj_run *run = x->runs + r;
        if (run->kind == RS_OBJ_RUN_TEXT) {
            write_text(mesh, x, normals, x->text + run->start, x->text + run->start + run->count,
                       &at, out);
        } else if (run->kind == RS_OBJ_RUN_V) {
            for (size_t i = 0; out->ok && i < run->count && at.v < mesh->vertex_count; i++) {
                put_position(out, mesh, at.v++, as_float);
                rs_io_text_bytes(out, eol, eol_len);
            }
        } else {
            for (size_t i = 0; out->ok && i < run->count && at.f < mesh->face_count; i++) {
                put_face(out, mesh, at.f++, x->corner_vt, normals != NULL);
                rs_io_text_bytes(out, eol, eol_len);
            }
        }
    }
}

static void write_generic(const rsmooth_mesh *mesh, const void *no_extras, const double *normals,
                          bool as_float, rs_io_text_out *out) {
    (void)no_extras;
    rs_io_text_printf(out, "# written by rsmooth\n# %zu vertices, %zu faces\n", mesh->vertex_count,
                      mesh->face_count);
    char colors[256][16]; /* " %.4g" of each channel value / 255, formatted once */
    uint8_t color_len[256];
    if (mesh->vertex_colors)
        for (int c = 0; c < 256; c++)
            color_len[c] = (uint8_t)snprintf(colors[c], sizeof colors[c], " %.4g", c / 255.0);
    for (size_t i = 0; out->ok && i < mesh->vertex_count; i++) {
        put_position(out, mesh, i, as_float);
        if (mesh->vertex_colors) {
            const uint8_t *c = mesh->vertex_colors + 3 * i;
            for (int k = 0; k < 3; k++)
                rs_io_text_bytes(out, colors[c[k]], color_len[c[k]]);
        }
        rs_io_text_char(out, '\n');
    }
    if (normals)
        put_normals(out, mesh, normals, "\n", 1, as_float);
    for (size_t f = 0; out->ok && f < mesh->face_count; f++) {
        put_face(out, mesh, f, NULL, normals != NULL);
        rs_io_text_char(out, '\n');
    }
}

/* The OBJ record of the mesh, when it still describes it: its vertices and face structure are
 * unchanged (positions may differ: that is what smoothing does). */
static const rs_obj_extras *faithful_extras(const rsmooth_mesh *mesh) {
    const rs_obj_extras *x = mesh->extras ? mesh->extras->obj : NULL;
    bool faithful = x && x->vertex_count == mesh->vertex_count &&
                    x->face_count == mesh->face_count && mesh->face_offsets &&
                    x->offsets_hash == rs_obj_offsets_hash(mesh->face_offsets, mesh->face_count);
    return faithful ? x : NULL;
}

static bool wants_normals(const rsmooth_mesh *mesh, const rs_obj_extras *x) {
    return (x ? (x->kinds & RS_OBJ_NORMALS) != 0 : mesh->has_vertex_normals) &&
           rs_io_normals_available(mesh);
}

rsmooth_status rs_io_obj_check(const rsmooth_mesh *mesh, rsmooth_error *error) {
    return wants_normals(mesh, faithful_extras(mesh)) ? rs_io_check_normals(mesh, where, error)
                                                      : RSMOOTH_OK;
}

rsmooth_status rs_io_obj_write(const rsmooth_mesh *mesh, FILE *stream, rsmooth_error *error) {
    const rs_obj_extras *x = faithful_extras(mesh);
    return rs_io_text_write_mesh(mesh, stream, RSMOOTH_FORMAT_OBJ, "OBJ", write_faithful,
                                 write_generic, x, wants_normals(mesh, x), where, error);
}
