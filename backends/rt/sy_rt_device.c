/* sy_rt_device.c — device lifetime (Embree device + top-level scene), background and statistics.
 * Above the scene and texture modules (it releases their objects with the device); the handle pools
 * and error helpers they all use are sy_rt_base.c. */
#include "sy_rt_device.h"
#include "sy_rt_lights.h"
#include "sy_rt_lighttree.h"
#include "sy_rt_scene.h"
#include "sy_rt_texture.h"

#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

/* >>device */

/* Embree's memory monitor: counts every allocation and release of the device (geometry buffers,
 * BVHs, build scratch) from any build thread, and keeps the high-water mark. */
static bool embree_memory_monitor(void *user, ssize_t bytes, bool post)
{
    (void)post;
    sy_rt_device *dev = user;
    if (bytes > 0 && dev->max_memory > 0 &&
        atomic_load_explicit(&dev->embree_bytes, memory_order_relaxed) + (int64_t)bytes +
                (int64_t)sy_rt_light_tree_bytes(dev) > dev->max_memory) /* the light tree counts too */
        return false; /* Embree reports RTC_ERROR_OUT_OF_MEMORY */
    int64_t now = atomic_fetch_add_explicit(&dev->embree_bytes, (int64_t)bytes, memory_order_relaxed) + (int64_t)bytes;
    int64_t peak = atomic_load_explicit(&dev->embree_peak, memory_order_relaxed);
    while (now > peak && !atomic_compare_exchange_weak_explicit(&dev->embree_peak, &peak, now, memory_order_relaxed,
                                                                memory_order_relaxed)) {
    }
    return true;
}

