/* The rsmooth command's checks of what the command line asked for, and the output each input gets
 * (see cli_options.h). */
#define _POSIX_C_SOURCE 200809L
#include "cli_args.h"
#include "cli_files.h"
#include "cli_options.h"
#include "cli_stream.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

/* The sigmas and widths: checked here so a typo is a usage error before any file is read. */
static int check_params(options *opt) {
    const rsmooth_params *p = &opt->params;
    if (!(p->sigma_f > 0) || !isfinite(p->sigma_f))
        return cli_usage_error(NULL, "--sigma-f must be a positive number (got %g)", p->sigma_f);
    if (!(p->sigma_g > 0))
        return cli_usage_error(NULL, "--sigma-g must be positive, or 'inf' (got %g)", p->sigma_g);
    if (!(p->cutoff > 0 && p->cutoff <= 5))
        return cli_usage_error(NULL, "--cutoff must be in (0, 5] (got %g)", p->cutoff);
    if (!(p->normal_sigma_s > 0) || !isfinite(p->normal_sigma_s))
        return cli_usage_error(NULL, "--normal-sigma-s must be a positive number (got %g)",
                               p->normal_sigma_s);
    if (!(p->normal_sigma_n > 0 && p->normal_sigma_n <= 2))
        return cli_usage_error(NULL, "--normal-sigma-n must be in (0, 2] (got %g)",
                               p->normal_sigma_n);
    if (!(p->pass_confidence >= 0 && p->pass_confidence <= 1))
        return cli_usage_error(NULL, "--pass-confidence must be in [0, 1] (got %g)",
                               p->pass_confidence);
    if ((opt->given & GIVEN_PASSES) && p->passes == 0 && p->vertex_updates == 0)
        return cli_usage_error(NULL, "--passes 0 runs the normal update stage alone: give "
                                     "--vertex-updates (or --best) too");
    if (p->stage_normals == RSMOOTH_STAGE_NORMALS_LEARNED && p->vertex_updates == 0 && !opt->best)
        return cli_usage_error(NULL, "--stage learned runs in the normal update stage: give "
                                     "--best (or --vertex-updates) too");
    if (opt->model_path && p->stage_normals != RSMOOTH_STAGE_NORMALS_LEARNED)
        return cli_usage_error(NULL, "--model is the learned stage's: give --stage learned too");
    return -1;
}

/* --method against the options that belong to other methods. */
static int check_method(options *opt) {
    const char *name = cli_method_names[opt->method];
    bool umbrella = cli_method_uses_edges(opt->method);
    if (opt->umbrella_given && !umbrella)
        return cli_usage_error(NULL, "--lambda, --mu and --iterations need --method laplacian "
                                     "or taubin");
    if (umbrella && opt->confidence)
        return cli_usage_error(NULL, "--method %s has no confidence to write", name);
    if (umbrella && opt->colors)
        return cli_usage_error(NULL, "--method %s has no weights for --sigma-c", name);
    if (umbrella && opt->mask)
        return cli_usage_error(NULL, "--method %s moves every vertex: --mask is for the filter",
                               name);
    if (opt->auto_params && opt->method != METHOD_ROBUST)
        return cli_usage_error(NULL, "--auto picks the robust filter's sigmas: drop --method %s",
                               name);
    if (opt->method == METHOD_GAUSSIAN) {
        if (opt->sigma_g_given)
            return cli_usage_error(NULL, "--method gaussian has no influence weight: drop "
                                         "--sigma-g");
        opt->params.predictor = RSMOOTH_PREDICT_CENTROID;
        opt->params.sigma_g = INFINITY;
    }
    if (opt->method == METHOD_LAPLACIAN)
        opt->mu = 0;
    if (umbrella && !(opt->lambda > 0 && opt->lambda <= 1))
        return cli_usage_error(NULL, "--lambda must be in (0, 1] (got %g)", opt->lambda);
    if (opt->method == METHOD_TAUBIN && !(opt->mu >= -1 && opt->mu < 0))
        return cli_usage_error(NULL, "--mu must be in [-1, 0) (got %g)", opt->mu);
    return -1;
}

