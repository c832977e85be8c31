/* params.discrepancy_level's choice per region: where the filter's result is curved at the scale of
 * its triangles (an organic mesh coarse for its curvature), low-pass smoothing restores the
 * surface better than feature-preserving filtering; where it is made of flat faces and creases (a
 * machined part), the filter wins. A mesh has both (a statue on a plinth, a part with fillets), so
 * each vertex gets a blend of the two results, weighed by how flat its neighbourhood came out:
 *
 *   1. share[v]: of the pairs of facets sharing an edge at v in the filter's result, those whose
 *      normals lie within FLAT_ANGLE of each other, averaged over SHARE_SPREAD rings (a feature
 *      line's vertices would otherwise read curved);
 *   2. w[v] = clamp((share[v] - SHARE_LOW) / (SHARE_HIGH - SHARE_LOW), 0, 1);
 *   3. out = w * filter + (1 - w) * Taubin, Taubin's lambda|mu smoothing of the input run until
 *      the vertices moved (RMS) as far as the noise did (the discrepancy principle) and, for
 *      spatially correlated noise (discrepancy_gain), until an iteration adds little to the move:
 *      a scan's correlated noise sits at frequencies the principle stops short of;
 *   4. a boundary vertex (on an edge of one facet) moves at most the noise level, in its own edge
 *      lengths, from the input: neither smoother has the other side to lean on there, and a
 *      boundary pulled inwards opens holes between scans.
 *
 * The bounds were fitted by the region study with cross-validation that leaves whole
 * meshes out (docs/accuracy.md); the whole-mesh rule they replace was the same share below 0.52. */
#include "passes/region_choice.h"
#include "stages/normal_update.h"
#include "stages/taubin.h"

#include <math.h>
#include <string.h>

#define FLAT_ANGLE (2.0 * 3.14159265358979323846 / 180)
#define SHARE_LOW 0.2
#define SHARE_HIGH 0.8
#define SHARE_SPREAD 6
#define DISCREPANCY_MAX_ITERATIONS                                                                 \
    40 /* tuned Taubin needed 5-50 on the calibration meshes; at                                   \
        * high noise the move saturates below the level and more                                   \
        * iterations only shrink detail (the Stanford bunny at 0.5:                                \
        * E_v 0.93 at 40, 1.35 at 200) */

/* Per welded vertex r: flat[r] and pairs[r], the pairs of its facets sharing an edge at r; and
 * whether r is on the boundary (an edge at r that one facet has). */
static void count_pairs(const rs_facets *facets, const rs_adjacency *adj, const uint32_t *indices,
                        size_t vertex_count, double cos_max, double *share, uint8_t *boundary) {
    for (size_t r = 0; r < vertex_count; r++) {
        share[r] = NAN;
        boundary[r] = 0;
        if (adj->rep[r] != r)
            continue;
        size_t pairs = 0, flat = 0;
        for (size_t i = adj->start[r]; i < adj->start[r + 1]; i++) {
            const uint32_t *tf = indices + 3 * (size_t)facets->triangle[adj->facet[i]];
            for (int a = 0; a < 3; a++) { /* each edge (r, o) of facet i: how many facets have it */
                uint32_t o = adj->rep[tf[a]];
                if (o == r)
                    continue;
                size_t holders = 0;
                for (size_t j = adj->start[r]; j < adj->start[r + 1]; j++) {
                    const uint32_t *tg = indices + 3 * (size_t)facets->triangle[adj->facet[j]];
                    bool has = adj->rep[tg[0]] == o || adj->rep[tg[1]] == o || adj->rep[tg[2]] == o;
                    holders += has;
                    if (has && j > i) {
                        pairs++;
                        flat += rs_dot3(facets->normal + 3 * (size_t)adj->facet[i],
                                        facets->normal + 3 * (size_t)adj->facet[j]) >= cos_max;
                    }
                }
                boundary[r] |= holders == 1;
            }
        }
        if (pairs)
            share[r] = (double)flat / (double)pairs;
    }
}

/* share <- the mean over each vertex's facets of their welded corners' shares, `rounds` times
 * (NaN, a vertex without pairs, takes its neighbours' and counts for nothing). */
static bool spread(const rs_facets *facets, const rs_adjacency *adj, const uint32_t *indices,
                   size_t vertex_count, int rounds, double *share) {
    double *next = rs_alloc_array(vertex_count, sizeof *next);
    if (!next)
        return false;
    for (int round = 0; round < rounds; round++) {
        for (size_t r = 0; r < vertex_count; r++) {
            double sum = 0;
            size_t n = 0;
            for (size_t i = adj->start[r]; adj->rep[r] == r && i < adj->start[r + 1]; i++) {
                const uint32_t *t = indices + 3 * (size_t)facets->triangle[adj->facet[i]];
                for (int c = 0; c < 3; c++) {
                    double s = share[adj->rep[t[c]]];
                    if (!isnan(s))
                        sum += s, n++;
                }
            }
            next[r] = n ? sum / (double)n : share[r];
        }
        memcpy(share, next, vertex_count * sizeof *share);
    }
    rs_free(next);
    return true;
}

