/* sy_mediator_rt_internal.h — INTERNAL to mediators/rt (not installed): what the modules of the
 * core scene -> Embree back-end adapter (sy_mediator_rt.h) share: its state, the path tracer's
 * accumulation slots and display-filter configuration, and the functions one module calls in
 * another (prefix sy_rti_; none of them is API). The modules, bottom-up (each calls only those
 * before it; tests/core/layers_test.sh checks it), beside the radiance hook (sy_radiance_hook.c):
 *   sy_mediator_rt_base.c      the classes' parameter tables, error and camera translation
 *   sy_mediator_rt_mirror.c    the scene mirror's callbacks (bad input clamped) and the sync
 *   sy_mediator_rt_coverage.c  coverage: the image and the numbers (SY_CAP_COVERAGE); picks (SY_CAP_PICK)
 *   sy_mediator_rt_accum.c     the path tracer's accumulation slots
 *   sy_mediator_rt_filter.c    the path tracer's display filters (configuration, a filtered layer)
 *   sy_mediator_rt_radiance.c  the radiance filter's render (1-spp passes with path records)
 *   sy_mediator_rt_look.c      the resolved look (background, environment) on the device
 *   sy_mediator_rt_render.c    one render request; the benchmarks
 *   sy_mediator_rt.c           the classes: create, destroy, stats, AOVs, registration */
#ifndef SY_MEDIATOR_RT_INTERNAL_H
#define SY_MEDIATOR_RT_INTERNAL_H

#include "sy_mediator_rt.h"

#include "sy_backend_status.h"
#include "sy_rt.h"
#include "sy_mirror.h"
#include "sy_mirror_map.h"
#include "sy_highlight.h"

#include "sy_filter_adaptive.h"
#include "sy_filter_atrous.h"
#include "sy_filter_jbu.h"
#include "sy_filter_pixel.h"
#include "sy_filter_temporal.h"
#include "sy_radiance_hook.h"

#include <stdbool.h>
#include <stdint.h>

/* Path tracer: one accumulation per distinct request (camera, sizes, rectangle, background, seed);
 * a few are kept so that viewports sharing this context (stereo eyes, tiles) do not evict each
 * other. A slot restarts when the device published a change since its last pass. */
#define ACCUM_SLOTS 4
typedef struct accum_slot {
    sy_rt_accum *acc;
    sy_camera_view camera;
    uint32_t full_w, full_h, rect[4], bg, seed;
    uint64_t version;  /* device version the accumulation belongs to */
    uint64_t last_use;
    sy_filter_pixel *pixel;  /* pixel-filter state of this accumulation (display filter "pixel") */
    uint32_t pass_samples;   /* sample count of its last filter pass, 0 = none since the restart */
    sy_radiance_hook *radiance; /* radiance-filter state of this accumulation (display filter "radiance") */
} accum_slot;

/* Display filter of the path tracer (backends/filters), applied to the returned layer only: the
 * accumulation never sees it, so changing it never restarts sampling. */
typedef enum pt_filter_kind {
    PT_FILTER_NONE,
    PT_FILTER_PIXEL,
    PT_FILTER_ATROUS,
    PT_FILTER_JBU,
    PT_FILTER_ADAPTIVE,
    PT_FILTER_RADIANCE, /* not a display filter: it needs the path records of every 1-spp pass */
    PT_FILTER_KIND_COUNT
} pt_filter_kind;

typedef struct pt_filter_cfg {
    pt_filter_kind kind;
    sy_filter_pixel_params pixel;       /* threshold shared with adaptive */
    sy_filter_atrous_params atrous;
    sy_filter_jbu_params jbu;
    sy_filter_adaptive_params adaptive;
    sy_filter_radiance_params radiance; /* threshold T_u = the shared threshold */
    bool temporal;                      /* "temporal": reuse on frames whose camera or objects moved */
    bool temporal_motion;               /* "temporal_motion": object motion for the reprojection */
    bool temporal_deform;               /* "temporal_deform": per-vertex motion of deforming meshes */
} pt_filter_cfg;

/* The scene mirror (textures, materials, meshes, lights, backgrounds, nodes and placements) is
 * mediators/sy_mirror; this adapter turns its callbacks into Embree back-end calls. */
/* An instance's placement at each time step of a shutter of more than two steps (step 0 the open),
 * gathered over the armed syncs (sy_rti_motion, cb_instance). */
/* An instance moved since the last path-traced render (temporal reuse's object motion): its world
 * matrix then, and (ready) prev x now^-1, the map of this render's points to their earlier places. */
