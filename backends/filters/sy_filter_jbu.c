/* sy_filter_jbu.c — joint bilateral upsampling baseline (see sy_filter_jbu.h). */
#include "sy_filter_jbu.h"

#include <math.h>
#include <stdlib.h>

#define MISS_DEPTH 1e20f

void sy_filter_jbu_params_default(sy_filter_jbu_params *p)
{
    *p = (sy_filter_jbu_params){.factor = 4, .radius = 2, .sigma_spatial = 1.0f, .sigma_depth = 0.05f,
                                .sigma_normal = 0.25f, .demodulate_albedo = true, .threads = 0};
}

sy_filter_status sy_filter_jbu_params_check(const sy_filter_jbu_params *p, sy_filter_report *err)
{
    sy_filter_status s;
    if (!p) return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "jbu: params is NULL");
    if (p->factor < 1 || p->factor > 64)
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "jbu: factor = %u: must be 1..64", p->factor);
    if (p->radius < 1 || p->radius > 8)
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "jbu: radius = %u: must be 1..8", p->radius);
    if ((s = sy_filter_check_positive(p->sigma_spatial, "jbu: sigma_spatial", err))) return s;
    if ((s = sy_filter_check_positive(p->sigma_depth, "jbu: sigma_depth", err))) return s;
    if ((s = sy_filter_check_positive(p->sigma_normal, "jbu: sigma_normal", err))) return s;
    return sy_filter_check_threads(p->threads, "jbu", err);
}

static float clamp_depth(float d) { return isnan(d) ? MISS_DEPTH : d < MISS_DEPTH ? d : MISS_DEPTH; }

static float guide_arg(float dp, const float *np, float dq, const float *nq, float inv_d, float inv_n)
{
    float rd = fabsf(dp - dq) / fmaxf(fmaxf(dp, dq), 1e-6f); /* relative: scale-free across the view */
    float dn = 0.0f;
    for (int c = 0; c < 3; ++c) {
        float e = np[c] - nq[c];
        dn += e * e;
    }
    return 0.5f * rd * rd * inv_d + 0.5f * dn * inv_n;
}

typedef struct uctx {
    const sy_filter_jbu_params *p;
    const float *low, *ld, *ln;
    uint32_t lw, lh;
    const sy_filter_frame *g;
    float *out;
    float inv_s, inv_d, inv_n;
} uctx;

static void up_rows(void *vctx, uint32_t y0, uint32_t y1)
{
    uctx *c = vctx;
    int w = (int)c->g->width, k = (int)c->p->factor, R = (int)c->p->radius;
    for (int y = (int)y0; y < (int)y1; ++y)
        for (int x = 0; x < w; ++x) {
            size_t j = (size_t)y * w + x;
            /* low-res coordinates: sample q sits at full-res (q*k + k/2 + 0.5) */
            float fx = ((float)x + 0.5f - (float)(k / 2) - 0.5f) / (float)k;
            float fy = ((float)y + 0.5f - (float)(k / 2) - 0.5f) / (float)k;
            int bx = (int)floorf(fx), by = (int)floorf(fy);
            float dp = clamp_depth(c->g->depth[j]);
            const float *np = c->g->normal + 3 * j;
            bool gp_ok = isfinite(np[0]) && isfinite(np[1]) && isfinite(np[2]);
            double acc[3] = {0, 0, 0}, W = 0, accs[3] = {0, 0, 0}, Ws = 0;
            /* window floor(p_down) - R .. + R + 1, Gaussian times a smooth taper (1 - (d/(R+1))^2)^2
             * that reaches 0 at the window edge: no bias from an asymmetric truncation */
            float inv_rw = 1.0f / (float)((R + 1) * (R + 1));
            for (int qy = by - R; qy <= by + R + 1; ++qy) {
                if (qy < 0 || qy >= (int)c->lh) continue;
                for (int qx = bx - R; qx <= bx + R + 1; ++qx) {
                    if (qx < 0 || qx >= (int)c->lw) continue;
                    size_t q = (size_t)qy * c->lw + qx;
                    const float *v = c->low + 3 * q;
                    if (!isfinite(v[0]) || !isfinite(v[1]) || !isfinite(v[2])) continue;
                    float ex = fx - (float)qx, ey = fy - (float)qy;
                    float d2 = ex * ex + ey * ey, tp = 1.0f - d2 * inv_rw;
                    if (tp <= 0.0f) continue;
                    float ws = sy_filter_expneg(0.5f * d2 * c->inv_s) * tp * tp;
                    const float *nq = c->ln + 3 * q;
                    float wr = 1.0f;
                    if (gp_ok && isfinite(nq[0]) && isfinite(nq[1]) && isfinite(nq[2]))
                        wr = sy_filter_expneg(guide_arg(dp, np, clamp_depth(c->ld[q]), nq, c->inv_d, c->inv_n));
                    float wt = ws * wr;
                    for (int ch = 0; ch < 3; ++ch) acc[ch] += wt * v[ch], accs[ch] += ws * v[ch];
                    W += wt, Ws += ws;
                }
            }
            float *o = c->out + 3 * j;
            for (int ch = 0; ch < 3; ++ch)
                o[ch] = W > 1e-20 ? (float)(acc[ch] / W) : Ws > 0 ? (float)(accs[ch] / Ws) : 0.0f;
        }
}

