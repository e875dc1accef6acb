/* check_count.h — the counting check shared by tests that report every failed check of a run:
 * SY_CHECK_COUNT(counter, cond, fmt, ...) prints file:line, the condition and a printf-style
 * explanation when cond is false, adds one to counter and goes on. A test defines its CHECK on top
 * of it with its own counter (tests/core/check.h is the other kit: a failed check returns 1). */
#ifndef SY_TEST_CHECK_COUNT_H
#define SY_TEST_CHECK_COUNT_H

#include <stdio.h>

#define SY_CHECK_COUNT(counter, cond, ...)                                          \
    do {                                                                            \
        if (!(cond)) {                                                              \
            fprintf(stderr, "%s:%d: CHECK failed: %s: ", __FILE__, __LINE__, #cond); \
            fprintf(stderr, __VA_ARGS__);                                           \
            fputc('\n', stderr);                                                    \
            (counter)++;                                                            \
        }                                                                           \
    } while (0)

#endif /* SY_TEST_CHECK_COUNT_H */