typedef struct rt_move_rec {
    float prev[16];
    sy_mat4 to_prev;
    bool ready;
} rt_move_rec;

/* A mesh deformed since the last path-traced render (temporal reuse's per-vertex motion): its
 * positions at that render, copied from the device before its first update since (cb_primitive
 * update). A record not refreshed since the render before (its mesh stopped deforming) is freed at
 * the next render; a fresh one keeps its buffer for the next copy. */
typedef struct rt_deform_rec {
    float *prev;           /* float3 x vertex_count, own */
    uint32_t vertex_count;
    bool fresh;            /* copied since the last render */
} rt_deform_rec;

typedef struct rt_motion_rec {
    float xf[SY_MOTION_STEPS_MAX][16];
} rt_motion_rec;

typedef struct rt_state {
    sy_rt_device *dev;
    /* the message of the device's last failed call: its error callback (sy_rti_device_desc) writes
     * it on the thread of the call in progress, which is the only thread using the device */
    char rt_msg[SY_ERROR_MESSAGE_MAX];
    sy_mirror *mirror;
    uint32_t integrator;
    uint32_t max_depth, light_samples;
    uint32_t light_tree; /* sy_rt_light_tree_mode (the light_tree parameter) */
    uint32_t light_warnings_seen; /* the device's light_warnings already logged */
    uint32_t pixel_samples, env_samples; /* whitted: "spp", "env_samples" */
    float specular; /* "specular" parameter: KHR_materials_specular factor given to every material */
    /* the look (sy_look.h) applied to the device, with the back-end textures it resolved to */
    sy_look look;
    bool look_applied;
    uint32_t look_env_tex, look_bg_tex;
    sy_rt_texture studio;   /* the built-in studio environment, made on first use */
    sy_rt_texture gradient; /* the baked sky/ground gradient of the current look, 0 = none */
    sy_gradient gradient_baked;
    sy_mediator_rt_counters counters;
    uint64_t frames_rendered;
    accum_slot slots[ACCUM_SLOTS]; /* path tracer only */
    int last_slot;                 /* slot of the last render, -1 = none */
    uint64_t use_clock;
    sy_mirror_map inst_node;       /* back-end instance slot index + 1 -> core node id (coverage) */
    sy_mirror_map inst_sel;        /* the same keys, only the selected instances (uint8_t 1; sy_highlight.h) */
    sy_mirror_map inst_place;      /* the same keys -> the placement (ID AOVs) */
    sy_rt_camera last_cam;         /* the camera and rectangle of the last render (ID AOVs) */
    sy_rt_render_desc last_desc;
    pt_filter_cfg filter;          /* path tracer display filter */
    float *fbuf[SY_RT_AOV_COUNT + 1]; /* filter inputs: the AOV planes + world positions */
    size_t fbuf_px;                /* pixels the fbuf planes hold */
    float *fcol;                   /* per column of the rectangle: its pixel centres' window x (positions) */
    size_t fcol_cap;
    sy_mediator_rt_filter_info finfo; /* last filtered frame */
    /* temporal reuse (filter.temporal): one history per context, fed by every path-traced render
     * whose camera differs from the previous render's (temporal_cam), or (filter.temporal_motion)
     * whose scene changed since only by moves (sy_rti_temporal_moving) */
    sy_filter_temporal *temporal;
    sy_camera_view temporal_cam;
    bool temporal_have_cam;
    bool temporal_rest; /* this render's camera rests and its accumulation continues: blend (sy_rti_temporal_rest) */
    /* object motion for temporal reuse: the device version of the last render (temporal_version);
     * the versions move_from .. move_to that syncs published with moves only (instance transforms,
     * visibility, deformed vertices: sync_other false), 0 .. 0 when the last change was anything else;
     * temporal_from: per instance handle moved since the last render, its world matrix then
     * (rt_move_rec; recorded only while filter.temporal is on); the coverage ids and motion planes */
    uint64_t temporal_version, move_from, move_to;
    bool sync_other;
    sy_mirror_map temporal_from;
    uint32_t *motion_ids;
    float *motion_buf;
    size_t motion_px;
    /* per-vertex motion (filter.temporal_deform): per rt mesh handle deformed since the last render,
     * its positions then (rt_deform_rec; temporal_fresh of them copied since the last render); the
     * coverage hits (instance, triangle, barycentrics) of the renders that have some */
    sy_mirror_map temporal_deform;
    uint32_t temporal_fresh;
    sy_rt_coverage_hit *motion_hits;
    size_t motion_hits_px;
    /* motion blur (SY_CAP_MOTION, sy_rti_motion): MOTION_ARMED between BEGIN and OPENED (the sync in
     * between gives each moved instance its close transform), MOTION_ON until END */
    enum { MOTION_OFF, MOTION_ARMED, MOTION_ON } motion;
    uint32_t motion_samples;  /* Whitted's time samples per pixel (sy_rt_render_desc.time_samples) */
    bool motion_other;        /* the armed sync made a mesh or moved a light: not interpolated */
    uint32_t motion_instances; /* instances given motion by the armed sync */
    uint32_t motion_meshes;   /* deformed meshes given motion (two vertex time steps) by the armed sync */
    uint32_t motion_steps;    /* time steps of the shutter (SY_MOTION_STEPS): 2, or 3 .. SY_MOTION_STEPS_MAX */
    uint32_t motion_k;        /* while armed with more than two steps: the step the coming sync is at */
    sy_mirror_map motion_rec; /* while armed with more than two steps: instance handle -> rt_motion_rec */
    uint32_t motion_cam_count; /* MOTION_ON: the moving cameras given (sy_rti_motion_camera; a stereo pair: 2) */
    struct rt_motion_cam {
        sy_camera_view open; /* a request with this camera (the shutter's open) moves it ... */
        sy_rt_camera close;  /* ... to this one at its close (sy_rt_render_desc.camera_close) */
        uint32_t steps;      /* ... through these between (camera_mid, camera_steps) */
        sy_rt_camera mid[SY_MOTION_STEPS_MAX];
    } motion_cams[SY_MOTION_CAMERAS_MAX];
} rt_state;

