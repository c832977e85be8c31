/* The writers' number printer (lib/io/float_print.c) against C's own conversions: every printed
 * double reads back (strtod) as the same bits, every float (strtof, and strtod then a cast to
 * float, as the readers do) as the same float, and its digits are those of the smallest precision
 * p for which "%.{p}g" reads back (the independent oracle: glibc's correctly rounded printf);
 * where the writers' old text ("%.15g" when it read back, else "%.17g"; "%.6g" and "%.9g" for
 * floats) was shortest, the text is the same byte for byte. Random bit patterns (subnormals
 * included), short decimals, powers of two and of ten and their neighbours, boundaries. "%.9g"
 * (rs_io_print_g9) against snprintf. Integers. */
#include "io/float_print.h"
#include "test_util.h"

#include <float.h>
#include <inttypes.h>
#include <stdbool.h>
#include <stdint.h>
#include <string.h>
#include <time.h>

static uint64_t rng_state = 0x9e3779b97f4a7c15u;

static uint64_t next_u64(void) { /* splitmix64 */
    uint64_t z = (rng_state += 0x9e3779b97f4a7c15u);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
    return z ^ (z >> 31);
}

/* A decimal text as significant digits (no leading or trailing zeros) and the power of ten of
 * the first one; "0" for zero. */
typedef struct normal_decimal {
    char digits[40];
    int exponent;
} normal_decimal;

static normal_decimal normalise(const char *s) {
    normal_decimal d = {{0}, 0};
    size_t n = 0;
    int point = -1, count = 0; /* digits before the point */
    if (*s == '-' || *s == '+')
        s++;
    for (; (*s >= '0' && *s <= '9') || *s == '.'; s++) {
        if (*s == '.') {
            point = count;
            continue;
        }
        count++;
        if (n == 0 && *s == '0') {
            d.exponent--; /* a leading zero: the first significant digit is further right */
            continue;
        }
        if (n < sizeof d.digits - 1)
            d.digits[n++] = *s;
    }
    if (point < 0)
        point = count;
    int e = 0;
    if (*s == 'e' || *s == 'E')
        e = atoi(s + 1);
    while (n > 0 && d.digits[n - 1] == '0')
        d.digits[--n] = '\0';
    if (n == 0)
        return (normal_decimal){"0", 0};
    d.exponent += point - 1 + e;
    return d;
}

static uint64_t double_bits(double v) {
    uint64_t b;
    memcpy(&b, &v, sizeof b);
    return b;
}

static uint32_t float_bits(float v) {
    uint32_t b;
    memcpy(&b, &v, sizeof b);
    return b;
}

static long checked_double, checked_float, old_format_double, old_format_float,
    power_of_two_shorter;

/* Whether `text` reads back as v: strtod's bits for a double; for a float, strtof's and
 * (float)strtod's (the readers parse doubles, then round to float). */
static bool reads_back(const char *text, double v, bool is_float) {
    if (!is_float)
        return double_bits(strtod(text, NULL)) == double_bits(v);
    float f = (float)v;
    return float_bits(strtof(text, NULL)) == float_bits(f) &&
           float_bits((float)strtod(text, NULL)) == float_bits(f);
}

/* No decimal of `digits` significant digits reads back as v: neither v rounded to that many
 * digits nor its two neighbours at that length (v's rounding interval is narrower than one step
 * there). */
static bool none_of_length(double v, int digits, bool is_float) {
    if (digits < 1)
        return true;
    char t[64];
    snprintf(t, sizeof t, "%.*e", digits - 1, fabs(v));
    uint64_t m = 0;
    const char *s = t;
    for (; *s != 'e'; s++)
        if (*s != '.')
            m = m * 10 + (uint64_t)(*s - '0');
    int e = atoi(s + 1) - (digits - 1);
    for (int d = -1; d <= 1; d++) {
        if (m + (uint64_t)(int64_t)d == 0)
            continue;
        snprintf(t, sizeof t, "%s%" PRIu64 "e%d", v < 0 ? "-" : "", m + (uint64_t)(int64_t)d, e);
        if (reads_back(t, v, is_float))
            return false;
    }
    return true;
}

