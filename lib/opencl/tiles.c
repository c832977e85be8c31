/* Spatial tiles: a mesh whose buffers exceed the device's memory (or the caller's budget) is cut
 * into boxes of vertices, each run with every facet its vertices' results depend on.
 *
 * A vertex p moves by the facets whose centroids lie within `radius` of it. Their mollified normals
 * come from their own vertices (within `reach`, the mesh's largest centroid-to-vertex distance),
 * which moved by the facets within `mollify_radius` of them. So a tile holding the facets whose
 * centroids lie within radius + reach + mollify_radius of its box computes its vertices as the
 * whole mesh would, bit for bit (cells count from a lattice fixed in space, and the kernels'
 * differences do not depend on the blocks). The
 * bilateral normal filter instead reads only facets' own centroids, areas and normals: each of its
 * normal_iterations rounds reaches normal_radius further, so the halo is radius +
 * normal_iterations * normal_radius there. Boxes are halved along their longest side until a tile
 * fits. */
#include "opencl/cl_internal.h"

#include <math.h>
#include <string.h>

#define ABSENT UINT32_MAX
/* Halvings before giving up: far more than any budget that can hold one vertex's halo needs. */
#define MAX_DEPTH 96

typedef struct tiler {
    rsmooth_context *ctx;
    const rs_problem *whole;
    const rs_result_sink *sink; /* the whole call's (target NULL) */
    rs_run_stats *stats;
    double halo;
    uint64_t budget;
    uint32_t *sub_index; /* whole vertex -> its index in the current tile, ABSENT elsewhere */
    size_t vertices_done, vertices_total; /* of the core vertices the call solves */
    rsmooth_error *error;
} tiler;

/* A tile's progress mapped into the whole call's. */
typedef struct tile_progress {
    const rs_problem *whole;
    double from, span;
} tile_progress;

static int report_tile_progress(void *user, double fraction) {
    const tile_progress *tp = user;
    return !rs_progress(tp->whole, tp->from + tp->span * fraction);
}

/* Device bytes a tile of `vertices` core vertices and `facets` facets is expected to need (a
 * facet brings about half a vertex of its own). The bilateral rounds' lists are planned for only
 * in tiles of at least 256 halo discs of facets, at least half of them the tile's own (about two
 * per core vertex): splitting smaller to make room for them costs more in halos (K bilateral
 * reaches wide) than the lists save (measured on Bunny0.2 with the best preset: one tile that
 * searches in every round beat 2 to 9 with lists). Tiles take their lists wherever they fit
 * anyway, planned or not. */
static uint64_t estimate_bytes(const rs_problem *pb, size_t vertices, size_t facets) {
    size_t v = vertices > facets / 2 ? vertices : facets / 2;
    double halo = pb->bilateral ? rs_halo_radius(pb, 0) : 0; /* the bilateral halo needs no reach */
    bool lists = pb->bilateral && pb->normal_iterations >= 2 && /* one round searches */
                 (uint64_t)facets <= 4 * (uint64_t)vertices &&
                 (double)facets >= 256 * 3.14159 * halo * halo / pb->mean_area;
    uint64_t per_facet = RS_DEVICE_BYTES_PER_FACET +
                         (pb->bilateral ? RS_DEVICE_BYTES_PER_BILATERAL_FACET : 0) +
                         (lists ? RS_DEVICE_BYTES_PER_BILATERAL_LIST_FACET(pb) : 0) +
                         (pb->colors ? RS_DEVICE_BYTES_PER_COLOR_FACET : 0);
    uint64_t per_vertex =
        RS_DEVICE_BYTES_PER_VERTEX + (pb->colors ? RS_DEVICE_BYTES_PER_COLOR_VERTEX : 0);
    return (uint64_t)facets * per_facet + (uint64_t)v * per_vertex;
}

double rs_halo_radius(const rs_problem *pb, double reach) {
    if (pb->bilateral)
        return pb->radius + pb->normal_iterations * pb->normal_radius;
    return pb->radius + (pb->mollify ? pb->mollify_radius + reach : 0);
}

