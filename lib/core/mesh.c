/* Argument checks and per-facet data (centroid c_q, area a_q, unit normal n_q) shared by both
 * paths. */
#include "core/edge_bucket.h"
#include "core/rsmooth_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

rsmooth_status rs_check_mesh_structure(rsmooth_scalar scalar, const void *positions,
                                       size_t vertex_count, const uint32_t *indices,
                                       size_t triangle_count, rsmooth_error *error,
                                       const char *where) {
    if (scalar != RSMOOTH_FLOAT32 && scalar != RSMOOTH_FLOAT64)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "scalar must be RSMOOTH_FLOAT32 or RSMOOTH_FLOAT64 (got %d)", (int)scalar);
    if (!positions)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "positions is NULL");
    if (vertex_count == 0)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "the mesh has no vertices");
    if (vertex_count > UINT32_MAX)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "vertex count %zu exceeds the 32-bit index range", vertex_count);
    size_t scalar_size = scalar == RSMOOTH_FLOAT32 ? sizeof(float) : sizeof(double);
    if (rs_mul_overflows(vertex_count, 3 * scalar_size))
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "vertex count %zu overflows the size of the position array", vertex_count);
    if (triangle_count > 0 && !indices)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "indices is NULL but triangle count is %zu", triangle_count);
    if (rs_mul_overflows(triangle_count, 3 * sizeof(uint32_t)) || triangle_count > UINT32_MAX)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "triangle count %zu is too large", triangle_count);
    for (size_t i = 0; i < 3 * triangle_count; i++)
        if (indices[i] >= vertex_count)
            return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                           "triangle %zu: index %u >= vertex count %zu", i / 3, indices[i],
                           vertex_count);
    return RSMOOTH_OK;
}

rsmooth_status rs_check_mesh_arrays(rsmooth_scalar scalar, const void *positions,
                                    size_t vertex_count, const uint32_t *indices,
                                    size_t triangle_count, double *magnitude, rsmooth_error *error,
                                    const char *where) {
    rsmooth_status st = rs_check_mesh_structure(scalar, positions, vertex_count, indices,
                                                triangle_count, error, where);
    if (st != RSMOOTH_OK)
        return st;
    return rs_check_coordinates(scalar, positions, vertex_count, "vertex", magnitude, error, where);
}

rsmooth_status rs_check_coordinates(rsmooth_scalar scalar, const void *positions, size_t count,
                                    const char *noun, double *magnitude, rsmooth_error *error,
                                    const char *where) {
    double largest = 0;
    for (size_t i = 0; i < 3 * count; i++) {
        double x = fabs(rs_coordinate(scalar, positions, i));
        if (!(x <= RS_MAX_COORDINATE)) {
            if (!isfinite(x))
                return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                               "%s %zu has a non-finite coordinate", noun, i / 3);
            return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                           "%s %zu has coordinate %.17g beyond the supported magnitude %g", noun,
                           i / 3, rs_coordinate(scalar, positions, i), RS_MAX_COORDINATE);
        }
        largest = x > largest ? x : largest;
    }
    if (magnitude)
        *magnitude = largest;
    return RSMOOTH_OK;
}

rsmooth_status rs_check_colors(const float *colors, size_t vertex_count, rsmooth_error *error,
                               const char *where) {
    for (size_t i = 0; colors && i < 3 * vertex_count; i++)
        if (!isfinite(colors[i]))
            return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                           "vertex %zu has a non-finite colour component (%g)", i / 3,
                           (double)colors[i]);
        else if (fabsf(colors[i]) > (float)RS_MAX_COLOR)
            return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                           "vertex %zu has colour component %.9g beyond the supported magnitude %g",
                           i / 3, (double)colors[i], RS_MAX_COLOR);
    return RSMOOTH_OK;
}

bool rs_mean_edge_length(const double *xyz, size_t vertex_count, const uint32_t *indices,
                         size_t triangle_count, double *out_length) {
    return rs_mean_edge_length_below(xyz, vertex_count, indices, triangle_count, INFINITY,
                                     out_length);
}

