/* sy_stats.c — layer statistics for comparing back-ends (see sy_stats.h). */
#include "sy_stats.h"

#include <math.h>
#include <string.h>

void sy_layer_stats_get(const sy_layer *l, sy_layer_stats *out)
{
    memset(out, 0, sizeof *out);
    size_t n = (size_t)l->width * l->height;
    out->pixels = n;
    double sum = 0, rgb[3] = {0, 0, 0};
    for (size_t i = 0; i < n; ++i) {
        if (!sy_layer_covered(l, i)) continue;
        const float *p = l->rgba + 4 * i;
        out->covered++;
        if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2])) {
            out->nonfinite++;
            continue;
        }
        sum += 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
        for (int k = 0; k < 3; ++k) rgb[k] += p[k];
    }
    uint64_t m = out->covered - out->nonfinite;
    if (m) {
        out->mean_luminance = sum / (double)m;
        for (int k = 0; k < 3; ++k) out->mean_rgb[k] = rgb[k] / (double)m;
    }
}

sy_result sy_layer_coverage_iou(const sy_layer *a, const sy_layer *b, double *iou, sy_error *err)
{
    if (a->width != b->width || a->height != b->height)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "coverage IoU: layer sizes differ (%ux%u vs %ux%u)", a->width,
                            a->height, b->width, b->height);
    size_t n = (size_t)a->width * a->height;
    uint64_t inter = 0, uni = 0;
    for (size_t i = 0; i < n; ++i) {
        bool ca = sy_layer_covered(a, i), cb = sy_layer_covered(b, i);
        inter += ca && cb;
        uni += ca || cb;
    }
    *iou = uni ? (double)inter / (double)uni : 1.0;
    return SY_OK;
}
