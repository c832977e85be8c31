/* Vertex normals recomputed from positions: what writers emit for files that carried normals, so
 * filtered meshes never keep their noisy input normals. Point clouds (no triangles) keep theirs. */
#include "io/io_internal.h"

#include <math.h>
#include <string.h>

rsmooth_status rsmooth_mesh_vertex_normals(const rsmooth_mesh *mesh, double *normals,
                                           rsmooth_error *error) {
    static const char where[] = "rsmooth_mesh_vertex_normals";
    rs_error_clear(error);
    if (!mesh || !normals)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "mesh or normals is NULL");
    if (mesh->triangle_count > 0 && !mesh->triangles)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "%zu triangles but triangles is NULL", mesh->triangle_count);
    memset(normals, 0, mesh->vertex_count * 3 * sizeof *normals);
    for (size_t t = 0; t < mesh->triangle_count; t++) {
        const uint32_t *tri = mesh->triangles + 3 * t;
        if (tri[0] >= mesh->vertex_count || tri[1] >= mesh->vertex_count ||
            tri[2] >= mesh->vertex_count)
            return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                           "triangle %zu has an index out of range", t);
        const double *a = mesh->positions + 3 * (size_t)tri[0];
        const double *b = mesh->positions + 3 * (size_t)tri[1];
        const double *c = mesh->positions + 3 * (size_t)tri[2];
        double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        double e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        /* The cross product's length is twice the area: summing it weights faces by area. */
        double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                       e1[0] * e2[1] - e1[1] * e2[0]};
        for (int corner = 0; corner < 3; corner++)
            for (int k = 0; k < 3; k++)
                normals[3 * (size_t)tri[corner] + k] += n[k];
    }
    for (size_t v = 0; v < mesh->vertex_count; v++) {
        double *n = normals + 3 * v;
        double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (int k = 0; k < 3; k++)
            n[k] = len > 0 ? n[k] / len : 0;
    }
    return RSMOOTH_OK;
}

rsmooth_status rs_io_vertex_normals(const rsmooth_mesh *mesh, double **normals, const char *where,
                                    rsmooth_error *error) {
    *normals = rs_alloc_array(mesh->vertex_count, 3 * sizeof(double));
    if (!*normals)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "normals of %zu vertices",
                       mesh->vertex_count);
    if (mesh->triangle_count == 0 && mesh->vertex_normals) {
        /* a point cloud: no triangle to recompute from, so its own normals (filtered or read) */
        memcpy(*normals, mesh->vertex_normals, mesh->vertex_count * 3 * sizeof(double));
        return RSMOOTH_OK;
    }
    rsmooth_error inner;
    if (rsmooth_mesh_vertex_normals(mesh, *normals, &inner) != RSMOOTH_OK) {
        rs_free(*normals);
        *normals = NULL;
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "normals: %s",
                       inner.message);
    }
    return RSMOOTH_OK;
}
