/* The normal-update stage's cycles on the device (kernels/stage.cl): the plan's lists uploaded
 * once, every cycle enqueued without a round trip (the host waits only to report a cycle's end,
 * when the caller asked for progress), the positions read back once. The host version
 * (stages/normal_update.c) is what this is verified against; a plan too large for the device is
 * refused with RSMOOTH_ERROR_OUT_OF_MEMORY, and the host runs it instead (the stage's reach grows
 * with its cycles, so it is not cut into tiles). */
#include "core/stage_plan.h"
#include "opencl/cl_run.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char where[] = "rsmooth_smooth (normal update stage)";

enum {
    SB_FACET_VERTEX,
    SB_FACET_REST,
    SB_REST_CENTROID,
    SB_CENTROID,
    SB_SHIFT,
    SB_NORMAL,
    SB_REP,
    SB_REP_START,
    SB_REP_FACET,
    SB_REP_OFFSET,
    SB_PATCH_START,
    SB_PATCH,
    SB_EDGE_START,
    SB_EDGE,
    SB_NEAR_START,
    SB_NEAR,
    SB_MASK,
    SB_D0,
    SB_UPLOADED, /* the buffers above start from the host; those below are the device's own */
    SB_D1 = SB_UPLOADED,
    SB_PATCH_MEAN,
    SB_PATCH_SCORE,
    SB_GUIDANCE,
    SB_FILTERED0,
    SB_FILTERED1,
    SB_COUNT
};

typedef struct stage_run {
    rsmooth_context *ctx;
    const rs_stage_plan *plan;
    void *packed[SB_UPLOADED]; /* the host arrays this file packed (the rest are the plan's) */
    const void *from[SB_UPLOADED];
    size_t data[SB_UPLOADED]; /* bytes of each host array */
    size_t size[SB_COUNT];    /* bytes of each buffer: at least 16, an empty list's too */
    cl_mem buf[SB_COUNT];
    bool dbl;                 /* the kernels in double (else float) */
    size_t real;              /* bytes of one REAL: 8 or 4 */
    const cl_kernel *kernels; /* RS_STAGE_KERNELS of them, in the run's precision */
} stage_run;

/* Element i of an array of REAL4 (x, y, z, w). */
static void put4(const stage_run *r, void *array, size_t i, const double *xyz, double w) {
    if (r->dbl) {
        double *to = (double *)array + 4 * i;
        memcpy(to, xyz, 3 * sizeof *to);
        to[3] = w;
    } else {
        float *to = (float *)array + 4 * i;
        for (int k = 0; k < 3; k++)
            to[k] = (float)xyz[k];
        to[3] = (float)w;
    }
}

/* Buffer b from `bytes` of host array `from` (NULL: the device's own, or packed below). */
static void plan_buffer(stage_run *r, int b, const void *from, size_t bytes) {
    r->size[b] = bytes > 16 ? bytes : 16;
    if (b < SB_UPLOADED) {
        r->from[b] = from;
        r->data[b] = bytes;
    }
}

/* Buffer b packed here: `count` elements of `size` bytes, zeroed. */
static void *packed_buffer(stage_run *r, int b, size_t count, size_t size) {
    plan_buffer(r, b, NULL, count * size);
    r->packed[b] = rs_calloc_array(count ? count : 1, size);
    r->from[b] = r->packed[b];
    return r->packed[b];
}

/* A CSR start array as 32-bit offsets. */
static cl_uint *starts32(stage_run *r, int b, const size_t *start, size_t count) {
    cl_uint *s = packed_buffer(r, b, count + 1, sizeof *s);
    for (size_t i = 0; s && i <= count; i++)
        s[i] = (cl_uint)start[i];
    return s;
}

/* Every buffer's size, and the host arrays that need packing: the facets' input geometry and the
 * (welded vertex, facet) offsets from the plan's doubles, 32-bit list starts. false when out of
 * memory or a list exceeds 32-bit offsets. */
