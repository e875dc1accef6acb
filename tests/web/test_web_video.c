/* test_web_video.c — sy web's video encoder module (apps/web/sy_web_video.h), VP8 and VP9:
 *
 *   moving        40 frames of a moving synthetic picture (a soft gradient, a textured disc that
 *                 moves 3 pixels a frame, a sharp bar that turns) at the default quantizer,
 *                 decoded with libvpx's decoder: every frame's luma PSNR >= 32 dB and SSIM >= 0.95
 *                 against the RGBA that went in (measured: 35.3 dB and 0.977-0.981 for either
 *                 codec; 0.95 is the SSIM target, 32 dB is 3 dB under the measure so a
 *                 libvpx update that shifts its rates a little passes while a broken colour
 *                 conversion or a lost reference frame, 15-25 dB, fails), the delta frames cost
 *                 less than the keyframe, and a
 *                 picture that stays costs under a tenth of its keyframe (inter prediction works)
 *                 and gets no keyframe of libvpx's own in 300 frames;
 *                 keyframes exactly where asked (frame 0, 15, 30) and nowhere else; a smaller
 *                 size goes on (decoded at that size), a larger one restarts the stream with a
 *                 keyframe; a finer quantizer gives a better picture
 *   bad           codec names ("vp8", "vp9" only), a quantizer out of range, a size of 0,
 *                 garbage and a delta frame given to a fresh decoder: errors, no crash
 * Skips (77) in a build without libvpx. */
#include "../support/sy_check.h"
#include "sy_filter_metrics.h"
#include "sy_web_video.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define W 192
#define H 108

/* frame t: a gradient, a disc with a checker texture moving right and down, a bar turning */
static void picture(uint8_t *px, uint32_t w, uint32_t h, int t)
{
    double cx = 40 + 3.0 * t, cy = 30 + 1.5 * t, a = 0.05 * t;
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            uint8_t *p = px + ((size_t)y * w + x) * 4;
            double r = 40 + 120.0 * x / w, g = 60 + 100.0 * y / h, b = 90;
            double dx = x - cx, dy = y - cy;
            if (dx * dx + dy * dy < 22 * 22) {
                int chk = ((int)floor(dx / 4) + (int)floor(dy / 4)) & 1;
                r = chk ? 230 : 180, g = chk ? 200 : 60, b = chk ? 40 : 30;
            }
            double u = (x - w * 0.7) * cos(a) + (y - h * 0.5) * sin(a), v = -(x - w * 0.7) * sin(a) + (y - h * 0.5) * cos(a);
            if (fabs(u) < 25 && fabs(v) < 3) r = g = b = 250;
            p[0] = (uint8_t)r, p[1] = (uint8_t)g, p[2] = (uint8_t)b, p[3] = 255;
        }
}

static void luma(const uint8_t *px, uint32_t n, float *out)
{
    for (uint32_t i = 0; i < n; ++i)
        out[i] = (0.2126f * px[4 * i] + 0.7152f * px[4 * i + 1] + 0.0722f * px[4 * i + 2]) / 255.0f;
}

static double psnr(const float *a, const float *b, uint32_t n)
{
    double se = 0;
    for (uint32_t i = 0; i < n; ++i) se += (double)(a[i] - b[i]) * (a[i] - b[i]);
    return se > 0 ? 10 * log10(n / se) : 99;
}

