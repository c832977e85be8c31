/* rsmooth-bench: prints figures, never asserts them (machines here are shared and noisy; compare
 * ratios measured in one run, and medians).
 *
 *   rsmooth-bench io [--triangles N] [--repeat R] [--dir DIR]
 *     Mesh file speed: writes and reads a binary PLY (and an OBJ) of a generated N-triangle mesh,
 *     beside a raw write and read of the same number of bytes in the same process: the
 *     disk-bound limit. One JSON object on stdout with medians over R repetitions. */
#define _POSIX_C_SOURCE 200809L
#include "mesh_shapes.h"
#include "rsmooth.h"
#include "rsmooth_io.h"

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

static int bench_io(int argc, char **argv) {
    long triangles = 1000000;
    int repeat = 3;
    const char *dir = "/tmp";
    for (int i = 2; i + 1 < argc; i += 2) {
        if (!strcmp(argv[i], "--triangles"))
            triangles = atol(argv[i + 1]);
        else if (!strcmp(argv[i], "--repeat"))
            repeat = atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--dir"))
            dir = argv[i + 1];
        else {
            fprintf(stderr, "rsmooth-bench: unknown option %s\n", argv[i]);
            return 2;
        }
    }
    if (triangles < 100 || repeat < 1 || repeat > 99) {
        fprintf(stderr, "rsmooth-bench: need --triangles >= 100 and --repeat in 1..99\n");
        return 2;
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

int main(int argc, char **argv) {
    if (argc >= 2 && !strcmp(argv[1], "io"))
        return bench_io(argc, argv);
    fprintf(stderr,
            "usage: rsmooth-bench io [--triangles N] [--repeat R] [--dir DIR]\n"
            "  prints mesh-file read/write speed beside raw I/O of the same bytes (JSON)\n");
    return argc >= 2 && (!strcmp(argv[1], "-h") || !strcmp(argv[1], "--help")) ? 0 : 2;
}