static bool pack_plan(stage_run *r) {
    const rs_stage_plan *p = r->plan;
    size_t nf = p->facet_count, nv = p->vertex_count, ni = p->rep_start[nv];
    size_t np = p->filter ? p->patch_start[nf] : 0, ne = p->filter ? p->edge_start[nf] : 0;
    size_t nn = p->filter ? p->near_start[nf] : 0;
    if (nf > UINT32_MAX / 2 || nv > UINT32_MAX / 2 || ni > UINT32_MAX || np > UINT32_MAX ||
        ne > UINT32_MAX / 2 || nn > UINT32_MAX)
        return false;
    static const uint8_t every_vertex = 1;
    plan_buffer(r, SB_REP, p->rep, nv * sizeof(cl_uint));
    plan_buffer(r, SB_REP_FACET, p->rep_facet, ni * sizeof(cl_uint));
    plan_buffer(r, SB_PATCH, p->patch, np * sizeof(cl_uint));
    plan_buffer(r, SB_EDGE, p->edge, 2 * ne * sizeof(cl_uint));
    plan_buffer(r, SB_NEAR, p->near, nn * sizeof(cl_uint));
    plan_buffer(r, SB_MASK, p->move_mask ? (const void *)p->move_mask : &every_vertex,
                p->move_mask ? nv : 1);
    plan_buffer(r, SB_D1, NULL, nv * 4 * r->real);
    plan_buffer(r, SB_PATCH_MEAN, NULL, nf * 4 * r->real);
    plan_buffer(r, SB_PATCH_SCORE, NULL, nf * r->real);
    plan_buffer(r, SB_GUIDANCE, NULL, nf * 4 * r->real);
    plan_buffer(r, SB_FILTERED0, NULL, nf * 4 * r->real);
    plan_buffer(r, SB_FILTERED1, NULL, nf * 4 * r->real);
    bool lists = !p->filter || (starts32(r, SB_PATCH_START, p->patch_start, nf) &&
                                starts32(r, SB_EDGE_START, p->edge_start, nf) &&
                                starts32(r, SB_NEAR_START, p->near_start, nf));
    if (!p->filter) { /* unread: the rounds do not run */
        plan_buffer(r, SB_PATCH_START, NULL, 0);
        plan_buffer(r, SB_EDGE_START, NULL, 0);
        plan_buffer(r, SB_NEAR_START, NULL, 0);
    }
    size_t r4 = 4 * r->real;
    cl_uint4 *fv = packed_buffer(r, SB_FACET_VERTEX, nf, sizeof *fv);
    void *rest = packed_buffer(r, SB_FACET_REST, 2 * nf, r4);
    void *rc = packed_buffer(r, SB_REST_CENTROID, nf, r4);
    void *cen = packed_buffer(r, SB_CENTROID, nf, r4);
    void *normal = packed_buffer(r, SB_NORMAL, nf, r4);
    void *offset = packed_buffer(r, SB_REP_OFFSET, ni, r4);
    bool zeros =
        packed_buffer(r, SB_SHIFT, nf, r4) && packed_buffer(r, SB_D0, nv, r4); /* d starts at 0 */
    if (!lists || !zeros || !fv || !rest || !rc || !cen || !normal || !offset ||
        !starts32(r, SB_REP_START, p->rep_start, nv))
        return false;
    for (size_t f = 0; f < nf; f++) {
        const uint32_t *t = p->facet_vertex + 3 * f;
        const double *a = p->xyz + 3 * (size_t)t[0], *b = p->xyz + 3 * (size_t)t[1];
        const double *c = p->xyz + 3 * (size_t)t[2];
        double e1[3], e2[3];
        rs_sub3(b, a, e1);
        rs_sub3(c, a, e2);
        fv[f] = (cl_uint4){{t[0], t[1], t[2], 0}};
        put4(r, rest, 2 * f, e1, 0);
        put4(r, rest, 2 * f + 1, e2, 0);
        put4(r, rc, f, p->facet_centroid + 3 * f, 0);
        put4(r, cen, f, p->facet_centroid + 3 * f, p->facet_area[f]);
        put4(r, normal, f, p->facet_normal + 3 * f, 0);
    }
    for (size_t v = 0; v < nv; v++)
        for (size_t i = p->rep_start[v]; i < p->rep_start[v + 1]; i++) {
            double gap[3];
            rs_sub3(p->facet_centroid + 3 * (size_t)p->rep_facet[i], p->xyz + 3 * v, gap);
            put4(r, offset, i, gap, 0);
        }
    return true;
}

