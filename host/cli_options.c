/* The rsmooth command's option table and what each option sets (see cli_options.h). */
#include "cli_options.h"
#include "cli_args.h"
#include "cli_files.h"
#include "cli_getopt.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum {
    OPT_HELP = 1,
    OPT_VERSION,
    OPT_OUTPUT,
    OPT_IN_PLACE,
    OPT_SUFFIX,
    OPT_FORMAT,
    OPT_CONFIDENCE,
    OPT_DEVICE,
    OPT_MEMORY_BUDGET,
    OPT_METHOD,
    OPT_LAMBDA,
    OPT_MU,
    OPT_ITERATIONS,
    OPT_SIGMA_F,
    OPT_SIGMA_G,
    OPT_CUTOFF,
    OPT_NORMALS,
    OPT_INFLUENCE,
    OPT_NORMAL_SIGMA_S,
    OPT_NORMAL_SIGMA_N,
    OPT_PASS_CONFIDENCE,
    OPT_SIGMA_C,
    OPT_NORMAL_ITERATIONS,
    OPT_PASSES,
    OPT_AUTO,
    OPT_BEST,
    OPT_ABSOLUTE,
    OPT_NO_MOLLIFY,
    OPT_ASCII,
    OPT_JSON,
    OPT_STATS,
    OPT_LIST_DEVICES,
    OPT_FORCE,
    OPT_QUIET,
    OPT_MASK,
    OPT_VERTEX_UPDATES,
    OPT_GUIDED_SIGMA_S,
    OPT_GUIDED_SIGMA_N,
    OPT_GUIDED_ROUNDS,
    OPT_STAGE_REPEATS,
    OPT_MAX_MEMORY,
    OPT_TMPDIR,
    OPT_PROGRESS,
    OPT_GUIDED_RADIUS,
    OPT_STAGE,
    OPT_MODEL,
    OPT_NO_GUARD
};

static const cli_option table[] = {{"help", 'h', false, OPT_HELP},
                                   {"version", 0, false, OPT_VERSION},
                                   {"output", 'o', true, OPT_OUTPUT},
                                   {"in-place", 0, false, OPT_IN_PLACE},
                                   {"suffix", 0, true, OPT_SUFFIX},
                                   {"format", 0, true, OPT_FORMAT},
                                   {"confidence", 0, true, OPT_CONFIDENCE},
                                   {"device", 0, true, OPT_DEVICE},
                                   {"memory-budget", 0, true, OPT_MEMORY_BUDGET},
                                   {"max-memory", 0, true, OPT_MAX_MEMORY},
                                   {"tmpdir", 0, true, OPT_TMPDIR},
                                   {"method", 0, true, OPT_METHOD},
                                   {"lambda", 0, true, OPT_LAMBDA},
                                   {"mu", 0, true, OPT_MU},
                                   {"iterations", 0, true, OPT_ITERATIONS},
                                   {"sigma-f", 0, true, OPT_SIGMA_F},
                                   {"sigma-g", 0, true, OPT_SIGMA_G},
                                   {"cutoff", 0, true, OPT_CUTOFF},
                                   {"normals", 0, true, OPT_NORMALS},
                                   {"influence", 0, true, OPT_INFLUENCE},
                                   {"normal-sigma-s", 0, true, OPT_NORMAL_SIGMA_S},
                                   {"normal-sigma-n", 0, true, OPT_NORMAL_SIGMA_N},
                                   {"pass-confidence", 0, true, OPT_PASS_CONFIDENCE},
                                   {"sigma-c", 0, true, OPT_SIGMA_C},
                                   {"mask", 0, true, OPT_MASK},
                                   {"normal-iterations", 0, true, OPT_NORMAL_ITERATIONS},
                                   {"passes", 0, true, OPT_PASSES},
                                   {"vertex-updates", 0, true, OPT_VERTEX_UPDATES},
                                   {"guided-sigma-s", 0, true, OPT_GUIDED_SIGMA_S},
                                   {"guided-sigma-n", 0, true, OPT_GUIDED_SIGMA_N},
                                   {"guided-rounds", 0, true, OPT_GUIDED_ROUNDS},
                                   {"stage-repeats", 0, true, OPT_STAGE_REPEATS},
                                   {"guided-radius", 0, true, OPT_GUIDED_RADIUS},
                                   {"stage", 0, true, OPT_STAGE},
                                   {"model", 0, true, OPT_MODEL},
                                   {"auto", 0, false, OPT_AUTO},
                                   {"best", 0, false, OPT_BEST},
                                   {"absolute", 0, false, OPT_ABSOLUTE},
                                   {"no-mollify", 0, false, OPT_NO_MOLLIFY},
                                   {"no-guard", 0, false, OPT_NO_GUARD},
                                   {"ascii", 0, false, OPT_ASCII},
                                   {"json", 0, false, OPT_JSON},
                                   {"stats", 0, false, OPT_STATS},
                                   {"list-devices", 0, false, OPT_LIST_DEVICES},
                                   {"force", 'f', false, OPT_FORCE},
                                   {"quiet", 'q', false, OPT_QUIET},
                                   {"progress", 0, false, OPT_PROGRESS},
                                   {NULL, 0, false, 0}};

