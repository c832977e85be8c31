/* The OpenCL path: host-side facet data and grid, upload, mollify -> normals -> robust kernels,
 * download and scatter back to the caller's vertex order. Coordinates travel as float32 in units of
 * the cell size, relative to their own cell's corner (see kernels/common.cl), so precision does not
 * depend on where the mesh sits; displacements return to double before they are added. */
#include "rsmooth_internal.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* Vertices clamped far outside the grid have no neighbours; keep their floats finite anyway. */
#define LOCAL_CLAMP 1e6

typedef struct packed {
    cl_float4 *facet_centroid, *facet_normal, *facet_edge1, *facet_edge2;
    cl_uint4 *facet_vertices;
    cl_float4 *vertex_local;
    cl_int4 *vertex_cell;
    uint32_t *order; /* grid position -> caller's vertex index */
    uint32_t *rank;  /* caller's vertex index -> grid position */
    double mean_area;
} packed;

static void packed_free(packed *pk) {
    rs_free(pk->facet_centroid);
    rs_free(pk->facet_normal);
    rs_free(pk->facet_edge1);
    rs_free(pk->facet_edge2);
    rs_free(pk->facet_vertices);
    rs_free(pk->vertex_local);
    rs_free(pk->vertex_cell);
    rs_free(pk->order);
    rs_free(pk->rank);
}

static cl_float4 local_point(const rs_grid *grid, const double p[3], const int32_t cell[3]) {
    cl_float4 out;
    for (int k = 0; k < 3; k++) {
        double corner = grid->origin[k] + (double)cell[k] * grid->cell_size;
        double x = (p[k] - corner) / grid->cell_size;
        out.s[k] = (float)(x < -LOCAL_CLAMP ? -LOCAL_CLAMP : x > LOCAL_CLAMP ? LOCAL_CLAMP : x);
    }
    out.s[3] = 0;
    return out;
}

static rsmooth_status pack(const rs_problem *pb, const rs_grid *grid, packed *pk,
                           rsmooth_error *error) {
    size_t nf = pb->facet_count, nv = pb->vertex_count;
    memset(pk, 0, sizeof *pk);
    pk->facet_centroid = rs_alloc_array(nf, sizeof(cl_float4));
    pk->facet_normal = rs_alloc_array(nf, sizeof(cl_float4));
    pk->facet_edge1 = rs_alloc_array(nf, sizeof(cl_float4));
    pk->facet_edge2 = rs_alloc_array(nf, sizeof(cl_float4));
    pk->facet_vertices = rs_alloc_array(nf, sizeof(cl_uint4));
    pk->vertex_local = rs_alloc_array(nv, sizeof(cl_float4));
    pk->vertex_cell = rs_alloc_array(nv, sizeof(cl_int4));
    pk->order = rs_alloc_array(nv, sizeof(uint32_t));
    pk->rank = rs_alloc_array(nv, sizeof(uint32_t));
    if (!pk->facet_centroid || !pk->facet_normal || !pk->facet_edge1 || !pk->facet_edge2 ||
        !pk->facet_vertices || !pk->vertex_local || !pk->vertex_cell || !pk->order || !pk->rank)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, "rsmooth_smooth",
                       "no memory for device staging arrays");

    rsmooth_status st = rs_grid_order_points(grid, pb->xyz, nv, pk->order, error);
    if (st != RSMOOTH_OK)
        return st;
    for (size_t i = 0; i < nv; i++) {
        uint32_t v = pk->order[i];
        pk->rank[v] = (uint32_t)i;
        int32_t cell[3];
        rs_grid_cell_of(grid, pb->xyz + 3 * (size_t)v, cell);
        pk->vertex_local[i] = local_point(grid, pb->xyz + 3 * (size_t)v, cell);
        pk->vertex_cell[i] = (cl_int4){{cell[0], cell[1], cell[2], 0}};
    }

    double area_sum = 0;
    for (size_t q = 0; q < nf; q++)
        area_sum += pb->area[q];
    pk->mean_area = area_sum / (double)nf;
    const double inv_h = 1 / grid->cell_size;
    for (size_t c = 0; c < grid->cell_count; c++) {
        const int32_t *cell = grid->cell_coord + 4 * c;
        for (uint32_t j = grid->cell_start[c]; j < grid->cell_start[c + 1]; j++) {
            uint32_t q = grid->facet_order[j];
            cl_float4 cen = local_point(grid, pb->centroid + 3 * (size_t)q, cell);
            cen.s[3] = (float)log(pb->area[q] / pk->mean_area);
            pk->facet_centroid[j] = cen;
            for (int k = 0; k < 3; k++)
                pk->facet_normal[j].s[k] = (float)pb->normal[3 * (size_t)q + k];
            pk->facet_normal[j].s[3] = 0;
            const uint32_t *tri = pb->indices + 3 * (size_t)pb->facet_triangle[q];
            const double *a = pb->xyz + 3 * (size_t)tri[0];
            const double *b = pb->xyz + 3 * (size_t)tri[1];
            const double *d = pb->xyz + 3 * (size_t)tri[2];
            for (int k = 0; k < 3; k++) {
                pk->facet_edge1[j].s[k] = (float)((b[k] - a[k]) * inv_h);
                pk->facet_edge2[j].s[k] = (float)((d[k] - a[k]) * inv_h);
            }
            pk->facet_edge1[j].s[3] = pk->facet_edge2[j].s[3] = 0;
            pk->facet_vertices[j] =
                (cl_uint4){{pk->rank[tri[0]], pk->rank[tri[1]], pk->rank[tri[2]], 0}};
        }
    }
    return RSMOOTH_OK;
}

