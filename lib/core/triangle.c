/* The one formula every path uses for a triangle's centroid, unit normal and area (and the sums
 * of its cross products that make area-weighted vertex normals): the filter's
 * paths and the streaming reader (rsmooth_io) alike, which is why it sits with the objects both
 * libraries carry. */
#include "core/rsmooth_internal.h"

#include <math.h>

bool rs_triangle_normal(const double *xyz, const uint32_t *tri, double normal[3], double *area) {
    const double *a = xyz + 3 * (size_t)tri[0], *b = xyz + 3 * (size_t)tri[1];
    const double *c = xyz + 3 * (size_t)tri[2];
    double e1[3], e2[3], n[3];
    rs_sub3(b, a, e1);
    rs_sub3(c, a, e2);
    rs_cross3(e1, e2, n);
    double len = sqrt(rs_dot3(n, n));
    if (!(len > 0) || !isfinite(len))
        return false;
    double inv_len = 1 / len;
    for (int k = 0; k < 3; k++)
        normal[k] = n[k] * inv_len;
    *area = 0.5 * len;
    return true;
}

bool rs_triangle_geometry(const double *xyz, const uint32_t *tri, double centroid[3],
                          double normal[3], double *area) {
    if (!rs_triangle_normal(xyz, tri, normal, area))
        return false;
    rs_triangle_centroid(xyz, tri, centroid);
    return true;
}

void rs_add_area_normals(const double *xyz, const uint32_t *indices, size_t triangle_count,
                         const uint32_t *rep, double *normal) {
    for (size_t t = 0; t < triangle_count; t++) {
        const uint32_t *tri = indices + 3 * t;
        double e1[3], e2[3], n[3];
        rs_sub3(xyz + 3 * (size_t)tri[1], xyz + 3 * (size_t)tri[0], e1);
        rs_sub3(xyz + 3 * (size_t)tri[2], xyz + 3 * (size_t)tri[0], e2);
        rs_cross3(e1, e2, n); /* twice the area times the unit normal */
        for (int c = 0; c < 3; c++) {
            size_t v = rep ? rep[tri[c]] : tri[c];
            for (int k = 0; k < 3; k++)
                normal[3 * v + (size_t)k] += n[k];
        }
    }
}
