/* test_filters_radiance.c — radiance filtering (backends/filters/sy_filter_radiance.h) on
 * synthetic stored samples: a textured Lambertian plane under constant incident radiance (the
 * filter re-shades with each pixel's own albedo, so texture stays sharp and the result converges
 * to albedo * L), no leaking across a depth step (world-space prism), the switch to plain path
 * tracing (correction phase) and the unbiased buffer, NaN isolation, parameter rejection, and
 * resuming on an existing estimate (sy_filter_radiance_seed), and the batched BSDF path against
 * single calls. */
#include "sy_filter_radiance.h"
#include "synth.h"

#include <string.h>

typedef struct scene {
    uint32_t w, h;
    sy_filter_rf_shading *sh;
    sy_filter_rf_sample *sm;
    float *truth; /* 4/px */
    float *L;     /* incident radiance per pixel (scalar) */
    uint64_t rng;
} scene;

static int scene_init(scene *s, uint32_t w, uint32_t h, bool step, float exponent)
{
    size_t n = (size_t)w * h;
    s->w = w, s->h = h, s->rng = 42;
    s->sh = calloc(n, sizeof *s->sh), s->sm = calloc(n, sizeof *s->sm);
    s->truth = calloc(4 * n, sizeof(float)), s->L = calloc(n, sizeof(float));
    CHECK(s->sh && s->sm && s->truth && s->L);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            size_t i = (size_t)y * w + x;
            bool right = step && x >= w / 2;
            float d = right ? 6.0f : 2.0f;
            sy_filter_rf_shading *sh = s->sh + i;
            float dir[3] = {((float)x + 0.5f - (float)w / 2) * 0.01f, ((float)h / 2 - (float)y - 0.5f) * 0.01f, -1.0f};
            float dl = sqrtf(dir[0] * dir[0] + dir[1] * dir[1] + 1.0f);
            for (int c = 0; c < 3; ++c) {
                sh->position[c] = dir[c] * d;
                sh->ray_dir[c] = dir[c] / dl;
                sh->wo[c] = -dir[c] / dl;
                sh->throughput[c] = 1.0f;
            }
            sh->normal[2] = 1.0f;
            sh->path_length = d * dl;
            bool check = ((x / 8) + (y / 8)) & 1;
            sh->diffuse[0] = check ? 0.8f : 0.2f, sh->diffuse[1] = 0.5f, sh->diffuse[2] = check ? 0.1f : 0.6f;
            sh->exponent = exponent;
            if (exponent > 0) sh->specular[0] = sh->specular[1] = sh->specular[2] = 0.2f;
            sh->flags = SY_FILTER_RF_VALID;
            s->L[i] = right ? 1.0f : 0.25f;
            for (int c = 0; c < 3; ++c) {
                sh->direct[c] = 0.05f * sh->diffuse[c];
                s->truth[4 * i + c] = sh->direct[c] + sh->diffuse[c] * s->L[i]; /* Lambert: rho * L */
            }
            s->truth[4 * i + 3] = 1;
        }
    return 0;
}

/* one frame: cosine-sampled directions, radiance L (1 + rel_sd * N(0,1)) */
static void scene_frame(scene *s, float rel_sd, uint32_t k)
{
    size_t n = (size_t)s->w * s->h;
    for (size_t i = 0; i < n; ++i) {
        sy_filter_rf_shading *sh = s->sh + i;
        sy_filter_rf_sample *sm = s->sm + i;
        double u1 = synth_uniform(&s->rng), u2 = synth_uniform(&s->rng), r = sqrt(u1);
        memcpy(sm->position, sh->position, sizeof sm->position);
        memcpy(sm->normal, sh->normal, sizeof sm->normal);
        sm->wi[0] = (float)(r * cos(6.283185307 * u2)), sm->wi[1] = (float)(r * sin(6.283185307 * u2));
        sm->wi[2] = (float)sqrt(1.0 - u1);
        float L = s->L[i] * (1.0f + rel_sd * (float)synth_gauss(&s->rng));
        for (int c = 0; c < 3; ++c) sm->radiance[c] = L;
        sm->hit_distance = INFINITY;
        sm->flags = SY_FILTER_RF_VALID;
        float fc[3], pdf;
        sy_filter_rf_bsdf_default(sh, sm->wi, fc, &pdf, NULL);
        for (int c = 0; c < 3; ++c) sh->pt_indirect[c] = pdf > 0 ? fc[c] / pdf * L : 0.0f;
        float lum = sy_filter_luminance(sh->diffuse) * s->L[i] * rel_sd;
        sh->variance = k >= 2 ? lum * lum : 0.0f; /* the integrator's running estimate (exact here) */
    }
}

