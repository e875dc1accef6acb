/* fuzz_exr.c — libFuzzer target for the OpenEXR reader, from memory (sy_exr_read_memory) with
 * limits small enough that no input can ask for more than 64 MiB of planes. */
#include "sy_exr.h"

#include <stddef.h>

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size);

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size)
{
    sy_exr_image *img = NULL;
    sy_error err = {0};
    sy_exr_read_options o = {.max_pixels = 1u << 22, .max_samples = (size_t)1 << 24};
    if (sy_exr_read_memory(data, size, "fuzz.exr", &o, &img, &err) == SY_OK) {
        volatile float sink = 0;
        for (int c = 0; c < img->channel_count; c++)
            sink += img->channels[c].data[(size_t)img->width * (size_t)img->height - 1];
        (void)sink;
    }
    sy_exr_image_free(img);
    return 0;
}
