/* fuzz_gltf.c — libFuzzer target for the glTF loader (JSON .gltf; GLB inputs are recognised by
 * their magic too, fuzz_glb.c concentrates on the container): each input is loaded from memory
 * into a fresh scene with small limits; any result code is fine, crashes, leaks, hangs and
 * sanitizer reports are not. External URIs resolve in fuzz_resource_dir(). */
#include "fuzz_util.h"
#include "sy_gltf.h"

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size);

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size)
{
    sy_scene *s;
    if (sy_scene_create(&s, NULL) != SY_OK) return 0;
    sy_gltf_options o = {0};
    o.max_file_bytes = 1u << 20;
    o.max_vertices = 1u << 18;
    o.max_indices = 1u << 19;
    o.max_image_pixels = 1u << 18;
    o.max_instances = 1u << 12;
    sy_gltf_info info = {0};
    sy_error err = {0};
    if (sy_gltf_load_memory(data, size, "fuzz.gltf", fuzz_resource_dir(), s, &o, &info, &err) == SY_OK)
        sy_scene_commit(s, NULL, NULL);
    sy_gltf_info_free(&info);
    sy_scene_destroy(s);
    return 0;
}