static void scene_free(scene *s) { free(s->sh), free(s->sm), free(s->truth), free(s->L); }

static sy_filter_radiance_input input(const scene *s)
{
    return (sy_filter_radiance_input){.width = s->w, .height = s->h, .pixel_angle = 0.01f, .shading = s->sh,
                                      .samples = s->sm};
}

/* What most tests here share: the scene (no glossy lobe), a filter with params p (NULL: the
 * defaults), its input over the scene and its output image (4 floats a pixel). */
typedef struct rig {
    scene s;
    size_t n; /* pixels */
    sy_filter_radiance *rf;
    sy_filter_report err;
    sy_filter_radiance_input in;
    float *out;
} rig;

static int rig_open(rig *r, uint32_t w, uint32_t h, bool step, const sy_filter_radiance_params *p)
{
    memset(r, 0, sizeof *r);
    CHECK(scene_init(&r->s, w, h, step, 0.0f) == 0);
    r->n = (size_t)w * h;
    CHECK(sy_filter_radiance_create(p, &r->rf, &r->err) == SY_FILTER_OK);
    r->out = malloc(4 * r->n * sizeof(float));
    CHECK(r->out);
    r->in = input(&r->s);
    return 0;
}

/* The end of a test: the rig freed; 0 (passed) for its return. */
static int rig_close(rig *r)
{
    free(r->out);
    sy_filter_radiance_destroy(r->rf);
    scene_free(&r->s);
    return 0;
}

static int test_texture_and_convergence(void)
{
    rig r;
    CHECK(rig_open(&r, 96, 64, false, NULL) == 0);
    float *pt = calloc(4 * r.n, sizeof(float));
    CHECK(pt);
    sy_filter_stats st;
    for (uint32_t k = 1; k <= 8; ++k) {
        scene_frame(&r.s, 1.0f, k);
        CHECK(sy_filter_radiance_frame(r.rf, &r.in, r.out, &st, &r.err) == SY_FILTER_OK);
        for (size_t i = 0; i < r.n; ++i)
            for (int c = 0; c < 3; ++c) pt[4 * i + c] += (r.s.sh[i].direct[c] + r.s.sh[i].pt_indirect[c] - pt[4 * i + c]) / (float)k;
    }
    double b = rel_mse(pt, r.s.truth, r.n), e = rel_mse(r.out, r.s.truth, r.n);
    printf("radiance 8 frames: relMSE PT %.5f RF %.5f (%.1fx), %.2f ms/frame, correction share %.2f\n", b, e, b / e,
           st.seconds * 1e3, st.mean_blend);
    CHECK(b / e >= 4.0);
    /* texture preserved: at checker boundaries the red channel keeps the 0.8/0.2 contrast */
    double hi = 0, lo = 0;
    uint32_t cnt = 0;
    for (uint32_t y = 4; y < r.s.h - 4; ++y) {
        size_t a = (size_t)y * r.s.w + 39, bb = (size_t)y * r.s.w + 40; /* 39 | 40: a checker edge */
        bool ca = ((39 / 8) + (y / 8)) & 1;
        hi += ca ? r.out[4 * a] : r.out[4 * bb], lo += ca ? r.out[4 * bb] : r.out[4 * a], ++cnt;
    }
    hi /= cnt, lo /= cnt;
    /* truth: red albedo 0.8 | 0.2 times (direct 0.05 + incident 0.25) */
    printf("radiance texture edge: red %.4f | %.4f (truth %.4f | %.4f)\n", hi, lo, 0.8 * 0.3, 0.2 * 0.3);
    CHECK(fabs(hi - 0.8 * 0.3) < 0.01 && fabs(lo - 0.2 * 0.3) < 0.005);
    free(pt);
    return rig_close(&r);
}

