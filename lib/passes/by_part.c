/* rs_filter_passes: the mesh part by part (core/parts.c), each in its own unit, then the fold
 * guard over the whole result. A mesh of one part without an edge out of line, which is nearly
 * every mesh, goes to the passes exactly as it is: the same bits as before parts existed. */
#include "core/parts.h"
#include "passes/one_part.h"
#include "stages/fold_guard.h"

#include <math.h>
#include <string.h>

/* The call's outputs while the parts run: written to the caller's arrays only when all succeed. */
typedef struct whole_outputs {
    void *positions;
    float *weight, *confidence;
} whole_outputs;

/* A part's unit when an edge of it is out of line: the mean of its other edges (caller's units),
 * and its own mean over every edge, which the passes would otherwise use. */
static rsmooth_status trimmed_unit(rsmooth_scalar scalar, const rs_submesh *sub, double limit,
                                   double *unit, double *own, rsmooth_error *error,
                                   const char *where) {
    double magnitude = 0, scale = 1;
    rsmooth_status st = rs_check_coordinates(scalar, sub->positions, sub->vertex_count, "vertex",
                                             &magnitude, error, where);
    if (st == RSMOOTH_OK)
        st = rs_mesh_scale(scalar, sub->positions, sub->indices, sub->triangle_count, magnitude,
                           &scale, error, where);
    if (st != RSMOOTH_OK)
        return st;
    double *xyz = rs_alloc_array(sub->vertex_count ? sub->vertex_count : 1, 3 * sizeof *xyz);
    bool ok = xyz != NULL;
    if (ok) {
        rs_scale_positions(scalar, sub->positions, sub->vertex_count, scale, xyz);
        ok = rs_mean_edge_length_below(xyz, sub->vertex_count, sub->indices, sub->triangle_count,
                                       limit * scale, unit) &&
             rs_mean_edge_length(xyz, sub->vertex_count, sub->indices, sub->triangle_count, own);
    }
    rs_free(xyz);
    if (!ok)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "no memory for a part's unit");
    *unit /= scale; /* exact: a power of two */
    *own /= scale;
    return RSMOOTH_OK;
}

/* params in the part's unit: relative widths made absolute in it, and the levels that stay in
 * the part's own mean edge lengths rescaled to it. */
static void in_unit(rsmooth_params *p, double unit, double own) {
    if (!(unit > 0) || !(own > 0) || unit == own)
        return;
    if (!p->absolute) {
        p->sigma_f *= unit;
        p->sigma_g *= unit; /* +INFINITY stays */
        p->normal_sigma_s *= unit;
        p->guided_sigma_s *= unit;
        p->absolute = 1;
    }
    p->discrepancy_level *= unit / own;
    p->discrepancy_gain *= unit / own;
}

