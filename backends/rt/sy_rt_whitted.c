/* sy_rt_whitted.c — the Whitted integrator, the deterministic preview.
 *
 * Per pixel: pixel_samples camera rays (1 = the pixel centre; more = stratified jittered points,
 * the first points of an Owen-scrambled Sobol sequence per pixel, averaged: a box filter over the
 * pixel); where the standard error of those samples' (compressed) luminance exceeds REFINE_STDERR,
 * REFINE_FACTOR x as many (at most REFINE_MAX_SPP; edges, mirror reflections, penumbrae). Per hit,
 * shading model (glTF metallic-roughness, Whitted-style):
 *   - emission (front side, or both sides when double-sided) is ADDED to the reflected light;
 *   - unlit materials show their base colour (plus emission);
 *   - direct light from punctual lights with the path tracer's BSDF (sy_rt_bsdf.h) and a hard
 *     shadow ray; with the light tree (render desc light_tree, sy_rt_lighttree.h) instead
 *     n_area samples per point of area and punctual lights together, each picked by the tree
 *     (direct_tree: many lights cost n_area shadow rays, not one per light);
 *   - direct light from emissive triangles and the environment by the ratio estimator: the
 *     unshadowed light in closed form ("analytic", below) times (shadowed / unshadowed) sums of the
 *     same stochastic samples, each weighted by the path tracer's BSDF. Unshadowed, the result is
 *     the closed form exactly, whatever the sample count (no grain); only the visibility is
 *     sampled. The sums of a pixel's camera samples whose first hits lie on the same instance with
 *     similar normals are pooled (one ratio per pixel and surface: a pixel's shadow estimate uses
 *     spp x n samples); secondary hits take their own ratio;
 *   - roughness below SY_RT_BSDF_DELTA_ROUGHNESS (the path tracer's delta lobes): recursive
 *     perfect reflection, metal part tinted by the base colour, dielectric part weighted by
 *     Schlick Fresnel * specular;
 *   - transmission: exact dielectric Fresnel between reflection and refraction (tinted by base
 *     colour), total internal reflection;
 *   - alpha blend: the surface is composited over what the continued ray sees.
 * Analytic: the BSDF as Lambert (plus the sheen as diffuse light of its directional albedo) and
 * GGX lobes (base, clear coat) whose albedos and linearly transformed cosines come from the LTC
 * tables (backends/ltc/sy_ltc.h, Heitz et al. 2016, the tables the rasterizer uses). Emitters:
 * each emissive triangle, two coplanar ones sharing an edge merged into a quad, integrated over the
 * polygon (clipless form, exact when wholly above the horizon) when there are at most
 * ANALYTIC_MAX_TRIANGLES and none is textured (else the triangles are sampled by power as
 * before); the light of a pixel's first hit is reused by its other camera samples on the same
 * surface. Environment: split sum, diffuse from the irradiance map, glossy lobes from the GGX
 * maps prefiltered per roughness at the lobe's dominant direction (sy_rt_envfilter.h). Materials
 * the model does not describe (iridescence, anisotropy) keep the sampled estimates (area lights by
 * power, the environment by MIS of an environment and a BSDF sample).
 * Samples: area lights n = ceil(area_light_samples / pixel_samples) per shading point (by default
 * 8 per pixel for the closed form's visibility, 16 for the sampled estimators), each a
 * polygon chosen in proportion to its closed-form light and a direction uniform in the solid angle
 * of one of its triangles (Arvo 1995) where the point is near it, through a uniform point on it from
 * farther away (sample_tri), so the samples' weights vary little and the ratio of few
 * samples is nearly the visibility the BSDF sees; a point none of whose samples reached an emitter
 * (under the horizon) draws up to RETRIES more. The environment env_light_samples per shading
 * point, each an environment and a BSDF sample (MIS). The numbers come from the pixel's
 * Owen-scrambled Sobol sequence (sy_rt_sampler.h), sample k of pixel sample j being point j*n + k
 * of a set chosen by the recursion depth, so the samples of one pixel are stratified together and
 * every pixel has its own scramble: no pattern shared between pixels (no banding), no change
 * between frames (deterministic). Shadow rays pass alpha-masked holes, alpha-blended and
 * transmissive surfaces with their transmittance (sy_rt_shadow.h). Camera rays that hit nothing
 * see the background; every other escaping ray sees the environment light (black without one). */
#include "sy_rt_whitted.h"
#include "sy_ltc.h"
#include "sy_rt_bsdf.h"
#include "sy_rt_envfilter.h"
#include "sy_rt_sheen.h"
#include "sy_rt_iridescence.h"
#include "sy_rt_lights.h"
#include "sy_rt_lighttree.h"
#include "sy_rt_sampler.h"
#include "sy_rt_shadow.h"
#include "sy_rt_surface.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>

#define INV_PI 0.31830988618f

/* Emissive triangles up to this many are integrated analytically (each costs every shading point
 * three polygon integrals); with more, or with a textured emitter, area lights are sampled. */
#define ANALYTIC_MAX_TRIANGLES 64u
#define RETRIES 8u
/* Adaptive refinement: a pixel whose first spp samples (each with its own visibility ratio) have
 * a standard error above REFINE_STDERR in y / (1 + y) takes REFINE_FACTOR x spp samples (at most
 * REFINE_MAX_SPP; the Sobol points continue, still stratified): edges, mirror reflections and
 * penumbrae get them, smooth regions keep spp. */
#define REFINE_STDERR 0.01
#define REFINE_FACTOR 2u
#define REFINE_MAX_SPP 64u

/* Sobol sets of a pixel: 0 = sub-pixel positions; per recursion depth d, area-light samples,
 * environment samples and BSDF samples for the environment. */
#define SET_AREA(d) (1u + 3u * (d))
#define SET_ENV(d) (2u + 3u * (d))
#define SET_BSDF(d) (3u + 3u * (d))

typedef struct whitted_job {
    const sy_rt_sobol *sobol; /* the device's */
    sy_rt_env env;
    bool area_analytic; /* emissive triangles integrated analytically (LTC) */
    struct apoly *poly; /* area_analytic: the emitters as planar polygons */
    struct apoly_soa *pv; /* the same, structure of arrays (apoly_soa) */
    uint32_t n_poly;
    uint32_t spp;    /* camera rays per pixel */
    bool motion;     /* some instance or the camera moves over the shutter: each camera ray has its own time */
    uint32_t spp_max; /* up to this many where the first spp disagree (adaptive refinement) */
    uint32_t n_area; /* area-light samples per shading point */
    uint32_t n_env;  /* environment samples per shading point (0 without an environment) */
    const sy_rt_lighttree *lt; /* light_tree: area and punctual lights sampled together through it */
} whitted_job;

/* One camera sample's analytic direct light at its first hit, kept apart so that the pixel's
 * visibility ratio pools all its samples (see the comment at the top): per kind (0 area, 1
 * environment) the analytic light and the shadowed / unshadowed sums of its samples. */
typedef struct psample {
    bool used;
    const void *inst; /* the hit's instance and shading normal: samples pool with their like */
    sy_rt_v3 n;
    float w;          /* what the surface's light is scaled by (alpha blending) */
    sy_rt_v3 a[2], num[2], den[2];
    uint32_t group;   /* the first sample it pools with */
    sy_rt_v3 gnum[2], gden[2]; /* a group's first sample: the group's sums */
} psample;

