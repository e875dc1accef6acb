/** @file
 * sy_context.h — contexts: a back-end instance with its adapted scene (a consumer of the scene
 * plus the mediator's state), reference counted and shared by every viewport that shows the same
 * scene with the same back-end, and the pool that caches them.
 * Ownership: contexts are reference counted; sy_context_pool owns a reference to each cached one.
 * Thread-safety: a context and a pool are single-threaded: sync and render of one context must not
 * run concurrently. */
#ifndef SY_CONTEXT_H
#define SY_CONTEXT_H

#include "sy_registry.h"
#include "sy_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A back-end instance with its adapted scene, shared by reference count (opaque). */
typedef struct sy_context sy_context;

/** Creates a context: a consumer on the scene plus the mediator's state. Caller owns one ref. */
sy_result sy_context_create(sy_scene *scene, const char *backend, const sy_params *params, uint32_t root_node_id,
                            sy_context **out, sy_error *err);
/** Adds a reference; returns c. */
sy_context *sy_context_retain(sy_context *c);
void sy_context_release(sy_context *c); /**< the last release destroys the mediator state */
/** Pulls everything committed since the last sync and hands it to the mediator. Cost is
 * proportional to the changes. */
sy_result sy_context_sync(sy_context *c, sy_error *err);
/** Renders the request into layer (rect_w x rect_h) with the context's mediator. */
sy_result sy_context_render(sy_context *c, const sy_render_request *req, sy_layer *layer, sy_error *err);
/** The context's mediator class. */
const sy_mediator_class *sy_context_class(const sy_context *c);
/** The mediator's own state (for the mediator module's diagnostics functions). Borrowed. */
void *sy_context_state(const sy_context *c);
/** The next sync and render of this context give what a new context on the scene as it then is
 * would give, bit for bit: progressive back-ends (SY_CAP_PROGRESSIVE) start a new accumulation at
 * sample 0 with the request's seed even when nothing visible changed (without it an unchanged scene
 * goes on accumulating), and the ray tracers place the next sync's moved nodes as a fresh build does
 * (their fast path for moves hits in the last bits differently; the next commit rebuilds the top
 * level instead). Call it before each frame of an image sequence, so that frame k is what a fresh
 * `sy render --at T` of its time renders (sy render --frames does, per frame). A cluster context
 * forwards it to its servers with its next frame. Back-ends without the class hook: nothing.
 * Thread-safety: as sy_context_render. */
void sy_context_restart(sy_context *c);
/** Motion blur in one render (SY_CAP_MOTION; others: SY_ERR_UNSUPPORTED naming the back-end), for a
 * shutter from time T0 (open) to T1 (close): commit the scene at T1 and call
 * sy_context_motion_begin (it syncs), commit the scene at T0 and call sy_context_motion_open (it
 * syncs: every node moved between T1 and T0 is placed at T0 for ray time 0 and at T1 for ray time
 * 1, interpolated linearly for each ray's time in [0, 1)); render (each pixel sample at its own
 * time; time_samples: the fewest samples per pixel of back-ends with a fixed count, 0 = their
 * default); then sy_context_motion_end (the context stays at T0, sharp). Meshes deformed between T1
 * and T0 (skins, morphs) are interpolated too, vertex by vertex. *native false from _open: the
 * changes hold what the back-end cannot interpolate (moved lights, meshes made anew): call
 * sy_context_motion_end and blur another way (sub-frames). The request's camera is the open's; a
 * camera that moves over the shutter is given at its close with sy_context_motion_camera after
 * _open. Errors leave the motion ended. Thread-safety: as sy_context_render. */
sy_result sy_context_motion_begin(sy_context *c, uint32_t time_samples, sy_error *err);
/** Most time steps of a shutter (sy_context_motion_begin_steps). */
#define SY_MOTION_STEPS_MAX 9
/** Curved motion: sy_context_motion_begin for a shutter sampled at `steps` (2 to
 * SY_MOTION_STEPS_MAX) equally spaced times T_k = T0 + k / (steps - 1) x (T1 - T0): commit the scene
 * at T1 (the close) and call this (it syncs), then for k = steps - 2 down to 1 commit it at T_k and
 * call sy_context_motion_step, then commit it at T0 and call sy_context_motion_open. Every instance
 * that moves and every mesh that deforms (skins, morphs) is placed at each step and interpolated
 * linearly between consecutive steps (a turn becomes steps - 1 chords of its arc); so is a camera
 * given at each step with sy_context_motion_camera. steps 2 is sy_context_motion_begin. SY_ERR_UNSUPPORTED (the motion ended)
 * when the back-end takes only two steps. Thread-safety: as sy_context_render. */
sy_result sy_context_motion_begin_steps(sy_context *c, uint32_t time_samples, uint32_t steps, sy_error *err);
/** Syncs the scene committed at an intermediate time step (see sy_context_motion_begin_steps).
 * Errors leave the motion ended. Thread-safety: as sy_context_render. */
sy_result sy_context_motion_step(sy_context *c, sy_error *err);
/** The second step of motion blur (see sy_context_motion_begin): syncs the scene committed at the
 * shutter's open; *native says whether the back-end interpolates every change. Thread-safety: as
 * sy_context_render. */
