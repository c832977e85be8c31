/* Streaming (rsmooth_stream_smooth) against the in-memory filter, the oracle:
 *   - a noisy cylinder of 400k triangles under a memory cap far below what the in-memory run
 *     holds: the same positions bit for bit on the OpenCL device (the requirement is 1e-6 mean edge
 *     lengths; pieces see the whole mesh's cells, and the kernels' differences do not depend on
 *     how vertices share blocks); under a cap below its positions (read in runs) the same bytes,
 *     with 32-bit and with 64-bit vertex ids in the temporary files;
 *   - the reference path (ctx NULL): the same bits as rsmooth_smooth(NULL, ...) in memory, and
 *     the same bytes when 3 ranks (threads, synced through a barrier) share the pieces;
 *   - three passes with pass_confidence and a move mask, each pass streamed from the one
 *     before: the in-memory bits, alone and over 3 ranks; the held vertices' bytes the input's,
 *     and the confidence rule moving fewer vertices than the passes without it; the same on a
 *     float32 file read in runs (its passes after the first read doubles);
 *   - the best mode (the normal update stage, a step per cycle, then its robust pass) with a
 *     mask: the in-memory bits on the device and, over 3 ranks, on the reference path; a cap too
 *     small for the stage's halo refused with the size it needs;
 *   - bilateral normals (a wider halo); a float32, big-endian file with colours, a face property
 *     and an element after the faces: the bytes the in-memory writer gives the same positions;
 *     big-endian without them (faces of fixed rows, read on every core): the same positions;
 *   - refusals, each with nothing written and no temporary file left behind. */
#define _GNU_SOURCE
#include "mesh_shapes.h"
#include "rsmooth.h"
#include "rsmooth_io.h"
#include "test_cl_util.h"
#include "test_util.h"

#include <dirent.h>
#include <float.h>
#include <math.h>
#include <pthread.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static char dir[64];

static const char *path_in_dir(const char *name) {
    static char buf[8][256];
    static int next;
    char *p = buf[next++ % 8];
    snprintf(p, 256, "%s/%s", dir, name);
    return p;
}

/* Files in the test folder (temporaries would show up here: they go beside the output). */
static int files_in_dir(void) {
    DIR *d = opendir(dir);
    int n = 0;
    for (struct dirent *e; d && (e = readdir(d)) != NULL;)
        n += e->d_name[0] != '.' || (strcmp(e->d_name, ".") && strcmp(e->d_name, ".."));
    if (d)
        closedir(d);
    return n;
}

static void put(FILE *f, const void *p, size_t n, bool swap) {
    unsigned char b[8];
    memcpy(b, p, n);
    for (size_t i = 0; swap && i < n / 2; i++) {
        unsigned char t = b[i];
        b[i] = b[n - 1 - i];
        b[n - 1 - i] = t;
    }
    fwrite(b, 1, n, f);
}

/* A binary PLY of `m`: float or double x y z; `extras`: colours, a face property and an element
 * after the faces; `swap`: the other byte order than this machine's. */
static void write_ply(const char *path, const shape_mesh *m, bool f32, bool swap, bool extras,
                      bool normals) {
    FILE *f = fopen(path, "wb");
    CHECK(f != NULL);
    const uint16_t one = 1;
    bool le = *(const unsigned char *)&one == 1;
    fprintf(f, "ply\nformat %s 1.0\ncomment test mesh\nelement vertex %zu\n",
            le != swap ? "binary_little_endian" : "binary_big_endian", m->vertex_count);
    const char *t = f32 ? "float" : "double";
    fprintf(f, "property %s x\nproperty %s y\nproperty %s z\n", t, t, t);
    if (normals)
        fprintf(f, "property float nx\nproperty float ny\nproperty float nz\n");
    if (extras)
        fprintf(f, "property uchar red\nproperty uchar green\nproperty uchar blue\n");
    fprintf(f, "element face %zu\nproperty list uchar int vertex_indices\n", m->triangle_count);
    if (extras)
        fprintf(f, "property int flags\nelement material 2\nproperty float k\n");
    fprintf(f, "end_header\n");
    for (size_t v = 0; v < m->vertex_count; v++) {
        for (int k = 0; k < 3; k++) {
            double x = m->xyz[3 * v + (size_t)k];
            float xf = (float)x;
            put(f, f32 ? (const void *)&xf : (const void *)&x, f32 ? 4 : 8, swap);
        }
        for (int k = 0; normals && k < 3; k++) {
            float n = k == 2 ? 1.0f : 0.0f;
            put(f, &n, 4, swap);
        }
        unsigned char rgb[3] = {(unsigned char)v, (unsigned char)(v >> 8), 7};
        if (extras)
            fwrite(rgb, 1, 3, f);
    }
    for (size_t t3 = 0; t3 < m->triangle_count; t3++) {
        fputc(3, f);
        for (int c = 0; c < 3; c++) {
            int32_t i = (int32_t)m->indices[3 * t3 + (size_t)c];
            put(f, &i, 4, swap);
        }
        int32_t flags = (int32_t)t3;
        if (extras)
            put(f, &flags, 4, swap);
    }
    float k[2] = {0.25f, 0.5f};
    for (int i = 0; extras && i < 2; i++)
        put(f, &k[i], 4, swap);
    CHECK(fclose(f) == 0);
}

