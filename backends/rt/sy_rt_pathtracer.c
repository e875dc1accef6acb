/* sy_rt_pathtracer.c — the progressive path tracer (see sy_rt_pathtracer.h).
 *
 * Per sample: a camera ray through a uniformly jittered point of the pixel (box filter of one
 * pixel); emissive surfaces emit (emissive x strength, textured) and also scatter with their BSDF
 * (a black, non-specular emitter such as the Cornell light shows exactly its emission; textured
 * emitters such as DamagedHelmet's need the reflection too); at every vertex emission is added with its MIS weight (the previous vertex's BSDF pdf
 * against the light-selection pdf), one light sample is taken (light category uniformly among
 * area / environment / punctual, an emissive triangle by power through the alias table, a uniform
 * point on it; with the light tree, render desc light_tree and sy_rt_lighttree.h, two categories:
 * the tree's pick among area and punctual lights by their importance at the point, and the
 * environment, shared at each point by what each can bring (env_share); an emitter hit or an
 * escape of a BSDF ray then takes its MIS weight from the tree's pdf and the shares at the
 * previous vertex), then the BSDF is sampled. max_depth bounds the number of scattering events;
 * Russian roulette (survival = min(1, sqrt(max throughput)), as Cycles does) starts at the fifth
 * bounce: on the Cornell box it cost 41 % more error per sample from the third with survival
 * min(0.95, max throughput), for 8 % less time (tests/cycles/equal_error.sh). Alpha-blended
 * surfaces are crossed stochastically with probability 1 - alpha, and shadow rays are attenuated
 * by 1 - alpha through them (sy_rt_shadow.h; shadow rays toward punctual lights also pass
 * transmissive surfaces, see unoccluded()). A camera ray that leaves the scene (straight through
 * blended surfaces, before any scattering) sees the background (never a light); every other ray
 * sees the environment light, black without one.
 *
 * Path records (desc->records, the radiance filter's stored-sample hook, sy_rt.h): the path is
 * split at P0, the first vertex that sampled a non-specular lobe; a second throughput beta_s,
 * started there, gathers the incident estimate along P0's sampled direction. Without records the
 * extra work is a few untaken branches.
 *
 * Random numbers (Owen-scrambled Sobol, padded 4D sets, sy_rt_sampler.h): set 0 = the directions of
 * the first two BSDF samples, stratified together in 4D (the one-bounce indirect light is a 4D
 * integral over them: on the Cornell box 4.5 % less error than the first direction paired with the
 * pixel point, 8 % less than sets of their own); per bounce k set 1 + 2k = light sample, set 2 + 2k
 * = BSDF lobe choice, direction (from the third bounce on) and roulette; set 2's dimensions 1 and 2,
 * unused by the first bounce, place the camera ray in the pixel. Alpha-blend decisions use a hash
 * of their own.
 *
 * Stage timers (desc->stage_times, sy_rt_raylog.h >>stage timers, `sy bench limit`): one pixel in
 * SY_RT_STAGE_SUBSET runs a second inlined copy of the path loop (trace_sample with timed = true)
 * that reads the time stamp counter at every change of stage (LAP); the light sample's functions,
 * shared by both copies, do so when the tile's clock is set (CLAP). The samples are the same. */
#include "sy_rt_pathtracer.h"
#include "sy_rt_accum.h"
#include "sy_rt_bsdf.h"
#include "sy_rt_lights.h"
#include "sy_rt_lighttree.h"
#include "sy_rt_raylog.h"
#include "sy_rt_sampler.h"
#include "sy_rt_shadow.h"

#include <stdatomic.h>
#include <string.h>

typedef struct pt_job {
    sy_rt_accum *acc;
    sy_rt_pt_record *records; /* optional path records of the rectangle (sy_rt.h >>path records) */
    sy_rt_ray_log *log;       /* optional ray log (sy_rt_raylog.h) */
    sy_rt_stage_times *stages; /* optional stage timers (sy_rt_raylog.h >>stage timers) */
    uint32_t first, count;
    const sy_rt_sobol *sobol; /* the device's */
    sy_rt_env env;
    uint32_t categories;     /* light categories present */
    bool has_area, has_env, has_punctual;
    const sy_rt_lighttree *lt; /* light_tree: area and punctual lights are one category, picked by the tree */
} pt_job;

/* With the light tree and an environment, the environment's share of the light samples at point p
 * with the tree's normal n: the irradiance it can give (pi x its mean radiance) against the light
 * the tree's top level can bring (its importances, in the same units), like the entries of that
 * level among themselves. The tree's share is the rest. */
