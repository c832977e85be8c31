/* How much a mesh's roughness at the scale of its edges looks like shape rather than noise.
 *
 * Each vertex's umbrella offset (the mean of its neighbours less itself) along its normal is its
 * surface's bend at that vertex. On a clean mesh the bend varies smoothly from vertex to vertex,
 * however coarse the mesh: a vertex's bend and the mean of its neighbours' are strongly
 * correlated (0.37 to 0.99 on 27 of the 28 clean meshes of ../shared/data/clean). Noise bends
 * each vertex on its own, and its offset pushes the neighbours' the other way: the correlation
 * falls to -0.66 to 0.07 on the 30 noisy accuracy cases, and 0.10 to 0.17 on the two raw range
 * scans, whose noise is partly correlated. Pearson's correlation over the welded vertices.
 * Deterministic: sums in vertex order on one thread. */
#include "core/shape_correlation.h"
#include "core/weld.h"

#include <math.h>
#include <string.h>

/* Pearson's correlation of x and y over the entries `valid` marks; 1 when either barely varies
 * (a mesh that bends alike everywhere, a plane, a sphere, a cube). */
static double correlation(const double *x, const double *y, const uint8_t *valid, size_t count) {
    double n = 0, sx = 0, sy = 0;
    for (size_t i = 0; i < count; i++)
        if (valid[i]) {
            n++;
            sx += x[i];
            sy += y[i];
        }
    if (n < 2)
        return 1;
    double mx = sx / n, my = sy / n, xx = 0, yy = 0, xy = 0;
    for (size_t i = 0; i < count; i++)
        if (valid[i]) {
            xx += (x[i] - mx) * (x[i] - mx);
            yy += (y[i] - my) * (y[i] - my);
            xy += (x[i] - mx) * (y[i] - my);
        }
    /* offsets in units of the edges: spreads below 1e-9 of an edge are rounding */
    if (!(xx > 1e-18 * n) || !(yy > 1e-18 * n))
        return 1;
    return xy / sqrt(xx * yy);
}

/* Per welded vertex: its umbrella offset along its normal (`bend`), valid where it has both. */
static bool bends(const double *xyz, size_t vertex_count, const uint32_t *indices,
                  size_t triangle_count, const uint32_t *rep, const uint64_t *edge,
                  size_t edge_count, double *bend, uint8_t *valid) {
    double *normal = rs_calloc_array(vertex_count, 3 * sizeof *normal);
    double *sum = rs_calloc_array(vertex_count, 3 * sizeof *sum);
    double *degree = rs_calloc_array(vertex_count, sizeof *degree);
    if (!normal || !sum || !degree) {
        rs_free(normal);
        rs_free(sum);
        rs_free(degree);
        return false;
    }
    rs_add_area_normals(xyz, indices, triangle_count, rep, normal);
    for (size_t i = 0; i < edge_count; i++) {
        size_t a = (size_t)(edge[i] >> 32), b = (size_t)(edge[i] & 0xffffffffu);
        for (int k = 0; k < 3; k++) {
            sum[3 * a + (size_t)k] += xyz[3 * b + (size_t)k];
            sum[3 * b + (size_t)k] += xyz[3 * a + (size_t)k];
        }
        degree[a]++;
        degree[b]++;
    }
    for (size_t v = 0; v < vertex_count; v++) {
        const double *n = normal + 3 * v;
        double len = sqrt(rs_dot3(n, n));
        valid[v] = rep[v] == v && degree[v] > 0 && len > 0;
        bend[v] = 0;
        if (valid[v])
            for (int k = 0; k < 3; k++)
                bend[v] +=
                    (sum[3 * v + (size_t)k] / degree[v] - xyz[3 * v + (size_t)k]) * n[k] / len;
    }
    rs_free(normal);
    rs_free(sum);
    rs_free(degree);
    return true;
}

bool rs_shape_correlation_welded(const double *xyz, size_t vertex_count, const uint32_t *indices,
                                 size_t triangle_count, const uint32_t *rep, const uint64_t *edge,
                                 size_t edge_count, double *out) {
    *out = 1;
    double *bend = rs_alloc_array(vertex_count ? vertex_count : 1, sizeof *bend);
    double *around = rs_calloc_array(vertex_count ? vertex_count : 1, sizeof *around);
    double *count = rs_calloc_array(vertex_count ? vertex_count : 1, sizeof *count);
    uint8_t *valid = rs_alloc_array(vertex_count ? vertex_count : 1, 1);
    bool ok = bend && around && count && valid &&
              bends(xyz, vertex_count, indices, triangle_count, rep, edge, edge_count, bend, valid);
    if (ok) {
        for (size_t i = 0; i < edge_count; i++) { /* the neighbours' mean bend */
            size_t a = (size_t)(edge[i] >> 32), b = (size_t)(edge[i] & 0xffffffffu);
            if (valid[a] && valid[b]) {
                around[a] += bend[b];
                around[b] += bend[a];
                count[a]++;
                count[b]++;
            }
        }
        for (size_t v = 0; v < vertex_count; v++) {
            valid[v] = valid[v] && count[v] > 0;
            around[v] = valid[v] ? around[v] / count[v] : 0;
        }
        *out = correlation(bend, around, valid, vertex_count);
    }
    rs_free(bend);
    rs_free(around);
    rs_free(count);
    rs_free(valid);
    return ok;
}

bool rs_shape_correlation(const double *xyz, size_t vertex_count, const uint32_t *indices,
                          size_t triangle_count, double *out) {
    *out = 1;
    if (vertex_count == 0 || triangle_count == 0)
        return true;
    uint32_t *rep = rs_alloc_array(vertex_count, sizeof *rep);
    uint64_t *edge = NULL;
    size_t edge_count = 0;
    bool ok = rep && rs_weld(xyz, vertex_count, rep) &&
              (edge = rs_welded_edges(rep, indices, triangle_count, &edge_count, NULL)) != NULL &&
              rs_shape_correlation_welded(xyz, vertex_count, indices, triangle_count, rep, edge,
                                          edge_count, out);
    rs_free(rep);
    rs_free(edge);
    return ok;
}
