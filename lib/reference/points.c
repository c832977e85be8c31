/* Point clouds with normals (beyond the paper): the reference filter with the points as its facets.
 * A point is a facet whose centroid is the point, whose plane is its tangent plane and whose area
 * is estimated from how far its nearest neighbours are; rs_reference_solve then runs the bilateral
 * normal filter and Eq. 3 on them unchanged (the device's pass, api/points.c, runs the same
 * problem through the mesh path's kernels instead). Points always take the bilateral filter when
 * they take one at all: the paper's mollification moves triangle corners, and points have none. */
#include "reference/points.h"
#include "core/spatial.h"

#include <math.h>
#include <string.h>

/* s_i, a point's spacing, is its mean distance to this many nearest others: on the vertices of a
 * mesh, 6 (a regular vertex's ring) makes the mean s_i within a few percent of the mean edge
 * length, so relative sigmas mean the same for a mesh and for its vertices as a point cloud. */
#define SPACING_NEIGHBOURS 6
/* The area per point of a regular triangular lattice of spacing s is (sqrt(3) / 2) s^2: the
 * points' areas then sum to about the surface's. */
#define LATTICE_AREA 0.86602540378443864676
/* Points per chunk of the threaded neighbour search. */
#define SPACING_GRAIN 4096

typedef struct spacing_job {
    const rs_kdtree *tree;
    double *spacing; /* per point: s_i */
} spacing_job;

static void spacing_range(void *ctx, size_t begin, size_t end, size_t chunk) {
    const spacing_job *job = ctx;
    double d2[SPACING_NEIGHBOURS];
    (void)chunk;
    for (size_t i = begin; i < end; i++) {
        size_t found = rs_kdtree_nearest(job->tree, job->tree->xyz + 3 * i, (uint32_t)i,
                                         SPACING_NEIGHBOURS, d2);
        double sum = 0;
        for (size_t j = 0; j < found; j++)
            sum += sqrt(d2[j]);
        job->spacing[i] = found ? sum / (double)found : 0;
    }
}

/* The mean of n spacings, summed in point order: the same on every run. */
static double mean_spacing(const double *spacing, size_t n) {
    double sum = 0;
    for (size_t i = 0; i < n; i++)
        sum += spacing[i];
    return sum / (double)n;
}

double rs_point_spacings(const rs_kdtree *tree, double *spacing) {
    spacing_job job = {tree, spacing};
    rs_parallel_for(tree->count, SPACING_GRAIN, spacing_range, &job);
    return mean_spacing(spacing, tree->count);
}

/* Checks positions (what rs_check_mesh_arrays checks, worded for points) and chooses the scale
 * of internal units (scale.c). */
rsmooth_status rs_check_point_positions(rsmooth_scalar scalar, const void *positions,
                                        size_t point_count, double *scale, rsmooth_error *error,
                                        const char *caller) {
    if (scalar != RSMOOTH_FLOAT32 && scalar != RSMOOTH_FLOAT64)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, caller,
                       "scalar must be RSMOOTH_FLOAT32 or RSMOOTH_FLOAT64 (got %d)", (int)scalar);
    if (!positions)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, caller, "positions is NULL");
    if (point_count == 0)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, caller, "the point cloud is empty");
    if (point_count >= UINT32_MAX || rs_mul_overflows(point_count, 3 * sizeof(double)))
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, caller,
                       "point count %zu exceeds the 32-bit index range", point_count);
    double magnitude = 0;
    rsmooth_status st =
        rs_check_coordinates(scalar, positions, point_count, "point", &magnitude, error, caller);
    if (st != RSMOOTH_OK)
        return st;
    return rs_points_scale(scalar, positions, point_count, magnitude, scale, error, caller);
}

/* Normal i of the caller's array made unit length into out[0..2]; NULL, or what is wrong with it.
 * Scaled by its largest component first, so lengths near the double range neither overflow nor
 * vanish. */