/* One part through the passes, its results scattered into `whole`. */
static rsmooth_status filter_part(rs_filter_fn one_pass, rs_stage_runner stage,
                                  rs_network_runner network, void *ctx, rsmooth_scalar scalar,
                                  const rs_parts *parts, uint32_t part, const void *positions,
                                  size_t vertex_count, const uint32_t *indices,
                                  size_t triangle_count, const rsmooth_params *resolved,
                                  rs_pass_progress *progress, whole_outputs *whole,
                                  rsmooth_report *report, rsmooth_error *error, const char *where) {
    rs_submesh sub;
    if (!rs_submesh_make(&sub, parts, part, scalar, positions, vertex_count, indices,
                         triangle_count, resolved->move_mask))
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "no memory for a part");
    rsmooth_status st = RSMOOTH_OK;
    size_t n = sub.vertex_count, record = rs_vertex_bytes(scalar);
    void *out = rs_alloc_array(n ? n : 1, record);
    float *weight = whole->weight ? rs_alloc_array(n ? n : 1, sizeof *weight) : NULL;
    float *confidence = whole->confidence ? rs_alloc_array(n ? n : 1, sizeof *confidence) : NULL;
    float *colors = resolved->colors ? rs_alloc_array(n ? n : 1, 3 * sizeof *colors) : NULL;
    if (!out || (whole->weight && !weight) || (whole->confidence && !confidence) ||
        (resolved->colors && !colors)) {
        st = rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "no memory for a part");
        goto done;
    }
    rsmooth_params p = *resolved;
    p.move_mask = sub.move;
    if (colors) {
        for (size_t s = 0; s < n; s++)
            memcpy(colors + 3 * s, resolved->colors + 3 * (size_t)sub.vertex[s],
                   3 * sizeof *colors);
        p.colors = colors;
    }
    if (progress->progress || progress->cancel) {
        p.progress = NULL;
        p.progress_cancel = rs_report_pass_progress;
        p.progress_user = progress;
    }
    double limit = parts->edge_limit[part], unit = 0, own = 0;
    st = trimmed_unit(scalar, &sub, limit, &unit, &own, error, where);
    if (st != RSMOOTH_OK)
        goto done;
    in_unit(&p, unit, own);
    st = rs_filter_one_part(one_pass, stage, network, ctx, scalar, sub.positions, n, sub.indices,
                            sub.triangle_count, &p, out, weight, confidence, report, error, where);
    if (st != RSMOOTH_OK)
        goto done;
    if (report)
        report->mean_edge_length = unit; /* the part's unit, in the caller's units */
    for (size_t s = 0; s < n; s++)
        if (sub.move[s]) {
            size_t v = sub.vertex[s];
            memcpy((char *)whole->positions + v * record, (const char *)out + s * record, record);
            if (weight)
                whole->weight[v] = weight[s];
            if (confidence)
                whole->confidence[v] = confidence[s];
        }
done:
    rs_free(out);
    rs_free(weight);
    rs_free(confidence);
    rs_free(colors);
    rs_submesh_free(&sub);
    return st;
}

/* Every part in turn into `whole` (the input where no part moves a vertex). */
static rsmooth_status filter_parts(rs_filter_fn one_pass, rs_stage_runner stage,
                                   rs_network_runner network, void *ctx, rsmooth_scalar scalar,
                                   const rs_parts *parts, const void *positions,
                                   size_t vertex_count, const uint32_t *indices,
                                   size_t triangle_count, const rsmooth_params *resolved,
                                   whole_outputs *whole, rsmooth_report *report, size_t *smoothed,
                                   rsmooth_error *error, const char *where) {
    memcpy(whole->positions, positions, vertex_count * rs_vertex_bytes(scalar));
    if (whole->weight)
        memset(whole->weight, 0, vertex_count * sizeof *whole->weight);
    if (whole->confidence)
        memset(whole->confidence, 0, vertex_count * sizeof *whole->confidence);
    uint32_t largest = rs_parts_largest(parts);
    rs_pass_progress progress = {resolved->progress, resolved->progress_cancel,
                                 resolved->progress_user, 0, (int)parts->count};
    rsmooth_report one;
    bool first = true;
    *smoothed = 0;
    for (uint32_t part = 0; part < parts->count; part++) {
        if (parts->vertices[part] == 0)
            continue; /* outliers alone, or nothing the caller lets move */
        progress.pass = (int)part;
        rs_report_init(&one);
        rsmooth_status st = filter_part(one_pass, stage, network, ctx, scalar, parts, part,
                                        positions, vertex_count, indices, triangle_count, resolved,
                                        &progress, whole, report ? &one : NULL, error, where);
        if (st != RSMOOTH_OK)
            return st;
        if (report)
            rs_add_part_report(report, &one, part == largest, first);
        first = false;
        ++*smoothed;
    }
    if (report && first) /* nothing to smooth: the whole mesh's counts */
        rs_report_init(report);
    return RSMOOTH_OK;
}

/* The fold guard over the whole result, holding what the call holds: the caller's mask and the
 * outliers. -1 when out of memory. */
