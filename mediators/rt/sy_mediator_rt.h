/** @file
 * sy_mediator_rt.h — the mediator between the core scene and the Embree back-end (backends/rt).
 *
 * One Embree scene adapter serving several integrators: the "whitted" and "pathtracer" classes
 * registered here and "coverage" share this adapter; only the integrator chosen at render
 * time differs. The adapter keeps a mirror of the node graph built from change lists, flattens it
 * (one world transform per geometry placement; a DAG node reached along k paths gets k placements),
 * bakes geometry of nodes flagged SY_NODE_STATIC whose mesh is used once into the top-level BVH,
 * instances everything else (shared meshes are one BLAS), and syncs incrementally: a transform
 * change re-places the node's subtree only (rtcSetGeometryTransform, no BLAS rebuild).
 *
 * Parameters (sy_params; declared in each class's param_table, which core checks and `sy backends
 * --params` prints: the authority for names, ranges and defaults): max_depth (1..64, default 8;
 * pathtracer 1..1024, default 64),
 * light_samples (whitted: area-light samples per pixel, shared among its pixel samples; 1..1024,
 * default 16), threads (0 = all cores), specular (0..1, default 1: the KHR_materials_specular factor
 * of every material; 1 is glTF's dielectric F0 = 0.04 layer, 0 makes dielectrics pure Lambertian,
 * e.g. to match a Lambertian reference render). Whitted only: spp (anti-aliasing camera rays per
 * pixel, stratified jittered, box filter; 1..256, default 4; 1 = the pixel centre) and env_samples
 * (environment-light samples per shading point of each pixel sample; 1..256, default 4).
 *
 * The look (sy_look.h) is resolved by the scene mirror on every render (sy_mirror_look with the
 * request's background id) and applied to the device when it changed: the background is what
 * camera rays that hit nothing see (none, colour, the environment texture, or the world's gradient
 * baked into a small lat-long texture); the environment light (the world's texture, or the built-in
 * studio when the scene brings no light) is what every other escaping ray sees and is sampled as a
 * light. A change restarts progressive accumulation.
 *
 * Ownership/thread-safety: as any mediator (see core/sy_mediator.h). */
#ifndef SY_MEDIATOR_RT_H
#define SY_MEDIATOR_RT_H

#include "sy_mediator.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Registers whitted, pathtracer and coverage (the build's registration list calls it). */
sy_result sy_mediator_rt_register(sy_error *err);
/** The Whitted ray tracer class ("whitted"). Static storage. */
const sy_mediator_class *sy_mediator_rt_whitted_class(void);
/** The coverage class ("coverage"; caps DEPTH | TILES | ANALYSIS | COVERAGE): no shading; the layer
 * shows every visible object in a stable colour derived from its node id (alpha 1 where covered)
 * with depth. A culling service: which objects a camera sees and how many pixels each covers, with
 * occlusion (sy_context_coverage, SY_CAP_COVERAGE in core/sy_mediator.h). */
const sy_mediator_class *sy_mediator_rt_coverage_class(void);

/** The progressive path tracer class ("pathtracer"; caps PROGRESSIVE | DEPTH | TILES) on the same
 * adapter. Each render adds req->sample_count samples per pixel (0 = 1) to an accumulation kept per
 * distinct request (camera view, image size, rectangle, background, seed; up to 4 at once, least
 * recently used recycled). The accumulation restarts when the request's camera differs from the
 * last one or when a sync changed anything the back-end sees (transforms of placed geometry or
 * lights, meshes, materials, textures, lights, the background); changes nobody sees (attachments,
 * names, a camera no request uses) keep it. sy_mediator_stats.samples = samples so far of the last
 * render. req->sample_first is ignored: samples are numbered by the accumulation itself, and a
 * different req->seed gives an independent stream (cooperative cluster rendering relies on that).
 * sy_context_restart restarts every accumulation at the next request (sample 0), changed or not.
 * Whitted and the path tracer have SY_CAP_MOTION (sy_context_motion_begin / _open / _end): while in
 * motion, each pixel sample has its own time and the instances moved and the meshes deformed between
 * the two syncs are interpolated per ray, and so is a camera given at the close with
 * sy_context_motion_camera (docs/BACKENDS.md "Motion blur in one render").
 * Parameters: max_depth (bounces, 1..1024, default 64), specular, threads. */
