/* sy_rt_frame.c — one frame's render state: validation, camera rays (perspective and orthographic
 * with an arbitrary image-plane window, so off-axis stereo frusta are the same code), and the tile
 * scheduler that runs an integrator over the requested rectangle on the OpenMP thread team (see
 * sy_rt_frame.h). Below the integrators: it calls none of them (sy_rt_render.c dispatches). */
#include "sy_rt_frame.h"

#include <omp.h>
#include <stdatomic.h>
#include <stdio.h>
#include <string.h>

#define FAIL(r, ...) sy_rt_fail(dev, (r), __VA_ARGS__)

/* >>camera motion: a rotation as a unit quaternion (x, y, z, w) */

/* The rotation of the camera's axes (columns x, y, z, with their lengths in *scale): false when they
 * are not orthogonal or not right-handed (then the caller lerps the columns). */
static bool orientation(sy_rt_v3 x, sy_rt_v3 y, sy_rt_v3 z, float q[4], sy_rt_v3 *scale)
{
    *scale = v3(v3_length(x), v3_length(y), v3_length(z));
    if (!(scale->x > 0.0f) || !(scale->y > 0.0f) || !(scale->z > 0.0f)) return false;
    sy_rt_v3 a = v3_scale(x, 1.0f / scale->x), b = v3_scale(y, 1.0f / scale->y), c = v3_scale(z, 1.0f / scale->z);
    if (fabsf(v3_dot(a, b)) > 1e-3f || fabsf(v3_dot(a, c)) > 1e-3f || fabsf(v3_dot(b, c)) > 1e-3f ||
        v3_dot(v3_cross(a, b), c) < 0.5f)
        return false;
    /* the matrix [a b c] (columns) to a quaternion (Shepperd: the largest of the four first) */
    float m00 = a.x, m11 = b.y, m22 = c.z, tr = m00 + m11 + m22;
    if (tr > 0.0f) {
        float s = sqrtf(tr + 1.0f) * 2.0f;
        q[3] = 0.25f * s, q[0] = (b.z - c.y) / s, q[1] = (c.x - a.z) / s, q[2] = (a.y - b.x) / s;
    } else if (m00 > m11 && m00 > m22) {
        float s = sqrtf(1.0f + m00 - m11 - m22) * 2.0f;
        q[3] = (b.z - c.y) / s, q[0] = 0.25f * s, q[1] = (b.x + a.y) / s, q[2] = (c.x + a.z) / s;
    } else if (m11 > m22) {
        float s = sqrtf(1.0f + m11 - m00 - m22) * 2.0f;
        q[3] = (c.x - a.z) / s, q[0] = (b.x + a.y) / s, q[1] = 0.25f * s, q[2] = (c.y + b.z) / s;
    } else {
        float s = sqrtf(1.0f + m22 - m00 - m11) * 2.0f;
        q[3] = (a.y - b.x) / s, q[0] = (c.x + a.z) / s, q[1] = (c.y + b.z) / s, q[2] = 0.25f * s;
    }
    float n = sqrtf(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (int i = 0; i < 4; ++i) q[i] /= n;
    return true;
}

/* Spherical linear interpolation of unit quaternions a and b (b on a's hemisphere) at t. */
static void slerp(const float a[4], const float b[4], float t, float out[4])
{
    float d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
    float wa, wb;
    if (d > 0.9995f) { /* nearly the same: lerp (normalised below) */
        wa = 1.0f - t, wb = t;
    } else {
        float th = acosf(sy_rt_minf(d, 1.0f)), s = sinf(th);
        wa = sinf((1.0f - t) * th) / s, wb = sinf(t * th) / s;
    }
    float n = 0.0f;
    for (int i = 0; i < 4; ++i) out[i] = wa * a[i] + wb * b[i], n += out[i] * out[i];
    n = sqrtf(n);
    for (int i = 0; i < 4; ++i) out[i] /= n;
}

/* The unit axes (the rotation matrix's columns) of unit quaternion q. */
static void quat_axes(const float q[4], sy_rt_v3 r[3])
{
    float x = q[0], y = q[1], z = q[2], w = q[3];
    r[0] = v3(1.0f - 2.0f * (y * y + z * z), 2.0f * (x * y + w * z), 2.0f * (x * z - w * y));
    r[1] = v3(2.0f * (x * y - w * z), 1.0f - 2.0f * (x * x + z * z), 2.0f * (y * z + w * x));
    r[2] = v3(2.0f * (x * z + w * y), 2.0f * (y * z - w * x), 1.0f - 2.0f * (x * x + y * y));
}

/* The camera's numbers are usable (which: "" or "shutter close: ", before the messages). */
static sy_rt_result camera_check(const sy_rt_device *dev, const sy_rt_camera *cam, const char *which)
{
    for (int i = 0; i < 16; ++i)
        if (!isfinite(cam->camera_to_world[i]))
            return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "render: %scamera_to_world[%d] is not finite", which, i);
    if (cam->projection != SY_RT_PROJECTION_PERSPECTIVE && cam->projection != SY_RT_PROJECTION_ORTHOGRAPHIC)
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "render: %sunknown projection %d", which, (int)cam->projection);
    for (int i = 0; i < 4; ++i)
        if (!isfinite(cam->window[i])) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "render: %scamera window[%d] is not finite", which, i);
    if (!(cam->window[0] < cam->window[1]) || !(cam->window[2] < cam->window[3]))
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "render: %scamera window {%g, %g, %g, %g} needs left < right and bottom < top", which,
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
            return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "render: %scamera rays would start up to %g away (camera at %g %g %g), "
                        "beyond SY_RT_COORD_MAX (%g)", which, reach, (double)m[12], (double)m[13], (double)m[14],
                        (double)SY_RT_COORD_MAX);
    }
    if (!isfinite(cam->near_clip) || cam->near_clip < 0.0f || !isfinite(cam->far_clip) || cam->far_clip < 0.0f ||
        (cam->far_clip > 0.0f && cam->far_clip <= cam->near_clip))
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "render: %sclip range near %g far %g is invalid (0 <= near < far, far 0 = infinite)", which,
                    (double)cam->near_clip, (double)cam->far_clip);
    return SY_RT_OK;
}

