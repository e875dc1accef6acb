/* sy_filter_atrous.c — edge-avoiding a-trous wavelet filter (Dammertz et al. 2010), see
 * sy_filter_atrous.h. */
#include "sy_filter_atrous.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void sy_filter_atrous_params_default(sy_filter_atrous_params *p)
{
    /* [GAP spec §6.9, baseline sigmas not given]: values for linear radiance of an image exposed
     * to ~[0,1] and scenes of metre scale, tuned on the synthetic surrogate of `sy bench filters`. */
    *p = (sy_filter_atrous_params){.iterations = 5, .sigma_color = 0.6f, .sigma_normal = 0.3f,
                                   .sigma_position = 0.2f, .sigma_range = 0.0f, .halve_color_sigma = true,
                                   .demodulate_albedo = true, .threads = 0};
}

sy_filter_status sy_filter_atrous_params_check(const sy_filter_atrous_params *p, sy_filter_report *err)
{
    sy_filter_status s;
    if (!p) return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "a-trous: params is NULL");
    if (p->iterations < 1 || p->iterations > 10)
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "a-trous: iterations = %u: must be 1..10",
                              p->iterations);
    if ((s = sy_filter_check_positive(p->sigma_color, "a-trous: sigma_color", err))) return s;
    if ((s = sy_filter_check_positive(p->sigma_normal, "a-trous: sigma_normal", err))) return s;
    if ((s = sy_filter_check_positive(p->sigma_position, "a-trous: sigma_position", err))) return s;
    if ((s = sy_filter_check_nonnegative(p->sigma_range, "a-trous: sigma_range", err))) return s;
    return sy_filter_check_threads(p->threads, "a-trous", err);
}

typedef struct actx {
    const sy_filter_atrous_params *p;
    const sy_filter_frame *in;
    const uint8_t *ok;
    const float *src;
    float *dst;
    int step;
    float inv_c, inv_n, inv_x, inv_r;
} actx;

static void atrous_rows(void *vctx, uint32_t y0, uint32_t y1)
{
    static const float h[5] = {1.0f / 16, 1.0f / 4, 3.0f / 8, 1.0f / 4, 1.0f / 16};
    actx *c = vctx;
    int w = (int)c->in->width, hh = (int)c->in->height;
    const float *N = c->in->normal, *P = c->in->position, *Rg = c->in->range;
    for (int y = (int)y0; y < (int)y1; ++y)
        for (int x = 0; x < w; ++x) {
            size_t j = (size_t)y * w + x;
            float *o = c->dst + 3 * j;
            const float *cj = c->src + 3 * j, *nj = N + 3 * j, *pj = P + 3 * j;
            if (!c->ok[j]) { /* bad centre: normalised average of valid neighbours, spatial only */
                double acc[3] = {0, 0, 0}, W = 0;
                for (int dy = -2; dy <= 2; ++dy)
                    for (int dx = -2; dx <= 2; ++dx) {
                        int xx = x + dx * c->step, yy = y + dy * c->step;
                        if (xx < 0 || yy < 0 || xx >= w || yy >= hh) continue;
                        size_t i = (size_t)yy * w + xx;
                        if (!c->ok[i]) continue;
                        float k = h[dx + 2] * h[dy + 2];
                        for (int q = 0; q < 3; ++q) acc[q] += k * c->src[3 * i + q];
                        W += k;
                    }
                for (int q = 0; q < 3; ++q) o[q] = W > 0 ? (float)(acc[q] / W) : 0.0f;
                continue;
            }
            double acc[3] = {0, 0, 0}, W = 0;
            for (int dy = -2; dy <= 2; ++dy) {
                int yy = y + dy * c->step;
                if (yy < 0 || yy >= hh) continue;
                for (int dx = -2; dx <= 2; ++dx) {
                    int xx = x + dx * c->step;
                    if (xx < 0 || xx >= w) continue;
                    size_t i = (size_t)yy * w + xx;
                    if (!c->ok[i]) continue;
                    const float *ci = c->src + 3 * i, *ni = N + 3 * i, *pi = P + 3 * i;
                    float dc = 0, dn = 0, dp = 0, dr = 0;
                    for (int q = 0; q < 3; ++q) {
                        float a = cj[q] - ci[q], b = nj[q] - ni[q], e = pj[q] - pi[q];
                        dc += a * a, dn += b * b, dp += e * e;
                        if (Rg) {
                            float r = Rg[4 * j + q] - Rg[4 * i + q];
                            dr += r * r;
                        }
                    }
                    /* w = exp(-|dc|^2/phi_c) exp(-(|dn|^2/step^2)/phi_n) exp(-|dp|^2/phi_x) [EXT] */
                    float arg = dc * c->inv_c + dn / (float)(c->step * c->step) * c->inv_n + dp * c->inv_x +
                                (Rg ? dr * c->inv_r : 0.0f);
                    float k = h[dx + 2] * h[dy + 2] * sy_filter_expneg(arg);
                    for (int q = 0; q < 3; ++q) acc[q] += k * ci[q];
                    W += k;
                }
            }
            for (int q = 0; q < 3; ++q) o[q] = W > 0 ? (float)(acc[q] / W) : cj[q];
        }
}