static int test_depth_step(void)
{
    rig r;
    CHECK(rig_open(&r, 96, 48, true, NULL) == 0);
    for (uint32_t k = 1; k <= 4; ++k) {
        scene_frame(&r.s, 0.5f, k);
        CHECK(sy_filter_radiance_frame(r.rf, &r.in, r.out, NULL, &r.err) == SY_FILTER_OK);
    }
    double left = 0, lt = 0;
    for (uint32_t y = 0; y < r.s.h; ++y) {
        size_t i = (size_t)y * r.s.w + r.s.w / 2 - 1;
        left += r.out[4 * i + 1], lt += r.s.truth[4 * i + 1];
    }
    left /= r.s.h, lt /= r.s.h;
    printf("radiance depth step: column left of edge %.4f (truth %.4f; right side is 4x brighter)\n", left, lt);
    CHECK(fabs(left - lt) < 0.05 * lt + 0.005);
    return rig_close(&r);
}

static int test_correction_phase(void)
{
    sy_filter_radiance_params p;
    sy_filter_radiance_params_default(&p);
    p.unbiased_switch = true;
    rig r;
    CHECK(rig_open(&r, 32, 24, false, &p) == 0);
    float *pt = calloc(3 * r.n, sizeof(float));
    CHECK(pt);
    sy_filter_stats st;
    for (uint32_t k = 1; k <= 8; ++k) {
        scene_frame(&r.s, 0.001f, k); /* tiny variance: radius < 1 right after warm-up */
        CHECK(sy_filter_radiance_frame(r.rf, &r.in, r.out, &st, &r.err) == SY_FILTER_OK);
        for (size_t i = 0; i < 3 * r.n; ++i) pt[i] += (r.s.sh[i / 3].direct[i % 3] + r.s.sh[i / 3].pt_indirect[i % 3] - pt[i]) / (float)k;
        if (k <= p.warmup_frames) CHECK(st.mean_blend < 0.5);
    }
    printf("radiance correction phase: share %.3f after 8 frames\n", st.mean_blend);
    CHECK(st.mean_blend == 1.0);
    const float *rad = sy_filter_radiance_radius(r.rf);
    for (size_t i = 0; i < r.n; ++i) {
        CHECK(rad[i] == 0.0f);
        for (int c = 0; c < 3; ++c) CHECK(r.out[4 * i + c] == pt[3 * i + c]); /* exactly the PT mean */
    }
    /* a very glossy pixel (e > specular_limit) is never filtered */
    sy_filter_radiance_reset(r.rf);
    for (size_t i = 0; i < r.n; ++i) r.s.sh[i].exponent = 10000.0f, r.s.sh[i].specular[1] = 0.1f;
    scene_frame(&r.s, 1.0f, 1);
    CHECK(sy_filter_radiance_frame(r.rf, &r.in, r.out, &st, &r.err) == SY_FILTER_OK);
    CHECK(st.mean_blend == 1.0 && sy_filter_radiance_frame_index(r.rf) == 1);
    free(pt);
    return rig_close(&r);
}