static float env_share(const pt_job *j, sy_rt_v3 p, sy_rt_v3 n)
{
    float e = j->env.irradiance, t = sy_rt_lighttree_total_importance(j->lt, p, n);
    float share = e / (e + t);
    return isfinite(share) && share >= 0.0f ? sy_rt_minf(share, 1.0f) : 0.5f;
}

/* The pixel a tile is at: its sampler seed and, for the sets below PT_SEED_SETS (the camera's and
 * the first 15 bounces'), each set's scramble derived on its first use and kept for the pixel's
 * other samples (the points bit for bit sy_rt_sobol_sample4's). */
enum { PT_SEED_SETS = 32 };
typedef struct pt_pixel {
    uint32_t px, py, pseed;
    uint32_t have; /* bit s: set[s] derived */
    sy_rt_sobol_seed set[PT_SEED_SETS];
} pt_pixel;

static void pixel_start(pt_pixel *pp, const sy_rt_frame *f, uint32_t px, uint32_t py)
{
    pp->px = px, pp->py = py, pp->have = 0;
    pp->pseed = sy_rt_hash32(px ^ sy_rt_hash32(py ^ sy_rt_hash32(f->seed ^ 0x5bd1e995u)));
}

/* Point index of set `set` for the pixel. */
static inline void pixel_sample4(pt_pixel *pp, const sy_rt_sobol *sobol, uint32_t set, uint32_t index, float out[4])
{
    if (set >= PT_SEED_SETS) {
        sy_rt_sobol_sample4(sobol, pp->pseed, set, index, out);
        return;
    }
    if (!(pp->have >> set & 1u)) sy_rt_sobol_seed_of(sobol, pp->pseed, set, &pp->set[set]), pp->have |= 1u << set;
    sy_rt_sobol_sample4_seeded(sobol, &pp->set[set], index, out);
}

typedef struct pt_ctx {
    const sy_rt_frame *f;
    const sy_rt_device *dev;
    const pt_job *job;
    sy_rt_ictx ictx;
    uint64_t rays;
    sy_rt_ray_buf *log; /* the tile's rays when the job logs them, else NULL */
    sy_rt_stage_clock *clk; /* the tile's stage clock while a timed pixel runs, else NULL */
} pt_ctx;

/* Stage changes (sy_rt_raylog.h >>stage timers): LAP in the path loop's timed copy (timed is a
 * constant there), CLAP in the functions both copies call. */
#define LAP(st)                                         \
    do {                                                \
        if (timed) sy_rt_stage_lap(c->clk, (st));       \
    } while (0)
#define CLAP(st)                                        \
    do {                                                \
        if (c->clk) sy_rt_stage_lap(c->clk, (st));      \
    } while (0)

static float maxc(sy_rt_v3 v) { return sy_rt_maxf(v.x, sy_rt_maxf(v.y, v.z)); }
static float power_heuristic(float a, float b)
{
    float a2 = a * a, b2 = b * b;
    return a2 + b2 > 0.0f ? a2 / (a2 + b2) : 0.0f;
}

/* What a shadow ray lets through: alpha-masked holes and alpha-blended surfaces (1 - alpha, the
 * probability with which paths cross them). Transmissive (refracting) surfaces block shadow rays
 * toward emitters and the environment: light from those arrives along sampled refraction paths,
 * and a straight-line shadow ray would count it twice. Punctual lights can never be hit by a
 * path, so their shadow rays (punctual = true) pass transmissive surfaces with the straight-line
 * transmittance of sy_rt_shadow.h, as Whitted's do (without it a light behind glass is lost). */
static sy_rt_v3 unoccluded(pt_ctx *c, sy_rt_v3 org, sy_rt_v3 dir, float tfar, bool punctual)
{
    CLAP(SY_RT_STAGE_SHADOW);
    sy_rt_v3 tr = sy_rt_shadow_transmittance(c->dev, &c->ictx.rtc, org, dir, tfar, punctual, &c->rays, c->log);
    CLAP(SY_RT_STAGE_LIGHT);
    return tr;
}

/* The BSDF toward a light sample (its own stage when timed). */
static sy_rt_v3 eval_toward(pt_ctx *c, const sy_rt_bsdf *b, sy_rt_v3 wo, sy_rt_v3 wi, float *pdf)
{
    CLAP(SY_RT_STAGE_BSDF_EVAL);
    sy_rt_v3 f = sy_rt_bsdf_eval(b, wo, wi, pdf);
    CLAP(SY_RT_STAGE_LIGHT);
    return f;
}

/* One light sample from the shading point: returns f * Le * cos * MIS weight / pdf (visibility
 * included). */
