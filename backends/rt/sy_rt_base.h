/* sy_rt_base.h — internal to the ray-tracing back-end: the base every rt module builds on (index +
 * generation handle pools and the create / update frame of pooled kinds, the error report, Embree
 * error capture). Defined in sy_rt_base.c, which calls no other rt module, so the device, scene, texture and light modules
 * stack on it without calling each other in a loop. Not part of the public API (sy_rt.h). */
#ifndef SY_RT_BASE_H
#define SY_RT_BASE_H

#include "sy_rt.h"

#include <embree3/rtcore.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
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

/* A kind of pooled object whose create, update and destroy calls share one frame (materials,
 * lights): its name in messages, its pool (offsetof(sy_rt_device, ...)), its item's size, the check
 * of a description (SY_RT_OK or the reported failure), set, which stores a checked description in
 * the item (fresh: a new, zeroed item) and marks what an update changes for the next commit, and
 * mark, which marks what a new (gone false) or destroyed (gone true, before it is freed) item
 * changes. */
typedef struct sy_rt_kind {
    const char *what;
    size_t pool;
    size_t size;
    sy_rt_result (*validate)(const sy_rt_device *dev, const void *desc);
    void (*set)(sy_rt_device *dev, void *item, const void *desc, bool fresh);
    void (*mark)(sy_rt_device *dev, const void *item, bool gone);
} sy_rt_kind;
/* The frame of a create call: dev, desc and id present ("WHAT: NULL argument"), *id zeroed, desc
 * validated, a zeroed item set from it and added to its pool (*id its handle), then marked. */
sy_rt_result sy_rt_item_create(sy_rt_device *dev, const sy_rt_kind *k, const void *desc, uint32_t *id);
/* The frame of an update call: dev and desc present ("WHAT update: NULL argument"), id live
 * ("WHAT update: stale handle"), desc validated, then set on the item. */
sy_rt_result sy_rt_item_update(sy_rt_device *dev, const sy_rt_kind *k, uint32_t id, const void *desc);
/* The frame of a destroy call: dev present ("WHAT destroy: NULL device"), id live ("WHAT destroy:
 * stale handle"), the item taken from its pool, marked and freed. */
sy_rt_result sy_rt_item_destroy(sy_rt_device *dev, const sy_rt_kind *k, uint32_t id);
/* Defines the public calls of kind K that sy_rt.h declares: sy_rt_NAME_create(dev, desc, out),
 * sy_rt_NAME_update(dev, handle, desc) and sy_rt_NAME_destroy(dev, handle), over the frames above. */
#define SY_RT_KIND_CALLS(NAME, K)                                                                   \
    sy_rt_result sy_rt_##NAME##_create(sy_rt_device *dev, const sy_rt_##NAME##_desc *desc, sy_rt_##NAME *out) \
    {                                                                                               \
        return sy_rt_item_create(dev, &(K), desc, out ? &out->id : NULL);                           \
    }                                                                                               \
    sy_rt_result sy_rt_##NAME##_update(sy_rt_device *dev, sy_rt_##NAME h, const sy_rt_##NAME##_desc *desc) \
    {                                                                                               \
        return sy_rt_item_update(dev, &(K), h.id, desc);                                            \
    }                                                                                               \
    sy_rt_result sy_rt_##NAME##_destroy(sy_rt_device *dev, sy_rt_##NAME h)                          \
    {                                                                                               \
        return sy_rt_item_destroy(dev, &(K), h.id);                                                 \
    }

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
