/* Reproducible synthetic noise for meshes (Gaussian along normals or in random directions, and
 * impulsive noise), the corruption the denoising experiments and `rsmooth noise` apply. */
#ifndef RSMOOTH_MESH_NOISE_H
#define RSMOOTH_MESH_NOISE_H

#include "mesh_noise_correlated.h"

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

typedef enum mesh_noise_direction {
    MESH_NOISE_NORMAL = 0, /* along the area-weighted vertex normal (a random direction for
                            * vertices no triangle uses, which have none) */
    MESH_NOISE_RANDOM = 1  /* along a uniformly random unit direction, drawn per vertex */
} mesh_noise_direction;

typedef struct mesh_noise_options {
    /* Standard deviation of the displacement along the chosen direction, in mean edge lengths of
     * the input (mean over unique undirected edges, as shape_mean_edge_length). >= 0, finite. */
    double sigma;
    mesh_noise_direction direction;
    /* 0: every vertex gets Gaussian noise. f in (0, 1]: impulsive noise as the denoising
     * literature's benchmarks use it: exactly round(f * vertex_count) vertices, chosen uniformly
     * at random without replacement, are each displaced by Gaussian noise of `sigma` along their
     * direction; every other vertex stays bit-identical. (The Twelve0.5Impulsive benchmark model
     * is this: 2305 of its 4610 vertices moved along their normals, std 0.49 mean edge lengths,
     * kurtosis 3.0; the rest differ only by the file's decimal rounding.) A displaced vertex moves
     * exactly as under plain Gaussian noise (f = 0) with the same seed: the same noise, masked. */
    double impulsive_fraction;
    /* Same seed, options and mesh: bit-identical output on every platform with a correctly
     * rounded (or identical) libm; splitmix64 streams, no rand(). */
    uint64_t seed;
    /* > 0: band-limited noise instead of i.i.d. noise: each vertex's Gaussian is replaced by
     * mesh_band_limited_field's, a Gaussian smoothing of width `correlation` mean edge lengths
     * (still of standard deviation 1 per vertex, so `sigma` keeps its meaning). 0: off. */
    double correlation;
    /* > 0: scan-line stripes of width `stripes` mean edge lengths (mesh_stripe_field, root mean
     * square over the vertices exactly 1, times sigma) instead of i.i.d. noise; not with
     * `correlation`. 0: off. */
    double stripes;
} mesh_noise_options;

/* Adds noise to `xyz` (3 * vertex_count doubles) in place. `triangles` (3 * triangle_count
 * indices) give the normals and the mean edge length. With the NORMAL direction, no impulsive
 * fraction and no unreferenced vertex, the result equals shape_add_normal_noise's for the same
 * seed. A mesh without edges has no unit: nothing moves. Returns 0, or -1 on bad options (sigma
 * negative or not finite, fraction outside [0, 1], unknown direction), bad arrays (NULL, an index
 * out of range, correlation or stripes negative or not finite, both set) or out of memory;
 * xyz is then unchanged. */
int mesh_add_noise(double *xyz, size_t vertex_count, const uint32_t *triangles,
                   size_t triangle_count, const mesh_noise_options *options);

/* How many vertices mesh_add_noise displaces: vertex_count for fraction 0, else
 * round(fraction * vertex_count) (halves away from zero). */
size_t mesh_noise_moved_count(size_t vertex_count, double impulsive_fraction);

/* The unit of sigma: the mean length of the unique undirected edges (0 when there is none, NAN
 * when out of memory). Indices must be in range. */
double mesh_noise_mean_edge_length(const double *xyz, size_t vertex_count,
                                   const uint32_t *triangles, size_t triangle_count);

/* The arrays every noise model checks: present where counted, sizes that fit, every index below
 * vertex_count. */
bool mesh_noise_arrays_valid(const double *xyz, size_t vertex_count, const uint32_t *triangles,
                             size_t triangle_count);

/* A copy of the positions (3 * vertex_count doubles) times a power of two, *unit, that brings the
 * largest coordinate near 1, so squares and cross products neither overflow nor underflow at any
 * scale; the scaling is exact. The caller frees it; NULL when out of memory. */
double *mesh_noise_scaled_copy(const double *xyz, size_t vertex_count, double *unit);

#endif
