/* fuzz_gltf.c — libFuzzer target for the glTF loader: each input is written to a scratch file
 * (.glb when it starts with the GLB magic, else .gltf) and loaded into a fresh scene with small
 * limits; any result code is fine, crashes, leaks, hangs and sanitizer reports are not. External
 * URIs resolve inside the empty scratch directory. */
#include "fuzz_util.h"
#include "sy_gltf.h"

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size);

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size)
{
    const char *p = fuzz_write_input(data, size, size >= 4 && !memcmp(data, "glTF", 4) ? ".glb" : ".gltf");
    if (!p) return 0;
    sy_scene *s;
    if (sy_scene_create(&s, NULL) != SY_OK) return 0;
    sy_gltf_options o = {0};
    o.max_file_bytes = 1u << 24;
    o.max_vertices = 1u << 20;
    o.max_indices = 1u << 21;
    o.max_image_pixels = 1u << 20;
    o.max_instances = 1u << 12;
    sy_gltf_info info = {0};
    sy_error err = {0};
    if (sy_gltf_load(p, s, &o, &info, &err) == SY_OK) sy_scene_commit(s, NULL, NULL);
    sy_gltf_info_free(&info);
    sy_scene_destroy(s);
    return 0;
}