static unsigned char *slurp(const char *path, size_t *size) {
    FILE *f = fopen(path, "rb");
    CHECK(f != NULL);
    fseek(f, 0, SEEK_END);
    *size = (size_t)ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *b = malloc(*size ? *size : 1);
    CHECK(b && fread(b, 1, *size, f) == *size);
    fclose(f);
    return b;
}

/* The in-memory filter on the file as the command reads it: positions in double. */
static double *smooth_in_memory(rsmooth_context *ctx, const char *path,
                                const rsmooth_params *params, double *mean_edge) {
    rsmooth_mesh *mesh = NULL;
    rsmooth_error err;
    CHECK_STATUS(rsmooth_mesh_read_file(path, &mesh, &err), RSMOOTH_OK);
    double *out = malloc(mesh->vertex_count * 3 * sizeof *out);
    CHECK(out != NULL);
    rsmooth_report rep;
    rsmooth_report_init(&rep);
    if (ctx)
        CHECK_STATUS(rsmooth_smooth(ctx, RSMOOTH_FLOAT64, mesh->positions, mesh->vertex_count,
                                    mesh->triangles, mesh->triangle_count, params, out,
                                    OUTPUTS(NULL, NULL, &rep), &err),
                     RSMOOTH_OK);
    else
        CHECK_STATUS(rsmooth_smooth(NULL, RSMOOTH_FLOAT64, mesh->positions, mesh->vertex_count,
                                    mesh->triangles, mesh->triangle_count, params, out,
                                    OUTPUTS(NULL, NULL, &rep), &err),
                     RSMOOTH_OK);
    *mean_edge = rep.mean_edge_length;
    rsmooth_mesh_destroy(mesh);
    return out;
}

/* Largest distance between the output file's positions and `expected`, in mean edge lengths. */
static double deviation(const char *path, const double *expected, double mean_edge) {
    rsmooth_mesh *mesh = NULL;
    rsmooth_error err;
    CHECK_STATUS(rsmooth_mesh_read_file(path, &mesh, &err), RSMOOTH_OK);
    double worst = 0;
    for (size_t i = 0; i < 3 * mesh->vertex_count; i++) {
        /* a float32 file holds the result rounded, where results 1e-7 edge lengths apart can
         * round one float step apart: beyond that step is the deviation */
        bool f32 = mesh->precision == RSMOOTH_FLOAT32;
        double e = f32 ? (double)(float)expected[i] : expected[i];
        double step = f32 ? fabs(e) * FLT_EPSILON : 0;
        worst = fmax(worst, fmax(0, fabs(mesh->positions[i] - e) - step));
    }
    rsmooth_mesh_destroy(mesh);
    return worst / mean_edge;
}

static rsmooth_status stream(rsmooth_context *ctx, const char *in, const char *out, uint64_t cap,
                             const rsmooth_params *params, rsmooth_stream_report *rep,
                             rsmooth_error *err) {
    rsmooth_stream_options so;
    rsmooth_stream_options_init(&so);
    so.max_memory = cap;
    so.replace = 1;
    rsmooth_stream_report_init(rep);
    rsmooth_status st = rsmooth_stream_smooth(ctx, in, out, params, &so, rep, err);
    if (st != RSMOOTH_OK)
        fprintf(stderr, "%s: %s\n", in, err->message);
    return st;
}

/* `m` written to `in` as float32 in the other byte order than this machine's (with the extras
 * or not) and streamed to `out` under 12 MB: its deviation from the in-memory positions, which
 * *expected receives. */
