/* sy_rt_base.c — the base every module of the ray-tracing back-end builds on: index + generation
 * handle pools, the error report and the capture of Embree's errors (see sy_rt_base.h). Calls no
 * other rt module. */
#include "sy_rt_device.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

sy_rt_result sy_rt_failv(sy_rt_error_fn fn, void *user, char *keep, size_t keep_len, sy_rt_result r, const char *fmt,
                         va_list ap)
{
    char buf[SY_RT_ERROR_MAX];
    vsnprintf(buf, sizeof buf, fmt, ap);
    if (keep && keep_len > 0) snprintf(keep, keep_len, "%s", buf);
    if (fn) fn(user, r, buf);
    return r;
}

sy_rt_result sy_rt_fail(const sy_rt_device *dev, sy_rt_result r, const char *fmt, ...)
{
    if (!dev) return r;
    sy_rt_report *rep = dev->report;
    va_list ap;
    va_start(ap, fmt);
    sy_rt_failv(rep->fn, rep->user, rep->message, sizeof rep->message, r, fmt, ap);
    va_end(ap);
    return r;
}

const char *sy_rt_embree_error_name(enum RTCError e)
{
    switch (e) {
    case RTC_ERROR_NONE: return "none";
    case RTC_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION: return "invalid operation";
    case RTC_ERROR_OUT_OF_MEMORY: return "out of memory";
    case RTC_ERROR_UNSUPPORTED_CPU: return "unsupported CPU";
    case RTC_ERROR_CANCELLED: return "cancelled";
    default: return "unknown error";
    }
}

/* Embree calls this synchronously on the thread that caused the error (or a build thread). */
void sy_rt_embree_error_callback(void *user, enum RTCError code, const char *msg)
{
    sy_rt_device *dev = user;
    pthread_mutex_lock(&dev->rtc_err_lock);
    snprintf(dev->rtc_msg, sizeof dev->rtc_msg, "%s (%s)", msg ? msg : "", sy_rt_embree_error_name(code));
    pthread_mutex_unlock(&dev->rtc_err_lock);
}

sy_rt_result sy_rt_check_embree(sy_rt_device *dev, const char *what)
{
    enum RTCError code = rtcGetDeviceError(dev->rtc);
    if (code == RTC_ERROR_NONE) return SY_RT_OK;
    pthread_mutex_lock(&dev->rtc_err_lock);
    sy_rt_result r = sy_rt_fail(dev, SY_RT_ERROR_EMBREE, "%s: embree: %s", what,
                                dev->rtc_msg[0] ? dev->rtc_msg : sy_rt_embree_error_name(code));
    dev->rtc_msg[0] = '\0';
    pthread_mutex_unlock(&dev->rtc_err_lock);
    return r;
}

/* >>pool */

bool sy_rt_pool_insert(sy_rt_pool *p, void *item, uint32_t *id_out)
{
    uint32_t idx;
    if (p->free_count > 0) {
        idx = p->free_idx[--p->free_count];
    } else {
        if (p->count >= SY_RT_POOL_MAX) return false;
        if (p->count == p->cap) {
            uint32_t ncap = p->cap ? p->cap * 2u : 64u;
            if (ncap > SY_RT_POOL_MAX) ncap = SY_RT_POOL_MAX;
            void **items = realloc(p->items, (size_t)ncap * sizeof *items);
            if (!items) return false;
            p->items = items;
            uint32_t *gens = realloc(p->gens, (size_t)ncap * sizeof *gens);
            if (!gens) return false;
            p->gens = gens;
            uint32_t *fr = realloc(p->free_idx, (size_t)ncap * sizeof *fr);
            if (!fr) return false;
            p->free_idx = fr;
            p->cap = ncap;
        }
        idx = p->count++;
        p->gens[idx] = 1;
    }
    p->items[idx] = item;
    p->live++;
    *id_out = (p->gens[idx] << SY_RT_INDEX_BITS) | (idx + 1u);
    return true;
}

