/* Wavefront OBJ writer: v lines (with r g b when the mesh has colours) and f lines of polygons. */
#include "io/io_internal.h"

#include <errno.h>
#include <string.h>

rsmooth_status rs_io_obj_write(const rsmooth_mesh *mesh, FILE *stream, rsmooth_error *error) {
    /* %.9g and %.17g are the shortest fixed widths that round-trip float and double exactly. */
    const char *vertex_format =
        mesh->precision == RSMOOTH_FLOAT32 ? "v %.9g %.9g %.9g" : "v %.17g %.17g %.17g";
    errno = 0;
    bool ok = fprintf(stream, "# written by rsmooth\n# %zu vertices, %zu faces\n",
                      mesh->vertex_count, mesh->face_count) >= 0;
    for (size_t i = 0; ok && i < mesh->vertex_count; i++) {
        const double *p = mesh->positions + 3 * i;
        double x = p[0], y = p[1], z = p[2];
        if (mesh->precision == RSMOOTH_FLOAT32) { /* what a float file would hold */
            x = (float)x;
            y = (float)y;
            z = (float)z;
        }
        ok = fprintf(stream, vertex_format, x, y, z) >= 0;
        if (ok && mesh->vertex_colors) {
            const uint8_t *c = mesh->vertex_colors + 3 * i;
            ok = fprintf(stream, " %.4g %.4g %.4g", c[0] / 255.0, c[1] / 255.0, c[2] / 255.0) >= 0;
        }
        ok = ok && putc('\n', stream) != EOF;
    }
    for (size_t f = 0; ok && f < mesh->face_count; f++) {
        ok = putc('f', stream) != EOF;
        for (uint32_t k = mesh->face_offsets[f]; ok && k < mesh->face_offsets[f + 1]; k++)
            ok = fprintf(stream, " %lu", (unsigned long)mesh->face_indices[k] + 1) >= 0;
        ok = ok && putc('\n', stream) != EOF;
    }
    ok = ok && fflush(stream) == 0 && !ferror(stream);
    if (!ok)
        return rs_fail(error, RSMOOTH_ERROR_IO, "rsmooth_mesh_write_stream", "writing OBJ: %s",
                       errno ? strerror(errno) : "stream error");
    return RSMOOTH_OK;
}