/* Every buffer, refused whole (RSMOOTH_ERROR_OUT_OF_MEMORY, nothing run) where they do not fit. */
static rsmooth_status create_buffers(stage_run *r, rs_stage_stats *stats, rsmooth_error *error) {
    rsmooth_context *ctx = r->ctx;
    uint64_t total = 0, largest = 0;
    for (int b = 0; b < SB_COUNT; b++) {
        total += r->size[b];
        largest = r->size[b] > largest ? r->size[b] : largest;
    }
    if (total > rs_cl_usable_memory(ctx) || largest > ctx->max_allocation)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where,
                       "the stage needs %llu bytes on %s (usable %llu)", (unsigned long long)total,
                       ctx->device_name, (unsigned long long)rs_cl_usable_memory(ctx));
    for (int b = 0; b < SB_COUNT; b++) {
        cl_int err = CL_SUCCESS;
        r->buf[b] = clCreateBuffer(ctx->context, CL_MEM_READ_WRITE, r->size[b], NULL, &err);
        if (err == CL_SUCCESS && b < SB_UPLOADED && r->data[b] > 0) {
            err = clEnqueueWriteBuffer(ctx->queue, r->buf[b], CL_FALSE, 0, r->data[b], r->from[b],
                                       0, NULL, NULL);
            stats->bytes_to_device += r->data[b];
        }
        if (err != CL_SUCCESS)
            return rs_cl_fail(error, err, "clCreateBuffer", ctx->device_name);
    }
    cl_int err = clFinish(ctx->queue);
    return err == CL_SUCCESS ? RSMOOTH_OK : rs_cl_fail(error, err, "clFinish", ctx->device_name);
}

/* Enqueues `kernel` over `count` work-items (none when count is 0). */
static cl_int launch(rsmooth_context *ctx, cl_kernel kernel, size_t count) {
    if (count == 0)
        return CL_SUCCESS;
    size_t local = ctx->local_size, global = (count + local - 1) / local * local;
    return clEnqueueNDRangeKernel(ctx->queue, kernel, 1, NULL, &global, &local, 0, NULL, NULL);
}

/* Sets the next `count` arguments of a kernel to buffers. */
static void mem_args(arg_setter *s, int count, const cl_mem *const *mems) {
    for (int i = 0; i < count; i++)
        arg(s, sizeof(cl_mem), mems[i]);
}
#define MEMS(s, ...)                                                                               \
    mem_args(s, (int)(sizeof((const cl_mem *[]){__VA_ARGS__}) / sizeof(cl_mem *)),                 \
             (const cl_mem *const[]){__VA_ARGS__})

/* Facet geometry from the displacements in `d` (stage_facets). */
static cl_int enqueue_facets(stage_run *r, const cl_mem *d) {
    const cl_mem *b = r->buf;
    cl_uint nf = (cl_uint)r->plan->facet_count;
    arg_setter s = {r->kernels[RS_STAGE_FACETS], 0, CL_SUCCESS};
    arg(&s, sizeof nf, &nf);
    MEMS(&s, &b[SB_FACET_VERTEX], &b[SB_FACET_REST], &b[SB_REST_CENTROID], d, &b[SB_CENTROID],
         &b[SB_SHIFT], &b[SB_NORMAL]);
    return s.err != CL_SUCCESS ? s.err : launch(r->ctx, s.kernel, nf);
}

/* One guided round from the normals in `in` to `out` (stage_patch, stage_guidance,
 * stage_filter). */