sy_filter_status sy_filter_jbu_upsample(const sy_filter_jbu_params *p, const float *low, const float *ld,
                                        const float *ln, uint32_t lw, uint32_t lh, const sy_filter_frame *g,
                                        float *out3, sy_filter_report *err)
{
    sy_filter_jbu_params d;
    if (!p) sy_filter_jbu_params_default(&d), p = &d;
    sy_filter_status s = sy_filter_jbu_params_check(p, err);
    if (s) return s;
    if (!g || g->width == 0 || g->height == 0 || !g->depth || !g->normal)
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "jbu: the guide needs size, depth and normal");
    if (!low || !ld || !ln || !out3) return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "jbu: NULL buffer");
    uint32_t ew = (g->width + p->factor - 1) / p->factor, eh = (g->height + p->factor - 1) / p->factor;
    if (lw != ew || lh != eh)
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT,
                              "jbu: low-res size %ux%u does not match %ux%u / %u = %ux%u", lw, lh, g->width,
                              g->height, p->factor, ew, eh);
    uctx c = {.p = p, .low = low, .ld = ld, .ln = ln, .lw = lw, .lh = lh, .g = g, .out = out3,
              .inv_s = 1.0f / (p->sigma_spatial * p->sigma_spatial),
              .inv_d = 1.0f / (p->sigma_depth * p->sigma_depth), .inv_n = 1.0f / (p->sigma_normal * p->sigma_normal)};
    sy_filter_parallel_rows(p->threads, g->height, up_rows, &c);
    return SY_FILTER_OK;
}

