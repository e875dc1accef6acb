/** @file
 * sy_mediator.h — the one small interface between core and every back-end: mediator classes
 * (a vtable registered by name), render requests, RGBA float + depth layers, and reference-counted
 * contexts (back-end instance + its adapted scene) shared by every viewport that shows the same
 * scene with the same back-end.
 *
 * A mediator translates the core scene into its back-end's own scene and keeps it in sync from
 * change lists; it never reads the live sy_scene (the application may already be editing the next
 * frame). A back-end only ever sees "fill this rectangle of pixels for this camera".
 *
 * Ownership: layers are owned by whoever created them (sy_layer_create / sy_layer_destroy).
 * Contexts are reference counted; sy_context_pool owns a reference to each cached context.
 * Thread-safety: the registry is safe to use from any thread (mutex). A context and a pool are
 * single-threaded: sync and render of one context must not run concurrently. */
#ifndef SY_MEDIATOR_H
#define SY_MEDIATOR_H

#include "sy_changes.h"
#include "sy_params.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- layers ---- */
/** A rendered rectangle: RGBA and depth planes (sy_layer_create). */
typedef struct sy_layer {
    /** @{ size in pixels */
    uint32_t width, height; /** @} */
    float *rgba;  /**< width*height*4, linear premultiplied, row 0 = top */
    float *depth; /**< width*height, linear distance along the view axis, +INFINITY = nothing */
} sy_layer;

/** Allocates a layer cleared to transparent black and +INFINITY depth. */
sy_result sy_layer_create(uint32_t width, uint32_t height, sy_layer *out, sy_error *err);
void sy_layer_destroy(sy_layer *l); /**< frees the buffers, zeroes the struct */
/** Clears to transparent black and +INFINITY depth. */
void sy_layer_clear(sy_layer *l);
/** Counts pixels with a non-finite colour component (tests: must be zero). */
size_t sy_layer_count_nonfinite(const sy_layer *l);

/* ---- camera and render requests ---- */
/** What a back-end renders: camera placement, projection and image-plane window. */
typedef struct sy_camera_view {
    sy_mat4 camera_to_world; /**< the camera looks down its local -Z, +Y up */
    uint32_t projection;     /**< sy_projection */
    /** Image-plane window {left, right, bottom, top}: for perspective in tangent space at distance 1
     * (symmetric and off-axis frusta alike), for orthographic in camera units. The full image maps
     * onto this window; pixel (x, y) has its centre at (x + 0.5, y + 0.5), row 0 at the top. */
    float window[4];
    /** @{ zfar 0 = infinite */
    float znear, zfar; /** @} */
} sy_camera_view;

/** SY_OK when the view is one every back-end can render: finite, the camera's position and every
 * element of its matrix within SY_COORD_MAX (sy_math.h), an orthographic window within it too;
 * otherwise SY_ERR_INVALID_ARGUMENT saying which value is out of range. sy_context_render checks
 * every request with it, so no back-end is given a camera beyond the range. */
sy_result sy_camera_view_check(const sy_camera_view *v, sy_error *err);

/** Camera view for a camera object at a world matrix, for an image of the given aspect
 * (width / height). The image aspect wins over the camera's own aspect, keeping yfov / ymag. */
sy_camera_view sy_camera_view_make(const sy_camera_data *cam, const sy_mat4 *world, float image_aspect);
/** A perspective view (yfov 45 degrees) looking at the bounds from +Z/+Y, framing all of it. */
sy_camera_view sy_camera_view_frame_bounds(const sy_bounds *b, float image_aspect);

/** Progress of a long render. */
typedef struct sy_progress {
    /** @{ units of work (tiles, samples) */
    uint64_t done, total; /** @} */
} sy_progress;
/** Receives progress reports. */
typedef void (*sy_progress_fn)(void *user, const sy_progress *p);

/** What to render: the camera view, the full image, the rectangle to fill, samples, background. */
typedef struct sy_render_request {
    sy_camera_view camera; /**< the camera */
    /** @{ the whole image */
    uint32_t full_width, full_height; /** @} */
    /** @{ sub-rectangle to fill; the layer is rect_w x rect_h */
    uint32_t rect_x, rect_y, rect_w, rect_h; /** @} */
    /** @{ progressive back-ends: samples to add; 0 count = default */
    uint32_t sample_first, sample_count; /** @} */
    uint32_t background_id; /**< sy_background handle id, 0 = the back-end's default (black) */
    uint32_t seed; /**< seed for the back-end's sampling (same seed = same image) */
    /** Interactive preview (back-ends with SY_CAP_PREVIEW): in (0, 1), the share of its full per-pixel
     * work the back-end may spend on this frame (a frame-time governor's choice while the view
     * moves); 0 or 1 (or anything else) = full quality. */
    float preview;
    sy_progress_fn progress; /**< optional, called from the rendering thread(s) serially */
    void *progress_user; /**< passed to progress */
} sy_render_request;

/* ---- parameters: "key=value" pairs given to a back-end (sy_params) and each class's declared
 * table of them (sy_param_table): sy_params.h ---- */

