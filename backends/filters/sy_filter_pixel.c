/* sy_filter_pixel.c — pixel filtering (Schwenk 2013 ch. 3): range buffer composition, brute-force
 * and iterated separable cross bilateral filters with per-pixel variance reduction factor r,
 * adaptive widths, antialiasing recovery, and the blending operator with spike withholding.
 * Section numbers refer to ../shared/notes/filters-spec.md. */
#include "sy_filter_pixel.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define MAX_TAPS 511 /* separable pass window (2R+1), R <= 255 */
#define MISS_DEPTH 1e18f /* squared differences stay finite in float */
#define EXP_SCALE 64.0f
#define EXP_TABLE 1280 /* exp(-x) tabulated on [0, 20) */

struct sy_filter_pixel {
    sy_filter_pixel_params p;
    uint32_t w, h;
    bool have_pass;
    float *guide;   /* 4/px: range RGB + depth (copy used by the pass) */
    uint8_t *ok;    /* 1 = value and guide finite */
    float *val;     /* 4/px: HV RGB + per-sample variance (filter input / ping-pong) */
    float *tmp;     /* 4/px */
    float *racc;    /* 1/px: r propagated through one separable iteration */
    float *rtmp;    /* 1/px */
    float *sigma;   /* 1/px: spatial sigma per pixel */
    float *lf;      /* 4/px: filtered HV RGB + smoothed per-sample variance (state) */
    float *r;       /* 1/px: reduction factor of lf */
    float *a0;      /* 1/px: normalised centre weight (covariance term) */
    float *npass;   /* 1/px: spp at the pass */
    float *s;       /* 1/px: blend factor of the last run */
    float *lf3;     /* 3/px: filtered HV for diagnostics */
    float expt[EXP_TABLE + 2]; /* exp(-x) at x = i / EXP_SCALE: the separable pass's weights */
};

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void sy_filter_pixel_params_default(sy_filter_pixel_params *p)
{
    *p = (sy_filter_pixel_params){
        .threshold = 0.01f, .sigma_s = 8.0f, .sigma_c = 0.02f, .sigma_d = 2.0f, .schedule_start = 4,
        .kernel = SY_FILTER_PIXEL_SEPARABLE, .iterations = 3, .adaptive_width = true, .adaptive_c = 4.0f,
        .adaptive_sigma0 = 0.0f, .spike_withholding = true, .spike_c = 2.0f, .aa_recovery = true,
        .all_high_variance = false, .use_covariance = false, .headlight_weight = 0.5f, .threads = 0,
    };
}

sy_filter_status sy_filter_pixel_params_check(const sy_filter_pixel_params *p, sy_filter_error *err)
{
    sy_filter_status s;
    if (!p) return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "pixel filter: params is NULL");
    if ((s = sy_filter_check_nonnegative(p->threshold, "pixel filter: threshold t", err))) return s;
    if ((s = sy_filter_check_positive(p->sigma_s, "pixel filter: sigma_s", err))) return s;
    if ((s = sy_filter_check_range(p->sigma_s, 0.0f, 1000.0f, "pixel filter: sigma_s", err))) return s;
    if ((s = sy_filter_check_positive(p->sigma_c, "pixel filter: sigma_c", err))) return s;
    if ((s = sy_filter_check_positive(p->sigma_d, "pixel filter: sigma_d", err))) return s;
    if (p->schedule_start == 0 || (p->schedule_start & (p->schedule_start - 1)))
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT,
                              "pixel filter: schedule_start = %u: must be a power of two >= 1", p->schedule_start);
    if (p->kernel != SY_FILTER_PIXEL_BRUTE && p->kernel != SY_FILTER_PIXEL_SEPARABLE)
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "pixel filter: kernel = %d: unknown",
                              (int)p->kernel);
    if (p->iterations < 1 || p->iterations > 8)
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "pixel filter: iterations = %u: must be 1..8",
                              p->iterations);
    if ((s = sy_filter_check_range(p->adaptive_c, 1.0f, 1000.0f, "pixel filter: adaptive_c", err))) return s;
    if ((s = sy_filter_check_nonnegative(p->adaptive_sigma0, "pixel filter: adaptive_sigma0", err))) return s;
    if ((s = sy_filter_check_range(p->spike_c, 1.0f, 1e6f, "pixel filter: spike_c", err))) return s;
    if ((s = sy_filter_check_range(p->headlight_weight, 0.0f, 1.0f, "pixel filter: headlight_weight", err))) return s;
    if (p->threads > SY_FILTER_MAX_THREADS)
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "pixel filter: threads = %u: at most %u",
                              p->threads, SY_FILTER_MAX_THREADS);
    return SY_FILTER_OK;
}

bool sy_filter_pixel_scheduled(const sy_filter_pixel_params *p, uint32_t frame)
{
    return frame >= p->schedule_start && frame && !(frame & (frame - 1));
}

float sy_filter_blend_factor(float u, float f, float t, float c)
{
    if (!(u > t)) return 1.0f; /* case 2 (also u = f = 0) */
    if (c > 0.0f) {            /* spec 1.7 [DERIVED]: covariance c = a0 u kept */
        float den = u + f - 2.0f * c, disc = (f - c) * (f - c) - den * (f - t);
        if (disc < 0.0f || den <= 0.0f) return 0.0f;
        float s = ((f - c) + sqrtf(disc)) / den;
        return s < 0.0f ? 0.0f : s > 1.0f ? 1.0f : s;
    }
    float disc = t * u + t * f - u * f;
    if (disc < 0.0f) return 0.0f; /* case 1 */
    float s = (f + sqrtf(disc)) / (u + f);
    return s < 0.0f ? 0.0f : s > 1.0f ? 1.0f : s;
}

