/* sy_rt_texture.h — textures of the ray-tracing back-end: storage of 8-bit (sRGB/linear) and
 * float texels with their sampler, and the bilinear/nearest lookup with repeat/clamp/mirror wrap
 * used by the integrators. Internal to backends/rt. */
#ifndef SY_RT_TEXTURE_H
#define SY_RT_TEXTURE_H

#include "sy_rt_device.h"

typedef struct sy_rt_texture_data {
    uint32_t width, height, channels;
    sy_rt_texel_format format;
    void *pixels;           /* own copy: uint8_t or float */
    const float *srgb_lut;  /* device LUT for SY_RT_TEXEL_UNORM8_SRGB, else NULL */
    sy_rt_wrap wrap_s, wrap_t;
    sy_rt_filter filter;
    /* Where texels are zero, for sy_rt_texture_region_zero: a summed-area table over blocks of
     * 2^zero_shift x 2^zero_shift texels counting the blocks that hold a texel with a non-zero
     * colour channel ((zero_bw + 1) x (zero_bh + 1) entries, at most 513 x 513), built on first use;
     * NULL until then (zero_failed: its allocation failed, every region counts as lit). */
    uint32_t *zero_sat;
    uint32_t zero_shift, zero_bw, zero_bh;
    bool zero_failed;
} sy_rt_texture_data;

/* Samples at glTF texture coordinates (u, v), (0,0) = top-left of the image. out = linear RGBA
 * (grey is replicated to RGB, missing alpha is 1). */
void sy_rt_texture_sample(const sy_rt_texture_data *tex, float u, float v, float out[4]);

/* sy_rt_texture_sample_ref for a set handle (out of line). */
bool sy_rt_texture_sample_set_ref(const sy_rt_device *dev, const sy_rt_texture_ref *ref, const float uv[2][2],
                                  float out[4]);
/* Looks up ref's texture in dev and samples it at ref's texture-coordinate set of uv (both sets of
 * the hit point), through ref's transform; returns false (out untouched) for a zero/stale handle.
 * The common untextured slot costs a test, not a call. */
static inline bool sy_rt_texture_sample_ref(const sy_rt_device *dev, const sy_rt_texture_ref *ref,
                                            const float uv[2][2], float out[4])
{
    return ref->texture.id != 0 && sy_rt_texture_sample_set_ref(dev, ref, uv, out);
}

/* The texture coordinates ref reads at a hit point with coordinate sets uv (transform applied). */
void sy_rt_texture_ref_uv(const sy_rt_texture_ref *ref, const float uv[2][2], float out[2]);

/* True when every lookup of tex (either filter, any wrap mode) at texture coordinates inside the
 * triangle uv[0..2] reads a texel whose colour channels are all zero (alpha aside): such a
 * triangle of a textured emitter emits nothing. False when unsure (non-finite coordinates, no
 * memory for the table). Builds tex's block table on first use (O(texels), then O(1) a triangle):
 * not thread-safe; the light tree's build calls it, never a render thread. */
bool sy_rt_texture_region_zero(sy_rt_texture_data *tex, const float uv[3][2]);

/* Frees a texture object (pool removal is the caller's). */
void sy_rt_texture_free(sy_rt_texture_data *tex);

#endif /* SY_RT_TEXTURE_H */
