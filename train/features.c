/* rsmooth-train-features: the learned normals' descriptors of one mesh, as the library computes
 * them (lib/learned/), written as NumPy arrays for train/. The training reads the very numbers
 * the library will feed the network, so the two never disagree on what a descriptor is.
 *
 *   rsmooth-train-features MESH OUTDIR [--model FILE --stages S] [--predict]
 *                          [--truth CLEAN | --truth-surface SURFACE]
 *
 * With --model, the first S stages run first and the descriptors are those the next stage reads;
 * --predict also writes every stage's output normals (the library's reference path, double).
 * --noise-from takes the noise level from another mesh (the noisy input, when MESH is the result
 * of the stage before the learned one). --truth names the clean mesh (the same triangles): each
 * facet's target is its clean normal;
 * --truth-surface a surface to measure against (a range scan's reconstruction): each facet's
 * target is the normal of the surface's triangle nearest its centroid. Both also write how sharp
 * the truth is around each facet (1 - the least cosine between its target and its 8 nearest
 * facets' targets), which the training samples by.
 * Writes OUTDIR/{descriptor,frame,normal,triangle}.npy, predicted.npy with --predict and
 * {target,sharp}.npy with a truth. */
#include "learned/learned.h"
#include "metrics/surface_index.h"
#include "rsmooth.h"
#include "rsmooth_io.h"
#include "stages/normal_update.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int fail(const char *what, const char *detail) {
    fprintf(stderr, "rsmooth-train-features: %s: %s\n", what, detail);
    return 1;
}

/* Writes a C-order .npy (version 1.0) of `count` rows of `cols` values of `descr` ("<f4", "<u4",
 * "<f8"), each value `size` bytes. */
static int write_npy(const char *dir, const char *name, const char *descr, const void *data,
                     size_t count, size_t cols, size_t size) {
    char path[4096], header[256];
    snprintf(path, sizeof path, "%s/%s.npy", dir, name);
    int n = snprintf(header, sizeof header,
                     "{'descr': '%s', 'fortran_order': False, 'shape': (%zu, %zu), }", descr, count,
                     cols);
    int total = 10 + n + 1, pad = (64 - total % 64) % 64;
    FILE *f = fopen(path, "wb");
    if (!f)
        return fail(path, strerror(errno));
    unsigned short len = (unsigned short)(n + pad + 1);
    fwrite("\x93NUMPY\x01\x00", 1, 8, f);
    fputc(len & 0xff, f);
    fputc(len >> 8, f);
    fwrite(header, 1, (size_t)n, f);
    for (int i = 0; i < pad; i++)
        fputc(' ', f);
    fputc('\n', f);
    size_t written = count ? fwrite(data, size, count * cols, f) : 0;
    if (fclose(f) != 0 || written != count * cols)
        return fail(path, "could not be written");
    return 0;
}

static float *to_float(const double *v, size_t count) {
    float *out = malloc(count ? count * sizeof(float) : 1);
    for (size_t i = 0; out && i < count; i++)
        out[i] = (float)v[i];
    return out;
}

/* The descriptors and frames of every facet with the given stage-input normals. */
static int write_descriptors(const char *dir, const rs_learned_input *in) {
    size_t n = in->facet_count;
    float *desc = malloc((n ? n : 1) * RS_LEARNED_INPUTS * sizeof(float));
    float *frames = malloc((n ? n : 1) * 9 * sizeof(float));
    if (!desc || !frames)
        return fail(dir, "out of memory");
    double d[RS_LEARNED_INPUTS], frame[3][3];
    for (size_t f = 0; f < n; f++) {
        rs_learned_descriptor(in, f, d, frame);
        for (int k = 0; k < RS_LEARNED_INPUTS; k++)
            desc[f * RS_LEARNED_INPUTS + k] = (float)d[k];
        for (int k = 0; k < 9; k++)
            frames[f * 9 + k] = (float)frame[k / 3][k % 3];
    }
    int rc = write_npy(dir, "descriptor", "<f4", desc, n, RS_LEARNED_INPUTS, 4) ||
             write_npy(dir, "frame", "<f4", frames, n, 9, 4);
    free(desc);
    free(frames);
    return rc;
}

