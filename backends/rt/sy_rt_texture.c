/* sy_rt_texture.c — texture creation (validated, copied) and sampling with wrap modes and
 * nearest/bilinear filtering. */
#include "sy_rt_texture.h"

#include <stdlib.h>
#include <string.h>

sy_rt_result sy_rt_texture_create(sy_rt_device *dev, const sy_rt_texture_desc *d, sy_rt_texture *out)
{
    if (!dev || !d || !out) return sy_rt_fail(dev, SY_RT_ERROR_INVALID_ARGUMENT, "texture: NULL argument");
    out->id = 0;
    if (d->width == 0 || d->height == 0)
        return sy_rt_fail(dev, SY_RT_ERROR_INVALID_ARGUMENT, "texture: size %ux%u is empty", d->width, d->height);
    if (d->channels < 1 || d->channels > 4)
        return sy_rt_fail(dev, SY_RT_ERROR_INVALID_ARGUMENT, "texture: channels = %u, expected 1..4", d->channels);
    if (!d->pixels) return sy_rt_fail(dev, SY_RT_ERROR_INVALID_ARGUMENT, "texture: pixels is NULL");
    size_t elem;
    switch (d->format) {
    case SY_RT_TEXEL_UNORM8: case SY_RT_TEXEL_UNORM8_SRGB: elem = 1; break;
    case SY_RT_TEXEL_FLOAT32: elem = sizeof(float); break;
    default: return sy_rt_fail(dev, SY_RT_ERROR_INVALID_ARGUMENT, "texture: unknown texel format %d", (int)d->format);
    }
    if ((unsigned)d->wrap_s > SY_RT_WRAP_MIRROR || (unsigned)d->wrap_t > SY_RT_WRAP_MIRROR)
        return sy_rt_fail(dev, SY_RT_ERROR_INVALID_ARGUMENT, "texture: unknown wrap mode");
    if ((unsigned)d->filter > SY_RT_FILTER_NEAREST)
        return sy_rt_fail(dev, SY_RT_ERROR_INVALID_ARGUMENT, "texture: unknown filter");
    size_t bytes;
    if (!sy_rt_size_mul(d->width, d->height, &bytes) || !sy_rt_size_mul(bytes, d->channels, &bytes) ||
        !sy_rt_size_mul(bytes, elem, &bytes))
        return sy_rt_fail(dev, SY_RT_ERROR_LIMIT, "texture: %ux%ux%u texels overflow size_t", d->width, d->height, d->channels);

    sy_rt_texture_data *t = calloc(1, sizeof *t);
    void *px = t ? malloc(bytes) : NULL;
    if (!px) {
        free(t);
        return sy_rt_fail(dev, SY_RT_ERROR_OUT_OF_MEMORY, "texture: cannot allocate %zu bytes", bytes);
    }
    memcpy(px, d->pixels, bytes);
    t->width = d->width; t->height = d->height; t->channels = d->channels;
    t->format = d->format; t->pixels = px;
    t->srgb_lut = d->format == SY_RT_TEXEL_UNORM8_SRGB ? dev->srgb_lut : NULL;
    t->wrap_s = d->wrap_s; t->wrap_t = d->wrap_t; t->filter = d->filter;
    if (!sy_rt_pool_insert(&dev->textures, t, &out->id)) {
        sy_rt_texture_free(t);
        return sy_rt_fail(dev, SY_RT_ERROR_LIMIT, "texture: pool full or out of memory");
    }
    dev->dirty = true;
    return SY_RT_OK;
}

sy_rt_result sy_rt_texture_destroy(sy_rt_device *dev, sy_rt_texture tex)
{
    if (!dev) return sy_rt_fail(dev, SY_RT_ERROR_INVALID_ARGUMENT, "texture destroy: NULL device");
    sy_rt_texture_data *t = sy_rt_pool_take(dev, &dev->textures, tex.id, "texture destroy");
    if (!t) return SY_RT_ERROR_INVALID_HANDLE;
    sy_rt_texture_free(t);
    /* Emissive textures shape the area lights only at sample time, so no rebuild is needed. */
    dev->dirty = true;
    return SY_RT_OK;
}

void sy_rt_texture_free(sy_rt_texture_data *tex)
{
    if (!tex) return;
    free(tex->pixels);
    free(tex);
}

/* Maps an integer texel coordinate into [0, n) by the wrap mode. */
static uint32_t wrap_index(int64_t i, uint32_t n, sy_rt_wrap mode)
{
    int64_t nn = (int64_t)n;
    switch (mode) {
    case SY_RT_WRAP_CLAMP:
        return (uint32_t)(i < 0 ? 0 : (i >= nn ? nn - 1 : i));
    case SY_RT_WRAP_MIRROR: {
        int64_t m = i % (2 * nn);
        if (m < 0) m += 2 * nn;
        return (uint32_t)(m < nn ? m : 2 * nn - 1 - m);
    }
    default: {
        int64_t m = i % nn;
        return (uint32_t)(m < 0 ? m + nn : m);
    }
    }
}

/* The wrapped index of i + 1 from w, the wrapped index of i: repeat and clamp without a second
 * division (bilinear taps are neighbours). */