/* one stream of `frames` frames at quantizer q; keyframes asked at `every`; fills worst PSNR / SSIM */
static int stream(sy_web_codec c, uint32_t q, int frames, int every, double *min_psnr, double *min_ssim, size_t *first,
                  size_t *rest)
{
    sy_error err = {0};
    sy_web_video_encoder *e = NULL;
    sy_web_video_decoder *d = NULL;
    CHECK_OK(sy_web_video_encoder_create(c, q, &e, &err), err);
    CHECK_OK(sy_web_video_decoder_create(c, &d, &err), err);
    uint8_t *px = malloc(W * H * 4);
    float *la = malloc(W * H * sizeof *la), *lb = malloc(W * H * sizeof *lb);
    CHECK(px && la && lb);
    *min_psnr = *min_ssim = 1e9, *first = *rest = 0;
    for (int t = 0; t < frames; ++t) {
        picture(px, W, H, t);
        const uint8_t *data = NULL, *out = NULL;
        size_t len = 0;
        bool key = false;
        bool ask = every && t % every == 0 && t > 0;
        CHECK_OK(sy_web_video_encode(e, px, W, H, ask, &data, &len, &key, &err), err);
        EXPECT_MSG(key == (t == 0 || ask), "%s frame %d: keyframe %d, asked %d", sy_web_codec_name(c), t, key, ask || t == 0);
        if (t == 0) *first = len;
        else *rest += len;
        uint32_t ow = 0, oh = 0;
        CHECK_OK(sy_web_video_decode(d, data, len, &out, &ow, &oh, &err), err);
        CHECK(ow == W && oh == H);
        luma(px, W * H, la), luma(out, W * H, lb);
        double p = psnr(la, lb, W * H), s = sy_filter_ssim_gray(la, lb, W, H);
        if (p < *min_psnr) *min_psnr = p;
        if (s < *min_ssim) *min_ssim = s;
    }
    uint64_t n = 0, k = 0;
    sy_web_video_encoder_counts(e, &n, &k);
    EXPECT(n == (uint64_t)frames);
    EXPECT(k == (uint64_t)(every ? (frames - 1) / every + 1 : 1));
    EXPECT(sy_web_video_encoder_psnr(e) > 25);
    /* a smaller size goes on in the stream; a larger one is a keyframe without asking; both
     * decodable by the same decoder */
    static const uint32_t sizes[3][2] = {{97, 61}, {W / 2, H / 2}, {W + 32, H + 16}};
    uint8_t *other = malloc((W + 32) * (H + 16) * 4);
    CHECK(other);
    for (int k = 0; k < 3; ++k) {
        uint32_t sw = sizes[k][0], sh = sizes[k][1];
        picture(other, sw, sh, 3 + k);
        const uint8_t *data = NULL, *out = NULL;
        size_t len = 0;
        bool key = false;
        uint32_t ow = 0, oh = 0;
        CHECK_OK(sy_web_video_encode(e, other, sw, sh, false, &data, &len, &key, &err), err);
        if (k == 2) EXPECT_MSG(key, "%s: a larger frame is no keyframe", sy_web_codec_name(c));
        CHECK_OK(sy_web_video_decode(d, data, len, &out, &ow, &oh, &err), err);
        EXPECT_MSG(ow == sw && oh == sh, "%s: decoded %ux%u, sent %ux%u", sy_web_codec_name(c), ow, oh, sw, sh);
    }
    free(other);
    free(px), free(la), free(lb);
    sy_web_video_encoder_destroy(e);
    sy_web_video_decoder_destroy(d);
    return 0;
}

static int test_moving(void)
{
    for (sy_web_codec c = SY_WEB_CODEC_VP8; c <= SY_WEB_CODEC_VP9; ++c) {
        double p = 0, s = 0, pf = 0, sf = 0;
        size_t first = 0, rest = 0, f2 = 0, r2 = 0;
        CHECK(stream(c, SY_WEB_VIDEO_QUANTIZER, 40, 15, &p, &s, &first, &rest) == 0);
        printf("%s q%u: worst luma PSNR %.2f dB, SSIM %.4f; first frame %zu bytes, then %.0f per frame\n", sy_web_codec_name(c),
               SY_WEB_VIDEO_QUANTIZER, p, s, first, rest / 39.0);
        EXPECT_MSG(p >= 32.0, "%s: worst PSNR %.2f dB", sy_web_codec_name(c), p);
        EXPECT_MSG(s >= 0.95, "%s: worst SSIM %.4f", sy_web_codec_name(c), s);
        CHECK(stream(c, 10, 20, 0, &pf, &sf, &f2, &r2) == 0);
        printf("%s q10: worst luma PSNR %.2f dB, SSIM %.4f; first frame %zu bytes, then %.0f per frame\n", sy_web_codec_name(c),
               pf, sf, f2, r2 / 19.0);
        EXPECT_MSG(pf > p && sf >= s, "%s: q10 %.2f dB / %.4f is not better than q%u %.2f / %.4f", sy_web_codec_name(c), pf, sf,
                   SY_WEB_VIDEO_QUANTIZER, p, s);
        /* the moving picture's delta frames cost less than its keyframe; a picture that stays
         * costs a small fraction in its delta frames (inter prediction works) */
        EXPECT_MSG(rest / 39.0 < first, "%s: delta frames %.0f bytes against a keyframe of %zu", sy_web_codec_name(c), rest / 39.0, first);
        sy_error err = {0};
        sy_web_video_encoder *e = NULL;
        uint8_t *px = malloc(W * H * 4);
        CHECK(px);
        CHECK_OK(sy_web_video_encoder_create(c, SY_WEB_VIDEO_QUANTIZER, &e, &err), err);
        picture(px, W, H, 5);
        size_t lens[4] = {0};
        int keys = 0;
        for (int k = 0; k < 300; ++k) { /* past libvpx's default keyframe interval (VP9: 128) */
            const uint8_t *data = NULL;
            bool key = false;
            size_t len = 0;
            CHECK_OK(sy_web_video_encode(e, px, W, H, false, &data, &len, &key, &err), err);
            if (k < 4) lens[k] = len;
            keys += key;
        }
        EXPECT_MSG(lens[3] * 10 < lens[0], "%s: a picture that stays: %zu bytes after a keyframe of %zu", sy_web_codec_name(c),
                   lens[3], lens[0]);
        EXPECT_MSG(keys == 1, "%s: %d keyframes in 300 frames, one asked", sy_web_codec_name(c), keys);
        sy_web_video_encoder_destroy(e);
        free(px);
    }
    return 0;
}

