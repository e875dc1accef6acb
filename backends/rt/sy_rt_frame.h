/* sy_rt_frame.h — per-frame render state shared by the integrators and the benchmark: the
 * validated camera with its primary-ray generator, the output rectangle, and the tile scheduler
 * (OpenMP: the process's thread team, dynamic tiles, progress and cancellation). Internal to
 * backends/rt. */
#ifndef SY_RT_FRAME_H
#define SY_RT_FRAME_H

#include "sy_rt_device.h"

#define SY_RT_TILE_SIZE 16u

typedef struct sy_rt_frame {
    const sy_rt_device *dev;
    sy_rt_projection projection;
    float window[4];
    sy_rt_v3 cam_pos, cam_x, cam_y, cam_z; /* camera-to-world columns */
    sy_rt_v3 forward;                      /* unit viewing axis (-Z in world) */
    float near_clip, far_clip;
    uint32_t image_width, image_height;
    uint32_t x, y, width, height;          /* output rectangle in full-image pixels */
    sy_rt_integrator integrator;
    uint32_t max_depth, light_samples, seed; /* light_samples 0: the integrator's default */
    float *rgba, *depth;                   /* output, row 0 = top of the rectangle */
    /* motion blur of the camera (sy_rt_render_desc.camera_close, camera_mid): the camera above at ray
     * time 0 (cam_step[0]), cam_step[k] at time k / (cam_steps - 1); cam_motion false when there is
     * none or every step equals the camera */
    bool cam_motion;
    bool cam_slerp;                        /* every orientation orthogonal: slerp, else the columns lerped */
    uint32_t cam_steps;
    struct sy_rt_cam_step {
        sy_rt_v3 pos, x, y, z;             /* camera-to-world columns */
        float q[4];                        /* the orientation (x, y, z, w), on the previous step's hemisphere */
        sy_rt_v3 scale;                    /* the columns' lengths */
        float window[4], near_clip, far_clip;
    } cam_step[SY_RT_MOTION_STEPS_MAX];
} sy_rt_frame;

/* Validates camera and desc and fills a frame (output pointers included). */
sy_rt_result sy_rt_frame_init(sy_rt_frame *f, const sy_rt_device *dev, const sy_rt_camera *cam,
                              const sy_rt_render_desc *desc, float *rgba, float *depth);

/* Camera ray through the centre of full-image pixel (px, py). The direction is not normalised:
 * `*axial` receives the viewing-axis distance per unit of t (depth = t * axial), and tnear/tfar
 * implement the near/far clip planes. */
void sy_rt_frame_ray(const sy_rt_frame *f, uint32_t px, uint32_t py, struct RTCRay *ray, float *axial);
/* The same through an arbitrary full-image point (fx, fy) (pixel (x, y) covers [x, x+1) x [y, y+1));
 * sy_rt_frame_ray(px, py) is sy_rt_frame_ray_at(px + 0.5, py + 0.5). */
void sy_rt_frame_ray_at(const sy_rt_frame *f, float fx, float fy, struct RTCRay *ray, float *axial);
/* The same at ray time `time` in [0, 1) (motion blur): the camera interpolated from the open to the
 * close (f->cam_motion; see sy_rt_render_desc.camera_close), ray->time set; without camera motion
 * sy_rt_frame_ray_at's ray bit for bit, with ray->time = time. */
void sy_rt_frame_ray_time(const sy_rt_frame *f, float fx, float fy, float time, struct RTCRay *ray, float *axial);

/* rtcIntersect1 on the top scene, then on the moved instances' scene (sy_rt_device.h); a hit on a
 * twin is reported under its instance's top-level id, so callers never see the difference. */
static inline void sy_rt_intersect_scenes(const sy_rt_device *dev, struct RTCIntersectContext *ctx,
                                          struct RTCRayHit *rh)
{
    rtcIntersect1(dev->top, ctx, rh);
    if (dev->dyn_count) {
        sy_rt_ictx *x = (sy_rt_ictx *)ctx; /* every context is one (sy_rt_context_init) */
        float t = rh->ray.tfar;
        sy_rt_ictx_enter_dyn(x);
        rtcIntersect1(dev->dyn, ctx, rh);
        sy_rt_ictx_leave_dyn(x);
        if (rh->ray.tfar < t) rh->hit.instID[0] = sy_rt_dyn_to_top(dev, rh->hit.instID[0]);
    }
}

/* Shadow / visibility ray shared by the integrators: true when nothing in the top scene blocks
 * org + t*dir for t in (0, tfar) at the context's time (sy_rt_ictx.time). Alpha-mask filters installed on geometry apply. */
