/* Spatially correlated unit-variance noise fields over a mesh's vertices (what real range scans
 * have): band-limited Gaussian noise and scan-line stripes. mesh_add_noise scales them. */
#ifndef RSMOOTH_MESH_NOISE_CORRELATED_H
#define RSMOOTH_MESH_NOISE_CORRELATED_H

#include <stddef.h>
#include <stdint.h>

/* splitmix64's finaliser: the noise models' streams for their directions and phases. */
static inline uint64_t mesh_noise_mix64(uint64_t z) {
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* Band-limited noise: out[v] = sum_u w(|p_u - p_v|) g_u / sqrt(sum_u w^2), over the vertices u
 * within 3 `length` (Euclidean, no geodesics) of v, w(d) = exp(-d^2 / (2 length^2)), g the
 * seed's i.i.d. standard Gaussians (g_v the v-th Gaussian of `seed`, as for plain noise). Each
 * out[v] is then exactly N(0, 1); two vertices at distance d correlate by about
 * exp(-d^2 / (4 length^2)) on an evenly sampled surface. `length` > 0 in the units of xyz.
 * Returns 0, or -1 when out of memory. */
int mesh_band_limited_field(const double *xyz, size_t vertex_count, double length, uint64_t seed,
                            double *out);

/* Scan-line stripes: a direction u is drawn from `seed`, space is cut into slabs of width
 * `width` across u (the first slab boundary at a random phase), slab k gets an amplitude a_k ~
 * N(0, 1), and out[v] = a_k sin(pi f), f in [0, 1) v's position across its slab: ridges and
 * grooves along the slabs, continuous (0 on the boundaries). The field is then scaled so that its
 * root mean square over the vertices is exactly 1 (unless it is 0 everywhere). Returns 0. */
int mesh_stripe_field(const double *xyz, size_t vertex_count, double width, uint64_t seed,
                      double *out);

#endif