enum {
    BUF_FACET_CENTROID,
    BUF_FACET_NORMAL,
    BUF_FACET_EDGE1,
    BUF_FACET_EDGE2,
    BUF_FACET_VERTICES,
    BUF_CELL_COORD,
    BUF_CELL_START,
    BUF_TABLE,
    BUF_VERTEX_LOCAL,
    BUF_VERTEX_CELL,
    BUF_VERTEX_SHIFT,
    BUF_MOLLIFIED_NORMAL,
    BUF_VERTEX_RESULT,
    BUF_VERTEX_EXTRA,
    BUF_COUNT
};

/* Sets kernel arguments in order; stops at the first failure. */
typedef struct arg_setter {
    cl_kernel kernel;
    cl_uint index;
    cl_int err;
} arg_setter;

static void arg(arg_setter *s, size_t size, const void *value) {
    if (s->err == CL_SUCCESS)
        s->err = clSetKernelArg(s->kernel, s->index, size, value);
    s->index++;
}

/* Slices a kernel launch takes when the caller wants progress reports. Every work-item computes
 * its own vertex alone, so slicing never changes the result. */
#define PROGRESS_SLICES 32
#define MOLLIFY_SHARE 0.45

/* Runs `kernel` over `count` work-items and waits; with progress requested, in slices enqueued
 * together (the device never idles between them) and reported as each completes, as fractions
 * from `from` to `to` of the whole filter. */
static cl_int run_1d(rsmooth_context *ctx, const rs_problem *pb, cl_kernel kernel, size_t count,
                     double from, double to) {
    size_t local = ctx->local_size;
    size_t slices = pb->progress && count > PROGRESS_SLICES * local ? PROGRESS_SLICES : 1;
    size_t slice = (count + slices - 1) / slices;
    slice = (slice + local - 1) / local * local;
    cl_event done[PROGRESS_SLICES];
    size_t ends[PROGRESS_SLICES];
    size_t enqueued = 0;
    cl_int err = CL_SUCCESS;
    for (size_t start = 0; start < count && err == CL_SUCCESS; start += slice) {
        size_t n = count - start < slice ? count - start : slice;
        size_t global = (n + local - 1) / local * local;
        err = clEnqueueNDRangeKernel(ctx->queue, kernel, 1, &start, &global, &local, 0, NULL,
                                     &done[enqueued]);
        if (err == CL_SUCCESS)
            ends[enqueued++] = start + n;
    }
    if (err == CL_SUCCESS)
        err = clFlush(ctx->queue);
    for (size_t i = 0; i < enqueued; i++) {
        if (err == CL_SUCCESS)
            err = clWaitForEvents(1, &done[i]);
        if (err == CL_SUCCESS)
            rs_progress(pb, from + (to - from) * (double)ends[i] / (double)count);
        clReleaseEvent(done[i]);
    }
    return err == CL_SUCCESS ? clFinish(ctx->queue) : err;
}

