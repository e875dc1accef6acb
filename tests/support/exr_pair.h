/* exr_pair.h — the two OpenEXR files the EXR comparison tools read (exr_equal, exr_error):
 * header-only. Thread-safety: any thread. */
#ifndef SY_TEST_EXR_PAIR_H
#define SY_TEST_EXR_PAIR_H

#include "sy_exr.h"

#include <stdio.h>

/* Reads path_a into *a and path_b into *b (both owned by the caller: sy_exr_image_free). Returns 0,
 * or 2, the tools' exit status for unreadable input, after printing "tool: reason" with nothing
 * left allocated. */
static inline int exr_read_pair(const char *tool, const char *path_a, const char *path_b, sy_exr_image **a,
                                sy_exr_image **b)
{
    sy_error e = {0};
    *a = *b = NULL;
    if (sy_exr_read(path_a, a, &e) != SY_OK || sy_exr_read(path_b, b, &e) != SY_OK) {
        fprintf(stderr, "%s: %s\n", tool, e.message);
        sy_exr_image_free(*a);
        *a = NULL;
        return 2;
    }
    return 0;
}

#endif /* SY_TEST_EXR_PAIR_H */
