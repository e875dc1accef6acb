/* test_filters_temporal.c — temporal reuse (sy_filter_temporal.h) on an analytic scene with a
 * known answer: a pinhole camera at (cx, 0, 0) looking down -Z at a wall z = -5 and a square
 * occluder z = -2, |x|, |y| <= 0.5, both facing the camera. Checked: the reprojected history of a
 * constant-colour wall stays that colour through a pan (and a change of resolution); history and
 * new samples blend with the documented weight; a disocclusion (wall seen behind the occluder's old
 * place) is rejected; neighbourhood clamping pulls stale history to the new samples; noise falls
 * several times over a noisy pan; with the direct/indirect split an emitter stays sharp while the
 * noise is filtered; object motion vectors keep a sliding object's history on the object; the
 * passes' column blocks leave no trace (a mirror-symmetric frame stays symmetric); NaN pixels stay
 * isolated; bad parameters and frames are refused; the a-trous edge-stopping weight stays within
 * its documented bounds of exp; misses (sky) pass through exactly and do not change the hits; the
 * image's edges and its inside, filtered by different loops, give the same pixels; the
 * reprojection's scalar and AVX2 versions give the same values. */
#include "sy_filter_temporal.h"
#include "sy_filter_temporal_internal.h"
#include "synth.h"

#include <math.h>
#include <string.h>

#define YFOV 1.0471976f /* 60 degrees */

typedef struct scene {
    uint32_t w, h;
    float cx;
    bool occluder;
    float ox;     /* the occluder's x offset (object motion) */
    bool stripes; /* the occluder's irradiance in two halves of its own (left 0.4, right 1.6 x e_occ) */
    float *color, *albedo, *normal, *depth, *position;
    float *out;  /* the filter's output for the frame (4 floats a pixel), sized with it */
    float m[16]; /* world_to_pixel */
    uint64_t rng;
} scene;

/* the pixel's ray from (cx, 0, 0): direction (u, v, -1) */
static void ray_of(const scene *s, float x, float y, float *u, float *v)
{
    float th = tanf(0.5f * YFOV), asp = (float)s->w / (float)s->h;
    *u = (2.0f * x / (float)s->w - 1.0f) * th * asp;
    *v = (1.0f - 2.0f * y / (float)s->h) * th;
}

/* frees the frame's images (the scene's fields stay) */
static void scene_free(scene *s)
{
    free(s->color), free(s->albedo), free(s->normal), free(s->depth), free(s->position), free(s->out);
}

/* renders the scene at camera x cx: every hit has albedo 0.5, radiance = 0.5 * E with E the wall's
 * or the occluder's irradiance, times (1 + noise * N(0,1)) when noise > 0 */
static int scene_render(scene *s, uint32_t w, uint32_t h, float cx, float e_wall, float e_occ, float noise)
{
    size_t n = (size_t)w * h;
    if (n > (size_t)s->w * s->h || !s->color) {
        scene_free(s);
        s->color = malloc(4 * n * sizeof(float)), s->albedo = malloc(3 * n * sizeof(float));
        s->normal = malloc(3 * n * sizeof(float)), s->depth = malloc(n * sizeof(float));
        s->position = malloc(3 * n * sizeof(float)), s->out = malloc(4 * n * sizeof(float));
        CHECK(s->color && s->albedo && s->normal && s->depth && s->position && s->out);
    }
    s->w = w, s->h = h, s->cx = cx;
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            size_t i = (size_t)y * w + x;
            float u, v;
            ray_of(s, (float)x + 0.5f, (float)y + 0.5f, &u, &v);
            float lx = cx + 2.0f * u - s->ox; /* x on the occluder, in its own frame */
            bool occ = s->occluder && fabsf(lx) <= 0.5f && fabsf(2.0f * v) <= 0.5f;
            float d = occ ? 2.0f : 5.0f, e = occ ? e_occ : e_wall;
            if (occ && s->stripes) e *= lx > 0.0f ? 1.6f : 0.4f;
            float f = noise > 0.0f ? (float)fmax(0.0, 1.0 + noise * synth_gauss(&s->rng)) : 1.0f;
            s->depth[i] = d;
            float p[3] = {cx + d * u, d * v, -d};
            for (int q = 0; q < 3; ++q) {
                s->position[3 * i + q] = p[q];
                s->normal[3 * i + q] = q == 2 ? 1.0f : 0.0f;
                s->albedo[3 * i + q] = 0.5f;
                s->color[4 * i + q] = 0.5f * e * f;
            }
            s->color[4 * i + 3] = 1.0f;
        }
    /* world_to_pixel: W = -z_cam = -p.z; x W = sx (p.x - cx) + W th asp sx; y W = -sy p.y + W th sy */
    float th = tanf(0.5f * YFOV), asp = (float)w / (float)h;
    float sx = (float)w / (2.0f * th * asp), sy = (float)h / (2.0f * th);
    memset(s->m, 0, sizeof s->m);
    s->m[0] = sx, s->m[8] = -th * asp * sx, s->m[12] = -cx * sx; /* row 0 */
    s->m[5] = -sy, s->m[9] = -th * sy;                           /* row 1 */
    s->m[10] = -1.0f;                                             /* row 2 (unused) */
    s->m[11] = -1.0f;                                             /* row 3: w */
    return 0;
}

static sy_filter_frame scene_frame(const scene *s)
{
    return (sy_filter_frame){.width = s->w, .height = s->h, .color_channels = 4, .variance_channels = 1,
                             .color = s->color, .albedo = s->albedo, .normal = s->normal, .depth = s->depth,
                             .position = s->position, .spp_uniform = 1.0f};
}

static sy_filter_temporal_params plain_params(void)
{
    sy_filter_temporal_params p;
    sy_filter_temporal_params_default(&p);
    p.clamp_gamma = 0.0f, p.atrous_iterations = 0, p.alpha = 0.25f, p.threads = 2;
    return p;
}

/* A test's temporal filter with parameters p (NULL: the defaults); NULL, the failure counted, when
 * sy_filter_temporal_create refuses them. */
static sy_filter_temporal *temporal_open(const sy_filter_temporal_params *p)
{
    sy_filter_temporal *t = NULL;
    sy_filter_report err = {0};
    sy_filter_status r = sy_filter_temporal_create(p, &t, &err);
    EXPECT_MSG(r == SY_FILTER_OK && t, "sy_filter_temporal_create: %d (%s)", (int)r, err.message);
    return t;
}

/* A test of the direct / indirect split: its filter (the defaults on 2 threads; NULL, the failure
 * counted, when refused) and the two parts' buffers for n pixels (*dir, *ind: 3 floats per pixel,
 * NULL when out of memory; the caller frees them). */
