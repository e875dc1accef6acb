/* sy_bench_stream.h — `sy bench stream`: the bytes and the quality of sy web's JPEG stream against
 * its video stream (VP8 / VP9) on a 10 s orbit (sy_bench_stream.c says how). Not a timed test.
 * Thread-safety: runs on the calling thread (and the back-end's workers). */
#ifndef SY_BENCH_STREAM_H
#define SY_BENCH_STREAM_H

#include "sy_viewport.h"

/* Renders 10 x fps frames of width x height along the orbit (vd: root, camera, back-end) and
 * prints, per codec setting, bytes per frame and SSIM against the float frame, then the cheapest
 * JPEG with mean SSIM >= 0.95 and each video codec's cheapest setting at least as good. */
sy_result sy_bench_stream(sy_scene *scene, const sy_viewport_desc *vd, const char *label, uint32_t width, uint32_t height,
                          uint32_t fps, sy_error *err);

#endif
