/* rsmooth render: flat-shaded PNG pictures of meshes side by side, to judge smoothing by eye. */
#define _POSIX_C_SOURCE 200809L
#include "cli_args.h"
#include "cli_commands.h"
#include "cli_files.h"
#include "cli_getopt.h"
#include "cli_output.h"
#include "mesh_render.h"
#include "png_write.h"
#include "rsmooth_io.h"

#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define DEFAULT_PANEL 800
#define MAX_SIDE 16384 /* keeps the supersampled buffers within a few GiB */

static const char render_usage[] =
    "usage: rsmooth render IN... -o OUT.png [options]\n"
    "\n"
    "Draws each mesh IN (OBJ, PLY, OFF, STL) in its own panel, side by side, all from the same\n"
    "camera fitted to every mesh together, so a mesh and its smoothed copy appear at the same\n"
    "place and size. Faces are flat-shaded (one shade per triangle), which shows sharp edges and\n"
    "residual noise plainly. Meshes with vertex colours (such as the file `rsmooth --confidence`\n"
    "writes) are drawn in them; others in light grey. Up is +y.\n"
    "\n"
    "Options:\n"
    "  -o, --output FILE   the PNG to write (required)\n"
    "  --size WxH          each panel's size in pixels (default 800x800); the picture is the\n"
    "                      panels side by side, 6 pixels apart\n"
    "  --azimuth DEG       camera angle about the up axis; 0 looks along -z (default 35)\n"
    "  --elevation DEG     camera angle above the horizon, in (-90, 90) (default 25)\n"
    "  --orthographic      parallel projection instead of perspective\n"
    "  -f, --force         replace OUT if it exists, keeping its permissions, owner and group\n"
    "                      (a symbolic link is written through: rsmooth --help, Output files)\n"
    "  -h, --help          print this help\n"
    "\n"
    "Example:\n"
    "  rsmooth render noisy.ply smooth.ply conf.ply -o compare.png\n"
    "\n"
    "Options take values as --size 400x300 or --size=400x300, before or after the files.\n"
    "\n"
    "Exit status: 0 success, 2 bad usage, an unreadable or malformed input or an OUT that may\n"
    "not be written, 1 other.\n";

static bool parse_size(const char *s, int *w, int *h) {
    char *end;
    errno = 0;
    long a = strtol(s, &end, 10);
    if (end == s || (*end != 'x' && *end != 'X') || errno != 0)
        return false;
    const char *rest = end + 1;
    long b = strtol(rest, &end, 10);
    if (end == rest || *end != '\0' || errno != 0)
        return false;
    if (a < 1 || b < 1 || a > MAX_SIDE || b > MAX_SIDE)
        return false;
    *w = (int)a;
    *h = (int)b;
    return true;
}

typedef struct picture {
    const uint8_t *rgb;
    int width, height;
} picture;

static int write_picture(FILE *stream, void *user, char *message, size_t size) {
    const picture *p = user;
    return png_write_rgb(stream, p->rgb, p->width, p->height, message, size);
}

/* What the command line asked for. */
typedef struct render_job {
    const char *output;
    bool force;
    int width, height; /* --size (0: not given), then the whole picture's */
    render_options options;
    const char **inputs;
    size_t input_count;
} render_job;

/* Reads the command line into `job` (its inputs allocated): -1 to go on, else the exit status
 * (0 after --help). */
