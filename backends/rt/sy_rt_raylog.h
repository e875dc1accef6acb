/* sy_rt_raylog.h — the path tracer's optional ray log (issue 19, part 6, "distance to the
 * limit"): every ray a path-traced frame casts (extension rays and shadow rays) as given to Embree,
 * with what Embree answered. Replayed with raw Embree by sy_rt_limit.h (`sy bench limit`). Also
 * the path tracer's optional stage timers (issue 39, part 5: >>stage timers below).
 *
 * Logging is off by default: sy_rt_render_desc.ray_log NULL costs the path tracer one untaken
 * branch per ray. With a log, each tile gathers its rays in a buffer of its own (in the order the
 * tile cast them) and appends it to the log under the log's lock when the tile ends.
 *
 * Ownership: the caller creates and destroys a log; a render appends to it. Thread-safety: one
 * render at a time may append to a log. Internal to backends/rt (sy_rt_limit and tests use it);
 * calls nothing else of the back-end (the integrators call it). */
#ifndef SY_RT_RAYLOG_H
#define SY_RT_RAYLOG_H

#include "sy_rt_frame.h"

#include <pthread.h>
#include <stdatomic.h>
#include <time.h>

/* What the ray was cast for. */
enum { SY_RT_RAY_EXTENSION = 0, SY_RT_RAY_SHADOW = 1 };

/* One recorded ray as given to Embree, and its answer. Closest-hit queries (rtcIntersect1):
 * geom/prim/inst the hit (geom RTC_INVALID_GEOMETRY_ID on a miss). Occlusion queries
 * (rtcOccluded1): geom 1 when occluded, 0 when clear. */
typedef struct sy_rt_logged_ray {
    float org[3], tnear;
    float dir[3], tfar;
    uint32_t mask, flags;
    uint32_t geom, prim, inst;
    uint32_t kind; /* SY_RT_RAY_EXTENSION or SY_RT_RAY_SHADOW */
} sy_rt_logged_ray;

/* A growable array of rays (per tile while rendering, per query type in the log). */
typedef struct sy_rt_ray_buf {
    sy_rt_logged_ray *v;
    size_t n, cap;
    bool failed; /* an append ran out of memory (the rays after it are missing) */
} sy_rt_ray_buf;

/* The log of one or more renders: closest-hit queries and occlusion queries apart, since each is
 * replayed with its own Embree call. */
struct sy_rt_ray_log {
    sy_rt_ray_buf intersect, occluded;
    uint64_t kind_count[2]; /* rays per kind (extension, shadow), both queries */
    pthread_mutex_t lock;
};
typedef struct sy_rt_ray_log sy_rt_ray_log;

sy_rt_result sy_rt_ray_log_create(sy_rt_device *dev, sy_rt_ray_log **out); /* dev (may be NULL) receives the error report */
void sy_rt_ray_log_destroy(sy_rt_ray_log *log); /* NULL is a no-op */
void sy_rt_ray_log_clear(sy_rt_ray_log *log);   /* back to no rays (keeps the memory) */

/* Recording (the integrators; buf is a tile's own buffer). Records the ray as passed to Embree
 * (tfar before the query) with the hit of rh / the occlusion answer. */
void sy_rt_ray_buf_add_hit(sy_rt_ray_buf *buf, uint32_t kind, sy_rt_v3 org, sy_rt_v3 dir, float tnear, float tfar,
                           const struct RTCRayHit *rh);
void sy_rt_ray_buf_add_occluded(sy_rt_ray_buf *buf, sy_rt_v3 org, sy_rt_v3 dir, float tnear, float tfar, bool occluded);
/* Moves buf's rays into the log (under its lock) and empties buf (its memory is kept). */
void sy_rt_ray_log_append(sy_rt_ray_log *log, sy_rt_ray_buf *buf);
void sy_rt_ray_buf_free(sy_rt_ray_buf *buf);

/* >>stage timers: where a path-traced frame's time goes (`sy bench limit`'s per-stage table).
 * With sy_rt_render_desc.stage_times set, the path tracer reads the time stamp counter at every
 * change of stage on a sampled subset of the pixels (one in SY_RT_STAGE_SUBSET, spread by a hash of
 * the pixel) and adds the ticks to the stage that ended; without it (the default) the untimed
 * pixels' code has no timer in it (the timed path loop is a separate inlined copy) and the light
 * sample's own stages cost one untaken branch each. Reading the counter costs ticks of its own:
 * the timed path loop measures them where it runs (SY_RT_STAGE_NULL: an empty span per bounce),
 * and the benchmark subtracts them per span; sy_rt_stage_lap_cost measures them in a tight loop
 * (a lower bound). */
