/* Pieces of a larger mesh: the filter on a few of its vertices, with the whole mesh's figures.
 *
 * The filter reads the whole mesh in two numbers only: the mean edge length (the unit of the
 * sigmas) and the mean facet area (the scale of every area weight). Everything else is local:
 * vertex p moves by the facets whose centroids lie within the halo of rsmooth_piece_halo. So a
 * piece holding its core vertices and every facet within that halo, given the two numbers,
 * computes its core vertices as the whole run would. This is what streaming (rsmooth_io's
 * rsmooth_stream_smooth) and the MPI driver cut a mesh into. */
#include "api/path.h"
#include "reference/reference.h"

#include <float.h>
#include <math.h>
#include <string.h>

static const char where[] = "rsmooth_smooth_piece";

/* A piece's typical edge in internal units lies in [2^PIECE_EDGE_MIN_LOG2, 2^PIECE_EDGE_MAX_LOG2):
 * its fourth power (in a facet's normal) is then a double, neither 0 nor infinite. scale.c puts
 * a whole mesh's within [2^-251, 1); a piece's may be somewhat shorter or longer. */
#define PIECE_EDGE_MIN_LOG2 (-256)
#define PIECE_EDGE_MAX_LOG2 250

rsmooth_status rsmooth_piece_info_init(rsmooth_piece_info *info) {
    if (!info)
        return RSMOOTH_ERROR_INVALID_ARGUMENT;
    memset(info, 0, sizeof *info);
    info->struct_size = sizeof *info;
    return RSMOOTH_OK;
}

/* The params a piece can honour: one pass of the filter, nothing that reads the whole mesh. */
static rsmooth_status check_piece_params(const rsmooth_params *params, rsmooth_params *p,
                                         rsmooth_error *error, const char *caller) {
    rsmooth_status st = rs_params_resolve(params, p, error, caller);
    if (st != RSMOOTH_OK)
        return st;
    const char *field = p->passes != 1             ? "passes (other than 1)"
                        : p->vertex_updates != 0   ? "vertex_updates (the normal update stage)"
                        : p->colors                ? "colors"
                        : p->move_mask             ? "move_mask"
                        : p->discrepancy_level > 0 ? "discrepancy_level"
                                                   : NULL;
    if (field)
        return rs_fail(error, RSMOOTH_ERROR_UNSUPPORTED, caller,
                       "%s: a piece is filtered in one pass from local data only", field);
    return RSMOOTH_OK;
}

rsmooth_status rsmooth_piece_halo(const rsmooth_params *params, double mean_edge_length,
                                  double reach, double *out_halo, rsmooth_error *error) {
    static const char caller[] = "rsmooth_piece_halo";
    rs_error_clear(error);
    if (!out_halo)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, caller, "out_halo is NULL");
    if (!(mean_edge_length >= 0) || !isfinite(mean_edge_length) || !(reach >= 0) ||
        !isfinite(reach))
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, caller,
                       "mean_edge_length %g and reach %g must be finite and >= 0", mean_edge_length,
                       reach);
    rsmooth_params p;
    rsmooth_status st = check_piece_params(params, &p, error, caller);
    if (st != RSMOOTH_OK)
        return st;
    rs_problem pb;
    memset(&pb, 0, sizeof pb);
    st = rs_problem_apply_params(&pb, &p, p.absolute ? 1 : mean_edge_length, error, caller);
    if (st != RSMOOTH_OK)
        return st;
    double halo = rs_halo_radius(&pb, reach);
    if (!isfinite(halo)) /* a piece cut with it would hold the whole mesh, or nothing */
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, caller,
                       "mean_edge_length %g and reach %g give a halo of %g: beyond double range",
                       mean_edge_length, reach, halo);
    *out_halo = halo;
    return RSMOOTH_OK;
}

/* The first published rsmooth_piece_info (0.7): a caller built against it stays valid, the fields
 * added since at their defaults. */
#define PIECE_INFO_V0_SIZE (offsetof(rsmooth_piece_info, scale) + sizeof(double))

/* The caller's record as this version has it, the fields its struct_size leaves out at 0. */
static rsmooth_status read_info(const rsmooth_piece_info *info, rsmooth_piece_info *full,
                                rsmooth_error *error) {
    if (!info)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "info is NULL");
    if (info->struct_size < PIECE_INFO_V0_SIZE)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "info->struct_size %zu: call rsmooth_piece_info_init first",
                       info->struct_size);
    rsmooth_piece_info_init(full);
    memcpy(full, info, info->struct_size < sizeof *full ? info->struct_size : sizeof *full);
    full->struct_size = sizeof *full;
    return RSMOOTH_OK;
}

/* The fields a caller sets, before anything is read: the whole mesh's figures as the in-memory
 * path has them (positive wherever a mesh has a facet) and a scale it can choose (scale.c). */
