/* Reproducible synthetic noise for meshes: Gaussian (normal or random directions), impulsive. */
#include "mesh_noise.h"

#include "mesh_shapes.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The three random streams are independent, so choosing the impulsive vertices or drawing a
 * direction never shifts the Gaussian stream: vertex v always gets the v-th Gaussian of `seed`,
 * which is what makes impulsive noise the plain noise masked, and NORMAL noise equal to
 * shape_add_normal_noise. The offsets are arbitrary odd constants. */
#define SELECT_STREAM 0xA0761D6478BD642Full
#define DIRECTION_STREAM 0xE7037ED1A0B428DBull

static uint64_t mix64(uint64_t z) {
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

static uint64_t splitmix64(uint64_t *state) {
    *state += 0x9E3779B97F4A7C15ull;
    return mix64(*state);
}

/* Uniform in [0, n), n > 0: rejects the low 2^64 mod n values so every residue is equally likely
 * (a plain modulo favours small values), with integer arithmetic only, so every platform agrees. */
static uint64_t uniform_below(uint64_t *state, uint64_t n) {
    uint64_t threshold = (0 - n) % n;
    for (;;) {
        uint64_t r = splitmix64(state);
        if (r >= threshold)
            return r % n;
    }
}

/* Uniform on the unit sphere: a standard normal 3-vector is isotropic, so normalising it is
 * uniform (no trigonometric parametrisation to get the area element right). */
static void random_direction(uint64_t *state, double d[3]) {
    for (;;) {
        for (int k = 0; k < 3; k++)
            d[k] = shape_gaussian(state);
        double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (len > 1e-150) {
            for (int k = 0; k < 3; k++)
                d[k] /= len;
            return;
        }
    }
}

size_t mesh_noise_moved_count(size_t vertex_count, double impulsive_fraction) {
    if (!(impulsive_fraction > 0))
        return vertex_count;
    if (impulsive_fraction >= 1)
        return vertex_count;
    double k = round(impulsive_fraction * (double)vertex_count);
    return k >= (double)vertex_count ? vertex_count : (size_t)k;
}

/* A copy of the positions times a power of two, *unit, that brings the largest coordinate near 1,
 * so squares and cross products neither overflow nor underflow at any scale (at 1e-300 they
 * would vanish); the scaling is exact, so at ordinary scales every result has the same bits.
 * NULL when out of memory. */
double *mesh_noise_scaled_copy(const double *xyz, size_t vertex_count, double *unit) {
    double largest = 0;
    for (size_t i = 0; i < 3 * vertex_count; i++)
        largest = fmax(largest, fabs(xyz[i]));
    int exponent = 0;
    frexp(largest, &exponent);
    *unit = ldexp(1.0, -exponent);
    double *scaled = malloc((vertex_count ? 3 * vertex_count : 1) * sizeof *scaled);
    for (size_t i = 0; scaled && i < 3 * vertex_count; i++)
        scaled[i] = xyz[i] * *unit;
    return scaled;
}

/* The mean edge length of positions already scaled by `unit`, in the caller's units. */
static double scaled_mean_edge_length(const double *scaled, double unit, size_t vertex_count,
                                      const uint32_t *triangles, size_t triangle_count) {
    /* A read-only view: shape_mean_edge_length does not write through the pointers. */
    shape_mesh view = {vertex_count, (double *)scaled, triangle_count, (uint32_t *)triangles};
    return shape_mean_edge_length(&view) / unit;
}

double mesh_noise_mean_edge_length(const double *xyz, size_t vertex_count,
                                   const uint32_t *triangles, size_t triangle_count) {
    double unit = 1;
    double *scaled = mesh_noise_scaled_copy(xyz, vertex_count, &unit);
    if (!scaled)
        return NAN;
    double edge = scaled_mean_edge_length(scaled, unit, vertex_count, triangles, triangle_count);
    free(scaled);
    return edge;
}

/* Floyd's sampling: exactly k distinct indices of [0, n), each k-subset equally likely, in O(k)
 * draws, marked in `chosen` (n bytes, zeroed by the caller). */
static void choose_vertices(unsigned char *chosen, size_t n, size_t k, uint64_t *state) {
    for (size_t j = n - k; j < n; j++) {
        size_t t = (size_t)uniform_below(state, (uint64_t)j + 1);
        if (chosen[t])
            chosen[j] = 1;
        else
            chosen[t] = 1;
    }
}

bool mesh_noise_arrays_valid(const double *xyz, size_t vertex_count, const uint32_t *triangles,
                             size_t triangle_count) {
    if ((vertex_count && !xyz) || (triangle_count && !triangles) ||
        vertex_count > SIZE_MAX / (3 * sizeof(double)) ||
        triangle_count > SIZE_MAX / (3 * sizeof(uint32_t)))
        return false;
    for (size_t i = 0; i < 3 * triangle_count; i++)
        if (triangles[i] >= vertex_count)
            return false;
    return true;
}

int mesh_add_noise(double *xyz, size_t vertex_count, const uint32_t *triangles,
                   size_t triangle_count, const mesh_noise_options *options) {
    if (!options || !(options->sigma >= 0) || !isfinite(options->sigma) ||
        !(options->impulsive_fraction >= 0 && options->impulsive_fraction <= 1) ||
        (options->direction != MESH_NOISE_NORMAL && options->direction != MESH_NOISE_RANDOM) ||
        !(options->correlation >= 0) || !isfinite(options->correlation) ||
        !(options->stripes >= 0) || !isfinite(options->stripes) ||
        (options->correlation > 0 && options->stripes > 0))
        return -1;
    if (!mesh_noise_arrays_valid(xyz, vertex_count, triangles, triangle_count))
        return -1;
    if (vertex_count == 0 || options->sigma == 0)
        return 0; /* adding 0 could still turn -0.0 into +0.0: leave the bits alone */

    /* edge lengths and normals from the scaled copy (see mesh_noise_scaled_copy) */
    double unit = 1;
    double *scaled = mesh_noise_scaled_copy(xyz, vertex_count, &unit);
    if (!scaled)
        return -1;
    double edge = scaled_mean_edge_length(scaled, unit, vertex_count, triangles, triangle_count);
    double scale = options->sigma * edge;
    if (isnan(edge) || !isfinite(scale)) {
        free(scaled);
        return -1;
    }
    if (scale == 0) {
        free(scaled);
        return 0;
    }

    size_t moved = mesh_noise_moved_count(vertex_count, options->impulsive_fraction);
    unsigned char *chosen = NULL;
    double *normals = NULL;
    if (moved < vertex_count) {
        chosen = calloc(vertex_count, 1);
        if (!chosen) {
            free(scaled);
            return -1;
        }
        uint64_t select_state = mix64(options->seed ^ SELECT_STREAM);
        choose_vertices(chosen, vertex_count, moved, &select_state);
    }
    if (options->direction == MESH_NOISE_NORMAL) {
        normals = malloc(3 * vertex_count * sizeof *normals);
        /* The normals of the input, before any vertex moves. */
        shape_mesh view = {vertex_count, scaled, triangle_count, (uint32_t *)triangles};
        if (!normals || shape_vertex_normals(&view, normals) != 0) {
            free(normals);
            free(chosen);
            free(scaled);
            return -1;
        }
    }
    /* correlated noise: a field of unit-variance values replaces the i.i.d. Gaussians */
    double *field = NULL;
    if (options->correlation > 0 || options->stripes > 0) {
        field = malloc(vertex_count * sizeof *field);
        int bad = !field;
        if (!bad && options->correlation > 0)
            bad = mesh_band_limited_field(scaled, vertex_count, options->correlation * edge * unit,
                                          options->seed, field) != 0;
        else if (!bad)
            bad = mesh_stripe_field(scaled, vertex_count, options->stripes * edge * unit,
                                    options->seed, field) != 0;
        if (bad) {
            free(field);
            free(normals);
            free(chosen);
            free(scaled);
            return -1;
        }
    }
    free(scaled);

    /* All displacements are computed from the input's normals and added in one pass; a vertex's
     * move does not depend on another's. */
    uint64_t gauss_state = options->seed;
    uint64_t direction_base = mix64(options->seed ^ DIRECTION_STREAM);
    for (size_t v = 0; v < vertex_count; v++) {
        double g = shape_gaussian(&gauss_state); /* drawn for every vertex: see the top */
        if (field)
            g = field[v];
        if (chosen && !chosen[v])
            continue;
        double d[3];
        const double *n = normals ? normals + 3 * v : NULL;
        if (n && (n[0] != 0 || n[1] != 0 || n[2] != 0)) {
            memcpy(d, n, sizeof d);
        } else {
            /* A stream of its own per vertex, so a vertex's direction does not depend on which
             * others were chosen or lack a normal. */
            uint64_t direction_state = mix64(direction_base ^ (uint64_t)v);
            random_direction(&direction_state, d);
        }
        for (int k = 0; k < 3; k++)
            xyz[3 * v + k] += scale * g * d[k];
    }
    free(field);
    free(normals);
    free(chosen);
    return 0;
}