const sy_mediator_class *sy_mediator_rt_pathtracer_class(void);

/** Feature buffers of the last path-traced render of a context (its rectangle), as separate planes
 * indexed like the back-end's sy_rt_aov: 0 colour RGBA (4 channels), 1 variance of the colour mean
 * RGB (Welford), 2 albedo and 3 normal of the first non-specular hit, 4 depth (1), 5 direct and
 * 6 indirect radiance (3 each). Ownership: the caller frees with sy_mediator_rt_aovs_free. */
#define SY_MEDIATOR_RT_AOV_COUNT 7
/** Feature buffers (see above). */
typedef struct sy_mediator_rt_aovs {
    /** @{ rectangle size and samples per pixel */
    uint32_t width, height, samples; /** @} */
    uint64_t nonfinite_samples; /**< samples replaced by zero because they were NaN/Inf */
    float *planes[SY_MEDIATOR_RT_AOV_COUNT]; /**< width*height*channels floats each, row 0 = top */
} sy_mediator_rt_aovs;
/** Copies the feature buffers of the context's last path-traced render into *out. */
sy_result sy_mediator_rt_aovs_get(void *state, sy_mediator_rt_aovs *out, sy_error *err);
/** Frees the planes of *aovs (NULL-safe). */
void sy_mediator_rt_aovs_free(sy_mediator_rt_aovs *aovs);
const char *sy_mediator_rt_aov_name(uint32_t index);   /**< "color", "variance", "albedo", ... */
uint32_t sy_mediator_rt_aov_channels(uint32_t index);  /**< 4, 3, 3, 3, 1, 3, 3 */

/** Display filter of the path tracer (backends/filters), applied per viewport to the layer the path
 * tracer returns, computed from the accumulation's feature buffers; per accumulation slot (the
 * pixel filter's state restarts with the slot's accumulation). Display-only: changing the filter
 * or its options never restarts the accumulation. Parameters (at creation, the initial value):
 *   filter=none|pixel|atrous|jbu|adaptive|radiance (default none). "radiance" (Schwenk 2013 ch. 4)
 *     is not a pure display filter: it runs on the path tracer's stored-sample hook (per-pixel path
 *     records, sy_radiance_hook.h); every sample of a request is its own 1-spp pass and filter
 *     frame, the accumulation still receives every sample, and switching to it resumes from the
 *     accumulation (seeded with its mean and variance)
 *   threshold=T   perceived-variance threshold t of the pixel filter's blend, of the adaptive
 *                 preview and the radiance filter's T_u (default 0.01, >= 0; adaptive and radiance
 *                 need > 0)
 *   rf_warmup_frames (0..64, default 4), rf_warmup_radius (pixels, > 0, default 8), rf_max_radius
 *   (1..128, default 24), rf_kernel=epanechnikov|silverman|uniform|gaussian, rf_ao=0|1 (default 1),
 *   rf_prism_thickness (prism half thickness / tangent extent, > 0, default 0.25),
 *   rf_grazing_epsilon (> 0, default 0.1), rf_glossy_limit (default 128), rf_specular_limit
 *   (default 4096), rf_unbiased=0|1 (show the plain path-traced mean in the correction phase,
 *   default 0): the radiance filter's options, checked whatever the filter
 *   sigma_s (pixels, default 8), sigma_c (virtual-flash colour, default 0.02), sigma_d (depth, scene
 *   units, default 2): the pixel filter's cross-bilateral kernel (> 0)
 *   filter_kernel=separable|brute (default separable), filter_iterations (1..8, default 3),
 *   filter_start (first filter pass at this sample count, a power of two, default 4; then at every
 *   power of two), atrous_iterations (1..10, default 5), jbu_factor (1..64, default 4).
 *   temporal=0|1 (default 0): temporal reuse on frames whose camera moved (sy_filter_temporal.h):
 *   a render whose camera differs from the previous render's and whose accumulation restarted
 *   draws its samples with a seed of its own and returns the reprojected, blended and filtered
 *   estimate (the display filter does not run on it); a render whose camera did not move returns
 *   the accumulation (or the display filter's image), blended with the last estimate while the
 *   camera rests after moving frames, until the accumulation takes over alone at 64 samples
 *   (sy_filter_temporal_rest: no pop when the camera stops; a camera that never moved, or 64
 *   samples on, is the accumulation bit for bit). sy view and sy web set it
 *   (sy_interactive_set_temporal); turning it off forgets the history.
 *   temporal_motion=0|1 (default 1): temporal reuse follows moving instances: a sync that changed
 *   only instance transforms (or visibility, or deformed vertices) since the previous render makes
 *   that render a moving frame under a still camera too (instead of restarting the history), and
 *   every moving frame gives the filter per-pixel object motion (the instance under each pixel
 *   centre, sy_rt_coverage, and M_prev M_now^-1 p - p at its world position p; unmoved instances
 *   0). 0: the camera's motion alone, as before (the baseline of
 *   tests/integration/test_pathtracer_motion.c).
 *   temporal_deform=0|1 (default 1): with temporal_motion, deformed (skinned, morphed) meshes too:
 *   their pose at the previous render is kept (a copy of the device's vertices before their first
 *   update since, only for meshes that deform), and a pixel whose first hit is on one gets the
 *   hit's motion from it (sy_rt_coverage_hits: its triangle and barycentrics; M_prev x_prev - M_now
 *   x_now). 0: their pixels get no motion, as before (the baseline of
 *   tests/integration/test_pathtracer_deform.c).
 * sy_mediator_rt_set_filter changes it live: name (NULL = opts' "filter" or unchanged) and the keys
 * present in opts (NULL = none; absent keys keep their values). Only the threshold keeps the pixel
 * filter's filtered buffer; any other change recomputes it at the next frame. On error nothing
 * changes. Thread-safety: like render (the thread that renders the context). */
