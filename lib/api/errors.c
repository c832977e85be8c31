/* The public status text and error record (rsmooth.h): core/status.c keeps them. */
#include "core/rsmooth_internal.h"

const char *rsmooth_status_str(rsmooth_status status) {
    return rs_status_str(status);
}

void rsmooth_error_init(rsmooth_error *error) {
    rs_error_init(error);
}
