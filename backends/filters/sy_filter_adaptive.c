/* sy_filter_adaptive.c — adaptive-resolution preview after ../shared/seeds/003 (see
 * sy_filter_adaptive.h). */
#include "sy_filter_adaptive.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define MAX_LEVELS 13

void sy_filter_adaptive_params_default(sy_filter_adaptive_params *p)
{
    *p = (sy_filter_adaptive_params){.target_spp = 4.0f, .variance_weight = 0.5f, .threshold = 0.01f,
                                     .max_level = 5, .threads = 0};
}

sy_filter_status sy_filter_adaptive_params_check(const sy_filter_adaptive_params *p, sy_filter_report *err)
{
    sy_filter_status s;
    if (!p) return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "adaptive preview: params is NULL");
    if ((s = sy_filter_check_range(p->target_spp, 1.0f, 1e6f, "adaptive preview: target_spp", err))) return s;
    if ((s = sy_filter_check_nonnegative(p->variance_weight, "adaptive preview: variance_weight", err))) return s;
    if ((s = sy_filter_check_positive(p->threshold, "adaptive preview: threshold", err))) return s;
    if (p->max_level > MAX_LEVELS - 1)
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "adaptive preview: max_level = %u: at most %d",
                              p->max_level, MAX_LEVELS - 1);
    return sy_filter_check_threads(p->threads, "adaptive preview", err);
}

/* texel: sum n*c (3), sum n, sum n^2 var (of the mean) */
typedef struct level {
    uint32_t w, h;
    float *t; /* 5 floats per texel */
} level;

typedef struct actx {
    const sy_filter_adaptive_params *p;
    const sy_filter_frame *in;
    const uint8_t *ok;
    level *lv;
    uint32_t nlev;
    float *out, *lvl_out;
} actx;

static void sample_level(const level *L, uint32_t l, uint32_t x, uint32_t y, float out[3], float *wsum)
{
    float scale = (float)(1u << l);
    float fx = ((float)x + 0.5f) / scale - 0.5f, fy = ((float)y + 0.5f) / scale - 0.5f;
    const float R = 2.5f;
    int x0 = (int)ceilf(fx - R), x1 = (int)floorf(fx + R), y0 = (int)ceilf(fy - R), y1 = (int)floorf(fy + R);
    double acc[3] = {0, 0, 0}, W = 0;
    for (int ty = y0; ty <= y1; ++ty) {
        if (ty < 0 || ty >= (int)L->h) continue;
        for (int tx = x0; tx <= x1; ++tx) {
            if (tx < 0 || tx >= (int)L->w) continue;
            float dx = (float)tx - fx, dy = (float)ty - fy, d = sqrtf(dx * dx + dy * dy);
            if (d >= R) continue;
            float t = d / R, sm = t * t * (3.0f - 2.0f * t), sm2 = sm * sm, sm4 = sm2 * sm2;
            float g = expf(-0.5f * d * d) * (1.0f - sm4 * sm4); /* sigma = 1 texel, window E = 8 */
            const float *tx5 = L->t + 5 * ((size_t)ty * L->w + tx);
            for (int c = 0; c < 3; ++c) acc[c] += g * tx5[c];
            W += g * tx5[3];
        }
    }
    for (int c = 0; c < 3; ++c) out[c] = W > 0 ? (float)(acc[c] / W) : 0.0f;
    *wsum = (float)W;
}

