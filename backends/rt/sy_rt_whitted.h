/* sy_rt_whitted.h — SY_RT_INTEGRATOR_WHITTED: direct light from punctual lights (hard shadows)
 * and from emissive triangles (a fixed, stratified, per-pixel-rotated set of area-light samples:
 * soft shadows without frame-to-frame noise), Lambert + GGX highlights, recursive perfect mirror
 * reflection and Fresnel refraction, alpha blending. Internal to backends/rt. */
#ifndef SY_RT_WHITTED_H
#define SY_RT_WHITTED_H

#include "sy_rt_render.h"

/* sy_rt_tile_fn for the Whitted integrator (user is unused). */
void sy_rt_whitted_tile(const sy_rt_frame *f, void *user, uint32_t x0, uint32_t y0, uint32_t x1, uint32_t y1);

#endif /* SY_RT_WHITTED_H */
