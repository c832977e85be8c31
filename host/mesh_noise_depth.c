/* Depth-sensor noise along the camera rays: spread sigma (z / z_mean)^2, the quadratic growth of
 * structured-light depth error (Khoshelham & Elberink 2012), larger towards grazing angles (Nguyen,
 * Izadi & Lovell 2012), plus depth quantisation and scan-line ridges. */
#include "mesh_noise_depth.h"

#include "mesh_noise.h"
#include "mesh_shapes.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Its own stream for the camera and the ridges' phase, so the Gaussian stream is the plain noise's
 * (vertex v gets the v-th Gaussian of the seed). An arbitrary odd constant. */
#define VIEW_STREAM 0x2D358DCCAA6C78A5ull
#define PI 3.14159265358979323846

static double dot3(const double a[3], const double b[3]) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* a / |a|; false when a is zero or its length is not finite. */
static bool normalise(double a[3]) {
    double len = sqrt(dot3(a, a));
    if (!(len > 1e-150) || !isfinite(len))
        return false;
    for (int k = 0; k < 3; k++)
        a[k] /= len;
    return true;
}

static bool options_valid(const mesh_depth_noise_options *o) {
    if (!o || !(o->sigma >= 0) || !isfinite(o->sigma) || !(o->quantum >= 0) ||
        !isfinite(o->quantum) || !(o->ridge_amplitude >= 0) || !isfinite(o->ridge_amplitude) ||
        !(o->ridge_period > 0) || !isfinite(o->ridge_period) ||
        !(o->grazing >= 0.01 && o->grazing <= 1))
        return false;
    double v[3] = {o->view[0], o->view[1], o->view[2]};
    return !o->have_view || normalise(v);
}

/* The camera in the scaled copy: on the view direction, MESH_DEPTH_CAMERA_DIAGONALS bounding-box
 * diagonals from the box's centre, looking at the centre; `across` is the image's horizontal axis
 * (perpendicular to the view, and to the world axis least along it, so it is well defined). */
typedef struct depth_camera {
    double position[3], view[3], across[3];
    double phase; /* of the ridges, in [0, 2 pi) */
} depth_camera;

static void place_camera(const double *xyz, size_t n, const mesh_depth_noise_options *o,
                         depth_camera *cam) {
    uint64_t state = mesh_noise_mix64(o->seed ^ VIEW_STREAM);
    if (o->have_view) {
        memcpy(cam->view, o->view, sizeof cam->view);
        normalise(cam->view);
    } else {
        do { /* an isotropic direction: a normalised Gaussian 3-vector */
            for (int k = 0; k < 3; k++)
                cam->view[k] = shape_gaussian(&state);
        } while (!normalise(cam->view));
    }
    cam->phase = 2 * PI * (double)(mesh_noise_mix64(state + 1) >> 11) * 0x1.0p-53;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t v = 0; v < n; v++)
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], xyz[3 * v + k]);
            hi[k] = fmax(hi[k], xyz[3 * v + k]);
        }
    double extent[3] = {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
    double diagonal = sqrt(dot3(extent, extent));
    for (int k = 0; k < 3; k++)
        cam->position[k] =
            0.5 * (lo[k] + hi[k]) + MESH_DEPTH_CAMERA_DIAGONALS * diagonal * cam->view[k];
    int least = 0;
    for (int k = 1; k < 3; k++)
        if (fabs(cam->view[k]) < fabs(cam->view[least]))
            least = k;
    double axis[3] = {0, 0, 0};
    axis[least] = 1;
    cam->across[0] = cam->view[1] * axis[2] - cam->view[2] * axis[1];
    cam->across[1] = cam->view[2] * axis[0] - cam->view[0] * axis[2];
    cam->across[2] = cam->view[0] * axis[1] - cam->view[1] * axis[0];
    normalise(cam->across);
}

