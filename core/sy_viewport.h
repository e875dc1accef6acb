/** @file
 * sy_viewport.h — windows, viewports and compositing.
 *
 * A window has a size and an ordered list of viewports (back to front). A viewport has a
 * rectangle in the window, a root node, a camera node, an optional background, a back-end name
 * and parameters, an eye (mono / left / right), an active flag and a composite mode. Rendering a
 * window syncs and renders each active viewport into an RGBA float + depth layer, then composites
 * them in order (replace, depth-composite or alpha-over), so different back-ends share one image.
 * Stereo is two viewports with off-axis frusta computed here from the eye separation and the
 * zero-parallax distance; back-ends never know.
 *
 * A viewport's view may also be set directly (sy_viewport_set_view: an interactive camera, see
 * sy_interactive.h): the camera-to-world matrix is the viewport's own state, used in place of the
 * camera node's world matrix, so moving the view changes nothing in the scene and needs no commit
 * (the application's pending changes stay pending).
 *
 * Picking (sy_window_pick, sy_viewport_pick) asks the same viewports, with the same camera views,
 * eyes and contexts, what is under one pixel: the layer in front answers (see sy_window_pick and
 * docs/BACKENDS.md, "Picking").
 *
 * Ownership: the window owns its viewports (sy_window_destroy frees them); a view set directly is
 * copied into the viewport; contexts come from a caller-owned sy_context_pool; a pick's answer
 * (sy_pick_result) is plain data in the caller's struct. Thread-safety: single-threaded, like the
 * scene it renders (a viewport's view included); a pick syncs and uses the viewport's context, so
 * it must not run beside a render of the same window or pool. */
#ifndef SY_VIEWPORT_H
#define SY_VIEWPORT_H

#include "sy_mediator.h"
#include "sy_post.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Which eye a viewport renders. */
typedef enum sy_eye { SY_EYE_MONO = 0, SY_EYE_LEFT = 1, SY_EYE_RIGHT = 2 } sy_eye;

/** How a viewport's layer is composited over the ones below it. */
typedef enum sy_composite {
    SY_COMPOSITE_REPLACE = 0,    /**< the viewport's pixels replace what is below */
    SY_COMPOSITE_DEPTH = 1,      /**< per pixel, the nearer depth wins */
    SY_COMPOSITE_ALPHA_OVER = 2, /**< premultiplied "over" the pixels below */
} sy_composite;

/** A viewport: rectangle, scene root, camera, back-end and its parameters, eye, composite mode. */
typedef struct sy_viewport_desc {
    /** @{ rectangle in the window, row 0 = top; 0 size = whole window */
    uint32_t x, y, width, height; /** @} */
    sy_node root;                 /**< {0}: every root of the scene */
    sy_node camera;               /**< a node carrying a camera; {0}: frame the root's bounds */
    sy_background background;     /**< {0}: black */
    const char *backend;          /**< registered mediator name (copied) */
    const char *params;           /**< "k=v,k=v" for the back-end (copied), may be NULL */
    uint32_t eye;                 /**< sy_eye */
    float eye_separation;         /**< metres, for stereo (default 0.065 when 0) */
    float zero_parallax;          /**< metres, distance of the screen plane (default 2 when 0) */
    uint32_t composite;           /**< sy_composite */
    bool inactive;                /**< created inactive */
    sy_post_desc post;            /**< applied to this viewport's layer before compositing */
} sy_viewport_desc;

/** A window: a size and an ordered list of viewports, back to front (opaque). */
typedef struct sy_window sy_window;
/** A viewport of a window (opaque, owned by the window). */
typedef struct sy_viewport sy_viewport;

/** Creates a window of width x height pixels without viewports. */
sy_result sy_window_create(uint32_t width, uint32_t height, sy_window **out, sy_error *err);
/** Destroys the window and its viewports (NULL-safe). */
void sy_window_destroy(sy_window *w);
/** Changes the window's size. */
sy_result sy_window_resize(sy_window *w, uint32_t width, uint32_t height, sy_error *err);
/** The window's size. */
void sy_window_size(const sy_window *w, uint32_t *width, uint32_t *height);

/** Appends a viewport on top of the existing ones. The pointer (out may be NULL) is owned by the
 * window. */
