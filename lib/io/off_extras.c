/* OFF extras: the record's release and what converting to another format drops from it. */
#include "io/off_format.h"

static void texts_free(rs_off_texts *texts) {
    rs_free(texts->text);
    rs_free(texts->offsets);
}

void rs_io_off_extras_free(rs_off_extras *extras) {
    if (!extras)
        return;
    texts_free(&extras->vertex);
    texts_free(&extras->face);
    rs_free(extras);
}

size_t rs_io_off_losses(const rs_off_extras *extras, rsmooth_format target, char *list,
                        size_t size) {
    if (!extras || target == RSMOOTH_FORMAT_OFF)
        return 0;
    size_t lost = 0;
    if (extras->face.offsets)
        lost += rs_io_loss_add(list, size, "OFF face colours");
    if (extras->texcoords)
        lost += rs_io_loss_add(list, size, "OFF texture coordinates");
    if (extras->alpha)
        lost += rs_io_loss_add(list, size, "OFF colour alpha");
    return lost;
}
