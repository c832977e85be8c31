/* Checks for the test programs: always on (no assert, which release builds compile out), each
 * failure printing the file, line and both values. A test returns 0 on success, 77 to be skipped.
 */
#ifndef RSMOOTH_TEST_UTIL_H
#define RSMOOTH_TEST_UTIL_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#define TEST_SKIP 77

/* A smoothing call's optional outputs (rsmooth_outputs: weights, confidence, report), for the
 * tests that give them in one argument. */
#define OUTPUTS(weight, confidence, report)                                                        \
    (&(rsmooth_outputs){sizeof(rsmooth_outputs), (weight), (confidence), (report)})

/* Smaller cases of the same checks: tests/CMakeLists.txt sets RSMOOTH_TEST_SMALL=1 for every test
 * of a sanitizer build (RSMOOTH_SANITIZE), where host code runs 5-15 times slower. A test then
 * makes its meshes and repeats smaller, never its assertions fewer or weaker; the plain build runs
 * the full sizes. Setting it by hand runs a plain build's tests small too. */
static inline int test_small(void) {
    const char *small = getenv("RSMOOTH_TEST_SMALL");
    return small && small[0] == '1' && small[1] == '\0';
}

#define CHECK(cond)                                                                                \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond);               \
            exit(1);                                                                               \
        }                                                                                          \
    } while (0)

#define CHECK_EQ_INT(a, b)                                                                         \
    do {                                                                                           \
        long long check_a_ = (long long)(a), check_b_ = (long long)(b);                            \
        if (check_a_ != check_b_) {                                                                \
            fprintf(stderr, "%s:%d: CHECK_EQ_INT failed: %s = %lld, %s = %lld\n", __FILE__,        \
                    __LINE__, #a, check_a_, #b, check_b_);                                         \
            exit(1);                                                                               \
        }                                                                                          \
    } while (0)

#define CHECK_NEAR(a, b, tol)                                                                      \
    do {                                                                                           \
        double check_a_ = (double)(a), check_b_ = (double)(b), check_t_ = (double)(tol);           \
        if (!(fabs(check_a_ - check_b_) <= check_t_)) {                                            \
            fprintf(stderr, "%s:%d: CHECK_NEAR failed: %s = %.17g, %s = %.17g, tol %g\n",          \
                    __FILE__, __LINE__, #a, check_a_, #b, check_b_, check_t_);                     \
            exit(1);                                                                               \
        }                                                                                          \
    } while (0)

/* a <= b, printing both. */
#define CHECK_LE(a, b)                                                                             \
    do {                                                                                           \
        double check_a_ = (double)(a), check_b_ = (double)(b);                                     \
        if (!(check_a_ <= check_b_)) {                                                             \
            fprintf(stderr, "%s:%d: CHECK_LE failed: %s = %.9g > %s = %.9g\n", __FILE__, __LINE__, \
                    #a, check_a_, #b, check_b_);                                                   \
            exit(1);                                                                               \
        }                                                                                          \
    } while (0)

#define CHECK_STATUS(expr, expected)                                                               \
    do {                                                                                           \
        int check_s_ = (int)(expr), check_e_ = (int)(expected);                                    \
        if (check_s_ != check_e_) {                                                                \
            fprintf(stderr, "%s:%d: %s returned status %d, expected %d\n", __FILE__, __LINE__,     \
                    #expr, check_s_, check_e_);                                                    \
            exit(1);                                                                               \
        }                                                                                          \
    } while (0)

#endif
