/* sy_rt_raylog.h — the path tracer's optional ray log (issue 19, part 6, "distance to the
 * limit"): every ray a path-traced frame casts (extension rays and shadow rays) as given to Embree,
 * with what Embree answered. Replayed with raw Embree by sy_rt_limit.h (`sy bench limit`).
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

#endif /* SY_RT_RAYLOG_H */
