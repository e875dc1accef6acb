/* sy_bench_temporal.c — `sy bench temporal` (issue 36): the path tracer's temporal reuse on a
 * moving camera (sy_filter_temporal.h, the "temporal" parameter). A camera path of N frames (an
 * orbit of 0.006 rad per frame around the scene camera's target), 1 sample per pixel per frame, is
 * rendered twice: plain (what a moving view showed before) and with temporal reuse; each view is
 * also rendered with many samples (the reference). Reported: per-frame relMSE against the reference
 * (mean over the frames after the first, and the ratio), the temporal flicker (mean absolute
 * frame-to-frame change of the displayed luminance on pixels whose reference changes by less than
 * 1 % + 0.002) and the ratio, the change of the display when the camera stops at the path's end
 * (sy_filter_temporal_rest: no pop), and the cost of the temporal stage per frame at 640x360 next to
 * one 1-spp pass there, and the cost of the object motion pass (every instance sliding under a still
 * camera) next to the rest of the stage, and for a scene with an animation (skins, morph targets)
 * the pass with per-vertex motion while it plays, next to the rest and to the rigid pass. Ratios
 * come from one run; nothing here is a timed test. */
#include "sy_anim.h"
#include "sy_bench.h"
#include "sy_interactive.h"
#include "sy_png.h"
#ifdef SY_HAVE_EMBREE
#include "sy_mediator_rt.h"
#endif

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef SY_HAVE_EMBREE
static double lum(const float *p)
{
    return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
}

/* relMSE of img against ref (RGB, 4 floats per pixel): mean of (x - r)^2 / (r^2 + 0.01) */
static double rel_mse(const float *img, const float *ref, size_t n)
{
    double s = 0;
    for (size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c) {
            double x = img[4 * i + c], r = ref[4 * i + c];
            if (!isfinite(x)) x = 0;
            s += (x - r) * (x - r) / (r * r + 0.01);
        }
    return s / (3.0 * (double)n);
}

/* the view after frame k of the path */
static void path_view(const sy_interactive_input *home, uint32_t k, sy_mat4 *m)
{
    sy_orbit o = home->orbit;
    sy_orbit_rotate(&o, 0.75f * (float)k, 0.0f); /* 0.006 rad per frame */
    sy_orbit_matrix(&o, m);
}

/* The nodes under root (depth first; a node shared by two parents comes twice) with a mesh and neither a light nor a camera: what
 * the object-motion cost moves. *out malloc()ed. */