static long guard_folds(rsmooth_scalar scalar, const void *positions, void *out_positions,
                        size_t vertex_count, const uint32_t *indices, size_t triangle_count,
                        const rs_parts *parts, const uint8_t *mask) {
    if (parts->whole || parts->outliers == 0)
        return rs_fold_guard(scalar, positions, out_positions, vertex_count, indices,
                             triangle_count, mask);
    uint8_t *movable = rs_alloc_array(vertex_count, 1);
    if (!movable)
        return -1;
    for (size_t v = 0; v < vertex_count; v++)
        movable[v] = !parts->outlier[v] && (!mask || mask[v]);
    long moved = rs_fold_guard(scalar, positions, out_positions, vertex_count, indices,
                               triangle_count, movable);
    rs_free(movable);
    return moved;
}

rsmooth_status rs_filter_passes(rs_filter_fn one_pass, rs_stage_runner stage,
                                rs_network_runner network, void *ctx, rsmooth_scalar scalar,
                                const void *positions, size_t vertex_count, const uint32_t *indices,
                                size_t triangle_count, const rsmooth_params *params,
                                void *out_positions, float *out_weight, float *out_confidence,
                                rsmooth_report *report, rsmooth_error *error, const char *where) {
    rs_error_clear(error);
    double t_start = rs_now_ms();
    rsmooth_params p;
    rsmooth_status st = rs_params_resolve(params, &p, error, where);
    if (st == RSMOOTH_OK)
        st = rs_check_outputs(scalar, positions, vertex_count, indices, triangle_count, &p,
                              out_positions, out_weight, out_confidence, error, where);
    if (st == RSMOOTH_OK)
        st = rs_check_mesh_arrays(scalar, positions, vertex_count, indices, triangle_count, NULL,
                                  error, where);
    if (st == RSMOOTH_OK)
        st = rs_check_colors(p.colors, vertex_count, error, where);
    if (st != RSMOOTH_OK)
        return st;
    rsmooth_report full; /* filled whole, then as much as the caller's struct holds */
    rs_report_init(&full);
    rsmooth_report *r = report ? &full : NULL;
    rs_parts parts;
    st = rs_parts_find(&parts, scalar, positions, vertex_count, indices, triangle_count, error,
                       where);
    size_t smoothed = parts.count;
    if (st == RSMOOTH_OK && parts.whole) {
        st = rs_filter_one_part(one_pass, stage, network, ctx, scalar, positions, vertex_count,
                                indices, triangle_count, params, out_positions, out_weight,
                                out_confidence, r, error, where);
    } else if (st == RSMOOTH_OK) {
        size_t record = rs_vertex_bytes(scalar);
        whole_outputs whole = {rs_alloc_array(vertex_count, record),
                               out_weight ? rs_alloc_array(vertex_count, sizeof(float)) : NULL,
                               out_confidence ? rs_alloc_array(vertex_count, sizeof(float)) : NULL};
        if (!whole.positions || (out_weight && !whole.weight) ||
            (out_confidence && !whole.confidence))
            st = rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "no memory for the parts");
        else
            st =
                filter_parts(one_pass, stage, network, ctx, scalar, &parts, positions, vertex_count,
                             indices, triangle_count, &p, &whole, r, &smoothed, error, where);
        if (st == RSMOOTH_OK) {
            memcpy(out_positions, whole.positions, vertex_count * record);
            if (out_weight)
                memcpy(out_weight, whole.weight, vertex_count * sizeof *out_weight);
            if (out_confidence)
                memcpy(out_confidence, whole.confidence, vertex_count * sizeof *out_confidence);
            full.vertex_count = vertex_count;
            full.triangle_count = triangle_count;
        }
        rs_free(whole.positions);
        rs_free(whole.weight);
        rs_free(whole.confidence);
    }
    long guarded = 0;
    if (st == RSMOOTH_OK && p.guard)
        guarded = guard_folds(scalar, positions, out_positions, vertex_count, indices,
                              triangle_count, &parts, p.move_mask);
    if (guarded < 0)
        st = rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "no memory for the fold guard");
    if (st == RSMOOTH_OK && report) {
        full.ms_total = rs_now_ms() - t_start; /* the parts and the guard too */
        full.parts = smoothed;
        full.outliers = parts.outliers;
        full.guarded_vertices = guarded > 0 ? (size_t)guarded : 0;
        rs_give_report(report, report->struct_size, &full);
    }
    rs_parts_free(&parts);
    return st;
}