static int parse_render_args(int argc, char **argv, render_job *job) {
    job->inputs = calloc((size_t)(argc > 0 ? argc : 1), sizeof *job->inputs);
    if (!job->inputs) {
        fprintf(stderr, "rsmooth render: out of memory\n");
        return 1;
    }
    render_options *options = &job->options;
    int status = 0;
    enum { R_HELP = 1, R_OUTPUT, R_SIZE, R_AZIMUTH, R_ELEVATION, R_ORTHOGRAPHIC, R_FORCE };
    static const cli_option table[] = {
        {"help", 'h', false, R_HELP},        {"output", 'o', true, R_OUTPUT},
        {"size", 0, true, R_SIZE},           {"azimuth", 0, true, R_AZIMUTH},
        {"elevation", 0, true, R_ELEVATION}, {"orthographic", 0, false, R_ORTHOGRAPHIC},
        {"force", 'f', false, R_FORCE},      {NULL, 0, false, 0}};
    cli_getopt_state s;
    cli_getopt_init(&s, argc, argv, "render", table);
    const char *value;
    int id;
    while (status == 0 && (id = cli_getopt(&s, &value)) != CLI_GETOPT_END) {
        if (id == CLI_GETOPT_ERROR) {
            status = 2;
        } else if (id == R_HELP) {
            fputs(render_usage, stdout);
            return 0;
        } else if (id == R_OUTPUT) {
            job->output = value;
        } else if (id == R_SIZE) {
            if (!parse_size(value, &job->width, &job->height))
                status = cli_usage_error("render", "--size wants WxH, each 1 to 16384: %s", value);
        } else if (id == R_AZIMUTH) {
            if (!cli_parse_number(value, &options->azimuth_deg) || !isfinite(options->azimuth_deg))
                status = cli_usage_error("render", "--azimuth wants degrees: %s", value);
        } else if (id == R_ELEVATION) {
            if (!cli_parse_number(value, &options->elevation_deg) ||
                !(options->elevation_deg > -90 && options->elevation_deg < 90))
                status =
                    cli_usage_error("render", "--elevation wants degrees in (-90, 90): %s", value);
        } else if (id == R_ORTHOGRAPHIC) {
            options->orthographic = true;
        } else if (id == R_FORCE) {
            job->force = true;
        } else {
            job->inputs[job->input_count++] = value;
        }
    }
    if (status == 0 && job->input_count == 0)
        status = cli_usage_error("render", "needs at least one mesh file");
    if (status == 0 && !job->output)
        status = cli_usage_error("render", "needs -o OUT.png");
    return status != 0 ? status : -1;
}

/* The picture's size (--size is each panel's, the default 800 x 800: the picture is the panels
 * side by side), and the output checked: -1 to go on, else the exit status. */
static int check_picture(render_job *job) {
    size_t n = job->input_count, gap = (size_t)job->options.gap;
    int panel_width = job->width ? job->width : DEFAULT_PANEL;
    int panel_height = job->width ? job->height : DEFAULT_PANEL;
    size_t total = n * (size_t)panel_width + (n - 1) * gap;
    if (total > MAX_SIDE && !job->width && n * 8 + (n - 1) * gap <= MAX_SIDE) {
        total = MAX_SIDE; /* many meshes: narrower panels by default */
    } else if (total > MAX_SIDE) {
        return cli_usage_error("render",
                               "%zu panels of %d pixels make a picture wider than %d: "
                               "give a smaller --size",
                               n, panel_width, MAX_SIDE);
    }
    job->width = (int)total;
    job->height = panel_height;
    for (size_t i = 0; i < n; i++) {
        if (cli_same_file(job->output, job->inputs[i])) {
            fprintf(stderr, "rsmooth render: %s: refusing to overwrite an input file\n",
                    job->output);
            return 2;
        }
    }
    return cli_check_output_path(job->output, job->force);
}

/* Reads the meshes, draws them and writes the picture: the exit status. */
static int draw(const render_job *job) {
    size_t n = job->input_count;
    int status = 0, width = job->width, height = job->height;
    rsmooth_mesh **meshes = calloc(n, sizeof *meshes);
    render_mesh *views = calloc(n, sizeof *views);
    uint8_t *rgb = NULL;
    if (!meshes || !views) {
        fprintf(stderr, "rsmooth render: out of memory\n");
        status = 1;
        goto done;
    }
    for (size_t i = 0; i < n && status == 0; i++) {
        status = cli_read_mesh(job->inputs[i], NULL, &meshes[i]);
        if (status == 0) {
            views[i].xyz = meshes[i]->positions;
            views[i].vertex_count = meshes[i]->vertex_count;
            views[i].triangles = meshes[i]->triangles;
            views[i].triangle_count = meshes[i]->triangle_count;
            views[i].colors = meshes[i]->vertex_colors;
        }
    }
    if (status != 0)
        goto done;
    rgb = malloc(3 * (size_t)width * (size_t)height);
    if (!rgb || mesh_render(views, n, &job->options, rgb, width, height) != 0) {
        /* The arguments were checked above; what is left is memory. */
        fprintf(stderr, "rsmooth render: out of memory for a %d x %d picture\n", width, height);
        status = 1;
        goto done;
    }
    picture pic = {rgb, width, height};
    status = cli_write_atomically(job->output, job->force, false, write_picture, &pic);
done:
    if (meshes)
        for (size_t i = 0; i < n; i++)
            rsmooth_mesh_destroy(meshes[i]);
    free(meshes);
    free(views);
    free(rgb);
    return status;
}

int cli_render_main(int argc, char **argv) {
    render_job job;
    memset(&job, 0, sizeof job);
    render_options_default(&job.options);
    int status = parse_render_args(argc, argv, &job);
    if (status < 0)
        status = check_picture(&job);
    if (status < 0)
        status = draw(&job);
    free(job.inputs);
    return status;
}