bool rs_mean_edge_length_below(const double *xyz, size_t vertex_count, const uint32_t *indices,
                               size_t triangle_count, double limit, double *out_length) {
    /* Unique edges without a global sort: each edge goes to the bucket of its lower vertex (a
     * counting sort, linear time), and duplicates are removed within a bucket (a handful). */
    *out_length = 0;
    size_t *start = rs_calloc_array(vertex_count + 1, sizeof *start);
    uint32_t *upper = rs_alloc_array(triangle_count > 0 ? 3 * triangle_count : 1, sizeof *upper);
    if (!start || !upper) {
        rs_free(start);
        rs_free(upper);
        return false;
    }
    for (size_t t = 0; t < triangle_count; t++)
        for (int e = 0; e < 3; e++) {
            uint32_t a = indices[3 * t + e], b = indices[3 * t + (e + 1) % 3];
            if (a != b) /* a repeated index is no edge */
                start[(a < b ? a : b) + 1]++;
        }
    for (size_t v = 0; v < vertex_count; v++)
        start[v + 1] += start[v];
    for (size_t t = 0; t < triangle_count; t++)
        for (int e = 0; e < 3; e++) {
            uint32_t a = indices[3 * t + e], b = indices[3 * t + (e + 1) % 3];
            if (a != b)
                upper[start[a < b ? a : b]++] = a < b ? b : a;
        }
    for (size_t v = vertex_count; v > 0; v--) /* the fill moved each start to the next's */
        start[v] = start[v - 1];
    start[0] = 0;
    double sum = 0;
    size_t unique = 0;
    for (size_t v = 0; v < vertex_count; v++) {
        uint32_t *bucket = upper + start[v];
        size_t n = start[v + 1] - start[v];
        rs_edge_bucket_order(bucket, n);
        for (size_t i = 0; i < n; i++) {
            if (rs_edge_repeats(bucket, n, i))
                continue;
            double d[3];
            rs_sub3(xyz + 3 * v, xyz + 3 * (size_t)bucket[i], d);
            double length = sqrt(rs_dot3(d, d));
            if (!(length <= limit)) /* out of line: left out of the unit */
                continue;
            sum += length;
            unique++;
        }
    }
    *out_length = unique ? sum / (double)unique : 0;
    rs_free(start);
    rs_free(upper);
    return true;
}

rsmooth_status rs_mesh_mean_edge_length(rsmooth_scalar scalar, const void *positions,
                                        size_t vertex_count, const uint32_t *indices,
                                        size_t triangle_count, double *out_length,
                                        rsmooth_error *error) {
    static const char where[] = "rsmooth_mean_edge_length";
    rs_error_clear(error);
    if (!out_length)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "out_length is NULL");
    rsmooth_status st = rs_check_mesh_structure(scalar, positions, vertex_count, indices,
                                                triangle_count, error, where);
    if (st != RSMOOTH_OK)
        return st;
    return rs_mesh_mean_edge(scalar, positions, vertex_count, indices, triangle_count, out_length,
                             error, where);
}

rsmooth_status rs_mesh_mean_edge(rsmooth_scalar scalar, const void *positions, size_t vertex_count,
                                 const uint32_t *indices, size_t triangle_count, double *out_length,
                                 rsmooth_error *error, const char *where) {
    double magnitude = 0, scale = 1;
    rsmooth_status st =
        rs_check_coordinates(scalar, positions, vertex_count, "vertex", &magnitude, error, where);
    if (st == RSMOOTH_OK)
        st = rs_mesh_scale(scalar, positions, indices, triangle_count, magnitude, &scale, error,
                           where);
    if (st != RSMOOTH_OK)
        return st;
    double *xyz = rs_alloc_array(vertex_count, 3 * sizeof *xyz);
    if (!xyz)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "no memory for positions");
    rs_scale_positions(scalar, positions, vertex_count, scale, xyz);
    bool ok = rs_mean_edge_length(xyz, vertex_count, indices, triangle_count, out_length);
    *out_length /= scale; /* exact: a power of two */
    rs_free(xyz);
    return ok ? RSMOOTH_OK
              : rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "no memory for edges");
}

void rs_problem_free(rs_problem *problem) {
    if (!problem)
        return;
    rs_free(problem->xyz);
    rs_free(problem->facet_triangle);
    rs_free(problem->centroid);
    rs_free(problem->normal);
    rs_free(problem->area);
    rs_free(problem->facet_color);
    memset(problem, 0, sizeof *problem);
}

