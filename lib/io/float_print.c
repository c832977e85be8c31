/* Shortest round-trip decimals: R. Giulietti, "The Schubfach way to render doubles" (2020).
 *
 * v = c 2^q has the rounding interval [vl, vr] = [(4c - 2) 2^(q-2), (4c + 2) 2^(q-2)] (lower
 * bound (4c - 1) 2^(q-2) when c is a power of two above the smallest exponent: the float below
 * is closer), closed when c is even (round half to even reads the bounds back as v), open when
 * odd. With k = floor(log10 of the interval's width), 10^k <= width < 10^(k+1): scaled by 10^-k
 * the interval holds one or two integers and at most one multiple of ten. So the shortest
 * decimal is that multiple of ten when the interval holds it, else floor(v 10^-k) or the next
 * integer, whichever the interval holds (the closer to v when both). The scaled bounds are
 * computed to two fractional bits with a sticky bit (round to odd) from a 126-bit upper
 * approximation of 10^-k (float_print_pow10.h), which the paper proves exact for every double:
 * the comparisons with integers then come out as with the exact values. Floats take the same
 * path with the same table (more than the 64 bits their proof needs). */
#include "io/float_print.h"

#include <stdio.h>
#include <string.h>

#include "io/float_print_pow10.h"

/* floor(a / 2^shift) for a signed a, without relying on >> of a negative value. */
static inline int64_t floor_shift(int64_t a, int shift) {
    int64_t d = (int64_t)1 << shift;
    return a >= 0 ? a / d : -((-a + d - 1) / d);
}

/* floor(q log10 2), floor(q log10 2 + log10 3/4) and floor(e log2 10) for |q|, |e| < 1200
 * (checked exactly by scripts/gen_pow10_table.py). */
static inline int floor_log10_pow2(int q) {
    return (int)floor_shift((int64_t)q * 661971961083, 41);
}
static inline int floor_log10_three_quarters_pow2(int q) {
    return (int)floor_shift((int64_t)q * 661971961083 - 274743187321, 41);
}
static inline int floor_log2_pow10(int e) {
    return (int)floor_shift((int64_t)e * 913124641741, 38);
}

/* The high 64 bits of a b, the low ones in *lo. */
static inline uint64_t mul_64x64(uint64_t a, uint64_t b, uint64_t *lo) {
#if defined(__SIZEOF_INT128__)
    __extension__ typedef unsigned __int128 u128;
    u128 p = (u128)a * b;
    *lo = (uint64_t)p;
    return (uint64_t)(p >> 64);
#else
    uint64_t a0 = (uint32_t)a, a1 = a >> 32, b0 = (uint32_t)b, b1 = b >> 32;
    uint64_t p00 = a0 * b0, p01 = a0 * b1, p10 = a1 * b0, p11 = a1 * b1;
    uint64_t mid = (p00 >> 32) + (uint32_t)p01 + (uint32_t)p10;
    *lo = (mid << 32) | (uint32_t)p00;
    return p11 + (p01 >> 32) + (p10 >> 32) + (mid >> 32);
#endif
}

/* g cp / 2^127 rounded to odd, g = hi 2^64 + lo: its integer part, with the lowest bit set when
 * the 63 bits below the point are not all zero (the product's lower 64 bits are dropped; the
 * paper's bound covers that). */
static inline uint64_t round_to_odd(const uint64_t g[2], uint64_t cp) {
    uint64_t lo_lo, hi_lo;
    uint64_t lo_hi = mul_64x64(g[1], cp, &lo_lo);
    uint64_t hi_hi = mul_64x64(g[0], cp, &hi_lo);
    uint64_t mid = hi_lo + lo_hi;
    hi_hi += mid < lo_hi;
    uint64_t integer = hi_hi << 1 | mid >> 63;
    return integer | ((mid & (UINT64_MAX >> 1)) != 0);
}

static rs_io_decimal strip_zeros(uint64_t digits, int exponent) {
    while (digits % 10 == 0) {
        digits /= 10;
        exponent++;
    }
    return (rs_io_decimal){digits, exponent};
}

