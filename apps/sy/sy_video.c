/* sy_video.c — video files through FFmpeg's libavcodec / libavformat / libswscale (see sy_video.h). */
#include "sy_video.h"
#include "sy_cli.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

bool sy_video_is_path(const char *path)
{
    return sy_cli_ends_with(path, ".mp4") || sy_cli_ends_with(path, ".webm");
}

#ifndef SY_HAVE_VIDEO

struct sy_video { int unused; };

sy_result sy_video_check(const char *path, sy_error *err)
{
    return sy_error_set(err, SY_ERR_UNSUPPORTED, "%s: this sy was built without video output (SY_WITH_VIDEO: FFmpeg's "
                        "libavcodec, libavformat, libswscale); write an image sequence (-o out_####.png)", path);
}
sy_result sy_video_open(const char *path, uint32_t w, uint32_t h, double fps, sy_video **out, sy_error *err)
{
    (void)w, (void)h, (void)fps;
    *out = NULL;
    return sy_video_check(path, err);
}
sy_result sy_video_add(sy_video *v, const uint8_t *rgba, sy_error *err)
{
    (void)v, (void)rgba;
    return sy_error_set(err, SY_ERR_UNSUPPORTED, "video output not built");
}
sy_result sy_video_finish(sy_video *v, uint32_t *frames_out, sy_error *err)
{
    (void)v, (void)frames_out;
    return sy_error_set(err, SY_ERR_UNSUPPORTED, "video output not built");
}
void sy_video_abort(sy_video *v) { (void)v; }

#else

#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/opt.h>
#include <libswscale/swscale.h>
#include <sys/stat.h>
#include <unistd.h>

struct sy_video {
    char *path, *tmp;
    AVFormatContext *fmt;
    AVCodecContext *enc;
    AVStream *st;
    struct SwsContext *sws;
    AVFrame *frame;
    AVPacket *pkt;
    uint8_t *rgba;  /* the frame in rows of `stride` bytes, padded: libswscale reads past a row's end */
    int stride;
    uint32_t w, h;
    int64_t pts;
    bool header;
};

static sy_result av_fail(sy_video *v, sy_error *err, const char *what, int e)
{
    char msg[AV_ERROR_MAX_STRING_SIZE] = "";
    av_strerror(e, msg, sizeof msg);
    return sy_error_set(err, SY_ERR_IO, "%s: %s: %s", v->path, what, msg);
}

/* sends frame (NULL: flush) and writes the packets the encoder has ready */
static sy_result encode(sy_video *v, AVFrame *frame, sy_error *err)
{
    int e = avcodec_send_frame(v->enc, frame);
    if (e < 0) return av_fail(v, err, "encoding a frame", e);
    for (;;) {
        e = avcodec_receive_packet(v->enc, v->pkt);
        if (e == AVERROR(EAGAIN) || e == AVERROR_EOF) return SY_OK;
        if (e < 0) return av_fail(v, err, "encoding a frame", e);
        av_packet_rescale_ts(v->pkt, v->enc->time_base, v->st->time_base);
        v->pkt->stream_index = v->st->index;
        e = av_interleaved_write_frame(v->fmt, v->pkt);
        if (e < 0) return av_fail(v, err, "writing a frame", e);
    }
}

sy_result sy_video_check(const char *path, sy_error *err)
{
    (void)path, (void)err;
    return SY_OK;
}

void sy_video_abort(sy_video *v)
{
    if (!v) return;
    if (v->fmt && v->fmt->pb) avio_closep(&v->fmt->pb);
    if (v->tmp) unlink(v->tmp);
    avformat_free_context(v->fmt);
    avcodec_free_context(&v->enc);
    sws_freeContext(v->sws);
    av_frame_free(&v->frame);
    av_packet_free(&v->pkt);
    av_free(v->rgba);
    free(v->path);
    free(v->tmp);
    free(v);
}

