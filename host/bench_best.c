/* rsmooth-bench best: the best mode's time beside the paper filter's, stage by stage, with its
 * normal-update stage on the host (double) and on the device (double, float32), alternating in one
 * run so the ratios are fair on a shared machine; and, with --drift, how far the device's stage is
 * from the host's after 1, 10, 100 and 1000 cycles in each precision. Prints one JSON object. */
#define _POSIX_C_SOURCE 200809L
#include "bench_best.h"
#include "mesh_shapes.h"
#include "rsmooth.h"
#include "rsmooth_io.h"

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static const char usage[] =
    "usage: rsmooth-bench best [MESH] [--triangles N] [--device D] [--repeat R] [--auto]\n"
    "                          [--drift]\n"
    "  times the best mode (rsmooth_params_init_best: the normal-update stage, then a robust\n"
    "  pass) against the paper filter at its defaults on the same device, the stage on the host\n"
    "  (double) and on the device (double where it has fp64, and float32): medians of R runs of\n"
    "  each, in turn, with the stage's parts (lists, upload, cycles, download), its bytes moved\n"
    "  and how far the device's result is from the host's, and the best mode with the learned\n"
    "  stage (--stage learned: its networks on the device) (JSON)\n"
    "  MESH            any mesh file rsmooth reads; default: a generated closed cylinder\n"
    "  --triangles N   generated mesh: about N triangles, noise 0.2 (default 200000)\n"
    "  --device D      as rsmooth --device (default: RSMOOTH_DEVICE, else auto)\n"
    "  --repeat R      timed runs of each, 1..99 (default 5)\n"
    "  --auto          the best mode as --best --auto runs it (parameters from the noise)\n"
    "  --drift         also the device stage's deviation from the host's after 1, 10, 100 and\n"
    "                  1000 cycles of one update, float32 and double (minutes)\n";

