/* What the rsmooth command prints besides its status lines: --list-devices, --json, --stats,
 * what a conversion drops, and the confidence colour ramp. */
#define _POSIX_C_SOURCE 200809L
#include "cli_report.h"
#include "cli_args.h"
#include "cli_files.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int cli_list_devices(void) {
    rsmooth_device_info devices[64];
    size_t n = rsmooth_list_devices(devices, 64);
    if (n == 0) {
        /* why: no OpenCL loader, or a loader without platforms. With no device to build for,
         * asking for a context fails at once and says which. */
        rsmooth_context *ctx = NULL;
        rsmooth_error err;
        rsmooth_context_options automatic = {.struct_size = sizeof automatic, .device = "auto"};
        if (rsmooth_context_create(&automatic, &ctx, &err) == RSMOOTH_ERROR_NO_DEVICE)
            printf("%s; --device reference still works\n", err.message);
        else
            printf("no OpenCL device (install an OpenCL driver, e.g. pocl-opencl-icd); "
                   "--device reference still works\n");
        rsmooth_context_destroy(ctx);
        return EXIT_OK;
    }
    /* the name column as wide as the longest name, the version last and whole */
    int width = 4;
    for (size_t i = 0; i < n && i < 64; i++)
        if ((int)strlen(devices[i].name) > width)
            width = (int)strlen(devices[i].name);
    printf("%-5s %-5s %-*s %6s %9s  %s\n", "P:D", "type", width, "name", "units", "memory",
           "version");
    for (size_t i = 0; i < n && i < 64; i++) {
        char pd[16];
        snprintf(pd, sizeof pd, "%d:%d", devices[i].platform_index, devices[i].device_index);
        char version[1024]; /* the field holds 63 bytes; this the whole version */
        if (rsmooth_device_version(devices[i].platform_index, devices[i].device_index, version,
                                   sizeof version) == 0)
            snprintf(version, sizeof version, "%s", devices[i].version);
        printf("%-5s %-5s %-*s %6u %6.1f GiB  %s\n", pd, devices[i].type, width, devices[i].name,
               devices[i].compute_units, (double)devices[i].global_memory / (1u << 30), version);
    }
    printf("--device auto picks the first GPU, else the first CPU device; --device reference runs "
           "the double-precision C path.\n");
    return EXIT_OK;
}

/* Red (low confidence) through yellow to blue (high): readable on white and for most colour-blind
 * viewers. */
void cli_confidence_colour(float c, uint8_t rgb[3]) {
    static const float stops[3][3] = {{215, 48, 39}, {254, 224, 144}, {69, 117, 180}};
    float x = c < 0 ? 0 : c > 1 ? 1 : c;
    int i = x < 0.5f ? 0 : 1;
    float t = x < 0.5f ? x * 2 : (x - 0.5f) * 2;
    for (int k = 0; k < 3; k++)
        rgb[k] = (uint8_t)lrintf(stops[i][k] + t * (stops[i + 1][k] - stops[i][k]));
}

void cli_print_harm(const char *input, const rsmooth_report *r) {
    if (r->parts > 1)
        fprintf(stderr,
                "rsmooth: %s: %zu parts of very different size, each smoothed in its own "
                "unit with its own triangles only\n",
                input, r->parts);
    if (r->outliers > 0)
        fprintf(stderr,
                "rsmooth: %s: %zu outlier vertices (every triangle they belong to out of "
                "scale with the surface around it) held where they were; their triangles "
                "moved no other vertex\n",
                input, r->outliers);
    if (r->guarded_vertices > 0)
        fprintf(stderr,
                "rsmooth: %s: %zu vertices pulled back toward the input so that no "
                "triangle turned over (--no-guard: the filter's result as it came)\n",
                input, r->guarded_vertices);
    if (r->stage_skipped)
        fprintf(stderr,
                "rsmooth: %s: the mesh reads clean: the normal update stage had nothing "
                "to remove and did not run (--no-guard runs it)\n",
                input);
}