static void triangle_normal(const double *xyz, const uint32_t *t, double n[3]) {
    double a[3], b[3];
    rs_sub3(xyz + 3 * (size_t)t[1], xyz + 3 * (size_t)t[0], a);
    rs_sub3(xyz + 3 * (size_t)t[2], xyz + 3 * (size_t)t[0], b);
    rs_cross3(a, b, n);
    double len = sqrt(rs_dot3(n, n));
    if (len > 0)
        rs_scale3(n, 1.0 / len);
}

/* Each facet's target normal from the truth (by triangle, or nearest on a surface), and how
 * sharp the truth is around it. */
static int write_targets(const char *dir, const char *path, bool surface, const rs_facets *facets,
                         const rs_learned_patches *patches, size_t triangle_count) {
    rsmooth_error err;
    rsmooth_mesh *truth = NULL;
    if (rsmooth_mesh_read_file(path, &truth, &err) != RSMOOTH_OK)
        return fail(path, err.message);
    if (!surface && truth->triangle_count != triangle_count)
        return fail(path, "not the same triangles as the mesh (use --truth-surface)");
    size_t n = facets->count;
    float *target = malloc((n ? n : 1) * 3 * sizeof(float));
    float *sharp = malloc((n ? n : 1) * sizeof(float));
    double *t = malloc((n ? n : 1) * 3 * sizeof(double));
    rs_surface_index *index = surface
                                  ? rs_surface_index_build(truth->positions, truth->vertex_count,
                                                           truth->triangles, truth->triangle_count)
                                  : NULL;
    if (!target || !sharp || !t || (surface && !index))
        return fail(path, "out of memory");
    for (size_t f = 0; f < n; f++) {
        size_t tri = facets->triangle[f];
        if (surface) {
            double closest[3];
            rs_surface_index_query(index, facets->centroid + 3 * f, closest, &tri);
        }
        triangle_normal(truth->positions, truth->triangles + 3 * tri, t + 3 * f);
        for (int k = 0; k < 3; k++)
            target[3 * f + k] = (float)t[3 * f + k];
    }
    for (size_t f = 0; f < n; f++) {
        double least = 1.0;
        for (int k = 1; k <= 8; k++) {
            double c = rs_dot3(t + 3 * f,
                               t + 3 * (size_t)patches->neighbour[f * RS_LEARNED_NEIGHBOURS + k]);
            least = c < least ? c : least;
        }
        sharp[f] = (float)(1.0 - least);
    }
    int rc = write_npy(dir, "target", "<f4", target, n, 3, 4) ||
             write_npy(dir, "sharp", "<f4", sharp, n, 1, 4);
    rs_surface_index_free(index);
    free(target);
    free(sharp);
    free(t);
    rsmooth_mesh_destroy(truth);
    return rc;
}

static rsmooth_status read_model(const char *path, rs_learned_model *model, rsmooth_error *err) {
    FILE *f = fopen(path, "rb");
    if (!f) {
        fail(path, strerror(errno));
        return RSMOOTH_ERROR_IO;
    }
    static unsigned char bytes[1 << 24];
    size_t size = fread(bytes, 1, sizeof bytes, f);
    fclose(f);
    return rs_learned_model_read(bytes, size, model, err, path);
}