static cl_int enqueue_round(stage_run *r, const cl_mem *in, const cl_mem *out) {
    const cl_mem *b = r->buf;
    const rs_stage_plan *p = r->plan;
    cl_uint nf = (cl_uint)p->facet_count;
    double inv_2s2 = LOG2_E * p->inv_2s2, inv_2t2 = LOG2_E * p->inv_2t2; /* base 2 */
    cl_float inv_2s2_f = (cl_float)inv_2s2, inv_2t2_f = (cl_float)inv_2t2;
    arg_setter s = {r->kernels[RS_STAGE_PATCH], 0, CL_SUCCESS};
    arg(&s, sizeof nf, &nf);
    MEMS(&s, &b[SB_PATCH_START], &b[SB_PATCH], &b[SB_EDGE_START], &b[SB_EDGE], &b[SB_CENTROID], in,
         &b[SB_PATCH_MEAN], &b[SB_PATCH_SCORE]);
    cl_int err = s.err != CL_SUCCESS ? s.err : launch(r->ctx, s.kernel, nf);
    s = (arg_setter){r->kernels[RS_STAGE_GUIDANCE], 0, err};
    arg(&s, sizeof nf, &nf);
    MEMS(&s, &b[SB_PATCH_START], &b[SB_PATCH], &b[SB_PATCH_SCORE], &b[SB_PATCH_MEAN],
         &b[SB_GUIDANCE]);
    err = s.err != CL_SUCCESS ? s.err : launch(r->ctx, s.kernel, nf);
    s = (arg_setter){r->kernels[RS_STAGE_FILTER], 0, err};
    arg(&s, sizeof nf, &nf);
    MEMS(&s, &b[SB_NEAR_START], &b[SB_NEAR], &b[SB_CENTROID], &b[SB_GUIDANCE], in);
    arg(&s, r->real, r->dbl ? (const void *)&inv_2s2 : &inv_2s2_f);
    arg(&s, r->real, r->dbl ? (const void *)&inv_2t2 : &inv_2t2_f);
    arg(&s, sizeof(cl_mem), out);
    return s.err != CL_SUCCESS ? s.err : launch(r->ctx, s.kernel, nf);
}

/* One vertex update from the displacements in `in` to `out` with the normals in `normal`. */
static cl_int enqueue_update(stage_run *r, const cl_mem *normal, const cl_mem *in,
                             const cl_mem *out) {
    const cl_mem *b = r->buf;
    cl_uint nv = (cl_uint)r->plan->vertex_count;
    cl_int mask_on = r->plan->move_mask != NULL;
    arg_setter s = {r->kernels[RS_STAGE_VERTEX], 0, CL_SUCCESS};
    arg(&s, sizeof nv, &nv);
    MEMS(&s, &b[SB_REP], &b[SB_REP_START], &b[SB_REP_FACET], &b[SB_REP_OFFSET], &b[SB_SHIFT],
         normal, &b[SB_MASK]);
    arg(&s, sizeof mask_on, &mask_on);
    MEMS(&s, in, out);
    return s.err != CL_SUCCESS ? s.err : launch(r->ctx, s.kernel, nv);
}

/* One cycle: fresh geometry (after the first), the guided rounds, the vertex updates; *d is the
 * buffer holding the displacements, before and after. */
static cl_int enqueue_cycle(stage_run *r, int cycle, int *d) {
    const rs_stage_plan *p = r->plan;
    cl_mem *b = r->buf;
    cl_int err = cycle > 0 ? enqueue_facets(r, &b[*d]) : CL_SUCCESS;
    /* the normals the updates read: a copy of the facets' own when no round runs, since the
     * updates' fresh geometry rewrites those */
    int normals = SB_FILTERED0;
    if (err == CL_SUCCESS && (!p->filter || p->rounds < 1))
        err = clEnqueueCopyBuffer(r->ctx->queue, b[SB_NORMAL], b[SB_FILTERED0], 0, 0,
                                  p->facet_count * 4 * r->real, 0, NULL, NULL);
    for (int round = 0; err == CL_SUCCESS && p->filter && round < p->rounds; round++) {
        int out = round % 2 ? SB_FILTERED1 : SB_FILTERED0;
        err = enqueue_round(r, round == 0 ? &b[SB_NORMAL] : &b[normals], &b[out]);
        normals = out;
    }
    for (int it = 0; err == CL_SUCCESS && it < p->updates; it++) {
        int next = *d == SB_D0 ? SB_D1 : SB_D0;
        if (it > 0)
            err = enqueue_facets(r, &b[*d]);
        if (err == CL_SUCCESS)
            err = enqueue_update(r, &b[normals], &b[*d], &b[next]);
        *d = next;
    }
    return err;
}

