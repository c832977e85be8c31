/* rsmooth_stream_smooth: the filter on a mesh file larger than memory.
 *
 *   1. the vertex block read (held whole when it fits, else a run of vertices at a time), the
 *      faces fanned into triangles on disk, and those joined with their corners' positions
 *      (stream_corners.c): no later step looks a position up by vertex id;
 *   2. the mesh's figures (stream_stats.c) and the halo of a piece (rsmooth_piece_halo);
 *   3. the pieces and their lists on disk (stream_pieces.c), sized to the memory cap;
 *   4. the output: a copy of the input, unnamed until it is complete;
 *   5. each piece (this rank's) filtered (rsmooth_smooth_piece, its memory kept for the next)
 *      and its core vertices written into the copy at their rows;
 *   6. the copy named as the output, atomically.
 * Each of 1-3 and 5 is a step; more steps run them again. The normal update stage
 * (params.vertex_updates, stream_stage.c) first gathers its reach's shares, then runs a step per
 * cycle; the filter runs a step per pass (params.passes). Each step after the first reads the
 * positions the one before wrote into a double block (stream_passes.c), the triangles kept; only
 * the last writes into the copy. Ranks (the MPI driver) run 1-3 alike, rank 0 makes the copy,
 * and each writes its own pieces' rows: disjoint bytes of one file, and all of a step's before
 * any rank starts the next. */
#define _GNU_SOURCE /* O_TMPFILE, linkat, renameat2 */
#include "io/output_file.h"
#include "stages/normal_update.h"
#include "stream/stream_internal.h"

#include <errno.h>
#include <fcntl.h>
#include <libgen.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define DEFAULT_MAX_MEMORY (1ull << 30)
/* What a piece holds per core vertex at its peak: its lists, its arrays, the filter's packed
 * facets and device buffers (a CPU device's are host memory), for about two facets per vertex
 * and their halo. Measured peak over the cap's share on the demo shapes: see README "Large
 * meshes". */
#define PIECE_BYTES_PER_VERTEX 1200
/* The normal update stage's steps per facet of a piece, its wide halo's included: its lists
 * (each facet's neighbours within the guided reach, its patch and the patch's edges) and work
 * arrays. Measured: about 1000 on the 4M terrain under 256M. */
#define STAGE_BYTES_PER_FACET 1100
/* Working memory besides the positions and the pieces: read buffers of 1 MB, the cell grid
 * (GRID_BYTES) and the lists' write buffers (as much again). */
#define GRID_BYTES (2ull << 20)
#define FIXED_BYTES (8ull << 20)
/* The smallest piece worth its halo. */
#define MIN_PIECE_VERTICES 1024

rsmooth_status rsmooth_stream_options_init(rsmooth_stream_options *options) {
    if (!options)
        return RSMOOTH_ERROR_INVALID_ARGUMENT;
    memset(options, 0, sizeof *options);
    options->struct_size = sizeof *options;
    return RSMOOTH_OK;
}

void rsmooth_stream_report_init(rsmooth_stream_report *report) {
    if (!report)
        return;
    memset(report, 0, sizeof *report);
    report->struct_size = sizeof *report;
}

rsmooth_status rsmooth_stream_vertex_count(const char *path, uint64_t *vertex_count,
                                           rsmooth_error *error) {
    static const char where[] = "rsmooth_stream_vertex_count";
    rs_error_clear(error);
    if (!path || !vertex_count)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "%s is NULL",
                       path ? "vertex_count" : "path");
    rs_stream_ply ply;
    rsmooth_status st = rs_stream_ply_open(&ply, path, DEFAULT_MAX_MEMORY / 4, error);
    if (st == RSMOOTH_OK)
        *vertex_count = ply.vertex_count;
    rs_stream_ply_close(&ply); /* (what a failed open holds too) */
    return st;
}

typedef struct stream_call {
    rsmooth_context *ctx;
    const char *input, *output;
    rsmooth_params params; /* the caller's, progress taken out (pieces report through us) */
    const rsmooth_params *caller_params;
    rsmooth_stream_options opt;
    rsmooth_stream_report rep;
    char dir[4096]; /* temporaries */
    rs_stream_ply ply;
    rs_stream_vertices vertices; /* held whole, or a run at a time */
    bool held;                   /* whole, from the plan to the end: the lists hold ids alone */
    rs_stream_corners corners;   /* the triangles with their corners' positions */
    rs_output out;               /* the output: its target, and the copy the results go into */
    uint64_t triangle_count;
    int ids_fd; /* the triangles' vertex ids, kept while a step is to come */
    /* The steps, each streamed (a plan, then the pieces): with the stage, its reach's shares and
     * its cycles; then the filter's passes. A position step (a cycle or a pass) reads what the
     * one before wrote (the first, the input), the last writes the output. */
    int steps, step;
    int cycles;             /* the stage's (0: none) */
    rs_stage_setting stage; /* its widths in mesh units once the input's unit is known */
    rs_stage_whole whole;   /* its scale and reach, of the input */
    double displacement;    /* how far a vertex lies from its input position, at most */
    double moved;           /* the same, of this rank's pieces in the step running */
    double input_longest;   /* the input's longest edge */
    int passes;             /* of the filter (params.passes; 0: the input comes back) */
    int pass;               /* the one running, from 0 */
    rs_pass_rule rule;      /* what the in-memory loop does after each pass */
    rs_pass_store store;    /* the positions between passes (passes above 1) */
    rs_stream_ply *source;  /* the positions this pass reads: the input's, or a block */
    uint64_t output_size;   /* the copy's, where a rank's store begins */
    rs_stream_stats stats;
    double halo;
    uint64_t piece_vertices;
    rs_stream_pieces pieces;
} stream_call;