static sy_filter_temporal *split_open(size_t n, float **dir, float **ind)
{
    sy_filter_temporal_params p;
    sy_filter_temporal_params_default(&p);
    p.threads = 2;
    *dir = malloc(3 * n * sizeof(float)), *ind = malloc(3 * n * sizeof(float));
    return temporal_open(&p);
}

/* The end of a test: the filter and the scene freed; 0 (passed) for its return. */
static int temporal_close(sy_filter_temporal *t, scene *s)
{
    sy_filter_temporal_destroy(t);
    scene_free(s);
    return 0;
}

static int test_constant_pan(void)
{
    scene s = {.rng = 7};
    sy_filter_temporal *t = temporal_open(NULL); /* the defaults: clamping and a-trous on */
    sy_filter_report err = {0};
    CHECK(t);
    sy_filter_temporal_stats st = {0};
    double maxd = 0;
    for (int k = 0; k < 8; ++k) {
        /* one frame at half resolution, one at 5x: its planes, 14.7 MB of working planes and 5.3 MB of
         * history, take planes_alloc's huge-page path (groups of 4 MiB or more) */
        uint32_t w = k == 5 ? 32 : k == 6 ? 320 : 64, h = k == 5 ? 24 : k == 6 ? 240 : 48;
        CHECK(scene_render(&s, w, h, 0.05f * (float)k, 0.6f, 0.6f, 0.0f) == 0);
        sy_filter_frame f = scene_frame(&s);
        CHECK(sy_filter_temporal_run(t, &f, s.m, s.out, &st, &err) == SY_FILTER_OK);
        for (size_t i = 0; i < (size_t)w * h; ++i)
            for (int q = 0; q < 4; ++q) maxd = fmax(maxd, fabs(s.out[4 * i + q] - (q == 3 ? 1.0 : 0.3)));
        if (k > 0) CHECK_MSG(st.reprojected > st.pixels * 8 / 10, "frame %d: %llu of %llu reprojected", k,
                             (unsigned long long)st.reprojected, (unsigned long long)st.pixels);
    }
    printf("constant wall, 8-frame pan (one at half size, one at 5x): max |out - 0.3| = %.2e, mean history %.1f\n",
           maxd, st.mean_history);
    CHECK(maxd < 1e-5);
    CHECK(st.mean_history > 4.0);
    return temporal_close(t, &s);
}

/* frame 1 radiance 0.5*A everywhere at cx = 0; frame 2 at cx = 0.3 radiance 0.5*B: where the
 * wall's point was visible in frame 1 the output is the blend (A + B)/2 * 0.5 (history length 1:
 * weight 1/2); where it was behind the occluder, or outside frame 1, it is 0.5*B */
static int test_blend_and_disocclusion(void)
{
    scene s = {.occluder = true};
    sy_filter_temporal_params p = plain_params();
    sy_filter_temporal *t = temporal_open(&p);
    sy_filter_report err = {0};
    const uint32_t w = 96, h = 64;
    CHECK(t);
    const float A = 0.4f, B = 0.8f;
    CHECK(scene_render(&s, w, h, 0.0f, A, A, 0.0f) == 0);
    sy_filter_frame f = scene_frame(&s);
    sy_filter_temporal_stats st;
    CHECK(sy_filter_temporal_run(t, &f, s.m, s.out, &st, &err) == SY_FILTER_OK);
    CHECK(st.reprojected == 0 && st.disoccluded == (uint64_t)w * h);
    scene prev = {.w = w, .h = h, .cx = 0.0f};
    CHECK(scene_render(&s, w, h, 0.3f, B, B, 0.0f) == 0);
    CHECK(sy_filter_temporal_run(t, &f, s.m, s.out, &st, &err) == SY_FILTER_OK);
    float th = tanf(0.5f * YFOV), asp = (float)w / (float)h;
    uint32_t n_blend = 0, n_disocc = 0, n_outside = 0;
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            size_t i = (size_t)y * w + x;
            if (s.depth[i] != 5.0f) continue; /* the wall only */
            const float *P = s.position + 3 * i;
            /* P seen from camera 1 (origin): pixel coordinates there, and the occluder's silhouette */
            float u = P[0] / 5.0f, v = P[1] / 5.0f;
            float px = (u / (th * asp) + 1.0f) * 0.5f * (float)prev.w, py = (1.0f - v / th) * 0.5f * (float)prev.h;
            float qx = 0.5f / 2.0f / (th * asp) * 0.5f * (float)w, qy = 0.5f / 2.0f / th * 0.5f * (float)h; /* half size */
            float cx0 = 0.5f * (float)w, cy0 = 0.5f * (float)h;
            bool inside_occ = fabsf(px - cx0) < qx - 1.5f && fabsf(py - cy0) < qy - 1.5f;
            bool clear = (fabsf(px - cx0) > qx + 1.5f || fabsf(py - cy0) > qy + 1.5f) && px > 1.5f &&
                         px < (float)w - 1.5f && py > 1.5f && py < (float)h - 1.5f;
            bool outside = px > (float)w + 1.0f;
            float got = s.out[4 * i];
            if (inside_occ) {
                CHECK_MSG(fabsf(got - 0.5f * B) < 1e-6f, "disoccluded (%u,%u): %g, want %g", x, y, got, 0.5f * B);
                n_disocc++;
            } else if (clear) {
                CHECK_MSG(fabsf(got - 0.25f * (A + B)) < 1e-6f, "reprojected (%u,%u): %g, want %g", x, y, got,
                          0.25f * (A + B));
                n_blend++;
            } else if (outside) {
                CHECK_MSG(fabsf(got - 0.5f * B) < 1e-6f, "new at the edge (%u,%u): %g", x, y, got);
                n_outside++;
            }
        }
    printf("pan 0.3 with an occluder: %u wall pixels blended, %u disoccluded rejected, %u new at the edge\n", n_blend,
           n_disocc, n_outside);
    CHECK(n_blend > 1000 && n_disocc > 50 && n_outside > 50);
    /* the occluder's own pixels are reprojected too (same surface, moved in the image) */
    uint32_t occ_blend = 0;
    for (size_t i = 0; i < (size_t)w * h; ++i)
        occ_blend += s.depth[i] == 2.0f && fabsf(s.out[4 * i] - 0.25f * (A + B)) < 1e-6f;
    CHECK(occ_blend > 100);
    return temporal_close(t, &s);
}

