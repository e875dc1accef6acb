/* exr_blur.c — test helper for motion blur (tests/integration/motion_blur_test.sh): statistics of
 * EXR renders of one view, read through formats/sy_exr.h.
 *   exr_blur mean A.exr [B.exr ...]        mean R G B A over all pixels of the pixel-wise mean of
 *                                          the files (the mean of sub-frame renders)
 *   exr_blur cover T A.exr                 pixels whose alpha exceeds T
 *   exr_blur iou T BLUR.exr U A.exr B.exr  IoU of {BLUR alpha > T} against {A alpha > U or B alpha > U}
 *                                          (a streak against the union of its endpoints' coverages)
 *   exr_blur width T A.exr                 the mean over the rows that have any of the pixels whose
 *                                          alpha exceeds T per row (a horizontal streak's width)
 *   exr_blur relmse A.exr REF.exr          relative MSE of A's RGB against REF's: the mean over pixels and
 *                                          channels of (a - r)^2 / (r^2 + 0.01)
 *   exr_blur centroid A.exr                the luminance-weighted mean column and row of A (pixel centres at
 *                                          x + 0.5, y + 0.5; where a light falls)
 * Prints the numbers on one line; exit 0, or 2 on bad input (unreadable file, no alpha channel,
 * different sizes). */
#include "sy_exr.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static sy_exr_image *load(const char *path, const sy_exr_image *like)
{
    sy_error e = {0};
    sy_exr_image *img = NULL;
    if (sy_exr_read(path, &img, &e) != SY_OK) {
        fprintf(stderr, "exr_blur: %s\n", e.message);
        return NULL;
    }
    if (!sy_exr_image_channel(img, "A") || !sy_exr_image_channel(img, "R") || !sy_exr_image_channel(img, "G") ||
        !sy_exr_image_channel(img, "B") || (like && (img->width != like->width || img->height != like->height))) {
        fprintf(stderr, "exr_blur: %s: no RGBA channels, or a size unlike the first file's\n", path);
        sy_exr_image_free(img);
        return NULL;
    }
    return img;
}

static int usage(void)
{
    fprintf(stderr, "usage: exr_blur mean A.exr [B.exr ...] | cover T A.exr | iou T BLUR.exr U A.exr B.exr |\n"
                    "       width T A.exr | relmse A.exr REF.exr | centroid A.exr\n");
    return 2;
}

int main(int argc, char **argv)
{
    if (argc < 3) return usage();
    if (!strcmp(argv[1], "mean")) {
        double sum[4] = {0, 0, 0, 0};
        size_t pixels = 0;
        sy_exr_image *first = NULL;
        for (int i = 2; i < argc; ++i) {
            sy_exr_image *img = load(argv[i], first);
            if (!img) {
                sy_exr_image_free(first);
                return 2;
            }
            static const char *const names[4] = {"R", "G", "B", "A"};
            pixels = (size_t)img->width * img->height;
            for (int c = 0; c < 4; ++c) {
                const float *p = sy_exr_image_channel(img, names[c]);
                for (size_t k = 0; k < pixels; ++k) sum[c] += p[k];
            }
            if (!first) first = img;
            else sy_exr_image_free(img);
        }
        sy_exr_image_free(first);
        double n = (double)pixels * (argc - 2);
        printf("%.9g %.9g %.9g %.9g\n", sum[0] / n, sum[1] / n, sum[2] / n, sum[3] / n);
        return 0;
    }
    int cover = !strcmp(argv[1], "cover");
    if ((cover || !strcmp(argv[1], "width")) && argc == 4) { /* the pixels whose alpha exceeds T: all, or per row */
        sy_exr_image *img = load(argv[3], NULL);
        if (!img) return 2;
        float t = strtof(argv[2], NULL);
        const float *a = sy_exr_image_channel(img, "A");
        size_t n = 0, rows = 0;
        for (int y = 0; y < img->height; ++y) {
            size_t k = 0;
            for (int x = 0; x < img->width; ++x) k += a[(size_t)y * (size_t)img->width + (size_t)x] > t;
            n += k, rows += k > 0;
        }
        if (cover) printf("%zu\n", n);
        else printf("%.4f\n", rows ? (double)n / (double)rows : 0.0);
        sy_exr_image_free(img);
        return 0;
    }
    if (!strcmp(argv[1], "centroid") && argc == 3) {
        sy_exr_image *a = load(argv[2], NULL);
        if (!a) return 2;
        const float *r = sy_exr_image_channel(a, "R"), *g = sy_exr_image_channel(a, "G"), *b = sy_exr_image_channel(a, "B");
        double sum = 0.0, sx = 0.0, sy = 0.0;
        for (int y = 0; y < a->height; ++y)
            for (int x = 0; x < a->width; ++x) {
                size_t k = (size_t)y * a->width + x;
                double l = 0.2126 * r[k] + 0.7152 * g[k] + 0.0722 * b[k];
                if (!(l > 0.0)) continue;
                sum += l, sx += l * (x + 0.5), sy += l * (y + 0.5);
            }
        sy_exr_image_free(a);
        if (!(sum > 0.0)) {
            fprintf(stderr, "exr_blur: %s: black\n", argv[2]);
            return 2;
        }
        printf("%.4f %.4f\n", sx / sum, sy / sum);
        return 0;
    }
    if (!strcmp(argv[1], "relmse") && argc == 4) {
        sy_exr_image *a = load(argv[2], NULL), *r = a ? load(argv[3], a) : NULL;
        if (!r) {
            sy_exr_image_free(a);
            return 2;
        }
        static const char *const names[3] = {"R", "G", "B"};
        size_t n = (size_t)a->width * (size_t)a->height;
        double sum = 0.0;
        for (int c = 0; c < 3; ++c) {
            const float *pa = sy_exr_image_channel(a, names[c]), *pr = sy_exr_image_channel(r, names[c]);
            for (size_t k = 0; k < n; ++k) {
                double d = (double)pa[k] - pr[k];
                sum += d * d / ((double)pr[k] * pr[k] + 0.01);
            }
        }
        printf("%.6g\n", n ? sum / (3.0 * (double)n) : 0.0);
        sy_exr_image_free(a);
        sy_exr_image_free(r);
        return 0;
    }
    if (!strcmp(argv[1], "iou") && argc == 7) {
        sy_exr_image *b = load(argv[3], NULL), *x = b ? load(argv[5], b) : NULL, *y = x ? load(argv[6], b) : NULL;
        int st = 2;
        if (y) {
            float t = strtof(argv[2], NULL), u = strtof(argv[4], NULL);
            const float *ab = sy_exr_image_channel(b, "A"), *ax = sy_exr_image_channel(x, "A"),
                        *ay = sy_exr_image_channel(y, "A");
            size_t inter = 0, uni = 0;
            for (size_t k = 0; k < (size_t)b->width * b->height; ++k) {
                int p = ab[k] > t, q = ax[k] > u || ay[k] > u;
                inter += p && q;
                uni += p || q;
            }
            printf("%.6f\n", uni ? (double)inter / (double)uni : 0.0);
            st = 0;
        }
        sy_exr_image_free(b);
        sy_exr_image_free(x);
        sy_exr_image_free(y);
        return st;
    }
    return usage();
}