typedef struct trace_ctx {
    const sy_rt_frame *f;
    const sy_rt_device *dev;
    const whitted_job *job;
    sy_rt_ictx ictx;
    uint32_t pseed;  /* per-pixel scramble seed */
    uint32_t sample; /* pixel sample index */
    sy_rt_v3 eye;    /* the camera ray's origin */
    psample *cur;    /* this camera sample's record (its depth-0 hit fills it) */
    /* The analytic area light of the pixel's first camera hit per lobe (without the albedos, which
     * textures vary within a pixel), reused by its other camera hits on the same instance with the
     * same normal and lobes (roughness within 0.01) within a hundredth of the eye distance (the
     * unshadowed light varies far less over a pixel than its shadows) */
    struct {
        bool valid;
        const void *inst;
        sy_rt_v3 p, n;
        sy_rt_v3 lobe[3]; /* per lobe (amodel's diffuse, base, coat): the emitters' sum */
        bool spec, coat;  /* the lobes it was computed with */
        float rough, rough_c;
        float cdf[ANALYTIC_MAX_TRIANGLES + 1u];
    } cache;
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

/* >>analytic: the unshadowed direct light in closed form (see the comment at the top). */

static float g_ltc1[SY_LTC_FLOATS], g_ltc2[SY_LTC_FLOATS];
static pthread_once_t g_ltc_once = PTHREAD_ONCE_INIT;
static void ltc_load(void) { sy_ltc_tables(g_ltc1, g_ltc2); }

/* Bilinear look-up of an LTC table at (u, v) in [0, 1]^2 (texel centres at the ends, as the
 * rasterizer's uv * 63/64 + 0.5/64). */
static void ltc_fetch(const float *tab, float u, float v, float out[4])
{
    float x = sy_rt_clampf(u, 0.0f, 1.0f) * (float)(SY_LTC_SIZE - 1), y = sy_rt_clampf(v, 0.0f, 1.0f) * (float)(SY_LTC_SIZE - 1);
    uint32_t x0 = (uint32_t)x, y0 = (uint32_t)y;
    if (x0 > SY_LTC_SIZE - 2) x0 = SY_LTC_SIZE - 2;
    if (y0 > SY_LTC_SIZE - 2) y0 = SY_LTC_SIZE - 2;
    float tx = x - (float)x0, ty = y - (float)y0;
    const float *a = tab + 4u * (y0 * SY_LTC_SIZE + x0), *b = a + 4, *c = a + 4 * SY_LTC_SIZE, *d = c + 4;
    for (int k = 0; k < 4; ++k)
        out[k] = (a[k] * (1.0f - tx) + b[k] * tx) * (1.0f - ty) + (c[k] * (1.0f - tx) + d[k] * tx) * ty;
}

/* The closed-form model of a shading point's BSDF: Lambert (plus the sheen, as diffuse light) and
 * GGX lobes with the LTC tables' albedos. The lobes' transforms (minv, minv_c: world -> the lobe's
 * cosine space, row-major) only where an emitter's polygons need them (amodel_matrices): the
 * environment's split sum and a cached polygon light need only the albedos. */
typedef struct amodel {
    sy_rt_v3 kd;        /* diffuse albedo (x the form factor / irradiance) */
    sy_rt_v3 fl;        /* the base's GGX albedo */
    sy_rt_v3 n, nc, wo; /* the shading normal, the coat's, the view */
    bool mats;          /* minv and minv_c are set */
    float minv[9];      /* the base's GGX lobe (0 rows when fl = 0) */
    sy_rt_v3 r_dir;     /* where the base's lobe looks into the prefiltered environment */
    float rough;
    float fc;           /* the coat's GGX albedo (0: none) */
    float minv_c[9];
    sy_rt_v3 rc_dir;
    float rough_c;
} amodel;

/* (T1, T2, n) rows with T1 in the plane of n and wo. */
static void make_frame(sy_rt_v3 n, sy_rt_v3 wo, float fr[9])
{
    sy_rt_v3 t1 = v3_sub(wo, v3_scale(n, v3_dot(wo, n)));
    if (v3_dot(t1, t1) < 1e-12f) t1 = fabsf(n.x) < 0.9f ? v3_cross(n, v3(1.0f, 0.0f, 0.0f)) : v3_cross(n, v3(0.0f, 1.0f, 0.0f));
    t1 = v3_normalize(t1);
    sy_rt_v3 t2 = v3_cross(n, t1);
    fr[0] = t1.x, fr[1] = t1.y, fr[2] = t1.z, fr[3] = t2.x, fr[4] = t2.y, fr[5] = t2.z, fr[6] = n.x, fr[7] = n.y, fr[8] = n.z;
}

/* The table coordinate of the view: sqrt(1 - n . wo). */
static float ggx_v(sy_rt_v3 n, sy_rt_v3 wo) { return sqrtf(1.0f - sy_rt_clampf(v3_dot(n, wo), 0.0f, 1.0f)); }

/* One GGX lobe of perceptual roughness r seen from wo: its albedo terms (t2[0] F0 + t2[1] (1 - F0)). */
static void ggx_albedo(sy_rt_v3 n, sy_rt_v3 wo, float r, float t2[4]) { ltc_fetch(g_ltc2, r, ggx_v(n, wo), t2); }

/* The same lobe's M^-1 x frame. */
static void ggx_matrix(sy_rt_v3 n, sy_rt_v3 wo, float r, float m[9])
{
    float fr[9], t1[4];
    make_frame(n, wo, fr);
    ltc_fetch(g_ltc1, r, ggx_v(n, wo), t1);
    /* M^-1 = rows (a, 0, c), (0, 1, 0), (b, 0, d) (the GLSL mat3 of columns (a,0,b), (0,1,0), (c,0,d)) */
    for (int j = 0; j < 3; ++j) {
        m[0 + j] = t1[0] * fr[0 + j] + t1[2] * fr[6 + j];
        m[3 + j] = fr[3 + j];
        m[6 + j] = t1[1] * fr[0 + j] + t1[3] * fr[6 + j];
    }
}

/* Frostbite's dominant direction of a GGX lobe (between the mirror direction and the normal). */
static sy_rt_v3 dominant_dir(sy_rt_v3 n, sy_rt_v3 wo, float alpha)
{
    sy_rt_v3 r = v3_sub(v3_scale(n, 2.0f * v3_dot(n, wo)), wo);
    float s = 1.0f - alpha, f = s * (sqrtf(s) + alpha);
    return v3_normalize(v3_add(v3_scale(n, 1.0f - f), v3_scale(r, f)));
}

/* The model of BSDF b, its albedos (amodel_matrices adds the lobes' transforms; env: the lobes'
 * directions into the prefiltered environment too); false when it has
 * lobes the model does not describe (iridescence, anisotropy): those keep the sampled estimates. */
static bool amodel_init(amodel *m, const sy_rt_bsdf *b, sy_rt_v3 wo, bool env)
{
    if (b->irid > 0.0f || b->aniso) return false;
    pthread_once(&g_ltc_once, ltc_load);
    float nv = sy_rt_clampf(v3_dot(b->n, wo), 1e-4f, 1.0f);
    m->n = b->n, m->wo = wo, m->mats = false;
    m->rough = sqrtf(b->alpha);
    m->fl = v3(0.0f, 0.0f, 0.0f);
    float t2[4] = {0, 0, 0, 0};
    ggx_albedo(b->n, wo, m->rough, t2);
    sy_rt_v3 fd = v3_scale(v3_add(v3_scale(b->f0c, t2[0]), v3_scale(v3_sub(v3(1.0f, 1.0f, 1.0f), b->f0c), t2[1])), b->spec);
    if (!b->delta) {
        sy_rt_v3 fm = v3_add(v3_scale(b->base, t2[0]), v3_scale(v3_sub(v3(1.0f, 1.0f, 1.0f), b->base), t2[1]));
        m->fl = v3_add(v3_scale(fm, b->w_metal), v3_scale(fd, b->w_diel));
    }
    /* the diffuse under the dielectric's Fresnel, as the BSDF's 1 - max(F) on average */
    float fdm = sy_rt_minf(sy_rt_maxf(fd.x, sy_rt_maxf(fd.y, fd.z)), 1.0f);
    m->kd = v3_scale(b->base, b->w_diel * (1.0f - fdm));
    if (b->q_sheen > 0.0f) m->kd = v3_add(m->kd, v3_scale(b->sheen, sy_rt_sheen_albedo(nv, b->sheen_r)));
    m->r_dir = env ? dominant_dir(b->n, wo, b->alpha) : b->n; /* read only by the environment's split sum */
    m->fc = 0.0f, m->rough_c = 0.0f, m->nc = b->n, m->rc_dir = m->r_dir;
    if (b->cc > 0.0f && !b->cc_delta && b->q_coat > 0.0f) {
        m->nc = b->cc_n ? b->ncc : b->n;
        float tc[4];
        m->rough_c = sqrtf(b->cc_alpha);
        ggx_albedo(m->nc, wo, m->rough_c, tc);
        m->fc = b->cc * (0.04f * tc[0] + 0.96f * tc[1]);
        if (env) m->rc_dir = dominant_dir(m->nc, wo, b->cc_alpha);
    }
    return true;
}

static void amodel_matrices(amodel *m)
{
    if (m->mats) return;
    ggx_matrix(m->n, m->wo, m->rough, m->minv);
    if (m->fc > 0.0f) ggx_matrix(m->nc, m->wo, m->rough_c, m->minv_c);
    m->mats = true;
}

/* An emitter for the closed form: one emissive triangle, or two coplanar ones sharing an edge with
 * the same emission merged into a quad (a rectangle light is one polygon: 4 edges, not 6). */
typedef struct apoly {
    sy_rt_v3 v[4];
    uint32_t nv;         /* 3 or 4 */
    uint32_t tri[2];     /* its triangles in dev->area */
    float split;         /* area of tri[0] / the polygon's area */
    sy_rt_v3 normal, emission;
    bool double_sided;
} apoly;

static bool same_point(sy_rt_v3 a, sy_rt_v3 b, float eps)
{
    return fabsf(a.x - b.x) <= eps && fabsf(a.y - b.y) <= eps && fabsf(a.z - b.z) <= eps;
}

/* Polygons of the emissive triangles (consecutive pairs merged where they form a planar quad).
 * Returns NULL when out of memory. */
static apoly *build_polys(const sy_rt_device *dev, uint32_t *count)
{
    apoly *out = malloc((size_t)dev->area_count * sizeof *out);
    if (!out) return NULL;
    uint32_t n = 0;
    for (uint32_t i = 0; i < dev->area_count; ++i) {
        const sy_rt_area_tri *a = &dev->area[i];
        apoly *p = &out[n++];
        p->v[0] = a->p0, p->v[1] = v3_add(a->p0, a->e1), p->v[2] = v3_add(a->p0, a->e2);
        p->nv = 3;
        p->tri[0] = p->tri[1] = i;
        p->split = 1.0f;
        p->normal = a->normal;
        p->emission = a->emission;
        p->double_sided = a->double_sided;
        if (i + 1u >= dev->area_count) continue;
        const sy_rt_area_tri *b = &dev->area[i + 1u];
        if (b->inst != a->inst || b->double_sided != a->double_sided || v3_dot(a->normal, b->normal) < 0.99999f ||
            a->emission.x != b->emission.x || a->emission.y != b->emission.y || a->emission.z != b->emission.z)
            continue;
        sy_rt_v3 w[3] = {b->p0, v3_add(b->p0, b->e1), v3_add(b->p0, b->e2)};
        float eps = 1e-5f * (v3_max_abs(a->e1) + v3_max_abs(a->e2) + v3_max_abs(a->p0));
        int shared[3], ns = 0, other = -1;
        for (int k = 0; k < 3; ++k) {
            shared[k] = -1;
            for (int m = 0; m < 3; ++m)
                if (same_point(p->v[k], w[m], eps)) shared[k] = m;
            if (shared[k] >= 0) ns++;
        }
        if (ns != 2) continue;
        for (int m = 0; m < 3; ++m)
            if (shared[0] != m && shared[1] != m && shared[2] != m) other = m;
        /* the shared edge (v[j], v[j+1]) of a's cycle; b's third vertex goes between them */
        int j = shared[0] >= 0 && shared[1] >= 0 ? 0 : (shared[1] >= 0 && shared[2] >= 0 ? 1 : 2);
        sy_rt_v3 q[4] = {p->v[j], w[other], p->v[(j + 1) % 3], p->v[(j + 2) % 3]};
        for (int k = 0; k < 4; ++k) p->v[k] = q[k];
        p->nv = 4;
        p->tri[1] = i + 1u;
        p->split = a->area / (a->area + b->area);
        ++i;
    }
    *count = n;
    return out;
}

/* The polygons as structure of arrays, for the closed form's vectorised loops (lobe_forms): four
 * vertex slots each, a triangle's as (v0, v0, v1, v2), so that its edge sum starts with the zero
 * edge and then adds the triangle's own edges in apoly's order (the same sums, bit for bit); its
 * second slot stays out of the centre (quad 0). */
typedef struct apoly_soa {
    float x[4][ANALYTIC_MAX_TRIANGLES], y[4][ANALYTIC_MAX_TRIANGLES], z[4][ANALYTIC_MAX_TRIANGLES];
    float quad[ANALYTIC_MAX_TRIANGLES]; /* 1: a quad, 0: a triangle */
    float nx[ANALYTIC_MAX_TRIANGLES], ny[ANALYTIC_MAX_TRIANGLES], nz[ANALYTIC_MAX_TRIANGLES];
    float scale[ANALYTIC_MAX_TRIANGLES];  /* its size, for the in-plane test */
    float dsided[ANALYTIC_MAX_TRIANGLES]; /* 1: double-sided */
} apoly_soa;

static void apoly_soa_fill(apoly_soa *q, const apoly *poly, uint32_t n)
{
    for (uint32_t i = 0; i < n; ++i) {
        const apoly *p = &poly[i];
        static const int tri_slot[4] = {0, 0, 1, 2};
        for (int k = 0; k < 4; ++k) {
            sy_rt_v3 v = p->v[p->nv == 4u ? k : tri_slot[k]];
            q->x[k][i] = v.x, q->y[k][i] = v.y, q->z[k][i] = v.z;
        }
        q->quad[i] = p->nv == 4u ? 1.0f : 0.0f;
        q->nx[i] = p->normal.x, q->ny[i] = p->normal.y, q->nz[i] = p->normal.z;
        q->scale[i] = v3_max_abs(v3_sub(p->v[1], p->v[0])) + v3_max_abs(v3_sub(p->v[2], p->v[0]));
        q->dsided[i] = p->double_sided ? 1.0f : 0.0f;
    }
}

/* GCC: an AVX2 clone beside the default (the loops below run 8 polygons at a time); clang (the fuzz
 * build) leaves a cloned static function's symbol undefined, so none there */
#if defined(__clang__)
#define SY_WHITTED_CLONES
#else
#define SY_WHITTED_CLONES __attribute__((target_clones("avx2", "default")))
#endif

/* The estimators a scene may not use (environment, light tree, sampled area lights, punctual
 * lights) stay out of line: inlined, they grew trace's frame and its prologue for every ray
 * (EmissiveStrengthTest 320x240: 0.058 -> 0.056 s) */
#define SY_WHITTED_COLD __attribute__((noinline))

/* The factor of an edge's cross product in the vector form factor (x: the cosine between the
 * edge's unit vertex directions; the fitted acos(x) / sin(acos(x)) of Heitz et al. 2016), branch-free */
static inline float edge_factor(float x)
{
    float y = fabsf(x);
    float a = 0.8543985f + (0.4965155f + 0.0145206f * y) * y, b = 3.4175940f + (4.1616724f + y) * y, v = a / b;
    float u = 1.0f - x * x;
    u = u > 1e-7f ? u : 1e-7f;
    return x > 0.0f ? v : 0.5f / sqrtf(u) - v;
}

/* One lobe's integral over every polygon at once, lane by lane (Heitz et al. 2016, clipless: the
 * vector form factor of the polygon's unit vertex directions, oriented towards its centre; both
 * sides count, the caller decides the emitting one). With m (a lobe's transform) the vertices
 * relative to the shading point go through it and z is their third coordinate; without (the
 * diffuse lobe) they stay in world space and z is along n. Per polygon: fz the form factor's z,
 * flen its length, above 1 where every vertex is above the horizon (then max(fz, 0) is the
 * integral; else lobe_value clips through ltc2's sphere term), below 1 where none is. */
static inline __attribute__((always_inline)) void
lobe_forms_body(const apoly_soa *restrict q, uint32_t n, float px, float py, float pz, const float *m, float nx,
                float ny, float nz, float *restrict fz, float *restrict flen, float *restrict above,
                float *restrict below, const bool world)
{
    /* world is a constant in each caller below: the other case's arithmetic folds away */
    float m0 = world ? 1.0f : m[0], m1 = world ? 0.0f : m[1], m2 = world ? 0.0f : m[2];
    float m3 = world ? 0.0f : m[3], m4 = world ? 1.0f : m[4], m5 = world ? 0.0f : m[5];
    float m6 = world ? 0.0f : m[6], m7 = world ? 0.0f : m[7], m8 = world ? 1.0f : m[8];
    for (uint32_t i = 0; i < n; ++i) {
        float lx[4], ly[4], lz[4], cx = 0.0f, cy = 0.0f, cz = 0.0f, up = 1.0f, down = 1.0f;
#pragma GCC unroll 4
        for (int k = 0; k < 4; ++k) {
            float vx = q->x[k][i] - px, vy = q->y[k][i] - py, vz = q->z[k][i] - pz;
            float tx = m0 * vx + m1 * vy + m2 * vz, ty = m3 * vx + m4 * vy + m5 * vz, tz = m6 * vx + m7 * vy + m8 * vz;
            float ax = world ? vx : tx, ay = world ? vy : ty, az = world ? vz : tz;
            float zk = world ? vx * nx + vy * ny + vz * nz : tz;
            float w = k == 1 ? q->quad[i] : 1.0f;
            cx = cx + ax * w, cy = cy + ay * w, cz = cz + az * w;
            up = zk >= 0.0f ? up : 0.0f;
            down = zk <= 0.0f ? down : 0.0f;
            float l2 = ax * ax + ay * ay + az * az, inv = l2 > 0.0f ? 1.0f / sqrtf(l2) : 0.0f;
            lx[k] = ax * inv, ly[k] = ay * inv, lz[k] = az * inv;
        }
        float fx = 0.0f, fy = 0.0f, fzz = 0.0f;
#pragma GCC unroll 4
        for (int e = 0; e < 4; ++e) { /* edges (3, 0), (0, 1), (1, 2), (2, 3) */
            int a0 = (e + 3) & 3, a1 = e;
            float t = edge_factor(lx[a0] * lx[a1] + ly[a0] * ly[a1] + lz[a0] * lz[a1]);
            float ex = (ly[a0] * lz[a1] - lz[a0] * ly[a1]) * t, ey = (lz[a0] * lx[a1] - lx[a0] * lz[a1]) * t,
                  ez = (lx[a0] * ly[a1] - ly[a0] * lx[a1]) * t;
            fx = e ? fx + ex : ex, fy = e ? fy + ey : ey, fzz = e ? fzz + ez : ez;
        }
        float flip = fx * cx + fy * cy + fzz * cz < 0.0f ? -1.0f : 1.0f;
        fx *= flip, fy *= flip, fzz *= flip;
        fz[i] = world ? fx * nx + fy * ny + fzz * nz : fzz;
        flen[i] = sqrtf(fx * fx + fy * fy + fzz * fzz);
        above[i] = up, below[i] = down;
    }
}

/* lobe_forms_body without a transform (the diffuse lobe, in world space along n) and with one */
SY_WHITTED_CLONES
static void lobe_forms_world(const apoly_soa *restrict q, uint32_t n, float px, float py, float pz, float nx, float ny,
                             float nz, float *restrict fz, float *restrict flen, float *restrict above,
                             float *restrict below)
{
    lobe_forms_body(q, n, px, py, pz, NULL, nx, ny, nz, fz, flen, above, below, true);
}

SY_WHITTED_CLONES
static void lobe_forms(const apoly_soa *restrict q, uint32_t n, float px, float py, float pz, const float *m,
                       float *restrict fz, float *restrict flen, float *restrict above, float *restrict below)
{
    lobe_forms_body(q, n, px, py, pz, m, 0.0f, 0.0f, 0.0f, fz, flen, above, below, false);
}

/* Whether polygon i lights the shading point (px, py, pz) at all: not in its plane, and on its
 * emitting side. */
SY_WHITTED_CLONES
static void poly_facing(const apoly_soa *restrict q, uint32_t n, float px, float py, float pz, float *restrict ok)
{
    for (uint32_t i = 0; i < n; ++i) {
        float side = -((q->x[0][i] - px) * q->nx[i] + (q->y[0][i] - py) * q->ny[i] + (q->z[0][i] - pz) * q->nz[i]);
        float as = fabsf(side);
        ok[i] = as > 1e-6f * q->scale[i] + 1e-9f && (side >= 0.0f || q->dsided[i] > 0.0f) ? 1.0f : 0.0f;
    }
}

/* A lobe's integral from lobe_forms' values: exact above the horizon, clipped through ltc2's
 * sphere term otherwise. */
static float lobe_value(float fz, float len, float above)
{
    if (above > 0.0f) return sy_rt_maxf(fz, 0.0f);
    if (!(len > 0.0f)) return 0.0f;
    float t[4];
    ltc_fetch(g_ltc2, fz / len * 0.5f + 0.5f, len, t);
    return len * t[3];
}

/* Unshadowed light from every polygon at the shading point x, per lobe and without the albedos:
 * lv[l][i] for lobe l (0 diffuse, 1 the base's GGX, 2 the coat's; 1 and 2 only where m has them)
 * and polygon i; 0 behind a one-sided emitter, in its plane or wholly under the horizon. Only the
 * polygons that light x go through lobe_forms (packed into their own arrays: behind a cube's faces
 * half of them do not). The diffuse lobe is the cosine itself: its integral in world space (a
 * rotation changes neither the edge vectors' lengths nor z = their sum . n). */
static void area_unshadowed_all(amodel *m, const apoly_soa *q, uint32_t n, sy_rt_v3 x,
                                float lv[3][ANALYTIC_MAX_TRIANGLES])
{
    float ok[ANALYTIC_MAX_TRIANGLES], fz[3][ANALYTIC_MAX_TRIANGLES], len[3][ANALYTIC_MAX_TRIANGLES];
    float above[3][ANALYTIC_MAX_TRIANGLES], below[ANALYTIC_MAX_TRIANGLES], unused[ANALYTIC_MAX_TRIANGLES];
    uint32_t idx[ANALYTIC_MAX_TRIANGLES], np = 0;
    apoly_soa pk; /* the polygons that light x (vertices and quad only) */
    sy_rt_v3 nn = m->n;
    bool spec = !v3_is_zero(m->fl), coat = m->fc > 0.0f;
    poly_facing(q, n, x.x, x.y, x.z, ok);
    for (uint32_t i = 0; i < n; ++i) {
        lv[0][i] = lv[1][i] = lv[2][i] = 0.0f;
        if (!(ok[i] > 0.0f)) continue;
        for (int k = 0; k < 4; ++k) pk.x[k][np] = q->x[k][i], pk.y[k][np] = q->y[k][i], pk.z[k][np] = q->z[k][i];
        pk.quad[np] = q->quad[i];
        idx[np++] = i;
    }
    if (np == 0) return;
    /* whole vector steps (8 lanes): the last polygon repeated, its copies' results unused */
    uint32_t nv = (np + 7u) & ~7u;
    for (uint32_t j = np; j < nv; ++j) {
        for (int k = 0; k < 4; ++k) pk.x[k][j] = pk.x[k][np - 1u], pk.y[k][j] = pk.y[k][np - 1u], pk.z[k][j] = pk.z[k][np - 1u];
        pk.quad[j] = pk.quad[np - 1u];
    }
    if (spec || coat) amodel_matrices(m);
    lobe_forms_world(&pk, nv, x.x, x.y, x.z, nn.x, nn.y, nn.z, fz[0], len[0], above[0], below);
    if (spec) lobe_forms(&pk, nv, x.x, x.y, x.z, m->minv, fz[1], len[1], above[1], unused);
    if (coat) lobe_forms(&pk, nv, x.x, x.y, x.z, m->minv_c, fz[2], len[2], above[2], unused);
    for (uint32_t j = 0; j < np; ++j) {
        if (below[j] > 0.0f) continue;
        uint32_t i = idx[j];
        lv[0][i] = lobe_value(fz[0][j], len[0][j], above[0][j]);
        if (spec) lv[1][i] = lobe_value(fz[1][j], len[1][j], above[1][j]);
        if (coat) lv[2][i] = lobe_value(fz[2][j], len[2][j], above[2][j]);
    }
}

/* Unshadowed light from the environment: split sum over the prefiltered maps. */
static sy_rt_v3 spec_env(const sy_rt_env *env, sy_rt_v3 d, float rough)
{
    const sy_rt_envfilter *ef = env->filter;
    float lv = sy_rt_clampf(rough, 0.0f, 1.0f) * (float)(SY_RT_ENVF_LEVELS - 1);
    uint32_t k = (uint32_t)lv;
    if (k > SY_RT_ENVF_LEVELS - 2) k = SY_RT_ENVF_LEVELS - 2;
    float t = lv - (float)k, u, v;
    sy_rt_latlong_uv(d, &u, &v);
    sy_rt_v3 b = sy_rt_envf_lookup_uv(&ef->spec[k + 1u], u, v);
    if (k == 0) /* between the map itself and the first level */
        return v3_add(v3_scale(sy_rt_env_eval_uv(env, u, v), 1.0f - t), v3_scale(b, t * env->intensity));
    return v3_scale(v3_add(v3_scale(sy_rt_envf_lookup_uv(&ef->spec[k], u, v), 1.0f - t), v3_scale(b, t)), env->intensity);
}

static sy_rt_v3 env_unshadowed(const amodel *m, const sy_rt_env *env, sy_rt_v3 n)
{
    sy_rt_v3 l = v3_mul(m->kd, v3_scale(sy_rt_envf_lookup(&env->filter->irr, n), env->intensity));
    if (!v3_is_zero(m->fl)) l = v3_add(l, v3_mul(m->fl, spec_env(env, m->r_dir, m->rough)));
    if (m->fc > 0.0f) l = v3_add(l, v3_scale(spec_env(env, m->rc_dir, m->rough_c), m->fc));
    return l;
}

/* The ratio estimator: analytic x (shadowed / unshadowed sums of the same samples), per channel
 * (coloured shadows through glass); where no sample saw the light, the analytic value as it is. */
static sy_rt_v3 ratio_apply(sy_rt_v3 a, sy_rt_v3 num, sy_rt_v3 den)
{
    float dl = v3_luminance(den);
    if (!(dl > 0.0f)) return a;
    float r = v3_luminance(num) / dl;
    return v3(a.x * (den.x > 0.0f ? num.x / den.x : r), a.y * (den.y > 0.0f ? num.y / den.y : r),
              a.z * (den.z > 0.0f ? num.z / den.z : r));
}

SY_WHITTED_COLD static sy_rt_v3 direct_area(trace_ctx *c, const sy_rt_surface *s, const sy_rt_bsdf *b, sy_rt_v3 p_off, sy_rt_v3 wo,
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
        sy_rt_area_tri moved; /* a moving emitter: where it is at the ray's time (motion blur) */
        const sy_rt_area_tri *t = sy_rt_area_at(&dev->area[lo], c->ictx.time, &moved);
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
        sy_rt_v3 tr = sy_rt_clip_removes(dev, q.x, q.y, q.z) ? v3(0.0f, 0.0f, 0.0f) /* an emitter point in a removed part */
                      : sy_rt_segment_to(p_off, q, &sdir, &tmax) ? shadow(c, p_off, sdir, tmax) : v3(1.0f, 1.0f, 1.0f);
        if (v3_is_zero(tr)) continue;
        sy_rt_v3 le = v3_mul(tr, t->textured ? sy_rt_surface_emission(dev, t->inst, t->prim, bu, bv) : t->emission);
        float g = cos_l / d2 * t->area / p_sel;
        sum = v3_add(sum, v3_scale(v3_mul(le, f), g));
    }
    return v3_scale(sum, 1.0f / (float)n);
}

