/* The rsmooth command's confidence mesh, --confidence (see cli_smooth.h). */
#define _POSIX_C_SOURCE 200809L
#include "cli_files.h"
#include "cli_output.h"
#include "cli_report.h"
#include "cli_smooth.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

int cli_write_confidence(rsmooth_mesh *mesh, const options *opt, float *confidence) {
    if (cli_same_file(opt->confidence, opt->output)) { /* e.g. out.ply and ./out.ply */
        fprintf(stderr, "rsmooth: %s: is the output file; the confidence mesh needs its own file\n",
                opt->confidence);
        return EXIT_USAGE;
    }
    size_t nv = mesh->vertex_count;
    uint8_t *colours = malloc(nv * 3);
    if (!colours) {
        fprintf(stderr, "rsmooth: %s: out of memory\n", opt->confidence);
        return EXIT_OTHER;
    }
    /* Normalised: the ramp spans the mesh's own range of confidence among vertices some facet
     * reached (those no facet reached, confidence 0, are red), so the lows show on any mesh;
     * the raw value stays in the quality property. */
    float lo = INFINITY, hi = 0;
    for (size_t v = 0; v < nv; v++)
        if (confidence[v] > 0) {
            lo = fminf(lo, confidence[v]);
            hi = fmaxf(hi, confidence[v]);
        }
    for (size_t v = 0; v < nv; v++) {
        float c = confidence[v];
        float x = !(c > 0) ? 0 : hi - lo > 1e-6f ? (c - lo) / (hi - lo) : 1;
        cli_confidence_colour(x, colours + 3 * v);
    }
    if (!opt->quiet)
        fprintf(stderr, "rsmooth: %s: confidence from %.3g (red) to %.3g (blue)\n", opt->confidence,
                lo < hi ? lo : hi, hi);
    float *quality = mesh->vertex_quality;
    uint8_t *input_colours = mesh->vertex_colors;
    struct rsmooth_mesh_extras *extras = mesh->extras;
    mesh->vertex_quality = confidence;
    mesh->vertex_colors = colours;
    mesh->extras = NULL;
    int code = cli_write_mesh(mesh, opt->confidence, cli_output_format(opt->confidence, opt->ascii),
                              opt->force, opt->quiet);
    mesh->vertex_quality = quality;
    mesh->vertex_colors = input_colours;
    mesh->extras = extras;
    free(colours);
    return code;
}