sy_filter_status sy_filter_range_compose(const sy_filter_frame *f, const float *cam, float hw, float *out,
                                         sy_filter_error *err)
{
    sy_filter_status s = sy_filter_check_frame(f, SY_FILTER_NEED_ALBEDO | SY_FILTER_NEED_DEPTH, "range buffer", err);
    if (s) return s;
    if ((s = sy_filter_check_range(hw, 0.0f, 1.0f, "range buffer: headlight_weight", err))) return s;
    if (!out) return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "range buffer: output is NULL");
    size_t n = (size_t)f->width * f->height;
    bool headlight = cam && f->position && f->normal;
    for (size_t i = 0; i < n; ++i) {
        const float *a = f->albedo + 3 * i;
        float k = 1.0f;
        if (headlight) {
            const float *nn = f->normal + 3 * i, *p = f->position + 3 * i;
            float v[3] = {cam[0] - p[0], cam[1] - p[1], cam[2] - p[2]};
            float lv = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
            float ln = sqrtf(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
            float c = (lv > 0.0f && ln > 0.0f) ? fabsf(nn[0] * v[0] + nn[1] * v[1] + nn[2] * v[2]) / (lv * ln) : 0.0f;
            if (!isfinite(c)) c = 0.0f;
            /* unoccluded headlight at the camera, no distance falloff (a falloff would make the
             * range colour depth dependent, which the depth term already covers) */
            k = (1.0f - hw) + hw * c;
        }
        for (int c = 0; c < 3; ++c) out[4 * i + c] = a[c] * k;
        float d = f->depth[i];
        out[4 * i + 3] = d < MISS_DEPTH ? d : MISS_DEPTH;
    }
    return SY_FILTER_OK;
}

/* ---- filter pass -------------------------------------------------------------------------- */

typedef struct pass_ctx {
    sy_filter_pixel *pf;
    const float *src; /* 4/px */
    float *dst;       /* 4/px */
    const float *rsrc;
    float *rdst;
    float *a0;
    float sig_scale; /* separable iteration scale of sigma */
    int dir;         /* 0 = horizontal, 1 = vertical */
    float inv2c, inv2d;
} pass_ctx;

static inline float range_arg(const float *gj, const float *gi, float inv2c, float inv2d)
{
    float dr = gj[0] - gi[0], dg = gj[1] - gi[1], db = gj[2] - gi[2], dd = gj[3] - gi[3];
    return (dr * dr + dg * dg + db * db) * inv2c + dd * dd * inv2d;
}

/* Brute-force 2D cross bilateral (Eq. 3.6), per-pixel sigma, truncated at 3 sigma. */
static void brute_rows(void *vctx, uint32_t y0, uint32_t y1)
{
    pass_ctx *c = vctx;
    sy_filter_pixel *pf = c->pf;
    int w = (int)pf->w, h = (int)pf->h;
    for (int y = (int)y0; y < (int)y1; ++y)
        for (int x = 0; x < w; ++x) {
            size_t j = (size_t)y * w + x;
            float sg = pf->sigma[j];
            int R = (int)ceilf(3.0f * sg);
            if (R > w + h) R = w + h;
            float inv2s = 0.5f / (sg * sg);
            const float *gj = pf->guide + 4 * j;
            bool gj_ok = isfinite(gj[0]) && isfinite(gj[1]) && isfinite(gj[2]) && !isnan(gj[3]);
            double A = 0, A2 = 0, acc[4] = {0, 0, 0, 0}, a0 = 0;
            for (int dy = -R; dy <= R; ++dy) {
                int yy = y + dy;
                if (yy < 0 || yy >= h) continue;
                for (int dx = -R; dx <= R; ++dx) {
                    int xx = x + dx;
                    if (xx < 0 || xx >= w) continue;
                    int d2 = dx * dx + dy * dy;
                    if (d2 > R * R) continue;
                    size_t i = (size_t)yy * w + xx;
                    if (!pf->ok[i]) continue;
                    float arg = (float)d2 * inv2s + (gj_ok ? range_arg(gj, pf->guide + 4 * i, c->inv2c, c->inv2d) : 0.0f);
                    float a = sy_filter_expneg(arg);
                    if (a == 0.0f) continue;
                    const float *v = c->src + 4 * i;
                    A += a, A2 += (double)a * a;
                    for (int k = 0; k < 4; ++k) acc[k] += a * v[k];
                    if (i == j) a0 = a;
                }
            }
            float *o = c->dst + 4 * j;
            if (A > 0) {
                for (int k = 0; k < 4; ++k) o[k] = (float)(acc[k] / A);
                c->rdst[j] = (float)(A2 / (A * A));
                c->a0[j] = (float)(a0 / A);
            } else {
                o[0] = o[1] = o[2] = o[3] = 0.0f;
                c->rdst[j] = 1.0f;
                c->a0[j] = 1.0f;
            }
        }
}

