/* sy_rt_whitted.c — the Whitted integrator.
 *
 * Per pixel: pixel_samples camera rays (1 = the pixel centre; more = stratified jittered points,
 * the first points of an Owen-scrambled Sobol sequence per pixel, averaged: a box filter over the
 * pixel). Per hit, shading model (glTF metallic-roughness, Whitted-style):
 *   - emission (front side, or both sides when double-sided) is ADDED to the reflected light;
 *   - unlit materials show their base colour (plus emission);
 *   - direct light from punctual lights, emissive triangles and the environment with the path
 *     tracer's BSDF (sy_rt_bsdf.h: GGX metal, GGX specular over Lambert scaled by 1 - F, the
 *     finite-density lobes), the environment with the path tracer's MIS of an environment sample
 *     and a BSDF sample, so Whitted's direct light is the path tracer's direct light;
 *   - roughness below SY_RT_BSDF_DELTA_ROUGHNESS (the path tracer's delta lobes): recursive
 *     perfect reflection, metal part tinted by the base colour, dielectric part weighted by
 *     Schlick Fresnel * specular;
 *   - transmission: exact dielectric Fresnel between reflection and refraction (tinted by base
 *     colour), total internal reflection;
 *   - alpha blend: the surface is composited over what the continued ray sees.
 * Shadow rays pass alpha-masked holes, alpha-blended and transmissive surfaces with their
 * transmittance (sy_rt_shadow.h). Camera rays that hit nothing see the background; every other
 * escaping ray sees the environment light (black without one).
 * Light samples: area lights take n = ceil(area_light_samples / pixel_samples) samples per shading
 * point (light chosen by power through the area-light CDF, uniform point on the triangle), the
 * environment env_light_samples (each an environment and a BSDF sample, MIS); the
 * numbers come from the pixel's Owen-scrambled Sobol sequence (sy_rt_sampler.h), sample k of pixel
 * sample j being point j*n + k of a set chosen by the recursion depth, so the samples of one pixel
 * are stratified together and every pixel has its own scramble: no pattern shared between pixels
 * (no banding), no change between frames (deterministic). */
#include "sy_rt_whitted.h"
#include "sy_rt_bsdf.h"
#include "sy_rt_iridescence.h"
#include "sy_rt_lights.h"
#include "sy_rt_sampler.h"
#include "sy_rt_shadow.h"
#include "sy_rt_surface.h"

#include <stdlib.h>

#define INV_PI 0.31830988618f

/* Sobol sets of a pixel: 0 = sub-pixel positions; per recursion depth d, area-light samples,
 * environment samples and BSDF samples for the environment. */
#define SET_AREA(d) (1u + 3u * (d))
#define SET_ENV(d) (2u + 3u * (d))
#define SET_BSDF(d) (3u + 3u * (d))

typedef struct whitted_job {
    const sy_rt_sobol *sobol; /* the device's */
    sy_rt_env env;
    uint32_t spp;    /* camera rays per pixel */
    uint32_t n_area; /* area-light samples per shading point */
    uint32_t n_env;  /* environment samples per shading point (0 without an environment) */
} whitted_job;

typedef struct trace_ctx {
    const sy_rt_frame *f;
    const sy_rt_device *dev;
    const whitted_job *job;
    sy_rt_ictx ictx;
    uint32_t pseed;  /* per-pixel scramble seed */
    uint32_t sample; /* pixel sample index */
} trace_ctx;

typedef struct rgba_t { sy_rt_v3 rgb; float a; } rgba_t;

/* Light let through between org and org + tfar*dir (alpha, transmission). */
static sy_rt_v3 shadow(trace_ctx *c, sy_rt_v3 org, sy_rt_v3 dir, float tfar)
{
    return sy_rt_shadow_transmittance(c->dev, &c->ictx.rtc, org, dir, tfar, true, NULL, NULL);
}
/* Specular reflectance at normal incidence of the dielectric part (KHR_materials_specular: factor
 * and colour). */
