/* sy_rt_shadow.h — shadow rays shared by the integrators: the light a segment lets through.
 * Alpha-masked holes are cut by the Embree filter (sy_rt_surface.h); alpha-blended surfaces pass
 * 1 - alpha; with `transmission` set, KHR_materials_transmission surfaces also pass
 * (1 - metallic) x transmission x base colour x (1 - F0) per crossing, F0 = specular x
 * ((ior - 1) / (ior + 1))^2: a straight-line approximation that ignores refraction (no caustic
 * focusing) and the angular dependence of Fresnel. Scenes without such materials (the device's
 * committed shadow_blend / shadow_transmission flags) pay one occlusion query, as before.
 * Internal to backends/rt; thread-safe (reads committed device state). */
#ifndef SY_RT_SHADOW_H
#define SY_RT_SHADOW_H

#include "sy_rt_frame.h"

struct sy_rt_ray_buf;

/* Transmittance (RGB in [0, 1]) of org + t*dir for t in (0, tfar). *rays (may be NULL) is
 * incremented by the rays traced; log (may be NULL, sy_rt_raylog.h) receives them. */
sy_rt_v3 sy_rt_shadow_transmittance(const sy_rt_device *dev, struct RTCIntersectContext *ctx, sy_rt_v3 org,
                                    sy_rt_v3 dir, float tfar, bool transmission, uint64_t *rays,
                                    struct sy_rt_ray_buf *log);

/* Recomputes dev->shadow_blend / shadow_transmission from the visible instances (at commit). */
void sy_rt_shadow_flags_update(sy_rt_device *dev);

#endif /* SY_RT_SHADOW_H */