/* The mean length of the edges at welded vertex r (input positions). */
static double local_edge(const rs_adjacency *adj, const rs_facets *facets, const uint32_t *indices,
                         const double *xyz, size_t r) {
    double sum = 0;
    size_t n = 0;
    for (size_t i = adj->start[r]; i < adj->start[r + 1]; i++) {
        const uint32_t *t = indices + 3 * (size_t)facets->triangle[adj->facet[i]];
        for (int c = 0; c < 3; c++)
            if (adj->rep[t[c]] != r) {
                double d[3];
                rs_sub3(xyz + 3 * (size_t)t[c], xyz + 3 * r, d);
                sum += sqrt(rs_dot3(d, d)), n++;
            }
    }
    return n ? sum / (double)n : 0;
}

/* The filter's weight for a vertex whose neighbourhood has this flat share (NaN: no pairs). */
static double region_weight(double share) {
    if (isnan(share))
        return 1; /* no two facets share an edge here: nothing says curved */
    double w = (share - SHARE_LOW) / (SHARE_HIGH - SHARE_LOW);
    return w < 0 ? 0 : w > 1 ? 1 : w;
}

int rs_region_choice(rsmooth_scalar scalar, const void *positions, size_t vertex_count,
                     const uint32_t *indices, size_t triangle_count, double level, double min_gain,
                     void *out_positions, double *out_mean_weight) {
    double *input = rs_alloc_array(vertex_count, 3 * sizeof(double));
    double *filtered = rs_alloc_array(vertex_count, 3 * sizeof(double));
    double *share = rs_alloc_array(vertex_count, sizeof(double));
    uint8_t *boundary = rs_alloc_array(vertex_count, 1);
    rs_facets facets;
    rs_adjacency adj;
    bool ok = input && filtered && share && boundary, built = false, adjacent = false;
    int iterations = 0;
    for (size_t i = 0; ok && i < 3 * vertex_count; i++) {
        input[i] = rs_coordinate(scalar, positions, i);
        filtered[i] = rs_coordinate(scalar, out_positions, i);
    }
    ok = ok && (built = rs_facets_build(&facets, filtered, indices, triangle_count));
    ok = ok && (adjacent = rs_adjacency_build(&adj, filtered, vertex_count, indices, &facets));
    double unit = 0, weight_sum = 0;
    if (ok) {
        count_pairs(&facets, &adj, indices, vertex_count, cos(FLAT_ANGLE), share, boundary);
        ok = spread(&facets, &adj, indices, vertex_count, SHARE_SPREAD, share) &&
             rs_mean_edge_length(input, vertex_count, indices, triangle_count, &unit);
    }
    double *low = ok && unit > 0 ? rs_alloc_array(vertex_count, 3 * sizeof(double)) : NULL;
    ok = ok && (unit > 0 ? low != NULL : true);
    if (low) { /* Taubin from the input, in its edge lengths */
        memcpy(low, input, vertex_count * 3 * sizeof(double));
        iterations = rs_taubin_until(low, vertex_count, indices, triangle_count, 0.5, -0.53,
                                     level * unit, min_gain * unit, DISCREPANCY_MAX_ITERATIONS);
        ok = iterations >= 0;
    }
    for (size_t v = 0; ok && low && v < vertex_count; v++) {
        uint32_t r = adj.rep[v];
        double w = region_weight(share[r]), x[3];
        weight_sum += w;
        for (int k = 0; k < 3; k++)
            x[k] = w * filtered[3 * v + k] + (1 - w) * low[3 * v + k];
        if (boundary[r]) { /* at most the noise level from the input */
            double d[3], limit = level * local_edge(&adj, &facets, indices, input, r);
            rs_sub3(x, input + 3 * v, d);
            double move = sqrt(rs_dot3(d, d));
            for (int k = 0; move > limit && k < 3; k++)
                x[k] = input[3 * v + k] + d[k] * (limit / move);
        }
        rs_store_position(scalar, out_positions, v, x, 1);
    }
    if (out_mean_weight)
        *out_mean_weight = low && vertex_count ? weight_sum / (double)vertex_count : 1;
    if (adjacent)
        rs_adjacency_free(&adj);
    if (built)
        rs_facets_free(&facets);
    rs_free(low);
    rs_free(input);
    rs_free(filtered);
    rs_free(share);
    rs_free(boundary);
    return ok ? iterations : -1;
}
