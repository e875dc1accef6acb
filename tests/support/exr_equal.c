/* exr_equal.c — test helper: exit 0 when two OpenEXR files hold the same size, the same channels and
 * bit-identical pixels (headers may differ: sy render records the back-end and the render time).
 *   exr_equal A.exr B.exr */
#include "exr_pair.h"

#include <stdio.h>
#include <string.h>

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: exr_equal A.exr B.exr\n");
        return 2;
    }
    sy_exr_image *a = NULL, *b = NULL;
    if (exr_read_pair("exr_equal", argv[1], argv[2], &a, &b)) return 2;
    int rc = 0;
    if (a->width != b->width || a->height != b->height || a->channel_count != b->channel_count) {
        fprintf(stderr, "exr_equal: %dx%d with %d channels against %dx%d with %d\n", a->width, a->height,
                a->channel_count, b->width, b->height, b->channel_count);
        rc = 1;
    }
    size_t n = (size_t)a->width * (size_t)a->height;
    for (int c = 0; rc == 0 && c < a->channel_count; ++c) {
        if (strcmp(a->channels[c].name, b->channels[c].name) != 0 ||
            memcmp(a->channels[c].data, b->channels[c].data, n * sizeof(float)) != 0) {
            fprintf(stderr, "exr_equal: channel %s differs\n", a->channels[c].name);
            rc = 1;
        }
    }
    sy_exr_image_free(a);
    sy_exr_image_free(b);
    return rc;
}
