/* sy_bench_filters.c — `sy bench filters` (issue 7): the noise-reduction filters of
 * backends/filters on the analytic surrogate (sy_bench_filters) and on the path tracer's buffers
 * against a reference EXR (sy_bench_filters_scene); see sy_bench.h. */
#include "sy_backend_status.h"
#include "sy_bench.h"

#include "sy_demo.h"
#ifdef SY_HAVE_EMBREE
#include "sy_mediator_rt.h"
#endif

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* ---- sy bench filters (issue 7): noise-reduction filters of backends/filters ---------------- */
#include "sy_filter_adaptive.h"
#include "sy_filter_atrous.h"
#include "sy_filter_jbu.h"
#include "sy_filter_metrics.h"
#include "sy_filter_pixel.h"
#include "sy_filter_radiance.h"
#include "sy_filter_synth.h"
#include "sy_png.h"

#include <time.h>

static double fb_cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

enum { FB_NONE, FB_PIXEL, FB_PIXEL_BRUTE, FB_RADIANCE, FB_ATROUS, FB_JBU, FB_ADAPTIVE, FB_COUNT };
static const char *const fb_names[FB_COUNT] = {"none", "pixel", "pixel-brute", "radiance", "atrous", "jbu", "adaptive"};

static sy_result fb_fail(sy_error *err, const sy_filter_report *fe, const char *what)
{
    return sy_backend_fail(err, (int)fe->code, "bench filters", what, fe->message);
}

/* One row of a table: sample count k, the method, its error against ref (relMSE, and relMSE without
 * a filter over it: the row of FB_NONE, first, sets *base_rel) and its time in ms. */
static sy_result fb_row(uint32_t k, int m, const float *img, const float *ref, uint32_t width, uint32_t height,
                        double ms, double *base_rel, sy_error *err)
{
    sy_filter_report fe = {0};
    sy_filter_metrics mt;
    if (sy_filter_metrics_compute(img, ref, width, height, 4, &mt, &fe)) return fb_fail(err, &fe, "metrics");
    if (m == FB_NONE) *base_rel = mt.relmse;
    printf("  %5u %-12s %9.5f %9.5f %7.4f %9.2fx %9.1f\n", k, fb_names[m], mt.rmse, mt.relmse, mt.ssim,
           mt.relmse > 0 ? *base_rel / mt.relmse : 0.0, ms);
    return SY_OK;
}

/* one filter application; pixel filters: a forced pass of *keep (created on first use, as a
 * viewport keeps its filter object between frames) */
static sy_filter_status fb_apply(int m, const sy_filter_frame *f, uint32_t threads, float *out, sy_filter_pixel **keep,
                                 sy_filter_report *fe)
{
    sy_filter_status s = SY_FILTER_OK;
    if (m == FB_PIXEL || m == FB_PIXEL_BRUTE) {
        sy_filter_pixel_params p;
        sy_filter_pixel_params_default(&p);
        p.threads = threads;
        if (m == FB_PIXEL_BRUTE) p.kernel = SY_FILTER_PIXEL_BRUTE, p.aa_recovery = false;
        if (!*keep) s = sy_filter_pixel_create(&p, keep, fe);
        if (!s) s = sy_filter_pixel_set_params(*keep, &p, fe);
        if (!s) s = sy_filter_pixel_run(*keep, f, (uint32_t)f->spp_uniform, true, out, NULL, fe);
    } else if (m == FB_ATROUS) {
        sy_filter_atrous_params p;
        sy_filter_atrous_params_default(&p);
        p.threads = threads;
        s = sy_filter_atrous(&p, f, out, NULL, fe);
    } else if (m == FB_JBU) {
        sy_filter_jbu_params p;
        sy_filter_jbu_params_default(&p);
        p.threads = threads;
        s = sy_filter_jbu(&p, f, out, NULL, fe);
    } else if (m == FB_ADAPTIVE) {
        sy_filter_adaptive_params p;
        sy_filter_adaptive_params_default(&p);
        p.threads = threads;
        s = sy_filter_adaptive(&p, f, out, NULL, NULL, fe);
    } else {
        size_t n = (size_t)f->width * f->height;
        for (size_t i = 0; i < n; ++i)
            for (int c = 0; c < 4; ++c) out[4 * i + c] = c < 3 ? f->color[4 * i + c] : 1.0f;
    }
    return s;
}