/* Inputs and where their results go: -o FILE, -o -, -o DIR/, --suffix or --in-place. */
static int check_files(options *opt) {
    const char *out = opt->output_option;
    size_t stdin_count = 0;
    for (size_t i = 0; i < opt->input_count; i++)
        stdin_count += !strcmp(opt->inputs[i], "-");
    if (opt->input_count == 0)
        return cli_usage_error(NULL, "no input file");
    if (stdin_count > 1)
        return cli_usage_error(NULL, "standard input ('-') can be read once only");
    if (opt->in_place && (out || opt->suffix))
        return cli_usage_error(NULL, "give -o OUTPUT, --suffix or --in-place, not two of them");
    if (opt->in_place && stdin_count)
        return cli_usage_error(NULL, "--in-place cannot replace standard input");
    /* -o DIR/ is always a folder; an existing folder named without the '/' only with several
     * inputs: for one input it stays the mistake the writer refuses ("is a directory"), rather
     * than a result left inside the folder by surprise */
    struct stat st;
    opt->output_dir = out && strcmp(out, "-") != 0 &&
                      (out[strlen(out) - 1] == '/' ||
                       (opt->input_count > 1 && stat(out, &st) == 0 && S_ISDIR(st.st_mode)));
    if (opt->output_dir && stat(out, &st) == 0 && !S_ISDIR(st.st_mode))
        return cli_usage_error(NULL, "-o %s: is not a folder", out); /* a missing one is made */
    bool named_after_input = opt->output_dir || opt->suffix;
    if (out && opt->suffix && !opt->output_dir)
        return cli_usage_error(NULL, "--suffix names each result after its input: with -o give "
                                     "a folder (-o DIR/), or leave -o out");
    if (!out && !opt->suffix && !opt->in_place)
        return cli_usage_error(NULL, "no output file (-o OUTPUT, -o DIR/, --suffix S, or "
                                     "--in-place)");
    if (stdin_count && named_after_input)
        return cli_usage_error(NULL, "standard input has no name to name its result after: "
                                     "give -o FILE or -o -");
    if (opt->input_count > 1 && out && !opt->output_dir)
        return cli_usage_error(NULL,
                               "%zu inputs: -o must be a folder (-o DIR/), or use --suffix "
                               "S or --in-place",
                               opt->input_count);
    if (opt->input_count > 1 && opt->confidence)
        return cli_usage_error(NULL, "--confidence names one file: give one input with it");
    bool to_stdout = out && !strcmp(out, "-");
    if (to_stdout && opt->json)
        return cli_usage_error(NULL, "--json prints on standard output, which -o - gives to the "
                                     "mesh");
    if (opt->confidence && !strcmp(opt->confidence, "-"))
        return cli_usage_error(NULL, "--confidence needs a file name");
    if (opt->format != RSMOOTH_FORMAT_AUTO && opt->in_place)
        return cli_usage_error(NULL, "--in-place keeps the input's name and so its format: drop "
                                     "--format");
    /* Two inputs of the same name would overwrite each other's result. */
    char a[4096], b[4096];
    for (size_t i = 0; named_after_input && i < opt->input_count; i++) {
        if (!cli_output_for(opt, opt->inputs[i], a, sizeof a))
            return cli_usage_error(NULL, "%s: its output name is too long", opt->inputs[i]);
        for (size_t j = 0; j < i; j++)
            if (cli_output_for(opt, opt->inputs[j], b, sizeof b) && !strcmp(a, b))
                return cli_usage_error(NULL, "%s and %s would both be written to %s",
                                       opt->inputs[j], opt->inputs[i], a);
    }
    return -1;
}

int cli_options_check(options *opt) {
    if (opt->list_devices)
        return -1;
    int code;
    if ((code = check_files(opt)) >= 0 || (code = check_params(opt)) >= 0 ||
        (code = check_method(opt)) >= 0)
        return code;
    return cli_stream_check(opt);
}