sy_result sy_mediator_rt_set_filter(void *state, const char *name, const sy_params *opts, sy_error *err);

/** The path tracer's current display filter and its last run. */
typedef struct sy_mediator_rt_filter_info {
    const char *name;           /**< current filter ("none", "pixel", ...), static storage */
    float threshold;            /**< current threshold */
    uint64_t frames;            /**< filtered frames so far */
    uint64_t nonfinite_pixels;  /**< last filtered frame: NaN/Inf input pixels kept out of neighbourhoods
                                   (radiance: NaN/Inf path records over the last render's passes) */
    uint64_t nonfinite_samples; /**< last filtered accumulation: NaN/Inf samples the back-end replaced by 0 */
    double seconds;             /**< last filter call's wall time (radiance: its frames in the last render) */
    bool filter_pass;           /**< pixel: a filter pass ran in the last frame */
    double mean_blend;          /**< pixel: mean blend factor s (1 = unfiltered everywhere); radiance:
                                   share of pixels in the correction phase (plain path tracing) */
    uint32_t last_pass_samples; /**< pixel: sample count of the last filter pass (0 = none yet) */
    bool temporal;              /**< the "temporal" parameter: reuse on frames whose camera moved */
    bool temporal_last;         /**< the last render showed the temporal estimate (its camera or, with
                                     temporal_motion, only its instances moved) */
    uint64_t temporal_frames;   /**< frames that showed the temporal estimate so far */
    double temporal_seconds;    /**< the last such frame's temporal stage (AOV read + filter), wall time */
    double temporal_filter_cpu_seconds; /**< of it: the filter's CPU time (all threads; sy_filter_temporal_stats) */
    double temporal_read_seconds;   /**< of it: reading the feature buffers and their world positions (wall) */
    double temporal_filter_seconds; /**< of it: the filter call (wall; sy_filter_temporal_run) */
    double temporal_phase_seconds[4]; /**< the filter call's phases (sy_filter_temporal_stats.phase_seconds) */
    double temporal_reused;     /**< the last such frame: share of hit pixels with a reprojected history */
    bool temporal_rest_last;    /**< the last render rested after moving frames: the accumulation blended
                                     with the last estimate (sy_filter_temporal_rest) */
    double temporal_motion_seconds;  /**< the last render: wall time of its object motion (coverage rays + the
                                          per-pixel motion), 0 when no instance moved */
    double temporal_motion_trace_seconds; /**< of it: the coverage rays (sy_rt_coverage, or sy_rt_coverage_hits
                                               when some mesh deformed); the rest is the per-pixel motion */
    uint64_t temporal_moving_pixels; /**< the last render: pixels given a non-zero object motion */
    uint64_t temporal_deformed_pixels; /**< of them: pixels of deformed meshes given per-vertex motion (temporal_deform) */
} sy_mediator_rt_filter_info;
/** Fills *out with the context's filter state. */
void sy_mediator_rt_filter_info_get(void *state, sy_mediator_rt_filter_info *out);

