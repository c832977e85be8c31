/* The software rasterizer behind `rsmooth render` (see mesh_render.h). */
#include "mesh_render.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define SUPERSAMPLE 2 /* samples per pixel along each axis: 2 x 2 box-filtered antialiasing */
#define PI 3.14159265358979323846

/* Light grey: dark enough that the brightest lit face stays below white, so faces never merge
 * into the background. */
static const double base_grey = 0.86;
/* Lights in camera space (x right, y up, z towards the viewer), fixed to the camera so every view
 * is lit alike. A strong key from the upper left and a weaker fill from the lower right give the
 * faces on either side of a sharp edge clearly different shades; the ambient term keeps faces
 * turned away from both lights from going black. */
static const double key_dir[3] = {-0.60, 0.60, 0.53};
static const double key_strength = 0.64;
static const double fill_dir[3] = {0.75, -0.10, 0.45};
static const double fill_strength = 0.26;
static const double ambient = 0.22;
static const uint8_t gap_grey = 0xD8;

typedef struct camera {
    bool ortho;
    double center[3], eye[3];
    double right[3], up[3], back[3];  /* orthonormal; back points from the scene to the eye */
    double key[3], fill[3];           /* light directions in world space */
    double scale, offset_x, offset_y; /* panel pixels = offset + scale * projected, y down */
} camera;

static double dot3(const double *a, const double *b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void normalize3(double *v) {
    double len = sqrt(dot3(v, v));
    if (len > 0) {
        v[0] /= len;
        v[1] /= len;
        v[2] /= len;
    }
}

/* Camera-space direction to world space. */
static void to_world(const camera *cam, const double *c, double *w) {
    for (int i = 0; i < 3; i++)
        w[i] = c[0] * cam->right[i] + c[1] * cam->up[i] + c[2] * cam->back[i];
    normalize3(w);
}

/* Projects world point `p` to the camera's image plane (x right, y up) and a depth key that
 * grows towards the eye and interpolates linearly in screen space (1 / distance for perspective,
 * which is what makes perspective-correct depth testing exact). False when behind the eye. */
static bool project(const camera *cam, const double *p, double *px, double *py, double *key) {
    if (cam->ortho) {
        double rel[3] = {p[0] - cam->center[0], p[1] - cam->center[1], p[2] - cam->center[2]};
        *px = dot3(rel, cam->right);
        *py = dot3(rel, cam->up);
        *key = dot3(rel, cam->back);
        return true;
    }
    double rel[3] = {p[0] - cam->eye[0], p[1] - cam->eye[1], p[2] - cam->eye[2]};
    double z = -dot3(rel, cam->back);
    if (!(z > 0))
        return false;
    *px = dot3(rel, cam->right) / z;
    *py = dot3(rel, cam->up) / z;
    *key = 1.0 / z;
    return true;
}

/* Aims the camera at the centre of the union of bounding boxes and fits the projection of every
 * vertex into a pw x ph panel. Fitting to the vertices rather than a bounding sphere keeps the
 * meshes large in the picture; one fit for all meshes keeps panels comparable. */
static void setup_camera(camera *cam, const render_mesh *meshes, size_t mesh_count,
                         const render_options *o, int pw, int ph) {
    memset(cam, 0, sizeof *cam);
    cam->ortho = o->orthographic;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t m = 0; m < mesh_count; m++) {
        for (size_t v = 0; v < meshes[m].vertex_count; v++) {
            for (int i = 0; i < 3; i++) {
                lo[i] = fmin(lo[i], meshes[m].xyz[3 * v + i]);
                hi[i] = fmax(hi[i], meshes[m].xyz[3 * v + i]);
            }
        }
    }
    double radius = 0;
    for (int i = 0; i < 3; i++) {
        if (!(lo[i] <= hi[i])) /* no vertices at all */
            lo[i] = hi[i] = 0;
        cam->center[i] = 0.5 * (lo[i] + hi[i]);
        radius += (hi[i] - lo[i]) * (hi[i] - lo[i]);
    }
    radius = 0.5 * sqrt(radius);
    if (!(radius > 0))
        radius = 1;

    double az = o->azimuth_deg * PI / 180, el = o->elevation_deg * PI / 180;
    cam->back[0] = cos(el) * sin(az);
    cam->back[1] = sin(el);
    cam->back[2] = cos(el) * cos(az);
    /* right = world up (0, 1, 0) x back; never zero since |elevation| < 90 */
    cam->right[0] = cam->back[2];
    cam->right[1] = 0;
    cam->right[2] = -cam->back[0];
    normalize3(cam->right);
    cam->up[0] = cam->back[1] * cam->right[2] - cam->back[2] * cam->right[1];
    cam->up[1] = cam->back[2] * cam->right[0] - cam->back[0] * cam->right[2];
    cam->up[2] = cam->back[0] * cam->right[1] - cam->back[1] * cam->right[0];
    /* Far enough that the bounding sphere fits the field of view: every vertex is in front. */
    double distance = radius / sin(0.5 * o->fov_deg * PI / 180);
    for (int i = 0; i < 3; i++)
        cam->eye[i] = cam->center[i] + distance * cam->back[i];
    to_world(cam, key_dir, cam->key);
    to_world(cam, fill_dir, cam->fill);

    double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
    for (size_t m = 0; m < mesh_count; m++) {
        for (size_t v = 0; v < meshes[m].vertex_count; v++) {
            double x, y, key;
            if (project(cam, meshes[m].xyz + 3 * v, &x, &y, &key)) {
                xmin = fmin(xmin, x);
                xmax = fmax(xmax, x);
                ymin = fmin(ymin, y);
                ymax = fmax(ymax, y);
            }
        }
    }
    if (!(xmin <= xmax)) {
        xmin = xmax = ymin = ymax = 0;
    }
    double avail_w = (1 - 2 * o->margin) * pw, avail_h = (1 - 2 * o->margin) * ph;
    double sx = xmax > xmin ? avail_w / (xmax - xmin) : INFINITY;
    double sy = ymax > ymin ? avail_h / (ymax - ymin) : INFINITY;
    cam->scale = fmin(sx, sy);
    if (!isfinite(cam->scale)) /* a single point: any scale draws nothing */
        cam->scale = 1;
    cam->offset_x = 0.5 * pw - cam->scale * 0.5 * (xmin + xmax);
    cam->offset_y = 0.5 * ph + cam->scale * 0.5 * (ymin + ymax);
}