/* The share of a quad's samples that its first triangle t0 takes (t1 the second): their solid
 * angles seen from x approximated at their centroids, area x cos / d^2 (the cosine is the same for
 * both: they are coplanar, so area / d^3 compares them), or `fallback` (their areas' share) where
 * that says nothing. Only the samples' density: the selection probability keeps them unbiased (the
 * exact form, Van Oosterom and Strackee's, cost 7 % of a render with atan2f). */
static float quad_split(const sy_rt_area_tri *t0, const sy_rt_area_tri *t1, sy_rt_v3 x, float fallback)
{
    sy_rt_v3 v0 = v3_sub(v3_add(t0->p0, v3_scale(v3_add(t0->e1, t0->e2), 1.0f / 3.0f)), x);
    sy_rt_v3 v1 = v3_sub(v3_add(t1->p0, v3_scale(v3_add(t1->e1, t1->e2), 1.0f / 3.0f)), x);
    float d0 = v3_dot(v0, v0), d1 = v3_dot(v1, v1);
    float w0 = t0->area * d1 * sqrtf(d1), w1 = t1->area * d0 * sqrtf(d0); /* a0 / d0^3 : a1 / d1^3, cross-multiplied */
    float split = w0 / (w0 + w1);
    return isfinite(split) && w0 + w1 > 0.0f ? split : fallback;
}

