/* STL reader (ascii and binary). */
#include "io/io_internal.h"

rsmooth_status rs_io_stl_read(const char *data, size_t size, rsmooth_mesh **mesh,
                              rsmooth_error *error) {
    (void)data, (void)size, (void)mesh;
    return rs_fail(error, RSMOOTH_ERROR_UNSUPPORTED, "rs_io_stl_read", "STL is not supported yet");
}

void rs_io_stl_extras_free(rs_stl_extras *extras) {
    (void)extras;
}

size_t rs_io_stl_losses(const rs_stl_extras *extras, rsmooth_format target, char *list,
                        size_t size) {
    (void)extras, (void)target, (void)list, (void)size;
    return 0;
}