/* stale history far from the new samples: clamped to their neighbourhood box */
static int test_clamp(void)
{
    scene s = {.rng = 11};
    sy_filter_temporal_params p = plain_params();
    p.clamp_gamma = 1.0f;
    sy_filter_temporal *t = temporal_open(&p);
    sy_filter_report err = {0};
    const uint32_t w = 48, h = 32;
    CHECK(t);
    CHECK(scene_render(&s, w, h, 0.0f, 0.1f, 0.1f, 0.0f) == 0);
    sy_filter_frame f = scene_frame(&s);
    CHECK(sy_filter_temporal_run(t, &f, s.m, s.out, NULL, &err) == SY_FILTER_OK);
    CHECK(scene_render(&s, w, h, 0.0f, 2.0f, 2.0f, 0.05f) == 0);
    CHECK(sy_filter_temporal_run(t, &f, s.m, s.out, NULL, &err) == SY_FILTER_OK);
    double worst = 0;
    for (size_t i = 0; i < (size_t)w * h; ++i) worst = fmax(worst, fabs(s.out[4 * i] - 1.0));
    /* unclamped: (0.05 + 1) / 2 = 0.525; clamped within about 2 standard deviations (0.05) of 1 */
    printf("clamp: history 0.05 against new samples 1 +- 5%%: worst |out - 1| = %.3f (unclamped 0.475)\n", worst);
    CHECK(worst < 0.15);
    return temporal_close(t, &s);
}

static int test_noisy_pan(void)
{
    scene s = {.occluder = true, .rng = 5};
    sy_filter_temporal *t = temporal_open(NULL);
    sy_filter_report err = {0};
    const uint32_t w = 96, h = 64;
    size_t n = (size_t)w * h;
    float *last = malloc(4 * n * sizeof(float)), *in_last = malloc(4 * n * sizeof(float));
    CHECK(t && last && in_last);
    double e_in = 0, e_out = 0, fl_in = 0, fl_out = 0;
    uint64_t cnt = 0, fcnt = 0;
    for (int k = 0; k < 20; ++k) {
        CHECK(scene_render(&s, w, h, 0.01f * (float)k, 0.6f, 1.0f, 1.0f) == 0); /* relative sd 1: "1 spp" */
        sy_filter_frame f = scene_frame(&s);
        CHECK(sy_filter_temporal_run(t, &f, s.m, s.out, NULL, &err) == SY_FILTER_OK);
        for (size_t i = 0; i < n && k >= 10; ++i) {
            double truth = s.depth[i] == 2.0f ? 0.5 : 0.3;
            e_in += (s.color[4 * i] - truth) * (s.color[4 * i] - truth) / (truth * truth + 0.01);
            e_out += (s.out[4 * i] - truth) * (s.out[4 * i] - truth) / (truth * truth + 0.01);
            cnt++;
            /* flicker on the wall away from the occluder's edges (the true value does not change) */
            if (s.depth[i] == 5.0f && (i % w) > 4 && (i % w) < w - 4 && fabsf(s.position[3 * i]) > 1.5f) {
                fl_in += fabs(s.color[4 * i] - in_last[4 * i]), fl_out += fabs(s.out[4 * i] - last[4 * i]), fcnt++;
            }
        }
        memcpy(last, s.out, 4 * n * sizeof(float));
        memcpy(in_last, s.color, 4 * n * sizeof(float));
    }
    e_in /= (double)cnt, e_out /= (double)cnt, fl_in /= (double)fcnt, fl_out /= (double)fcnt;
    printf("noisy pan (relative sd 1 per frame): relMSE %.5f -> %.5f (%.1fx), flicker %.4f -> %.4f (%.1fx)\n", e_in,
           e_out, e_in / e_out, fl_in, fl_out, fl_in / fl_out);
    CHECK(e_in / e_out > 5.0);
    CHECK(fl_in / fl_out > 5.0);
    /* the same frames with a-trous off are noisier: the spatial filter does work */
    free(last), free(in_last);
    return temporal_close(t, &s);
}

/* mean absolute change of the red channel between two RGBA images (the scene is grey) */
static double mean_change(const float *a, const float *b, size_t n)
{
    double d = 0;
    for (size_t i = 0; i < n; ++i) d += fabs(a[4 * i] - b[4 * i]);
    return d / (double)n;
}

/* The camera stops after a noisy pan (sy_filter_temporal_rest): the still frames blend the last
 * estimate with the accumulation of the resting view. Measured: the mean absolute change from the
 * last moving frame to the first still one (the pop) against the mean frame-to-frame change while
 * moving (the flicker the viewer already sees). Threshold 1.5x that flicker: a change at the stop
 * that stands out from the motion's own flicker is what reads as a pop; the plain accumulation
 * (2 samples) is checked to jump far beyond it, so the test can fail. No later still frame changes
 * by more than 1.5x the larger of that flicker and the plain accumulation's own change at that
 * sample count (what a still progressive image shows anyway): no pop when the fade ends either.
 * From rest_samples on the output is the accumulation bit for bit. */
static int test_rest(void)
{
    scene s = {.occluder = true, .rng = 11};
    sy_filter_temporal_params p;
    sy_filter_temporal_params_default(&p);
    sy_filter_temporal *t = temporal_open(&p);
    CHECK(t);
    sy_filter_report err = {0};
    const uint32_t w = 96, h = 64;
    size_t n = (size_t)w * h;
    float *last = malloc(4 * n * sizeof(float)), *acc = malloc(4 * n * sizeof(float));
    float *acc_last = malloc(4 * n * sizeof(float));
    double *sum = calloc(4 * n, sizeof(double));
    CHECK(last && acc && acc_last && sum);
    double moving = 0;
    int counted = 0;
    const int pan = 24;
    for (int k = 0; k < pan; ++k) {
        CHECK(scene_render(&s, w, h, 0.01f * (float)k, 0.6f, 1.0f, 1.0f) == 0); /* relative sd 1: "1 spp" */
        sy_filter_frame f = scene_frame(&s);
        CHECK(sy_filter_temporal_run(t, &f, s.m, s.out, NULL, &err) == SY_FILTER_OK);
        if (k >= pan - 8) moving += mean_change(s.out, last, n), counted++;
        memcpy(last, s.out, 4 * n * sizeof(float));
    }
    moving /= counted;
    /* the last moving frame's samples start the resting view's accumulation (as the path tracer's) */
    for (size_t i = 0; i < 4 * n; ++i) sum[i] = s.color[i], acc_last[i] = s.color[i];
    double pop = 0, pop_plain = 0, later = 0; /* later: the largest change over its bound */
    for (uint32_t spp = 2; spp <= p.rest_samples; ++spp) {
        CHECK(scene_render(&s, w, h, 0.01f * (float)(pan - 1), 0.6f, 1.0f, 1.0f) == 0);
        for (size_t i = 0; i < 4 * n; ++i) sum[i] += s.color[i], acc[i] = (float)(sum[i] / spp);
        bool blended = sy_filter_temporal_rest(t, w, h, acc, spp, s.out);
        CHECK_MSG(blended == (spp < p.rest_samples), "%u samples: blended %d", spp, blended);
        double ch = mean_change(s.out, last, n), own = mean_change(acc, acc_last, n);
        if (spp == 2) pop = ch, pop_plain = mean_change(acc, last, n);
        else later = fmax(later, ch / (1.5 * fmax(moving, own)));
        memcpy(last, s.out, 4 * n * sizeof(float));
        memcpy(acc_last, acc, 4 * n * sizeof(float));
    }
    CHECK(!memcmp(s.out, acc, 4 * n * sizeof(float))); /* converged: the accumulation exactly */
    CHECK(!sy_filter_temporal_rest(t, w, h, acc, 3, s.out) && !memcmp(s.out, acc, 4 * n * sizeof(float))); /* dropped */
    printf("camera stops: change at the stop %.5f (plain accumulation %.5f), flicker while moving %.5f; later "
           "frames' change at most %.2f of their bound\n",
           pop, pop_plain, moving, later);
    CHECK(pop <= 1.5 * moving);
    CHECK(pop_plain > 3.0 * moving);
    CHECK(later <= 1.0);
    free(last), free(acc), free(acc_last), free(sum);
    return temporal_close(t, &s);
}

