/* The denoising error of a mesh against its ground truth (rsmooth_compare): the mean face-normal
 * angle, Sun et al. 2007 E_v, RMS vertex displacement and the vertex-sampled Hausdorff distance,
 * the distances exact (surface_index.c).
 *
 * The figures follow ../shared/tools/meshmetrics.py (the independent oracle) except where that
 * script approximates: distances to a surface here are exact (the closest point over all
 * triangles), where the script only tries the 24 triangles with the nearest centroids.
 *
 * Both meshes are multiplied by one power of two (scale.c) on the way in, the truth's typical edge
 * brought near 1: every figure is a ratio of lengths or an angle, so that is exact and changes no
 * digit, while squared distances and cross products (edge lengths to the fourth power) neither
 * overflow nor underflow at any scale the library accepts. mean_edge and bbox_diag are divided by
 * it again. */
#include "metrics/metrics.h"
#include "core/rsmooth_internal.h"
#include "metrics/surface_index.h"

#include <math.h>
#include <stdbool.h>
#include <string.h>

static const char where[] = "rsmooth_compare";

/* Vertices per chunk of the distance queries (below this a chunk is not worth a thread). */
#define QUERY_CHUNK 1024

/* Mean length of the unique undirected edges (a repeated index is no edge), summed in the order of
 * the sorted edge keys (lower vertex, then upper), as the command always summed it; the edges are
 * those rsmooth_mean_edge_length counts. false when out of memory. */
static bool mean_edge_length(const double *xyz, const uint32_t *indices, size_t triangle_count,
                             double *out) {
    *out = 0;
    uint64_t *keys = rs_alloc_array(triangle_count, 3 * sizeof *keys);
    uint32_t *unused = rs_alloc_array(triangle_count, 3 * sizeof *unused);
    bool ok = keys && unused;
    size_t n = 0;
    for (size_t t = 0; ok && t < triangle_count; t++)
        for (int e = 0; e < 3; e++) {
            uint32_t a = indices[3 * t + e], b = indices[3 * t + (e + 1) % 3];
            if (a != b)
                keys[n++] = a < b ? (uint64_t)a << 32 | b : (uint64_t)b << 32 | a;
        }
    if (ok)
        ok = rs_radix_sort_u64(keys, unused, n);
    double sum = 0;
    size_t unique = 0;
    for (size_t i = 0; ok && i < n; i++) {
        if (i > 0 && keys[i] == keys[i - 1])
            continue;
        double d[3];
        rs_sub3(xyz + 3 * (size_t)(keys[i] >> 32), xyz + 3 * (size_t)(keys[i] & 0xffffffffu), d);
        sum += sqrt(rs_dot3(d, d));
        unique++;
    }
    if (ok && unique)
        *out = sum / (double)unique;
    rs_free(keys);
    rs_free(unused);
    return ok;
}

/* The distance queries, one vertex at a time: from each result vertex to the truth's surface, and
 * from each truth vertex to the result's (vertices used by some triangle; others get 0). */
typedef struct query_job {
    const rs_surface_index *truth_surface, *result_surface;
    const double *result_xyz, *truth_xyz;
    const bool *used;
    double *to_truth;  /* per vertex */
    double *to_result; /* per vertex */
} query_job;

static void query_range(void *ctx, size_t begin, size_t end, size_t chunk) {
    const query_job *job = ctx;
    (void)chunk;
    for (size_t v = begin; v < end; v++) {
        job->to_truth[v] = job->to_result[v] = 0;
        if (!job->used[v])
            continue;
        job->to_truth[v] =
            rs_surface_index_query(job->truth_surface, job->result_xyz + 3 * v, NULL, NULL);
        job->to_result[v] =
            rs_surface_index_query(job->result_surface, job->truth_xyz + 3 * v, NULL, NULL);
    }
}

/* The figures from validated, scaled positions (internal units); lengths in `m` stay in internal
 * units. false when out of memory. */