static rsmooth_status check_info(const rsmooth_piece_info *info, size_t vertex_count,
                                 rsmooth_error *error) {
    if (info->keep_memory != 0 && info->keep_memory != 1)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "info->keep_memory must be 0 or 1 (got %d)", info->keep_memory);
    if (info->core_count > vertex_count)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "info->core_count %zu exceeds the piece's %zu vertices", info->core_count,
                       vertex_count);
    if (!(info->mean_edge_length > 0) || !isfinite(info->mean_edge_length))
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "info->mean_edge_length %g must be finite and > 0", info->mean_edge_length);
    if (!(info->mean_area > 0) || !isfinite(info->mean_area))
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "info->mean_area %g must be finite and > 0", info->mean_area);
    /* No mesh has a mean area beyond this many squared mean edge lengths: a triangle holds at
     * most sqrt(3)/36 of its perimeter squared, a perimeter is at most the sum of the mesh's
     * edges (3T of them, each shared by at most T triangles), so the mean area is under
     * T^4 * mean edge^2 with T < 2^64 triangles. Beyond it the figures are not a mesh's. */
    if (info->mean_area > ldexp(info->mean_edge_length * info->mean_edge_length, 260))
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "info->mean_area %g is more than any mesh of mean edge length %g can have "
                       "(2^260 times its square)",
                       info->mean_area, info->mean_edge_length);
    if (info->scale != 0 && !rs_scale_possible(info->scale))
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "info->scale %g: neither 0 nor a power of two in [2^-500, 2^1000], the "
                       "scales a whole mesh is given (0: the piece chooses)",
                       info->scale);
    return RSMOOTH_OK;
}

/* In internal units (the figures times the scale) a power of two converts them exactly only
 * while they stay normal doubles. */
static bool exact_in_internal_units(double figure) {
    return isfinite(figure) && figure >= DBL_MIN;
}

/* The scale given, applied to this piece: its figures and its typical edge must stay where the
 * whole mesh's own scale keeps a mesh's (scale.c: typical edges in [2^-251, 1)), else the facets'
 * normals and areas (edge lengths to the fourth power) over- or underflow and every result is
 * off. A wrong scale is the caller's error; the whole mesh's never trips this. */
static rsmooth_status check_scale_fits(const rs_problem *pb, const double *positions,
                                       const uint32_t *indices, size_t triangle_count,
                                       const rsmooth_piece_info *info, rsmooth_error *error) {
    if (!exact_in_internal_units(pb->mean_edge_length) || !exact_in_internal_units(pb->mean_area))
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "info->mean_edge_length %g and info->mean_area %g at scale %g are %g and "
                       "%g internal units, beyond double's normal range: give positions times "
                       "the scale, the figures likewise, and scale 1",
                       info->mean_edge_length, info->mean_area, pb->scale, pb->mean_edge_length,
                       pb->mean_area);
    if (info->scale == 0 || pb->scale != info->scale)
        return RSMOOTH_OK; /* the piece's own choice */
    double typical = rs_typical_edge(RSMOOTH_FLOAT64, positions, indices, triangle_count);
    int e = 0; /* typical * scale in [2^(e-1), 2^e) */
    if (typical > 0)
        frexp(typical * info->scale, &e);
    if (typical > 0 && (e - 1 < PIECE_EDGE_MIN_LOG2 || e - 1 >= PIECE_EDGE_MAX_LOG2))
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "info->scale %g puts the piece's typical edge (%g) at 2^%d internal "
                       "units, where its facets' areas over- or underflow: not the whole mesh's "
                       "scale (which keeps typical edges near 1; 0: the piece chooses)",
                       info->scale, typical, e - 1);
    return RSMOOTH_OK;
}

