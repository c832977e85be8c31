/* The parts test's bins (core/part_scales.c): a triangle's size in quarter octaves,
 * floor(4 log2(size)), from the exponent and three thresholds. Against an oracle with more bits:
 * each bin's lower edge 2^(b/4) in long double, so the doubles just below and at or above it
 * (away from the edge by more than long double's rounding) must fall in bins b - 1 and b; every
 * power of two in its bin exactly; subnormals, 0, negatives and non-finite sizes in none; and
 * random sizes in floor(4 log2) of libm's, where that lies clear of an edge. */
#include "core/parts.h"
#include "test_util.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>

int main(void) {
    size_t edges = 0;
    for (int b = -4 * 1070; b <= 4 * 1020; b++) { /* subnormal to near DBL_MAX */
        long double t = exp2l((long double)b / 4);
        double at = (double)t;
        if ((long double)at < t)
            at = nextafter(at, INFINITY);
        double below = nextafter(at, 0);
        if ((long double)at - t < t * 0x1p-60L || t - (long double)below < t * 0x1p-60L)
            continue; /* within the oracle's own rounding: undecided */
        CHECK_EQ_INT(rs_scale_bin(at), b);
        CHECK_EQ_INT(rs_scale_bin(below), b - 1);
        edges++;
    }
    for (int e = -1074; e <= 1023; e++)
        CHECK_EQ_INT(rs_scale_bin(ldexp(1, e)), 4 * e);
    const double none[] = {0, -1, -0.0, NAN, INFINITY, -INFINITY};
    for (size_t i = 0; i < sizeof none / sizeof *none; i++)
        CHECK_EQ_INT(rs_scale_bin(none[i]), RS_NO_BIN);
    uint64_t x = 0x9E3779B97F4A7C15u;
    size_t compared = 0;
    for (int i = 0; i < 1000000; i++) {
        x ^= x << 13, x ^= x >> 7, x ^= x << 17;
        double s = ldexp(1.0 + (double)(x >> 11) * 0x1p-53, (int)(x % 2000) - 1000);
        double q = 4 * log2(s);
        if (fabs(q - round(q)) < 1e-9)
            continue;
        CHECK_EQ_INT(rs_scale_bin(s), (int)floor(q));
        compared++;
    }
    printf("%zu bin edges exact, 2098 powers of two, %zu random sizes as floor(4 log2)\n", edges,
           compared);
    return 0;
}
