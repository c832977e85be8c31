/* Wavefront OBJ writer: faithful to the file the mesh was read from, else v (r g b), vn and f. */
#include "io/obj_format.h"

#include <errno.h>
#include <math.h>
#include <string.h>

static const char where[] = "rsmooth_mesh_write_stream";

/* Writes " v" so that it reads back as the same value (the same float when `as_float`): with 15
 * significant digits when they suffice (unchanged coordinates keep their short form), else 17.
 * A value beyond float range is written as the double it is (text holds either). */
static bool put_coord(FILE *stream, double v, bool as_float) {
    char buf[40];
    as_float = as_float && isfinite((float)v);
    int short_digits = as_float ? 6 : 15, full_digits = as_float ? 9 : 17;
    double value = as_float ? (double)(float)v : v;
    int n = snprintf(buf, sizeof buf, " %.*g", short_digits, value);
    double back;
    if (!(n > 1 && rs_io_parse_double(buf + 1, (size_t)n - 1, &back) &&
          (as_float ? (float)back == (float)value : back == value)))
        n = snprintf(buf, sizeof buf, " %.*g", full_digits, value);
    return n > 0 && fwrite(buf, 1, (size_t)n, stream) == (size_t)n;
}

/* `as_float`: a float32 mesh that float32 holds at its scale (rs_io_float32_holds). */
static bool put_position(FILE *stream, const rsmooth_mesh *mesh, size_t v, bool as_float) {
    const double *p = mesh->positions + 3 * v;
    return putc('v', stream) != EOF && put_coord(stream, p[0], as_float) &&
           put_coord(stream, p[1], as_float) && put_coord(stream, p[2], as_float);
}

/* vertex_count vn lines, each ended by `eol`: recomputed normals to 9 digits (ample for a unit
 * vector), a point cloud's own normals (its data) so that they read back exactly. */
static bool put_normals(FILE *stream, const rsmooth_mesh *mesh, const double *normals,
                        const char *eol, size_t eol_len, bool as_float) {
    bool exact = rs_io_normals_are_data(mesh);
    bool ok = true;
    for (size_t i = 0; ok && i < mesh->vertex_count; i++) {
        const double *n = normals + 3 * i;
        if (exact)
            ok = fputs("vn", stream) != EOF && put_coord(stream, n[0], as_float) &&
                 put_coord(stream, n[1], as_float) && put_coord(stream, n[2], as_float);
        else
            ok = fprintf(stream, "vn %.9g %.9g %.9g", n[0], n[1], n[2]) >= 0;
        ok = ok && fwrite(eol, 1, eol_len, stream) == eol_len;
    }
    return ok;
}

/* Appends the decimal digits of v to *p. */
static void append_u64(char **p, uint64_t v) {
    char digits[20];
    int n = 0;
    do {
        digits[n++] = (char)('0' + v % 10);
        v /= 10;
    } while (v);
    while (n)
        *(*p)++ = digits[--n];
}

/* The corners of face f: "v", "v/vt", "v//vn" or "v/vt/vn", absolute and 1-based; a vertex's
 * normal has the vertex's index. Formatted by hand in chunks: faces are most of a file. */
static bool put_face(FILE *stream, const rsmooth_mesh *mesh, size_t f, const uint32_t *corner_vt,
                     bool normals) {
    char buf[1024];
    char *p = buf;
    *p++ = 'f';
    for (uint32_t k = mesh->face_offsets[f]; k < mesh->face_offsets[f + 1]; k++) {
        if (p - buf > (ptrdiff_t)sizeof buf - 70) { /* room for one corner: 3 numbers, 4 marks */
            if (fwrite(buf, 1, (size_t)(p - buf), stream) != (size_t)(p - buf))
                return false;
            p = buf;
        }
        uint64_t v = (uint64_t)mesh->face_indices[k] + 1;
        *p++ = ' ';
        append_u64(&p, v);
        bool vt = corner_vt && corner_vt[k] != RS_OBJ_NO_VT;
        if (vt) {
            *p++ = '/';
            append_u64(&p, (uint64_t)corner_vt[k] + 1);
        }
        if (normals) {
            *p++ = '/';
            if (!vt)
                *p++ = '/';
            append_u64(&p, v);
        }
    }
    return fwrite(buf, 1, (size_t)(p - buf), stream) == (size_t)(p - buf);
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
static bool write_text(const rsmooth_mesh *mesh, const rs_obj_extras *x, const double *normals,
                       const char *p, const char *end, faithful_cursor *at, FILE *stream) {
    bool ok = true;
    while (ok && p < end) {
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
            ok = put_position(stream, mesh, at->v++, at->as_float) &&
                 fwrite(q, 1, (size_t)(content_end - q), stream) == (size_t)(content_end - q);
        } else if (keyword && len == 2 && token[0] == 'v' && token[1] == 'n' && normals) {
            /* Every vn line ends as the file's first line does: the line replaced may be the
             * last, without a newline or with a lone '\r', and what follows it must still be a
             * line of its own when the file is read and written again. */
            if (!at->normals_written)
                ok = put_normals(stream, mesh, normals, x->crlf ? "\r\n" : "\n",
                                 x->crlf ? 2 : 1, at->as_float);
            at->normals_written = true;
            p = next;
            continue;
        } else if (keyword && len == 1 && token[0] == 'f' && at->f < mesh->face_count) {
            ok = put_face(stream, mesh, at->f++, x->corner_vt, normals != NULL);
            while (next_token(&q, content_end, &token, &len)) {
            }
            if (ok && q < content_end) /* a trailing comment */
                ok = putc(' ', stream) != EOF && fwrite(q, 1, (size_t)(content_end - q), stream) ==
                                                     (size_t)(content_end - q);
        } else {
            ok = fwrite(p, 1, (size_t)(content_end - p), stream) == (size_t)(content_end - p);
        }
        ok = ok && fwrite(ending, 1, ending_len, stream) == ending_len;
        p = next;
    }
    return ok;
}

