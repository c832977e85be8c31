/* Smooths a tetrahedron through the installed headers and library, reference path only. */
#include <rsmooth.h>
#include <rsmooth_io.h>

#include <stdio.h>

int main(void) {
    const float xyz[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    const uint32_t idx[] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
    float out[12];
    rsmooth_error err;
    rsmooth_status st = rsmooth_smooth_reference(RSMOOTH_FLOAT32, xyz, 4, idx, 4, NULL, out, NULL,
                                                 NULL, NULL, &err);
    printf("rsmooth %d.%d.%d: %s, format of x.ply: %d\n", RSMOOTH_VERSION_MAJOR,
           RSMOOTH_VERSION_MINOR, RSMOOTH_VERSION_PATCH, rsmooth_status_str(st),
           (int)rsmooth_format_from_path("x.ply"));
    return st == RSMOOTH_OK ? 0 : 1;
}
