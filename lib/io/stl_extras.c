/* STL extras: the record's release and what converting to another format drops from it. */
#include "io/stl_format.h"

void rs_io_stl_extras_free(rs_stl_extras *extras) {
    if (!extras)
        return;
    for (size_t i = 0; i < extras->solid_count; i++)
        rs_free(extras->solids[i].name);
    rs_free(extras->solids);
    rs_free(extras->attributes);
    rs_free(extras);
}

size_t rs_io_stl_losses(const rs_stl_extras *extras, rsmooth_format target, char *list,
                        size_t size) {
    if (!extras)
        return 0;
    size_t lost = 0;
    if (!rs_io_is_stl(target)) {
        bool named = extras->binary && !rs_stl_header_is_blank(extras->header);
        for (size_t i = 0; !named && i < extras->solid_count; i++)
            named = extras->solids[i].name_len > 0;
        if (named)
            lost += rs_io_loss_add(list, size, "STL header");
    }
    /* Only binary STL holds attributes. */
    if (extras->attributes && target != RSMOOTH_FORMAT_STL_BINARY)
        lost += rs_io_loss_add(list, size, "STL facet attributes");
    return lost;
}
