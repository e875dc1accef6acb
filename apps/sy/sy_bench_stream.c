/* sy_bench_stream.c — `sy bench stream` (issue 36, "a stream that costs less"): sy web's JPEG
 * stream against its video stream (VP8, VP9 through libvpx, apps/web/sy_web_video.h) on a 10 s
 * orbit of 10 degrees per second around the scene camera's target (the scripted orbit):
 * every frame is rendered once through the display chain the server uses (sy_post_display, over
 * black), then encoded and decoded by every setting of each codec (JPEG qualities; libvpx
 * quantizers, one encoder per setting fed every frame in order, as a viewer's is); each decoded
 * frame's SSIM against the float frame (Rec. 709 luma of the display-encoded colour clamped to
 * [0, 1], sy_filter_ssim_gray). Reported per setting: bytes per frame, SSIM mean and minimum,
 * encode time; then the cheapest JPEG whose mean SSIM is >= 0.95 and the cheapest setting of each
 * video codec at least as good, and their ratio of bytes. The depth channel that goes with every
 * moving frame: its bytes and coding time in format 3 (the grid of every fourth pixel, 12-bit, MED
 * prediction, deflate 6: apps/web/sy_web_frame.h) beside format 2's coding (every pixel, row
 * deltas, deflate 1; kept here only for the comparison), and the messages' bytes at the server's
 * defaults. See sy_bench_stream.h. */
#include "sy_bench_stream.h"

#include "sy_filter_metrics.h"
#include "sy_interactive.h"
#include "sy_jpeg.h"
#include "sy_post.h"
#include "sy_web_frame.h"
#include "sy_web_video.h"

#include <zlib.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const int jpeg_q[] = {10, 20, 30, 40, 50, 60, 70, 80, 90, 95};
static const uint32_t video_q[] = {8, 16, 24, 30, 36, 42, 48, 56};
#define NJ (sizeof jpeg_q / sizeof jpeg_q[0])
#define NV (sizeof video_q / sizeof video_q[0])
#define NCFG (NJ + 2 * NV)

typedef struct setting {
    sy_web_codec codec;
    int q;
    sy_web_video_encoder *enc;
    sy_web_video_decoder *dec;
    double bytes, ssim, ssim_min, enc_s;
    uint64_t keys;
} setting;

static void luma_f(const float *rgba, size_t n, float *out)
{
    for (size_t i = 0; i < n; ++i) {
        float c[3];
        for (int k = 0; k < 3; ++k) {
            float x = rgba[4 * i + k];
            c[k] = isfinite(x) ? (x < 0 ? 0 : x > 1 ? 1 : x) : 0;
        }
        out[i] = 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2];
    }
}

/* format 2's depth channel (docs/WEB.md before format 3): every pixel's 16-bit log depth as row
 * deltas, byte planes, deflate level 1; its bytes (0 on failure) */
static size_t format2_depth_bytes(const float *depth, uint32_t w, uint32_t h)
{
    size_t n = (size_t)w * h;
    float lo = INFINITY, hi = 0.0f;
    for (size_t i = 0; i < n; ++i)
        if (isfinite(depth[i]) && depth[i] > 0) lo = fminf(lo, depth[i]), hi = fmaxf(hi, depth[i]);
    if (!(lo <= hi)) lo = hi = 1.0f;
    double span = log((double)hi / lo), k = span > 0 ? 65534.0 / span : 0.0;
    uint8_t *planes = malloc(2 * n);
    uLongf cap = compressBound((uLong)(2 * n));
    uint8_t *z = malloc(cap);
    size_t out = 0;
    if (planes && z) {
        for (uint32_t y = 0; y < h; ++y) {
            uint16_t prev = 0;
            for (uint32_t x = 0; x < w; ++x) {
                size_t i = (size_t)y * w + x;
                uint16_t q = 0;
                if (isfinite(depth[i]) && depth[i] > 0) {
                    double v = 1.0 + floor(log((double)depth[i] / lo) * k + 0.5);
                    q = (uint16_t)(v < 1 ? 1 : v > 65535 ? 65535 : v);
                }
                uint16_t e = (uint16_t)(q - prev);
                prev = q;
                planes[i] = (uint8_t)(e & 0xff), planes[n + i] = (uint8_t)(e >> 8);
            }
        }
        if (compress2(z, &cap, planes, (uLong)(2 * n), 1) == Z_OK) out = cap;
    }
    free(planes);
    free(z);
    return out;
}