/* The piece's problem with the whole mesh's scale, unit and mean area in place of its own. */
static rsmooth_status prepare_piece(rs_problem *pb, const double *positions, size_t vertex_count,
                                    const uint32_t *indices, size_t triangle_count,
                                    const rsmooth_piece_info *info, const rsmooth_params *params,
                                    double *out_positions, const rsmooth_outputs *o, bool keep,
                                    rsmooth_error *error) {
    rsmooth_params p;
    rsmooth_status st = check_piece_params(params, &p, error, where);
    if (st != RSMOOTH_OK)
        return st;
    if (!out_positions)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "out_positions is NULL");
    size_t out_bytes = info->core_count * 3 * sizeof(double);
    size_t in_bytes = rs_mul_overflows(vertex_count, 3 * sizeof(double))
                          ? SIZE_MAX
                          : vertex_count * 3 * sizeof(double);
    size_t index_bytes = rs_mul_overflows(triangle_count, 3 * sizeof(uint32_t))
                             ? SIZE_MAX
                             : triangle_count * 3 * sizeof(uint32_t);
    size_t per_vertex = info->core_count * sizeof(float);
    /* every output apart from every other and from the inputs */
    const void *outs[3] = {out_positions, o->weight, o->confidence};
    size_t out_sizes[3] = {out_bytes, per_vertex, per_vertex};
    for (int a = 0; a < 3; a++) {
        bool overlap = in_bytes != SIZE_MAX && index_bytes != SIZE_MAX &&
                       (rs_ranges_overlap(outs[a], out_sizes[a], positions, in_bytes) ||
                        rs_ranges_overlap(outs[a], out_sizes[a], indices, index_bytes));
        for (int b = a + 1; b < 3; b++)
            overlap = overlap || rs_ranges_overlap(outs[a], out_sizes[a], outs[b], out_sizes[b]);
        if (overlap)
            return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                           "%s overlaps another output or the piece's positions or indices",
                           a == 0   ? "out_positions"
                           : a == 1 ? "outputs->weight"
                                    : "outputs->confidence");
    }
    st = rs_problem_prepare_within(pb, RSMOOTH_FLOAT64, positions, vertex_count, indices,
                                   triangle_count, &p, RS_UNCHECKED_OUTPUT, keep, info, error,
                                   where);
    if (st == RSMOOTH_OK)
        st = check_scale_fits(pb, positions, indices, triangle_count, info, error);
    return st;
}

/* The reference path on the whole piece, its core vertices kept. */
static rsmooth_status solve_reference(const rs_problem *pb, size_t core, double *out,
                                      const rsmooth_outputs *o, double t_start,
                                      rsmooth_error *error) {
    size_t n = pb->vertex_count;
    double *all = rs_alloc_array(n, 3 * sizeof *all);
    float *weight = o->weight ? rs_alloc_array(n, sizeof *weight) : NULL;
    float *confidence = o->confidence ? rs_alloc_array(n, sizeof *confidence) : NULL;
    rsmooth_status st = RSMOOTH_OK;
    if (!all || (o->weight && !weight) || (o->confidence && !confidence))
        st = rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "no memory for the piece");
    if (st == RSMOOTH_OK)
        st = rs_reference_solve(pb, RSMOOTH_FLOAT64, all, weight, confidence, NULL, o->report,
                                t_start, error, where);
    if (st == RSMOOTH_OK) {
        memcpy(out, all, core * 3 * sizeof *out);
        if (weight)
            memcpy(o->weight, weight, core * sizeof *weight);
        if (confidence)
            memcpy(o->confidence, confidence, core * sizeof *confidence);
    }
    rs_free(all);
    rs_free(weight);
    rs_free(confidence);
    return st;
}

rsmooth_status rsmooth_smooth_piece(rsmooth_context *ctx, const double *positions,
                                    size_t vertex_count, const uint32_t *indices,
                                    size_t triangle_count, const rsmooth_piece_info *caller_info,
                                    const rsmooth_params *params, double *out_positions,
                                    const rsmooth_outputs *outputs, rsmooth_error *error) {
    double t_start = rs_now_ms();
    rs_error_clear(error);
    rs_problem pb; /* freed on every path: empty until prepare_piece fills it */
    memset(&pb, 0, sizeof pb);
    rsmooth_piece_info full;
    const rsmooth_piece_info *info = &full;
    rsmooth_outputs o;
    rsmooth_status st = rs_read_outputs(outputs, &o, error, where);
    if (st == RSMOOTH_OK)
        st = read_info(caller_info, &full, error);
    if (st == RSMOOTH_OK)
        st = check_info(info, vertex_count, error);
    if (st != RSMOOTH_OK)
        return st;
    if (ctx) {
        size_t saved = 0;
        st = rs_device_enter(ctx, where, &saved, error);
        if (st != RSMOOTH_OK)
            return st;
        st = prepare_piece(&pb, positions, vertex_count, indices, triangle_count, info, params,
                           out_positions, &o, false, error);
        rs_device_call call = {ctx, where, NULL};
        rs_result_sink sink = {RSMOOTH_FLOAT64,  out_positions, o.weight, o.confidence, NULL,
                               info->core_count, NULL};
        if (st == RSMOOTH_OK && info->core_count > 0)
            st = rs_device_pass(&call, &pb, &sink, false, NULL, o.report, t_start, error);
        rs_device_leave(ctx, saved);
    } else {
        st = prepare_piece(&pb, positions, vertex_count, indices, triangle_count, info, params,
                           out_positions, &o, true, error);
        if (st == RSMOOTH_OK)
            st = solve_reference(&pb, info->core_count, out_positions, &o, t_start, error);
    }
    if (st == RSMOOTH_OK)
        st = rs_check_results(RSMOOTH_FLOAT64, out_positions, o.weight, o.confidence,
                              info->core_count, "vertex", error, where);
    rs_problem_free(&pb);
    if (!info->keep_memory)
        rs_release_free_memory();
    return st;
}
