/* Internal units. Both paths multiply the caller's coordinates by a power of two on the way in,
 * so that a typical edge is about 1 long, and divide by it on the way out. Squared distances,
 * cross products (edge lengths to the fourth power inside a normal's length) and areas then
 * neither overflow nor underflow a double at any scale from the smallest normal double to the
 * largest supported coordinate, and since multiplying by a power of two is exact, every result
 * is the same as at scale 1, bit for bit. */
#include "core/rsmooth_internal.h"

#include <math.h>

/* Pairs of points sampled (at a fixed stride, so the choice is deterministic) for the typical
 * size: the scale need only be right within many powers of two, so a few thousand suffice. */
#define SCALE_SAMPLES 4096

/* Scaled coordinates stay below 2^SCALED_MAGNITUDE_LOG2 in magnitude, so their squares stay
 * below 2^1000; a scaled typical edge must not fall below 2^-SCALED_EDGE_LOG2, so its fourth
 * power stays above 2^-1000. */
#define SCALED_MAGNITUDE_LOG2 500
#define SCALED_EDGE_LOG2 250
/* The scale itself stays a finite double. */
#define MAX_SCALE_LOG2 1000

/* The larger of |a_k - b_k|: a length that cannot overflow or underflow where the Euclidean one's
 * square could. */
static double chebyshev_distance(rsmooth_scalar scalar, const void *positions, size_t a, size_t b) {
    double d = 0;
    for (int k = 0; k < 3; k++)
        d = fmax(d, fabs(rs_coordinate(scalar, positions, 3 * a + (size_t)k) -
                         rs_coordinate(scalar, positions, 3 * b + (size_t)k)));
    return d;
}

/* The geometric mean of the non-zero distances a pair function gives for sampled items, or 0. */
typedef bool (*pair_fn)(const void *ctx, size_t item, size_t *a, size_t *b);

static double typical_distance(rsmooth_scalar scalar, const void *positions, size_t items,
                               pair_fn pair, const void *ctx) {
    size_t stride = items > SCALE_SAMPLES ? items / SCALE_SAMPLES : 1;
    double log_sum = 0;
    size_t used = 0;
    for (size_t i = 0; i < items; i += stride) {
        size_t a, b;
        if (!pair(ctx, i, &a, &b))
            continue;
        double d = chebyshev_distance(scalar, positions, a, b);
        if (d > 0) {
            log_sum += log2(d);
            used++;
        }
    }
    return used ? exp2(log_sum / (double)used) : 0;
}

static bool triangle_edge(const void *ctx, size_t t, size_t *a, size_t *b) {
    const uint32_t *tri = (const uint32_t *)ctx + 3 * t;
    /* the longest of the three edges would cost three distances; any one serves */
    *a = tri[0];
    *b = tri[tri[1] != tri[0] ? 1 : 2];
    return *a != *b;
}

static bool next_point(const void *ctx, size_t i, size_t *a, size_t *b) {
    size_t count = *(const size_t *)ctx;
    *a = i;
    *b = i + 1;
    return i + 1 < count;
}

/* 2^e for an integer e, exact (ldexp of 1 is). */
static double power_of_two(int e) {
    return ldexp(1.0, e);
}

/* The scale for a typical length and the largest coordinate magnitude (see scale.c's top), or 0
 * when no power of two keeps both in range. */
static double choose_scale(double typical, double magnitude) {
    int e = 0;
    if (typical > 0)
        frexp(typical, &e); /* typical = m 2^e, m in [0.5, 1): 2^-e brings it near 1 */
    else if (magnitude > 0)
        frexp(magnitude, &e);
    /* then keep the largest coordinate within 2^SCALED_MAGNITUDE_LOG2 */
    int m = 0;
    if (magnitude > 0)
        frexp(magnitude, &m);
    if (m - e > SCALED_MAGNITUDE_LOG2)
        e = m - SCALED_MAGNITUDE_LOG2;
    if (e < -MAX_SCALE_LOG2) /* subnormal input: as far up as the double range goes */
        e = -MAX_SCALE_LOG2;
    if (typical > 0) {
        int t;
        frexp(typical, &t);
        if (t - e < -SCALED_EDGE_LOG2)
            return 0;
    }
    return power_of_two(-e);
}

void rs_scale_positions(rsmooth_scalar scalar, const void *positions, size_t count, double scale,
                        double *out) {
    for (size_t i = 0; i < 3 * count; i++)
        out[i] = rs_coordinate(scalar, positions, i) * scale;
}

/* The scale for a typical length and the largest coordinate, or the refusal naming them. */
static rsmooth_status scale_for(double typical, double magnitude, const char *owner,
                                const char *length, double *scale, rsmooth_error *error,
                                const char *where) {
    *scale = choose_scale(typical, magnitude);
    if (*scale > 0)
        return RSMOOTH_OK;
    return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                   "%s largest coordinate (%g) is more than 1e225 of %s (%g): beyond what "
                   "double precision can weigh areas over",
                   owner, magnitude, length, typical);
}

/* choose_scale's exponent e (scale 2^-e) is at least -MAX_SCALE_LOG2, and at most that of the
 * largest typical length: two coordinates within RS_MAX_COORDINATE lie at most twice that apart. */
bool rs_scale_possible(double scale) {
    int top = 0, e = 0;
    (void)frexp(2 * RS_MAX_COORDINATE, &top);
    return scale > 0 && frexp(scale, &e) == 0.5 && e - 1 <= MAX_SCALE_LOG2 && 1 - e <= top;
}

double rs_typical_edge(rsmooth_scalar scalar, const void *positions, const uint32_t *indices,
                       size_t triangle_count) {
    return typical_distance(scalar, positions, triangle_count, triangle_edge, indices);
}

rsmooth_status rs_mesh_scale(rsmooth_scalar scalar, const void *positions, const uint32_t *indices,
                             size_t triangle_count, double magnitude, double *scale,
                             rsmooth_error *error, const char *where) {
    double typical = typical_distance(scalar, positions, triangle_count, triangle_edge, indices);
    return scale_for(typical, magnitude, "the mesh's", "its typical edge length", scale, error,
                     where);
}

rsmooth_status rs_points_scale(rsmooth_scalar scalar, const void *positions, size_t count,
                               double magnitude, double *scale, rsmooth_error *error,
                               const char *where) {
    double typical = typical_distance(scalar, positions, count, next_point, &count);
    return scale_for(typical, magnitude, "the points'", "their typical spacing", scale, error,
                     where);
}
