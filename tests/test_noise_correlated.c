/* Spatially correlated noise: mesh_add_noise's --correlation and --stripes give the spread and
 * the correlation they promise (measured here from the offsets, not from the generator), and the
 * noise estimate's correlated_level / correlation_length read them on the project's own shapes
 * while a clean shape reads near 0. */
#include "mesh_noise.h"
#include "mesh_shapes.h"
#include "rsmooth.h"
#include "test_util.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

/* The offsets along the clean normals of `m` after noise `o`, in mean edge lengths (caller
 * frees); *noisy_out gets the noisy positions when not NULL (caller frees). */
static double *offsets(const shape_mesh *m, const mesh_noise_options *o, double **noisy_out) {
    size_t nv = m->vertex_count;
    double *xyz = malloc(3 * nv * sizeof *xyz), *n = malloc(3 * nv * sizeof *n);
    double *d = malloc(nv * sizeof *d);
    CHECK(xyz && n && d);
    memcpy(xyz, m->xyz, 3 * nv * sizeof *xyz);
    CHECK_EQ_INT(shape_vertex_normals(m, n), 0);
    CHECK_EQ_INT(mesh_add_noise(xyz, nv, m->indices, m->triangle_count, o), 0);
    double edge = shape_mean_edge_length(m);
    for (size_t v = 0; v < nv; v++) {
        d[v] = 0;
        for (int k = 0; k < 3; k++)
            d[v] += (xyz[3 * v + k] - m->xyz[3 * v + k]) * n[3 * v + k] / edge;
    }
    free(n);
    if (noisy_out)
        *noisy_out = xyz;
    else
        free(xyz);
    return d;
}

static double rms(const double *d, size_t n) {
    double s = 0;
    for (size_t i = 0; i < n; i++)
        s += d[i] * d[i];
    return sqrt(s / (double)n);
}

/* Pearson correlation of the offsets at the two ends of every triangle edge (each edge once per
 * triangle side: the weighting does not matter for the oracle). */
static double edge_correlation(const shape_mesh *m, const double *d) {
    double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0, n = 0;
    for (size_t t = 0; t < m->triangle_count; t++)
        for (int k = 0; k < 3; k++) {
            double a = d[m->indices[3 * t + k]], b = d[m->indices[3 * t + (k + 1) % 3]];
            sa += a, sb += b, saa += a * a, sbb += b * b, sab += a * b, n++;
        }
    double ca = saa / n - (sa / n) * (sa / n), cb = sbb / n - (sb / n) * (sb / n);
    return (sab / n - sa / n * sb / n) / sqrt(ca * cb);
}

static mesh_noise_options noise(double sigma, double correlation, double stripes, uint64_t seed) {
    mesh_noise_options o = {sigma, MESH_NOISE_NORMAL, 0, seed, correlation, stripes};
    return o;
}

/* The generator on a 200 x 200 plane (40401 vertices, normals all +z). */
static void test_generator(void) {
    shape_mesh plane;
    CHECK_EQ_INT(shape_plane(&plane, 200, 200, 1.0), 0);
    size_t nv = plane.vertex_count;
    mesh_noise_options white = noise(0.3, 0, 0, 11), band = noise(0.3, 3, 0, 11),
                       stripes = noise(0.3, 0, 6, 11);
    double *dw = offsets(&plane, &white, NULL), *db = offsets(&plane, &band, NULL);
    double *ds = offsets(&plane, &stripes, NULL);
    double cw = edge_correlation(&plane, dw), cb = edge_correlation(&plane, db),
           cs = edge_correlation(&plane, ds);
    printf("plane: rms white %.4f band L=3 %.4f stripes W=6 %.4f (sigma 0.3); neighbour "
           "correlation %.3f %.3f %.3f\n",
           rms(dw, nv), rms(db, nv), rms(ds, nv), cw, cb, cs);
    CHECK_NEAR(rms(dw, nv), 0.3, 0.3 * 0.02);
    /* each vertex has standard deviation sigma; the sample rms of a field with ~300 independent
     * patches scatters by a few per cent */
    CHECK_NEAR(rms(db, nv), 0.3, 0.3 * 0.08);
    CHECK_NEAR(rms(ds, nv), 0.3, 1e-9); /* rescaled to exactly sigma */
    CHECK(fabs(cw) < 0.03);
    CHECK(cb > 0.9); /* exp(-d^2 / 4 L^2) at d ~ 1.1: 0.97 */
    CHECK(cs > 0.8);
    /* reproducible with the seed, different with another */
    double *db2 = offsets(&plane, &band, NULL);
    CHECK(memcmp(db, db2, nv * sizeof *db) == 0);
    mesh_noise_options other = noise(0.3, 3, 0, 12);
    double *db3 = offsets(&plane, &other, NULL);
    CHECK(memcmp(db, db3, nv * sizeof *db) != 0);
    /* the band-limited field is mean-free and does not depend on position: the plane's two halves
     * read alike */
    CHECK_NEAR(rms(db, nv / 2), rms(db + nv / 2, nv - nv / 2), 0.3 * 0.15);
    free(dw), free(db), free(ds), free(db2), free(db3);
    shape_free(&plane);
}

