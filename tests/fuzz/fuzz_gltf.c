/* fuzz_gltf.c — libFuzzer target for the glTF loader (JSON .gltf; GLB inputs are recognised by
 * their magic too, fuzz_glb.c concentrates on the container): each input is loaded from memory
 * into a fresh scene with small limits; any result code is fine, crashes, leaks, hangs and
 * sanitizer reports are not. External URIs resolve in fuzz_resource_dir(). */
#define SY_FUZZ_GLTF
#include "fuzz_util.h"

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size);

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size)
{
    fuzz_load_gltf(data, size, "fuzz.gltf");
    return 0;
}