sy_result sy_window_add_viewport(sy_window *w, const sy_viewport_desc *desc, sy_viewport **out, sy_error *err);
/** Number of viewports. */
uint32_t sy_window_viewport_count(const sy_window *w);
/** The i-th viewport, back to front (NULL when i is out of range). */
sy_viewport *sy_window_viewport(const sy_window *w, uint32_t i);

/** Makes the viewport take part in rendering, or not. */
void sy_viewport_set_active(sy_viewport *v, bool active);
/** true when the viewport is active. */
bool sy_viewport_active(const sy_viewport *v);
/** Switches the back-end (cached contexts make switching back instant). An unregistered back-end or
 * parameters its class does not accept (sy_mediator_class_check_params) fail here, keeping the
 * current back-end. */
sy_result sy_viewport_set_backend(sy_viewport *v, const char *backend, const char *params, sy_error *err);
/** Sets the viewport's camera node ({0}: frame the root's bounds). */
void sy_viewport_set_camera(sy_viewport *v, sy_node camera);
/** Sets the view directly: camera_to_world (copied) replaces the camera node's world matrix; the
 * camera node's camera still gives the projection (field of view, near and far planes), and a
 * viewport without a camera node takes the projection of the view framing the root's bounds.
 * Nothing in the scene changes (no commit is needed or made). NULL: the camera node's world matrix
 * again. */
void sy_viewport_set_view(sy_viewport *v, const sy_mat4 *camera_to_world);
/** Sets the viewport's background (the world: sy_viewport_desc.background; {0}: none), e.g. to switch
 * environments (sy web's menu). A background object created for it must be committed before the
 * render that uses it, as any scene change. */
void sy_viewport_set_background(sy_viewport *v, sy_background background);
/** The viewport's background ({0}: none). */
sy_background sy_viewport_background(const sy_viewport *v);
/** Sets the viewport's section planes (SY_CAP_CLIP back-ends): up to SY_CLIP_PLANES_MAX planes
 * {a, b, c, d} in world coordinates (copied); what a*x + b*y + c*z + d >= 0 for all of them keeps
 * is drawn, picked and seen by every ray, the rest is cut away. count 0 removes them. Planes
 * sy_clip_planes_check refuses (more than SY_CLIP_PLANES_MAX, a value not finite or beyond
 * SY_COORD_MAX, a zero normal) fail with SY_ERR_INVALID_ARGUMENT naming the plane, keeping the
 * planes set before. They travel in the viewport's camera view (sy_viewport_camera_view), so a
 * back-end without SY_CAP_CLIP refuses to render or pick with them (SY_ERR_UNSUPPORTED). */
sy_result sy_viewport_set_clip_planes(sy_viewport *v, const float (*planes)[4], uint32_t count, sy_error *err);
/** The number of section planes set; copies them into planes (may be NULL; room for
 * SY_CLIP_PLANES_MAX). */
uint32_t sy_viewport_clip_planes(const sy_viewport *v, float (*planes)[4]);
/** Capping of the section planes: rgb (linear RGB, each channel in [0, 1]; copied) fills the cut
 * faces of closed meshes in every SY_CAP_CLIP back-end (sy_camera_view.clip_cap); NULL turns capping
 * off (the default: a cut closed mesh shows its inside). A colour sy_clip_cap_check refuses (not
 * finite, outside [0, 1]) fails with SY_ERR_INVALID_ARGUMENT, keeping the setting before. Without
 * section planes it has no effect. */
sy_result sy_viewport_set_clip_cap(sy_viewport *v, const float rgb[3], sy_error *err);
/** true when capping is on; its colour into rgb (may be NULL). */
bool sy_viewport_clip_cap(const sy_viewport *v, float rgb[3]);
/** true and *camera_to_world (may be NULL) when a view is set directly (sy_viewport_set_view). */
bool sy_viewport_view(const sy_viewport *v, sy_mat4 *camera_to_world);
/** The viewport's back-end name (borrowed). */
const char *sy_viewport_backend(const sy_viewport *v);

/** The camera view a viewport renders with (the view set directly, else its camera node's world
 * matrix as of the last commit, or a view framing the root's bounds), with the eye's off-axis
 * frustum applied and the viewport's section planes. */
sy_result sy_viewport_camera_view(const sy_viewport *v, const sy_scene *scene, uint32_t window_width,
                                  uint32_t window_height, sy_camera_view *out, sy_error *err);