static double now_ms(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

static int compare_doubles(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *v, int n) {
    qsort(v, (size_t)n, sizeof *v, compare_doubles);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

typedef struct mesh_in {
    double *xyz;
    uint32_t *indices;
    size_t vertex_count, triangle_count;
    rsmooth_mesh *file; /* when read from a file: owns xyz and indices */
    shape_mesh shape;   /* when generated */
} mesh_in;

/* The modes timed, in the order each round runs them. */
enum { PAPER, BEST_HOST, BEST_DEVICE, BEST_FLOAT, BEST_LEARNED, MODES };
static const char *const mode_names[MODES] = {"paper", "best_stage_host", "best_stage_device",
                                              "best_stage_device_float32", "best_learned"};

typedef struct figures {
    double total[99], stage[99], lists[99], upload[99], cycles[99], download[99];
    rsmooth_report last;
} figures;

static int run(rsmooth_context *ctx, const mesh_in *m, const rsmooth_params *p, int mode,
               double *out, rsmooth_report *report) {
    setenv("RSMOOTH_STAGE", mode == BEST_HOST ? "host" : "device", 1);
    if (mode == BEST_FLOAT)
        setenv("RSMOOTH_STAGE_PRECISION", "float", 1);
    else
        unsetenv("RSMOOTH_STAGE_PRECISION");
    rsmooth_error err;
    rsmooth_report_init(report);
    rsmooth_status st = rsmooth_smooth(
        ctx, RSMOOTH_FLOAT64, m->xyz, m->vertex_count, m->indices, m->triangle_count, p, out,
        &(rsmooth_outputs){.struct_size = sizeof(rsmooth_outputs), .report = report}, &err);
    if (st != RSMOOTH_OK)
        fprintf(stderr, "rsmooth-bench best: %s: %s\n", rsmooth_status_str(st), err.message);
    return st == RSMOOTH_OK ? 0 : 1;
}

/* A JSON string: quotes, backslashes and control characters escaped. */
static void print_string(const char *s) {
    putchar('"');
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\')
            printf("\\%c", c);
        else if (c < 0x20)
            printf("\\u%04x", c);
        else
            putchar(c);
    }
    putchar('"');
}

static double max_gap(const double *a, const double *b, size_t nv, double edge) {
    double worst = 0;
    for (size_t v = 0; v < nv; v++) {
        double d2 = 0;
        for (int k = 0; k < 3; k++)
            d2 += (a[3 * v + k] - b[3 * v + k]) * (a[3 * v + k] - b[3 * v + k]);
        worst = fmax(worst, sqrt(d2) / edge);
    }
    return worst;
}

/* The stage alone after 1..1000 cycles of one update: the device's deviation from the host's. */
static int print_drift(rsmooth_context *ctx, const mesh_in *m, const rsmooth_params *best,
                       double *a, double *b) {
    printf(",\"drift\":[");
    for (int cycles = 1, first = 1; cycles <= 1000; cycles *= 10, first = 0) {
        rsmooth_params p = *best;
        p.passes = 0;
        p.stage_repeats = cycles;
        p.vertex_updates = 1;
        rsmooth_report r;
        double dev[2];
        if (run(ctx, m, &p, BEST_HOST, a, &r))
            return 1;
        for (int i = 0; i < 2; i++) {
            if (run(ctx, m, &p, i ? BEST_DEVICE : BEST_FLOAT, b, &r))
                return 1;
            dev[i] = max_gap(a, b, m->vertex_count, r.mean_edge_length);
        }
        printf("%s{\"cycles\":%d,\"float32\":%.3g,\"double\":%.3g}", first ? "" : ",", cycles,
               dev[0], dev[1]);
        fflush(stdout);
    }
    printf("]");
    return 0;
}

static void print_mode(int mode, figures *f, int repeat, double paper) {
    const rsmooth_report *r = &f->last;
    double total = median(f->total, repeat);
    printf(",\"%s\":{\"ms_total\":%.3f,\"ratio_to_paper\":%.3f", mode_names[mode], total,
           total / paper);
    if (mode != PAPER)
        printf(",\"stage\":{\"on_device\":%s,\"float_bits\":%d,\"cycles\":%d,"
               "\"bytes_to_device\":%llu,\"bytes_from_device\":%llu,\"ms\":{\"total\":%.3f,"
               "\"lists\":%.3f,\"upload\":%.3f,\"cycles\":%.3f,\"download\":%.3f}}",
               r->stage_on_device ? "true" : "false", r->stage_float_bits, r->stage_cycles,
               (unsigned long long)r->stage_bytes_to_device,
               (unsigned long long)r->stage_bytes_from_device, median(f->stage, repeat),
               median(f->lists, repeat), median(f->upload, repeat), median(f->cycles, repeat),
               median(f->download, repeat));
    printf("}");
}

static int load(const char *path, double triangles, mesh_in *m) {
    memset(m, 0, sizeof *m);
    if (path) {
        rsmooth_error err;
        if (rsmooth_mesh_read_file(path, &m->file, &err) != RSMOOTH_OK) {
            fprintf(stderr, "rsmooth-bench: %s: %s\n", path, err.message);
            return 2;
        }
        m->xyz = m->file->positions;
        m->indices = m->file->triangles;
        m->vertex_count = m->file->vertex_count;
        m->triangle_count = m->file->triangle_count;
        return 0;
    }
    if (shape_capped_cylinder(&m->shape, 1.0, 1.5, (size_t)triangles) != 0 ||
        shape_add_normal_noise(&m->shape, 0.2, 1) != 0) {
        fprintf(stderr, "rsmooth-bench: cannot generate a %.0f-triangle cylinder\n", triangles);
        return 1;
    }
    m->xyz = m->shape.xyz;
    m->indices = m->shape.indices;
    m->vertex_count = m->shape.vertex_count;
    m->triangle_count = m->shape.triangle_count;
    return 0;
}

/* Parses the options; returns -1 to go on, else the exit status. */
static int parse(int argc, char **argv, const char **path, double *triangles, const char **device,
                 int *repeat, bool *automatic, bool *drift) {
    for (int i = 2; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            fputs(usage, stdout);
            return 0;
        } else if (!strcmp(a, "--auto")) {
            *automatic = true;
        } else if (!strcmp(a, "--drift")) {
            *drift = true;
        } else if (!strcmp(a, "--triangles") || !strcmp(a, "--device") || !strcmp(a, "--repeat")) {
            if (i + 1 >= argc) {
                fprintf(stderr, "rsmooth-bench best: %s needs a value\n%s", a, usage);
                return 2;
            }
            const char *v = argv[++i];
            char *end = NULL;
            double x = strcmp(a, "--device") ? strtod(v, &end) : 0;
            if (!strcmp(a, "--device"))
                *device = v;
            else if (*end || !(x >= (a[2] == 't' ? 100 : 1)) || x > (a[2] == 't' ? 1e9 : 99) ||
                     x != floor(x)) {
                fprintf(stderr, "rsmooth-bench best: %s: not a whole number in range: %s\n", a, v);
                return 2;
            } else if (a[2] == 't') {
                *triangles = x;
            } else {
                *repeat = (int)x;
            }
        } else if (a[0] == '-' || *path) {
            fprintf(stderr, "rsmooth-bench best: unexpected %s\n%s", a, usage);
            return 2;
        } else {
            *path = a;
        }
    }
    return -1;
}

