/** @file
 * sy_filter_jbu.h — joint bilateral upsampling (Kopf et al. 2007) of a sparse, downsampled
 * high-variance (indirect) solution guided by full-resolution depth and normals, after
 * ../shared/seeds/004 (G-buffer-driven JBU of indirect light): the baseline "jbu".
 *
 * sy_filter_jbu_upsample: low-resolution values sampled at block centres (pixel (bx*k + k/2,
 * by*k + k/2) of the full image, k = factor) with their depth/normal, upsampled to full resolution:
 *   out(p) = sum_q v_q f(|p_down - q|) g_d(|d_p - d_q| / d_p) g_n(|n_p - n_q|) / sum_q (...)
 * f, g Gaussians; 2*radius x 2*radius low-res window. When every weight vanishes (no compatible
 * low-res sample) the spatial weights alone are used.
 * sy_filter_jbu: the whole baseline on a frame: demodulate the HV buffer by albedo, build the
 * sparse solution (each block's average over the pixels whose depth/normal match the block centre
 * — k^2 samples at the centre's surface), upsample, remodulate, add the LV buffer.
 *
 * Inputs: color, depth, normal (required); direct/indirect, albedo (optional). Output RGBA.
 * Thread-safety: stateless, reentrant. */
#ifndef SY_FILTER_JBU_H
#define SY_FILTER_JBU_H

#include "sy_filter.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Joint bilateral upsampling options (sy_filter_jbu_params_default gives the defaults). */
typedef struct sy_filter_jbu_params {
    uint32_t factor;     /**< downsampling factor k; default 4 (1..64) */
    uint32_t radius;     /**< low-res window half size; default 2 (1..8) */
    float sigma_spatial; /**< low-res pixels; default 1.0 (> 0) */
    float sigma_depth;   /**< relative depth difference; default 0.05 (> 0) */
    float sigma_normal;  /**< |n_p - n_q|; default 0.25 (> 0) */
    bool demodulate_albedo; /**< default true */
    uint32_t threads;    /**< OpenMP team size; 0 = the OpenMP default (sy_filter_parallel_rows) */
} sy_filter_jbu_params;

/** Fills p with the defaults. */
void sy_filter_jbu_params_default(sy_filter_jbu_params *p);
/** Checks every field; the message names the field and the bound. */
sy_filter_status sy_filter_jbu_params_check(const sy_filter_jbu_params *p, sy_filter_report *err);

/** low: lw*lh*3 values; low_depth: lw*lh; low_normal: lw*lh*3 (the guides at the block centres).
 * The full-res guides come from `guide` (depth, normal). out3: width*height*3. lw and lh must
 * equal ceil(width/k), ceil(height/k). */
sy_filter_status sy_filter_jbu_upsample(const sy_filter_jbu_params *p, const float *low, const float *low_depth,
                                        const float *low_normal, uint32_t lw, uint32_t lh,
                                        const sy_filter_frame *guide, float *out3, sy_filter_report *err);

/** Filters in (see above) into out_rgba (width*height*4 floats); stats may be NULL. */
sy_filter_status sy_filter_jbu(const sy_filter_jbu_params *p, const sy_filter_frame *in, float *out_rgba,
                               sy_filter_stats *stats, sy_filter_report *err);

#ifdef __cplusplus
}
#endif

#endif /* SY_FILTER_JBU_H */