typedef enum step_kind { STEP_SHARES, STEP_CYCLE, STEP_PASS } step_kind;

static step_kind kind_of(const stream_call *c) {
    if (c->cycles == 0)
        return STEP_PASS;
    return c->step == 0 ? STEP_SHARES : c->step <= c->cycles ? STEP_CYCLE : STEP_PASS;
}

/* The position steps (the cycles, then the passes) from 0; the shares' step is -1. */
static int position_step(const stream_call *c) {
    return c->cycles ? c->step - 1 : c->step;
}

static bool last_position_step(const stream_call *c) {
    return position_step(c) + 1 == c->cycles + c->passes;
}

static double now_ms(void) {
    return rs_now_ms();
}

static int sync_ranks(const stream_call *c, int status) {
    return c->opt.ranks > 1 && c->opt.sync ? c->opt.sync(c->opt.sync_user, status) : status;
}

/* `fraction` of the pass running, as a fraction of the whole call. */
static bool report_progress(const stream_call *c, double fraction) {
    const rsmooth_params *p = c->caller_params;
    if (!p)
        return true;
    if (c->steps > 1)
        fraction = (c->step + fraction) / c->steps;
    if (p->progress)
        p->progress(p->progress_user, fraction);
    return !p->progress_cancel || p->progress_cancel(p->progress_user, fraction) == 0;
}

/* The output's folder, for the temporaries and the partial output. */
static void output_dir(const char *output, char *dir, size_t size) {
    snprintf(dir, size, "%s", output);
    char *slash = strrchr(dir, '/');
    if (!slash)
        snprintf(dir, size, ".");
    else if (slash == dir)
        dir[1] = 0;
    else
        *slash = 0;
}

/* The temporaries' folder: options->tmpdir (an existing folder, its name whole), else the output's.
 */
static rsmooth_status check_tmpdir(stream_call *c, rsmooth_error *error) {
    if (!c->opt.tmpdir) {
        output_dir(c->output, c->dir, sizeof c->dir);
        return RSMOOTH_OK;
    }
    if (!c->opt.tmpdir[0])
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, RS_STREAM_WHERE,
                       "options->tmpdir is empty: name a folder, or NULL for the output's");
    if (strlen(c->opt.tmpdir) >= sizeof c->dir)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, RS_STREAM_WHERE,
                       "options->tmpdir is %zu bytes long: at most %zu", strlen(c->opt.tmpdir),
                       sizeof c->dir - 1);
    struct stat sb;
    if (stat(c->opt.tmpdir, &sb) != 0 || !S_ISDIR(sb.st_mode))
        return rs_fail(error, RSMOOTH_ERROR_IO, RS_STREAM_WHERE, "options->tmpdir %s: %s",
                       c->opt.tmpdir,
                       stat(c->opt.tmpdir, &sb) != 0 ? strerror(errno) : "not a folder");
    snprintf(c->dir, sizeof c->dir, "%s", c->opt.tmpdir);
    return RSMOOTH_OK;
}

/* The caller's params taken apart: the stage's cycles and the passes are this call's steps, the
 * pieces' params one pass's. Checked before any file is read. */
static rsmooth_status take_params(stream_call *c, const rsmooth_params *params,
                                  rsmooth_error *error) {
    c->caller_params = params;
    if (params)
        c->params = *params;
    else
        rsmooth_params_init(&c->params);
    rsmooth_params *p = &c->params;
    p->progress = NULL;
    p->progress_cancel = NULL;
    if (p->passes < 0 || p->passes > RS_MAX_ROUNDS)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, RS_STREAM_WHERE,
                       "passes must be in [0, %d] (got %d)", RS_MAX_ROUNDS, p->passes);
    if (p->vertex_updates < 0 || p->vertex_updates > RS_MAX_UPDATES)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, RS_STREAM_WHERE,
                       "vertex_updates must be in [0, %d] (got %d)", RS_MAX_UPDATES,
                       p->vertex_updates);
    if (p->vertex_updates > 0 && p->stage_normals == RSMOOTH_STAGE_NORMALS_LEARNED)
        return rs_fail(error, RSMOOTH_ERROR_UNSUPPORTED, RS_STREAM_WHERE,
                       "stage_normals learned: streaming runs the guided stage only (yet)");
    c->passes = p->passes;
    c->rule.mask = p->move_mask;
    c->cycles = p->vertex_updates > 0 ? p->stage_repeats : 0;
    c->stage = (rs_stage_setting){.sigma_s = p->guided_sigma_s,
                                  .sigma_n = p->guided_sigma_n,
                                  .radius = p->guided_radius,
                                  .rounds = p->guided_rounds,
                                  .updates = p->vertex_updates,
                                  .cycles = 1};
    p->passes = 1;
    p->move_mask = NULL;
    p->vertex_updates = 0;
    double halo = 0; /* the rest of the params' checks (the stage's widths among them) */
    rsmooth_status st = rsmooth_piece_halo(p, 1, 0, &halo, error);
    if (st != RSMOOTH_OK)
        return st;
    c->rule.keep_confidence = c->passes > 1 ? p->pass_confidence : 0;
    c->steps = (c->cycles ? 1 + c->cycles : 0) + c->passes;
    if (c->steps == 0) /* nothing runs: one plan checks the mesh, the input comes back */
        c->steps = 1;
    return RSMOOTH_OK;
}

