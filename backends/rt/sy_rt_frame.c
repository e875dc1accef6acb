/* sy_rt_frame.c — one frame's render state: validation, camera rays (perspective and orthographic
 * with an arbitrary image-plane window, so off-axis stereo frusta are the same code), and the tile
 * scheduler that runs an integrator over the requested rectangle on the OpenMP thread team (see
 * sy_rt_frame.h). Below the integrators: it calls none of them (sy_rt_render.c dispatches). */
#include "sy_rt_frame.h"

#include <omp.h>
#include <stdatomic.h>
#include <string.h>

#define FAIL(r, ...) sy_rt_fail(dev, (r), __VA_ARGS__)

sy_rt_result sy_rt_frame_init(sy_rt_frame *f, const sy_rt_device *dev, const sy_rt_camera *cam,
                              const sy_rt_render_desc *d, float *rgba, float *depth)
{
    memset(f, 0, sizeof *f);
    for (int i = 0; i < 16; ++i)
        if (!isfinite(cam->camera_to_world[i]))
            return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "render: camera_to_world[%d] is not finite", i);
    if (cam->projection != SY_RT_PROJECTION_PERSPECTIVE && cam->projection != SY_RT_PROJECTION_ORTHOGRAPHIC)
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "render: unknown projection %d", (int)cam->projection);
    for (int i = 0; i < 4; ++i)
        if (!isfinite(cam->window[i])) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "render: camera window[%d] is not finite", i);
    if (!(cam->window[0] < cam->window[1]) || !(cam->window[2] < cam->window[3]))
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "render: camera window {%g, %g, %g, %g} needs left < right and bottom < top",
                    (double)cam->window[0], (double)cam->window[1], (double)cam->window[2], (double)cam->window[3]);
    /* SY_RT_COORD_MAX: the farthest a camera ray starts (its position, plus the window for an
     * orthographic camera) */
    {
        const float *m = cam->camera_to_world;
        double reach = fmax(fabs(m[12]), fmax(fabs(m[13]), fabs(m[14])));
        if (cam->projection == SY_RT_PROJECTION_ORTHOGRAPHIC) {
            double w = fmax(fmax(fabs(cam->window[0]), fabs(cam->window[1])), fmax(fabs(cam->window[2]), fabs(cam->window[3])));
            double ax = fmax(fabs(m[0]) + fabs(m[4]), fmax(fabs(m[1]) + fabs(m[5]), fabs(m[2]) + fabs(m[6])));
            reach += w * ax;
        }
        if (!(reach <= SY_RT_COORD_MAX))
            return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "render: camera rays would start up to %g away (camera at %g %g %g), "
                        "beyond SY_RT_COORD_MAX (%g)", reach, (double)m[12], (double)m[13], (double)m[14],
                        (double)SY_RT_COORD_MAX);
    }
    if (!isfinite(cam->near_clip) || cam->near_clip < 0.0f || !isfinite(cam->far_clip) || cam->far_clip < 0.0f ||
        (cam->far_clip > 0.0f && cam->far_clip <= cam->near_clip))
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "render: clip range near %g far %g is invalid (0 <= near < far, far 0 = infinite)",
                    (double)cam->near_clip, (double)cam->far_clip);
    if (d->integrator != SY_RT_INTEGRATOR_PRIMARY && d->integrator != SY_RT_INTEGRATOR_WHITTED &&
        d->integrator != SY_RT_INTEGRATOR_PATHTRACER && d->integrator != SY_RT_INTEGRATOR_COVERAGE)
        return FAIL(SY_RT_ERROR_UNSUPPORTED, "render: integrator %d is not implemented", (int)d->integrator);
    if (d->image_width == 0 || d->image_height == 0)
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "render: image size %ux%u is empty", d->image_width, d->image_height);
    if (d->width == 0 || d->height == 0 || d->x >= d->image_width || d->y >= d->image_height ||
        d->width > d->image_width - d->x || d->height > d->image_height - d->y)
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "render: rectangle %ux%u at (%u, %u) is empty or outside the %ux%u image",
                    d->width, d->height, d->x, d->y, d->image_width, d->image_height);
    size_t n;
    if (!sy_rt_size_mul(d->width, d->height, &n) || !sy_rt_size_mul(n, 4u * sizeof(float), &n))
        return FAIL(SY_RT_ERROR_LIMIT, "render: %ux%u rectangle overflows size_t", d->width, d->height);
    if (d->pixel_samples > 65536u || d->env_light_samples > 65536u || d->area_light_samples > 65536u ||
        (uint64_t)(d->pixel_samples ? d->pixel_samples : 1u) * (d->env_light_samples ? d->env_light_samples : 4u) > 65536u)
        return FAIL(SY_RT_ERROR_LIMIT, "render: pixel_samples %u, env_light_samples %u, area_light_samples %u: at most 65536 "
                    "each and 65536 environment samples per pixel", d->pixel_samples, d->env_light_samples, d->area_light_samples);
    if (!rgba && d->integrator != SY_RT_INTEGRATOR_PATHTRACER && d->integrator != SY_RT_INTEGRATOR_COVERAGE) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "render: rgba is NULL");

    const float *m = cam->camera_to_world;
    f->dev = dev;
    f->projection = cam->projection;
    memcpy(f->window, cam->window, sizeof f->window);
    f->cam_x = v3(m[0], m[1], m[2]);
    f->cam_y = v3(m[4], m[5], m[6]);
    f->cam_z = v3(m[8], m[9], m[10]);
    f->cam_pos = v3(m[12], m[13], m[14]);
    f->forward = v3_normalize(v3_scale(f->cam_z, -1.0f));
    if (v3_is_zero(f->forward)) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "render: camera Z axis is zero");
    f->near_clip = cam->near_clip;
    f->far_clip = cam->far_clip;
    f->image_width = d->image_width;
    f->image_height = d->image_height;
    f->x = d->x;
    f->y = d->y;
    f->width = d->width;
    f->height = d->height;
    f->integrator = d->integrator;
    f->max_depth = d->max_depth ? d->max_depth : 8u;
    f->light_samples = d->area_light_samples ? d->area_light_samples : 16u;
    f->seed = d->seed;
    f->rgba = rgba;
    f->depth = depth;
    return SY_RT_OK;
}

