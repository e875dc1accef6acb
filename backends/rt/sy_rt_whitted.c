/* sy_rt_whitted.c — the Whitted integrator.
 *
 * Shading model (glTF metallic-roughness, Whitted-style):
 *   - emitters are pure emitters: a surface whose material emits shows its emission radiance
 *     (front side, or both sides when double-sided) and nothing else;
 *   - unlit materials show their base colour;
 *   - direct light: Lambert base*(1-metallic)*(1-transmission)/pi plus a GGX highlight (Schlick
 *     Fresnel, F0 = mix(0.04-from-IOR * specular, base, metallic)) for roughness > 0;
 *   - roughness == 0: recursive perfect reflection, metal part tinted by the base colour,
 *     dielectric part weighted by Schlick Fresnel * specular;
 *   - transmission: exact dielectric Fresnel between reflection and refraction (tinted by base
 *     colour), total internal reflection;
 *   - alpha blend: the surface is composited over what the continued ray sees.
 * Area lights use N samples per shading point: stratified light selection by power over the
 * area-light CDF and an R2 point set on the triangle, rotated per pixel (Cranley-Patterson) by a
 * hash of the full-image pixel, the seed and the recursion depth. The pattern never changes between
 * frames, so the image is deterministic. */
#include "sy_rt_whitted.h"
#include "sy_rt_lights.h"
#include "sy_rt_surface.h"

#define INV_PI 0.31830988618f

typedef struct trace_ctx {
    const sy_rt_frame *f;
    const sy_rt_device *dev;
    struct RTCIntersectContext ictx;
    uint32_t px, py;
} trace_ctx;

typedef struct rgba_t { sy_rt_v3 rgb; float a; } rgba_t;


/* True when nothing blocks the segment org + t*dir, t in (0, tfar). */
static bool visible(trace_ctx *c, sy_rt_v3 org, sy_rt_v3 dir, float tfar)
{
    return sy_rt_segment_clear(c->dev, &c->ictx, org, dir, tfar);
}

/* Specular reflectance at normal incidence of the dielectric part. */
static float dielectric_f0(const sy_rt_material_desc *d)
{
    float r = (d->ior - 1.0f) / (d->ior + 1.0f);
    return r * r * d->specular;
}

static sy_rt_v3 schlick(sy_rt_v3 f0, float cos_t)
{
    float m = 1.0f - sy_rt_clampf(cos_t, 0.0f, 1.0f);
    float m5 = m * m * m * m * m;
    return v3_add(f0, v3_scale(v3_sub(v3(1.0f, 1.0f, 1.0f), f0), m5));
}

/* BRDF value for light direction wi and view direction wo (both unit, away from the surface). */
static sy_rt_v3 brdf(const sy_rt_surface *s, sy_rt_v3 wi, sy_rt_v3 wo)
{
    const sy_rt_material_desc *d = &s->mat->desc;
    sy_rt_v3 r = v3_scale(s->base, (1.0f - s->metallic) * (1.0f - d->transmission) * INV_PI);
    if (s->roughness <= 0.0f) return r; /* delta lobe: handled by recursive reflection */
    float f0d = dielectric_f0(d);
    sy_rt_v3 f0 = v3_add(v3_scale(v3(f0d, f0d, f0d), 1.0f - s->metallic), v3_scale(s->base, s->metallic));
    if (v3_is_zero(f0)) return r;
    sy_rt_v3 h = v3_normalize(v3_add(wi, wo));
    float nl = v3_dot(s->ns, wi), nv = fmaxf(v3_dot(s->ns, wo), 1e-4f), nh = fmaxf(v3_dot(s->ns, h), 0.0f);
    float a = fmaxf(s->roughness * s->roughness, 1e-4f), a2 = a * a;
    float dd = nh * nh * (a2 - 1.0f) + 1.0f;
    float D = a2 * INV_PI / (dd * dd);
    float V = 0.5f / (nl * sqrtf(nv * nv * (1.0f - a2) + a2) + nv * sqrtf(nl * nl * (1.0f - a2) + a2));
    return v3_add(r, v3_scale(schlick(f0, v3_dot(wi, h)), D * V));
}

