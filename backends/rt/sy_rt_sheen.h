/* sy_rt_sheen.h — KHR_materials_sheen's microfacet lobe for the path tracer and Whitted: the
 * "Charlie" distribution (Estevez and Kulla 2017, "Production Friendly Microfacet Sheen BRDF"),
 * its fitted visibility term, and the lobe's directional albedo E(n . v, roughness) that the
 * specification's albedo scaling needs (the base below the sheen is scaled by
 * 1 - max(sheen colour) x E(n . wo)). Formulas as the Khronos glTF Sample Viewer writes them
 * (brdf.glsl: D_Charlie, V_Sheen). Pure functions on plain floats, thread-safe.
 * Internal to backends/rt. */
#ifndef SY_RT_SHEEN_H
#define SY_RT_SHEEN_H

/* Sheen roughness below this is evaluated at it: the Charlie lobe of roughness r -> 0 becomes a
 * grazing spike that neither a table nor sampling resolves (Filament's cloth model clamps the
 * same way). */
#define SY_RT_SHEEN_MIN_ROUGHNESS 0.07f

/* D_Charlie x V_Sheen (no colour, no cosine): the sheen BRDF for n . l = nl, n . v = nv,
 * n . h = nh, all > 0; r = sheen roughness, clamped to [SY_RT_SHEEN_MIN_ROUGHNESS, 1]. */
float sy_rt_sheen_brdf(float r, float nl, float nv, float nh);

/* Directional albedo of that BRDF: integral over the hemisphere of brdf x n . l, for n . v = mu,
 * read bilinearly from a 32 x 16 table over mu in [0, 1] and roughness in [0, 1]. */
float sy_rt_sheen_albedo(float mu, float r);

/* The same albedo by direct numerical quadrature over the hemisphere (theta_steps x 2
 * theta_steps midpoints); what the table was generated with and what tests check it against.
 * Slow (not for rendering). */
double sy_rt_sheen_albedo_integrate(float mu, float r, int theta_steps);

#endif /* SY_RT_SHEEN_H */