int bench_best(int argc, char **argv) {
    const char *path = NULL, *device = NULL;
    double triangles = 200000;
    int repeat = 5;
    bool automatic = false, drift = false;
    int code = parse(argc, argv, &path, &triangles, &device, &repeat, &automatic, &drift);
    if (code >= 0)
        return code;
    mesh_in m;
    if ((code = load(path, triangles, &m)) != 0)
        return code;
    rsmooth_context *ctx = NULL;
    rsmooth_error err;
    if (rsmooth_context_create(
            &(rsmooth_context_options){.struct_size = sizeof(rsmooth_context_options),
                                       .device = device},
            &ctx, &err) != RSMOOTH_OK) {
        fprintf(stderr, "rsmooth-bench best: %s\n", err.message);
        code = 3;
        goto done;
    }
    rsmooth_params params[MODES];
    rsmooth_params_init(&params[PAPER]);
    rsmooth_params_init_best(&params[BEST_HOST]);
    double ms_auto = 0;
    if (automatic) {
        double t0 = now_ms();
        if (rsmooth_params_auto(RSMOOTH_FLOAT64, m.xyz, m.vertex_count, m.indices, m.triangle_count,
                                &params[BEST_HOST], NULL, &err) != RSMOOTH_OK) {
            fprintf(stderr, "rsmooth-bench best: --auto: %s\n", err.message);
            code = 1;
            goto done;
        }
        ms_auto = now_ms() - t0;
    }
    params[BEST_DEVICE] = params[BEST_FLOAT] = params[BEST_LEARNED] = params[BEST_HOST];
    /* the learned stage (docs/model.md): its networks on the device, its descriptors on the host */
    params[BEST_LEARNED].stage_normals = RSMOOTH_STAGE_NORMALS_LEARNED;
    size_t nv = m.vertex_count;
    double *out[MODES];
    figures *f = calloc(MODES, sizeof *f);
    code = f == NULL;
    for (int i = 0; i < MODES; i++)
        out[i] = malloc((nv ? nv : 1) * 3 * sizeof(double));
    for (int i = 0; i < MODES && f; i++)
        code |= !out[i] || run(ctx, &m, &params[i], i, out[i], &f[i].last); /* warm-up */
    for (int k = 0; k < repeat && !code; k++)
        for (int i = 0; i < MODES && !code; i++) {
            rsmooth_report *r = &f[i].last;
            double t0 = now_ms();
            code = run(ctx, &m, &params[i], i, out[i], r);
            f[i].total[k] = now_ms() - t0;
            f[i].stage[k] = r->ms_stage;
            f[i].lists[k] = r->ms_stage_lists;
            f[i].upload[k] = r->ms_stage_upload;
            f[i].cycles[k] = r->ms_stage_cycles;
            f[i].download[k] = r->ms_stage_download;
        }
    if (!code) {
        double edge = f[PAPER].last.mean_edge_length;
        printf("{\"mesh\":");
        print_string(path ? path : "generated cylinder");
        printf(",\"vertices\":%zu,\"triangles\":%zu,\"device\":", nv, m.triangle_count);
        rsmooth_context_info info = {.struct_size = sizeof info};
        rsmooth_context_get_info(ctx, &info);
        print_string(info.device_name);
        printf(",\"repeat\":%d,\"auto\":%s,\"ms_auto_estimate\":%.3f", repeat,
               automatic ? "true" : "false", ms_auto);
        double paper = median(f[PAPER].total, repeat);
        for (int i = 0; i < MODES; i++)
            print_mode(i, &f[i], repeat, paper);
        printf(",\"device_from_host_max\":{\"double\":%.3g,\"float32\":%.3g}",
               max_gap(out[BEST_DEVICE], out[BEST_HOST], nv, edge),
               max_gap(out[BEST_FLOAT], out[BEST_HOST], nv, edge));
        if (drift)
            code = print_drift(ctx, &m, &params[BEST_HOST], out[BEST_HOST], out[BEST_DEVICE]);
        printf("}\n");
    }
    for (int i = 0; i < MODES; i++)
        free(out[i]);
    free(f);
done:
    unsetenv("RSMOOTH_STAGE");
    unsetenv("RSMOOTH_STAGE_PRECISION");
    rsmooth_context_destroy(ctx);
    if (m.file)
        rsmooth_mesh_destroy(m.file);
    else
        shape_free(&m.shape);
    return code;
}
