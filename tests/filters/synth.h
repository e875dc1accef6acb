/* synth.h — synthetic progressive-render surrogate shared by the filter tests and nothing else:
 * a piecewise-smooth scene (depth step, albedo checker, smooth indirect illumination) rendered
 * "at n spp" analytically as the truth plus Gaussian noise with the per-pixel variance of an
 * n-sample mean, with the AOVs a path tracer provides. Deterministic (fixed-seed xorshift). */
#ifndef SY_TEST_FILTERS_SYNTH_H
#define SY_TEST_FILTERS_SYNTH_H

#include "../support/sy_check.h"
#include "sy_filter.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

typedef struct synth {
    uint32_t w, h;
    float *color, *var, *albedo, *normal, *depth, *position, *direct, *indirect, *truth, *truth_ind;
    uint64_t rng;
} synth;

static inline double synth_uniform(uint64_t *s)
{
    *s ^= *s << 13, *s ^= *s >> 7, *s ^= *s << 17;
    return ((*s >> 11) + 0.5) * (1.0 / 9007199254740992.0);
}

static inline double synth_gauss(uint64_t *s)
{
    double u = synth_uniform(s), v = synth_uniform(s);
    return sqrt(-2.0 * log(u)) * cos(6.283185307179586 * v);
}

/* geometry/material only (truth); rel_sd = per-sample relative std. dev. of the indirect part.
 * 0, or 1 after a failed check. */
static inline int synth_init(synth *s, uint32_t w, uint32_t h, uint64_t seed)
{
    size_t n = (size_t)w * h;
    s->w = w, s->h = h, s->rng = seed ? seed : 1;
    s->color = calloc(4 * n, sizeof(float)), s->var = calloc(n, sizeof(float));
    s->albedo = calloc(3 * n, sizeof(float)), s->normal = calloc(3 * n, sizeof(float));
    s->depth = calloc(n, sizeof(float)), s->position = calloc(3 * n, sizeof(float));
    s->direct = calloc(3 * n, sizeof(float)), s->indirect = calloc(3 * n, sizeof(float));
    s->truth = calloc(4 * n, sizeof(float)), s->truth_ind = calloc(3 * n, sizeof(float));
    CHECK(s->color && s->var && s->albedo && s->normal && s->depth && s->position && s->direct && s->indirect &&
          s->truth && s->truth_ind);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            size_t i = (size_t)y * w + x;
            bool right = x >= w / 2;
            float d = right ? 6.0f : 2.0f; /* depth step in the middle */
            bool check = y < h / 2 && (((x / 16) + (y / 16)) & 1);
            float a[3] = {0.7f, 0.7f, 0.7f};
            if (check) a[0] = 0.8f, a[1] = 0.3f, a[2] = 0.2f;
            if (right) a[0] *= 0.6f, a[2] = 0.7f;
            float E = 0.5f + 0.3f * sinf((float)x / 40.0f) * cosf((float)y / 30.0f);
            if (right) E *= 0.4f;
            for (int c = 0; c < 3; ++c) {
                s->albedo[3 * i + c] = a[c];
                s->truth_ind[3 * i + c] = a[c] * E;
                s->direct[3 * i + c] = a[c] * (right ? 0.1f : 0.3f);
                s->truth[4 * i + c] = s->truth_ind[3 * i + c] + s->direct[3 * i + c];
            }
            s->truth[4 * i + 3] = 1.0f;
            s->normal[3 * i + 2] = 1.0f;
            if (right) s->normal[3 * i + 0] = 0.6f, s->normal[3 * i + 2] = 0.8f;
            s->depth[i] = d;
            s->position[3 * i + 0] = ((float)x - (float)w / 2) * 0.01f * d;
            s->position[3 * i + 1] = ((float)h / 2 - (float)y) * 0.01f * d;
            s->position[3 * i + 2] = -d;
        }
    return 0;
}

/* Noisy n-spp render: indirect mean + N(0, (rel_sd*ind)^2/n) per channel (fully correlated
 * across channels, as one path), variance estimate with chi-square-like error. */
static inline void synth_render(synth *s, float spp, float rel_sd)
{
    size_t n = (size_t)s->w * s->h;
    for (size_t i = 0; i < n; ++i) {
        double g = synth_gauss(&s->rng);
        float lum = sy_filter_luminance(s->truth_ind + 3 * i);
        for (int c = 0; c < 3; ++c) {
            float m = s->truth_ind[3 * i + c];
            s->indirect[3 * i + c] = m + (float)g * rel_sd * m / sqrtf(spp);
            s->color[4 * i + c] = s->indirect[3 * i + c] + s->direct[3 * i + c];
        }
        s->color[4 * i + 3] = 1.0f;
        double e = spp > 1.5f ? 1.0 + synth_gauss(&s->rng) * sqrt(2.0 / (spp - 1.0)) : 0.0;
        if (e < 0.05) e = spp > 1.5f ? 0.05 : 0.0;
        s->var[i] = (float)((rel_sd * lum) * (rel_sd * lum) / spp * e);
    }
}

static inline sy_filter_frame synth_frame(const synth *s, float spp)
{
    return (sy_filter_frame){.width = s->w, .height = s->h, .color_channels = 4, .variance_channels = 1,
                             .color = s->color, .variance = s->var, .albedo = s->albedo, .normal = s->normal,
                             .depth = s->depth, .position = s->position, .direct = s->direct,
                             .indirect = s->indirect, .spp_uniform = spp};
}

/* Frees the buffers; 0, so that a test ends with `return synth_free(&s);`. */
static inline int synth_free(synth *s)
{
    free(s->color), free(s->var), free(s->albedo), free(s->normal), free(s->depth), free(s->position);
    free(s->direct), free(s->indirect), free(s->truth), free(s->truth_ind);
    return 0;
}

static inline double rel_mse(const float *img, const float *ref, size_t n)
{
    double r = 0;
    for (size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c) {
            double d = (double)img[4 * i + c] - ref[4 * i + c];
            r += d * d / ((double)ref[4 * i + c] * ref[4 * i + c] + 0.01);
        }
    return r / (3.0 * (double)n);
}

#endif