static uint32_t wrap_next(int64_t i, uint32_t w, uint32_t n, sy_rt_wrap mode)
{
    if (mode == SY_RT_WRAP_REPEAT) return w + 1u == n ? 0u : w + 1u;
    if (mode == SY_RT_WRAP_CLAMP) return i + 1 < 0 ? 0u : (i + 1 >= (int64_t)n ? n - 1u : (uint32_t)(i + 1));
    return wrap_index(i + 1, n, mode);
}

static void fetch(const sy_rt_texture_data *t, uint32_t x, uint32_t y, float out[4])
{
    size_t base = ((size_t)y * t->width + x) * t->channels;
    if (t->format != SY_RT_TEXEL_FLOAT32 && t->channels >= 3) { /* RGB(A) 8-bit, the common case: no per-channel tests */
        const uint8_t *b = (const uint8_t *)t->pixels + base;
        const float *lut = t->srgb_lut;
        out[0] = lut ? lut[b[0]] : (float)b[0] * (1.0f / 255.0f);
        out[1] = lut ? lut[b[1]] : (float)b[1] * (1.0f / 255.0f);
        out[2] = lut ? lut[b[2]] : (float)b[2] * (1.0f / 255.0f);
        out[3] = t->channels == 4 ? (float)b[3] * (1.0f / 255.0f) : 1.0f; /* alpha is linear */
        return;
    }
    float c[4] = {0.0f, 0.0f, 0.0f, 1.0f};
    for (uint32_t k = 0; k < t->channels; ++k) {
        if (t->format == SY_RT_TEXEL_FLOAT32) {
            c[k] = ((const float *)t->pixels)[base + k];
        } else {
            uint8_t b = ((const uint8_t *)t->pixels)[base + k];
            bool is_alpha = (t->channels == 2 && k == 1) || k == 3;
            c[k] = (t->srgb_lut && !is_alpha) ? t->srgb_lut[b] : (float)b * (1.0f / 255.0f);
        }
    }
    switch (t->channels) {
    case 1: out[0] = out[1] = out[2] = c[0]; out[3] = 1.0f; break;
    case 2: out[0] = out[1] = out[2] = c[0]; out[3] = c[1]; break;
    default: out[0] = c[0]; out[1] = c[1]; out[2] = c[2]; out[3] = c[3]; break;
    }
}

/* Texel-space coordinate, kept within a range where int64 conversion is exact and safe. */
static double texel_coord(float u, uint32_t n)
{
    if (!isfinite(u)) return 0.0;
    double x = (double)u * (double)n;
    if (x > 1e15) x = 1e15;
    if (x < -1e15) x = -1e15;
    return x;
}

void sy_rt_texture_sample(const sy_rt_texture_data *t, float u, float v, float out[4])
{
    double x = texel_coord(u, t->width), y = texel_coord(v, t->height);
    if (t->filter == SY_RT_FILTER_NEAREST) {
        fetch(t, wrap_index((int64_t)floor(x), t->width, t->wrap_s),
              wrap_index((int64_t)floor(y), t->height, t->wrap_t), out);
        return;
    }
    x -= 0.5; y -= 0.5; /* texel centres sit at half-integer coordinates */
    double fx0 = floor(x), fy0 = floor(y);
    float fx = (float)(x - fx0), fy = (float)(y - fy0);
    int64_t ix = (int64_t)fx0, iy = (int64_t)fy0;
    uint32_t x0 = wrap_index(ix, t->width, t->wrap_s), x1 = wrap_next(ix, x0, t->width, t->wrap_s);
    uint32_t y0 = wrap_index(iy, t->height, t->wrap_t), y1 = wrap_next(iy, y0, t->height, t->wrap_t);
    float a[4], b[4], c[4], d[4];
    fetch(t, x0, y0, a); fetch(t, x1, y0, b); fetch(t, x0, y1, c); fetch(t, x1, y1, d);
    for (int k = 0; k < 4; ++k) {
        float top = a[k] + (b[k] - a[k]) * fx;
        float bot = c[k] + (d[k] - c[k]) * fx;
        out[k] = top + (bot - top) * fy;
    }
}

void sy_rt_texture_ref_uv(const sy_rt_texture_ref *ref, const float uv[2][2], float out[2])
{
    const float *c = uv[ref->texcoord & 1u];
    if (!ref->transformed) {
        out[0] = c[0];
        out[1] = c[1];
        return;
    }
    const float *m = ref->transform;
    out[0] = m[0] * c[0] + m[1] * c[1] + m[2];
    out[1] = m[3] * c[0] + m[4] * c[1] + m[5];
}

bool sy_rt_texture_sample_set_ref(const sy_rt_device *dev, const sy_rt_texture_ref *ref, const float uv[2][2],
                                  float out[4])
{
    const sy_rt_texture_data *t = sy_rt_pool_get(&dev->textures, ref->texture.id);
    if (!t) return false;
    float c[2];
    sy_rt_texture_ref_uv(ref, uv, c);
    sy_rt_texture_sample(t, c[0], c[1], out);
    return true;
}
