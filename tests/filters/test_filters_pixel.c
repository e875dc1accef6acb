/* test_filters_pixel.c — pixel filtering (backends/filters/sy_filter_pixel.h) on synthetic data
 * with known answers: convergence of a noisy constant, no bleeding across depth/albedo steps,
 * consistency of the blend operator, r = 1/n for equal weights, NaN isolation (other pixels
 * bit-identical whatever non-finite value a bad pixel holds), the same output for every thread
 * count, parameter rejection, and relMSE reduction >= 4x at a 4-spp noise level. */
#include "sy_filter_pixel.h"
#include "synth.h"

#include <string.h>

/* The filtered frame (malloc'ed), or NULL after a failed check (the caller CHECKs it). */
static float *run(sy_filter_pixel_params *p, const sy_filter_frame *f, uint32_t frame, sy_filter_stats *st)
{
    sy_filter_pixel *pf = NULL;
    sy_filter_report err = {0};
    EXPECT(sy_filter_pixel_create(p, &pf, &err) == SY_FILTER_OK);
    float *out = malloc((size_t)f->width * f->height * 4 * sizeof(float));
    EXPECT(out);
    if (pf && out) {
        sy_filter_status r = sy_filter_pixel_run(pf, f, frame, true, out, st, &err);
        EXPECT_MSG(r == SY_FILTER_OK, "run: %s", err.message);
        if (r != SY_FILTER_OK) free(out), out = NULL;
    } else {
        free(out), out = NULL;
    }
    sy_filter_pixel_destroy(pf);
    return out;
}

/* A test's own frame buffers, w x h (the synthetic scene of synth.h does not fit): colour (RGBA),
 * variance (luminance), albedo and depth. planes_alloc: true when all four were allocated;
 * planes_frame: the frame that reads them at spp samples; planes_free frees them. */
typedef struct planes {
    uint32_t w, h;
    float *col, *var, *alb, *dep;
} planes;

static bool planes_alloc(planes *o, uint32_t w, uint32_t h)
{
    size_t n = (size_t)w * h;
    o->w = w, o->h = h;
    o->col = malloc(4 * n * sizeof(float)), o->var = malloc(n * sizeof(float));
    o->alb = malloc(3 * n * sizeof(float)), o->dep = malloc(n * sizeof(float));
    return o->col && o->var && o->alb && o->dep;
}

static sy_filter_frame planes_frame(const planes *o, float spp)
{
    return (sy_filter_frame){.width = o->w, .height = o->h, .color_channels = 4, .variance_channels = 1,
                             .color = o->col, .variance = o->var, .albedo = o->alb, .depth = o->dep,
                             .spp_uniform = spp};
}

static void planes_free(planes *o)
{
    free(o->col), free(o->var), free(o->alb), free(o->dep);
}

/* the report's callback: called once per failure with the code and the message the report keeps */
typedef struct report_count {
    int calls;
    sy_filter_status code;
} report_count;
static void count_error(void *user, sy_filter_status code, const char *message)
{
    report_count *c = user;
    c->calls++;
    c->code = code;
    (void)message;
}

