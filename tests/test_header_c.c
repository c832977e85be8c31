/* The public headers compile on their own as C11 (-Wpedantic) and, as test_header_cxx.cpp, as C++.
 */
#include "rsmooth.h"
#include "rsmooth_cl.h"
#include "rsmooth_io.h"

#include <stdio.h>
#include <string.h>

int main(void) {
    rsmooth_params params;
    if (rsmooth_params_init(&params) != RSMOOTH_OK || params.struct_size != sizeof params)
        return 1;
    for (int s = RSMOOTH_OK; s <= RSMOOTH_ERROR_NUMERICAL; s++)
        if (strlen(rsmooth_status_str((rsmooth_status)s)) == 0)
            return 1;
    printf("headers ok: rsmooth %d.%d.%d\n", RSMOOTH_VERSION_MAJOR, RSMOOTH_VERSION_MINOR,
           RSMOOTH_VERSION_PATCH);
    return 0;
}
