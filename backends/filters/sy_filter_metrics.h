/** @file
 * sy_filter_metrics.h — image-quality metrics for the filter harness: RMSE, relative MSE and SSIM
 * (Wang, Bovik, Sheikh, Simoncelli 2004) of an image against a reference.
 *
 * Images are float RGB or RGBA (channels 3 or 4; alpha ignored), width*height pixels.
 *   RMSE    sqrt(mean over pixels and RGB of (x - y)^2), linear radiance.
 *   relMSE  mean over pixels and RGB of (x - y)^2 / (y^2 + eps), eps = 0.01 (the usual denoising
 *           definition; robust in dark regions).
 *   SSIM    mean SSIM over all pixels of the display-encoded luminance: each image's linear RGB is
 *           clamped to [0, 1], sRGB-encoded, converted to Rec.709 luma; 11x11 Gaussian window with
 *           sigma 1.5 (normalised over the part inside the image), K1 = 0.01, K2 = 0.03, L = 1.
 * Non-finite pixels of either image are skipped and counted (nonfinite_out).
 * Thread-safety: pure functions. */
#ifndef SY_FILTER_METRICS_H
#define SY_FILTER_METRICS_H

#include "sy_filter.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Error metrics of an image against a reference. */
typedef struct sy_filter_metrics {
    /** @{ root mean squared error; relative MSE; SSIM */
    double rmse, relmse, ssim; /** @} */
    uint64_t nonfinite; /**< pixels skipped */
} sy_filter_metrics;

/** RMSE, relMSE and SSIM of image against reference (width x height x channels floats). */
sy_filter_status sy_filter_metrics_compute(const float *image, const float *reference, uint32_t width,
                                           uint32_t height, uint32_t channels, sy_filter_metrics *out,
                                           sy_filter_report *err);

/** SSIM alone on two single-channel images already in [0, 1] (dynamic range L = 1). */
double sy_filter_ssim_gray(const float *a, const float *b, uint32_t width, uint32_t height);

/** The Rec. 709 luma of n RGBA8 pixels (the display-encoded values / 255, alpha ignored) into out
 * (n floats in [0, 1]): what sy_filter_ssim_gray compares of 8-bit images. */
void sy_filter_luma_rgba8(const uint8_t *rgba, size_t n, float *out);

#ifdef __cplusplus
}
#endif

#endif /* SY_FILTER_METRICS_H */
