/* What the text mesh writers (OBJ, OFF) share: the file around their body (the normals computed
 * first, the byte-order mark, the buffered writer, the flush), the choice between the input's
 * layout and rsmooth's own, and numbers written so that they read back as they are. Calls
 * text_out.c, float_print.c and mesh_normals.c. */
#include "io/io_internal.h"
#include "io/text_out.h"

#include <errno.h>
#include <math.h>
#include <string.h>

void rs_io_text_coordinate(rs_io_text_out *out, double v, bool as_float) {
    if (as_float && isfinite((float)v)) /* else the double it is: text holds either */
        rs_io_text_float(out, (float)v);
    else
        rs_io_text_double(out, v);
}

void rs_io_text_normal(rs_io_text_out *out, double n, bool exact, bool as_float) {
    rs_io_text_char(out, ' ');
    if (exact)
        rs_io_text_coordinate(out, n, as_float);
    else
        rs_io_text_g9(out, n);
}

rsmooth_status rs_io_text_write_mesh(const rsmooth_mesh *mesh, FILE *stream, rsmooth_format format,
                                     const char *name, rs_io_text_body faithful,
                                     rs_io_text_body generic, const void *extras, bool want_normals,
                                     const char *where, rsmooth_error *error) {
    double *normals = NULL;
    if (want_normals) {
        rsmooth_status status = rs_io_vertex_normals(mesh, &normals, where, error);
        if (status != RSMOOTH_OK)
            return status;
    }
    rs_io_text_out out;
    rs_io_text_open(&out, stream);
    errno = 0;
    bool ok = rs_io_put_bom(mesh, format, stream);
    if (ok)
        (extras ? faithful : generic)(mesh, extras, normals, rs_io_float32_holds(mesh), &out);
    ok = rs_io_text_close(&out) && ok;
    ok = ok && fflush(stream) == 0 && !ferror(stream);
    rs_free(normals);
    if (!ok)
        return rs_fail(error, RSMOOTH_ERROR_IO, where, "writing %s: %s", name,
                       errno ? strerror(errno) : "stream error");
    return RSMOOTH_OK;
}
