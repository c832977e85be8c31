/* `rsmooth noise`: corrupts a mesh with reproducible Gaussian, impulsive, correlated or
 * depth-sensor noise (experiments, training data). */
#include "cli_args.h"
#include "cli_commands.h"
#include "cli_files.h"
#include "cli_getopt.h"
#include "mesh_noise.h"
#include "mesh_noise_depth.h"
#include "rsmooth_io.h"

#include <ctype.h>
#include <errno.h>
#include <inttypes.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define DEFAULT_SEED 1
/* Mean edge lengths: larger noise no longer leaves a noisy copy of the mesh. */
#define MAX_SIGMA 1e6
/* The largest coordinate magnitude rsmooth reads (rsmooth.h): the output must stay readable. */
#define MAX_COORDINATE 1e150
/* --depth-sensor's defaults: a step of half the noise, the cosine below which a vertex grazes,
 * ridges a quarter of the noise every 4 edges */
#define DEFAULT_QUANTUM_OF_SIGMA 0.5
#define DEFAULT_GRAZING 0.15
#define DEFAULT_RIDGES 0.25
#define DEFAULT_RIDGE_PERIOD 4.0

static const char noise_usage_text[] =
    "usage: rsmooth noise INPUT OUTPUT --sigma S [options]\n"
    "\n"
    "Adds synthetic noise to a mesh, the corruption used to test denoisers: a clean mesh, its\n"
    "noisy copy, the result of smoothing the copy, then `rsmooth compare` against the clean one.\n"
    "Only vertex positions change: vertex order, faces and everything else the file holds are\n"
    "kept when OUTPUT has INPUT's format (vertex normals are recomputed).\n"
    "\n"
    "Options:\n"
    "  --sigma S        standard deviation of each vertex's displacement along its direction,\n"
    "                   in mean edge lengths of INPUT (the mean over its unique edges); in\n"
    "                   [0, 1e6]. Required. Noise that would carry a coordinate beyond 1e150\n"
    "                   (what rsmooth reads) is refused and nothing is written.\n"
    "  --direction D    normal (default): along the vertex normal (area-weighted normals of\n"
    "                   INPUT; a vertex no triangle uses gets a random direction). random:\n"
    "                   along a uniformly random unit direction per vertex, so the noise also\n"
    "                   slides vertices within the surface.\n"
    "  --impulsive F    impulsive noise, as in the denoising benchmarks (Twelve0.5Impulsive):\n"
    "                   exactly round(F x vertex count) vertices, chosen at random, each get\n"
    "                   the Gaussian displacement; all others stay exactly where they are.\n"
    "                   F in (0, 1]; without this option every vertex moves.\n"
    "  --correlation L  spatially correlated (band-limited) noise, as real range scans have:\n"
    "                   each vertex's i.i.d. Gaussian is replaced by the Gaussian-weighted\n"
    "                   average, weights exp(-d^2 / 2 (L e)^2), of the Gaussians of all\n"
    "                   vertices within 3 L e of it (Euclidean distance d, e the mean edge\n"
    "                   length), divided by the root of the sum of the squared weights, so each\n"
    "                   vertex's displacement still has standard deviation --sigma; two\n"
    "                   vertices d apart correlate by about exp(-d^2 / 4 (L e)^2). L > 0 mean\n"
    "                   edge lengths (at most 100).\n"
    "  --stripes W      scan-line stripes instead of i.i.d. noise: a direction u drawn from\n"
    "                   the seed cuts space into slabs W mean edge lengths wide (the first\n"
    "                   boundary at a random phase); slab k gets a Gaussian amplitude a_k and a\n"
    "                   vertex a fraction f across it is displaced by a_k sin(pi f) (ridges and\n"
    "                   grooves along u's normal planes, continuous), the whole scaled so the\n"
    "                   root mean square displacement over the vertices is exactly --sigma.\n"
    "                   W > 0 (at most 1e6); not with --correlation.\n"
    "  --depth-sensor   depth-camera noise, Kinect-like structured light or time of flight, for\n"
    "                   training data that looks like real scans. A camera looks at INPUT's\n"
    "                   bounding-box centre from 3 bounding-box diagonals away, along --view or\n"
    "                   a direction drawn from the seed. Each vertex moves along the ray from\n"
    "                   the camera to it (not along its normal) by a Gaussian of standard\n"
    "                   deviation --sigma x (z / z_mean)^2, z its distance from the camera and\n"
    "                   z_mean the mean over the vertices (depth error grows with the square of\n"
    "                   depth), plus scan-line ridges; its depth is then rounded to --quantum\n"
    "                   steps. Where a sensor sees the surface edge-on or from behind it returns\n"
    "                   no depth; here no vertex or face is removed (training pairs need the\n"
    "                   clean mesh's vertices and faces, one for one), so such holes are strong\n"
    "                   noise instead: the Gaussian is divided by max(c, --grazing), c the\n"
    "                   cosine between the vertex normal and the direction to the camera. Not\n"
    "                   with --direction, --impulsive, --correlation or --stripes.\n"
    "  --view X,Y,Z     with --depth-sensor: the camera's direction from the bounding-box centre,\n"
    "                   three numbers not all zero (default: drawn from the seed)\n"
    "  --quantum Q      with --depth-sensor: the depth step at the mean depth in mean edge\n"
    "                   lengths, growing as (z / z_mean)^2 like the noise; in [0, 1e6], 0 off\n"
    "                   (default 0.5 x --sigma)\n"
    "  --grazing C      with --depth-sensor: the cosine below which a vertex grazes and gets\n"
    "                   1 / C times the noise (a vertex seen from behind too); in [0.01, 1]\n"
    "                   (default 0.15)\n"
    "  --ridges A       with --depth-sensor: scan-line ridges, A sigma (z / z_mean)^2\n"
    "                   sin(2 pi x / P + phase) added to the depth, x along the image's\n"
    "                   horizontal axis (the phase from the seed); A a fraction of --sigma\n"
    "                   in [0, 10], 0 off (default 0.25)\n"
    "  --ridge-period P with --depth-sensor: the ridges' period P in mean edge lengths at the\n"
    "                   mean depth; in (0, 1e6] (default 4)\n"
    "  --seed N         seed of the random generator, an integer in [0, 2^64) (default 1).\n"
    "                   The same INPUT, options and seed give the same OUTPUT, byte for\n"
    "                   byte; a vertex moved by --impulsive moves exactly as without it.\n"
    "  --ascii          write PLY and STL as ascii (default binary little-endian)\n"
    "  -f, --force      replace OUTPUT if it exists (never INPUT), keeping its permissions,\n"
    "                   owner and group; a symbolic link is written through (rsmooth --help,\n"
    "                   Output files)\n"
    "  -q, --quiet      print nothing but errors\n"
    "  -h, --help       print this help\n"
    "\n"
    "Examples:\n"
    "  rsmooth noise fandisk.obj fandisk-0.3.obj --sigma 0.3 --seed 7\n"
    "  rsmooth noise part.ply part-impulsive.ply --sigma 0.5 --impulsive 0.1\n"
    "  rsmooth noise bunny.obj bunny-scan.obj --sigma 0.15 --correlation 2\n"
    "  rsmooth noise chair.ply chair-kinect.ply --sigma 0.2 --depth-sensor --view 0,1,2\n"
    "\n"
    "Exit status: 0 success, 2 bad usage, a bad input file or an OUTPUT that may not be\n"
    "written, 1 other.\n";

