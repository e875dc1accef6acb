/* sy_check.h — the one check kit of the C tests. Header-only; a test executable includes it in one
 * translation unit (the counters below are per translation unit).
 *
 * Two forms, each with the same variants:
 *
 *   CHECK...   fatal, like gtest's ASSERT: a failed check prints file:line, what failed and why,
 *              counts one failure and makes the enclosing function `return 1`. Use it in test
 *              functions returning int (0 = passed; RUN below) or in main, and wherever later
 *              steps depend on the checked value (a pointer that must not be NULL, a call that
 *              must succeed).
 *   EXPECT...  non-fatal, like gtest's EXPECT: a failed check prints the same, counts one failure
 *              and the function goes on, so one run reports every problem. Any function may use it.
 *
 *   X(cond)                  cond must hold
 *   X_MSG(cond, fmt, ...)    the same, plus a printf-style explanation (the values that mattered)
 *   X_OK(call, e)            call returns sy_result SY_OK; e is the sy_error it was given, whose
 *                            message is printed on failure
 *   X_ERR(call, code, e)     call returns exactly the sy_result `code`
 *   X_NEAR(a, b, eps)        |a - b| <= eps, compared as doubles (both values printed)
 *   X_SAYS(e, needle)        the sy_error e's message contains the string needle
 *
 * RUN(fn) runs a test function `int fn(void)` and prints "ok: fn" or "FAILED: fn"; a function that
 * returned non-zero or recorded a failed EXPECT failed. main ends with
 * `return sy_check_finish("name");`, which prints the summary and returns 1 when any check failed
 * (either form, counted in sy_check_failures), 0 otherwise. A test with no test functions uses the
 * checks in main directly and ends the same way. A test whose main only runs its test functions
 * writes none: SY_CHECK_MAIN("name", SY_TEST(fn1), SY_TEST(fn2), ...) is that main.
 *
 * A test's ctest fails on its exit status only: never print a failure without counting it. */
#ifndef SY_TEST_SY_CHECK_H
#define SY_TEST_SY_CHECK_H

#include <math.h>
#include <stdio.h>
#include <string.h>

/* The _OK / _ERR forms need sy_result (core); tests of a part without core (the filters, the
 * Embree or GL back-end alone) use the other forms. */
#if __has_include("sy_common.h")
#include "sy_common.h"
#endif

#define TEST_PI 3.14159265358979323846

/* Failed checks of either form (and test functions that failed without a check); checks run. */
static int sy_check_failures __attribute__((unused));
static int sy_check_count __attribute__((unused));

/* The one place a failure is reported: "file:line: CHECK failed: cond[: explanation]". */
#define SY_CHECK_REPORT_(kind, cond_text, ...)                                                      \
    do {                                                                                            \
        fprintf(stderr, "%s:%d: %s failed: %s", __FILE__, __LINE__, kind, cond_text);               \
        fprintf(stderr, __VA_ARGS__);                                                               \
        fputc('\n', stderr);                                                                        \
        sy_check_failures++;                                                                        \
    } while (0)

/* What a failed check does next: the fatal form returns, the non-fatal form goes on. */
#define SY_CHECK_FATAL_ return 1
#define SY_CHECK_GOON_ (void)0

/* The one place a check is counted and, when `ok` is false, reported (SY_CHECK_REPORT_ with the
 * printf-style tail) before `then`. The variants below evaluate their operands once, then call it. */
#define SY_CHECK_IF_(kind, then, ok, text, ...)                                                     \
    do {                                                                                            \
        sy_check_count++;                                                                           \
        if (!(ok)) {                                                                                \
            SY_CHECK_REPORT_(kind, text, __VA_ARGS__);                                              \
            then;                                                                                   \
        }                                                                                           \
    } while (0)

#define SY_CHECK_COND_(kind, then, cond, text) SY_CHECK_IF_(kind, then, cond, text, "%s", "")
#define SY_CHECK_COND_MSG_(kind, then, cond, text, ...) SY_CHECK_IF_(kind, then, cond, text ": ", __VA_ARGS__)

#define SY_CHECK_OK_(kind, then, call, text, e)                                                     \
    do {                                                                                            \
        sy_result sy_check_r_ = (call);                                                             \
        SY_CHECK_IF_(kind, then, sy_check_r_ == SY_OK, text, " -> %s (%s)", sy_result_str(sy_check_r_), (e).message); \
    } while (0)

#define SY_CHECK_ERR_(kind, then, call, text, code, e)                                              \
    do {                                                                                            \
        sy_result sy_check_r_ = (call);                                                             \
        SY_CHECK_IF_(kind, then, sy_check_r_ == (code), text, " -> %s, expected %s (%s)",           \
                     sy_result_str(sy_check_r_), sy_result_str(code), sy_check_r_ ? (e).message : ""); \
    } while (0)

#define SY_CHECK_NEAR_(kind, then, a, b, ta, tb, eps)                                               \
    do {                                                                                            \
        double sy_check_a_ = (double)(a), sy_check_b_ = (double)(b);                                \
        SY_CHECK_IF_(kind, then, fabs(sy_check_a_ - sy_check_b_) <= (eps), ta " ~ " tb,             \
                     ": %s = %.9g, %s = %.9g (eps %g)", ta, sy_check_a_, tb, sy_check_b_, (double)(eps)); \
    } while (0)