/* Vertices with no facet within reach of their tile stay where they are, with zero weight. */
static void store_unmoved(tiler *t, const uint32_t *verts, size_t n) {
    const rs_result_sink *sink = t->sink;
    for (size_t i = 0; i < n; i++) {
        rs_store_position(sink->scalar, sink->positions, verts[i], t->whole->xyz + 3 * verts[i],
                          1 / t->whole->scale);
        if (sink->weight)
            sink->weight[verts[i]] = 0;
        if (sink->confidence)
            sink->confidence[verts[i]] = 0;
    }
    t->vertices_done += n;
}

/* Runs the tile of core vertices `verts` with facets `facets` (indices into the whole problem):
 * core vertices first, then the other vertices of those facets. */
static rsmooth_status run_tile(tiler *t, const uint32_t *verts, size_t n, const uint32_t *facets,
                               size_t m, uint64_t *needed) {
    const rs_problem *w = t->whole;
    if (m == 0) { /* stray vertices far from every facet */
        store_unmoved(t, verts, n);
        return RSMOOTH_OK;
    }
    rs_problem sub = *w;
    sub.xyz = NULL;
    sub.centroid = sub.normal = sub.area = NULL; /* computed from the vertices where needed */
    sub.facet_color = NULL;
    float *colors = NULL; /* the tile's vertices' colours, when the colour factor is on */
    uint32_t *list = rs_alloc_array(n + 3 * m, sizeof *list); /* tile vertex -> whole vertex */
    uint32_t *indices = rs_alloc_array(m, 3 * sizeof *indices);
    sub.facet_triangle = rs_alloc_array(m, sizeof(uint32_t));
    size_t count = 0;
    rsmooth_status st = RSMOOTH_OK;
    if (!list || !indices || !sub.facet_triangle) {
        st = rs_fail(t->error, RSMOOTH_ERROR_OUT_OF_MEMORY, "rsmooth_smooth",
                     "no memory for a tile of %zu facets", m);
        goto done;
    }
    for (; count < n; count++) {
        t->sub_index[verts[count]] = (uint32_t)count;
        list[count] = verts[count];
    }
    for (size_t j = 0; j < m; j++) {
        size_t q = facets[j];
        const uint32_t *tri = w->indices + 3 * (size_t)w->facet_triangle[q];
        for (int c = 0; c < 3; c++) {
            if (t->sub_index[tri[c]] == ABSENT) {
                t->sub_index[tri[c]] = (uint32_t)count;
                list[count++] = tri[c];
            }
            indices[3 * j + c] = t->sub_index[tri[c]];
        }
        sub.facet_triangle[j] = (uint32_t)j;
    }
    sub.xyz = rs_alloc_array(count, 3 * sizeof(double));
    if (!sub.xyz) {
        st = rs_fail(t->error, RSMOOTH_ERROR_OUT_OF_MEMORY, "rsmooth_smooth",
                     "no memory for a tile of %zu vertices", count);
        goto done;
    }
    for (size_t v = 0; v < count; v++)
        memcpy(sub.xyz + 3 * v, w->xyz + 3 * (size_t)list[v], 3 * sizeof(double));
    if (w->colors) {
        colors = rs_alloc_array(count, 3 * sizeof *colors);
        if (!colors) {
            st = rs_fail(t->error, RSMOOTH_ERROR_OUT_OF_MEMORY, "rsmooth_smooth",
                         "no memory for a tile of %zu vertices", count);
            goto done;
        }
        for (size_t v = 0; v < count; v++)
            memcpy(colors + 3 * v, w->colors + 3 * (size_t)list[v], 3 * sizeof *colors);
        sub.colors = colors;
    }
    sub.vertex_count = count;
    sub.indices = indices;
    sub.triangle_count = sub.facet_count = m;

    tile_progress tp = {w, (double)t->vertices_done / (double)t->vertices_total,
                        (double)n / (double)t->vertices_total};
    if (w->progress || w->progress_cancel) {
        sub.progress = NULL;
        sub.progress_cancel = report_tile_progress;
        sub.progress_user = &tp;
    }
    rs_result_sink sink = *t->sink;
    sink.target = verts;
    sink.core_count = n;
    st = rs_cl_run(t->ctx, &sub, &sink, t->stats, needed, t->error);
    if (st == RSMOOTH_OK)
        t->vertices_done += n;

done:
    for (size_t v = 0; v < count; v++)
        t->sub_index[list[v]] = ABSENT;
    rs_free(list);
    rs_free(indices);
    rs_free(colors);
    sub.indices = NULL;
    rs_problem_free(&sub);
    return st;
}

