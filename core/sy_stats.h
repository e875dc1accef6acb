/** @file
 * sy_stats.h — statistics of rendered layers used to compare back-ends: mean luminance over the
 * pixels an image covers, and the coverage overlap (intersection over union) of two images.
 *
 * A pixel is covered when something was hit there: its depth is finite. A layer without depth
 * falls back to alpha > 0.5. Luminance is Rec. 709 Y of linear RGB.
 * Ownership: plain values. Thread-safety: pure functions. */
#ifndef SY_STATS_H
#define SY_STATS_H

#include "sy_mediator.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Statistics of a layer (sy_layer_stats_get). */
typedef struct sy_layer_stats {
    uint64_t pixels;         /**< width x height */
    uint64_t covered;        /**< pixels where something was hit */
    double mean_luminance;   /**< over covered pixels (0 when none) */
    double mean_rgb[3];      /**< over covered pixels */
    uint64_t nonfinite;      /**< covered pixels with a NaN/Inf colour (left out of the means) */
} sy_layer_stats;

static inline bool sy_layer_covered(const sy_layer *l, size_t i)
{
    return l->depth ? l->depth[i] < 1e30f : l->rgba[4 * i + 3] > 0.5f;
}

/** Fills *out with the layer's statistics. */
void sy_layer_stats_get(const sy_layer *l, sy_layer_stats *out);

/** |covered in a AND b| / |covered in a OR b|; 1 when neither covers anything. The layers must have
 * the same size (SY_ERR_INVALID_ARGUMENT otherwise). */
sy_result sy_layer_coverage_iou(const sy_layer *a, const sy_layer *b, double *iou, sy_error *err);

#ifdef __cplusplus
}
#endif
#endif /* SY_STATS_H */
