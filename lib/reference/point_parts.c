/* Point clouds part by part, as meshes are (core/parts.c): a point's scale is its spacing (its
 * mean distance to its 6 nearest others), and points whose spacings differ by more than about 8
 * times with none between are filtered apart, each part with its own spacing as its unit. A
 * point thrown far from the cloud has a spacing far out of line: it makes a part of one, too
 * small to be a surface, and is held where it is, moving no other point. A cloud of one part,
 * nearly every cloud, is filtered as it is: the same bits as before parts existed. */
#include "core/parts.h"
#include "core/spatial.h"
#include "reference/points.h"

#include <string.h>

/* Each point's part from its spacing in the input; *parts of them. The spacings (internal
 * units, rs_free them) are what a cloud of one part's first pass measures. */
static rsmooth_status find_parts(rsmooth_scalar scalar, const void *positions, size_t n,
                                 uint32_t *part, size_t *parts, double **spacings,
                                 rsmooth_error *error, const char *where) {
    double scale = 1;
    rsmooth_status st = rs_check_point_positions(scalar, positions, n, &scale, error, where);
    if (st != RSMOOTH_OK)
        return st;
    double *xyz = rs_alloc_array(n, 3 * sizeof *xyz);
    double *spacing = *spacings = rs_alloc_array(n, sizeof *spacing);
    int16_t *bin = rs_alloc_array(n, sizeof *bin);
    double *limit = NULL;
    rs_kdtree tree;
    bool ok = xyz && spacing && bin;
    if (ok) {
        rs_scale_positions(scalar, positions, n, scale, xyz);
        ok = rs_kdtree_build(&tree, xyz, n);
    }
    if (ok) {
        rs_point_spacings(&tree, spacing);
        rs_kdtree_free(&tree);
        for (size_t i = 0; i < n; i++)
            bin[i] = rs_scale_bin(spacing[i]);
        *parts = rs_scale_parts(bin, n, part, &limit);
        ok = *parts != SIZE_MAX;
    }
    rs_free(xyz);
    rs_free(bin);
    rs_free(limit);
    return ok ? RSMOOTH_OK
              : rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "no memory for %zu points", n);
}

/* The arrays of one part: the caller's, gathered. */
typedef struct point_part {
    size_t n;
    uint32_t *point; /* per part point: the cloud's */
    void *positions, *normals, *out_positions, *out_normals;
    float *confidence, *colors;
    uint8_t *mask;
} point_part;

static void free_part(point_part *q) {
    rs_free(q->point);
    rs_free(q->positions);
    rs_free(q->normals);
    rs_free(q->out_positions);
    rs_free(q->out_normals);
    rs_free(q->confidence);
    rs_free(q->colors);
    rs_free(q->mask);
    memset(q, 0, sizeof *q);
}

static bool gather(point_part *q, const uint32_t *part, uint32_t which, size_t n,
                   rsmooth_scalar scalar, const void *positions, const void *normals,
                   const rsmooth_params *p) {
    size_t record = rs_vertex_bytes(scalar);
    memset(q, 0, sizeof *q);
    for (size_t i = 0; i < n; i++)
        q->n += part[i] == which;
    size_t m = q->n ? q->n : 1;
    q->point = rs_alloc_array(m, sizeof *q->point);
    q->positions = rs_alloc_array(m, record);
    q->normals = rs_alloc_array(m, record);
    q->out_positions = rs_alloc_array(m, record);
    q->out_normals = rs_alloc_array(m, record);
    q->confidence = rs_alloc_array(m, sizeof *q->confidence);
    q->colors = p->colors ? rs_alloc_array(m, 3 * sizeof *q->colors) : NULL;
    q->mask = p->move_mask ? rs_alloc_array(m, 1) : NULL;
    if (!q->point || !q->positions || !q->normals || !q->out_positions || !q->out_normals ||
        !q->confidence || (p->colors && !q->colors) || (p->move_mask && !q->mask))
        return false;
    for (size_t i = 0, j = 0; i < n; i++)
        if (part[i] == which) {
            q->point[j] = (uint32_t)i;
            memcpy((char *)q->positions + j * record, (const char *)positions + i * record, record);
            memcpy((char *)q->normals + j * record, (const char *)normals + i * record, record);
            if (q->colors)
                memcpy(q->colors + 3 * j, p->colors + 3 * i, 3 * sizeof *q->colors);
            if (q->mask)
                q->mask[j] = p->move_mask[i];
            j++;
        }
    return true;
}

/* The whole cloud's outputs while the parts run (the caller's may be its inputs). */
typedef struct cloud_out {
    void *positions, *normals;
    float *confidence;
} cloud_out;

/* Held points first (their input, the input's unit normal, confidence 0), then each part of
 * enough points through the one-part call, scattered. */