sy_filter_status sy_filter_jbu(const sy_filter_jbu_params *p, const sy_filter_frame *in, float *out,
                               sy_filter_stats *stats, sy_filter_report *err)
{
    double t0 = sy_filter_clock(false);
    sy_filter_jbu_params d;
    if (!p) sy_filter_jbu_params_default(&d), p = &d;
    sy_filter_status s = sy_filter_jbu_params_check(p, err);
    if (s) return s;
    uint32_t need = SY_FILTER_NEED_COLOR | SY_FILTER_NEED_DEPTH | SY_FILTER_NEED_NORMAL;
    if ((s = sy_filter_check_frame(in, need, "jbu", err))) return s;
    if (!out) return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "jbu: output is NULL");
    bool split = in->direct && in->indirect;
    if (split) need |= SY_FILTER_NEED_SPLIT;
    bool demod = p->demodulate_albedo && in->albedo;
    if (demod) need |= SY_FILTER_NEED_ALBEDO;
    uint32_t w = in->width, h = in->height, k = p->factor;
    uint32_t lw = (w + k - 1) / k, lh = (h + k - 1) / k;
    size_t n = (size_t)w * h, ln = (size_t)lw * lh;
    uint8_t *ok = malloc(n);
    float *hv = malloc(3 * n * sizeof(float)), *up = malloc(3 * n * sizeof(float));
    float *low = malloc(3 * ln * sizeof(float)), *ld = malloc(ln * sizeof(float)), *lnrm = malloc(3 * ln * sizeof(float));
    if (!ok || !hv || !up || !low || !ld || !lnrm) {
        free(ok), free(hv), free(up), free(low), free(ld), free(lnrm);
        return sy_filter_fail(err, SY_FILTER_ERROR_OUT_OF_MEMORY, "jbu: out of memory for %ux%u", w, h);
    }
    uint64_t bad = sy_filter_scan_finite(in, need, ok);
    for (size_t i = 0; i < n; ++i)
        for (int q = 0; q < 3; ++q) {
            float v = split ? in->indirect[3 * i + q] : in->color[(size_t)in->color_channels * i + q];
            float m = demod && in->albedo[3 * i + q] > 0.01f ? in->albedo[3 * i + q] : 1.0f;
            hv[3 * i + q] = ok[i] ? v / m : NAN;
        }
    float inv_d = 1.0f / (p->sigma_depth * p->sigma_depth), inv_n = 1.0f / (p->sigma_normal * p->sigma_normal);
    for (uint32_t by = 0; by < lh; ++by)
        for (uint32_t bx = 0; bx < lw; ++bx) {
            size_t q = (size_t)by * lw + bx;
            uint32_t cx = bx * k + k / 2, cy = by * k + k / 2;
            if (cx >= w) cx = w - 1;
            if (cy >= h) cy = h - 1;
            size_t cj = (size_t)cy * w + cx;
            ld[q] = clamp_depth(in->depth[cj]);
            for (int c = 0; c < 3; ++c) lnrm[3 * q + c] = in->normal[3 * cj + c];
            double acc[3] = {0, 0, 0}, W = 0;
            for (uint32_t y = by * k; y < (by + 1) * k && y < h; ++y)
                for (uint32_t x = bx * k; x < (bx + 1) * k && x < w; ++x) {
                    size_t i = (size_t)y * w + x;
                    if (!ok[i]) continue;
                    /* the sparse sample: only pixels on the centre's surface contribute */
                    float a = guide_arg(ld[q], lnrm + 3 * q, clamp_depth(in->depth[i]), in->normal + 3 * i, inv_d, inv_n);
                    if (i != cj && a > 2.0f) continue;
                    for (int c = 0; c < 3; ++c) acc[c] += hv[3 * i + c];
                    W += 1;
                }
            for (int c = 0; c < 3; ++c) low[3 * q + c] = W > 0 ? (float)(acc[c] / W) : NAN;
        }
    s = sy_filter_jbu_upsample(p, low, ld, lnrm, lw, lh, in, up, err);
    if (s == SY_FILTER_OK)
        for (size_t i = 0; i < n; ++i) {
            float *o = out + 4 * i;
            for (int q = 0; q < 3; ++q) {
                float lv = split ? in->direct[3 * i + q] : 0.0f;
                float m = demod && isfinite(in->albedo[3 * i + q]) && in->albedo[3 * i + q] > 0.01f ? in->albedo[3 * i + q] : 1.0f;
                o[q] = (isfinite(lv) ? lv : 0.0f) + up[3 * i + q] * m;
            }
            o[3] = in->color_channels == 4 && isfinite(in->color[4 * i + 3]) ? in->color[4 * i + 3] : 1.0f;
        }
    free(ok), free(hv), free(up), free(low), free(ld), free(lnrm);
    if (stats && s == SY_FILTER_OK) {
        *stats = (sy_filter_stats){.nonfinite_samples = bad, .filtered_pixels = n, .filter_pass = true,
                                   .seconds = sy_filter_clock(false) - t0};
    }
    return s;
}