static rsmooth_status check_arguments(stream_call *c, const rsmooth_params *params,
                                      const rsmooth_stream_options *options, rsmooth_error *error) {
    if (!c->input || !c->output)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, RS_STREAM_WHERE, "%s is NULL",
                       c->input ? "output" : "input");
    rsmooth_stream_options_init(&c->opt);
    if (options) {
        if (options->struct_size < sizeof *options)
            return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, RS_STREAM_WHERE,
                           "options->struct_size %zu: call rsmooth_stream_options_init first",
                           options->struct_size);
        c->opt = *options;
    }
    if (c->opt.ranks < 0)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, RS_STREAM_WHERE,
                       "options->ranks %d: give 0 or 1 alone, else the number of ranks",
                       c->opt.ranks);
    if (c->opt.ranks > 1 && (c->opt.rank < 0 || c->opt.rank >= c->opt.ranks))
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, RS_STREAM_WHERE,
                       "options->rank %d of %d ranks: give a rank in [0, ranks)", c->opt.rank,
                       c->opt.ranks);
    if (c->opt.ranks <= 1 && c->opt.rank != 0)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, RS_STREAM_WHERE,
                       "options->rank %d with options->ranks %d: alone, the rank is 0", c->opt.rank,
                       c->opt.ranks);
    if (c->opt.ranks > 1 && !c->opt.sync) /* each rank would write its own pieces only */
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, RS_STREAM_WHERE,
                       "options->ranks %d without options->sync: the ranks cannot agree, and "
                       "each would write only its own pieces",
                       c->opt.ranks);
    if (c->opt.ranks <= 1) {
        c->opt.ranks = 1;
        c->opt.rank = 0;
    }
    if (c->opt.max_memory == 0)
        c->opt.max_memory = DEFAULT_MAX_MEMORY;
    rsmooth_status st = take_params(c, params, error);
    if (st == RSMOOTH_OK)
        st = check_tmpdir(c, error);
    if (st != RSMOOTH_OK)
        return st;
    /* what the command checks for its in-memory outputs: only files, links to them written
     * through, nothing replaced unasked */
    return rs_output_resolve(&c->out, c->output, c->opt.replace != 0, RS_STREAM_REPLACE_HINT,
                             RS_STREAM_WHERE, error);
}

static rsmooth_status cancelled(const stream_call *c, double fraction, rsmooth_error *error) {
    return report_progress(c, fraction)
               ? RSMOOTH_OK
               : rs_fail(error, RSMOOTH_ERROR_CANCELLED, RS_STREAM_WHERE, "cancelled");
}

/* Step 1: the vertices (their extent), the triangles, and the corner records. The positions get
 * what the cap leaves beside the fixed buffers: all of them when they fit in half of it (then
 * they stay, and the passes after need not read them again), else runs as long as the cap
 * allows, one pass over the triangles per run. The first pass reads the input's positions and
 * writes the triangles; a later one reads the positions the pass before wrote. */
static rsmooth_status read_input(stream_call *c, rs_stream_extent *extent, rsmooth_error *error) {
    bool f32 = c->source->xyz_type == RS_PLY_FLOAT32;
    uint64_t position_bytes = c->ply.vertex_count * 3 * (f32 ? 4 : 8);
    uint64_t room = c->opt.max_memory - FIXED_BYTES;
    bool hold = position_bytes <= room / 2;
    rsmooth_status st = rs_stream_vertices_open(&c->vertices, c->source,
                                                hold ? position_bytes : room, extent, error);
    if (st == RSMOOTH_OK)
        st = cancelled(c, 0.03, error);
    if (st != RSMOOTH_OK)
        return st;
    if (c->ids_fd < 0) {
        c->ids_fd = rs_stream_temporary(c->dir);
        if (c->ids_fd < 0)
            return rs_fail(error, RSMOOTH_ERROR_IO, RS_STREAM_WHERE,
                           "cannot create a temporary file in %s: %s", c->dir, strerror(errno));
        st = rs_stream_ply_write_triangles(&c->ply, c->ids_fd, c->dir, &c->triangle_count, error);
        if (st == RSMOOTH_OK && c->ply.face_count == 0) /* the in-memory reader's word for it */
            st = rs_fail_parse(error, -1, (int64_t)c->ply.size, RS_STREAM_WHERE,
                               "%s: %llu vertices but no faces and no vertex normals: a mesh "
                               "needs faces, a point cloud normals (nx, ny, nz)",
                               c->input, (unsigned long long)c->ply.vertex_count);
    }
    c->corners.ids_fd = c->ids_fd;
    if (st == RSMOOTH_OK)
        st = rs_stream_corners_make(&c->vertices, hold, c->ids_fd, c->ply.id_bytes,
                                    c->triangle_count, c->dir, &c->corners, error);
    if (st == RSMOOTH_OK && !c->corners.held)
        rs_stream_vertices_release(&c->vertices); /* the statistics get the room */
    return st;
}

/* The triangles' ids once the records (or the pieces' lists) hold them: their disk comes back,
 * unless a later pass reads them again. */
static void drop_triangle_ids(stream_call *c) {
    if (c->ids_fd >= 0 && c->step + 1 >= c->steps) {
        close(c->ids_fd);
        c->ids_fd = -1;
    }
    c->corners.ids_fd = -1;
}