/* --- sy_mediator_rt_base.c --- */
/* The classes' parameter tables (sy_params.h); the counts are checked where they are defined. */
#define SY_RTI_WHITTED_PARAM_COUNT 8
#define SY_RTI_COVERAGE_PARAM_COUNT 5
#define SY_RTI_PATHTRACER_PARAM_COUNT 29
#ifndef SY_RTI_DEFINING_PARAMS
extern const sy_param_decl sy_rti_whitted_params[SY_RTI_WHITTED_PARAM_COUNT];
extern const sy_param_decl sy_rti_coverage_params[SY_RTI_COVERAGE_PARAM_COUNT];
extern const sy_param_decl sy_rti_pathtracer_params[SY_RTI_PATHTRACER_PARAM_COUNT];
#endif
extern const sy_param_table sy_rti_whitted_table, sy_rti_coverage_table, sy_rti_pt_table;
/* A failed call on st's device as an sy_error: the code cast (sy_backend_status.h) and "WHAT: MSG",
 * MSG being what the device reported through its error callback. */
sy_result sy_rti_fail(const rt_state *st, sy_error *err, sy_rt_result r, const char *what);
/* The device options that report the device's errors into st->rt_msg. */
sy_rt_device_desc sy_rti_device_desc(rt_state *st, uint32_t threads, uint64_t max_memory_bytes);
void sy_rti_camera_of(const sy_camera_view *v, sy_rt_camera *cam);

/* --- sy_mediator_rt_mirror.c --- */
extern const sy_mirror_callbacks sy_rti_mirror_callbacks;
/* The node an instance belongs to (0: unknown). */
uint32_t sy_rti_inst_node_get(const rt_state *st, uint32_t handle);
/* Whether an instance is selected (highlighted, sy_highlight.h). */
bool sy_rti_inst_selected(const rt_state *st, uint32_t handle);
/* Placement of an instance (which of its node's paths; 0 when unknown), as picks report it. */
uint32_t sy_rti_inst_placement_get(const rt_state *st, uint32_t handle);
sy_result sy_rti_sync(void *state, const sy_changes *changes, sy_error *err);
/* SY_CAP_MOTION (sy_mediator_class.motion): the phases of a motion-blurred render. */
sy_result sy_rti_motion(void *state, sy_motion_phase phase, uint32_t time_samples, bool *native, sy_error *err);
/* SY_CAP_MOTION (sy_mediator_class.motion_camera): the camera at the shutter's close. */
sy_result sy_rti_motion_camera(void *state, const sy_camera_view *open, uint32_t steps, const sy_camera_view *later,
                               sy_error *err);

/* --- sy_mediator_rt_coverage.c --- */
sy_result sy_rti_coverage_render(rt_state *st, const sy_rt_camera *cam, const sy_rt_render_desc *d, sy_layer *layer,
                                 sy_error *err);
