/* Point clouds with normals (rsmooth_smooth_points, ctx NULL): equal to an independent O(N^2)
 * evaluation of the same equations, denoising analytic shapes (a sphere, a cube whose edges stay
 * sharp), and refusing bad input. */
#include "mesh_shapes.h"
#include "rsmooth.h"
#include "test_util.h"

#include <stdbool.h>
#include <stdint.h>
#include <string.h>

/* ---- the brute force: every point against every other, double precision --------------------- */

static double dot(const double *a, const double *b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static double dist2(const double *a, const double *b) {
    double d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
    return dot(d, d);
}

static int compare_double(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* s_i: the mean distance to the 6 nearest other points, by sorting all distances. */
static void bf_spacings(const double *xyz, size_t n, double *s) {
    double *d = malloc((n + 1) * sizeof *d);
    CHECK(d);
    for (size_t i = 0; i < n; i++) {
        size_t m = 0;
        for (size_t j = 0; j < n; j++)
            if (j != i)
                d[m++] = sqrt(dist2(xyz + 3 * i, xyz + 3 * j));
        qsort(d, m, sizeof *d, compare_double);
        size_t k = m < 6 ? m : 6;
        double sum = 0;
        for (size_t j = 0; j < k; j++)
            sum += d[j];
        s[i] = k ? sum / (double)k : 0;
    }
    free(d);
}

static double bf_color_dist2(const float *colors, size_t q, size_t v) {
    double s = 0;
    for (int c = 0; c < 3; c++) {
        double d = (double)colors[3 * q + c] - (double)colors[3 * v + c];
        s += d * d;
    }
    return s;
}

static double bf_influence(int influence, double x2) { /* x2 in units of sigma_g^2 */
    switch (influence) {
    case RSMOOTH_INFLUENCE_TUKEY:
        return x2 < 5 ? (1 - x2 / 5) * (1 - x2 / 5) : 0;
    case RSMOOTH_INFLUENCE_LORENTZIAN:
        return 1 / (1 + x2);
    case RSMOOTH_INFLUENCE_HUBER:
        return x2 <= 1 ? 1 : 1 / sqrt(x2);
    default:
        return exp(-x2 / 2);
    }
}

/* The whole filter as the header documents it. Outputs as the library's (positions, normals,
 * confidence). */
static void bf_points(const double *in_xyz, const double *in_nrm, size_t n, const rsmooth_params *p,
                      double *out_xyz, double *out_nrm, double *out_conf) {
    double *xyz = malloc(3 * n * sizeof *xyz), *next = malloc(3 * n * sizeof *next);
    double *unit_n = malloc(3 * n * sizeof *unit_n), *filtered = malloc(3 * n * sizeof *filtered);
    double *prev_n = malloc(3 * n * sizeof *prev_n), *round_n = malloc(3 * n * sizeof *round_n);
    double *s = malloc(n * sizeof *s), *area = malloc(n * sizeof *area);
    double *conf = malloc(n * sizeof *conf), *prev_conf = malloc(n * sizeof *prev_conf);
    CHECK(xyz && next && unit_n && filtered && prev_n && round_n && s && area && conf && prev_conf);
    memcpy(xyz, in_xyz, 3 * n * sizeof *xyz);
    for (size_t i = 0; i < n; i++) {
        double len = sqrt(dot(in_nrm + 3 * i, in_nrm + 3 * i));
        for (int k = 0; k < 3; k++)
            unit_n[3 * i + k] = in_nrm[3 * i + k] / len;
    }
    double unit = 0;
    for (int pass = 0; pass < p->passes; pass++) {
        bf_spacings(xyz, n, s);
        if (pass == 0) {
            for (size_t i = 0; i < n; i++)
                unit += s[i];
            unit = p->absolute ? 1 : unit / (double)n;
        }
        for (size_t i = 0; i < n; i++)
            area[i] = sqrt(3.0) / 2 * s[i] * s[i];
        const double sf = p->sigma_f * unit, sg = p->sigma_g * unit, radius = p->cutoff * sf;
        const bool centroid = p->predictor == RSMOOTH_PREDICT_CENTROID;
        /* normals: the input's, bilaterally filtered when mollify is on */
        memcpy(filtered, unit_n, 3 * n * sizeof *filtered);
        if (p->mollify && !centroid && unit > 0) {
            const double ss = p->normal_sigma_s * unit, reach = p->cutoff * ss;
            const double tn = p->normal_sigma_n;
            for (int round = 0; round < p->normal_iterations; round++) {
                memcpy(round_n, filtered, 3 * n * sizeof *round_n);
                for (size_t r = 0; r < n; r++) {
                    double acc[3] = {0, 0, 0};
                    for (size_t q = 0; q < n; q++) {
                        double d2 = dist2(xyz + 3 * q, xyz + 3 * r);
                        if (!(d2 <= reach * reach))
                            continue;
                        double w = area[q] * exp(-d2 / (2 * ss * ss)) *
                                   exp(-dist2(round_n + 3 * q, round_n + 3 * r) / (2 * tn * tn));
                        for (int k = 0; k < 3; k++)
                            acc[k] += w * round_n[3 * q + k];
                    }
                    double len = sqrt(dot(acc, acc));
                    for (int k = 0; k < 3; k++)
                        filtered[3 * r + k] = len > 0 ? acc[k] / len : round_n[3 * r + k];
                }
            }
        }
        /* Eq. 3 with the points as facets */
        for (size_t v = 0; v < n; v++) {
            const double *pv = xyz + 3 * v;
            double k = 0, kf = 0, acc[3] = {0, 0, 0};
            for (size_t q = 0; q < n && unit > 0; q++) {
                double d2 = dist2(xyz + 3 * q, pv);
                if (!(d2 <= radius * radius))
                    continue;
                const double *nq = filtered + 3 * q;
                double d[3] = {xyz[3 * q] - pv[0], xyz[3 * q + 1] - pv[1], xyz[3 * q + 2] - pv[2]};
                double t = dot(nq, d), step[3];
                for (int c = 0; c < 3; c++)
                    step[c] = centroid ? d[c] : t * nq[c];
                double af = area[q] * exp(-d2 / (2 * sf * sf));
                double g =
                    isinf(p->sigma_g) ? 1 : bf_influence(p->influence, dot(step, step) / (sg * sg));
                if (p->colors) /* a point's own colour is its facet's */
                    g *= exp(-bf_color_dist2(p->colors, q, v) / (2 * p->sigma_c * p->sigma_c));
                for (int c = 0; c < 3; c++)
                    acc[c] += af * g * step[c];
                k += af * g;
                kf += af;
            }
            for (int c = 0; c < 3; c++)
                next[3 * v + c] = pv[c] + (k > 0 ? acc[c] / k : 0);
            conf[v] = kf > 0 ? (float)fmin(1, k / kf) : 0; /* float, as the library keeps it */
        }
        if (pass > 0 && p->pass_confidence > 0)
            for (size_t v = 0; v < n; v++)
                if (prev_conf[v] >= p->pass_confidence) {
                    memcpy(next + 3 * v, xyz + 3 * v, 3 * sizeof *next);
                    memcpy(filtered + 3 * v, prev_n + 3 * v, 3 * sizeof *filtered);
                    conf[v] = prev_conf[v];
                }
        memcpy(xyz, next, 3 * n * sizeof *xyz);
        memcpy(prev_n, filtered, 3 * n * sizeof *prev_n);
        memcpy(prev_conf, conf, n * sizeof *conf);
    }
    memcpy(out_xyz, xyz, 3 * n * sizeof *xyz);
    memcpy(out_nrm, prev_n, 3 * n * sizeof *prev_n);
    memcpy(out_conf, prev_conf, n * sizeof *prev_conf);
    free(xyz), free(next), free(unit_n), free(filtered), free(prev_n), free(round_n);
    free(s), free(area), free(conf), free(prev_conf);
}

/* A noisy point cloud: the vertices of `mesh` moved along its normals by `noise` mean edge
 * lengths, with the normals a scanner gives: those of the noisy surface. */
static void noisy_cloud(shape_mesh *mesh, double noise, uint64_t seed, double **normals) {
    CHECK(shape_add_normal_noise(mesh, noise, seed) == 0);
    *normals = malloc(3 * mesh->vertex_count * sizeof **normals);
    CHECK(*normals && shape_vertex_normals(mesh, *normals) == 0);
}

/* (a) The library against the brute force, variant by variant. */
static void test_oracle(void) {
    shape_mesh meshes[2];
    memset(meshes, 0, sizeof meshes);
    double *normals[2];
    CHECK(shape_cube(&meshes[0], 8, 2.0) == 0); /* 386 points, sharp edges and corners */
    noisy_cloud(&meshes[0], 0.3, 11, &normals[0]);
    CHECK(shape_sphere(&meshes[1], 3, 1.0) == 0); /* 642 points, curved */
    noisy_cloud(&meshes[1], 0.3, 12, &normals[1]);
    /* Uneven lengths: the filter normalises them. */
    for (size_t i = 0; i < meshes[1].vertex_count; i++)
        for (int k = 0; k < 3; k++)
            normals[1][3 * i + k] *= 0.5 + (double)(i % 7);
    for (int m = 0; m < 2; m++) {
        const shape_mesh *mesh = &meshes[m];
        size_t n = mesh->vertex_count;
        double *want = malloc(3 * n * sizeof *want), *want_n = malloc(3 * n * sizeof *want_n);
        double *want_c = malloc(n * sizeof *want_c), *got = malloc(3 * n * sizeof *got);
        double *got_n = malloc(3 * n * sizeof *got_n);
        float *got_c = malloc(n * sizeof *got_c);
        float *xyz32 = malloc(3 * n * sizeof *xyz32), *nrm32 = malloc(3 * n * sizeof *nrm32);
        float *got32 = malloc(3 * n * sizeof *got32), *got32_n = malloc(3 * n * sizeof *got32_n);
        float *colors = malloc(3 * n * sizeof *colors);
        CHECK(colors);
        for (size_t i = 0; i < n; i++) { /* red below z = 0, blue above, slightly varied */
            bool low = mesh->xyz[3 * i + 2] < 0;
            colors[3 * i] = low ? 0.9f - 0.01f * (float)(i % 5) : 0.1f;
            colors[3 * i + 1] = 0.2f;
            colors[3 * i + 2] = low ? 0.1f : 0.8f + 0.01f * (float)(i % 3);
        }
        double *xyz64 = malloc(3 * n * sizeof *xyz64), *nrm64 = malloc(3 * n * sizeof *nrm64);
        CHECK(want && want_n && want_c && got && got_n && got_c && xyz32 && nrm32 && got32 &&
              got32_n && xyz64 && nrm64);
        double spacing = 0;
        CHECK_STATUS(rsmooth_point_spacing(RSMOOTH_FLOAT64, mesh->xyz, n, &spacing, NULL),
                     RSMOOTH_OK);
        for (int variant = 0; variant < 12; variant++) {
            rsmooth_params p;
            rsmooth_params_init(&p);
            const char *what = "defaults";
            switch (variant) {
            case 1:
                what = "mollify off (input normals)";
                p.mollify = 0;
                break;
            case 2:
                what = "best";
                rsmooth_params_init_best(&p);
                break;
            case 3:
                what = "3 passes, pass_confidence 0.6";
                p.passes = 3;
                p.pass_confidence = 0.6;
                p.sigma_f = 1.5;
                break;
            case 4:
                what = "tukey";
                p.influence = RSMOOTH_INFLUENCE_TUKEY;
                break;
            case 5:
                what = "lorentzian, sigma_g 0.3";
                p.influence = RSMOOTH_INFLUENCE_LORENTZIAN;
                p.sigma_g = 0.3;
                break;
            case 6:
                what = "sigma_g inf";
                p.sigma_g = INFINITY;
                break;
            case 7:
                what = "centroid predictor (Gaussian smoothing)";
                p.predictor = RSMOOTH_PREDICT_CENTROID;
                p.sigma_g = INFINITY;
                break;
            case 8:
                what = "absolute sigmas";
                p.absolute = 1;
                p.sigma_f = 1.5 * spacing;
                p.sigma_g = 0.4 * spacing;
                p.normal_sigma_s = 0.8 * spacing;
                break;
            case 9:
                what = "huber, cutoff 3, 2 bilateral rounds, normal_sigma_n 0.6";
                p.influence = RSMOOTH_INFLUENCE_HUBER;
                p.cutoff = 3;
                p.normal_iterations = 2;
                p.normal_sigma_n = 0.6;
                break;
            case 10: /* the points of the half z < 0 red, the others blue */
                what = "colour, sigma_c 0.3";
                p.colors = colors;
                p.sigma_c = 0.3;
                break;
            case 11:
                what = "colour, sigma_c 0.3, tukey, 2 passes";
                p.colors = colors;
                p.sigma_c = 0.3;
                p.influence = RSMOOTH_INFLUENCE_TUKEY;
                p.passes = 2;
                break;
            }
            bf_points(mesh->xyz, normals[m], n, &p, want, want_n, want_c);
            rsmooth_report report;
            rsmooth_error err;
            rsmooth_status st =
                rsmooth_smooth_points(NULL, RSMOOTH_FLOAT64, mesh->xyz, normals[m], n, &p, got,
                                      got_n, OUTPUTS(NULL, got_c, &report), &err);
            if (st != RSMOOTH_OK)
                fprintf(stderr, "%s: %s\n", what, err.message);
            CHECK_STATUS(st, RSMOOTH_OK);
            double worst = 0, worst_n = 0, worst_c = 0, moved = 0;
            for (size_t i = 0; i < 3 * n; i++) {
                worst = fmax(worst, fabs(got[i] - want[i]));
                worst_n = fmax(worst_n, fabs(got_n[i] - want_n[i]));
                moved = fmax(moved, fabs(got[i] - mesh->xyz[i]));
            }
            for (size_t i = 0; i < n; i++)
                worst_c = fmax(worst_c, fabs(got_c[i] - want_c[i]));
            printf("%s, %s: max |p - oracle| %.3g spacings (moved up to %.3g), normals %.3g, "
                   "confidence %.3g\n",
                   m ? "sphere" : "cube", what, worst / spacing, moved / spacing, worst_n, worst_c);
            CHECK_LE(worst, 1e-9 * spacing);
            CHECK_LE(worst_n, 1e-9);
            CHECK_LE(worst_c, 1e-6);
            CHECK(moved > 0.01 * spacing); /* the comparison is not of two no-ops */
            CHECK_EQ_INT(report.vertex_count, n);
            CHECK_EQ_INT(report.triangle_count, 0);
            CHECK_EQ_INT(report.facet_count, n);
            CHECK_NEAR(report.mean_edge_length, spacing, 1e-12 * spacing);
            if (!p.absolute)
                CHECK_NEAR(report.sigma_f, p.sigma_f * spacing, 1e-12 * spacing);

            /* float32 arrays: the same filter on the rounded input, results rounded */
            for (size_t i = 0; i < 3 * n; i++) {
                xyz32[i] = (float)mesh->xyz[i];
                nrm32[i] = (float)normals[m][i];
                xyz64[i] = xyz32[i];
                nrm64[i] = nrm32[i];
            }
            if (variant == 0 || variant == 3) {
                bf_points(xyz64, nrm64, n, &p, want, want_n, want_c);
                CHECK_STATUS(rsmooth_smooth_points(NULL, RSMOOTH_FLOAT32, xyz32, nrm32, n, &p,
                                                   got32, got32_n, NULL, NULL),
                             RSMOOTH_OK);
                for (size_t i = 0; i < 3 * n; i++) {
                    CHECK_NEAR(got32[i], want[i], 1e-6 * (fabs(want[i]) + spacing));
                    CHECK_NEAR(got32_n[i], want_n[i], 1e-6);
                }
            }
        }
        free(want), free(want_n), free(want_c), free(got), free(got_n), free(got_c);
        free(xyz32), free(nrm32), free(got32), free(got32_n), free(xyz64), free(nrm64),
            free(colors);
        free(normals[m]);
        shape_free(&meshes[m]);
    }
}

/* The spacing is the mesh's mean edge length where it should be: on a plane's grid (each interior
 * vertex's 6 nearest are its 4 axis neighbours and 2 diagonals, the ring of the split quads) and
 * close to it on a sphere. */
static void test_spacing(void) {
    shape_mesh plane = {0}, sphere = {0};
    CHECK(shape_plane(&plane, 30, 30, 0.1) == 0);
    CHECK(shape_sphere(&sphere, 4, 1.0) == 0);
    const shape_mesh *meshes[2] = {&plane, &sphere};
    const double tolerance[2] = {0.03, 0.1};
    for (int m = 0; m < 2; m++) {
        double spacing = 0, edge = shape_mean_edge_length(meshes[m]);
        CHECK_STATUS(rsmooth_point_spacing(RSMOOTH_FLOAT64, meshes[m]->xyz, meshes[m]->vertex_count,
                                           &spacing, NULL),
                     RSMOOTH_OK);
        printf("%s: point spacing %.6g, mean edge length %.6g (ratio %.4f)\n",
               m ? "sphere" : "plane", spacing, edge, spacing / edge);
        CHECK_NEAR(spacing / edge, 1, tolerance[m]);
    }
    double one[3] = {1, 2, 3}, s = -1;
    CHECK_STATUS(rsmooth_point_spacing(RSMOOTH_FLOAT64, one, 1, &s, NULL), RSMOOTH_OK);
    CHECK(s == 0);
    shape_free(&plane);
    shape_free(&sphere);
}

/* (b) A unit sphere with radial noise: the mean |(distance to the centre) - 1| drops by 40% or
 * more. Normals from the noisy surface, as a scanner's would be. */
static void test_sphere(void) {
    shape_mesh sphere = {0};
    CHECK(shape_sphere(&sphere, 5, 1.0) == 0); /* 10242 points: spacing 0.04, curvature small */
    size_t n = sphere.vertex_count;
    double spacing = 0;
    CHECK_STATUS(rsmooth_point_spacing(RSMOOTH_FLOAT64, sphere.xyz, n, &spacing, NULL), RSMOOTH_OK);
    uint64_t state = 99;
    for (size_t i = 0; i < n; i++) { /* radial noise of 0.3 spacings */
        double r = 1 + 0.3 * spacing * shape_gaussian(&state);
        for (int k = 0; k < 3; k++)
            sphere.xyz[3 * i + k] *= r;
    }
    double *normals = malloc(3 * n * sizeof *normals), *out = malloc(3 * n * sizeof *out);
    CHECK(normals && out && shape_vertex_normals(&sphere, normals) == 0);
    const char *names[2] = {"defaults", "sigma_f 1.5, sigma_g 0.7"};
    for (int setting = 0; setting < 2; setting++) {
        rsmooth_params p;
        rsmooth_params_init(&p);
        if (setting == 1) {
            p.sigma_f = 1.5;
            p.sigma_g = 0.7;
        }
        CHECK_STATUS(rsmooth_smooth_points(NULL, RSMOOTH_FLOAT64, sphere.xyz, normals, n, &p, out,
                                           NULL, NULL, NULL),
                     RSMOOTH_OK);
        double before = 0, after = 0;
        for (size_t i = 0; i < n; i++) {
            before += fabs(sqrt(dot(sphere.xyz + 3 * i, sphere.xyz + 3 * i)) - 1);
            after += fabs(sqrt(dot(out + 3 * i, out + 3 * i)) - 1);
        }
        before /= (double)n;
        after /= (double)n;
        printf("sphere, %s: mean |r - 1| %.4g -> %.4g spacings (%.0f%% less)\n", names[setting],
               before / spacing, after / spacing, 100 * (1 - after / before));
        CHECK_LE(after, 0.6 * before);
    }
    free(normals);
    free(out);
    shape_free(&sphere);
}

/* Distance of p from the surface of the cube [-h, h]^3. */
static double cube_distance(const double *p, double h) {
    double outside = 0, inside = INFINITY;
    for (int k = 0; k < 3; k++) {
        double d = fabs(p[k]) - h;
        outside += d > 0 ? d * d : 0;
        inside = fmin(inside, -d);
    }
    return outside > 0 ? sqrt(outside) : inside;
}

/* Distance of p from the nearest edge of the cube [-h, h]^3 (as an infinite line). */
static double edge_distance(const double *p, double h) {
    double best = INFINITY;
    for (int axis = 0; axis < 3; axis++) { /* edges parallel to `axis` */
        int a = (axis + 1) % 3, b = (axis + 2) % 3;
        double da = fabs(p[a]) - h, db = fabs(p[b]) - h;
        best = fmin(best, sqrt(da * da + db * db));
    }
    return best;
}

/* (b) A noisy cube: its faces come out flat (the noise drops by 40% or more away from the edges),
 * and its edges stay sharp: points near an edge end no farther from the surface than the noise
 * put them, where plain Gaussian smoothing of the points rounds the edges far beyond that. */
static void test_cube(void) {
    shape_mesh cube = {0};
    const double h = 1;
    CHECK(shape_cube(&cube, 40, 2 * h) == 0); /* 9602 points, spacing 0.05 */
    size_t n = cube.vertex_count;
    double spacing = 0;
    CHECK_STATUS(rsmooth_point_spacing(RSMOOTH_FLOAT64, cube.xyz, n, &spacing, NULL), RSMOOTH_OK);
    double *clean = malloc(3 * n * sizeof *clean), *normals = NULL;
    CHECK(clean);
    memcpy(clean, cube.xyz, 3 * n * sizeof *clean);
    noisy_cloud(&cube, 0.3, 5, &normals);
    double *out = malloc(3 * n * sizeof *out);
    CHECK(out);
    for (int setting = 0; setting < 2; setting++) {
        rsmooth_params p;
        rsmooth_params_init(&p);
        if (setting == 1) { /* plain Gaussian smoothing of the points, to compare with */
            p.predictor = RSMOOTH_PREDICT_CENTROID;
            p.sigma_g = INFINITY;
        }
        CHECK_STATUS(rsmooth_smooth_points(NULL, RSMOOTH_FLOAT64, cube.xyz, normals, n, &p, out,
                                           NULL, NULL, NULL),
                     RSMOOTH_OK);
        double face_before = 0, face_after = 0;
        double edge_noise = 0, edge_after = 0, edge_noise_max = 0, edge_after_max = 0;
        size_t faces = 0, edges = 0;
        for (size_t i = 0; i < n; i++) {
            double e = edge_distance(clean + 3 * i, h);
            if (e > 4 * spacing) { /* on a face, away from its edges */
                face_before += fabs(cube_distance(cube.xyz + 3 * i, h));
                face_after += fabs(cube_distance(out + 3 * i, h));
                faces++;
            } else if (e < 0.5 * spacing) { /* on an edge */
                double before = fabs(cube_distance(cube.xyz + 3 * i, h));
                double after = fabs(cube_distance(out + 3 * i, h));
                edge_noise += before;
                edge_after += after;
                edge_noise_max = fmax(edge_noise_max, before);
                edge_after_max = fmax(edge_after_max, after);
                edges++;
            }
        }
        face_before /= (double)faces;
        face_after /= (double)faces;
        edge_noise /= (double)edges;
        edge_after /= (double)edges;
        printf("cube, %s: faces (%zu points) mean distance %.4g -> %.4g spacings (%.0f%% less); "
               "edges (%zu points) mean distance %.4g -> %.4g, max %.4g -> %.4g spacings\n",
               setting ? "Gaussian smoothing" : "defaults", faces, face_before / spacing,
               face_after / spacing, 100 * (1 - face_after / face_before), edges,
               edge_noise / spacing, edge_after / spacing, edge_noise_max / spacing,
               edge_after_max / spacing);
        CHECK(faces > n / 2 && edges > 100);
        if (setting == 0) {
            CHECK_LE(face_after, 0.6 * face_before);
            CHECK_LE(edge_after, edge_noise);
            CHECK_LE(edge_after_max, edge_noise_max);
        } else {
            CHECK(edge_after > 2 * edge_noise); /* rounded: what the filter avoids */
        }
    }
    free(clean);
    free(normals);
    free(out);
    shape_free(&cube);
}

/* Degenerate clouds: one point, and every point in one place, stay where they are. */
static void test_degenerate(void) {
    double one[3] = {1, 2, 3}, n1[3] = {0, 0, 2}, out[12], out_n[12];
    float conf[4] = {-1, -1, -1, -1};
    CHECK_STATUS(rsmooth_smooth_points(NULL, RSMOOTH_FLOAT64, one, n1, 1, NULL, out, out_n,
                                       OUTPUTS(NULL, conf, NULL), NULL),
                 RSMOOTH_OK);
    CHECK(out[0] == 1 && out[1] == 2 && out[2] == 3 && out_n[2] == 1 && conf[0] == 0);
    double same[12] = {1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1};
    double nn[12] = {0, 0, 1, 0, 1, 0, 1, 0, 0, 0, 0, -1};
    CHECK_STATUS(rsmooth_smooth_points(NULL, RSMOOTH_FLOAT64, same, nn, 4, NULL, out, out_n,
                                       OUTPUTS(NULL, conf, NULL), NULL),
                 RSMOOTH_OK);
    for (int i = 0; i < 12; i++)
        CHECK(out[i] == 1 && out_n[i] == nn[i]);
    /* In place: outputs may be the inputs. */
    double xyz[9] = {0, 0, 0, 1, 0, 0.1, 0, 1, -0.1}, nrm[9] = {0, 0, 1, 0, 0, 1, 0, 0, 1};
    CHECK_STATUS(
        rsmooth_smooth_points(NULL, RSMOOTH_FLOAT64, xyz, nrm, 3, NULL, xyz, nrm, NULL, NULL),
        RSMOOTH_OK);
    for (int i = 0; i < 9; i++)
        CHECK(isfinite(xyz[i]) && isfinite(nrm[i]));
}

/* (c) Bad input: a clear error naming what is wrong, and nothing written. */
static void test_bad_input(void) {
    enum { N = 40 };
    double xyz[3 * N], nrm[3 * N], out[3 * N], out_n[3 * N];
    for (int i = 0; i < N; i++) {
        xyz[3 * i] = i % 7, xyz[3 * i + 1] = i / 7, xyz[3 * i + 2] = 0.01 * (i % 3);
        nrm[3 * i] = 0, nrm[3 * i + 1] = 0, nrm[3 * i + 2] = 1;
    }
    rsmooth_error err;
    rsmooth_params p;
    rsmooth_params_init(&p);
#define EXPECT_INVALID(call, text)                                                                 \
    do {                                                                                           \
        for (int i_ = 0; i_ < 3 * N; i_++)                                                         \
            out[i_] = -7;                                                                          \
        CHECK_STATUS(call, RSMOOTH_ERROR_INVALID_ARGUMENT);                                        \
        CHECK_EQ_INT(err.status, RSMOOTH_ERROR_INVALID_ARGUMENT);                                  \
        if (!strstr(err.message, text)) {                                                          \
            fprintf(stderr, "message '%s' lacks '%s'\n", err.message, text);                       \
            exit(1);                                                                               \
        }                                                                                          \
        for (int i_ = 0; i_ < 3 * N; i_++)                                                         \
            CHECK(out[i_] == -7);                                                                  \
        printf("refused: %s\n", err.message);                                                      \
    } while (0)
    EXPECT_INVALID(
        rsmooth_smooth_points(NULL, RSMOOTH_FLOAT64, NULL, nrm, N, &p, out, NULL, NULL, &err),
        "positions is NULL");
    EXPECT_INVALID(
        rsmooth_smooth_points(NULL, RSMOOTH_FLOAT64, xyz, NULL, N, &p, out, NULL, NULL, &err),
        "normals is NULL");
    EXPECT_INVALID(
        rsmooth_smooth_points(NULL, RSMOOTH_FLOAT64, xyz, nrm, 0, &p, out, NULL, NULL, &err),
        "empty");
    EXPECT_INVALID(
        rsmooth_smooth_points(NULL, RSMOOTH_FLOAT64, xyz, nrm, N, &p, NULL, NULL, NULL, &err),
        "out_positions is NULL");
    EXPECT_INVALID(
        rsmooth_smooth_points(NULL, (rsmooth_scalar)5, xyz, nrm, N, &p, out, NULL, NULL, &err),
        "scalar");
    nrm[3 * 17] = nrm[3 * 17 + 1] = nrm[3 * 17 + 2] = 0;
    EXPECT_INVALID(
        rsmooth_smooth_points(NULL, RSMOOTH_FLOAT64, xyz, nrm, N, &p, out, NULL, NULL, &err),
        "point 17 has a zero-length normal");
    nrm[3 * 17 + 2] = NAN;
    EXPECT_INVALID(
        rsmooth_smooth_points(NULL, RSMOOTH_FLOAT64, xyz, nrm, N, &p, out, NULL, NULL, &err),
        "point 17 has a non-finite normal");
    nrm[3 * 17 + 2] = INFINITY;
    EXPECT_INVALID(
        rsmooth_smooth_points(NULL, RSMOOTH_FLOAT64, xyz, nrm, N, &p, out, NULL, NULL, &err),
        "point 17 has a non-finite normal");
    nrm[3 * 17 + 2] = 1e300; /* huge but finite: fine */
    CHECK_STATUS(
        rsmooth_smooth_points(NULL, RSMOOTH_FLOAT64, xyz, nrm, N, &p, out, NULL, NULL, &err),
        RSMOOTH_OK);
    xyz[3 * 23 + 1] = NAN;
    EXPECT_INVALID(
        rsmooth_smooth_points(NULL, RSMOOTH_FLOAT64, xyz, nrm, N, &p, out, NULL, NULL, &err),
        "point 23 has a non-finite coordinate");
    xyz[3 * 23 + 1] = 1e200;
    EXPECT_INVALID(
        rsmooth_smooth_points(NULL, RSMOOTH_FLOAT64, xyz, nrm, N, &p, out, NULL, NULL, &err),
        "point 23 has coordinate");
    xyz[3 * 23 + 1] = 0;
    EXPECT_INVALID(
        rsmooth_smooth_points(NULL, RSMOOTH_FLOAT64, xyz, nrm, N, &p, out, out + 3, NULL, &err),
        "overlap");
    p.sigma_f = -1;
    EXPECT_INVALID(
        rsmooth_smooth_points(NULL, RSMOOTH_FLOAT64, xyz, nrm, N, &p, out, NULL, NULL, &err),
        "sigma_f");
    rsmooth_params_init(&p);
    p.passes = 0;
    EXPECT_INVALID(
        rsmooth_smooth_points(NULL, RSMOOTH_FLOAT64, xyz, nrm, N, &p, out, out_n, NULL, &err),
        "passes");
    double s;
    CHECK_STATUS(rsmooth_point_spacing(RSMOOTH_FLOAT64, xyz, N, NULL, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK_STATUS(rsmooth_point_spacing(RSMOOTH_FLOAT64, NULL, N, &s, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
#undef EXPECT_INVALID
}

int main(void) {
    test_oracle();
    test_spacing();
    test_sphere();
    test_cube();
    test_degenerate();
    test_bad_input();
    printf("points: all checks passed\n");
    return 0;
}