/* Writes the file the mesh was read from, run by run. */
static bool write_faithful(const rsmooth_mesh *mesh, const rs_obj_extras *x, const double *normals,
                           bool as_float, FILE *stream) {
    faithful_cursor at = {0, 0, false, as_float};
    const char *eol = x->crlf ? "\r\n" : "\n";
    size_t eol_len = x->crlf ? 2 : 1;
    bool ok = true;
    for (size_t r = 0; ok && r < x->run_count; r++) {
        const rs_obj_run *run = x->runs + r;
        if (run->kind == RS_OBJ_RUN_TEXT) {
            ok = write_text(mesh, x, normals, x->text + run->start,
                            x->text + run->start + run->count, &at, stream);
        } else if (run->kind == RS_OBJ_RUN_V) {
            for (size_t i = 0; ok && i < run->count && at.v < mesh->vertex_count; i++)
                ok = put_position(stream, mesh, at.v++, as_float) &&
                     fwrite(eol, 1, eol_len, stream) == eol_len;
        } else {
            for (size_t i = 0; ok && i < run->count && at.f < mesh->face_count; i++)
                ok = put_face(stream, mesh, at.f++, x->corner_vt, normals != NULL) &&
                     fwrite(eol, 1, eol_len, stream) == eol_len;
        }
    }
    return ok;
}

static bool write_generic(const rsmooth_mesh *mesh, const double *normals, bool as_float,
                          FILE *stream) {
    bool ok = fprintf(stream, "# written by rsmooth\n# %zu vertices, %zu faces\n",
                      mesh->vertex_count, mesh->face_count) >= 0;
    for (size_t i = 0; ok && i < mesh->vertex_count; i++) {
        ok = put_position(stream, mesh, i, as_float);
        if (ok && mesh->vertex_colors) {
            const uint8_t *c = mesh->vertex_colors + 3 * i;
            ok = fprintf(stream, " %.4g %.4g %.4g", c[0] / 255.0, c[1] / 255.0, c[2] / 255.0) >= 0;
        }
        ok = ok && putc('\n', stream) != EOF;
    }
    if (ok && normals)
        ok = put_normals(stream, mesh, normals, "\n", 1, as_float);
    for (size_t f = 0; ok && f < mesh->face_count; f++)
        ok = put_face(stream, mesh, f, NULL, normals != NULL) && putc('\n', stream) != EOF;
    return ok;
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
    const bool faithful = x != NULL;
    bool want_normals = wants_normals(mesh, x);
    double *normals = NULL;
    if (want_normals) {
        rsmooth_status status = rs_io_vertex_normals(mesh, &normals, where, error);
        if (status != RSMOOTH_OK)
            return status;
    }
    errno = 0;
    bool ok = rs_io_put_bom(mesh, RSMOOTH_FORMAT_OBJ, stream);
    const bool as_float = rs_io_float32_holds(mesh);
    ok = ok && (faithful ? write_faithful(mesh, x, normals, as_float, stream)
                         : write_generic(mesh, normals, as_float, stream));
    rs_free(normals);
    ok = ok && fflush(stream) == 0 && !ferror(stream);
    if (!ok)
        return rs_fail(error, RSMOOTH_ERROR_IO, where, "writing OBJ: %s",
                       errno ? strerror(errno) : "stream error");
    return RSMOOTH_OK;
}