/* the direct/indirect split: a sharp emitter (direct part 10x brighter than the wall around it)
 * in the direct part stays sharp through a pan while the noisy indirect part is filtered */
static int test_split(void)
{
    scene s = {.occluder = true, .rng = 9};
    const uint32_t w = 96, h = 64;
    size_t n = (size_t)w * h;
    float *dir, *ind;
    sy_filter_temporal *t = split_open(n, &dir, &ind);
    sy_filter_report err = {0};
    CHECK(t && dir && ind);
    double e_in = 0, e_out = 0, worst_edge = 0, cnt = 0;
    for (int k = 0; k < 12; ++k) {
        /* the render's colour carries the noise; the split: direct = the noise-free part (the
         * occluder glows: radiance 5, the wall 0.1), indirect = colour - direct */
        CHECK(scene_render(&s, w, h, 0.01f * (float)k, 0.2f, 0.2f, 1.0f) == 0);
        for (size_t i = 0; i < n; ++i) {
            float d = s.depth[i] == 2.0f ? 5.0f : 0.1f;
            for (int q = 0; q < 3; ++q) {
                dir[3 * i + q] = d, ind[3 * i + q] = s.color[4 * i + q];
                s.color[4 * i + q] += d;
            }
        }
        sy_filter_frame f = scene_frame(&s);
        f.direct = dir, f.indirect = ind;
        CHECK(sy_filter_temporal_run(t, &f, s.m, s.out, NULL, &err) == SY_FILTER_OK);
        if (k < 6) continue;
        for (uint32_t y = 1; y + 1 < h; ++y)
            for (uint32_t x = 1; x + 1 < w; ++x) {
                size_t i = (size_t)y * w + x;
                double truth = (s.depth[i] == 2.0f ? 5.0 : 0.1) + 0.1;
                e_in += (s.color[4 * i] - truth) * (s.color[4 * i] - truth) / (truth * truth + 0.01);
                e_out += (s.out[4 * i] - truth) * (s.out[4 * i] - truth) / (truth * truth + 0.01);
                cnt += 1;
                /* wall pixels next to the emitter: no light crept over the edge */
                bool edge = s.depth[i] == 5.0f && (s.depth[i - 1] == 2.0f || s.depth[i + 1] == 2.0f ||
                                                   s.depth[i - w] == 2.0f || s.depth[i + w] == 2.0f);
                if (edge) worst_edge = fmax(worst_edge, fabs(s.out[4 * i] - truth));
            }
    }
    e_in /= cnt, e_out /= cnt;
    printf("split: relMSE %.5f -> %.5f (%.1fx); wall next to the emitter: worst |out - truth| %.3f (emitter 5.1, wall 0.2)\n",
           e_in, e_out, e_in / e_out, worst_edge);
    CHECK(e_in / e_out > 5.0);
    CHECK(worst_edge < 0.1);
    free(dir), free(ind);
    return temporal_close(t, &s);
}

/* object motion (frame.motion): the two-tone occluder slides 0.05 per frame in x in front of the
 * wall under a still camera, noisy samples (relative sd 1). Without motion vectors its history comes
 * from the same pixel, another place on the object (the plane test passes: it slides in its own
 * plane), and its bright half smears over the dark one behind the edge (ghosting); with them the
 * history follows the object. The relMSE on the occluder's pixels (frames 10-29) falls at least 2x
 * (6.3x when written), and the wall's does not rise. */
static double motion_run(bool with_motion, double *e_wall)
{
    scene s = {.occluder = true, .stripes = true, .rng = 23};
    sy_filter_temporal *t = NULL;
    sy_filter_report err = {0};
    if (sy_filter_temporal_create(NULL, &t, &err) != SY_FILTER_OK) return -1.0;
    const uint32_t w = 96, h = 64;
    size_t n = (size_t)w * h;
    float *mv = malloc(3 * n * sizeof(float));
    double e = 0, ew = 0;
    uint64_t cnt = 0, cw = 0;
    const float step = 0.05f;
    for (int k = 0; k < 30 && mv; ++k) {
        s.ox = -0.75f + step * (float)k;
        if (scene_render(&s, w, h, 0.0f, 0.6f, 1.0f, 1.0f)) break;
        for (size_t i = 0; i < n; ++i) /* the occluder was step to the left a frame ago */
            for (int q = 0; q < 3; ++q) mv[3 * i + q] = q == 0 && s.depth[i] == 2.0f ? -step : 0.0f;
        sy_filter_frame f = scene_frame(&s);
        if (with_motion) f.motion = mv;
        if (sy_filter_temporal_run(t, &f, s.m, s.out, NULL, &err)) break;
        for (size_t i = 0; i < n && k >= 10; ++i) {
            float u, v;
            ray_of(&s, (float)(i % w) + 0.5f, (float)(i / w) + 0.5f, &u, &v);
            double truth = 0.3;
            if (s.depth[i] == 2.0f) {
                float lx = 2.0f * u - s.ox;
                truth = 0.5 * (lx > 0.0f ? 1.6 : 0.4);
            }
            double d2 = (s.out[4 * i] - truth) * (s.out[4 * i] - truth) / (truth * truth + 0.01);
            if (s.depth[i] == 2.0f) e += d2, cnt++;
            else ew += d2, cw++;
        }
    }
    free(mv);
    sy_filter_temporal_destroy(t);
    scene_free(&s);
    *e_wall = cw ? ew / (double)cw : -1.0;
    return cnt > 1000 ? e / (double)cnt : -1.0;
}

