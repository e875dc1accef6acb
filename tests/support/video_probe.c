/* video_probe.c — reads a video back through libavformat / libavcodec for the sequence tests:
 *   video_probe VIDEO [FRAME PNG]
 * prints "frames N fps F codec NAME" (N: the decoded frames, F: the stream's average frame rate)
 * and, given FRAME and PNG, "mean video R G B png R G B": the mean 8-bit RGB of decoded frame
 * FRAME (0-based, converted to RGB24) and of the PNG (over black). Exit 1 on a read error. */
#include "sy_png.h"

#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libswscale/swscale.h>
#include <stdio.h>
#include <stdlib.h>

int main(int argc, char **argv)
{
    if (argc != 2 && argc != 4) {
        fprintf(stderr, "usage: video_probe VIDEO [FRAME PNG]\n");
        return 2;
    }
    int want = argc == 4 ? atoi(argv[2]) : -1;
    av_log_set_level(AV_LOG_ERROR);
    AVFormatContext *fmt = NULL;
    if (avformat_open_input(&fmt, argv[1], NULL, NULL) < 0 || avformat_find_stream_info(fmt, NULL) < 0) {
        fprintf(stderr, "%s: cannot read\n", argv[1]);
        return 1;
    }
    int si = av_find_best_stream(fmt, AVMEDIA_TYPE_VIDEO, -1, -1, NULL, 0);
    if (si < 0) return fprintf(stderr, "%s: no video stream\n", argv[1]), 1;
    AVStream *st = fmt->streams[si];
    const AVCodec *codec = avcodec_find_decoder(st->codecpar->codec_id);
    AVCodecContext *dec = codec ? avcodec_alloc_context3(codec) : NULL;
    if (!dec || avcodec_parameters_to_context(dec, st->codecpar) < 0 || avcodec_open2(dec, codec, NULL) < 0)
        return fprintf(stderr, "%s: no decoder\n", argv[1]), 1;
    AVPacket *pkt = av_packet_alloc();
    AVFrame *fr = av_frame_alloc();
    long frames = 0;
    double mean[3] = {0, 0, 0};
    bool have = false, eof = false;
    while (!eof) {
        int e = av_read_frame(fmt, pkt);
        if (e < 0) {
            eof = true;
            avcodec_send_packet(dec, NULL);
        } else if (pkt->stream_index == si) {
            avcodec_send_packet(dec, pkt);
        }
        av_packet_unref(pkt);
        while (avcodec_receive_frame(dec, fr) == 0) {
            if (frames == want) {
                int w = fr->width, h = fr->height;
                struct SwsContext *sws =
                    sws_getContext(w, h, fr->format, w, h, AV_PIX_FMT_RGB24, SWS_BICUBIC, NULL, NULL, NULL);
                uint8_t *rgb = malloc((size_t)w * h * 3 + 64); /* libswscale may write past the last row */
                uint8_t *dst[1] = {rgb};
                int stride[1] = {w * 3};
                sws_scale(sws, (const uint8_t *const *)fr->data, fr->linesize, 0, h, dst, stride);
                for (long i = 0; i < (long)w * h; ++i)
                    for (int c = 0; c < 3; ++c) mean[c] += rgb[i * 3 + c];
                for (int c = 0; c < 3; ++c) mean[c] /= (double)w * h;
                free(rgb);
                sws_freeContext(sws);
                have = true;
            }
            frames++;
        }
    }
    AVRational r = st->avg_frame_rate;
    printf("frames %ld fps %g codec %s\n", frames, r.den ? (double)r.num / r.den : 0.0, codec->name);
    int rc = 0;
    if (want >= 0) {
        int w = 0, h = 0;
        uint8_t *px = NULL;
        sy_error err = {0};
        if (!have || sy_png_read_rgba8(argv[3], &w, &h, &px, &err) != SY_OK) {
            fprintf(stderr, "no frame %d or %s: %s\n", want, argv[3], err.message);
            rc = 1;
        } else {
            double pm[3] = {0, 0, 0};
            for (long i = 0; i < (long)w * h; ++i)
                for (int c = 0; c < 3; ++c) pm[c] += px[i * 4 + c] * (px[i * 4 + 3] / 255.0);
            printf("mean video %.2f %.2f %.2f png %.2f %.2f %.2f\n", mean[0], mean[1], mean[2], pm[0] / ((double)w * h),
                   pm[1] / ((double)w * h), pm[2] / ((double)w * h));
            free(px);
        }
    }
    av_frame_free(&fr);
    av_packet_free(&pkt);
    avcodec_free_context(&dec);
    avformat_close_input(&fmt);
    return rc;
}
