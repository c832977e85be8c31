/* rsmooth-bench: prints figures, never asserts them (machines here are shared and noisy; compare
 * ratios measured in one run, and medians).
 *
 *   rsmooth-bench io [--triangles N] [--repeat R] [--dir DIR]
 *     Mesh file speed: writes and reads a binary PLY, an ascii PLY and an OBJ of a generated
 *     N-triangle mesh, beside a raw write and read of the same number of bytes in the same
 *     process: the disk-bound limit. One JSON object on stdout with medians over R repetitions.
 *
 *   rsmooth-bench filter [MESH] [--triangles N] [--noise S] [--sigma-f X] [--sigma-g Y]
 *                        [--device D] [--repeat R] [--no-roofline]
 *     The OpenCL filter (rsmooth_smooth, float32): program build (first and cached), the first
 *     run, then median/min/max of each stage over R runs and whether they are bit-identical;
 *     pairs each pass examined against the useful ones (within reach, counted apart in
 *     bench_pairs.c), and useful pairs per second against a native roofline of the same
 *     arithmetic on all cores (bench_roofline.c); peak memory over the input's. One JSON object.
 *
 *   rsmooth-bench best [MESH] [--triangles N] [--device D] [--repeat R] [--auto] [--drift]
 *     The best mode against the paper filter, its normal-update stage on the host and on the
 *     device (bench_best.c). One JSON object.
 */
#define _POSIX_C_SOURCE 200809L
#include "bench_best.h"
#include "bench_pairs.h"
#include "bench_roofline.h"
#include "cli_args.h"
#include "mesh_shapes.h"
#include "rsmooth.h"
#include "rsmooth_io.h"

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

