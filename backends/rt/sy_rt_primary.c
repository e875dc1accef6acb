/* sy_rt_primary.c — the primary-ray integrator: coherent ray packets (rtcIntersect16 over 4x4 pixel
 * blocks aligned to the full-image pixel grid, so a pixel always shares its packet with the same
 * neighbours whatever the tile or sub-rectangle; lanes outside the tile are masked off) and the
 * lean eye-light shading of sy_rt_surface_eyelight. */
#include "sy_rt_primary.h"
#include "sy_rt_lights.h"
#include "sy_rt_surface.h"

#include <string.h>

#define PKT_W 4u
#define PKT_H 4u
#define PKT_N (PKT_W * PKT_H)

void sy_rt_primary_tile(const sy_rt_frame *f, void *user, uint32_t x0, uint32_t y0, uint32_t x1, uint32_t y1)
{
    (void)user;
    const sy_rt_device *dev = f->dev;
    sy_rt_ictx ctx;
    sy_rt_context_init(dev, &ctx, RTC_INTERSECT_CONTEXT_FLAG_COHERENT);
    float *const depth = f->depth;
    const uint32_t bx0 = x0 - x0 % PKT_W, by0 = y0 - y0 % PKT_H;
    for (uint32_t by = by0; by < y1; by += PKT_H) {
        for (uint32_t bx = bx0; bx < x1; bx += PKT_W) {
            struct RTCRayHit16 rh;
            _Alignas(64) int valid[PKT_N];
            float axial[PKT_N];
            for (uint32_t k = 0; k < PKT_N; ++k) {
                uint32_t px = bx + k % PKT_W, py = by + k / PKT_W;
                struct RTCRay r;
                bool on = px >= x0 && px < x1 && py >= y0 && py < y1;
                valid[k] = on ? -1 : 0;
                if (on) {
                    sy_rt_frame_ray(f, px, py, &r, &axial[k]);
                } else {
                    r = (struct RTCRay){.tnear = 0.0f, .tfar = -INFINITY, .mask = 0xffffffffu, .dir_z = -1.0f};
                    axial[k] = 1.0f;
                }
                rh.ray.org_x[k] = r.org_x; rh.ray.org_y[k] = r.org_y; rh.ray.org_z[k] = r.org_z;
                rh.ray.dir_x[k] = r.dir_x; rh.ray.dir_y[k] = r.dir_y; rh.ray.dir_z[k] = r.dir_z;
                rh.ray.tnear[k] = r.tnear; rh.ray.tfar[k] = r.tfar;
                rh.ray.time[k] = r.time; rh.ray.mask[k] = r.mask;
                rh.ray.id[k] = r.id; rh.ray.flags[k] = r.flags;
                rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
                rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
            }
            rtcIntersect16(valid, dev->top, &ctx.rtc, &rh);
            if (dev->dyn_count) { /* moved instances (sy_rt_device.h) */
                float t[PKT_N];
                memcpy(t, rh.ray.tfar, sizeof t);
                sy_rt_ictx_enter_dyn(&ctx);
                rtcIntersect16(valid, dev->dyn, &ctx.rtc, &rh);
                sy_rt_ictx_leave_dyn(&ctx);
                for (uint32_t k = 0; k < PKT_N; ++k)
                    if (valid[k] && rh.ray.tfar[k] < t[k]) rh.hit.instID[0][k] = sy_rt_dyn_to_top(dev, rh.hit.instID[0][k]);
            }
            for (uint32_t k = 0; k < PKT_N; ++k) {
                if (!valid[k]) continue;
                uint32_t px = bx + k % PKT_W, py = by + k / PKT_W;
                size_t o = (size_t)(py - f->y) * f->width + (px - f->x);
                float *c = f->rgba + 4u * o;
                const sy_rt_instance_data *in = rh.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID
                                                    ? NULL : sy_rt_hit_instance(dev, rh.hit.geomID[k], rh.hit.instID[0][k]);
                if (!in) {
                    sy_rt_v3 bg, d = v3(rh.ray.dir_x[k], rh.ray.dir_y[k], rh.ray.dir_z[k]);
                    c[3] = sy_rt_background_eval(dev, &d, &bg);
                    c[0] = bg.x;
                    c[1] = bg.y;
                    c[2] = bg.z;
                    if (depth) depth[o] = INFINITY;
                    continue;
                }
                sy_rt_v3 dir = v3(rh.ray.dir_x[k], rh.ray.dir_y[k], rh.ray.dir_z[k]);
                float t_cap;
                if (sy_rt_clip_cap(dev, in, rh.hit.primID[k], v3(rh.ray.org_x[k], rh.ray.org_y[k], rh.ray.org_z[k]), dir,
                                   rh.ray.tnear[k], rh.ray.tfar[k], &t_cap)) { /* a section cap: its flat colour */
                    memcpy(c, dev->clip_cap_color, 3 * sizeof *c);
                    c[3] = 1.0f;
                    if (depth) depth[o] = t_cap * axial[k];
                    continue;
                }
                sy_rt_v3 col = sy_rt_surface_eyelight(dev, in, rh.hit.primID[k], rh.hit.u[k], rh.hit.v[k], dir);
                c[0] = col.x;
                c[1] = col.y;
                c[2] = col.z;
                c[3] = 1.0f;
                if (depth) depth[o] = rh.ray.tfar[k] * axial[k];
            }
        }
    }
}
