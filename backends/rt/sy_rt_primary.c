/* sy_rt_primary.c — the primary-ray integrator: one coherent rtcIntersect1 per pixel and eye-light
 * shading from the shared surface evaluation. */
#include "sy_rt_primary.h"
#include "sy_rt_surface.h"

void sy_rt_primary_tile(const sy_rt_frame *f, void *user, uint32_t x0, uint32_t y0, uint32_t x1, uint32_t y1)
{
    (void)user;
    const sy_rt_device *dev = f->dev;
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    const sy_rt_background *bg = &dev->background;
    float bg_alpha = bg->mode == SY_RT_BACKGROUND_COLOR ? 1.0f : 0.0f;
    for (uint32_t py = y0; py < y1; ++py) {
        for (uint32_t px = x0; px < x1; ++px) {
            struct RTCRayHit rh;
            float axial;
            sy_rt_frame_ray(f, px, py, &rh.ray, &axial);
            rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
            rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
            rtcIntersect1(dev->top, &ctx, &rh);
            size_t o = (size_t)(py - f->y) * f->width + (px - f->x);
            float *c = f->rgba + 4u * o;
            const sy_rt_instance_data *in = rh.hit.geomID == RTC_INVALID_GEOMETRY_ID
                                                ? NULL : sy_rt_hit_instance(dev, rh.hit.geomID, rh.hit.instID[0]);
            if (!in) {
                c[0] = bg_alpha * bg->color[0];
                c[1] = bg_alpha * bg->color[1];
                c[2] = bg_alpha * bg->color[2];
                c[3] = bg_alpha;
                if (f->depth) f->depth[o] = INFINITY;
                continue;
            }
            sy_rt_v3 dir = v3(rh.ray.dir_x, rh.ray.dir_y, rh.ray.dir_z);
            sy_rt_surface s;
            sy_rt_surface_fetch(dev, in, rh.hit.primID, rh.hit.u, rh.hit.v, dir, &s);
            sy_rt_v3 col;
            if (s.mat->emissive) col = s.emission;
            else if (s.mat->desc.unlit) col = s.base;
            else col = v3_scale(s.base, fabsf(v3_dot(s.ns, v3_normalize(dir))));
            c[0] = col.x;
            c[1] = col.y;
            c[2] = col.z;
            c[3] = 1.0f;
            if (f->depth) f->depth[o] = rh.ray.tfar * axial;
        }
    }
}