static void out_rows(void *vctx, uint32_t y0, uint32_t y1)
{
    actx *c = vctx;
    const sy_filter_adaptive_params *p = c->p;
    uint32_t w = c->in->width;
    uint32_t vl = c->nlev > 2 ? 2 : c->nlev - 1; /* variance read through a coarser level (seed step 1) */
    for (uint32_t y = y0; y < y1; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            size_t i = (size_t)y * w + x;
            float n = sy_filter_pixel_spp(c->in, i);
            float lvl = log2f(p->target_spp / n) * 0.5f;
            /* a variance estimate needs two samples: below that only the density term counts */
            if (c->in->variance && p->variance_weight > 0.0f && n >= 2.0f) {
                const level *L = &c->lv[vl];
                uint32_t tx = x >> vl, ty = y >> vl;
                if (tx >= L->w) tx = L->w - 1;
                if (ty >= L->h) ty = L->h - 1;
                const float *t = L->t + 5 * ((size_t)ty * L->w + tx);
                if (t[3] > 0.0f) {
                    float m[3] = {t[0] / t[3], t[1] / t[3], t[2] / t[3]};
                    float lm = sy_filter_luminance(m);
                    float lb = lm / fmaxf(1.0f - lm, 1e-6f); /* expanded mean luminance */
                    /* variance of one pixel's mean ~ the level's variance times its pixel count */
                    float u0 = t[4] / (t[3] * t[3]) * (float)(1u << (2 * vl)) / fmaxf(lb * lb, 1e-12f);
                    lvl += p->variance_weight * 0.5f * log2f(fmaxf(u0 / p->threshold, 1e-12f));
                }
            }
            /* a pixel whose own estimate has no variance after two or more samples (emitters seen
             * directly, background) is exact: never blur it (nor spread its energy into the mip) */
            if (c->in->variance && n >= 2.0f && c->ok[i] && sy_filter_pixel_variance(c->in, i) == 0.0f) lvl = 0.0f;
            if (!c->ok[i] && lvl < 1.0f) lvl = 1.0f; /* a NaN/Inf pixel is shown from its neighbours */
            if (!(lvl > 0.0f)) lvl = 0.0f;
            if (lvl > (float)(c->nlev - 1)) lvl = (float)(c->nlev - 1);
            float *o = c->out + 4 * i;
            uint32_t l0 = (uint32_t)lvl;
            float fr = lvl - (float)l0, a[3], b[3], wa, wb;
            const float *own = c->in->color + (size_t)c->in->color_channels * i;
            if (lvl == 0.0f) { /* level 0: the accumulated pixel itself, bit-exact */
                for (int q = 0; q < 3; ++q) o[q] = own[q];
                o[3] = c->in->color_channels == 4 && isfinite(own[3]) ? own[3] : 1.0f;
                if (c->lvl_out) c->lvl_out[i] = 0.0f;
                continue;
            }
            if (l0 == 0) { /* own colour, range-compressed like the pyramid */
                float comp = 1.0f / (1.0f + fmaxf(sy_filter_luminance(own), 0.0f));
                for (int q = 0; q < 3; ++q) a[q] = own[q] * comp;
                wa = 1.0f;
            } else
                sample_level(&c->lv[l0], l0, x, y, a, &wa);
            if (fr > 0.0f && l0 + 1 < c->nlev) {
                sample_level(&c->lv[l0 + 1], l0 + 1, x, y, b, &wb);
                if (wa <= 0.0f) fr = 1.0f;
                if (wb <= 0.0f) fr = 0.0f;
            } else
                b[0] = b[1] = b[2] = 0.0f, fr = 0.0f;
            float v[3], lo = 0.0f;
            for (int q = 0; q < 3; ++q) v[q] = (1.0f - fr) * a[q] + fr * b[q];
            lo = sy_filter_luminance(v);
            float ex = 1.0f / fmaxf(1.0f - lo, 1e-6f); /* expand: c = v / (1 - lum(v)) */
            for (int q = 0; q < 3; ++q) o[q] = v[q] * ex;
            o[3] = c->in->color_channels == 4 && isfinite(c->in->color[4 * i + 3]) ? c->in->color[4 * i + 3] : 1.0f;
            if (c->lvl_out) c->lvl_out[i] = lvl;
        }
}