/* Per-pixel rotation bits for the sample pattern at a recursion depth. */
static uint32_t pixel_hash(const trace_ctx *c, uint32_t depth)
{
    return sy_rt_hash32(c->px ^ sy_rt_hash32(c->py ^ sy_rt_hash32(c->f->seed ^ sy_rt_hash32(depth + 0x9e3779b9u))));
}

static float fracf_(float x) { return x - floorf(x); }

static sy_rt_v3 direct_area(trace_ctx *c, const sy_rt_surface *s, sy_rt_v3 p_off, sy_rt_v3 wo, uint32_t depth)
{
    const sy_rt_device *dev = c->dev;
    uint32_t n = c->f->light_samples;
    uint32_t h = pixel_hash(c, depth);
    float r0 = sy_rt_u01(h), r1 = sy_rt_u01(sy_rt_hash32(h + 1u)), r2 = sy_rt_u01(sy_rt_hash32(h + 2u));
    sy_rt_v3 sum = v3(0.0f, 0.0f, 0.0f);
    for (uint32_t i = 0; i < n; ++i) {
        /* Stratified light selection by power (upper bound in the CDF). */
        float xi = ((float)i + r0) / (float)n;
        uint32_t lo = 0, hi = dev->area_count;
        while (lo + 1u < hi) {
            uint32_t mid = (lo + hi) / 2u;
            if (dev->area_cdf[mid] <= xi) lo = mid; else hi = mid;
        }
        float p_sel = dev->area_cdf[lo + 1u] - dev->area_cdf[lo];
        if (!(p_sel > 0.0f)) continue;
        const sy_rt_area_tri *t = &dev->area[lo];
        /* R2 low-discrepancy point set, uniformly warped onto the triangle. */
        float u1 = fracf_(r1 + 0.7548776662f * (float)i), u2 = fracf_(r2 + 0.5698402910f * (float)i);
        float su = sqrtf(u1);
        float bu = su * (1.0f - u2), bv = su * u2;
        sy_rt_v3 q = v3_add(t->p0, v3_add(v3_scale(t->e1, bu), v3_scale(t->e2, bv)));
        sy_rt_v3 wi = v3_sub(q, s->p);
        float d2 = v3_dot(wi, wi);
        if (!(d2 > 0.0f)) continue;
        float d = sqrtf(d2);
        wi = v3_scale(wi, 1.0f / d);
        float cos_l = -v3_dot(t->normal, wi);
        if (t->double_sided) cos_l = fabsf(cos_l);
        float cos_s = v3_dot(s->ns, wi);
        if (cos_l <= 0.0f || cos_s <= 0.0f || v3_dot(s->ng_facing, wi) <= 0.0f) continue;
        float tmax = d - sy_rt_ray_eps(q) - sy_rt_ray_eps(s->p);
        if (tmax > 0.0f && !visible(c, p_off, wi, tmax)) continue;
        sy_rt_v3 le = sy_rt_surface_emission(dev, t->inst, t->prim, bu, bv);
        float g = cos_s * cos_l / d2 * t->area / p_sel;
        sum = v3_add(sum, v3_scale(v3_mul(le, brdf(s, wi, wo)), g));
    }
    return v3_scale(sum, 1.0f / (float)n);
}

static sy_rt_v3 direct_punctual(trace_ctx *c, const sy_rt_surface *s, sy_rt_v3 p_off, sy_rt_v3 wo)
{
    const sy_rt_device *dev = c->dev;
    sy_rt_v3 sum = v3(0.0f, 0.0f, 0.0f);
    for (uint32_t i = 0; i < dev->punctual_count; ++i) {
        sy_rt_v3 wi, e;
        float tmax;
        if (!sy_rt_punctual_incident(&dev->punctual[i], s->p, &wi, &e, &tmax)) continue;
        float cos_s = v3_dot(s->ns, wi);
        if (cos_s <= 0.0f || v3_dot(s->ng_facing, wi) <= 0.0f) continue;
        if (!visible(c, p_off, wi, tmax)) continue;
        sum = v3_add(sum, v3_scale(v3_mul(e, brdf(s, wi, wo)), cos_s));
    }
    return sum;
}

