/* Exact decimal text for the mesh writers (not installed): the shortest decimal that reads back
 * as the same double or float (float_print.c), and unsigned integers. Prefix rs_io_. */
#ifndef RSMOOTH_IO_FLOAT_PRINT_H
#define RSMOOTH_IO_FLOAT_PRINT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* The most bytes one rs_io_print_* call writes ("-2.2250738585072014e-308" is 24). */
#define RS_IO_PRINT_MAX 32

/* A finite nonzero magnitude as digits 10^exponent: digits has no trailing zero. */
typedef struct rs_io_decimal {
    uint64_t digits;
    int exponent;
} rs_io_decimal;

/* Writes v (no terminating NUL) and returns the number of bytes, at most RS_IO_PRINT_MAX: the
 * shortest digits above, laid out as "%.{P}g" lays out its digits, P = 15 when they are at most
 * 15 and 17 otherwise (floats: 6 and 9): plain decimal, or d.ddde+XX from P digits up or below
 * 1e-4, as C's strtod and every mesh tool read it. So for a normal v the text is "%.15g"'s
 * ("%.6g"'s) when that is shortest, "%.17g"'s ("%.9g"'s) when 17 (9) digits are needed, and one
 * digit shorter than "%.17g"'s when 16 suffice. Zero is "0" or "-0"; NaN and infinities "nan",
 * "-nan", "inf", "-inf", as glibc prints them. */
size_t rs_io_print_double(char *out, double v);
size_t rs_io_print_float(char *out, float v);

/* Writes exactly what snprintf "%.9g" writes for v (correctly rounded to 9 significant digits,
 * ties to even) and returns the number of bytes, at most RS_IO_PRINT_MAX. */
size_t rs_io_print_g9(char *out, double v);

/* Writes the decimal digits of v and returns their number (at most 20). */
static inline size_t rs_io_print_u64(char *out, uint64_t v) {
    static const char pairs[201] = "00010203040506070809101112131415161718192021222324252627282930"
                                   "31323334353637383940414243444546474849505152535455565758596061"
                                   "62636465666768697071727374757677787980818283848586878889909192"
                                   "93949596979899";
    char tmp[20];
    char *p = tmp + sizeof tmp;
    while (v >= 100) {
        unsigned r = (unsigned)(v % 100);
        v /= 100;
        p -= 2;
        p[0] = pairs[2 * r];
        p[1] = pairs[2 * r + 1];
    }
    if (v >= 10) {
        p -= 2;
        p[0] = pairs[2 * v];
        p[1] = pairs[2 * v + 1];
    } else {
        *--p = (char)('0' + v);
    }
    size_t n = (size_t)(tmp + sizeof tmp - p);
    for (size_t i = 0; i < n; i++)
        out[i] = p[i];
    return n;
}

#endif /* RSMOOTH_IO_FLOAT_PRINT_H */