static int test_params(void)
{
    sy_filter_pixel_params p;
    sy_filter_report err = {0};
    sy_filter_pixel *pf = NULL;
    sy_filter_pixel_params_default(&p);
    CHECK(sy_filter_pixel_params_check(&p, &err) == SY_FILTER_OK);
    p.threshold = -0.1f;
    CHECK(sy_filter_pixel_create(&p, &pf, &err) == SY_FILTER_ERROR_INVALID_ARGUMENT && !pf);
    CHECK(strstr(err.message, "threshold") != NULL);
    sy_filter_pixel_params_default(&p);
    p.sigma_s = 0.0f;
    CHECK(sy_filter_pixel_params_check(&p, &err) == SY_FILTER_ERROR_INVALID_ARGUMENT && strstr(err.message, "sigma_s"));
    sy_filter_pixel_params_default(&p);
    p.sigma_c = 0.0f;
    CHECK(sy_filter_pixel_params_check(&p, &err) == SY_FILTER_ERROR_INVALID_ARGUMENT && strstr(err.message, "sigma_c"));
    sy_filter_pixel_params_default(&p);
    p.sigma_d = NAN;
    CHECK(sy_filter_pixel_params_check(&p, &err) == SY_FILTER_ERROR_INVALID_ARGUMENT && strstr(err.message, "sigma_d"));
    sy_filter_pixel_params_default(&p);
    p.schedule_start = 3;
    CHECK(sy_filter_pixel_params_check(&p, &err) == SY_FILTER_ERROR_INVALID_ARGUMENT);
    sy_filter_pixel_params_default(&p);
    CHECK(sy_filter_pixel_scheduled(&p, 4) && sy_filter_pixel_scheduled(&p, 8) && sy_filter_pixel_scheduled(&p, 1024));
    CHECK(!sy_filter_pixel_scheduled(&p, 1) && !sy_filter_pixel_scheduled(&p, 2) && !sy_filter_pixel_scheduled(&p, 6));
    /* a frame without required buffers is rejected, naming the buffer */
    CHECK(sy_filter_pixel_create(&p, &pf, &err) == SY_FILTER_OK);
    sy_filter_frame f = {.width = 4, .height = 4, .color_channels = 4, .variance_channels = 1, .spp_uniform = 1};
    float out[64];
    CHECK(sy_filter_pixel_run(pf, &f, 4, false, out, NULL, &err) == SY_FILTER_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(err.message, "color") != NULL);
    report_count rc = {0};
    sy_filter_report rep = {.error = count_error, .user = &rc};
    CHECK(sy_filter_pixel_run(pf, &f, 4, false, out, NULL, &rep) == SY_FILTER_ERROR_INVALID_ARGUMENT);
    CHECK(rc.calls == 1 && rc.code == SY_FILTER_ERROR_INVALID_ARGUMENT && rep.code == SY_FILTER_ERROR_INVALID_ARGUMENT &&
          strcmp(rep.message, err.message) == 0);
    CHECK(sy_filter_pixel_params_check(&p, &rep) == SY_FILTER_OK && rc.calls == 1);
    sy_filter_pixel_destroy(pf);
    return 0;
}

static int test_blend_factor(void)
{
    /* case 2: u <= t -> exactly 1; case 1: even L_f misses t -> 0; case 3 in (0,1) and meets t */
    CHECK(sy_filter_blend_factor(0.005f, 0.001f, 0.01f, 0.0f) == 1.0f);
    CHECK(sy_filter_blend_factor(0.0f, 0.0f, 0.01f, 0.0f) == 1.0f);
    CHECK(sy_filter_blend_factor(1.0f, 0.5f, 0.01f, 0.0f) == 0.0f);
    float u = 0.1f, f = 0.002f, t = 0.01f, s = sy_filter_blend_factor(u, f, t, 0.0f);
    CHECK(s > 0.0f && s < 1.0f);
    CHECK(fabsf(s * s * u + (1 - s) * (1 - s) * f - t) < 1e-5f); /* on the constraint boundary */
    /* continuity at u = t */
    CHECK(fabsf(sy_filter_blend_factor(t * 1.0001f, 0.1f * t, t, 0.0f) - 1.0f) < 0.01f);
    return 0;
}