/* The input's header, and whether the cap can hold anything at all. */
static rsmooth_status open_input(stream_call *c, rsmooth_error *error) {
    /* the header, its parse and the output's: about three times its size */
    rsmooth_status st = rs_stream_ply_open(&c->ply, c->input, c->opt.max_memory / 4, error);
    if (st != RSMOOTH_OK)
        return st;
    c->rep.vertex_count = c->ply.vertex_count;
    c->rep.face_count = c->ply.face_count;
    uint64_t cap = c->opt.max_memory;
    uint64_t least = FIXED_BYTES + MIN_PIECE_VERTICES * PIECE_BYTES_PER_VERTEX;
    if (cap < least)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, RS_STREAM_WHERE,
                       "%s: a memory cap of %.1f MB is too small: its buffers and the smallest "
                       "piece take %.1f MB; give at least %llu MB",
                       c->input, (double)cap / (1 << 20), (double)least / (1 << 20),
                       (unsigned long long)((least >> 20) + 1));
    c->source = &c->ply;
    return RSMOOTH_OK;
}

/* The first step's figures: the input's unit, which fixes the widths in mesh units for every step
 * after (as the in-memory loops fix them: the stage and the passes after the first), and the
 * stage's scale. */
static void input_figures(stream_call *c) {
    double unit = c->stats.mean_edge_length;
    c->rep.mean_edge_length = unit;
    c->input_longest = c->stats.longest_edge;
    rsmooth_params *p = &c->params;
    if ((c->cycles > 0 || c->passes > 1) && !p->absolute && unit > 0) {
        p->sigma_f *= unit;
        p->sigma_g *= unit; /* +INFINITY stays */
        p->normal_sigma_s *= unit;
        c->stage.sigma_s *= unit;
        p->absolute = 1;
    }
    c->whole.scale = rs_stage_scale_of(c->stats.magnitude, c->stage.sigma_s);
}

/* The mesh's figures for this step, and the halo its pieces need. */
static rsmooth_status figures(stream_call *c, const rs_stream_extent *extent, uint64_t held,
                              rsmooth_error *error) {
    rsmooth_status st =
        rs_stream_statistics(&c->corners, c->ply.vertex_count, extent,
                             c->opt.max_memory - held - FIXED_BYTES, &c->stats, error);
    if (!c->corners.held) /* the records hold the ids too */
        drop_triangle_ids(c);
    if (st != RSMOOTH_OK)
        return st;
    if (c->step == 0)
        input_figures(c);
    switch (kind_of(c)) {
    case STEP_SHARES:
        c->halo = rs_stage_shares_halo(c->stats.longest_edge);
        break;
    case STEP_CYCLE:
        c->halo = rs_stage_cycle_halo(&c->stage, fmax(c->input_longest, c->stats.longest_edge),
                                      c->whole.reach, c->displacement);
        break;
    case STEP_PASS: /* from the reach's bound: the pieces are counted in the pass measuring it */
        st = rsmooth_piece_halo(&c->params, c->stats.mean_edge_length, c->stats.reach_bound,
                                &c->halo, error);
        break;
    }
    c->rep.halo = c->halo;
    return st;
}

/* A length in the step's mean edges (about the vertices' spacing on a surface). */
static double in_mean_edges(const stream_call *c, double length) {
    return length / (c->stats.mean_edge_length > 0 ? c->stats.mean_edge_length : 1);
}

/* The cap a stage piece needs: a core of the smallest piece's vertices and `halo` around it, on a
 * surface (about 2 facets a vertex, a vertex a mean edge apart). */
static double stage_cap_needed(const stream_call *c, uint64_t room, double halo) {
    double side = sqrt((double)MIN_PIECE_VERTICES) + 2 * in_mean_edges(c, halo);
    return 2 * side * side * STAGE_BYTES_PER_FACET + (double)(c->opt.max_memory - room);
}

/* The stage's pieces: their facets, halo included, bounded by what `room` holds; their cores as
 * large as the halo around them allows (as stage_cap_needed reckons), which the cut corrects where
 * a piece still holds more. A cap too small for the halo is refused with the size it needs: at
 * the first step already for the first cycle's (its reach taken as radius mean edges, and a
 * quarter more for what the cycles move), so that a run seldom stops later. */
static rsmooth_status stage_pieces(stream_call *c, uint64_t room, uint64_t *facets_max,
                                   rsmooth_error *error) {
    *facets_max = room / STAGE_BYTES_PER_FACET;
    double halo = c->halo;
    if (kind_of(c) == STEP_SHARES)
        halo =
            fmax(halo, 1.25 * rs_stage_cycle_halo(&c->stage, c->stats.longest_edge,
                                                  c->stage.radius * c->stats.mean_edge_length, 0));
    double needed = stage_cap_needed(c, room, halo);
    if (needed > (double)c->opt.max_memory)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, RS_STREAM_WHERE,
                       "%s: the normal update stage's pieces reach %.0f mean edges beyond their "
                       "vertices: a memory cap of %.1f MB cannot hold one; give at least %.0f MB",
                       c->input, in_mean_edges(c, halo), (double)c->opt.max_memory / (1 << 20),
                       ceil(needed / (1 << 20)));
    double side = sqrt((double)*facets_max / 2) - 2 * in_mean_edges(c, c->halo);
    c->piece_vertices = side > 1 ? (uint64_t)(side * side) : 1;
    return RSMOOTH_OK;
}

/* Steps 1-3 of a step: everything before the output is touched (the first step) or the step's
 * results are written. */
