/* sy_filter_metrics.c — RMSE, relative MSE and SSIM (Wang et al. 2004), see sy_filter_metrics.h. */
#include "sy_filter_metrics.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>

static float srgb_encode(float v)
{
    if (!(v > 0.0f)) return 0.0f;
    if (v >= 1.0f) return 1.0f;
    return v <= 0.0031308f ? 12.92f * v : 1.055f * powf(v, 1.0f / 2.4f) - 0.055f;
}

enum { SSIM_R = 5 }; /* the Gaussian window's radius (sigma 1.5) */

/* One pass of the separable Gaussian over w x h pixels, along y when vertical, else along x: out
 * holds 5 values per pixel, the window's weighted means of the moments a, b, a^2, b^2, ab, taken
 * at each tap from the images a and b (the first pass, in NULL) or read from in (the second). */
static void moments_pass(const float *g, uint32_t w, uint32_t h, bool vertical, const float *a, const float *b,
                         const float *in, float *out)
{
    const int R = SSIM_R;
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            double s[5] = {0, 0, 0, 0, 0}, W = 0;
            for (int k = -R; k <= R; ++k) {
                int xx = (int)x + (vertical ? 0 : k), yy = (int)y + (vertical ? k : 0);
                if (xx < 0 || xx >= (int)w || yy < 0 || yy >= (int)h) continue;
                size_t i = (size_t)yy * w + xx;
                float wt = g[k + R];
                if (in) {
                    for (int q = 0; q < 5; ++q) s[q] += wt * in[5 * i + q];
                } else {
                    float va = a[i], vb = b[i];
                    s[0] += wt * va, s[1] += wt * vb, s[2] += wt * va * va, s[3] += wt * vb * vb, s[4] += wt * va * vb;
                }
                W += wt;
            }
            for (int q = 0; q < 5; ++q) out[5 * ((size_t)y * w + x) + q] = (float)(s[q] / W);
        }
}

void sy_filter_luma_rgba8(const uint8_t *rgba, size_t n, float *out)
{
    for (size_t i = 0; i < n; ++i)
        out[i] = (0.2126f * rgba[4 * i] + 0.7152f * rgba[4 * i + 1] + 0.0722f * rgba[4 * i + 2]) / 255.0f;
}

double sy_filter_ssim_gray(const float *a, const float *b, uint32_t w, uint32_t h)
{
    const int R = SSIM_R;
    float g[2 * SSIM_R + 1];
    for (int k = -R; k <= R; ++k) g[k + R] = expf(-0.5f * (float)(k * k) / (1.5f * 1.5f));
    const double C1 = (0.01 * 1.0) * (0.01 * 1.0), C2 = (0.03 * 1.0) * (0.03 * 1.0);
    size_t n = (size_t)w * h;
    /* separable Gaussian moments: mu_a, mu_b, E[a^2], E[b^2], E[ab] */
    float *tmp = malloc(5 * n * sizeof(float)), *mom = malloc(5 * n * sizeof(float));
    if (!tmp || !mom) {
        free(tmp), free(mom);
        return NAN;
    }
    moments_pass(g, w, h, false, a, b, NULL, tmp);
    moments_pass(g, w, h, true, NULL, NULL, tmp, mom);
    double total = 0;
    for (size_t i = 0; i < n; ++i) {
        const float *m = mom + 5 * i;
        double ma = m[0], mb = m[1];
        double va = fmax(m[2] - ma * ma, 0.0), vb = fmax(m[3] - mb * mb, 0.0), cov = m[4] - ma * mb;
        total += ((2 * ma * mb + C1) * (2 * cov + C2)) / ((ma * ma + mb * mb + C1) * (va + vb + C2));
    }
    free(tmp), free(mom);
    return total / (double)n;
}

sy_filter_status sy_filter_metrics_compute(const float *img, const float *ref, uint32_t w, uint32_t h, uint32_t ch,
                                           sy_filter_metrics *out, sy_filter_report *err)
{
    if (!img || !ref || !out) return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "metrics: NULL buffer");
    if (w == 0 || h == 0 || w > SY_FILTER_MAX_SIDE || h > SY_FILTER_MAX_SIDE || (ch != 3 && ch != 4))
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "metrics: size %ux%u x %u channels invalid", w, h,
                              ch);
    size_t n = (size_t)w * h;
    float *la = malloc(n * sizeof(float)), *lb = malloc(n * sizeof(float));
    if (!la || !lb) {
        free(la), free(lb);
        return sy_filter_fail(err, SY_FILTER_ERROR_OUT_OF_MEMORY, "metrics: out of memory");
    }
    double se = 0, rel = 0;
    uint64_t bad = 0, cnt = 0;
    for (size_t i = 0; i < n; ++i) {
        const float *x = img + ch * i, *y = ref + ch * i;
        bool ok = isfinite(x[0]) && isfinite(x[1]) && isfinite(x[2]) && isfinite(y[0]) && isfinite(y[1]) &&
                  isfinite(y[2]);
        if (!ok) {
            ++bad;
            la[i] = lb[i] = 0.0f;
            continue;
        }
        for (int c = 0; c < 3; ++c) {
            double d = (double)x[c] - y[c];
            se += d * d;
            rel += d * d / ((double)y[c] * y[c] + 0.01);
        }
        ++cnt;
        float ex[3] = {srgb_encode(x[0]), srgb_encode(x[1]), srgb_encode(x[2])};
        float ey[3] = {srgb_encode(y[0]), srgb_encode(y[1]), srgb_encode(y[2])};
        la[i] = sy_filter_luminance(ex), lb[i] = sy_filter_luminance(ey);
    }
    out->rmse = cnt ? sqrt(se / (3.0 * (double)cnt)) : 0.0;
    out->relmse = cnt ? rel / (3.0 * (double)cnt) : 0.0;
    out->ssim = sy_filter_ssim_gray(la, lb, w, h);
    out->nonfinite = bad;
    free(la), free(lb);
    if (isnan(out->ssim)) return sy_filter_fail(err, SY_FILTER_ERROR_OUT_OF_MEMORY, "metrics: out of memory (SSIM)");
    return SY_FILTER_OK;
}
