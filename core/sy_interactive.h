/** @file
 * sy_interactive.h — the interactive view of sy view's window and sy web's page, once: the orbit
 * camera the input steers (sy_orbit.h), the display-filter keys, the frame-time governor that sizes
 * each frame (sy_governor.h), the display filter applied to the back-end's context, and the 8-bit
 * image a window or a JPEG shows.
 *
 * The camera never touches the scene: the orbit's camera-to-world matrix is set on the viewport
 * (sy_viewport_set_view), so a moving frame commits nothing and whatever the application has
 * pending stays pending until it commits itself. The projection (field of view, near, far) is the
 * application's camera node's.
 *
 * Two halves, for the two threads of an interactive front-end:
 *   - sy_interactive_input: a plain value the input thread changes (drags, wheel, fly, keys F [ ] R);
 *     the caller guards it with its own lock and hands a copy to the render thread;
 *   - sy_interactive: the render thread's state (governor, the view last planned, the filter last
 *     applied): sy_interactive_plan per frame, render what it says, sy_interactive_report its time.
 * The display filters are the values of the "filter" parameter (an enum) in the parameter table of
 * the registered class with SY_CAP_FILTERS (sy_params.h), "none" first; without such a class only
 * "none". The initial back-end is the registry's (sy_interactive_backend_index).
 *
 * Ownership: sy_interactive is the caller's (create / destroy); inputs and frames are plain values;
 * images from sy_interactive_rgba8 are malloc()ed for the caller. Thread-safety: the input functions
 * are pure (on caller-owned values); a sy_interactive is used by one thread at a time, the one that
 * owns the scene while it renders. */
#ifndef SY_INTERACTIVE_H
#define SY_INTERACTIVE_H

#include "sy_governor.h"
#include "sy_orbit.h"
#include "sy_viewport.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- the input side ---- */

/** What the input steers: the orbit and the display filter. */
typedef struct sy_interactive_input {
    sy_orbit orbit;          /**< the view */
    sy_orbit home;           /**< where key R returns to (the camera's pose at the start) */
    uint32_t filter;         /**< the display filter: index among sy_interactive_filter_name's */
    float threshold;         /**< its threshold (keys [ and ] halve / double it) */
    uint64_t filter_version; /**< counts filter and threshold changes */
} sy_interactive_input;

/** The start: the orbit of the camera node's world matrix (as of the last commit) around the root's
 * bounds ({0} or a root without bounds: the whole scene's); a camera of {0} frames the bounds at
 * aspect (width / height). filter: a name among the display filters (NULL: "none"; another name is
 * SY_ERR_INVALID_ARGUMENT listing them); threshold: >= 0 and finite (0: 0.01). */
sy_result sy_interactive_input_init(const sy_scene *scene, sy_node root, sy_node camera, float aspect,
                                    const char *filter, float threshold, sy_interactive_input *out, sy_error *err);
/** A drag of dx, dy pixels: button 0 turns around the target (sy_orbit_rotate), any other pans. */
void sy_interactive_drag(sy_interactive_input *in, int button, float dx, float dy);
/** Wheel notches (positive: closer, sy_orbit_zoom). */
void sy_interactive_wheel(sy_interactive_input *in, float steps);
/** Flies the target along the view: move[0] right, move[1] up (world +Y), move[2] back (each -1, 0 or
 * 1), at 0.8 x the distance per second over dt seconds. false when move is all zero. */
bool sy_interactive_fly(sy_interactive_input *in, const float move[3], float dt);
/** The keys the interactive views share (lower or upper case): F cycles the display filter, [ and ]
 * halve / double its threshold (within 1e-6..1e3), R returns the orbit home. true when the key is
 * one of them. */
bool sy_interactive_key(sy_interactive_input *in, int key);

/** The number of display filters (1 when no registered class offers SY_CAP_FILTERS). */
uint32_t sy_interactive_filter_count(void);
/** The name of display filter index (modulo the count) into out (32 bytes); returns out. */
const char *sy_interactive_filter_name(uint32_t index, char out[32]);

/** The registry index of the back-end named name (NULL: the registry's default,
 * sy_mediator_default); SY_ERR_NOT_FOUND when it is not registered. */
sy_result sy_interactive_backend_index(const char *name, uint32_t *index, sy_error *err);

/** The vertical field of view (radians) of camera node camera's camera: what a saved view keeps
 * (sy_bookmarks.h); 0 for an orthographic camera or a node without one. */