typedef struct noise_args {
    const char *input, *output;
    mesh_noise_options noise;
    bool have_sigma, impulsive, ascii, force, quiet;
    /* --depth-sensor; its options; which of them were given (to refuse them without it) */
    bool depth, have_direction, have_quantum;
    mesh_depth_noise_options depth_noise;
    char depth_option[sizeof((cli_getopt_state *)0)->spelled];
} noise_args;

/* Decimal digits only: strtoull would take "-1" as 2^64 - 1, and a seed must be typed exactly. */
static bool parse_seed(const char *text, uint64_t *out) {
    if (!isdigit((unsigned char)text[0]))
        return false;
    char *end = NULL;
    errno = 0;
    unsigned long long v = strtoull(text, &end, 10);
    if (*end != '\0' || errno == ERANGE)
        return false;
#if ULLONG_MAX > UINT64_MAX
    if (v > UINT64_MAX)
        return false;
#endif
    *out = (uint64_t)v;
    return true;
}

/* "X,Y,Z": three finite numbers, not all zero, divided by the largest magnitude so that even
 * "1e-200,0,0" has a length the noise can normalise. */
static bool parse_view(const char *text, double view[3]) {
    char buffer[256];
    if (strlen(text) >= sizeof buffer)
        return false;
    strcpy(buffer, text);
    char *part = buffer;
    double largest = 0;
    for (int k = 0; k < 3; k++) {
        char *comma = strchr(part, ',');
        if ((k < 2) != (comma != NULL))
            return false;
        if (comma)
            *comma = '\0';
        if (!cli_parse_number(part, &view[k]) || !isfinite(view[k]))
            return false;
        largest = fmax(largest, fabs(view[k]));
        part = comma ? comma + 1 : part;
    }
    for (int k = 0; largest > 0 && k < 3; k++)
        view[k] /= largest;
    return largest > 0;
}