static sy_rt_v3 gram_schmidt(sy_rt_v3 v, sy_rt_v3 w) { return v3_sub(v, v3_scale(w, v3_dot(v, w))); }

/* A direction wi from x toward triangle t, uniform in its solid angle (Arvo 1995, as pbrt-v4
 * writes it), the point q it reaches and 1 / its pdf, where x is near the triangle: its longest
 * edge longer than x's distance to its plane (Cycles' rule; there area |cos| / d^2 varies most over
 * the triangle). A triangle farther away, under about 1e-4 sr or degenerate gets a uniform point on
 * its area instead (1 / pdf = area cos / d^2): its weights vary little, and it skips the
 * trigonometry (EmissiveStrengthTest, emitters mostly seen from afar: Whitted 0.92x the time,
 * relMSE 0.00057 -> 0.00061 against 256 spp). False: no direction. */
static bool sample_tri(const sy_rt_area_tri *t, sy_rt_v3 x, float u1, float u2, sy_rt_v3 *wi, sy_rt_v3 *q, float *w)
{
    float h = v3_dot(v3_sub(t->p0, x), t->normal); /* x's signed distance to the plane */
    sy_rt_v3 e3 = v3_sub(t->e2, t->e1);
    float l2 = sy_rt_maxf(v3_dot(t->e1, t->e1), sy_rt_maxf(v3_dot(t->e2, t->e2), v3_dot(e3, e3)));
    if (l2 > h * h) {
        sy_rt_v3 p1 = v3_add(t->p0, t->e1), p2 = v3_add(t->p0, t->e2);
        sy_rt_v3 a = v3_normalize(v3_sub(t->p0, x)), b = v3_normalize(v3_sub(p1, x)), c = v3_normalize(v3_sub(p2, x));
        sy_rt_v3 nab = v3_cross(a, b), nca = v3_cross(c, a);
        float lab = v3_length(nab), lca = v3_length(nca);
        /* the solid angle (spherical excess) by Van Oosterom and Strackee's tan(E / 2) = |a . (b x c)| /
         * (1 + a.b + b.c + c.a): one atan2, and exact for small triangles where the sum of the three
         * angles minus pi loses its digits */
        float tan_num = fabsf(v3_dot(a, v3_cross(b, c))), tan_den = 1.0f + v3_dot(a, b) + v3_dot(b, c) + v3_dot(c, a);
        float area_sa = 2.0f * sy_rt_atan2f(tan_num, tan_den);
        if (lab > 1e-6f && lca > 1e-6f) {
            /* alpha, the angle at a: between the planes (a, b) and (a, c) */
            float ca = sy_rt_clampf(-v3_dot(nab, nca) / (lab * lca), -1.0f, 1.0f), sa = sqrtf(1.0f - ca * ca);
            if (area_sa > 1e-4f && isfinite(area_sa) && sa > 0.0f) {
                float sx, cx; /* sin and cos of pi + u1 area_sa: -sin, -cos of u1 area_sa */
                sx = sinf(u1 * area_sa), cx = cosf(u1 * area_sa);
                float sphi = -sx * ca + cx * sa, cphi = -cx * ca - sx * sa;
                float k1 = cphi + ca, k2 = sphi - sa * v3_dot(a, b);
                float cbp = (k2 + (k2 * cphi - k1 * sphi) * ca) / ((k2 * sphi + k1 * cphi) * sa);
                cbp = sy_rt_clampf(isfinite(cbp) ? cbp : 1.0f, -1.0f, 1.0f);
                float sbp = sy_rt_sin_of_cos(cbp);
                sy_rt_v3 cp = v3_add(v3_scale(a, cbp), v3_scale(v3_normalize(gram_schmidt(c, a)), sbp));
                float ct = 1.0f - u2 * (1.0f - v3_dot(cp, b)), st = sy_rt_sin_of_cos(ct);
                sy_rt_v3 d = v3_add(v3_scale(b, ct), v3_scale(v3_normalize(gram_schmidt(cp, b)), st));
                float tt = h / v3_dot(d, t->normal); /* the distance to the plane along d */
                if (isfinite(tt) && tt > 0.0f && isfinite(d.x + d.y + d.z)) {
                    *wi = d;
                    *q = v3_madd(x, d, tt);
                    *w = area_sa;
                    return true;
                }
            }
        }
    }
    float su = sqrtf(u1);
    float bu = su * (1.0f - u2), bv = su * u2;
    *q = v3_add(t->p0, v3_add(v3_scale(t->e1, bu), v3_scale(t->e2, bv)));
    sy_rt_v3 v = v3_sub(*q, x);
    float d2 = v3_dot(v, v);
    if (!(d2 > 0.0f)) return false;
    *wi = v3_scale(v, 1.0f / sqrtf(d2));
    *w = fabsf(v3_dot(t->normal, *wi)) / d2 * t->area;
    return true;
}