/* Prints v (as a float when `is_float`) and checks the text against C's conversions. */
static void check_value(double v, bool is_float) {
    char text[RS_IO_PRINT_MAX + 1];
    size_t len = is_float ? rs_io_print_float(text, (float)v) : rs_io_print_double(text, v);
    CHECK(len > 0 && len <= RS_IO_PRINT_MAX);
    text[len] = '\0';
    char *end;
    strtod(text, &end);
    if (*end != '\0' || !reads_back(text, v, is_float)) {
        fprintf(stderr, "%s %a printed as '%s' does not read back\n", is_float ? "float" : "double",
                v, text);
        exit(1);
    }
    normal_decimal mine = normalise(text);
    const int n = (int)strlen(mine.digits);
    /* A power of two's interval reaches twice as far up as down: %.{n}g may round down out of it
     * while a decimal of n digits above v is in it. There the text may be shorter than p, and
     * is then checked shortest by trying the decimals one digit shorter. */
    bool power_of_two = is_float ? (float_bits((float)v) & 0x7fffffu) == 0
                                 : (double_bits(v) & ((UINT64_C(1) << 52) - 1)) == 0;
    /* The oracle: the smallest p for which %.{p}g reads back. Elsewhere v's interval is
     * symmetric, so %.{p}g reading back implies %.{p+1}g does (it is at least as close): the
     * search may start at n - 1, and does from 1 for powers of two and every 64th value. */
    const int max_p = is_float ? 9 : 17;
    static unsigned long calls;
    char oracle[64];
    int p = power_of_two || calls++ % 64 == 0 || n < 2 ? 1 : n - 1;
    for (; p <= max_p; p++) {
        snprintf(oracle, sizeof oracle, "%.*g", p, v);
        if (reads_back(oracle, v, is_float))
            break;
    }
    CHECK(p <= max_p);
    normal_decimal theirs = normalise(oracle);
    bool equal = strcmp(mine.digits, theirs.digits) == 0 && mine.exponent == theirs.exponent;
    if (!(equal && n == p) && !(power_of_two && n < p && none_of_length(v, n - 1, is_float))) {
        fprintf(stderr, "%s %a: printed '%s', shortest by %%.%dg is '%s'\n",
                is_float ? "float" : "double", v, text, p, oracle);
        exit(1);
    }
    if (n < p)
        power_of_two_shorter++;
    /* The writers' old text, %.15g when it read back, else %.17g (floats: %.6g, %.9g), where
     * that was shortest: not for 16 digits (7 or 8 for floats), nor for subnormals, whose %.15g
     * reads back with needless digits. */
    const int short_p = is_float ? 6 : 15;
    bool normal = fabs(v) >= (is_float ? FLT_MIN : DBL_MIN);
    if (normal && n == p && (n <= short_p || n == max_p)) {
        snprintf(oracle, sizeof oracle, "%.*g", n <= short_p ? short_p : max_p, v);
        if (strcmp(text, oracle) != 0) {
            fprintf(stderr, "%s %a: printed '%s', %%.%dg gives '%s'\n",
                    is_float ? "float" : "double", v, text, n <= short_p ? short_p : max_p, oracle);
            exit(1);
        }
        *(is_float ? &old_format_float : &old_format_double) += 1;
    }
    *(is_float ? &checked_float : &checked_double) += 1;
}

static void check_double(double v) {
    check_value(v, false);
}

static void check_float(float v) {
    check_value((double)v, true);
}

static void check_g9(double v) {
    char text[RS_IO_PRINT_MAX + 1], oracle[64];
    size_t n = rs_io_print_g9(text, v);
    CHECK(n > 0 && n <= RS_IO_PRINT_MAX);
    text[n] = '\0';
    snprintf(oracle, sizeof oracle, "%.9g", v);
    if (strcmp(text, oracle) != 0) {
        fprintf(stderr, "%%.9g of %a: printed '%s', snprintf gives '%s'\n", v, text, oracle);
        exit(1);
    }
}

/* v and both its neighbours, as double and g9 (and as float, when it is one). */
static void check_around(double v) {
    double vs[3] = {nextafter(v, -INFINITY), v, nextafter(v, INFINITY)};
    for (int i = 0; i < 3; i++)
        if (isfinite(vs[i])) {
            check_double(vs[i]);
            check_double(-vs[i]);
            check_g9(vs[i]);
        }
    float f = (float)v;
    if (isfinite(f) && (double)f == v) {
        float fs[3] = {nextafterf(f, -INFINITY), f, nextafterf(f, INFINITY)};
        for (int i = 0; i < 3; i++)
            if (isfinite(fs[i])) {
                check_float(fs[i]);
                check_float(-fs[i]);
            }
    }
}