static int test_bad(void)
{
    sy_error err = {0};
    sy_web_codec c = SY_WEB_CODEC_JPEG;
    EXPECT(sy_web_codec_from_name("vp8", 3, &c) && c == SY_WEB_CODEC_VP8);
    EXPECT(sy_web_codec_from_name("vp9", 3, &c) && c == SY_WEB_CODEC_VP9);
    EXPECT(!sy_web_codec_from_name("vp8x", 4, &c) && !sy_web_codec_from_name("VP8", 3, &c) && !sy_web_codec_from_name("", 0, &c) &&
           !sy_web_codec_from_name("jpeg", 4, &c) && !sy_web_codec_from_name("vp", 2, &c));
    sy_web_video_encoder *e = NULL;
    sy_web_video_decoder *d = NULL;
    EXPECT_ERR(sy_web_video_encoder_create(SY_WEB_CODEC_JPEG, 30, &e, &err), SY_ERR_INVALID_ARGUMENT, err);
    EXPECT_ERR(sy_web_video_encoder_create(SY_WEB_CODEC_VP8, 64, &e, &err), SY_ERR_INVALID_ARGUMENT, err);
    CHECK_OK(sy_web_video_encoder_create(SY_WEB_CODEC_VP8, 30, &e, &err), err);
    uint8_t px[16 * 16 * 4] = {0};
    const uint8_t *data = NULL, *out = NULL;
    size_t len = 0;
    bool key = false;
    uint32_t ow = 0, oh = 0;
    EXPECT_ERR(sy_web_video_encode(e, px, 0, 16, false, &data, &len, &key, &err), SY_ERR_INVALID_ARGUMENT, err);
    CHECK_OK(sy_web_video_encode(e, px, 16, 16, false, &data, &len, &key, &err), err);
    px[100] = 255;
    CHECK_OK(sy_web_video_encode(e, px, 16, 16, false, &data, &len, &key, &err), err);
    EXPECT(!key);
    CHECK_OK(sy_web_video_decoder_create(SY_WEB_CODEC_VP8, &d, &err), err);
    /* a delta frame first: refused (libvpx wants a keyframe to start) */
    EXPECT_ERR(sy_web_video_decode(d, data, len, &out, &ow, &oh, &err), SY_ERR_PROTOCOL, err);
    uint8_t junk[300];
    for (int i = 0; i < 300; ++i) junk[i] = (uint8_t)(i * 37 + 11);
    EXPECT(sy_web_video_decode(d, junk, sizeof junk, &out, &ow, &oh, &err) != SY_OK);
    EXPECT_ERR(sy_web_video_decode(d, junk, 0, &out, &ow, &oh, &err), SY_ERR_PROTOCOL, err);
    sy_web_video_decoder_destroy(d);
    sy_web_video_encoder_destroy(e);
    EXPECT(sy_web_video_encoder_bytes(1920, 1200) > 1920 * 1200 * 3 / 2);
    return 0;
}

int main(void)
{
    if (!sy_web_codec_available(SY_WEB_CODEC_VP8)) {
        printf("skipped: this build has no libvpx (libvpx-dev)\n");
        return 77;
    }
    RUN(test_moving);
    RUN(test_bad);
    return sy_check_finish("web_video");
}
