/* OFF writer: faithful to the OFF file the mesh was read from, else OFF / COFF / NOFF / CNOFF. */
#include "io/off_format.h"
#include "io/text_out.h"

#include <string.h>

static const char where[] = "rsmooth_mesh_write_stream";

/* `sep` and v, read back as the same value (rs_io_text_coordinate). */
static void put_coord(rs_io_text_out *out, bool sep, double v, bool as_float) {
    if (sep)
        rs_io_text_char(out, ' ');
    rs_io_text_coordinate(out, v, as_float);
}

/* " text" for element i of `texts`, nothing when it is empty. */
static void put_text(rs_io_text_out *out, const rs_off_texts *texts, size_t i) {
    if (!texts->offsets || texts->offsets[i + 1] <= texts->offsets[i])
        return;
    rs_io_text_char(out, ' ');
    rs_io_text_bytes(out, texts->text + texts->offsets[i],
                     texts->offsets[i + 1] - texts->offsets[i]);
}

/* "n i1 .. in", then the face's text when `face_texts`. */
static void put_faces(rs_io_text_out *out, const rsmooth_mesh *mesh,
                      const rs_off_texts *face_texts) {
    for (size_t f = 0; out->ok && f < mesh->face_count; f++) {
        uint32_t begin = mesh->face_offsets[f], end = mesh->face_offsets[f + 1];
        rs_io_text_u64(out, end - begin);
        for (uint32_t k = begin; k < end; k++) {
            char *p = rs_io_text_reserve(out, 12); /* " index" */
            *p = ' ';
            out->used += 1 + rs_io_print_u64(p + 1, mesh->face_indices[k]);
        }
        if (face_texts)
            put_text(out, face_texts, f);
        rs_io_text_char(out, '\n');
    }
}

/* A vertex line's position, then the recomputed normal when `normals`. */
/* `as_float`: a float32 mesh that float32 holds at its scale (rs_io_float32_holds). */
static void put_vertex(rs_io_text_out *out, const rsmooth_mesh *mesh, size_t v,
                       const double *normals, bool as_float) {
    const double *p = mesh->positions + 3 * v;
    put_coord(out, false, p[0], as_float);
    put_coord(out, true, p[1], as_float);
    put_coord(out, true, p[2], as_float);
    if (normals) { /* recomputed: 9 digits ("%.9g"); a point cloud's own (its data): exact */
        bool exact = rs_io_normals_are_data(mesh);
        for (int c = 0; c < 3; c++)
            rs_io_text_normal(out, normals[3 * v + (size_t)c], exact, as_float);
    }
}

/* The file the mesh was read from: its keyword, edge count and the text after each vertex's
 * position and each face's indices. */
static void write_faithful(const rsmooth_mesh *mesh, const void *extras, const double *normals,
                           bool as_float, rs_io_text_out *out) {
    const rs_off_extras *x = extras;
    rs_io_text_printf(out, "%s\n%zu %zu %llu\n", x->keyword, mesh->vertex_count, mesh->face_count,
                      (unsigned long long)x->edge_count);
    for (size_t v = 0; out->ok && v < mesh->vertex_count; v++) {
        put_vertex(out, mesh, v, normals, as_float);
        put_text(out, &x->vertex, v);
        rs_io_text_char(out, '\n');
    }
    put_faces(out, mesh, &x->face);
}

/* OFF, COFF, NOFF or CNOFF from the mesh's own fields. */
static void write_generic(const rsmooth_mesh *mesh, const void *no_extras, const double *normals,
                          bool as_float, rs_io_text_out *out) {
    (void)no_extras;
    const uint8_t *colors = mesh->vertex_colors;
    rs_io_text_printf(out, "%s%sOFF\n%zu %zu 0\n", colors ? "C" : "", normals ? "N" : "",
                      mesh->vertex_count, mesh->face_count);
    for (size_t v = 0; out->ok && v < mesh->vertex_count; v++) {
        put_vertex(out, mesh, v, normals, as_float);
        if (colors) {
            char *p = rs_io_text_reserve(out, 20);
            char *start = p;
            for (int c = 0; c < 3; c++) {
                *p++ = ' ';
                p += rs_io_print_u64(p, colors[3 * v + (size_t)c]);
            }
            memcpy(p, " 255", 4);
            out->used += (size_t)(p + 4 - start);
        }
        rs_io_text_char(out, '\n');
    }
    put_faces(out, mesh, NULL);
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
    return rs_io_text_write_mesh(mesh, stream, RSMOOTH_FORMAT_OFF, "OFF", write_faithful,
                                 write_generic, x, wants_normals(mesh, x), where, error);
}