sy_result sy_context_motion_open(sy_context *c, bool *native, sy_error *err);
/** Most moving cameras of one motion (sy_context_motion_camera: a stereo pair's two eyes, ...). */
#define SY_MOTION_CAMERAS_MAX 4
/** A camera that moves over the shutter (after sy_context_motion_open; see sy_context_motion_begin):
 * open is the view at the shutter's open, later[0 .. steps - 2] the views at the equally spaced
 * times after it (steps 2 .. SY_MOTION_STEPS_MAX; later[steps - 2] the close: steps 2 is the open and
 * the close alone); a render request whose camera is open has each camera ray built at its own
 * time, position and window interpolated linearly between the two steps around it, orientation by
 * slerp, until sy_context_motion_end (requests with another camera stay still). Called again with
 * another open view it adds that camera (each stereo eye: its own view at each step, one call per
 * eye; up to SY_MOTION_CAMERAS_MAX), with the same open view it replaces it. SY_ERR_UNSUPPORTED naming the back-end when its class does not interpolate
 * the camera (then blur another way), SY_ERR_INVALID_ARGUMENT when the motion is not open or holds
 * SY_MOTION_CAMERAS_MAX others. On error the motion stays as it was. Thread-safety: as sy_context_render. */
sy_result sy_context_motion_camera(sy_context *c, const sy_camera_view *open, uint32_t steps,
                                  const sy_camera_view *later, sy_error *err);
/** Ends motion blur (see sy_context_motion_begin): the context renders sharp again. Thread-safety:
 * as sy_context_render. */
void sy_context_motion_end(sy_context *c);
/** Fills out with the mediator's statistics. */
void sy_context_stats(const sy_context *c, sy_mediator_stats *out);
/** The instance's capabilities (sy_mediator_caps): the class's, or what caps_of says for its parameters. */
uint32_t sy_context_caps(const sy_context *c);
/** Feature buffers of the last render; SY_ERR_UNSUPPORTED naming the back-end without SY_CAP_AOVS.
 * out is the caller's: sy_aovs_free. */
sy_result sy_context_aovs(sy_context *c, sy_aovs *out, sy_error *err);
/** Display filter (SY_CAP_FILTERS; others: SY_ERR_UNSUPPORTED naming the back-end). opts are checked
 * against the class's table first: only keys declared SY_PARAM_LIVE may change here. */
sy_result sy_context_set_filter(sy_context *c, const char *name, const sy_params *opts, sy_error *err);
/** Fills out (name "none" for a back-end without filters). */
void sy_context_filter_info(const sy_context *c, sy_filter_info *out);
/** Per-node pixel coverage (SY_CAP_COVERAGE; others: SY_ERR_UNSUPPORTED naming the back-end): a ray
 * through every pixel centre of view at width x height, the nearest visible object's node counted,
 * sorted by pixels, most first (ties: smaller node id first); nodes covering nothing are left out.
 * Covers what the context last synced. Ownership: *entries_out is malloc()ed, the caller frees it
 * (NULL and 0 on failure). */
sy_result sy_context_coverage(sy_context *c, const sy_camera_view *view, uint32_t width, uint32_t height,
                              sy_coverage_entry **entries_out, uint32_t *count_out, sy_error *err);

/** What is under pixel (x, y) of view rendered at width x height (SY_CAP_PICK; others:
 * SY_ERR_UNSUPPORTED naming the back-end): the nearest surface the ray through the pixel's centre
 * meets in what the context last synced, as sy_pick_result says. x >= width, y >= height or a zero
 * size: SY_ERR_INVALID_ARGUMENT naming the values; a view sy_camera_view_check refuses: its error.
 * A miss is no error (out->hit false). out's viewport fields are left as they are. Covers what the
 * context last synced (sy_viewport_pick syncs first). Thread-safety: as sy_context_render (never
 * beside a sync or render of the same context). */
sy_result sy_context_pick(sy_context *c, const sy_camera_view *view, uint32_t width, uint32_t height, uint32_t x,
                          uint32_t y, sy_pick_result *out, sy_error *err);

/** A cache of contexts keyed by (scene, back-end, parameters, root): viewports showing the same
 * scene with the same back-end share one context, so the scene is converted once and switching
 * back to a back-end is instant. */
typedef struct sy_context_pool sy_context_pool;
/** Creates an empty pool. */
sy_result sy_context_pool_create(sy_context_pool **out, sy_error *err);
void sy_context_pool_destroy(sy_context_pool *p); /**< releases the pool's references */
/** Returns a borrowed context (valid while the pool lives), creating it on first use. */
sy_result sy_context_pool_get(sy_context_pool *p, sy_scene *scene, const char *backend, const sy_params *params,
                              uint32_t root_node_id, sy_context **out, sy_error *err);
/** Number of contexts in the pool. */
uint32_t sy_context_pool_size(const sy_context_pool *p);

#ifdef __cplusplus
}
#endif
#endif /* SY_CONTEXT_H */