rsmooth_status rsmooth_smooth(rsmooth_context *ctx, rsmooth_scalar scalar, const void *positions,
                              size_t vertex_count, const uint32_t *indices, size_t triangle_count,
                              const rsmooth_params *params, void *out_positions, float *out_weight,
                              float *out_confidence, rsmooth_report *report, rsmooth_error *error) {
    static const char where[] = "rsmooth_smooth";
    double t_start = rs_now_ms();
    rs_error_clear(error);
    if (!ctx)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "ctx is NULL");
    rs_problem pb;
    rsmooth_status st = rs_problem_prepare(&pb, scalar, positions, vertex_count, indices,
                                           triangle_count, params, out_positions, error, where);
    if (st != RSMOOTH_OK)
        return st;
    double t_facets = rs_now_ms();
    double t_grid = t_facets, t_upload = t_facets, t_mollify = t_facets, t_normals = t_facets;
    double t_robust = t_facets;

    rs_grid grid;
    memset(&grid, 0, sizeof grid);
    packed pk;
    memset(&pk, 0, sizeof pk);
    cl_mem buf[BUF_COUNT] = {0};
    cl_float4 *result = NULL, *extra = NULL;

    if (pb.facet_count == 0) {
        rs_store_unmoved(&pb, scalar, out_positions, out_weight, out_confidence);
        goto done;
    }
    st = rs_grid_build(&grid, pb.centroid, pb.facet_count, pb.radius, error);
    if (st == RSMOOTH_OK)
        st = pack(&pb, &grid, &pk, error);
    if (st != RSMOOTH_OK)
        goto cleanup;
    t_grid = rs_now_ms();

    size_t nv = vertex_count, nf = pb.facet_count, nc = grid.cell_count;
    size_t table_size = (size_t)grid.table_mask + 1;
    const struct {
        size_t size;
        void *host;
        cl_mem_flags flags;
    } spec[BUF_COUNT] = {
        [BUF_FACET_CENTROID] = {nf * sizeof(cl_float4), pk.facet_centroid, CL_MEM_READ_ONLY},
        [BUF_FACET_NORMAL] = {nf * sizeof(cl_float4), pk.facet_normal, CL_MEM_READ_ONLY},
        [BUF_FACET_EDGE1] = {nf * sizeof(cl_float4), pk.facet_edge1, CL_MEM_READ_ONLY},
        [BUF_FACET_EDGE2] = {nf * sizeof(cl_float4), pk.facet_edge2, CL_MEM_READ_ONLY},
        [BUF_FACET_VERTICES] = {nf * sizeof(cl_uint4), pk.facet_vertices, CL_MEM_READ_ONLY},
        [BUF_CELL_COORD] = {nc * 4 * sizeof(cl_int), grid.cell_coord, CL_MEM_READ_ONLY},
        [BUF_CELL_START] = {(nc + 1) * sizeof(cl_uint), grid.cell_start, CL_MEM_READ_ONLY},
        [BUF_TABLE] = {table_size * sizeof(cl_int), grid.table, CL_MEM_READ_ONLY},
        [BUF_VERTEX_LOCAL] = {nv * sizeof(cl_float4), pk.vertex_local, CL_MEM_READ_ONLY},
        [BUF_VERTEX_CELL] = {nv * sizeof(cl_int4), pk.vertex_cell, CL_MEM_READ_ONLY},
        [BUF_VERTEX_SHIFT] = {nv * sizeof(cl_float4), NULL, CL_MEM_READ_WRITE},
        [BUF_MOLLIFIED_NORMAL] = {nf * sizeof(cl_float4), NULL, CL_MEM_READ_WRITE},
        [BUF_VERTEX_RESULT] = {nv * sizeof(cl_float4), NULL, CL_MEM_WRITE_ONLY},
        [BUF_VERTEX_EXTRA] = {nv * sizeof(cl_float4), NULL, CL_MEM_WRITE_ONLY},
    };
    for (int b = 0; b < BUF_COUNT; b++) {
        cl_int err = CL_SUCCESS;
        buf[b] = clCreateBuffer(ctx->context, spec[b].flags, spec[b].size, NULL, &err);
        if (err == CL_SUCCESS && spec[b].host)
            err = clEnqueueWriteBuffer(ctx->queue, buf[b], CL_FALSE, 0, spec[b].size, spec[b].host,
                                       0, NULL, NULL);
        if (err != CL_SUCCESS) {
            st = rs_cl_fail(error, err, "clCreateBuffer/clEnqueueWriteBuffer", ctx->device_name);
            goto cleanup;
        }
    }
    cl_int err = clFinish(ctx->queue);
    if (err != CL_SUCCESS) {
        st = rs_cl_fail(error, err, "clFinish (upload)", ctx->device_name);
        goto cleanup;
    }
    t_upload = rs_now_ms();

    /* Lengths in cell units (h), so every float the kernels see is of order one. */
    const double h = grid.cell_size;
    cl_uint vcount = (cl_uint)nv, fcount = (cl_uint)nf, mask = grid.table_mask;
    cl_float reach2 = (cl_float)((pb.radius / h) * (pb.radius / h));
    cl_float mollify_reach2 = (cl_float)((pb.mollify_radius / h) * (pb.mollify_radius / h));
    cl_float inv_2sm2 = (cl_float)(h * h / (2 * pb.sigma_m * pb.sigma_m));
    cl_float inv_2sf2 = (cl_float)(h * h / (2 * pb.sigma_f * pb.sigma_f));
    cl_float inv_2sg2 =
        isinf(pb.sigma_g) ? 0.0f : (cl_float)(h * h / (2 * pb.sigma_g * pb.sigma_g));
    cl_int want_confidence = out_confidence != NULL;
    cl_int predict_centroid = pb.predict_centroid;

    cl_mem normals = buf[BUF_FACET_NORMAL];
    if (pb.mollify) {
        arg_setter s = {ctx->kernels[RS_KERNEL_MOLLIFY], 0, CL_SUCCESS};
        arg(&s, sizeof vcount, &vcount);
        arg(&s, sizeof mollify_reach2, &mollify_reach2);
        arg(&s, sizeof inv_2sm2, &inv_2sm2);
        arg(&s, sizeof(cl_mem), &buf[BUF_VERTEX_LOCAL]);
        arg(&s, sizeof(cl_mem), &buf[BUF_VERTEX_CELL]);
        arg(&s, sizeof(cl_mem), &buf[BUF_FACET_CENTROID]);
        arg(&s, sizeof(cl_mem), &buf[BUF_CELL_COORD]);
        arg(&s, sizeof(cl_mem), &buf[BUF_CELL_START]);
        arg(&s, sizeof(cl_mem), &buf[BUF_TABLE]);
        arg(&s, sizeof mask, &mask);
        arg(&s, sizeof(cl_mem), &buf[BUF_VERTEX_SHIFT]);
        err = s.err != CL_SUCCESS ? s.err : run_1d(ctx, &pb, s.kernel, nv, 0, MOLLIFY_SHARE);
        if (err != CL_SUCCESS) {
            st = rs_cl_fail(error, err, "mollify_vertex", ctx->device_name);
            goto cleanup;
        }
        t_mollify = rs_now_ms();

        s = (arg_setter){ctx->kernels[RS_KERNEL_NORMALS], 0, CL_SUCCESS};
        arg(&s, sizeof fcount, &fcount);
        arg(&s, sizeof(cl_mem), &buf[BUF_FACET_VERTICES]);
        arg(&s, sizeof(cl_mem), &buf[BUF_FACET_EDGE1]);
        arg(&s, sizeof(cl_mem), &buf[BUF_FACET_EDGE2]);
        arg(&s, sizeof(cl_mem), &buf[BUF_FACET_NORMAL]);
        arg(&s, sizeof(cl_mem), &buf[BUF_VERTEX_SHIFT]);
        arg(&s, sizeof(cl_mem), &buf[BUF_MOLLIFIED_NORMAL]);
        err = s.err != CL_SUCCESS ? s.err
                                  : run_1d(ctx, &pb, s.kernel, nf, MOLLIFY_SHARE, MOLLIFY_SHARE);
        if (err != CL_SUCCESS) {
            st = rs_cl_fail(error, err, "mollified_facet_normal", ctx->device_name);
            goto cleanup;
        }
        normals = buf[BUF_MOLLIFIED_NORMAL];
    } else {
        t_mollify = rs_now_ms();
    }
    t_normals = rs_now_ms();

    arg_setter s = {ctx->kernels[RS_KERNEL_ROBUST], 0, CL_SUCCESS};
    arg(&s, sizeof vcount, &vcount);
    arg(&s, sizeof reach2, &reach2);
    arg(&s, sizeof inv_2sf2, &inv_2sf2);
    arg(&s, sizeof inv_2sg2, &inv_2sg2);
    arg(&s, sizeof want_confidence, &want_confidence);
    arg(&s, sizeof predict_centroid, &predict_centroid);
    arg(&s, sizeof(cl_mem), &buf[BUF_VERTEX_LOCAL]);
    arg(&s, sizeof(cl_mem), &buf[BUF_VERTEX_CELL]);
    arg(&s, sizeof(cl_mem), &buf[BUF_FACET_CENTROID]);
    arg(&s, sizeof(cl_mem), &normals);
    arg(&s, sizeof(cl_mem), &buf[BUF_CELL_COORD]);
    arg(&s, sizeof(cl_mem), &buf[BUF_CELL_START]);
    arg(&s, sizeof(cl_mem), &buf[BUF_TABLE]);
    arg(&s, sizeof mask, &mask);
    arg(&s, sizeof(cl_mem), &buf[BUF_VERTEX_RESULT]);
    arg(&s, sizeof(cl_mem), &buf[BUF_VERTEX_EXTRA]);
    err = s.err != CL_SUCCESS ? s.err
                              : run_1d(ctx, &pb, s.kernel, nv, pb.mollify ? MOLLIFY_SHARE : 0, 1);
    if (err != CL_SUCCESS) {
        st = rs_cl_fail(error, err, "robust_vertex", ctx->device_name);
        goto cleanup;
    }
    t_robust = rs_now_ms();

    result = rs_alloc_array(nv, sizeof(cl_float4));
    extra = rs_alloc_array(nv, sizeof(cl_float4));
    if (!result || !extra) {
        st = rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "no memory for results");
        goto cleanup;
    }
    err = clEnqueueReadBuffer(ctx->queue, buf[BUF_VERTEX_RESULT], CL_TRUE, 0,
                              nv * sizeof(cl_float4), result, 0, NULL, NULL);
    if (err == CL_SUCCESS)
        err = clEnqueueReadBuffer(ctx->queue, buf[BUF_VERTEX_EXTRA], CL_TRUE, 0,
                                  nv * sizeof(cl_float4), extra, 0, NULL, NULL);
    if (err != CL_SUCCESS) {
        st = rs_cl_fail(error, err, "clEnqueueReadBuffer", ctx->device_name);
        goto cleanup;
    }
    for (size_t i = 0; i < nv; i++) {
        uint32_t v = pk.order[i];
        const double *p = pb.xyz + 3 * (size_t)v;
        double out[3];
        for (int k = 0; k < 3; k++)
            out[k] = p[k] + (double)result[i].s[k] * h;
        rs_store_position(scalar, out_positions, v, out);
        double k = (double)result[i].s[3] * exp(-(double)extra[i].s[1]) * pk.mean_area;
        double kf = (double)extra[i].s[0] * pk.mean_area;
        if (out_weight)
            out_weight[v] = (float)k;
        if (out_confidence)
            out_confidence[v] = kf > 0 ? (float)fmin(1.0, k / kf) : 0.0f;
    }

done:
    rs_progress(&pb, 1.0);
    if (report) {
        double now = rs_now_ms();
        rs_report_problem(report, &pb, &grid, ctx->device_name);
        report->ms_facets = t_facets - t_start;
        report->ms_grid = t_grid - t_facets;
        report->ms_upload = t_upload - t_grid;
        report->ms_mollify = t_mollify - t_upload;
        report->ms_normals = t_normals - t_mollify;
        report->ms_robust = t_robust - t_normals;
        report->ms_download = pb.facet_count ? now - t_robust : 0;
        report->ms_total = now - t_start;
    }
    st = RSMOOTH_OK;

cleanup:
    for (int b = 0; b < BUF_COUNT; b++)
        if (buf[b])
            clReleaseMemObject(buf[b]);
    rs_free(result);
    rs_free(extra);
    packed_free(&pk);
    rs_grid_free(&grid);
    rs_problem_free(&pb);
    return st;
}
