/* The names of the rsmooth command's methods and filter choices, and what a method needs (see
 * cli_options.h): the bottom of the command's option files, calling none of them. */
#include "cli_options.h"

const char *const cli_method_names[4] = {"robust", "gaussian", "laplacian", "taubin"};
const char *const cli_normal_filter_names[2] = {"mollify", "bilateral"};
const char *const cli_influence_names[4] = {"gaussian", "tukey", "lorentzian", "huber"};

bool cli_method_uses_edges(method m) {
    return m == METHOD_LAPLACIAN || m == METHOD_TAUBIN;
}
