/* Depth-sensor noise (Kinect-like structured light or time of flight): each vertex is moved along
 * the ray from a camera to it, with a spread that grows with depth, depth quantisation, scan-line
 * ridges and strong noise where the surface grazes the ray. `rsmooth noise --depth-sensor`. */
#ifndef RSMOOTH_MESH_NOISE_DEPTH_H
#define RSMOOTH_MESH_NOISE_DEPTH_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* The camera sits this many bounding-box diagonals from the box's centre: far enough that the
 * whole mesh is in front of it, near enough that depth varies across the mesh (by up to a factor
 * (3 + 1/2) / (3 - 1/2) = 1.4, so the spread by up to 2). */
#define MESH_DEPTH_CAMERA_DIAGONALS 3.0

typedef struct mesh_depth_noise_options {
    /* Standard deviation of the displacement along the ray at the mean depth, in mean edge lengths
     * of the input. At depth z (the distance from the camera) it is sigma (z / z_mean)^2, z_mean
     * the mean of z over the vertices: structured-light depth error grows with the square of
     * depth. >= 0, finite. */
    double sigma;
    /* Depth step at the mean depth, in mean edge lengths (q (z / z_mean)^2 at depth z): the noisy
     * depth is rounded to a multiple of it, as a sensor's disparity resolution does. 0: off. */
    double quantum;
    /* Scan-line ridges: A sigma (z / z_mean)^2 sin(2 pi x / period + phase) added to the depth, x
     * the vertex's coordinate along the image's horizontal axis, projected to the mean depth (so
     * the ridges are straight lines in the image), in mean edge lengths. A >= 0 (0: off), period
     * > 0 mean edge lengths; the phase is drawn from the seed. */
    double ridge_amplitude, ridge_period;
    /* Holes at grazing angles: with c the cosine between the vertex normal and the direction to the
     * camera, the Gaussian part is multiplied by 1 / max(c, grazing), so a vertex seen edge-on or
     * from behind (c <= grazing) gets 1 / grazing times the noise. In (0, 1]. A real sensor
     * returns no depth there; the geometry is kept (the same vertices and faces as the clean
     * mesh, which training pairs need), so a hole is modelled as the strongest noise. In
     * [0.01, 1]: below, the noise would dwarf the mesh. */
    double grazing;
    /* The camera's direction from the bounding-box centre (need not be unit; not zero) when
     * have_view, else an isotropic direction drawn from the seed. */
    bool have_view;
    double view[3];
    /* Same seed, options and mesh: bit-identical output (splitmix64 streams, as mesh_add_noise;
     * vertex v's Gaussian is the v-th of `seed`, as for plain noise). */
    uint64_t seed;
} mesh_depth_noise_options;

/* What mesh_add_depth_noise chose, in the input's units: the camera's position and the unit
 * direction from the bounding-box centre to it. */
typedef struct mesh_depth_noise_camera {
    double position[3], view[3];
} mesh_depth_noise_camera;

/* Moves each vertex of `xyz` (3 * vertex_count doubles, in place) along the ray from the camera
 * to it by N(0, 1) sigma (z / z_mean)^2 / max(c, grazing) plus the ridge term, then rounds its
 * distance from the camera to the depth step; a vertex no triangle uses has no normal and is taken
 * as facing the camera. `triangles` (3 * triangle_count indices) give the normals and the mean
 * edge length (the unit). Vertex order and faces are the caller's and never change. `camera`
 * (may be NULL) receives the camera (zeros for an empty mesh). A mesh without a non-zero edge has
 * no unit: nothing moves. Returns 0, or -1 on bad options (a value out of its range or not finite,
 * a zero view), bad arrays (NULL, an index out of range) or out of memory; xyz is then unchanged.
 */
int mesh_add_depth_noise(double *xyz, size_t vertex_count, const uint32_t *triangles,
                         size_t triangle_count, const mesh_depth_noise_options *options,
                         mesh_depth_noise_camera *camera);

#endif
