/** @file
 * sy_filter_pixel.h — pixel filtering (Schwenk 2013, chapter 3; ../shared/notes/filters-spec.md §1):
 * the high-variance part of a progressive path tracer's image is cross-bilaterally filtered,
 * guided by a nearly noise-free range buffer (virtual flash RGB + depth), on frames 2^i; every
 * frame the unfiltered and filtered HV buffers are blended per pixel with the largest unbiased
 * share s that keeps the perceived variance under the threshold t. Once the unfiltered estimate's
 * perceived variance is <= t, s = 1 and the output is exactly the unfiltered image (consistency).
 *
 * Inputs (sy_filter_frame): color (3/4 ch), variance (of the mean, 1 or 3 ch), spp or spp_uniform;
 * direct + indirect for the default LV/HV split (without them, or with all_high_variance, the
 * whole colour is HV); the range buffer, given (frame.range) or composed by
 * sy_filter_range_compose from albedo + normal + depth (+ position and camera_position for the
 * headlight).
 * Output: RGBA float, alpha copied from colour (1 for 3-channel colour).
 *
 * Ownership: sy_filter_pixel owns its state buffers (filtered HV, smoothed variance, r, s); it owns
 * no threads: every row-parallel phase runs on the process's OpenMP thread team with
 * params.threads threads (sy_filter_parallel_rows). The output does not depend on the thread count.
 * Thread-safety: one object per thread at a time; runs on params.threads threads internally. */
#ifndef SY_FILTER_PIXEL_H
#define SY_FILTER_PIXEL_H

#include "sy_filter.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Kernels of the pixel filter. */
typedef enum sy_filter_pixel_kernel {
    SY_FILTER_PIXEL_BRUTE = 0,    /**< brute-force 2D cross bilateral, window 3 sigma_s (Eq. 3.6) */
    SY_FILTER_PIXEL_SEPARABLE = 1 /**< fast iterated separable filter (Sec. 3.6.1, Eq. 3.14) */
} sy_filter_pixel_kernel;

/** Pixel filter options (sy_filter_pixel_params_default gives the defaults). */
typedef struct sy_filter_pixel_params {
    float threshold;         /**< t, perceived-variance threshold; default 0.01 (>= 0) */
    float sigma_s;           /**< spatial std. dev. in pixels; default 8 (> 0, <= 1000) */
    float sigma_c;           /**< range colour std. dev., linear sRGB; default 0.02 (> 0) */
    float sigma_d;           /**< range depth std. dev., scene units; default 2 (> 0) */
    uint32_t schedule_start; /**< first filter frame, a power of two; default 4 (frames 4, 8, 16, ...) */
    sy_filter_pixel_kernel kernel; /**< default SEPARABLE */
    uint32_t iterations;     /**< separable iterations N; default 3 (1..8) */
    bool adaptive_width;     /**< Sec. 3.6.3; default true */
    float adaptive_c;        /**< clamp factor c of Eq. 3.16; default 4 (>= 1) */
    float adaptive_sigma0;   /**< sigma_bar(0) of Eq. 3.17; 0 = 2 * sigma_s (default) */
    bool spike_withholding;  /**< Sec. 3.6.4; default true */
    float spike_c;           /**< band factor c of Eq. 3.18; default 2 (>= 1) */
    bool aa_recovery;        /**< Sec. 3.6.5 (separable kernel only); default true */
    bool all_high_variance;  /**< classify every path as HV (Fig. 3.7 setting); default false */
    bool use_covariance;     /**< keep Cov = a0 Var in the blend (spec 1.7 [DERIVED]); default false */
    float headlight_weight;  /**< composed range buffer: share of the headlight term (needs position +
                                frame.has_camera); default 0.5, [0, 1] */
    uint32_t threads;        /**< OpenMP team size; 0 = the OpenMP default (sy_filter_parallel_rows) */
} sy_filter_pixel_params;

/** Fills p with the defaults. */
void sy_filter_pixel_params_default(sy_filter_pixel_params *p);
/** The single validation point: every field checked, message names the field and the bound. */
sy_filter_status sy_filter_pixel_params_check(const sy_filter_pixel_params *p, sy_filter_report *err);

/** Range buffer ("virtual flash image", Sec. 3.3.3) from AOVs: RGB = albedo * ((1 - w) + w * cos),
 * cos = |n . v| toward an unoccluded headlight at camera_position (position buffer needed; without
 * camera_position or position only the ambient term is used), A = depth (+INF misses -> 1e18).
 * out_rgba: width*height*4 floats. [GAP spec 1.5 ambient/headlight weighting]: w = headlight_weight,
 * default 0.5 — equal parts texture edges (ambient) and normal variation (headlight). */
sy_filter_status sy_filter_range_compose(const sy_filter_frame *f, const float *camera_position,
                                         float headlight_weight, float *out_rgba, sy_filter_report *err);

/** Blend factor s (Eq. 3.13) for perceived variances u = Var[L_u]/L_b^2, f = Var[L_f]/L_b^2 and
 * threshold t; with c > 0 the covariance-aware root of spec 1.7 is used. */
float sy_filter_blend_factor(float u, float f, float t, float c);

/** True when frame (1-based count of accumulated frames) is a scheduled filter frame: a power of
 * two >= schedule_start. */
bool sy_filter_pixel_scheduled(const sy_filter_pixel_params *p, uint32_t frame);

/** A pixel filter with its state (opaque): the filtered buffer of the last pass. */
typedef struct sy_filter_pixel sy_filter_pixel;

/** Creates a pixel filter with options p. */
sy_filter_status sy_filter_pixel_create(const sy_filter_pixel_params *p, sy_filter_pixel **out, sy_filter_report *err);
/** Destroys the filter (NULL-safe). */
void sy_filter_pixel_destroy(sy_filter_pixel *pf);
/** Forget the filtered buffer (call on every scene/camera change; the frame counter restarts). */
void sy_filter_pixel_reset(sy_filter_pixel *pf);
/** Changes the options (checked first; on error nothing changes). */
sy_filter_status sy_filter_pixel_set_params(sy_filter_pixel *pf, const sy_filter_pixel_params *p, sy_filter_report *err);

/** One presented frame: runs a filter pass when `frame` is scheduled (or force_pass), then blends.
 * frame = number of accumulated frames (1-based). Before the first pass the output is unfiltered.
 * A size change resets the state. out_rgba: width*height*4 floats. */
sy_filter_status sy_filter_pixel_run(sy_filter_pixel *pf, const sy_filter_frame *in, uint32_t frame, bool force_pass,
                                     float *out_rgba, sy_filter_stats *stats, sy_filter_report *err);

/** Per-pixel diagnostics of the last run (NULL before the first pass): blend factor s, variance
 * reduction factor r = sum a_i^2 (normalised weights), filtered HV RGB (3 ch). Owned by pf. */
const float *sy_filter_pixel_blend(const sy_filter_pixel *pf);
/** Variance reduction factor r per pixel of the last pass (owned by pf; NULL before the first pass). */
const float *sy_filter_pixel_reduction(const sy_filter_pixel *pf);
/** Filtered HV RGB of the last pass (3 ch; owned by pf; NULL before the first pass). */
const float *sy_filter_pixel_filtered(const sy_filter_pixel *pf);

#ifdef __cplusplus
}
#endif

#endif /* SY_FILTER_PIXEL_H */