enum {
    N_HELP = 1,
    N_SIGMA,
    N_IMPULSIVE,
    N_DIRECTION,
    N_SEED,
    N_ASCII,
    N_FORCE,
    N_QUIET,
    N_CORRELATION,
    N_STRIPES,
    N_DEPTH,
    N_VIEW,
    N_QUANTUM,
    N_GRAZING,
    N_RIDGES,
    N_RIDGE_PERIOD
};

/* --view, --quantum, --grazing, --ridges, --ridge-period: -1 when taken, else the exit status. */
static int parse_depth_option(int id, const char *spelled, const char *value, noise_args *a) {
    mesh_depth_noise_options *d = &a->depth_noise;
    if (!a->depth_option[0])
        snprintf(a->depth_option, sizeof a->depth_option, "%s", spelled);
    if (id == N_VIEW) {
        if (!parse_view(value, d->view))
            return cli_usage_error("noise",
                                   "--view must be three finite numbers X,Y,Z, not all zero "
                                   "(got '%s')",
                                   value);
        d->have_view = true;
        return -1;
    }
    /* each option's range: the quantum and the period in mean edge lengths, like --sigma */
    static const struct {
        int id;
        double least, most;
        bool least_open;
    } ranges[] = {{N_QUANTUM, 0, MAX_SIGMA, false},
                  {N_GRAZING, 0.01, 1, false},
                  {N_RIDGES, 0, 10, false},
                  {N_RIDGE_PERIOD, 0, MAX_SIGMA, true}};
    for (size_t i = 0; i < sizeof ranges / sizeof ranges[0]; i++) {
        if (ranges[i].id != id)
            continue;
        double x;
        if (!cli_parse_number(value, &x) ||
            !(ranges[i].least_open ? x > ranges[i].least : x >= ranges[i].least) ||
            !(x <= ranges[i].most))
            return cli_usage_error("noise", "%s must be in %c%g, %g] (got '%s')", spelled,
                                   ranges[i].least_open ? '(' : '[', ranges[i].least,
                                   ranges[i].most, value);
        if (id == N_QUANTUM)
            d->quantum = x, a->have_quantum = true;
        else if (id == N_GRAZING)
            d->grazing = x;
        else if (id == N_RIDGES)
            d->ridge_amplitude = x;
        else
            d->ridge_period = x;
    }
    return -1;
}

/* Options that exclude each other, and what --depth-sensor's defaults become once --sigma is
 * known. Returns -1 when the command should go on, else the exit status. */
