/* sy_web_video.c — sy web's video stream: VP8 / VP9 encoders (one per viewer) and decoders through
 * libvpx, RGBA8 <-> I420 (BT.601, studio range) (see sy_web_video.h). */
#include "sy_web_video.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char *const codec_names[SY_WEB_CODEC_COUNT] = {"jpeg", "vp8", "vp9"};

uint32_t sy_web_video_quantizer(int quality)
{
    double q = floor((double)SY_WEB_VIDEO_QUANTIZER + (80.0 - quality) * 1.6 + 0.5);
    return (uint32_t)(q < 4 ? 4 : q > 63 ? 63 : q);
}

const char *sy_web_codec_name(sy_web_codec c) { return (unsigned)c < SY_WEB_CODEC_COUNT ? codec_names[c] : "?"; }

bool sy_web_codec_from_name(const char *name, size_t len, sy_web_codec *out)
{
    for (int c = SY_WEB_CODEC_VP8; c < SY_WEB_CODEC_COUNT; ++c)
        if (len == strlen(codec_names[c]) && !memcmp(name, codec_names[c], len)) {
            *out = (sy_web_codec)c;
            return true;
        }
    return false;
}

size_t sy_web_video_encoder_bytes(uint32_t width, uint32_t height)
{
    /* libvpx keeps up to 8 reference / scratch frames of I420 with 32-pixel borders (VP9: up to 12
     * with its frame buffer pool), plus the input image and per-macroblock state */
    size_t pad = (size_t)(width + 64) * (height + 64) * 3 / 2;
    return 16 * pad + (size_t)width * height * 3 / 2 + 4u * 1024 * 1024;
}

#ifndef SY_WEB_HAVE_VPX

struct sy_web_video_encoder { int unused; };
struct sy_web_video_decoder { int unused; };

bool sy_web_codec_available(sy_web_codec c) { return c == SY_WEB_CODEC_JPEG; }

sy_result sy_web_video_encoder_create(sy_web_codec c, uint32_t quantizer, sy_web_video_encoder **out, sy_error *err)
{
    (void)quantizer;
    *out = NULL;
    return sy_error_set(err, SY_ERR_UNSUPPORTED, "web: no %s encoder in this build (libvpx-dev was not found)", sy_web_codec_name(c));
}
void sy_web_video_encoder_destroy(sy_web_video_encoder *e) { (void)e; }
sy_result sy_web_video_encode(sy_web_video_encoder *e, const uint8_t *rgba, uint32_t width, uint32_t height, bool keyframe,
                              const uint8_t **data, size_t *len, bool *is_key, sy_error *err)
{
    (void)e, (void)rgba, (void)width, (void)height, (void)keyframe, (void)data, (void)len, (void)is_key;
    return sy_error_set(err, SY_ERR_UNSUPPORTED, "web: no video encoder in this build");
}
void sy_web_video_encoder_counts(const sy_web_video_encoder *e, uint64_t *frames, uint64_t *keyframes)
{
    (void)e;
    *frames = *keyframes = 0;
}
double sy_web_video_encoder_psnr(const sy_web_video_encoder *e)
{
    (void)e;
    return 0;
}
sy_result sy_web_video_decoder_create(sy_web_codec c, sy_web_video_decoder **out, sy_error *err)
{
    *out = NULL;
    return sy_error_set(err, SY_ERR_UNSUPPORTED, "web: no %s decoder in this build (libvpx-dev was not found)", sy_web_codec_name(c));
}
void sy_web_video_decoder_destroy(sy_web_video_decoder *d) { (void)d; }
sy_result sy_web_video_decode(sy_web_video_decoder *d, const uint8_t *data, size_t len, const uint8_t **rgba,
                              uint32_t *width, uint32_t *height, sy_error *err)
{
    (void)d, (void)data, (void)len, (void)rgba, (void)width, (void)height;
    return sy_error_set(err, SY_ERR_UNSUPPORTED, "web: no video decoder in this build");
}

#else

#include <vpx/vp8cx.h>
#include <vpx/vp8dx.h>
#include <vpx/vpx_decoder.h>
#include <vpx/vpx_encoder.h>

bool sy_web_codec_available(sy_web_codec c) { return (unsigned)c < SY_WEB_CODEC_COUNT; }

struct sy_web_video_encoder {
    sy_web_codec codec;
    uint32_t q;
    vpx_codec_ctx_t ctx;
    bool open;
    vpx_image_t *img;
    uint32_t w, h;   /* the current frame size */
    uint32_t w0, h0; /* the size the stream started with: smaller frames go on in it (VP9 scales its references) */
    vpx_codec_enc_cfg_t cfg;
    double psnr;     /* the last frame's PSNR (dB, libvpx's, all planes) */
    int64_t pts;
    uint8_t *out;
    size_t out_len, out_cap;
    uint64_t frames, keyframes;
};