/* one setting on one frame: encode, decode, SSIM */
static sy_result run_setting(setting *s, const uint8_t *px, uint32_t w, uint32_t h, const float *ref, float *tmp, sy_error *err)
{
    size_t n = (size_t)w * h;
    double t0 = sy_time_now();
    sy_result r;
    if (s->codec == SY_WEB_CODEC_JPEG) {
        uint8_t *jpeg = NULL, *dec = NULL;
        size_t len = 0;
        uint32_t dw = 0, dh = 0;
        r = sy_jpeg_encode_rgba8(px, w, h, s->q, &jpeg, &len, err);
        s->enc_s += sy_time_now() - t0;
        if (r == SY_OK) r = sy_jpeg_decode_rgba8(jpeg, len, n, &dec, &dw, &dh, err);
        if (r == SY_OK) {
            sy_filter_luma_rgba8(dec, n, tmp);
            s->bytes += (double)len;
        }
        free(jpeg);
        free(dec);
    } else {
        const uint8_t *pkt = NULL, *dec = NULL;
        size_t len = 0;
        bool key = false;
        uint32_t dw = 0, dh = 0;
        r = sy_web_video_encode(s->enc, px, w, h, false, &pkt, &len, &key, err);
        s->enc_s += sy_time_now() - t0;
        if (r == SY_OK) r = sy_web_video_decode(s->dec, pkt, len, &dec, &dw, &dh, err);
        if (r == SY_OK) {
            sy_filter_luma_rgba8(dec, n, tmp);
            s->bytes += (double)len, s->keys += key;
        }
    }
    if (r != SY_OK) return r;
    double v = sy_filter_ssim_gray(ref, tmp, w, h);
    s->ssim += v;
    if (v < s->ssim_min) s->ssim_min = v;
    return SY_OK;
}

/* the cheapest setting of each video codec whose mean SSIM is at least JPEG setting j's */
static void compare(const setting *cfg, uint32_t ncfg, uint32_t frames, int j, const char *what)
{
    double sj = cfg[j].ssim / frames;
    printf("  %s: Q %d, %.0f bytes per frame (SSIM %.4f)\n", what, cfg[j].q, cfg[j].bytes / frames, sj);
    for (int c = SY_WEB_CODEC_VP8; c <= SY_WEB_CODEC_VP9; ++c) {
        int best = -1;
        for (uint32_t i = 0; i < ncfg; ++i)
            if ((int)cfg[i].codec == c && cfg[i].ssim / frames >= sj && (best < 0 || cfg[i].bytes < cfg[best].bytes)) best = (int)i;
        if (best < 0) {
            if (sy_web_codec_available((sy_web_codec)c))
                printf("    %s: no quantizer reaches SSIM %.4f\n", sy_web_codec_name((sy_web_codec)c), sj);
            continue;
        }
        printf("    %s at SSIM >= %.4f: q %d, %.0f bytes per frame (SSIM %.4f, min %.4f): %.3f of JPEG's bytes (1/%.1f)\n",
               sy_web_codec_name((sy_web_codec)c), sj, cfg[best].q, cfg[best].bytes / frames, cfg[best].ssim / frames,
               cfg[best].ssim_min, cfg[best].bytes / cfg[j].bytes, cfg[j].bytes / cfg[best].bytes);
    }
}

