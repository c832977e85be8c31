/* rsmooth compare: the denoising error of a result mesh against its ground truth, as the library's
 * rsmooth_compare computes it. */
#include "cli_args.h"
#include "cli_commands.h"
#include "cli_files.h"
#include "cli_getopt.h"
#include "rsmooth.h"
#include "rsmooth_io.h"

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

static const char compare_usage[] =
    "usage: rsmooth compare RESULT TRUTH [--json]\n"
    "\n"
    "Measures how far a denoised mesh RESULT is from its ground truth TRUTH. Both must have the\n"
    "same vertices in the same order and the same faces (a filter's output against the clean\n"
    "mesh the noisy input was made from). Files: OBJ, PLY, OFF, STL; polygons count as the\n"
    "triangles of their fans.\n"
    "\n"
    "Metrics (lower is better; 0 for identical meshes), one a line with its unit:\n"
    "  theta      mean angle between corresponding face normals, in degrees (faces with zero\n"
    "             area in either mesh are left out). Measures how well features and flat parts\n"
    "             are restored.\n"
    "  ev         area-weighted RMS distance from the result's vertices to the truth's surface\n"
    "             (Sun et al. 2007 E_v; exact closest points on the triangles, each vertex\n"
    "             weighted by the area of the result's faces around it), in thousandths of the\n"
    "             truth's bounding-box diagonal.\n"
    "  rms_v      RMS distance between corresponding vertices, in mean edge lengths of the\n"
    "             truth (it also counts sliding along the surface, which ev does not).\n"
    "  hausdorff  symmetric Hausdorff distance between the two surfaces sampled at their\n"
    "             vertices: the farthest any result vertex is from the truth's surface or any\n"
    "             truth vertex from the result's surface, in thousandths of the truth's\n"
    "             bounding-box diagonal.\n"
    "  mean_edge  mean length of the truth's unique edges, in its units (the unit of rms_v).\n"
    "  bbox_diag  diagonal of the truth's bounding box, in its units (the unit of ev and\n"
    "             hausdorff, times 1/1000).\n"
    "\n"
    "Options:\n"
    "  --json      print one JSON object with the keys theta, ev, rms_v, hausdorff, mean_edge,\n"
    "              bbox_diag (in the units above; a figure that does not exist, no face with\n"
    "              area, is null), theta_count (the triangles theta averages), vertices and\n"
    "              triangles (faces fanned into triangles): the keys of Python's\n"
    "              rsmooth.compare. \"faces\", the triangles' old key, is kept until 0.12\n"
    "  -h, --help  print this help\n"
    "\n"
    "The figures agree with ../shared/tools/meshmetrics.py, except that ev there tries only the\n"
    "24 triangles with the nearest centroids, so it can be slightly larger.\n"
    "\n"
    "Exit status: 0 success, 2 bad usage or unreadable, malformed or mismatched files, 1 other.\n";

/* A figure as JSON: NAN and infinities have no JSON spelling. */
static void print_json_number(const char *key, double value, bool last) {
    if (isfinite(value))
        printf("\"%s\": %.17g%s", key, value, last ? "" : ", ");
    else
        printf("\"%s\": null%s", key, last ? "" : ", ");
}