static int settle_noise_args(noise_args *a) {
    if (a->noise.correlation > 0 && a->noise.stripes > 0)
        return cli_usage_error("noise", "--correlation and --stripes exclude each other");
    if (!a->depth && a->depth_option[0])
        return cli_usage_error("noise", "%s is an option of --depth-sensor (give both)",
                               a->depth_option);
    if (a->depth) {
        /* the depth model chooses its own direction (the ray) and moves every vertex */
        const char *other = a->have_direction          ? "--direction"
                            : a->impulsive             ? "--impulsive"
                            : a->noise.correlation > 0 ? "--correlation"
                            : a->noise.stripes > 0     ? "--stripes"
                                                       : NULL;
        if (other)
            return cli_usage_error("noise", "--depth-sensor and %s exclude each other", other);
    }
    if (!a->have_sigma)
        return cli_usage_error("noise",
                               "--sigma is required (in mean edge lengths, e.g. --sigma 0.3)");
    a->depth_noise.sigma = a->noise.sigma;
    a->depth_noise.seed = a->noise.seed;
    if (!a->have_quantum)
        a->depth_noise.quantum = DEFAULT_QUANTUM_OF_SIGMA * a->noise.sigma;
    return -1;
}

/* Returns -1 when the command should go on, else the exit status. */
static int parse_noise_args(int argc, char **argv, noise_args *a) {
    memset(a, 0, sizeof *a);
    a->noise.direction = MESH_NOISE_NORMAL;
    a->noise.seed = DEFAULT_SEED;
    a->depth_noise.grazing = DEFAULT_GRAZING;
    a->depth_noise.ridge_amplitude = DEFAULT_RIDGES;
    a->depth_noise.ridge_period = DEFAULT_RIDGE_PERIOD;
    static const cli_option table[] = {{"help", 'h', false, N_HELP},
                                       {"sigma", 0, true, N_SIGMA},
                                       {"impulsive", 0, true, N_IMPULSIVE},
                                       {"direction", 0, true, N_DIRECTION},
                                       {"seed", 0, true, N_SEED},
                                       {"ascii", 0, false, N_ASCII},
                                       {"force", 'f', false, N_FORCE},
                                       {"quiet", 'q', false, N_QUIET},
                                       {"correlation", 0, true, N_CORRELATION},
                                       {"stripes", 0, true, N_STRIPES},
                                       {"depth-sensor", 0, false, N_DEPTH},
                                       {"view", 0, true, N_VIEW},
                                       {"quantum", 0, true, N_QUANTUM},
                                       {"grazing", 0, true, N_GRAZING},
                                       {"ridges", 0, true, N_RIDGES},
                                       {"ridge-period", 0, true, N_RIDGE_PERIOD},
                                       {NULL, 0, false, 0}};
    cli_getopt_state s;
    cli_getopt_init(&s, argc, argv, "noise", table);
    const char *value;
    int id, code;
    while ((id = cli_getopt(&s, &value)) != CLI_GETOPT_END) {
        double x;
        if (id == CLI_GETOPT_ERROR) {
            return EXIT_USAGE;
        } else if (id == N_HELP) {
            fputs(noise_usage_text, stdout);
            return EXIT_OK;
        } else if (id == N_SIGMA || id == N_IMPULSIVE) {
            if (!cli_parse_number(value, &x))
                return cli_usage_error("noise", "%s: not a number: '%s'", s.spelled, value);
            if (id == N_SIGMA) {
                if (!(x >= 0 && x <= MAX_SIGMA))
                    return cli_usage_error("noise",
                                           "--sigma must be in [0, %g] mean edge lengths "
                                           "(got '%s')",
                                           MAX_SIGMA, value);
                a->noise.sigma = x;
                a->have_sigma = true;
            } else {
                /* 0 would mean "every vertex" to mesh_add_noise: a surprise for someone who asked
                 * for impulsive noise, so it is refused here. */
                if (!(x > 0 && x <= 1))
                    return cli_usage_error("noise",
                                           "--impulsive must be a fraction in (0, 1] (got '%s'); "
                                           "leave it out to move every vertex",
                                           value);
                a->noise.impulsive_fraction = x;
                a->impulsive = true;
            }
        } else if (id == N_CORRELATION || id == N_STRIPES) {
            /* beyond 100 edges the neighbour sums of --correlation cost too much; stripes
             * cost nothing */
            double most = id == N_CORRELATION ? 100 : MAX_SIGMA;
            if (!cli_parse_number(value, &x) || !(x > 0 && x <= most))
                return cli_usage_error("noise",
                                       "%s must be in (0, %g] mean edge lengths (got '%s')",
                                       s.spelled, most, value);
            if (id == N_CORRELATION)
                a->noise.correlation = x;
            else
                a->noise.stripes = x;
        } else if (id >= N_VIEW && id <= N_RIDGE_PERIOD) {
            if ((code = parse_depth_option(id, s.spelled, value, a)) >= 0)
                return code;
        } else if (id == N_DEPTH) {
            a->depth = true;
        } else if (id == N_DIRECTION) {
            a->have_direction = true;
            if (!strcmp(value, "normal"))
                a->noise.direction = MESH_NOISE_NORMAL;
            else if (!strcmp(value, "random"))
                a->noise.direction = MESH_NOISE_RANDOM;
            else
                return cli_usage_error("noise", "--direction: '%s' is not normal or random", value);
        } else if (id == N_SEED) {
            if (!parse_seed(value, &a->noise.seed))
                return cli_usage_error("noise", "--seed: not an integer in [0, 2^64): '%s'", value);
        } else if (id == N_ASCII) {
            a->ascii = true;
        } else if (id == N_FORCE) {
            a->force = true;
        } else if (id == N_QUIET) {
            a->quiet = true;
        } else if (!a->input) {
            a->input = value;
        } else if (!a->output) {
            a->output = value;
        } else {
            return cli_usage_error("noise", "unexpected argument '%s' (INPUT and OUTPUT only)",
                                   value);
        }
    }
    if (!a->input)
        return cli_usage_error("noise", "no input file");
    if (!a->output)
        return cli_usage_error("noise", "no output file");
    return settle_noise_args(a);
}

