/* fuzz_x3d.c — libFuzzer target for the X3D loader, from memory; relative URLs (Inline,
 * ImageTexture) resolve in fuzz_resource_dir(). */
#include "fuzz_util.h"
#include "sy_x3d.h"

#include <stddef.h>

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size);

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size)
{
    sy_scene *s;
    if (sy_scene_create(&s, NULL) != SY_OK) return 0;
    sy_x3d_options o = {0};
    FUZZ_LIMITS(o);
    o.max_inline_depth = 4;
    sy_x3d_info info = {0};
    sy_error err = {0};
    sy_result r = sy_x3d_load_memory(data, size, "fuzz.x3d", fuzz_resource_dir(), s, &o, &info, &err);
    sy_x3d_info_free(&info);
    FUZZ_COMMIT_AND_DESTROY(s, r);
    return 0;
}
