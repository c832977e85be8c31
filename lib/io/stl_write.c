/* STL writer (ascii and binary). */
#include "io/io_internal.h"

rsmooth_status rs_io_stl_write(const rsmooth_mesh *mesh, FILE *stream, bool binary,
                               rsmooth_error *error) {
    (void)mesh, (void)stream, (void)binary;
    return rs_fail(error, RSMOOTH_ERROR_UNSUPPORTED, "rs_io_stl_write", "STL is not supported yet");
}