sy_result sy_rti_coverage(void *state, const sy_camera_view *view, uint32_t width, uint32_t height,
                          sy_coverage_entry **entries_out, uint32_t *count_out, sy_error *err);
/* SY_CAP_PICK (sy_context_pick): one ray through the pixel's centre (sy_rt_pick). */
sy_result sy_rti_pick(void *state, const sy_camera_view *view, uint32_t width, uint32_t height, uint32_t x, uint32_t y,
                      sy_pick_result *out, sy_error *err);

/* --- sy_mediator_rt_accum.c --- */
sy_result sy_rti_pt_slot(rt_state *st, const sy_render_request *req, sy_error *err);
void sy_rti_pt_restart(void *state); /* sy_context_restart: every slot restarts at its next request */
/* true when two camera views are the same (matrix, projection, window, planes) */
bool sy_rti_same_view(const sy_camera_view *a, const sy_camera_view *b);

/* --- sy_mediator_rt_filter.c --- */
void sy_rti_filter_cfg_default(pt_filter_cfg *c, uint32_t threads);
sy_result sy_rti_filter_cfg_apply(pt_filter_cfg *base, const char *name, const sy_params *p_in, bool all, sy_error *err);
/* The slot's feature buffers into st->fbuf (the variance with `variance`; the world positions, the
 * last plane, with `positions`): one pass, rows split over the filters' threads. */
sy_result sy_rti_filter_read_aovs(rt_state *st, const accum_slot *a, const sy_render_request *req, bool variance,
                                  bool positions, sy_error *err);
sy_result sy_rti_filter_layer(rt_state *st, const sy_render_request *req, sy_layer *layer, sy_error *err);
/* Temporal reuse after a path-traced render of `samples` samples into the slot st->last_slot: when
 * st->filter.temporal is on, the accumulation holds only this render's samples and the camera moved
 * since the previous render, or only instances moved (sy_rti_temporal_moving; their motion given to
 * the filter per pixel), writes the estimate into layer and sets *done; otherwise leaves the
 * layer alone (*done false). Records the camera either way. */
sy_result sy_rti_temporal_layer(rt_state *st, const sy_render_request *req, uint32_t samples, sy_layer *layer,
                                bool *done, sy_error *err);
/* Temporal reuse's per-vertex motion: keeps the pose of the rt mesh `mesh` at the last render
 * (copied from the device) before the sync rewrites its vertices; called by cb_primitive_update. */
void sy_rti_temporal_deform_record(rt_state *st, uint32_t mesh);
/* Frees temporal reuse's state (the filter, the moved instances' matrices, the deformed meshes' earlier poses, the motion planes);
 * the context's destroy calls it. */
void sy_rti_temporal_free(rt_state *st);
/* Whether a path-traced render of req is a moving frame for temporal reuse: the camera moved since
 * the previous render, or only instances moved since (object motion); false while it is off. */
bool sy_rti_temporal_moving(const rt_state *st, const sy_render_request *req);
/* After the display filter of a render that sy_rti_temporal_layer left alone: while the camera rests
 * after moving frames, the layer (the accumulation) blended with the last temporal estimate until the
 * accumulation takes over (sy_filter_temporal_rest). */
void sy_rti_temporal_rest(rt_state *st, const sy_render_request *req, sy_layer *layer);

/* --- sy_mediator_rt_radiance.c --- */
sy_result sy_rti_radiance_render(rt_state *st, const sy_render_request *req, const sy_rt_camera *cam,
                                 sy_rt_render_desc *d, sy_layer *layer, sy_error *err);

/* --- sy_mediator_rt_look.c --- */
sy_result sy_rti_apply_look(rt_state *st, uint32_t background_id, sy_error *err);

/* --- sy_mediator_rt_render.c --- */
/* The selection flags (sy_highlight.h) of rectangle m of a full_w x full_h image: m.w * m.h bytes,
 * malloc()ed; NULL when out of memory or the device failed (then the frame goes unhighlighted). */
uint8_t *sy_rti_selection_flags(rt_state *st, const sy_rt_camera *cam, uint32_t full_w, uint32_t full_h,
                                sy_highlight_rect m);
/* Logs the device's light warnings not logged yet (sy_mediator_rt_render.c). */
void sy_rti_log_light_warnings(rt_state *st);
sy_result sy_rti_render(void *state, const sy_render_request *req, sy_layer *layer, sy_error *err);

#endif