static sy_rt_v3 dielectric_f0(const sy_rt_material_desc *d, const sy_rt_surface *s)
{
    float r = (d->ior - 1.0f) / (d->ior + 1.0f);
    sy_rt_v3 c = s->specular_color;
    return v3_scale(v3(sy_rt_minf(r * r * c.x, 1.0f), sy_rt_minf(r * r * c.y, 1.0f), sy_rt_minf(r * r * c.z, 1.0f)),
                    s->specular);
}

static sy_rt_v3 schlick(sy_rt_v3 f0, float cos_t)
{
    float m = 1.0f - sy_rt_clampf(cos_t, 0.0f, 1.0f);
    float m5 = m * m * m * m * m;
    return v3_add(f0, v3_scale(v3_sub(v3(1.0f, 1.0f, 1.0f), f0), m5));
}

/* Sobol point k of this pixel sample's shading-point samples in set `set`. */
static void light_u(const trace_ctx *c, uint32_t set, uint32_t n, uint32_t k, float u[4])
{
    sy_rt_sobol_sample4(c->job->sobol, c->pseed, set, c->sample * n + k, u);
}

static sy_rt_v3 direct_area(trace_ctx *c, const sy_rt_surface *s, const sy_rt_bsdf *b, sy_rt_v3 p_off, sy_rt_v3 wo,
                            uint32_t depth)
{
    const sy_rt_device *dev = c->dev;
    uint32_t n = c->job->n_area;
    sy_rt_v3 sum = v3(0.0f, 0.0f, 0.0f);
    for (uint32_t i = 0; i < n; ++i) {
        float u[4];
        light_u(c, SET_AREA(depth), n, i, u);
        /* Light selection by power (upper bound in the CDF). */
        float xi = u[0];
        uint32_t lo = 0, hi = dev->area_count;
        while (lo + 1u < hi) {
            uint32_t mid = (lo + hi) / 2u;
            if (dev->area_cdf[mid] <= xi) lo = mid; else hi = mid;
        }
        float p_sel = dev->area_cdf[lo + 1u] - dev->area_cdf[lo];
        if (!(p_sel > 0.0f)) continue;
        const sy_rt_area_tri *t = &dev->area[lo];
        float su = sqrtf(u[1]);
        float bu = su * (1.0f - u[2]), bv = su * u[2];
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
        float pdf_b;
        sy_rt_v3 f = sy_rt_bsdf_eval(b, wo, wi, &pdf_b); /* includes cos_s */
        if (v3_is_zero(f)) continue;
        sy_rt_v3 sdir;
        float tmax;
        sy_rt_v3 tr = sy_rt_segment_to(p_off, q, &sdir, &tmax) ? shadow(c, p_off, sdir, tmax) : v3(1.0f, 1.0f, 1.0f);
        if (v3_is_zero(tr)) continue;
        sy_rt_v3 le = v3_mul(tr, t->textured ? sy_rt_surface_emission(dev, t->inst, t->prim, bu, bv) : t->emission);
        float g = cos_l / d2 * t->area / p_sel;
        sum = v3_add(sum, v3_scale(v3_mul(le, f), g));
    }
    return v3_scale(sum, 1.0f / (float)n);
}

static float power_heuristic(float a, float b)
{
    float a2 = a * a, b2 = b * b;
    return a2 + b2 > 0.0f ? a2 / (a2 + b2) : 0.0f;
}

/* Environment light, exactly the path tracer's direct light from the environment: per sample one
 * direction from the environment's importance distribution and one from the BSDF (the path
 * tracer's sy_rt_bsdf, so glossy lobes that the environment's distribution rarely hits are found),
 * combined with the power heuristic, each with a shadow ray. Delta lobes (roughness 0 mirrors,
 * refraction) see the environment through Whitted's recursive rays instead. */