sy_result sy_bench_stream(sy_scene *scene, const sy_viewport_desc *vd, const char *label, uint32_t width, uint32_t height,
                          uint32_t fps, sy_error *err)
{
    uint32_t frames = 10 * fps;
    size_t n = (size_t)width * height;
    setting cfg[NCFG];
    memset(cfg, 0, sizeof cfg);
    uint32_t ncfg = 0;
    for (size_t i = 0; i < NJ; ++i) cfg[ncfg++] = (setting){.codec = SY_WEB_CODEC_JPEG, .q = jpeg_q[i]};
    sy_result r = SY_OK;
    for (int c = SY_WEB_CODEC_VP8; c <= SY_WEB_CODEC_VP9 && sy_web_codec_available((sy_web_codec)c); ++c)
        for (size_t i = 0; i < NV && r == SY_OK; ++i) {
            setting *s = &cfg[ncfg++];
            *s = (setting){.codec = (sy_web_codec)c, .q = (int)video_q[i]};
            r = sy_web_video_encoder_create(s->codec, video_q[i], &s->enc, err);
            if (r == SY_OK) r = sy_web_video_decoder_create(s->codec, &s->dec, err);
        }
    for (uint32_t i = 0; i < ncfg; ++i) cfg[i].ssim_min = 1e9;
    sy_window *win = NULL;
    sy_viewport *vp = NULL;
    sy_context_pool *pool = NULL;
    sy_layer img = {0};
    float *ref = malloc(n * sizeof *ref), *tmp = malloc(n * sizeof *tmp);
    if (r == SY_OK && (!ref || !tmp)) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench stream: out of memory");
    sy_interactive_input home;
    if (r == SY_OK)
        r = sy_interactive_input_init(scene, vd->root, vd->camera, (float)width / (float)height, NULL, 0.0f, &home, err);
    if (r == SY_OK) r = sy_window_create(width, height, &win, err);
    if (r == SY_OK) r = sy_window_add_viewport(win, vd, &vp, err);
    if (r == SY_OK) r = sy_context_pool_create(&pool, err);
    if (r == SY_OK) r = sy_layer_create(width, height, &img, err);
    if (r == SY_OK)
        printf("sy bench stream: %s, back-end %s, %ux%u, %u frames (10 s at %u fps), orbit of 10 degrees per second; "
               "SSIM of each decoded frame against the float frame (luma)\n", label, vd->backend, width, height, frames, fps);
    double render_s = 0, d2_bytes = 0, d3_bytes = 0, d2_s = 0, d3_s = 0;
    /* 10 degrees per second: sy_orbit_rotate turns 0.008 rad per pixel of drag */
    const float dx = (float)(10.0 * 3.14159265358979 / 180.0 / fps / 0.008);
    sy_orbit o = home.orbit;
    for (uint32_t k = 0; k < frames && r == SY_OK; ++k) {
        sy_mat4 m;
        sy_orbit_matrix(&o, &m);
        sy_orbit_rotate(&o, dx, 0.0f);
        sy_viewport_set_view(vp, &m);
        sy_window_render_opts ro = {.sample_count = 1, .preview = 1.0f, .post = sy_post_display()};
        double t0 = sy_time_now();
        r = sy_window_render(win, scene, pool, &ro, &img, err);
        render_s += sy_time_now() - t0;
        uint8_t *px = r == SY_OK ? sy_interactive_rgba8(&img, SY_RGBA8_OVER_BLACK) : NULL;
        if (r == SY_OK && !px) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench stream: out of memory");
        if (r == SY_OK) luma_f(img.rgba, n, ref);
        if (r == SY_OK) { /* the depth channel of this frame, both codings */
            double t1 = sy_time_now();
            d2_bytes += (double)format2_depth_bytes(img.depth, width, height);
            double t2 = sy_time_now();
            uint8_t *z = NULL;
            size_t zl = 0;
            float a = 0, b = 0;
            r = sy_web_frame_depth_code(img.depth, width, height, &z, &zl, &a, &b, err);
            d3_s += sy_time_now() - t2, d2_s += t2 - t1, d3_bytes += (double)zl;
            free(z);
        }
        for (uint32_t i = 0; i < ncfg && r == SY_OK; ++i) r = run_setting(&cfg[i], px, width, height, ref, tmp, err);
        free(px);
        if (r == SY_OK && (k + 1) % (frames / 10 ? frames / 10 : 1) == 0) {
            printf("\r  %u / %u frames", k + 1, frames);
            fflush(stdout);
        }
    }
    if (r == SY_OK) {
        printf("\r  render %.1f ms per frame\n", render_s / frames * 1e3);
        printf("  codec  setting  bytes/frame   kbit/s  SSIM mean    min  keyframes  encode ms\n");
        for (uint32_t i = 0; i < ncfg; ++i) {
            setting *s = &cfg[i];
            printf("  %-5s  %s%-5d  %11.0f  %7.0f     %.4f  %.4f  %9llu  %9.2f\n", sy_web_codec_name(s->codec),
                   s->codec == SY_WEB_CODEC_JPEG ? "Q " : "q ", s->q, s->bytes / frames, s->bytes / frames * fps * 8 / 1e3,
                   s->ssim / frames, s->ssim_min, (unsigned long long)s->keys, s->enc_s / frames * 1e3);
        }
        printf("  depth channel per moving frame: format 2 (every pixel, row deltas, deflate 1) %.0f bytes (%.2f ms); "
               "format 3 (every fourth pixel, 12-bit, MED, deflate 6) %.0f bytes (%.2f ms): 1/%.1f; a still view's refinements: 0\n",
               d2_bytes / frames, d2_s / frames * 1e3, d3_bytes / frames, d3_s / frames * 1e3,
               d3_bytes > 0 ? d2_bytes / d3_bytes : 0.0);
        /* the server's defaults: JPEG at --quality 80, video at SY_WEB_VIDEO_QUANTIZER; with the
         * 192-byte header and the depth channel, a moving frame's message in format 2 and 3 */
        for (uint32_t i = 0; i < ncfg; ++i)
            if ((cfg[i].codec == SY_WEB_CODEC_JPEG && cfg[i].q == 80) ||
                (cfg[i].codec != SY_WEB_CODEC_JPEG && cfg[i].q == (int)SY_WEB_VIDEO_QUANTIZER))
                printf("  the server's default %s (%s %d): %.0f bytes per frame, SSIM %.4f (min %.4f); "
                       "message with depth: format 2 %.0f, format 3 %.0f bytes\n",
                       sy_web_codec_name(cfg[i].codec), cfg[i].codec == SY_WEB_CODEC_JPEG ? "Q" : "q", cfg[i].q,
                       cfg[i].bytes / frames, cfg[i].ssim / frames, cfg[i].ssim_min,
                       (cfg[i].bytes + d2_bytes) / frames + SY_WEB_FRAME_HEADER,
                       (cfg[i].bytes + d3_bytes) / frames + SY_WEB_FRAME_HEADER);
        /* the cheapest JPEG at mean SSIM >= 0.95, then each video codec's cheapest at least as good;
         * the same at the SSIM of JPEG at the server's quality (80) */
        int best_j = -1, j80 = -1;
        for (uint32_t i = 0; i < ncfg; ++i) {
            if (cfg[i].codec != SY_WEB_CODEC_JPEG) continue;
            if (cfg[i].q == 80) j80 = (int)i;
            if (cfg[i].ssim / frames >= 0.95 && (best_j < 0 || cfg[i].bytes < cfg[best_j].bytes)) best_j = (int)i;
        }
        if (best_j < 0) printf("  no JPEG quality reaches a mean SSIM of 0.95\n");
        else compare(cfg, ncfg, frames, best_j, "JPEG at SSIM >= 0.95");
        if (j80 >= 0) compare(cfg, ncfg, frames, j80, "JPEG at the server's quality");
    }
    for (uint32_t i = 0; i < ncfg; ++i) {
        sy_web_video_encoder_destroy(cfg[i].enc);
        sy_web_video_decoder_destroy(cfg[i].dec);
    }
    sy_layer_destroy(&img);
    sy_context_pool_destroy(pool);
    sy_window_destroy(win);
    free(ref);
    free(tmp);
    return r;
}
