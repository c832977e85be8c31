/* rsmooth: the command. Reads a mesh, smooths it on an OpenCL device (or the reference path), and
 * writes the result atomically: a temporary file beside the output, renamed when complete. This
 * file is the front door: the subcommands, the options (cli_options.c, cli_options_check.c), and
 * each input in turn through cli_smooth_file (cli_smooth_file.c: one file's steps). */
#define _POSIX_C_SOURCE 200809L
#include "cli_args.h"
#include "cli_commands.h"
#include "cli_files.h"
#include "cli_options.h"
#include "cli_report.h"
#include "cli_smooth.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* Several inputs: each smoothed in turn, going on past one that fails; a summary at the end. */
static int smooth_files(options *opt) {
    size_t failed = 0;
    char *failures = NULL; /* "a.ply, b.obj" */
    for (size_t i = 0; i < opt->input_count; i++) {
        char output[4096];
        options job = *opt;
        job.input = opt->inputs[i];
        job.output = output;
        cli_output_for(opt, job.input, output, sizeof output); /* checked to fit */
        if (cli_smooth_file(&job, job.input) == EXIT_OK)
            continue;
        failed++;
        size_t length = strlen(job.input), used = failures ? strlen(failures) : 0;
        char *grown = realloc(failures, used + length + 3);
        if (grown) {
            failures = grown;
            snprintf(failures + used, length + 3, "%s%s", used ? ", " : "", job.input);
        }
    }
    size_t n = opt->input_count;
    if (failed)
        fprintf(stderr, "rsmooth: %zu files: %zu smoothed, %zu failed (%s)\n", n, n - failed,
                failed, failures ? failures : "out of memory for their names");
    else if (!opt->quiet)
        fprintf(stderr, "rsmooth: %zu files: %zu smoothed\n", n, n);
    free(failures);
    return failed ? EXIT_USAGE : EXIT_OK;
}

/* A first word that is no file but nearly a subcommand ("compre"): the subcommand was meant, and
 * saying so beats "no output file". -1, or the usage exit status (printed). */
static int check_subcommand_typo(int argc, char **argv) {
    static const char *const commands[] = {"compare", "noise", "render"};
    struct stat st;
    if (argc < 2 || argv[1][0] == '-' || stat(argv[1], &st) == 0)
        return -1;
    size_t length = strlen(argv[1]);
    for (size_t k = 0; k < sizeof commands / sizeof *commands; k++)
        if (cli_close_enough(cli_edit_distance(argv[1], length, commands[k]), length))
            return cli_usage_error(NULL, "%s: no such file or command: did you mean \"%s\"?",
                                   argv[1], commands[k]);
    return -1;
}

int main(int argc, char **argv) {
    if (argc >= 2 && !strcmp(argv[1], "compare"))
        return cli_compare_main(argc - 1, argv + 1);
    if (argc >= 2 && !strcmp(argv[1], "noise"))
        return cli_noise_main(argc - 1, argv + 1);
    if (argc >= 2 && !strcmp(argv[1], "render"))
        return cli_render_main(argc - 1, argv + 1);
    int code;
    if ((code = check_subcommand_typo(argc, argv)) >= 0)
        return code;
    options opt;
    code = cli_options_parse(argc, argv, &opt);
    if (code >= 0)
        return code;
    if ((code = cli_check_environment()) >= 0) {
        cli_options_free(&opt);
        return code;
    }
    if (opt.list_devices) {
        cli_options_free(&opt);
        return cli_list_devices();
    }
    if (opt.input_count == 1) {
        char output[4096];
        const char *path = opt.inputs[0];
        opt.input = strcmp(path, "-") ? path : "<stdin>";
        opt.output = output;
        cli_output_for(&opt, path, output, sizeof output); /* checked to fit */
        code = cli_smooth_file(&opt, path);
    } else {
        code = smooth_files(&opt);
    }
    cli_options_free(&opt);
    return code;
}
