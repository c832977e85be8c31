/* What a filter call writes: positions back in the caller's type and units, and the last check
 * before RSMOOTH_OK that none of it is NaN, infinite or out of range. A call never returns success
 * with a non-finite output, whatever went wrong inside. */
#include "core/rsmooth_internal.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

void rs_store_position(rsmooth_scalar scalar, void *out_positions, size_t v, const double p[3],
                       double unscale) {
    for (int c = 0; c < 3; c++) {
        double x = p[c] * unscale; /* exact: a power of two */
        if (scalar == RSMOOTH_FLOAT32)
            ((float *)out_positions)[3 * v + c] = (float)x;
        else
            ((double *)out_positions)[3 * v + c] = x;
    }
}

void rs_store_unmoved(const rs_problem *problem, size_t count, rsmooth_scalar scalar,
                      void *out_positions, float *out_weight, float *out_confidence) {
    for (size_t v = 0; v < count; v++) {
        rs_store_position(scalar, out_positions, v, problem->xyz + 3 * v, 1 / problem->scale);
        if (out_weight)
            out_weight[v] = 0;
        if (out_confidence)
            out_confidence[v] = 0;
    }
}

float rs_weight_value(double k, double unscale) {
    double w = k * unscale * unscale; /* areas: the scale squared */
    if (!(w <= FLT_MAX))
        return NAN; /* rs_check_results reports it (a tiny k rounds to 0, as floats do) */
    return (float)w;
}

rsmooth_status rs_check_results(rsmooth_scalar scalar, const void *out_positions,
                                const float *out_weight, const float *out_confidence, size_t count,
                                const char *noun, rsmooth_error *error, const char *where) {
    for (size_t i = 0; i < 3 * count; i++) {
        double x = rs_coordinate(scalar, out_positions, i);
        if (!isfinite(x))
            return rs_fail(error, RSMOOTH_ERROR_NUMERICAL, where,
                           "the result for %s %zu is not finite%s", noun, i / 3,
                           scalar == RSMOOTH_FLOAT32 && !isnan(x)
                               ? " in float32 (beyond FLT_MAX): pass float64 positions"
                               : "");
        if (fabs(x) > RS_MAX_COORDINATE)
            return rs_fail(error, RSMOOTH_ERROR_NUMERICAL, where,
                           "the result for %s %zu has coordinate %.17g beyond the supported "
                           "magnitude %g",
                           noun, i / 3, x, RS_MAX_COORDINATE);
    }
    for (size_t v = 0; out_weight && v < count; v++)
        if (!isfinite(out_weight[v]) || out_weight[v] < 0)
            return rs_fail(error, RSMOOTH_ERROR_NUMERICAL, where,
                           "the weight k(p) of %s %zu does not fit a float: this mesh's areas "
                           "are beyond float32's range; pass out_weight = NULL (the confidence "
                           "is scale-free)",
                           noun, v);
    for (size_t v = 0; out_confidence && v < count; v++)
        if (!(out_confidence[v] >= 0 && out_confidence[v] <= 1))
            return rs_fail(error, RSMOOTH_ERROR_NUMERICAL, where,
                           "the confidence of %s %zu (%g) is not in [0, 1]", noun, v,
                           (double)out_confidence[v]);
    return RSMOOTH_OK;
}

void rs_report_init(rsmooth_report *report) {
    if (!report)
        return;
    memset(report, 0, sizeof *report);
    report->struct_size = sizeof *report;
}

void rs_report_problem(rsmooth_report *report, const rs_problem *problem, size_t cell_count,
                       const char *device) {
    memset(report, 0, sizeof *report);
    report->vertex_count = problem->vertex_count;
    report->triangle_count = problem->triangle_count;
    report->facet_count = problem->facet_count;
    report->mean_edge_length = problem->mean_edge_length;
    report->sigma_f = problem->sigma_f;
    report->sigma_g = problem->sigma_g;
    report->radius = problem->radius;
    report->mollify_radius = problem->bilateral ? problem->normal_radius
                             : problem->mollify ? problem->mollify_radius
                                                : 0;
    rs_report_unscale(report, 1 / problem->scale);
    report->grid_cell_count = cell_count;
    snprintf(report->device, sizeof report->device, "%s", device);
}

void rs_report_unscale(rsmooth_report *report, double unscale) {
    report->mean_edge_length *= unscale; /* exact: a power of two */
    report->sigma_f *= unscale;
    report->sigma_g *= unscale;
    report->radius *= unscale;
    report->mollify_radius *= unscale;
}

void rs_give_report(rsmooth_report *report, size_t struct_size, const rsmooth_report *full) {
    /* the sizes rsmooth_report had: 0.5's (up to tiles), 0.6's (discrepancy_iterations), this */
    size_t v05 = offsetof(rsmooth_report, discrepancy_iterations);
    size_t v06 = offsetof(rsmooth_report, region_filter_share);
    size_t n = struct_size == v05 || struct_size == v06 ? struct_size : sizeof *full;
    memcpy(report, full, n);
    report->struct_size = struct_size;
}

void rs_add_report_times(rsmooth_report *to, const rsmooth_report *from) {
    to->ms_setup += from->ms_setup;
    to->ms_facets += from->ms_facets;
    to->ms_grid += from->ms_grid;
    to->ms_upload += from->ms_upload;
    to->ms_mollify += from->ms_mollify;
    to->ms_normals += from->ms_normals;
    to->ms_robust += from->ms_robust;
    to->ms_download += from->ms_download;
    to->pairs_mollify += from->pairs_mollify;
    to->pairs_robust += from->pairs_robust;
    to->tiles = from->tiles > to->tiles ? from->tiles : to->tiles;
}

/* `from`'s times and work added to `to`'s: a part's facets, cells and stage are its own. */
static void add_work(rsmooth_report *to, const rsmooth_report *from) {
    rs_add_report_times(to, from);
    to->facet_count += from->facet_count;
    to->grid_cell_count += from->grid_cell_count;
    to->ms_total += from->ms_total;
    to->ms_stage += from->ms_stage;
    to->ms_stage_cycles += from->ms_stage_cycles;
}

void rs_add_part_report(rsmooth_report *sum, const rsmooth_report *part, bool largest, bool first) {
    if (first) {
        *sum = *part;
    } else if (largest) {
        rsmooth_report others = *sum;
        *sum = *part;
        add_work(sum, &others);
    } else {
        add_work(sum, part);
    }
}

bool rs_read_sized(const void *given, void *out, size_t full) {
    memset(out, 0, full);
    if (!given)
        return true;
    size_t size = 0; /* the caller's struct_size: the first field of every such struct */
    memcpy(&size, given, sizeof size);
    if (size == 0)
        size = full;
    if (size < sizeof size)
        return false;
    memcpy(out, given, size < full ? size : full);
    memcpy(out, &full, sizeof full); /* the copy is whole */
    return true;
}

rsmooth_status rs_read_outputs(const rsmooth_outputs *given, rsmooth_outputs *out,
                               rsmooth_error *error, const char *where) {
    if (!rs_read_sized(given, out, sizeof *out))
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "outputs->struct_size is %zu: set it to sizeof(rsmooth_outputs)",
                       given->struct_size);
    return RSMOOTH_OK;
}
