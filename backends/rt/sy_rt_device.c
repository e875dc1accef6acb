/* sy_rt_device.c — device lifetime (Embree device + top-level scene), handle pools, error
 * helpers, Embree error capture, background and statistics. */
#include "sy_rt_device.h"
#include "sy_rt_scene.h"
#include "sy_rt_texture.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* >>errors */

const char *sy_rt_result_str(sy_rt_result r)
{
    switch (r) {
    case SY_RT_OK: return "ok";
    case SY_RT_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case SY_RT_ERROR_INVALID_HANDLE: return "invalid handle";
    case SY_RT_ERROR_OUT_OF_MEMORY: return "out of memory";
    case SY_RT_ERROR_LIMIT: return "limit exceeded";
    case SY_RT_ERROR_EMBREE: return "embree error";
    case SY_RT_ERROR_UNSUPPORTED: return "unsupported";
    case SY_RT_ERROR_INVALID_OPERATION: return "invalid operation";
    case SY_RT_ERROR_CANCELLED: return "cancelled";
    case SY_RT_ERROR_SYSTEM: return "system error";
    default: return "unknown result";
    }
}

sy_rt_result sy_rt_fail(char *err, size_t err_len, sy_rt_result r, const char *fmt, ...)
{
    if (err && err_len > 0) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err, err_len, fmt, ap);
        va_end(ap);
    }
    return r;
}

static const char *rtc_error_name(enum RTCError e)
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
static void rtc_error_callback(void *user, enum RTCError code, const char *msg)
{
    sy_rt_device *dev = user;
    pthread_mutex_lock(&dev->rtc_err_lock);
    snprintf(dev->rtc_msg, sizeof dev->rtc_msg, "%s (%s)", msg ? msg : "", rtc_error_name(code));
    pthread_mutex_unlock(&dev->rtc_err_lock);
}

