/* smoke_stats.c — test helper for the smoke test (smoke_test.sh): what one render shows. Reads an
 * OpenEXR file that `sy render` wrote and prints
 *   covered C mean M
 * C: the fraction of pixels where something was hit (alpha > 0; every pixel when the file has no
 * alpha), M: the mean luminance (Rec. 709, linear) over those pixels (0 when none is covered).
 *   smoke_stats IMAGE.exr
 * Exit status: 0 after printing, 2 on bad arguments or an unreadable file, or one without R, G, B
 * or with a non-finite pixel (printed as the reason). */
#include "sy_exr.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static const float *plane(const sy_exr_image *im, const char *name)
{
    for (int i = 0; i < im->channel_count; ++i)
        if (!strcmp(im->channels[i].name, name)) return im->channels[i].data;
    return NULL;
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: smoke_stats IMAGE.exr\n");
        return 2;
    }
    sy_exr_image *im = NULL;
    sy_error e = {0};
    if (sy_exr_read(argv[1], &im, &e) != SY_OK) {
        fprintf(stderr, "smoke_stats: %s: %s\n", argv[1], e.message);
        return 2;
    }
    const float *r = plane(im, "R"), *g = plane(im, "G"), *b = plane(im, "B"), *a = plane(im, "A");
    if (!r || !g || !b) {
        fprintf(stderr, "smoke_stats: %s: no R, G, B channels\n", argv[1]);
        sy_exr_image_free(im);
        return 2;
    }
    size_t n = (size_t)im->width * (size_t)im->height, covered = 0;
    double sum = 0.0;
    int status = 0;
    for (size_t i = 0; i < n; ++i) {
        if (!isfinite(r[i]) || !isfinite(g[i]) || !isfinite(b[i]) || (a && !isfinite(a[i]))) {
            fprintf(stderr, "smoke_stats: %s: pixel %zu is not finite\n", argv[1], i);
            status = 2;
            break;
        }
        if (a && !(a[i] > 0.0f)) continue;
        covered++;
        sum += 0.2126 * r[i] + 0.7152 * g[i] + 0.0722 * b[i];
    }
    if (status == 0)
        printf("covered %.4f mean %.4f\n", n ? (double)covered / (double)n : 0.0, covered ? sum / (double)covered : 0.0);
    sy_exr_image_free(im);
    return status;
}
