/* The OpenCL path: host-side facet data and grid (on every core), buffers the device reads in
 * place, mollify -> normals (or the bilateral normal filter's rounds) -> robust kernels, results
 * mapped and scattered back to the caller's vertex order. Coordinates travel as float32 in units
 * of the cell size, relative to a nearby cell's corner (see kernels/common.cl), so precision does
 * not depend on where the mesh sits; displacements return to double before they are added. */
#include "opencl/cl_grid.h"
#include "opencl/cl_run.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Exponents reach the kernels in base 2: natural ones times log2(e). */

/* Elements per chunk below which a host loop is not worth a thread. */
#define PARALLEL_GRAIN 4096

/* Vertices clamped far outside the grid have no neighbours; keep their floats finite anyway. */
#define LOCAL_CLAMP 1e6

typedef struct packed {
    cl_float4 *facet_centroid, *facet_normal; /* in grid order */
    cl_uint *facet_vertices; /* in the caller's facet order: slots of the three vertices */
    cl_uint *facet_place;    /* caller's facet -> its place in grid order */
    size_t lanes;            /* vertices per block (the context's) */
    size_t block_count;
    cl_int4 *block_cell;    /* per block: its anchor, the lowest cell it spans */
    cl_float *block_pos;    /* per block: `lanes` x, then y, then z, each local to its
                             * vertex's own cell (so no float depends on the block it is in) */
    cl_uchar *block_offset; /* per block, as block_pos: each vertex's cell minus the anchor,
                             * 0 or 1 per axis */
    uint32_t *slot;         /* caller's vertex index -> block * lanes + lane */
    /* the colour factor's, NULL when it is off */
    cl_float4 *facet_color; /* in grid order: the mean colour of the facet's corners, 0 */
    cl_float *block_color;  /* per block, as block_pos: `lanes` first components, ... */
} packed;

static void packed_free(packed *pk) {
    rs_free(pk->facet_centroid);
    rs_free(pk->facet_normal);
    rs_free(pk->facet_vertices);
    rs_free(pk->facet_place);
    rs_free(pk->block_cell);
    rs_free(pk->block_pos);
    rs_free(pk->block_offset);
    rs_free(pk->slot);
    rs_free(pk->facet_color);
    rs_free(pk->block_color);
}

static cl_float4 local_point(const rs_grid *grid, const double p[3], const int32_t cell[3]) {
    cl_float4 out;
    for (int k = 0; k < 3; k++) {
        double corner = (grid->origin_cell[k] + (double)cell[k]) * grid->cell_size;
        double x = (p[k] - corner) * grid->inv_cell_size;
        out.s[k] = (float)(x < -LOCAL_CLAMP ? -LOCAL_CLAMP : x > LOCAL_CLAMP ? LOCAL_CLAMP : x);
    }
    out.s[3] = 0;
    return out;
}

/* Whether a vertex of cell `c` joins the block spanning cells [lo, hi] with `lanes` vertices: a
 * block holds at most `width` vertices and spans at most two cells per axis, so its lanes lie in a
 * box of at most two cells and its neighbour search stays small. */
static bool joins_block(size_t lanes, size_t width, const int32_t lo[3], const int32_t hi[3],
                        const int32_t *c) {
    if (lanes == 0 || lanes == width)
        return false;
    for (int k = 0; k < 3; k++) {
        int32_t a = c[k] < lo[k] ? c[k] : lo[k], b = c[k] > hi[k] ? c[k] : hi[k];
        if (b - a > 1)
            return false;
    }
    return true;
}

/* Cuts the vertices, in grid order (`cells` per position), into blocks: block b holds positions
 * start[b] .. start[b + 1] - 1 (start has room for count + 1). Returns the block count. Blocks hold
 * at most `width` vertices. One pass: each block's anchor is found again when it is filled. */
static size_t cut_blocks(const int32_t *cells, size_t count, size_t width, uint32_t *start) {
    size_t blocks = 0, lanes = 0;
    int32_t lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    for (size_t i = 0; i < count; i++) {
        const int32_t *c = cells + 3 * i;
        if (!joins_block(lanes, width, lo, hi, c)) {
            start[blocks++] = (uint32_t)i;
            lanes = 0;
            memcpy(lo, c, sizeof lo);
            memcpy(hi, c, sizeof hi);
        }
        for (int k = 0; k < 3; k++) {
            lo[k] = c[k] < lo[k] ? c[k] : lo[k];
            hi[k] = c[k] > hi[k] ? c[k] : hi[k];
        }
        lanes++;
    }
    start[blocks] = (uint32_t)count;
    return blocks;
}

typedef struct block_job {
    const rs_problem *pb;
    const rs_grid *grid;
    packed *pk;
    const uint32_t *order, *start;
    const int32_t *cells; /* per grid position: the vertex's cell */
} block_job;

/* Slots, positions local to their own cells and cell offsets from the anchor of the vertices of
 * blocks [begin, end). The kernels subtract the whole-cell distance between a facet's cell and a
 * vertex's (a small exact integer) from the two local positions, so every difference they compute
 * is the same bits whichever vertices share the block: a tile or a piece of a larger mesh gets the
 * whole mesh's results. */
