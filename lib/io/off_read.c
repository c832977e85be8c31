/* OFF reader (OFF, COFF, NOFF, CNOFF). */
#include "io/io_internal.h"

rsmooth_status rs_io_off_read(const char *data, size_t size, rsmooth_mesh **mesh,
                              rsmooth_error *error) {
    (void)data, (void)size, (void)mesh;
    return rs_fail(error, RSMOOTH_ERROR_UNSUPPORTED, "rs_io_off_read", "OFF is not supported yet");
}

void rs_io_off_extras_free(rs_off_extras *extras) {
    (void)extras;
}

size_t rs_io_off_losses(const rs_off_extras *extras, rsmooth_format target, char *list,
                        size_t size) {
    (void)extras, (void)target, (void)list, (void)size;
    return 0;
}
