/* test_filters_baselines.c — the comparison filters and metrics of backends/filters: a-trous is the
 * identity on a noise-free piecewise-constant image and reduces noise on a noisy one; JBU
 * reproduces a smooth function and does not bleed across a depth step; the adaptive-resolution
 * preview blurs a 1-spp image and is exact once converged; NaN isolation; RMSE/relMSE/SSIM known
 * values; parameter rejection. */
#include "sy_filter_adaptive.h"
#include "sy_filter_atrous.h"
#include "sy_filter_jbu.h"
#include "sy_filter_metrics.h"
#include "synth.h"

#include <string.h>

static int test_atrous(void)
{
    synth s;
    CHECK(synth_init(&s, 96, 64, 3) == 0);
    size_t n = (size_t)s.w * s.h;
    /* noise-free: indirect = truth; the piecewise-constant variant (E constant per half) */
    for (size_t i = 0; i < n; ++i) {
        float E = (i % s.w) >= s.w / 2 ? 0.2f : 0.5f;
        for (int c = 0; c < 3; ++c) {
            s.indirect[3 * i + c] = s.albedo[3 * i + c] * E;
            s.color[4 * i + c] = s.indirect[3 * i + c] + s.direct[3 * i + c];
        }
        s.color[4 * i + 3] = 1;
    }
    sy_filter_frame f = synth_frame(&s, 1);
    sy_filter_atrous_params p;
    sy_filter_atrous_params_default(&p);
    float *out = malloc(4 * n * sizeof(float));
    sy_filter_report err = {0};
    sy_filter_stats st;
    CHECK(out && sy_filter_atrous(&p, &f, out, &st, &err) == SY_FILTER_OK);
    double maxd = 0;
    for (size_t i = 0; i < n; ++i)
        for (int c = 0; c < 4; ++c) maxd = fmax(maxd, fabs(out[4 * i + c] - s.color[4 * i + c]));
    printf("a-trous noise-free: max |out - in| = %.2e\n", maxd);
    CHECK(maxd < 1e-5);
    /* noisy: error reduced */
    synth_render(&s, 4, 1.0f);
    CHECK(sy_filter_atrous(&p, &f, out, &st, &err) == SY_FILTER_OK);
    double b = rel_mse(s.color, s.truth, n), e = rel_mse(out, s.truth, n);
    printf("a-trous 4 spp: relMSE %.5f -> %.5f (%.1fx), %.2f ms\n", b, e, b / e, st.seconds * 1e3);
    CHECK(e < b / 2);
    /* NaN does not spread */
    s.indirect[3 * 100] = NAN;
    CHECK(sy_filter_atrous(&p, &f, out, &st, &err) == SY_FILTER_OK);
    CHECK(st.nonfinite_samples == 1);
    for (size_t i = 0; i < 4 * n; ++i) CHECK(isfinite(out[i]));
    p.sigma_color = 0.0f;
    CHECK(sy_filter_atrous(&p, &f, out, &st, &err) == SY_FILTER_ERROR_INVALID_ARGUMENT && strstr(err.message, "sigma_color"));
    sy_filter_atrous_params_default(&p);
    p.iterations = 0;
    CHECK(sy_filter_atrous(&p, &f, out, &st, &err) == SY_FILTER_ERROR_INVALID_ARGUMENT);
    free(out);
    return synth_free(&s);
}