static void fill_blocks(void *ctx, size_t begin, size_t end, size_t chunk) {
    const block_job *job = ctx;
    packed *pk = job->pk;
    const size_t width = pk->lanes;
    (void)chunk;
    for (size_t b = begin; b < end; b++) {
        cl_float *pos = pk->block_pos + 3 * width * b;
        cl_uchar *offset = pk->block_offset + 3 * width * b;
        cl_int4 low = {{INT32_MAX, INT32_MAX, INT32_MAX, 0}}; /* the anchor: the lowest cell */
        for (uint32_t i = job->start[b]; i < job->start[b + 1]; i++)
            for (int k = 0; k < 3; k++)
                low.s[k] = job->cells[3 * (size_t)i + k] < low.s[k] ? job->cells[3 * (size_t)i + k]
                                                                    : low.s[k];
        pk->block_cell[b] = low;
        const cl_int *anchor = low.s;
        for (uint32_t i = job->start[b]; i < job->start[b + 1]; i++) {
            uint32_t v = job->order[i], lane = i - job->start[b];
            const int32_t *cell = job->cells + 3 * (size_t)i;
            pk->slot[v] = (uint32_t)(b * width + lane);
            cl_float4 local = local_point(job->grid, job->pb->xyz + 3 * (size_t)v, cell);
            const float *color = job->pb->colors ? job->pb->colors + 3 * (size_t)v : NULL;
            /* lane 0 also fills the unused lanes, so they compute something harmless */
            for (size_t l = lane; l < (lane == 0 ? width : lane + 1); l++)
                for (int k = 0; k < 3; k++) {
                    pos[k * width + l] = local.s[k];
                    offset[k * width + l] = (cl_uchar)(cell[k] - anchor[k]); /* 0 or 1 */
                    if (color)
                        pk->block_color[3 * width * b + k * width + l] = color[k];
                }
        }
    }
}

/* Vertices in grid order, cut into blocks (cut_blocks), positions local to each block's anchor. */
static rsmooth_status pack_blocks(const rs_problem *pb, const rs_grid *grid, packed *pk,
                                  rsmooth_error *error) {
    size_t nv = pb->vertex_count;
    uint32_t *order = rs_alloc_array(nv, sizeof *order); /* grid position -> vertex */
    int32_t *cells = rs_alloc_array(nv, 3 * sizeof *cells);
    uint32_t *start = NULL;
    rsmooth_status st = RSMOOTH_OK;
    if (!order || !cells) {
        st = rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, "rsmooth_smooth", "no memory for blocks");
        goto done;
    }
    if ((st = rs_grid_order_points(grid, pb->xyz, nv, order, cells, error)) != RSMOOTH_OK)
        goto done;
    const size_t width = pk->lanes;
    start = rs_alloc_array(nv + 1, sizeof *start);
    if (!start) {
        st = rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, "rsmooth_smooth", "no memory for blocks");
        goto done;
    }
    size_t blocks = cut_blocks(cells, nv, width, start);
    pk->block_count = blocks;
    pk->block_cell = rs_alloc_array(blocks, sizeof(cl_int4));
    pk->block_pos = rs_alloc_array(blocks, 3 * width * sizeof(cl_float));
    pk->block_offset = rs_alloc_array(blocks, 3 * width * sizeof(cl_uchar));
    if (pb->colors)
        pk->block_color = rs_alloc_array(blocks, 3 * width * sizeof(cl_float));
    if (!pk->block_cell || !pk->block_pos || !pk->block_offset ||
        (pb->colors && !pk->block_color)) {
        st = rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, "rsmooth_smooth", "no memory for blocks");
        goto done;
    }
    block_job job = {pb, grid, pk, order, start, cells};
    rs_parallel_for(blocks, PARALLEL_GRAIN / width, fill_blocks, &job);
done:
    rs_free(order);
    rs_free(cells);
    rs_free(start);
    return st;
}

typedef struct facet_job {
    const rs_problem *pb;
    const rs_grid *grid;
    const double *centroid; /* 3 per facet, build_grid's */
    packed *pk;
} facet_job;

