/* fuzz_glb.c — libFuzzer target for the binary glTF container (.glb): the input is loaded from
 * memory as a .glb (header, chunk table, JSON chunk, BIN chunk as buffer 0). Mutations that change
 * the size would always fail the header's total-length check, so when the input is at least a
 * header long, a copy with the total length set to the input size is loaded as well (the chunk
 * lengths stay as mutated). External URIs resolve in fuzz_resource_dir(). */
#include "fuzz_util.h"
#include "sy_gltf.h"

#include <string.h>

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size);

static void load(const unsigned char *data, size_t size)
{
    sy_scene *s;
    if (sy_scene_create(&s, NULL) != SY_OK) return;
    sy_gltf_options o = {0};
    o.max_file_bytes = 1u << 20;
    o.max_vertices = 1u << 18;
    o.max_indices = 1u << 19;
    o.max_image_pixels = 1u << 18;
    o.max_instances = 1u << 12;
    sy_gltf_info info = {0};
    sy_error err = {0};
    if (sy_gltf_load_memory(data, size, "fuzz.glb", fuzz_resource_dir(), s, &o, &info, &err) == SY_OK)
        sy_scene_commit(s, NULL, NULL);
    sy_gltf_info_free(&info);
    sy_scene_destroy(s);
}

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size)
{
    if (size < 12 || size > 0xffffffffu) {
        load(data, size);
        return 0;
    }
    uint32_t len = (uint32_t)data[8] | (uint32_t)data[9] << 8 | (uint32_t)data[10] << 16 | (uint32_t)data[11] << 24;
    if (len != size) {
        load(data, size); /* the header check itself */
        unsigned char *copy = malloc(size);
        if (!copy) return 0;
        memcpy(copy, data, size);
        copy[8] = (unsigned char)size;
        copy[9] = (unsigned char)(size >> 8);
        copy[10] = (unsigned char)(size >> 16);
        copy[11] = (unsigned char)(size >> 24);
        load(copy, size);
        free(copy);
        return 0;
    }
    load(data, size);
    return 0;
}