static int test_jbu(void)
{
    const uint32_t w = 64, h = 48, k = 4, lw = w / k, lh = h / k;
    size_t n = (size_t)w * h;
    float *depth = malloc(n * sizeof(float)), *normal = calloc(3 * n, sizeof(float)), *out = malloc(3 * n * sizeof(float));
    float low[3 * 16 * 12], ld[16 * 12], ln[3 * 16 * 12];
    CHECK(depth && normal && out);
    for (size_t i = 0; i < n; ++i) depth[i] = 3.0f, normal[3 * i + 2] = 1.0f;
    /* smooth function sampled at block centres */
#define SMOOTH(x, y) (0.3f + 0.004f * (x) + 0.002f * (y) + 0.00002f * (x) * (y))
    for (uint32_t by = 0; by < lh; ++by)
        for (uint32_t bx = 0; bx < lw; ++bx) {
            size_t q = (size_t)by * lw + bx;
            float cx = (float)(bx * k + k / 2) + 0.5f, cy = (float)(by * k + k / 2) + 0.5f;
            for (int c = 0; c < 3; ++c) low[3 * q + c] = SMOOTH(cx, cy);
            ld[q] = 3.0f, ln[3 * q] = 0, ln[3 * q + 1] = 0, ln[3 * q + 2] = 1;
        }
    sy_filter_frame g = {.width = w, .height = h, .depth = depth, .normal = normal};
    sy_filter_jbu_params p;
    sy_filter_jbu_params_default(&p);
    sy_filter_report err = {0};
    CHECK(sy_filter_jbu_upsample(&p, low, ld, ln, lw, lh, &g, out, &err) == SY_FILTER_OK);
    double maxe = 0;
    for (uint32_t y = 8; y < h - 8; ++y)
        for (uint32_t x = 8; x < w - 8; ++x) {
            float t = SMOOTH((float)x + 0.5f, (float)y + 0.5f);
            maxe = fmax(maxe, fabs(out[3 * ((size_t)y * w + x)] - t) / t);
        }
    printf("jbu smooth: max relative error (interior) %.2e\n", maxe);
    CHECK(maxe < 2e-3);
    /* depth step: low-res values differ per side; no bleeding */
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) depth[(size_t)y * w + x] = x >= 30 ? 9.0f : 3.0f;
    for (uint32_t by = 0; by < lh; ++by)
        for (uint32_t bx = 0; bx < lw; ++bx) {
            size_t q = (size_t)by * lw + bx;
            bool right = bx * k + k / 2 >= 30;
            ld[q] = right ? 9.0f : 3.0f;
            for (int c = 0; c < 3; ++c) low[3 * q + c] = right ? 1.0f : 0.1f;
        }
    CHECK(sy_filter_jbu_upsample(&p, low, ld, ln, lw, lh, &g, out, &err) == SY_FILTER_OK);
    for (uint32_t y = 0; y < h; ++y) {
        CHECK(fabsf(out[3 * ((size_t)y * w + 29)] - 0.1f) < 1e-3f);
        CHECK(fabsf(out[3 * ((size_t)y * w + 30)] - 1.0f) < 1e-3f);
    }
    /* size mismatch and bad params rejected */
    CHECK(sy_filter_jbu_upsample(&p, low, ld, ln, lw + 1, lh, &g, out, &err) == SY_FILTER_ERROR_INVALID_ARGUMENT);
    p.sigma_depth = 0;
    CHECK(sy_filter_jbu_upsample(&p, low, ld, ln, lw, lh, &g, out, &err) == SY_FILTER_ERROR_INVALID_ARGUMENT &&
          strstr(err.message, "sigma_depth"));
    free(depth), free(normal), free(out);
    /* the whole baseline on the surrogate: error reduced, NaN isolated */
    synth s;
    CHECK(synth_init(&s, 96, 64, 13) == 0);
    synth_render(&s, 4, 1.0f);
    sy_filter_frame f = synth_frame(&s, 4);
    size_t m = (size_t)s.w * s.h;
    float *o4 = malloc(4 * m * sizeof(float));
    sy_filter_jbu_params_default(&p);
    sy_filter_stats st;
    s.indirect[3 * 500 + 2] = NAN;
    CHECK(o4 && sy_filter_jbu(&p, &f, o4, &st, &err) == SY_FILTER_OK);
    CHECK(st.nonfinite_samples == 1);
    for (size_t i = 0; i < 4 * m; ++i) CHECK(isfinite(o4[i]));
    s.indirect[3 * 500 + 2] = s.truth_ind[3 * 500 + 2];
    CHECK(sy_filter_jbu(&p, &f, o4, &st, &err) == SY_FILTER_OK);
    double b = rel_mse(s.color, s.truth, m), e = rel_mse(o4, s.truth, m);
    printf("jbu 4 spp: relMSE %.5f -> %.5f (%.1fx)\n", b, e, b / e);
    CHECK(e < b / 2);
    free(o4);
    return synth_free(&s);
}

