/* A host that passes arrays (rsmooth.h only): smooths a tetrahedron on the reference path through
 * the installed header and library. Built by test_package.sh with the README's own lines. */
#include <rsmooth.h>

#include <stdio.h>

int main(void) {
    const float xyz[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    const uint32_t idx[] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
    float out[12];
    rsmooth_error err;
    rsmooth_status st =
        rsmooth_smooth(NULL, RSMOOTH_FLOAT32, xyz, 4, idx, 4, NULL, out, NULL, &err);
    int major, minor, patch;
    rsmooth_version(&major, &minor, &patch);
    printf("app: header %d.%d.%d, library %d.%d.%d: %s\n", RSMOOTH_VERSION_MAJOR,
           RSMOOTH_VERSION_MINOR, RSMOOTH_VERSION_PATCH, major, minor, patch,
           rsmooth_status_str(st));
    return st == RSMOOTH_OK && major == RSMOOTH_VERSION_MAJOR && minor == RSMOOTH_VERSION_MINOR ? 0
                                                                                                : 1;
}