static sy_rt_v3 direct_env(trace_ctx *c, const sy_rt_surface *s, const sy_rt_bsdf *b, sy_rt_v3 p_off, sy_rt_v3 wo,
                           uint32_t depth)
{
    const sy_rt_env *env = &c->job->env;
    sy_rt_v3 sum = v3(0.0f, 0.0f, 0.0f);
    uint32_t n = c->job->n_env;
    for (uint32_t i = 0; i < n; ++i) {
        float ul[4], ub[4];
        light_u(c, SET_ENV(depth), n, i, ul);
        light_u(c, SET_BSDF(depth), n, i, ub);
        /* light strategy */
        sy_rt_v3 wi, le;
        float pdf_l = sy_rt_env_sample(env, ul[0], ul[1], &wi, &le);
        if (pdf_l > 0.0f && !v3_is_zero(le) && v3_dot(s->ng_facing, wi) > 0.0f) {
            float pdf_b;
            sy_rt_v3 f = sy_rt_bsdf_eval(b, wo, wi, &pdf_b);
            if (!v3_is_zero(f)) {
                sy_rt_v3 tr = shadow(c, p_off, wi, INFINITY);
                if (!v3_is_zero(tr))
                    sum = v3_add(sum, v3_scale(v3_mul(v3_mul(f, le), tr), power_heuristic(pdf_l, pdf_b) / pdf_l));
            }
        }
        /* BSDF strategy */
        sy_rt_bsdf_sample bs;
        if (sy_rt_bsdf_sample_dir(b, wo, ub, &bs) && !bs.specular && !bs.transmit && bs.pdf > 0.0f &&
            v3_dot(s->ng_facing, bs.wi) > 0.0f) {
            sy_rt_v3 lb = sy_rt_env_eval(env, bs.wi);
            if (!v3_is_zero(lb)) {
                sy_rt_v3 tr = shadow(c, p_off, bs.wi, INFINITY);
                if (!v3_is_zero(tr))
                    sum = v3_add(sum, v3_scale(v3_mul(v3_mul(bs.weight, lb), tr),
                                               power_heuristic(bs.pdf, sy_rt_env_pdf(env, bs.wi))));
            }
        }
    }
    return v3_scale(sum, 1.0f / (float)n);
}

static sy_rt_v3 direct_punctual(trace_ctx *c, const sy_rt_surface *s, const sy_rt_bsdf *b, sy_rt_v3 p_off, sy_rt_v3 wo)
{
    const sy_rt_device *dev = c->dev;
    sy_rt_v3 sum = v3(0.0f, 0.0f, 0.0f);
    for (uint32_t i = 0; i < dev->punctual_count; ++i) {
        sy_rt_v3 wi, e;
        float tmax;
        if (!sy_rt_punctual_incident(&dev->punctual[i], s->p, &wi, &e, &tmax)) continue;
        float cos_s = v3_dot(s->ns, wi);
        if (cos_s <= 0.0f || v3_dot(s->ng_facing, wi) <= 0.0f) continue;
        float pdf_b;
        sy_rt_v3 f = sy_rt_bsdf_eval(b, wo, wi, &pdf_b); /* includes cos_s */
        if (v3_is_zero(f)) continue;
        sy_rt_v3 tr = shadow(c, p_off, wi, tmax);
        if (v3_is_zero(tr)) continue;
        sum = v3_add(sum, v3_mul(v3_mul(e, tr), f));
    }
    return sum;
}

static rgba_t trace(trace_ctx *c, sy_rt_v3 org, sy_rt_v3 dir, float tnear, float tfar, uint32_t depth, bool camera,
                    struct RTCIntersectContext *ictx, float *t_hit);

/* Radiance along a secondary ray (the environment on a miss, never alpha). */
static sy_rt_v3 trace_secondary(trace_ctx *c, sy_rt_v3 org, sy_rt_v3 dir, uint32_t depth)
{
    return trace(c, org, dir, 0.0f, INFINITY, depth, false, &c->ictx.rtc, NULL).rgb;
}

/* A secondary ray travelling inside material m's volume (KHR_materials_volume): its light is
 * absorbed over the distance to the next hit (Beer-Lambert); a ray that leaves through an opening
 * is not. */