/* The noisy mesh must be one rsmooth reads back: every coordinate finite and within
 * MAX_COORDINATE. Else says which vertex went where and returns EXIT_USAGE (nothing written). */
static int check_coordinates(const noise_args *a, const rsmooth_mesh *mesh) {
    for (size_t v = 0; v < mesh->vertex_count; v++) {
        const double *p = mesh->positions + 3 * v;
        if (fabs(p[0]) <= MAX_COORDINATE && fabs(p[1]) <= MAX_COORDINATE &&
            fabs(p[2]) <= MAX_COORDINATE)
            continue;
        fprintf(stderr,
                "rsmooth noise: %s: not written: --sigma %g would move vertex %zu of %s "
                "to (%.17g, %.17g, %.17g), beyond the supported magnitude %g (lower --sigma)\n",
                a->output, a->noise.sigma, v, a->input, p[0], p[1], p[2], MAX_COORDINATE);
        return EXIT_USAGE;
    }
    return EXIT_OK;
}

/* What --depth-sensor did, with the camera it placed (so a drawn view can be given back). */
static void print_depth_summary(const noise_args *a, size_t nv, double edge,
                                const mesh_depth_noise_camera *camera) {
    const mesh_depth_noise_options *d = &a->depth_noise;
    fprintf(
        stderr,
        "rsmooth noise: %s: %zu vertices; depth sensor at (%.6g, %.6g, %.6g), view %.6g,%.6g,"
        "%.6g from the bounding-box centre; sigma %.6g mean edge lengths = %.6g mesh units at "
        "the mean depth, along the rays; quantum %.6g, ridges %.6g x sigma every %.6g mean edge "
        "lengths; grazing below cosine %.6g; seed %" PRIu64 "; wrote %s\n",
        a->input, nv, camera->position[0], camera->position[1], camera->position[2],
        camera->view[0], camera->view[1], camera->view[2], d->sigma, d->sigma * edge, d->quantum,
        d->ridge_amplitude, d->ridge_period, d->grazing, d->seed, a->output);
}