/* One 1D pass of the iterated separable filter (Sec. 3.6.1) with optional antialiasing recovery
 * (Sec. 3.6.5). The guide is always the original range buffer (cross filter). r propagates
 * exactly for independent inputs: r_out(j) = sum_i (a_i/A)^2 r_in(i). */
static void sep_rows(void *vctx, uint32_t y0, uint32_t y1)
{
    pass_ctx *c = vctx;
    sy_filter_pixel *pf = c->pf;
    int w = (int)pf->w, h = (int)pf->h;
    int len = c->dir == 0 ? w : h;
    bool aa = pf->p.aa_recovery;
    float wa[MAX_TAPS], w0[MAX_TAPS], w2[MAX_TAPS];
    for (int y = (int)y0; y < (int)y1; ++y)
        for (int x = 0; x < w; ++x) {
            size_t j = (size_t)y * w + x;
            int pos = c->dir == 0 ? x : y;
            ptrdiff_t step = c->dir == 0 ? 1 : w;
            float sg = pf->sigma[j] * c->sig_scale;
            if (sg < 0.3f) { /* neighbour weights < exp(-5.5): the pass is the identity here */
                memcpy(c->dst + 4 * j, c->src + 4 * j, 4 * sizeof(float));
                c->rdst[j] = c->rsrc[j];
                continue;
            }
            int R = (int)ceilf(3.0f * sg);
            if (R > (MAX_TAPS - 1) / 2) R = (MAX_TAPS - 1) / 2;
            int lo = pos - R < 0 ? -pos : -R, hi = pos + R >= len ? len - 1 - pos : R;
            float inv2s = 0.5f / (sg * sg);
            const float *gj = pf->guide + 4 * j;
            bool gj_ok = isfinite(gj[0]) && isfinite(gj[1]) && isfinite(gj[2]) && !isnan(gj[3]);
            /* antialiasing recovery: detect an edge across the pass direction at j */
            bool edge = false;
            float ahat = 0.0f, wedge = 0.0f;
            const float *g0 = NULL, *g2 = NULL;
            if (aa && gj_ok && pos > 0 && pos < len - 1 && pf->ok[j - step] && pf->ok[j + step]) {
                g0 = pf->guide + 4 * (j - step);
                g2 = pf->guide + 4 * (j + step);
            }
            /* cheap gate: the Sobel gradient needs a colour step across this pixel's own row */
            if (g0) {
                float e0 = g2[0] - g0[0], e1 = g2[1] - g0[1], e2 = g2[2] - g0[2];
                if (e0 * e0 + e1 * e1 + e2 * e2 < pf->p.sigma_c * pf->p.sigma_c) g0 = g2 = NULL;
            }
            if (g0) {
                /* 1D Sobel (smoothing across the pass direction, 1-2-1) of the range RGB */
                ptrdiff_t ortho = c->dir == 0 ? w : 1;
                int opos = c->dir == 0 ? y : x, olen = c->dir == 0 ? h : w;
                float grad[3] = {0, 0, 0}, wsum = 0;
                for (int o = -1; o <= 1; ++o) {
                    if (opos + o < 0 || opos + o >= olen) continue;
                    size_t jo = (size_t)((ptrdiff_t)j + o * ortho);
                    if (!pf->ok[jo - step] || !pf->ok[jo + step]) continue;
                    float wt = o == 0 ? 2.0f : 1.0f;
                    for (int k = 0; k < 3; ++k) grad[k] += wt * (pf->guide[4 * (jo + step) + k] - pf->guide[4 * (jo - step) + k]);
                    wsum += wt;
                }
                float gm = wsum > 0 ? sqrtf(grad[0] * grad[0] + grad[1] * grad[1] + grad[2] * grad[2]) / wsum : 0.0f;
                /* [GAP spec 1.10(d)]: recovery only where the Sobel gradient marks an edge stronger
                 * than two colour sigmas; flat regions keep the symmetric window (no variance loss). */
                if (gm > 2.0f * pf->p.sigma_c) {
                    float d[3] = {g2[0] - g0[0], g2[1] - g0[1], g2[2] - g0[2]};
                    float p1[3] = {gj[0] - g0[0], gj[1] - g0[1], gj[2] - g0[2]};
                    float dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                    if (dd > 0.0f) {
                        ahat = (p1[0] * d[0] + p1[1] * d[1] + p1[2] * d[2]) / dd;
                        ahat = ahat < 0.0f ? 0.0f : ahat > 1.0f ? 1.0f : ahat;
                        float b2 = 0.0f;
                        for (int k = 0; k < 3; ++k) {
                            float e = p1[k] - ahat * d[k];
                            b2 += e * e;
                        }
                        wedge = sy_filter_expneg(0.5f * b2 / (pf->p.sigma_c * pf->p.sigma_c)); /* Eq. 3.20 */
                        edge = wedge > 1e-3f;
                    }
                }
            }
            if (!edge) { /* common case: one fused loop, float accumulators */
                float W = 0.0f, acc0 = 0.0f, acc1 = 0.0f, acc2 = 0.0f, acc3 = 0.0f, rr = 0.0f, cen = 0.0f;
                const float *gi = pf->guide + 4 * (size_t)((ptrdiff_t)j + lo * step);
                const float *vi = c->src + 4 * (size_t)((ptrdiff_t)j + lo * step);
                const float *ri = c->rsrc + (size_t)((ptrdiff_t)j + lo * step);
                const uint8_t *oki = pf->ok + (size_t)((ptrdiff_t)j + lo * step);
                /* branch-free body (invalid taps get weight 0) so the compiler can vectorise it */
                float rc = gj_ok ? c->inv2c : 0.0f, rd = gj_ok ? c->inv2d : 0.0f;
                float g0r = gj[0], g0g = gj[1], g0b = gj[2], g0d = gj_ok ? gj[3] : 0.0f;
                for (int t = lo; t <= hi; ++t, gi += 4 * step, vi += 4 * step, ri += step, oki += step) {
                    float dr = g0r - gi[0], dg = g0g - gi[1], db = g0b - gi[2], dd = g0d - gi[3];
                    float arg = (float)(t * t) * inv2s + (dr * dr + dg * dg + db * db) * rc + dd * dd * rd;
                    /* linear interpolation in the table: relative error < 3e-5 */
                    float xs = arg * EXP_SCALE;
                    xs = xs < (float)EXP_TABLE ? xs : (float)EXP_TABLE;
                    int ix = (int)xs;
                    float fr = xs - (float)ix, e0 = pf->expt[ix];
                    float a = *oki ? e0 + fr * (pf->expt[ix + 1] - e0) : 0.0f;
                    W += a;
                    acc0 += a * vi[0], acc1 += a * vi[1], acc2 += a * vi[2], acc3 += a * vi[3];
                    rr += a * a * *ri;
                }
                if (pf->ok[j]) cen = sy_filter_expneg(0.0f);
                float *o = c->dst + 4 * j;
                if (W > 0.0f) {
                    float iw = 1.0f / W;
                    o[0] = acc0 * iw, o[1] = acc1 * iw, o[2] = acc2 * iw, o[3] = acc3 * iw;
                    c->rdst[j] = rr * iw * iw;
                    if (c->a0) c->a0[j] *= cen * iw;
                } else {
                    memcpy(o, c->src + 4 * j, 4 * sizeof(float));
                    c->rdst[j] = c->rsrc[j];
                }
                continue;
            }
            double Aa = 0, A0 = 0, A2 = 0;
            for (int t = lo; t <= hi; ++t) {
                size_t i = (size_t)((ptrdiff_t)j + t * step);
                float sp = (float)(t * t) * inv2s;
                int k = t - lo;
                wa[k] = w0[k] = w2[k] = 0.0f;
                if (!pf->ok[i]) continue;
                const float *gi = pf->guide + 4 * i;
                wa[k] = sy_filter_expneg(sp + (gj_ok ? range_arg(gj, gi, c->inv2c, c->inv2d) : 0.0f));
                Aa += wa[k];
                if (edge) {
                    if (t <= -1) w0[k] = sy_filter_expneg(sp + range_arg(g0, gi, c->inv2c, c->inv2d)), A0 += w0[k];
                    if (t >= 1) w2[k] = sy_filter_expneg(sp + range_arg(g2, gi, c->inv2c, c->inv2d)), A2 += w2[k];
                }
            }
            /* combined normalised weights: L = w (1-a) L_0 + w a L_2 + (1-w) L_a (Eqs. 3.19, 3.20) */
            float ca = 1.0f, c0 = 0.0f, c2 = 0.0f;
            if (edge && A0 > 0 && A2 > 0) ca = 1.0f - wedge, c0 = wedge * (1.0f - ahat), c2 = wedge * ahat;
            else if (edge && A0 > 0 && ahat < 0.5f) ca = 1.0f - wedge, c0 = wedge;
            else if (edge && A2 > 0 && ahat >= 0.5f) ca = 1.0f - wedge, c2 = wedge;
            double acc[4] = {0, 0, 0, 0}, rr = 0, cen = 0;
            if (Aa <= 0) ca = 0.0f;
            float sa = Aa > 0 ? ca / (float)Aa : 0.0f, s0 = A0 > 0 ? c0 / (float)A0 : 0.0f,
                  s2 = A2 > 0 ? c2 / (float)A2 : 0.0f;
            float total = 0.0f;
            for (int t = lo; t <= hi; ++t) {
                int k = t - lo;
                float cw = sa * wa[k] + s0 * w0[k] + s2 * w2[k];
                if (cw == 0.0f) continue;
                size_t i = (size_t)((ptrdiff_t)j + t * step);
                const float *v = c->src + 4 * i;
                for (int q = 0; q < 4; ++q) acc[q] += cw * v[q];
                rr += (double)cw * cw * c->rsrc[i];
                total += cw;
                if (t == 0) cen = cw;
            }
            float *o = c->dst + 4 * j;
            if (total > 0.0f) {
                for (int q = 0; q < 4; ++q) o[q] = (float)(acc[q] / total);
                c->rdst[j] = (float)(rr / ((double)total * total));
                if (c->a0) c->a0[j] *= (float)(cen / total);
            } else {
                memcpy(o, c->src + 4 * j, 4 * sizeof(float));
                c->rdst[j] = c->rsrc[j];
            }
        }
}