/* Area lights with the model m: the analytic unshadowed light of every emissive triangle, and
 * n_area samples, each picking a polygon in proportion to its analytic light (luminance) and a
 * direction toward one of its triangles (sample_tri: uniform in its solid angle where near), for the
 * visibility ratio (with weights nearly constant over the emitter, the ratio of few samples is
 * nearly the visibility the BSDF sees). */
static sy_rt_v3 direct_area_analytic(trace_ctx *c, const sy_rt_surface *s, const sy_rt_bsdf *b, amodel *m,
                                     sy_rt_v3 p_off, sy_rt_v3 wo, uint32_t depth)
{
    const sy_rt_device *dev = c->dev;
    const apoly *poly = c->job->poly;
    uint32_t nt = c->job->n_poly;
    float local[ANALYTIC_MAX_TRIANGLES + 1u]; /* a secondary hit's table (the cache is the camera hit's) */
    float *cdf = c->cache.cdf;
    sy_rt_v3 lobe[3] = {c->cache.lobe[0], c->cache.lobe[1], c->cache.lobe[2]};
    bool cam = depth == 0u, spec = !v3_is_zero(m->fl), coat = m->fc > 0.0f;
    if (!(cam && c->cache.valid && c->cache.inst == (const void *)s->inst && v3_dot(c->cache.n, b->n) > 0.9995f &&
          v3_length(v3_sub(c->cache.p, s->p)) <= 0.01f * v3_length(v3_sub(s->p, c->eye)) && c->cache.spec == spec &&
          c->cache.coat == coat && (!spec || fabsf(c->cache.rough - m->rough) <= 0.01f) &&
          (!coat || fabsf(c->cache.rough_c - m->rough_c) <= 0.01f))) {
        if (!cam) cdf = local;
        lobe[0] = lobe[1] = lobe[2] = v3(0.0f, 0.0f, 0.0f);
        cdf[0] = 0.0f;
        float lv[3][ANALYTIC_MAX_TRIANGLES];
        area_unshadowed_all(m, c->job->pv, nt, s->p, lv);
        for (uint32_t i = 0; i < nt; ++i) {
            if (lv[0][i] == 0.0f && lv[1][i] == 0.0f && lv[2][i] == 0.0f) {
                cdf[i + 1u] = cdf[i];
                continue;
            }
            sy_rt_v3 e = poly[i].emission;
            for (int l = 0; l < 3; ++l) lobe[l] = v3_add(lobe[l], v3_scale(e, lv[l][i]));
            /* polygons picked in proportion to their light with this point's albedos (the
             * cache's other points keep the table: only the samples' density) */
            sy_rt_v3 ai = v3_mul(v3_add(v3_add(v3_scale(m->kd, lv[0][i]), v3_scale(m->fl, lv[1][i])),
                                        v3_scale(v3(m->fc, m->fc, m->fc), lv[2][i])), e);
            cdf[i + 1u] = cdf[i] + sy_rt_maxf(v3_luminance(ai), 0.0f);
        }
        if (cam) {
            c->cache.valid = true, c->cache.inst = s->inst, c->cache.p = s->p, c->cache.n = b->n;
            for (int l = 0; l < 3; ++l) c->cache.lobe[l] = lobe[l];
            c->cache.spec = spec, c->cache.coat = coat, c->cache.rough = m->rough, c->cache.rough_c = m->rough_c;
        }
    }
    sy_rt_v3 a = v3_add(v3_add(v3_mul(m->kd, lobe[0]), v3_mul(m->fl, lobe[1])), v3_scale(lobe[2], m->fc));
    float total = cdf[nt];
    if (!(total > 0.0f)) return v3(0.0f, 0.0f, 0.0f);
    uint32_t n = c->job->n_area;
    sy_rt_v3 num = v3(0.0f, 0.0f, 0.0f), den = v3(0.0f, 0.0f, 0.0f);
    /* Samples that reach no light (under the horizon where an emitter straddles it) say nothing
     * about visibility: while none has, up to RETRIES more are drawn (from a second scramble of
     * the same set), so that few samples per point (spp >= light_samples) do not fall back on the
     * unshadowed light where only part of an emitter is above the horizon */
    for (uint32_t k = 0; k < n || (v3_is_zero(den) && k < n + RETRIES); ++k) {
        float u[4];
        if (k < n) light_u(c, SET_AREA(depth), n, k, u);
        else sy_rt_sobol_sample4(c->job->sobol, c->pseed ^ 0x5bd1e995u, SET_AREA(depth), c->sample * RETRIES + (k - n), u);
        float xi = u[0] * total;
        uint32_t i = sy_rt_cdf_last_le(cdf, nt, xi);
        float p_sel = (cdf[i + 1u] - cdf[i]) / total;
        if (!(p_sel > 0.0f)) continue;
        /* one of the polygon's triangles by solid angle (u[0] rescaled), a direction uniform in
         * its solid angle (small or degenerate ones: a uniform point on it) */
        float ut = (xi - cdf[i]) / (cdf[i + 1u] - cdf[i]);
        const apoly *pg = &poly[i];
        const sy_rt_area_tri *t = &dev->area[pg->tri[0]];
        sy_rt_v3 wi, q;
        float w_dir; /* 1 / the direction's pdf (solid angle) */
        if (pg->nv == 4u) {
            const sy_rt_area_tri *t1 = &dev->area[pg->tri[1]];
            float split = quad_split(t, t1, s->p, pg->split);
            if (ut < split) p_sel *= split;
            else t = t1, p_sel *= 1.0f - split;
        }
        if (!sample_tri(t, s->p, u[1], u[2], &wi, &q, &w_dir)) continue;
        float cos_l = -v3_dot(t->normal, wi);
        if (t->double_sided) cos_l = fabsf(cos_l);
        if (cos_l <= 0.0f || v3_dot(s->ns, wi) <= 0.0f || v3_dot(s->ng_facing, wi) <= 0.0f) continue;
        float pdf_b;
        sy_rt_v3 f = sy_rt_bsdf_eval(b, wo, wi, &pdf_b);
        if (v3_is_zero(f)) continue;
        sy_rt_v3 e = v3_scale(v3_mul(f, t->emission), w_dir / p_sel);
        den = v3_add(den, e);
        sy_rt_v3 sdir;
        float tmax;
        sy_rt_v3 tr = sy_rt_clip_removes(dev, q.x, q.y, q.z) ? v3(0.0f, 0.0f, 0.0f) /* an emitter point in a removed part */
                      : sy_rt_segment_to(p_off, q, &sdir, &tmax) ? shadow(c, p_off, sdir, tmax) : v3(1.0f, 1.0f, 1.0f);
        num = v3_add(num, v3_mul(e, tr));
    }
    if (depth == 0u && c->cur) {
        c->cur->used = true, c->cur->a[0] = a, c->cur->num[0] = num, c->cur->den[0] = den;
        return v3(0.0f, 0.0f, 0.0f);
    }
    return ratio_apply(a, num, den);
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
SY_WHITTED_COLD static sy_rt_v3 direct_env(trace_ctx *c, const sy_rt_surface *s, const sy_rt_bsdf *b, const amodel *m, sy_rt_v3 p_off,
                           sy_rt_v3 wo, uint32_t depth)
{
    const sy_rt_env *env = &c->job->env;
    sy_rt_v3 sum = v3(0.0f, 0.0f, 0.0f), den = v3(0.0f, 0.0f, 0.0f);
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
                sy_rt_v3 e = v3_scale(v3_mul(f, le), power_heuristic(pdf_l, pdf_b) / pdf_l);
                den = v3_add(den, e);
                sy_rt_v3 tr = shadow(c, p_off, wi, INFINITY);
                if (!v3_is_zero(tr)) sum = v3_add(sum, v3_mul(e, tr));
            }
        }
        /* BSDF strategy */
        sy_rt_bsdf_sample bs;
        if (sy_rt_bsdf_sample_dir(b, wo, ub, &bs) && !bs.specular && !bs.transmit && bs.pdf > 0.0f &&
            v3_dot(s->ng_facing, bs.wi) > 0.0f) {
            float pdf_env;
            sy_rt_v3 lb = sy_rt_env_eval_pdf(env, bs.wi, &pdf_env);
            if (!v3_is_zero(lb)) {
                sy_rt_v3 e = v3_scale(v3_mul(bs.weight, lb), power_heuristic(bs.pdf, pdf_env));
                den = v3_add(den, e);
                sy_rt_v3 tr = shadow(c, p_off, bs.wi, INFINITY);
                if (!v3_is_zero(tr)) sum = v3_add(sum, v3_mul(e, tr));
            }
        }
    }
    if (m && depth == 0u && c->cur) {
        c->cur->used = true, c->cur->a[1] = env_unshadowed(m, env, b->n), c->cur->num[1] = sum, c->cur->den[1] = den;
        return v3(0.0f, 0.0f, 0.0f);
    }
    if (m) return ratio_apply(env_unshadowed(m, env, b->n), sum, den);
    return v3_scale(sum, 1.0f / (float)n);
}

