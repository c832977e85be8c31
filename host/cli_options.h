/* The rsmooth command's options: what the command line asked for (cli_options.c reads it through
 * the option table, cli_options_check.c refuses what cannot work together), each input's output
 * name and format (cli_output_name.c), the method names (cli_method.c) and the help text
 * (cli_help.c). Calls flow one way: options -> checks -> stream check -> names. */
#ifndef RSMOOTH_CLI_OPTIONS_H
#define RSMOOTH_CLI_OPTIONS_H

#include "rsmooth.h"
#include "rsmooth_io.h"

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* rsmooth --help. */
extern const char cli_usage_text[];

/* --method: the filter, or a baseline to compare it with. */
typedef enum method { METHOD_ROBUST, METHOD_GAUSSIAN, METHOD_LAPLACIAN, METHOD_TAUBIN } method;
extern const char *const cli_method_names[4];
/* --normals and --influence values, in enum order. */
extern const char *const cli_normal_filter_names[2];
extern const char *const cli_influence_names[4];

/* Laplacian and Taubin iterate on the mesh's edges (rsmooth_smooth_taubin): no sigmas, no
 * confidence. */
bool cli_method_uses_edges(method m);

/* Parameters the command line set explicitly: --auto leaves them as given. */
enum {
    GIVEN_SIGMA_F = 1u << 0,
    GIVEN_SIGMA_G = 1u << 1,
    GIVEN_NORMAL_SIGMA_S = 1u << 2,
    GIVEN_NORMAL_SIGMA_N = 1u << 3,
    GIVEN_NORMAL_ITERATIONS = 1u << 4,
    GIVEN_PASSES = 1u << 5,
    GIVEN_INFLUENCE = 1u << 6,
    GIVEN_VERTEX_UPDATES = 1u << 7,
    GIVEN_GUIDED_SIGMA_S = 1u << 8,
    GIVEN_GUIDED_SIGMA_N = 1u << 9,
    GIVEN_GUIDED_ROUNDS = 1u << 10,
    GIVEN_STAGE_REPEATS = 1u << 11,
    GIVEN_GUIDED_RADIUS = 1u << 12
};

typedef struct options {
    const char **inputs; /* the operands (argv's strings), input_count of them; "-": stdin */
    size_t input_count;
    const char *input, *output; /* the file being worked on and its output ("-": stdout) */
    const char *output_option;  /* -o as given */
    const char *confidence, *device;
    const char *mask;      /* --mask: a file of the vertex indices that may move */
    const char *suffix;    /* --suffix: each result beside its input, the name + suffix */
    bool output_dir;       /* -o names a folder (ends in '/' or is one): results go in there */
    rsmooth_format format; /* --format: AUTO when not given (then the extension, or for -o -
                            * the input's format) */
    rsmooth_params params;
    method method;
    double lambda, mu;
    unsigned iterations;
    uint64_t memory_budget; /* 0: the library's default */
    uint64_t max_memory;    /* --max-memory: stream the file under this cap (0: in memory) */
    const char *tmpdir;     /* --tmpdir: the streaming path's temporary files */
    const char *model_path; /* --model: the learned model's file (read whole into model) */
    void *model;
    bool colors;                        /* --sigma-c: the input's vertex colours in the weight */
    bool sigma_g_given, umbrella_given; /* for consistency checks against --method */
    bool ascii, json, force, quiet, in_place, stats, list_devices, best;
    bool progress;           /* --progress: the bar even where stderr is no terminal */
    bool auto_params;        /* --auto */
    unsigned given;          /* GIVEN_* bits: parameters set on the command line */
    double noise;            /* --auto's estimate */
    double noise_correlated; /* --auto's rms including the correlated part (= noise when none) */
    double noise_correlation_length; /* its correlation length, edges (0: uncorrelated) */
    double noise_shape_correlation;  /* how alike neighbours bend (clean: 0.3 or more) */
    char noise_preset[32];           /* what --auto chose ("clean": nothing to remove) */
} options;

/* Reads the command line into `opt` and checks it (cli_options_check). Returns -1 when the
 * program should go on, else the exit status (0 after --help or --version; 2 after a usage
 * error, printed). On -1, cli_options_free releases what it holds. */
int cli_options_parse(int argc, char **argv, options *opt);
void cli_options_free(options *opt);

/* The checks of ranges and combinations, made before any file is read so that a typo is a usage
 * error at once; also decides opt->output_dir. -1 or the usage exit status (printed). */
int cli_options_check(options *opt);

/* The output path for `input` (`size` bytes at `out`): -o's, the input itself (--in-place), or
 * named after the input (in -o's folder, with --suffix, with --format's extension). Returns
 * false when it does not fit. */
bool cli_output_for(const options *opt, const char *input, char *out, size_t size);

/* The format a result is written in: --format (ascii with --ascii), else by the output's
 * extension; for standard output the input's format (`source`), written as a file named with
 * its extension would be (PLY and STL binary unless --ascii). */
rsmooth_format cli_result_format(const options *opt, const char *output, rsmooth_format source);

#endif
