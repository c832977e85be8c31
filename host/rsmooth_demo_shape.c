/* rsmooth-demo-shape: makes the demo's noisy shape with sharp edges (and its ground truth), and
 * measures a result against that truth. It is what `make demo` runs around the rsmooth command. */
#define _POSIX_C_SOURCE 200809L
#include "mesh_shapes.h"
#include "rsmooth.h"
#include "rsmooth_io.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char usage_text[] =
    "usage: rsmooth-demo-shape make NOISY TRUTH [--noise S] [--triangles N] [--seed K]\n"
    "       rsmooth-demo-shape compare RESULT TRUTH\n"
    "\n"
    "make     writes a closed capped cylinder (sharp rims, curved side, flat caps) of about N\n"
    "         triangles (default 40000) to TRUTH, and the same with Gaussian noise of S mean\n"
    "         edge lengths along the vertex normals (default 0.3, seed K) to NOISY.\n"
    "compare  prints the mean face-normal angle to TRUTH (degrees) and the RMS and maximum\n"
    "         vertex distance (mean edge lengths of TRUTH); both meshes share vertex order.\n";

static int to_io_mesh(const shape_mesh *s, rsmooth_mesh **out) {
    rsmooth_error err;
    if (rsmooth_mesh_create(s->vertex_count, s->triangle_count, 3 * s->triangle_count, out, &err) !=
        RSMOOTH_OK)
        return -1;
    rsmooth_mesh *m = *out;
    memcpy(m->positions, s->xyz, s->vertex_count * 3 * sizeof(double));
    for (size_t t = 0; t < s->triangle_count; t++) {
        m->face_offsets[t + 1] = (uint32_t)(3 * (t + 1));
        memcpy(m->face_indices + 3 * t, s->indices + 3 * t, 3 * sizeof(uint32_t));
    }
    m->precision = RSMOOTH_FLOAT64;
    return rsmooth_mesh_triangulate(m, &err) == RSMOOTH_OK ? 0 : -1;
}

static int write_shape(const shape_mesh *s, const char *path) {
    rsmooth_mesh *m = NULL;
    rsmooth_error err;
    if (to_io_mesh(s, &m) != 0) {
        fprintf(stderr, "rsmooth-demo-shape: out of memory\n");
        return 1;
    }
    rsmooth_status st = rsmooth_mesh_write_file(m, path, RSMOOTH_FORMAT_AUTO, &err);
    rsmooth_mesh_destroy(m);
    if (st != RSMOOTH_OK) {
        fprintf(stderr, "rsmooth-demo-shape: %s: %s\n", path, err.message);
        return 1;
    }
    return 0;
}

static int make(int argc, char **argv) {
    double noise = 0.3;
    long triangles = 40000;
    unsigned long long seed = 1;
    for (int i = 4; i < argc; i += 2) {
        if (i + 1 >= argc) {
            fprintf(stderr, "rsmooth-demo-shape: %s needs a value\n", argv[i]);
            return 2;
        }
        if (!strcmp(argv[i], "--noise"))
            noise = atof(argv[i + 1]);
        else if (!strcmp(argv[i], "--triangles"))
            triangles = atol(argv[i + 1]);
        else if (!strcmp(argv[i], "--seed"))
            seed = strtoull(argv[i + 1], NULL, 10);
        else {
            fprintf(stderr, "rsmooth-demo-shape: unknown option %s\n", argv[i]);
            return 2;
        }
    }
    if (!(noise >= 0) || triangles < 100) {
        fprintf(stderr, "rsmooth-demo-shape: need --noise >= 0 and --triangles >= 100\n");
        return 2;
    }
    shape_mesh truth, noisy;
    if (shape_capped_cylinder(&truth, 1.0, 1.5, (size_t)triangles) != 0 ||
        shape_copy(&truth, &noisy) != 0 || shape_add_normal_noise(&noisy, noise, seed) != 0) {
        fprintf(stderr, "rsmooth-demo-shape: cannot make the shape\n");
        return 1;
    }
    int code = write_shape(&noisy, argv[2]) || write_shape(&truth, argv[3]);
    if (code == 0)
        printf("made %s (noise %.2f mean edge lengths) and %s: %zu vertices, %zu triangles\n",
               argv[2], noise, argv[3], truth.vertex_count, truth.triangle_count);
    shape_free(&truth);
    shape_free(&noisy);
    return code;
}

static rsmooth_mesh *read_or_complain(const char *path) {
    rsmooth_mesh *m = NULL;
    rsmooth_error err;
    if (rsmooth_mesh_read_file(path, &m, &err) != RSMOOTH_OK) {
        fprintf(stderr, "rsmooth-demo-shape: %s: %s\n", path, err.message);
        return NULL;
    }
    return m;
}

static int compare(const char *result_path, const char *truth_path) {
    rsmooth_mesh *result = read_or_complain(result_path), *truth = read_or_complain(truth_path);
    int code = 2;
    if (!result || !truth)
        goto done;
    if (result->vertex_count != truth->vertex_count ||
        result->triangle_count != truth->triangle_count) {
        fprintf(stderr, "rsmooth-demo-shape: %s and %s differ in vertex or triangle count\n",
                result_path, truth_path);
        goto done;
    }
    shape_mesh t = {truth->vertex_count, truth->positions, truth->triangle_count, truth->triangles};
    double edge = shape_mean_edge_length(&t), sum2 = 0, max = 0;
    for (size_t v = 0; v < truth->vertex_count; v++) {
        double d2 = 0;
        for (int k = 0; k < 3; k++) {
            double d = result->positions[3 * v + k] - truth->positions[3 * v + k];
            d2 += d * d;
        }
        sum2 += d2;
        max = fmax(max, sqrt(d2));
    }
    printf("%s: normal error %.2f deg, vertex error rms %.4f max %.4f mean edge lengths\n",
           result_path, shape_face_normal_error_deg(&t, result->positions),
           sqrt(sum2 / (double)truth->vertex_count) / edge, max / edge);
    code = 0;
done:
    rsmooth_mesh_destroy(result);
    rsmooth_mesh_destroy(truth);
    return code;
}

int main(int argc, char **argv) {
    if (argc >= 4 && !strcmp(argv[1], "make"))
        return make(argc, argv);
    if (argc == 4 && !strcmp(argv[1], "compare"))
        return compare(argv[2], argv[3]);
    fputs(usage_text,
          argc > 1 && (!strcmp(argv[1], "-h") || !strcmp(argv[1], "--help")) ? stdout : stderr);
    return argc > 1 && (!strcmp(argv[1], "-h") || !strcmp(argv[1], "--help")) ? 0 : 2;
}
