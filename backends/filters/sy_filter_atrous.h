/** @file
 * sy_filter_atrous.h — edge-avoiding a-trous wavelet filter (Dammertz et al. 2010), the baseline
 * of ../shared/notes/filters-spec.md §3.1/§3.2 ("atrous", and "atrous2" when a range buffer is
 * given): iterations of a 5x5 B3-spline kernel with taps 2^i pixels apart, weights = products of
 * edge-stopping functions on the (current) colour, normal and world position, colour sigma halved
 * every iteration, output normalised by the weight sum. Filters the high-variance part (indirect
 * when direct + indirect are given, else the whole colour), optionally divided by the albedo
 * before and multiplied back after ("postmultiplication by filtered irradiance", §3.2).
 *
 * Inputs: color, normal, position (required); direct/indirect, albedo, range (optional).
 * Output: RGBA float (alpha copied from colour). Thread-safety: stateless, reentrant. */
#ifndef SY_FILTER_ATROUS_H
#define SY_FILTER_ATROUS_H

#include "sy_filter.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Edge-avoiding a-trous options (sy_filter_atrous_params_default gives the defaults). */
typedef struct sy_filter_atrous_params {
    uint32_t iterations;  /**< default 5 (Dammertz); the thesis' progressive variant uses 3 (1..10) */
    float sigma_color;    /**< edge stop on the current colour (linear radiance); default 0.6 (> 0) */
    float sigma_normal;   /**< edge stop on normals (divided by the step width as in the paper); default 0.3 */
    float sigma_position; /**< edge stop on world positions, scene units; default 0.2 */
    float sigma_range;    /**< range-buffer RGB edge stop ("atrous2"); 0 = off (default) */
    bool halve_color_sigma; /**< default true (original) */
    bool demodulate_albedo; /**< default true */
    uint32_t threads;       /**< OpenMP team size; 0 = the OpenMP default (sy_filter_parallel_rows) */
} sy_filter_atrous_params;

/** Fills p with the defaults. */
void sy_filter_atrous_params_default(sy_filter_atrous_params *p);
/** Checks every field; the message names the field and the bound. */
sy_filter_status sy_filter_atrous_params_check(const sy_filter_atrous_params *p, sy_filter_report *err);

/** out_rgba: width*height*4 floats; stats may be NULL. */
sy_filter_status sy_filter_atrous(const sy_filter_atrous_params *p, const sy_filter_frame *in, float *out_rgba,
                                  sy_filter_stats *stats, sy_filter_report *err);

#ifdef __cplusplus
}
#endif

#endif /* SY_FILTER_ATROUS_H */