/* Index of `value` among `count` names, or -1. */
static int find_name(const char *value, const char *const *names, int count) {
    for (int k = 0; k < count; k++)
        if (!strcmp(value, names[k]))
            return k;
    return -1;
}

/* What apply_choice and apply_number return for an option that is not theirs. */
#define NOT_HANDLED (-3)

/* The options that name one of a few choices: --format, --method, --normals, --influence. */
static int apply_choice(options *opt, int id, const char *value) {
    switch (id) {
    case OPT_STAGE: {
        static const char *const names[] = {"guided", "learned"};
        int k = find_name(value, names, 2);
        if (k < 0)
            return cli_usage_error(NULL, "--stage: '%s' is not guided or learned", value);
        opt->params.stage_normals =
            k ? RSMOOTH_STAGE_NORMALS_LEARNED : RSMOOTH_STAGE_NORMALS_GUIDED;
        break;
    }
    case OPT_FORMAT: {
        static const char *const names[] = {"obj", "ply", "off", "stl"};
        static const rsmooth_format formats[] = {RSMOOTH_FORMAT_OBJ, RSMOOTH_FORMAT_PLY_BINARY,
                                                 RSMOOTH_FORMAT_OFF, RSMOOTH_FORMAT_STL_BINARY};
        int k = find_name(value, names, 4);
        if (k < 0)
            return cli_usage_error(NULL, "--format: '%s' is not ply, obj, off or stl", value);
        opt->format = formats[k];
        break;
    }
    case OPT_METHOD: {
        int m = find_name(value, cli_method_names, 4);
        if (m < 0)
            return cli_usage_error(
                NULL, "--method: '%s' is not robust, gaussian, laplacian or taubin", value);
        opt->method = (method)m;
        break;
    }
    case OPT_NORMALS: {
        int k = find_name(value, cli_normal_filter_names, 2);
        if (k < 0)
            return cli_usage_error(NULL, "--normals: '%s' is not mollify or bilateral", value);
        opt->params.normal_filter = k;
        break;
    }
    case OPT_INFLUENCE: {
        int k = find_name(value, cli_influence_names, 4);
        if (k < 0)
            return cli_usage_error(NULL,
                                   "--influence: '%s' is not gaussian, tukey, lorentzian "
                                   "or huber",
                                   value);
        opt->params.influence = k;
        opt->given |= GIVEN_INFLUENCE;
        break;
    }
    default:
        return NOT_HANDLED;
    }
    return -1;
}