static sy_rt_v3 sample_light(pt_ctx *c, const sy_rt_bsdf *b, const sy_rt_surface *s, sy_rt_v3 wo, const float u[4],
                             float p_env)
{
    const pt_job *j = c->job;
    const sy_rt_device *dev = c->dev;
    sy_rt_v3 zero = v3(0.0f, 0.0f, 0.0f);
    uint32_t cat;
    float ur, p_cat;
    if (j->lt && j->has_env) { /* the tree, then the environment, each by its share (env_share) */
        float p_tree_cat = 1.0f - p_env;
        if (u[0] < p_tree_cat) cat = 0u, ur = sy_rt_clampf(u[0] / p_tree_cat, 0.0f, 0.99999994f), p_cat = p_tree_cat;
        else cat = 1u, ur = sy_rt_clampf((u[0] - p_tree_cat) / p_env, 0.0f, 0.99999994f), p_cat = p_env;
    } else { /* uniformly among the categories present */
        float x = u[0] * (float)j->categories;
        cat = (uint32_t)x;
        if (cat >= j->categories) cat = j->categories - 1u;
        ur = sy_rt_clampf(x - (float)cat, 0.0f, 0.99999994f);
        p_cat = 1.0f / (float)j->categories;
    }
    /* category order: area, environment, punctual (only those present); with the light tree:
     * the tree (area and punctual), environment */
    int kind = -1;
    uint32_t k = 0;
    if (j->lt) kind = cat == 0u ? 3 : 1;
    else if (j->has_area && k++ == cat) kind = 0;
    else if (j->has_env && k++ == cat) kind = 1;
    else if (j->has_punctual) kind = 2;
    sy_rt_v3 p_off = v3_madd(s->p, b->ng, sy_rt_ray_eps(s->p));
    float p_tree = 1.0f; /* kind 3: the tree's selection probability and the triangle it picked */
    uint32_t tree_tri = 0;
    if (kind == 3) {
        uint32_t li = sy_rt_lighttree_pick(j->lt, s->p, sy_rt_light_tree_normal(b->ng, b->q_trans), ur, &p_tree);
        if (li == SY_RT_LT_NONE || !(p_tree > 0.0f)) return zero;
        if (li >= dev->area_count) { /* a punctual light */
            sy_rt_v3 wi, e;
            float tmax;
            if (!sy_rt_punctual_incident(&dev->punctual[li - dev->area_count], s->p, &wi, &e, &tmax)) return zero;
            float pdf_b;
            sy_rt_v3 f = eval_toward(c, b, wo, wi, &pdf_b);
            if (v3_is_zero(f)) return zero;
            sy_rt_v3 tr = unoccluded(c, p_off, wi, tmax, true);
            if (v3_is_zero(tr)) return zero;
            return v3_scale(v3_mul(f, v3_mul(tr, e)), 1.0f / (p_tree * p_cat));
        }
        tree_tri = li; /* a triangle: below */
    }
    if (kind == 0 || kind == 3) {
        sy_rt_area_tri moved; /* a moving emitter: where it is at the path's time (motion blur) */
        const sy_rt_area_tri *t = sy_rt_area_at(&dev->area[kind == 3 ? tree_tri : sy_rt_alias_pick(dev, ur)], c->ictx.time, &moved);
        float su = sqrtf(u[1]), bu = su * (1.0f - u[2]), bv = su * u[2];
        sy_rt_v3 q = v3_add(t->p0, v3_add(v3_scale(t->e1, bu), v3_scale(t->e2, bv)));
        sy_rt_v3 wi = v3_sub(q, s->p);
        float d2 = v3_dot(wi, wi);
        if (!(d2 > 0.0f)) return zero;
        float d = sqrtf(d2);
        wi = v3_scale(wi, 1.0f / d);
        float cos_l = -v3_dot(t->normal, wi);
        if (t->double_sided) cos_l = fabsf(cos_l);
        if (!(cos_l > 1e-7f)) return zero;
        float pdf_b;
        sy_rt_v3 f = eval_toward(c, b, wo, wi, &pdf_b);
        if (v3_is_zero(f)) return zero;
        float pdf_l = (kind == 3 ? p_tree / t->area : t->pdf_select) * d2 / cos_l * p_cat;
        if (!(pdf_l > 0.0f)) return zero;
        sy_rt_v3 sdir;
        float tmax;
        sy_rt_v3 tr = sy_rt_clip_removes(dev, q.x, q.y, q.z) ? v3(0.0f, 0.0f, 0.0f) /* an emitter point in a removed part */
                      : sy_rt_segment_to(p_off, q, &sdir, &tmax) ? unoccluded(c, p_off, sdir, tmax, false) : v3(1.0f, 1.0f, 1.0f);
        if (v3_is_zero(tr)) return zero;
        sy_rt_v3 le = v3_mul(tr, t->textured ? sy_rt_surface_emission(dev, t->inst, t->prim, bu, bv) : t->emission);
        return v3_scale(v3_mul(f, le), power_heuristic(pdf_l, pdf_b) / pdf_l);
    }
    if (kind == 1) {
        sy_rt_v3 wi, le;
        float pdf_l = sy_rt_env_sample(&j->env, ur, u[1], &wi, &le) * p_cat;
        if (!(pdf_l > 0.0f) || v3_is_zero(le)) return zero;
        float pdf_b;
        sy_rt_v3 f = eval_toward(c, b, wo, wi, &pdf_b);
        if (v3_is_zero(f)) return zero;
        sy_rt_v3 tr = unoccluded(c, p_off, wi, INFINITY, false);
        if (v3_is_zero(tr)) return zero;
        return v3_scale(v3_mul(f, v3_mul(tr, le)), power_heuristic(pdf_l, pdf_b) / pdf_l);
    }
    if (kind == 2) {
        uint32_t n = dev->punctual_count, i = (uint32_t)(ur * (float)n);
        if (i >= n) i = n - 1u;
        sy_rt_v3 wi, e;
        float tmax;
        if (!sy_rt_punctual_incident(&dev->punctual[i], s->p, &wi, &e, &tmax)) return zero;
        float pdf_b;
        sy_rt_v3 f = eval_toward(c, b, wo, wi, &pdf_b);
        if (v3_is_zero(f)) return zero;
        sy_rt_v3 tr = unoccluded(c, p_off, wi, tmax, true);
        if (v3_is_zero(tr)) return zero;
        return v3_scale(v3_mul(f, v3_mul(tr, e)), (float)n / p_cat);
    }
    return zero;
}