const char *rs_point_unit_normal(rsmooth_scalar scalar, const void *normals, size_t i,
                                 double out[3]) {
    double m = 0;
    for (int k = 0; k < 3; k++) {
        out[k] = rs_coordinate(scalar, normals, 3 * i + (size_t)k);
        if (!isfinite(out[k]))
            return "non-finite";
        m = fmax(m, fabs(out[k]));
    }
    if (!(m > 0))
        return "zero-length";
    for (int k = 0; k < 3; k++)
        out[k] /= m;
    double len = sqrt(rs_dot3(out, out));
    for (int k = 0; k < 3; k++)
        out[k] /= len;
    return NULL;
}

rsmooth_status rs_point_spacing(rsmooth_scalar scalar, const void *positions, size_t point_count,
                                double *out_spacing, rsmooth_error *error) {
    static const char caller[] = "rsmooth_point_spacing";
    rs_error_clear(error);
    if (!out_spacing)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, caller, "out_spacing is NULL");
    double scale = 1;
    rsmooth_status st =
        rs_check_point_positions(scalar, positions, point_count, &scale, error, caller);
    if (st != RSMOOTH_OK)
        return st;
    double *xyz = rs_alloc_array(point_count, 3 * sizeof *xyz);
    double *spacing = rs_alloc_array(point_count, sizeof *spacing);
    rs_kdtree tree;
    bool ok = xyz && spacing;
    if (ok) {
        rs_scale_positions(scalar, positions, point_count, scale, xyz);
        ok = rs_kdtree_build(&tree, xyz, point_count);
    }
    if (ok) {
        *out_spacing = rs_point_spacings(&tree, spacing) / scale; /* exact: a power of two */
        rs_kdtree_free(&tree);
    }
    rs_free(xyz);
    rs_free(spacing);
    return ok ? RSMOOTH_OK
              : rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, caller, "no memory for %zu points",
                        point_count);
}

/* Arrays of one call: the current and next positions; the input's unit normals, the previous
 * pass's filtered normals and this pass's; per-point spacing and area; confidence of this and the
 * previous pass. */
typedef struct point_arrays {
    double *xyz, *next, *input_normal, *normal, *filtered, *spacing, *area;
    double *color; /* the colours as doubles, when the colour term is on */
    float *confidence, *prev_confidence;
} point_arrays;

static void free_arrays(point_arrays *a) {
    rs_free(a->xyz);
    rs_free(a->input_normal);
    rs_free(a->next);
    rs_free(a->normal);
    rs_free(a->filtered);
    rs_free(a->spacing);
    rs_free(a->area);
    rs_free(a->confidence);
    rs_free(a->prev_confidence);
    rs_free(a->color);
}

/* One call of smooth_points: the caller's inputs, the resolved parameters and the state its
 * steps share across the passes. */
typedef struct points_run {
    rs_points_solve_fn solve; /* a pass's filter: the reference path's or the device's */
    void *solve_ctx;
    const char *where; /* the public function called */
    rsmooth_scalar scalar;
    const void *positions, *normals; /* the caller's */
    size_t n;                        /* points */
    rsmooth_params p;                /* resolved */
    double scale;                    /* internal units per caller unit (scale.c) */
    point_arrays a;
    rs_kdtree tree;              /* of the pass's positions, while the pass measures spacings */
    const double *given_spacing; /* the input's, measured by the caller (point_parts.c), or NULL */
    /* The unit of relative sigmas: the input's spacing, kept through the passes (as meshes keep
     * their input's mean edge length), so later passes do not shrink their reach. */
    double unit, input_spacing;
    rs_pass_progress pp;
    bool reports;            /* the caller asked for progress or cancellation */
    size_t weighted_points;  /* points of positive area in the first pass: the report's facets */
    rsmooth_report sum, one; /* the passes' so far, and this pass's */
    rsmooth_report *report;  /* the caller's, or NULL */
    rsmooth_error *error;
} points_run;

static rsmooth_status no_memory(points_run *r) {
    return rs_fail(r->error, RSMOOTH_ERROR_OUT_OF_MEMORY, r->where, "no memory for %zu points",
                   r->n);
}