typedef struct box_ctx {
    const float *src;
    const uint8_t *ok;
    float *dst, *tmp;
    int w, h, R;
} box_ctx;

static void box_h_rows(void *vctx, uint32_t y0, uint32_t y1)
{
    box_ctx *b = vctx;
    int w = b->w, R = b->R;
    for (int y = (int)y0; y < (int)y1; ++y)
        for (int x = 0; x < w; ++x) {
            double s = 0;
            int n = 0;
            for (int t = -R; t <= R; ++t) {
                int xx = x + t;
                if (xx < 0 || xx >= w || !b->ok[(size_t)y * w + xx]) continue;
                s += b->src[(size_t)y * w + xx], ++n;
            }
            b->tmp[(size_t)y * w + x] = n ? (float)(s / n) : NAN;
        }
}

static void box_v_rows(void *vctx, uint32_t y0, uint32_t y1)
{
    box_ctx *b = vctx;
    int w = b->w, h = b->h, R = b->R;
    for (int y = (int)y0; y < (int)y1; ++y)
        for (int x = 0; x < w; ++x) {
            double s = 0;
            int n = 0;
            for (int t = -R; t <= R; ++t) {
                int yy = y + t;
                if (yy < 0 || yy >= h) continue;
                float v = b->tmp[(size_t)yy * w + x];
                if (isnan(v)) continue;
                s += v, ++n;
            }
            b->dst[(size_t)y * w + x] = n ? (float)(s / n) : 0.0f;
        }
}

