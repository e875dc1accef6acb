/* gl_test.h — what the GL back-end's tests share: CHECK (counted in `failures`, the run goes on;
 * tests/support/check_count.h) and MUST (a sy_gl call that must succeed; its message is in the
 * caller's char buffer `e`; exit 1 otherwise). */
#ifndef SY_TEST_GL_TEST_H
#define SY_TEST_GL_TEST_H

#include "../support/check_count.h"

#include <stdio.h>
#include <stdlib.h>

static int failures;
#define CHECK(c, ...) SY_CHECK_COUNT(failures, c, __VA_ARGS__)
#define MUST(call)                                                                                 \
    do {                                                                                           \
        sy_gl_result r_ = (call);                                                                  \
        if (r_ != SY_GL_OK) {                                                                      \
            fprintf(stderr, "%s:%d: %s failed (%d): %s\n", __FILE__, __LINE__, #call, (int)r_, e); \
            exit(1);                                                                               \
        }                                                                                          \
    } while (0)

#endif /* SY_TEST_GL_TEST_H */
