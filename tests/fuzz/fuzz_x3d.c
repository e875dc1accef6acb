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
    o.max_file_bytes = 1u << 20;
    o.max_vertices = 1u << 18;
    o.max_image_pixels = 1u << 18;
    o.max_inline_depth = 4;
    o.max_scene_bytes = (uint64_t)64 << 20; /* the file budget, small like the other limits */
    sy_x3d_info info = {0};
    sy_error err = {0};
    if (sy_x3d_load_memory(data, size, "fuzz.x3d", fuzz_resource_dir(), s, &o, &info, &err) == SY_OK)
        sy_scene_commit(s, NULL, NULL);
    sy_x3d_info_free(&info);
    sy_scene_destroy(s);
    return 0;
}