/* Resolves the parameters and checks the caller's arrays, before anything is allocated. */
static rsmooth_status check_call(points_run *r, const rsmooth_params *params, void *out_positions,
                                 void *out_normals, float *out_confidence) {
    rsmooth_error *error = r->error;
    rsmooth_status st = rs_params_resolve(params, &r->p, error, r->where);
    if (st != RSMOOTH_OK)
        return st;
    if (r->p.passes < 1) /* (0 is a mesh's: its stage alone, or nothing) */
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, r->where,
                       "passes must be at least 1 for a point cloud (got %d)", r->p.passes);
    if ((st = rs_check_point_positions(r->scalar, r->positions, r->n, &r->scale, error,
                                       r->where)) != RSMOOTH_OK)
        return st;
    if ((st = rs_check_colors(r->p.colors, r->n, error, r->where)) != RSMOOTH_OK)
        return st;
    if (!r->normals)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, r->where,
                       "normals is NULL: a point cloud needs a normal per point");
    for (size_t i = 0; i < r->n; i++) {
        double n[3];
        const char *wrong = rs_point_unit_normal(r->scalar, r->normals, i, n);
        if (wrong)
            return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, r->where,
                           "point %zu has a %s normal", i, wrong);
    }
    if (!out_positions)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, r->where, "out_positions is NULL");
    /* Every input is read before any output is written, so outputs may be the inputs; but two
     * outputs in one place would mix. */
    size_t vec_bytes = r->n * rs_vertex_bytes(r->scalar);
    size_t conf_bytes = r->n * sizeof(float);
    if (rs_ranges_overlap(out_positions, vec_bytes, out_normals, vec_bytes) ||
        rs_ranges_overlap(out_positions, vec_bytes, out_confidence, conf_bytes) ||
        rs_ranges_overlap(out_normals, vec_bytes, out_confidence, conf_bytes))
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, r->where,
                       "out_positions, out_normals and out_confidence overlap");
    return RSMOOTH_OK;
}

/* The arrays of point_arrays, filled with the scaled positions, the unit input normals and the
 * colours; false when memory ran out. */
static bool load_points(points_run *r) {
    size_t n = r->n;
    point_arrays *a = &r->a;
    a->xyz = rs_alloc_array(n, 3 * sizeof(double));
    a->next = rs_alloc_array(n, 3 * sizeof(double));
    a->input_normal = rs_alloc_array(n, 3 * sizeof(double));
    a->normal = rs_alloc_array(n, 3 * sizeof(double));
    a->filtered = rs_alloc_array(n, 3 * sizeof(double));
    a->spacing = rs_alloc_array(n, sizeof(double));
    a->area = rs_alloc_array(n, sizeof(double));
    a->confidence = rs_alloc_array(n, sizeof(float));
    a->prev_confidence = rs_alloc_array(n, sizeof(float));
    if (r->p.colors && !isinf(r->p.sigma_c)) {
        /* a point is its own facet: its colour is the facet's */
        a->color = rs_alloc_array(n, 3 * sizeof(double));
        if (!a->color)
            return false;
        for (size_t i = 0; i < 3 * n; i++)
            a->color[i] = r->p.colors[i];
    }
    if (!a->xyz || !a->next || !a->input_normal || !a->normal || !a->filtered || !a->spacing ||
        !a->area || !a->confidence || !a->prev_confidence)
        return false;
    rs_scale_positions(r->scalar, r->positions, n, r->scale, a->xyz);
    for (size_t i = 0; i < n; i++)
        rs_point_unit_normal(r->scalar, r->normals, i, a->input_normal + 3 * i);
    return true;
}

/* The pass's problem: every point a facet at its position, with the input's normal and an area
 * from its spacing at the pass's positions. */