/* The shortest decimal in the rounding interval of c 2^q (c > 0); `closer_below`: the float
 * below is half as far as the one above. */
static rs_io_decimal to_decimal(uint64_t c, int q, bool closer_below) {
    const uint64_t open = c & 1; /* odd c: the bounds read back as the neighbours */
    const uint64_t cb = c << 2, cbr = cb + 2;
    uint64_t cbl;
    int k;
    if (closer_below) {
        cbl = cb - 1;
        k = floor_log10_three_quarters_pow2(q);
    } else {
        cbl = cb - 2;
        k = floor_log10_pow2(q);
    }
    const int h = q + floor_log2_pow10(-k) + 2; /* in [2, 9]: cbr << h < 2^64 */
    const uint64_t *g = rs_pow10_table[-k - RS_POW10_MIN];
    const uint64_t vb = round_to_odd(g, cb << h), vbl = round_to_odd(g, cbl << h),
                   vbr = round_to_odd(g, cbr << h); /* 4 v 10^-k, 4 vl 10^-k, 4 vr 10^-k */
    const uint64_t s = vb >> 2;
    /* One digit fewer: the multiple of ten at or below v, or the one above. */
    const uint64_t sp10 = s / 10 * 10, tp10 = sp10 + 10;
    const bool up_in = vbl + open <= sp10 << 2, wp_in = (tp10 << 2) + open <= vbr;
    if (up_in != wp_in) /* the interval is narrower than 10: never both */
        return strip_zeros(up_in ? sp10 : tp10, k);
    const uint64_t t = s + 1;
    const bool u_in = vbl + open <= s << 2, w_in = (t << 2) + open <= vbr;
    if (u_in != w_in)
        return strip_zeros(u_in ? s : t, k);
    /* Both: the closer to v, the even one on a tie (vb is then exactly 4s + 2). */
    const uint64_t mid = (s + t) << 1;
    return strip_zeros(vb < mid || (vb == mid && (s & 1) == 0) ? s : t, k);
}

/* The decimal with the fewest significant digits that lies in the rounding interval of |v| (so
 * that strtod / strtof, rounding to nearest even, read it back as |v|), the closest to |v| among
 * them (ties to an even last digit). These are the digits of the smallest precision p for which
 * "%.{p}g" reads back as v, except at some powers of two, whose interval reaches twice as far up
 * as down: there "%.{p}g" may round down out of it where a decimal one digit shorter above v is
 * in it. v finite and nonzero. */
static rs_io_decimal rs_io_shortest_double(double v) {
    uint64_t bits;
    memcpy(&bits, &v, sizeof bits);
    const uint64_t fraction = bits & (((uint64_t)1 << 52) - 1);
    const int biased = (int)(bits >> 52 & 0x7ff);
    if (biased == 0) /* subnormal */
        return to_decimal(fraction, -1074, false);
    return to_decimal(fraction | (uint64_t)1 << 52, biased - 1075, fraction == 0 && biased > 1);
}

static rs_io_decimal rs_io_shortest_float(float v) {
    uint32_t bits;
    memcpy(&bits, &v, sizeof bits);
    const uint32_t fraction = bits & ((1u << 23) - 1);
    const int biased = (int)(bits >> 23 & 0xff);
    if (biased == 0)
        return to_decimal(fraction, -149, false);
    return to_decimal(fraction | 1u << 23, biased - 150, fraction == 0 && biased > 1);
}

/* Number of decimal digits of d >= 1. */
static int digit_count(uint64_t d) {
    int n = 1;
    for (; d >= 10; d /= 10)
        n++;
    return n;
}

/* Lays out digits 10^exponent as "%.{P}g" lays out its digits: P = short_p when they are at most
 * short_p, else full_p. */