/* Records P0 of a path (sy_rt.h >>path records): the vertex where the first non-specular lobe was
 * sampled, with everything gathered so far as the prefix. */
static void record_p0(sy_rt_pt_record *rec, const sy_rt_surface *s, const sy_rt_bsdf *b, sy_rt_v3 wo, sy_rt_v3 d,
                      float path_len, sy_rt_v3 beta, sy_rt_v3 prefix, sy_rt_v3 wi)
{
    const sy_rt_v3 v[7] = {prefix, s->p, b->n, wo, d, beta, wi};
    float *dst[7] = {rec->prefix, rec->position, rec->normal, rec->wo, rec->ray_dir, rec->throughput, rec->wi};
    for (int i = 0; i < 7; ++i) dst[i][0] = v[i].x, dst[i][1] = v[i].y, dst[i][2] = v[i].z;
    rec->path_length = path_len;
    rec->glossy_exponent = !b->delta && b->q_metal + b->q_spec >= 0.25f ? 2.0f / (b->alpha * b->alpha) - 2.0f : 0.0f;
    sy_rt_bsdf_pack(b, rec->bsdf);
    rec->flags = SY_RT_RECORD_P0;
}

/* Traces one path; rec (NULL = not requested) receives its record. Always inlined: the call without
 * a record (a constant NULL) compiles to a path loop without the record's work and branches. */
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
static inline void trace_sample(pt_ctx *c, pt_pixel *pp, uint32_t index, sy_rt_pt_sample *out,
                         sy_rt_pt_record *rec, const bool timed)
{
    const sy_rt_frame *f = c->f;
    const sy_rt_device *dev = c->dev;
    const pt_job *j = c->job;
    const uint32_t px = pp->px, py = pp->py, pseed = pp->pseed;
    /* set 0: the first two BSDF directions, stratified together; set 2 (the first vertex's BSDF
     * set): lobe choice, the pixel point, roulette */
    float dirs[4], first_bsdf[4];
    pixel_sample4(pp, j->sobol, 0u, index, dirs);
    pixel_sample4(pp, j->sobol, 2u, index, first_bsdf);
    if (dev->motion_count || f->cam_motion) { /* motion blur: the sample's time, stratified over the pixel's samples (the
                              * first dimension of a set no bounce uses, scrambled apart); every ray
                              * of the path, shadow rays too, has it */
        float tu[4];
        sy_rt_sobol_sample4(j->sobol, pseed ^ 0x68e31da4u, 0xfffffffu, index, tu);
        c->ictx.time = tu[0];
    }
    struct RTCRay ray;
    float axial;
    sy_rt_frame_ray_time(f, (float)px + first_bsdf[1], (float)py + first_bsdf[2], c->ictx.time, &ray, &axial);
    (void)axial;
    /* every segment's direction is a unit vector (the camera's here; BSDF samples are unit), so
     * ray parameters are distances */
    sy_rt_v3 org = v3(ray.org_x, ray.org_y, ray.org_z), dir = v3(ray.dir_x, ray.dir_y, ray.dir_z);
    float cam_len = v3_length(dir);
    dir = v3_scale(dir, 1.0f / cam_len);
    float tnear = ray.tnear * cam_len, tfar = ray.tfar * cam_len;
    /* extra decorrelated bits for alpha-blend decisions */
    uint32_t rng = sy_rt_hash32(pseed ^ sy_rt_hash32(index + 0x2545f491u));

    sy_rt_v3 beta = v3(1.0f, 1.0f, 1.0f), L = v3(0.0f, 0.0f, 0.0f), direct = L;
    bool specular = true, features = false, first = true;
    float pdf_prev = 0.0f;
    sy_rt_v3 prev_p = v3(0.0f, 0.0f, 0.0f), prev_n = prev_p; /* light tree: the previous vertex's point and normal */
    uint32_t bounce = 0, crossings = 0;
    out->alpha = 0.0f;
    out->depth = INFINITY;
    out->albedo = out->normal = v3(0.0f, 0.0f, 0.0f);
    float p_area_sel = j->has_area ? 1.0f / (float)j->categories : 0.0f;
    float p_env_sel = j->has_env ? 1.0f / (float)j->categories : 0.0f;
    const bool env_split = j->lt && j->has_env; /* the two shares are the previous vertex's env_share */
    /* path record: after P0 every contribution x (before the path throughput) also goes into the
     * incident estimate with the throughput beta_s gathered after P0 */
    bool after_p0 = false, want_hit = false;
    sy_rt_v3 beta_s = v3(0.0f, 0.0f, 0.0f), incident = beta_s;
    float path_len = 0.0f;
    if (rec) rec->flags = 0, rec->hit_distance = INFINITY;
    const sy_rt_material_data *medium = NULL; /* the absorbing volume the ray travels in (KHR_materials_volume) */

    for (;;) {
        struct RTCRayHit rh;
        LAP(SY_RT_STAGE_NULL); /* the cost of a change of stage, here */
        LAP(SY_RT_STAGE_TRAVERSAL);
        const sy_rt_instance_data *in = sy_rt_intersect(dev, &c->ictx.rtc, org, dir, tnear, tfar, &rh);
        LAP(SY_RT_STAGE_SHADING);
        c->rays++;
        if (c->log) sy_rt_ray_buf_add_hit(c->log, SY_RT_RAY_EXTENSION, org, dir, tnear, tfar, &rh);
        const sy_rt_v3 d = dir;
        if (rec) {
            if (want_hit) rec->hit_distance = in ? rh.ray.tfar : INFINITY, want_hit = false;
            if (!after_p0 && in) path_len += rh.ray.tfar;
        }
        if (medium && in) { /* Beer-Lambert absorption over the segment inside (an escaping ray: an open mesh) */
            float t = rh.ray.tfar * v3_length(dir);
            sy_rt_v3 tr = v3(expf(-medium->sigma[0] * t), expf(-medium->sigma[1] * t), expf(-medium->sigma[2] * t));
            beta = v3_mul(beta, tr);
            if (after_p0) beta_s = v3_mul(beta_s, tr);
        }
        if (!in) {
            if (bounce == 0u) { /* a camera ray (through alpha-blended crossings) sees the background */
                sy_rt_v3 bg;
                float a = sy_rt_background_eval(dev, &d, &bg);
                if (first) out->alpha = a;
                sy_rt_v3 contrib = v3_mul(beta, bg);
                L = v3_add(L, contrib);
                direct = v3_add(direct, contrib);
            } else if (j->env.mode) { /* every other ray sees the environment light */
                float pdf_env;
                sy_rt_v3 le = sy_rt_env_eval_pdf(&j->env, d, &pdf_env);
                float w = specular ? 1.0f : power_heuristic(pdf_prev, pdf_env * p_env_sel);
                sy_rt_v3 contrib = v3_scale(v3_mul(beta, le), w);
                L = v3_add(L, contrib);
                if (after_p0) incident = v3_add(incident, v3_scale(v3_mul(beta_s, le), w));
                if (bounce <= 1u) direct = v3_add(direct, contrib);
            }
            break;
        }
        float t_cap;
        if (sy_rt_clip_cap(dev, in, rh.hit.primID, org, dir, tnear, rh.ray.tfar, &t_cap)) {
            /* a section cap: camera rays see its flat colour, every other ray an opaque black surface */
            if (bounce == 0u) {
                sy_rt_v3 contrib = v3_mul(beta, v3_load(dev->clip_cap_color));
                L = v3_add(L, contrib);
                direct = v3_add(direct, contrib);
            }
            if (first) {
                out->alpha = 1.0f;
                out->depth = v3_dot(v3_sub(v3_madd(org, dir, t_cap), f->cam_pos), f->forward);
                if (!features) out->albedo = v3_load(dev->clip_cap_color), features = true;
            }
            break;
        }
        sy_rt_surface s;
        LAP(SY_RT_STAGE_HIT_FETCH);
        sy_rt_surface_fetch_at(dev, in, c->ictx.time, rh.hit.primID, rh.hit.u, rh.hit.v, d, &s);
        LAP(SY_RT_STAGE_SHADING);
        if (s.mat->desc.alpha_mode == SY_RT_ALPHA_BLEND && s.alpha < 1.0f) {
            rng = sy_rt_hash32(rng + 0x9e3779b9u);
            if (sy_rt_u01(rng) >= sy_rt_clampf(s.alpha, 0.0f, 1.0f)) { /* pass through */
                if (++crossings > 64u) break;
                org = v3_madd(s.p, s.ng_facing, -sy_rt_ray_eps(s.p));
                dir = d;
                tnear = 0.0f;
                tfar = INFINITY;
                continue;
            }
        }
        if (first) {
            out->alpha = 1.0f;
            out->depth = v3_dot(v3_sub(s.p, f->cam_pos), f->forward);
            first = false;
        }
        /* an emitter's light, where it is not black (a textured emitter's black texels add
         * nothing: no MIS weight, whose light-tree pdf walks the tree) */
        if (s.mat->emissive && (s.front || s.mat->desc.double_sided) && !v3_is_zero(s.emission)) {
            float w = 1.0f;
            if (!specular) {
                float dist = rh.ray.tfar, cos_l = fabsf(v3_dot(s.ng, d));
                float pdf_a = 0.0f; /* area-measure pdf of light sampling at this point */
                /* a moving emitter: its triangle as light sampling takes it at this path's time */
                uint32_t ai = sy_rt_area_index(dev, in, rh.hit.primID);
                sy_rt_area_tri moved;
                const sy_rt_area_tri *at = ai != UINT32_MAX ? sy_rt_area_at(&dev->area[ai], c->ictx.time, &moved) : NULL;
                if (at) /* (none for a triangle light sampling leaves out: zero area) */
                    pdf_a = j->lt ? sy_rt_lighttree_pdf(j->lt, prev_p, prev_n, ai) / at->area
                            : at == &moved ? moved.pdf_select : sy_rt_area_pdf(dev, in);
                float pdf_l = cos_l > 0.0f ? pdf_a * dist * dist / cos_l * p_area_sel : 0.0f;
                w = power_heuristic(pdf_prev, pdf_l);
            }
            sy_rt_v3 contrib = v3_scale(v3_mul(beta, s.emission), w);
            L = v3_add(L, contrib);
            if (after_p0) incident = v3_add(incident, v3_scale(v3_mul(beta_s, s.emission), w));
            if (bounce <= 1u) direct = v3_add(direct, contrib);
        }
        if (s.mat->desc.unlit) {
            sy_rt_v3 contrib = v3_mul(beta, s.base);
            L = v3_add(L, contrib);
            if (after_p0) incident = v3_add(incident, v3_mul(beta_s, s.base));
            if (bounce == 0u) direct = v3_add(direct, contrib);
            if (!features) out->albedo = s.base, out->normal = s.ns, features = true;
            break;
        }
        if (bounce >= f->max_depth) break;
        sy_rt_v3 wo = v3_scale(d, -1.0f);
        sy_rt_bsdf b;
        LAP(SY_RT_STAGE_BSDF_INIT);
        sy_rt_bsdf_init(&b, &s, wo);
        LAP(SY_RT_STAGE_SHADING);
        bool evaluable = sy_rt_bsdf_evaluable(&b);
        if (!features && (evaluable || b.q_metal + b.q_spec + b.q_diff + b.q_trans == 0.0f)) {
            out->albedo = b.base;
            out->normal = b.n;
            features = true;
        }
        float ul[4], ub[4];
        LAP(SY_RT_STAGE_RNG);
        pixel_sample4(pp, j->sobol, 1u + 2u * bounce, index, ul);
        if (bounce == 0u) {
            ub[0] = first_bsdf[0], ub[1] = dirs[0], ub[2] = dirs[1], ub[3] = first_bsdf[3];
        } else {
            pixel_sample4(pp, j->sobol, 2u + 2u * bounce, index, ub);
            if (bounce == 1u) ub[1] = dirs[2], ub[2] = dirs[3];
        }
        LAP(SY_RT_STAGE_SHADING);
        float p_env_here = p_env_sel;
        if (env_split) {
            LAP(SY_RT_STAGE_LIGHT);
            p_env_here = env_share(j, s.p, sy_rt_light_tree_normal(b.ng, b.q_trans));
            LAP(SY_RT_STAGE_SHADING);
        }
        if (evaluable && j->categories) {
            LAP(SY_RT_STAGE_LIGHT);
            sy_rt_v3 le = sample_light(c, &b, &s, wo, ul, p_env_here);
            LAP(SY_RT_STAGE_SHADING);
            sy_rt_v3 contrib = v3_mul(beta, le);
            L = v3_add(L, contrib);
            if (after_p0) incident = v3_add(incident, v3_mul(beta_s, le));
            if (bounce == 0u) direct = v3_add(direct, contrib);
        }
        sy_rt_bsdf_sample bs;
        LAP(SY_RT_STAGE_BSDF_SAMPLE);
        if (!sy_rt_bsdf_sample_dir(&b, wo, ub, &bs)) break;
        LAP(SY_RT_STAGE_SHADING);
        if (after_p0) {
            beta_s = v3_mul(beta_s, bs.weight);
        } else if (rec && !bs.specular) {
            record_p0(rec, &s, &b, wo, d, path_len, beta, L, bs.wi);
            after_p0 = want_hit = true;
            beta_s = v3(1.0f, 1.0f, 1.0f);
        }
        beta = v3_mul(beta, bs.weight);
        specular = bs.specular;
        pdf_prev = bs.pdf;
        if (j->lt) prev_p = s.p, prev_n = sy_rt_light_tree_normal(b.ng, b.q_trans);
        if (env_split) p_env_sel = p_env_here, p_area_sel = 1.0f - p_env_here;
        bounce++;
        if (bounce >= 5u) {
            float q = sy_rt_minf(sqrtf(maxc(beta)), 1.0f);
            if (!(ub[3] < q)) break;
            beta = v3_scale(beta, 1.0f / q);
            beta_s = v3_scale(beta_s, 1.0f / q);
        }
        if (v3_is_zero(beta)) break;
        /* refraction into a volume enters it, out of one leaves it; reflections keep the medium */
        if (bs.transmit) medium = s.front && s.mat->volume ? s.mat : NULL;
        org = v3_madd(s.p, b.ng, bs.transmit ? -sy_rt_ray_eps(s.p) : sy_rt_ray_eps(s.p));
        dir = bs.wi;
        tnear = 0.0f;
        tfar = INFINITY;
    }
    out->color = L;
    out->direct = direct;
    if (rec) {
        const sy_rt_v3 pre = after_p0 ? v3(rec->prefix[0], rec->prefix[1], rec->prefix[2]) : L;
        rec->color[0] = L.x, rec->color[1] = L.y, rec->color[2] = L.z;
        rec->prefix[0] = pre.x, rec->prefix[1] = pre.y, rec->prefix[2] = pre.z;
        rec->incident[0] = incident.x, rec->incident[1] = incident.y, rec->incident[2] = incident.z;
    }
}