static rsmooth_status plan(stream_call *c, rsmooth_error *error) {
    double t0 = now_ms();
    rs_stream_extent extent;
    rsmooth_status st = read_input(c, &extent, error);
    if (st == RSMOOTH_OK)
        st = cancelled(c, 0.08, error);
    if (st != RSMOOTH_OK)
        return st;
    c->rep.triangle_count = c->triangle_count;
    c->rep.ms_read += now_ms() - t0;

    double t1 = now_ms();
    /* the positions' bytes in memory: all of them, or none (released after the records) */
    uint64_t held = c->vertices.xyz ? c->vertices.run * 3 * (c->vertices.f32 ? 4 : 8) : 0;
    st = figures(c, &extent, held, error);
    if (st != RSMOOTH_OK)
        return st;
    c->rep.ms_statistics += now_ms() - t1;
    st = cancelled(c, 0.15, error);
    if (st != RSMOOTH_OK)
        return st;

    double t2 = now_ms();
    /* the pieces have the cap but the fixed buffers and the positions when those are held (the
     * lists then hold ids alone); else the positions are let go first */
    uint64_t cap = c->opt.max_memory;
    c->held = c->corners.held != NULL;
    held = c->held ? held : 0;
    uint64_t room = cap - held - FIXED_BYTES, facets_max = 0;
    if (kind_of(c) == STEP_PASS)
        c->piece_vertices = room / PIECE_BYTES_PER_VERTEX;
    else {
        st = stage_pieces(c, room, &facets_max, error);
        if (st != RSMOOTH_OK)
            return st;
    }
    uint64_t planned = held + FIXED_BYTES +
                       (facets_max ? facets_max * STAGE_BYTES_PER_FACET
                                   : c->piece_vertices * PIECE_BYTES_PER_VERTEX);
    if (planned > c->rep.memory_planned)
        c->rep.memory_planned = planned;
    rs_stream_pieces_free(&c->pieces);
    c->stats.parts_tested = c->step > 0;
    st = rs_stream_pieces_build(&c->vertices, &c->corners, &c->stats, c->halo, c->piece_vertices,
                                facets_max, GRID_BYTES, c->opt.rank, c->opt.ranks,
                                kind_of(c) == STEP_SHARES, c->dir, &c->pieces, error);
    if (st == RSMOOTH_OK && c->stats.reach > c->stats.reach_bound) /* (the bound's premise) */
        st = rs_fail(error, RSMOOTH_ERROR_NUMERICAL, RS_STREAM_WHERE,
                     "%s: a facet's corner lies %g from its centroid, beyond the %g its longest "
                     "edge allows: the pieces' halo would leave facets out",
                     c->input, c->stats.reach, c->stats.reach_bound);
    if (st == RSMOOTH_OK && !c->stats.whole && c->step == 0)
        st = rs_fail(error, RSMOOTH_ERROR_UNSUPPORTED, RS_STREAM_WHERE,
                     "%s holds parts of very different size, or vertices far off the surface "
                     "(triangles out of scale with the rest): streaming does not keep them "
                     "apart yet; smooth it without --max-memory",
                     c->input);
    c->rep.facet_count = c->stats.facet_count;
    /* at their largest, beside the pieces' lists: the triangles' ids, and the corner records
     * when they were written (the positions not held) */
    uint64_t ids = 3 * c->ply.id_bytes * c->triangle_count;
    uint64_t records = c->corners.fd >= 0 ? c->corners.record * c->triangle_count : 0;
    /* the pieces' lists (and the positions, when held) hold what the filter needs: the rest goes */
    if (!c->held)
        rs_stream_vertices_release(&c->vertices);
    c->corners.held = NULL;
    if (c->corners.fd >= 0)
        close(c->corners.fd);
    c->corners.fd = -1;
    drop_triangle_ids(c);
    if (st != RSMOOTH_OK)
        return st;
    c->rep.pieces += c->pieces.count;
    c->rep.position_runs += c->vertices.runs_read;
    c->rep.vertex_id_bits = (unsigned)(8 * c->ply.id_bytes);
    /* a later step keeps the ids beside the lists, and the blocks between steps */
    uint64_t kept = c->ids_fd >= 0 ? ids : 0;
    uint64_t store = c->steps > 1 && c->opt.ranks == 1
                         ? rs_pass_store_bytes(c->ply.vertex_count, c->triangle_count,
                                               c->rule.keep_confidence > 0, c->cycles > 0)
                         : 0;
    uint64_t joining = ids + records + store,
             listing = (records ? records : ids) + c->pieces.temporary_bytes + kept + store;
    uint64_t temporary = joining > listing ? joining : listing;
    if (temporary > c->rep.temporary_bytes)
        c->rep.temporary_bytes = temporary;
    c->rep.ms_buckets += now_ms() - t2;
    return cancelled(c, 0.2, error);
}

/* Step 4: the copy of the input the results go into, beside the output's target. Alone: unnamed
 * where the system allows, until step 6. Ranks: a named partial file (output_file.h), made by rank
 * 0 and opened by the others once it exists. */
static rsmooth_status make_copy(stream_call *c, rsmooth_error *error) {
    rsmooth_status st = c->opt.ranks > 1
                            ? rs_output_create_partial(&c->out, true, RS_STREAM_WHERE, error)
                            : rs_output_create(&c->out, RS_STREAM_WHERE, error);
    if (st != RSMOOTH_OK)
        return st;
    if (!rs_stream_ply_write_copy(&c->ply, c->out.fd))
        return rs_fail(error, RSMOOTH_ERROR_IO, RS_STREAM_WHERE, "cannot write %s: %s", c->output,
                       strerror(errno));
    return RSMOOTH_OK;
}

/* The filter on an assembled piece (k vertices at xyz, its n core vertices first; m triangles):
 * the core's results into `out`. It is handed over in internal units, its positions times the
 * whole mesh's scale (exact: a power of two) and the figures as the in-memory path holds them, at
 * scale 1: in the caller's units a mesh at 1e-300 has no double for its mean area. The results
 * come back divided by the scale, as the in-memory path divides them. */