float sy_interactive_fov(const sy_scene *scene, sy_node camera);
/** Sets fov (radians, in (0, pi)) as the camera's vertical field of view and commits the scene: a
 * recalled saved view's (sy view, sy web). SY_ERR_NOT_FOUND when the node has no camera. Called
 * by the thread that owns the scene. */
sy_result sy_interactive_set_fov(sy_scene *scene, sy_node camera, float fov, sy_error *err);

/* ---- the render side ---- */

/** The render thread's state (opaque). */
typedef struct sy_interactive sy_interactive;

/** Creates it with a governor of those settings (NULL: the defaults; sy_governor_desc). */
sy_result sy_interactive_create(const sy_governor_desc *gov, sy_interactive **out, sy_error *err);
void sy_interactive_destroy(sy_interactive *ia); /**< NULL-safe */

/** What a frame shows, for sy_interactive_plan. */
typedef struct sy_interactive_view {
    const sy_orbit *orbit;          /**< the view (its matrix goes to the viewports) */
    sy_viewport *const *viewports;  /**< viewports whose view is set to the orbit's (may be none) */
    uint32_t viewport_count;        /**< how many */
    const sy_mediator_class *backend; /**< the back-end (a switch resets the governor's cost model) */
    uint32_t caps;                  /**< capabilities to plan with (sy_mediator_class_caps, maybe less) */
    /** @{ the display size */
    uint32_t width, height; /** @} */
    uint64_t filter_version;        /**< sy_interactive_input.filter_version (a change redraws) */
    bool changed;                   /**< something else shown changed (stereo, overlay) */
} sy_interactive_view;

/** Sets the orbit's view on the viewports (never the scene), then plans the frame with the
 * governor: the view changed when the orbit, back-end, display size or v->changed did since the
 * last plan. *camera_to_world (may be NULL) receives the orbit's matrix. */
void sy_interactive_plan(sy_interactive *ia, const sy_interactive_view *v, double now_ms, sy_governor_frame *out,
                         sy_mat4 *camera_to_world);
/** The measured time of frame f as planned; new_context: the frame made a back-end context (its
 * time says nothing about the next frames and is left out). */
void sy_interactive_report(sy_interactive *ia, const sy_governor_frame *f, double ms, bool new_context);
/** The orbit's matrix at the last plan (false before the first). */
bool sy_interactive_view_matrix(const sy_interactive *ia, sy_mat4 *camera_to_world);

/** Temporal reuse on moving frames (default on): where the back-end's class declares a live
 * boolean "temporal" parameter (the path tracer: sy_filter_temporal.h), sy_interactive_apply_filter
 * sets it to `on` with the filter, so a frame whose camera moved shows the reprojected, filtered
 * history instead of its few noisy samples, and a still view shows the accumulation unchanged. */
void sy_interactive_set_temporal(sy_interactive *ia, bool on);

/** The governor's smallest resolution scale from the next plan on (sy_governor_set_min_scale; 0: the
 * governor's default): sy web raises it while every viewer's page warps. */
void sy_interactive_set_min_scale(sy_interactive *ia, float min_scale);

/** Applies display filter `filter` (index) at threshold to the back-end's context in pool (made
 * there when missing, for root_id), when the filter, its version or enabled changed or the context is
 * new; enabled false turns it off (the governor does while the view moves). A back-end without
 * SY_CAP_FILTERS: nothing (info->name ""). *info (may be NULL): the context's filter now. The
 * "temporal" parameter goes with it (sy_interactive_set_temporal). */
sy_result sy_interactive_apply_filter(sy_interactive *ia, sy_context_pool *pool, sy_scene *scene, uint32_t root_id,
                                      const sy_mediator_class *cls, uint32_t filter, float threshold, uint64_t version,
                                      bool enabled, sy_filter_info *info, sy_error *err);

/** How sy_interactive_rgba8 treats alpha. */
typedef enum sy_rgba8_alpha {
    SY_RGBA8_STRAIGHT = 0,   /**< colour divided by alpha where alpha > 0, alpha kept (a window) */
    SY_RGBA8_OVER_BLACK = 1, /**< premultiplied colour as it is, alpha 1 (composited over black: a JPEG) */
} sy_rgba8_alpha;
/** The 8-bit RGBA of a display-referred layer (after sy_post_display), malloc()ed (NULL when out of
 * memory). */
uint8_t *sy_interactive_rgba8(const sy_layer *img, sy_rgba8_alpha alpha);

#ifdef __cplusplus
}
#endif
#endif /* SY_INTERACTIVE_H */