static void pt_tile(const sy_rt_frame *f, void *user, uint32_t x0, uint32_t y0, uint32_t x1, uint32_t y1)
{
    pt_job *j = user;
    pt_ctx c;
    c.f = f;
    c.dev = f->dev;
    c.job = j;
    sy_rt_context_init(f->dev, &c.ictx, RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT);
    c.rays = 0;
    sy_rt_ray_buf tile_log = {0};
    c.log = j->log ? &tile_log : NULL;
    c.clk = NULL;
    sy_rt_stage_clock clk_mem, *clk = NULL;
    if (j->stages && !j->records) memset(&clk_mem, 0, sizeof clk_mem), clk = &clk_mem;
    uint64_t bad = 0, timed = 0;
    pt_pixel pp;
    for (uint32_t py = y0; py < y1; ++py)
        for (uint32_t px = x0; px < x1; ++px) {
            size_t pix = (size_t)(py - f->y) * f->width + (px - f->x);
            float *rec = j->acc->data + pix * SY_RT_ACC_STRIDE;
            sy_rt_pt_record *prec = j->records ? j->records + pix : NULL;
            pixel_start(&pp, f, px, py);
            if (clk && sy_rt_hash32(px * 0x9e3779b1u ^ sy_rt_hash32(py)) % SY_RT_STAGE_SUBSET == 0u) {
                /* a timed pixel (records are off while timing) */
                c.clk = clk;
                clk->cur = SY_RT_STAGE_RNG;
                clk->last = sy_rt_stage_tick();
                for (uint32_t k = 0; k < j->count; ++k) {
                    sy_rt_pt_sample s;
                    trace_sample(&c, &pp, j->first + k, &s, NULL, true);
                    sy_rt_stage_lap(clk, SY_RT_STAGE_ACCUM);
                    if (!sy_rt_accum_add(rec, j->first + k + 1u, &s)) bad++;
                    sy_rt_stage_lap(clk, SY_RT_STAGE_RNG);
                }
                c.clk = NULL;
                timed += j->count;
                continue;
            }
            for (uint32_t k = 0; k < j->count; ++k) {
                sy_rt_pt_sample s;
                if (prec && k + 1u == j->count) trace_sample(&c, &pp, j->first + k, &s, prec, false);
                else trace_sample(&c, &pp, j->first + k, &s, NULL, false);
                if (!sy_rt_accum_add(rec, j->first + k + 1u, &s)) bad++;
            }
        }
    if (bad) atomic_fetch_add(&j->acc->nonfinite, bad);
    if (clk) sy_rt_stage_times_add(j->stages, clk, timed);
    atomic_fetch_add(&j->acc->rays, c.rays);
    if (c.log) {
        sy_rt_ray_log_append(j->log, c.log);
        sy_rt_ray_buf_free(c.log);
    }
}

