/* What both PLY data readers (ply_binary.c, ply_ascii.c) share while reading an element's items:
 * faces and their indices, the checks of a vertex as read, and list items' storage. They call
 * nothing above this file; ply_read.c drives them. */
#include "io/ply_reader.h"

#include <math.h>

static const char where[] = RS_PLY_READ_WHERE;

rsmooth_status rs_ply_face_begin(rs_ply_reader *r, uint64_t n, uint64_t item, int64_t line,
                                 int64_t offset, rsmooth_error *error) {
    if (n < 3)
        return rs_fail_parse(error, line, offset, where,
                             "face %llu has %llu vertices (at least 3 needed)",
                             (unsigned long long)item, (unsigned long long)n);
    if (n >= RS_IO_MAX_FACE_INDICES - r->indices.count)
        return rs_fail_parse(error, line, offset, where, "too many face indices (32-bit offsets)");
    if (!rs_io_u32vec_reserve(&r->indices, (size_t)n))
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "%zu face indices",
                       r->indices.count + (size_t)n);
    return RSMOOTH_OK;
}

rsmooth_status rs_ply_face_index(rs_ply_reader *r, double v, int64_t line, int64_t offset,
                                 rsmooth_error *error) {
    /* The vertex count comes from the header, so faces before the vertex data check as well. */
    if (!(v >= 0 && v < (double)r->vertex_count && v == floor(v)))
        return rs_fail_parse(error, line, offset, where,
                             "face index %.17g out of range (%zu vertices)", v, r->vertex_count);
    r->indices.data[r->indices.count++] = (uint32_t)v;
    return RSMOOTH_OK;
}

/* A vertex as read (its row stored): coordinates rsmooth supports, finite normals (a point cloud's
 * data; a mesh's are recomputed, but a file holding others is not what it claims) and finite colour
 * channels (they become vertex_colors). */
rsmooth_status rs_ply_check_vertex(const rs_ply_reader *r, size_t i, int64_t line, int64_t offset,
                                   rsmooth_error *error) {
    rsmooth_status status = rs_io_check_vertex(r->positions + 3 * i, i, line, offset, where, error);
    if (status != RSMOOTH_OK)
        return status;
    const double *n = r->normal_values ? r->normal_values + 3 * i : NULL;
    if (n && (!isfinite(n[0]) || !isfinite(n[1]) || !isfinite(n[2])))
        return rs_fail_parse(error, line, offset, where, "vertex %zu has a non-finite normal", i);
    const rs_ply_element *v = r->vertex_element;
    for (int c = 0; r->color[0] != SIZE_MAX && c < 3; c++) {
        const rs_ply_property *p = &v->properties[r->color[c]];
        if (rs_ply_type_is_float(p->type) &&
            !isfinite(rs_ply_host_value(v->rows + i * v->row_size + p->row_offset, p->type)))
            return rs_fail_parse(error, line, offset, where,
                                 "vertex %zu has a non-finite colour ('%.40s')", i, p->name);
    }
    return RSMOOTH_OK;
}

/* Room for `extra` more bytes of list items (geometric growth). */
bool rs_ply_list_reserve(rs_ply_element *e, size_t extra) {
    if (e->list_capacity - e->list_bytes >= extra)
        return true;
    if (extra > SIZE_MAX / 2 - e->list_bytes)
        return false;
    size_t need = e->list_bytes + extra;
    size_t capacity = e->list_capacity ? e->list_capacity : 256;
    while (capacity < need)
        capacity = capacity > SIZE_MAX / 4 ? need : 2 * capacity;
    unsigned char *items = rs_realloc_array(e->list_items, capacity, 1);
    if (!items)
        return false;
    e->list_items = items;
    e->list_capacity = capacity;
    return true;
}

rsmooth_status rs_ply_list_oom(const rs_ply_element *e, rsmooth_error *error) {
    return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "list values of element '%.40s'",
                   e->name);
}