static rsmooth_status pass_problem(points_run *r, int pass, rs_problem *pb) {
    size_t n = r->n;
    point_arrays *a = &r->a;
    double spacing;
    if (pass == 0 && r->given_spacing) { /* the same tree over the same positions gave them */
        memcpy(a->spacing, r->given_spacing, n * sizeof *a->spacing);
        spacing = mean_spacing(a->spacing, n);
    } else if (rs_kdtree_build(&r->tree, a->xyz, n)) {
        spacing = rs_point_spacings(&r->tree, a->spacing);
    } else {
        return no_memory(r);
    }
    if (pass == 0) {
        r->input_spacing = spacing;
        r->unit = r->p.absolute ? r->scale : spacing;
    }
    double area_sum = 0;
    size_t positive = 0;
    for (size_t i = 0; i < n; i++) {
        a->area[i] = LATTICE_AREA * a->spacing[i] * a->spacing[i];
        area_sum += a->area[i];
        positive += a->area[i] > 0;
    }
    if (pass == 0)
        r->weighted_points = positive;

    memset(pb, 0, sizeof *pb);
    pb->vertex_count = n;
    pb->scale = 1; /* the solve writes next positions in internal units, as a.xyz holds */
    pb->xyz = a->xyz;
    pb->facet_count = n; /* points of zero area (duplicates) just carry no weight */
    pb->centroid = a->xyz;
    pb->normal = a->input_normal;
    pb->area = a->area;
    pb->mean_edge_length = r->input_spacing; /* what the report gives as the unit */
    pb->mean_area = area_sum / (double)n;
    rsmooth_status st = rs_problem_apply_params(pb, &r->p, r->unit, r->error, r->where);
    if (st != RSMOOTH_OK)
        return st;
    pb->facet_color = pb->colors ? a->color : NULL;
    pb->progress = NULL;
    pb->progress_cancel = r->reports ? rs_report_pass_progress : NULL;
    pb->progress_user = &r->pp;
    rs_kdtree_free(&r->tree);
    return RSMOOTH_OK;
}

/* After a pass's solve: confident points keep the pass before's result, held points their input
 * position; then this pass's arrays become the next pass's input. */
static void finish_pass(points_run *r, int pass) {
    size_t n = r->n;
    point_arrays *a = &r->a;
    const rsmooth_params *p = &r->p;
    if (pass > 0 && p->pass_confidence > 0) {
        /* confident points keep what the pass before gave them */
        for (size_t v = 0; v < n; v++)
            if (a->prev_confidence[v] >= p->pass_confidence) {
                memcpy(a->next + 3 * v, a->xyz + 3 * v, 3 * sizeof(double));
                memcpy(a->filtered + 3 * v, a->normal + 3 * v, 3 * sizeof(double));
                a->confidence[v] = a->prev_confidence[v];
            }
    }
    for (size_t v = 0; p->move_mask && v < n; v++)
        if (!p->move_mask[v]) /* held still (scaled by a power of two: exact both ways) */
            for (int k = 0; k < 3; k++)
                a->next[3 * v + (size_t)k] =
                    rs_coordinate(r->scalar, r->positions, 3 * v + (size_t)k) * r->scale;
    /* the next pass starts from these positions; its output replaces these normals */
    double *t = a->xyz;
    a->xyz = a->next;
    a->next = t;
    t = a->normal;
    a->normal = a->filtered;
    a->filtered = t;
    float *c = a->prev_confidence;
    a->prev_confidence = a->confidence;
    a->confidence = c;
}

/* One pass: the bilateral filter's solve on the points at the previous pass's positions. */
static rsmooth_status run_pass(points_run *r, int pass) {
    double t_pass = rs_now_ms();
    r->pp.pass = pass;
    if (r->reports && rs_report_pass_progress(&r->pp, 0) != 0)
        return rs_cancelled(r->error, r->where);
    rs_problem pb;
    rsmooth_status st = pass_problem(r, pass, &pb);
    if (st != RSMOOTH_OK)
        return st;
    /* Every pass filters the input's normals (pb.normal), at the pass's positions. A mesh's
     * passes recompute facet normals from the smoother positions; points have no normals but
     * the input's, and filtering the previous pass's output again stacks the rounds, which
     * flattens curved parts into facets (on point clouds of the benchmark models, 2 or 3
     * passes so gave 2-6% lower E_v but 10-30% larger normal errors). The reference solve
     * writes the normals it predicted with; with no facet to weigh, they stay the input's. */
    point_arrays *a = &r->a;
    memcpy(a->filtered, a->input_normal, r->n * 3 * sizeof(double));
    st = r->solve(r->solve_ctx, &pb, a->next, a->confidence, a->filtered,
                  r->report ? &r->one : NULL, t_pass, r->error, r->where);
    if (st != RSMOOTH_OK)
        return st;
    if (r->report) {
        r->one.facet_count = r->weighted_points;
        rs_add_pass_report(&r->sum, &r->one);
    }
    finish_pass(r, pass);
    return RSMOOTH_OK;
}

