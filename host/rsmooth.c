/* rsmooth: the command. Reads a mesh, smooths it on an OpenCL device (or the reference path), and
 * writes the result atomically: a temporary file beside the output, renamed when complete. */
#define _POSIX_C_SOURCE 200809L
#include "rsmooth.h"
#include "rsmooth_io.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

/* Exit statuses. */
enum { EXIT_OK = 0, EXIT_OTHER = 1, EXIT_USAGE = 2, EXIT_DEVICE = 3 };

static const char usage_text[] =
    "usage: rsmooth INPUT -o OUTPUT [options]\n"
    "\n"
    "Removes noise from a triangle mesh while keeping its sharp edges and corners, with the\n"
    "non-iterative filter of Jones, Durand & Desbrun (SIGGRAPH 2003). Each vertex moves to a\n"
    "weighted average of its projections onto the planes of nearby triangles; triangles whose\n"
    "plane would pull the vertex far (across a sharp edge) get little weight. One pass, and no\n"
    "connectivity needed: triangle soups, cracked and non-manifold scans work.\n"
    "\n"
    "Files: OBJ and PLY (ascii or binary), chosen by extension. Vertex order and faces are kept.\n"
    "\n"
    "The two widths, in mean edge lengths of the input (a scan's point spacing):\n"
    "  --sigma-f X     spatial width: how far around a vertex triangles are consulted (they are\n"
    "                  ignored beyond 2 X). Larger removes coarser noise and costs more time.\n"
    "                  Default 2.\n"
    "  --sigma-g Y     influence width: how far a triangle's plane may be from the vertex before\n"
    "                  it counts as the other side of a feature. Larger smooths more and rounds\n"
    "                  edges; smaller keeps edges and leaves more noise. 'inf' turns it off\n"
    "                  (plain Gaussian-weighted smoothing). Default 0.5.\n"
    "  Rule of thumb (the paper's): raise both until the surface is smooth enough, then lower\n"
    "  --sigma-g until the sharp features come back.\n"
    "\n"
    "Options:\n"
    "  -o, --output FILE     result mesh (.obj or .ply); refuses to replace a file without --force\n"
    "  --absolute            read --sigma-f and --sigma-g in the mesh's own units\n"
    "  --cutoff C            ignore triangles farther than C * sigma-f (default 2, range (0, 5])\n"
    "  --no-mollify          predict with the raw (noisy) normals: the paper's ablation, worse\n"
    "  --device D            auto (default: first GPU, else CPU; falls back to the reference path\n"
    "                        with a warning when no OpenCL exists), gpu, cpu, reference (double\n"
    "                        precision on one CPU thread), P:D (platform and device index), or a\n"
    "                        part of the device name. Also read from RSMOOTH_DEVICE.\n"
    "  --confidence FILE     also write the mesh coloured by confidence k(p) / sum a f in [0, 1]\n"
    "                        (PLY: 'quality' property plus colours; OBJ: vertex colours). Low\n"
    "                        confidence (red) marks vertices few triangles agreed on.\n"
    "  --ascii               write PLY as ascii (default binary little-endian)\n"
    "  --json                print one JSON object of counts, sigmas, device and stage times (ms)\n"
    "  -f, --force           replace existing output files\n"
    "  -q, --quiet           print nothing but errors\n"
    "  --version             print the version\n"
    "  -h, --help            print this help\n"
    "\n"
    "Exit status: 0 success, 2 bad usage or bad input file, 3 OpenCL device failure, 1 other.\n";

typedef struct options {
    const char *input, *output, *confidence, *device;
    rsmooth_params params;
    bool ascii, json, force, quiet;
} options;

__attribute__((format(printf, 1, 2))) static int usage_error(const char *fmt, ...) {
    va_list args;
    va_start(args, fmt);
    fprintf(stderr, "rsmooth: ");
    vfprintf(stderr, fmt, args);
    fprintf(stderr, "\nTry 'rsmooth --help'.\n");
    va_end(args);
    return EXIT_USAGE;
}

static bool parse_number(const char *text, double *out) {
    char *end = NULL;
    errno = 0;
    double v = strtod(text, &end);
    if (end == text || *end != '\0' || errno == ERANGE)
        return false;
    *out = v;
    return true;
}