static sy_rt_v3 trace_inside(trace_ctx *c, const sy_rt_material_data *m, sy_rt_v3 org, sy_rt_v3 dir, uint32_t depth)
{
    if (!m->volume) return trace_secondary(c, org, dir, depth);
    float t;
    sy_rt_v3 l = trace(c, org, dir, 0.0f, INFINITY, depth, false, &c->ictx.rtc, &t).rgb;
    if (!isfinite(t)) return l;
    return v3_mul(l, v3(expf(-m->sigma[0] * t), expf(-m->sigma[1] * t), expf(-m->sigma[2] * t)));
}

static sy_rt_v3 reflect(sy_rt_v3 d, sy_rt_v3 n) { return v3_sub(d, v3_scale(n, 2.0f * v3_dot(d, n))); }

/* Shades a hit; d is the unit ray direction; camera: the ray is a camera ray (for what an
 * alpha-blended surface shows behind it). */
static rgba_t shade(trace_ctx *c, const sy_rt_surface *s, sy_rt_v3 d, uint32_t depth, bool camera)
{
    const sy_rt_material_desc *md = &s->mat->desc;
    rgba_t out = {v3(0.0f, 0.0f, 0.0f), 1.0f};
    sy_rt_v3 emit = v3(0.0f, 0.0f, 0.0f);
    if (s->mat->emissive && (s->front || md->double_sided)) emit = s->emission;
    if (md->unlit) {
        out.rgb = s->base;
    } else {
        sy_rt_v3 wo = v3_scale(d, -1.0f);
        float eps = sy_rt_ray_eps(s->p);
        sy_rt_v3 p_out = v3_madd(s->p, s->ng_facing, eps);  /* the side the ray came from */
        sy_rt_v3 p_in = v3_madd(s->p, s->ng_facing, -eps);  /* the other side */
        sy_rt_v3 L = v3(0.0f, 0.0f, 0.0f);
        sy_rt_bsdf b;
        sy_rt_bsdf_init(&b, s, wo);
        if (sy_rt_bsdf_evaluable(&b)) {
            L = direct_punctual(c, s, &b, p_out, wo);
            if (c->dev->area_count) L = v3_add(L, direct_area(c, s, &b, p_out, wo, depth));
            if (c->job->n_env) L = v3_add(L, direct_env(c, s, &b, p_out, wo, depth));
        }
        bool recurse = depth + 1u < c->f->max_depth;
        float cos_o = fmaxf(v3_dot(s->ns, wo), 0.0f);
        if (recurse && b.delta) { /* the path tracer's delta lobes: a perfect mirror */
            sy_rt_v3 w = v3_scale(s->base, s->metallic);
            float fd = (1.0f - s->metallic) * (1.0f - s->transmission);
            if (fd > 0.0f) w = v3_add(w, v3_scale(schlick(dielectric_f0(md, s), cos_o), fd));
            if (b.irid > 0.0f) { /* KHR_materials_iridescence: the thin film's Fresnel mixed into both */
                sy_rt_v3 fm = sy_rt_iridescence_fresnel(cos_o, b.irid_ior, b.irid_thick, s->base);
                sy_rt_v3 fi = v3_scale(sy_rt_iridescence_fresnel(cos_o, b.irid_ior, b.irid_thick, b.f0c), b.spec);
                sy_rt_v3 wm = v3_add(v3_scale(s->base, 1.0f - b.irid), v3_scale(fm, b.irid));
                sy_rt_v3 wd = v3_add(v3_scale(schlick(dielectric_f0(md, s), cos_o), 1.0f - b.irid), v3_scale(fi, b.irid));
                w = v3_add(v3_scale(wm, s->metallic), v3_scale(wd, fd));
            }
            w = v3_scale(w, b.under); /* under a coat and a sheen */
            if (v3_max_abs(w) > 1e-4f) {
                sy_rt_v3 r = reflect(d, s->ns);
                if (v3_dot(r, s->ng_facing) > 0.0f) L = v3_add(L, v3_mul(w, trace_secondary(c, p_out, r, depth + 1u)));
            }
        }
        if (recurse && b.cc > 0.0f && b.cc_delta) { /* a smooth clearcoat: its mirror ray (F0 0.04) */
            sy_rt_v3 nc = b.cc_n ? b.ncc : s->ns; /* the coat's own normal */
            float w = b.cc * schlick(v3(0.04f, 0.04f, 0.04f), b.cc_n ? fmaxf(v3_dot(nc, wo), 0.0f) : cos_o).x;
            sy_rt_v3 r = reflect(d, nc);
            if (v3_dot(r, s->ng_facing) > 0.0f) L = v3_add(L, v3_scale(trace_secondary(c, p_out, r, depth + 1u), w));
        }
        float wt = (1.0f - s->metallic) * s->transmission * b.under;
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
            /* KHR_materials_iridescence on the way in: the film's colour in the Fresnel split */
            sy_rt_v3 fr = v3(F, F, F), ft = v3(1.0f - F, 1.0f - F, 1.0f - F);
            if (b.irid > 0.0f && s->front && F < 1.0f) {
                sy_rt_v3 fi = sy_rt_iridescence_fresnel(ci, b.irid_ior, b.irid_thick, v3(b.f0d, b.f0d, b.f0d));
                fr = v3(sy_rt_clampf(F + b.irid * (fi.x - F), 0.0f, 1.0f), sy_rt_clampf(F + b.irid * (fi.y - F), 0.0f, 1.0f),
                        sy_rt_clampf(F + b.irid * (fi.z - F), 0.0f, 1.0f));
                ft = v3(1.0f - fr.x, 1.0f - fr.y, 1.0f - fr.z);
            }
            /* entering (front): the refracted ray is inside; leaving: the reflected one stays inside */
            if (F > 0.0f)
                L = v3_add(L, v3_mul(s->front ? trace_secondary(c, p_out, r, depth + 1u) : trace_inside(c, s->mat, p_out, r, depth + 1u),
                                     v3_scale(fr, wt)));
            if (F < 1.0f) {
                sy_rt_v3 lt = s->front ? trace_inside(c, s->mat, p_in, tdir, depth + 1u) : trace_secondary(c, p_in, tdir, depth + 1u);
                L = v3_add(L, v3_mul(v3_mul(s->base, lt), v3_scale(ft, wt)));
            }
        }
        out.rgb = L;
    }
    out.rgb = v3_add(emit, out.rgb); /* emission adds to the reflected light */
    if (md->alpha_mode == SY_RT_ALPHA_BLEND && s->alpha < 1.0f) {
        float a = sy_rt_clampf(s->alpha, 0.0f, 1.0f);
        rgba_t behind = {v3(0.0f, 0.0f, 0.0f), 0.0f};
        if (depth + 1u < c->f->max_depth)
            behind = trace(c, v3_madd(s->p, s->ng_facing, -sy_rt_ray_eps(s->p)), d, 0.0f, INFINITY, depth + 1u, camera,
                           &c->ictx.rtc, NULL);
        out.rgb = v3_add(v3_scale(out.rgb, a), v3_scale(behind.rgb, 1.0f - a));
        out.a = a + (1.0f - a) * behind.a;
    }
    return out;
}