int main(int argc, char **argv) {
    const char *mesh_path = NULL, *dir = NULL, *model_path = NULL, *truth_path = NULL;
    const char *noise_from = NULL;
    bool truth_surface = false;
    int stages = 0;
    bool predict = false;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--model") && i + 1 < argc)
            model_path = argv[++i];
        else if (!strcmp(argv[i], "--stages") && i + 1 < argc)
            stages = atoi(argv[++i]);
        else if ((!strcmp(argv[i], "--truth") || !strcmp(argv[i], "--truth-surface")) &&
                 i + 1 < argc) {
            truth_surface = !strcmp(argv[i], "--truth-surface");
            truth_path = argv[++i];
        } else if (!strcmp(argv[i], "--noise-from") && i + 1 < argc)
            noise_from = argv[++i];
        else if (!strcmp(argv[i], "--predict"))
            predict = true;
        else if (!mesh_path)
            mesh_path = argv[i];
        else if (!dir)
            dir = argv[i];
        else
            return fail(argv[i], "unexpected argument (usage: MESH OUTDIR [--model FILE "
                                 "--stages S] [--predict])");
    }
    if (!mesh_path || !dir)
        return fail("usage", "rsmooth-train-features MESH OUTDIR [--model FILE --stages S] "
                             "[--predict]");
    rsmooth_error err;
    rsmooth_mesh *mesh = NULL;
    if (rsmooth_mesh_read_file(mesh_path, &mesh, &err) != RSMOOTH_OK)
        return fail(mesh_path, err.message);
    rs_learned_model model = {0};
    if ((model_path || predict) &&
        (model_path ? read_model(model_path, &model, &err)
                    : rs_learned_model_builtin(&model, &err)) != RSMOOTH_OK)
        return fail(model_path ? model_path : "built-in model", err.message);
    rs_facets facets;
    double mean_edge = 0, noise = 0;
    if (!rs_facets_build(&facets, mesh->positions, mesh->triangles, mesh->triangle_count) ||
        !rs_mean_edge_length(mesh->positions, mesh->vertex_count, mesh->triangles,
                             mesh->triangle_count, &mean_edge))
        return fail(mesh_path, "out of memory");
    rsmooth_mesh *noisy = mesh;
    if (noise_from && rsmooth_mesh_read_file(noise_from, &noisy, &err) != RSMOOTH_OK)
        return fail(noise_from, err.message);
    if (rsmooth_estimate_noise(RSMOOTH_FLOAT64, noisy->positions, noisy->vertex_count,
                               noisy->triangles, noisy->triangle_count, &noise, &err) != RSMOOTH_OK)
        return fail(noise_from ? noise_from : mesh_path, err.message);
    if (noisy != mesh)
        rsmooth_mesh_destroy(noisy);
    rs_learned_patches patches;
    if (!rs_learned_patches_build(&patches, facets.centroid, facets.count))
        return fail(mesh_path, "out of memory");
    rs_learned_input in = {facets.count, facets.centroid, facets.area, facets.normal,
                           &patches,     mean_edge,       noise};
    size_t n = facets.count;
    double *normals = malloc((n ? n : 1) * 3 * sizeof(double));
    memcpy(normals, facets.normal, n * 3 * sizeof(double));
    if (stages > 0 && !rs_learned_normals(&model, stages, &in, NULL, normals))
        return fail(mesh_path, "out of memory");
    in.normal = normals;
    float *nf = to_float(normals, 3 * n);
    int rc = write_descriptors(dir, &in) || write_npy(dir, "normal", "<f4", nf, n, 3, 4) ||
             write_npy(dir, "triangle", "<u4", facets.triangle, n, 1, 4);
    if (!rc && truth_path)
        rc = write_targets(dir, truth_path, truth_surface, &facets, &patches, mesh->triangle_count);
    if (!rc && predict) {
        in.normal = facets.normal;
        rs_learned_normals(&model, (int)model.stage_count, &in, NULL, normals);
        rc = write_npy(dir, "predicted", "<f8", normals, n, 3, 8);
    }
    printf("%s: %zu facets, mean edge %.9g, noise %.4f mean edges\n", mesh_path, n, mean_edge,
           noise);
    free(nf);
    free(normals);
    rs_learned_patches_free(&patches);
    rs_facets_free(&facets);
    rs_learned_model_free(&model);
    rsmooth_mesh_destroy(mesh);
    return rc;
}
