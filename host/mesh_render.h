/* A small deterministic software rasterizer: flat-shaded pictures of meshes side by side. */
#ifndef RSMOOTH_MESH_RENDER_H
#define RSMOOTH_MESH_RENDER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* One mesh to draw in its own panel. */
typedef struct render_mesh {
    const double *xyz; /* 3 * vertex_count */
    size_t vertex_count;
    const uint32_t *triangles; /* 3 * triangle_count, indices < vertex_count, either winding */
    size_t triangle_count;
    const uint8_t *colors; /* 3 * vertex_count RGB, or NULL for the light grey base colour */
} render_mesh;

typedef struct render_options {
    double azimuth_deg;   /* about the +y (up) axis; 0 looks from +z towards -z, 90 from +x */
    double elevation_deg; /* above the xz plane; within (-90, 90) */
    bool orthographic;    /* else perspective with field of view fov_deg */
    double fov_deg;       /* perspective only: the angle the bounding sphere fills, (0, 170) */
    double margin;        /* empty fraction of each panel on every side, [0, 0.45] */
    int gap;              /* pixels between panels (light grey), >= 0 */
} render_options;

/* Azimuth 35, elevation 25 (a 3/4 view that shows three sides of a box), perspective with a 30
 * degree field of view, 4% margin, 6 pixel gap. */
void render_options_default(render_options *options);

/* Draws `mesh_count` meshes side by side into `rgb` (3 * width * height bytes, rows top to bottom),
 * each in a panel of floor((width - (mesh_count - 1) * gap) / mesh_count) x height pixels; the
 * panels are centred as a strip. One camera for all panels, fitted to every vertex of every mesh
 * (projected extent centred in a panel, filling 1 - 2 * margin of it in its tighter direction), so
 * a mesh and its smoothed copy are drawn at the same place and scale. Background exactly white.
 * Same input, same bytes: no threads, no clock. Returns 0, or -1 on bad arguments (rgb untouched)
 * or when out of memory. */
int mesh_render(const render_mesh *meshes, size_t mesh_count, const render_options *options,
                uint8_t *rgb, int width, int height);

#endif