sy_filter_status sy_filter_adaptive(const sy_filter_adaptive_params *p, const sy_filter_frame *in, float *out,
                                    float *level_out, sy_filter_stats *stats, sy_filter_report *err)
{
    double t0 = sy_filter_clock(false);
    sy_filter_adaptive_params d;
    if (!p) sy_filter_adaptive_params_default(&d), p = &d;
    sy_filter_status s = sy_filter_adaptive_params_check(p, err);
    if (s) return s;
    uint32_t need = SY_FILTER_NEED_COLOR;
    if ((s = sy_filter_check_frame(in, need, "adaptive preview", err))) return s;
    if (!out) return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "adaptive preview: output is NULL");
    if (in->variance && in->variance_channels != 1 && in->variance_channels != 3)
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT,
                              "adaptive preview: variance_channels = %u: must be 1 or 3", in->variance_channels);
    if (in->variance) need |= SY_FILTER_NEED_VARIANCE;
    size_t n = (size_t)in->width * in->height;
    level lv[MAX_LEVELS] = {{0}};
    uint32_t nlev = 0;
    uint8_t *ok = malloc(n);
    bool oom = !ok;
    for (uint32_t l = 0, w = in->width, h = in->height; l <= p->max_level && !oom; ++l) {
        lv[l].w = w, lv[l].h = h;
        lv[l].t = calloc((size_t)w * h * 5, sizeof(float));
        oom = !lv[l].t;
        nlev = l + 1;
        if (w == 1 && h == 1) break;
        w = (w + 1) / 2, h = (h + 1) / 2;
    }
    if (oom) {
        free(ok);
        for (uint32_t l = 0; l < nlev; ++l) free(lv[l].t);
        return sy_filter_fail(err, SY_FILTER_ERROR_OUT_OF_MEMORY, "adaptive preview: out of memory for %ux%u",
                              in->width, in->height);
    }
    uint64_t bad = sy_filter_scan_finite(in, need, ok);
    for (size_t i = 0; i < n; ++i) {
        if (!ok[i]) continue;
        float nn = sy_filter_pixel_spp(in, i);
        if (in->variance && nn >= 2.0f && sy_filter_pixel_variance(in, i) == 0.0f) continue; /* exact: see below */
        float *t = lv[0].t + 5 * i;
        /* colour stored range-compressed, c / (1 + lum(c)) (expanded after sampling): an HDR emitter
         * seen directly would otherwise bleed a bright halo over its dark neighbourhood */
        const float *col = in->color + (size_t)in->color_channels * i;
        float comp = 1.0f / (1.0f + fmaxf(sy_filter_luminance(col), 0.0f));
        for (int c = 0; c < 3; ++c) t[c] = nn * col[c] * comp;
        t[3] = nn;
        t[4] = nn * nn * sy_filter_pixel_variance(in, i);
    }
    for (uint32_t l = 1; l < nlev; ++l)
        for (uint32_t y = 0; y < lv[l].h; ++y)
            for (uint32_t x = 0; x < lv[l].w; ++x) {
                float *t = lv[l].t + 5 * ((size_t)y * lv[l].w + x);
                for (uint32_t dy = 0; dy < 2; ++dy)
                    for (uint32_t dx = 0; dx < 2; ++dx) {
                        uint32_t sx = 2 * x + dx, sy = 2 * y + dy;
                        if (sx >= lv[l - 1].w || sy >= lv[l - 1].h) continue;
                        const float *u = lv[l - 1].t + 5 * ((size_t)sy * lv[l - 1].w + sx);
                        for (int c = 0; c < 5; ++c) t[c] += u[c];
                    }
            }
    actx c = {.p = p, .in = in, .ok = ok, .lv = lv, .nlev = nlev, .out = out, .lvl_out = level_out};
    sy_filter_parallel_rows(p->threads, in->height, out_rows, &c);
    free(ok);
    for (uint32_t l = 0; l < nlev; ++l) free(lv[l].t);
    if (stats && s == SY_FILTER_OK) {
        *stats = (sy_filter_stats){.nonfinite_samples = bad, .filtered_pixels = n, .filter_pass = true,
                                   .seconds = sy_filter_clock(false) - t0};
    }
    return s;
}
