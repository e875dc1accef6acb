/* sy_rt_bench.c — sy_rt_bench_rays: times the PRIMARY integrator and a raw-Embree kernel that
 * generates the same camera rays through the same tile scheduler and only stores the hit
 * distance, so the difference is exactly what the renderer adds (hit lookup, surface evaluation,
 * shading, output). It also compares the two depth images: the comparison is only fair when both
 * traced the same rays to the same hits. */
#include "sy_rt_bench.h"
#include "sy_rt_primary.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <time.h>

static void raw_hit(const sy_rt_frame *f, void *user, size_t o, const struct RTCRayHit *rh, float axial)
{
    (void)f;
    ((float *)user)[o] = rh->hit.geomID == RTC_INVALID_GEOMETRY_ID ? INFINITY : rh->ray.tfar * axial;
}

static void raw_tile(const sy_rt_frame *f, void *user, uint32_t x0, uint32_t y0, uint32_t x1, uint32_t y1)
{
    sy_rt_frame_tile_hits(f, x0, y0, x1, y1, raw_hit, user);
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

sy_rt_result sy_rt_bench_rays(sy_rt_device *dev, const sy_rt_camera *camera, uint32_t width, uint32_t height,
                              uint32_t repeats, sy_rt_bench_result *out)
{
    if (dev && camera) sy_rt_clip_begin(dev, camera);
    if (!dev || !camera || !out) return sy_rt_fail(dev, SY_RT_ERROR_INVALID_ARGUMENT, "bench: NULL argument");
    if (repeats == 0) return sy_rt_fail(dev, SY_RT_ERROR_INVALID_ARGUMENT, "bench: repeats must be >= 1");
    if (dev->dirty)
        return sy_rt_fail(dev, SY_RT_ERROR_INVALID_OPERATION, "bench: the device has uncommitted changes; call sy_rt_commit first");
    size_t pixels, bytes;
    if (!sy_rt_size_mul(width, height, &pixels) || !sy_rt_size_mul(pixels, 4u * sizeof(float), &bytes))
        return sy_rt_fail(dev, SY_RT_ERROR_LIMIT, "bench: %ux%u overflows size_t", width, height);
    float *rgba = malloc(bytes ? bytes : 1);
    float *depth = malloc(pixels * sizeof(float) + 1), *raw = malloc(pixels * sizeof(float) + 1);
    if (!rgba || !depth || !raw) {
        free(rgba);
        free(depth);
        free(raw);
        return sy_rt_fail(dev, SY_RT_ERROR_OUT_OF_MEMORY, "bench: cannot allocate %ux%u buffers", width, height);
    }
    sy_rt_render_desc rd = {.integrator = SY_RT_INTEGRATOR_PRIMARY, .image_width = width, .image_height = height,
                            .width = width, .height = height};
    sy_rt_frame f;
    sy_rt_result r = sy_rt_frame_init(&f, dev, camera, &rd, rgba, depth);
    double best_primary = INFINITY, best_raw = INFINITY;
    for (uint32_t i = 0; r == SY_RT_OK && i <= repeats; ++i) { /* i == 0 warms up */
        double t0 = now_s();
        r = sy_rt_run_tiles(&f, sy_rt_primary_tile, NULL, NULL, NULL);
        double t1 = now_s();
        if (r == SY_RT_OK) r = sy_rt_run_tiles(&f, raw_tile, raw, NULL, NULL);
        double t2 = now_s();
        if (i > 0) {
            best_primary = fmin(best_primary, t1 - t0);
            best_raw = fmin(best_raw, t2 - t1);
        }
    }
    uint64_t hits = 0, differ = 0; /* the last frame of each: same rays, same hits, same depths */
    for (size_t i = 0; r == SY_RT_OK && i < pixels; ++i) {
        bool hp = isfinite(depth[i]), hr = isfinite(raw[i]);
        hits += hp;
        if (hp != hr || (hp && fabsf(depth[i] - raw[i]) > 1e-4f * fmaxf(1.0f, fabsf(raw[i])))) differ++;
    }
    free(rgba);
    free(depth);
    free(raw);
    if (r != SY_RT_OK) return r;
    out->hits = hits;
    out->differing_pixels = differ;
    out->width = width;
    out->height = height;
    out->repeats = repeats;
    out->threads = (uint32_t)sy_rt_render_threads(dev);
    out->primary_seconds = best_primary;
    out->raw_seconds = best_raw;
    out->primary_mrays = (double)pixels / best_primary * 1e-6;
    out->raw_mrays = (double)pixels / best_raw * 1e-6;
    out->overhead_percent = (best_primary / best_raw - 1.0) * 100.0;
    return SY_RT_OK;
}