/* Returns -1 when parsing succeeded and the program should go on, else an exit status. */
static int parse_args(int argc, char **argv, options *opt) {
    memset(opt, 0, sizeof *opt);
    rsmooth_params_init(&opt->params);
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *value = i + 1 < argc ? argv[i + 1] : NULL;
        double x;
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            fputs(usage_text, stdout);
            return EXIT_OK;
        } else if (!strcmp(a, "--version")) {
            printf("rsmooth %d.%d.%d\n", RSMOOTH_VERSION_MAJOR, RSMOOTH_VERSION_MINOR,
                   RSMOOTH_VERSION_PATCH);
            return EXIT_OK;
        } else if (!strcmp(a, "-o") || !strcmp(a, "--output") || !strcmp(a, "--confidence") ||
                   !strcmp(a, "--device")) {
            if (!value)
                return usage_error("%s needs a value", a);
            if (a[2] == 'c')
                opt->confidence = value;
            else if (a[2] == 'd')
                opt->device = value;
            else
                opt->output = value;
            i++;
        } else if (!strcmp(a, "--sigma-f") || !strcmp(a, "--sigma-g") || !strcmp(a, "--cutoff")) {
            if (!value)
                return usage_error("%s needs a value", a);
            if (!parse_number(value, &x) || isnan(x))
                return usage_error("not a number: '%s'", value);
            if (!strcmp(a, "--sigma-f"))
                opt->params.sigma_f = x;
            else if (!strcmp(a, "--sigma-g"))
                opt->params.sigma_g = x;
            else
                opt->params.cutoff = x;
            i++;
        } else if (!strcmp(a, "--absolute")) {
            opt->params.absolute = 1;
        } else if (!strcmp(a, "--no-mollify")) {
            opt->params.mollify = 0;
        } else if (!strcmp(a, "--ascii")) {
            opt->ascii = true;
        } else if (!strcmp(a, "--json")) {
            opt->json = true;
        } else if (!strcmp(a, "-f") || !strcmp(a, "--force")) {
            opt->force = true;
        } else if (!strcmp(a, "-q") || !strcmp(a, "--quiet")) {
            opt->quiet = true;
        } else if (a[0] == '-' && a[1] != '\0') {
            return usage_error("unknown option '%s'", a);
        } else if (!opt->input) {
            opt->input = a;
        } else {
            return usage_error("unexpected argument '%s' (one input file only)", a);
        }
    }
    if (!opt->input)
        return usage_error("%s", "no input file");
    if (!opt->output)
        return usage_error("%s", "no output file (-o OUTPUT)");
    /* Check the sigmas here so a typo is a usage error before any file is read. */
    rsmooth_params *p = &opt->params;
    if (!(p->sigma_f > 0) || !isfinite(p->sigma_f))
        return usage_error("--sigma-f must be a positive number (got %g)", p->sigma_f);
    if (!(p->sigma_g > 0))
        return usage_error("--sigma-g must be positive, or 'inf' (got %g)", p->sigma_g);
    if (!(p->cutoff > 0 && p->cutoff <= 5))
        return usage_error("--cutoff must be in (0, 5] (got %g)", p->cutoff);
    return -1;
}

static bool same_file(const char *a, const char *b) {
    struct stat sa, sb;
    return stat(a, &sa) == 0 && stat(b, &sb) == 0 && sa.st_dev == sb.st_dev &&
           sa.st_ino == sb.st_ino;
}

/* Refuses to touch the input or, without --force, an existing file. */
static int check_output_path(const options *opt, const char *path) {
    if (same_file(path, opt->input)) {
        fprintf(stderr, "rsmooth: %s: refusing to overwrite the input file\n", path);
        return EXIT_USAGE;
    }
    struct stat st;
    if (!opt->force && stat(path, &st) == 0) {
        fprintf(stderr, "rsmooth: %s: already exists (use --force to replace it)\n", path);
        return EXIT_USAGE;
    }
    if (stat(path, &st) == 0 && S_ISDIR(st.st_mode)) {
        fprintf(stderr, "rsmooth: %s: is a directory\n", path);
        return EXIT_USAGE;
    }
    rsmooth_format f = rsmooth_format_from_path(path);
    if (f == RSMOOTH_FORMAT_AUTO) {
        fprintf(stderr, "rsmooth: %s: unknown output format (use .obj or .ply)\n", path);
        return EXIT_USAGE;
    }
    return -1;
}