static rsmooth_status filter_parts(rs_points_solve_fn solve, void *solve_ctx, const char *where,
                                   rsmooth_scalar scalar, const void *positions,
                                   const void *normals, size_t n, const rsmooth_params *p,
                                   const uint32_t *part, size_t parts, const size_t *size,
                                   cloud_out *out, rsmooth_report *report, rsmooth_error *error) {
    size_t record = rs_vertex_bytes(scalar);
    memcpy(out->positions, positions, n * record);
    for (size_t i = 0; i < n; i++) {
        double u[3] = {0, 0, 0};
        rs_point_unit_normal(scalar, normals, i, u);
        rs_store_position(scalar, out->normals, i, u, 1);
        out->confidence[i] = 0;
    }
    rs_pass_progress progress = {p->progress, p->progress_cancel, p->progress_user, 0, (int)parts};
    uint32_t largest = 0; /* the first of the most points */
    for (uint32_t which = 1; which < parts; which++)
        if (size[which] > size[largest])
            largest = which;
    bool first = true;
    for (uint32_t which = 0; which < parts; which++) {
        if (size[which] < RS_MIN_PART_POINTS)
            continue;
        point_part q;
        if (!gather(&q, part, which, n, scalar, positions, normals, p)) {
            free_part(&q);
            return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "no memory for a part");
        }
        rsmooth_params sub = *p;
        sub.colors = q.colors;
        sub.move_mask = q.mask;
        if (progress.progress || progress.cancel) {
            progress.pass = (int)which;
            sub.progress = NULL;
            sub.progress_cancel = rs_report_pass_progress;
            sub.progress_user = &progress;
        }
        rsmooth_report one;
        rs_report_init(&one);
        rsmooth_status st = rs_smooth_points_one_part(
            solve, solve_ctx, where, scalar, q.positions, q.normals, q.n, NULL, &sub,
            q.out_positions, q.out_normals, q.confidence, report ? &one : NULL, error);
        if (st == RSMOOTH_OK)
            for (size_t j = 0; j < q.n; j++) {
                size_t i = q.point[j];
                memcpy((char *)out->positions + i * record, (char *)q.out_positions + j * record,
                       record);
                memcpy((char *)out->normals + i * record, (char *)q.out_normals + j * record,
                       record);
                out->confidence[i] = q.confidence[j];
            }
        if (st == RSMOOTH_OK && report)
            rs_add_part_report(report, &one, which == largest, first);
        first = false;
        free_part(&q);
        if (st != RSMOOTH_OK)
            return st;
    }
    return RSMOOTH_OK;
}

rsmooth_status rs_smooth_points_with(rs_points_solve_fn solve, void *solve_ctx, const char *where,
                                     rsmooth_scalar scalar, const void *positions,
                                     const void *normals, size_t point_count,
                                     const rsmooth_params *params, void *out_positions,
                                     void *out_normals, float *out_confidence,
                                     rsmooth_report *report, rsmooth_error *error) {
    size_t caller_size = report ? report->struct_size : 0;
    rsmooth_params p;
    uint32_t *part = NULL;
    double *spacing = NULL; /* the input's: the whole cloud's first pass reads them */
    size_t *size = NULL, parts = 1;
    /* what the one-part call checks it reports itself, in its words */
    bool checked = rs_params_resolve(params, &p, NULL, where) == RSMOOTH_OK &&
                   rs_check_point_positions(scalar, positions, point_count, &(double){1}, NULL,
                                            where) == RSMOOTH_OK;
    rsmooth_status st = RSMOOTH_OK;
    if (checked) {
        part = rs_alloc_array(point_count, sizeof *part);
        st = part ? find_parts(scalar, positions, point_count, part, &parts, &spacing, error, where)
                  : rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "no memory for parts");
        size = st == RSMOOTH_OK ? rs_calloc_array(parts ? parts : 1, sizeof *size) : NULL;
        if (st == RSMOOTH_OK && !size)
            st = rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "no memory for parts");
        for (size_t i = 0; st == RSMOOTH_OK && i < point_count; i++)
            if (part[i] != RS_NO_PART)
                size[part[i]]++;
    }
    size_t outliers = 0;
    for (size_t i = 0; size && i < point_count; i++)
        outliers += part[i] == RS_NO_PART || size[part[i]] < RS_MIN_PART_POINTS;
    rsmooth_report full;
    rs_report_init(&full);
    rsmooth_report *r = report ? &full : NULL;
    if (st == RSMOOTH_OK && (!checked || (parts <= 1 && outliers == 0))) {
        st = rs_smooth_points_one_part(solve, solve_ctx, where, scalar, positions, normals,
                                       point_count, spacing, params, out_positions, out_normals,
                                       out_confidence, r, error);
    } else if (st == RSMOOTH_OK) {
        size_t record = rs_vertex_bytes(scalar);
        cloud_out out = {rs_alloc_array(point_count, record), rs_alloc_array(point_count, record),
                         rs_alloc_array(point_count, sizeof(float))};
        st = out.positions && out.normals && out.confidence
                 ? filter_parts(solve, solve_ctx, where, scalar, positions, normals, point_count,
                                &p, part, parts, size, &out, r, error)
                 : rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "no memory for parts");
        if (st == RSMOOTH_OK) { /* every input read: the outputs may be the inputs */
            memcpy(out_positions, out.positions, point_count * record);
            if (out_normals)
                memcpy(out_normals, out.normals, point_count * record);
            if (out_confidence)
                memcpy(out_confidence, out.confidence, point_count * sizeof(float));
            full.vertex_count = point_count;
        }
        rs_free(out.positions);
        rs_free(out.normals);
        rs_free(out.confidence);
    }
    if (st == RSMOOTH_OK && report) {
        size_t smoothed = 0;
        for (size_t q = 0; size && q < parts; q++)
            smoothed += size[q] >= RS_MIN_PART_POINTS;
        full.parts = size ? smoothed : 1;
        full.outliers = outliers;
        rs_give_report(report, caller_size, &full);
    }
    rs_free(part);
    rs_free(spacing);
    rs_free(size);
    return st;
}

rsmooth_status rs_reference_points_pass(void *ctx, const rs_problem *pb, double *out_next,
                                        float *out_confidence, double *out_normals,
                                        rsmooth_report *report, double t_start,
                                        rsmooth_error *error, const char *where) {
    (void)ctx;
    return rs_reference_solve(pb, RSMOOTH_FLOAT64, out_next, NULL, out_confidence, out_normals,
                              report, t_start, error, where);
}