static rgba_t trace(trace_ctx *c, sy_rt_v3 org, sy_rt_v3 dir, float tnear, float tfar, uint32_t depth,
                    struct RTCIntersectContext *ictx, float *t_hit);

/* Radiance along a secondary ray (background radiance on a miss, never alpha). */
static sy_rt_v3 trace_secondary(trace_ctx *c, sy_rt_v3 org, sy_rt_v3 dir, uint32_t depth)
{
    return trace(c, org, dir, 0.0f, INFINITY, depth, &c->ictx, NULL).rgb;
}

static sy_rt_v3 reflect(sy_rt_v3 d, sy_rt_v3 n) { return v3_sub(d, v3_scale(n, 2.0f * v3_dot(d, n))); }

/* Shades a hit; d is the unit ray direction. */
static rgba_t shade(trace_ctx *c, const sy_rt_surface *s, sy_rt_v3 d, uint32_t depth)
{
    const sy_rt_material_desc *md = &s->mat->desc;
    rgba_t out = {v3(0.0f, 0.0f, 0.0f), 1.0f};
    if (s->mat->emissive && (s->front || md->double_sided)) {
        out.rgb = s->emission;
        return out;
    }
    if (md->unlit) {
        out.rgb = s->base;
    } else {
        sy_rt_v3 wo = v3_scale(d, -1.0f);
        float eps = sy_rt_ray_eps(s->p);
        sy_rt_v3 p_out = v3_madd(s->p, s->ng_facing, eps);  /* the side the ray came from */
        sy_rt_v3 p_in = v3_madd(s->p, s->ng_facing, -eps);  /* the other side */
        sy_rt_v3 L = direct_punctual(c, s, p_out, wo);
        if (c->dev->area_count) L = v3_add(L, direct_area(c, s, p_out, wo, depth));
        bool recurse = depth + 1u < c->f->max_depth;
        float cos_o = fmaxf(v3_dot(s->ns, wo), 0.0f);
        if (recurse && s->roughness <= 0.0f) {
            sy_rt_v3 w = v3_scale(s->base, s->metallic);
            float fd = (1.0f - s->metallic) * (1.0f - md->transmission);
            if (fd > 0.0f) {
                float f0 = dielectric_f0(md);
                w = v3_add(w, v3_scale(schlick(v3(f0, f0, f0), cos_o), fd));
            }
            if (v3_max_abs(w) > 1e-4f) {
                sy_rt_v3 r = reflect(d, s->ns);
                if (v3_dot(r, s->ng_facing) > 0.0f) L = v3_add(L, v3_mul(w, trace_secondary(c, p_out, r, depth + 1u)));
            }
        }
        float wt = (1.0f - s->metallic) * md->transmission;
        if (recurse && wt > 0.0f) {
            /* Exact dielectric Fresnel; eta = n_incident / n_transmitted. */
            float eta = s->front ? 1.0f / md->ior : md->ior;
            float ci = sy_rt_clampf(v3_dot(s->ns, wo), 0.0f, 1.0f);
            float st2 = eta * eta * (1.0f - ci * ci);
            float F = 1.0f;
            sy_rt_v3 tdir = v3(0.0f, 0.0f, 0.0f);
            if (st2 < 1.0f) {
                float ct = sqrtf(1.0f - st2);
                float rs = (eta * ci - ct) / (eta * ci + ct), rp = (ci - eta * ct) / (ci + eta * ct);
                F = 0.5f * (rs * rs + rp * rp);
                tdir = v3_normalize(v3_add(v3_scale(d, eta), v3_scale(s->ns, eta * ci - ct)));
            }
            sy_rt_v3 r = reflect(d, s->ns);
            if (F > 0.0f) L = v3_add(L, v3_scale(trace_secondary(c, p_out, r, depth + 1u), wt * F));
            if (F < 1.0f) L = v3_add(L, v3_scale(v3_mul(s->base, trace_secondary(c, p_in, tdir, depth + 1u)), wt * (1.0f - F)));
        }
        out.rgb = L;
    }
    if (md->alpha_mode == SY_RT_ALPHA_BLEND && s->alpha < 1.0f) {
        float a = sy_rt_clampf(s->alpha, 0.0f, 1.0f);
        rgba_t behind = {v3(0.0f, 0.0f, 0.0f), 0.0f};
        if (depth + 1u < c->f->max_depth)
            behind = trace(c, v3_madd(s->p, s->ng_facing, -sy_rt_ray_eps(s->p)), d, 0.0f, INFINITY, depth + 1u, &c->ictx, NULL);
        out.rgb = v3_add(v3_scale(out.rgb, a), v3_scale(behind.rgb, 1.0f - a));
        out.a = a + (1.0f - a) * behind.a;
    }
    return out;
}

