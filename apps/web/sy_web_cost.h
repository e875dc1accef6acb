/** @file
 * sy_web_cost.h — what a streamed frame costs beyond its render (docs/WEB.md, "One view for
 * everyone"): the encoders that run on the network thread (each video viewer's VP8 / VP9 encoder;
 * JPEG is made on the render thread, inside the frame's own time) are timed per frame and kept as
 * a cost per pixel; the render thread adds that cost, at the size it rendered, to the time it
 * reports to the frame-time governor (core/sy_governor.h), so a slow encoder makes the governor
 * pick a smaller moving frame just as a slow render does.
 *
 * Ownership: plain values. Thread-safety: none (the server updates and reads them under its mutex). */
#ifndef SY_WEB_COST_H
#define SY_WEB_COST_H

#include "sy_common.h"

#ifdef __cplusplus
extern "C" {
#endif

/** One encoder's cost: ms per pixel, an exponentially weighted mean over the frames it encoded
 * (weight SY_WEB_COST_WEIGHT for the newest). */
typedef struct sy_web_encode_cost {
    double per_px_ms; /**< 0 before the first frame */
    uint64_t frames;  /**< frames measured */
} sy_web_encode_cost;

#define SY_WEB_COST_WEIGHT 0.3 /**< the newest frame's weight in the mean */

/** Counts one encoded frame of pixels pixels that took ms; non-finite or negative times and empty
 * frames are ignored. Returns the change of per_px_ms (to keep a sum over encoders). */
double sy_web_encode_cost_add(sy_web_encode_cost *c, double ms, uint64_t pixels);

/** A frame's whole cost for the governor: its render time (render, display chain, what the render
 * thread encodes) plus encode_per_px_ms (the sum over the encoders that will take it) x its pixels. */
double sy_web_frame_cost_ms(double render_ms, double encode_per_px_ms, uint32_t width, uint32_t height);

#ifdef __cplusplus
}
#endif
#endif /* SY_WEB_COST_H */
