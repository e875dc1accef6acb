/* sy_rt_shadow.c — shadow-ray transmittance through alpha-blended and transmissive surfaces
 * (see sy_rt_shadow.h): an occlusion query when nothing in the scene is see-through, otherwise
 * closest-hit steps along the segment, multiplying what every crossed surface lets through. */
#include "sy_rt_shadow.h"
#include "sy_rt_raylog.h"
#include "sy_rt_surface.h"

/* Most surfaces one shadow ray crosses before it counts as blocked. */
#define MAX_CROSSINGS 32u

static bool material_blend(const sy_rt_material_data *m) { return m->desc.alpha_mode == SY_RT_ALPHA_BLEND; }
static bool material_transmits(const sy_rt_material_data *m)
{
    return m->desc.transmission > 0.0f && m->desc.metallic < 1.0f;
}

void sy_rt_shadow_flags_update(sy_rt_device *dev)
{
    bool blend = false, trans = false;
    for (uint32_t i = 0; i < dev->instances.count && !(blend && trans); ++i) {
        const sy_rt_instance_data *in = dev->instances.items[i];
        if (!in || (in->flags & SY_RT_INSTANCE_HIDDEN)) continue;
        const sy_rt_material_data *m = sy_rt_material_lookup(dev, in->material);
        blend = blend || material_blend(m);
        trans = trans || material_transmits(m);
    }
    dev->shadow_blend = blend;
    dev->shadow_transmission = trans;
}

sy_rt_v3 sy_rt_shadow_transmittance(const sy_rt_device *dev, struct RTCIntersectContext *ctx, sy_rt_v3 org,
                                    sy_rt_v3 dir, float tfar, bool transmission, uint64_t *rays,
                                    sy_rt_ray_buf *log)
{
    const sy_rt_v3 one = v3(1.0f, 1.0f, 1.0f), zero = v3(0.0f, 0.0f, 0.0f);
    if (!dev->shadow_blend && !(transmission && dev->shadow_transmission)) {
        if (rays) ++*rays;
        bool clear = sy_rt_segment_clear(dev, ctx, org, dir, tfar);
        if (log) sy_rt_ray_buf_add_occluded(log, org, dir, 0.0f, tfar, !clear);
        return clear ? one : zero;
    }
    sy_rt_v3 T = one;
    float tnear = 0.0f, inv_len = 1.0f / sy_rt_maxf(v3_length(dir), 1e-30f);
    const sy_rt_material_data *medium = NULL; /* the absorbing volume entered (KHR_materials_volume) */
    float t_enter = 0.0f;
    for (uint32_t k = 0; k <= MAX_CROSSINGS; ++k) {
        if (!(tnear < tfar)) return T;
        struct RTCRayHit rh;
        if (rays) ++*rays;
        const sy_rt_instance_data *in = sy_rt_intersect(dev, ctx, org, dir, tnear, tfar, &rh);
        if (log) sy_rt_ray_buf_add_hit(log, SY_RT_RAY_SHADOW, org, dir, tnear, tfar, &rh);
        if (!in) return T;
        if (k == MAX_CROSSINGS) break;
        const sy_rt_material_data *m = sy_rt_material_lookup(dev, in->material);
        bool blend = material_blend(m), trans = transmission && material_transmits(m);
        if (!blend && !trans) return zero;
        sy_rt_surface s;
        sy_rt_surface_fetch_at(dev, in, ((const sy_rt_ictx *)ctx)->time, rh.hit.primID, rh.hit.u, rh.hit.v, dir, &s);
        float a = blend ? sy_rt_clampf(s.alpha, 0.0f, 1.0f) : 1.0f; /* opacity */
        sy_rt_v3 pass = v3(1.0f - a, 1.0f - a, 1.0f - a);
        if (trans) {
            const sy_rt_material_desc *d = &m->desc;
            float r = (d->ior - 1.0f) / (d->ior + 1.0f), f0 = sy_rt_minf(r * r * v3_max_abs(s.specular_color), 1.0f);
            float w = a * (1.0f - s.metallic) * s.transmission * (1.0f - f0 * s.specular);
            sy_rt_v3 base = v3(sy_rt_clampf(s.base.x, 0.0f, 1.0f), sy_rt_clampf(s.base.y, 0.0f, 1.0f),
                               sy_rt_clampf(s.base.z, 0.0f, 1.0f));
            pass = v3_madd(pass, base, w);
        }
        T = v3_mul(T, pass);
        if (trans && m->volume) { /* Beer-Lambert over the path inside, from its front face to a back face */
            if (s.front) {
                medium = m, t_enter = rh.ray.tfar;
            } else if (medium == m) {
                float len = (rh.ray.tfar - t_enter) / inv_len;
                T = v3_mul(T, v3(expf(-m->sigma[0] * len), expf(-m->sigma[1] * len), expf(-m->sigma[2] * len)));
                medium = NULL;
            }
        }
        if (v3_max_abs(T) < 1e-6f) return zero;
        tnear = rh.ray.tfar + sy_rt_ray_eps(s.p) * inv_len;
    }
    return zero;
}
