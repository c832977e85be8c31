/* OFF writer: faithful to the OFF file the mesh was read from, else OFF / COFF / NOFF / CNOFF. */
#include "io/off_format.h"

#include <errno.h>
#include <math.h>
#include <string.h>

static const char where[] = "rsmooth_mesh_write_stream";

/* Writes `sep` and v so that v reads back as the same value (the same float when `as_float`): with
 * 15 significant digits when they suffice (unchanged coordinates keep their short form), else 17. */
static bool put_coord(FILE *stream, const char *sep, double v, bool as_float) {
    char buf[40];
    as_float = as_float && isfinite((float)v); /* else the double it is: text holds either */
    int short_digits = as_float ? 6 : 15, full_digits = as_float ? 9 : 17;
    double value = as_float ? (double)(float)v : v;
    size_t skip = strlen(sep);
    int n = snprintf(buf, sizeof buf, "%s%.*g", sep, short_digits, value);
    double back;
    if (!(n > (int)skip && rs_io_parse_double(buf + skip, (size_t)n - skip, &back) &&
          (as_float ? (float)back == (float)value : back == value)))
        n = snprintf(buf, sizeof buf, "%s%.*g", sep, full_digits, value);
    return n > 0 && fwrite(buf, 1, (size_t)n, stream) == (size_t)n;
}

/* " text" for element i of `texts`, nothing when it is empty. */
static bool put_text(FILE *stream, const rs_off_texts *texts, size_t i) {
    if (!texts->offsets || texts->offsets[i + 1] <= texts->offsets[i])
        return true;
    size_t len = texts->offsets[i + 1] - texts->offsets[i];
    return putc(' ', stream) != EOF &&
           fwrite(texts->text + texts->offsets[i], 1, len, stream) == len;
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

/* "n i1 .. in", then the face's text when `face_texts`; formatted by hand in chunks, as faces are
 * most of a file. */
static bool put_faces(FILE *stream, const rsmooth_mesh *mesh, const rs_off_texts *face_texts) {
    char buf[1024];
    for (size_t f = 0; f < mesh->face_count; f++) {
        uint32_t begin = mesh->face_offsets[f], end = mesh->face_offsets[f + 1];
        char *p = buf;
        append_u64(&p, end - begin);
        for (uint32_t k = begin; k < end; k++) {
            if (p - buf > (ptrdiff_t)sizeof buf - 24) { /* room for " index" */
                if (fwrite(buf, 1, (size_t)(p - buf), stream) != (size_t)(p - buf))
                    return false;
                p = buf;
            }
            *p++ = ' ';
            append_u64(&p, mesh->face_indices[k]);
        }
        if (fwrite(buf, 1, (size_t)(p - buf), stream) != (size_t)(p - buf) ||
            (face_texts && !put_text(stream, face_texts, f)) || putc('\n', stream) == EOF)
            return false;
    }
    return true;
}

/* A vertex line's position, then the recomputed normal when `normals`. */
/* `as_float`: a float32 mesh that float32 holds at its scale (rs_io_float32_holds). */
static bool put_vertex(FILE *stream, const rsmooth_mesh *mesh, size_t v, const double *normals,
                       bool as_float) {
    const double *p = mesh->positions + 3 * v;
    bool ok = put_coord(stream, "", p[0], as_float) && put_coord(stream, " ", p[1], as_float) &&
              put_coord(stream, " ", p[2], as_float);
    if (ok && normals) { /* recomputed: 9 digits; a point cloud's own (its data): exact */
        const double *n = normals + 3 * v;
        if (rs_io_normals_are_data(mesh))
            ok = put_coord(stream, " ", n[0], as_float) && put_coord(stream, " ", n[1], as_float) &&
                 put_coord(stream, " ", n[2], as_float);
        else
            ok = fprintf(stream, " %.9g %.9g %.9g", n[0], n[1], n[2]) >= 0;
    }
    return ok;
}

/* The file the mesh was read from: its keyword, edge count and the text after each vertex's
 * position and each face's indices. */
static bool write_faithful(const rsmooth_mesh *mesh, const rs_off_extras *x, const double *normals,
                           bool as_float, FILE *stream) {
    bool ok = fprintf(stream, "%s\n%zu %zu %llu\n", x->keyword, mesh->vertex_count,
                      mesh->face_count, (unsigned long long)x->edge_count) >= 0;
    for (size_t v = 0; ok && v < mesh->vertex_count; v++)
        ok = put_vertex(stream, mesh, v, normals, as_float) && put_text(stream, &x->vertex, v) &&
             putc('\n', stream) != EOF;
    return ok && put_faces(stream, mesh, &x->face);
}

/* OFF, COFF, NOFF or CNOFF from the mesh's own fields. */
static bool write_generic(const rsmooth_mesh *mesh, const double *normals, bool as_float,
                          FILE *stream) {
    const uint8_t *colors = mesh->vertex_colors;
    bool ok = fprintf(stream, "%s%sOFF\n%zu %zu 0\n", colors ? "C" : "", normals ? "N" : "",
                      mesh->vertex_count, mesh->face_count) >= 0;
    for (size_t v = 0; ok && v < mesh->vertex_count; v++) {
        ok = put_vertex(stream, mesh, v, normals, as_float);
        if (ok && colors)
            ok = fprintf(stream, " %u %u %u 255", colors[3 * v], colors[3 * v + 1],
                         colors[3 * v + 2]) >= 0;
        ok = ok && putc('\n', stream) != EOF;
    }
    return ok && put_faces(stream, mesh, NULL);
}

/* The OFF record of the mesh, while it describes it: its counts are unchanged. */
static const rs_off_extras *faithful_extras(const rsmooth_mesh *mesh) {
    const rs_off_extras *x = mesh->extras ? mesh->extras->off : NULL;
    return x && x->vertex_count == mesh->vertex_count && x->face_count == mesh->face_count ? x
                                                                                           : NULL;
}

/* NOFF lines need normals; otherwise only normals there are (see rs_io_normals_available) */
static bool wants_normals(const rsmooth_mesh *mesh, const rs_off_extras *x) {
    return x ? x->normals : mesh->has_vertex_normals && rs_io_normals_available(mesh);
}

rsmooth_status rs_io_off_check(const rsmooth_mesh *mesh, rsmooth_error *error) {
    return wants_normals(mesh, faithful_extras(mesh)) ? rs_io_check_normals(mesh, where, error)
                                                      : RSMOOTH_OK;
}

rsmooth_status rs_io_off_write(const rsmooth_mesh *mesh, FILE *stream, rsmooth_error *error) {
    const rs_off_extras *x = faithful_extras(mesh);
    const bool faithful = x != NULL;
    bool want_normals = wants_normals(mesh, x);
    double *normals = NULL;
    if (want_normals) {
        rsmooth_status status = rs_io_vertex_normals(mesh, &normals, where, error);
        if (status != RSMOOTH_OK)
            return status;
    }
    errno = 0;
    bool ok = rs_io_put_bom(mesh, RSMOOTH_FORMAT_OFF, stream) &&
              (faithful ? write_faithful(mesh, x, normals, rs_io_float32_holds(mesh), stream)
                        : write_generic(mesh, normals, rs_io_float32_holds(mesh), stream));
    rs_free(normals);
    ok = ok && fflush(stream) == 0 && !ferror(stream);
    if (!ok)
        return rs_fail(error, RSMOOTH_ERROR_IO, where, "writing OFF: %s",
                       errno ? strerror(errno) : "stream error");
    return RSMOOTH_OK;
}