/* a noisy constant converges to the constant; at low variance the output IS the unfiltered value */
static int test_constant_and_consistency(void)
{
    planes o;
    CHECK(planes_alloc(&o, 64, 48));
    const size_t n = (size_t)o.w * o.h;
    uint64_t rng = 7;
    for (int kernel = 0; kernel < 2; ++kernel) {
        for (float spp = 4; spp <= 4096; spp *= 8) {
            double sd = 0.5 / sqrt(spp); /* per-sample relative sd 1 around 0.5 */
            for (size_t i = 0; i < n; ++i) {
                for (int c = 0; c < 3; ++c) o.col[4 * i + c] = 0.5f + (float)(sd * synth_gauss(&rng));
                o.col[4 * i + 3] = 1.0f;
                o.var[i] = (float)(sd * sd);
                o.alb[3 * i] = o.alb[3 * i + 1] = o.alb[3 * i + 2] = 0.6f;
                o.dep[i] = 3.0f;
            }
            sy_filter_frame f = planes_frame(&o, spp);
            sy_filter_pixel_params p;
            sy_filter_pixel_params_default(&p);
            p.kernel = (sy_filter_pixel_kernel)kernel;
            p.spike_withholding = false;
            p.threads = 2;
            sy_filter_stats st;
            float *out = run(&p, &f, (uint32_t)spp, &st);
            CHECK(out);
            double e = 0, eu = 0;
            for (size_t i = 0; i < n; ++i) {
                double d = out[4 * i] - 0.5, du = o.col[4 * i] - 0.5;
                e += d * d, eu += du * du;
            }
            e = sqrt(e / n), eu = sqrt(eu / n);
            printf("kernel %d spp %5.0f: rmse filtered %.5f unfiltered %.5f mean s %.3f\n", kernel, spp, e, eu,
                   st.mean_blend);
            CHECK(e <= eu * 1.0001 + 1e-9);
            /* the blend keeps the perceived variance near t: sd <= ~sqrt(t) * 0.5 (plus estimate noise) */
            CHECK(e <= 1.5 * sqrt(p.threshold) * 0.5);
            if (spp == 4) CHECK(e < eu / 3.0);
            /* consistency: perceived variance (sd/0.5)^2 = 1/spp <= t = 0.01 from 100 spp on:
             * s = 1 and the output equals the unfiltered value exactly */
            if (spp >= 256) {
                CHECK(st.mean_blend == 1.0);
                for (size_t i = 0; i < n; ++i)
                    for (int c = 0; c < 3; ++c) CHECK(out[4 * i + c] == o.col[4 * i + c]);
            }
            free(out);
        }
    }
    planes_free(&o);
    return 0;
}

/* r of n equal weights = 1/n: 3x1 image, sigma_s huge, identical range values */
static int test_reduction_factor(void)
{
    float col[12] = {1, 0, 0, 1, 0, 1, 0, 1, 0, 0, 1, 1}, var[3] = {1, 1, 1}, alb[9] = {.5f, .5f, .5f, .5f, .5f, .5f, .5f, .5f, .5f},
          dep[3] = {1, 1, 1};
    sy_filter_frame f = {.width = 3, .height = 1, .color_channels = 4, .variance_channels = 1, .color = col,
                         .variance = var, .albedo = alb, .depth = dep, .spp_uniform = 1};
    sy_filter_pixel_params p;
    sy_filter_pixel_params_default(&p);
    p.sigma_s = 1000.0f, p.adaptive_width = false, p.aa_recovery = false;
    for (int kernel = 0; kernel < 2; ++kernel) {
        p.kernel = (sy_filter_pixel_kernel)kernel;
        sy_filter_pixel *pf = NULL;
        sy_filter_report err = {0};
        CHECK(sy_filter_pixel_create(&p, &pf, &err) == SY_FILTER_OK);
        float out[12];
        CHECK(sy_filter_pixel_run(pf, &f, 4, true, out, NULL, &err) == SY_FILTER_OK);
        const float *r = sy_filter_pixel_reduction(pf), *lf = sy_filter_pixel_filtered(pf);
        CHECK(r && lf);
        for (int i = 0; i < 3; ++i) {
            printf("kernel %d pixel %d: r = %.6f, L_f = %.4f %.4f %.4f\n", kernel, i, r[i], lf[3 * i], lf[3 * i + 1],
                   lf[3 * i + 2]);
            CHECK(fabsf(r[i] - 1.0f / 3.0f) < 2e-3f);
            for (int c = 0; c < 3; ++c) CHECK(fabsf(lf[3 * i + c] - 1.0f / 3.0f) < 2e-3f);
        }
        sy_filter_pixel_destroy(pf);
    }
    return 0;
}