static double now_ms(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

static int compare_double(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *v, int n) {
    qsort(v, (size_t)n, sizeof *v, compare_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

static long peak_rss_kib(void) {
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return ru.ru_maxrss;
}

/* Raw write and read of `bytes` bytes through stdio, fsync'd like nothing else: the page cache
 * serves both, exactly as it serves the mesh files, so the ratio is fair. */
static void raw_io(const char *path, size_t bytes, double *write_ms, double *read_ms) {
    char *buffer = malloc(bytes);
    if (!buffer) {
        *write_ms = *read_ms = -1;
        return;
    }
    memset(buffer, 0x5a, bytes);
    double t0 = now_ms();
    FILE *f = fopen(path, "wb");
    size_t written = f ? fwrite(buffer, 1, bytes, f) : 0;
    if (f)
        fclose(f);
    *write_ms = now_ms() - t0;
    t0 = now_ms();
    f = fopen(path, "rb");
    size_t got = f ? fread(buffer, 1, bytes, f) : 0;
    if (f)
        fclose(f);
    *read_ms = now_ms() - t0;
    if (written != bytes || got != bytes)
        *write_ms = *read_ms = -1;
    free(buffer);
    unlink(path);
}

/* Exit statuses, as the rsmooth command's. */
enum { EXIT_OK = 0, EXIT_OTHER = 1, EXIT_USAGE = 2, EXIT_DEVICE = 3 };

static const char io_usage[] =
    "usage: rsmooth-bench io [--triangles N] [--repeat R] [--dir DIR]\n"
    "  times writing and reading a binary PLY, an ascii PLY and an OBJ of a generated noisy\n"
    "  closed cylinder beside a raw write and read of the same bytes (the disk-bound limit);\n"
    "  medians over R repetitions (JSON)\n"
    "  --triangles N   about N triangles, at least 100 (default 1000000)\n"
    "  --repeat R      repetitions, 1..99 (default 3)\n"
    "  --dir DIR       where the files are written, then removed (default /tmp)\n";

static int io_usage_error(const char *message, const char *value) {
    fprintf(stderr, "rsmooth-bench io: %s '%s'\nTry 'rsmooth-bench io --help'.\n", message, value);
    return EXIT_USAGE;
}

static int bench_io(int argc, char **argv) {
    double triangles = 1000000, x;
    int repeat = 3;
    const char *dir = "/tmp";
    for (int i = 2; i < argc; i++) {
        const char *a = argv[i], *value = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            fputs(io_usage, stdout);
            return EXIT_OK;
        } else if (strcmp(a, "--triangles") && strcmp(a, "--repeat") && strcmp(a, "--dir")) {
            return io_usage_error("unknown option", a);
        } else if (!value) {
            return io_usage_error("an option needs a value:", a);
        } else if (!strcmp(a, "--dir")) {
            dir = value;
        } else if (!strcmp(a, "--triangles")) {
            if (!cli_parse_number(value, &triangles) ||
                !(triangles >= 100 && triangles <= 1e9 && triangles == floor(triangles)))
                return io_usage_error("--triangles must be a whole number in [100, 1e9]:", value);
        } else if (!cli_parse_number(value, &x) || !(x >= 1 && x <= 99 && x == floor(x))) {
            return io_usage_error("--repeat must be a whole number in 1..99:", value);
        } else {
            repeat = (int)x;
        }
        i++;
    }
    shape_mesh shape;
    if (shape_capped_cylinder(&shape, 1.0, 1.5, (size_t)triangles) != 0 ||
        shape_add_normal_noise(&shape, 0.3, 1) != 0) {
        fprintf(stderr, "rsmooth-bench: cannot generate the mesh\n");
        return 1;
    }
    rsmooth_mesh *mesh = NULL;
    rsmooth_error err;
    if (rsmooth_mesh_create(shape.vertex_count, shape.triangle_count, 3 * shape.triangle_count,
                            &mesh, &err) != RSMOOTH_OK) {
        fprintf(stderr, "rsmooth-bench: %s\n", err.message);
        return 1;
    }
    memcpy(mesh->positions, shape.xyz, shape.vertex_count * 3 * sizeof(double));
    memcpy(mesh->face_indices, shape.indices, shape.triangle_count * 3 * sizeof(uint32_t));
    for (size_t t = 0; t <= shape.triangle_count; t++)
        mesh->face_offsets[t] = (uint32_t)(3 * t);
    mesh->precision = RSMOOTH_FLOAT32;
    rsmooth_mesh_triangulate(mesh, &err);
    shape_free(&shape);

    static const struct {
        const char *name, *ext;
        rsmooth_format format;
    } formats[] = {{"ply_binary", "ply", RSMOOTH_FORMAT_PLY_BINARY},
                   {"ply_ascii", "ply", RSMOOTH_FORMAT_PLY_ASCII},
                   {"obj", "obj", RSMOOTH_FORMAT_OBJ}};
    printf("{\"triangles\":%zu,\"vertices\":%zu", mesh->triangle_count, mesh->vertex_count);
    for (size_t f = 0; f < sizeof formats / sizeof *formats; f++) {
        char path[4096];
        snprintf(path, sizeof path, "%s/rsmooth-bench-%d.%s", dir, (int)getpid(), formats[f].ext);
        double w[99], r[99], rw[99], rr[99];
        long bytes = 0;
        for (int i = 0; i < repeat; i++) {
            double t0 = now_ms();
            if (rsmooth_mesh_write_file(mesh, path, formats[f].format, &err) != RSMOOTH_OK) {
                fprintf(stderr, "rsmooth-bench: %s\n", err.message);
                return 1;
            }
            w[i] = now_ms() - t0;
            struct stat st;
            stat(path, &st);
            bytes = (long)st.st_size;
            rsmooth_mesh *back = NULL;
            t0 = now_ms();
            if (rsmooth_mesh_read_file(path, &back, &err) != RSMOOTH_OK) {
                fprintf(stderr, "rsmooth-bench: %s\n", err.message);
                return 1;
            }
            r[i] = now_ms() - t0;
            rsmooth_mesh_destroy(back);
            unlink(path);
            raw_io(path, (size_t)bytes, &rw[i], &rr[i]);
        }
        double mw = median(w, repeat), mr = median(r, repeat), mrw = median(rw, repeat),
               mrr = median(rr, repeat);
        printf(",\"%s\":{\"bytes\":%ld,\"write_ms\":%.1f,\"read_ms\":%.1f,\"raw_write_ms\":%.1f,"
               "\"raw_read_ms\":%.1f,\"write_MBps\":%.0f,\"read_MBps\":%.0f,"
               "\"write_vs_raw\":%.2f,\"read_vs_raw\":%.2f}",
               formats[f].name, bytes, mw, mr, mrw, mrr, bytes / 1e3 / mw, bytes / 1e3 / mr,
               mw / mrw, mr / mrr);
    }
    printf(",\"repeat\":%d,\"peak_rss_MiB\":%.0f}\n", repeat, peak_rss_kib() / 1024.0);
    rsmooth_mesh_destroy(mesh);
    return 0;
}

/* ---- filter ---------------------------------------------------------------------------------- */

static const char filter_usage[] =
    "usage: rsmooth-bench filter [MESH] [--triangles N] [--noise S] [--sigma-f X] [--sigma-g Y]\n"
    "                            [--device D] [--repeat R] [--memory-budget SIZE] [--no-pairs]\n"
    "                            [--no-roofline]\n"
    "  times the OpenCL filter (float32 positions): program build (first and cached), the first\n"
    "  run, then median/min/max of each stage over R runs and whether they are bit-identical;\n"
    "  pairs each pass examined against the useful ones (within reach), useful pairs per second\n"
    "  against a native roofline of the same arithmetic on all cores, and peak memory (JSON)\n"
    "  MESH            any mesh file rsmooth reads; default: a generated closed cylinder\n"
    "                  (radius 1, height 1.5: sharp rims, curved side, flat caps)\n"
    "  --triangles N   generated mesh: about N triangles (default 200000)\n"
    "  --noise S       generated mesh: normal noise of S mean edge lengths, seed 1 (default 0.2)\n"
    "  --sigma-f X     spatial width in mean edge lengths (default 2)\n"
    "  --sigma-g Y     influence width in mean edge lengths, or 'inf' (default 0.5)\n"
    "  --device D      as rsmooth --device: auto, gpu, cpu, P:D or part of a name (default:\n"
    "                  RSMOOTH_DEVICE, else auto)\n"
    "  --repeat R      timed runs after the first, 1..99 (default 7)\n"
    "  --memory-budget SIZE  device memory one run may hold (e.g. 256M): larger meshes run in\n"
    "                  spatial tiles (\"tiles\" in the output)\n"
    "  --no-pairs      skip counting the useful pairs (and the roofline): seconds on big meshes\n"
    "  --no-roofline   skip the native roofline (several seconds)\n"
    "  The first program build compiles from source only when rsmooth's program cache\n"
    "  (RSMOOTH_CACHE_DIR) holds no binary of it (\"program_cache_first\": \"miss\"), and\n"
    "  PoCL's (POCL_CACHE_DIR) none either: point both at empty folders to time that.\n";

typedef struct filter_options {
    const char *mesh_path; /* NULL: generated */
    const char *device;
    double triangles, noise;
    bool shape_option_given; /* --triangles or --noise */
    rsmooth_params params;
    int repeat;
    uint64_t memory_budget; /* 0: the library's default */
    bool roofline, pairs;
} filter_options;

static int filter_usage_error(const char *message, const char *value) {
    fprintf(stderr, "rsmooth-bench filter: %s%s%s%s\nTry 'rsmooth-bench filter --help'.\n", message,
            value ? " '" : "", value ? value : "", value ? "'" : "");
    return EXIT_USAGE;
}

/* Returns -1 when the program should go on, else the exit status. */
static int parse_filter_args(int argc, char **argv, filter_options *opt) {
    memset(opt, 0, sizeof *opt);
    rsmooth_params_init(&opt->params);
    opt->triangles = 200000;
    opt->noise = 0.2;
    opt->repeat = 7;
    opt->roofline = true;
    opt->pairs = true;
    for (int i = 2; i < argc; i++) {
        const char *a = argv[i], *value = i + 1 < argc ? argv[i + 1] : NULL;
        double x = 0;
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            fputs(filter_usage, stdout);
            return EXIT_OK;
        } else if (!strcmp(a, "--no-roofline")) {
            opt->roofline = false;
        } else if (!strcmp(a, "--no-pairs")) {
            opt->pairs = opt->roofline = false;
        } else if (!strcmp(a, "--memory-budget")) {
            if (!value)
                return filter_usage_error("--memory-budget needs a value", NULL);
            if (!cli_parse_bytes(value, &opt->memory_budget) || opt->memory_budget == 0)
                return filter_usage_error("--memory-budget: not a byte count above 0 (leave it "
                                          "out for most of the device's memory):",
                                          value);
            i++;
        } else if (!strcmp(a, "--device")) {
            if (!value)
                return filter_usage_error("--device needs a value", NULL);
            opt->device = argv[++i];
        } else if (!strcmp(a, "--triangles") || !strcmp(a, "--noise") || !strcmp(a, "--sigma-f") ||
                   !strcmp(a, "--sigma-g") || !strcmp(a, "--repeat")) {
            if (!value)
                return filter_usage_error("an option needs a value:", a);
            if (!cli_parse_number(value, &x))
                return filter_usage_error("not a number:", value);
            i++;
            if (!strcmp(a, "--triangles")) {
                if (!(x >= 100 && x <= 1e9 && x == floor(x)))
                    return filter_usage_error("--triangles must be a whole number in [100, 1e9]:",
                                              value);
                opt->triangles = x;
                opt->shape_option_given = true;
            } else if (!strcmp(a, "--noise")) {
                if (!(x >= 0 && isfinite(x)))
                    return filter_usage_error("--noise must be >= 0 and finite:", value);
                opt->noise = x;
                opt->shape_option_given = true;
            } else if (!strcmp(a, "--sigma-f")) {
                if (!(x > 0 && isfinite(x)))
                    return filter_usage_error("--sigma-f must be a positive number:", value);
                opt->params.sigma_f = x;
            } else if (!strcmp(a, "--sigma-g")) {
                if (!(x > 0))
                    return filter_usage_error("--sigma-g must be positive, or 'inf':", value);
                opt->params.sigma_g = x;
            } else {
                if (!(x >= 1 && x <= 99 && x == floor(x)))
                    return filter_usage_error("--repeat must be a whole number in 1..99:", value);
                opt->repeat = (int)x;
            }
        } else if (a[0] == '-' && a[1] != '\0') {
            return filter_usage_error("unknown option", a);
        } else if (!opt->mesh_path) {
            opt->mesh_path = a;
        } else {
            return filter_usage_error("one mesh file only; unexpected", a);
        }
    }
    if (opt->mesh_path && opt->shape_option_given)
        return filter_usage_error("--triangles and --noise shape the generated mesh; not with",
                                  opt->mesh_path);
    return -1;
}

/* The mesh as rsmooth_smooth gets it: float32 positions, uint32 triangles (owned here). */
typedef struct bench_input {
    size_t vertex_count, triangle_count;
    float *positions;
    uint32_t *indices;
} bench_input;

static void bench_input_free(bench_input *in) {
    free(in->positions);
    free(in->indices);
    memset(in, 0, sizeof *in);
}

/* Fills `in` from doubles; 0, or -1 when memory runs out. */
static int bench_input_set(bench_input *in, const double *xyz, size_t vertex_count,
                           const uint32_t *indices, size_t triangle_count) {
    in->vertex_count = vertex_count;
    in->triangle_count = triangle_count;
    in->positions = malloc((vertex_count ? vertex_count : 1) * 3 * sizeof *in->positions);
    in->indices = malloc((triangle_count ? triangle_count : 1) * 3 * sizeof *in->indices);
    if (!in->positions || !in->indices)
        return -1;
    for (size_t i = 0; i < 3 * vertex_count; i++)
        in->positions[i] = (float)xyz[i];
    memcpy(in->indices, indices, triangle_count * 3 * sizeof *indices);
    return 0;
}

/* Reads MESH or generates the cylinder; prints what fails and returns an exit status. */
static int load_input(const filter_options *opt, bench_input *in) {
    memset(in, 0, sizeof *in);
    int failed;
    if (opt->mesh_path) {
        rsmooth_mesh *mesh = NULL;
        rsmooth_error err;
        rsmooth_status st = rsmooth_mesh_read_file(opt->mesh_path, &mesh, &err);
        if (st != RSMOOTH_OK) {
            if (err.line >= 0)
                fprintf(stderr, "rsmooth-bench: %s:%lld: %s\n", opt->mesh_path, (long long)err.line,
                        err.message);
            else
                fprintf(stderr, "rsmooth-bench: %s: %s\n", opt->mesh_path, err.message);
            return st == RSMOOTH_ERROR_OUT_OF_MEMORY ? EXIT_OTHER : EXIT_USAGE;
        }
        if (mesh->triangle_count == 0) {
            fprintf(stderr, "rsmooth-bench: %s: no triangles to smooth\n", opt->mesh_path);
            rsmooth_mesh_destroy(mesh);
            return EXIT_USAGE;
        }
        failed = bench_input_set(in, mesh->positions, mesh->vertex_count, mesh->triangles,
                                 mesh->triangle_count);
        rsmooth_mesh_destroy(mesh);
    } else {
        shape_mesh shape;
        if (shape_capped_cylinder(&shape, 1.0, 1.5, (size_t)opt->triangles) != 0 ||
            shape_add_normal_noise(&shape, opt->noise, 1) != 0) {
            fprintf(stderr, "rsmooth-bench: cannot generate a %.0f-triangle cylinder\n",
                    opt->triangles);
            return EXIT_OTHER;
        }
        failed =
            bench_input_set(in, shape.xyz, shape.vertex_count, shape.indices, shape.triangle_count);
        shape_free(&shape);
    }
    if (failed) {
        fprintf(stderr, "rsmooth-bench: out of memory for the mesh\n");
        bench_input_free(in);
        return EXIT_OTHER;
    }
    return EXIT_OK;
}

/* Creates a context, timed; prints what fails and returns an exit status. */
static int create_context(const char *device, uint64_t memory_budget, rsmooth_context **ctx,
                          double *ms) {
    rsmooth_error err;
    rsmooth_context_options o = {
        .struct_size = sizeof o, .device = device, .memory_budget = memory_budget};
    double t0 = now_ms();
    rsmooth_status st = rsmooth_context_create(&o, ctx, &err);
    *ms = now_ms() - t0;
    if (st == RSMOOTH_OK)
        return EXIT_OK;
    if (st == RSMOOTH_ERROR_INVALID_ARGUMENT) { /* a setting: RSMOOTH_MEMORY_BUDGET */
        fprintf(stderr, "rsmooth-bench: %s\n", err.message);
        return EXIT_USAGE;
    }
    fprintf(stderr, "rsmooth-bench: device '%s': %s: %s\n", device ? device : "auto",
            rsmooth_status_str(st), err.message);
    if (err.build_log[0])
        fprintf(stderr, "%s\n", err.build_log);
    return st == RSMOOTH_ERROR_OUT_OF_MEMORY ? EXIT_OTHER : EXIT_DEVICE;
}

/* Resident memory now, from /proc/self/statm; -1 when unreadable. */
static double rss_bytes(void) {
    long pages = -1, resident = -1;
    FILE *f = fopen("/proc/self/statm", "r");
    if (f) {
        if (fscanf(f, "%ld %ld", &pages, &resident) != 2)
            resident = -1;
        fclose(f);
    }
    return resident < 0 ? -1 : (double)resident * (double)sysconf(_SC_PAGESIZE);
}

/* Resets the peak resident size getrusage reports to the current one (Linux 4.0+), so the peak
 * read later is the filter's and not, say, the mesh generator's. False where refused. */
static bool reset_peak_rss(void) {
    FILE *f = fopen("/proc/self/clear_refs", "w");
    if (!f)
        return false;
    bool ok = fputs("5", f) >= 0;
    return fclose(f) == 0 && ok;
}

/* A number, or null where it does not exist (NaN, infinite). */
static void print_json_number(const char *key, double value) {
    if (isfinite(value))
        printf("\"%s\":%.6g", key, value);
    else
        printf("\"%s\":null", key);
}

/* One pass's pair figures. */
static void print_pass(const char *name, uint64_t examined, uint64_t useful, bool counted,
                       double median_ms, double roofline_pairs_per_s, bool roofline) {
    double per_s = median_ms > 0 && counted ? (double)useful / (median_ms / 1e3) : NAN;
    printf(",\"%s\":{\"examined\":%llu,", name, (unsigned long long)examined);
    if (counted)
        printf("\"useful\":%llu,", (unsigned long long)useful);
    else
        printf("\"useful\":null,");
    print_json_number("useful_pairs_per_s", per_s);
    putchar(',');
    print_json_number("waste",
                      examined > 0 && counted ? 1 - (double)useful / (double)examined : NAN);
    if (roofline) {
        putchar(',');
        print_json_number("roofline_pairs_per_s",
                          roofline_pairs_per_s > 0 ? roofline_pairs_per_s : NAN);
        putchar(',');
        print_json_number("ratio", roofline_pairs_per_s > 0 ? per_s / roofline_pairs_per_s : NAN);
    }
    putchar('}');
}

/* The stages of rsmooth_report, in the order they run. */
enum {
    STAGE_FACETS,
    STAGE_GRID,
    STAGE_UPLOAD,
    STAGE_MOLLIFY,
    STAGE_NORMALS,
    STAGE_ROBUST,
    STAGE_DOWNLOAD,
    STAGE_TOTAL,
    STAGE_COUNT
};
static const char *const stage_names[STAGE_COUNT] = {"facets",  "grid",   "upload",   "mollify",
                                                     "normals", "robust", "download", "total"};

static void stage_times(const rsmooth_report *r, double ms[STAGE_COUNT]) {
    const double v[STAGE_COUNT] = {r->ms_facets,  r->ms_grid,   r->ms_upload,   r->ms_mollify,
                                   r->ms_normals, r->ms_robust, r->ms_download, r->ms_total};
    memcpy(ms, v, sizeof v);
}

/* One filter benchmark: its options and input, the context and buffers it runs with, and the
 * figures it prints, filled in by its steps in the order they run. */
typedef struct filter_bench {
    filter_options opt;
    bench_input in;
    rsmooth_context *ctx;
    float *first, *out; /* the first run's output, and each timed run's */
    bench_grid grid;    /* the pair-counting grid */
    /* the program build, from source (unless cached) and again from the cache */
    double ms_create_first, ms_create_cached, ms_build_first, ms_build_cached;
    const char *cache_first, *cache_cached;
    double codegen_ms; /* the warm-up run on two triangles */
    bool peak_reset;
    double baseline, first_run_ms, first_run_peak, peak; /* bytes resident; ms */
    rsmooth_report report;                               /* the last run's */
    bool identical;                                      /* every timed run as the first */
    double median_ms[STAGE_COUNT], min_ms[STAGE_COUNT], max_ms[STAGE_COUNT];
    uint64_t useful_mollify, useful_robust;
    bench_roofline roof;
    bool have_roofline;
} filter_bench;

/* A context's info. */
static rsmooth_context_info context_info(const rsmooth_context *ctx) {
    rsmooth_context_info info = {.struct_size = sizeof info};
    rsmooth_context_get_info(ctx, &info);
    return info;
}

/* The context twice, to time the program build from source and from the cache; the second stays.
 * An exit status. */
static int build_programs(filter_bench *b) {
    /* The program build twice: from source (unless rsmooth's program cache has it), then from
     * the binary the first stored (or, with that cache off, from source with PoCL's). The
     * option's budget wins over the environment's, as in the rsmooth command. */
    int code = create_context(b->opt.device, b->opt.memory_budget, &b->ctx, &b->ms_create_first);
    if (code != EXIT_OK)
        return code;
    rsmooth_context_info info = {.struct_size = sizeof info};
    rsmooth_context_get_info(b->ctx, &info);
    b->ms_build_first = info.build_ms;
    b->cache_first = info.program_cache;
    rsmooth_context_destroy(b->ctx);
    b->ctx = NULL;
    code = create_context(b->opt.device, b->opt.memory_budget, &b->ctx, &b->ms_create_cached);
    if (code != EXIT_OK)
        return code;
    rsmooth_context_get_info(b->ctx, &info);
    b->ms_build_cached = info.build_ms;
    b->cache_cached = info.program_cache;
    return EXIT_OK;
}

/* The output buffers, touched, and the kernels' code generated on a tiny mesh: what the memory
 * baseline should count. An exit status. */
static int prepare_runs(filter_bench *b) {
    const size_t nv = b->in.vertex_count;
    b->first = malloc(nv * 3 * sizeof *b->first);
    b->out = malloc(nv * 3 * sizeof *b->out);
    if (!b->first || !b->out) {
        fprintf(stderr, "rsmooth-bench: out of memory for the output\n");
        return EXIT_OTHER;
    }
    memset(b->first, 0, nv * 3 * sizeof *b->first); /* touched, so the baseline counts them */
    memset(b->out, 0, nv * 3 * sizeof *b->out);
    /* PoCL generates each kernel's code at its first launch (about a second, and tens of MiB
     * that stay): a two-triangle mesh pays for that before the baseline is taken, so the memory
     * figures are the filter's own. */
    b->codegen_ms = 0;
    static const float tiny_xyz[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0.1f};
    static const uint32_t tiny_idx[] = {0, 1, 2, 2, 1, 3};
    float tiny_out[12];
    rsmooth_report tiny;
    rsmooth_error tiny_err;
    if (rsmooth_smooth(b->ctx, RSMOOTH_FLOAT32, tiny_xyz, 4, tiny_idx, 2, &b->opt.params, tiny_out,
                       &(rsmooth_outputs){.struct_size = sizeof(rsmooth_outputs), .report = &tiny},
                       &tiny_err) == RSMOOTH_OK)
        b->codegen_ms = tiny.ms_total;
    return EXIT_OK;
}

/* The first run, then the timed ones, with the memory they reach; each stage's median, min and
 * max. An exit status (the failure printed). */
static int time_runs(filter_bench *b) {
    const size_t nv = b->in.vertex_count, nt = b->in.triangle_count;
    const filter_options *opt = &b->opt;
    b->peak_reset = reset_peak_rss();
    b->baseline = rss_bytes();

    /* The first run includes PoCL's one-time code generation for each kernel. */
    memset(&b->report, 0, sizeof b->report);
    rsmooth_error err;
    rsmooth_status st = rsmooth_smooth(
        b->ctx, RSMOOTH_FLOAT32, b->in.positions, nv, b->in.indices, nt, &opt->params, b->first,
        &(rsmooth_outputs){.struct_size = sizeof(rsmooth_outputs), .report = &b->report}, &err);
    b->first_run_ms = b->report.ms_total;
    b->first_run_peak = (double)peak_rss_kib() * 1024;
    double ms[STAGE_COUNT][99];
    b->identical = true;
    for (int i = 0; i < opt->repeat && st == RSMOOTH_OK; i++) {
        st = rsmooth_smooth(
            b->ctx, RSMOOTH_FLOAT32, b->in.positions, nv, b->in.indices, nt, &opt->params, b->out,
            &(rsmooth_outputs){.struct_size = sizeof(rsmooth_outputs), .report = &b->report}, &err);
        double stage[STAGE_COUNT];
        stage_times(&b->report, stage);
        for (int s = 0; s < STAGE_COUNT; s++)
            ms[s][i] = stage[s];
        b->identical = b->identical && memcmp(b->first, b->out, nv * 3 * sizeof *b->out) == 0;
    }
    b->peak = (double)peak_rss_kib() * 1024;
    if (st != RSMOOTH_OK) {
        const char *name = opt->mesh_path ? opt->mesh_path : "generated mesh";
        if (st == RSMOOTH_ERROR_OPENCL)
            fprintf(stderr, "rsmooth-bench: %s: device '%s': %s\n", name,
                    context_info(b->ctx).device_name, err.message);
        else
            fprintf(stderr, "rsmooth-bench: %s: %s\n", name, err.message);
        return st == RSMOOTH_ERROR_OPENCL             ? EXIT_DEVICE
               : st == RSMOOTH_ERROR_INVALID_ARGUMENT ? EXIT_USAGE
                                                      : EXIT_OTHER;
    }
    for (int s = 0; s < STAGE_COUNT; s++) {
        b->median_ms[s] = median(ms[s], opt->repeat); /* sorts: min and max at the ends */
        b->min_ms[s] = ms[s][0];
        b->max_ms[s] = ms[s][opt->repeat - 1];
    }
    return EXIT_OK;
}

/* The useful pairs of each pass and the native roofline, counted after the peak was read: the
 * grid and the roofline use memory of their own. An exit status. */
static int count_pairs(filter_bench *b) {
    const rsmooth_report *report = &b->report;
    const size_t nv = b->in.vertex_count, nt = b->in.triangle_count;
    const double cell = fmax(report->radius, report->mollify_radius);
    if (report->facet_count > 0 && b->opt.pairs) {
        if (bench_grid_build(&b->grid, b->in.positions, b->in.indices, nt, cell) != 0) {
            fprintf(stderr, "rsmooth-bench: cannot build the pair-counting grid (out of memory, "
                            "or the mesh spans over 2^30 cells)\n");
            return EXIT_OTHER;
        }
        b->useful_robust = bench_pairs_within(&b->grid, b->in.positions, nv, report->radius);
        if (report->mollify_radius > 0)
            b->useful_mollify =
                bench_pairs_within(&b->grid, b->in.positions, nv, report->mollify_radius);
    }
    memset(&b->roof, 0, sizeof b->roof);
    b->have_roofline = false;
    if (b->opt.roofline && b->grid.facet_count > 0) {
        const bench_roofline_setup setup = {
            .sigma_f = report->sigma_f,
            .sigma_g = report->sigma_g,
            .sigma_m = report->sigma_f / 2, /* the library mollifies with sigma_f / 2 */
            .radius = report->radius,
            .mollify_radius = report->mollify_radius,
        };
        b->have_roofline = bench_roofline_run(&b->grid, b->in.positions, nv, &setup, &b->roof) == 0;
        if (!b->have_roofline)
            fprintf(stderr, "rsmooth-bench: roofline skipped: out of memory\n");
    }
    return EXIT_OK;
}

/* The JSON object's first part: the mesh, the widths, the run's layout and the device. */
static void print_setup(const filter_bench *b) {
    const filter_options *opt = &b->opt;
    const rsmooth_report *report = &b->report;
    printf("{\"mode\":\"filter\",\"mesh\":");
    cli_print_json_string(opt->mesh_path ? opt->mesh_path : "generated");
    if (!opt->mesh_path)
        printf(",\"noise\":%.6g", opt->noise);
    printf(",\"vertices\":%zu,\"triangles\":%zu,\"facets\":%zu,\"mean_edge_length\":%.6g,",
           b->in.vertex_count, b->in.triangle_count, report->facet_count, report->mean_edge_length);
    print_json_number("sigma_f", opt->params.sigma_f);
    putchar(',');
    print_json_number("sigma_g", opt->params.sigma_g); /* null: inf, the influence off */
    putchar(',');
    print_json_number("sigma_f_abs", report->sigma_f);
    putchar(',');
    print_json_number("sigma_g_abs", report->sigma_g);
    printf(",\"radius\":%.6g,\"mollify_radius\":%.6g,\"grid_cell_count\":%zu,\"tiles\":%zu,"
           "\"memory_budget\":%llu,\"device\":",
           report->radius, report->mollify_radius, report->grid_cell_count, report->tiles,
           (unsigned long long)context_info(b->ctx).memory_budget);
    cli_print_json_string(report->device);
    rsmooth_context_info info = context_info(b->ctx);
    printf(",\"kernel_variant\":\"%s\",\"lanes\":%u,\"work_group\":%zu",
           info.lanes > 1 ? "block" : "group", info.lanes, info.group);
}

/* The JSON object's rest: the times, the pairs, the roofline and the memory. */
static void print_figures(const filter_bench *b) {
    const filter_options *opt = &b->opt;
    const rsmooth_report *report = &b->report;
    printf(",\"repeat\":%d,\"context_create_first_ms\":%.1f,\"program_build_first_ms\":%.1f,"
           "\"context_create_cached_ms\":%.1f,\"program_build_cached_ms\":%.1f,"
           "\"program_cache_first\":\"%s\",\"program_cache_cached\":\"%s\","
           "\"kernel_codegen_ms\":%.2f,\"first_run_ms\":%.2f,\"ms\":{",
           opt->repeat, b->ms_create_first, b->ms_build_first, b->ms_create_cached,
           b->ms_build_cached, b->cache_first, b->cache_cached, b->codegen_ms, b->first_run_ms);
    for (int s = 0; s < STAGE_COUNT; s++)
        printf("%s\"%s\":{\"median\":%.3f,\"min\":%.3f,\"max\":%.3f}", s ? "," : "", stage_names[s],
               b->median_ms[s], b->min_ms[s], b->max_ms[s]);
    printf("},\"bit_identical\":%s", b->identical ? "true" : "false");
    print_pass("mollify", report->pairs_mollify, b->useful_mollify, opt->pairs,
               b->median_ms[STAGE_MOLLIFY], b->roof.mollify_pairs_per_s, b->have_roofline);
    print_pass("robust", report->pairs_robust, b->useful_robust, opt->pairs,
               b->median_ms[STAGE_ROBUST], b->roof.robust_pairs_per_s, b->have_roofline);
    const bench_roofline *roof = &b->roof;
    if (b->have_roofline)
        printf(",\"roofline\":{\"threads\":%d,\"openmp\":%s,\"lanes\":%d,\"window\":%zu,"
               "\"seconds\":%.2f}",
               roof->threads, roof->openmp ? "true" : "false", roof->lanes, roof->window,
               roof->seconds);
    else
        printf(",\"roofline\":null");
    const double nv = (double)b->in.vertex_count, nt = (double)b->in.triangle_count;
    const double input_bytes = nv * 3 * sizeof(float) + nt * 3 * sizeof(uint32_t);
    printf(",\"rss_baseline_MiB\":%.1f,\"peak_rss_MiB\":%.1f,\"first_run_peak_rss_MiB\":%.1f,"
           "\"peak_rss_reset\":%s,\"input_MiB\":%.1f,",
           b->baseline / 1048576, b->peak / 1048576, b->first_run_peak / 1048576,
           b->peak_reset ? "true" : "false", input_bytes / 1048576);
    print_json_number("filter_bytes_per_triangle",
                      b->baseline >= 0 ? (b->peak - b->baseline) / nt : NAN);
    printf("}\n");
}

static int bench_filter(int argc, char **argv) {
    filter_bench b;
    memset(&b, 0, sizeof b);
    int code = parse_filter_args(argc, argv, &b.opt);
    if (code >= 0)
        return code;
    if ((code = load_input(&b.opt, &b.in)) != EXIT_OK)
        return code;
    if ((code = build_programs(&b)) == EXIT_OK && (code = prepare_runs(&b)) == EXIT_OK &&
        (code = time_runs(&b)) == EXIT_OK && (code = count_pairs(&b)) == EXIT_OK) {
        print_setup(&b);
        print_figures(&b);
    }
    bench_grid_free(&b.grid);
    rsmooth_context_destroy(b.ctx);
    free(b.first);
    free(b.out);
    bench_input_free(&b.in);
    return code;
}

/* ---- points ---------------------------------------------------------------------------------- */

/* rsmooth-bench points: the point-cloud filter on the device (rsmooth_smooth_points) on a mesh's
 * vertices, with the normals of its noisy surface, against the mesh filter (rsmooth_smooth) on
 * that mesh: the same vertex count, float32 arrays both, the same sigmas. One JSON object of
 * medians over R runs after a first. */
static const char points_usage[] =
    "usage: rsmooth-bench points [MESH] [--vertices N] [--noise S] [--sigma-f X] [--sigma-g Y]\n"
    "                            [--device D] [--repeat R]\n"
    "  times rsmooth_smooth_points on a mesh's vertices (normals: the area-weighted ones of its\n"
    "  surface) against rsmooth_smooth on the mesh itself (paper's mollification, and bilateral\n"
    "  normals as the points take them): medians of R runs after a first, per-stage medians of\n"
    "  the points, whether repeats are bit-identical (JSON)\n"
    "  MESH            any mesh file rsmooth reads; default: the generated noisy closed cylinder\n"
    "  --vertices N    generated mesh: about N vertices (default 200000)\n"
    "  --noise S, --sigma-f X, --sigma-g Y, --device D, --repeat R: as 'filter' (default R 5)\n";

typedef struct points_bench {
    const char *mesh_path, *device;
    double vertices, noise;
    rsmooth_params params;
    int repeat;
    float *xyz, *normals, *out, *first;
    uint32_t *indices;
    size_t vertex_count, triangle_count;
    rsmooth_context *ctx;
} points_bench;

static int points_args(int argc, char **argv, points_bench *b) {
    rsmooth_params_init(&b->params);
    b->vertices = 200000;
    b->noise = 0.2;
    b->repeat = 5;
    for (int i = 2; i < argc; i++) {
        const char *a = argv[i], *value = i + 1 < argc ? argv[i + 1] : NULL;
        double x = 0;
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            fputs(points_usage, stdout);
            return EXIT_OK;
        } else if (!strcmp(a, "--device") && value) {
            b->device = argv[++i];
        } else if (value &&
                   (!strcmp(a, "--vertices") || !strcmp(a, "--noise") || !strcmp(a, "--sigma-f") ||
                    !strcmp(a, "--sigma-g") || !strcmp(a, "--repeat"))) {
            i++;
            bool ok = cli_parse_number(value, &x);
            if (!strcmp(a, "--vertices") && (ok = ok && x >= 50 && x <= 5e8))
                b->vertices = x;
            else if (!strcmp(a, "--noise") && (ok = ok && x >= 0 && isfinite(x)))
                b->noise = x;
            else if (!strcmp(a, "--sigma-f") && (ok = ok && x > 0 && isfinite(x)))
                b->params.sigma_f = x;
            else if (!strcmp(a, "--sigma-g") && (ok = ok && x > 0))
                b->params.sigma_g = x;
            else if (!strcmp(a, "--repeat") && (ok = ok && x >= 1 && x <= 99 && x == floor(x)))
                b->repeat = (int)x;
            if (!ok) {
                fprintf(stderr, "rsmooth-bench points: bad value for %s: '%s'\n", a, value);
                return EXIT_USAGE;
            }
        } else if (a[0] != '-' && !b->mesh_path) {
            b->mesh_path = a;
        } else {
            fprintf(stderr,
                    "rsmooth-bench points: unexpected '%s'\nTry 'rsmooth-bench points "
                    "--help'.\n",
                    a);
            return EXIT_USAGE;
        }
    }
    return -1;
}

