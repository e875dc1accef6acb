/** @file
 * sy_web_video.h — the video stream of sy web (docs/WEB.md, "The video stream"): VP8 or VP9
 * through libvpx (Debian's libvpx-dev), one encoder per viewer with realtime settings and a fixed
 * quantizer, keyframes only when asked (a new viewer, a new size, another back-end, the page's
 * request); the frame's colour goes in as 8-bit RGBA and is converted to I420 (BT.601, studio
 * range: what a VP8 / VP9 decoder, the browser's WebCodecs VideoDecoder included, assumes). A
 * decoder (libvpx) for clients, tests and `sy bench stream`.
 *
 * Built without libvpx (SY_WEB_HAVE_VPX undefined) every codec but JPEG is unavailable:
 * sy_web_codec_available says so and the create functions fail with SY_ERR_UNSUPPORTED, so the
 * server streams JPEG to every viewer.
 *
 * Ownership: an encoder or decoder is owned by its creator (destroy); the bytes an encode or
 * decode returns belong to the encoder / decoder and stay valid until its next call.
 * Thread-safety: one encoder or decoder per thread at a time; different ones are independent. */
#ifndef SY_WEB_VIDEO_H
#define SY_WEB_VIDEO_H

#include "sy_common.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The payload of a frame (header offset 184, docs/WEB.md): JPEG (0, as format 2 always had) or a
 * video codec's frame. */
typedef enum sy_web_codec {
    SY_WEB_CODEC_JPEG = 0,
    SY_WEB_CODEC_VP8 = 1,
    SY_WEB_CODEC_VP9 = 2,
    SY_WEB_CODEC_COUNT
} sy_web_codec;

/** "jpeg", "vp8", "vp9" ("?" beyond). */
const char *sy_web_codec_name(sy_web_codec c);
/** The codec of a name a page sends ("vp8", "vp9"; case-sensitive); false for anything else. */
bool sy_web_codec_from_name(const char *name, size_t len, sy_web_codec *out);
/** Whether this build can encode and decode c (JPEG: always; VP8 / VP9: built with libvpx). */
bool sy_web_codec_available(sy_web_codec c);

/** The default quantizer (libvpx's 0..63 scale) of the streamed frames: the cheapest setting whose
 * mean SSIM against the float frame stays >= 0.95 on the orbits of `sy bench stream` (docs/WEB.md). */
#define SY_WEB_VIDEO_QUANTIZER 36u

/** The quantizer for the server's quality setting (`--quality`, JPEG's 1..100 scale, which applies
 * to the video stream too): 80, the default, gives SY_WEB_VIDEO_QUANTIZER; each step of quality
 * is 1.6 steps of quantizer, within 4..63 (95: 12, 90: 20, 60 and below: 63). */
uint32_t sy_web_video_quantizer(int quality);

/** The most memory one encoder of w x h takes (an upper estimate: libvpx's reference, source
 * and scratch frames plus the I420 input), for the server's per-viewer budget. */
size_t sy_web_video_encoder_bytes(uint32_t width, uint32_t height);

typedef struct sy_web_video_encoder sy_web_video_encoder;

/** An encoder of codec c (VP8 or VP9) at quantizer q (0..63, lower = better). Its size is set
 * by the first frame. SY_ERR_UNSUPPORTED: c is not available in this build. */
sy_result sy_web_video_encoder_create(sy_web_codec c, uint32_t quantizer, sy_web_video_encoder **out, sy_error *err);
void sy_web_video_encoder_destroy(sy_web_video_encoder *e);

/** Encodes one frame of width x height RGBA8 pixels (rows top to bottom, alpha ignored). A size
 * within the stream's first one goes on in the same stream (VP9 predicts from scaled references;
 * VP8 and libvpx where it cannot scale send a keyframe); a larger one restarts the stream with a
 * keyframe. keyframe forces one. *data / *len: the codec's frame
 * (owned by e until its next call); *is_key: it is a keyframe. */
sy_result sy_web_video_encode(sy_web_video_encoder *e, const uint8_t *rgba, uint32_t width, uint32_t height, bool keyframe,
                              const uint8_t **data, size_t *len, bool *is_key, sy_error *err);

/** Frames this encoder has produced and how many of them were keyframes. */
void sy_web_video_encoder_counts(const sy_web_video_encoder *e, uint64_t *frames, uint64_t *keyframes);

/** The last frame's quality as libvpx measured it while encoding: PSNR in dB over Y, U and V
 * against the I420 that went in (0 before the first frame). */
double sy_web_video_encoder_psnr(const sy_web_video_encoder *e);

typedef struct sy_web_video_decoder sy_web_video_decoder;

/** A decoder of codec c (VP8 or VP9); SY_ERR_UNSUPPORTED as above. */
sy_result sy_web_video_decoder_create(sy_web_codec c, sy_web_video_decoder **out, sy_error *err);
void sy_web_video_decoder_destroy(sy_web_video_decoder *d);

/** Decodes one frame (len bytes) into RGBA8 (*rgba: owned by d until its next call, alpha 255);
 * SY_ERR_PROTOCOL for bytes the decoder refuses (a delta frame without its keyframe included). */
sy_result sy_web_video_decode(sy_web_video_decoder *d, const uint8_t *data, size_t len, const uint8_t **rgba,
                              uint32_t *width, uint32_t *height, sy_error *err);

#ifdef __cplusplus
}
#endif
#endif /* SY_WEB_VIDEO_H */
