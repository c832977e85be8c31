/* PLY extras: the elements, properties and comments a PLY file carries beyond positions and faces. */
#include "io/io_internal.h"

void rs_io_ply_extras_free(rs_ply_extras *extras) {
    (void)extras; /* not yet kept */
}

size_t rs_io_ply_losses(const rs_ply_extras *extras, rsmooth_format target, char *list,
                        size_t size) {
    (void)extras, (void)target, (void)list, (void)size;
    return 0;
}
