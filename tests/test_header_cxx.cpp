// The public headers compile as C++ (test_header_c.c checks C11).
#include "rsmooth.h"
#include "rsmooth_cl.h"
#include "rsmooth_io.h"

#include <cstdio>
#include <cstring>

int main(void) {
    rsmooth_params params;
    if (rsmooth_params_init(&params) != RSMOOTH_OK || params.struct_size != sizeof params)
        return 1;
    for (int s = RSMOOTH_OK; s <= RSMOOTH_ERROR_UNSUPPORTED; s++)
        if (strlen(rsmooth_status_str((rsmooth_status)s)) == 0)
            return 1;
    printf("headers ok: rsmooth %d.%d.%d\n", RSMOOTH_VERSION_MAJOR, RSMOOTH_VERSION_MINOR,
           RSMOOTH_VERSION_PATCH);
    return 0;
}