/** Counters of the adapter, for tests and benchmarks. */
typedef struct sy_mediator_rt_counters {
    /** @{ live back-end objects (baked instances are merged into the top-level BVH) */
    uint32_t instances, baked_instances, meshes, materials, textures, lights; /** @} */
    uint32_t last_sync_placements; /**< node placements recomputed by the last sync */
    uint32_t last_sync_entries;    /**< change entries handled by the last sync */
    double last_sync_top_commit_seconds; /**< of the last sync: Embree's rebuild of the top-level BVH
                                          * (rtcCommitScene over every instance; 0 when not needed) */
    /** @{ of the last sync: the mirror's deformation of skinned / morphed meshes, and the updates of
     * their vertices in the device (copy + BVH refit, sy_rt_mesh_update; sy_mirror_sync_stats) */
    double last_sync_deform_seconds, last_sync_refit_seconds; /** @} */
    /** @{ of the last sync: primitive instances given a deformed pose, and of them the poses another
     * context's mirror had deformed already (shared, not deformed again: sy_deform_cache.h) */
    uint32_t last_sync_deformed, last_sync_deform_shared; /** @} */
    uint32_t accum_restarts;       /**< path tracer: accumulations restarted (not counting the first) */
    uint64_t last_render_rays;     /**< path tracer: rays traced by the last render */
    uint32_t warnings;             /**< out-of-range material / light values clamped (each also logged:
                                    * sy_log, module "rt", item "material|light ID") */
    char last_warning[160]; /**< the last warning */
    /** @{ memory of the back-end (sy_rt_stats): mesh arrays it copied, mesh arrays it shares with
     * the scene's blobs, Embree's allocations now and at their peak */
    uint64_t mesh_bytes, shared_bytes, embree_bytes, embree_peak_bytes; /** @} */
    /** @{ the light tree (light_tree parameter; sy_rt_stats): lights in it, bytes it holds, seconds
     * of its last full build and of its last refit, lights that refit changed, builds and refits */
    uint32_t light_tree_lights;
    uint64_t light_tree_bytes;
    double light_tree_build_seconds, light_tree_refit_seconds;
    uint32_t light_tree_refit_changed;
    uint64_t light_tree_builds, light_tree_refits; /** @} */
} sy_mediator_rt_counters;
/** state is the mediator state of a context whose class is one of this adapter's classes. */
void sy_mediator_rt_counters_get(void *state, sy_mediator_rt_counters *out);
/** The top level's dynamic LOW-quality builder when most instances move (sy_rt_set_top_fast; default
 * off: slower with Embree 3.13; sy bench anim compares it). state as sy_mediator_rt_counters_get. */
void sy_mediator_rt_set_top_fast(void *state, bool on);

/** Ray throughput of this adapter's device on the given view (see backends/rt/sy_rt_bench.h):
 * our PRIMARY integrator against raw rtcIntersect1 on the same rays, in one run. */