/* The mesh (read or generated), its float32 positions and its area-weighted vertex normals. */
static int points_input(points_bench *b) {
    shape_mesh shape;
    memset(&shape, 0, sizeof shape);
    rsmooth_mesh *mesh = NULL;
    rsmooth_error err;
    if (b->mesh_path) {
        if (rsmooth_mesh_read_file(b->mesh_path, &mesh, &err) != RSMOOTH_OK) {
            fprintf(stderr, "rsmooth-bench: %s: %s\n", b->mesh_path, err.message);
            return EXIT_USAGE;
        }
        shape = (shape_mesh){mesh->vertex_count, mesh->positions, mesh->triangle_count,
                             mesh->triangles};
    } else if (shape_capped_cylinder(&shape, 1.0, 1.5, (size_t)(2 * b->vertices)) != 0 ||
               shape_add_normal_noise(&shape, b->noise, 1) != 0) {
        fprintf(stderr, "rsmooth-bench: cannot generate the cylinder\n");
        return EXIT_OTHER;
    }
    size_t nv = shape.vertex_count, nt = shape.triangle_count;
    double *normals = malloc((nv ? nv : 1) * 3 * sizeof *normals);
    b->xyz = malloc((nv ? nv : 1) * 3 * sizeof *b->xyz);
    b->normals = malloc((nv ? nv : 1) * 3 * sizeof *b->normals);
    b->out = malloc((nv ? nv : 1) * 3 * sizeof *b->out);
    b->first = malloc((nv ? nv : 1) * 3 * sizeof *b->first);
    b->indices = malloc((nt ? nt : 1) * 3 * sizeof *b->indices);
    int code = EXIT_OK;
    if (!normals || !b->xyz || !b->normals || !b->out || !b->first || !b->indices ||
        shape_vertex_normals(&shape, normals) != 0) {
        fprintf(stderr, "rsmooth-bench: out of memory for the mesh\n");
        code = EXIT_OTHER;
    } else {
        for (size_t i = 0; i < 3 * nv; i++) {
            b->xyz[i] = (float)shape.xyz[i];
            b->normals[i] = (float)normals[i];
        }
        memcpy(b->indices, shape.indices, nt * 3 * sizeof *b->indices);
        b->vertex_count = nv;
        b->triangle_count = nt;
    }
    free(normals);
    if (mesh)
        rsmooth_mesh_destroy(mesh);
    else
        shape_free(&shape);
    return code;
}