/* A failure of sy_rt_device_create before the device exists: reported to the desc's callback. */
static sy_rt_result create_fail(const sy_rt_device_desc *desc, sy_rt_result r, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
static sy_rt_result create_fail(const sy_rt_device_desc *desc, sy_rt_result r, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    sy_rt_failv(desc ? desc->error : NULL, desc ? desc->error_user : NULL, NULL, 0, r, fmt, ap);
    va_end(ap);
    return r;
}

const char *sy_rt_device_error(const sy_rt_device *dev)
{
    return dev ? dev->report->message : "";
}

sy_rt_result sy_rt_device_create(const sy_rt_device_desc *desc, sy_rt_device **out)
{
    if (!out) return create_fail(desc, SY_RT_ERROR_INVALID_ARGUMENT, "device create: out is NULL");
    *out = NULL;
    sy_rt_device *dev = calloc(1, sizeof *dev);
    if (!dev) return create_fail(desc, SY_RT_ERROR_OUT_OF_MEMORY, "device create: out of memory");
    if (pthread_mutex_init(&dev->rtc_err_lock, NULL) != 0) {
        free(dev);
        return create_fail(desc, SY_RT_ERROR_SYSTEM, "device create: pthread_mutex_init failed");
    }
    dev->report = &dev->report_store;
    dev->report->fn = desc ? desc->error : NULL;
    dev->report->user = desc ? desc->error_user : NULL;
    uint32_t threads = desc ? desc->thread_count : 0;
    if (threads > 1024) threads = 1024;
    dev->thread_count = threads; /* 0: the OpenMP default team size, looked up per render */
    sy_rt_sobol_init(&dev->sobol);
    uint64_t limit = desc ? desc->max_memory_bytes : 0;
    dev->max_memory = limit > (uint64_t)INT64_MAX ? INT64_MAX : (int64_t)limit;

    char config[64];
    snprintf(config, sizeof config, "threads=%d", sy_rt_render_threads(dev));
    dev->rtc = rtcNewDevice(config);
    if (!dev->rtc) {
        enum RTCError e = rtcGetDeviceError(NULL);
        pthread_mutex_destroy(&dev->rtc_err_lock);
        free(dev);
        return create_fail(desc, SY_RT_ERROR_EMBREE, "device create: rtcNewDevice(\"%s\") failed: %s", config,
                           sy_rt_embree_error_name(e));
    }
    rtcSetDeviceErrorFunction(dev->rtc, sy_rt_embree_error_callback, dev);
    rtcSetDeviceMemoryMonitorFunction(dev->rtc, embree_memory_monitor, dev);
    dev->top = rtcNewScene(dev->rtc);
    dev->dyn = rtcNewScene(dev->rtc);
    sy_rt_result r = sy_rt_check_embree(dev, "device create: top-level scenes");
    if (r == SY_RT_OK && (!dev->top || !dev->dyn))
        r = sy_rt_fail(dev, SY_RT_ERROR_EMBREE, "device create: rtcNewScene failed");
    if (r != SY_RT_OK) {
        sy_rt_device_destroy(dev);
        return r;
    }
    /* The stale filter of moved instances (sy_rt_device.h) runs from the intersection context, so
     * every scene whose geometry it must see carries the flag: the top scene (baked geometry) and
     * each BLAS (sy_rt_mesh.c, sy_rt_mesh_blas). The moved instances' scene is small and rebuilt often. */
    rtcSetSceneFlags(dev->top, RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);
    rtcSetSceneBuildQuality(dev->top, RTC_BUILD_QUALITY_MEDIUM);
    rtcSetSceneBuildQuality(dev->dyn, RTC_BUILD_QUALITY_LOW);
    rtcCommitScene(dev->dyn);

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
    dev->dirty = dev->top_dirty = dev->shadow_dirty = true;
    *out = dev;
    return SY_RT_OK;
}

int sy_rt_render_threads(const sy_rt_device *dev)
{
    return dev->thread_count ? (int)dev->thread_count : omp_get_max_threads();
}

void sy_rt_device_destroy(sy_rt_device *dev)
{
    if (!dev) return;
    sy_rt_scene_release_all(dev);
    for (uint32_t i = 0; i < dev->textures.count; ++i) sy_rt_texture_free(dev->textures.items[i]);
    sy_rt_pool_free(&dev->textures);
    if (dev->top) rtcReleaseScene(dev->top);
    if (dev->dyn) rtcReleaseScene(dev->dyn);
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
    out->last_top_commit_seconds = dev->last_top_commit_seconds;
    out->top_builds = dev->top_builds;
    out->top_fast_builds = dev->top_fast_builds;
    out->moved_instances = dev->stale_count;
    out->mesh_bytes = dev->mesh_bytes;
    out->shared_bytes = dev->shared_bytes;
    int64_t now = atomic_load(&((sy_rt_device *)dev)->embree_bytes), peak = atomic_load(&((sy_rt_device *)dev)->embree_peak);
    out->embree_bytes = now > 0 ? (uint64_t)now : 0u;
    out->embree_peak_bytes = peak > 0 ? (uint64_t)peak : 0u;
    const sy_rt_lighttree *lt = dev->light_tree;
    out->light_tree_lights = lt ? lt->light_count - lt->skipped : 0u;
    out->light_tree_bytes = sy_rt_light_tree_bytes(dev);
    out->light_tree_build_seconds = dev->light_tree_build_seconds;
    out->light_tree_refit_seconds = dev->light_tree_refit_seconds;
    out->light_tree_refit_changed = dev->light_tree_refit_changed;
    out->light_tree_builds = dev->light_tree_builds;
    out->light_tree_refits = dev->light_tree_refits;
    out->light_warnings = dev->light_warnings;
    memcpy(out->light_warning, dev->light_warning, sizeof out->light_warning);
}

sy_rt_result sy_rt_set_background(sy_rt_device *dev, const sy_rt_background *bg)
{
    if (!dev || !bg) return sy_rt_fail(dev, SY_RT_ERROR_INVALID_ARGUMENT, "background: NULL argument");
    if (bg->mode != SY_RT_BACKGROUND_NONE && bg->mode != SY_RT_BACKGROUND_COLOR && bg->mode != SY_RT_BACKGROUND_TEXTURE)
        return sy_rt_fail(dev, SY_RT_ERROR_INVALID_ARGUMENT, "background: unknown mode %d", (int)bg->mode);
    sy_rt_background b = {.mode = bg->mode};
    if (bg->mode == SY_RT_BACKGROUND_COLOR) {
        for (int k = 0; k < 3; ++k)
            if (!isfinite(bg->color[k]) || bg->color[k] < 0.0f)
                return sy_rt_fail(dev, SY_RT_ERROR_INVALID_ARGUMENT,
                                  "background: colour[%d] = %g is not a finite non-negative radiance", k, (double)bg->color[k]);
        memcpy(b.color, bg->color, sizeof b.color);
    } else if (bg->mode == SY_RT_BACKGROUND_TEXTURE) {
        if (!sy_rt_pool_get(&dev->textures, bg->texture.id))
            return sy_rt_fail(dev, SY_RT_ERROR_INVALID_HANDLE, "background: texture 0x%08x is not a live texture",
                              bg->texture.id);
        if (!isfinite(bg->intensity) || bg->intensity < 0.0f)
            return sy_rt_fail(dev, SY_RT_ERROR_INVALID_ARGUMENT,
                              "background: intensity %g is not a finite non-negative number", (double)bg->intensity);
        b.texture = bg->texture;
        b.intensity = bg->intensity;
    }
    dev->background_staged = b;
    dev->dirty = true;
    return SY_RT_OK;
}