/* ---- mediator classes ---- */
/** Typed capabilities: the rest of the library and the applications ask these (sy_context_caps,
 * sy_mediator_class.caps), never a back-end's name. */
typedef enum sy_mediator_caps {
    SY_CAP_DEPTH = 1u << 0,       /**< fills the depth layer */
    SY_CAP_PROGRESSIVE = 1u << 1, /**< accumulates samples across render calls */
    SY_CAP_TILES = 1u << 2,       /**< renders any sub-rectangle exactly like the full image */
    SY_CAP_ANALYSIS = 1u << 3,    /**< draws an analysis image (e.g. object coverage), not the scene's look:
                                     comparisons of looks (sy compare) leave it out */
    SY_CAP_SAMPLE_RANGES = 1u << 4, /**< its samples split across renderers: renders with distinct seeds (or
                                       sample_first ranges) draw independent samples, and their images
                                       merged by sample count estimate the same pixel (cooperative) */
    SY_CAP_AOVS = 1u << 5,        /**< keeps feature buffers (variance, albedo, normal, ...): sy_context_aovs */
    SY_CAP_FILTERS = 1u << 6,     /**< display noise filters: sy_context_set_filter / sy_context_filter_info */
    SY_CAP_REMOTE = 1u << 7,      /**< renders on other machines (the cluster mediator) */
    SY_CAP_PREVIEW = 1u << 8,     /**< honours sy_render_request.preview: cheaper frames of lower fidelity
                                     while a view moves (fewer samples per pixel), on the same context */
    SY_CAP_COVERAGE = 1u << 9,    /**< counts the pixels each node covers, occlusion included: sy_context_coverage
                                     (a culling service asks it of whichever class offers it) */
} sy_mediator_caps;

/* ---- feature buffers (SY_CAP_AOVS) ---- */
#define SY_AOVS_MAX 16 /**< most planes in a sy_aovs */
/** One feature buffer plane. */
typedef struct sy_aov_plane {
    const char *name;  /**< "color", "depth", "variance", "albedo", "normal", ... (static storage) */
    uint32_t channels; /**< values per pixel */
    float *data;       /**< width*height*channels floats, row 0 = top; malloc()ed, owned by the sy_aovs */
} sy_aov_plane;
/** Feature buffers of a render (SY_CAP_AOVS). */
typedef struct sy_aovs {
    /** @{ size in pixels */
    uint32_t width, height; /** @} */
    uint64_t samples;           /**< samples per pixel accumulated */
    uint64_t nonfinite_samples; /**< samples replaced by zero because they were NaN/Inf */
    uint32_t count; /**< planes used */
    sy_aov_plane planes[SY_AOVS_MAX]; /**< the planes */
} sy_aovs;
void sy_aovs_free(sy_aovs *a); /**< frees every plane, zeroes the struct; NULL-safe */

/* ---- display filters (SY_CAP_FILTERS) ---- */
/** A display filter's state and its last run (SY_CAP_FILTERS). */
typedef struct sy_filter_info {
    char name[32];              /**< current filter, "none" when unfiltered */
    float threshold;            /**< current threshold */
    uint64_t frames;            /**< filtered frames so far */
    uint64_t nonfinite_pixels;  /**< last filtered frame: NaN/Inf input pixels kept out of neighbourhoods */
    uint64_t nonfinite_samples; /**< last filtered accumulation: NaN/Inf samples the back-end replaced by 0 */
    double seconds;             /**< last filter call's wall time */
    uint32_t last_pass_samples; /**< samples of the last filter pass (0 = none yet, or the filter runs every frame) */
    double mean_blend;          /**< mean share of the unfiltered image in the output (1 = unfiltered everywhere) */
} sy_filter_info;

/* ---- per-node coverage (SY_CAP_COVERAGE) ---- */
/** Pixels one node covers (sy_context_coverage). */
typedef struct sy_coverage_entry {
    uint32_t node_id; /**< the core node (sy_node.id) whose placement covers the pixels */
    uint32_t pixels;  /**< pixels it covers */
} sy_coverage_entry;

/** What a class's create receives. */
typedef struct sy_mediator_create_args {
    uint32_t root_node_id; /**< 0 = every root of the scene */
    const sy_params *params; /**< the context's parameters, checked against the class's param_table */
    const void *class_user; /**< the class's user pointer (sy_mediator_class.user) */
} sy_mediator_create_args;

/** Statistics of a mediator instance. */
typedef struct sy_mediator_stats {
    uint64_t samples;        /**< progressive: samples accumulated per pixel so far */
    /** @{ seconds of the last sync and the last render */
    double last_sync_seconds, last_render_seconds; /** @} */
} sy_mediator_stats;