/* The options that take a number, each checked against its range. */
static int apply_number(options *opt, int id, const char *name, const char *value) {
    double x = 0;
    bool number = value && cli_parse_number(value, &x);
    switch (id) {
    case OPT_LAMBDA:
    case OPT_MU:
    case OPT_ITERATIONS:
    case OPT_SIGMA_F:
    case OPT_SIGMA_G:
    case OPT_CUTOFF:
    case OPT_NORMAL_SIGMA_S:
    case OPT_NORMAL_SIGMA_N:
    case OPT_PASS_CONFIDENCE:
        if (!number)
            return cli_usage_error(NULL, "%s: not a number: '%s'", name, value);
        if (id == OPT_LAMBDA)
            opt->lambda = x, opt->umbrella_given = true;
        else if (id == OPT_MU)
            opt->mu = x, opt->umbrella_given = true;
        else if (id == OPT_ITERATIONS) {
            if (!(x >= 0 && x <= 1e6 && x == floor(x)))
                return cli_usage_error(NULL,
                                       "--iterations must be a whole number in [0, 1e6] "
                                       "(got '%s')",
                                       value);
            opt->iterations = (unsigned)x;
            opt->umbrella_given = true;
        } else if (id == OPT_SIGMA_F)
            opt->params.sigma_f = x, opt->given |= GIVEN_SIGMA_F;
        else if (id == OPT_SIGMA_G)
            opt->params.sigma_g = x, opt->sigma_g_given = true, opt->given |= GIVEN_SIGMA_G;
        else if (id == OPT_CUTOFF)
            opt->params.cutoff = x;
        else if (id == OPT_NORMAL_SIGMA_S)
            opt->params.normal_sigma_s = x, opt->given |= GIVEN_NORMAL_SIGMA_S;
        else if (id == OPT_NORMAL_SIGMA_N)
            opt->params.normal_sigma_n = x, opt->given |= GIVEN_NORMAL_SIGMA_N;
        else
            opt->params.pass_confidence = x;
        break;
    case OPT_SIGMA_C:
        if (!number || !(x > 0))
            return cli_usage_error(NULL, "--sigma-c must be a positive number (got '%s')", value);
        opt->params.sigma_c = x;
        opt->colors = true;
        break;
    case OPT_NORMAL_ITERATIONS:
    case OPT_PASSES: /* passes 0: --vertex-updates alone */
        if (!number || !(x >= (id == OPT_PASSES ? 0 : 1) && x <= 100 && x == floor(x)))
            return cli_usage_error(NULL, "%s must be a whole number in [%d, 100] (got '%s')", name,
                                   id == OPT_PASSES ? 0 : 1, value);
        if (id == OPT_PASSES)
            opt->params.passes = (int)x, opt->given |= GIVEN_PASSES;
        else
            opt->params.normal_iterations = (int)x, opt->given |= GIVEN_NORMAL_ITERATIONS;
        break;
    case OPT_STAGE_REPEATS:
        if (!number || !(x >= 1 && x <= 1000 && x == floor(x)))
            return cli_usage_error(NULL, "%s must be a whole number in [1, 1000] (got '%s')", name,
                                   value);
        opt->params.stage_repeats = (int)x, opt->given |= GIVEN_STAGE_REPEATS;
        break;
    case OPT_GUIDED_RADIUS:
        if (!number || !(x >= 1 && x <= 8))
            return cli_usage_error(NULL, "%s must be a number in [1, 8] (got '%s')", name, value);
        opt->params.guided_radius = x, opt->given |= GIVEN_GUIDED_RADIUS;
        break;
    case OPT_VERTEX_UPDATES:
    case OPT_GUIDED_ROUNDS:
        if (!number || !(x >= (id == OPT_VERTEX_UPDATES ? 0 : 1) &&
                         x <= (id == OPT_VERTEX_UPDATES ? 1000 : 100) && x == floor(x)))
            return cli_usage_error(NULL, "%s must be a whole number in [%d, %d] (got '%s')", name,
                                   id == OPT_VERTEX_UPDATES ? 0 : 1,
                                   id == OPT_VERTEX_UPDATES ? 1000 : 100, value);
        if (id == OPT_VERTEX_UPDATES)
            opt->params.vertex_updates = (int)x, opt->given |= GIVEN_VERTEX_UPDATES;
        else
            opt->params.guided_rounds = (int)x, opt->given |= GIVEN_GUIDED_ROUNDS;
        break;
    case OPT_GUIDED_SIGMA_S:
    case OPT_GUIDED_SIGMA_N:
        if (!number || !(x > 0 && isfinite(x)) || (id == OPT_GUIDED_SIGMA_N && !(x <= 2)))
            return cli_usage_error(NULL, "%s must be a positive number%s (got '%s')", name,
                                   id == OPT_GUIDED_SIGMA_N ? " in (0, 2]" : "", value);
        if (id == OPT_GUIDED_SIGMA_S)
            opt->params.guided_sigma_s = x, opt->given |= GIVEN_GUIDED_SIGMA_S;
        else
            opt->params.guided_sigma_n = x, opt->given |= GIVEN_GUIDED_SIGMA_N;
        break;
    default:
        return NOT_HANDLED;
    }
    return -1;
}