static sy_result moving_nodes(sy_scene *scene, sy_node root, uint32_t **out, uint32_t *count, sy_error *err)
{
    uint32_t cap = 64, n = 0, top = 0, scap = 64;
    uint32_t *list = malloc(cap * sizeof *list), *stack = malloc(scap * sizeof *stack);
    sy_result r = list && stack ? SY_OK : sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench temporal: out of memory");
    if (r == SY_OK) stack[top++] = root.id;
    while (r == SY_OK && top) {
        uint32_t id = stack[--top];
        const sy_node_data *d = sy_node_get(scene, (sy_node){id});
        if (!d) continue;
        if (d->mesh.id && !d->light.id && !d->camera.id) {
            if (n == cap) {
                uint32_t *g = realloc(list, 2 * cap * sizeof *list);
                if (!g) { r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench temporal: out of memory"); break; }
                list = g, cap *= 2;
            }
            list[n++] = id;
        }
        uint32_t nc = 0;
        const uint32_t *c = sy_node_children(d, &nc);
        for (uint32_t i = 0; i < nc && r == SY_OK; ++i) {
            if (top == scap) {
                uint32_t *g = realloc(stack, 2 * scap * sizeof *stack);
                if (!g) { r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench temporal: out of memory"); break; }
                stack = g, scap *= 2;
            }
            stack[top++] = c[i];
        }
    }
    free(stack);
    if (r != SY_OK) {
        free(list);
        list = NULL, n = 0;
    }
    *out = list, *count = n;
    return r;
}

typedef struct bench_win {
    sy_window *win;
    sy_viewport *vp;
} bench_win;

static sy_result bench_win_make(const sy_viewport_desc *vd, const char *params, uint32_t w, uint32_t h, bench_win *b,
                                sy_error *err)
{
    sy_viewport_desc d = *vd;
    d.backend = "pathtracer";
    d.params = params;
    sy_result r = sy_window_create(w, h, &b->win, err);
    if (r == SY_OK) r = sy_window_add_viewport(b->win, &d, &b->vp, err);
    return r;
}

static sy_result bench_win_frame(bench_win *b, const sy_mat4 *view, sy_scene *scene, sy_context_pool *pool,
                                 uint32_t samples, uint32_t seed, sy_layer *out, double *secs, sy_error *err);

/* Sorts three series of n frames each (their medians at [n / 2]). */
static void sort3(uint32_t n, double *a, double *b, double *c)
{
    qsort(a, n, sizeof a[0], sy_bench_cmp_double);
    qsort(b, n, sizeof b[0], sy_bench_cmp_double);
    qsort(c, n, sizeof c[0], sy_bench_cmp_double);
}

/* One frame k of the object motion measurements: the scene (moved by the caller) committed and
 * rendered under the path's first view at 1 spp; for k > 0 the motion pass's seconds into
 * motion[k - 1], the rest of the temporal stage into rest[k - 1] and the motion pass without its
 * coverage rays into pixels[k - 1]; *fi the context's filter info. */
static sy_result motion_frame(bench_win *cost, const sy_interactive_input *home, sy_scene *scene, sy_context_pool *pool,
                              sy_context *ctx, uint32_t k, sy_layer *a, sy_mediator_rt_filter_info *fi, double *motion,
                              double *rest, double *pixels, sy_error *err)
{
    sy_result r = sy_scene_commit(scene, NULL, err);
    sy_mat4 m;
    path_view(home, 0, &m);
    double s;
    if (r == SY_OK) r = bench_win_frame(cost, &m, scene, pool, 1, 0, a, &s, err);
    if (r == SY_OK && k > 0) {
        sy_mediator_rt_filter_info_get(sy_context_state(ctx), fi);
        motion[k - 1] = fi->temporal_motion_seconds, rest[k - 1] = fi->temporal_seconds - fi->temporal_motion_seconds;
        pixels[k - 1] = fi->temporal_motion_seconds - fi->temporal_motion_trace_seconds;
    }
    return r;
}

static sy_result bench_win_frame(bench_win *b, const sy_mat4 *view, sy_scene *scene, sy_context_pool *pool,
                                 uint32_t samples, uint32_t seed, sy_layer *out, double *secs, sy_error *err)
{
    sy_viewport_set_view(b->vp, view);
    uint32_t w, h;
    sy_window_size(b->win, &w, &h);
    if (out->width != w || out->height != h) {
        sy_layer_destroy(out);
        sy_result r = sy_layer_create(w, h, out, err);
        if (r != SY_OK) return r;
    }
    sy_window_render_opts ro = {.sample_count = samples, .seed = seed};
    double t0 = sy_time_now();
    sy_result r = sy_window_render(b->win, scene, pool, &ro, out, err);
    *secs = sy_time_now() - t0;
    return r;
}
#endif

sy_result sy_bench_temporal(sy_scene *scene, const sy_viewport_desc *vd, const char *label, uint32_t width,
                            uint32_t height, uint32_t frames, uint32_t ref_spp, uint32_t cost_frames,
                            const char *png_prefix, sy_error *err)
{
#ifndef SY_HAVE_EMBREE
    (void)scene, (void)vd, (void)label, (void)width, (void)height, (void)frames, (void)ref_spp, (void)cost_frames;
    (void)png_prefix;
    SY_BENCH_WITHOUT(err, "temporal", "SY_WITH_EMBREE");
#else
    bench_win plain = {0}, temporal = {0}, ref = {0}, cost = {0};
    sy_context_pool *pool = NULL;
    size_t n = (size_t)width * height;
    /* series: 0 plain (today's moving frames: one seed, so the noise pattern stays on the screen),
     * 1 plain with a seed per frame (independent noise), 2 temporal; 3 the reference */
    enum { SERIES = 3 };
    static const char *const names[SERIES + 1] = {"plain", "fresh", "temporal", "reference"};
    sy_layer img[SERIES + 1] = {{0}};
    float *prev[SERIES + 1] = {NULL};
    bool mem = true;
    for (int q = 0; q <= SERIES; ++q) mem = mem && (prev[q] = malloc(4 * n * sizeof(float))) != NULL;
    sy_interactive_input home;
    sy_result r = mem ? SY_OK : sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench temporal: out of memory");
    if (r == SY_OK)
        r = sy_interactive_input_init(scene, vd->root, vd->camera, (float)width / (float)height, NULL, 0.0f, &home, err);
    /* three contexts: plain, temporal, the reference */
    if (r == SY_OK) r = bench_win_make(vd, "temporal=0", width, height, &plain, err);
    if (r == SY_OK) r = bench_win_make(vd, "temporal=1", width, height, &temporal, err);
    if (r == SY_OK) r = bench_win_make(vd, "temporal=0,light_samples=16", width, height, &ref, err);
    if (r == SY_OK) r = sy_context_pool_create(&pool, err);
    double e[SERIES] = {0}, fl[SERIES] = {0}, t_ref = 0;
    uint64_t f_count = 0;
    uint32_t counted = 0, nonfinite = 0;
    printf("%s, %ux%u, %u frames of 1 spp, orbit 0.006 rad/frame, reference %u spp per view:\n", label, width, height,
           frames, ref_spp);
    printf("  frame  relMSE plain   fresh  temporal\n");
    for (uint32_t k = 0; k < frames && r == SY_OK; ++k) {
        sy_mat4 m;
        path_view(&home, k, &m);
        double s;
        r = bench_win_frame(&plain, &m, scene, pool, 1, 0, &img[0], &s, err);
        if (r == SY_OK) r = bench_win_frame(&plain, &m, scene, pool, 1, 1000 + k, &img[1], &s, err);
        if (r == SY_OK) r = bench_win_frame(&temporal, &m, scene, pool, 1, 0, &img[2], &s, err);
        if (r == SY_OK) r = bench_win_frame(&ref, &m, scene, pool, ref_spp, 77, &img[3], &s, err);
        if (r != SY_OK) break;
        t_ref += s;
        double ek[SERIES];
        for (int q = 0; q < SERIES; ++q) ek[q] = rel_mse(img[q].rgba, img[3].rgba, n);
        for (size_t i = 0; i < 4 * n; ++i) nonfinite += !isfinite(img[2].rgba[i]);
        if (k > 0) { /* the first frame has no history */
            for (int q = 0; q < SERIES; ++q) e[q] += ek[q];
            counted++;
            for (size_t i = 0; i < n; ++i) {
                double lr = lum(img[3].rgba + 4 * i), lr0 = lum(prev[3] + 4 * i);
                if (!(fabs(lr - lr0) <= 0.01 * lr + 0.002)) continue; /* the true value changed */
                for (int q = 0; q < SERIES; ++q) fl[q] += fabs(lum(img[q].rgba + 4 * i) - lum(prev[q] + 4 * i));
                f_count++;
            }
        }
        if (k % 10 == 0 || k + 1 == frames) {
            printf("  %5u  %12.5f  %6.5f  %8.5f\n", k, ek[0], ek[1], ek[2]);
            fflush(stdout);
        }
        if (png_prefix && k == frames / 2) { /* the middle frame of each series */
            char path[1100];
            for (int q = 0; q <= SERIES && r == SY_OK; ++q) {
                snprintf(path, sizeof path, "%s_%s.png", png_prefix, names[q]);
                r = sy_png_write(path, (int)width, (int)height, img[q].rgba, NULL, err); /* the display tone map */
            }
        }
        for (int q = 0; q <= SERIES; ++q) memcpy(prev[q], img[q].rgba, 4 * n * sizeof(float));
    }
    sy_mediator_rt_filter_info fi = {0};
    if (r == SY_OK && counted) {
        for (int q = 0; q < SERIES; ++q) e[q] /= counted, fl[q] /= (double)(f_count ? f_count : 1);
        printf("  mean relMSE (frames 1..%u): plain %.5f, fresh %.5f, temporal %.5f: %.1fx lower than plain, %.1fx "
               "than fresh\n",
               frames - 1, e[0], e[1], e[2], e[0] / e[2], e[1] / e[2]);
        printf("  flicker (mean |change| of luminance on the %.1f %% of pixels whose reference changes < 1 %% + 0.002): "
               "plain %.5f, fresh %.5f, temporal %.5f: %.1fx lower than plain, %.1fx than fresh\n",
               100.0 * (double)f_count / ((double)n * counted), fl[0], fl[1], fl[2], fl[0] / fl[2], fl[1] / fl[2]);
        printf("  temporal: %u non-finite values; reference %.1f s per view\n", nonfinite, t_ref / frames);
    }
    /* the camera stops at the path's last view (sy_filter_temporal_rest): the change of the display at
     * the stop (the first still frame against the last moving one) and after it, against the flicker
     * while moving and against what the plain accumulation (2 samples) would have shown */
    if (r == SY_OK && counted) {
        sy_context *tc = NULL;
        sy_params tp0 = {0};
        r = sy_params_parse("temporal=1", &tp0, err);
        if (r == SY_OK) r = sy_context_pool_get(pool, scene, "pathtracer", &tp0, vd->root.id, &tc, err);
        sy_mat4 m;
        path_view(&home, frames - 1, &m);
        double stop = 0, stop_plain = 0, later = 0, s;
        for (uint32_t k = 0; k < 8 && r == SY_OK; ++k) {
            r = bench_win_frame(&temporal, &m, scene, pool, 1, 0, &img[2], &s, err);
            if (r != SY_OK) break;
            double ch = 0;
            for (size_t i = 0; i < n; ++i) ch += fabs(lum(img[2].rgba + 4 * i) - lum(prev[2] + 4 * i));
            ch /= (double)n;
            if (k == 0) {
                stop = ch;
                sy_mediator_rt_aovs acc = {0};
                r = sy_mediator_rt_aovs_get(sy_context_state(tc), &acc, err);
                for (size_t i = 0; r == SY_OK && i < n; ++i)
                    stop_plain += fabs(lum(acc.planes[0] + 4 * i) - lum(prev[2] + 4 * i));
                stop_plain /= (double)n;
                sy_mediator_rt_aovs_free(&acc);
            } else {
                later = fmax(later, ch);
            }
            memcpy(prev[2], img[2].rgba, 4 * n * sizeof(float));
        }
        if (r == SY_OK)
            printf("  camera stops (8 still frames of 1 spp at the last view; mean |change| of luminance, all "
                   "pixels): at the stop %.5f (the plain 2-spp accumulation would jump %.5f), largest after it "
                   "%.5f; flicker while moving %.5f\n",
                   stop, stop_plain, later, fl[2]);
    }
    sy_layer a = {0};
    /* cost at 640x360: the temporal stage of cost_frames moving frames (median; its parts: the feature
     * buffers' read, the filter's phases), and one 1-spp pass */
    uint32_t cn = cost_frames < 1 ? 1 : cost_frames > 12 ? 12 : cost_frames, mid = cn / 2;
    sy_context *ctx = NULL;
    if (r == SY_OK) r = bench_win_make(vd, "temporal=1", 640, 360, &cost, err);
    sy_params tp = {0};
    if (r == SY_OK) r = sy_params_parse("temporal=1", &tp, err);
    if (r == SY_OK) r = sy_context_pool_get(pool, scene, "pathtracer", &tp, vd->root.id, &ctx, err);
    /* per frame: the stage, the frame without it, the filter's CPU time, the read, the filter's phases */
    enum { C_STAGE, C_FRAME, C_CPU, C_READ, C_PHASE, C_COUNT = C_PHASE + 4 };
    double cs[C_COUNT][12];
    for (uint32_t k = 0; k <= cn && r == SY_OK; ++k) {
        sy_mat4 m;
        path_view(&home, k, &m);
        double s;
        r = bench_win_frame(&cost, &m, scene, pool, 1, 0, &a, &s, err);
        if (r == SY_OK && k > 0) {
            sy_mediator_rt_filter_info_get(sy_context_state(ctx), &fi);
            cs[C_STAGE][k - 1] = fi.temporal_seconds, cs[C_FRAME][k - 1] = s - fi.temporal_seconds;
            cs[C_CPU][k - 1] = fi.temporal_filter_cpu_seconds, cs[C_READ][k - 1] = fi.temporal_read_seconds;
            for (int q = 0; q < 4; ++q) cs[C_PHASE + q][k - 1] = fi.temporal_phase_seconds[q];
        }
    }
    if (r == SY_OK) {
        for (int q = 0; q < C_COUNT; ++q) qsort(cs[q], cn, sizeof cs[q][0], sy_bench_cmp_double);
        printf("  cost at 640x360: temporal stage %.1f ms per frame (median of %u; AOV read + reprojection + "
               "a-trous), the 1-spp frame without it %.1f ms: %.2fx; the filter's CPU time %.1f ms (all threads); "
               "reused history on %.0f %% of the hits\n",
               cs[C_STAGE][mid] * 1e3, cn, cs[C_FRAME][mid] * 1e3, cs[C_STAGE][mid] / cs[C_FRAME][mid],
               cs[C_CPU][mid] * 1e3, 100.0 * fi.temporal_reused);
        printf("  its parts (medians, wall ms): feature buffers read %.1f; filter: planes %.1f, reprojection and "
               "blend %.1f, a-trous %.1f, output %.1f\n",
               cs[C_READ][mid] * 1e3, cs[C_PHASE][mid] * 1e3, cs[C_PHASE + 1][mid] * 1e3, cs[C_PHASE + 2][mid] * 1e3,
               cs[C_PHASE + 3][mid] * 1e3);
    }
    /* object motion at 640x360: the camera still at the path's start, every node under the viewport's
     * root with a mesh (and no light or camera: a moved light is not a move) sliding sideways by 0.2 %
     * of the orbit distance per frame (every instance moves), cost_frames frames: the object motion
     * pass (coverage rays + per-pixel motion) against the rest of the temporal stage (AOV read,
     * reprojection, a-trous) */
    uint32_t nkids = 0;
    uint32_t *kids = NULL;
    if (r == SY_OK) r = moving_nodes(scene, vd->root, &kids, &nkids, err);
    sy_mat4 *saved = nkids ? malloc(nkids * sizeof *saved) : NULL;
    if (r == SY_OK && nkids && !saved) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench temporal: out of memory");
    for (uint32_t i = 0; saved && i < nkids; ++i) saved[i] = sy_node_get(scene, (sy_node){kids[i]})->transform.matrix;
    double om[12] = {0}, os[12] = {0}, ot[12] = {0};
    uint64_t moving = 0;
    for (uint32_t k = 0; k <= cn && r == SY_OK && saved; ++k) {
        for (uint32_t i = 0; i < nkids && r == SY_OK; ++i) {
            sy_mat4 m = saved[i];
            m.m[12] += 0.002f * home.orbit.dist * (float)k;
            r = sy_node_set_matrix(scene, (sy_node){kids[i]}, &m, err);
        }
        if (r == SY_OK) r = motion_frame(&cost, &home, scene, pool, ctx, k, &a, &fi, om, os, ot, err);
        moving = fi.temporal_moving_pixels;
    }
    if (saved) { /* the scene as it was */
        for (uint32_t i = 0; i < nkids; ++i) (void)sy_node_set_matrix(scene, (sy_node){kids[i]}, &saved[i], NULL);
        (void)sy_scene_commit(scene, NULL, NULL);
        if (r == SY_OK) {
            sort3(cn, om, os, ot);
            printf("  object motion at 640x360 (still camera, every instance sliding): motion pass %.2f ms per frame "
                   "(median of %u; coverage rays + per-pixel motion, of it the per-pixel motion %.2f ms), the rest of "
                   "the temporal stage %.1f ms: %.2fx; %llu moving pixels\n",
                   om[mid] * 1e3, cn, ot[mid] * 1e3, os[mid] * 1e3, om[mid] / os[mid], (unsigned long long)moving);
        }
        free(saved);
    }
    free(kids);
    /* deforming meshes at 640x360: a scene with an animation plays it (every clip, 1/24 s per frame)
     * under the still camera, cost_frames frames: the object motion pass with per-vertex motion (coverage
     * rays with triangles and barycentrics + the hit at the earlier pose) against the rest of the
     * stage and against the rigid pass above (same run, same view) */
    double dm[12], ds[12], dt[12];
    uint64_t dpx = 0, dmov = 0;
    bool animated = false;
    for (uint32_t k = 0; k <= cn && r == SY_OK; ++k) {
        sy_anim_stats as = {0};
        r = sy_scene_set_time_ex(scene, (sy_animation){0}, (double)k / 24.0, &as, err);
        if (r != SY_OK || (k == 0 && as.channels == 0 && as.weights == 0)) break;
        animated = true;
        r = motion_frame(&cost, &home, scene, pool, ctx, k, &a, &fi, dm, ds, dt, err);
        dpx = fi.temporal_deformed_pixels, dmov = fi.temporal_moving_pixels;
    }
    if (r == SY_OK && animated) {
        sort3(cn, dm, ds, dt);
        printf("  animation at 640x360 (still camera, every clip at 24 fps): motion pass %.2f ms per frame (median of "
               "%u; per-vertex motion on %llu deformed pixels of %llu moving; of it the per-pixel motion %.2f ms), the "
               "rest of the temporal stage %.1f ms: %.2fx; the rigid pass above %.2f ms: %.2fx of it\n",
               dm[mid] * 1e3, cn, (unsigned long long)dpx, (unsigned long long)dmov, dt[mid] * 1e3, ds[mid] * 1e3,
               dm[mid] / ds[mid], om[mid] * 1e3, om[mid] > 0 ? dm[mid] / om[mid] : 0.0);
    }
    for (int q = 0; q <= SERIES; ++q) free(prev[q]), sy_layer_destroy(&img[q]);
    sy_layer_destroy(&a);
    sy_context_pool_destroy(pool);
    sy_window_destroy(plain.win), sy_window_destroy(temporal.win), sy_window_destroy(ref.win), sy_window_destroy(cost.win);
    return r;
#endif
}
