/* fuzz_glb.c — libFuzzer target for the binary glTF container (.glb): the input is loaded from
 * memory as a .glb (header, chunk table, JSON chunk, BIN chunk as buffer 0). Mutations that change
 * the size would always fail the header's total-length check, so when the input is at least a
 * header long, a copy with the total length set to the input size is loaded as well (the chunk
 * lengths stay as mutated). External URIs resolve in fuzz_resource_dir(). */
#define SY_FUZZ_GLTF
#include "fuzz_util.h"

#include <string.h>

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size);

static void load(const unsigned char *data, size_t size)
{
    fuzz_load_gltf(data, size, "fuzz.glb");
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
