/* sy_rt_iridescence.h — KHR_materials_iridescence's thin-film Fresnel for the path tracer and
 * Whitted: the reflectance of a thin dielectric film (index film_ior, thickness in nm) over a base of
 * normal-incidence reflectance f0, at incidence cosine cos_i from air, as the specification's
 * appendix and the Khronos glTF Sample Viewer (iridescence.glsl, after Belcour and Barla 2017,
 * "A Practical Extension to Microfacet Theory for the Modeling of Varying Iridescence") evaluate
 * it: Airy summation of two orders with the spectral sensitivity folded into linear Rec.709 RGB;
 * one change: the air-film interface reflects by exact Fresnel (Schlick there reflects at grazing
 * angles even when the film has the outside's index), so a film fading out (thinner than 30 nm)
 * leaves exactly the base's Schlick Fresnel.
 * Pure function, thread-safe. Internal to backends/rt. */
#ifndef SY_RT_IRIDESCENCE_H
#define SY_RT_IRIDESCENCE_H

#include "sy_rt_math.h"

sy_rt_v3 sy_rt_iridescence_fresnel(float cos_i, float film_ior, float thickness_nm, sy_rt_v3 f0);

#endif /* SY_RT_IRIDESCENCE_H */