/* The occupied cell holding grid position j: the last whose start is at or below it. */
static size_t cell_at(const rs_grid *grid, size_t j) {
    size_t lo = 0, hi = grid->cell_count; /* cell_start[lo] <= j < cell_start[hi] */
    while (hi - lo > 1) {
        size_t mid = lo + (hi - lo) / 2;
        if (grid->cell_start[mid] <= j)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

/* Facets [begin, end) in grid order: each one's place, and its cell's number left in its centroid's
 * slot for pack_facets (it reads it back just before overwriting that slot, so the grid's cell is
 * reused rather than found again from the centroid, at no extra memory or cache line). */
static void place_facets(void *ctx, size_t begin, size_t end, size_t chunk) {
    const facet_job *job = ctx;
    const rs_grid *grid = job->grid;
    (void)chunk;
    size_t cell = cell_at(grid, begin);
    for (size_t j = begin; j < end; j++) {
        while (grid->cell_start[cell + 1] <= j)
            cell++;
        job->pk->facet_place[grid->facet_order[j]] = (uint32_t)j;
        uint32_t number = (uint32_t)cell;
        memcpy(&job->pk->facet_centroid[j], &number, sizeof number);
    }
}

/* Facets [begin, end) in the caller's order (mostly coherent in memory: their corners are read
 * here), written to their places in grid order. */
static void pack_facets(void *ctx, size_t begin, size_t end, size_t chunk) {
    const facet_job *job = ctx;
    const rs_problem *pb = job->pb;
    packed *pk = job->pk;
    (void)chunk;
    for (size_t q = begin; q < end; q++) {
        uint32_t j = pk->facet_place[q], cell;
        memcpy(&cell, &pk->facet_centroid[j], sizeof cell); /* place_facets' */
        const double *c = job->centroid + 3 * q;
        double n[3], area = 0, color[3] = {0, 0, 0};
        if (pb->indices) {
            const uint32_t *tri = pb->indices + 3 * (size_t)pb->facet_triangle[q];
            rs_triangle_normal(pb->xyz, tri, n, &area);
            if (pb->colors)
                rs_triangle_color(pb->colors, tri, color);
        } else { /* a point: its own normal, area and colour */
            for (int k = 0; k < 3; k++) {
                n[k] = pb->normal[3 * q + k];
                color[k] = pb->colors ? (double)pb->colors[3 * q + k] : 0;
            }
            area = pb->area[q];
        }
        cl_float4 cen = local_point(job->grid, c, job->grid->cell_coord + 4 * (size_t)cell);
        /* the ratio in double: area and mean area apart could each leave float's range; a point
         * of zero area (7 or more in one place) weighs as little as the kernels' exp2 can give */
        cen.s[3] = area > 0 ? (float)log2(area / pb->mean_area) : (float)-LOCAL_CLAMP;
        pk->facet_centroid[j] = cen;
        pk->facet_normal[j] = (cl_float4){{(float)n[0], (float)n[1], (float)n[2], 0}};
        if (pb->colors)
            pk->facet_color[j] =
                (cl_float4){{(float)color[0], (float)color[1], (float)color[2], 0}};
    }
}

static void facet_slots(void *ctx, size_t begin, size_t end, size_t chunk) {
    const facet_job *job = ctx;
    const rs_problem *pb = job->pb;
    packed *pk = job->pk;
    (void)chunk;
    for (size_t q = begin; q < end; q++) {
        /* a point is its own three corners (only the paper's mollification reads them) */
        const uint32_t point[3] = {(uint32_t)q, (uint32_t)q, (uint32_t)q};
        const uint32_t *tri = pb->indices ? pb->indices + 3 * (size_t)pb->facet_triangle[q] : point;
        for (int corner = 0; corner < 3; corner++)
            pk->facet_vertices[3 * q + corner] = pk->slot[tri[corner]];
    }
}

/* Frees *centroid (build_grid's) once the facets no longer need it. */
static rsmooth_status pack(const rs_problem *pb, const rs_grid *grid, double **centroid,
                           size_t lanes, packed *pk, rsmooth_error *error) {
    size_t nf = pb->facet_count, nv = pb->vertex_count;
    memset(pk, 0, sizeof *pk);
    pk->lanes = lanes;
    pk->facet_centroid = rs_alloc_array(nf, sizeof(cl_float4));
    pk->facet_normal = rs_alloc_array(nf, sizeof(cl_float4));
    pk->facet_vertices = rs_alloc_array(nf, 3 * sizeof(cl_uint));
    pk->facet_place = rs_alloc_array(nf, sizeof(cl_uint));
    pk->slot = rs_alloc_array(nv, sizeof(uint32_t));
    if (pb->colors)
        pk->facet_color = rs_alloc_array(nf, sizeof(cl_float4));
    if (!pk->facet_centroid || !pk->facet_normal || !pk->facet_vertices || !pk->facet_place ||
        !pk->slot || (pb->colors && !pk->facet_color))
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, "rsmooth_smooth",
                       "no memory for device staging arrays");

    /* Facets are read in the caller's order. What the pair loops read (centroid, normal) goes to
     * its place in grid order; the vertex slots, which only the per-facet normals kernel reads,
     * stay in the caller's order, with `place` to find the rest. The centroids go before the
     * blocks are packed: 24 bytes per facet less at that peak. */
    facet_job job = {pb, grid, *centroid, pk};
    rs_parallel_for(nf, PARALLEL_GRAIN, place_facets, &job);
    rs_parallel_for(nf, PARALLEL_GRAIN, pack_facets, &job);
    rs_free(*centroid);
    *centroid = NULL;
    job.centroid = NULL;
    rsmooth_status st = pack_blocks(pb, grid, pk, error);
    if (st != RSMOOTH_OK)
        return st;
    rs_parallel_for(nf, PARALLEL_GRAIN, facet_slots, &job);
    return RSMOOTH_OK;
}

/* Grid cells per reach: small cells hug the ball of reach around a block (less work wasted on
 * facets out of reach), large ones hold more vertices per block; measured on PoCL's CPU device
 * (rsmooth-bench filter), cells about two mean edges wide did best. RSMOOTH_CELLS_PER_REACH
 * overrides it, for such measurements. */
static int cells_per_reach(const rsmooth_context *ctx, const rs_problem *pb) {
    long forced = rs_environment_integer(&ctx->env, RS_ENV_CELLS_PER_REACH, 1, 8, 0);
    if (forced)
        return (int)forced;
    double cells = floor(pb->radius / (2 * pb->mean_edge_length));
    return cells < 1 || !isfinite(cells) ? 1 : cells > 3 ? 3 : (int)cells;
}

/* The grid over the facets' centroids, in a box that also holds every vertex of a facet, so the
 * kernels can form each facet's edges from its vertices' block positions (no vertex is clamped).
 * The centroids (*centroid, 3 per facet, the caller frees them) live on until the facets are
 * packed, which reads them instead of computing them again. */
typedef struct centroid_job {
    const rs_problem *pb;
    double *centroid;
    double (*box)[6]; /* per chunk: lo x, y, z, hi x, y, z */
} centroid_job;

static void centroids_and_box(void *ctx, size_t begin, size_t end, size_t chunk) {
    const centroid_job *job = ctx;
    const rs_problem *pb = job->pb;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t q = begin; q < end; q++) {
        /* a point is its own centroid and its one vertex */
        const uint32_t point[3] = {(uint32_t)q, (uint32_t)q, (uint32_t)q};
        const uint32_t *tri = pb->indices ? pb->indices + 3 * (size_t)pb->facet_triangle[q] : point;
        if (pb->indices)
            rs_facet_centroid(pb, q, job->centroid + 3 * q);
        else
            memcpy(job->centroid + 3 * q, pb->centroid + 3 * q, 3 * sizeof(double));
        for (int c = 0; c < 3; c++)
            for (int k = 0; k < 3; k++) {
                double x = pb->xyz[3 * (size_t)tri[c] + k];
                lo[k] = x < lo[k] ? x : lo[k];
                hi[k] = x > hi[k] ? x : hi[k];
            }
    }
    for (int k = 0; k < 3; k++) {
        job->box[chunk][k] = lo[k];
        job->box[chunk][3 + k] = hi[k];
    }
}