/* light_tree: n_area samples of area and punctual lights together, each light picked by the tree
 * (its estimated contribution at the point), a uniform point on a triangle. */
SY_WHITTED_COLD static sy_rt_v3 direct_tree(trace_ctx *c, const sy_rt_surface *s, const sy_rt_bsdf *b, sy_rt_v3 p_off, sy_rt_v3 wo,
                            uint32_t depth)
{
    const sy_rt_device *dev = c->dev;
    const sy_rt_lighttree *lt = c->job->lt;
    uint32_t n = c->job->n_area;
    sy_rt_v3 sum = v3(0.0f, 0.0f, 0.0f), nl = sy_rt_light_tree_normal(s->ng_facing, b->q_trans);
    for (uint32_t i = 0; i < n; ++i) {
        float u[4], p_sel;
        light_u(c, SET_AREA(depth), n, i, u);
        uint32_t li = sy_rt_lighttree_pick(lt, s->p, nl, u[0], &p_sel);
        if (li == SY_RT_LT_NONE || !(p_sel > 0.0f)) continue;
        sy_rt_v3 wi, le, q = s->p;
        float g, tmax = INFINITY, bu = 0.0f, bv = 0.0f;
        const sy_rt_area_tri *t = NULL;
        sy_rt_area_tri moved; /* a moving emitter: where it is at the ray's time (motion blur) */
        if (li < dev->area_count) {
            t = sy_rt_area_at(&dev->area[li], c->ictx.time, &moved);
            float su = sqrtf(u[1]);
            bu = su * (1.0f - u[2]), bv = su * u[2];
            q = v3_add(t->p0, v3_add(v3_scale(t->e1, bu), v3_scale(t->e2, bv)));
            wi = v3_sub(q, s->p);
            float d2 = v3_dot(wi, wi);
            if (!(d2 > 0.0f)) continue;
            wi = v3_scale(wi, 1.0f / sqrtf(d2));
            float cos_l = -v3_dot(t->normal, wi);
            if (t->double_sided) cos_l = fabsf(cos_l);
            if (cos_l <= 0.0f) continue;
            le = t->emission;
            g = cos_l / d2 * t->area / p_sel;
        } else {
            if (!sy_rt_punctual_incident(&dev->punctual[li - dev->area_count], s->p, &wi, &le, &tmax)) continue;
            g = 1.0f / p_sel;
        }
        if (v3_dot(s->ns, wi) <= 0.0f || v3_dot(s->ng_facing, wi) <= 0.0f) continue;
        float pdf_b;
        sy_rt_v3 f = sy_rt_bsdf_eval(b, wo, wi, &pdf_b); /* includes cos_s */
        if (v3_is_zero(f)) continue;
        sy_rt_v3 sdir, tr;
        if (t) {
            tr = sy_rt_clip_removes(dev, q.x, q.y, q.z) ? v3(0.0f, 0.0f, 0.0f) /* an emitter point in a removed part */
                 : sy_rt_segment_to(p_off, q, &sdir, &tmax) ? shadow(c, p_off, sdir, tmax) : v3(1.0f, 1.0f, 1.0f);
            if (!v3_is_zero(tr) && t->textured) le = sy_rt_surface_emission(dev, t->inst, t->prim, bu, bv);
        } else {
            tr = shadow(c, p_off, wi, tmax);
        }
        if (v3_is_zero(tr)) continue;
        sum = v3_add(sum, v3_scale(v3_mul(v3_mul(le, tr), f), g));
    }
    return v3_scale(sum, 1.0f / (float)n);
}

