/* sy_post.c — exposure, tone mapping, sRGB and anaglyph on layers (see sy_post.h). */
#include "sy_post.h"

#include <math.h>

float sy_srgb_encode(float linear)
{
    if (!(linear > 0.0f)) return 0.0f; /* also NaN */
    if (linear >= 1.0f) return 1.0f;
    if (linear <= 0.0031308f) return 12.92f * linear;
    return 1.055f * powf(linear, 1.0f / 2.4f) - 0.055f;
}

uint8_t sy_unorm8(float v)
{
    if (!(v > 0.0f)) return 0; /* also NaN */
    if (v >= 1.0f) return 255;
    return (uint8_t)(v * 255.0f + 0.5f);
}

float sy_srgb_decode(float encoded)
{
    if (!(encoded > 0.0f)) return 0.0f;
    if (encoded >= 1.0f) return 1.0f;
    if (encoded <= 0.04045f) return encoded / 12.92f;
    return powf((encoded + 0.055f) / 1.055f, 2.4f);
}

float sy_tonemap_apply(sy_tonemap op, float x)
{
    if (!(x > 0.0f)) return 0.0f; /* negative, zero and NaN */
    if (isinf(x)) return 1.0f;
    float y;
    switch (op) {
    case SY_TONEMAP_REINHARD: y = x / (1.0f + x); break;
    case SY_TONEMAP_ACES: y = (x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f); break;
    case SY_TONEMAP_CLAMP:
    default: y = x; break;
    }
    if (!(y > 0.0f)) return 0.0f;
    return y < 1.0f ? y : 1.0f;
}

sy_post_desc sy_post_display(void)
{
    sy_post_desc d = {.enabled = true, .tonemap = SY_TONEMAP_DISPLAY, .srgb = true};
    return d;
}

void sy_layer_post_apply(sy_layer *l, const sy_post_desc *post)
{
    if (!post || !post->enabled) return;
    float scale = exp2f(post->exposure_stops);
    size_t n = (size_t)l->width * l->height;
    for (size_t i = 0; i < n; ++i) {
        float *p = l->rgba + 4 * i;
        float a = p[3];
        if (!(a > 0.0f)) {
            p[0] = p[1] = p[2] = 0.0f;
            continue;
        }
        for (int c = 0; c < 3; ++c) {
            float v = sy_tonemap_apply((sy_tonemap)post->tonemap, p[c] / a * scale);
            if (post->srgb) v = sy_srgb_encode(v);
            p[c] = v * a;
        }
    }
}

sy_result sy_layer_anaglyph(const sy_layer *left, const sy_layer *right, sy_layer *out, sy_error *err)
{
    if (left->width != right->width || left->height != right->height || out->width != left->width ||
        out->height != left->height)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "anaglyph: layers of different sizes (%ux%u, %ux%u, %ux%u)",
                            left->width, left->height, right->width, right->height, out->width, out->height);
    size_t n = (size_t)left->width * left->height;
    for (size_t i = 0; i < n; ++i) {
        const float *a = left->rgba + 4 * i, *b = right->rgba + 4 * i;
        float *o = out->rgba + 4 * i;
        o[0] = a[0];
        o[1] = b[1];
        o[2] = b[2];
        o[3] = a[3] > b[3] ? a[3] : b[3];
        out->depth[i] = left->depth[i] < right->depth[i] ? left->depth[i] : right->depth[i];
    }
    return SY_OK;
}