static int test_object_motion(void)
{
    double wall_cam, wall_obj;
    double cam = motion_run(false, &wall_cam), obj = motion_run(true, &wall_obj);
    printf("sliding two-tone occluder, still camera: relMSE on the object %.5f camera-only -> %.5f with object "
           "motion (%.1fx); wall %.5f -> %.5f\n",
           cam, obj, cam / obj, wall_cam, wall_obj);
    CHECK(cam > 0.0 && obj > 0.0 && wall_cam > 0.0 && wall_obj > 0.0);
    CHECK(cam / obj > 2.0);
    CHECK(wall_obj < 1.1 * wall_cam);
    /* a non-finite motion finds no history (and nothing non-finite reaches the output); a zero motion
     * is the camera-only reprojection */
    scene s = {.occluder = true, .rng = 3};
    sy_filter_temporal *t = temporal_open(NULL);
    sy_filter_report err = {0};
    const uint32_t w = 48, h = 32;
    size_t n = (size_t)w * h;
    float *mv = malloc(3 * n * sizeof(float));
    CHECK(t && mv);
    sy_filter_temporal_stats st = {0};
    for (int k = 0; k < 3; ++k) {
        CHECK(scene_render(&s, w, h, 0.02f * (float)k, 0.6f, 1.0f, 0.0f) == 0);
        for (size_t i = 0; i < 3 * n; ++i) mv[i] = k == 2 ? NAN : 0.0f;
        sy_filter_frame f = scene_frame(&s);
        f.motion = mv;
        CHECK(sy_filter_temporal_run(t, &f, s.m, s.out, &st, &err) == SY_FILTER_OK);
        for (size_t i = 0; i < 4 * n; ++i) CHECK(isfinite(s.out[i]));
        if (k == 1) CHECK(st.reprojected > st.pixels * 8 / 10);
    }
    CHECK(st.reprojected == 0 && st.nonfinite == 0);
    free(mv);
    return temporal_close(t, &s);
}

static int test_bad_input(void)
{
    scene s = {0};
    sy_filter_temporal *t = temporal_open(NULL);
    sy_filter_report err = {0};
    const uint32_t w = 32, h = 24;
    size_t n = (size_t)w * h;
    CHECK(t);
    CHECK(scene_render(&s, w, h, 0.0f, 0.6f, 0.6f, 0.0f) == 0);
    s.color[4 * 100] = NAN, s.normal[3 * 200] = INFINITY;
    sy_filter_frame f = scene_frame(&s);
    sy_filter_temporal_stats st;
    for (int k = 0; k < 3; ++k) {
        CHECK(sy_filter_temporal_run(t, &f, s.m, s.out, &st, &err) == SY_FILTER_OK);
        for (size_t i = 0; i < 4 * n; ++i) CHECK(isfinite(s.out[i]));
        CHECK(st.nonfinite == 2);
        /* neighbours of the bad pixels are untouched by them */
        CHECK(fabsf(s.out[4 * 101] - 0.3f) < 1e-5f && fabsf(s.out[4 * 201] - 0.3f) < 1e-5f);
    }
    /* misses pass through */
    s.depth[50] = INFINITY;
    s.color[4 * 50] = 7.0f;
    CHECK(sy_filter_temporal_run(t, &f, s.m, s.out, &st, &err) == SY_FILTER_OK);
    CHECK(s.out[4 * 50] == 7.0f);
    float bad[16];
    memcpy(bad, s.m, sizeof bad);
    bad[3] = NAN;
    CHECK(sy_filter_temporal_run(t, &f, bad, s.out, &st, &err) == SY_FILTER_ERROR_INVALID_ARGUMENT &&
          strstr(err.message, "world_to_pixel"));
    f.position = NULL;
    CHECK(sy_filter_temporal_run(t, &f, s.m, s.out, &st, &err) == SY_FILTER_ERROR_INVALID_ARGUMENT);
    sy_filter_temporal_params p;
    sy_filter_temporal_params_default(&p);
    p.alpha = 0.0f;
    CHECK(sy_filter_temporal_set_params(t, &p, &err) == SY_FILTER_ERROR_INVALID_ARGUMENT && strstr(err.message, "alpha"));
    sy_filter_temporal_params_default(&p);
    p.atrous_iterations = 9;
    CHECK(sy_filter_temporal_set_params(t, &p, &err) == SY_FILTER_ERROR_INVALID_ARGUMENT &&
          strstr(err.message, "atrous_iterations"));
    sy_filter_temporal_params_default(&p);
    p.max_history = 0;
    sy_filter_temporal *t2 = NULL;
    CHECK(sy_filter_temporal_create(&p, &t2, &err) == SY_FILTER_ERROR_INVALID_ARGUMENT && !t2);
    sy_filter_temporal_destroy(t);
    sy_filter_temporal_destroy(NULL);
    scene_free(&s);
    return 0;
}

/* The passes split a row into column blocks (the integration pass's 128-column blocks, the a-trous
 * passes' 128-column chunks after their first `step` columns): the output must not depend on where
 * those boundaries fall. A scene mirror-symmetric about the image's centre line (the noise of the
 * left half mirrored onto the right) at 300 columns puts the boundaries (128, 256; 8 + 128k) at
 * columns whose mirror images are inside blocks, so a block edge that loses or shifts a tap breaks
 * the symmetry. Only rounding differs between a pixel and its mirror (the taps run left to right,
 * the reprojection's bilinear weights): a few ulps, which the a-trous passes' luminance edge stop
 * (1 / (sigma sqrt(variance) + 1e-6), large where the variance is small) raises to up to a few
 * 1e-4 of the largest value (measured here: 4.0e-5; with a constant light 1.2e-5 without a-trous
 * passes, 1.3e-4 with them); a block that loses a tap or a column differs by a good part of it
 * (seen: 0.06-7.5). */