/* separable (2R+1)^2 box mean over valid pixels, row-parallel */
static void box_masked(uint32_t threads, const float *src, const uint8_t *ok, float *dst, float *tmp, int w, int h,
                       int R)
{
    box_ctx b = {src, ok, dst, tmp, w, h, R};
    sy_filter_parallel_rows(threads, (uint32_t)h, box_h_rows, &b, NULL);
    sy_filter_parallel_rows(threads, (uint32_t)h, box_v_rows, &b, NULL);
}

void sy_filter_pixel_destroy(sy_filter_pixel *pf)
{
    if (!pf) return;
    free(pf->guide), free(pf->ok), free(pf->val), free(pf->tmp), free(pf->racc), free(pf->rtmp);
    free(pf->sigma), free(pf->lf), free(pf->r), free(pf->a0), free(pf->npass), free(pf->s), free(pf->lf3);
    free(pf);
}

sy_filter_status sy_filter_pixel_create(const sy_filter_pixel_params *p, sy_filter_pixel **out, sy_filter_error *err)
{
    if (!out) return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "pixel filter: out is NULL");
    *out = NULL;
    sy_filter_pixel_params d;
    if (!p) sy_filter_pixel_params_default(&d), p = &d;
    sy_filter_status s = sy_filter_pixel_params_check(p, err);
    if (s) return s;
    sy_filter_pixel *pf = calloc(1, sizeof *pf);
    if (!pf) return sy_filter_fail(err, SY_FILTER_ERROR_OUT_OF_MEMORY, "pixel filter: out of memory");
    pf->p = *p;
    for (int i = 0; i <= EXP_TABLE + 1; ++i) pf->expt[i] = i >= EXP_TABLE ? 0.0f : expf(-(float)i / EXP_SCALE);
    *out = pf;
    return SY_FILTER_OK;
}

sy_filter_status sy_filter_pixel_set_params(sy_filter_pixel *pf, const sy_filter_pixel_params *p, sy_filter_error *err)
{
    if (!pf) return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "pixel filter: object is NULL");
    sy_filter_status s = sy_filter_pixel_params_check(p, err);
    if (s == SY_FILTER_OK) pf->p = *p; /* the filtered buffer stays valid; new sigmas apply next pass */
    return s;
}

void sy_filter_pixel_reset(sy_filter_pixel *pf)
{
    if (pf) pf->have_pass = false;
}

const float *sy_filter_pixel_blend(const sy_filter_pixel *pf) { return pf && pf->have_pass ? pf->s : NULL; }
const float *sy_filter_pixel_reduction(const sy_filter_pixel *pf) { return pf && pf->have_pass ? pf->r : NULL; }
const float *sy_filter_pixel_filtered(const sy_filter_pixel *pf) { return pf && pf->have_pass ? pf->lf3 : NULL; }

static sy_filter_status ensure_size(sy_filter_pixel *pf, uint32_t w, uint32_t h, sy_filter_error *err)
{
    if (pf->w == w && pf->h == h && pf->guide) return SY_FILTER_OK;
    sy_filter_pixel_params p = pf->p;
    free(pf->guide), free(pf->ok), free(pf->val), free(pf->tmp), free(pf->racc), free(pf->rtmp);
    free(pf->sigma), free(pf->lf), free(pf->r), free(pf->a0), free(pf->npass), free(pf->s), free(pf->lf3);
    pf->guide = pf->val = pf->tmp = pf->racc = pf->rtmp = pf->sigma = pf->lf = pf->r = pf->a0 = pf->npass = NULL;
    pf->s = pf->lf3 = NULL, pf->ok = NULL, pf->have_pass = false;
    pf->p = p;
    size_t n = (size_t)w * h;
    pf->guide = malloc(4 * n * sizeof(float));
    pf->ok = malloc(n);
    pf->val = malloc(4 * n * sizeof(float));
    pf->tmp = malloc(4 * n * sizeof(float));
    pf->racc = malloc(n * sizeof(float));
    pf->rtmp = malloc(n * sizeof(float));
    pf->sigma = malloc(n * sizeof(float));
    pf->lf = malloc(4 * n * sizeof(float));
    pf->r = malloc(n * sizeof(float));
    pf->a0 = malloc(n * sizeof(float));
    pf->npass = malloc(n * sizeof(float));
    pf->s = malloc(n * sizeof(float));
    pf->lf3 = malloc(3 * n * sizeof(float));
    if (!pf->guide || !pf->ok || !pf->val || !pf->tmp || !pf->racc || !pf->rtmp || !pf->sigma || !pf->lf || !pf->r ||
        !pf->a0 || !pf->npass || !pf->s || !pf->lf3) {
        pf->w = pf->h = 0;
        return sy_filter_fail(err, SY_FILTER_ERROR_OUT_OF_MEMORY, "pixel filter: out of memory for %ux%u", w, h);
    }
    pf->w = w, pf->h = h;
    return SY_FILTER_OK;
}

