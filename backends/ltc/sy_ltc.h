/* sy_ltc.h — the linearly-transformed-cosine tables for GGX (Heitz et al. 2016; the data, its source
 * and licence: data/README.md), shared by the rasterizer (uploaded as two 64 x 64 RGBA float
 * textures, sy_gl_ibl.c) and the ray tracer (Whitted's analytic area lights and its split-sum
 * environment, sy_rt_whitted.c). Data only: includes no back-end header; each back-end compiles it
 * in (backends/ltc/CMakeLists.txt, sy_ltc_use).
 *
 * Layout (row-major, texel (x, y) at [(y * 64 + x) * 4]): x = roughness (perceptual, glTF's),
 * y = sqrt(1 - cos theta_v); sampled at uv * (63/64) + 0.5/64.
 *  ltc1: the inverse transform M^-1 = mat3((a, 0, b), (0, 1, 0), (c, 0, d)) as (a, b, c, d)
 *        in the (T1, T2, N) frame with T1 in the plane of N and the view direction.
 *  ltc2: x = BRDF norm with F0 = 1, y = the Fresnel (1 - F0) part (specular = F0 x + (1-F0) y),
 *        w = the horizon-clipped sphere form factor indexed by (x = 0.5 + 0.5 z, y = |F|)
 *        for the clipless polygon integral. */
#ifndef SY_LTC_H
#define SY_LTC_H

#define SY_LTC_SIZE 64
#define SY_LTC_FLOATS (SY_LTC_SIZE * SY_LTC_SIZE * 4) /**< floats in one table */

/* Decodes the two tables (data/ltc_ggx.bin, embedded at build time) into ltc1 and ltc2, each of
 * SY_LTC_FLOATS floats owned by the caller. Reads constant data only: thread-safe. */
void sy_ltc_tables(float *ltc1, float *ltc2);

#endif /* SY_LTC_H */