/* One run of what `which` names (0 points, 1 mesh, 2 mesh with bilateral normals), timed. */
static rsmooth_status points_run_one(points_bench *b, int which, rsmooth_report *r, double *ms) {
    rsmooth_params p = b->params;
    if (which == 2)
        p.normal_filter = RSMOOTH_NORMALS_BILATERAL;
    rsmooth_error err;
    rsmooth_report_init(r);
    double t0 = now_ms();
    rsmooth_status st =
        which == 0
            ? rsmooth_smooth_points(
                  b->ctx, RSMOOTH_FLOAT32, b->xyz, b->normals, b->vertex_count, &p, b->out, NULL,
                  &(rsmooth_outputs){.struct_size = sizeof(rsmooth_outputs), .report = r}, &err)
            : rsmooth_smooth(
                  b->ctx, RSMOOTH_FLOAT32, b->xyz, b->vertex_count, b->indices, b->triangle_count,
                  &p, b->out,
                  &(rsmooth_outputs){.struct_size = sizeof(rsmooth_outputs), .report = r}, &err);
    *ms = now_ms() - t0;
    if (st != RSMOOTH_OK)
        fprintf(stderr, "rsmooth-bench: %s: %s\n",
                which ? "rsmooth_smooth" : "rsmooth_smooth_points", err.message);
    return st;
}