static int test_block_symmetry(void)
{
    const uint32_t w = 300, h = 40;
    size_t n = (size_t)w * h;
    float *dir = malloc(3 * n * sizeof(float)), *ind = malloc(3 * n * sizeof(float));
    CHECK(dir && ind);
    for (int split = 0; split < 2; ++split) { /* the colour alone, then direct and indirect parts */
        scene s = {.rng = 23, .occluder = true};
        sy_filter_temporal *t = temporal_open(NULL); /* the defaults: clamping and 4 a-trous passes */
        sy_filter_report err = {0};
        CHECK(t);
        double maxd = 0, maxv = 0;
        for (int k = 0; k < 4; ++k) { /* the light changes from frame to frame: no pass's stale plane matches */
            CHECK(scene_render(&s, w, h, 0.0f, 0.3f + 0.3f * (float)(k & 1), 1.0f + 0.6f * (float)k, 1.0f) == 0);
            for (uint32_t y = 0; y < h; ++y)
                for (uint32_t x = 0; x < w / 2; ++x) {
                    size_t i = (size_t)y * w + x, j = (size_t)y * w + (w - 1 - x);
                    memcpy(s.color + 4 * j, s.color + 4 * i, 4 * sizeof(float));
                    s.position[3 * j] = -s.position[3 * i];
                }
            for (size_t i = 0; split && i < n; ++i) /* direct: noise-free, the occluder glowing */
                for (int q = 0; q < 3; ++q) {
                    dir[3 * i + q] = s.depth[i] == 2.0f ? 3.0f : 0.2f, ind[3 * i + q] = s.color[4 * i + q];
                    s.color[4 * i + q] += dir[3 * i + q];
                }
            sy_filter_frame f = scene_frame(&s);
            if (split) f.direct = dir, f.indirect = ind;
            CHECK(sy_filter_temporal_run(t, &f, s.m, s.out, NULL, &err) == SY_FILTER_OK);
            for (uint32_t y = 0; y < h; ++y)
                for (uint32_t x = 0; x < w / 2; ++x)
                    for (int q = 0; q < 3; ++q) {
                        float a = s.out[4 * ((size_t)y * w + x) + q], b = s.out[4 * ((size_t)y * w + (w - 1 - x)) + q];
                        maxd = fmax(maxd, fabs(a - b)), maxv = fmax(maxv, fabs(a));
                    }
        }
        printf("mirror-symmetric 300x40 frames%s: max |out(x) - out(w-1-x)| = %.2e (largest value %.3f)\n",
               split ? ", direct and indirect" : "", maxd, maxv);
        CHECK(maxv > 0.1);
        CHECK(maxd <= 2e-3 * maxv);
        temporal_close(t, &s);
    }
    free(dir), free(ind);
    return 0;
}

/* sky_run's image and where its misses lie in frame k: left of a column off the 16-column groups,
 * the top rows, a band between hits inside the a-trous rows' first chunk of 128 columns (PF_COLS)
 * and one across the start of their second: runs of misses that hits and a chunk's end interrupt,
 * at every pass's step (each band holds a whole group of 16 columns however they are aligned) */
enum { SKY_W = 300, SKY_H = 40 };
static bool sky_miss(uint32_t x, uint32_t y, int k)
{
    uint32_t u = (uint32_t)k;
    return x < 37u + u || y < 9 || (x >= 60u && x < 100u + u) || (x >= 120u && x < 150u + u);
}

/* Sky: misses (depth +inf) where sky_miss says, the rest the scene's noisy wall and occluder; a pan
 * of 4 frames with the default passes, at the sky colour sky (times a pattern that changes from
 * frame to frame, so that a miss left out keeps no older frame's right value). Out: every
 * frame's output (4 x 4 n floats, *out, the caller frees), the hits' relMSE against the noise-free
 * scene in the last frame's input and output; false when a miss did not pass through exactly. */
static bool sky_run(bool split, float sky, float **out, double *e_in, double *e_out)
{
    scene s = {.occluder = true, .rng = 21};
    const uint32_t w = SKY_W, h = SKY_H;
    size_t n = (size_t)w * h;
    float *dir, *ind;
    sy_filter_temporal *t = split_open(n, &dir, &ind);
    sy_filter_report err = {0};
    *out = malloc(4 * 4 * n * sizeof(float));
    bool through = t && dir && ind && *out;
    for (int k = 0; k < 4 && through; ++k) {
        through = scene_render(&s, w, h, 0.02f * (float)k, 0.6f, 1.0f, 1.0f) == 0;
        for (size_t i = 0; i < n; ++i) {
            uint32_t x = (uint32_t)(i % w), y = (uint32_t)(i / w);
            bool miss = sky_miss(x, y, k);
            if (miss) {
                s.depth[i] = INFINITY;
                for (int q = 0; q < 3; ++q) {
                    s.color[4 * i + q] = sky * (1.0f + 0.5f * sinf(0.37f * (float)(i * 3 + q) + (float)k));
                    s.normal[3 * i + q] = 0.0f, s.position[3 * i + q] = 0.0f;
                }
            }
            for (int q = 0; q < 3; ++q) { /* the split: a quarter of a hit's colour is direct light */
                float c = s.color[4 * i + q], d = miss ? 0.0f : 0.25f * c;
                dir[3 * i + q] = d, ind[3 * i + q] = miss ? c : c - d;
            }
        }
        sy_filter_frame f = scene_frame(&s);
        if (split) f.direct = dir, f.indirect = ind;
        through = through && sy_filter_temporal_run(t, &f, s.m, s.out, NULL, &err) == SY_FILTER_OK;
        for (size_t i = 0; i < n && through; ++i)
            if (s.depth[i] == INFINITY)
                for (int q = 0; q < 4; ++q) through = through && s.out[4 * i + q] == s.color[4 * i + q];
        if (through) memcpy(*out + 4 * n * (size_t)k, s.out, 4 * n * sizeof(float));
        *e_in = *e_out = 0.0;
        for (size_t i = 0; i < n; ++i) {
            if (s.depth[i] == INFINITY) continue;
            double truth = s.depth[i] == 2.0f ? 0.5 : 0.3, di = s.color[4 * i] - truth, d_o = s.out[4 * i] - truth;
            *e_in += di * di / (truth * truth), *e_out += d_o * d_o / (truth * truth);
        }
    }
    free(dir), free(ind);
    sy_filter_temporal_destroy(t);
    scene_free(&s);
    return through;
}

/* the a-trous rows skip groups of columns without a hit and the reprojection groups without
 * history: misses still pass through exactly, the hits are filtered (their noise falls), and their
 * output is the same whatever the sky */
static int test_sky(void)
{
    for (int split = 0; split < 2; ++split) {
        float *a = NULL, *b = NULL;
        double ein = 0, eout = 0, ein2 = 0, eout2 = 0;
        bool ta = sky_run(split, 0.3f, &a, &ein, &eout), tb = sky_run(split, 50.0f, &b, &ein2, &eout2);
        EXPECT_MSG(ta && tb, "split %d: a miss did not pass through", split);
        printf("sky, split %d: hits' relMSE sum %.2f -> %.2f after 4 frames\n", split, ein, eout);
        EXPECT_MSG(eout < 0.05 * ein, "split %d: the hits were not filtered (relMSE sum %.3f -> %.3f)", split, ein, eout);
        const size_t n = (size_t)SKY_W * SKY_H;
        size_t hits = 0, same = 0;
        for (size_t k = 0; ta && tb && k < 4; ++k)
            for (size_t i = 0; i < n; ++i) {
                if (sky_miss((uint32_t)(i % SKY_W), (uint32_t)(i / SKY_W), (int)k)) continue;
                ++hits;
                same += memcmp(a + 4 * (n * k + i), b + 4 * (n * k + i), 4 * sizeof(float)) == 0;
            }
        EXPECT_MSG(hits > 20000 && same == hits, "split %d: %zu of %zu hits depend on the sky", split, hits - same, hits);
        free(a), free(b);
    }
    return 0;
}