void cli_print_json(const rsmooth_report *r, const options *opt, double ms_read, double ms_write) {
    printf("{\"input\":");
    cli_print_json_string(opt->input);
    printf(",\"output\":");
    cli_print_json_string(opt->output);
    /* what ran: --auto's blend per region is the filter and Taubin's smoothing; --auto on a mesh
     * that reads clean ran nothing */
    const char *ran = cli_method_names[opt->method];
    if (r->discrepancy_iterations > 0)
        ran = "robust+taubin";
    else if (!cli_method_uses_edges(opt->method) && opt->params.passes == 0 &&
             opt->params.vertex_updates == 0)
        ran = "none";
    printf(",\"method\":\"%s\"", ran);
    if (r->discrepancy_iterations > 0) /* --auto's choice per region: blended with Taubin's */
        printf(",\"region_choice\":{\"taubin_iterations\":%d,\"lambda\":0.5,\"mu\":-0.53,"
               "\"filter_share\":%.4f}",
               r->discrepancy_iterations, r->region_filter_share);
    if (cli_method_uses_edges(opt->method))
        printf(",\"lambda\":%.9g,\"mu\":%.9g,\"iterations\":%u", opt->lambda, opt->mu,
               opt->iterations);
    else {
        const rsmooth_params *p = &opt->params;
        /* a point cloud (no triangles) has the bilateral normal filter only, and its unit is the
         * point spacing (given as mean_edge_length) */
        bool points = r->triangle_count == 0;
        int filter = points ? RSMOOTH_NORMALS_BILATERAL : p->normal_filter;
        if (points)
            printf(",\"point_cloud\":true");
        printf(",\"normals\":\"%s\"", p->mollify ? cli_normal_filter_names[filter] : "input");
        if (p->mollify && filter == RSMOOTH_NORMALS_BILATERAL)
            printf(",\"normal_sigma_s\":%.9g,\"normal_sigma_n\":%.9g,\"normal_iterations\":%d",
                   p->normal_sigma_s, p->normal_sigma_n, p->normal_iterations);
        if (p->colors) /* the colour factor's width; null: off */
            printf(",\"sigma_c\":%.9g", p->sigma_c);
        else
            printf(",\"sigma_c\":null");
        printf(",\"influence\":\"%s\",\"passes\":%d,\"pass_confidence\":%.9g",
               cli_influence_names[p->influence], p->passes, p->pass_confidence);
        printf(",\"vertex_updates\":%d", p->vertex_updates);
        if (p->vertex_updates > 0)
            printf(",\"guided_sigma_s\":%.9g,\"guided_sigma_n\":%.9g,\"guided_radius\":%.9g,"
                   "\"guided_rounds\":%d,\"stage_repeats\":%d,\"discrepancy_level\":%.9g,"
                   "\"discrepancy_iterations\":%d",
                   p->guided_sigma_s, p->guided_sigma_n, p->guided_radius, p->guided_rounds,
                   p->stage_repeats, p->discrepancy_level, r->discrepancy_iterations);
        if (opt->auto_params) {
            printf(",\"noise_estimate\":%.9g,\"shape_correlation\":%.9g,\"preset\":", opt->noise,
                   opt->noise_shape_correlation);
            cli_print_json_string(opt->noise_preset);
        }
        if (opt->auto_params && opt->noise_correlation_length > 0)
            printf(",\"noise_correlated\":%.9g,\"noise_correlation_length\":%.9g",
                   opt->noise_correlated, opt->noise_correlation_length);
    }
    /* mean_edge_length to the last bit: the figure rsmooth compare's mean_edge and Python's
     * rsmooth.mean_edge_length give for the same file */
    printf(",\"vertices\":%zu,\"triangles\":%zu,\"facets\":%zu,\"mean_edge_length\":%.17g,"
           "\"sigma_f\":%.9g,",
           r->vertex_count, r->triangle_count, r->facet_count, r->mean_edge_length, r->sigma_f);
    if (isinf(r->sigma_g))
        printf("\"sigma_g\":null,");
    else
        printf("\"sigma_g\":%.9g,", r->sigma_g);
    printf("\"radius\":%.9g,\"grid_cells\":%zu,\"pairs_robust\":%llu,\"tiles\":%zu,\"parts\":%zu,"
           "\"outliers\":%zu,\"guarded_vertices\":%zu,\"stage_skipped\":%s,\"device\":",
           r->radius, r->grid_cell_count, (unsigned long long)r->pairs_robust, r->tiles, r->parts,
           r->outliers, r->guarded_vertices, r->stage_skipped ? "true" : "false");
    cli_print_json_string(r->device);
    if (r->stage_cycles > 0) /* the normal-update stage: where it ran, its parts, its traffic */
        printf(",\"stage\":{\"on_device\":%s,\"float_bits\":%d,\"cycles\":%d,"
               "\"bytes_to_device\":%llu,"
               "\"bytes_from_device\":%llu,\"ms\":{\"lists\":%.3f,\"upload\":%.3f,"
               "\"cycles\":%.3f,\"download\":%.3f,\"total\":%.3f}}",
               r->stage_on_device ? "true" : "false", r->stage_float_bits, r->stage_cycles,
               (unsigned long long)r->stage_bytes_to_device,
               (unsigned long long)r->stage_bytes_from_device, r->ms_stage_lists,
               r->ms_stage_upload, r->ms_stage_cycles, r->ms_stage_download, r->ms_stage);
    printf(",\"ms\":{\"read\":%.3f,\"setup\":%.3f,\"facets\":%.3f,\"grid\":%.3f,\"upload\":%.3f,"
           "\"mollify\":%.3f,\"normals\":%.3f,\"robust\":%.3f,\"download\":%.3f,\"filter\":%.3f,"
           "\"write\":%.3f}}\n",
           ms_read, r->ms_setup, r->ms_facets, r->ms_grid, r->ms_upload, r->ms_mollify,
           r->ms_normals, r->ms_robust, r->ms_download, r->ms_total, ms_write);
}