static double random_double(void) {
    for (;;) {
        double v;
        uint64_t b = next_u64();
        memcpy(&v, &b, sizeof v);
        if (isfinite(v))
            return v;
    }
}

static float random_float(void) {
    for (;;) {
        float v;
        uint32_t b = (uint32_t)next_u64();
        memcpy(&v, &b, sizeof v);
        if (isfinite(v))
            return v;
    }
}

/* A decimal of 1 to `max_digits` random digits at a random power of ten, as a text. */
static void random_short_decimal(char *text, size_t size, int max_digits, int min_e, int max_e) {
    int digits = 1 + (int)(next_u64() % (uint64_t)max_digits);
    uint64_t m = 0;
    for (int i = 0; i < digits; i++)
        m = m * 10 + next_u64() % 10;
    int e = min_e + (int)(next_u64() % (uint64_t)(max_e - min_e + 1));
    snprintf(text, size, "%" PRIu64 "e%d", m, e);
}

static void check_specials(void) {
    static const struct {
        double v;
        const char *text;
    } fixed[] = {{0.0, "0"},
                 {-0.0, "-0"},
                 {1.0, "1"},
                 {0.1, "0.1"},
                 {100.0, "100"},
                 {1e15, "1e+15"},
                 {1e14, "100000000000000"},
                 {1e-4, "0.0001"},
                 {1e-5, "1e-05"},
                 {5e-324, "5e-324"},
                 {1.5, "1.5"},
                 {-2.25e-7, "-2.25e-07"},
                 {123456.75, "123456.75"}};
    for (size_t i = 0; i < sizeof fixed / sizeof *fixed; i++) {
        char text[RS_IO_PRINT_MAX + 1];
        text[rs_io_print_double(text, fixed[i].v)] = '\0';
        if (strcmp(text, fixed[i].text) != 0) {
            fprintf(stderr, "%a: printed '%s', expected '%s'\n", fixed[i].v, text, fixed[i].text);
            exit(1);
        }
    }
    char text[RS_IO_PRINT_MAX + 1];
    text[rs_io_print_double(text, INFINITY)] = '\0';
    CHECK(strcmp(text, "inf") == 0);
    text[rs_io_print_double(text, -INFINITY)] = '\0';
    CHECK(strcmp(text, "-inf") == 0);
    text[rs_io_print_double(text, NAN)] = '\0';
    CHECK(strcmp(text, "nan") == 0 || strcmp(text, "-nan") == 0);
    text[rs_io_print_float(text, -0.0f)] = '\0';
    CHECK(strcmp(text, "-0") == 0);
    text[rs_io_print_float(text, 16777216.0f)] = '\0';
    CHECK(strcmp(text, "16777216") == 0);
    text[rs_io_print_float(text, 0.1f)] = '\0';
    CHECK(strcmp(text, "0.1") == 0);

    static const double boundaries[] = {DBL_MIN,
                                        DBL_MAX,
                                        5e-324,
                                        9007199254740992.0,
                                        9007199254740993.0,
                                        9007199254740994.0,
                                        4503599627370496.0,
                                        1e23,
                                        8.41e21,
                                        5e-310,
                                        2.2250738585072011e-308,
                                        1.7976931348623157e308,
                                        FLT_MAX,
                                        FLT_MIN,
                                        1.4e-45,
                                        16777216.0,
                                        16777217.0,
                                        0.3,
                                        2.0 / 3.0,
                                        1e-7,
                                        9.5e-5,
                                        0.000123456789,
                                        123456789012345680.0,
                                        1e21,
                                        1e22,
                                        33554432.0,
                                        3.4028235677973366e38};
    for (size_t i = 0; i < sizeof boundaries / sizeof *boundaries; i++)
        check_around(boundaries[i]);
    check_float(FLT_TRUE_MIN);
    check_float(-FLT_TRUE_MIN);
    for (int e = -1074; e <= 1023; e++) /* powers of two: the closer lower neighbour */
        check_around(ldexp(1.0, e));
    for (int e = -323; e <= 308; e++) { /* powers of ten, as read from text */
        char t[16];
        snprintf(t, sizeof t, "1e%d", e);
        check_around(strtod(t, NULL));
        float f = strtof(t, NULL);
        if (f != 0 && isfinite(f))
            check_around((double)f);
    }
    for (uint64_t m = 1; m <= 300; m++) { /* integers and the first subnormals */
        check_around((double)m);
        check_around(ldexp((double)m, -1074));
        check_float(ldexpf((float)m, -149));
    }
}