/* Flat colour of one triangle, or false for a degenerate one (no area, nothing to draw). */
static bool face_colour(const camera *cam, const render_mesh *mesh, const uint32_t *t,
                        uint8_t out[3]) {
    const double *a = mesh->xyz + 3 * (size_t)t[0], *b = mesh->xyz + 3 * (size_t)t[1],
                 *c = mesh->xyz + 3 * (size_t)t[2];
    double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                   e1[0] * e2[1] - e1[1] * e2[0]};
    if (!(dot3(n, n) > 0))
        return false;
    normalize3(n);
    /* Two-sided: light the side facing the eye, so open meshes and either winding look alike. */
    double view[3];
    if (cam->ortho) {
        memcpy(view, cam->back, sizeof view);
    } else {
        for (int i = 0; i < 3; i++)
            view[i] = cam->eye[i] - a[i];
    }
    if (dot3(n, view) < 0) {
        n[0] = -n[0];
        n[1] = -n[1];
        n[2] = -n[2];
    }
    double shade = ambient + key_strength * fmax(0, dot3(n, cam->key)) +
                   fill_strength * fmax(0, dot3(n, cam->fill));
    for (int i = 0; i < 3; i++) {
        double base = base_grey * 255;
        if (mesh->colors) /* flat shading: the face's mean vertex colour */
            base = (mesh->colors[3 * (size_t)t[0] + i] + mesh->colors[3 * (size_t)t[1] + i] +
                    mesh->colors[3 * (size_t)t[2] + i]) /
                   3.0;
        double value = floor(base * shade + 0.5);
        out[i] = (uint8_t)(value > 255 ? 255 : value < 0 ? 0 : value);
    }
    return true;
}

/* Rasterizes one triangle into the supersampled colour and depth buffers (sw x sh samples). */
static void draw_triangle(const camera *cam, const render_mesh *mesh, const uint32_t *t,
                          uint8_t *color, double *depth, int sw, int sh) {
    double x[3], y[3], k[3];
    for (int j = 0; j < 3; j++) {
        double px, py;
        if (!project(cam, mesh->xyz + 3 * (size_t)t[j], &px, &py, &k[j]))
            return;
        x[j] = SUPERSAMPLE * (cam->offset_x + cam->scale * px);
        y[j] = SUPERSAMPLE * (cam->offset_y - cam->scale * py);
    }
    double area = (x[1] - x[0]) * (y[2] - y[0]) - (y[1] - y[0]) * (x[2] - x[0]);
    if (!(area != 0) || !isfinite(area))
        return;
    uint8_t rgb[3];
    if (!face_colour(cam, mesh, t, rgb))
        return;
    /* Samples sit at pixel centres (i + 0.5); clip the triangle's box to the panel. */
    double fx0 = ceil(fmin(x[0], fmin(x[1], x[2])) - 0.5),
           fx1 = floor(fmax(x[0], fmax(x[1], x[2])) - 0.5);
    double fy0 = ceil(fmin(y[0], fmin(y[1], y[2])) - 0.5),
           fy1 = floor(fmax(y[0], fmax(y[1], y[2])) - 0.5);
    if (fx1 < 0 || fy1 < 0 || fx0 > sw - 1 || fy0 > sh - 1)
        return;
    int ix0 = fx0 < 0 ? 0 : (int)fx0, ix1 = fx1 > sw - 1 ? sw - 1 : (int)fx1;
    int iy0 = fy0 < 0 ? 0 : (int)fy0, iy1 = fy1 > sh - 1 ? sh - 1 : (int)fy1;
    double inv = 1.0 / area;
    for (int iy = iy0; iy <= iy1; iy++) {
        double py = iy + 0.5;
        for (int ix = ix0; ix <= ix1; ix++) {
            double px = ix + 0.5;
            /* Barycentric weights from edge functions; the sign of `area` absorbs the winding.
             * Samples on a shared edge belong to both triangles, so there are no cracks. */
            double w0 = ((x[2] - x[1]) * (py - y[1]) - (y[2] - y[1]) * (px - x[1])) * inv;
            double w1 = ((x[0] - x[2]) * (py - y[2]) - (y[0] - y[2]) * (px - x[2])) * inv;
            double w2 = 1.0 - w0 - w1;
            if (w0 < 0 || w1 < 0 || w2 < 0)
                continue;
            double key = w0 * k[0] + w1 * k[1] + w2 * k[2];
            size_t s = (size_t)iy * (size_t)sw + (size_t)ix;
            if (key > depth[s]) {
                depth[s] = key;
                memcpy(color + 3 * s, rgb, 3);
            }
        }
    }
}