static void hv_lv(const sy_filter_pixel *pf, const sy_filter_frame *in, size_t i, float hv[3], float lv[3])
{
    if (!pf->p.all_high_variance && in->direct && in->indirect) {
        for (int c = 0; c < 3; ++c) hv[c] = in->indirect[3 * i + c], lv[c] = in->direct[3 * i + c];
    } else {
        for (int c = 0; c < 3; ++c) hv[c] = in->color[(size_t)in->color_channels * i + c], lv[c] = 0.0f;
    }
}

typedef struct prep_ctx {
    sy_filter_pixel *pf;
    const sy_filter_frame *in;
    const float *bv, *bl; /* adaptive width: smoothed variance of the mean and luminance */
    float s0;
} prep_ctx;

static void prep_rows(void *vctx, uint32_t y0, uint32_t y1)
{
    prep_ctx *c = vctx;
    sy_filter_pixel *pf = c->pf;
    const sy_filter_frame *in = c->in;
    for (size_t i = (size_t)y0 * pf->w; i < (size_t)y1 * pf->w; ++i) {
        float hv[3], lv[3];
        hv_lv(pf, in, i, hv, lv);
        float *v = pf->val + 4 * i;
        v[0] = hv[0], v[1] = hv[1], v[2] = hv[2];
        v[3] = sy_filter_pixel_variance(in, i) * sy_filter_pixel_spp(in, i);
        const float *g = pf->guide + 4 * i;
        bool ok = pf->ok[i] && isfinite(g[0]) && isfinite(g[1]) && isfinite(g[2]) && !isnan(g[3]);
        for (int k = 0; k < 4 && ok; ++k) ok = isfinite(v[k]);
        pf->ok[i] = ok;
        if (!ok) v[0] = v[1] = v[2] = v[3] = 0.0f;
        pf->npass[i] = sy_filter_pixel_spp(in, i);
    }
}

/* Eqs. 3.15-3.17 per pixel from the box-smoothed u */
static void sigma_rows(void *vctx, uint32_t y0, uint32_t y1)
{
    prep_ctx *c = vctx;
    sy_filter_pixel *pf = c->pf;
    const sy_filter_pixel_params *p = &pf->p;
    for (size_t i = (size_t)y0 * pf->w; i < (size_t)y1 * pf->w; ++i) {
        float L = fmaxf(c->bl[i], 1e-6f);
        float u = c->bv[i] / (L * L);
        /* [GAP spec 1.10(b)]: the target f of Eq. 3.15 is the threshold t (perceived units) */
        float tgt = fmaxf(p->threshold, 1e-6f);
        float e = 0.5f * sqrtf(u / tgt) - 0.5f;
        float sg = 1.5f * (e > 0.0f ? e : 0.0f);
        float guide = c->s0 / sqrtf(fmaxf(pf->npass[i], 1.0f)); /* Eq. 3.17, n >= 1 */
        float lo = guide / p->adaptive_c, hi = guide * p->adaptive_c;
        sg = sg < lo ? lo : sg > hi ? hi : sg; /* Eq. 3.16 */
        if (sg > p->sigma_s) sg = p->sigma_s;
        pf->sigma[i] = sg < 0.25f ? 0.25f : sg;
    }
}