static int test_nan_and_params(void)
{
    rig r;
    CHECK(rig_open(&r, 32, 24, false, NULL) == 0);
    scene_frame(&r.s, 1.0f, 1);
    r.s.sm[100].radiance[1] = NAN;
    r.s.sh[200].pt_indirect[0] = INFINITY;
    sy_filter_stats st;
    CHECK(sy_filter_radiance_frame(r.rf, &r.in, r.out, &st, &r.err) == SY_FILTER_OK);
    printf("radiance nan: %llu reported\n", (unsigned long long)st.nonfinite_samples);
    CHECK(st.nonfinite_samples == 2);
    for (size_t i = 0; i < 4 * r.n; ++i) CHECK(isfinite(r.out[i]));
    r.in.pixel_angle = 0;
    CHECK(sy_filter_radiance_frame(r.rf, &r.in, r.out, &st, &r.err) == SY_FILTER_ERROR_INVALID_ARGUMENT &&
          strstr(r.err.message, "pixel_angle"));
    sy_filter_radiance_destroy(r.rf);
    r.rf = NULL; /* a refused create below leaves nothing to destroy */
    sy_filter_radiance_params p;
    sy_filter_radiance_params_default(&p);
    p.threshold = -0.01f;
    CHECK(sy_filter_radiance_create(&p, &r.rf, &r.err) == SY_FILTER_ERROR_INVALID_ARGUMENT && strstr(r.err.message, "threshold"));
    sy_filter_radiance_params_default(&p);
    p.warmup_radius = 0.0f;
    CHECK(sy_filter_radiance_params_check(&p, &r.err) == SY_FILTER_ERROR_INVALID_ARGUMENT);
    return rig_close(&r);
}

/* Seeded with a converged mean (k = 1000, per-sample variance equal to the frame noise): the next
 * frame is k + 1 = 1001 with T_k = 2001 T_u, every pixel in the correction phase, and the output is
 * the running mean (1000 * seed + plain PT) / 1001; bad seeds are rejected. */
static int test_seed(void)
{
    rig r;
    CHECK(rig_open(&r, 32, 24, false, NULL) == 0);
    float *var = malloc(r.n * sizeof(float));
    CHECK(var);
    for (size_t i = 0; i < r.n; ++i) var[i] = 0.05f * sy_filter_luminance(r.s.truth + 4 * i);
    CHECK(sy_filter_radiance_seed(r.rf, r.s.w, r.s.h, r.s.truth, 4, var, 1000, &r.err) == SY_FILTER_OK);
    CHECK(sy_filter_radiance_frame_index(r.rf) == 1000);
    scene_frame(&r.s, 1.0f, 1001);
    sy_filter_stats st;
    CHECK(sy_filter_radiance_frame(r.rf, &r.in, r.out, &st, &r.err) == SY_FILTER_OK);
    double worst = 0;
    for (size_t i = 0; i < r.n; ++i)
        for (int c = 0; c < 3; ++c) {
            double pt = r.s.sh[i].direct[c] + r.s.sh[i].pt_indirect[c];
            double want = (1000.0 * r.s.truth[4 * i + c] + pt) / 1001.0;
            worst = fmax(worst, fabs(r.out[4 * i + c] - want) / (want + 1e-3));
        }
    printf("radiance seed: correction share %.3f, worst relative deviation from the resumed mean %.2e\n",
           st.mean_blend, worst);
    CHECK(st.mean_blend == 1.0 && worst < 1e-4);
    CHECK(sy_filter_radiance_seed(r.rf, r.s.w, r.s.h, r.s.truth, 2, var, 10, &r.err) == SY_FILTER_ERROR_INVALID_ARGUMENT);
    CHECK(sy_filter_radiance_seed(r.rf, r.s.w, r.s.h, r.s.truth, 4, var, 0, &r.err) == SY_FILTER_ERROR_INVALID_ARGUMENT);
    CHECK(sy_filter_radiance_seed(r.rf, 0, r.s.h, r.s.truth, 4, var, 10, &r.err) == SY_FILTER_ERROR_INVALID_ARGUMENT);
    free(var);
    return rig_close(&r);
}

/* The batched BSDF path (default, vectorised Lambert case) equals one single-direction call per
 * neighbour bit for bit, for a Lambertian and a glossy owner, and the filter gives the same image
 * whichever callback form it gets and however many threads it uses. */
static uint64_t g_batch_dirs;
static void batch_via_single(const sy_filter_rf_shading *s, uint32_t count, const float *const wi[3],
                             float *const f_cos[3], float *pdf, void *user)
{
    EXPECT(user == &g_batch_dirs && count >= 1 && count <= 64); /* a callback: counted, goes on */
    for (uint32_t m = 0; m < count; ++m) {
        float w[3] = {wi[0][m], wi[1][m], wi[2][m]}, fc[3];
        sy_filter_rf_bsdf_default(s, w, fc, pdf + m, NULL);
        f_cos[0][m] = fc[0], f_cos[1][m] = fc[1], f_cos[2][m] = fc[2];
    }
    g_batch_dirs += count;
}

