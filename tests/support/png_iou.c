/* png_iou.c — test helper: coverage IoU of two PNG images of the same view (a browser's canvas
 * against `sy render`). A pixel is covered when it differs from its image's background colour by
 * more than a tolerance in any of R, G, B; the background colour of each image is its top-left
 * pixel (the views these tests use leave the corners empty) unless --bg gives it.
 * With --lum REL also the mean luminance of each image (Rec. 709 weights of the linearised sRGB
 * values, over every pixel, 0..1), and B's within REL of A's (|lum_b / lum_a - 1| <= REL) is required.
 *   png_iou A.png B.png [--min IOU] [--tol 0..255] [--bg R,G,B] [--lum REL]
 * Prints "iou X covered_a A covered_b B" (with --lum: "lum_a LA lum_b LB"); exit 0 when IoU >=
 * --min (default 0: always) and the luminances agree, 1 otherwise,
 * 2 on bad input (unreadable file, different sizes, an image with nothing covered). */
#include <math.h>
#include "sy_png.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int covered(const uint8_t *p, const int bg[3], int tol)
{
    for (int c = 0; c < 3; ++c) {
        int d = (int)p[c] - bg[c];
        if (d > tol || d < -tol) return 1;
    }
    return 0;
}

int main(int argc, char **argv)
{
    double min_iou = 0.0, lum_rel = -1.0;
    int tol = 24, bg[3] = {0, 0, 0}, have_bg = 0;
    const char *path[2] = {NULL, NULL};
    int np = 0;
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--min") && i + 1 < argc) min_iou = atof(argv[++i]);
        else if (!strcmp(argv[i], "--tol") && i + 1 < argc) tol = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--lum") && i + 1 < argc) lum_rel = atof(argv[++i]);
        else if (!strcmp(argv[i], "--bg") && i + 1 < argc) {
            if (sscanf(argv[++i], "%d,%d,%d", &bg[0], &bg[1], &bg[2]) != 3) {
                fprintf(stderr, "png_iou: --bg wants R,G,B (0..255), got '%s'\n", argv[i]);
                return 2;
            }
            have_bg = 1;
        } else if (np < 2 && argv[i][0] != '-') path[np++] = argv[i];
        else {
            fprintf(stderr, "usage: png_iou A.png B.png [--min IOU] [--tol 0..255] [--bg R,G,B] [--lum REL]\n");
            return 2;
        }
    }
    if (np != 2 || tol < 0 || tol > 255) {
        fprintf(stderr, "usage: png_iou A.png B.png [--min IOU] [--tol 0..255] [--bg R,G,B] [--lum REL]\n");
        return 2;
    }
    int w[2], h[2];
    uint8_t *px[2] = {NULL, NULL};
    sy_error e = {0};
    for (int k = 0; k < 2; ++k)
        if (sy_png_read_rgba8(path[k], &w[k], &h[k], &px[k], &e) != SY_OK) {
            fprintf(stderr, "png_iou: %s\n", e.message);
            free(px[0]);
            return 2;
        }
    int rc = 2;
    if (w[0] != w[1] || h[0] != h[1]) {
        fprintf(stderr, "png_iou: %s is %dx%d, %s is %dx%d\n", path[0], w[0], h[0], path[1], w[1], h[1]);
    } else {
        int bga[3], bgb[3];
        for (int c = 0; c < 3; ++c) {
            bga[c] = have_bg ? bg[c] : px[0][c];
            bgb[c] = have_bg ? bg[c] : px[1][c];
        }
        size_t n = (size_t)w[0] * (size_t)h[0], inter = 0, uni = 0, ca = 0, cb = 0;
        for (size_t i = 0; i < n; ++i) {
            int a = covered(px[0] + 4 * i, bga, tol), b = covered(px[1] + 4 * i, bgb, tol);
            inter += (size_t)(a & b);
            uni += (size_t)(a | b);
            ca += (size_t)a;
            cb += (size_t)b;
        }
        if (ca == 0 || cb == 0) {
            fprintf(stderr, "png_iou: %s covers nothing (background %d,%d,%d, tolerance %d)\n",
                    ca == 0 ? path[0] : path[1], ca == 0 ? bga[0] : bgb[0], ca == 0 ? bga[1] : bgb[1],
                    ca == 0 ? bga[2] : bgb[2], tol);
        } else {
            double iou = (double)inter / (double)uni;
            rc = iou >= min_iou ? 0 : 1;
            if (lum_rel >= 0) {
                double lum[2] = {0, 0};
                for (int k = 0; k < 2; ++k) {
                    for (size_t i = 0; i < n; ++i) {
                        double y = 0;
                        static const double wt[3] = {0.2126, 0.7152, 0.0722};
                        for (int c = 0; c < 3; ++c) {
                            double v = px[k][4 * i + c] / 255.0;
                            y += wt[c] * (v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4));
                        }
                        lum[k] += y;
                    }
                    lum[k] /= (double)n;
                }
                printf("iou %.4f covered_a %zu covered_b %zu lum_a %.5f lum_b %.5f\n", iou, ca, cb, lum[0], lum[1]);
                double rel = lum[0] > 0 ? fabs(lum[1] / lum[0] - 1.0) : INFINITY;
                if (!(rel <= lum_rel)) {
                    fprintf(stderr, "png_iou: mean luminance %.5f against %.5f: %.1f%% apart, more than %.1f%%\n", lum[1], lum[0],
                            100 * rel, 100 * lum_rel);
                    rc = 1;
                }
            } else {
                printf("iou %.4f covered_a %zu covered_b %zu\n", iou, ca, cb);
            }
            if (iou < min_iou) fprintf(stderr, "png_iou: IoU %.4f < %.4f\n", iou, min_iou);
        }
    }
    free(px[0]);
    free(px[1]);
    return rc;
}