static double swapped_case(rsmooth_context *ctx, const shape_mesh *m, const char *in,
                           const char *out, bool extras, double **expected,
                           rsmooth_stream_report *rep) {
    double edge = 0;
    rsmooth_error err;
    write_ply(in, m, true, true, extras, false);
    *expected = smooth_in_memory(ctx, in, NULL, &edge);
    CHECK_STATUS(stream(ctx, in, out, 12u << 20, NULL, rep, &err), RSMOOTH_OK);
    return deviation(out, *expected, edge);
}

/* ---- ranks as threads: the sync is a barrier and a shared maximum */

typedef struct ranks_state {
    pthread_barrier_t barrier;
    pthread_mutex_t lock;
    int worst, result;
} ranks_state;

static int thread_sync(void *user, int status) {
    ranks_state *s = user;
    pthread_mutex_lock(&s->lock);
    if (status > s->worst)
        s->worst = status;
    pthread_mutex_unlock(&s->lock);
    pthread_barrier_wait(&s->barrier);
    int worst = s->worst;
    pthread_barrier_wait(&s->barrier); /* everyone has read it */
    if (pthread_barrier_wait(&s->barrier) == PTHREAD_BARRIER_SERIAL_THREAD)
        s->worst = 0;
    pthread_barrier_wait(&s->barrier);
    return worst;
}

typedef struct rank_job {
    ranks_state *state;
    int rank, ranks;
    const char *in, *out;
    const rsmooth_params *params;
    uint64_t cap;
    rsmooth_status status;
    rsmooth_stream_report rep;
} rank_job;

static void *run_rank(void *arg) {
    rank_job *job = arg;
    rsmooth_stream_options so;
    rsmooth_stream_options_init(&so);
    so.max_memory = job->cap;
    so.replace = 1;
    so.rank = job->rank;
    so.ranks = job->ranks;
    so.sync = thread_sync;
    so.sync_user = job->state;
    rsmooth_error err;
    rsmooth_stream_report_init(&job->rep);
    job->status = rsmooth_stream_smooth(NULL, job->in, job->out, job->params, &so, &job->rep, &err);
    if (job->status != RSMOOTH_OK)
        fprintf(stderr, "rank %d: %s\n", job->rank, err.message);
    return NULL;
}

/* `in` streamed by 3 ranks (threads) into `out`; the pieces they shared, all passes. */
static size_t three_ranks(const char *in, const char *out, const rsmooth_params *params,
                          uint64_t cap) {
    ranks_state state;
    pthread_barrier_init(&state.barrier, NULL, 3);
    pthread_mutex_init(&state.lock, NULL);
    state.worst = 0;
    rank_job jobs[3];
    pthread_t threads[3];
    for (int r = 0; r < 3; r++) {
        jobs[r] = (rank_job){&state, r, 3, in, out, params, cap, RSMOOTH_OK, {0}};
        pthread_create(&threads[r], NULL, run_rank, &jobs[r]);
    }
    size_t shared = 0;
    for (int r = 0; r < 3; r++) {
        pthread_join(threads[r], NULL);
        CHECK_STATUS(jobs[r].status, RSMOOTH_OK);
        shared += jobs[r].rep.pieces_here;
    }
    printf("3 ranks: %zu + %zu + %zu of %zu pieces\n", jobs[0].rep.pieces_here,
           jobs[1].rep.pieces_here, jobs[2].rep.pieces_here, jobs[0].rep.pieces);
    CHECK(shared == jobs[0].rep.pieces);
    pthread_barrier_destroy(&state.barrier);
    pthread_mutex_destroy(&state.lock);
    return shared;
}

/* Whether two files hold the same bytes. */
static bool same_files(const char *a_path, const char *b_path) {
    size_t a_size, b_size;
    unsigned char *a = slurp(a_path, &a_size), *b = slurp(b_path, &b_size);
    bool same = a_size == b_size && !memcmp(a, b, a_size);
    free(a);
    free(b);
    return same;
}

/* Vertices whose position differs between two results, and held vertices (mask 0) whose result
 * is not the input's position bit for bit. */
static void count_moves(const char *input, const double *a, const double *b, const uint8_t *mask,
                        size_t *differ, size_t *held_moved) {
    rsmooth_mesh *mesh = NULL;
    rsmooth_error err;
    CHECK_STATUS(rsmooth_mesh_read_file(input, &mesh, &err), RSMOOTH_OK);
    *differ = *held_moved = 0;
    for (size_t v = 0; v < mesh->vertex_count; v++) {
        *differ += memcmp(a + 3 * v, b + 3 * v, 3 * sizeof *a) != 0;
        *held_moved += !mask[v] && memcmp(a + 3 * v, mesh->positions + 3 * v, 3 * sizeof *a) != 0;
    }
    rsmooth_mesh_destroy(mesh);
}