struct sy_web_video_decoder {
    sy_web_codec codec;
    vpx_codec_ctx_t ctx;
    uint8_t *rgba;
    size_t cap;
};

static uint8_t clamp8(int v) { return (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : v); }

/* RGBA8 -> I420, BT.601 studio range (the integer form of ITU-R BT.601); chroma from the mean of
 * each 2 x 2 block (the last row / column of an odd size alone). */
static void rgba_to_i420(const uint8_t *rgba, uint32_t w, uint32_t h, vpx_image_t *img)
{
    for (uint32_t y = 0; y < h; ++y) {
        const uint8_t *s = rgba + (size_t)y * w * 4;
        uint8_t *d = img->planes[VPX_PLANE_Y] + (size_t)y * img->stride[VPX_PLANE_Y];
        for (uint32_t x = 0; x < w; ++x, s += 4) d[x] = (uint8_t)(((66 * s[0] + 129 * s[1] + 25 * s[2] + 128) >> 8) + 16);
    }
    for (uint32_t y = 0; y < (h + 1) / 2; ++y) {
        uint8_t *u = img->planes[VPX_PLANE_U] + (size_t)y * img->stride[VPX_PLANE_U];
        uint8_t *v = img->planes[VPX_PLANE_V] + (size_t)y * img->stride[VPX_PLANE_V];
        for (uint32_t x = 0; x < (w + 1) / 2; ++x) {
            int r = 0, g = 0, b = 0, n = 0;
            for (uint32_t dy = 0; dy < 2; ++dy)
                for (uint32_t dx = 0; dx < 2; ++dx) {
                    uint32_t px = 2 * x + dx, py = 2 * y + dy;
                    if (px >= w || py >= h) continue;
                    const uint8_t *s = rgba + ((size_t)py * w + px) * 4;
                    r += s[0], g += s[1], b += s[2], n++;
                }
            r = (r + n / 2) / n, g = (g + n / 2) / n, b = (b + n / 2) / n;
            u[x] = (uint8_t)(((-38 * r - 74 * g + 112 * b + 128) >> 8) + 128);
            v[x] = (uint8_t)(((112 * r - 94 * g - 18 * b + 128) >> 8) + 128);
        }
    }
}

static void enc_close(sy_web_video_encoder *e)
{
    if (e->open) vpx_codec_destroy(&e->ctx);
    e->open = false;
    vpx_img_free(e->img);
    e->img = NULL;
    e->w = e->h = e->w0 = e->h0 = 0;
}

static sy_result enc_open(sy_web_video_encoder *e, uint32_t w, uint32_t h, sy_error *err)
{
    vpx_codec_iface_t *iface = e->codec == SY_WEB_CODEC_VP9 ? vpx_codec_vp9_cx() : vpx_codec_vp8_cx();
    vpx_codec_enc_cfg_t cfg;
    if (vpx_codec_enc_config_default(iface, &cfg, 0))
        return sy_error_set(err, SY_ERR_BACKEND, "web: %s: no default encoder configuration", sy_web_codec_name(e->codec));
    cfg.g_w = w, cfg.g_h = h;
    cfg.g_timebase.num = 1, cfg.g_timebase.den = 1000; /* pts in ms */
    cfg.g_threads = 1;         /* one encoder per viewer on the network thread */
    cfg.g_lag_in_frames = 0;   /* realtime: each frame out as it goes in */
    cfg.g_pass = VPX_RC_ONE_PASS;
    cfg.g_error_resilient = 0;
    cfg.rc_end_usage = VPX_VBR;
    cfg.rc_min_quantizer = cfg.rc_max_quantizer = e->q; /* a fixed quantizer: the quality the bench measured */
    cfg.rc_target_bitrate = 100000;                      /* kbit/s: never the limit */
    cfg.rc_dropframe_thresh = 0;                         /* every frame given is sent */
    cfg.rc_resize_allowed = 0;
    cfg.kf_mode = VPX_KF_DISABLED; /* keyframes when asked (VPX_EFLAG_FORCE_KF) and the first */
    cfg.kf_min_dist = 0, cfg.kf_max_dist = 1000000; /* VP9 counts its interval (128) even without kf_mode */
    if (vpx_codec_enc_init(&e->ctx, iface, &cfg, VPX_CODEC_USE_PSNR))
        return sy_error_set(err, SY_ERR_BACKEND, "web: %s encoder of %ux%u: %s", sy_web_codec_name(e->codec), w, h,
                            vpx_codec_error(&e->ctx));
    e->open = true;
    if (e->codec == SY_WEB_CODEC_VP9) {
        vpx_codec_control(&e->ctx, VP8E_SET_CPUUSED, 8);
        vpx_codec_control(&e->ctx, VP9E_SET_COLOR_SPACE, VPX_CS_BT_601);
        vpx_codec_control(&e->ctx, VP9E_SET_AQ_MODE, 0);
    } else {
        vpx_codec_control(&e->ctx, VP8E_SET_CPUUSED, 8);
        vpx_codec_control(&e->ctx, VP8E_SET_NOISE_SENSITIVITY, 0);
    }
    e->img = vpx_img_alloc(NULL, VPX_IMG_FMT_I420, w, h, 16);
    if (!e->img) {
        enc_close(e);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "web: out of memory for a %ux%u video frame", w, h);
    }
    e->w = e->w0 = w, e->h = e->h0 = h;
    e->cfg = cfg;
    return SY_OK;
}