static rsmooth_status filter_piece(stream_call *c, double *xyz, size_t k, const uint32_t *tri,
                                   size_t m, size_t n, double *out, float *confidence,
                                   rsmooth_error *error) {
    if (c->stats.facet_count == 0) { /* nothing moves, as in memory (and no mean area) */
        memcpy(out, xyz, n * 3 * sizeof *out);
        for (size_t v = 0; confidence && v < n; v++)
            confidence[v] = 0;
        return RSMOOTH_OK;
    }
    const double scale = c->stats.scale;
    for (size_t i = 0; i < 3 * k; i++)
        xyz[i] *= scale;
    rsmooth_params params = c->params; /* absolute widths: in internal units too */
    if (params.absolute) {
        params.sigma_f *= scale;
        params.sigma_g *= scale; /* +INFINITY stays */
        params.normal_sigma_s *= scale;
    }
    rsmooth_piece_info info;
    rsmooth_piece_info_init(&info);
    info.core_count = n;
    info.mean_edge_length = c->stats.scaled_mean_edge_length;
    info.mean_area = c->stats.scaled_mean_area;
    info.scale = 1;
    info.keep_memory = 1; /* for the next piece; handed back once, at the end */
    rsmooth_report rep;
    rsmooth_report_init(&rep);
    rsmooth_outputs outputs = {
        .struct_size = sizeof outputs, .confidence = confidence, .report = &rep};
    rsmooth_status st =
        rsmooth_smooth_piece(c->ctx, xyz, k, tri, m, &info, &params, out, &outputs, error);
    if (st != RSMOOTH_OK)
        return st;
    if (!c->rep.device[0])
        snprintf(c->rep.device, sizeof c->rep.device, "%s", rep.device);
    const double unscale = 1 / scale;
    for (size_t i = 0; i < 3 * n; i++)
        out[i] *= unscale;
    return RSMOOTH_OK;
}

/* A step's results for a piece's core: into the copy (the last, checked as the in-memory writer
 * checks them first), else into the block the next step reads, with the confidences the next
 * pass keeps vertices by. */
static rsmooth_status write_results(stream_call *c, const uint64_t *core, size_t n,
                                    const double *out, const float *confidence,
                                    rsmooth_error *error) {
    if (last_position_step(c)) {
        rsmooth_status st = rs_stream_ply_check_positions(&c->ply, core, n, out, c->output, error);
        if (st != RSMOOTH_OK)
            return st;
        if (!rs_stream_ply_write_positions(&c->ply, c->out.fd, core, n, out))
            return rs_fail(error, RSMOOTH_ERROR_IO, RS_STREAM_WHERE, "cannot write %s: %s",
                           c->output, strerror(errno));
        return RSMOOTH_OK;
    }
    int errnum = 0;
    const rs_stream_ply *block = &c->store.block[position_step(c) % 2];
    if (!rs_stream_ply_write_positions(block, c->store.fd, core, n, out) ||
        (confidence &&
         !rs_pass_store_write_confidence(&c->store, c->pass % 2, core, n, confidence)))
        errnum = errno ? errno : EIO;
    if (!errnum)
        return RSMOOTH_OK;
    return c->store.own ? rs_stream_unwritten(c->dir, errnum, error)
                        : rs_fail(error, RSMOOTH_ERROR_IO, RS_STREAM_WHERE,
                                  "cannot write the positions between steps into %s: %s",
                                  c->out.temporary, strerror(errnum));
}

/* Step 5 of a pass for one piece: filtered, the rules after a pass applied, written. */
static rsmooth_status pass_piece(stream_call *c, rs_stream_piece_arrays *a, rsmooth_error *error) {
    size_t n = a->n;
    double *out = rs_alloc_array(n ? n : 1, 3 * sizeof *out);
    /* the rules after a pass (stream_passes.c) read the core's positions before the pass, and
     * the next pass keeps vertices by their confidence */
    bool rules = c->rule.mask || (c->rule.keep_confidence > 0 && c->pass > 0);
    bool confident = c->rule.keep_confidence > 0;
    double *before = rules ? rs_alloc_array(n ? n : 1, 3 * sizeof *before) : NULL;
    float *confidence = confident ? rs_alloc_array(n ? n : 1, sizeof *confidence) : NULL;
    rsmooth_status st = RSMOOTH_OK;
    if (!out || (rules && !before) || (confident && !confidence))
        st = rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, RS_STREAM_WHERE,
                     "no memory for a piece of %zu facets", a->m);
    if (st == RSMOOTH_OK && before)
        memcpy(before, a->xyz, n * 3 * sizeof *before);
    if (st == RSMOOTH_OK)
        st = filter_piece(c, a->xyz, a->k, a->tri, a->m, n, out, confidence, error);
    if (st == RSMOOTH_OK && rules &&
        !rs_pass_rules(&c->store, &c->rule, a->core, n, before, out, confidence))
        st = rs_fail(error, RSMOOTH_ERROR_IO, RS_STREAM_WHERE,
                     "cannot read the confidences between passes: %s", strerror(errno));
    double t = now_ms();
    if (st == RSMOOTH_OK)
        st = write_results(c, a->core, n, out, confidence, error);
    c->rep.ms_write += now_ms() - t;
    rs_free(out);
    rs_free(before);
    rs_free(confidence);
    return st;
}