void sy_rt_frame_ray(const sy_rt_frame *f, uint32_t px, uint32_t py, struct RTCRay *ray, float *axial)
{
    sy_rt_frame_ray_at(f, (float)px + 0.5f, (float)py + 0.5f, ray, axial);
}

void sy_rt_frame_ray_at(const sy_rt_frame *f, float fx, float fy, struct RTCRay *ray, float *axial)
{
    const float *w = f->window;
    float sx = w[0] + fx / (float)f->image_width * (w[1] - w[0]);
    float sy = w[3] - fy / (float)f->image_height * (w[3] - w[2]);
    sy_rt_v3 org, dir;
    if (f->projection == SY_RT_PROJECTION_PERSPECTIVE) {
        org = f->cam_pos;
        dir = v3_sub(v3_add(v3_scale(f->cam_x, sx), v3_scale(f->cam_y, sy)), f->cam_z);
    } else {
        org = v3_add(f->cam_pos, v3_add(v3_scale(f->cam_x, sx), v3_scale(f->cam_y, sy)));
        dir = v3_scale(f->cam_z, -1.0f);
    }
    float a = v3_dot(dir, f->forward);
    *axial = a;
    ray->org_x = org.x; ray->org_y = org.y; ray->org_z = org.z;
    ray->dir_x = dir.x; ray->dir_y = dir.y; ray->dir_z = dir.z;
    ray->tnear = f->near_clip / a;
    ray->tfar = f->far_clip > 0.0f ? f->far_clip / a : INFINITY;
    ray->time = 0.0f;
    ray->mask = 0xffffffffu;
    ray->id = 0;
    ray->flags = 0;
}

/* >>scheduler */

/* One tile job on the process's OpenMP thread team: tiles are handed out one at a time in any
 * order (schedule(dynamic)); each tile's pixels depend only on the tile, never on the thread or the
 * order, so the result is the same for every thread count. Cancellation: a flag every worker reads
 * before a tile; once set the remaining tiles are skipped (the loop still runs out, at the cost of
 * one counter increment per skipped tile). Progress: reported after each finished tile under a
 * per-job lock, so calls are serialised, from whichever team thread finished the tile. */
sy_rt_result sy_rt_run_tiles(const sy_rt_frame *f, sy_rt_tile_fn fn, void *user, sy_rt_progress_fn progress,
                             void *progress_user)
{
    const sy_rt_device *dev = f->dev;
    uint64_t tiles_x64 = ((uint64_t)f->width + SY_RT_TILE_SIZE - 1u) / SY_RT_TILE_SIZE;
    uint64_t tiles_y64 = ((uint64_t)f->height + SY_RT_TILE_SIZE - 1u) / SY_RT_TILE_SIZE;
    if (tiles_x64 * tiles_y64 > INT32_MAX)
        return FAIL(SY_RT_ERROR_LIMIT, "render: %ux%u rectangle has too many tiles", f->width, f->height);
    const uint32_t tiles_x = (uint32_t)tiles_x64;
    const int tiles_total = (int)(tiles_x64 * tiles_y64);
    int threads = sy_rt_render_threads(f->dev);
    if (threads > tiles_total) threads = tiles_total;
    atomic_bool cancelled;
    atomic_init(&cancelled, false);
    uint32_t done = 0;
    omp_lock_t progress_lock;
    if (progress) omp_init_lock(&progress_lock);

#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) if (threads > 1) default(none) \
    shared(f, fn, user, progress, progress_user, cancelled, done, progress_lock) firstprivate(tiles_x, tiles_total)
    for (int t = 0; t < tiles_total; ++t) {
        if (atomic_load_explicit(&cancelled, memory_order_relaxed)) continue;
        uint32_t x0 = f->x + ((uint32_t)t % tiles_x) * SY_RT_TILE_SIZE, y0 = f->y + ((uint32_t)t / tiles_x) * SY_RT_TILE_SIZE;
        uint32_t x1 = x0 + SY_RT_TILE_SIZE, y1 = y0 + SY_RT_TILE_SIZE;
        if (x1 > f->x + f->width) x1 = f->x + f->width;
        if (y1 > f->y + f->height) y1 = f->y + f->height;
        fn(f, user, x0, y0, x1, y1);
        if (progress) {
            omp_set_lock(&progress_lock);
            sy_rt_progress p = {++done, (uint32_t)tiles_total};
            if (!progress(&p, progress_user)) atomic_store(&cancelled, true);
            omp_unset_lock(&progress_lock);
        }
    }

    if (progress) omp_destroy_lock(&progress_lock);
    if (atomic_load(&cancelled)) return FAIL(SY_RT_ERROR_CANCELLED, "render: cancelled by the progress callback");
    return SY_RT_OK;
}
