/* The checks every writer makes before its first byte: a mesh that is not well-formed, values no
 * reader would read back. Each format's own refusals are its writer's (rs_io_*_check), and
 * mesh_file.c runs them all in order (rs_io_check_writable). */
#include "io/io_internal.h"

#include <math.h>

rsmooth_status rs_io_mesh_check(const rsmooth_mesh *mesh, const char *where, rsmooth_error *error) {
    if (!mesh)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "mesh is NULL");
    if ((uint64_t)mesh->vertex_count >= RS_IO_MAX_VERTICES)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "vertex count %zu not below 2^32", mesh->vertex_count);
    if (mesh->vertex_count > 0 && !mesh->positions)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "positions is NULL");
    if (mesh->face_count == 0)
        return RSMOOTH_OK;
    if (!mesh->face_offsets || !mesh->face_indices)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "%zu faces but face_offsets or face_indices is NULL", mesh->face_count);
    if (mesh->face_offsets[0] != 0)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "face_offsets[0] is %u, not 0",
                       (unsigned)mesh->face_offsets[0]);
    for (size_t f = 0; f < mesh->face_count; f++) {
        uint32_t begin = mesh->face_offsets[f], end = mesh->face_offsets[f + 1];
        if (end < begin || end - begin < 3)
            return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                           "face %zu has %lld vertices (at least 3 needed)", f,
                           (long long)end - (long long)begin);
        for (uint32_t i = begin; i < end; i++)
            if (mesh->face_indices[i] >= mesh->vertex_count)
                return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                               "face %zu: index %u >= vertex count %zu", f,
                               (unsigned)mesh->face_indices[i], mesh->vertex_count);
    }
    return RSMOOTH_OK;
}

rsmooth_status rs_io_mesh_check_values(const rsmooth_mesh *mesh, const char *where,
                                       rsmooth_error *error) {
    rsmooth_status status =
        rs_io_check_position_values(mesh->positions, mesh->vertex_count, NULL, where, error);
    if (status != RSMOOTH_OK)
        return status;
    for (size_t i = 0; mesh->vertex_quality && i < mesh->vertex_count; i++)
        if (!isfinite(mesh->vertex_quality[i]))
            return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                           "vertex %zu has a non-finite quality (%g): not written", i,
                           (double)mesh->vertex_quality[i]);
    return RSMOOTH_OK;
}