static int test_adaptive(void)
{
    synth s;
    CHECK(synth_init(&s, 128, 96, 17) == 0);
    size_t n = (size_t)s.w * s.h;
    float *out = malloc(4 * n * sizeof(float)), *lvl = malloc(n * sizeof(float));
    CHECK(out && lvl);
    sy_filter_adaptive_params p;
    sy_filter_adaptive_params_default(&p);
    sy_filter_report err = {0};
    sy_filter_stats st;
    synth_render(&s, 1, 1.0f);
    /* 1 spp: no variance estimate yet (0) -> the spp term alone picks level 1 (target 4) */
    sy_filter_frame f = synth_frame(&s, 1);
    CHECK(sy_filter_adaptive(&p, &f, out, lvl, &st, &err) == SY_FILTER_OK);
    double b = rel_mse(s.color, s.truth, n), e = rel_mse(out, s.truth, n), ml = 0;
    for (size_t i = 0; i < n; ++i) ml += lvl[i];
    printf("adaptive 1 spp: relMSE %.5f -> %.5f (%.1fx), mean level %.2f\n", b, e, b / e, ml / n);
    CHECK(ml / n >= 0.99 && e < b / 2);
    /* 4 spp with variance: level from variance */
    synth_render(&s, 4, 1.0f);
    f = synth_frame(&s, 4);
    CHECK(sy_filter_adaptive(&p, &f, out, lvl, &st, &err) == SY_FILTER_OK);
    b = rel_mse(s.color, s.truth, n), e = rel_mse(out, s.truth, n), ml = 0;
    for (size_t i = 0; i < n; ++i) ml += lvl[i];
    printf("adaptive 4 spp: relMSE %.5f -> %.5f (%.1fx), mean level %.2f\n", b, e, b / e, ml / n);
    CHECK(ml / n > 0.5 && e < b / 2);
    /* converged: level 0 everywhere, output exact */
    synth_render(&s, 4096, 1.0f);
    f = synth_frame(&s, 4096);
    CHECK(sy_filter_adaptive(&p, &f, out, lvl, &st, &err) == SY_FILTER_OK);
    for (size_t i = 0; i < n; ++i) {
        CHECK(lvl[i] == 0.0f);
        for (int c = 0; c < 3; ++c) CHECK(fabsf(out[4 * i + c] - s.color[4 * i + c]) <= 1e-6f * fabsf(s.color[4 * i + c]) + 1e-7f);
    }
    /* NaN pixel: shown from neighbours, counted */
    s.color[4 * 300 + 1] = NAN;
    CHECK(sy_filter_adaptive(&p, &f, out, lvl, &st, &err) == SY_FILTER_OK);
    CHECK(st.nonfinite_samples == 1 && isfinite(out[4 * 300 + 1]) && lvl[300] >= 1.0f);
    CHECK(out[4 * 0] == s.color[0]);
    p.threshold = -1;
    CHECK(sy_filter_adaptive(&p, &f, out, lvl, &st, &err) == SY_FILTER_ERROR_INVALID_ARGUMENT && strstr(err.message, "threshold"));
    free(out), free(lvl);
    return synth_free(&s);
}