/** A mediator class: the vtable and capabilities of one back-end kind (see docs/BACKENDS.md). */
typedef struct sy_mediator_class {
    const char *name; /**< "whitted", "pathtracer", "raster", ... */
    uint32_t caps;    /**< sy_mediator_caps every instance has */
    sy_result (*create)(const sy_mediator_create_args *args, void **state_out, sy_error *err); /**< creates an instance (its state) for args */
    void (*destroy)(void *state); /**< destroys an instance */
    /** Applies a change list (the first one is a snapshot). */
    sy_result (*sync)(void *state, const sy_changes *changes, sy_error *err);
    /** Fills layer (rect_w x rect_h) for the request. */
    sy_result (*render)(void *state, const sy_render_request *req, sy_layer *layer, sy_error *err);
    void (*stats)(void *state, sy_mediator_stats *out); /**< optional */
    /** Optional: the capabilities of an instance made with these parameters, when they depend on them
     * (the cluster: those of the servers' back-end in that mode); NULL = caps. */
    uint32_t (*caps_of)(const sy_params *params, const void *class_user);
    /** SY_CAP_AOVS: copies the feature buffers of the last render into out (caller frees). */
    sy_result (*aovs)(void *state, sy_aovs *out, sy_error *err);
    /** SY_CAP_FILTERS: sets the display filter ("none" turns it off) and its options; the info of the
     * filter now set. */
    sy_result (*set_filter)(void *state, const char *name, const sy_params *opts, sy_error *err);
    void (*filter_info)(void *state, sy_filter_info *out); /**< SY_CAP_FILTERS: the filter now set */
    /** SY_CAP_COVERAGE: per-node pixel coverage of view at width x height (sy_context_coverage). */
    sy_result (*coverage)(void *state, const sy_camera_view *view, uint32_t width, uint32_t height,
                          sy_coverage_entry **entries_out, uint32_t *count_out, sy_error *err);
    const void *user; /**< handed to create as class_user (a class registered at run time: its configuration) */
    /** The parameters an instance accepts: name, type, range or values, default, help (sy_params.h;
     * SY_PARAM_TABLE(array)). Core checks every context's parameters against it before create and
     * wherever they change later (sy_mediator_class_check_params), so create reads them through the
     * typed getters (sy_param_int, ...: declared defaults) and sees only declared, valid keys. An
     * empty table: the class accepts no parameter. */
    sy_param_table param_table;
    /** Optional: checks the given keys param_table does not declare (undeclared) instead of refusing
     * them; all holds every given key. The cluster checks the keys it forwards against the servers'
     * back-end. NULL: an undeclared key is an error listing the valid names. */
    sy_result (*check_params)(const sy_params *all, const sy_params *undeclared, const void *class_user,
                              sy_error *err);
    /** How strongly the class offers itself as the default back-end (sy_mediator_default): the
     * registered class of the highest rank above 0 is it; 0 (the default): never. The built-in
     * ones: raster 20 (the complete look, fastest), whitted 10. */
    int default_rank;
} sy_mediator_class;

/** Registry (process-wide; the one piece of global state). The class must outlive the process's
 * use of it (a static const struct). Registering a name twice replaces nothing and fails. */
sy_result sy_mediator_register(const sy_mediator_class *cls, sy_error *err);
/** The class registered under name, or NULL. */
const sy_mediator_class *sy_mediator_find(const char *name);
/** The default back-end: the registered class of the highest default_rank above 0 (the first
 * registered of equal ranks), or NULL when none offers itself. Every program's default (sy render,
 * sy view, sy web, sy compare) is this class. */
const sy_mediator_class *sy_mediator_default(void);
/** The name of sy_mediator_default's class, or "" when no class offers itself (a name no back-end
 * has, so that a lookup of it fails naming it). */
const char *sy_mediator_default_name(void);
/** The first registered class (registration order) whose caps hold every bit of caps, or NULL:
 * how a program finds a back-end by what it can do (sy_mediator_with_caps(SY_CAP_COVERAGE)). */
const sy_mediator_class *sy_mediator_with_caps(uint32_t caps);
/** Number of registered classes. */
uint32_t sy_mediator_count(void);
/** The i-th registered class (i < sy_mediator_count), or NULL. */
const sy_mediator_class *sy_mediator_at(uint32_t i);
/** Capabilities of an instance of cls made with params (NULL = none): cls->caps, or cls->caps_of for the parameters. */
uint32_t sy_mediator_class_caps(const sy_mediator_class *cls, const sy_params *params);
/** Checks params (NULL = none) against cls->param_table (and cls->check_params): an unknown key is
 * SY_ERR_INVALID_ARGUMENT naming it and the valid keys, a malformed value, one out of range or not
 * in the enum names the key, the value and what is allowed; every message names the back-end. The
 * one validation of back-end parameters: contexts, viewports and filters call it; an application
 * may too, to refuse bad input up front (sy render: a usage error). */
sy_result sy_mediator_class_check_params(const sy_mediator_class *cls, const sy_params *params, sy_error *err);
/** The class's parameters as a listing (sy_param_table_format; the same return convention). */
size_t sy_mediator_class_format_params(const sy_mediator_class *cls, const char *indent, char *buf, size_t len);

/* ---- contexts ---- */
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
#endif /* SY_MEDIATOR_H */
