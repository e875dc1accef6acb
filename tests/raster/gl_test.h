/* gl_test.h — what the GL back-end's tests share: the check kit (tests/support/sy_check.h; the
 * tests use its counted EXPECT form and end with sy_check_finish) and MUST (a sy_gl call that must succeed; its message is in the
 * caller's char buffer `e`; exit 1 otherwise). */
#ifndef SY_TEST_GL_TEST_H
#define SY_TEST_GL_TEST_H

#include "../support/sy_check.h"

#include <stdio.h>
#include <stdlib.h>

#define MUST(call)                                                                                 \
    do {                                                                                           \
        sy_gl_result r_ = (call);                                                                  \
        if (r_ != SY_GL_OK) {                                                                      \
            fprintf(stderr, "%s:%d: %s failed (%d): %s\n", __FILE__, __LINE__, #call, (int)r_, e); \
            exit(1);                                                                               \
        }                                                                                          \
    } while (0)

#endif /* SY_TEST_GL_TEST_H */