rsmooth_status rs_check_outputs(rsmooth_scalar scalar, const void *positions, size_t vertex_count,
                                const uint32_t *indices, size_t triangle_count,
                                const rsmooth_params *params, const void *out_positions,
                                const float *out_weight, const float *out_confidence,
                                rsmooth_error *error, const char *where) {
    if (!out_positions)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "out_positions is NULL");
    if (rs_mul_overflows(vertex_count, 3 * sizeof(double)) ||
        rs_mul_overflows(triangle_count, 3 * sizeof(uint32_t)))
        return RSMOOTH_OK; /* no such arrays: the count checks refuse the call */
    size_t xyz = vertex_count * rs_vertex_bytes(scalar);
    size_t per_vertex = vertex_count * sizeof(float);
    const struct {
        const char *name;
        const void *at;
        size_t bytes;
    } in[] = {{"positions", positions, xyz},
              {"indices", indices, triangle_count * 3 * sizeof(uint32_t)},
              {"params->colors", params ? params->colors : NULL, 3 * per_vertex},
              {"params->move_mask", params ? params->move_mask : NULL, vertex_count}},
      out[] = {{"out_positions", out_positions, xyz},
               {"out_weight", out_weight, per_vertex},
               {"out_confidence", out_confidence, per_vertex}};
    const size_t ins = sizeof in / sizeof *in, outs = sizeof out / sizeof *out;
    for (size_t o = 0; o < outs; o++) {
        if (!out[o].at || out[o].bytes == 0)
            continue;
        for (size_t i = 0; i < ins + o; i++) { /* every input, and the outputs before this one */
            const char *name = i < ins ? in[i].name : out[i - ins].name;
            const void *at = i < ins ? in[i].at : out[i - ins].at;
            size_t bytes = i < ins ? in[i].bytes : out[i - ins].bytes;
            if (rs_ranges_overlap(out[o].at, out[o].bytes, at, bytes))
                return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                               "%s overlaps %s: smoothing reads every input while writing, and "
                               "each output needs its own memory",
                               out[o].name, name);
        }
    }
    return RSMOOTH_OK;
}

/* Triangles per block of the facet loops (and elements per chunk below which a loop is not worth
 * a thread). */
#define GEOMETRY_BLOCK 8192

typedef struct geometry_job {
    rs_problem *problem;
    rsmooth_scalar scalar;
    const void *positions;
    const uint32_t *indices;
    bool keep;
    size_t triangle_count;
    uint8_t *valid;   /* per triangle: non-zero area */
    size_t *count;    /* per block of GEOMETRY_BLOCK triangles: its facets, then their start */
    double *area_sum; /* per block */
} geometry_job;

static void convert_positions(void *ctx, size_t begin, size_t end, size_t chunk) {
    const geometry_job *job = ctx;
    (void)chunk;
    const double scale = job->problem->scale;
    for (size_t i = 3 * begin; i < 3 * end; i++)
        job->problem->xyz[i] = rs_coordinate(job->scalar, job->positions, i) * scale;
}

/* First pass, over blocks [begin, end): which triangles are facets, how many per block, their
 * area. Blocks have a fixed size, so the area sum (and the mean area every weight is scaled by)
 * does not depend on the thread count. */
static void find_facets(void *ctx, size_t begin, size_t end, size_t chunk) {
    const geometry_job *job = ctx;
    (void)chunk;
    for (size_t b = begin; b < end; b++) {
        size_t n = 0, last = (b + 1) * GEOMETRY_BLOCK;
        double sum = 0;
        for (size_t t = b * GEOMETRY_BLOCK; t < last && t < job->triangle_count; t++) {
            double normal[3], area = 0; /* (the centroid waits for the facets kept) */
            job->valid[t] =
                rs_triangle_normal(job->problem->xyz, job->indices + 3 * t, normal, &area);
            if (job->valid[t]) {
                n++;
                sum += area;
            }
        }
        job->count[b] = n;
        job->area_sum[b] = sum;
    }
}

/* Second pass: each block writes its facets from where the blocks before it end. */
static void store_facets(void *ctx, size_t begin, size_t end, size_t chunk) {
    const geometry_job *job = ctx;
    rs_problem *pb = job->problem;
    (void)chunk;
    for (size_t b = begin; b < end; b++) {
        size_t f = job->count[b], last = (b + 1) * GEOMETRY_BLOCK;
        for (size_t t = b * GEOMETRY_BLOCK; t < last && t < job->triangle_count; t++) {
            if (!job->valid[t])
                continue;
            pb->facet_triangle[f] = (uint32_t)t;
            if (job->keep)
                rs_triangle_geometry(pb->xyz, job->indices + 3 * t, pb->centroid + 3 * f,
                                     pb->normal + 3 * f, &pb->area[f]);
            f++;
        }
    }
}

const char rs_unchecked_output[1];