static rsmooth_status build_grid(rsmooth_context *ctx, const rs_problem *pb, rs_grid *grid,
                                 double **centroid_out, rsmooth_error *error) {
    size_t nf = pb->facet_count, chunks = rs_parallel_chunks(nf, PARALLEL_GRAIN);
    double *centroid = rs_alloc_array(nf, 3 * sizeof *centroid);
    double(*box)[6] = rs_alloc_array(chunks, sizeof *box);
    if (!centroid || !box) {
        rs_free(centroid);
        rs_free(box);
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, "rsmooth_smooth",
                       "no memory for %zu centroids", nf);
    }
    centroid_job job = {pb, centroid, box};
    rs_parallel_for(nf, PARALLEL_GRAIN, centroids_and_box, &job);
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t c = 0; c < chunks; c++)
        for (int k = 0; k < 3; k++) {
            lo[k] = box[c][k] < lo[k] ? box[c][k] : lo[k];
            hi[k] = box[c][3 + k] > hi[k] ? box[c][3 + k] : hi[k];
        }
    /* on the device where it sorts faster (rs_cl_device_grid), else (or where it declines the
     * grid) on the host: the same grid either way */
    int split = cells_per_reach(ctx, pb);
    bool done = false;
    rsmooth_status st = RSMOOTH_OK;
    if (rs_cl_device_grid(ctx))
        st = rs_cl_grid_build_columns(ctx, grid, centroid, nf, pb->radius, split, lo, hi, &done,
                                      error);
    if (st == RSMOOTH_OK && !done)
        st = rs_grid_build_columns(grid, centroid, nf, pb->radius, split, lo, hi, error);
    *centroid_out = centroid;
    rs_free(box);
    return st;
}

typedef struct result_job {
    const rs_problem *pb;
    const rs_result_sink *sink;
    const packed *pk;
    const cl_float *result, *extra; /* mapped block_result and block_extra */
    double h;
} result_job;

/* Positions (p + displacement, in double), k and confidence of vertices [begin, end). */
static void store_results(void *ctx, size_t begin, size_t end, size_t chunk) {
    const result_job *job = ctx;
    const rs_result_sink *sink = job->sink;
    const double mean_area = job->pb->mean_area, unscale = 1 / job->pb->scale;
    const size_t width = job->pk->lanes;
    (void)chunk;
    for (size_t v = begin; v < end; v++) {
        size_t b = job->pk->slot[v] / width, lane = job->pk->slot[v] % width;
        const cl_float *res = job->result + 4 * width * b + lane;
        const cl_float *ext = job->extra + 2 * width * b + lane;
        const double *p = job->pb->xyz + 3 * v;
        size_t to = sink->target ? sink->target[v] : v;
        double out[3];
        for (int k = 0; k < 3; k++)
            out[k] = p[k] + (double)res[k * width] * job->h;
        rs_store_position(sink->scalar, sink->positions, to, out, unscale);
        double k = (double)res[3 * width] * exp2(-(double)ext[width]) * mean_area;
        double kf = (double)ext[0] * mean_area;
        if (sink->weight)
            sink->weight[to] = rs_weight_value(k, unscale);
        if (sink->confidence)
            sink->confidence[to] = kf > 0 ? (float)fmin(1.0, k / kf) : 0.0f;
    }
}

typedef struct normal_job {
    const packed *pk;
    const cl_float4 *normal; /* mapped: the predictors' normals, in grid order */
    double *out;             /* 3 per facet, in the problem's order */
} normal_job;

static void store_normals(void *ctx, size_t begin, size_t end, size_t chunk) {
    const normal_job *job = ctx;
    (void)chunk;
    for (size_t q = begin; q < end; q++)
        for (int k = 0; k < 3; k++)
            job->out[3 * q + k] = (double)job->normal[job->pk->facet_place[q]].s[k];
}

/* One run on the device, its steps below in order: the host-side grid and packing, the buffers,
 * the predictors' normals, the robust pass, the results. */
typedef struct cl_run {
    rsmooth_context *ctx;
    const rs_problem *pb;
    const rs_result_sink *sink;
    rsmooth_error *error;
    rs_grid grid;
    packed pk;
    cl_mem buf[BUF_COUNT];
    cl_mem normals; /* the predictors' normals, once filtered */
    uint64_t bilateral_pairs;
    cl_float *result, *extra; /* mapped results, per block, as block_result and block_extra */
    cl_uint *pairs;           /* and block_pairs */
    double *out_normals;      /* the caller's, for the predictors' normals (optional) */
    cl_float4 *normal_map;    /* and those normals, mapped when out_normals takes them */
    double t_start, t_grid, t_upload, t_mollify, t_normals, t_robust;
} cl_run;