/* Solves the vertices `verts` (reordered in place) with candidate facets `facets` (a superset of
 * those within the halo of their box). */
static rsmooth_status solve_region(tiler *t, uint32_t *verts, size_t n, const uint32_t *facets,
                                   size_t facet_count, int depth) {
    const rs_problem *w = t->whole;
    if (n == 0)
        return RSMOOTH_OK;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], w->xyz[3 * (size_t)verts[i] + k]);
            hi[k] = fmax(hi[k], w->xyz[3 * (size_t)verts[i] + k]);
        }
    uint32_t *near = rs_alloc_array(facet_count ? facet_count : 1, sizeof *near);
    if (!near)
        return rs_fail(t->error, RSMOOTH_ERROR_OUT_OF_MEMORY, "rsmooth_smooth",
                       "no memory to plan tiles");
    size_t m = 0;
    for (size_t j = 0; j < facet_count; j++) {
        double c[3];
        rs_facet_centroid(w, facets[j], c);
        bool inside = true;
        for (int k = 0; k < 3; k++)
            inside = inside && c[k] >= lo[k] - t->halo && c[k] <= hi[k] + t->halo;
        if (inside)
            near[m++] = facets[j];
    }
    int axis = 0;
    for (int k = 1; k < 3; k++)
        if (hi[k] - lo[k] > hi[axis] - lo[axis])
            axis = k;
    double mid = 0.5 * (lo[axis] + hi[axis]);
    bool can_split = n >= 2 && depth < MAX_DEPTH && mid > lo[axis];

    rsmooth_status st = RSMOOTH_OK;
    uint64_t needed = 0;
    if (!can_split || estimate_bytes(w, n, m) <= t->budget) {
        st = run_tile(t, verts, n, near, m, &needed);
        if (st != RSMOOTH_ERROR_OUT_OF_MEMORY || needed == 0 || !can_split) {
            if (st == RSMOOTH_ERROR_OUT_OF_MEMORY && needed > 0)
                st = rs_fail(t->error, st, "rsmooth_smooth",
                             "device memory budget of %llu bytes is too small: the %zu facets "
                             "within reach of %zu vertices need %llu",
                             (unsigned long long)t->budget, m, n, (unsigned long long)needed);
            rs_free(near);
            return st;
        }
        rs_error_clear(t->error);
    }
    size_t below = 0; /* vertices left of mid come first */
    for (size_t i = 0; i < n; i++) {
        if (w->xyz[3 * (size_t)verts[i] + axis] < mid) {
            uint32_t v = verts[i];
            verts[i] = verts[below];
            verts[below++] = v;
        }
    }
    st = solve_region(t, verts, below, near, m, depth + 1);
    if (st == RSMOOTH_OK)
        st = solve_region(t, verts + below, n - below, near, m, depth + 1);
    rs_free(near);
    return st;
}

/* Reaches far beyond the mesh (a spatial width thousands of times its size) make every facet
 * weigh alike, and the kernels' float sums of those weights lose the result (0.14 edge lengths
 * off at sigma_f 1e5 on a 2,000-triangle shape, measured against the reference path; within
 * 1e-3 up to reaches of 2,000 mesh sizes): the device refuses them, the reference path runs them.
 */
#define MAX_REACH_PER_SIZE 1024.0

static rsmooth_status check_reach(const rs_problem *pb, rsmooth_error *error) {
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t v = 0; v < pb->vertex_count; v++) /* finite (checked): no fmin's NaN rules */
        for (int k = 0; k < 3; k++) {
            double x = pb->xyz[3 * v + k];
            lo[k] = x < lo[k] ? x : lo[k];
            hi[k] = x > hi[k] ? x : hi[k];
        }
    double size = 0;
    for (int k = 0; k < 3; k++)
        size = fmax(size, hi[k] - lo[k]);
    double reach = fmax(pb->radius, pb->normal_radius);
    if (pb->facet_count > 0 && size > 0 && reach > MAX_REACH_PER_SIZE * size)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, "rsmooth_smooth",
                       "the filter's reach (cutoff times sigma_f) is %.3g times the mesh's size: "
                       "every triangle would weigh alike, which the device's float sums cannot "
                       "resolve; keep the reach below %g times the mesh's size, or use the "
                       "reference path",
                       reach / size, MAX_REACH_PER_SIZE);
    return RSMOOTH_OK;
}