static void print_points_figures(const points_bench *b, double med[3], double stages[6],
                                 bool identical) {
    printf("{\"mode\":\"points\",\"device\":\"%s\",\"input\":\"%s\",\"points\":%zu,"
           "\"triangles\":%zu,\"sigma_f\":%g,\"sigma_g\":%g,\"repeat\":%d,",
           context_info(b->ctx).device_name, b->mesh_path ? b->mesh_path : "cylinder",
           b->vertex_count, b->triangle_count, b->params.sigma_f, b->params.sigma_g, b->repeat);
    const char *keys[5] = {"points_ms", "mesh_ms", "mesh_bilateral_ms", "points_over_mesh",
                           "points_over_mesh_bilateral"};
    double values[5] = {med[0], med[1], med[2], med[0] / med[1], med[0] / med[2]};
    for (int k = 0; k < 5; k++) {
        print_json_number(keys[k], values[k]);
        printf(",");
    }
    static const char *const names[6] = {"spacing", "grid",   "upload",
                                         "normals", "robust", "download"};
    printf("\"points_stages_ms\":{");
    for (int s = 0; s < 6; s++)
        printf("%s\"%s\":%.3f", s ? "," : "", names[s], stages[s]);
    printf("},\"points_identical\":%s}\n", identical ? "true" : "false");
}