/* Near rounding ties: the exact midpoint between a value and its upper neighbour (exact in long
 * double, or double for floats), rounded to a few lengths of decimal, read back and printed. */
static void check_ties(long count) {
    static const int lengths[] = {6, 7, 8, 9, 12, 15, 16, 17, 18, 21, 25};
    char text[64];
    for (long i = 0; i < count; i++) {
        double v = fabs(random_double()), up = nextafter(v, INFINITY);
        if (isfinite(up)) {
            long double mid = ((long double)v + (long double)up) / 2;
            for (size_t l = 0; l < sizeof lengths / sizeof *lengths; l++) {
                snprintf(text, sizeof text, "%.*Le", lengths[l], mid);
                check_around(strtod(text, NULL));
            }
        }
        float f = fabsf(random_float()), fu = nextafterf(f, INFINITY);
        if (isfinite(fu)) {
            double mid = ((double)f + (double)fu) / 2;
            for (size_t l = 0; l < 6; l++) {
                snprintf(text, sizeof text, "%.*e", lengths[l], mid);
                float back = strtof(text, NULL);
                if (isfinite(back)) {
                    check_float(back);
                    check_float(nextafterf(back, INFINITY));
                }
            }
        }
    }
}

static void check_integers(long count) {
    char text[24], oracle[24];
    uint64_t values[] = {0,
                         1,
                         9,
                         10,
                         99,
                         100,
                         101,
                         999,
                         1000,
                         4294967295u,
                         4294967296u,
                         UINT64_MAX,
                         UINT64_MAX / 10,
                         10000000000000000000u};
    for (size_t i = 0; i < sizeof values / sizeof *values; i++) {
        text[rs_io_print_u64(text, values[i])] = '\0';
        snprintf(oracle, sizeof oracle, "%" PRIu64, values[i]);
        CHECK(strcmp(text, oracle) == 0);
    }
    for (long i = 0; i < count; i++) {
        uint64_t v = next_u64() >> (next_u64() % 64);
        text[rs_io_print_u64(text, v)] = '\0';
        snprintf(oracle, sizeof oracle, "%" PRIu64, v);
        CHECK(strcmp(text, oracle) == 0);
    }
}

static double seconds(void) {
    return (double)clock() / CLOCKS_PER_SEC;
}

int main(int argc, char **argv) {
    /* scale 1: about 5 million values; under the sanitizers (test_small) a fifth of them */
    long scale = argc > 1 ? atol(argv[1]) : 1, divide = test_small() ? 5 : 1;
    double t0 = seconds();
    check_specials();
    check_integers(1000000 / divide);
    check_ties(5000 * scale / divide);
    double t1 = seconds();
    for (long i = 0; i < 1500000 * scale / divide; i++)
        check_double(random_double());
    double t2 = seconds();
    for (long i = 0; i < 1500000 * scale / divide; i++)
        check_float(random_float());
    double t3 = seconds();
    char text[64];
    for (long i = 0; i < 500000 * scale / divide; i++) {
        random_short_decimal(text, sizeof text, 17, -330, 310);
        double v = strtod(text, NULL);
        if (isfinite(v)) {
            check_double(v);
            check_g9(v);
        }
        random_short_decimal(text, sizeof text, 9, -50, 40);
        float f = strtof(text, NULL);
        if (isfinite(f))
            check_float(f);
    }
    double t4 = seconds();
    for (long i = 0; i < 200000 * scale / divide;
         i++) { /* unit-vector components, as normals are */
        double v = (double)(int64_t)next_u64() / 9223372036854775808.0;
        check_g9(v);
        check_g9(random_double());
    }
    double t5 = seconds();
    printf("float_print: %ld doubles (%ld also in the old %%.15g/%%.17g text), %ld floats (%ld in "
           "the old %%.6g/%%.9g text): all read back and all shortest; %ld powers of two a digit "
           "shorter than the shortest %%.{p}g that reads back\n",
           checked_double, old_format_double, checked_float, old_format_float,
           power_of_two_shorter);
    printf("seconds: specials, integers and ties %.1f, random doubles %.1f, random floats %.1f, "
           "short decimals %.1f, %%.9g %.1f\n",
           t1 - t0, t2 - t1, t3 - t2, t4 - t3, t5 - t4);
    return 0;
}
