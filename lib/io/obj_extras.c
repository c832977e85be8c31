/* OBJ extras: texture coordinates, groups, objects, materials and smoothing groups of an OBJ file. */
#include "io/io_internal.h"

void rs_io_obj_extras_free(rs_obj_extras *extras) {
    (void)extras; /* not yet kept */
}

size_t rs_io_obj_losses(const rs_obj_extras *extras, rsmooth_format target, char *list,
                        size_t size) {
    (void)extras, (void)target, (void)list, (void)size;
    return 0;
}
