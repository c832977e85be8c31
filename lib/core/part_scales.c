/* The size of a triangle, and the parts a histogram of sizes falls into (core/parts.h has the
 * rule): what the in-memory path (parts.c) and the streamed one (stream/stream_stats.c) both
 * read, so that they decide alike. No threads and no mesh arrays beyond a triangle's corners. */
#include "core/parts.h"

#include <math.h>
#include <string.h>

#define BIN_MIN RS_PART_BIN_MIN
#define BIN_COUNT RS_PART_BIN_COUNT

/* |a - b| for two vertices, without overflow or underflow of the squares. */
static double edge_length(rsmooth_scalar scalar, const void *positions, uint32_t a, uint32_t b) {
    double d[3], m = 0;
    for (int k = 0; k < 3; k++) {
        d[k] = rs_coordinate(scalar, positions, 3 * (size_t)a + (size_t)k) -
               rs_coordinate(scalar, positions, 3 * (size_t)b + (size_t)k);
        m = fmax(m, fabs(d[k]));
    }
    if (!(m > 0))
        return 0;
    double s = 0;
    for (int k = 0; k < 3; k++)
        s += (d[k] / m) * (d[k] / m);
    return m * sqrt(s);
}

double rs_triangle_scale(rsmooth_scalar scalar, const void *positions, const uint32_t tri[3],
                         double *longest) {
    double e0 = edge_length(scalar, positions, tri[0], tri[1]);
    double e1 = edge_length(scalar, positions, tri[1], tri[2]);
    double e2 = edge_length(scalar, positions, tri[2], tri[0]);
    double lo = fmin(e0, fmin(e1, e2));
    *longest = fmax(e0, fmax(e1, e2));
    return e0 + e1 + e2 - lo - *longest; /* the median */
}

/* floor(4 log2(scale)) exactly, from the exponent and the mantissa against 2^(-3/4), 2^(-1/2)
 * and 2^(-1/4) (each the smallest double at or above it): no libm call per triangle, and no
 * rounding of log2 near a bin's edge. */
_Static_assert(RS_PART_BINS_PER_OCTAVE == 4, "rs_scale_bin's thresholds are quarter octaves");

int16_t rs_scale_bin(double scale) {
    if (!(scale > 0) || !isfinite(scale))
        return RS_NO_BIN;
    int e = 0;
    double f = frexp(scale, &e); /* scale = f 2^e, f in [1/2, 1) */
    int quarters =
        (f >= 0x1.306fe0a31b716p-1) + (f >= 0x1.6a09e667f3bcdp-1) + (f >= 0x1.ae89f995ad3aep-1);
    return (int16_t)(RS_PART_BINS_PER_OCTAVE * (e - 1) + quarters);
}

size_t rs_cut_parts(const size_t *histogram, uint32_t *part_of_bin, double *limit,
                    size_t limit_capacity) {
    size_t parts = 0;
    int last = 0, first = 0;
    size_t in_part = 0;
    bool open = false;
    for (int b = 0; b <= BIN_COUNT; b++) {
        bool occupied = b < BIN_COUNT && histogram[b] > 0;
        bool ends =
            open && (b == BIN_COUNT ||
                     (occupied && b - last > RS_PART_GAP_OCTAVES * RS_PART_BINS_PER_OCTAVE));
        if (ends) { /* the part [first, last]: its median bin bounds its typical scale */
            size_t seen = 0;
            int median = first;
            for (int m = first; m <= last; m++) {
                seen += histogram[m];
                if (2 * seen >= in_part) {
                    median = m;
                    break;
                }
            }
            if (parts < limit_capacity)
                limit[parts] = RS_EDGE_OUT_OF_LINE *
                               exp2((double)(median + BIN_MIN + 1) / RS_PART_BINS_PER_OCTAVE);
            parts++;
            open = false;
            in_part = 0;
        }
        if (occupied) {
            if (!open) {
                open = true;
                first = b;
            }
            part_of_bin[b] = (uint32_t)parts;
            in_part += histogram[b];
            last = b;
        }
    }
    return parts;
}

size_t rs_scale_parts(const int16_t *bin, size_t count, uint32_t *part, double **limit) {
    size_t *histogram = rs_calloc_array(BIN_COUNT, sizeof *histogram);
    uint32_t *part_of_bin = rs_alloc_array(BIN_COUNT, sizeof *part_of_bin);
    size_t parts = SIZE_MAX;
    *limit = NULL;
    if (histogram && part_of_bin) {
        for (size_t i = 0; i < count; i++)
            if (bin[i] != RS_NO_BIN)
                histogram[bin[i] - BIN_MIN]++;
        parts = rs_cut_parts(histogram, part_of_bin, NULL, 0);
        *limit = rs_alloc_array(parts ? parts : 1, sizeof **limit);
        if (*limit) {
            rs_cut_parts(histogram, part_of_bin, *limit, parts);
            for (size_t i = 0; i < count; i++)
                part[i] = bin[i] == RS_NO_BIN ? RS_NO_PART : part_of_bin[bin[i] - BIN_MIN];
        } else {
            parts = SIZE_MAX;
        }
    }
    rs_free(histogram);
    rs_free(part_of_bin);
    return parts;
}

bool rs_scales_whole(const size_t *histogram, double longest) {
    uint32_t *part_of_bin = rs_alloc_array(BIN_COUNT, sizeof *part_of_bin);
    if (!part_of_bin)
        return false;
    double limit = 0;
    size_t parts = rs_cut_parts(histogram, part_of_bin, &limit, 1);
    rs_free(part_of_bin);
    return parts <= 1 && longest <= limit;
}