static sy_filter_status filter_pass(sy_filter_pixel *pf, const sy_filter_frame *in, sy_filter_error *err)
{
    const sy_filter_pixel_params *p = &pf->p;
    int w = (int)pf->w, h = (int)pf->h;
    size_t n = (size_t)w * h;
    sy_filter_status s;
    if (in->range) {
        for (size_t i = 0; i < n; ++i) {
            memcpy(pf->guide + 4 * i, in->range + 4 * i, 4 * sizeof(float));
            if (pf->guide[4 * i + 3] > MISS_DEPTH) pf->guide[4 * i + 3] = MISS_DEPTH;
        }
    } else if ((s = sy_filter_range_compose(in, in->has_camera ? in->camera_position : NULL, p->headlight_weight,
                                            pf->guide, err)))
        return s;
    /* filter input: HV RGB + per-sample variance (variance of the mean times n, spec 1.2 [GAP]:
     * the smoothed per-sample variance is stored so the blend can divide by the current n) */
    prep_ctx pc = {.pf = pf, .in = in};
    if ((s = sy_filter_parallel_rows(p->threads, pf->h, prep_rows, &pc, err))) return s;
    /* [GAP spec 1.2, variance before two samples]: Welford gives no variance at 1 spp. There the
     * per-sample variance is taken as the squared deviation of the pixel's HV luminance from its
     * 5x5 neighbourhood mean; the bilateral pass smooths it like any variance estimate. */
    bool any_single = false;
    for (size_t i = 0; i < n && !any_single; ++i) any_single = pf->ok[i] && pf->npass[i] < 2.0f;
    if (any_single) {
        float *lum = pf->racc, *mean = pf->rtmp, *t3 = pf->tmp;
        for (size_t i = 0; i < n; ++i) lum[i] = pf->ok[i] ? sy_filter_luminance(pf->val + 4 * i) : 0.0f;
        box_masked(p->threads, lum, pf->ok, mean, t3, w, h, 2);
        for (size_t i = 0; i < n; ++i)
            if (pf->ok[i] && pf->npass[i] < 2.0f) {
                float d = lum[i] - mean[i];
                pf->val[4 * i + 3] = d * d * 25.0f / 24.0f;
            }
    }
    /* spatial sigma per pixel: fixed, or adaptive (Sec. 3.6.3, Eqs. 3.15-3.17) */
    if (p->adaptive_width) {
        /* u from 5x5 box-smoothed variance of the mean and background luminance (raw early
         * estimates differ too much between neighbours to size kernels from) */
        float *vm = pf->racc, *lb = pf->rtmp, *t1 = pf->tmp, *t2 = pf->tmp + n, *t3 = pf->tmp + 2 * n;
        for (size_t i = 0; i < n; ++i) {
            float hv[3], lv[3];
            hv_lv(pf, in, i, hv, lv);
            vm[i] = pf->ok[i] ? pf->val[4 * i + 3] / pf->npass[i] : 0.0f;
            lb[i] = pf->ok[i] ? sy_filter_luminance(hv) + sy_filter_luminance(lv) : 0.0f;
        }
        box_masked(p->threads, vm, pf->ok, t1, t3, w, h, 2);
        box_masked(p->threads, lb, pf->ok, t2, t3, w, h, 2);
        float s0 = p->adaptive_sigma0 > 0.0f ? p->adaptive_sigma0 : 2.0f * p->sigma_s; /* [GAP spec 1.10(b)]:
                                           sigma_bar(0) = 2 sigma_s, so the guide equals sigma_s at frame 4 */
        pc.bv = t1, pc.bl = t2, pc.s0 = s0;
        if ((s = sy_filter_parallel_rows(p->threads, pf->h, sigma_rows, &pc, err))) return s;
    } else {
        for (size_t i = 0; i < n; ++i) pf->sigma[i] = p->sigma_s;
    }
    pass_ctx c = {.pf = pf, .inv2c = 0.5f / (p->sigma_c * p->sigma_c), .inv2d = 0.5f / (p->sigma_d * p->sigma_d)};
    if (p->kernel == SY_FILTER_PIXEL_BRUTE) {
        c.src = pf->val, c.dst = pf->lf, c.rdst = pf->r, c.a0 = pf->a0;
        if ((s = sy_filter_parallel_rows(p->threads, pf->h, brute_rows, &c, err))) return s;
    } else {
        /* Eq. 3.14: sigma_k = sigma sqrt(3) 2^(N-k) / sqrt(4^N - 1); sum of squares = sigma^2 */
        uint32_t N = p->iterations;
        float norm = sqrtf(3.0f) / sqrtf(powf(4.0f, (float)N) - 1.0f);
        float *cur = pf->val, *other = pf->lf;
        /* [GAP spec 1.10(a)]: r of the iterated filter. One separable iteration propagates r
         * exactly (r_k); iterations compose like convolved Gaussians, whose 1/r add up:
         * 1/r - 1 = sum_k (1/r_k - 1) (exact for untruncated Gaussians, 1 for a no-op kernel).
         * Where windows are cut (image border, range edges) repeated averaging of the same few
         * pixels gains nothing, so r is bounded below by the smallest single-iteration r_k. */
        float *inv = malloc(2 * n * sizeof(float));
        if (!inv) return sy_filter_fail(err, SY_FILTER_ERROR_OUT_OF_MEMORY, "pixel filter: out of memory");
        float *rmin = inv + n;
        for (size_t i = 0; i < n; ++i) inv[i] = 0.0f, rmin[i] = 1.0f, pf->a0[i] = 1.0f;
        for (uint32_t k = 1; k <= N; ++k) {
            c.sig_scale = norm * powf(2.0f, (float)(N - k));
            for (size_t i = 0; i < n; ++i) pf->racc[i] = 1.0f;
            c.src = cur, c.dst = pf->tmp, c.rsrc = pf->racc, c.rdst = pf->rtmp, c.dir = 0;
            c.a0 = k == N ? pf->a0 : NULL;
            if ((s = sy_filter_parallel_rows(p->threads, pf->h, sep_rows, &c, err))) return free(inv), s;
            c.src = pf->tmp, c.dst = other, c.rsrc = pf->rtmp, c.rdst = pf->racc, c.dir = 1;
            if ((s = sy_filter_parallel_rows(p->threads, pf->h, sep_rows, &c, err))) return free(inv), s;
            for (size_t i = 0; i < n; ++i) {
                inv[i] += 1.0f / fmaxf(pf->racc[i], 1e-12f) - 1.0f;
                rmin[i] = fminf(rmin[i], pf->racc[i]);
            }
            float *t = cur;
            cur = other, other = t;
        }
        if (cur != pf->lf) memcpy(pf->lf, cur, 4 * n * sizeof(float));
        for (size_t i = 0; i < n; ++i) pf->r[i] = fmaxf(1.0f / (1.0f + inv[i]), rmin[i]);
        free(inv);
    }
    for (size_t i = 0; i < n; ++i) memcpy(pf->lf3 + 3 * i, pf->lf + 4 * i, 3 * sizeof(float));
    pf->have_pass = true;
    return SY_FILTER_OK;
}

