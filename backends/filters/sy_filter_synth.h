/** @file
 * sy_filter_synth.h — analytic progressive-render surrogate for benchmarking and demonstrating the
 * filters without a renderer: two Lambertian planes (depth step in the middle, normals facing the
 * camera) with a checker texture, lit by smooth indirect illumination with a sharp shadow edge and
 * a noise-free direct part. Each step "traces" 1 sample per pixel: the incident radiance along a
 * cosine-sampled direction is E(x) * X, X ~ Exp(1) (positive, skewed, relative sd 1, like path
 * tracing), so the pixel estimate is albedo * E * X. It keeps the accumulated buffers a
 * progressive path tracer exposes (colour mean RGBA, Welford variance of the mean per channel,
 * albedo, normal, depth, position, direct/indirect split) and this step's radiance-filter inputs
 * (sy_filter_rf_shading/sample), plus the exact converged image.
 *
 * Ownership: the object owns every buffer it returns; they change with each step.
 * Thread-safety: one thread at a time. */
#ifndef SY_FILTER_SYNTH_H
#define SY_FILTER_SYNTH_H

#include "sy_filter.h"
#include "sy_filter_radiance.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The analytic progressive-render surrogate (opaque). */
typedef struct sy_filter_synth sy_filter_synth;

/** Creates a width x height surrogate with no samples; seed fixes the sample sequence. */
sy_filter_status sy_filter_synth_create(uint32_t width, uint32_t height, uint64_t seed, sy_filter_synth **out,
                                        sy_filter_report *err);
/** Destroys it (NULL-safe). */
void sy_filter_synth_destroy(sy_filter_synth *s);
/** Forget all samples (spp back to 0); the seed sequence continues. */
void sy_filter_synth_reset(sy_filter_synth *s);
/** Trace one more sample per pixel. */
void sy_filter_synth_step(sy_filter_synth *s);
/** Samples per pixel so far. */
uint32_t sy_filter_synth_spp(const sy_filter_synth *s);
/** The accumulated buffers (color 4 ch, variance 3 ch of the mean; spp_uniform = samples so far). */
sy_filter_frame sy_filter_synth_frame(const sy_filter_synth *s);
/** This step's radiance-filter input (pixel_angle set). */
sy_filter_radiance_input sy_filter_synth_rf_input(const sy_filter_synth *s);
/** The converged image, RGBA. */
const float *sy_filter_synth_reference(const sy_filter_synth *s);

#ifdef __cplusplus
}
#endif

#endif /* SY_FILTER_SYNTH_H */