/* no bleeding across a depth step and across an albedo (range colour) step */
static int test_edges(void)
{
    const uint32_t w = 80, h = 40;
    planes o;
    CHECK(planes_alloc(&o, w, h));
    for (int which = 0; which < 2; ++which)
        for (int kernel = 0; kernel < 2; ++kernel) {
            uint64_t rng = 99;
            for (uint32_t y = 0; y < h; ++y)
                for (uint32_t x = 0; x < w; ++x) {
                    size_t i = (size_t)y * w + x;
                    bool right = x >= w / 2;
                    float m = right ? 0.8f : 0.1f;
                    for (int c = 0; c < 3; ++c) o.col[4 * i + c] = m + 0.3f * m * (float)synth_gauss(&rng);
                    o.col[4 * i + 3] = 1;
                    o.var[i] = 0.09f * m * m;
                    float a = which == 1 && right ? 0.9f : 0.4f; /* albedo step (range colour) */
                    o.alb[3 * i] = o.alb[3 * i + 1] = o.alb[3 * i + 2] = a;
                    o.dep[i] = which == 0 && right ? 8.0f : 2.0f; /* or depth step */
                }
            sy_filter_frame f = planes_frame(&o, 4);
            sy_filter_pixel_params p;
            sy_filter_pixel_params_default(&p);
            p.kernel = (sy_filter_pixel_kernel)kernel;
            p.threshold = 0.0f; /* pure filtered output */
            p.spike_withholding = false;
            float *out = run(&p, &f, 4, NULL);
            CHECK(out);
            double left = 0, rightv = 0;
            for (uint32_t y = 0; y < h; ++y) left += out[4 * ((size_t)y * w + w / 2 - 1)], rightv += out[4 * ((size_t)y * w + w / 2)];
            left /= h, rightv /= h;
            printf("%s step, kernel %d: column left of edge %.4f (0.1), right %.4f (0.8)\n", which ? "albedo" : "depth",
                   kernel, left, rightv);
            CHECK(fabs(left - 0.1) < 0.02 && fabs(rightv - 0.8) < 0.06);
            free(out);
        }
    planes_free(&o);
    return 0;
}

/* NaN/Inf pixels are counted and do not spread; their own output is finite */
static int test_nan(void)
{
    synth s;
    CHECK(synth_init(&s, 48, 32, 5) == 0);
    synth_render(&s, 4, 1.0f);
    sy_filter_frame f = synth_frame(&s, 4);
    sy_filter_pixel_params p;
    sy_filter_pixel_params_default(&p);
    sy_filter_stats st;
    float *ref = run(&p, &f, 4, &st);
    CHECK(ref);
    CHECK(st.nonfinite_samples == 0);
    size_t bad = 10 * 48 + 10;
    s.indirect[3 * bad] = NAN, s.color[4 * bad] = NAN;
    s.indirect[3 * (bad + 20) + 1] = INFINITY, s.color[4 * (bad + 20) + 1] = INFINITY;
    float *out = run(&p, &f, 4, &st);
    CHECK(out);
    printf("nan test: %llu non-finite pixels reported\n", (unsigned long long)st.nonfinite_samples);
    CHECK(st.nonfinite_samples == 2);
    for (size_t i = 0; i < 48 * 32; ++i)
        for (int c = 0; c < 4; ++c) CHECK(isfinite(out[4 * i + c]));
    /* far pixels are unaffected; the bad pixels show plausible (filtered) values */
    CHECK(out[0] == ref[0]);
    CHECK(fabsf(out[4 * bad] - s.truth[4 * bad]) < 0.3f);
    free(ref), free(out);
    return synth_free(&s);
}

/* NaN/Inf isolation, strictly: a bad pixel's contents never reach another pixel. Whatever
 * non-finite value (NaN or +-Inf, in the colour/HV buffers, the variance or the range guide) a
 * back-end delivers at the same pixels, every other output pixel is bit-identical, all outputs
 * are finite, the bad pixels are counted and show their neighbourhood's filtered value; with the
 * brute-force kernel too, and on the blend-only frames after a pass. */
