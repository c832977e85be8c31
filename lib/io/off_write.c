/* OFF writer. */
#include "io/io_internal.h"

rsmooth_status rs_io_off_write(const rsmooth_mesh *mesh, FILE *stream, rsmooth_error *error) {
    (void)mesh, (void)stream;
    return rs_fail(error, RSMOOTH_ERROR_UNSUPPORTED, "rs_io_off_write", "OFF is not supported yet");
}