sy_filter_status sy_filter_atrous(const sy_filter_atrous_params *p, const sy_filter_frame *in, float *out,
                                  sy_filter_stats *stats, sy_filter_report *err)
{
    double t0 = sy_filter_clock(false);
    sy_filter_atrous_params d;
    if (!p) sy_filter_atrous_params_default(&d), p = &d;
    sy_filter_status s = sy_filter_atrous_params_check(p, err);
    if (s) return s;
    uint32_t need = SY_FILTER_NEED_COLOR | SY_FILTER_NEED_NORMAL | SY_FILTER_NEED_POSITION;
    if ((s = sy_filter_check_frame(in, need, "a-trous", err))) return s;
    if (!out) return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "a-trous: output is NULL");
    bool split = in->direct && in->indirect;
    if (split) need |= SY_FILTER_NEED_SPLIT;
    if (p->demodulate_albedo && in->albedo) need |= SY_FILTER_NEED_ALBEDO;
    size_t n = (size_t)in->width * in->height;
    uint8_t *ok = malloc(n);
    float *a = malloc(3 * n * sizeof(float)), *b = malloc(3 * n * sizeof(float)), *mod = malloc(3 * n * sizeof(float));
    if (!ok || !a || !b || !mod) {
        free(ok), free(a), free(b), free(mod);
        return sy_filter_fail(err, SY_FILTER_ERROR_OUT_OF_MEMORY, "a-trous: out of memory for %ux%u", in->width,
                              in->height);
    }
    uint64_t bad = sy_filter_scan_finite(in, need, ok);
    for (size_t i = 0; i < n; ++i)
        for (int q = 0; q < 3; ++q) {
            float v = split ? in->indirect[3 * i + q] : in->color[(size_t)in->color_channels * i + q];
            float m = 1.0f;
            /* demodulate by albedo (irradiance filtering); dark albedo keeps the radiance as is */
            if (p->demodulate_albedo && in->albedo && ok[i] && in->albedo[3 * i + q] > 0.01f) m = in->albedo[3 * i + q];
            mod[3 * i + q] = m;
            a[3 * i + q] = ok[i] ? v / m : 0.0f;
        }
    actx c = {.p = p, .in = in, .ok = ok, .inv_n = 1.0f / (p->sigma_normal * p->sigma_normal),
              .inv_x = 1.0f / (p->sigma_position * p->sigma_position),
              .inv_r = p->sigma_range > 0.0f ? 1.0f / (p->sigma_range * p->sigma_range) : 0.0f};
    sy_filter_frame view = *in;
    if (p->sigma_range <= 0.0f) view.range = NULL;
    c.in = &view;
    float sc = p->sigma_color;
    for (uint32_t it = 0; it < p->iterations && s == SY_FILTER_OK; ++it) {
        c.src = a, c.dst = b, c.step = 1 << it, c.inv_c = 1.0f / (sc * sc);
        sy_filter_parallel_rows(p->threads, in->height, atrous_rows, &c);
        float *t = a;
        a = b, b = t;
        if (p->halve_color_sigma) sc *= 0.5f;
    }
    if (s == SY_FILTER_OK)
        for (size_t i = 0; i < n; ++i) {
            float *o = out + 4 * i;
            for (int q = 0; q < 3; ++q) {
                float lv = split ? in->direct[3 * i + q] : 0.0f;
                o[q] = (isfinite(lv) ? lv : 0.0f) + a[3 * i + q] * mod[3 * i + q];
            }
            o[3] = in->color_channels == 4 && isfinite(in->color[4 * i + 3]) ? in->color[4 * i + 3] : 1.0f;
        }
    free(ok), free(a), free(b), free(mod);
    if (stats && s == SY_FILTER_OK) {
        *stats = (sy_filter_stats){.nonfinite_samples = bad, .filtered_pixels = n, .filter_pass = true,
                                   .mean_blend = 0.0,
                                   .seconds = sy_filter_clock(false) - t0};
    }
    return s;
}