static int test_nan_isolation(void)
{
    enum { W = 40, H = 28 };
    synth s;
    CHECK(synth_init(&s, W, H, 11) == 0);
    synth_render(&s, 4, 1.0f);
    const size_t bad[3] = {5 * W + 7, 5 * W + 8, 20 * W + 30}; /* two adjacent, one on its own */
    float keep_c[3][4], keep_i[3][3], keep_v[3], keep_a[3][3], keep_d[3]; /* variance: 1 channel */
    for (int b = 0; b < 3; ++b) {
        memcpy(keep_c[b], s.color + 4 * bad[b], sizeof keep_c[b]);
        memcpy(keep_i[b], s.indirect + 3 * bad[b], sizeof keep_i[b]);
        keep_v[b] = s.var[bad[b]];
        memcpy(keep_a[b], s.albedo + 3 * bad[b], sizeof keep_a[b]);
        keep_d[b] = s.depth[bad[b]];
    }
    for (int kernel = 0; kernel < 2; ++kernel) {
        float *out[4] = {NULL, NULL, NULL, NULL};
        float *blend[4] = {NULL, NULL, NULL, NULL};
        for (int v = 0; v < 4; ++v) {
            for (int b = 0; b < 3; ++b) { /* restore, then poison in variant v */
                memcpy(s.color + 4 * bad[b], keep_c[b], sizeof keep_c[b]);
                memcpy(s.indirect + 3 * bad[b], keep_i[b], sizeof keep_i[b]);
                s.var[bad[b]] = keep_v[b];
                memcpy(s.albedo + 3 * bad[b], keep_a[b], sizeof keep_a[b]);
                s.depth[bad[b]] = keep_d[b];
                if (v == 0) s.color[4 * bad[b]] = NAN, s.indirect[3 * bad[b]] = NAN;
                if (v == 1) s.color[4 * bad[b] + 1] = INFINITY, s.indirect[3 * bad[b] + 1] = -INFINITY;
                if (v == 2) s.var[bad[b]] = NAN;
                if (v == 3) s.albedo[3 * bad[b]] = INFINITY, s.depth[bad[b]] = NAN;
            }
            sy_filter_frame f = synth_frame(&s, 4);
            sy_filter_pixel_params p;
            sy_filter_pixel_params_default(&p);
            if (kernel) p.kernel = SY_FILTER_PIXEL_BRUTE, p.aa_recovery = false;
            sy_filter_pixel *pf = NULL;
            sy_filter_report err = {0};
            sy_filter_stats st;
            CHECK(sy_filter_pixel_create(&p, &pf, &err) == SY_FILTER_OK);
            out[v] = malloc(2 * W * H * 4 * sizeof(float));
            blend[v] = malloc(W * H * sizeof(float));
            CHECK(out[v] && blend[v]);
            CHECK(sy_filter_pixel_run(pf, &f, 4, false, out[v], &st, &err) == SY_FILTER_OK);
            CHECK(st.filter_pass && st.nonfinite_samples == 3);
            memcpy(blend[v], sy_filter_pixel_blend(pf), W * H * sizeof(float));
            CHECK(sy_filter_pixel_run(pf, &f, 5, false, out[v] + W * H * 4, &st, &err) == SY_FILTER_OK);
            CHECK(!st.filter_pass && st.nonfinite_samples == 3);
            sy_filter_pixel_destroy(pf);
            for (size_t i = 0; i < 2 * W * H * 4; ++i) CHECK(isfinite(out[v][i]));
        }
        size_t differ = 0, filtered = 0;
        double worst = 0; /* the bad pixels themselves: their neighbourhood's value (range-weighted, or
                             spatial only where their own guide is broken), near the converged one */
        for (int v = 0; v < 4; ++v)
            for (size_t i = 0; i < 2 * W * H; ++i) {
                size_t px = i % (W * H);
                bool is_bad = px == bad[0] || px == bad[1] || px == bad[2];
                for (int c = 0; c < 3; ++c)
                    if (!is_bad) differ += out[v][4 * i + c] != out[0][4 * i + c];
                    else worst = fmax(worst, fabs(out[v][4 * i + c] - s.truth[4 * px + c]));
            }
        for (size_t i = 0; i < W * H; ++i) filtered += blend[0][i] < 1.0f;
        printf("nan isolation (%s): 4 kinds of bad values at 3 pixels: %zu values of other pixels differ, %zu of %d "
               "pixels filtered, bad pixels within %.3f of the converged value\n",
               kernel ? "brute" : "separable", differ, filtered, W * H, worst);
        CHECK(differ == 0);
        CHECK(worst < 0.3);
        CHECK(filtered > W * H / 2); /* the test is not vacuous: neighbourhoods were used */
        for (int b = 0; b < 3; ++b) CHECK(blend[0][bad[b]] == 0.0f); /* bad pixels: filtered value only */
        for (int v = 0; v < 4; ++v) free(out[v]), free(blend[v]);
    }
    return synth_free(&s);
}

/* The worker pool: the result does not depend on the thread count (rows are claimed dynamically),
 * the object keeps its pool across frames and rebuilds it when params.threads changes. */
