/* png_ssim.c — test helper: SSIM (Wang et al. 2004, sy_filter_ssim_gray) of PNG images against
 * references of the same size, on the Rec. 709 luma of the display-encoded colour (the 8-bit
 * values / 255, as sy bench stream measures its codecs). For the warp's estimate against the
 * server's true frame of the same view (tests/browser/browser_test.sh orbit, warp_orbit.sh).
 *   png_ssim [--min S] A.png REF.png [A2.png REF2.png ...]
 * Prints "ssim X A.png" per pair; exit 0 when every pair's SSIM is >= --min (default 0: always),
 * 1 otherwise, 2 on bad input (an unreadable file, sizes that differ, an odd count of files). */
#include "sy_filter_metrics.h"
#include "sy_png.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* the luma of an RGBA8 image, 0..1 (sy_filter_luma_rgba8); NULL when out of memory */
static float *luma(const uint8_t *px, size_t n)
{
    float *y = malloc(n * sizeof *y);
    if (y) sy_filter_luma_rgba8(px, n, y);
    return y;
}

int main(int argc, char **argv)
{
    double min = 0.0;
    int first = 1;
    if (argc > 2 && !strcmp(argv[1], "--min")) min = atof(argv[2]), first = 3;
    int np = argc - first;
    if (np < 2 || np % 2) {
        fprintf(stderr, "usage: png_ssim [--min S] A.png REF.png [A2.png REF2.png ...]\n");
        return 2;
    }
    int rc = 0;
    for (int i = first; i + 1 < argc && rc != 2; i += 2) {
        int w[2], h[2];
        uint8_t *px[2] = {NULL, NULL};
        float *y[2] = {NULL, NULL};
        sy_error e = {0};
        for (int k = 0; k < 2 && rc != 2; ++k)
            if (sy_png_read_rgba8(argv[i + k], &w[k], &h[k], &px[k], &e) != SY_OK) {
                fprintf(stderr, "png_ssim: %s\n", e.message);
                rc = 2;
            }
        if (rc != 2 && (w[0] != w[1] || h[0] != h[1])) {
            fprintf(stderr, "png_ssim: %s is %dx%d, %s is %dx%d\n", argv[i], w[0], h[0], argv[i + 1], w[1], h[1]);
            rc = 2;
        }
        size_t n = rc == 2 ? 0 : (size_t)w[0] * (size_t)h[0];
        if (rc != 2 && (!(y[0] = luma(px[0], n)) || !(y[1] = luma(px[1], n)))) {
            fprintf(stderr, "png_ssim: out of memory\n");
            rc = 2;
        }
        if (rc != 2) {
            double s = sy_filter_ssim_gray(y[0], y[1], (uint32_t)w[0], (uint32_t)h[0]);
            printf("ssim %.4f %s\n", s, argv[i]);
            if (!(s >= min)) {
                fprintf(stderr, "png_ssim: %s against %s: SSIM %.4f < %.4f\n", argv[i], argv[i + 1], s, min);
                rc = 1;
            }
        }
        free(px[0]), free(px[1]), free(y[0]), free(y[1]);
    }
    return rc;
}