static int bench_points(int argc, char **argv) {
    points_bench b;
    memset(&b, 0, sizeof b);
    int code = points_args(argc, argv, &b);
    double ms_context = 0;
    if (code < 0 && (code = points_input(&b)) == EXIT_OK &&
        (code = create_context(b.device, 0, &b.ctx, &ms_context)) == EXIT_OK) {
        double runs[3][100], stage[6][100], med[3], stages[6];
        bool identical = true;
        rsmooth_report r;
        /* the three interleaved, so a busy machine slows each alike */
        for (int i = 0; i <= b.repeat && code == EXIT_OK; i++) /* the first not counted */
            for (int which = 0; which < 3 && code == EXIT_OK; which++) {
                double ms = 0;
                if (points_run_one(&b, which, &r, &ms) != RSMOOTH_OK) {
                    code = EXIT_OTHER;
                    break;
                }
                if (which == 0 && i == 0)
                    memcpy(b.first, b.out, b.vertex_count * 3 * sizeof *b.out);
                else if (which == 0)
                    identical &= !memcmp(b.first, b.out, b.vertex_count * 3 * sizeof *b.out);
                if (i == 0)
                    continue;
                runs[which][i - 1] = ms;
                if (which == 0) { /* ms_facets: the passes' spacings and areas (k-d tree) */
                    double s[6] = {r.ms_facets, r.ms_grid,
                                   r.ms_upload, r.ms_mollify + r.ms_normals,
                                   r.ms_robust, r.ms_download};
                    for (int k = 0; k < 6; k++)
                        stage[k][i - 1] = s[k];
                }
            }
        if (code == EXIT_OK) {
            for (int w = 0; w < 3; w++)
                med[w] = median(runs[w], b.repeat);
            for (int k = 0; k < 6; k++)
                stages[k] = median(stage[k], b.repeat);
            print_points_figures(&b, med, stages, identical);
        }
    }
    rsmooth_context_destroy(b.ctx);
    free(b.xyz), free(b.normals), free(b.out), free(b.first), free(b.indices);
    return code;
}

int main(int argc, char **argv) {
    if (argc >= 2 && !strcmp(argv[1], "io"))
        return bench_io(argc, argv);
    if (argc >= 2 && !strcmp(argv[1], "filter"))
        return bench_filter(argc, argv);
    if (argc >= 2 && !strcmp(argv[1], "best"))
        return bench_best(argc, argv);
    if (argc >= 2 && !strcmp(argv[1], "points"))
        return bench_points(argc, argv);
    bool help = argc >= 2 && (!strcmp(argv[1], "-h") || !strcmp(argv[1], "--help"));
    fprintf(help ? stdout : stderr,
            "%s%s"
            "  rsmooth-bench best [MESH] ...: the best mode against the paper filter, stage by "
            "stage\n"
            "  rsmooth-bench points ...: a point cloud on the device against the mesh filter\n"
            "Each prints one JSON object of figures on stdout, never a pass or fail; "
            "'rsmooth-bench MODE --help'\n(io, filter, best, points) prints one mode's help.\n",
            io_usage, filter_usage);
    return help ? EXIT_OK : EXIT_USAGE;
}
