/* What writers refuse, checked before their first byte (and by rsmooth_mesh_check_writable without
 * writing): a mesh that is not well-formed, values no reader would read back, and per format what
 * its file cannot hold, float32 at the mesh's own scale among them. */
#include "io/io_internal.h"

#include <float.h>
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

rsmooth_status rs_io_check_position_values(const double *xyz, size_t count, const uint32_t *ids,
                                           const char *where, rsmooth_error *error) {
    for (size_t i = 0; i < 3 * count; i++) {
        double x = xyz[i];
        size_t vertex = ids ? ids[i / 3] : i / 3;
        if (!isfinite(x))
            return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                           "vertex %zu has a non-finite coordinate (%g): not written", vertex, x);
        if (!rs_io_coordinate_ok(x))
            return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                           "vertex %zu has coordinate %s beyond the supported magnitude %s: not "
                           "written (rsmooth could not read it back)",
                           vertex, rs_io_shortest(x).text,
                           rs_io_shortest(RS_MAX_COORDINATE).text);
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

bool rs_io_float32_misfit_find(const double *xyz, size_t vertex_count, const uint32_t *indices,
                               size_t index_count, unsigned axes, rs_io_float32_misfit *misfit) {
    size_t n = indices ? index_count : vertex_count;
    double largest = 0;
    for (size_t i = 0; i < n; i++) {
        const double *p = xyz + 3 * (size_t)(indices ? indices[i] : i);
        largest = fmax(largest, fmax(fabs(p[0]), fmax(fabs(p[1]), fabs(p[2]))));
    }
    const double tolerance = rs_io_float32_tolerance(largest);
    for (size_t i = 0; i < n; i++) {
        size_t v = indices ? indices[i] : i;
        for (int c = 0; c < 3; c++) {
            double x = xyz[3 * v + (size_t)c];
            if (((axes >> c) & 1) && rs_io_float32_misfits(x, tolerance)) {
                *misfit = (rs_io_float32_misfit){v, c, x, (float)x, largest};
                return true;
            }
        }
    }
    return false;
}

bool rs_io_float32_holds(const rsmooth_mesh *mesh) {
    rs_io_float32_misfit misfit;
    return mesh->precision == RSMOOTH_FLOAT32 &&
           !rs_io_float32_misfit_find(mesh->positions, mesh->vertex_count, NULL, 0, 7, &misfit) &&
           !(rs_io_normals_are_data(mesh) &&
             rs_io_float32_misfit_find(mesh->vertex_normals, mesh->vertex_count, NULL, 0, 7,
                                       &misfit));
}

rsmooth_status rs_io_check_writable(const rsmooth_mesh *mesh, rsmooth_format format,
                                    const char *where, rsmooth_error *error) {
    rsmooth_status status = rs_io_mesh_check(mesh, where, error);
    if (status == RSMOOTH_OK)
        status = rs_io_mesh_check_values(mesh, where, error);
    if (status != RSMOOTH_OK)
        return status;
    switch (format) {
    case RSMOOTH_FORMAT_OBJ:
        return rs_io_obj_check(mesh, error);
    case RSMOOTH_FORMAT_PLY_ASCII:
    case RSMOOTH_FORMAT_PLY_BINARY:
        return rs_io_ply_check(mesh, error);
    case RSMOOTH_FORMAT_PLY_BINARY_BE:
        return rs_fail(error, RSMOOTH_ERROR_UNSUPPORTED, where,
                       "big-endian PLY output is not supported");
    case RSMOOTH_FORMAT_OFF:
        return rs_io_off_check(mesh, error);
    case RSMOOTH_FORMAT_STL_ASCII:
        return rs_io_stl_check(mesh, false, error);
    case RSMOOTH_FORMAT_STL_BINARY:
        return rs_io_stl_check(mesh, true, error);
    case RSMOOTH_FORMAT_AUTO:
        break;
    }
    return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                   "format %d: give OBJ, PLY, OFF or STL", (int)format);
}

rsmooth_status rsmooth_mesh_check_writable(const rsmooth_mesh *mesh, rsmooth_format format,
                                           rsmooth_error *error) {
    rs_error_clear(error);
    return rs_io_check_writable(mesh, format, "rsmooth_mesh_check_writable", error);
}
