/** @file
 * sy_governor.h — the frame-time governor of interactive views (sy view, sy web): while the view
 * moves it picks a render size (and, for progressive back-ends, one sample per pixel) so that each
 * frame fits a time budget; when the view stops it refines to full quality (full resolution, then
 * progressive samples added a few per frame, each frame still within the budget so that input
 * stays responsive) until a sample limit, then says the caller may sleep until the next input.
 *
 * The cost model: frame time = fixed + per x (pixels x samples), fitted by exponentially weighted
 * least squares over the frames reported (forgetting factor 0.7), one fit for plain frames (one
 * sample, no display filter: every moving frame) and one for refining frames (several samples or a
 * display filter), each anchored at its weighted mean (so it always passes through the recent
 * operating point); a frame more than 4x off the prediction counts as 4x (one stall moves the
 * model a bounded step; two in a row restart the fit: a lasting change is learned at once). Moving
 * frames aim at 80 % of the budget, refining frames at 85 %, and less where the measured times
 * spread around the model (a machine shared with other processes): at budget / (about the 95th
 * percentile of measured / predicted over the last 32 frames), never below 50 %, so that the slow
 * frames fit too. The resolution scale grows at most 2x per frame and the samples of a refining
 * frame at most 2x over the previous one.
 *
 * What it trades: resolution, samples per frame and the display filter (off while moving). It does
 * not trade back-end parameters (a path tracer's max_depth, Whitted's spp, raster msaa): those are
 * creation parameters of a context, contexts are pooled by their parameters (sy_context_pool), and
 * only display-filter options are live (SY_PARAM_LIVE, sy_context_set_filter), so a cheaper
 * parameter while moving would translate the scene a second time into a second context.
 *
 * Use: per frame, sy_governor_plan() with the display size, the back-end's capabilities and whether
 * the view changed; render what it says (or wait / sleep when it says so); then
 * sy_governor_report() with the measured time of that frame. Leave out a frame whose time says
 * nothing about the next (one that built a back-end's scene: its first). On a back-end switch call
 * sy_governor_reset().
 *
 * Ownership: the governor is the caller's (sy_governor_create / sy_governor_destroy); frames are
 * plain values. Thread-safety: a governor is used by one thread at a time; there is no global
 * state. */
#ifndef SY_GOVERNOR_H
#define SY_GOVERNOR_H

#include "sy_common.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A frame-time governor (opaque). */
typedef struct sy_governor sy_governor;

/** Settings; zero fields take the defaults. */
typedef struct sy_governor_desc {
    double budget_ms;     /**< frame budget while the view moves (ms, > 0); 0 = 33 */
    float min_scale;      /**< smallest resolution scale (0, 1]; 0 = 0.125 */
    uint32_t max_samples; /**< progressive: most samples per pixel it refines to when still; 0 = 65536 */
    double settle_ms;     /**< the view counts as moving until this long after its last change (ms); 0 = 150 */
} sy_governor_desc;

/** The preview level of moving frames (back-ends with SY_CAP_PREVIEW): a quarter of the full
 * per-pixel work, e.g. Whitted's 4 camera rays and 16 light samples per pixel become 1 and 4. */
#define SY_GOVERNOR_PREVIEW 0.25f

/** What to render this frame (sy_governor_plan). */
typedef struct sy_governor_frame {
    /** @{ render size (<= the display size; the display scales it up); 0 when the display is empty */
    uint32_t width, height; /** @} */
    float scale;      /**< width / display width (0 when the display is empty) */
    uint32_t samples; /**< progressive back-ends: samples to add this frame (1 while moving) */
    bool filter;      /**< the display filter may run this frame (refining frames of a back-end with SY_CAP_FILTERS) */
    bool moving;      /**< a moving frame (budgeted) rather than a refining one */
    bool idle;        /**< nothing left to refine: render nothing, sleep until input */
    /** sy_window_render_opts.preview for this frame: SY_GOVERNOR_PREVIEW on moving frames of a
     * back-end with SY_CAP_PREVIEW (fewer samples per pixel, same context), 1 otherwise. */
    float preview;
    /** > 0: nothing to render before this many ms from now (the view is still settling after a
     * moving frame was shown): wait for input at most this long, then plan again. The other fields
     * then describe the last moving frame, so a caller that renders anyway does no harm. */
    double wait_ms;
} sy_governor_frame;

/** Creates a governor; d may be NULL (all defaults). A negative or non-finite budget or settle
 * time, or a min_scale outside [0, 1], is SY_ERR_INVALID_ARGUMENT naming the field. */
sy_result sy_governor_create(const sy_governor_desc *d, sy_governor **out, sy_error *err);
void sy_governor_destroy(sy_governor *g); /**< NULL-safe */
/** The settings in use, defaults filled in. */
void sy_governor_settings(const sy_governor *g, sy_governor_desc *out);

/** Plans the next frame for a display of display_w x display_h pixels. view_changed: camera, scene,
 * size or back-end changed since the last planned frame (a new size or caps counts as a change by
 * itself); now_ms: a monotonic clock in ms; caps: the back-end's sy_mediator_caps (SY_CAP_PROGRESSIVE:
 * refine by samples; SY_CAP_FILTERS: a display filter may run while refining). Planning a frame
 * counts it as rendered (samples accumulated so far). */
void sy_governor_plan(sy_governor *g, uint32_t display_w, uint32_t display_h, uint32_t caps, bool view_changed,
                      double now_ms, sy_governor_frame *out);
/** The measured time (ms) of frame f, as planned; idle, waiting, empty frames and non-finite or
 * negative times are ignored. */
void sy_governor_report(sy_governor *g, const sy_governor_frame *f, double render_ms);
/** Back-end switched: forget the cost model; the next plan starts over as after a view change. */
void sy_governor_reset(sy_governor *g);
/** Sets the smallest resolution scale from the next plan on (as sy_governor_desc.min_scale: (0, 1],
 * 0 = 0.125; a value outside [0, 1] or NaN leaves it as it is). */
void sy_governor_set_min_scale(sy_governor *g, float min_scale);
/** Something shown changed that keeps the view and the back-end's accumulation (a display filter):
 * when the governor is idle, the next plan gives one more refining frame (1 sample). */
void sy_governor_redraw(sy_governor *g);

/** The fitted cost model of moving (plain) or refining frames: frame ms = *fixed_ms + *per_ms x
 * pixels x samples. false (outputs 0) while no frame of that kind was reported since the last reset. */
bool sy_governor_cost(const sy_governor *g, bool moving, double *fixed_ms, double *per_ms);

#ifdef __cplusplus
}
#endif
#endif /* SY_GOVERNOR_H */