static bool compute(const double *result_xyz, const double *truth_xyz, size_t vertex_count,
                    const uint32_t *triangles, size_t triangle_count, rsmooth_metrics *m) {
    bool ok = false;
    double *area = rs_calloc_array(vertex_count, sizeof *area);
    bool *used = rs_calloc_array(vertex_count, sizeof *used);
    double *distances = rs_alloc_array(vertex_count, 2 * sizeof *distances);
    rs_surface_index *truth_surface = NULL, *result_surface = NULL;
    if (!area || !used || !distances ||
        !mean_edge_length(truth_xyz, triangles, triangle_count, &m->mean_edge))
        goto done;

    double lo[3], hi[3];
    for (int k = 0; k < 3; k++) {
        lo[k] = INFINITY;
        hi[k] = -INFINITY;
    }
    double sum2 = 0;
    for (size_t v = 0; v < vertex_count; v++) {
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], truth_xyz[3 * v + k]);
            hi[k] = fmax(hi[k], truth_xyz[3 * v + k]);
        }
        double d[3];
        rs_sub3(result_xyz + 3 * v, truth_xyz + 3 * v, d);
        sum2 += rs_dot3(d, d);
    }
    double diagonal[3];
    rs_sub3(lo, hi, diagonal);
    m->bbox_diag = sqrt(rs_dot3(diagonal, diagonal));
    m->rms_v = sqrt(sum2 / (double)vertex_count) / m->mean_edge;

    /* theta with atan2(|n1 x n2|, n1 . n2): exact for small angles, where acos of a dot product
     * near 1 loses half the digits, and it needs no normalisation. */
    double angle_sum = 0;
    size_t angle_count = 0;
    for (size_t t = 0; t < triangle_count; t++) {
        const uint32_t *f = triangles + 3 * t;
        double e1[3], e2[3], nr[3], nt[3], x[3];
        rs_sub3(result_xyz + 3 * (size_t)f[1], result_xyz + 3 * (size_t)f[0], e1);
        rs_sub3(result_xyz + 3 * (size_t)f[2], result_xyz + 3 * (size_t)f[0], e2);
        rs_cross3(e1, e2, nr);
        rs_sub3(truth_xyz + 3 * (size_t)f[1], truth_xyz + 3 * (size_t)f[0], e1);
        rs_sub3(truth_xyz + 3 * (size_t)f[2], truth_xyz + 3 * (size_t)f[0], e2);
        rs_cross3(e1, e2, nt);
        double len_r = sqrt(rs_dot3(nr, nr));
        for (int c = 0; c < 3; c++) {
            area[f[c]] += 0.5 * len_r;
            used[f[c]] = true;
        }
        if (!(len_r > 0) || !(rs_dot3(nt, nt) > 0))
            continue; /* no normal: the script's NaN, skipped there too */
        rs_cross3(nr, nt, x);
        angle_sum += atan2(sqrt(rs_dot3(x, x)), rs_dot3(nr, nt));
        angle_count++;
    }
    m->theta_count = angle_count;
    m->theta =
        angle_count ? angle_sum / (double)angle_count * (180.0 / 3.14159265358979323846) : NAN;

    truth_surface = rs_surface_index_build(truth_xyz, vertex_count, triangles, triangle_count);
    result_surface = rs_surface_index_build(result_xyz, vertex_count, triangles, triangle_count);
    if (!truth_surface || !result_surface)
        goto done; /* the arrays were checked and scaled: only memory can be missing */
    query_job job = {truth_surface, result_surface,          result_xyz, truth_xyz, used,
                     distances,     distances + vertex_count};
    rs_parallel_for(vertex_count, QUERY_CHUNK, query_range, &job);
    /* Summed in vertex order, one thread: the same figures with any thread count. */
    double weighted = 0, weight = 0, farthest = 0;
    for (size_t v = 0; v < vertex_count; v++) {
        if (!used[v])
            continue;
        double d = job.to_truth[v];
        farthest = fmax(farthest, d);
        if (area[v] > 0) {
            weighted += area[v] * d * d;
            weight += area[v];
        }
        farthest = fmax(farthest, job.to_result[v]);
    }
    m->ev = weight > 0 ? sqrt(weighted / weight) / m->bbox_diag * 1e3 : NAN;
    m->hausdorff = farthest / m->bbox_diag * 1e3;
    ok = true;
done:
    rs_surface_index_free(truth_surface);
    rs_surface_index_free(result_surface);
    rs_free(area);
    rs_free(used);
    rs_free(distances);
    return ok;
}

rsmooth_status rs_compare(rsmooth_scalar scalar, const void *result_positions,
                          const void *truth_positions, size_t vertex_count, const uint32_t *indices,
                          size_t triangle_count, rsmooth_metrics *out, rsmooth_error *error) {
    rs_error_clear(error);
    if (!out)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "out is NULL");
    if (!result_positions)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "result_positions is NULL");
    if (!truth_positions)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "truth_positions is NULL");
    rsmooth_status st = rs_check_mesh_structure(scalar, truth_positions, vertex_count, indices,
                                                triangle_count, error, where);
    if (st != RSMOOTH_OK)
        return st;
    if (triangle_count == 0)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "the meshes have no triangles: there is no surface to compare");
    double result_magnitude = 0, truth_magnitude = 0, scale = 1;
    st = rs_check_coordinates(scalar, result_positions, vertex_count, "result vertex",
                              &result_magnitude, error, where);
    if (st == RSMOOTH_OK)
        st = rs_check_coordinates(scalar, truth_positions, vertex_count, "truth vertex",
                                  &truth_magnitude, error, where);
    /* One scale for both, from the truth's edges, keeping either mesh's largest coordinate in
     * range. */
    if (st == RSMOOTH_OK)
        st = rs_mesh_scale(scalar, truth_positions, indices, triangle_count,
                           fmax(result_magnitude, truth_magnitude), &scale, error, where);
    if (st != RSMOOTH_OK)
        return st;

    double *result_xyz = rs_alloc_array(vertex_count, 3 * sizeof *result_xyz);
    double *truth_xyz = rs_alloc_array(vertex_count, 3 * sizeof *truth_xyz);
    rsmooth_metrics m;
    memset(&m, 0, sizeof m);
    bool ok = result_xyz && truth_xyz;
    if (ok) {
        rs_scale_positions(scalar, result_positions, vertex_count, scale, result_xyz);
        rs_scale_positions(scalar, truth_positions, vertex_count, scale, truth_xyz);
        ok = compute(result_xyz, truth_xyz, vertex_count, indices, triangle_count, &m);
    }
    rs_free(result_xyz);
    rs_free(truth_xyz);
    rs_release_free_memory();
    if (!ok)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where,
                       "no memory to compare meshes of %zu vertices and %zu triangles",
                       vertex_count, triangle_count);
    m.vertex_count = vertex_count;
    m.triangle_count = triangle_count;
    m.mean_edge /= scale; /* exact: a power of two */
    m.bbox_diag /= scale;
    *out = m;
    return RSMOOTH_OK;
}