static int test_batched_bsdf(void)
{
    for (int glossy = 0; glossy < 2; ++glossy) {
        scene s;
        CHECK(scene_init(&s, 80, 48, true, glossy ? 20.0f : 0.0f) == 0);
        size_t n = (size_t)s.w * s.h;
        /* batch vs single on the frame's own directions (some below the horizon: wi flipped) */
        scene_frame(&s, 1.0f, 1);
        enum { M = 37 };
        float wx[M], wy[M], wz[M], fr[M], fg[M], fb[M], pd[M];
        for (int m = 0; m < M; ++m) {
            const float *w = s.sm[(size_t)m * 53 % n].wi;
            float sg = m % 5 == 0 ? -1.0f : 1.0f;
            wx[m] = w[0], wy[m] = w[1], wz[m] = sg * w[2];
        }
        const sy_filter_rf_shading *owner = s.sh + n / 2 + 3;
        const float *const wi[3] = {wx, wy, wz};
        float *const fc[3] = {fr, fg, fb};
        sy_filter_rf_bsdf_default_batch(owner, M, wi, fc, pd, NULL);
        int diff = 0, zero = 0;
        for (int m = 0; m < M; ++m) {
            float w[3] = {wx[m], wy[m], wz[m]}, f1[3], p1;
            sy_filter_rf_bsdf_default(owner, w, f1, &p1, NULL);
            diff += memcmp(f1, (float[3]){fr[m], fg[m], fb[m]}, sizeof f1) != 0 || memcmp(&p1, pd + m, sizeof p1) != 0;
            zero += pd[m] == 0.0f;
        }
        CHECK(diff == 0 && zero >= M / 5); /* the flipped directions have pdf 0 */
        /* the filter: default (batched) vs per-neighbour single calls vs a user batch; 1 vs all threads */
        float *out[3];
        sy_filter_radiance *rf[3];
        sy_filter_report err = {0};
        for (int v = 0; v < 3; ++v) {
            sy_filter_radiance_params p;
            sy_filter_radiance_params_default(&p);
            p.threads = v == 1 ? 1 : 0;
            out[v] = malloc(4 * n * sizeof(float));
            CHECK(out[v] && sy_filter_radiance_create(&p, &rf[v], &err) == SY_FILTER_OK);
        }
        g_batch_dirs = 0;
        for (uint32_t k = 1; k <= 3; ++k) {
            scene_frame(&s, 1.0f, k);
            for (int v = 0; v < 3; ++v) {
                sy_filter_radiance_input in = input(&s);
                if (v == 1) in.bsdf = sy_filter_rf_bsdf_default;
                if (v == 2) in.bsdf_batch = batch_via_single, in.bsdf = sy_filter_rf_bsdf_default, in.bsdf_user = &g_batch_dirs;
                CHECK(sy_filter_radiance_frame(rf[v], &in, out[v], NULL, &err) == SY_FILTER_OK);
            }
        }
        bool same = memcmp(out[0], out[1], 4 * n * sizeof(float)) == 0 && memcmp(out[0], out[2], 4 * n * sizeof(float)) == 0;
        printf("radiance batched BSDF (%s): %d/%d directions equal single calls, filter images %s (%llu neighbours "
               "re-shaded in batches)\n", glossy ? "glossy" : "Lambert", M - diff, M, same ? "identical" : "DIFFER",
               (unsigned long long)g_batch_dirs);
        CHECK(same && g_batch_dirs > 10 * n); /* the frames did gather */
        for (int v = 0; v < 3; ++v) sy_filter_radiance_destroy(rf[v]), free(out[v]);
        scene_free(&s);
    }
    return 0;
}

SY_CHECK_MAIN("filters radiance", SY_TEST(test_batched_bsdf), SY_TEST(test_texture_and_convergence),
              SY_TEST(test_depth_step), SY_TEST(test_correction_phase), SY_TEST(test_nan_and_params),
              SY_TEST(test_seed))