void render_options_default(render_options *options) {
    options->azimuth_deg = 35;
    options->elevation_deg = 25;
    options->orthographic = false;
    options->fov_deg = 30;
    options->margin = 0.04;
    options->gap = 6;
}

static bool valid_options(const render_options *o) {
    return isfinite(o->azimuth_deg) && o->elevation_deg > -90 && o->elevation_deg < 90 &&
           (o->orthographic || (o->fov_deg > 0 && o->fov_deg < 170)) && o->margin >= 0 &&
           o->margin <= 0.45 && o->gap >= 0;
}

int mesh_render(const render_mesh *meshes, size_t mesh_count, const render_options *options,
                uint8_t *rgb, int width, int height) {
    if (!meshes || mesh_count == 0 || !options || !rgb || width <= 0 || height <= 0 ||
        !valid_options(options) || mesh_count > (size_t)width)
        return -1;
    long long gaps = (long long)(mesh_count - 1) * options->gap;
    if (gaps >= width)
        return -1;
    int pw = (int)((width - gaps) / (long long)mesh_count), ph = height;
    if (pw <= 0)
        return -1;
    for (size_t m = 0; m < mesh_count; m++) {
        const render_mesh *mesh = &meshes[m];
        if ((mesh->vertex_count && !mesh->xyz) || (mesh->triangle_count && !mesh->triangles))
            return -1;
        for (size_t i = 0; i < 3 * mesh->triangle_count; i++)
            if (mesh->triangles[i] >= mesh->vertex_count)
                return -1;
    }
    if ((size_t)pw > SIZE_MAX / SUPERSAMPLE / SUPERSAMPLE / (size_t)ph / sizeof(double))
        return -1;
    int sw = SUPERSAMPLE * pw, sh = SUPERSAMPLE * ph;
    size_t samples = (size_t)sw * (size_t)sh;
    uint8_t *color = malloc(3 * samples);
    double *depth = malloc(samples * sizeof *depth);
    if (!color || !depth) {
        free(color);
        free(depth);
        return -1;
    }

    camera cam;
    setup_camera(&cam, meshes, mesh_count, options, pw, ph);
    memset(rgb, 255, 3 * (size_t)width * (size_t)height);
    long long strip = (long long)mesh_count * pw + gaps;
    int left = (int)((width - strip) / 2);
    for (size_t m = 0; m < mesh_count; m++) {
        int x0 = left + (int)m * (pw + options->gap);
        if (m > 0) { /* the gap before this panel */
            for (int y = 0; y < height; y++)
                memset(rgb + 3 * ((size_t)y * (size_t)width + (size_t)(x0 - options->gap)),
                       gap_grey, 3 * (size_t)options->gap);
        }
        memset(color, 255, 3 * samples);
        for (size_t s = 0; s < samples; s++)
            depth[s] = -INFINITY;
        for (size_t t = 0; t < meshes[m].triangle_count; t++)
            draw_triangle(&cam, &meshes[m], meshes[m].triangles + 3 * t, color, depth, sw, sh);
        /* Box filter: the mean of each pixel's samples, rounded, so all-white stays 255. */
        for (int y = 0; y < ph; y++) {
            for (int x = 0; x < pw; x++) {
                uint8_t *out = rgb + 3 * ((size_t)y * (size_t)width + (size_t)(x0 + x));
                for (int c = 0; c < 3; c++) {
                    unsigned sum = 0;
                    for (int dy = 0; dy < SUPERSAMPLE; dy++)
                        for (int dx = 0; dx < SUPERSAMPLE; dx++)
                            sum += color[3 * ((size_t)(SUPERSAMPLE * y + dy) * (size_t)sw +
                                              (size_t)(SUPERSAMPLE * x + dx)) +
                                         c];
                    out[c] = (uint8_t)((sum + SUPERSAMPLE * SUPERSAMPLE / 2) /
                                       (SUPERSAMPLE * SUPERSAMPLE));
                }
            }
        }
    }
    free(color);
    free(depth);
    return 0;
}