sy_result sy_video_open(const char *path, uint32_t w, uint32_t h, double fps, sy_video **out, sy_error *err)
{
    *out = NULL;
    bool webm = sy_cli_ends_with(path, ".webm");
    sy_video *v = calloc(1, sizeof *v);
    if (!v || !(v->path = strdup(path)) || !(v->tmp = malloc(strlen(path) + 16))) {
        if (v) free(v->path);
        free(v);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", path);
    }
    sprintf(v->tmp, "%s.tmp-XXXXXX", path);
    int fd = mkstemp(v->tmp);
    if (fd < 0) {
        free(v->tmp);
        v->tmp = NULL;
        sy_video_abort(v);
        return sy_error_set(err, SY_ERR_IO, "%s: cannot create a temporary file in its folder", path);
    }
    mode_t mask = umask(0);
    umask(mask);
    fchmod(fd, 0666 & ~mask); /* as any other output (mkstemp made it 0600) */
    close(fd);
    av_log_set_level(AV_LOG_ERROR); /* the encoders' statistics are not sy's output */
    v->w = w, v->h = h;
    int vw = w < 2 ? 2 : (int)(w & ~1u), vh = h < 2 ? 2 : (int)(h & ~1u);
    const AVCodec *codec = NULL;
    if (webm) codec = avcodec_find_encoder_by_name("libvpx-vp9");
    else if (!(codec = avcodec_find_encoder(AV_CODEC_ID_H264))) codec = avcodec_find_encoder(AV_CODEC_ID_MPEG4);
    int e = 0;
    sy_result r = SY_OK;
    if (!codec)
        r = sy_error_set(err, SY_ERR_UNSUPPORTED, "%s: libavcodec has no %s encoder", path,
                         webm ? "VP9 (libvpx-vp9)" : "H.264 or MPEG-4");
    if (r == SY_OK && (e = avformat_alloc_output_context2(&v->fmt, NULL, webm ? "webm" : "mp4", v->tmp)) < 0)
        r = av_fail(v, err, "output format", e);
    if (r == SY_OK && (!(v->st = avformat_new_stream(v->fmt, NULL)) || !(v->enc = avcodec_alloc_context3(codec)) ||
                       !(v->frame = av_frame_alloc()) || !(v->pkt = av_packet_alloc())))
        r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", path);
    if (r == SY_OK) {
        v->enc->width = vw, v->enc->height = vh;
        v->enc->pix_fmt = AV_PIX_FMT_YUV420P;
        v->enc->framerate = av_d2q(fps, 100000);
        v->enc->time_base = av_inv_q(v->enc->framerate);
        v->enc->gop_size = 12;
        if (codec->id == AV_CODEC_ID_MPEG4) v->enc->bit_rate = 8000000;
        if (codec->id == AV_CODEC_ID_H264) av_opt_set(v->enc->priv_data, "crf", "18", 0);
        if (codec->id == AV_CODEC_ID_VP9) {
            av_opt_set(v->enc->priv_data, "crf", "24", 0);
            av_opt_set(v->enc->priv_data, "deadline", "realtime", 0);
            av_opt_set_int(v->enc->priv_data, "cpu-used", 8, 0);
            v->enc->bit_rate = 0;
        }
        if (v->fmt->oformat->flags & AVFMT_GLOBALHEADER) v->enc->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
        if ((e = avcodec_open2(v->enc, codec, NULL)) < 0) r = av_fail(v, err, "opening the encoder", e);
    }
    if (r == SY_OK && (e = avcodec_parameters_from_context(v->st->codecpar, v->enc)) < 0)
        r = av_fail(v, err, "stream", e);
    if (r == SY_OK) {
        v->st->time_base = v->enc->time_base;
        v->st->avg_frame_rate = v->enc->framerate;
        v->frame->format = AV_PIX_FMT_YUV420P, v->frame->width = vw, v->frame->height = vh;
        if ((e = av_frame_get_buffer(v->frame, 0)) < 0) r = av_fail(v, err, "frame buffer", e);
    }
    if (r == SY_OK && !(v->sws = sws_getContext((int)w, (int)h, AV_PIX_FMT_RGBA, vw, vh, AV_PIX_FMT_YUV420P,
                                                SWS_BICUBIC, NULL, NULL, NULL)))
        r = sy_error_set(err, SY_ERR_UNSUPPORTED, "%s: no RGBA to YUV 4:2:0 conversion", path);
    v->stride = (int)((w * 4 + 63) & ~63u);
    if (r == SY_OK && !(v->rgba = av_mallocz((size_t)v->stride * (h + 1) + 64)))
        r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", path);
    if (r == SY_OK && (e = avio_open(&v->fmt->pb, v->tmp, AVIO_FLAG_WRITE)) < 0) r = av_fail(v, err, "opening", e);
    if (r == SY_OK && (e = avformat_write_header(v->fmt, NULL)) < 0) r = av_fail(v, err, "writing the header", e);
    if (r != SY_OK) {
        sy_video_abort(v);
        return r;
    }
    v->header = true;
    *out = v;
    return SY_OK;
}

sy_result sy_video_add(sy_video *v, const uint8_t *rgba, sy_error *err)
{
    int e = av_frame_make_writable(v->frame);
    if (e < 0) return av_fail(v, err, "frame buffer", e);
    for (uint32_t y = 0; y < v->h; ++y)
        memcpy(v->rgba + (size_t)y * v->stride, rgba + (size_t)y * v->w * 4, (size_t)v->w * 4);
    const uint8_t *src[1] = {v->rgba};
    const int stride[1] = {v->stride};
    sws_scale(v->sws, src, stride, 0, (int)v->h, v->frame->data, v->frame->linesize);
    v->frame->pts = v->pts++;
    return encode(v, v->frame, err);
}

sy_result sy_video_finish(sy_video *v, uint32_t *frames_out, sy_error *err)
{
    sy_result r = encode(v, NULL, err);
    int e = 0;
    if (r == SY_OK && (e = av_write_trailer(v->fmt)) < 0) r = av_fail(v, err, "writing the trailer", e);
    if (r == SY_OK && (e = avio_closep(&v->fmt->pb)) < 0) r = av_fail(v, err, "closing", e);
    if (r == SY_OK && rename(v->tmp, v->path) != 0)
        r = sy_error_set(err, SY_ERR_IO, "%s: cannot rename the finished video into place", v->path);
    if (r == SY_OK && frames_out) *frames_out = (uint32_t)v->pts;
    if (r == SY_OK) {
        free(v->tmp);
        v->tmp = NULL; /* renamed: nothing to remove */
    }
    sy_video_abort(v);
    return r;
}

#endif