/* --model FILE: the whole file in memory (the library checks that it is a model, and says what
 * is wrong with it). -1, or the usage exit status (printed). */
static int load_model(options *opt, const char *path) {
    FILE *f = fopen(path, "rb");
    long size = -1;
    if (f && fseek(f, 0, SEEK_END) == 0)
        size = ftell(f);
    if (!f || size < 0 || fseek(f, 0, SEEK_SET) != 0) {
        int e = errno;
        if (f)
            fclose(f);
        return cli_usage_error(NULL, "--model: cannot read %s: %s", path, strerror(e));
    }
    free(opt->model);
    opt->model = malloc(size ? (size_t)size : 1);
    size_t got = opt->model ? fread(opt->model, 1, (size_t)size, f) : 0;
    fclose(f);
    if (got != (size_t)size)
        return cli_usage_error(NULL, "--model: cannot read %s whole", path);
    rsmooth_error err;
    if (rsmooth_model_check(opt->model, (size_t)size, NULL, &err) != RSMOOTH_OK) {
        const char *why = err.message;
        if (!strncmp(why, "the model: ", 11))
            why += 11;
        return cli_usage_error(NULL, "--model %s: %s", path, why);
    }
    opt->model_path = path;
    opt->params.model = opt->model;
    opt->params.model_size = (size_t)size;
    return -1;
}

/* Sets what option `id` (spelled `name`, e.g. "--sigma-f") with `value` asks for. -1, or the exit
 * status (--help, --version, or a bad value). */