static int test_threads(void)
{
    synth s;
    CHECK(synth_init(&s, 77, 45, 21) == 0); /* odd sizes: partial vector chunks and row bands */
    synth_render(&s, 4, 1.0f);
    sy_filter_frame f = synth_frame(&s, 4);
    size_t n = (size_t)77 * 45;
    float *ref = NULL;
    sy_filter_pixel *pf = NULL;
    sy_filter_report err = {0};
    sy_filter_pixel_params p;
    sy_filter_pixel_params_default(&p);
    CHECK(sy_filter_pixel_create(&p, &pf, &err) == SY_FILTER_OK);
    static const uint32_t counts[] = {1, 2, 3, 8, 0, 1};
    for (size_t k = 0; k < sizeof counts / sizeof counts[0]; ++k) {
        p.threads = counts[k];
        CHECK(sy_filter_pixel_set_params(pf, &p, &err) == SY_FILTER_OK);
        float *out = malloc(n * 4 * sizeof(float));
        CHECK(out);
        for (uint32_t frame = 4; frame <= 5; ++frame) /* a pass, then a blend-only frame */
            CHECK(sy_filter_pixel_run(pf, &f, frame, frame == 4, out, NULL, &err) == SY_FILTER_OK);
        if (!ref)
            ref = out;
        else {
            CHECK(memcmp(out, ref, n * 4 * sizeof(float)) == 0);
            free(out);
        }
    }
    printf("threads: 1, 2, 3, 8, all, 1 give bit-identical output\n");
    sy_filter_pixel_destroy(pf);
    free(ref);
    return synth_free(&s);
}

/* image quality on the analytic surrogate: relMSE reduction >= 4x at 4 spp */
static int test_quality(void)
{
    synth s;
    CHECK(synth_init(&s, 160, 120, 11) == 0);
    synth_render(&s, 4, 1.0f);
    sy_filter_frame f = synth_frame(&s, 4);
    size_t n = (size_t)s.w * s.h;
    double base = rel_mse(s.color, s.truth, n);
    for (int kernel = 0; kernel < 2; ++kernel) {
        sy_filter_pixel_params p;
        sy_filter_pixel_params_default(&p);
        p.kernel = (sy_filter_pixel_kernel)kernel;
        sy_filter_stats st;
        float *out = run(&p, &f, 4, &st);
        CHECK(out);
        double e = rel_mse(out, s.truth, n);
        printf("quality, kernel %d: relMSE unfiltered %.5f filtered %.5f (%.1fx), mean s %.3f\n", kernel, base, e,
               base / e, st.mean_blend);
        CHECK(base / e >= 4.0);
        free(out);
    }
    return synth_free(&s);
}

/* range buffer: albedo x ((1 - w) + w |n . v|), depth in A, misses clamped */
static int test_range_compose(void)
{
    float alb[6] = {0.5f, 0.4f, 0.2f, 0.5f, 0.4f, 0.2f}, nrm[6] = {0, 0, 1, 1, 0, 0}, pos[6] = {0, 0, -2, 0, 0, -2};
    float dep[2] = {2.0f, INFINITY}, cam[3] = {0, 0, 0}, out[8];
    sy_filter_frame f = {.width = 2, .height = 1, .albedo = alb, .normal = nrm, .position = pos, .depth = dep,
                         .spp_uniform = 1};
    sy_filter_report err = {0};
    CHECK(sy_filter_range_compose(&f, cam, 0.5f, out, &err) == SY_FILTER_OK);
    for (int c = 0; c < 3; ++c) {
        CHECK(fabsf(out[c] - alb[c]) < 1e-6f);              /* facing the headlight: full */
        CHECK(fabsf(out[4 + c] - 0.5f * alb[c]) < 1e-6f);   /* grazing: ambient half only */
    }
    CHECK(out[3] == 2.0f && out[7] == 1e18f);
    CHECK(sy_filter_range_compose(&f, cam, 1.5f, out, &err) == SY_FILTER_ERROR_INVALID_ARGUMENT &&
          strstr(err.message, "headlight_weight"));
    return 0;
}

SY_CHECK_MAIN("filters pixel", SY_TEST(test_params), SY_TEST(test_range_compose), SY_TEST(test_blend_factor),
              SY_TEST(test_reduction_factor), SY_TEST(test_constant_and_consistency), SY_TEST(test_edges),
              SY_TEST(test_nan), SY_TEST(test_nan_isolation), SY_TEST(test_threads), SY_TEST(test_quality))
