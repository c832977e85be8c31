/* The rsmooth command's output names and formats: where each input's result goes and in what
 * format it is written (see cli_options.h). Called by the checks, the smoothing and streaming
 * flows; calls nothing of theirs. */
#include "cli_files.h"
#include "cli_options.h"

#include <stdio.h>
#include <string.h>

/* The file extension --format writes. */
static const char *format_extension(rsmooth_format f) {
    switch (f) {
    case RSMOOTH_FORMAT_OBJ:
        return ".obj";
    case RSMOOTH_FORMAT_PLY_ASCII:
    case RSMOOTH_FORMAT_PLY_BINARY:
        return ".ply";
    case RSMOOTH_FORMAT_OFF:
        return ".off";
    case RSMOOTH_FORMAT_STL_ASCII:
    case RSMOOTH_FORMAT_STL_BINARY:
        return ".stl";
    default:
        return "";
    }
}

bool cli_output_for(const options *opt, const char *input, char *out, size_t size) {
    const char *o = opt->output_option;
    if (opt->in_place || (o && !opt->output_dir))
        return snprintf(out, size, "%s", opt->in_place ? input : o) < (int)size;
    /* named after the input: its folder (or -o's), its name, the suffix, its extension (or
     * --format's) */
    const char *slash = strrchr(input, '/');
    const char *base = slash ? slash + 1 : input;
    const char *dot = strrchr(base, '.');
    size_t stem = dot && dot != base ? (size_t)(dot - base) : strlen(base);
    const char *extension = opt->format != RSMOOTH_FORMAT_AUTO ? format_extension(opt->format)
                            : dot && dot != base               ? dot
                                                               : "";
    int folder = opt->output_dir ? (int)strlen(o) : slash ? (int)(slash - input + 1) : 0;
    const char *sep = opt->output_dir && o[strlen(o) - 1] != '/' ? "/" : "";
    int n = snprintf(out, size, "%.*s%s%.*s%s%s", folder, opt->output_dir ? o : input, sep,
                     (int)stem, base, opt->suffix ? opt->suffix : "", extension);
    return n >= 0 && n < (int)size;
}

rsmooth_format cli_result_format(const options *opt, const char *output, rsmooth_format source) {
    rsmooth_format f = opt->format;
    if (f == RSMOOTH_FORMAT_AUTO && strcmp(output, "-") != 0)
        return cli_output_format(output, opt->ascii);
    if (f == RSMOOTH_FORMAT_AUTO) /* standard output: the input's format, as a file of its name */
        f = source == RSMOOTH_FORMAT_PLY_ASCII || source == RSMOOTH_FORMAT_PLY_BINARY_BE
                ? RSMOOTH_FORMAT_PLY_BINARY
            : source == RSMOOTH_FORMAT_STL_ASCII ? RSMOOTH_FORMAT_STL_BINARY
                                                 : source;
    if (opt->ascii && f == RSMOOTH_FORMAT_PLY_BINARY)
        return RSMOOTH_FORMAT_PLY_ASCII;
    if (opt->ascii && f == RSMOOTH_FORMAT_STL_BINARY)
        return RSMOOTH_FORMAT_STL_ASCII;
    return f;
}
