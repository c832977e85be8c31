/* Vertex normals recomputed from positions: what writers emit for files that carried normals, so
 * filtered meshes never keep their noisy input normals. Point clouds (no triangles) keep theirs. */
#include "io/io_internal.h"

#include <limits.h>
#include <math.h>
#include <string.h>

/* A triangle's cross product (twice its area along its normal) overflows beyond coordinates of
 * about 1e154 and underflows below 1e-162, so each is carried as a vector of magnitude about 1
 * times 2^e, and each vertex's sum at the exponent of its largest term (smaller terms scaled into
 * it). */
static void add_scaled(double sum[3], int *sum_exponent, const double m[3], int e) {
    if (*sum_exponent == INT_MIN) { /* the first term */
        memcpy(sum, m, 3 * sizeof *sum);
        *sum_exponent = e;
        return;
    }
    if (e > *sum_exponent) {
        for (int k = 0; k < 3; k++)
            sum[k] = ldexp(sum[k], *sum_exponent - e);
        *sum_exponent = e;
    }
    for (int k = 0; k < 3; k++)
        sum[k] += ldexp(m[k], e - *sum_exponent);
}

/* The largest magnitude among n values, as the exponent of frexp (0 when all are 0). */
static int max_exponent(const double *v, int n) {
    double largest = 0;
    for (int k = 0; k < n; k++)
        largest = fmax(largest, fabs(v[k]));
    int e = 0;
    frexp(largest, &e);
    return e;
}

rsmooth_status rsmooth_mesh_vertex_normals(const rsmooth_mesh *mesh, double *normals,
                                           rsmooth_error *error) {
    static const char where[] = "rsmooth_mesh_vertex_normals";
    rs_error_clear(error);
    if (!mesh || !normals)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "mesh or normals is NULL");
    if (mesh->triangle_count > 0 && !mesh->triangles)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "%zu triangles but triangles is NULL", mesh->triangle_count);
    int *exponents = rs_alloc_array(mesh->vertex_count ? mesh->vertex_count : 1, sizeof(int));
    if (!exponents)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "%zu vertices",
                       mesh->vertex_count);
    memset(normals, 0, mesh->vertex_count * 3 * sizeof *normals);
    for (size_t v = 0; v < mesh->vertex_count; v++)
        exponents[v] = INT_MIN; /* no term yet */
    for (size_t t = 0; t < mesh->triangle_count; t++) {
        const uint32_t *tri = mesh->triangles + 3 * t;
        if (tri[0] >= mesh->vertex_count || tri[1] >= mesh->vertex_count ||
            tri[2] >= mesh->vertex_count) {
            rs_free(exponents);
            return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                           "triangle %zu has an index out of range", t);
        }
        const double *a = mesh->positions + 3 * (size_t)tri[0];
        const double *b = mesh->positions + 3 * (size_t)tri[1];
        const double *c = mesh->positions + 3 * (size_t)tri[2];
        double edges[6] = {b[0] - a[0], b[1] - a[1], b[2] - a[2],
                           c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        int edge_exponent = max_exponent(edges, 6);
        for (int k = 0; k < 6; k++) /* powers of two: exact */
            edges[k] = ldexp(edges[k], -edge_exponent);
        const double *e1 = edges, *e2 = edges + 3;
        double m[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                       e1[0] * e2[1] - e1[1] * e2[0]};
        if (!isfinite(m[0] + m[1] + m[2]) || (m[0] == 0 && m[1] == 0 && m[2] == 0))
            continue; /* zero area (or coordinates no double difference holds): no weight */
        int m_exponent = max_exponent(m, 3);
        for (int k = 0; k < 3; k++)
            m[k] = ldexp(m[k], -m_exponent);
        for (int corner = 0; corner < 3; corner++)
            add_scaled(normals + 3 * (size_t)tri[corner], &exponents[tri[corner]], m,
                       2 * edge_exponent + m_exponent);
    }
    rs_free(exponents);
    for (size_t v = 0; v < mesh->vertex_count; v++) {
        double *n = normals + 3 * v;
        double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (int k = 0; k < 3; k++)
            n[k] = len > 0 ? n[k] / len : 0;
    }
    return RSMOOTH_OK;
}

rsmooth_status rs_io_check_normals(const rsmooth_mesh *mesh, const char *where,
                                   rsmooth_error *error) {
    if (rs_io_normals_are_data(mesh)) {
        /* a point cloud: no triangle to recompute from, so its own normals (filtered or read),
         * which must be finite to be read back */
        for (size_t i = 0; i < 3 * mesh->vertex_count; i++)
            if (!isfinite(mesh->vertex_normals[i]))
                return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                               "vertex %zu has a non-finite normal (%g): not written", i / 3,
                               mesh->vertex_normals[i]);
        return RSMOOTH_OK;
    }
    if (mesh->triangle_count > 0 && !mesh->triangles)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "normals: %zu triangles but triangles is NULL", mesh->triangle_count);
    for (size_t t = 0; t < 3 * mesh->triangle_count; t++)
        if (mesh->triangles[t] >= mesh->vertex_count)
            return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                           "normals: triangle %zu has an index out of range", t / 3);
    return RSMOOTH_OK;
}

rsmooth_status rs_io_vertex_normals(const rsmooth_mesh *mesh, double **normals, const char *where,
                                    rsmooth_error *error) {
    *normals = NULL;
    rsmooth_status status = rs_io_check_normals(mesh, where, error);
    if (status != RSMOOTH_OK)
        return status;
    *normals = rs_alloc_array(mesh->vertex_count, 3 * sizeof(double));
    if (!*normals)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "normals of %zu vertices",
                       mesh->vertex_count);
    if (rs_io_normals_are_data(mesh)) {
        memcpy(*normals, mesh->vertex_normals, mesh->vertex_count * 3 * sizeof(double));
        return RSMOOTH_OK;
    }
    rsmooth_error inner;
    status = rsmooth_mesh_vertex_normals(mesh, *normals, &inner);
    if (status != RSMOOTH_OK) {
        rs_free(*normals);
        *normals = NULL;
        return rs_fail(error, status, where, "normals: %s", inner.message);
    }
    return RSMOOTH_OK;
}
