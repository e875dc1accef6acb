/** @file
 * sy_filter_adaptive.h — adaptive-resolution preview (../shared/seeds/003, Sec. 4.3): while few
 * samples exist, each pixel is displayed from a coarser level of a sample-count-weighted mip
 * pyramid of the colour, the level chosen from its samples per pixel and its (mip-smoothed)
 * perceived variance,
 *   level = log4(target_spp / spp) + variance_weight * log4(u / threshold)   clamped to [0, max_level]
 * (the seed's LoD' = LoD + V_m log4(Var), with LoD from the sample density), so a 1-spp image is
 * shown as a smooth low-resolution image rather than single-sample noise, and the level falls to 0
 * (the exact accumulated image) as samples arrive. Levels >= 1 are sampled with the seed's windowed
 * Gaussian (sigma 1 texel, truncation R = 2.5, window 1 - smoothstep(0, R, d)^8) on the two nearest
 * levels and interpolated linearly (no pops when the level changes).
 *
 * Inputs: color (required), variance, spp (optional; without variance only the spp term counts).
 * Output RGBA. Thread-safety: stateless, reentrant. */
#ifndef SY_FILTER_ADAPTIVE_H
#define SY_FILTER_ADAPTIVE_H

#include "sy_filter.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Adaptive-resolution preview options (sy_filter_adaptive_params_default gives the defaults). */
typedef struct sy_filter_adaptive_params {
    float target_spp;      /**< samples a displayed texel should hold; default 4 (>= 1) */
    float variance_weight; /**< V_m; default 0.5 (>= 0) */
    float threshold;       /**< perceived variance target t; default 0.01 (> 0) */
    uint32_t max_level;    /**< default 5 (0..12) */
    uint32_t threads;      /**< OpenMP team size; 0 = the OpenMP default (sy_filter_parallel_rows) */
} sy_filter_adaptive_params;

/** Fills p with the defaults. */
void sy_filter_adaptive_params_default(sy_filter_adaptive_params *p);
/** Checks every field; the message names the field and the bound. */
sy_filter_status sy_filter_adaptive_params_check(const sy_filter_adaptive_params *p, sy_filter_report *err);

/** out_rgba: width*height*4; level_out (optional, width*height): the fractional level used. */
sy_filter_status sy_filter_adaptive(const sy_filter_adaptive_params *p, const sy_filter_frame *in, float *out_rgba,
                                    float *level_out, sy_filter_stats *stats, sy_filter_report *err);

#ifdef __cplusplus
}
#endif

#endif /* SY_FILTER_ADAPTIVE_H */