/* A frame of another size: within the stream's first size, the stream goes on at the new size
 * (VP9 predicts from its scaled references; libvpx sends a keyframe itself where it cannot, VP8
 * always); larger: a new stream. */
static sy_result enc_resize(sy_web_video_encoder *e, uint32_t w, uint32_t h, sy_error *err)
{
    if (w <= e->w0 && h <= e->h0) {
        vpx_codec_enc_cfg_t cfg = e->cfg;
        cfg.g_w = w, cfg.g_h = h;
        vpx_image_t *img = vpx_img_alloc(NULL, VPX_IMG_FMT_I420, w, h, 16);
        if (img && vpx_codec_enc_config_set(&e->ctx, &cfg) == VPX_CODEC_OK) {
            vpx_img_free(e->img);
            e->img = img, e->cfg = cfg, e->w = w, e->h = h;
            return SY_OK;
        }
        vpx_img_free(img);
    }
    enc_close(e);
    return enc_open(e, w, h, err);
}

sy_result sy_web_video_encoder_create(sy_web_codec c, uint32_t quantizer, sy_web_video_encoder **out, sy_error *err)
{
    *out = NULL;
    if (c != SY_WEB_CODEC_VP8 && c != SY_WEB_CODEC_VP9)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "web: %s is no video codec", sy_web_codec_name(c));
    if (quantizer > 63) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "web: quantizer %u is not in 0..63", quantizer);
    sy_web_video_encoder *e = calloc(1, sizeof *e);
    if (!e) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "web: out of memory for an encoder");
    e->codec = c, e->q = quantizer;
    *out = e;
    return SY_OK;
}

void sy_web_video_encoder_destroy(sy_web_video_encoder *e)
{
    if (!e) return;
    enc_close(e);
    free(e->out);
    free(e);
}

void sy_web_video_encoder_counts(const sy_web_video_encoder *e, uint64_t *frames, uint64_t *keyframes)
{
    *frames = e->frames, *keyframes = e->keyframes;
}

double sy_web_video_encoder_psnr(const sy_web_video_encoder *e) { return e->psnr; }

sy_result sy_web_video_encode(sy_web_video_encoder *e, const uint8_t *rgba, uint32_t width, uint32_t height, bool keyframe,
                              const uint8_t **data, size_t *len, bool *is_key, sy_error *err)
{
    *data = NULL, *len = 0, *is_key = false;
    if (!width || !height || width > 16384 || height > 16384)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "web: a video frame of %ux%u", width, height);
    if (e->open && (e->w != width || e->h != height)) {
        sy_result r = enc_resize(e, width, height, err);
        if (r != SY_OK) return r;
    } else if (!e->open) {
        sy_result r = enc_open(e, width, height, err);
        if (r != SY_OK) return r;
        keyframe = true;
    }
    rgba_to_i420(rgba, width, height, e->img);
    vpx_codec_err_t vr = vpx_codec_encode(&e->ctx, e->img, e->pts, 1, keyframe ? VPX_EFLAG_FORCE_KF : 0, VPX_DL_REALTIME);
    e->pts++;
    if (vr != VPX_CODEC_OK) {
        sy_result r = sy_error_set(err, SY_ERR_BACKEND, "web: %s encoding a %ux%u frame: %s", sy_web_codec_name(e->codec),
                                   width, height, vpx_codec_error_detail(&e->ctx) ? vpx_codec_error_detail(&e->ctx) : vpx_codec_error(&e->ctx));
        enc_close(e); /* the next frame starts a new stream */
        return r;
    }
    e->out_len = 0;
    bool key = false;
    vpx_codec_iter_t it = NULL;
    const vpx_codec_cx_pkt_t *p;
    while ((p = vpx_codec_get_cx_data(&e->ctx, &it))) {
        if (p->kind == VPX_CODEC_PSNR_PKT) e->psnr = p->data.psnr.psnr[0];
        if (p->kind != VPX_CODEC_CX_FRAME_PKT) continue;
        size_t need = e->out_len + p->data.frame.sz;
        if (need > e->out_cap) {
            size_t cap = need + need / 2 + 4096;
            uint8_t *o = realloc(e->out, cap);
            if (!o) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "web: out of memory for a video frame of %zu bytes", need);
            e->out = o, e->out_cap = cap;
        }
        memcpy(e->out + e->out_len, p->data.frame.buf, p->data.frame.sz);
        e->out_len = need;
        if (p->data.frame.flags & VPX_FRAME_IS_KEY) key = true;
    }
    if (!e->out_len) {
        enc_close(e);
        return sy_error_set(err, SY_ERR_BACKEND, "web: %s gave no frame for %ux%u", sy_web_codec_name(e->codec), width, height);
    }
    e->frames++;
    if (key) e->keyframes++;
    *data = e->out, *len = e->out_len, *is_key = key;
    return SY_OK;
}