static const char where[] = "rsmooth_smooth";

/* The grid and the packed facets and vertex blocks, on the host. */
static rsmooth_status prepare_host(cl_run *r) {
    double *centroid = NULL; /* build_grid's, for pack */
    rsmooth_status st = build_grid(r->ctx, r->pb, &r->grid, &centroid, r->error);
    if (st == RSMOOTH_OK)
        st = pack(r->pb, &r->grid, &centroid, r->ctx->lanes, &r->pk, r->error);
    rs_free(centroid);
    if (st != RSMOOTH_OK)
        return st;
    rs_free(r->grid.facet_order); /* packing was its last use: 4 bytes per facet less at the peak */
    r->grid.facet_order = NULL;
    r->t_grid = rs_now_ms();
    return RSMOOTH_OK;
}

/* Every buffer of the run, refused whole (with the bytes it needs in *needed, for the tiles)
 * where they do not fit the device. */
static rsmooth_status create_buffers(cl_run *r, uint64_t *needed) {
    rsmooth_context *ctx = r->ctx;
    const rs_problem *pb = r->pb;
    const packed *pk = &r->pk;
    const rs_grid *grid = &r->grid;
    size_t nf = pb->facet_count, nc = grid->cell_count;
    size_t nb = pk->block_count, ns = nb * ctx->lanes; /* blocks and slots */
    bool paper_mollify = pb->mollify && !pb->bilateral;
    const struct {
        size_t size;
        void *host;
        cl_mem_flags flags;
    } spec[BUF_COUNT] = {
        [BUF_FACET_CENTROID] = {nf * sizeof(cl_float4), pk->facet_centroid, CL_MEM_READ_ONLY},
        /* the input normals, replaced in place by the mollified ones (bilateral: by the rounds
         * that write here) */
        [BUF_FACET_NORMAL] = {nf * sizeof(cl_float4), pk->facet_normal, CL_MEM_READ_WRITE},
        [BUF_FACET_VERTICES] = {nf * 3 * sizeof(cl_uint), pk->facet_vertices, CL_MEM_READ_ONLY},
        [BUF_FACET_PLACE] = {nf * sizeof(cl_uint), pk->facet_place, CL_MEM_READ_ONLY},
        [BUF_CELL_COORD] = {nc * 4 * sizeof(cl_int), grid->cell_coord, CL_MEM_READ_ONLY},
        [BUF_CELL_START] = {(nc + 1) * sizeof(cl_uint), grid->cell_start, CL_MEM_READ_ONLY},
        [BUF_COLUMN_FIRST] = {(grid->column_count + 1) * sizeof(cl_uint), grid->column_first,
                              CL_MEM_READ_ONLY},
        [BUF_COLUMN_TABLE] = {((size_t)grid->column_mask + 1) * sizeof(cl_int), grid->column_table,
                              CL_MEM_READ_ONLY},
        [BUF_BLOCK_POS] = {ns * 3 * sizeof(cl_float), pk->block_pos, CL_MEM_READ_ONLY},
        [BUF_BLOCK_CELL] = {nb * sizeof(cl_int4), pk->block_cell, CL_MEM_READ_ONLY},
        [BUF_BLOCK_OFFSET] = {ns * 3 * sizeof(cl_uchar), pk->block_offset, CL_MEM_READ_ONLY},
        [BUF_BLOCK_SHIFT] = {paper_mollify ? ns * 3 * sizeof(cl_float) : 0, NULL,
                             CL_MEM_READ_WRITE},
        [BUF_BLOCK_RESULT] = {ns * 4 * sizeof(cl_float), NULL, CL_MEM_WRITE_ONLY},
        [BUF_BLOCK_EXTRA] = {ns * 2 * sizeof(cl_float), NULL, CL_MEM_WRITE_ONLY},
        [BUF_BLOCK_PAIRS] = {nb * 2 * sizeof(cl_uint), NULL, CL_MEM_WRITE_ONLY},
        [BUF_FACET_SCRATCH] = {pb->bilateral ? nf * sizeof(cl_float4) : 0, NULL, CL_MEM_READ_WRITE},
        [BUF_CELL_PAIRS] = {pb->bilateral ? nc * sizeof(cl_ulong) : 0, NULL, CL_MEM_WRITE_ONLY},
        [BUF_FACET_COLOR] = {pb->colors ? nf * sizeof(cl_float4) : 0, pk->facet_color,
                             CL_MEM_READ_ONLY},
        [BUF_BLOCK_COLOR] = {pb->colors ? ns * 3 * sizeof(cl_float) : 0, pk->block_color,
                             CL_MEM_READ_ONLY},
    };
    uint64_t total = 0, largest = 0;
    for (int b = 0; b < BUF_COUNT; b++) {
        total += spec[b].size;
        largest = spec[b].size > largest ? spec[b].size : largest;
    }
    if (total > rs_cl_usable_memory(ctx) || largest > ctx->max_allocation) {
        *needed = total;
        return rs_fail(r->error, RSMOOTH_ERROR_OUT_OF_MEMORY, where,
                       "%zu facets need %llu bytes on %s (usable %llu, largest buffer %llu of at "
                       "most %llu)",
                       nf, (unsigned long long)total, ctx->device_name,
                       (unsigned long long)rs_cl_usable_memory(ctx), (unsigned long long)largest,
                       (unsigned long long)ctx->max_allocation);
    }
    /* Inputs are handed over in place where the device shares the host's memory (a CPU device
     * reads the staging arrays themselves: no copy, no second allocation; they are aligned for
     * it, see alloc.c), else copied at creation (rs_cl_input_flags). They stay alive until the
     * buffers are released. */
    for (int b = 0; b < BUF_COUNT; b++) {
        if (spec[b].size == 0) /* a buffer this run's mode does not use */
            continue;
        cl_int err = CL_SUCCESS;
        cl_mem_flags flags = spec[b].flags | (spec[b].host ? rs_cl_input_flags(ctx) : 0);
        r->buf[b] = clCreateBuffer(ctx->context, flags, spec[b].size, spec[b].host, &err);
        if (err != CL_SUCCESS)
            return rs_cl_fail(r->error, err, "clCreateBuffer", ctx->device_name);
    }
    cl_int err = clFinish(ctx->queue);
    if (err != CL_SUCCESS)
        return rs_cl_fail(r->error, err, "clFinish (upload)", ctx->device_name);
    r->t_upload = rs_now_ms();
    return RSMOOTH_OK;
}

