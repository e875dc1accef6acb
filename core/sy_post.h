/** @file
 * sy_post.h — the display post-process chain: exposure, tone mapping (Reinhard, ACES filmic fit),
 * exact sRGB encoding, and red-cyan anaglyph of a stereo pair. It runs on finished layers
 * (per viewport before compositing, or per window after it), never inside a back-end, so
 * display-only parameters never restart a progressive back-end's accumulation.
 * Thread-safety: pure functions on caller-owned memory. */
#ifndef SY_POST_H
#define SY_POST_H

#include "sy_mediator.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Tone-mapping operators. */
typedef enum sy_tonemap {
    SY_TONEMAP_CLAMP = 0,    /**< plain clamp to [0, 1] (a zero-initialised chain's) */
    SY_TONEMAP_REINHARD = 1, /**< x / (1 + x) */
    SY_TONEMAP_ACES = 2,     /**< Narkowicz 2015 ACES filmic fit, then clamp */
    SY_TONEMAP_MAX_ENUM = 0x7fffffff
} sy_tonemap;

/** Exact piecewise sRGB OETF: linear [0, 1] -> encoded [0, 1]; input is clamped, NaN gives 0. */
float sy_srgb_encode(float linear);
/** Exact inverse (EOTF): encoded [0, 1] -> linear [0, 1]; input is clamped, NaN gives 0. */
float sy_srgb_decode(float encoded);
/** One channel in [0, 1] to 8 bits, rounded to nearest: the one float-to-8-bit conversion of
 * the library (PNG, JPEG, the window, the web stream). Clamps; NaN gives 0. */
uint8_t sy_unorm8(float v);
/** Applies the operator to one linear channel value; returns [0, 1]. Negative and NaN give 0,
 * +INFINITY gives 1. An unknown operator behaves as CLAMP. */
float sy_tonemap_apply(sy_tonemap op, float linear);

/** A post-process chain. Zero-initialised = disabled (identity). */
typedef struct sy_post_desc {
    bool enabled; /**< false = identity (the rest is ignored) */
    float exposure_stops; /**< colour x 2^stops */
    uint32_t tonemap;     /**< sy_tonemap */
    bool srgb;            /**< encode to sRGB (display-referred output in [0, 1]) */
} sy_post_desc;

/** The tone map of every image meant to be looked at (a window, a browser's canvas, a PNG, a
 * contact sheet), unless the user asks for another: one policy for every program. */
#define SY_TONEMAP_DISPLAY SY_TONEMAP_ACES
/** The display chain: SY_TONEMAP_DISPLAY, then sRGB encoding, no exposure change. */
sy_post_desc sy_post_display(void);

/** Applies the chain in place to un-premultiplied colour (alpha and depth untouched; colour is
 * re-premultiplied afterwards). No-op when !post->enabled. */
void sy_layer_post_apply(sy_layer *l, const sy_post_desc *post);

/** Red-cyan colour anaglyph of two equally sized layers: red from the left eye, green and blue
 * from the right; alpha and depth are the per-pixel maximum / minimum. out may alias neither. */
sy_result sy_layer_anaglyph(const sy_layer *left, const sy_layer *right, sy_layer *out, sy_error *err);

#ifdef __cplusplus
}
#endif
#endif /* SY_POST_H */