/* The last pass's positions, normals and confidence into the caller's arrays, and the report. */
static rsmooth_status write_points(points_run *r, void *out_positions, void *out_normals,
                                   float *out_confidence, double t_start) {
    const point_arrays *a = &r->a;
    for (size_t v = 0; v < r->n; v++) {
        rs_store_position(r->scalar, out_positions, v, a->xyz + 3 * v, 1 / r->scale);
        if (out_normals)
            rs_store_position(r->scalar, out_normals, v, a->normal + 3 * v, 1); /* unit vectors */
        if (out_confidence)
            out_confidence[v] = a->prev_confidence[v];
    }
    if (r->report) {
        *r->report = r->sum;
        rs_report_unscale(r->report, 1 / r->scale);
        r->report->ms_total = rs_now_ms() - t_start;
    }
    return rs_check_results(r->scalar, out_positions, NULL, out_confidence, r->n, "point", r->error,
                            r->where);
}

static rsmooth_status smooth_points(rs_points_solve_fn solve, void *solve_ctx, const char *where,
                                    rsmooth_scalar scalar, const void *positions,
                                    const void *normals, size_t point_count,
                                    const double *given_spacing, const rsmooth_params *params,
                                    void *out_positions, void *out_normals, float *out_confidence,
                                    rsmooth_report *report, rsmooth_error *error) {
    double t_start = rs_now_ms();
    rs_error_clear(error);
    points_run r;
    memset(&r, 0, sizeof r);
    r.solve = solve;
    r.solve_ctx = solve_ctx;
    r.where = where;
    r.scalar = scalar;
    r.positions = positions;
    r.normals = normals;
    r.n = point_count;
    r.given_spacing = given_spacing;
    r.scale = 1;
    r.report = report;
    r.error = error;
    rsmooth_status st = check_call(&r, params, out_positions, out_normals, out_confidence);
    if (st != RSMOOTH_OK)
        return st;
    if (!load_points(&r)) {
        st = no_memory(&r);
        goto done;
    }
    if (r.p.mollify) /* the one normal filter points have */
        r.p.normal_filter = RSMOOTH_NORMALS_BILATERAL;
    r.pp = (rs_pass_progress){r.p.progress, r.p.progress_cancel, r.p.progress_user, 0, r.p.passes};
    r.reports = r.p.progress || r.p.progress_cancel;
    for (int pass = 0; pass < r.p.passes && st == RSMOOTH_OK; pass++)
        st = run_pass(&r, pass);
    if (st == RSMOOTH_OK)
        st = write_points(&r, out_positions, out_normals, out_confidence, t_start);
done:
    rs_kdtree_free(&r.tree);
    free_arrays(&r.a);
    rs_release_free_memory();
    return st;
}

rsmooth_status rs_smooth_points_one_part(rs_points_solve_fn solve, void *solve_ctx,
                                         const char *where, rsmooth_scalar scalar,
                                         const void *positions, const void *normals,
                                         size_t point_count, const double *given_spacing,
                                         const rsmooth_params *params, void *out_positions,
                                         void *out_normals, float *out_confidence,
                                         rsmooth_report *report, rsmooth_error *error) {
    size_t caller_size = report ? report->struct_size : 0; /* the report's fillers reset it */
    rsmooth_status st = smooth_points(solve, solve_ctx, where, scalar, positions, normals,
                                      point_count, given_spacing, params, out_positions,
                                      out_normals, out_confidence, report, error);
    if (report)
        report->struct_size = caller_size;
    return st;
}