/* The paper's mollification (Sec. 3.2): the vertices' shifts, then each facet's normal from its
 * shifted corners, in place of the input normal. */
static rsmooth_status run_mollify(cl_run *r) {
    rsmooth_context *ctx = r->ctx;
    const rs_problem *pb = r->pb;
    cl_mem *buf = r->buf;
    /* Lengths in cell units (h), so every float the kernels see is of order one. */
    const double h = r->grid.cell_size;
    cl_uint bcount = (cl_uint)r->pk.block_count, fcount = (cl_uint)pb->facet_count;
    cl_uint mask = r->grid.column_mask;
    cl_float mollify_reach2 = (cl_float)((pb->mollify_radius / h) * (pb->mollify_radius / h));
    /* Exponents in base 2 (the kernels' fast_exp2): 1 / 2 sigma^2 scaled by log2 e. */
    cl_float inv_2sm2 = (cl_float)(LOG2_E * h * h / (2 * pb->sigma_m * pb->sigma_m));
    arg_setter s = {ctx->kernels[RS_KERNEL_MOLLIFY], 0, CL_SUCCESS};
    arg(&s, sizeof bcount, &bcount);
    arg(&s, sizeof mollify_reach2, &mollify_reach2);
    arg(&s, sizeof inv_2sm2, &inv_2sm2);
    arg(&s, sizeof(cl_mem), &buf[BUF_BLOCK_POS]);
    arg(&s, sizeof(cl_mem), &buf[BUF_BLOCK_CELL]);
    arg(&s, sizeof(cl_mem), &buf[BUF_BLOCK_OFFSET]);
    arg(&s, sizeof(cl_mem), &buf[BUF_FACET_CENTROID]);
    arg_grid(&s, buf, &mask);
    arg(&s, sizeof(cl_mem), &buf[BUF_BLOCK_SHIFT]);
    arg(&s, sizeof(cl_mem), &buf[BUF_BLOCK_PAIRS]);
    cl_int err = s.err != CL_SUCCESS
                     ? s.err
                     : rs_cl_run_1d(ctx, pb, s.kernel, r->pk.block_count, 0, MOLLIFY_SHARE);
    if (err != CL_SUCCESS)
        return rs_cl_fail(r->error, err, "mollify_block", ctx->device_name);
    r->t_mollify = rs_now_ms();

    s = (arg_setter){ctx->kernels[RS_KERNEL_NORMALS], 0, CL_SUCCESS};
    arg(&s, sizeof fcount, &fcount);
    arg(&s, sizeof(cl_mem), &buf[BUF_FACET_VERTICES]);
    arg(&s, sizeof(cl_mem), &buf[BUF_FACET_PLACE]);
    arg(&s, sizeof(cl_mem), &buf[BUF_BLOCK_POS]);
    arg(&s, sizeof(cl_mem), &buf[BUF_BLOCK_CELL]);
    arg(&s, sizeof(cl_mem), &buf[BUF_BLOCK_OFFSET]);
    arg(&s, sizeof(cl_mem), &buf[BUF_FACET_NORMAL]);
    arg(&s, sizeof(cl_mem), &buf[BUF_BLOCK_SHIFT]);
    err = s.err != CL_SUCCESS
              ? s.err
              : rs_cl_run_1d(ctx, pb, s.kernel, pb->facet_count, MOLLIFY_SHARE, MOLLIFY_SHARE);
    if (err != CL_SUCCESS)
        return rs_cl_fail(r->error, err, "mollified_facet_normal", ctx->device_name);
    return RSMOOTH_OK;
}

/* The predictors' normals: the bilateral filter's rounds, the paper's mollification, or the
 * input normals as they are. */
static rsmooth_status run_normals(cl_run *r) {
    r->normals = r->buf[BUF_FACET_NORMAL];
    r->t_mollify = r->t_normals = r->t_upload;
    if (r->pb->bilateral) {
        cl_int err =
            rs_cl_run_bilateral(r->ctx, r->pb, &r->grid, r->buf, &r->normals, &r->bilateral_pairs);
        if (err != CL_SUCCESS)
            return rs_cl_fail(r->error, err, "bilateral_cell_normals", r->ctx->device_name);
        r->t_mollify = rs_now_ms();
    } else if (r->pb->mollify) {
        rsmooth_status st = run_mollify(r);
        if (st != RSMOOTH_OK)
            return st;
    } else {
        r->t_mollify = rs_now_ms();
    }
    r->t_normals = rs_now_ms();
    return RSMOOTH_OK;
}