sy_rt_result sy_rt_frame_init(sy_rt_frame *f, const sy_rt_device *dev, const sy_rt_camera *cam,
                              const sy_rt_render_desc *d, float *rgba, float *depth)
{
    memset(f, 0, sizeof *f);
    sy_rt_result cr = camera_check(dev, cam, "");
    if (cr != SY_RT_OK) return cr;
    if (d->camera_close && (cr = camera_check(dev, d->camera_close, "shutter close: ")) != SY_RT_OK) return cr;
    if (d->camera_close && d->camera_close->projection != cam->projection)
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "render: the camera at the shutter's close has another projection");
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
    f->light_samples = d->area_light_samples; /* 0: the integrator's default */
    f->seed = d->seed;
    f->rgba = rgba;
    f->depth = depth;
    uint32_t steps = d->camera_close ? (d->camera_steps > 2u ? d->camera_steps : 2u) : 0u;
    if (steps > SY_RT_MOTION_STEPS_MAX || (steps > 2u && !d->camera_mid))
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "render: %u camera steps (2 .. %u, camera_mid for more than 2)",
                    d->camera_steps, SY_RT_MOTION_STEPS_MAX);
    for (uint32_t k = 1; k < steps; ++k) { /* the steps after the open; moving when one differs from it */
        const sy_rt_camera *ck = k + 1u == steps ? d->camera_close : d->camera_mid + (k - 1u);
        if (k + 1u < steps) {
            char which[32];
            snprintf(which, sizeof which, "camera step %u: ", k);
            if ((cr = camera_check(dev, ck, which)) != SY_RT_OK) return cr;
            if (ck->projection != cam->projection)
                return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "render: camera step %u has another projection", k);
        }
        if (memcmp(ck->camera_to_world, cam->camera_to_world, sizeof cam->camera_to_world) |
            memcmp(ck->window, cam->window, sizeof cam->window) | (ck->near_clip != cam->near_clip) |
            (ck->far_clip != cam->far_clip))
            f->cam_motion = true;
    }
    if (f->cam_motion) {
        f->cam_steps = steps;
        f->cam_slerp = true;
        bool finite = f->far_clip > 0.0f, mixed = false;
        for (uint32_t k = 0; k < steps; ++k) {
            const sy_rt_camera *ck = k == 0 ? cam : k + 1u == steps ? d->camera_close : d->camera_mid + (k - 1u);
            const float *m1 = ck->camera_to_world;
            struct sy_rt_cam_step *c = &f->cam_step[k];
            c->x = v3(m1[0], m1[1], m1[2]);
            c->y = v3(m1[4], m1[5], m1[6]);
            c->z = v3(m1[8], m1[9], m1[10]);
            c->pos = v3(m1[12], m1[13], m1[14]);
            if (v3_is_zero(c->z)) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "render: camera step %u: camera Z axis is zero", k);
            memcpy(c->window, ck->window, sizeof c->window);
            c->near_clip = ck->near_clip;
            c->far_clip = ck->far_clip;
            mixed |= (c->far_clip > 0.0f) != finite;
            f->cam_slerp = orientation(c->x, c->y, c->z, c->q, &c->scale) && f->cam_slerp;
            const float *p = k ? f->cam_step[k - 1u].q : NULL;
            if (p && p[0] * c->q[0] + p[1] * c->q[1] + p[2] * c->q[2] + p[3] * c->q[3] < 0.0f)
                for (int i = 0; i < 4; ++i) c->q[i] = -c->q[i]; /* the shorter way round */
        }
        if (mixed) { /* infinite at one step and finite at another: infinite throughout */
            f->far_clip = 0.0f;
            for (uint32_t k = 0; k < steps; ++k) f->cam_step[k].far_clip = 0.0f;
        }
    }
    return SY_RT_OK;
}

