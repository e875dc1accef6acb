/* fuzz_web_frame.c — libFuzzer target for sy web's binary frames as a client reads them
 * (sy_web_frame_parse, then sy_web_frame_depth on a frame with a depth channel: the grid's
 * inflate, the 12-bit check, the interpolation to every pixel). Any result code is fine; crashes
 * and sanitizer reports are not. */
#include "sy_web_frame.h"

#include <stdlib.h>

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size);

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size)
{
    sy_web_frame_info fi;
    const uint8_t *payload = NULL, *depth = NULL;
    if (sy_web_frame_parse(data, size, &fi, &payload, &depth, NULL) == SY_OK && fi.depth_len) {
        float *d = NULL;
        if (sy_web_frame_depth(&fi, depth, &d, NULL) == SY_OK) free(d);
    }
    return 0;
}