int cli_noise_main(int argc, char **argv) {
    noise_args a;
    int code = parse_noise_args(argc, argv, &a);
    if (code >= 0)
        return code;
    /* Before reading, so a typo in OUTPUT costs no time on a large INPUT. */
    if ((code = cli_check_output(a.output, a.input, a.force, false, false)) >= 0)
        return code;

    rsmooth_mesh *mesh = NULL;
    if ((code = cli_read_mesh(a.input, NULL, &mesh)) != EXIT_OK)
        return code;
    rsmooth_format format = cli_output_format(a.output, a.ascii);
    /* what the output's format cannot hold, before the work (a binary STL of a mesh at 1e100) */
    if ((code = cli_check_writable(mesh, a.output, format, a.input)) >= 0)
        goto cleanup;

    size_t nv = mesh->vertex_count;
    double edge =
        mesh_noise_mean_edge_length(mesh->positions, nv, mesh->triangles, mesh->triangle_count);
    code = EXIT_OTHER;
    if (isnan(edge)) {
        fprintf(stderr, "rsmooth noise: %s: out of memory\n", a.input);
        goto cleanup;
    }
    if (!(edge > 0) && (a.noise.sigma > 0 || (a.depth && a.depth_noise.quantum > 0))) {
        fprintf(stderr, "rsmooth noise: %s: no edge of non-zero length, so no unit for --sigma\n",
                a.input);
        code = EXIT_USAGE;
        goto cleanup;
    }
    mesh_depth_noise_camera camera;
    int failed = a.depth ? mesh_add_depth_noise(mesh->positions, nv, mesh->triangles,
                                                mesh->triangle_count, &a.depth_noise, &camera)
                         : mesh_add_noise(mesh->positions, nv, mesh->triangles,
                                          mesh->triangle_count, &a.noise);
    if (failed) { /* the options were checked: only memory is left to fail */
        fprintf(stderr, "rsmooth noise: %s: out of memory\n", a.input);
        goto cleanup;
    }

    if ((code = check_coordinates(&a, mesh)) != EXIT_OK)
        goto cleanup;
    if ((code = cli_check_writable(mesh, a.output, format, a.input)) >= 0)
        goto cleanup; /* the noise carried a value out of the format's range */

    char lost[512];
    if (!a.quiet && rsmooth_mesh_conversion_losses(mesh, format, lost, sizeof lost) > 0)
        fprintf(stderr, "rsmooth noise: %s: this format cannot hold, so drops: %s\n", a.output,
                lost);
    if ((code = cli_write_mesh(mesh, a.output, format, a.force, a.quiet)) != EXIT_OK)
        goto cleanup;

    if (!a.quiet && a.depth)
        print_depth_summary(&a, nv, edge, &camera);
    else if (!a.quiet) {
        size_t moved =
            a.noise.sigma > 0 ? mesh_noise_moved_count(nv, a.noise.impulsive_fraction) : 0;
        char impulsive[128] = "";
        if (a.impulsive)
            snprintf(impulsive, sizeof impulsive, " (impulsive %g)", a.noise.impulsive_fraction);
        if (a.noise.correlation > 0)
            snprintf(impulsive + strlen(impulsive), sizeof impulsive - strlen(impulsive),
                     "; band-limited, correlation length %g mean edge lengths",
                     a.noise.correlation);
        if (a.noise.stripes > 0)
            snprintf(impulsive + strlen(impulsive), sizeof impulsive - strlen(impulsive),
                     "; scan-line stripes %g mean edge lengths wide", a.noise.stripes);
        fprintf(stderr,
                "rsmooth noise: %s: %zu vertices; sigma %.6g mean edge lengths = %.6g mesh units "
                "%s; moved %zu of %zu vertices%s; seed %" PRIu64 "; wrote %s\n",
                a.input, nv, a.noise.sigma, a.noise.sigma * edge,
                a.noise.direction == MESH_NOISE_NORMAL ? "along normals" : "in random directions",
                moved, nv, impulsive, a.noise.seed, a.output);
    }

cleanup:
    rsmooth_mesh_destroy(mesh);
    return code;
}
