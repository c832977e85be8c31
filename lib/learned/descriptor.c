/* Each facet's descriptor for the learned normals: its patch (the nearest facets by centroid, so
 * no connectivity is needed: soups and cracked scans have patches too), seen in a frame of its
 * own so that the network learns one case for every orientation. The frame is the eigenbasis of
 * the patch's normal voting tensor: z the dominant normal direction (turned to the patch's mean
 * normal), x the direction across a crease (turned so the mean normal leans toward +x). Where the
 * sign rules are unstable (a balanced crease, a flat patch) the two choices are mirror images,
 * and training sees both. */
#include "auto/eigen3.h"
#include "core/spatial.h"
#include "learned/learned.h"

#include <math.h>
#include <string.h>

typedef struct patch_job {
    rs_learned_patches *patches;
    const rs_kdtree *tree;
    const double *centroid;
    size_t k; /* neighbours other than the facet itself */
} patch_job;

static void find_patches(void *ctx, size_t begin, size_t end, size_t chunk) {
    (void)chunk;
    patch_job *job = ctx;
    double dist2[RS_LEARNED_NEIGHBOURS];
    for (size_t f = begin; f < end; f++) {
        uint32_t *row = job->patches->neighbour + f * RS_LEARNED_NEIGHBOURS;
        row[0] = (uint32_t)f;
        size_t found = rs_kdtree_nearest_ids(job->tree, job->centroid + 3 * f, (uint32_t)f, job->k,
                                             dist2, row + 1);
        for (size_t k = 1 + found; k < RS_LEARNED_NEIGHBOURS; k++)
            row[k] = (uint32_t)f; /* a mesh of few facets: the facet itself fills the patch */
    }
}

bool rs_learned_patches_build(rs_learned_patches *patches, const double *centroid,
                              size_t facet_count) {
    memset(patches, 0, sizeof *patches);
    patches->neighbour =
        rs_alloc_array(facet_count ? facet_count : 1, RS_LEARNED_NEIGHBOURS * sizeof(uint32_t));
    rs_kdtree tree;
    if (!patches->neighbour || !rs_kdtree_build(&tree, centroid, facet_count)) {
        rs_free(patches->neighbour);
        patches->neighbour = NULL;
        return false;
    }
    patches->facet_count = facet_count;
    patch_job job = {patches, &tree, centroid, RS_LEARNED_NEIGHBOURS - 1};
    rs_parallel_for(facet_count, 256, find_patches, &job);
    rs_kdtree_free(&tree);
    return true;
}

void rs_learned_patches_free(rs_learned_patches *patches) {
    rs_free(patches->neighbour);
    memset(patches, 0, sizeof *patches);
}

/* The frame's spatial width, and the filtered normals' (spatial, normal) widths: spatial in mean
 * edge lengths, normal in unit-vector distance (0: no normal weight). */
#define FRAME_WIDTH 2.0
static const double filter_width[RS_LEARNED_FILTERED][2] = {
    {1.0, 0.35}, {2.0, 0.35}, {1.0, 0.0}, {2.0, 0.0}};

static void rotate(const double frame[3][3], const double v[3], double out[3]) {
    for (int r = 0; r < 3; r++)
        out[r] = rs_dot3(frame[r], v);
}

/* The frame from the weighted normal tensor of the patch, and its eigenvalues, largest first,
 * over their sum. */
static void patch_frame(const rs_learned_input *in, const uint32_t *row, const double *c0,
                        double frame[3][3], double shape[3]) {
    double t[3][3] = {{0}}, mean[3] = {0, 0, 0};
    double inv = 1.0 / (2.0 * FRAME_WIDTH * FRAME_WIDTH * in->mean_edge * in->mean_edge);
    for (int k = 0; k < RS_LEARNED_NEIGHBOURS; k++) {
        const double *n = in->normal + 3 * (size_t)row[k];
        double d[3];
        rs_sub3(in->centroid + 3 * (size_t)row[k], c0, d);
        double w = in->area[row[k]] * exp(-rs_dot3(d, d) * inv);
        for (int a = 0; a < 3; a++) {
            mean[a] += w * n[a];
            for (int b = 0; b < 3; b++)
                t[a][b] += w * n[a] * n[b];
        }
    }
    double values[3], vectors[3][3];
    rs_symmetric_eigen3(t, values, vectors);
    double z[3], x[3];
    memcpy(z, vectors[2], sizeof z);
    memcpy(x, vectors[1], sizeof x);
    if (rs_dot3(z, mean) < 0)
        rs_scale3(z, -1.0);
    if (rs_dot3(x, mean) < 0)
        rs_scale3(x, -1.0);
    double y[3];
    rs_cross3(z, x, y);
    memcpy(frame[0], x, sizeof x);
    memcpy(frame[1], y, sizeof y);
    memcpy(frame[2], z, sizeof z);
    double sum = values[0] + values[1] + values[2];
    for (int k = 0; k < 3; k++)
        shape[k] = sum > 0 ? values[2 - k] / sum : (k == 0);
}

/* Bilateral averages of the patch's normals, unit, in the frame. */
static void filtered_normals(const rs_learned_input *in, const uint32_t *row, const double *c0,
                             const double *n0, const double frame[3][3], double *out) {
    double e2 = in->mean_edge * in->mean_edge;
    for (int w = 0; w < RS_LEARNED_FILTERED; w++) {
        double ss = 1.0 / (2.0 * filter_width[w][0] * filter_width[w][0] * e2);
        double sn =
            filter_width[w][1] > 0 ? 1.0 / (2.0 * filter_width[w][1] * filter_width[w][1]) : 0.0;
        double sum[3] = {0, 0, 0};
        for (int k = 0; k < RS_LEARNED_NEIGHBOURS; k++) {
            const double *n = in->normal + 3 * (size_t)row[k];
            double d[3], dn[3];
            rs_sub3(in->centroid + 3 * (size_t)row[k], c0, d);
            rs_sub3(n, n0, dn);
            double weight = in->area[row[k]] * exp(-rs_dot3(d, d) * ss - rs_dot3(dn, dn) * sn);
            for (int a = 0; a < 3; a++)
                sum[a] += weight * n[a];
        }
        double len = sqrt(rs_dot3(sum, sum));
        if (len > 0)
            rs_scale3(sum, 1.0 / len);
        else
            memcpy(sum, n0, sizeof sum);
        rotate(frame, sum, out + 3 * w);
    }
}

void rs_learned_descriptor(const rs_learned_input *in, size_t f, double *descriptor,
                           double frame[3][3]) {
    const uint32_t *row = in->patches->neighbour + f * RS_LEARNED_NEIGHBOURS;
    const double *c0 = in->centroid + 3 * f, *n0 = in->normal + 3 * f;
    double shape[3];
    patch_frame(in, row, c0, frame, shape);
    double inv_e = 1.0 / in->mean_edge;
    double *out = descriptor;
    for (int k = 0; k < RS_LEARNED_NEIGHBOURS; k++) {
        size_t j = row[k];
        double d[3];
        rotate(frame, in->normal + 3 * j, out);
        rs_sub3(in->centroid + 3 * j, c0, d);
        rs_scale3(d, inv_e);
        rotate(frame, d, out + 3);
        out[6] = in->area[j] * inv_e * inv_e;
        out += RS_LEARNED_PER_NEIGHBOUR;
    }
    filtered_normals(in, row, c0, n0, frame, out);
    out += 3 * RS_LEARNED_FILTERED;
    memcpy(out, shape, sizeof shape);
    out[3] = in->noise_level;
}
