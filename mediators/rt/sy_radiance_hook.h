/* sy_radiance_hook.h — glue between the path tracer's stored-sample hook (backends/rt path
 * records, sy_rt.h ">>path records") and the radiance filter (backends/filters,
 * sy_filter_radiance.h, Schwenk 2013 ch. 4). The two back-end libraries never include each other;
 * this mediator-side module converts one 1-spp pass of records into the filter's per-pixel
 * shading points and incident-radiance samples, keeps the running variance of every pixel's
 * indirect estimate, and hands the filter the path tracer's real BSDF (sy_rt_pt_record_bsdf) as
 * its re-shading callback.
 *
 * Data flow per frame (= one path per pixel):
 *   sy_rt_render(samples = 1, records = sy_radiance_hook_records())
 *   sy_radiance_hook_frame()  records -> sy_filter_rf_shading / sy_filter_rf_sample
 *                             -> sy_filter_radiance_frame -> RGB of the running filtered mean
 * Resuming: when the first frame after a reset comes on top of an accumulation that already holds
 * N samples (the filter was switched on or changed while the path tracer kept going), the filter
 * is seeded with that accumulation (sy_filter_radiance_seed: mean, per-sample variance, k = N), so
 * switching filters never throws samples away.
 *
 * Ownership: the hook owns its records, conversion buffers and filter. Thread-safety: one thread
 * at a time (the thread rendering the context); the filter runs multithreaded inside. */
#ifndef SY_RADIANCE_HOOK_H
#define SY_RADIANCE_HOOK_H

#include "sy_common.h"
#include "sy_filter_radiance.h"
#include "sy_rt.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct sy_radiance_hook sy_radiance_hook;

sy_result sy_radiance_hook_create(const sy_filter_radiance_params *p, sy_radiance_hook **out, sy_error *err);
void sy_radiance_hook_destroy(sy_radiance_hook *h); /* NULL is a no-op */
/* Restart: the next frame is frame 1 (or seeded, see above). */
void sy_radiance_hook_reset(sy_radiance_hook *h);
/* New filter parameters (validated; on error nothing changes); restarts the filter. */
sy_result sy_radiance_hook_set_params(sy_radiance_hook *h, const sy_filter_radiance_params *p, sy_error *err);
/* The records buffer for a w x h pass (reallocated, and the hook reset, when the size changes). */
sy_result sy_radiance_hook_records(sy_radiance_hook *h, uint32_t w, uint32_t hgt, sy_rt_pt_record **out, sy_error *err);

typedef struct sy_radiance_hook_frame_desc {
    float pixel_angle; /* world size of one pixel at unit distance (perspective), or of one pixel
                          (orthographic, with path lengths then taken as 1) */
    bool orthographic;
    /* the accumulation the records were added to, for seeding after a reset (samples BEFORE this
     * pass; 0 = nothing to resume from): RGB(A) mean with its channel count, and the variance of
     * the mean (3 channels, as SY_RT_AOV_VARIANCE) */
    uint32_t prior_samples;
    const float *prior_color;
    uint32_t prior_color_channels;
    const float *prior_variance;
    const float *prior_direct; /* 3 ch direct part of the mean (its complement seeds the indirect
                                  variance mean) or NULL */
} sy_radiance_hook_frame_desc;

/* One radiance-filter frame from the records last written (the size given to
 * sy_radiance_hook_records). rgba (w * h * 4, may be NULL) receives the filtered running mean in
 * RGB; its alpha is left alone (the caller's coverage). stats: the filter's (NaN/Inf records
 * counted in nonfinite_samples and kept out of every neighbourhood). */
sy_result sy_radiance_hook_frame(sy_radiance_hook *h, const sy_radiance_hook_frame_desc *d, float *rgba,
                                 sy_filter_stats *stats, sy_error *err);
uint32_t sy_radiance_hook_frame_index(const sy_radiance_hook *h); /* frames since the last reset */

#ifdef __cplusplus
}
#endif

#endif /* SY_RADIANCE_HOOK_H */