SY_WHITTED_COLD static sy_rt_v3 direct_punctual(trace_ctx *c, const sy_rt_surface *s, const sy_rt_bsdf *b, sy_rt_v3 p_off, sy_rt_v3 wo)
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
            L = c->job->lt ? direct_tree(c, s, &b, p_out, wo, depth) : direct_punctual(c, s, &b, p_out, wo);
            amodel am;
            bool model = (c->job->area_analytic || c->job->env.filter) && amodel_init(&am, &b, wo, c->job->env.filter != NULL);
            if (model && depth == 0u && c->cur) c->cur->inst = s->inst, c->cur->n = b.n, c->cur->w = 1.0f;
            if (c->dev->area_count && !c->job->lt)
                L = v3_add(L, model && c->job->area_analytic ? direct_area_analytic(c, s, &b, &am, p_out, wo, depth)
                                                             : direct_area(c, s, &b, p_out, wo, depth));
            if (c->job->n_env) L = v3_add(L, direct_env(c, s, &b, model && c->job->env.filter ? &am : NULL, p_out, wo, depth));
        }
        bool recurse = depth + 1u < c->f->max_depth;
        float cos_o = sy_rt_maxf(v3_dot(s->ns, wo), 0.0f);
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
            float w = b.cc * schlick(v3(0.04f, 0.04f, 0.04f), b.cc_n ? sy_rt_maxf(v3_dot(nc, wo), 0.0f) : cos_o).x;
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
        if (depth == 0u && c->cur) c->cur->w = a;
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
        if (camera) r.a = sy_rt_background_eval(c->dev, &dir, &r.rgb); /* the background */
        else r.rgb = sy_rt_env_eval(&c->job->env, v3_normalize(dir)); /* the environment light */
        if (t_hit) *t_hit = INFINITY;
        return r;
    }
    float t_cap;
    if (sy_rt_clip_cap(c->dev, in, rh.hit.primID, org, dir, tnear, rh.ray.tfar, &t_cap)) {
        /* a section cap: camera rays see its flat colour, every other ray an opaque black surface */
        if (t_hit) *t_hit = t_cap;
        rgba_t r = {camera ? v3_load(c->dev->clip_cap_color) : v3(0.0f, 0.0f, 0.0f), 1.0f};
        return r;
    }
    if (t_hit) *t_hit = rh.ray.tfar;
    sy_rt_v3 d = v3_normalize(dir);
    sy_rt_surface s;
    sy_rt_surface_fetch_at(c->dev, in, ((const sy_rt_ictx *)ictx)->time, rh.hit.primID, rh.hit.u, rh.hit.v, d, &s);
    return shade(c, &s, d, depth, camera);
}

/* Adds the pooled direct light of the pixel's samples ps[0 .. n) to *sum: samples whose depth-0 hits
 * lie on the same instance with shading normals within about 25 degrees share their shadowed /
 * unshadowed sums, each scaling its own analytic light by the group's ratio. */
