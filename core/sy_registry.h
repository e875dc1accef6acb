/** @file
 * sy_registry.h — mediator classes and their registry: the vtable a back-end registers by name,
 * its typed capabilities (SY_CAP_*) with the feature buffers, display filters and coverage they
 * offer, and the calls that find a class by name, by default rank or by capabilities.
 * Thread-safety: the registry is safe to use from any thread (mutex); classes are static data. */
#ifndef SY_REGISTRY_H
#define SY_REGISTRY_H

#include "sy_changes.h"
#include "sy_layer.h"
#include "sy_params.h"
#include "sy_request.h"

#ifdef __cplusplus
extern "C" {
#endif

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
    SY_CAP_PICK = 1u << 10,       /**< answers what is under a pixel (node, mesh, primitive, triangle, position,
                                     normal, material): sy_context_pick, sy_viewport_pick */
    SY_CAP_MOTION = 1u << 12,     /**< motion blur in one render: instances move over the shutter, each ray at its
                                   * own time (sy_context_motion_begin / _open / _end; the class's motion hook) */
    SY_CAP_CLIP = 1u << 11,       /**< honours the view's section planes (sy_camera_view.clip_planes) in renders,
                                     picks and coverage; a view with planes is refused (SY_ERR_UNSUPPORTED)
                                     by a class without it */
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

/* ---- picking (SY_CAP_PICK) ---- */
/** What is under one pixel (sy_context_pick, sy_viewport_pick, sy_window_pick): the nearest surface
 * the ray through the pixel's centre meets, as the back-end draws it. Plain data. On a miss `hit` is
 * false and every other field but the viewport's (viewport, eye, pixel) is zero. */
typedef struct sy_pick_result {
    bool hit;               /**< a surface is under the pixel */
    uint32_t viewport;      /**< window picks: index of the viewport that answered (back to front), UINT32_MAX = none */
    uint32_t eye;           /**< that viewport's eye (sy_eye) */
    /** @{ the pixel in the viewport's own rectangle (row 0 = top) */
    uint32_t pixel_x, pixel_y; /** @} */
    uint32_t node_id;       /**< the core node (sy_node.id) whose mesh was hit */
    uint32_t placement;     /**< which of the node's placements (DAG paths, in the mirror's order) */
    uint32_t mesh_id;       /**< the node's mesh (sy_mesh.id) */
    uint32_t primitive;     /**< the primitive's index in the mesh */
    uint32_t triangle;      /**< the triangle's index in the primitive (strokes: in their tessellation) */
    /** Barycentric weights of the triangle's vertices 0, 1 and 2 at the hit (sum 1). */
    float barycentrics[3];
    float position[3];      /**< world position of the hit */
    /** Unit geometric normal of the triangle in world space, on its front side as glTF defines it
     * (counter-clockwise in object space; a mirroring world matrix keeps it the front), whichever
     * side was seen. */
    float normal[3];
    uint32_t material_id;   /**< the primitive's material (sy_material.id); 0 = the default material */
    float distance;         /**< from the ray's origin (the eye; orthographic: the image plane) to the hit */
    float depth;            /**< along the viewing axis (what the layer's depth plane holds) */
    /** 0, or 1 + the index of the section plane whose cap the pick hit (a capped view,
     * sy_viewport_set_clip_cap: the ray met a closed mesh's back face after entering the kept region
     * through that plane); then position, distance and depth are the cap's point on the plane and
     * normal is the plane's, facing the eye; node, mesh, primitive and material are the solid's,
     * triangle and barycentrics the back face's. */
    uint32_t cap_plane;
} sy_pick_result;

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

/** The phases of a motion-blurred render (SY_CAP_MOTION, sy_mediator_class.motion). */
typedef enum sy_motion_phase {
    SY_MOTION_BEGIN = 1,  /**< synced at the shutter's close; the next sync is its open */
    SY_MOTION_OPENED = 2, /**< the sync at the open is done */
    SY_MOTION_END = 3,    /**< motion off */
    SY_MOTION_STEPS = 4,  /**< right after BEGIN: the shutter has time_samples (3 .. SY_MOTION_STEPS_MAX)
                           * equally spaced time steps; the syncs until OPENED come from the close
                           * towards the open, each followed by SY_MOTION_STEP, the last by OPENED */
    SY_MOTION_STEP = 5,   /**< the sync of an intermediate time step is done; the next is the step before */
} sy_motion_phase;

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
    /** SY_CAP_PICK: what is under pixel (x, y) (x < width, y < height) of view rendered at width x
     * height, as last synced: fills out's hit and node .. depth fields (sy_context_pick). Optional;
     * appended last so classes that set fields by name need no change. */
    sy_result (*pick)(void *state, const sy_camera_view *view, uint32_t width, uint32_t height, uint32_t x,
                      uint32_t y, sy_pick_result *out, sy_error *err);
    /** Optional (sy_context_restart): the next render is what a new instance holding the same scene
     * renders: progressive back-ends start new accumulations (sample 0, the request's seed) even where
     * nothing visible changed; back-ends with fast paths for moves (the ray tracers' twin instances)
     * place the next sync's moves as a fresh build does. NULL: nothing to do. */
    void (*restart)(void *state);
    /** SY_CAP_MOTION (sy_context_motion_begin, _open, _end): phase SY_MOTION_BEGIN: what the instance
     * has synced is the scene at the shutter's close; the next sync brings the scene at its open, and
     * every instance it moves is to be placed there at ray time 0 and where it was (the close) at
     * time 1. SY_MOTION_OPENED: that sync is done; *native (not NULL here) false when it brought
     * changes the class cannot interpolate (deformed meshes, moved lights: the caller then ends the
     * motion and blurs by sub-frames). SY_MOTION_END: no motion any more (every instance stays where
     * the last sync put it; native NULL). time_samples: BEGIN's wish for samples per pixel of the
     * integrators that take a fixed number (0: the class's default). SY_MOTION_STEPS and
     * SY_MOTION_STEP (curved motion, sy_context_motion_begin_steps / sy_context_motion_step): a
     * class that does not take more than two steps returns SY_ERR_UNSUPPORTED for STEPS. Optional;
     * appended last. */
    sy_result (*motion)(void *state, sy_motion_phase phase, uint32_t time_samples, bool *native, sy_error *err);
    /** SY_CAP_MOTION, optional (sy_context_motion_camera): while in motion (after SY_MOTION_OPENED),
     * a request whose camera is open is rendered with each camera ray built at its own time between
     * open and later[steps - 2] (the shutter's close) through later[0 .. steps - 3] (the equally
     * spaced steps between; steps 2 .. SY_MOTION_STEPS_MAX), until SY_MOTION_END; requests with
     * another camera stay still. Another open adds a camera (stereo eyes; up to SY_MOTION_CAMERAS_MAX,
     * then SY_ERR_INVALID_ARGUMENT), the same open replaces its steps. NULL: the class does not interpolate the camera (the caller blurs a
     * moving camera by sub-frames). Appended last. */
    sy_result (*motion_camera)(void *state, const sy_camera_view *open, uint32_t steps, const sy_camera_view *later,
                               sy_error *err);
} sy_mediator_class;

/** Registry (process-wide; the one piece of global state). The class must outlive the process's
 * use of it (a static const struct). Registering a name twice replaces nothing and fails. */
sy_result sy_mediator_register(const sy_mediator_class *cls, sy_error *err);
/** The class registered under name, or NULL. */
const sy_mediator_class *sy_mediator_find(const char *name);
/** The class registered under name; NULL with *err SY_ERR_NOT_FOUND "back-end 'NAME' is not
 * registered (available: the registered names)" when there is none. */
const sy_mediator_class *sy_mediator_require(const char *name, sy_error *err);
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

#ifdef __cplusplus
}
#endif
#endif /* SY_REGISTRY_H */