/* Whether `scale` is a power of two that keeps coordinates up to `magnitude` below 2^500. */
static bool usable_scale(double scale, double magnitude) {
    int e = 0;
    return scale > 0 && isfinite(scale) && frexp(scale, &e) == 0.5 &&
           magnitude * scale < ldexp(1.0, 500);
}

/* rs_problem_prepare and _within: with `checked`, the caller has checked the arrays, outputs and
 * colours (rs_filter_passes, at the call's entry), and only the coordinates' magnitude is read. */
static rsmooth_status problem_prepare(rs_problem *problem, rsmooth_scalar scalar,
                                      const void *positions, size_t vertex_count,
                                      const uint32_t *indices, size_t triangle_count,
                                      const rsmooth_params *params, const void *out_positions,
                                      bool keep_facet_data, const rsmooth_piece_info *whole,
                                      bool checked, rsmooth_error *error, const char *where) {
    memset(problem, 0, sizeof *problem);
    rsmooth_params p;
    rsmooth_status st = rs_params_resolve(params, &p, error, where);
    if (st != RSMOOTH_OK)
        return st;
    double magnitude = 0;
    if (checked)
        st = rs_check_coordinates(scalar, positions, vertex_count, "vertex", &magnitude, error,
                                  where);
    else
        st = rs_check_mesh_arrays(scalar, positions, vertex_count, indices, triangle_count,
                                  &magnitude, error, where);
    if (st == RSMOOTH_OK && !checked && out_positions != RS_UNCHECKED_OUTPUT)
        st = rs_check_outputs(scalar, positions, vertex_count, indices, triangle_count, &p,
                              out_positions, NULL, NULL, error, where);
    if (st == RSMOOTH_OK && !checked)
        st = rs_check_colors(p.colors, vertex_count, error, where);
    if (st != RSMOOTH_OK)
        return st;
    double scale = whole ? whole->scale : 0;
    if (!usable_scale(scale, magnitude))
        st = rs_mesh_scale(scalar, positions, indices, triangle_count, magnitude, &scale, error,
                           where);
    if (st != RSMOOTH_OK)
        return st;

    problem->scale = scale;
    problem->vertex_count = vertex_count;
    problem->indices = indices;
    problem->triangle_count = triangle_count;
    problem->xyz = rs_alloc_array(vertex_count, 3 * sizeof(double));
    problem->facet_triangle = rs_alloc_array(triangle_count, sizeof(uint32_t));
    if (keep_facet_data) {
        problem->centroid = rs_alloc_array(triangle_count, 3 * sizeof(double));
        problem->normal = rs_alloc_array(triangle_count, 3 * sizeof(double));
        problem->area = rs_alloc_array(triangle_count, sizeof(double));
    }
    if (!problem->xyz || !problem->facet_triangle ||
        (keep_facet_data && (!problem->centroid || !problem->normal || !problem->area))) {
        rs_problem_free(problem);
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "no memory for facet data");
    }
    size_t blocks = (triangle_count + GEOMETRY_BLOCK - 1) / GEOMETRY_BLOCK;
    geometry_job job = {problem,        scalar, positions, indices, keep_facet_data,
                        triangle_count, NULL,   NULL,      NULL};
    job.valid = rs_alloc_array(triangle_count, 1);
    job.count = rs_calloc_array(blocks, sizeof *job.count);
    job.area_sum = rs_calloc_array(blocks, sizeof *job.area_sum);
    if (!job.valid || !job.count || !job.area_sum) {
        rs_free(job.valid);
        rs_free(job.count);
        rs_free(job.area_sum);
        rs_problem_free(problem);
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "no memory for facet data");
    }
    rs_parallel_for(vertex_count, GEOMETRY_BLOCK, convert_positions, &job);
    rs_parallel_for(blocks, 1, find_facets, &job);
    size_t f = 0; /* block b's facets start at the sum of the counts before it */
    double area_sum = 0;
    for (size_t b = 0; b < blocks; b++) {
        size_t n = job.count[b];
        job.count[b] = f;
        f += n;
        area_sum += job.area_sum[b];
    }
    rs_parallel_for(blocks, 1, store_facets, &job);
    rs_free(job.valid);
    rs_free(job.count);
    rs_free(job.area_sum);
    problem->facet_count = f;
    problem->mean_area = f ? area_sum / (double)f : 0;

    if (whole) { /* a power of two: the products are exact, as the whole run's own are */
        problem->mean_edge_length = whole->mean_edge_length * scale;
        problem->mean_area = whole->mean_area * scale * scale;
    } else if (!rs_mean_edge_length(problem->xyz, vertex_count, indices, triangle_count,
                                    &problem->mean_edge_length)) {
        rs_problem_free(problem);
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "no memory for edges");
    }
    rsmooth_status applied = rs_problem_apply_params(
        problem, &p, p.absolute ? scale : problem->mean_edge_length, error, where);
    if (applied != RSMOOTH_OK) {
        rs_problem_free(problem);
        return applied;
    }
    if (keep_facet_data && problem->colors && problem->facet_count > 0) {
        problem->facet_color = rs_alloc_array(problem->facet_count, 3 * sizeof(double));
        if (!problem->facet_color) {
            rs_problem_free(problem);
            return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "no memory for colours");
        }
        for (size_t q = 0; q < problem->facet_count; q++)
            rs_triangle_color(problem->colors, indices + 3 * (size_t)problem->facet_triangle[q],
                              problem->facet_color + 3 * q);
    }
    return RSMOOTH_OK;
}

