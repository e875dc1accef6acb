/* sy_rt_limit.h — "distance to the limit" (issue 19, part 6): the rays of a path-traced frame
 * (sy_rt_raylog.h) traced again with raw Embree on the same RTCScene: rtcIntersect1/rtcOccluded1,
 * the packet forms rtcIntersect4/8/16 + rtcOccluded4/8/16 and the streams rtcIntersect1M /
 * rtcOccluded1M, on the back-end's OpenMP thread team. The path tracer's rays per second as a
 * share of the replay's is the cost of everything that is not ray casting. Used by
 * `sy bench limit` (through sy_mediator_rt_bench_limit) and tests/rt/test_rt_raylog.c.
 * Ownership: replays are created and destroyed by the caller and borrow the log and the device.
 * Thread-safety: a replay reads the log and the committed device; one call at a time per device
 * (it uses the device's thread team). Internal to backends/rt. */
#ifndef SY_RT_LIMIT_H
#define SY_RT_LIMIT_H

#include "sy_rt_raylog.h"

/* The replay forms. */
typedef enum sy_rt_ray_form {
    SY_RT_FORM_1 = 0,  /* rtcIntersect1 / rtcOccluded1 */
    SY_RT_FORM_4,      /* rtcIntersect4 / rtcOccluded4: consecutive rays of the log as one packet */
    SY_RT_FORM_8,
    SY_RT_FORM_16,
    SY_RT_FORM_STREAM, /* rtcIntersect1M / rtcOccluded1M over runs of 64 consecutive rays */
    SY_RT_FORM_COUNT
} sy_rt_ray_form;
const char *sy_rt_ray_form_name(sy_rt_ray_form form); /* "rtcIntersect1/rtcOccluded1", ... */
/* Whether Embree runs the form natively (RTC_DEVICE_PROPERTY_NATIVE_RAYn_SUPPORTED; 1 and the
 * streams always) rather than emulating it with single rays. */
bool sy_rt_ray_form_native(const sy_rt_device *dev, sy_rt_ray_form form);

/* Prepared rays of one form (the packets built before timing, so the replay times Embree alone). */
typedef struct sy_rt_ray_replay sy_rt_ray_replay;
sy_rt_result sy_rt_ray_replay_create(const sy_rt_device *dev, const sy_rt_ray_log *log, sy_rt_ray_form form,
                                     sy_rt_ray_replay **out);
void sy_rt_ray_replay_destroy(sy_rt_ray_replay *rp); /* NULL is a no-op */
/* Traces every ray of the log once in the prepared form on sy_rt_render_threads(dev) threads
 * (OpenMP, dynamic chunks, in log order within a chunk) and returns the wall time. When mismatches
 * is not NULL it receives the rays whose answer differs from the recorded one (closest hits: geom,
 * prim or inst; occlusion: occluded or not); checking costs a little, so time without it. */
double sy_rt_ray_replay_run(sy_rt_ray_replay *rp, uint64_t *mismatches);

/* The benchmark (sy bench limit): one path-traced frame of `samples` samples per pixel is logged,
 * then per repeat the frame (without log) and each replay form are timed, interleaved. */
typedef struct sy_rt_limit_result {
    uint32_t width, height, samples, repeats, threads;
    uint64_t rays, extension_rays, shadow_rays;     /* of one frame (the logged one) */
    uint64_t intersect_queries, occluded_queries;   /* the same by query type */
    double frame_seconds[3];                        /* min, median, max of the path-traced frame */
    double form_seconds[SY_RT_FORM_COUNT][3];       /* min, median, max per replay form */
    double share[SY_RT_FORM_COUNT][3];              /* per repeat: form time / frame time (= the path
                                                     * tracer's rays/s over the form's), min, median, max */
    uint64_t mismatches[SY_RT_FORM_COUNT];          /* replayed answers that differ from the log */
    bool native[SY_RT_FORM_COUNT];                  /* sy_rt_ray_form_native */
    /* per stage (sy_rt_raylog.h >>stage timers): one more frame per repeat with the stage timers
     * on (not in frame_seconds), the counter's own cost per lap subtracted */
    double stage_share[SY_RT_STAGE_COUNT];          /* share of the timed pixels' ticks, sums to 1 */
    double stage_ns_per_sample[SY_RT_STAGE_COUNT];  /* ns per timed sample (ticks at the TSC rate measured
                                                     * over the timed frames) */
    uint64_t stage_samples;                         /* timed samples, all repeats */
    uint64_t stage_laps, stage_dropped;             /* spans timed, spans left out (sy_rt_raylog.h) */
    double lap_ticks;                               /* the counter's cost per lap in the path loop, subtracted */
    double lap_ticks_tight;                         /* the same in a tight loop (sy_rt_stage_lap_cost) */
    double timed_frame_seconds;                     /* median of the timed frames (the timers' cost) */
} sy_rt_limit_result;
/* desc: a PATHTRACER desc (its accum, samples, max_depth, seed, rectangle; ray_log, stage_times
 * and progress are ignored); the accum is reset before every frame. The device must be committed. */
sy_rt_result sy_rt_bench_limit(sy_rt_device *dev, const sy_rt_camera *camera, const sy_rt_render_desc *desc,
                               uint32_t repeats, sy_rt_limit_result *out);

#endif /* SY_RT_LIMIT_H */