#define SY_RT_STAGE_SUBSET 8u
/* A span longer than this (ticks; about 0.1 ms at 2.5 GHz) is left out: on a loaded machine it is
 * a thread that lost its core, and one such span would outweigh thousands of real ones. */
#define SY_RT_STAGE_MAX_LAP 250000u
typedef enum sy_rt_stage {
    SY_RT_STAGE_RNG = 0,       /* Sobol sample sets, the camera ray, per-pixel set-up */
    SY_RT_STAGE_TRAVERSAL,     /* extension rays: sy_rt_intersect (rtcIntersect1 + the instance look-up) */
    SY_RT_STAGE_SHADOW,        /* shadow rays: rtcOccluded1 / rtcIntersect1 through alpha (sy_rt_shadow.h) */
    SY_RT_STAGE_HIT_FETCH,     /* sy_rt_surface_fetch_at: vertices, normals, UVs, material, textures */
    SY_RT_STAGE_BSDF_INIT,     /* sy_rt_bsdf_init: the BSDF's lobes and their weights at the hit */
    SY_RT_STAGE_SHADING,       /* the rest: misses (environment), emission and MIS weights, alpha, the
                                * path's bookkeeping */
    SY_RT_STAGE_LIGHT,         /* light selection (alias table / light tree) and the point on the light */
    SY_RT_STAGE_BSDF_EVAL,     /* the BSDF evaluated toward the light sample */
    SY_RT_STAGE_BSDF_SAMPLE,   /* BSDF sampling (lobe, direction, weight, pdf) and Russian roulette */
    SY_RT_STAGE_ACCUM,         /* adding the sample to the pixel's accumulation */
    SY_RT_STAGE_COUNT,
    /* not a stage: an empty span once per bounce (two reads back to back in the path loop), the
     * cost of one change of stage where the path tracer runs */
    SY_RT_STAGE_NULL = SY_RT_STAGE_COUNT,
    SY_RT_STAGE_SLOTS
} sy_rt_stage;
const char *sy_rt_stage_name(sy_rt_stage s); /* "traversal (extension rays)", ... */

/* Ticks per stage summed over a frame's timed pixels (a render adds to them; atomic adds at the
 * end of each tile). laps[s]: counter reads that ended a span of stage s. */
typedef struct sy_rt_stage_times {
    _Atomic uint64_t ticks[SY_RT_STAGE_SLOTS];
    _Atomic uint64_t laps[SY_RT_STAGE_SLOTS];
    _Atomic uint64_t samples; /* timed samples */
    _Atomic uint64_t dropped; /* spans longer than SY_RT_STAGE_MAX_LAP, left out */
} sy_rt_stage_times;

static inline uint64_t sy_rt_stage_tick(void)
{
#if defined(__x86_64__) || defined(__i386__)
    return __builtin_ia32_rdtsc();
#else
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec;
#endif
}
/* A thread's running timer: the stage now running and when it began. */
typedef struct sy_rt_stage_clock {
    uint64_t ticks[SY_RT_STAGE_SLOTS], laps[SY_RT_STAGE_SLOTS];
    uint64_t last, dropped;
    uint32_t cur;
} sy_rt_stage_clock;
/* Ends the running stage and starts `next`. */
static inline void sy_rt_stage_lap(sy_rt_stage_clock *c, sy_rt_stage next)
{
    uint64_t t = sy_rt_stage_tick();
    if (t - c->last <= SY_RT_STAGE_MAX_LAP) c->ticks[c->cur] += t - c->last, c->laps[c->cur]++;
    else c->dropped++; /* the thread was most likely descheduled */
    c->last = t;
    c->cur = (uint32_t)next;
}
/* Ticks one lap adds by itself (the median of a few runs of back-to-back laps). */
double sy_rt_stage_lap_cost(void);
/* Adds a tile's clock to the frame's totals. */
void sy_rt_stage_times_add(sy_rt_stage_times *t, const sy_rt_stage_clock *c, uint64_t samples);

#endif /* SY_RT_RAYLOG_H */