rsmooth_status rs_problem_prepare(rs_problem *problem, rsmooth_scalar scalar, const void *positions,
                                  size_t vertex_count, const uint32_t *indices,
                                  size_t triangle_count, const rsmooth_params *params,
                                  bool keep_facet_data, rsmooth_error *error, const char *where) {
    return problem_prepare(problem, scalar, positions, vertex_count, indices, triangle_count,
                           params, RS_UNCHECKED_OUTPUT, keep_facet_data, NULL, true, error, where);
}

rsmooth_status rs_problem_prepare_within(rs_problem *problem, rsmooth_scalar scalar,
                                         const void *positions, size_t vertex_count,
                                         const uint32_t *indices, size_t triangle_count,
                                         const rsmooth_params *params, const void *out_positions,
                                         bool keep_facet_data, const rsmooth_piece_info *whole,
                                         rsmooth_error *error, const char *where) {
    return problem_prepare(problem, scalar, positions, vertex_count, indices, triangle_count,
                           params, out_positions, keep_facet_data, whole, false, error, where);
}

rsmooth_status rs_problem_apply_params(rs_problem *problem, const rsmooth_params *p, double unit,
                                       rsmooth_error *error, const char *where) {
    problem->sigma_f = p->sigma_f * unit;
    problem->sigma_g = isinf(p->sigma_g) ? INFINITY : p->sigma_g * unit;
    problem->sigma_m = problem->sigma_f / 2;
    problem->radius = p->cutoff * problem->sigma_f;
    problem->mollify_radius =
        (p->mollify_cutoff > 0 ? p->mollify_cutoff : p->cutoff) * problem->sigma_f;
    problem->predict_centroid = p->predictor == RSMOOTH_PREDICT_CENTROID;
    problem->mollify = p->mollify != 0 && !problem->predict_centroid;
    problem->bilateral = problem->mollify && p->normal_filter == RSMOOTH_NORMALS_BILATERAL;
    problem->normal_sigma_s = p->normal_sigma_s * unit;
    problem->normal_sigma_n = p->normal_sigma_n;
    problem->normal_radius = problem->bilateral ? p->cutoff * problem->normal_sigma_s : 0;
    problem->normal_iterations = p->normal_iterations;
    problem->influence = isinf(problem->sigma_g) ? RSMOOTH_INFLUENCE_GAUSSIAN : p->influence;
    problem->colors = isinf(p->sigma_c) ? NULL : p->colors; /* +INFINITY: the factor is 1 */
    problem->sigma_c = p->sigma_c;
    problem->progress = p->progress;
    problem->progress_cancel = p->progress_cancel;
    problem->progress_user = p->progress_user;
    if (unit > 0 && (!isfinite(problem->radius) || !isfinite(problem->mollify_radius) ||
                     !isfinite(problem->normal_radius) ||
                     (isfinite(p->sigma_g) && !isfinite(problem->sigma_g))))
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "sigma_f %g, sigma_g %g or normal_sigma_s %g (%s) with cutoff %g: the "
                       "reach exceeds the range of numbers on this mesh",
                       p->sigma_f, p->sigma_g, p->normal_sigma_s,
                       p->absolute ? "absolute" : "mean edge lengths", p->cutoff);
    if (!(problem->sigma_f > 0))
        problem->facet_count = 0; /* no edge of non-zero length: nothing can move */
    return RSMOOTH_OK;
}
