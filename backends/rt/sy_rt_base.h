/* sy_rt_base.h — internal to the ray-tracing back-end: the base every rt module builds on (index +
 * generation handle pools, the error report, Embree error capture). Defined in
 * sy_rt_base.c, which calls no other rt module, so the device, scene, texture and light modules
 * stack on it without calling each other in a loop. Not part of the public API (sy_rt.h). */
#ifndef SY_RT_BASE_H
#define SY_RT_BASE_H

#include "sy_rt.h"

#include <embree3/rtcore.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdint.h>

/* >>pool: index + generation handles. id = generation << SY_RT_INDEX_BITS | (index + 1). */
#define SY_RT_INDEX_BITS 22u
#define SY_RT_INDEX_MASK ((1u << SY_RT_INDEX_BITS) - 1u)
#define SY_RT_POOL_MAX (SY_RT_INDEX_MASK - 1u) /* most live objects per type */
#define SY_RT_GEN_MASK ((1u << (32u - SY_RT_INDEX_BITS)) - 1u)

typedef struct sy_rt_pool {
    void **items;       /* slot -> object or NULL */
    uint32_t *gens;     /* slot -> current generation (1..SY_RT_GEN_MASK) */
    uint32_t *free_idx; /* stack of free slots */
    uint32_t count;     /* slots in use or on the free stack */
    uint32_t cap;
    uint32_t free_count;
    uint32_t live;
} sy_rt_pool;

/* Stores item in a slot; *id_out gets its handle. Returns false when out of memory or full. */
bool sy_rt_pool_insert(sy_rt_pool *p, void *item, uint32_t *id_out);
/* Object for id, or NULL for a zero, stale or foreign id (inline: every hit looks up its material). */
static inline void *sy_rt_pool_get(const sy_rt_pool *p, uint32_t id)
{
    uint32_t slot = id & SY_RT_INDEX_MASK;
    if (slot == 0 || slot > p->count) return NULL;
    uint32_t idx = slot - 1u;
    if (p->gens[idx] != (id >> SY_RT_INDEX_BITS)) return NULL;
    return p->items[idx];
}
/* Frees the slot of a valid id (bumps its generation) and returns its object (NULL if invalid). */
void *sy_rt_pool_remove(sy_rt_pool *p, uint32_t id);
void sy_rt_pool_free(sy_rt_pool *p);
/* The calls' side of a pool (dev's error report, "WHAT: ..." messages): sy_rt_pool_find returns
 * the object for id, sy_rt_pool_take removes and returns it; both report SY_RT_ERROR_INVALID_HANDLE
 * "WHAT: stale handle 0x..." and return NULL for a zero, stale or foreign id. */
void *sy_rt_pool_find(const sy_rt_device *dev, const sy_rt_pool *p, uint32_t id, const char *what);
void *sy_rt_pool_take(const sy_rt_device *dev, sy_rt_pool *p, uint32_t id, const char *what);
/* Stores a new object (from malloc) in the pool, *id its handle; when the pool is full or out of
 * memory, frees it and reports SY_RT_ERROR_LIMIT "WHAT: pool full or out of memory". */
sy_rt_result sy_rt_pool_add(sy_rt_device *dev, sy_rt_pool *pool, void *item, uint32_t *id, const char *what);

/* >>errors */

#define SY_RT_ERROR_MAX 512 /* bytes of a reported message, NUL included (as core's sy_error) */

/* A device's error report: its callback and the last message. */
typedef struct sy_rt_report {
    sy_rt_error_fn fn;
    void *user;
    char message[SY_RT_ERROR_MAX];
} sy_rt_report;

/* Reports a failure: formats the printf-style message into dev's last error and hands it to dev's
 * error callback (nothing when dev is NULL); returns r. */
sy_rt_result sy_rt_fail(const sy_rt_device *dev, sy_rt_result r, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
/* The same with a va_list, reporting to callback fn (may be NULL) and keeping the text in keep
 * (keep_len bytes; may be NULL): sy_rt_device_create before it has a device. */
sy_rt_result sy_rt_failv(sy_rt_error_fn fn, void *user, char *keep, size_t keep_len, sy_rt_result r, const char *fmt,
                         va_list ap);
/* Returns SY_RT_OK, or reports SY_RT_ERROR_EMBREE with "what: embree: <embree message>" when Embree
 * recorded an error since the last check. */
sy_rt_result sy_rt_check_embree(sy_rt_device *dev, const char *what);

/* "invalid argument", "out of memory", ... for an Embree error code. */
const char *sy_rt_embree_error_name(enum RTCError e);
/* The Embree device error callback (rtcSetDeviceErrorFunction with the sy_rt_device as user):
 * keeps the last message for sy_rt_check_embree. Called on the thread that caused the error. */
void sy_rt_embree_error_callback(void *user, enum RTCError code, const char *msg);

#endif /* SY_RT_BASE_H */