/* Traces a ray; returns premultiplied radiance + coverage. t_hit (optional) gets the hit t. */
static rgba_t trace(trace_ctx *c, sy_rt_v3 org, sy_rt_v3 dir, float tnear, float tfar, uint32_t depth,
                    struct RTCIntersectContext *ictx, float *t_hit)
{
    struct RTCRayHit rh;
    const sy_rt_instance_data *in = sy_rt_intersect(c->dev, ictx, org, dir, tnear, tfar, &rh);
    if (!in) {
        const sy_rt_background *bg = &c->dev->background;
        rgba_t r = {v3(0.0f, 0.0f, 0.0f), 0.0f};
        if (bg->mode == SY_RT_BACKGROUND_COLOR) {
            r.rgb = v3_load(bg->color);
            r.a = 1.0f;
        }
        if (c->dev->env_dist) { /* an environment map replaces the colour */
            sy_rt_env env;
            sy_rt_env_get(c->dev, &env);
            if (env.mode == 2) {
                r.rgb = sy_rt_env_eval(&env, v3_normalize(dir));
                r.a = 1.0f;
            }
        }
        if (t_hit) *t_hit = INFINITY;
        return r;
    }
    if (t_hit) *t_hit = rh.ray.tfar;
    sy_rt_v3 d = v3_normalize(dir);
    sy_rt_surface s;
    sy_rt_surface_fetch(c->dev, in, rh.hit.primID, rh.hit.u, rh.hit.v, d, &s);
    return shade(c, &s, d, depth);
}

void sy_rt_whitted_tile(const sy_rt_frame *f, void *user, uint32_t x0, uint32_t y0, uint32_t x1, uint32_t y1)
{
    (void)user;
    trace_ctx c;
    c.f = f;
    c.dev = f->dev;
    rtcInitIntersectContext(&c.ictx);
    struct RTCIntersectContext primary_ctx;
    rtcInitIntersectContext(&primary_ctx);
    primary_ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    for (uint32_t py = y0; py < y1; ++py) {
        for (uint32_t px = x0; px < x1; ++px) {
            c.px = px;
            c.py = py;
            struct RTCRay ray;
            float axial, t;
            sy_rt_frame_ray(f, px, py, &ray, &axial);
            rgba_t r = trace(&c, v3(ray.org_x, ray.org_y, ray.org_z), v3(ray.dir_x, ray.dir_y, ray.dir_z), ray.tnear,
                             ray.tfar, 0u, &primary_ctx, &t);
            size_t o = (size_t)(py - f->y) * f->width + (px - f->x);
            float *out = f->rgba + 4u * o;
            out[0] = r.rgb.x;
            out[1] = r.rgb.y;
            out[2] = r.rgb.z;
            out[3] = r.a;
            if (f->depth) f->depth[o] = isfinite(t) ? t * axial : INFINITY;
        }
    }
}