rsmooth_status rs_cl_filter(rsmooth_context *ctx, const rs_problem *pb, const rs_result_sink *sink,
                            rs_run_stats *stats, rsmooth_error *error) {
    rsmooth_status reach_ok = check_reach(pb, error);
    if (reach_ok != RSMOOTH_OK)
        return reach_ok;
    uint64_t budget = rs_cl_usable_memory(ctx);
    if (estimate_bytes(pb, pb->vertex_count, pb->facet_count) <= budget) {
        uint64_t needed = 0;
        rsmooth_status st = rs_cl_run(ctx, pb, sink, stats, &needed, error);
        if (st != RSMOOTH_ERROR_OUT_OF_MEMORY || needed == 0)
            return st;
        rs_error_clear(error);
    }
    double reach = 0; /* largest centroid-to-vertex distance */
    for (size_t q = 0; q < pb->facet_count; q++) {
        const uint32_t *tri = pb->indices + 3 * (size_t)pb->facet_triangle[q];
        double centroid[3];
        rs_facet_centroid(pb, q, centroid);
        for (int c = 0; c < 3; c++) {
            double d[3];
            rs_sub3(pb->xyz + 3 * (size_t)tri[c], centroid, d);
            reach = fmax(reach, sqrt(rs_dot3(d, d)));
        }
    }
    /* Tiles write to scratch first, so a tile that fails leaves the caller's arrays untouched.
     * Only the sink's core vertices are solved (a piece of a larger mesh: its first ones). */
    size_t nv = sink->core_count < pb->vertex_count ? sink->core_count : pb->vertex_count;
    uint32_t *verts = rs_alloc_array(nv ? nv : 1, sizeof *verts);
    uint32_t *facets = rs_alloc_array(pb->facet_count, sizeof *facets);
    uint32_t *sub_index = rs_alloc_array(pb->vertex_count, sizeof *sub_index);
    double *positions = rs_alloc_array(nv, 3 * sizeof *positions);
    float *weight = sink->weight ? rs_alloc_array(nv, sizeof *weight) : NULL;
    float *confidence = sink->confidence ? rs_alloc_array(nv, sizeof *confidence) : NULL;
    rsmooth_status st = RSMOOTH_OK;
    if (!verts || !facets || !sub_index || !positions || (sink->weight && !weight) ||
        (sink->confidence && !confidence)) {
        st = rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, "rsmooth_smooth",
                     "no memory to plan tiles");
    } else {
        for (size_t v = 0; v < nv; v++)
            verts[v] = (uint32_t)v;
        for (size_t v = 0; v < pb->vertex_count; v++)
            sub_index[v] = ABSENT;
        for (size_t q = 0; q < pb->facet_count; q++)
            facets[q] = (uint32_t)q;
        /* a little extra: a facet exactly at the halo must not round out of it */
        double halo = rs_halo_radius(pb, reach) * (1 + 1e-6);
        rs_result_sink scratch = {RSMOOTH_FLOAT64, positions, weight, confidence, NULL, nv, NULL};
        tiler t = {ctx, pb, &scratch, stats, halo, budget, sub_index, 0, nv, error};
        st = solve_region(&t, verts, nv, facets, pb->facet_count, 0);
    }
    for (size_t v = 0; st == RSMOOTH_OK && v < nv; v++) {
        rs_store_position(sink->scalar, sink->positions, v, positions + 3 * v, 1); /* unscaled */
        if (weight)
            sink->weight[v] = weight[v];
        if (confidence)
            sink->confidence[v] = confidence[v];
    }
    rs_free(positions);
    rs_free(weight);
    rs_free(confidence);
    rs_free(verts);
    rs_free(facets);
    rs_free(sub_index);
    return st;
}