/* Writes through a temporary file beside `path`, renamed into place only when complete. */
static int write_atomically(const rsmooth_mesh *mesh, const char *path, bool ascii) {
    rsmooth_format format = rsmooth_format_from_path(path);
    if (format == RSMOOTH_FORMAT_PLY_BINARY && ascii)
        format = RSMOOTH_FORMAT_PLY_ASCII;
    size_t n = strlen(path) + 16;
    char *tmp = malloc(n);
    if (!tmp)
        return EXIT_OTHER;
    snprintf(tmp, n, "%s.tmp-XXXXXX", path);
    int fd = mkstemp(tmp);
    if (fd < 0) {
        fprintf(stderr, "rsmooth: %s: cannot create a temporary file beside it: %s\n", path,
                strerror(errno));
        free(tmp);
        return EXIT_OTHER;
    }
    FILE *f = fdopen(fd, "wb");
    rsmooth_error err;
    rsmooth_status st = f ? rsmooth_mesh_write_stream(mesh, f, format, &err) : RSMOOTH_ERROR_IO;
    if (!f) {
        snprintf(err.message, sizeof err.message, "%s", strerror(errno));
        close(fd);
    }
    if (f && fclose(f) != 0 && st == RSMOOTH_OK) {
        st = RSMOOTH_ERROR_IO;
        snprintf(err.message, sizeof err.message, "%s", strerror(errno));
    }
    if (st == RSMOOTH_OK) {
        /* mkstemp creates 0600; give the result the usual permissions. */
        mode_t mask = umask(0);
        umask(mask);
        chmod(tmp, 0666 & ~mask);
        if (rename(tmp, path) != 0) {
            snprintf(err.message, sizeof err.message, "%s", strerror(errno));
            st = RSMOOTH_ERROR_IO;
        }
    }
    if (st != RSMOOTH_OK) {
        fprintf(stderr, "rsmooth: %s: cannot write: %s\n", path, err.message);
        remove(tmp);
    }
    free(tmp);
    return st == RSMOOTH_OK ? EXIT_OK : EXIT_OTHER;
}

/* Red (low confidence) through yellow to blue (high): readable on white and for most colour-blind
 * viewers. */
static void confidence_colour(float c, uint8_t rgb[3]) {
    static const float stops[3][3] = {{215, 48, 39}, {254, 224, 144}, {69, 117, 180}};
    float x = c < 0 ? 0 : c > 1 ? 1 : c;
    int i = x < 0.5f ? 0 : 1;
    float t = x < 0.5f ? x * 2 : (x - 0.5f) * 2;
    for (int k = 0; k < 3; k++)
        rgb[k] = (uint8_t)lrintf(stops[i][k] + t * (stops[i + 1][k] - stops[i][k]));
}

/* A JSON string literal of `text` (quotes, backslashes and control characters escaped). */
static void print_json_string(const char *text) {
    putchar('"');
    for (const unsigned char *c = (const unsigned char *)text; *c; c++) {
        if (*c == '"' || *c == '\\')
            printf("\\%c", *c);
        else if (*c < 0x20)
            printf("\\u%04x", *c);
        else
            putchar(*c);
    }
    putchar('"');
}

static void print_json(const rsmooth_report *r, const char *input, const char *output,
                       double ms_read, double ms_write, double ms_setup) {
    printf("{\"input\":");
    print_json_string(input);
    printf(",\"output\":");
    print_json_string(output);
    printf(",\"vertices\":%zu,\"triangles\":%zu,"
           "\"facets\":%zu,\"mean_edge_length\":%.9g,\"sigma_f\":%.9g,",
           r->vertex_count, r->triangle_count, r->facet_count,
           r->mean_edge_length, r->sigma_f);
    if (isinf(r->sigma_g))
        printf("\"sigma_g\":null,");
    else
        printf("\"sigma_g\":%.9g,", r->sigma_g);
    printf("\"radius\":%.9g,\"grid_cells\":%zu,\"device\":", r->radius, r->grid_cell_count);
    print_json_string(r->device);
    printf(",\"ms\":{\"read\":%.3f,"
           "\"setup\":%.3f,\"facets\":%.3f,\"grid\":%.3f,\"upload\":%.3f,\"mollify\":%.3f,"
           "\"normals\":%.3f,\"robust\":%.3f,\"download\":%.3f,\"filter\":%.3f,\"write\":%.3f}}\n",
           ms_read, ms_setup, r->ms_facets, r->ms_grid,
           r->ms_upload, r->ms_mollify, r->ms_normals, r->ms_robust, r->ms_download, r->ms_total,
           ms_write);
}

