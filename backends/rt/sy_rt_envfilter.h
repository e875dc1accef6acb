/* sy_rt_envfilter.h — the environment light prefiltered for Whitted (the rasterizer's split-sum
 * image-based lighting, sy_gl_ibl.c, done on the CPU): GGX-prefiltered lat-long maps at roughness
 * 0.2, 0.4, .., 1 (normal = view = reflection direction, 64 deterministic Hammersley samples per
 * texel read from a box-filtered mip chain of the map, filtered importance sampling; 64 x 32 and
 * 32 x 16 texels) and a cosine-convolved irradiance map (32 x 16). Built once per committed environment on the first Whitted
 * render (sy_rt_envfilter_ensure), freed with the environment (sy_rt_env_free); read-only while
 * rendering. Radiance without the environment's intensity (the lookups multiply it in).
 * Internal to backends/rt. */
#ifndef SY_RT_ENVFILTER_H
#define SY_RT_ENVFILTER_H

#include "sy_rt_device.h"

#define SY_RT_ENVF_LEVELS 6 /* level k: roughness k / (LEVELS - 1); level 0 is the map itself */

typedef struct sy_rt_envf_map {
    uint32_t w, h;
    float *rgb; /* w x h x 3, row 0 = +y (v = 0), u = 0.5 + atan2(x, -z) / 2 pi as the environment */
} sy_rt_envf_map;

typedef struct sy_rt_envfilter {
    sy_rt_envf_map spec[SY_RT_ENVF_LEVELS]; /* [0] unused (the environment itself) */
    sy_rt_envf_map irr;                     /* E(n) / pi: what a white Lambert surface reflects */
    size_t bytes;
} sy_rt_envfilter;

/* Builds dev->env_filter for the committed environment when there is one and it has none yet.
 * Fails only when out of memory (the device keeps no filter then). */
sy_rt_result sy_rt_envfilter_ensure(sy_rt_device *dev);
void sy_rt_envfilter_free(sy_rt_envfilter *f);

/* Bilinear look-up of map m in direction d (unit): u wraps, v clamps. */
sy_rt_v3 sy_rt_envf_lookup(const sy_rt_envf_map *m, sy_rt_v3 d);
/* The same with d's lat-long coordinates (sy_rt_latlong_uv) given (several maps, one d). */
sy_rt_v3 sy_rt_envf_lookup_uv(const sy_rt_envf_map *m, float u, float v);

#endif /* SY_RT_ENVFILTER_H */