static void pool_resolve(psample *ps, uint32_t n, sy_rt_v3 *sum)
{
    uint32_t lead[256], nl = 0;
    for (uint32_t k = 0; k < n; ++k) {
        psample *p = &ps[k];
        if (!p->used) continue;
        uint32_t g = k;
        for (uint32_t i = 0; i < nl; ++i)
            if (ps[lead[i]].inst == p->inst && v3_dot(ps[lead[i]].n, p->n) > 0.9f) {
                g = lead[i];
                break;
            }
        if (g == k) {
            if (nl < 256u) lead[nl++] = k;
            for (int t = 0; t < 2; ++t) p->gnum[t] = v3(0.0f, 0.0f, 0.0f), p->gden[t] = v3(0.0f, 0.0f, 0.0f);
        }
        p->group = g;
        for (int t = 0; t < 2; ++t) {
            ps[g].gnum[t] = v3_add(ps[g].gnum[t], p->num[t]);
            ps[g].gden[t] = v3_add(ps[g].gden[t], p->den[t]);
        }
    }
    for (uint32_t k = 0; k < n; ++k) {
        const psample *p = &ps[k];
        if (!p->used) continue;
        const psample *g = &ps[p->group];
        sy_rt_v3 l = v3_add(ratio_apply(p->a[0], g->gnum[0], g->gden[0]), ratio_apply(p->a[1], g->gnum[1], g->gden[1]));
        *sum = v3_add(*sum, v3_scale(l, p->w));
    }
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
    /* the pixel's samples' records (without them, when out of memory or past 256 samples, every
     * shading point takes its own ratio) */
    psample *ps = j->spp_max <= 256u && (j->area_analytic || j->env.filter) ? malloc(j->spp_max * sizeof *ps) : NULL;
    c.cur = NULL;
    for (uint32_t py = y0; py < y1; ++py) {
        for (uint32_t px = x0; px < x1; ++px) {
            c.pseed = sy_rt_hash32(px ^ sy_rt_hash32(py ^ sy_rt_hash32(f->seed ^ 0x3c6ef372u)));
            c.cache.valid = false;
            sy_rt_v3 sum = v3(0.0f, 0.0f, 0.0f);
            float alpha = 0.0f, dsum = 0.0f;
            uint32_t hits = 0;
            /* per sample: its luminance (own ratio), compressed y / (1 + y), for the refinement test */
            double ts = 0.0, ts2 = 0.0;
            uint32_t n_samples = j->spp;
            for (uint32_t k = 0; k < n_samples; ++k) {
                float fx = (float)px + 0.5f, fy = (float)py + 0.5f;
                if (j->spp_max > 1u) {
                    float u[4];
                    sy_rt_sobol_sample4(j->sobol, c.pseed, 0u, k, u);
                    fx = (float)px + u[0];
                    fy = (float)py + u[1];
                    /* motion blur: the sample's time, the third dimension of the same Sobol set
                     * (stratified jointly with the point); its shadow and secondary rays share it */
                    if (j->motion) c.ictx.time = primary_ctx.time = u[2];
                }
                c.sample = k;
                if (ps) {
                    c.cur = &ps[k];
                    c.cur->used = false;
                    for (int t = 0; t < 2; ++t)
                        c.cur->a[t] = c.cur->num[t] = c.cur->den[t] = v3(0.0f, 0.0f, 0.0f);
                }
                struct RTCRay ray;
                float axial, t;
                sy_rt_frame_ray_time(f, fx, fy, primary_ctx.time, &ray, &axial); /* the camera at that time */
                c.eye = v3(ray.org_x, ray.org_y, ray.org_z);
                rgba_t r = trace(&c, v3(ray.org_x, ray.org_y, ray.org_z), v3(ray.dir_x, ray.dir_y, ray.dir_z), ray.tnear,
                                 ray.tfar, 0u, true, &primary_ctx.rtc, &t);
                sum = v3_add(sum, r.rgb);
                alpha += r.a;
                if (isfinite(t)) dsum += t * axial, hits++;
                if (n_samples < j->spp_max) {
                    sy_rt_v3 own = r.rgb;
                    if (ps && c.cur->used)
                        own = v3_add(own, v3_scale(v3_add(ratio_apply(c.cur->a[0], c.cur->num[0], c.cur->den[0]),
                                                          ratio_apply(c.cur->a[1], c.cur->num[1], c.cur->den[1])),
                                                   c.cur->w));
                    double y = (double)sy_rt_maxf(v3_luminance(own), 0.0f), ty = y / (1.0 + y);
                    ts += ty, ts2 += ty * ty;
                    /* after the first spp: the standard error of their mean, compressed */
                    if (k + 1u == j->spp) {
                        double m = ts / (double)j->spp, var = ts2 / (double)j->spp - m * m;
                        if (var > 0.0 && sqrt(var / (double)j->spp) > REFINE_STDERR) n_samples = j->spp_max;
                    }
                }
            }
            if (ps) pool_resolve(ps, n_samples, &sum);
            size_t o = (size_t)(py - f->y) * f->width + (px - f->x);
            float *out = f->rgba + 4u * o;
            float n = (float)n_samples; /* divide (not multiply by 1/n): n equal samples average exactly */
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
    free(ps);
}

sy_rt_result sy_rt_whitted_render(const sy_rt_frame *f, const sy_rt_render_desc *desc)
{
    const sy_rt_device *dev = f->dev;
    whitted_job *j = malloc(sizeof *j);
    if (!j) return sy_rt_fail(dev, SY_RT_ERROR_OUT_OF_MEMORY, "render: out of memory");
    j->sobol = &f->dev->sobol;
    sy_rt_env_get(f->dev, &j->env);
    j->spp = desc->pixel_samples ? desc->pixel_samples : 1u;
    /* motion blur: at least time_samples samples per pixel (default 16, as many as the sub-frames
     * sy render --shutter averages otherwise), each at its own stratified time */
    j->motion = dev->motion_count > 0 || f->cam_motion;
    if (j->motion) {
        uint32_t ts = desc->time_samples ? desc->time_samples : 16u;
        if (ts < 2u) ts = 2u; /* one stratified time would not blur */
        if (j->spp < ts) j->spp = ts;
    }
    j->spp_max = j->spp > 1u && j->spp < REFINE_MAX_SPP ? (j->spp * REFINE_FACTOR < REFINE_MAX_SPP ? j->spp * REFINE_FACTOR : REFINE_MAX_SPP) : j->spp;
    j->n_env = j->env.mode ? (desc->env_light_samples ? desc->env_light_samples : 4u) : 0u;
    j->lt = sy_rt_light_tree_get(dev, desc->light_tree);
    if (j->lt && j->lt->node_count + j->lt->top_count == 0) j->lt = NULL; /* every light left out */
    j->area_analytic = !j->lt && dev->area_count > 0 && dev->area_count <= ANALYTIC_MAX_TRIANGLES;
    /* textured emitters, and emitters that move over the shutter (the closed form integrates the
     * open's polygons; the sampled estimator places each at its ray's time: sy_rt_area_at), take the
     * sampled estimator */
    for (uint32_t i = 0; j->area_analytic && i < dev->area_count; ++i)
        if (dev->area[i].textured || dev->area[i].inst->motion || dev->area[i].inst->mesh->motion) j->area_analytic = false;
    /* light_samples 0: 8 per pixel for the closed form's visibility (relMSE against 256 spp on
     * EmissiveStrengthTest 0.00057, the demo 0.00064; 16 gave 0.00033 and 0.00060 at 1.2x the
     * time), 16 where the samples carry the light itself */
    uint32_t light_samples = f->light_samples ? f->light_samples : j->area_analytic ? 8u : 16u;
    j->n_area = (light_samples + j->spp - 1u) / j->spp;
    j->poly = NULL;
    j->pv = NULL;
    j->n_poly = 0;
    if (j->area_analytic &&
        (!(j->poly = build_polys(dev, &j->n_poly)) || !(j->pv = malloc(sizeof *j->pv)))) {
        free(j->poly);
        free(j);
        return sy_rt_fail(dev, SY_RT_ERROR_OUT_OF_MEMORY, "render: out of memory");
    }
    if (j->pv) apoly_soa_fill(j->pv, j->poly, j->n_poly);
    sy_rt_result r = sy_rt_run_tiles(f, whitted_tile, j, desc->progress, desc->progress_user_data);
    free(j->pv);
    free(j->poly);
    free(j);
    return r;
}