/* Step 5 for one piece: its lists read, its arrays assembled, then the step's work on it. */
static rsmooth_status run_piece(stream_call *c, const rs_piece *p, rsmooth_error *error) {
    double t_piece = now_ms();
    step_kind kind = kind_of(c);
    rs_piece_source src = {c->held ? &c->vertices : NULL, c->corners.f32, c->pieces.id_bytes,
                           c->pieces.vertex_record, c->pieces.facet_record};
    rs_stream_piece_arrays a;
    rsmooth_status st = rs_stream_piece_load(&c->pieces, &src, p, kind == STEP_CYCLE, &a, error);
    if (st != RSMOOTH_OK)
        return st;
    c->rep.ms_assemble += now_ms() - t_piece;
    if (kind == STEP_PASS)
        st = pass_piece(c, &a, error);
    else if (kind == STEP_SHARES)
        st = rs_stream_stage_shares(&c->store, &a, &c->stage, c->whole.scale, error);
    else {
        st = rs_stream_stage_cycle(&c->ply, &a, &c->stage, &c->whole, c->rule.mask, &c->moved,
                                   error);
        double t = now_ms();
        if (st == RSMOOTH_OK)
            st = write_results(c, a.core, a.n, a.xyz, NULL, error);
        c->rep.ms_write += now_ms() - t;
    }
    rs_stream_piece_arrays_free(&a);
    return st;
}

static rsmooth_status run_pieces(stream_call *c, rsmooth_error *error) {
    double t0 = now_ms(), others = c->rep.ms_write + c->rep.ms_assemble;
    c->rule.pass = c->pass;
    c->moved = 0;
    uint64_t total = 0, done = 0;
    for (size_t i = 0; i < c->pieces.count; i++)
        if (c->pieces.pieces[i].rank == c->opt.rank)
            total += c->pieces.pieces[i].facet_count + c->pieces.pieces[i].vertex_count;
    for (size_t i = 0; i < c->pieces.count; i++) {
        const rs_piece *p = &c->pieces.pieces[i];
        if (p->rank != c->opt.rank)
            continue;
        rsmooth_status st = run_piece(c, p, error);
        if (st != RSMOOTH_OK)
            return st;
        c->rep.pieces_here++;
        c->rep.facets_filtered += p->facet_count;
        if (p->facet_count > c->rep.piece_facets_max)
            c->rep.piece_facets_max = p->facet_count;
        done += p->facet_count + p->vertex_count;
        if (!report_progress(c, 0.25 + 0.75 * (double)done / (double)(total ? total : 1)))
            return rs_fail(error, RSMOOTH_ERROR_CANCELLED, RS_STREAM_WHERE, "cancelled");
    }
    c->rep.ms_filter += now_ms() - t0 - (c->rep.ms_write + c->rep.ms_assemble - others);
    return RSMOOTH_OK;
}

/* A status that another rank failed with, said so here. */
static rsmooth_status others_failed(int worst, rsmooth_status mine, rsmooth_error *error) {
    if (mine != RSMOOTH_OK || worst == RSMOOTH_OK)
        return mine;
    return rs_fail(error, (rsmooth_status)worst, RS_STREAM_WHERE,
                   "another rank failed (%s); its message says why",
                   rsmooth_status_str((rsmooth_status)worst));
}

/* Step 4 and what the passes need from it: the copy (rank 0's), open on every rank, and the
 * store between passes (alone a temporary of its own; ranks the copy's tail, which they share). */
static rsmooth_status open_copy(stream_call *c, rsmooth_error *error) {
    rsmooth_status st = RSMOOTH_OK;
    if (c->opt.rank == 0) {
        double t = now_ms();
        st = make_copy(c, error);
        c->rep.ms_copy = now_ms() - t;
    }
    st = others_failed(sync_ranks(c, st), st, error);
    if (st == RSMOOTH_OK && c->opt.rank != 0)
        st = rs_output_create_partial(&c->out, false, RS_STREAM_WHERE, error);
    c->output_size = c->ply.out_header_size + (c->ply.data_end - c->ply.data_start);
    if (st == RSMOOTH_OK && c->steps > 1)
        st = c->opt.ranks > 1
                 ? rs_pass_store_open(&c->store, c->out.fd, c->output_size, c->ply.vertex_count,
                                      c->triangle_count, c->dir, error)
                 : rs_pass_store_open(&c->store, -1, 0, c->ply.vertex_count, c->triangle_count,
                                      c->dir, error);
    return st;
}

/* After a step every rank has written: the stage's reach from the shares, or the largest
 * displacement after a cycle (the ranks' own through their slots in the store). */
static rsmooth_status after_step(stream_call *c, rsmooth_error *error) {
    if (kind_of(c) == STEP_SHARES) {
        double sum;
        uint64_t pairs;
        if (!rs_pass_store_sum_shares(&c->store, &sum, &pairs))
            return rs_fail(error, RSMOOTH_ERROR_IO, RS_STREAM_WHERE,
                           "cannot read the guided filter's shares: %s", strerror(errno));
        c->whole.reach = rs_stage_reach(&c->stage, sum, pairs, c->whole.scale);
        return RSMOOTH_OK;
    }
    if (kind_of(c) != STEP_CYCLE)
        return RSMOOTH_OK;
    if (c->opt.ranks == 1) {
        c->displacement = fmax(c->displacement, c->moved);
        return RSMOOTH_OK;
    }
    rsmooth_status st = rs_pass_store_put_slot(&c->store, c->opt.rank, c->moved)
                            ? RSMOOTH_OK
                            : rs_fail(error, RSMOOTH_ERROR_IO, RS_STREAM_WHERE,
                                      "cannot write %s: %s", c->out.temporary, strerror(errno));
    st = others_failed(sync_ranks(c, st), st, error);
    double largest = 0;
    if (st == RSMOOTH_OK && !rs_pass_store_largest_slot(&c->store, c->opt.ranks, &largest))
        st = rs_fail(error, RSMOOTH_ERROR_IO, RS_STREAM_WHERE, "cannot read %s: %s",
                     c->out.temporary, strerror(errno));
    c->displacement = fmax(c->displacement, largest);
    return st;
}

