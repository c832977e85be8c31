/* The coordinate checks readers and writers share (rs_io_coordinate_ok: what rsmooth writes, it
 * reads), and the shortest digits their messages print. */
#include "io/io_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

rs_io_digits rs_io_shortest(double v) {
    rs_io_digits d;
    for (int digits = 1; digits <= 17; digits++) {
        snprintf(d.text, sizeof d.text, "%.*g", digits, v);
        if (!isfinite(v) || strtod(d.text, NULL) == v)
            break;
    }
    return d;
}

rsmooth_status rs_io_check_vertex(const double xyz[3], size_t number, int64_t line,
                                  int64_t byte_offset, const char *where, rsmooth_error *error) {
    for (int k = 0; k < 3; k++) {
        if (!isfinite(xyz[k]))
            return rs_fail_parse(error, line, byte_offset, where,
                                 "vertex %zu has a non-finite coordinate", number);
        if (!rs_io_coordinate_ok(xyz[k]))
            return rs_fail_parse(error, line, byte_offset, where,
                                 "vertex %zu has coordinate %s beyond the supported magnitude %s",
                                 number, rs_io_shortest(xyz[k]).text,
                                 rs_io_shortest(RS_MAX_COORDINATE).text);
    }
    return RSMOOTH_OK;
}

rsmooth_status rs_io_check_position_values(const double *xyz, size_t count, const uint64_t *ids,
                                           const char *where, rsmooth_error *error) {
    for (size_t i = 0; i < 3 * count; i++) {
        double x = xyz[i];
        size_t vertex = ids ? ids[i / 3] : i / 3;
        if (!isfinite(x))
            return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                           "vertex %zu has a non-finite coordinate (%g): not written", vertex, x);
        if (!rs_io_coordinate_ok(x))
            return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                           "vertex %zu has coordinate %s beyond the supported magnitude %s: not "
                           "written (rsmooth could not read it back)",
                           vertex, rs_io_shortest(x).text, rs_io_shortest(RS_MAX_COORDINATE).text);
    }
    return RSMOOTH_OK;
}