static int test_metrics(void)
{
    const uint32_t w = 40, h = 30;
    size_t n = (size_t)w * h;
    float *a = malloc(3 * n * sizeof(float)), *b = malloc(3 * n * sizeof(float));
    CHECK(a && b);
    uint64_t rng = 5;
    for (size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c) a[3 * i + c] = 0.2f + 0.5f * (float)((i % w) + c) / (float)w, b[3 * i + c] = a[3 * i + c];
    sy_filter_metrics m;
    sy_filter_report err = {0};
    CHECK(sy_filter_metrics_compute(a, b, w, h, 3, &m, &err) == SY_FILTER_OK);
    CHECK(m.rmse == 0.0 && m.relmse == 0.0 && fabs(m.ssim - 1.0) < 1e-9);
    for (size_t i = 0; i < 3 * n; ++i) a[i] = b[i] + 0.1f;
    CHECK(sy_filter_metrics_compute(a, b, w, h, 3, &m, &err) == SY_FILTER_OK);
    CHECK(fabs(m.rmse - 0.1) < 1e-6);
    double rel = 0;
    for (size_t i = 0; i < 3 * n; ++i) rel += 0.01 / ((double)b[i] * b[i] + 0.01);
    CHECK(fabs(m.relmse - rel / (3.0 * n)) < 1e-6);
    CHECK(m.ssim < 1.0 && m.ssim > 0.8); /* a brightness shift lowers only the luminance term */
    double s_small, s_big;
    for (size_t i = 0; i < 3 * n; ++i) a[i] = b[i] + 0.02f * (float)synth_gauss(&rng);
    CHECK(sy_filter_metrics_compute(a, b, w, h, 3, &m, &err) == SY_FILTER_OK);
    s_small = m.ssim;
    for (size_t i = 0; i < 3 * n; ++i) a[i] = b[i] + 0.2f * (float)synth_gauss(&rng);
    CHECK(sy_filter_metrics_compute(a, b, w, h, 3, &m, &err) == SY_FILTER_OK);
    s_big = m.ssim;
    printf("ssim: small noise %.4f, large noise %.4f\n", s_small, s_big);
    CHECK(s_small > s_big && s_small < 1.0 && s_big < 0.5);
    a[7] = NAN;
    CHECK(sy_filter_metrics_compute(a, b, w, h, 3, &m, &err) == SY_FILTER_OK && m.nonfinite == 1);
    CHECK(sy_filter_metrics_compute(a, b, w, h, 2, &m, &err) == SY_FILTER_ERROR_INVALID_ARGUMENT);
    free(a), free(b);
    return 0;
}

static int test_position_from_depth(void)
{
    /* camera at (1, 2, 3) looking down -Z: the centre pixel at depth 4 lies at (1, 2, -1) */
    float m[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 1, 2, 3, 1}, depth[9], pos[27];
    for (int i = 0; i < 9; ++i) depth[i] = 4.0f;
    depth[0] = INFINITY;
    sy_filter_report err = {0};
    CHECK(sy_filter_position_from_depth(3, 3, m, 1.0f, depth, pos, &err) == SY_FILTER_OK);
    CHECK(fabsf(pos[12] - 1) < 1e-6f && fabsf(pos[13] - 2) < 1e-6f && fabsf(pos[14] + 1) < 1e-6f);
    float th = tanf(0.5f), u = (2.0f * 2.5f / 3.0f - 1.0f) * th; /* right column, middle row */
    CHECK(fabsf(pos[15] - (1 + 4 * u)) < 1e-5f && fabsf(pos[17] + 1) < 1e-6f);
    CHECK(isfinite(pos[0]) && pos[2] < -1e17f);
    CHECK(sy_filter_position_from_depth(3, 3, m, 0.0f, depth, pos, &err) == SY_FILTER_ERROR_INVALID_ARGUMENT &&
          strstr(err.message, "yfov"));
    return 0;
}

SY_CHECK_MAIN("filters baselines", SY_TEST(test_position_from_depth), SY_TEST(test_atrous), SY_TEST(test_jbu),
              SY_TEST(test_adaptive), SY_TEST(test_metrics))