static double fb_median(double *v, uint32_t n)
{
    qsort(v, n, sizeof *v, sy_bench_cmp_double);
    return v[n / 2];
}

/* Writes the contact sheet (rows: 1, 4, 16, 64, 256 spp) and says so: lead, then the line naming
 * the columns. */
static sy_result fb_sheet_write(const char *path, const float *sheet, size_t w, size_t h, const char *lead,
                                const char *columns, sy_error *err)
{
    sy_result r = sy_png_write(path, (int)w, (int)h, sheet, NULL, err);
    if (r == SY_OK) printf("%scontact sheet %s: rows = spp 1, 4, 16, 64, 256; columns = %s\n", lead, path, columns);
    return r;
}

/* Median wall time of one 1-spp path-tracing pass of the built-in demo scene at width x height (after
 * a warm-up pass that includes the translation): the yardstick the pixel filter's cost is given in. */
static sy_result fb_pt_pass(uint32_t width, uint32_t height, uint32_t repeats, double *secs, sy_error *err)
{
#ifndef SY_HAVE_EMBREE
    (void)width, (void)height, (void)repeats, (void)secs;
    SY_BENCH_WITHOUT(err, "filters (a path-traced pass)", "SY_WITH_EMBREE");
#else
    sy_scene *s = NULL;
    sy_demo_info demo;
    sy_window *win = NULL;
    sy_viewport *vp = NULL;
    sy_context_pool *pool = NULL;
    sy_layer img = {0};
    double *t = calloc(repeats, sizeof *t), warm;
    sy_result r = t ? sy_scene_create(&s, err) : sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench filters: out of memory");
    if (r == SY_OK) r = sy_demo_build(s, &demo, err);
    if (r == SY_OK) r = sy_scene_commit(s, NULL, err);
    sy_viewport_desc vd = {.root = demo.root, .camera = demo.camera, .background = demo.background,
                           .backend = "pathtracer"};
    if (r == SY_OK) r = sy_window_create(width, height, &win, err);
    if (r == SY_OK) r = sy_window_add_viewport(win, &vd, &vp, err);
    if (r == SY_OK) r = sy_context_pool_create(&pool, err);
    if (r == SY_OK) r = sy_layer_create(width, height, &img, err);
    if (r == SY_OK) r = sy_bench_frame(win, s, pool, 1, &img, &warm, err);
    for (uint32_t i = 0; i < repeats && r == SY_OK; ++i) r = sy_bench_frame(win, s, pool, 1, &img, &t[i], err);
    if (r == SY_OK) {
        qsort(t, repeats, sizeof *t, sy_bench_cmp_double);
        *secs = t[repeats / 2];
    }
    sy_layer_destroy(&img);
    sy_context_pool_destroy(pool);
    sy_window_destroy(win);
    sy_scene_destroy(s);
    free(t);
    return r;
#endif
}