/* Every vertex's distance from the camera (z, scaled units) and their mean. */
static double depths(const double *xyz, size_t n, const depth_camera *cam, double *z) {
    double sum = 0;
    for (size_t v = 0; v < n; v++) {
        double r[3];
        for (int k = 0; k < 3; k++)
            r[k] = xyz[3 * v + k] - cam->position[k];
        z[v] = sqrt(dot3(r, r));
        sum += z[v];
    }
    return sum / (double)n;
}

/* The new distance from the camera of a vertex at distance z (scaled units), ray the unit
 * direction from the camera to it, normal its unit normal (zero when it has none), g its
 * Gaussian, edge the mean edge length. */
static double noisy_depth(const mesh_depth_noise_options *o, const depth_camera *cam, double edge,
                          double z_mean, double z, const double ray[3], const double normal[3],
                          double g) {
    double growth = (z / z_mean) * (z / z_mean);
    /* c = cosine between the normal and the direction to the camera: <= 0 seen from behind */
    double c = -dot3(normal, ray), facing = 1;
    if (normal[0] != 0 || normal[1] != 0 || normal[2] != 0)
        facing = fmax(c, o->grazing);
    double spread = o->sigma * edge * growth;
    /* the image's horizontal coordinate at the mean depth: straight ridges in the image, however
     * far the surface */
    double x = dot3(ray, cam->across) / -dot3(ray, cam->view) * z_mean;
    double ridge =
        o->ridge_amplitude * spread * sin(2 * PI * x / (o->ridge_period * edge) + cam->phase);
    double depth = z + spread * g / facing + ridge;
    if (o->quantum > 0) {
        double step = o->quantum * edge * growth;
        depth = step * round(depth / step);
    }
    return depth;
}

int mesh_add_depth_noise(double *xyz, size_t vertex_count, const uint32_t *triangles,
                         size_t triangle_count, const mesh_depth_noise_options *options,
                         mesh_depth_noise_camera *camera) {
    if (!options_valid(options) ||
        !mesh_noise_arrays_valid(xyz, vertex_count, triangles, triangle_count))
        return -1;
    if (camera)
        memset(camera, 0, sizeof *camera); /* an empty mesh has no camera */
    if (vertex_count == 0)
        return 0;

    double unit = 1;
    double *scaled = mesh_noise_scaled_copy(xyz, vertex_count, &unit);
    double *normals = malloc(3 * vertex_count * sizeof *normals);
    double *z = malloc(vertex_count * sizeof *z);
    int status = -1;
    if (!scaled || !normals || !z)
        goto done;
    /* the input's normals and unit, before any vertex moves */
    shape_mesh view = {vertex_count, scaled, triangle_count, (uint32_t *)triangles};
    double edge = shape_mean_edge_length(&view);
    if (isnan(edge) || shape_vertex_normals(&view, normals) != 0)
        goto done;
    depth_camera cam;
    place_camera(scaled, vertex_count, options, &cam);
    if (camera) {
        for (int k = 0; k < 3; k++) {
            camera->position[k] = cam.position[k] / unit;
            camera->view[k] = cam.view[k];
        }
    }
    status = 0;
    if (!(edge > 0) || (options->sigma == 0 && options->quantum == 0))
        goto done; /* no unit, or nothing to add: leave the bits alone */

    double z_mean = depths(scaled, vertex_count, &cam, z);
    uint64_t gauss_state = options->seed;
    for (size_t v = 0; v < vertex_count; v++) {
        double g = shape_gaussian(&gauss_state); /* drawn for every vertex: the plain stream */
        double ray[3];
        for (int k = 0; k < 3; k++)
            ray[k] = (scaled[3 * v + k] - cam.position[k]) / z[v];
        double depth = noisy_depth(options, &cam, edge, z_mean, z[v], ray, normals + 3 * v, g);
        /* the move in the caller's units (the scaled copy is the input times unit, exactly); a
         * vertex left where it was keeps its bits (adding 0 would turn -0.0 into +0.0) */
        for (int k = 0; depth != z[v] && k < 3; k++)
            xyz[3 * v + k] += (depth - z[v]) * ray[k] / unit;
    }
done:
    free(z);
    free(normals);
    free(scaled);
    return status;
}
