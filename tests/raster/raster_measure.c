/* raster_measure.c — a measuring helper (not a test): compares two EXR renders of the same view,
 * e.g. raster against the path tracer. Prints the mean luminance (Rec.709) over covered pixels
 * (alpha > 0 in either image) and, for each --region NAME X0 Y0 X1 Y1 (fractions of the image,
 * row 0 = top), the mean luminance of both images inside it and the ratio A / B.
 *
 *   raster_measure A.exr B.exr [--region NAME X0 Y0 X1 Y1]...
 *
 * Exit status: 0 after printing, 2 on bad arguments or unreadable files. */
#include "sy_exr.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const float *plane(const sy_exr_image *im, const char *name)
{
    for (int i = 0; i < im->channel_count; ++i)
        if (!strcmp(im->channels[i].name, name)) return im->channels[i].data;
    return NULL;
}

static double lum(const float *r, const float *g, const float *b, size_t i)
{
    return 0.2126 * r[i] + 0.7152 * g[i] + 0.0722 * b[i];
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: raster_measure A.exr B.exr [--region NAME X0 Y0 X1 Y1]...\n");
        return 2;
    }
    sy_exr_image *im[2] = {NULL, NULL};
    const float *c[2][4];
    for (int k = 0; k < 2; ++k) {
        sy_error e = {0};
        if (sy_exr_read(argv[1 + k], &im[k], &e) != SY_OK) {
            fprintf(stderr, "raster_measure: %s: %s\n", argv[1 + k], e.message);
            return 2;
        }
        const char *names[4] = {"R", "G", "B", "A"};
        for (int j = 0; j < 4; ++j) c[k][j] = plane(im[k], names[j]);
        if (!c[k][0] || !c[k][1] || !c[k][2]) {
            fprintf(stderr, "raster_measure: %s: no R, G, B channels\n", argv[1 + k]);
            return 2;
        }
    }
    int w = im[0]->width, h = im[0]->height;
    if (im[1]->width != w || im[1]->height != h) {
        fprintf(stderr, "raster_measure: sizes differ (%dx%d vs %dx%d)\n", w, h, im[1]->width, im[1]->height);
        return 2;
    }
    double sum[2] = {0, 0};
    size_t covered = 0;
    for (size_t i = 0; i < (size_t)w * h; ++i) {
        bool cov = (c[0][3] ? c[0][3][i] > 0.0f : true) || (c[1][3] ? c[1][3][i] > 0.0f : true);
        if (!cov) continue;
        covered++;
        for (int k = 0; k < 2; ++k) sum[k] += lum(c[k][0], c[k][1], c[k][2], i);
    }
    double ma = covered ? sum[0] / covered : 0, mb = covered ? sum[1] / covered : 0;
    printf("%-12s %10s %10s %8s\n", "region", "A", "B", "A/B");
    printf("%-12s %10.5f %10.5f %8.3f   (%zu covered pixels)\n", "covered", ma, mb, mb > 0 ? ma / mb : 0.0, covered);
    for (int a = 3; a + 5 < argc; a += 6) {
        if (strcmp(argv[a], "--region")) break;
        float f[4];
        for (int j = 0; j < 4; ++j) f[j] = strtof(argv[a + 2 + j], NULL);
        int x0 = (int)(f[0] * w), y0 = (int)(f[1] * h), x1 = (int)(f[2] * w), y1 = (int)(f[3] * h);
        double s[2] = {0, 0};
        size_t n = 0;
        for (int y = y0; y < y1 && y < h; ++y)
            for (int x = x0; x < x1 && x < w; ++x, ++n)
                for (int k = 0; k < 2; ++k) s[k] += lum(c[k][0], c[k][1], c[k][2], (size_t)y * w + x);
        double ra = n ? s[0] / n : 0, rb = n ? s[1] / n : 0;
        printf("%-12s %10.5f %10.5f %8.3f\n", argv[a + 1], ra, rb, rb > 0 ? ra / rb : 0.0);
    }
    sy_exr_image_free(im[0]);
    sy_exr_image_free(im[1]);
    return 0;
}