sy_rt_result sy_rt_pathtracer_render(const sy_rt_frame *f, const sy_rt_render_desc *desc)
{
    const sy_rt_device *dev = f->dev;
    sy_rt_accum *acc = desc->accum;
    if (!acc) return sy_rt_fail(dev, SY_RT_ERROR_INVALID_ARGUMENT, "render: the path tracer needs an accum");
    if (acc->width != f->width || acc->height != f->height)
        return sy_rt_fail(dev, SY_RT_ERROR_INVALID_ARGUMENT,
                          "render: accum is %ux%u but the rectangle is %ux%u", acc->width, acc->height, f->width, f->height);
    uint32_t count = desc->samples ? desc->samples : 1u;
    if (count > UINT32_MAX - 1u - acc->samples)
        return sy_rt_fail(dev, SY_RT_ERROR_LIMIT, "render: %u + %u samples per pixel overflow", acc->samples, count);
    pt_job j;
    memset(&j, 0, sizeof j);
    j.acc = acc;
    j.records = desc->records;
    j.log = desc->ray_log;
    j.stages = desc->stage_times;
    j.first = acc->samples;
    j.count = count;
    j.sobol = &f->dev->sobol;
    sy_rt_env_get(f->dev, &j.env);
    j.has_area = f->dev->area_count > 0 && f->dev->area_alias_prob;
    j.has_env = j.env.mode != 0;
    j.has_punctual = f->dev->punctual_count > 0;
    j.lt = sy_rt_light_tree_get(f->dev, desc->light_tree);
    if (j.lt && j.lt->node_count + j.lt->top_count == 0) j.lt = NULL; /* every light left out */
    j.categories = j.lt ? 1u + (uint32_t)j.has_env
                        : (uint32_t)j.has_area + (uint32_t)j.has_env + (uint32_t)j.has_punctual;
    atomic_store(&acc->rays, 0u);
    sy_rt_result r = sy_rt_run_tiles(f, pt_tile, &j, desc->progress, desc->progress_user_data);
    if (r == SY_RT_ERROR_CANCELLED) {
        /* Tiles that ran hold more samples than the others: the accumulation is inconsistent. */
        sy_rt_accum_reset(acc);
        return r;
    }
    if (r != SY_RT_OK) return r;
    acc->samples += count;
    size_t n = (size_t)f->width * f->height;
    for (size_t i = 0; i < n; ++i) {
        const float *rec = acc->data + i * SY_RT_ACC_STRIDE;
        if (f->rgba) memcpy(f->rgba + 4u * i, rec + SY_RT_ACC_COLOR, 4u * sizeof(float));
        if (f->depth) f->depth[i] = rec[SY_RT_ACC_HITS] > 0.0f ? rec[SY_RT_ACC_DEPTH] : INFINITY;
    }
    return SY_RT_OK;
}
