/* sy_rt_whitted.h — SY_RT_INTEGRATOR_WHITTED: anti-aliased camera rays (stratified jittered pixel
 * samples), direct light from punctual lights, emissive triangles and the environment (stratified,
 * per-pixel Owen-scrambled samples: soft shadows without banding or frame-to-frame noise) with
 * shadow rays through alpha-blended and transmissive surfaces, Lambert + GGX highlights, emission
 * added, recursive perfect mirror reflection and Fresnel refraction, alpha blending. Internal to
 * backends/rt. */
#ifndef SY_RT_WHITTED_H
#define SY_RT_WHITTED_H

#include "sy_rt_frame.h"

/* Renders the frame's rectangle with the Whitted integrator (desc: pixel_samples,
 * env_light_samples, progress). */
sy_rt_result sy_rt_whitted_render(const sy_rt_frame *f, const sy_rt_render_desc *desc);

#endif /* SY_RT_WHITTED_H */