/* `with` (a mask in it) streamed from `in` under `cap` (ctx's device or the reference path)
 * into `out`, against its in-memory bits (the fold guard off, as on pieces): the deviation in
 * *dev, and the vertices where `without` in memory differs from `with` (what the option under
 * test changes) and the mask's held vertices that moved; over 3 ranks (reference path) too. */
typedef struct case_figures {
    double dev;
    size_t differ, held_moved;
    bool ranks_same;
    rsmooth_stream_report rep;
} case_figures;

static void streamed_case(rsmooth_context *ctx, const char *in, const char *out, uint64_t cap,
                          const rsmooth_params *with, const rsmooth_params *without, bool ranks,
                          case_figures *f) {
    double edge = 0;
    double *expected = smooth_in_memory(ctx, in, with, &edge);
    double *other = smooth_in_memory(ctx, in, without, &edge);
    count_moves(in, expected, other, with->move_mask, &f->differ, &f->held_moved);
    rsmooth_error err;
    CHECK_STATUS(stream(ctx, in, out, cap, with, &f->rep, &err), RSMOOTH_OK);
    f->dev = deviation(out, expected, edge);
    f->ranks_same = true;
    if (ranks) {
        three_ranks(in, path_in_dir("case_ranks.ply"), with, cap);
        f->ranks_same = same_files(out, path_in_dir("case_ranks.ply"));
        remove(path_in_dir("case_ranks.ply"));
    }
    remove(out);
    free(expected);
    free(other);
}

/* A mask holding every `nth` vertex. */
static uint8_t *every_nth_held(size_t vertex_count, size_t nth) {
    uint8_t *mask = malloc(vertex_count);
    CHECK(mask != NULL);
    for (size_t v = 0; v < vertex_count; v++)
        mask[v] = v % nth != 0;
    return mask;
}

/* Three passes, pass_confidence 0.6 and a mask holding every fourth vertex: the rule changes
 * vertices, the held ones keep their bytes, the in-memory bits. */
static void passes_case(rsmooth_context *ctx, const char *in, size_t vertex_count, uint64_t cap,
                        bool ranks) {
    rsmooth_params plain;
    rsmooth_params_init(&plain);
    plain.guard = 0;
    plain.passes = 3;
    plain.move_mask = every_nth_held(vertex_count, 4);
    rsmooth_params kept = plain;
    kept.pass_confidence = 0.6;
    case_figures f;
    streamed_case(ctx, in, path_in_dir("passes.ply"), cap, &kept, &plain, ranks, &f);
    printf("3 passes, confidence 0.6, 1 vertex in 4 held, cap %llu MB: %d passes, %zu pieces, "
           "%llu runs of positions, temporaries %llu MB; deviation %.3g; the confidence rule "
           "changes %zu of %zu vertices; held vertices moved %zu%s\n",
           (unsigned long long)(cap >> 20), f.rep.passes, f.rep.pieces,
           (unsigned long long)f.rep.position_runs,
           (unsigned long long)(f.rep.temporary_bytes >> 20), f.dev, f.differ, vertex_count,
           f.held_moved,
           ranks ? (f.ranks_same ? "; 3 ranks: the same bytes" : "; 3 ranks DIFFER") : "");
    CHECK(f.rep.passes == 3);
    CHECK(f.dev == 0);
    CHECK(f.differ > vertex_count / 100); /* the rule does something */
    CHECK(f.held_moved == 0);
    CHECK(f.ranks_same);
    free((void *)plain.move_mask);
}

/* The best mode (2 of its cycles) with a mask holding every fifth vertex: the stage moves most
 * vertices, the held ones keep their bytes, the in-memory bits. */