/* The image's edges and the inside take different paths through every pass (the clamp's statistics,
 * the variance blur and the a-trous rows tap by tap at an edge, in fused loops inside); both must
 * give the same sums in the same order. Frames A, and B: A moved one column to the right behind a
 * column of misses, whose taps weigh 0 and add nothing. Positions are pixel coordinates (x + 0.5,
 * y + 0.5; B's one more in x) and world_to_pixel takes them as they are, so that a still camera's
 * second frame finds its history at exactly its own pixel in both. B's columns 1.. equal A bit for
 * bit in both frames, though A's first columns went the edge's way and B's the inside's; with and
 * without the direct / indirect split. (A tap or weight one path lacks changes hundreds of pixels;
 * two additions swapped in one path may change none: the frames of sy render are compared bit for
 * bit, exr_equal, before such a change.) */
static int test_edge_inside(void)
{
    const uint32_t w = 120, h = 30;
    size_t n = (size_t)w * h, nb = (size_t)(w + 1) * h;
    scene a = {.occluder = true, .rng = 31}, b = {.occluder = true};
    float *dir = malloc(3 * n * sizeof(float)), *ind = malloc(3 * n * sizeof(float));
    float *dirb = malloc(3 * nb * sizeof(float)), *indb = malloc(3 * nb * sizeof(float));
    CHECK(dir && ind && dirb && indb);
    for (int split = 0; split < 2; ++split) {
        sy_filter_temporal *ta = temporal_open(NULL), *tb = temporal_open(NULL); /* the defaults */
        sy_filter_report err = {0};
        CHECK(ta && tb);
        for (int k = 0; k < 2; ++k) {
            /* the light changes: the second frame's history lies outside its clamp's box, which
             * then sets the output */
            CHECK(scene_render(&a, w, h, 0.1f, 0.3f + 0.5f * (float)k, 1.0f - 0.4f * (float)k, 1.0f) == 0);
            CHECK(scene_render(&b, w + 1, h, 0.1f, 0.3f, 1.0f, 0.0f) == 0); /* B's buffers; its pixels below */
            float m[16] = {[0] = 1.0f, [5] = 1.0f, [10] = 1.0f, [15] = 1.0f}; /* pixel = position */
            memcpy(a.m, m, sizeof m), memcpy(b.m, m, sizeof m);
            for (size_t i = 0; i < n; ++i) {
                a.position[3 * i] = (float)(i % w) + 0.5f, a.position[3 * i + 1] = (float)(i / w) + 0.5f;
                for (int q = 0; q < 3; ++q) { /* the split: a noise-free glowing occluder, the rest indirect */
                    dir[3 * i + q] = a.depth[i] == 2.0f ? 3.0f : 0.2f, ind[3 * i + q] = a.color[4 * i + q];
                    a.color[4 * i + q] += dir[3 * i + q];
                }
            }
            for (uint32_t y = 0; y < h; ++y)
                for (uint32_t x = 0; x <= w; ++x) {
                    size_t j = (size_t)y * (w + 1) + x, i = (size_t)y * w + x - 1;
                    if (x == 0) { /* a miss: sky colour, no geometry */
                        b.depth[j] = INFINITY;
                        for (int q = 0; q < 3; ++q) {
                            b.color[4 * j + q] = 0.7f, b.albedo[3 * j + q] = 0.5f;
                            b.normal[3 * j + q] = b.position[3 * j + q] = 0.0f;
                            dirb[3 * j + q] = 0.0f, indb[3 * j + q] = 0.7f;
                        }
                        b.color[4 * j + 3] = 1.0f;
                        continue;
                    }
                    memcpy(b.color + 4 * j, a.color + 4 * i, 4 * sizeof(float));
                    memcpy(b.albedo + 3 * j, a.albedo + 3 * i, 3 * sizeof(float));
                    memcpy(b.normal + 3 * j, a.normal + 3 * i, 3 * sizeof(float));
                    memcpy(b.position + 3 * j, a.position + 3 * i, 3 * sizeof(float));
                    b.position[3 * j] += 1.0f;
                    memcpy(dirb + 3 * j, dir + 3 * i, 3 * sizeof(float));
                    memcpy(indb + 3 * j, ind + 3 * i, 3 * sizeof(float));
                    b.depth[j] = a.depth[i];
                }
            sy_filter_frame fa = scene_frame(&a), fb = scene_frame(&b);
            if (split) fa.direct = dir, fa.indirect = ind, fb.direct = dirb, fb.indirect = indb;
            sy_filter_temporal_stats sa = {0}, sb = {0};
            CHECK(sy_filter_temporal_run(ta, &fa, a.m, a.out, &sa, &err) == SY_FILTER_OK);
            CHECK(sy_filter_temporal_run(tb, &fb, b.m, b.out, &sb, &err) == SY_FILTER_OK);
            size_t same = 0, changed = 0;
            for (uint32_t y = 0; y < h; ++y)
                for (uint32_t x = 0; x < w; ++x) {
                    size_t i = (size_t)y * w + x, j = (size_t)y * (w + 1) + x + 1;
                    same += memcmp(a.out + 4 * i, b.out + 4 * j, 4 * sizeof(float)) == 0;
                    changed += fabsf(a.out[4 * i] - a.color[4 * i]) > 1e-3f * a.color[4 * i];
                }
            printf("edge and inside, split %d, frame %d: %zu of %zu pixels the same bit for bit, %zu filtered\n",
                   split, k, same, n, changed);
            EXPECT_MSG(same == n, "split %d, frame %d: %zu pixels differ between the edge's path and the inside's",
                       split, k, n - same);
            EXPECT(changed > n / 2); /* the passes ran: most pixels differ from their input */
            /* the second frame's hits take their history (the clamp's statistics decide with it) */
            EXPECT(sa.reprojected == (k ? n : 0) && sb.reprojected == sa.reprojected);
        }
        sy_filter_temporal_destroy(ta), sy_filter_temporal_destroy(tb);
    }
    free(dir), free(ind), free(dirb), free(indb);
    scene_free(&b);
    return temporal_close(NULL, &a);
}

/* the a-trous edge-stopping weight (expneg, sy_filter_temporal_internal.h): 1 at 0, within -0.0003 %
 * and +6.2 % of exp(-x) over [0, EXP_MAX], exact at multiples of ln 2, never rising, NaN and large x
 * clamped to EXP_MAX, whose weight is a normal float below half an ulp of the centre's 0.25 */
