/* Whether float32 holds a mesh's coordinates at the mesh's own scale: binary STL's refusal and the
 * precision text writers print at. */
#include "io/io_internal.h"

#include <math.h>

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
