/* noise_accuracy driver: for each line "NOISY CLEAN" on stdin, the true noise of NOISY against
 * CLEAN and rs_estimate_noise_details on NOISY, as one JSON line. */
#define _POSIX_C_SOURCE 200809L
#include "auto/noise_estimate.h"
#include "mesh_shapes.h"
#include "rsmooth_io.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now_ms(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec * 1e3 + (double)t.tv_nsec * 1e-6;
}

int main(void) {
    char noisy_path[4096], clean_path[4096];
    while (scanf("%4095s %4095s", noisy_path, clean_path) == 2) {
        rsmooth_mesh *noisy = NULL, *clean = NULL;
        rsmooth_error err;
        if (rsmooth_mesh_read_file(noisy_path, &noisy, &err) != RSMOOTH_OK ||
            rsmooth_mesh_read_file(clean_path, &clean, &err) != RSMOOTH_OK) {
            fprintf(stderr, "%s\n", err.message);
            return 1;
        }
        size_t nv = clean->vertex_count;
        double t_n = NAN, t_all = NAN, t_tan = NAN, frac = NAN;
        shape_mesh view = {nv, clean->positions, clean->triangle_count, clean->triangles};
        double edge = shape_mean_edge_length(&view);
        if (noisy->vertex_count == nv) {
            double *normal = malloc(3 * nv * sizeof *normal);
            shape_vertex_normals(&view, normal);
            double s_all = 0, s_moved = 0, s_tan = 0;
            size_t n = 0, moved = 0;
            for (size_t v = 0; v < nv; v++) {
                const double *a = clean->positions + 3 * v, *b = noisy->positions + 3 * v;
                const double *nn = normal + 3 * v;
                if (nn[0] == 0 && nn[1] == 0 && nn[2] == 0)
                    continue;
                double d[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
                double along = d[0] * nn[0] + d[1] * nn[1] + d[2] * nn[2];
                double all = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                s_all += along * along;
                s_tan += all - along * along;
                n++;
                if (all > 0) {
                    moved++;
                    s_moved += along * along;
                }
            }
            free(normal);
            t_all = sqrt(s_all / n) / edge;
            t_n = moved ? sqrt(s_moved / moved) / edge : 0;
            t_tan = sqrt(s_tan / n / 2) / edge;
            frac = (double)moved / n;
        }
        rs_noise_details d;
        double t0 = now_ms();
        if (rs_estimate_noise_details(RSMOOTH_FLOAT64, noisy->positions, noisy->vertex_count,
                                      noisy->triangles, noisy->triangle_count, &d, &err,
                                      "driver") != RSMOOTH_OK) {
            fprintf(stderr, "%s\n", err.message);
            return 1;
        }
        double ms = now_ms() - t0;
        printf(
            "{\"noisy\": \"%s\", \"vertices\": %zu, \"true_level\": %.6g, \"true_overall\": %.6g, "
            "\"true_tangential\": %.6g, \"true_fraction\": %.6g, \"true_edge\": %.6g, "
            "\"level\": %.6g, \"impulsive\": %s, \"fraction\": %.6g, \"tangential\": %.6g, "
            "\"edge_clean\": %.6g, \"edge_noisy\": %.6g, \"overall\": %.6g, \"tail\": %.6g, "
            "\"samples\": %zu, \"ms\": %.2f, \"correlated\": %.6g, \"length\": %.6g, "
            "\"profile\": [%.6g, %.6g, %.6g], \"profile_floor\": [%.6g, %.6g, %.6g]}\n",
            noisy_path, nv, t_n, t_all, t_tan, frac, edge, d.level, d.impulsive ? "true" : "false",
            d.impulsive_fraction, d.tangential_level, d.mean_edge_clean, d.mean_edge_noisy,
            d.overall_level, d.tail_share, d.samples, ms, d.correlated_level, d.correlation_length,
            d.profile.low[0], d.profile.low[1], d.profile.low[2], d.profile.low_floor[0],
            d.profile.low_floor[1], d.profile.low_floor[2]);
        fflush(stdout);
        rsmooth_mesh_destroy(noisy);
        rsmooth_mesh_destroy(clean);
    }
    return 0;
}