static void stage_case(rsmooth_context *ctx, const char *in, size_t vertex_count, uint64_t cap,
                       bool ranks) {
    rsmooth_params best;
    rsmooth_params_init_best(&best);
    best.guard = 0;
    best.stage_repeats = 2;
    best.move_mask = every_nth_held(vertex_count, 5);
    rsmooth_params plain = best; /* the stage's share of the result: without it */
    plain.vertex_updates = 0;
    case_figures f;
    streamed_case(ctx, in, path_in_dir("best.ply"), cap, &best, &plain, ranks, &f);
    printf("best mode, 2 cycles, 1 vertex in 5 held, cap %llu MB on %s: %d cycles and %d pass "
           "streamed, %zu pieces (the largest %llu facets), temporaries %llu MB; deviation %.3g; "
           "the stage moves %zu of %zu vertices; held vertices moved %zu%s\n",
           (unsigned long long)(cap >> 20), ctx ? "the device" : "the reference path",
           f.rep.stage_cycles, f.rep.passes, f.rep.pieces,
           (unsigned long long)f.rep.piece_facets_max,
           (unsigned long long)(f.rep.temporary_bytes >> 20), f.dev, f.differ, vertex_count,
           f.held_moved,
           ranks ? (f.ranks_same ? "; 3 ranks: the same bytes" : "; 3 ranks DIFFER") : "");
    CHECK(f.rep.stage_cycles == 2 && f.rep.passes == 1);
    CHECK(f.dev == 0);
    CHECK(f.differ > vertex_count / 2);
    CHECK(f.held_moved == 0);
    CHECK(f.ranks_same);
    free((void *)best.move_mask);
}

static void check_refusal(rsmooth_context *ctx, const char *in, uint64_t cap,
                          const rsmooth_params *params, rsmooth_status expected,
                          const char *needle) {
    const char *out = path_in_dir("refused.ply");
    int before = files_in_dir();
    rsmooth_stream_report rep;
    rsmooth_error err;
    rsmooth_stream_options so;
    rsmooth_stream_options_init(&so);
    so.max_memory = cap;
    rsmooth_status st = rsmooth_stream_smooth(ctx, in, out, params, &so, &rep, &err);
    printf("refused %-40s %s: %s\n", needle, rsmooth_status_str(st), err.message);
    CHECK_EQ_INT(st, expected);
    CHECK(strstr(err.message, needle) != NULL);
    CHECK(access(out, F_OK) != 0);        /* nothing written */
    CHECK_EQ_INT(files_in_dir(), before); /* nothing left behind */
}