static rsmooth_noise_report read_noise(const shape_mesh *m, const double *xyz) {
    rsmooth_params p;
    rsmooth_params_init(&p);
    rsmooth_noise_report r;
    r.struct_size = sizeof r;
    rsmooth_error err;
    CHECK_STATUS(rsmooth_params_auto(RSMOOTH_FLOAT64, xyz, m->vertex_count, m->indices,
                                     m->triangle_count, &p, &r, &err),
                 RSMOOTH_OK);
    return r;
}

/* The estimate on a 40962-vertex sphere (radius 100: about 1 edge in 80 of curvature radius). */
static void test_estimate(void) {
    shape_mesh sphere;
    CHECK_EQ_INT(shape_sphere(&sphere, 6, 100.0), 0);
    size_t nv = sphere.vertex_count;
    rsmooth_noise_report clean = read_noise(&sphere, sphere.xyz);
    printf("sphere %zu vertices: clean level %.4f correlated %.4f length %.2f\n", nv, clean.level,
           clean.correlated_level, clean.correlation_length);
    CHECK(clean.correlated_level < 0.03);
    CHECK(clean.correlation_length == 0);

    const double lengths[] = {0, 1, 1.5};
    double read_length[3];
    for (int i = 0; i < 3; i++) {
        mesh_noise_options o = noise(0.3, lengths[i], 0, 21 + (uint64_t)i);
        double *noisy = NULL, *d = offsets(&sphere, &o, &noisy);
        double truth = rms(d, nv);
        rsmooth_noise_report r = read_noise(&sphere, noisy);
        printf("sphere L=%.1f: true rms %.4f; level %.4f correlated %.4f (%+.0f%%) length %.2f\n",
               lengths[i], truth, r.level, r.correlated_level,
               100 * (r.correlated_level / truth - 1), r.correlation_length);
        read_length[i] = r.correlation_length;
        if (lengths[i] == 0) { /* white noise: nothing correlated, the level as it is */
            CHECK(r.correlation_length == 0);
            CHECK(r.correlated_level == r.level);
            CHECK_NEAR(r.correlated_level, truth, 0.1 * truth);
        } else if (lengths[i] == 1) { /* level misses most of it; correlated_level reads it */
            CHECK(r.level < 0.5 * truth);
            CHECK_NEAR(r.correlated_level, truth, 0.35 * truth);
            CHECK(r.correlation_length > 0);
        } else { /* smoother noise: read as correlated but only in part (rsmooth.h: beyond
                  * about 1.5 edges it reads as shape) */
            CHECK(r.correlated_level > 2 * r.level);
            CHECK(r.correlated_level < 1.15 * truth);
            CHECK(r.correlation_length > 0);
        }
        free(d);
        free(noisy);
    }
    CHECK(read_length[2] > read_length[1]); /* smoother noise, longer correlation */
    shape_free(&sphere);
}

int main(void) {
    test_generator();
    test_estimate();
    return 0;
}
