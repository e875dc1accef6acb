/* gl_test.h — what the GL back-end's tests share: the check kit (tests/support/sy_check.h; the
 * tests use its counted EXPECT form and end with sy_check_finish), the buffer `e` that holds the
 * message of the last failed call (gl_test_on_error, the error callback every test device gets with
 * GL_TEST_REPORT in its desc) and MUST (a sy_gl call that must succeed; exit 1 otherwise). */
#ifndef SY_TEST_GL_TEST_H
#define SY_TEST_GL_TEST_H

#include "../support/sy_check.h"

#include <stdio.h>
#include <stdlib.h>

#include "sy_gl.h"

static char e[4096];
static inline void gl_test_on_error(void *user, sy_gl_result code, const char *message)
{
    (void)user, (void)code;
    snprintf(e, sizeof e, "%s", message);
}
/* in a sy_gl_device_desc initialiser: report errors into e */
#define GL_TEST_REPORT .error = gl_test_on_error

#define MUST(call)                                                                                 \
    do {                                                                                           \
        sy_gl_result r_ = (call);                                                                  \
        if (r_ != SY_GL_OK) {                                                                      \
            fprintf(stderr, "%s:%d: %s failed (%d): %s\n", __FILE__, __LINE__, #call, (int)r_, e); \
            exit(1);                                                                               \
        }                                                                                          \
    } while (0)

#endif /* SY_TEST_GL_TEST_H */
