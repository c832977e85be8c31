/* PLY extras: the elements, properties and comments a PLY file carries beyond positions and faces.
 */
#include "io/ply_format.h"

#include <stdio.h>

void rs_io_ply_extras_free(rs_ply_extras *extras) {
    if (!extras)
        return;
    for (size_t c = 0; c < extras->comment_count; c++)
        rs_free(extras->comments[c].text);
    rs_free(extras->comments);
    for (size_t e = 0; e < extras->element_count; e++) {
        rs_ply_element *el = &extras->elements[e];
        for (size_t k = 0; k < el->property_count; k++)
            rs_free(el->properties[k].name);
        rs_free(el->properties);
        rs_free(el->rows);
        rs_free(el->list_items);
        rs_free(el->name);
    }
    rs_free(extras->elements);
    rs_free(extras);
}

/* Names at most this many properties (and elements) one by one; the rest are counted in one entry,
 * so a file with hundreds of custom properties still gives a one-line warning. */
#define MAX_NAMED 6

size_t rs_io_ply_losses(const rs_ply_extras *extras, rsmooth_format target, char *list,
                        size_t size) {
    if (!extras || rs_io_is_ply(target))
        return 0;
    size_t lost = 0, named_properties = 0, named_elements = 0;
    size_t unnamed_properties = 0, unnamed_elements = 0;
    char what[128];
    for (size_t e = 0; e < extras->element_count; e++) {
        const rs_ply_element *el = &extras->elements[e];
        bool vertex = e == extras->vertex_element, face = e == extras->face_element;
        if (!vertex && !face) {
            lost++;
            if (named_elements < MAX_NAMED) {
                snprintf(what, sizeof what, "PLY element '%.60s'", el->name);
                rs_io_loss_add(list, size, what);
                named_elements++;
            } else {
                unnamed_elements++;
            }
            continue;
        }
        for (size_t k = 0; k < el->property_count; k++) {
            const rs_ply_property *p = &el->properties[k];
            /* Colours travel in vertex_colors, normals are recomputed: mesh_data.c reports them. */
            if (p->role != RS_PLY_STORED || p->color)
                continue;
            lost++;
            if (named_properties < MAX_NAMED) {
                snprintf(what, sizeof what, "PLY %s property '%.60s'", vertex ? "vertex" : "face",
                         p->name);
                rs_io_loss_add(list, size, what);
                named_properties++;
            } else {
                unnamed_properties++;
            }
        }
    }
    if (unnamed_properties > 0) {
        snprintf(what, sizeof what, "and %zu more PLY propert%s", unnamed_properties,
                 unnamed_properties == 1 ? "y" : "ies");
        rs_io_loss_add(list, size, what);
    }
    if (unnamed_elements > 0) {
        snprintf(what, sizeof what, "and %zu more PLY element%s", unnamed_elements,
                 unnamed_elements == 1 ? "" : "s");
        rs_io_loss_add(list, size, what);
    }
    if (extras->comment_count > 0)
        lost += rs_io_loss_add(list, size, "PLY comments");
    return lost;
}