sy_result sy_web_video_decoder_create(sy_web_codec c, sy_web_video_decoder **out, sy_error *err)
{
    *out = NULL;
    if (c != SY_WEB_CODEC_VP8 && c != SY_WEB_CODEC_VP9)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "web: %s is no video codec", sy_web_codec_name(c));
    sy_web_video_decoder *d = calloc(1, sizeof *d);
    if (!d) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "web: out of memory for a decoder");
    vpx_codec_dec_cfg_t cfg = {.threads = 1};
    if (vpx_codec_dec_init(&d->ctx, c == SY_WEB_CODEC_VP9 ? vpx_codec_vp9_dx() : vpx_codec_vp8_dx(), &cfg, 0)) {
        free(d);
        return sy_error_set(err, SY_ERR_BACKEND, "web: cannot start a %s decoder", sy_web_codec_name(c));
    }
    d->codec = c;
    *out = d;
    return SY_OK;
}

void sy_web_video_decoder_destroy(sy_web_video_decoder *d)
{
    if (!d) return;
    vpx_codec_destroy(&d->ctx);
    free(d->rgba);
    free(d);
}

sy_result sy_web_video_decode(sy_web_video_decoder *d, const uint8_t *data, size_t len, const uint8_t **rgba,
                              uint32_t *width, uint32_t *height, sy_error *err)
{
    *rgba = NULL, *width = *height = 0;
    if (!len || len > UINT32_MAX) return sy_error_set(err, SY_ERR_PROTOCOL, "web: a %s frame of %zu bytes", sy_web_codec_name(d->codec), len);
    if (vpx_codec_decode(&d->ctx, data, (unsigned)len, NULL, 0))
        return sy_error_set(err, SY_ERR_PROTOCOL, "web: %s refused a frame of %zu bytes: %s", sy_web_codec_name(d->codec), len,
                            vpx_codec_error(&d->ctx));
    vpx_codec_iter_t it = NULL;
    vpx_image_t *img = vpx_codec_get_frame(&d->ctx, &it);
    if (!img || img->fmt != VPX_IMG_FMT_I420)
        return sy_error_set(err, SY_ERR_PROTOCOL, "web: %s gave no 8-bit 4:2:0 picture", sy_web_codec_name(d->codec));
    uint32_t w = img->d_w, h = img->d_h;
    size_t need = (size_t)w * h * 4;
    if (need > d->cap) {
        uint8_t *p = realloc(d->rgba, need);
        if (!p) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "web: out of memory for a %ux%u picture", w, h);
        d->rgba = p, d->cap = need;
    }
    for (uint32_t y = 0; y < h; ++y) {
        const uint8_t *yp = img->planes[VPX_PLANE_Y] + (size_t)y * img->stride[VPX_PLANE_Y];
        const uint8_t *up = img->planes[VPX_PLANE_U] + (size_t)(y / 2) * img->stride[VPX_PLANE_U];
        const uint8_t *vp = img->planes[VPX_PLANE_V] + (size_t)(y / 2) * img->stride[VPX_PLANE_V];
        uint8_t *o = d->rgba + (size_t)y * w * 4;
        for (uint32_t x = 0; x < w; ++x, o += 4) {
            int c = yp[x] - 16, du = up[x / 2] - 128, dv = vp[x / 2] - 128;
            o[0] = clamp8((298 * c + 409 * dv + 128) >> 8);
            o[1] = clamp8((298 * c - 100 * du - 208 * dv + 128) >> 8);
            o[2] = clamp8((298 * c + 516 * du + 128) >> 8);
            o[3] = 255;
        }
    }
    *rgba = d->rgba, *width = w, *height = h;
    return SY_OK;
}

#endif