/** Off-axis stereo: shifts the camera along its local X by -/+ separation/2 and skews the window
 * so that the plane at zero_parallax coincides for both eyes. MONO returns the view unchanged. */
sy_camera_view sy_camera_view_eye(const sy_camera_view *mono, uint32_t eye, float separation, float zero_parallax);

/** What is under window point (x, y) in viewport v (SY_CAP_PICK of its back-end): the pixel
 * containing the point (floor(x), floor(y): pixel (x, y) covers [x, x+1) x [y, y+1)) is picked
 * through its centre with the camera view, eye and back-end the viewport renders with, after
 * syncing its context (from pool, as sy_window_render does). out->viewport is v's index, out->eye
 * its eye, pixel_x/y the pixel in its rectangle. A point outside v's rectangle, or NaN/infinite:
 * SY_ERR_INVALID_ARGUMENT naming the values; a back-end without SY_CAP_PICK: SY_ERR_UNSUPPORTED
 * naming it. Nothing under the pixel is no error (out->hit false). v need not be active.
 * Thread-safety: as sy_window_render (the scene, the pool and the window on one thread). */
sy_result sy_viewport_pick(sy_viewport *v, sy_scene *scene, sy_context_pool *pool, double x, double y,
                           sy_pick_result *out, sy_error *err);
/** Measurement: the distance between the world positions of two picks, in scene units (metres: glTF's
 * unit; the Assimp loader scales a file's units to metres by its UnitScaleFactor on the root, and
 * X3D's unit is the metre). SY_ERR_INVALID_ARGUMENT when either pick hit nothing (naming which). */
sy_result sy_pick_distance(const sy_pick_result *a, const sy_pick_result *b, double *out, sy_error *err);
/** Measurement: the signed distance of world point p from the plane {a, b, c, d} (a x + b y + c z + d
 * = 0), in scene units: (a p.x + b p.y + c p.z + d) / |(a, b, c)|, positive on the side a section
 * plane keeps. A plane sy_clip_planes_check refuses (not finite, a zero normal) or a point not
 * finite: SY_ERR_INVALID_ARGUMENT naming it. */
sy_result sy_plane_distance(const float plane[4], const float p[3], double *out, sy_error *err);
/** What is under window point (x, y) in the layer in front: every active viewport whose rectangle
 * holds the point is picked (sy_viewport_pick) and the answers are combined back to front as
 * sy_window_render composites the layers: a REPLACE viewport's answer (hit or miss) replaces those
 * below, a DEPTH one wins where it hit nearer (smaller depth), an ALPHA_OVER one wherever it hit.
 * Stereo: each eye is a viewport, so the eye is the one of the viewport that answers (side by side
 * or top/bottom: the half the point is in; both eyes over one rectangle: the composite order).
 * A point outside the window or not finite: SY_ERR_INVALID_ARGUMENT; no viewport there, or
 * nothing hit: SY_OK with out->hit false (out->viewport UINT32_MAX when no viewport holds it). */
sy_result sy_window_pick(sy_window *w, sy_scene *scene, sy_context_pool *pool, double x, double y,
                         sy_pick_result *out, sy_error *err);

/** Composites src (a viewport's layer) into dst at (x, y) with the given mode. */
void sy_layer_composite(sy_layer *dst, const sy_layer *src, uint32_t x, uint32_t y, uint32_t mode);

/** Options of sy_window_render. */
typedef struct sy_window_render_opts {
    uint32_t seed; /**< seed for the back-ends' sampling */
    uint32_t sample_count; /**< progressive back-ends: samples to add this call; 0 = default */
    float preview; /**< sy_render_request.preview for every viewport (0 = full quality) */
    sy_progress_fn progress; /**< optional progress callback */
    void *progress_user; /**< passed to progress */
    sy_post_desc post; /**< applied to the composited window image */
} sy_window_render_opts;

/** Syncs and renders every active viewport and composites into out (window-sized; created by the
 * caller with sy_layer_create). */
sy_result sy_window_render(sy_window *w, sy_scene *scene, sy_context_pool *pool, const sy_window_render_opts *opts,
                           sy_layer *out, sy_error *err);

#ifdef __cplusplus
}
#endif
#endif /* SY_VIEWPORT_H */
