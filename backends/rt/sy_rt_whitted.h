/* sy_rt_whitted.h — SY_RT_INTEGRATOR_WHITTED: the deterministic preview. Anti-aliased camera rays
 * (stratified jittered pixel samples, refined adaptively where a pixel's samples disagree); direct
 * light from punctual lights (hard shadows), and from emissive triangles and the environment in
 * closed form where unshadowed (linearly transformed cosines over the emitters' polygons with the
 * tables of backends/ltc; the environment prefiltered per roughness, sy_rt_envfilter.h) times a
 * visibility ratio from stochastic shadow rays pooled over the pixel's samples; shadow rays
 * through alpha-blended and transmissive surfaces; the path tracer's BSDF; emission added;
 * recursive perfect mirror reflection and Fresnel refraction; alpha blending. Internal to
 * backends/rt. */
#ifndef SY_RT_WHITTED_H
#define SY_RT_WHITTED_H

#include "sy_rt_frame.h"

/* Renders the frame's rectangle with the Whitted integrator (desc: pixel_samples,
 * env_light_samples, progress). */
sy_rt_result sy_rt_whitted_render(const sy_rt_frame *f, const sy_rt_render_desc *desc);

#endif /* SY_RT_WHITTED_H */