void sy_rt_frame_ray(const sy_rt_frame *f, uint32_t px, uint32_t py, struct RTCRay *ray, float *axial)
{
    sy_rt_frame_ray_at(f, (float)px + 0.5f, (float)py + 0.5f, ray, axial);
}

/* One camera's numbers for its rays (the frame's at time 0, or interpolated at a ray's time). */
typedef struct cam_basis {
    const float *window;
    sy_rt_v3 pos, x, y, z, forward;
    float near_clip, far_clip;
} cam_basis;

static inline void basis_ray(const sy_rt_frame *f, const cam_basis *c, float fx, float fy, struct RTCRay *ray,
                             float *axial)
{
    const float *w = c->window;
    float sx = w[0] + fx / (float)f->image_width * (w[1] - w[0]);
    float sy = w[3] - fy / (float)f->image_height * (w[3] - w[2]);
    sy_rt_v3 org, dir;
    if (f->projection == SY_RT_PROJECTION_PERSPECTIVE) {
        org = c->pos;
        dir = v3_sub(v3_add(v3_scale(c->x, sx), v3_scale(c->y, sy)), c->z);
    } else {
        org = v3_add(c->pos, v3_add(v3_scale(c->x, sx), v3_scale(c->y, sy)));
        dir = v3_scale(c->z, -1.0f);
    }
    float a = v3_dot(dir, c->forward);
    *axial = a;
    ray->org_x = org.x; ray->org_y = org.y; ray->org_z = org.z;
    ray->dir_x = dir.x; ray->dir_y = dir.y; ray->dir_z = dir.z;
    ray->tnear = c->near_clip / a;
    ray->tfar = c->far_clip > 0.0f ? c->far_clip / a : INFINITY;
    ray->time = 0.0f;
    ray->mask = 0xffffffffu;
    ray->id = 0;
    ray->flags = 0;
}

void sy_rt_frame_ray_at(const sy_rt_frame *f, float fx, float fy, struct RTCRay *ray, float *axial)
{
    cam_basis c = {f->window, f->cam_pos, f->cam_x, f->cam_y, f->cam_z, f->forward, f->near_clip, f->far_clip};
    basis_ray(f, &c, fx, fy, ray, axial);
}

static inline float lerpf(float a, float b, float t) { return a + (b - a) * t; }
static inline sy_rt_v3 v3_lerp(sy_rt_v3 a, sy_rt_v3 b, float t) { return v3_add(a, v3_scale(v3_sub(b, a), t)); }

void sy_rt_frame_ray_time(const sy_rt_frame *f, float fx, float fy, float time, struct RTCRay *ray, float *axial)
{
    if (!f->cam_motion || time == 0.0f) {
        sy_rt_frame_ray_at(f, fx, fy, ray, axial);
        ray->time = time;
        return;
    }
    /* the two steps around the time, as Embree finds them for moving instances */
    float st = time * (float)(f->cam_steps - 1u), t = st;
    uint32_t k = st > 0.0f ? (uint32_t)st : 0u;
    if (k > f->cam_steps - 2u) k = f->cam_steps - 2u;
    t = st - (float)k;
    const struct sy_rt_cam_step *a = &f->cam_step[k], *b = &f->cam_step[k + 1u];
    float window[4];
    for (int i = 0; i < 4; ++i) window[i] = lerpf(a->window[i], b->window[i], t);
    cam_basis c;
    c.window = window;
    c.pos = v3_lerp(a->pos, b->pos, t);
    c.near_clip = lerpf(a->near_clip, b->near_clip, t);
    c.far_clip = lerpf(a->far_clip, b->far_clip, t);
    if (f->cam_slerp) { /* the orientation slerped, the axes' lengths lerped */
        float q[4];
        slerp(a->q, b->q, t, q);
        sy_rt_v3 r[3];
        quat_axes(q, r);
        sy_rt_v3 s = v3_lerp(a->scale, b->scale, t);
        c.x = v3_scale(r[0], s.x), c.y = v3_scale(r[1], s.y), c.z = v3_scale(r[2], s.z);
    } else {
        c.x = v3_lerp(a->x, b->x, t);
        c.y = v3_lerp(a->y, b->y, t);
        c.z = v3_lerp(a->z, b->z, t);
    }
    c.forward = v3_normalize(v3_scale(c.z, -1.0f));
    if (v3_is_zero(c.forward)) c.forward = f->forward; /* lerped axes through zero (never with slerp) */
    basis_ray(f, &c, fx, fy, ray, axial);
    ray->time = time;
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