sy_result sy_bench_filters(uint32_t width, uint32_t height, uint32_t repeats, const char *png_path, sy_error *err)
{
    sy_filter_report fe = {0};
    sy_filter_synth *syn = NULL;
    if (sy_filter_synth_create(width, height, 12345, &syn, &fe)) return fb_fail(err, &fe, "surrogate");
    size_t n = (size_t)width * height;
    float *out = malloc(4 * n * sizeof(float));
    double *t = calloc(repeats, sizeof *t);
    sy_result r = out && t ? SY_OK : sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench filters: out of memory");
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    printf("sy bench filters: analytic render surrogate (two Lambertian planes, depth step, checker texture, smooth\n"
           "indirect light with a shadow edge, Exp(1) path noise), %ux%u, %ld cores\n\n", width, height, cores);
    /* 1. cost per filtered frame at 4 spp (median of repeats; all cores, then one thread) */
    for (int k = 0; k < 4 && r == SY_OK; ++k) sy_filter_synth_step(syn);
    sy_filter_frame f = sy_filter_synth_frame(syn);
    printf("filter time per frame at 4 spp (median of %u; wall time, and the CPU time the process used, which\n"
           "does not grow when other processes load the machine):\n", repeats);
    printf("  %-12s %12s %12s %12s %9s\n", "method", "all cores ms", "CPU ms", "1 thread ms", "speed-up");
    double t_pixel = 0;
    for (int m = FB_PIXEL; m < FB_COUNT && r == SY_OK; ++m) {
        double med[2] = {0, 0}, cpu = 0;
        for (int th = 0; th < 2 && r == SY_OK; ++th) {
            uint32_t reps = m == FB_PIXEL_BRUTE ? 1 : repeats;
            sy_filter_pixel *keep = NULL;
            if ((m == FB_PIXEL || m == FB_PIXEL_BRUTE) && fb_apply(m, &f, th ? 1 : 0, out, &keep, &fe)) /* warm-up */
                r = fb_fail(err, &fe, fb_names[m]);
            double c0 = fb_cpu_now();
            for (uint32_t i = 0; i < reps && r == SY_OK; ++i) {
                double a = sy_time_now();
                if (m == FB_RADIANCE) {
                    sy_filter_radiance_params p;
                    sy_filter_radiance_params_default(&p);
                    p.threads = th ? 1 : 0;
                    p.warmup_frames = 0; /* the variance-driven radius of frame 4 */
                    sy_filter_radiance *rf = NULL;
                    sy_filter_radiance_input in = sy_filter_synth_rf_input(syn);
                    if (sy_filter_radiance_create(&p, &rf, &fe) ||
                        sy_filter_radiance_frame(rf, &in, out, NULL, &fe))
                        r = fb_fail(err, &fe, fb_names[m]);
                    sy_filter_radiance_destroy(rf);
                } else if (fb_apply(m, &f, th ? 1 : 0, out, &keep, &fe))
                    r = fb_fail(err, &fe, fb_names[m]);
                t[i] = sy_time_now() - a;
            }
            if (th == 0) cpu = (fb_cpu_now() - c0) / reps;
            sy_filter_pixel_destroy(keep);
            med[th] = fb_median(t, reps);
        }
        if (m == FB_PIXEL) t_pixel = med[0];
        printf("  %-12s %12.2f %12.2f %12.2f %8.2fx\n", fb_names[m], med[0] * 1e3, cpu * 1e3, med[1] * 1e3,
               med[1] / med[0]);
    }
    if (r == SY_OK)
        printf("  fast pixel filter: %.1f ms per filtered frame (target < 50 ms at 640x480 on 2 cores;\n"
               "  on an otherwise idle machine wall time ~ CPU ms / cores)\n", t_pixel * 1e3);
    double pt_pass = 0;
    if (r == SY_OK) r = fb_pt_pass(width, height, repeats, &pt_pass, err);
    if (r == SY_OK)
        printf("  path tracing (demo scene, %ux%u, all cores): %.1f ms per 1-spp pass (median of %u);\n"
               "  fast pixel filter = %.2f x one path-tracing pass at 1 spp\n\n", width, height, pt_pass * 1e3,
               repeats, t_pixel / pt_pass);
    /* 2. quality against the converged image, progressive: every method sees the same samples */
    static const uint32_t spps[] = {1, 4, 16, 64, 256};
    enum { NS = sizeof spps / sizeof spps[0] };
    uint32_t scale = (width + 319) / 320, tw = width / scale, th = height / scale;
    size_t sheet_w = (size_t)tw * (FB_COUNT + 1), sheet_h = (size_t)th * NS;
    float *sheet = png_path ? calloc(sheet_w * sheet_h * 4, sizeof(float)) : NULL;
    if (png_path && !sheet && r == SY_OK) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench filters: out of memory");
    sy_filter_pixel *pf = NULL;
    sy_filter_radiance *rf = NULL;
    sy_filter_pixel_params pp;
    sy_filter_pixel_params_default(&pp);
    pp.schedule_start = 1; /* filter frames 1, 2, 4, 8, ...: every checkpoint below is a filter frame */
    float *rf_out = malloc(4 * n * sizeof(float)), *pix_out = malloc(4 * n * sizeof(float));
    if (r == SY_OK && (!rf_out || !pix_out)) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench filters: out of memory");
    if (r == SY_OK && (sy_filter_pixel_create(&pp, &pf, &fe) || sy_filter_radiance_create(NULL, &rf, &fe)))
        r = fb_fail(err, &fe, "create");
    const float *ref = sy_filter_synth_reference(syn);
    if (r == SY_OK) {
        printf("quality against the converged image (RMSE / relMSE / SSIM; pixel: 2^i schedule from frame 1;\n"
               "radiance: filtered every frame; others applied at the checkpoint):\n");
        printf("  %5s %-12s %9s %9s %7s %10s %9s\n", "spp", "method", "RMSE", "relMSE", "SSIM", "relMSE/PT", "ms");
    }
    sy_filter_synth_reset(syn);
    uint32_t si = 0;
    double rf_ms = 0, px_ms = 0;
    for (uint32_t k = 1; k <= spps[NS - 1] && r == SY_OK; ++k) {
        sy_filter_synth_step(syn);
        f = sy_filter_synth_frame(syn);
        sy_filter_radiance_input in = sy_filter_synth_rf_input(syn);
        sy_filter_stats st;
        if (sy_filter_radiance_frame(rf, &in, rf_out, &st, &fe)) {
            r = fb_fail(err, &fe, "radiance");
            break;
        }
        rf_ms = st.seconds * 1e3;
        if (sy_filter_pixel_run(pf, &f, k, false, pix_out, &st, &fe)) {
            r = fb_fail(err, &fe, "pixel");
            break;
        }
        px_ms = st.seconds * 1e3;
        if (k != spps[si]) continue;
        double base_rel = 0;
        for (int m = 0; m < FB_COUNT && r == SY_OK; ++m) {
            const float *img = out;
            double ms = 0;
            if (m == FB_RADIANCE) img = rf_out, ms = rf_ms;
            else if (m == FB_PIXEL) img = pix_out, ms = px_ms;
            else {
                double a = sy_time_now();
                if (m == FB_PIXEL_BRUTE && width * height > 400000u) continue;
                sy_filter_pixel *once = NULL;
                if (fb_apply(m, &f, 0, out, &once, &fe)) r = fb_fail(err, &fe, fb_names[m]);
                sy_filter_pixel_destroy(once);
                ms = (sy_time_now() - a) * 1e3;
            }
            if (r == SY_OK) r = fb_row(k, m, img, ref, width, height, ms, &base_rel, err);
            if (r != SY_OK) break;
            for (uint32_t y = 0; sheet && y < th; ++y) /* tile: box-downscaled image */
                for (uint32_t x = 0; x < tw; ++x)
                    for (int c = 0; c < 4; ++c) {
                        double acc = 0;
                        for (uint32_t dy = 0; dy < scale; ++dy)
                            for (uint32_t dx = 0; dx < scale; ++dx)
                                acc += img[4 * ((size_t)(y * scale + dy) * width + x * scale + dx) + c];
                        sheet[4 * ((si * (size_t)th + y) * sheet_w + (size_t)m * tw + x) + c] =
                            c == 3 ? 1.0f : (float)(acc / (scale * scale));
                    }
        }
        for (uint32_t y = 0; sheet && y < th; ++y)
            for (uint32_t x = 0; x < tw; ++x)
                for (int c = 0; c < 4; ++c)
                    sheet[4 * ((si * (size_t)th + y) * sheet_w + (size_t)FB_COUNT * tw + x) + c] =
                        ref[4 * ((size_t)(y * scale) * width + x * scale) + c];
        ++si;
    }
    if (r == SY_OK && sheet)
        r = fb_sheet_write(png_path, sheet, sheet_w, sheet_h, "\n",
                           "none, pixel, pixel-brute (blank above\n400k pixels), radiance, atrous, jbu, adaptive, reference",
                           err);
    sy_filter_pixel_destroy(pf);
    sy_filter_radiance_destroy(rf);
    free(rf_out), free(pix_out), free(sheet), free(out), free(t);
    sy_filter_synth_destroy(syn);
    return r;
}