/* Traces a ray; returns premultiplied radiance + coverage. t_hit (optional) gets the hit t. */
static rgba_t trace(trace_ctx *c, sy_rt_v3 org, sy_rt_v3 dir, float tnear, float tfar, uint32_t depth, bool camera,
                    struct RTCIntersectContext *ictx, float *t_hit)
{
    struct RTCRayHit rh;
    const sy_rt_instance_data *in = sy_rt_intersect(c->dev, ictx, org, dir, tnear, tfar, &rh);
    if (!in) {
        rgba_t r = {v3(0.0f, 0.0f, 0.0f), 0.0f};
        if (camera) r.a = sy_rt_background_eval(c->dev, dir, &r.rgb); /* the background */
        else r.rgb = sy_rt_env_eval(&c->job->env, v3_normalize(dir)); /* the environment light */
        if (t_hit) *t_hit = INFINITY;
        return r;
    }
    if (t_hit) *t_hit = rh.ray.tfar;
    sy_rt_v3 d = v3_normalize(dir);
    sy_rt_surface s;
    sy_rt_surface_fetch(c->dev, in, rh.hit.primID, rh.hit.u, rh.hit.v, d, &s);
    return shade(c, &s, d, depth, camera);
}

static void whitted_tile(const sy_rt_frame *f, void *user, uint32_t x0, uint32_t y0, uint32_t x1, uint32_t y1)
{
    const whitted_job *j = user;
    trace_ctx c;
    c.f = f;
    c.dev = f->dev;
    c.job = j;
    sy_rt_context_init(f->dev, &c.ictx, RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT);
    sy_rt_ictx primary_ctx;
    sy_rt_context_init(f->dev, &primary_ctx, RTC_INTERSECT_CONTEXT_FLAG_COHERENT);
    for (uint32_t py = y0; py < y1; ++py) {
        for (uint32_t px = x0; px < x1; ++px) {
            c.pseed = sy_rt_hash32(px ^ sy_rt_hash32(py ^ sy_rt_hash32(f->seed ^ 0x3c6ef372u)));
            sy_rt_v3 sum = v3(0.0f, 0.0f, 0.0f);
            float alpha = 0.0f, dsum = 0.0f;
            uint32_t hits = 0;
            for (uint32_t k = 0; k < j->spp; ++k) {
                float fx = (float)px + 0.5f, fy = (float)py + 0.5f;
                if (j->spp > 1u) {
                    float u[4];
                    sy_rt_sobol_sample4(j->sobol, c.pseed, 0u, k, u);
                    fx = (float)px + u[0];
                    fy = (float)py + u[1];
                }
                c.sample = k;
                struct RTCRay ray;
                float axial, t;
                sy_rt_frame_ray_at(f, fx, fy, &ray, &axial);
                rgba_t r = trace(&c, v3(ray.org_x, ray.org_y, ray.org_z), v3(ray.dir_x, ray.dir_y, ray.dir_z), ray.tnear,
                                 ray.tfar, 0u, true, &primary_ctx.rtc, &t);
                sum = v3_add(sum, r.rgb);
                alpha += r.a;
                if (isfinite(t)) dsum += t * axial, hits++;
            }
            size_t o = (size_t)(py - f->y) * f->width + (px - f->x);
            float *out = f->rgba + 4u * o;
            float n = (float)j->spp; /* divide (not multiply by 1/n): n equal samples average exactly */
            out[0] = sum.x / n;
            out[1] = sum.y / n;
            out[2] = sum.z / n;
            out[3] = alpha / n;
            /* coverage = any stratum hit, depth = the mean of those that hit: with fractional alpha
             * at anti-aliased edges, as the path tracer's accumulation and the raster's MSAA
             * resolve (nearest sample) give it, so depth compositing keeps the edges */
            if (f->depth) f->depth[o] = hits ? dsum / (float)hits : INFINITY;
        }
    }
}

sy_rt_result sy_rt_whitted_render(const sy_rt_frame *f, const sy_rt_render_desc *desc)
{
    const sy_rt_device *dev = f->dev;
    whitted_job *j = malloc(sizeof *j);
    if (!j) return sy_rt_fail(dev, SY_RT_ERROR_OUT_OF_MEMORY, "render: out of memory");
    j->sobol = &f->dev->sobol;
    sy_rt_env_get(f->dev, &j->env);
    j->spp = desc->pixel_samples ? desc->pixel_samples : 1u;
    j->n_area = (f->light_samples + j->spp - 1u) / j->spp;
    j->n_env = j->env.mode ? (desc->env_light_samples ? desc->env_light_samples : 4u) : 0u;
    sy_rt_result r = sy_rt_run_tiles(f, whitted_tile, j, desc->progress, desc->progress_user_data);
    free(j);
    return r;
}
