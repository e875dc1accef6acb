/* sy_video.h — the video files of `sy render --frames A:B -o anim.mp4|anim.webm` (sy_video.c):
 * 8-bit frames (tone mapped as for PNG, over black) encoded with FFmpeg's libavcodec — H.264 in
 * MP4 (MPEG-4 part 2 where libavcodec has no H.264 encoder), VP9 in WebM — muxed with libavformat
 * into a temporary file in the target's folder that is renamed over the target when the video is
 * finished (a failed or interrupted run leaves no half video). Built only with SY_WITH_VIDEO
 * (SY_HAVE_VIDEO); without it sy_video_open fails naming the missing feature.
 * A sy_video is owned by its caller and used from one thread. */
#ifndef SY_VIDEO_H
#define SY_VIDEO_H

#include "sy_common.h"

#include <stdbool.h>
#include <stdint.h>

typedef struct sy_video sy_video;

/* path ends in .mp4 or .webm */
bool sy_video_is_path(const char *path);
/* SY_OK when this sy writes videos; otherwise the error that names the missing feature (for path) */
sy_result sy_video_check(const char *path, sy_error *err);
/* Starts a video of w x h pixels (odd sizes are scaled to the even size below) at fps frames per
 * second; *out is released by sy_video_finish or sy_video_abort. */
sy_result sy_video_open(const char *path, uint32_t w, uint32_t h, double fps, sy_video **out, sy_error *err);
/* Appends one frame: w * h RGBA8 pixels, row 0 on top (alpha ignored). */
sy_result sy_video_add(sy_video *v, const uint8_t *rgba, sy_error *err);
/* Flushes the encoder, writes the trailer and renames the file into place; releases v. */
sy_result sy_video_finish(sy_video *v, uint32_t *frames_out, sy_error *err);
/* Removes the temporary file and releases v (NULL: nothing). */
void sy_video_abort(sy_video *v);

#endif /* SY_VIDEO_H */