static int compare_double(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* --stats: what the mesh is and what the filter did to it, in mean edge lengths. */
void cli_print_stats(const rsmooth_mesh *mesh, const double *out, const float *confidence,
                     const rsmooth_report *r) {
    size_t nv = mesh->vertex_count;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    unsigned char *used = calloc(nv, 1);
    double *moved = malloc(nv * sizeof *moved);
    if (!used || !moved) {
        free(used);
        free(moved);
        return;
    }
    for (size_t i = 0; i < 3 * mesh->triangle_count; i++)
        used[mesh->triangles[i]] = 1;
    size_t unreferenced = 0, low = 0;
    double conf_sum = 0, conf_min = 1;
    for (size_t v = 0; v < nv; v++) {
        double d2 = 0;
        for (int k = 0; k < 3; k++) {
            double x = mesh->positions[3 * v + k], d = out[3 * v + k] - x;
            lo[k] = fmin(lo[k], x);
            hi[k] = fmax(hi[k], x);
            d2 += d * d;
        }
        moved[v] = r->mean_edge_length > 0 ? sqrt(d2) / r->mean_edge_length : 0;
        unreferenced += !used[v];
        if (confidence) {
            conf_sum += confidence[v];
            conf_min = fmin(conf_min, confidence[v]);
            low += confidence[v] < 0.5f;
        }
    }
    qsort(moved, nv, sizeof *moved, compare_double);
    double moved_sum = 0;
    for (size_t v = 0; v < nv; v++)
        moved_sum += moved[v];
    bool points = mesh->triangle_count == 0; /* a point cloud: its unit is the point spacing */
    const char *unit = points ? "point spacings" : "mean edge lengths";
    if (points)
        fprintf(stderr,
                "cloud:       %zu points with normals, no faces\n"
                "size:        %.6g x %.6g x %.6g, point spacing %.6g\n"
                "filter:      sigma_f %.6g, sigma_g %.6g, reach %.6g (cloud units), %zu points "
                "of zero area (duplicates)\n",
                nv, hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], r->mean_edge_length, r->sigma_f,
                r->sigma_g, r->radius, nv - r->facet_count);
    else
        fprintf(stderr,
                "mesh:        %zu vertices (%zu referenced by no triangle), %zu faces, %zu "
                "triangles\n"
                "size:        %.6g x %.6g x %.6g, mean edge %.6g\n",
                nv, unreferenced, mesh->face_count, mesh->triangle_count, hi[0] - lo[0],
                hi[1] - lo[1], hi[2] - lo[2], r->mean_edge_length);
    if (!points && confidence) /* the robust filter and the Gaussian; umbrella methods have none */
        fprintf(stderr,
                "filter:      sigma_f %.6g, sigma_g %.6g, reach %.6g (mesh units), %zu grid "
                "cells in %zu tile%s, %zu triangles of zero area\n",
                r->sigma_f, r->sigma_g, r->radius, r->grid_cell_count, r->tiles,
                r->tiles == 1 ? "" : "s", r->triangle_count - r->facet_count);
    else if (!points)
        fprintf(stderr, "filter:      %s\n", r->device);
    fprintf(stderr, "moved:       mean %.4f, median %.4f, max %.4f %s\n", moved_sum / (double)nv,
            moved[nv / 2], moved[nv - 1], unit);
    if (confidence)
        fprintf(stderr, "confidence:  mean %.3f, min %.3f, %zu %s (%.1f%%) below 0.5\n",
                conf_sum / (double)nv, conf_min, low, points ? "points" : "vertices",
                100.0 * (double)low / (double)nv);
    free(used);
    free(moved);
}

/* Says on stderr what writing `mesh` as `format` drops. */
void cli_warn_losses(const rsmooth_mesh *mesh, const char *path, rsmooth_format format,
                     bool quiet) {
    char lost[512];
    if (!quiet && rsmooth_mesh_conversion_losses(mesh, format, lost, sizeof lost) > 0)
        fprintf(stderr, "rsmooth: %s: this format cannot hold, so drops: %s\n", path, lost);
}