/* The robust estimate (Eq. 3) of every vertex, with its weight and confidence. */
static rsmooth_status run_robust(cl_run *r) {
    rsmooth_context *ctx = r->ctx;
    const rs_problem *pb = r->pb;
    cl_mem *buf = r->buf;
    const double h = r->grid.cell_size;
    cl_uint bcount = (cl_uint)r->pk.block_count, mask = r->grid.column_mask;
    cl_float reach2 = (cl_float)((pb->radius / h) * (pb->radius / h));
    cl_float inv_2sf2 = (cl_float)(LOG2_E * h * h / (2 * pb->sigma_f * pb->sigma_f));
    cl_float inv_2sg2 =
        isinf(pb->sigma_g) ? 0.0f : (cl_float)(LOG2_E * h * h / (2 * pb->sigma_g * pb->sigma_g));
    /* the other influence functions take x^2 / sigma_g^2 itself */
    cl_float inv_sg2 = isinf(pb->sigma_g) ? 0.0f : (cl_float)(h * h / (pb->sigma_g * pb->sigma_g));
    cl_int influence = pb->influence;
    cl_int want_confidence = r->sink->confidence != NULL;
    cl_int predict_centroid = pb->predict_centroid;
    /* the colour factor's exponent, in base 2; colours have no length scale (finite however
     * small sigma_c is, so equal colours still give 0) */
    cl_int use_color = pb->colors != NULL;
    cl_float inv_2sc2 =
        use_color ? (cl_float)fmin(LOG2_E / (2 * pb->sigma_c * pb->sigma_c), FLT_MAX) : 0.0f;
    arg_setter s = {ctx->kernels[RS_KERNEL_ROBUST], 0, CL_SUCCESS};
    arg(&s, sizeof bcount, &bcount);
    arg(&s, sizeof reach2, &reach2);
    arg(&s, sizeof inv_2sf2, &inv_2sf2);
    arg(&s, sizeof inv_2sg2, &inv_2sg2);
    arg(&s, sizeof influence, &influence);
    arg(&s, sizeof inv_sg2, &inv_sg2);
    arg(&s, sizeof want_confidence, &want_confidence);
    arg(&s, sizeof predict_centroid, &predict_centroid);
    arg(&s, sizeof use_color, &use_color);
    arg(&s, sizeof inv_2sc2, &inv_2sc2);
    arg(&s, sizeof(cl_mem), &buf[BUF_BLOCK_POS]);
    arg(&s, sizeof(cl_mem), &buf[BUF_BLOCK_CELL]);
    arg(&s, sizeof(cl_mem), &buf[BUF_BLOCK_OFFSET]);
    arg(&s, sizeof(cl_mem), &buf[BUF_BLOCK_COLOR]); /* NULL without colour: never read */
    arg(&s, sizeof(cl_mem), &buf[BUF_FACET_CENTROID]);
    arg(&s, sizeof(cl_mem), &r->normals);
    arg(&s, sizeof(cl_mem), &buf[BUF_FACET_COLOR]);
    arg_grid(&s, buf, &mask);
    arg(&s, sizeof(cl_mem), &buf[BUF_BLOCK_RESULT]);
    arg(&s, sizeof(cl_mem), &buf[BUF_BLOCK_EXTRA]);
    arg(&s, sizeof(cl_mem), &buf[BUF_BLOCK_PAIRS]);
    cl_int err = s.err != CL_SUCCESS ? s.err
                                     : rs_cl_run_1d(ctx, pb, s.kernel, r->pk.block_count,
                                                    pb->mollify ? MOLLIFY_SHARE : 0, 1);
    if (err != CL_SUCCESS)
        return rs_cl_fail(r->error, err, "robust_block", ctx->device_name);
    r->t_robust = rs_now_ms();
    return RSMOOTH_OK;
}

/* The results mapped (not copied: a CPU device hands over its own memory), scattered to the
 * caller's vertices in the caller's type, and the run's figures added to *stats. */
/* Adds one run's stage times (up to t_end), cells and tile to `stats`; with `pairs`, the facet
 * pairs its blocks counted (on the host: the device store brings none back). */
static void add_run_stats(const cl_run *r, rs_run_stats *stats, double t_end, bool pairs) {
    stats->ms_grid += r->t_grid - r->t_start;
    stats->ms_upload += r->t_upload - r->t_grid;
    stats->ms_mollify += r->t_mollify - r->t_upload;
    stats->ms_normals += r->t_normals - r->t_mollify;
    stats->ms_robust += r->t_robust - r->t_normals;
    stats->ms_download += t_end - r->t_robust;
    const rs_problem *pb = r->pb;
    bool paper_mollify = pb->mollify && !pb->bilateral;
    for (size_t b = 0; pairs && b < r->pk.block_count; b++) {
        stats->pairs_mollify += paper_mollify ? (uint64_t)r->pairs[2 * b] * r->ctx->lanes : 0;
        stats->pairs_robust += (uint64_t)r->pairs[2 * b + 1] * r->ctx->lanes;
    }
    stats->pairs_mollify += r->bilateral_pairs;
    stats->cells += r->grid.cell_count;
    stats->tiles++;
}

