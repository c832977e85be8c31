/* The version of the library as loaded, for programs that check it against their header's. */
#include "core/rsmooth_internal.h"

#define STRING_(x) #x
#define STRING(x) STRING_(x)

const char *rsmooth_version(int *major, int *minor, int *patch) {
    if (major)
        *major = RSMOOTH_VERSION_MAJOR;
    if (minor)
        *minor = RSMOOTH_VERSION_MINOR;
    if (patch)
        *patch = RSMOOTH_VERSION_PATCH;
    return STRING(RSMOOTH_VERSION_MAJOR) "." STRING(RSMOOTH_VERSION_MINOR) "." STRING(
        RSMOOTH_VERSION_PATCH);
}