/* Steps 1-3 and 5 of each step, the copy made after the first one's plan; every rank's rows of
 * a step on disk before any rank reads them (or rank 0 names the file). `st`: how the call went
 * so far. Every rank meets the others as often as they: after a failure anywhere all stop after
 * the first step's meetings. */
static rsmooth_status run_steps(stream_call *c, rsmooth_status st, rsmooth_error *error) {
    c->rep.input_bytes_read = c->ply.data_start; /* the header */
    for (c->step = 0; c->step < c->steps; c->step++) {
        int p = position_step(c);
        c->pass = p - c->cycles;
        c->source = p <= 0 ? &c->ply : &c->store.block[(p - 1) % 2];
        if (st == RSMOOTH_OK)
            st = plan(c, error);
        st = others_failed(sync_ranks(c, st), st, error);
        if (c->step == 0) /* the faces and what follows them */
            c->rep.input_bytes_read += c->ply.face_start ? c->ply.size - c->ply.face_start : 0;
        if (st == RSMOOTH_OK && c->step == 0)
            st = open_copy(c, error);
        bool runs = c->passes > 0 || c->cycles > 0;
        if (st == RSMOOTH_OK && runs)
            st = run_pieces(c, error);
        int fd = c->step + 1 >= c->steps ? c->out.fd : c->store.fd;
        if (st == RSMOOTH_OK && c->opt.ranks > 1 && runs && fsync(fd) != 0)
            st = rs_fail(error, RSMOOTH_ERROR_IO, RS_STREAM_WHERE, "cannot write %s: %s",
                         c->out.temporary, strerror(errno));
        st = others_failed(sync_ranks(c, st), st, error);
        if (st == RSMOOTH_OK && runs && kind_of(c) != STEP_PASS) {
            st = after_step(c, error); /* (every rank agrees before the next step's plan) */
            st = others_failed(sync_ranks(c, st), st, error);
        }
        c->rep.passes += st == RSMOOTH_OK && runs && kind_of(c) == STEP_PASS;
        c->rep.stage_cycles += st == RSMOOTH_OK && kind_of(c) == STEP_CYCLE;
        rs_stream_vertices_release(&c->vertices); /* the next step reads its own */
        rs_release_free_memory(); /* what the pieces kept: the next step's plan needs the room */
        if (st != RSMOOTH_OK)
            break;
    }
    c->step = c->steps - 1;
    c->rep.input_bytes_read += c->ply.rows_read * c->ply.vertex_stride;
    if (c->opt.rank == 0 && c->out.fd >= 0)
        c->rep.input_bytes_read += c->ply.data_end - c->ply.data_start; /* the copy */
    return st;
}

rsmooth_status rsmooth_stream_smooth(rsmooth_context *ctx, const char *input, const char *output,
                                     const rsmooth_params *params,
                                     const rsmooth_stream_options *options,
                                     rsmooth_stream_report *report, rsmooth_error *error) {
    double t0 = now_ms();
    rs_error_clear(error);
    stream_call *c = rs_calloc_array(1, sizeof *c);
    if (!c)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, RS_STREAM_WHERE, "call record");
    c->ctx = ctx;
    c->input = input;
    c->output = output;
    c->corners.fd = c->corners.ids_fd = c->ids_fd = -1;
    c->store.fd = -1;
    c->out.fd = -1;
    c->out.guard = -1;
    c->ply.fd = -1;
    c->pieces.vertex_fd = c->pieces.facet_fd = -1;
    rsmooth_stream_report_init(&c->rep);
    rsmooth_status st = check_arguments(c, params, options, error);
    if (st == RSMOOTH_OK)
        st = open_input(c, error);
    st = run_steps(c, st, error);
    /* the copy cut back to the output's size: ranks kept the positions between passes after it */
    if (c->opt.rank == 0 && !rs_pass_store_close(&c->store, st == RSMOOTH_OK) && st == RSMOOTH_OK)
        st = rs_fail(error, RSMOOTH_ERROR_IO, RS_STREAM_WHERE, "cannot write %s: %s",
                     c->out.temporary, strerror(errno));
    if (c->opt.rank == 0 && c->out.fd >= 0 && st == RSMOOTH_OK)
        st = rs_output_publish(&c->out, c->opt.replace != 0, RS_STREAM_WHERE, error);
    if (st == RSMOOTH_OK && c->out.notes[0])
        snprintf(c->rep.notes, sizeof c->rep.notes, "%s", c->out.notes);
    rs_output_discard(&c->out); /* nothing half-written is left */
    st = others_failed(sync_ranks(c, st), st, error);
    if (st == RSMOOTH_OK)
        report_progress(c, 1.0);
    c->rep.ms_total = now_ms() - t0;
    if (report && report->struct_size >= sizeof report->struct_size) {
        /* a caller's older, smaller record gets the fields it has */
        size_t size = report->struct_size < sizeof *report ? report->struct_size : sizeof *report;
        memcpy(report, &c->rep, size);
        report->struct_size = size;
    }
    if (c->opt.rank != 0)
        rs_pass_store_close(&c->store, false);
    if (c->corners.fd >= 0)
        close(c->corners.fd);
    if (c->ids_fd >= 0)
        close(c->ids_fd);
    rs_stream_pieces_free(&c->pieces);
    if (c->ply.fd >= 0)
        rs_stream_ply_close(&c->ply);
    rs_stream_vertices_release(&c->vertices);
    rs_free(c);
    rs_release_free_memory(); /* what the pieces kept (rsmooth_piece_info.keep_memory) */
    return st;
}
