/* OBJ extras: texture coordinates, groups, objects, materials and smoothing groups of an OBJ file.
 */
#include "io/obj_format.h"

void rs_io_obj_extras_free(rs_obj_extras *extras) {
    if (!extras)
        return;
    rs_free(extras->text);
    rs_free(extras->corner_vt);
    rs_free(extras->runs);
    rs_free(extras);
}

size_t rs_io_obj_losses(const rs_obj_extras *extras, rsmooth_format target, char *list,
                        size_t size) {
    if (!extras || target == RSMOOTH_FORMAT_OBJ)
        return 0;
    /* Colours and normals are generic mesh fields: mesh_data.c reports them for targets that
     * cannot hold them. */
    static const struct {
        unsigned kind;
        const char *what;
    } kinds[] = {
        {RS_OBJ_TEXCOORDS, "OBJ texture coordinates"}, {RS_OBJ_GROUPS, "OBJ groups and objects"},
        {RS_OBJ_MATERIALS, "OBJ materials"},           {RS_OBJ_SMOOTHING, "OBJ smoothing groups"},
        {RS_OBJ_LINES, "OBJ lines and points"},        {RS_OBJ_COMMENTS, "OBJ comments"},
        {RS_OBJ_VERTEX_W, "OBJ vertex w coordinates"}, {RS_OBJ_OTHER, "OBJ other statements"}};
    size_t lost = 0;
    for (size_t i = 0; i < sizeof kinds / sizeof kinds[0]; i++)
        if (extras->kinds & kinds[i].kind)
            lost += rs_io_loss_add(list, size, kinds[i].what);
    return lost;
}