/* Every cycle, the host waiting only where the caller wants each cycle's end reported. */
static rsmooth_status run_cycles(stage_run *r, rs_cycle_fn cycle_done, void *user, int *d,
                                 rs_stage_stats *stats, rsmooth_error *error) {
    const rs_stage_plan *p = r->plan;
    for (int c = 0; c < p->cycles; c++) {
        cl_int err = enqueue_cycle(r, c, d);
        if (err == CL_SUCCESS)
            err = cycle_done ? clFinish(r->ctx->queue) : clFlush(r->ctx->queue);
        if (err != CL_SUCCESS)
            return rs_cl_fail(error, err, "stage kernels", r->ctx->device_name);
        stats->cycles = c + 1;
        if (cycle_done && cycle_done(user, c + 1, p->cycles) != 0)
            return rs_cancelled(error, where);
    }
    cl_int err = clFinish(r->ctx->queue);
    return err == CL_SUCCESS ? RSMOOTH_OK : rs_cl_fail(error, err, "clFinish", r->ctx->device_name);
}

/* The displacements back, added to the input in double. */
static rsmooth_status read_back(stage_run *r, int d, double *xyz, rs_stage_stats *stats,
                                rsmooth_error *error) {
    size_t nv = r->plan->vertex_count, bytes = nv * 4 * r->real;
    void *shift = rs_alloc_array(nv ? nv : 1, 4 * r->real);
    if (!shift)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "no memory for %zu vertices", nv);
    cl_int err =
        clEnqueueReadBuffer(r->ctx->queue, r->buf[d], CL_TRUE, 0, bytes, shift, 0, NULL, NULL);
    if (err == CL_SUCCESS) {
        stats->bytes_from_device += bytes;
        for (size_t v = 0; v < nv; v++)
            for (size_t k = 0; k < 3; k++)
                xyz[3 * v + k] += r->dbl ? ((const double *)shift)[4 * v + k]
                                         : (double)((const float *)shift)[4 * v + k];
    }
    rs_free(shift);
    return err == CL_SUCCESS ? RSMOOTH_OK
                             : rs_cl_fail(error, err, "clEnqueueReadBuffer", r->ctx->device_name);
}

/* Double where the device has it, unless RSMOOTH_STAGE_PRECISION=float asks for float (the drift
 * measurements; its value was checked when the context was made). */
static void choose_precision(stage_run *r) {
    bool has_double = r->ctx->kernels[RS_KERNEL_STAGE_DOUBLE] != NULL;
    r->dbl = has_double && !rs_environment_is(&r->ctx->env, RS_ENV_STAGE_PRECISION, "float");
    r->real = r->dbl ? sizeof(double) : sizeof(float);
    r->kernels = r->ctx->kernels + (r->dbl ? RS_KERNEL_STAGE_DOUBLE : RS_KERNEL_STAGE_FLOAT);
}

rsmooth_status rs_cl_stage_run(void *context, const rs_stage_plan *plan, double *xyz,
                               rs_cycle_fn cycle_done, void *user, rs_stage_stats *stats,
                               rsmooth_error *error) {
    stage_run r;
    memset(&r, 0, sizeof r);
    r.ctx = context;
    r.plan = plan;
    double t0 = rs_now_ms();
    choose_precision(&r);
    stats->float_bits = r.dbl ? 64 : 32;
    rsmooth_status st = pack_plan(&r) ? RSMOOTH_OK
                                      : rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where,
                                                "no memory for the stage's device arrays");
    if (st == RSMOOTH_OK)
        st = create_buffers(&r, stats, error);
    double t1 = rs_now_ms();
    int d = SB_D0;
    if (st == RSMOOTH_OK) {
        stats->on_device = true;
        snprintf(stats->device, sizeof stats->device, "%.127s", r.ctx->device_name);
        st = run_cycles(&r, cycle_done, user, &d, stats, error);
    }
    double t2 = rs_now_ms();
    if (st == RSMOOTH_OK)
        st = read_back(&r, d, xyz, stats, error);
    stats->ms_upload = t1 - t0;
    stats->ms_cycles = t2 - t1;
    stats->ms_download = rs_now_ms() - t2;
    for (int b = 0; b < SB_COUNT; b++)
        if (r.buf[b])
            clReleaseMemObject(r.buf[b]);
    for (int b = 0; b < SB_UPLOADED; b++)
        rs_free(r.packed[b]);
    return st;
}