sy_rt_result sy_rt_check_embree(sy_rt_device *dev, char *err, size_t err_len, const char *what)
{
    enum RTCError code = rtcGetDeviceError(dev->rtc);
    if (code == RTC_ERROR_NONE) return SY_RT_OK;
    pthread_mutex_lock(&dev->rtc_err_lock);
    sy_rt_result r = sy_rt_fail(err, err_len, SY_RT_ERROR_EMBREE, "%s: embree: %s", what,
                                dev->rtc_msg[0] ? dev->rtc_msg : rtc_error_name(code));
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

void *sy_rt_pool_get(const sy_rt_pool *p, uint32_t id)
{
    uint32_t slot = id & SY_RT_INDEX_MASK;
    if (slot == 0 || slot > p->count) return NULL;
    uint32_t idx = slot - 1u;
    if (p->gens[idx] != (id >> SY_RT_INDEX_BITS)) return NULL;
    return p->items[idx];
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

void sy_rt_pool_free(sy_rt_pool *p)
{
    free(p->items);
    free(p->gens);
    free(p->free_idx);
    memset(p, 0, sizeof *p);
}

/* >>device */

sy_rt_result sy_rt_device_create(const sy_rt_device_desc *desc, sy_rt_device **out, char *err, size_t err_len)
{
    if (!out) return sy_rt_fail(err, err_len, SY_RT_ERROR_INVALID_ARGUMENT, "device create: out is NULL");
    *out = NULL;
    sy_rt_device *dev = calloc(1, sizeof *dev);
    if (!dev) return sy_rt_fail(err, err_len, SY_RT_ERROR_OUT_OF_MEMORY, "device create: out of memory");
    if (pthread_mutex_init(&dev->rtc_err_lock, NULL) != 0) {
        free(dev);
        return sy_rt_fail(err, err_len, SY_RT_ERROR_SYSTEM, "device create: pthread_mutex_init failed");
    }
    uint32_t threads = desc ? desc->thread_count : 0;
    if (threads == 0) {
        long n = sysconf(_SC_NPROCESSORS_ONLN);
        threads = n > 0 ? (uint32_t)n : 1u;
    }
    if (threads > 1024) threads = 1024;
    dev->thread_count = threads;

    char config[64];
    snprintf(config, sizeof config, "threads=%u", threads);
    dev->rtc = rtcNewDevice(config);
    if (!dev->rtc) {
        enum RTCError e = rtcGetDeviceError(NULL);
        pthread_mutex_destroy(&dev->rtc_err_lock);
        free(dev);
        return sy_rt_fail(err, err_len, SY_RT_ERROR_EMBREE, "device create: rtcNewDevice(\"%s\") failed: %s",
                          config, rtc_error_name(e));
    }
    rtcSetDeviceErrorFunction(dev->rtc, rtc_error_callback, dev);
    dev->top = rtcNewScene(dev->rtc);
    sy_rt_result r = sy_rt_check_embree(dev, err, err_len, "device create: top-level scene");
    if (r != SY_RT_OK) {
        sy_rt_device_destroy(dev);
        return r;
    }
    rtcSetSceneBuildQuality(dev->top, RTC_BUILD_QUALITY_MEDIUM);

    for (int i = 0; i < 256; ++i) {
        double c = i / 255.0;
        dev->srgb_lut[i] = (float)(c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4));
    }
    sy_rt_material_desc_init(&dev->default_material.desc);
    dev->default_material.desc.base_color[0] = dev->default_material.desc.base_color[1] =
        dev->default_material.desc.base_color[2] = 0.8f;
    dev->default_material.desc.metallic = 0.0f;
    dev->background_staged.mode = SY_RT_BACKGROUND_NONE;
    dev->background = dev->background_staged;
    dev->dirty = dev->top_dirty = true;
    *out = dev;
    return SY_RT_OK;
}

void sy_rt_device_destroy(sy_rt_device *dev)
{
    if (!dev) return;
    sy_rt_scene_release_all(dev);
    for (uint32_t i = 0; i < dev->textures.count; ++i) sy_rt_texture_free(dev->textures.items[i]);
    sy_rt_pool_free(&dev->textures);
    if (dev->top) rtcReleaseScene(dev->top);
    if (dev->rtc) rtcReleaseDevice(dev->rtc);
    pthread_mutex_destroy(&dev->rtc_err_lock);
    free(dev);
}

void sy_rt_device_stats(const sy_rt_device *dev, sy_rt_stats *out)
{
    memset(out, 0, sizeof *out);
    if (!dev) return;
    out->meshes = dev->meshes.live;
    out->instances = dev->instances.live;
    out->materials = dev->materials.live;
    out->textures = dev->textures.live;
    out->lights = dev->lights.live;
    out->area_light_triangles = dev->area_count;
    out->version = dev->version;
}

sy_rt_result sy_rt_set_background(sy_rt_device *dev, const sy_rt_background *bg, char *err, size_t err_len)
{
    if (!dev || !bg) return sy_rt_fail(err, err_len, SY_RT_ERROR_INVALID_ARGUMENT, "background: NULL argument");
    if (bg->mode != SY_RT_BACKGROUND_NONE && bg->mode != SY_RT_BACKGROUND_COLOR && bg->mode != SY_RT_BACKGROUND_TEXTURE)
        return sy_rt_fail(err, err_len, SY_RT_ERROR_INVALID_ARGUMENT, "background: unknown mode %d", (int)bg->mode);
    sy_rt_background b = {.mode = bg->mode};
    if (bg->mode == SY_RT_BACKGROUND_COLOR) {
        for (int k = 0; k < 3; ++k)
            if (!isfinite(bg->color[k]) || bg->color[k] < 0.0f)
                return sy_rt_fail(err, err_len, SY_RT_ERROR_INVALID_ARGUMENT,
                                  "background: colour[%d] = %g is not a finite non-negative radiance", k, (double)bg->color[k]);
        memcpy(b.color, bg->color, sizeof b.color);
    } else if (bg->mode == SY_RT_BACKGROUND_TEXTURE) {
        if (!sy_rt_pool_get(&dev->textures, bg->texture.id))
            return sy_rt_fail(err, err_len, SY_RT_ERROR_INVALID_HANDLE, "background: texture 0x%08x is not a live texture",
                              bg->texture.id);
        if (!isfinite(bg->intensity) || bg->intensity < 0.0f)
            return sy_rt_fail(err, err_len, SY_RT_ERROR_INVALID_ARGUMENT,
                              "background: intensity %g is not a finite non-negative number", (double)bg->intensity);
        b.texture = bg->texture;
        b.intensity = bg->intensity;
    }
    dev->background_staged = b;
    dev->dirty = true;
    return SY_RT_OK;
}