static double now_ms(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

int main(int argc, char **argv) {
    options opt;
    int code = parse_args(argc, argv, &opt);
    if (code >= 0)
        return code;
    if ((code = check_output_path(&opt, opt.output)) >= 0)
        return code;
    if (opt.confidence && (code = check_output_path(&opt, opt.confidence)) >= 0)
        return code;
    if (opt.confidence && strcmp(opt.confidence, opt.output) == 0) {
        fprintf(stderr, "rsmooth: %s: the confidence mesh needs its own file\n", opt.confidence);
        return EXIT_USAGE;
    }

    double t0 = now_ms();
    rsmooth_mesh *mesh = NULL;
    rsmooth_error err;
    rsmooth_status st = rsmooth_mesh_read_file(opt.input, &mesh, &err);
    if (st != RSMOOTH_OK) {
        if (err.line >= 0)
            fprintf(stderr, "rsmooth: %s:%lld: %s\n", opt.input, (long long)err.line, err.message);
        else if (err.byte_offset >= 0)
            fprintf(stderr, "rsmooth: %s: byte %lld: %s\n", opt.input, (long long)err.byte_offset,
                    err.message);
        else
            fprintf(stderr, "rsmooth: %s: %s\n", opt.input, err.message);
        return st == RSMOOTH_ERROR_OUT_OF_MEMORY ? EXIT_OTHER : EXIT_USAGE;
    }
    double ms_read = now_ms() - t0;

    size_t nv = mesh->vertex_count;
    double *out = malloc(nv * 3 * sizeof *out);
    float *confidence = opt.confidence ? malloc(nv * sizeof *confidence) : NULL;
    rsmooth_context *ctx = NULL;
    rsmooth_report report;
    code = EXIT_OTHER;
    if (!out || (opt.confidence && !confidence)) {
        fprintf(stderr, "rsmooth: %s: out of memory\n", opt.input);
        goto cleanup;
    }

    const char *device = opt.device ? opt.device : getenv("RSMOOTH_DEVICE");
    bool reference = device && strcmp(device, "reference") == 0;
    double ms_setup = 0;
    if (!reference) {
        double t1 = now_ms();
        st = rsmooth_context_create(device, &ctx, &err);
        ms_setup = now_ms() - t1;
        bool automatic = !device || strcmp(device, "auto") == 0;
        if (st == RSMOOTH_ERROR_NO_DEVICE && automatic) {
            if (!opt.quiet)
                fprintf(stderr, "rsmooth: warning: %s; using the reference path (slower)\n",
                        err.message);
            reference = true;
        } else if (st != RSMOOTH_OK) {
            fprintf(stderr, "rsmooth: device %s: %s: %s\n", device ? device : "auto",
                    rsmooth_status_str(st), err.message);
            if (err.build_log[0])
                fprintf(stderr, "%s\n", err.build_log);
            code = st == RSMOOTH_ERROR_OUT_OF_MEMORY ? EXIT_OTHER : EXIT_DEVICE;
            goto cleanup;
        }
    }
    if (reference)
        st = rsmooth_smooth_reference(RSMOOTH_FLOAT64, mesh->positions, nv, mesh->triangles,
                                      mesh->triangle_count, &opt.params, out, NULL, confidence,
                                      &report, &err);
    else
        st = rsmooth_smooth(ctx, RSMOOTH_FLOAT64, mesh->positions, nv, mesh->triangles,
                            mesh->triangle_count, &opt.params, out, NULL, confidence, &report,
                            &err);
    if (st != RSMOOTH_OK) {
        if (st == RSMOOTH_ERROR_OPENCL)
            fprintf(stderr, "rsmooth: %s: device %s: %s\n", opt.input,
                    rsmooth_context_device_name(ctx), err.message);
        else
            fprintf(stderr, "rsmooth: %s: %s\n", opt.input, err.message);
        code = st == RSMOOTH_ERROR_OPENCL        ? EXIT_DEVICE
               : st == RSMOOTH_ERROR_INVALID_ARGUMENT ? EXIT_USAGE
                                                      : EXIT_OTHER;
        goto cleanup;
    }
    report.ms_setup = ms_setup;

    double t2 = now_ms();
    double *input_positions = mesh->positions;
    mesh->positions = out;
    code = write_atomically(mesh, opt.output, opt.ascii);
    if (code == EXIT_OK && opt.confidence) {
        uint8_t *colours = malloc(nv * 3);
        if (!colours) {
            code = EXIT_OTHER;
        } else {
            for (size_t v = 0; v < nv; v++)
                confidence_colour(confidence[v], colours + 3 * v);
            mesh->vertex_quality = confidence;
            mesh->vertex_colors = colours;
            code = write_atomically(mesh, opt.confidence, opt.ascii);
            mesh->vertex_quality = NULL;
            mesh->vertex_colors = NULL;
            free(colours);
        }
    }
    mesh->positions = input_positions;
    double ms_write = now_ms() - t2;
    if (code != EXIT_OK)
        goto cleanup;

    if (opt.json)
        print_json(&report, opt.input, opt.output, ms_read, ms_write, ms_setup);
    if (!opt.quiet)
        fprintf(stderr,
                "rsmooth: %s: %zu vertices, %zu triangles, mean edge %.6g; sigma_f %.6g, "
                "sigma_g %.6g (mesh units) on %s: filter %.1f ms; wrote %s%s%s\n",
                opt.input, report.vertex_count, report.triangle_count, report.mean_edge_length,
                report.sigma_f, report.sigma_g, report.device, report.ms_total, opt.output,
                opt.confidence ? " and " : "", opt.confidence ? opt.confidence : "");
    code = EXIT_OK;

cleanup:
    rsmooth_context_destroy(ctx);
    rsmooth_mesh_destroy(mesh);
    free(out);
    free(confidence);
    return code;
}