static size_t layout(char *out, bool negative, rs_io_decimal d, int short_p, int full_p) {
    char digits[20];
    const int n = (int)rs_io_print_u64(digits, d.digits);
    const int x = d.exponent + n - 1; /* the first digit's power of ten */
    const int p = n <= short_p ? short_p : full_p;
    char *o = out;
    if (negative)
        *o++ = '-';
    if (x < -4 || x >= p) {
        *o++ = digits[0];
        if (n > 1) {
            *o++ = '.';
            memcpy(o, digits + 1, (size_t)(n - 1));
            o += n - 1;
        }
        *o++ = 'e';
        *o++ = x < 0 ? '-' : '+';
        const unsigned e = (unsigned)(x < 0 ? -x : x);
        if (e < 10)
            *o++ = '0';
        o += rs_io_print_u64(o, e);
    } else if (x < 0) {
        *o++ = '0';
        *o++ = '.';
        for (int i = 0; i < -x - 1; i++)
            *o++ = '0';
        memcpy(o, digits, (size_t)n);
        o += n;
    } else if (n <= x + 1) {
        memcpy(o, digits, (size_t)n);
        o += n;
        for (int i = n; i < x + 1; i++)
            *o++ = '0';
    } else {
        memcpy(o, digits, (size_t)x + 1);
        o += x + 1;
        *o++ = '.';
        memcpy(o, digits + x + 1, (size_t)(n - x - 1));
        o += n - x - 1;
    }
    return (size_t)(o - out);
}

/* Zero, infinities and NaN as glibc's %g writes them; 0 when v is none of them. */
static size_t special(char *out, bool negative, bool zero, bool inf, bool nan) {
    const char *text = zero ? "0" : inf ? "inf" : nan ? "nan" : NULL;
    if (!text)
        return 0;
    size_t n = 0;
    if (negative)
        out[n++] = '-';
    for (; *text; text++)
        out[n++] = *text;
    return n;
}

/* A double's sign and magnitude bits; writes it as special() does when it is one of those. */
static size_t special_double(char *out, double v, bool *negative, uint64_t *magnitude) {
    uint64_t bits;
    memcpy(&bits, &v, sizeof bits);
    *negative = bits >> 63;
    *magnitude = bits & (UINT64_MAX >> 1);
    const uint64_t inf_bits = (uint64_t)0x7ff << 52;
    return special(out, *negative, *magnitude == 0, *magnitude == inf_bits, *magnitude > inf_bits);
}

size_t rs_io_print_double(char *out, double v) {
    bool negative;
    uint64_t magnitude;
    size_t n = special_double(out, v, &negative, &magnitude);
    return n ? n : layout(out, negative, rs_io_shortest_double(v), 15, 17);
}

size_t rs_io_print_float(char *out, float v) {
    uint32_t bits;
    memcpy(&bits, &v, sizeof bits);
    const bool negative = bits >> 31;
    const uint32_t magnitude = bits & 0x7fffffffu, inf_bits = 0x7f800000u;
    size_t n = special(out, negative, magnitude == 0, magnitude == inf_bits, magnitude > inf_bits);
    return n ? n : layout(out, negative, rs_io_shortest_float(v), 6, 9);
}

size_t rs_io_print_g9(char *out, double v) {
    bool negative;
    uint64_t magnitude;
    size_t n = special_double(out, v, &negative, &magnitude);
    if (n)
        return n;
    /* A normal v's 9-digit rounding is its shortest decimal's: a 9-digit midpoint strictly
     * between them would be a decimal of at most 10 digits in v's rounding interval, where no two
     * of them fit (they are 1e-10 apart relative to v, the interval 2^-52). Left to snprintf: a
     * shortest decimal that is itself the midpoint, and subnormals (wider intervals). */
    rs_io_decimal d = rs_io_shortest_double(v);
    int count = digit_count(d.digits);
    uint64_t scale = 1, rest = 0, half = 0;
    if (count > 9) {
        for (int i = 9; i < count; i++)
            scale *= 10;
        rest = d.digits % scale;
        half = scale / 2;
    }
    if (magnitude < (uint64_t)1 << 52 || (count > 9 && rest == half)) {
        int written = snprintf(out, RS_IO_PRINT_MAX, "%.9g", v);
        return written > 0 && written < RS_IO_PRINT_MAX ? (size_t)written : 0;
    }
    if (count > 9)
        d = strip_zeros(d.digits / scale + (rest > half), d.exponent + count - 9);
    return layout(out, negative, d, 9, 9);
}
