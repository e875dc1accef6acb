/* check.h — the tiny assertion kit of the core tests.
 *
 * Every test function returns int (0 = passed). CHECK(expr) prints file:line and the failed
 * expression and makes the enclosing function return 1; the CHECK_OK / CHECK_ERR forms also print
 * the sy_error message. RUN(fn) in main() runs one test function and counts failures. */
#ifndef SY_TEST_CHECK_H
#define SY_TEST_CHECK_H

#include <math.h>
#include <stdio.h>

#include "sy_common.h"

#define TEST_PI 3.14159265358979323846

#define CHECK(expr)                                                                 \
    do {                                                                            \
        if (!(expr)) {                                                              \
            fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #expr); \
            return 1;                                                               \
        }                                                                           \
    } while (0)

/* Like CHECK, plus a printf-style explanation. */
#define CHECK_MSG(expr, ...)                                                        \
    do {                                                                            \
        if (!(expr)) {                                                              \
            fprintf(stderr, "%s:%d: CHECK failed: %s: ", __FILE__, __LINE__, #expr); \
            fprintf(stderr, __VA_ARGS__);                                           \
            fputc('\n', stderr);                                                    \
            return 1;                                                               \
        }                                                                           \
    } while (0)

/* A call returning sy_result must succeed; `e` is the sy_error it was given. */
#define CHECK_OK(call, e)                                                                             \
    do {                                                                                              \
        sy_result check_r_ = (call);                                                                  \
        if (check_r_ != SY_OK) {                                                                      \
            fprintf(stderr, "%s:%d: CHECK_OK failed: %s -> %s (%s)\n", __FILE__, __LINE__, #call,     \
                    sy_result_str(check_r_), (e).message);                                            \
            return 1;                                                                                 \
        }                                                                                             \
    } while (0)

/* A call returning sy_result must fail with exactly `code`. */
#define CHECK_ERR(call, code, e)                                                                      \
    do {                                                                                              \
        sy_result check_r_ = (call);                                                                  \
        if (check_r_ != (code)) {                                                                     \
            fprintf(stderr, "%s:%d: CHECK_ERR failed: %s -> %s, expected %s (%s)\n", __FILE__, __LINE__, \
                    #call, sy_result_str(check_r_), sy_result_str(code),                              \
                    check_r_ ? (e).message : "");                                                     \
            return 1;                                                                                 \
        }                                                                                             \
    } while (0)

#define CHECK_NEAR(a, b, eps)                                                                          \
    do {                                                                                               \
        double check_a_ = (double)(a), check_b_ = (double)(b);                                         \
        if (!(fabs(check_a_ - check_b_) <= (eps))) {                                                   \
            fprintf(stderr, "%s:%d: CHECK_NEAR failed: %s = %.9g, %s = %.9g (eps %g)\n", __FILE__,     \
                    __LINE__, #a, check_a_, #b, check_b_, (double)(eps));                              \
            return 1;                                                                                  \
        }                                                                                              \
    } while (0)

#define RUN(fn)                                                       \
    do {                                                              \
        if ((fn)() != 0) {                                            \
            fprintf(stderr, "FAILED: %s\n", #fn);                     \
            failures++;                                               \
        } else {                                                      \
            printf("ok: %s\n", #fn);                                  \
        }                                                             \
    } while (0)

#endif /* SY_TEST_CHECK_H */