static int test_weight(void)
{
    CHECK(expneg(0.0f, EXP_MAX) == 1.0f);
    double lo = 2.0, hi = 0.0;
    float prev = 2.0f;
    for (int i = 0; i <= 1600000; ++i) {
        float x = (float)i * 1e-5f, e = expneg(x, EXP_MAX);
        double r = e / exp(-(double)x);
        lo = r < lo ? r : lo, hi = r > hi ? r : hi;
        CHECK(e <= prev);
        prev = e;
    }
    CHECK(lo > 1.0 - 3e-6 && lo <= 1.0);
    CHECK(hi > 1.06 && hi < 1.062);
    for (int k = 1; k <= 16; ++k) { /* x = k ln 2: 2^-k up to the float rounding of x */
        float e = expneg((float)k * 0.69314718f, EXP_MAX);
        CHECK(fabs(e * ldexp(1.0, k) - 1.0) < 1e-5);
    }
    float top = expneg(EXP_MAX, EXP_MAX);
    CHECK(expneg(NAN, EXP_MAX) == top && expneg(1e30f, EXP_MAX) == top && expneg(INFINITY, EXP_MAX) == top);
    CHECK(isnormal(top) && isnormal(0.125f * top * 0.125f * top));
    volatile float centre = 0.25f;
    CHECK(centre + 0.125f * top == centre);
    return 0;
}

/* The reprojection's two versions (sy_filter_temporal_reproject_row: the scalar loop and, on a CPU
 * with AVX2, 8 pixels at a time, with a plain load where a group's 8 taps lie on consecutive history
 * pixels and gathers elsewhere) give the same values bit for bit. World = pixel coordinates (M the
 * identity, so a point (x, y, z) lands at pixel (x - 0.5, y - 0.5)); the 64x20 history's pixel
 * (i, j) sits at (i + 0.5, j + 0.5, 0) with normal +z, its 11 reprojected planes random, a pixel
 * without a history (length 0) or normal here and there. Rows of 61 points (7 groups of 8, then 5
 * through the scalar loop): moved by 3.25 columns (every group's taps consecutive), jittered by up to
 * half a pixel in x and y (consecutive, repeated and skipped columns, two rows in one group), moved
 * past the left and the right edge, with misses and normals away from +z. */
static int test_reproject_paths(void)
{
    if (!sy_filter_temporal_reproject_avx2()) {
        printf("  test_reproject_paths: skipped: this CPU has no AVX2 (only the scalar loop runs)\n");
        return 0;
    }
    enum { HW = 64, HH = 20, W = 61, ROWS = 5 };
    const size_t hn = (size_t)HW * HH + 16, n = W + 3;
    float *base = calloc(17 * hn, sizeof(float));
    float *pts = calloc(8 * (size_t)W, sizeof(float));
    float *ra = calloc(12 * n, sizeof(float)), *rb = calloc(12 * n, sizeof(float));
    CHECK(base && pts && ra && rb);
    uint64_t rng = 99;
    for (size_t j = 0; j < (size_t)HW * HH; ++j) {
        for (int q = 0; q < 10; ++q) base[q * hn + j] = (float)synth_uniform(&rng);
        base[10 * hn + j] = synth_uniform(&rng) < 0.05 ? 0.0f : (float)(1 + (int)(synth_uniform(&rng) * 30.0));
        base[11 * hn + j] = (float)(j % HW) + 0.5f, base[12 * hn + j] = (float)(j / HW) + 0.5f;
        base[16 * hn + j] = synth_uniform(&rng) < 0.05 ? 0.0f : 1.0f; /* normal +z, or none */
    }
    float M[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    float *pa = pts, *pb = pa + W, *pc = pb + W, *na = pc + W, *nb = na + W, *nc = nb + W, *z = nc + W, *h = z + W;
    int reused[ROWS] = {0};
    for (int r = 0; r < ROWS; ++r) {
        for (int x = 0; x < W; ++x) {
            float y = 7.5f + 0.3f * (float)r;
            float dx = r == 0 ? 3.25f : r == 3 ? -9.0f : r == 4 ? 9.0f : 0.0f;
            float jx = r == 1 || r == 2 ? (float)synth_uniform(&rng) - 0.5f : 0.0f;
            float jy = r == 2 ? (float)synth_uniform(&rng) - 0.5f : 0.0f;
            pa[x] = (float)x + 0.5f + dx + jx, pb[x] = y + jy, pc[x] = 0.0f;
            bool miss = r >= 1 && synth_uniform(&rng) < 0.1, tilted = r >= 1 && synth_uniform(&rng) < 0.1;
            na[x] = tilted ? 0.8f : 0.0f, nb[x] = 0.0f, nc[x] = tilted ? 0.6f : 1.0f;
            z[x] = 1.0f, h[x] = miss ? 0.0f : 1.0f;
        }
        memset(ra, 0xff, 12 * n * sizeof(float)), memset(rb, 0xff, 12 * n * sizeof(float));
        sy_filter_temporal_reproject_row(false, W, n, M, HW, HH, hn, base, 0.5f, 0.9f, pa, pb, pc, na, nb, nc, z, h, ra,
                                         ra + 11 * n);
        sy_filter_temporal_reproject_row(true, W, n, M, HW, HH, hn, base, 0.5f, 0.9f, pa, pb, pc, na, nb, nc, z, h, rb,
                                         rb + 11 * n);
        for (int q = 0; q < 12; ++q)
            CHECK_MSG(memcmp(ra + q * n, rb + q * n, W * sizeof(float)) == 0, "row %d plane %d differs", r, q);
        for (int x = 0; x < W; ++x) reused[r] += ra[11 * n + x] > 0.0f;
    }
    printf("  reprojection, scalar and AVX2 the same; reused per row: %d %d %d %d %d of %d\n", reused[0], reused[1],
           reused[2], reused[3], reused[4], W);
    CHECK(reused[0] >= W - 4); /* all but the points past the history's right edge and its few gaps */
    CHECK(reused[1] > W / 2 && reused[2] > W / 2);
    CHECK(reused[3] < W - 6 && reused[4] < W - 6); /* the points moved outside find none */
    free(base), free(pts), free(ra), free(rb);
    return 0;
}

int main(void)
{
    RUN(test_constant_pan);
    RUN(test_blend_and_disocclusion);
    RUN(test_clamp);
    RUN(test_noisy_pan);
    RUN(test_rest);
    RUN(test_split);
    RUN(test_object_motion);
    RUN(test_block_symmetry);
    RUN(test_bad_input);
    RUN(test_weight);
    RUN(test_sky);
    RUN(test_edge_inside);
    RUN(test_reproject_paths);
    return sy_check_finish("filters temporal");
}
