/* fuzz_exr.c — libFuzzer target for the OpenEXR reader (input written to a scratch .exr file). */
#include "fuzz_util.h"
#include "sy_exr.h"

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size);

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size)
{
    const char *p = fuzz_write_input(data, size, ".exr");
    if (!p) return 0;
    sy_exr_image *img = NULL;
    sy_error err = {0};
    if (sy_exr_read(p, &img, &err) == SY_OK) {
        volatile float sink = 0;
        for (int c = 0; c < img->channel_count; c++)
            sink += img->channels[c].data[(size_t)img->width * (size_t)img->height - 1];
        (void)sink;
    }
    sy_exr_image_free(img);
    return 0;
}
