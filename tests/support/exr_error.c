/* exr_error.c — measurement helper: the error of an OpenEXR image against a reference of the same
 * size (tests/cycles/equal_error.sh). Prints one line:
 *   relmse R rmse E ssim S mean_ratio M
 * relMSE, RMSE and SSIM as backends/filters/sy_filter_metrics.h defines them (relMSE: mean over
 * pixels and RGB of (x - y)^2 / (y^2 + 0.01)); mean_ratio: the image's mean RGB over the
 * reference's. With --blocks N, then N rows of N numbers: the relMSE of each block of an N x N grid
 * (where the error is). Exit 0, or 2 with a message on unreadable or mismatched files.
 *   exr_error IMAGE.exr REFERENCE.exr [--blocks N] */
#include "exr_pair.h"
#include "sy_filter_metrics.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Interleaved RGB of an image with R, G and B channels; NULL with a message otherwise. */
static float *rgb_of(const sy_exr_image *img, const char *path)
{
    const float *c[3] = {sy_exr_image_channel(img, "R"), sy_exr_image_channel(img, "G"), sy_exr_image_channel(img, "B")};
    if (!c[0] || !c[1] || !c[2]) {
        fprintf(stderr, "exr_error: %s: no R, G and B channels\n", path);
        return NULL;
    }
    size_t n = (size_t)img->width * (size_t)img->height;
    float *rgb = malloc(3 * n * sizeof *rgb);
    if (!rgb) {
        fprintf(stderr, "exr_error: %s: out of memory\n", path);
        return NULL;
    }
    for (size_t i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k) rgb[3 * i + (size_t)k] = c[k][i];
    return rgb;
}

int main(int argc, char **argv)
{
    int blocks = argc == 5 && !strcmp(argv[3], "--blocks") ? atoi(argv[4]) : 0;
    if ((argc != 3 && argc != 5) || (argc == 5 && (blocks < 1 || blocks > 64))) {
        fprintf(stderr, "usage: exr_error IMAGE.exr REFERENCE.exr [--blocks N (1..64)]\n");
        return 2;
    }
    sy_exr_image *a = NULL, *b = NULL;
    if (exr_read_pair("exr_error", argv[1], argv[2], &a, &b)) return 2;
    int rc = 2;
    float *x = NULL, *y = NULL;
    if (a->width != b->width || a->height != b->height) {
        fprintf(stderr, "exr_error: %s is %dx%d but %s is %dx%d\n", argv[1], a->width, a->height, argv[2], b->width,
                b->height);
        goto done;
    }
    if (!(x = rgb_of(a, argv[1])) || !(y = rgb_of(b, argv[2]))) goto done;
    sy_filter_metrics m;
    sy_filter_report fe = {0};
    if (sy_filter_metrics_compute(x, y, (uint32_t)a->width, (uint32_t)a->height, 3, &m, &fe) != SY_FILTER_OK) {
        fprintf(stderr, "exr_error: %s\n", fe.message);
        goto done;
    }
    double sx = 0.0, sy = 0.0;
    for (size_t i = 0; i < 3 * (size_t)a->width * (size_t)a->height; ++i) sx += x[i], sy += y[i];
    printf("relmse %.6g rmse %.6g ssim %.6f mean_ratio %.5f\n", m.relmse, m.rmse, m.ssim, sy > 0.0 ? sx / sy : 0.0);
    for (int by = 0; by < blocks; ++by) {
        for (int bx = 0; bx < blocks; ++bx) {
            int x0 = bx * a->width / blocks, x1 = (bx + 1) * a->width / blocks;
            int y0 = by * a->height / blocks, y1 = (by + 1) * a->height / blocks;
            double rel = 0.0;
            size_t cnt = 0;
            for (int py = y0; py < y1; ++py)
                for (int px = x0; px < x1; ++px)
                    for (int k = 0; k < 3; ++k) {
                        size_t i = 3 * ((size_t)py * (size_t)a->width + (size_t)px) + (size_t)k;
                        double d = (double)x[i] - (double)y[i];
                        if (!isfinite(d)) continue;
                        rel += d * d / ((double)y[i] * (double)y[i] + 0.01), cnt++;
                    }
            printf("%s%.6g", bx ? " " : "", cnt ? rel / (double)cnt : 0.0);
        }
        printf("\n");
    }
    rc = 0;
done:
    free(x);
    free(y);
    sy_exr_image_free(a);
    sy_exr_image_free(b);
    return rc;
}