static inline bool sy_rt_segment_clear(const sy_rt_device *dev, struct RTCIntersectContext *ctx, sy_rt_v3 org,
                                       sy_rt_v3 dir, float tfar)
{
    struct RTCRay r;
    r.org_x = org.x, r.org_y = org.y, r.org_z = org.z;
    r.dir_x = dir.x, r.dir_y = dir.y, r.dir_z = dir.z;
    r.tnear = 0.0f;
    r.tfar = tfar;
    r.time = ((const sy_rt_ictx *)ctx)->time; /* every context is one (sy_rt_context_init) */
    r.mask = 0xffffffffu;
    r.id = 0;
    r.flags = 0;
    rtcOccluded1(dev->top, ctx, &r);
    if (r.tfar >= 0.0f && dev->dyn_count) { /* moved instances (sy_rt_device.h) */
        sy_rt_ictx *x = (sy_rt_ictx *)ctx;   /* every context is one (sy_rt_context_init) */
        sy_rt_ictx_enter_dyn(x);
        rtcOccluded1(dev->dyn, ctx, &r);
        sy_rt_ictx_leave_dyn(x);
    }
    return r.tfar >= 0.0f;
}

/* Nearest hit of org + t*dir, t in [tnear, tfar], in the top scene at the context's time
 * (sy_rt_ictx.time): fills *rh and returns the instance hit (as stored: shading at the ray's time
 * reads sy_rt_instance_at), or NULL for a miss. */
static inline const sy_rt_instance_data *sy_rt_intersect(const sy_rt_device *dev, struct RTCIntersectContext *ctx,
                                                         sy_rt_v3 org, sy_rt_v3 dir, float tnear, float tfar,
                                                         struct RTCRayHit *rh)
{
    rh->ray.org_x = org.x, rh->ray.org_y = org.y, rh->ray.org_z = org.z;
    rh->ray.dir_x = dir.x, rh->ray.dir_y = dir.y, rh->ray.dir_z = dir.z;
    rh->ray.tnear = tnear;
    rh->ray.tfar = tfar;
    rh->ray.time = ((const sy_rt_ictx *)ctx)->time; /* motion blur: the ray's time */
    rh->ray.mask = 0xffffffffu;
    rh->ray.id = 0;
    rh->ray.flags = 0;
    rh->hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    sy_rt_intersect_scenes(dev, ctx, rh);
    return rh->hit.geomID == RTC_INVALID_GEOMETRY_ID ? NULL
                                                     : sy_rt_hit_instance(dev, rh->hit.geomID, rh->hit.instID[0]);
}

/* Nearest hit of the camera ray through the centre of pixel (px, py) (sy_rt_frame_ray): fills *rh
 * (geomID RTC_INVALID_GEOMETRY_ID on a miss) and *axial. */
static inline void sy_rt_frame_hit(const sy_rt_frame *f, struct RTCIntersectContext *ctx, uint32_t px, uint32_t py,
                                   struct RTCRayHit *rh, float *axial)
{
    sy_rt_frame_ray(f, px, py, &rh->ray, axial);
    rh->ray.time = ((const sy_rt_ictx *)ctx)->time;
    rh->hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    sy_rt_intersect_scenes(f->dev, ctx, rh);
}

/* The nearest hit of every pixel centre of the tile [x0, x1) x [y0, y1) (one coherent context for
 * the tile): fn gets the pixel's offset in the frame's buffers ((py - f->y) * f->width + px - f->x),
 * the hit (geomID RTC_INVALID_GEOMETRY_ID on a miss) and its axial factor (depth = tfar * axial).
 * Inline, so a known fn is inlined into the loop (the ray benchmark and coverage). */
static inline void sy_rt_frame_tile_hits(const sy_rt_frame *f, uint32_t x0, uint32_t y0, uint32_t x1, uint32_t y1,
                                         void (*fn)(const sy_rt_frame *f, void *user, size_t o,
                                                    const struct RTCRayHit *rh, float axial),
                                         void *user)
{
    sy_rt_ictx ctx;
    sy_rt_context_init(f->dev, &ctx, RTC_INTERSECT_CONTEXT_FLAG_COHERENT);
    for (uint32_t py = y0; py < y1; ++py)
        for (uint32_t px = x0; px < x1; ++px) {
            struct RTCRayHit rh;
            float axial;
            sy_rt_frame_hit(f, &ctx.rtc, px, py, &rh, &axial);
            fn(f, user, (size_t)(py - f->y) * f->width + (px - f->x), &rh, axial);
        }
}

/* Renders one tile: pixels [x0, x1) x [y0, y1) in full-image coordinates. */
typedef void (*sy_rt_tile_fn)(const sy_rt_frame *f, void *user, uint32_t x0, uint32_t y0, uint32_t x1, uint32_t y1);

/* Runs fn over all tiles of the frame's rectangle on the OpenMP thread team (sy_rt_render_threads
 * threads, the calling thread among them; one thread when called from inside an active parallel
 * region), handing tiles out dynamically. fn runs concurrently on distinct tiles and must write
 * only its tile's pixels. progress (may be NULL) is called after each tile, serialised, from the
 * thread that finished it; returning false skips the tiles not yet started and gives
 * SY_RT_ERROR_CANCELLED once the running ones are done. */
sy_rt_result sy_rt_run_tiles(const sy_rt_frame *f, sy_rt_tile_fn fn, void *user, sy_rt_progress_fn progress,
                             void *progress_user);

#endif /* SY_RT_FRAME_H */