/* ---- sy bench filters SCENE: the same comparison on the path tracer's real buffers ---------- */
#include "sy_exr.h"

sy_result sy_bench_filters_scene(sy_scene *scene, const sy_viewport_desc *vd, const char *label, uint32_t width,
                                 uint32_t height, const char *reference_exr, const char *png_path, sy_error *err)
{
#ifndef SY_HAVE_EMBREE
    (void)scene, (void)vd, (void)label, (void)width, (void)height, (void)reference_exr, (void)png_path;
    SY_BENCH_WITHOUT(err, "filters on a scene (pathtracer)", "SY_WITH_EMBREE");
#else
    sy_filter_report fe = {0};
    sy_exr_image *refimg = NULL;
    sy_window *win = NULL;
    sy_viewport *vp = NULL;
    sy_context_pool *pool = NULL;
    sy_layer img = {0}, img_rf = {0};
    sy_viewport_desc dp = *vd, dp_rf;
    dp.backend = "pathtracer";
    /* radiance filtering is no display filter: it needs the path tracer's stored-sample hook, so it
     * runs in its own viewport (filter=radiance), on the same samples (same seed, deterministic) */
    char rf_params[512];
    snprintf(rf_params, sizeof rf_params, "%s%sfilter=radiance", vd->params ? vd->params : "",
             vd->params && *vd->params ? "," : "");
    dp_rf = dp;
    dp_rf.params = rf_params;
    sy_window *win_rf = NULL;
    sy_viewport *vp_rf = NULL;
    size_t n = (size_t)width * height;
    float *ref = malloc(4 * n * sizeof(float)), *out = malloc(4 * n * sizeof(float)), *pos = malloc(3 * n * sizeof(float));
    float *pix_out = malloc(4 * n * sizeof(float));
    sy_result r = ref && out && pos && pix_out ? SY_OK : sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench filters: out of memory");
    if (r == SY_OK) r = sy_exr_read(reference_exr, &refimg, err);
    if (r == SY_OK && (refimg->width != (int)width || refimg->height != (int)height))
        r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "bench filters: reference %s is %dx%d, the render %ux%u",
                         reference_exr, refimg->width, refimg->height, width, height);
    const float *rc[3] = {NULL, NULL, NULL};
    if (r == SY_OK) {
        rc[0] = sy_exr_image_channel(refimg, "R"), rc[1] = sy_exr_image_channel(refimg, "G");
        rc[2] = sy_exr_image_channel(refimg, "B");
        if (!rc[0] || !rc[1] || !rc[2])
            r = sy_error_set(err, SY_ERR_PARSE, "bench filters: reference %s has no R, G, B channels", reference_exr);
    }
    for (size_t i = 0; r == SY_OK && i < n; ++i)
        for (int c = 0; c < 4; ++c) ref[4 * i + c] = c < 3 ? rc[c][i] : 1.0f;
    /* camera: world matrix and vertical field of view, for positions and the headlight */
    float m[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}, yfov = 0.0f;
    if (r == SY_OK && vd->camera.id) {
        sy_mat4 w;
        const sy_node_data *nd = sy_node_get(scene, vd->camera);
        const sy_camera_data *cd = nd && nd->camera.id ? sy_camera_get(scene, nd->camera) : NULL;
        if (cd && cd->yfov > 0.0f && sy_node_world_matrix(scene, vd->camera, &w, err) == SY_OK) {
            memcpy(m, w.m, sizeof m);
            yfov = cd->yfov;
        }
    }
    if (r == SY_OK && yfov <= 0.0f)
        r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "bench filters: %s needs a perspective camera node", label);
    if (r == SY_OK) r = sy_window_create(width, height, &win, err);
    if (r == SY_OK) r = sy_window_add_viewport(win, &dp, &vp, err);
    if (r == SY_OK) r = sy_window_create(width, height, &win_rf, err);
    if (r == SY_OK) r = sy_window_add_viewport(win_rf, &dp_rf, &vp_rf, err);
    if (r == SY_OK) r = sy_context_pool_create(&pool, err);
    if (r == SY_OK) r = sy_layer_create(width, height, &img, err);
    if (r == SY_OK) r = sy_layer_create(width, height, &img_rf, err);
    sy_filter_pixel *pf = NULL;
    sy_filter_pixel_params pp;
    sy_filter_pixel_params_default(&pp);
    pp.schedule_start = 1;
    if (r == SY_OK && sy_filter_pixel_create(&pp, &pf, &fe)) r = fb_fail(err, &fe, "pixel");
    static const uint32_t spps[] = {1, 4, 16, 64, 256};
    enum { NS = sizeof spps / sizeof spps[0] };
    uint32_t methods[] = {FB_NONE, FB_PIXEL, FB_PIXEL_BRUTE, FB_RADIANCE, FB_ATROUS, FB_JBU, FB_ADAPTIVE};
    enum { NM = sizeof methods / sizeof methods[0] };
    size_t sheet_w = (size_t)width * (NM + 1), sheet_h = (size_t)height * NS;
    float *sheet = png_path && r == SY_OK ? calloc(sheet_w * sheet_h * 4, sizeof(float)) : NULL;
    if (r == SY_OK && png_path && !sheet) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench filters: out of memory");
    if (r == SY_OK) {
        printf("%s, %ux%u, path tracer buffers against %s (radiance: the path tracer's stored-sample\n"
               "hook, filtered every 1-spp pass, same samples; pixel: 2^i schedule from frame 1):\n", label, width,
               height, reference_exr);
        printf("  %5s %-12s %9s %9s %7s %10s %9s\n", "spp", "method", "RMSE", "relMSE", "SSIM", "relMSE/PT", "ms");
    }
    sy_context *ctx = NULL, *ctx_rf = NULL;
    sy_params none = {0}, rfp = {0};
    if (r == SY_OK) r = sy_params_parse(rf_params, &rfp, err);
    double pass_s = 0, t_pixel_ms = 0, rf_pass_s = 0, t_rf_ms = 0;
    uint32_t si = 0;
    for (uint32_t k = 1; k <= spps[NS - 1] && r == SY_OK; ++k) {
        double s;
        r = sy_bench_frame(win, scene, pool, 1, &img, &s, err);
        pass_s += s;
        if (r == SY_OK && !ctx) r = sy_context_pool_get(pool, scene, "pathtracer", &none, vd->root.id, &ctx, err);
        if (r == SY_OK) r = sy_bench_frame(win_rf, scene, pool, 1, &img_rf, &s, err); /* pass + radiance frame */
        rf_pass_s += s;
        if (r == SY_OK && !ctx_rf) r = sy_context_pool_get(pool, scene, "pathtracer", &rfp, vd->root.id, &ctx_rf, err);
        sy_mediator_rt_filter_info rfi = {0};
        if (r == SY_OK) sy_mediator_rt_filter_info_get(sy_context_state(ctx_rf), &rfi);
        if (r == SY_OK && k == 4) t_rf_ms = rfi.seconds * 1e3;
        sy_mediator_rt_aovs a = {0};
        if (r == SY_OK) r = sy_mediator_rt_aovs_get(sy_context_state(ctx), &a, err);
        if (r == SY_OK && (a.width != width || a.height != height))
            r = sy_error_set(err, SY_ERR_BACKEND, "bench filters: feature buffers are %ux%u, expected %ux%u", a.width,
                             a.height, width, height);
        if (r == SY_OK && sy_filter_position_from_depth(width, height, m, yfov, a.planes[4], pos, &fe))
            r = fb_fail(err, &fe, "positions");
        sy_filter_frame f = {.width = width, .height = height, .color_channels = 4, .variance_channels = 3,
                             .color = a.planes[0], .variance = a.planes[1], .albedo = a.planes[2],
                             .normal = a.planes[3], .depth = a.planes[4], .position = pos, .direct = a.planes[5],
                             .indirect = a.planes[6], .spp_uniform = (float)(a.samples ? a.samples : k), .has_camera = true,
                             .camera_position = {m[12], m[13], m[14]}};
        sy_filter_stats st;
        if (r == SY_OK && sy_filter_pixel_run(pf, &f, k, false, pix_out, &st, &fe)) r = fb_fail(err, &fe, "pixel");
        if (r == SY_OK && st.filter_pass && k == 4) t_pixel_ms = st.seconds * 1e3; /* the 4-spp pass */
        if (r == SY_OK && k == spps[si]) {
            double base_rel = 0;
            for (int mi = 0; mi < NM && r == SY_OK; ++mi) {
                int meth = (int)methods[mi];
                const float *im = out;
                double ms = meth == FB_PIXEL ? st.seconds * 1e3 : meth == FB_RADIANCE ? rfi.seconds * 1e3 : 0;
                if (meth == FB_PIXEL)
                    im = pix_out;
                else if (meth == FB_RADIANCE)
                    im = img_rf.rgba;
                else {
                    sy_filter_pixel *once = NULL;
                    double t0 = sy_time_now();
                    if (fb_apply(meth, &f, 0, out, &once, &fe)) r = fb_fail(err, &fe, fb_names[meth]);
                    ms = (sy_time_now() - t0) * 1e3;
                    sy_filter_pixel_destroy(once);
                }
                if (r == SY_OK) r = fb_row(k, meth, im, ref, width, height, ms, &base_rel, err);
                if (r != SY_OK) break;
                for (uint32_t y = 0; sheet && y < height; ++y)
                    for (uint32_t x = 0; x < width; ++x) { /* opaque: uncovered background shows black */
                        float *d = sheet + 4 * ((si * (size_t)height + y) * sheet_w + (size_t)mi * width + x);
                        const float *sp = im + 4 * ((size_t)y * width + x);
                        d[0] = sp[0], d[1] = sp[1], d[2] = sp[2], d[3] = 1.0f;
                    }
            }
            for (uint32_t y = 0; sheet && y < height; ++y)
                memcpy(sheet + 4 * ((si * (size_t)height + y) * sheet_w + (size_t)NM * width), ref + 4 * (size_t)y * width,
                       4 * width * sizeof(float));
            ++si;
        }
        sy_mediator_rt_aovs_free(&a);
    }
    if (r == SY_OK) {
        double pass_ms = pass_s / spps[NS - 1] * 1e3;
        printf("  path tracing: %.1f ms per 1-spp pass; fast pixel filter pass at 4 spp %.1f ms = %.2f x one pass\n",
               pass_ms, t_pixel_ms, t_pixel_ms / pass_ms);
        printf("  radiance filtering: %.1f ms per 1-spp pass with records + filter frame (frame 4: filter %.1f ms = "
               "%.2f x one plain pass)\n", rf_pass_s / spps[NS - 1] * 1e3, t_rf_ms, t_rf_ms / pass_ms);
    }
    if (r == SY_OK && sheet)
        r = fb_sheet_write(png_path, sheet, sheet_w, sheet_h, "  ",
                           "none, pixel, pixel-brute, radiance,\n  atrous, jbu, adaptive, reference", err);
    sy_filter_pixel_destroy(pf);
    free(sheet), free(ref), free(out), free(pos), free(pix_out);
    if (refimg) sy_exr_image_free(refimg);
    sy_layer_destroy(&img);
    sy_layer_destroy(&img_rf);
    sy_context_pool_destroy(pool);
    sy_window_destroy(win);
    sy_window_destroy(win_rf);
    return r;
#endif
}
