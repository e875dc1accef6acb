/* fuzz_cull_query.c — libFuzzer target for the body of POST /api/cull (sy_cull_parse_query, which
 * checks the view with sy_cull_view_check: positions within SY_COORD_MAX, a nonzero quaternion,
 * fov and sizes in range): each input is one body (at most 64 KiB). A view it accepts is turned
 * into the back-ends' camera (sy_cull_view_camera), whose matrix must be finite. */
#include "sy_cull.h"

#include <math.h>
#include <stdlib.h>

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size);

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size)
{
    sy_cull_view v;
    uint64_t budget;
    if (sy_cull_parse_query((const char *)data, size, &v, &budget, NULL) != SY_OK) return 0;
    sy_camera_view cv = sy_cull_view_camera(&v);
    for (int i = 0; i < 16; ++i)
        if (!isfinite(cv.camera_to_world.m[i]) || fabsf(cv.camera_to_world.m[i]) > 2 * SY_COORD_MAX) abort();
    return 0;
}