int cli_compare_main(int argc, char **argv) {
    const char *paths[2] = {NULL, NULL};
    size_t path_count = 0;
    bool json = false;
    static const cli_option table[] = {
        {"help", 'h', false, 1}, {"json", 0, false, 2}, {NULL, 0, false, 0}};
    cli_getopt_state s;
    cli_getopt_init(&s, argc, argv, "compare", table);
    const char *a;
    int id;
    while ((id = cli_getopt(&s, &a)) != CLI_GETOPT_END) {
        if (id == CLI_GETOPT_ERROR) {
            return 2;
        } else if (id == 1) {
            fputs(compare_usage, stdout);
            return 0;
        } else if (id == 2) {
            json = true;
        } else if (path_count < 2) {
            paths[path_count++] = a;
        } else {
            return cli_usage_error("compare", "too many files: %s", a);
        }
    }
    if (path_count != 2)
        return cli_usage_error("compare", "needs two files, RESULT and TRUTH");

    rsmooth_mesh *result = NULL, *truth = NULL;
    int status = cli_read_mesh(paths[0], NULL, &result);
    if (status == 0)
        status = cli_read_mesh(paths[1], NULL, &truth);
    if (status != 0)
        goto done;
    if (result->vertex_count != truth->vertex_count) {
        fprintf(stderr,
                "rsmooth compare: %s has %zu vertices but %s has %zu: they must be the same mesh "
                "with moved vertices\n",
                paths[0], result->vertex_count, paths[1], truth->vertex_count);
        status = 2;
        goto done;
    }
    if (result->triangle_count != truth->triangle_count) {
        fprintf(stderr,
                "rsmooth compare: %s has %zu triangles but %s has %zu: they must have the same "
                "faces\n",
                paths[0], result->triangle_count, paths[1], truth->triangle_count);
        status = 2;
        goto done;
    }
    for (size_t i = 0; i < 3 * result->triangle_count; i++) {
        if (result->triangles[i] != truth->triangles[i]) {
            fprintf(stderr,
                    "rsmooth compare: %s and %s differ at triangle %zu (of their faces fanned "
                    "into triangles): vertex or face order was changed\n",
                    paths[0], paths[1], i / 3 + 1);
            status = 2;
            goto done;
        }
    }
    if (result->triangle_count == 0) {
        fprintf(stderr, "rsmooth compare: %s and %s have no faces: nothing to compare\n", paths[0],
                paths[1]);
        status = 2;
        goto done;
    }
    rsmooth_metrics m;
    rsmooth_error err;
    rsmooth_status st =
        rsmooth_compare(RSMOOTH_FLOAT64, result->positions, truth->positions, result->vertex_count,
                        result->triangles, result->triangle_count, &m, &err);
    if (st != RSMOOTH_OK) {
        /* The readers checked indices and coordinates: what is left is mostly memory. */
        fprintf(stderr, "rsmooth compare: %s, %s: %s\n", paths[0], paths[1],
                err.message[0] ? err.message : rsmooth_status_str(st));
        status = st == RSMOOTH_ERROR_INVALID_ARGUMENT ? 2 : 1;
        goto done;
    }
    if (json) {
        printf("{");
        print_json_number("theta", m.theta, false);
        print_json_number("ev", m.ev, false);
        print_json_number("rms_v", m.rms_v, false);
        print_json_number("hausdorff", m.hausdorff, false);
        print_json_number("mean_edge", m.mean_edge, false);
        print_json_number("bbox_diag", m.bbox_diag, false);
        /* the keys rsmooth.compare returns; "faces" (the triangles) goes in 0.12 */
        printf("\"theta_count\": %zu, \"vertices\": %zu, \"triangles\": %zu, \"faces\": %zu}\n",
               m.theta_count, m.vertex_count, m.triangle_count, m.triangle_count);
    } else {
        printf("theta      %.6g degrees\n"
               "ev         %.6g thousandths of the bounding-box diagonal\n"
               "rms_v      %.6g mean edge lengths\n"
               "hausdorff  %.6g thousandths of the bounding-box diagonal\n"
               "mean_edge  %.6g (the truth's units)\n"
               "bbox_diag  %.6g (the truth's units)\n",
               m.theta, m.ev, m.rms_v, m.hausdorff, m.mean_edge, m.bbox_diag);
    }
    if (fflush(stdout) != 0 || ferror(stdout)) {
        fprintf(stderr, "rsmooth compare: cannot write the figures\n");
        status = 1;
    }
done:
    rsmooth_mesh_destroy(result);
    rsmooth_mesh_destroy(truth);
    return status;
}