void *sy_rt_pool_remove(sy_rt_pool *p, uint32_t id)
{
    void *item = sy_rt_pool_get(p, id);
    if (!item) return NULL;
    uint32_t idx = (id & SY_RT_INDEX_MASK) - 1u;
    p->items[idx] = NULL;
    /* Generation wraps within 1..SY_RT_GEN_MASK; a handle is only confused with a new object
     * after SY_RT_GEN_MASK reuses of the same slot. */
    p->gens[idx] = p->gens[idx] % SY_RT_GEN_MASK + 1u;
    p->free_idx[p->free_count++] = idx;
    p->live--;
    return item;
}

void *sy_rt_pool_find(const sy_rt_device *dev, const sy_rt_pool *p, uint32_t id, const char *what)
{
    void *item = sy_rt_pool_get(p, id);
    if (!item) sy_rt_fail(dev, SY_RT_ERROR_INVALID_HANDLE, "%s: stale handle 0x%08x", what, id);
    return item;
}

void *sy_rt_pool_take(const sy_rt_device *dev, sy_rt_pool *p, uint32_t id, const char *what)
{
    void *item = sy_rt_pool_remove(p, id);
    if (!item) sy_rt_fail(dev, SY_RT_ERROR_INVALID_HANDLE, "%s: stale handle 0x%08x", what, id);
    return item;
}

sy_rt_result sy_rt_pool_add(sy_rt_device *dev, sy_rt_pool *pool, void *item, uint32_t *id, const char *what)
{
    if (sy_rt_pool_insert(pool, item, id)) return SY_RT_OK;
    free(item);
    return sy_rt_fail(dev, SY_RT_ERROR_LIMIT, "%s: pool full or out of memory", what);
}

/* The pool of kind k in dev (not NULL). */
static sy_rt_pool *kind_pool(sy_rt_device *dev, const sy_rt_kind *k)
{
    return (sy_rt_pool *)((char *)dev + k->pool);
}

sy_rt_result sy_rt_item_create(sy_rt_device *dev, const sy_rt_kind *k, const void *desc, uint32_t *id)
{
    if (!dev || !desc || !id) return sy_rt_fail(dev, SY_RT_ERROR_INVALID_ARGUMENT, "%s: NULL argument", k->what);
    *id = 0;
    sy_rt_result r = k->validate(dev, desc);
    if (r != SY_RT_OK) return r;
    void *item = calloc(1, k->size);
    if (!item) return sy_rt_fail(dev, SY_RT_ERROR_OUT_OF_MEMORY, "%s: out of memory", k->what);
    k->set(dev, item, desc, true);
    sy_rt_result r2 = sy_rt_pool_add(dev, kind_pool(dev, k), item, id, k->what);
    if (r2 == SY_RT_OK) k->mark(dev, item, false);
    return r2;
}

sy_rt_result sy_rt_item_update(sy_rt_device *dev, const sy_rt_kind *k, uint32_t id, const void *desc)
{
    char what[64];
    snprintf(what, sizeof what, "%s update", k->what);
    if (!dev || !desc) return sy_rt_fail(dev, SY_RT_ERROR_INVALID_ARGUMENT, "%s: NULL argument", what);
    void *item = sy_rt_pool_find(dev, kind_pool(dev, k), id, what);
    if (!item) return SY_RT_ERROR_INVALID_HANDLE;
    sy_rt_result r = k->validate(dev, desc);
    if (r != SY_RT_OK) return r;
    k->set(dev, item, desc, false);
    return SY_RT_OK;
}

sy_rt_result sy_rt_item_destroy(sy_rt_device *dev, const sy_rt_kind *k, uint32_t id)
{
    char what[64];
    snprintf(what, sizeof what, "%s destroy", k->what);
    if (!dev) return sy_rt_fail(dev, SY_RT_ERROR_INVALID_ARGUMENT, "%s: NULL device", what);
    void *item = sy_rt_pool_take(dev, kind_pool(dev, k), id, what);
    if (!item) return SY_RT_ERROR_INVALID_HANDLE;
    k->mark(dev, item, true);
    free(item);
    return SY_RT_OK;
}

void sy_rt_pool_free(sy_rt_pool *p)
{
    free(p->items);
    free(p->gens);
    free(p->free_idx);
    memset(p, 0, sizeof *p);
}