typedef struct blend_ctx {
    sy_filter_pixel *pf;
    const sy_filter_frame *in;
    float *out;
} blend_ctx;

static void blend_rows(void *vctx, uint32_t y0, uint32_t y1)
{
    blend_ctx *b = vctx;
    sy_filter_pixel *pf = b->pf;
    const sy_filter_frame *in = b->in;
    const sy_filter_pixel_params *p = &pf->p;
    for (size_t i = (size_t)y0 * pf->w; i < (size_t)y1 * pf->w; ++i) {
        float hv[3], lv[3], *o = b->out + 4 * i;
        hv_lv(pf, in, i, hv, lv);
        o[3] = in->color_channels == 4 ? in->color[4 * i + 3] : 1.0f;
        if (!isfinite(o[3])) o[3] = 1.0f;
        bool own_ok = pf->ok[i];
        const float *col = in->color + (size_t)in->color_channels * i;
        if (!pf->have_pass) { /* the unfiltered estimate itself (bit-exact, not LV + HV rounded) */
            for (int c = 0; c < 3; ++c) o[c] = own_ok ? col[c] : 0.0f;
            continue;
        }
        const float *lf = pf->lf + 4 * i;
        if (!own_ok) { /* NaN/Inf pixel: show the neighbourhood's filtered value only */
            bool lv_ok = isfinite(lv[0]) && isfinite(lv[1]) && isfinite(lv[2]);
            for (int c = 0; c < 3; ++c) o[c] = (lv_ok ? lv[c] : 0.0f) + lf[c];
            pf->s[i] = 0.0f;
            continue;
        }
        /* Eq. 3.10: L_b = L_f + L_lv, evaluated with the current L_lv (luminance, spec 1.2 [GAP]) */
        float lb = sy_filter_luminance(lf) + sy_filter_luminance(lv);
        float lb2 = lb * lb > 1e-12f ? lb * lb : 1e-12f;
        float n_now = sy_filter_pixel_spp(in, i);
        float u = lf[3] / n_now / lb2;                 /* smoothed Var[L_u] now (Sec. 3.3.2) */
        float f = pf->r[i] * lf[3] / pf->npass[i] / lb2; /* Eq. 3.5 at the pass's sample count */
        float cov = p->use_covariance ? pf->a0[i] * lf[3] / pf->npass[i] / lb2 : 0.0f;
        float s = sy_filter_blend_factor(u, f, p->threshold, cov);
        pf->s[i] = s;
        if (s >= 1.0f) { /* converged under the threshold: exactly the unfiltered estimate */
            for (int c = 0; c < 3; ++c) o[c] = col[c];
            continue;
        }
        for (int c = 0; c < 3; ++c) {
            float lu = hv[c];
            /* Eq. 3.18 spike withholding; [GAP spec 1.10(c)]: per RGB channel, and only while the
             * blend still mixes (s < 1) so the converged output stays exactly unbiased */
            if (p->spike_withholding && s < 1.0f) {
                float loc = lf[c] / p->spike_c, hic = lf[c] * p->spike_c;
                lu = lu < loc ? loc : lu > hic ? hic : lu;
            }
            o[c] = lv[c] + s * lu + (1.0f - s) * lf[c];
        }
    }
}

sy_filter_status sy_filter_pixel_run(sy_filter_pixel *pf, const sy_filter_frame *in, uint32_t frame, bool force_pass,
                                     float *out, sy_filter_stats *stats, sy_filter_error *err)
{
    double t0 = now_s();
    if (!pf) return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "pixel filter: object is NULL");
    if (!out) return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "pixel filter: output is NULL");
    uint32_t need = SY_FILTER_NEED_COLOR | SY_FILTER_NEED_VARIANCE;
    if (!in || !in->range) need |= SY_FILTER_NEED_ALBEDO | SY_FILTER_NEED_DEPTH;
    sy_filter_status s = sy_filter_check_frame(in, need, "pixel filter", err);
    if (s) return s;
    if (pf->w != in->width || pf->h != in->height) {
        if ((s = ensure_size(pf, in->width, in->height, err))) return s;
    }
    if (!pf->p.all_high_variance && in->direct && in->indirect) need |= SY_FILTER_NEED_SPLIT;
    uint64_t bad = sy_filter_scan_finite(in, need, pf->ok);
    bool pass = force_pass || sy_filter_pixel_scheduled(&pf->p, frame);
    if (pass && (s = filter_pass(pf, in, err))) return s;
    blend_ctx b = {.pf = pf, .in = in, .out = out};
    if ((s = sy_filter_parallel_rows(pf->p.threads, pf->h, blend_rows, &b, err))) return s;
    if (stats) {
        size_t n = (size_t)pf->w * pf->h;
        double ssum = 0;
        if (pf->have_pass)
            for (size_t i = 0; i < n; ++i) ssum += pf->s[i];
        stats->nonfinite_samples = bad;
        stats->filtered_pixels = pf->have_pass ? n : 0;
        stats->filter_pass = pass;
        stats->mean_blend = pf->have_pass ? ssum / (double)n : 1.0;
        stats->seconds = now_s() - t0;
    }
    return SY_FILTER_OK;
}