#define SY_CHECK_SAYS_(kind, then, e, needle, te, tn)                                               \
    SY_CHECK_IF_(kind, then, strstr((e).message, (needle)) != NULL, te " says " tn, ": '%s' lacks '%s'", \
                 (e).message, (needle))

/* Fatal: the enclosing function returns 1. */
#define CHECK(cond) SY_CHECK_COND_("CHECK", SY_CHECK_FATAL_, cond, #cond)
#define CHECK_MSG(cond, ...) SY_CHECK_COND_MSG_("CHECK", SY_CHECK_FATAL_, cond, #cond, __VA_ARGS__)
#define CHECK_OK(call, e) SY_CHECK_OK_("CHECK_OK", SY_CHECK_FATAL_, call, #call, e)
#define CHECK_ERR(call, code, e) SY_CHECK_ERR_("CHECK_ERR", SY_CHECK_FATAL_, call, #call, code, e)
#define CHECK_NEAR(a, b, eps) SY_CHECK_NEAR_("CHECK_NEAR", SY_CHECK_FATAL_, a, b, #a, #b, eps)
#define CHECK_SAYS(e, needle) SY_CHECK_SAYS_("CHECK_SAYS", SY_CHECK_FATAL_, e, needle, #e, #needle)

/* Non-fatal: counted, the function goes on. */
#define EXPECT(cond) SY_CHECK_COND_("EXPECT", SY_CHECK_GOON_, cond, #cond)
#define EXPECT_MSG(cond, ...) SY_CHECK_COND_MSG_("EXPECT", SY_CHECK_GOON_, cond, #cond, __VA_ARGS__)
#define EXPECT_OK(call, e) SY_CHECK_OK_("EXPECT_OK", SY_CHECK_GOON_, call, #call, e)
#define EXPECT_ERR(call, code, e) SY_CHECK_ERR_("EXPECT_ERR", SY_CHECK_GOON_, call, #call, code, e)
#define EXPECT_NEAR(a, b, eps) SY_CHECK_NEAR_("EXPECT_NEAR", SY_CHECK_GOON_, a, b, #a, #b, eps)
#define EXPECT_SAYS(e, needle) SY_CHECK_SAYS_("EXPECT_SAYS", SY_CHECK_GOON_, e, needle, #e, #needle)

/* Runs `int fn(void)`, printing "ok: name" or "FAILED: name"; it failed when it returned non-zero
 * or any check failed while it ran. */
static inline void sy_check_run(const char *name, int (*fn)(void))
{
    int before = sy_check_failures;
    int rc = fn();
    if (rc != 0 || sy_check_failures != before) {
        if (sy_check_failures == before) sy_check_failures++;
        fprintf(stderr, "FAILED: %s\n", name);
    } else {
        printf("ok: %s\n", name);
    }
}

#define RUN(fn) sy_check_run(#fn, (fn))

/* The end of main: prints "name: N of M check(s) failed" (stderr) or "name: all M checks passed"
 * and returns the exit status, 1 when any check failed. */
static inline int sy_check_finish(const char *name)
{
    if (sy_check_failures) {
        fprintf(stderr, "%s: %d of %d check(s) failed\n", name, sy_check_failures, sy_check_count);
        return 1;
    }
    printf("%s: all %d checks passed\n", name, sy_check_count);
    return 0;
}

/* A test executable's functions, for SY_CHECK_MAIN: SY_TEST(fn) names `int fn(void)` by itself. */
typedef struct sy_check_test {
    const char *name;
    int (*fn)(void);
} sy_check_test;

#define SY_TEST(fn) {#fn, (fn)}

/* The whole main of a test executable that only runs its test functions: each in order, as RUN,
 * then `return sy_check_finish(title)`. Write it at file scope, without a semicolon:
 *   SY_CHECK_MAIN("test_blob", SY_TEST(test_hash), SY_TEST(test_store)) */
#define SY_CHECK_MAIN(title, ...)                                                                   \
    int main(void)                                                                                  \
    {                                                                                               \
        static const sy_check_test sy_check_tests_[] = {__VA_ARGS__};                               \
        for (size_t i = 0; i < sizeof sy_check_tests_ / sizeof sy_check_tests_[0]; i++)            \
            sy_check_run(sy_check_tests_[i].name, sy_check_tests_[i].fn);                           \
        return sy_check_finish(title);                                                              \
    }

/* A test function with a fixture (gtest's TEST_F), for RUN / SY_CHECK_MAIN:
 *   SY_FIXTURE_TEST(test_x, my_fixture, my_setup, my_teardown)
 *   {
 *       ... uses `my_fixture *f` ...
 *       return 0;
 *   }
 * defines `int test_x(void)`: a zeroed my_fixture, `int my_setup(my_fixture *)` (0 = ready; its
 * checks count), the body when it succeeded, then `void my_teardown(my_fixture *)` always (also
 * after a failed setup or body, so it must accept a partly set-up fixture). */
#define SY_FIXTURE_TEST(name, type, setup, teardown)                                                \
    static int name##_body(type *f);                                                                \
    static int name(void)                                                                           \
    {                                                                                               \
        type sy_fixture_ = {0};                                                                     \
        int sy_fixture_rc_ = (setup)(&sy_fixture_);                                                 \
        if (sy_fixture_rc_ == 0) sy_fixture_rc_ = name##_body(&sy_fixture_);                        \
        (teardown)(&sy_fixture_);                                                                   \
        return sy_fixture_rc_;                                                                      \
    }                                                                                               \
    static int name##_body(type *f)

#endif /* SY_TEST_SY_CHECK_H */