typedef struct sy_mediator_rt_bench {
    /** @{ primary rays per second (ours, raw Embree, in millions) and our overhead */
    double ours_mrays, raw_mrays, overhead_percent; /** @} */
    uint32_t threads; /**< render threads */
} sy_mediator_rt_bench;
/** Measures ray throughput (see sy_mediator_rt_bench) for view at width x height, best of repeats. */
sy_result sy_mediator_rt_bench_rays(void *state, const sy_camera_view *view, uint32_t width, uint32_t height,
                                    uint32_t repeats, sy_mediator_rt_bench *out, sy_error *err);

/** Distance to the limit (issue 19; backends/rt/sy_rt_raylog.h, sy_rt_limit.h): one path-traced frame is logged
 * (every extension and shadow ray with Embree's answer), then the frame and raw Embree on exactly
 * those rays in each form are timed, interleaved, `repeats` times. Forms, in order:
 * rtcIntersect1/rtcOccluded1, rtcIntersect4/rtcOccluded4, ...8, ...16, rtcIntersect1M/rtcOccluded1M. */
#define SY_MEDIATOR_RT_LIMIT_FORMS 5
/** Stages of the path tracer timed by sy_mediator_rt_bench_limit. */
#define SY_MEDIATOR_RT_LIMIT_STAGES 10
/** Result of sy_mediator_rt_bench_limit (times in seconds). */
typedef struct sy_mediator_rt_limit {
    /** @{ frame size, samples per pixel, repeats, render threads (the replay's too) */
    uint32_t width, height, samples, repeats, threads; /** @} */
    /** @{ rays of one frame: all, by purpose (extension, shadow), by query (closest hit, occlusion) */
    uint64_t rays, extension_rays, shadow_rays, intersect_queries, occluded_queries; /** @} */
    double frame_seconds[3];                                  /**< path-traced frame: min, median, max */
    double form_seconds[SY_MEDIATOR_RT_LIMIT_FORMS][3];       /**< raw Embree per form: min, median, max */
    double share[SY_MEDIATOR_RT_LIMIT_FORMS][3]; /**< per repeat, raw time / frame time = the path tracer's
                                                  * rays/s as a share of the form's: min, median, max */
    uint64_t mismatches[SY_MEDIATOR_RT_LIMIT_FORMS];          /**< replayed answers that differ from the frame's */
    bool native[SY_MEDIATOR_RT_LIMIT_FORMS];                  /**< Embree runs the form natively (not emulated) */
    const char *form_names[SY_MEDIATOR_RT_LIMIT_FORMS];       /**< static storage */
    /** @{ per stage of the path tracer (issue 39; backends/rt/sy_rt_raylog.h >>stage timers): one
     * more frame per repeat with timers on one pixel in 8; the share of the timed pixels' time
     * (sums to 1), thread-nanoseconds per timed sample, static names */
    double stage_share[SY_MEDIATOR_RT_LIMIT_STAGES];
    double stage_ns_per_sample[SY_MEDIATOR_RT_LIMIT_STAGES];
    const char *stage_names[SY_MEDIATOR_RT_LIMIT_STAGES]; /** @} */
    /** @{ the stages of extension and shadow-ray traversal (indices into the arrays above) */
    int stage_traversal, stage_shadow; /** @} */
    double timed_frame_seconds; /**< median time of the timed frames (what the timers cost) */
    double lap_ticks;           /**< the time stamp counter's own cost per stage change in the path loop, subtracted */
    double lap_ticks_tight;     /**< the same measured in a tight loop (a lower bound) */
    uint64_t stage_laps;    /**< spans timed */
    uint64_t stage_dropped; /**< spans left out as preempted (over ~0.1 ms) */
} sy_mediator_rt_limit;
/** Runs the distance-to-the-limit benchmark on a pathtracer context's device for the view at width
 * x height (the look of background_id applied as a render would), `samples` samples per pixel per
 * frame (>= 1), max_depth of the context. Memory: about 200 bytes per ray of the frame. */
sy_result sy_mediator_rt_bench_limit(void *state, const sy_camera_view *view, uint32_t background_id, uint32_t width,
                                     uint32_t height, uint32_t samples, uint32_t repeats, sy_mediator_rt_limit *out,
                                     sy_error *err);

#ifdef __cplusplus
}
#endif
#endif /* SY_MEDIATOR_RT_H */