int main(void) {
    snprintf(dir, sizeof dir, "/tmp/rsmooth-stream-XXXXXX");
    CHECK(mkdtemp(dir) != NULL);
    rsmooth_context *ctx = open_test_context();
    rsmooth_error err;
    rsmooth_stream_report rep;

    /* 1. A cap far below the need, on the device. */
    shape_mesh cyl;
    CHECK(shape_capped_cylinder(&cyl, 1.0, 2.0, 400000) == 0);
    CHECK(shape_add_normal_noise(&cyl, 0.3 * shape_mean_edge_length(&cyl), 5) == 0);
    char *big = strdup(path_in_dir("cylinder.ply"));
    write_ply(big, &cyl, false, false, false, false);
    double edge = 0;
    double *expected = smooth_in_memory(ctx, big, NULL, &edge);
    uint64_t cap = 20u << 20; /* the in-memory run holds about 190 bytes per triangle: 76 MB */
    CHECK_STATUS(stream(ctx, big, path_in_dir("capped.ply"), cap, NULL, &rep, &err), RSMOOTH_OK);
    double dev = deviation(path_in_dir("capped.ply"), expected, edge);
    printf("cylinder V=%zu T=%zu cap %llu MB: %zu pieces (largest %llu facets), planned %llu MB, "
           "mean edge %.17g vs %.17g; deviation %.3g mean edge lengths\n",
           cyl.vertex_count, cyl.triangle_count, (unsigned long long)(cap >> 20), rep.pieces,
           (unsigned long long)rep.piece_facets_max, (unsigned long long)(rep.memory_planned >> 20),
           rep.mean_edge_length, edge, dev);
    CHECK(rep.pieces >= 10);
    CHECK_LE(rep.memory_planned, cap);
    CHECK(rep.mean_edge_length == edge); /* summed in the same order: the same bits */
    CHECK(dev == 0);
    CHECK(rep.position_runs == 1); /* 4.8 MB of positions fit in half of what the cap leaves */
    CHECK(rep.vertex_id_bits == 32);
    /* the input read once (header, vertex rows, faces) and its data once more for the copy */
    size_t input_size;
    unsigned char *input = slurp(big, &input_size);
    size_t header_size = (size_t)(strstr((char *)input, "end_header\n") - (char *)input) + 11;
    printf("input %zu bytes (header %zu): %llu read\n", input_size, header_size,
           (unsigned long long)rep.input_bytes_read);
    CHECK(rep.input_bytes_read == 2 * input_size - header_size);
    free(input);
    free(expected);
    /* The mesh's figures are made on every core (stream_stats.c): 1 and 5 host threads cut the
     * work differently and must give the same bytes. */
    size_t capped_size;
    unsigned char *capped = slurp(path_in_dir("capped.ply"), &capped_size);
    for (int t = 0; t < 2; t++) {
        setenv("RSMOOTH_HOST_THREADS", t ? "5" : "1", 1);
        rsmooth_stream_report threads_rep;
        CHECK_STATUS(stream(ctx, big, path_in_dir("threads.ply"), cap, NULL, &threads_rep, &err),
                     RSMOOTH_OK);
        size_t size;
        unsigned char *bytes = slurp(path_in_dir("threads.ply"), &size);
        printf("%s host thread(s): mean edge %.17g, output %s\n", t ? "5" : "1",
               threads_rep.mean_edge_length,
               size == capped_size && !memcmp(bytes, capped, size) ? "the same bytes" : "DIFFERS");
        CHECK(threads_rep.mean_edge_length == edge);
        CHECK(size == capped_size && memcmp(bytes, capped, size) == 0);
        free(bytes);
        remove(path_in_dir("threads.ply"));
    }
    unsetenv("RSMOOTH_HOST_THREADS");
    /* A cap that holds only part of the positions (10 MB: 2 MB beside the fixed buffers, for
     * 4.8 MB of positions): they are read in runs by each pass that needs them, and the corner
     * records carry them to the pieces. Then the same with 64-bit vertex ids in every temporary
     * file, as meshes of 2^32 - 1 vertices and more have them (RSMOOTH_STREAM_WIDE_IDS forces
     * them on a small one). The same bytes. */
    /* 10 MB; 10 MB with wide ids; 20 MB (held) so; 14 MB: the positions fit the cap's room in one
     * run but take more than half of it, so they are let go for the pieces like runs */
    for (int run = 0; run < 4; run++) {
        bool wide = run == 1 || run == 2;
        uint64_t run_cap = run == 2 ? cap : run == 3 ? 14u << 20 : 10u << 20;
        if (wide)
            setenv("RSMOOTH_STREAM_WIDE_IDS", "1", 1);
        else
            unsetenv("RSMOOTH_STREAM_WIDE_IDS");
        rsmooth_stream_report runs_rep;
        CHECK_STATUS(stream(ctx, big, path_in_dir("runs.ply"), run_cap, NULL, &runs_rep, &err),
                     RSMOOTH_OK);
        size_t runs_size;
        unsigned char *runs_bytes = slurp(path_in_dir("runs.ply"), &runs_size);
        bool same = runs_size == capped_size && !memcmp(runs_bytes, capped, runs_size);
        printf("cap %llu MB, %u-bit ids: %llu runs of positions read, %zu pieces, planned %llu "
               "MB, temporaries %llu MB; output %s\n",
               (unsigned long long)(run_cap >> 20), runs_rep.vertex_id_bits,
               (unsigned long long)runs_rep.position_runs, runs_rep.pieces,
               (unsigned long long)(runs_rep.memory_planned >> 20),
               (unsigned long long)(runs_rep.temporary_bytes >> 20),
               same ? "the same bytes" : "DIFFERS");
        /* 3 runs each: extent, corners, grid, lists; or held; or one run read twice (the
         * extent, then the grid and lists) */
        CHECK(run == 2   ? runs_rep.position_runs == 1
              : run == 3 ? runs_rep.position_runs == 2
                         : runs_rep.position_runs >= 3 * 3);
        CHECK(runs_rep.vertex_id_bits == (wide ? 64u : 32u));
        CHECK_LE(runs_rep.memory_planned, run_cap);
        CHECK(same);
        free(runs_bytes);
        remove(path_in_dir("runs.ply"));
    }
    unsetenv("RSMOOTH_STREAM_WIDE_IDS");
    free(capped);

    /* 2. Bilateral normals widen the halo. */
    rsmooth_params bilateral;
    rsmooth_params_init(&bilateral);
    bilateral.normal_filter = RSMOOTH_NORMALS_BILATERAL;
    bilateral.normal_iterations = 3;
    expected = smooth_in_memory(ctx, big, &bilateral, &edge);
    CHECK_STATUS(stream(ctx, big, path_in_dir("bilateral.ply"), cap, &bilateral, &rep, &err),
                 RSMOOTH_OK);
    dev = deviation(path_in_dir("bilateral.ply"), expected, edge);
    printf("bilateral: %zu pieces, halo %.4g; deviation %.3g mean edge lengths\n", rep.pieces,
           rep.halo, dev);
    CHECK(dev == 0);
    free(expected);
    shape_free(&cyl);

    /* 3. The reference path: bit for bit, alone and over 3 ranks. */
    shape_mesh small;
    CHECK(shape_capped_cylinder(&small, 1.0, 1.0, 20000) == 0);
    CHECK(shape_add_normal_noise(&small, 0.3 * shape_mean_edge_length(&small), 9) == 0);
    char *in = strdup(path_in_dir("small.ply"));
    write_ply(in, &small, false, false, false, false);
    expected = smooth_in_memory(NULL, in, NULL, &edge);
    CHECK_STATUS(stream(NULL, in, path_in_dir("ref.ply"), 12u << 20, NULL, &rep, &err), RSMOOTH_OK);
    dev = deviation(path_in_dir("ref.ply"), expected, edge);
    printf("reference: %zu pieces; deviation %.3g (0: the same bits)\n", rep.pieces, dev);
    CHECK(rep.pieces >= 2);
    CHECK(dev == 0);
    free(expected);
    size_t shared = three_ranks(in, path_in_dir("ranks.ply"), NULL, 12u << 20);
    bool same = same_files(path_in_dir("ref.ply"), path_in_dir("ranks.ply"));
    printf("3 ranks: output %s the single run's\n", same ? "equals" : "DIFFERS");
    CHECK(shared == rep.pieces);
    CHECK(same);

    /* 3b. Passes, their confidence rule and a mask, and the best mode: the reference path alone
     * and over 3 ranks */
    passes_case(NULL, in, small.vertex_count, 12u << 20, true);
    stage_case(NULL, in, small.vertex_count, 40u << 20, true);

    /* 4. float32, the other byte order, extras: the bytes the in-memory writer gives the same
     * positions (little-endian, every other value and the header as read). */
    char *odd = strdup(path_in_dir("odd.ply"));
    dev = swapped_case(ctx, &small, odd, path_in_dir("odd_out.ply"), true, &expected, &rep);
    rsmooth_mesh *written = NULL;
    CHECK_STATUS(rsmooth_mesh_read_file(odd, &written, &err), RSMOOTH_OK);
    memcpy(written->positions, expected, written->vertex_count * 3 * sizeof *expected);
    CHECK_STATUS(rsmooth_mesh_write_file(written, path_in_dir("odd_memory.ply"),
                                         RSMOOTH_FORMAT_PLY_BINARY, &err),
                 RSMOOTH_OK);
    rsmooth_mesh_destroy(written);
    size_t a_size, b_size;
    unsigned char *a = slurp(path_in_dir("odd_memory.ply"), &a_size);
    unsigned char *b = slurp(path_in_dir("odd_out.ply"), &b_size);
    size_t differ = a_size == b_size ? 0 : SIZE_MAX;
    for (size_t i = 0; i < a_size && a_size == b_size; i++)
        differ += a[i] != b[i];
    printf("float32 big-endian with extras: deviation %.3g; %zu bytes of %zu differ from the "
           "in-memory writer's (SIZE_MAX: sizes %zu and %zu)\n",
           dev, differ, a_size, a_size, b_size);
    CHECK(differ == 0);
    CHECK(dev == 0);
    free(a);
    free(b);
    free(expected);

    /* 4b. the other byte order without extras: faces of 13-byte rows, read on every core with
     * their indices swapped (stream_ply.c's fixed rows) */
    char *swapped = strdup(path_in_dir("swapped.ply"));
    dev =
        swapped_case(ctx, &small, swapped, path_in_dir("swapped_out.ply"), false, &expected, &rep);
    printf("float32 big-endian, fixed face rows: %llu triangles, deviation %.3g\n",
           (unsigned long long)rep.triangle_count, dev);
    CHECK(rep.triangle_count == small.triangle_count);
    CHECK(dev == 0);
    free(expected);
    free(swapped);

    /* 4c. Passes on the device from a float32 file, whose positions the first pass holds and
     * the later ones (doubles) read in runs under 10 MB */
    shape_mesh mid;
    CHECK(shape_capped_cylinder(&mid, 1.0, 1.5, 100000) == 0);
    CHECK(shape_add_normal_noise(&mid, 0.3 * shape_mean_edge_length(&mid), 11) == 0);
    const char *mid_path = path_in_dir("mid.ply");
    write_ply(mid_path, &mid, true, false, false, false);
    passes_case(ctx, mid_path, mid.vertex_count, 10u << 20, false);
    /* 4d. the best mode on the device, in pieces a fraction of the mesh each */
    stage_case(ctx, mid_path, mid.vertex_count, 48u << 20, false);
    remove(mid_path);
    shape_free(&mid);

    /* 5. Refusals. */
    const char *normals = path_in_dir("normals.ply");
    write_ply(normals, &small, true, false, false, true);
    check_refusal(ctx, normals, 64u << 20, NULL, RSMOOTH_ERROR_UNSUPPORTED, "vertex normals");
    rsmooth_params staged;
    rsmooth_params_init_best(&staged);
    staged.stage_normals = RSMOOTH_STAGE_NORMALS_LEARNED;
    check_refusal(ctx, in, 64u << 20, &staged, RSMOOTH_ERROR_UNSUPPORTED, "stage_normals");
    staged.stage_normals = RSMOOTH_STAGE_NORMALS_GUIDED; /* its halo needs more than 12 MB */
    check_refusal(ctx, in, 12u << 20, &staged, RSMOOTH_ERROR_OUT_OF_MEMORY, "give at least");
    staged.discrepancy_level = 0.3; /* the choice per region reads the whole mesh */
    check_refusal(ctx, in, 64u << 20, &staged, RSMOOTH_ERROR_UNSUPPORTED, "discrepancy_level");
    check_refusal(ctx, big, 2u << 20, NULL, RSMOOTH_ERROR_OUT_OF_MEMORY, "give at least");
    check_refusal(ctx, path_in_dir("missing.ply"), 64u << 20, NULL, RSMOOTH_ERROR_IO,
                  "cannot open");
    rsmooth_mesh *mesh = NULL;
    CHECK_STATUS(rsmooth_mesh_create(3, 1, 3, &mesh, &err), RSMOOTH_OK);
    mesh->positions[3] = 1;
    mesh->positions[7] = 1;
    mesh->face_offsets[1] = 3;
    mesh->face_indices[1] = 1;
    mesh->face_indices[2] = 2;
    const char *ascii = path_in_dir("ascii.ply");
    CHECK_STATUS(rsmooth_mesh_write_file(mesh, ascii, RSMOOTH_FORMAT_PLY_ASCII, &err), RSMOOTH_OK);
    rsmooth_mesh_destroy(mesh);
    check_refusal(ctx, ascii, 64u << 20, NULL, RSMOOTH_ERROR_UNSUPPORTED, "binary PLY only");
    const char *trailing = path_in_dir("trailing.ply"); /* data the header's counts leave out */
    write_ply(trailing, &small, true, false, false, false);
    FILE *f = fopen(trailing, "ab");
    CHECK(f && fputs("left out", f) >= 0 && fclose(f) == 0);
    check_refusal(ctx, trailing, 64u << 20, NULL, RSMOOTH_ERROR_PARSE,
                  "after the data the header declares");
    small.indices[7] = (uint32_t)small.vertex_count; /* out of range */
    const char *bad = path_in_dir("bad_index.ply");
    write_ply(bad, &small, false, false, false, false);
    check_refusal(ctx, bad, 64u << 20, NULL, RSMOOTH_ERROR_PARSE, "face 2: index");
    CHECK(truncate(in, 1000) == 0);
    check_refusal(ctx, in, 64u << 20, NULL, RSMOOTH_ERROR_PARSE, "do not fit in the file");
    /* an existing output is kept unless replace is asked for */
    rsmooth_stream_options so;
    rsmooth_stream_options_init(&so);
    so.max_memory = 64u << 20;
    size_t before_size;
    unsigned char *before = slurp(path_in_dir("ref.ply"), &before_size);
    CHECK_STATUS(rsmooth_stream_smooth(ctx, odd, path_in_dir("ref.ply"), NULL, &so, &rep, &err),
                 RSMOOTH_ERROR_IO);
    printf("existing output: %s\n", err.message);
    unsigned char *after = slurp(path_in_dir("ref.ply"), &a_size);
    CHECK(a_size == before_size && !memcmp(before, after, a_size));
    free(before);
    free(after);
    shape_free(&small);

    /* the folder holds our files only: no temporary survived */
    printf("files left in %s: %d (the 15 the test wrote)\n", dir, files_in_dir());
    CHECK_EQ_INT(files_in_dir(), 15);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    CHECK(system(cmd) == 0);
    free(big);
    free(in);
    free(odd);
    rsmooth_context_destroy(ctx);
    printf("ok\n");
    return 0;
}