static rsmooth_status collect_results(cl_run *r, rs_run_stats *stats) {
    rsmooth_context *ctx = r->ctx;
    const rs_problem *pb = r->pb;
    size_t nv = pb->vertex_count, nb = r->pk.block_count, ns = nb * ctx->lanes;
    const rs_result_sink *sink = r->sink;
    if (sink->device && !sink->target && sink->core_count >= nv && !sink->weight &&
        !sink->confidence && !r->out_normals) {
        /* rsmooth_smooth_cl: the positions go to the caller's buffer on the device, nothing
         * comes back (the pair counts, 8 bytes a block, are left out of the report too) */
        rsmooth_status st =
            rs_cl_store_device(ctx, sink->device, r->buf[BUF_BLOCK_RESULT], r->pk.slot, nv,
                               ctx->lanes, pb->scale, r->grid.cell_size, r->error);
        if (st == RSMOOTH_OK)
            add_run_stats(r, stats, rs_now_ms(), false);
        return st;
    }
    cl_int err = CL_SUCCESS;
    r->result = clEnqueueMapBuffer(ctx->queue, r->buf[BUF_BLOCK_RESULT], CL_TRUE, CL_MAP_READ, 0,
                                   ns * 4 * sizeof(cl_float), 0, NULL, NULL, &err);
    if (err == CL_SUCCESS)
        r->extra = clEnqueueMapBuffer(ctx->queue, r->buf[BUF_BLOCK_EXTRA], CL_TRUE, CL_MAP_READ, 0,
                                      ns * 2 * sizeof(cl_float), 0, NULL, NULL, &err);
    if (err == CL_SUCCESS)
        r->pairs = clEnqueueMapBuffer(ctx->queue, r->buf[BUF_BLOCK_PAIRS], CL_TRUE, CL_MAP_READ, 0,
                                      nb * 2 * sizeof(cl_uint), 0, NULL, NULL, &err);
    if (err == CL_SUCCESS && r->out_normals && pb->mollify)
        r->normal_map =
            clEnqueueMapBuffer(ctx->queue, r->normals, CL_TRUE, CL_MAP_READ, 0,
                               pb->facet_count * sizeof(cl_float4), 0, NULL, NULL, &err);
    if (err != CL_SUCCESS)
        return rs_cl_fail(r->error, err, "clEnqueueMapBuffer", ctx->device_name);
    if (r->normal_map) {
        normal_job nj = {&r->pk, r->normal_map, r->out_normals};
        rs_parallel_for(pb->facet_count, PARALLEL_GRAIN, store_normals, &nj);
    }
    result_job rj = {pb, r->sink, &r->pk, r->result, r->extra, r->grid.cell_size};
    rs_parallel_for(r->sink->core_count < nv ? r->sink->core_count : nv, PARALLEL_GRAIN,
                    store_results, &rj);
    add_run_stats(r, stats, rs_now_ms(), true);
    return RSMOOTH_OK;
}

static void release_run(cl_run *r) {
    rsmooth_context *ctx = r->ctx;
    if (r->result)
        clEnqueueUnmapMemObject(ctx->queue, r->buf[BUF_BLOCK_RESULT], r->result, 0, NULL, NULL);
    if (r->extra)
        clEnqueueUnmapMemObject(ctx->queue, r->buf[BUF_BLOCK_EXTRA], r->extra, 0, NULL, NULL);
    if (r->pairs)
        clEnqueueUnmapMemObject(ctx->queue, r->buf[BUF_BLOCK_PAIRS], r->pairs, 0, NULL, NULL);
    if (r->normal_map)
        clEnqueueUnmapMemObject(ctx->queue, r->normals, r->normal_map, 0, NULL, NULL);
    if (r->result || r->extra || r->pairs || r->normal_map)
        clFinish(ctx->queue);
    for (int b = 0; b < BUF_COUNT; b++)
        if (r->buf[b])
            clReleaseMemObject(r->buf[b]);
    packed_free(&r->pk);
    rs_grid_free(&r->grid);
}

rsmooth_status rs_cl_run(rsmooth_context *ctx, const rs_problem *pb, const rs_result_sink *sink,
                         rs_run_stats *stats, uint64_t *needed, rsmooth_error *error) {
    return rs_cl_run_normals(ctx, pb, sink, NULL, stats, needed, error);
}

rsmooth_status rs_cl_run_normals(rsmooth_context *ctx, const rs_problem *pb,
                                 const rs_result_sink *sink, double *out_normals,
                                 rs_run_stats *stats, uint64_t *needed, rsmooth_error *error) {
    cl_run r;
    memset(&r, 0, sizeof r);
    r.ctx = ctx;
    r.out_normals = out_normals;
    r.pb = pb;
    r.sink = sink;
    r.error = error;
    r.t_start = r.t_grid = r.t_upload = rs_now_ms();
    *needed = 0;
    rsmooth_status st = prepare_host(&r);
    if (st == RSMOOTH_OK)
        st = create_buffers(&r, needed);
    if (st == RSMOOTH_OK)
        st = run_normals(&r);
    if (st == RSMOOTH_OK)
        st = run_robust(&r);
    if (st == RSMOOTH_OK)
        st = collect_results(&r, stats);
    release_run(&r);
    return st;
}

void rs_cl_report(rsmooth_report *report, const rs_problem *pb, const rs_run_stats *stats,
                  const char *device, double t_start, double t_facets) {
    rs_report_problem(report, pb, 0, device);
    report->grid_cell_count = stats->cells;
    report->ms_facets = t_facets - t_start;
    report->ms_grid = stats->ms_grid;
    report->ms_upload = stats->ms_upload;
    report->ms_mollify = stats->ms_mollify;
    report->ms_normals = stats->ms_normals;
    report->ms_robust = stats->ms_robust;
    report->ms_download = stats->ms_download;
    report->ms_total = rs_now_ms() - t_start;
    report->pairs_mollify = stats->pairs_mollify;
    report->pairs_robust = stats->pairs_robust;
    report->tiles = stats->tiles > 0 ? stats->tiles : 1; /* no facet: one trivial run */
}