static int apply(options *opt, int id, const char *name, const char *value) {
    int code = apply_choice(opt, id, value);
    if (code != NOT_HANDLED)
        return code;
    if ((code = apply_number(opt, id, name, value)) != NOT_HANDLED)
        return code;
    switch (id) {
    case OPT_HELP:
        fputs(cli_usage_text, stdout);
        return EXIT_OK;
    case OPT_VERSION:
        printf("rsmooth %d.%d.%d\n", RSMOOTH_VERSION_MAJOR, RSMOOTH_VERSION_MINOR,
               RSMOOTH_VERSION_PATCH);
        return EXIT_OK;
    case OPT_OUTPUT:
        opt->output_option = value;
        break;
    case OPT_CONFIDENCE:
        opt->confidence = value;
        break;
    case OPT_MASK:
        opt->mask = value;
        break;
    case OPT_DEVICE:
        opt->device = value;
        break;
    case OPT_SUFFIX:
        if (!*value || strchr(value, '/'))
            return cli_usage_error(NULL, "--suffix: '%s' is not a file name's end (e.g. _smooth)",
                                   value);
        opt->suffix = value;
        break;
    case OPT_MEMORY_BUDGET:
        if (!cli_parse_bytes(value, &opt->memory_budget) || opt->memory_budget == 0)
            return cli_usage_error(NULL,
                                   "--memory-budget: '%s' is not a byte count above 0 "
                                   "(examples: 256M, 1.5G; leave it out for most of "
                                   "the device's memory)",
                                   value);
        break;
    case OPT_MAX_MEMORY:
        if (!cli_parse_bytes(value, &opt->max_memory) || opt->max_memory == 0)
            return cli_usage_error(NULL,
                                   "--max-memory: '%s' is not a byte count above 0 "
                                   "(examples: 512M, 2G)",
                                   value);
        break;
    case OPT_MODEL:
        return load_model(opt, value);
    case OPT_TMPDIR:
        if (!*value)
            return cli_usage_error(NULL, "--tmpdir: an empty folder name");
        opt->tmpdir = value;
        break;
    case OPT_AUTO:
        opt->auto_params = true;
        break;
    case OPT_BEST:
        break; /* applied before the others, so the options after it can change it */
    case OPT_ABSOLUTE:
        opt->params.absolute = 1;
        break;
    case OPT_NO_MOLLIFY:
        opt->params.mollify = 0;
        break;
    case OPT_NO_GUARD:
        opt->params.guard = 0;
        break;
    case OPT_ASCII:
        opt->ascii = true;
        break;
    case OPT_JSON:
        opt->json = true;
        break;
    case OPT_STATS:
        opt->stats = true;
        break;
    case OPT_IN_PLACE:
        opt->in_place = true;
        break;
    case OPT_LIST_DEVICES:
        opt->list_devices = true;
        break;
    case OPT_FORCE:
        opt->force = true;
        break;
    case OPT_QUIET:
        opt->quiet = true;
        break;
    case OPT_PROGRESS:
        opt->progress = true;
        break;
    default:
        break;
    }
    return -1;
}

void cli_options_free(options *opt) {
    free(opt->inputs);
    opt->inputs = NULL;
    free(opt->model);
    opt->model = NULL;
}

int cli_options_parse(int argc, char **argv, options *opt) {
    memset(opt, 0, sizeof *opt);
    rsmooth_params_init(&opt->params);
    opt->lambda = 0.5;
    opt->mu = -0.53;
    opt->iterations = 10;
    /* Read whole first (every option with its value, in order), then applied: --best sets the
     * defaults the options given with it change, wherever it stands. */
    size_t n = 1; /* a bound on the options: grouped flags ("-fq") are several in one argument */
    for (int i = 0; i < argc; i++)
        n += strlen(argv[i]);
    struct given_option {
        const cli_option *option;
        const char *value;
    } *given = malloc(n * sizeof *given);
    opt->inputs = malloc(n * sizeof *opt->inputs);
    if (!given || !opt->inputs) {
        free(given);
        cli_options_free(opt);
        fprintf(stderr, "rsmooth: out of memory\n");
        return EXIT_OTHER;
    }
    size_t count = 0;
    cli_getopt_state s;
    cli_getopt_init(&s, argc, argv, NULL, table);
    int id, code = -1;
    const char *value;
    while ((id = cli_getopt(&s, &value)) != CLI_GETOPT_END && code < 0) {
        if (id == CLI_GETOPT_ERROR) {
            code = EXIT_USAGE;
        } else if (id == CLI_GETOPT_OPERAND) {
            opt->inputs[opt->input_count++] = value;
        } else {
            const cli_option *o = table;
            while (o->id != id)
                o++;
            given[count].option = o;
            given[count++].value = value;
            if (id == OPT_BEST && !opt->best) {
                rsmooth_params_init_best(&opt->params);
                opt->best = true;
            }
        }
    }
    for (size_t i = 0; i < count && code < 0; i++) {
        char name[64];
        snprintf(name, sizeof name, "--%s", given[i].option->name);
        code = apply(opt, given[i].option->id, name, given[i].value);
    }
    free(given);
    if (code < 0)
        code = cli_options_check(opt);
    if (code >= 0)
        cli_options_free(opt);
    return code;
}
