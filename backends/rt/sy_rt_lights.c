/* sy_rt_lights.c — alias table over emissive triangles, environment distribution and sampling,
 * sy_rt_set_environment, the background seen by camera rays (see sy_rt_lights.h). */
#include "sy_rt_lights.h"
#include "sy_rt_envfilter.h"
#include "sy_rt_lighttree.h"
#include "sy_rt_texture.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define PI_F 3.14159265358979f

/* >>alias (Vose 1991): every slot holds a probability and an alias; picking is one uniform number. */
bool sy_rt_alias_build(sy_rt_device *dev, const double *w, uint32_t n)
{
    free(dev->area_alias_prob);
    free(dev->area_alias_idx);
    dev->area_alias_prob = NULL;
    dev->area_alias_idx = NULL;
    if (n == 0) return true;
    float *prob = malloc((size_t)n * sizeof *prob);
    uint32_t *alias = malloc((size_t)n * sizeof *alias);
    double *scaled = malloc((size_t)n * sizeof *scaled);
    uint32_t *small = malloc((size_t)n * sizeof *small), *large = malloc((size_t)n * sizeof *large);
    if (!prob || !alias || !scaled || !small || !large) {
        free(prob), free(alias), free(scaled), free(small), free(large);
        return false;
    }
    double total = 0.0;
    for (uint32_t i = 0; i < n; ++i) total += w[i];
    uint32_t ns = 0, nl = 0;
    for (uint32_t i = 0; i < n; ++i) {
        scaled[i] = total > 0.0 ? w[i] * (double)n / total : 1.0;
        alias[i] = i;
        if (scaled[i] < 1.0) small[ns++] = i;
        else large[nl++] = i;
    }
    while (ns && nl) {
        uint32_t s = small[--ns], l = large[--nl];
        prob[s] = (float)scaled[s];
        alias[s] = l;
        scaled[l] = (scaled[l] + scaled[s]) - 1.0;
        if (scaled[l] < 1.0) small[ns++] = l;
        else large[nl++] = l;
    }
    while (nl) prob[large[--nl]] = 1.0f;
    while (ns) prob[small[--ns]] = 1.0f; /* rounding leftovers */
    free(scaled), free(small), free(large);
    dev->area_alias_prob = prob;
    dev->area_alias_idx = alias;
    return true;
}

uint32_t sy_rt_alias_pick(const sy_rt_device *dev, float u)
{
    uint32_t n = dev->area_count;
    float x = u * (float)n;
    uint32_t i = (uint32_t)x;
    if (i >= n) i = n - 1u;
    float frac = x - (float)i;
    return frac < dev->area_alias_prob[i] ? i : dev->area_alias_idx[i];
}

float sy_rt_emission_weight(const sy_rt_material_data *mat)
{
    float lum = v3_luminance(v3_load(mat->desc.emissive));
    if (!(lum > 0.0f)) lum = fmaxf(mat->desc.emissive[0], fmaxf(mat->desc.emissive[1], mat->desc.emissive[2]));
    return lum;
}

float sy_rt_area_pdf(const sy_rt_device *dev, const sy_rt_instance_data *inst)
{
    if (!dev->area_count || !(dev->area_power > 0.0f)) return 0.0f;
    const sy_rt_material_data *mat = sy_rt_material_lookup(dev, inst->material);
    return sy_rt_emission_weight(mat) * (mat->desc.double_sided ? 2.0f : 1.0f) / dev->area_power;
}

/* >>moving emitters (motion blur): an area triangle where its instance and mesh are at a ray's time */
const sy_rt_area_tri *sy_rt_area_at(const sy_rt_area_tri *t, float time, sy_rt_area_tri *scratch)
{
    const sy_rt_instance_data *in = t->inst;
    if (!(time > 0.0f) || !in || (!in->motion && !in->mesh->motion)) return t;
    sy_rt_instance_data posed;
    const sy_rt_instance_data *at = sy_rt_instance_at(in, time, &posed);
    const sy_rt_mesh_data *m = in->mesh;
    /* a deforming mesh: the two vertex steps around the time, as Embree finds them (sy_rt_surface_fetch_at) */
    const float *q0 = m->positions, *q1 = m->positions;
    float f = 0.0f;
    if (m->motion) {
        q1 = m->positions1, f = time;
        if (m->motion_steps > 2u) {
            float st = time * (float)(m->motion_steps - 1u);
            uint32_t seg = st > 0.0f ? (uint32_t)st : 0u;
            if (seg > m->motion_steps - 2u) seg = m->motion_steps - 2u;
            f = st - (float)seg;
            if (seg > 0u) q0 = m->pos_mid[seg];
            if (seg + 2u < m->motion_steps) q1 = m->pos_mid[seg + 1u];
        }
    }
    const uint32_t *ix = m->indices + 3u * t->prim;
    sy_rt_v3 o[3], p[3];
    for (int c = 0; c < 3; ++c) {
        const float *a = q0 + 3u * ix[c], *b = q1 + 3u * ix[c];
        o[c] = v3((1.0f - f) * a[0] + f * b[0], (1.0f - f) * a[1] + f * b[1], (1.0f - f) * a[2] + f * b[2]);
        p[c] = m4_point(at->xf, o[c]);
    }
    *scratch = *t;
    scratch->p0 = p[0];
    scratch->e1 = v3_sub(p[1], p[0]);
    scratch->e2 = v3_sub(p[2], p[0]);
    scratch->normal = v3_normalize(m3_mul(at->nrm, v3_cross(v3_sub(o[1], o[0]), v3_sub(o[2], o[0]))));
    float area = 0.5f * v3_length(v3_cross(scratch->e1, scratch->e2));
    if (!(area > 0.0f) || v3_is_zero(scratch->normal)) return t; /* degenerate then: the open's triangle */
    /* the selection picks the triangle by its open area, the point is uniform on its area now */
    scratch->pdf_select = t->pdf_select * t->area / area;
    scratch->area = area;
    return scratch;
}

/* >>environment */
sy_rt_result sy_rt_set_environment(sy_rt_device *dev, sy_rt_texture texture, float intensity)
{
    if (!dev) return sy_rt_fail(dev, SY_RT_ERROR_INVALID_ARGUMENT, "environment: NULL device");
    if (!isfinite(intensity) || intensity < 0.0f)
        return sy_rt_fail(dev, SY_RT_ERROR_INVALID_ARGUMENT,
                          "environment: intensity %g is not a finite non-negative number", (double)intensity);
    if (texture.id && !sy_rt_pool_get(&dev->textures, texture.id))
        return sy_rt_fail(dev, SY_RT_ERROR_INVALID_HANDLE, "environment: texture %u is not a live texture",
                          texture.id);
    dev->env_texture_staged = texture;
    dev->env_intensity_staged = intensity;
    dev->env_dirty = dev->dirty = true;
    return SY_RT_OK;
}

void sy_rt_env_free(sy_rt_device *dev)
{
    if (dev->env_dist) {
        free(dev->env_dist->marginal);
        free(dev->env_dist->conditional);
        free(dev->env_dist->texel_pdf);
        free(dev->env_dist->guide_marginal);
        free(dev->env_dist->guide_conditional);
        free(dev->env_dist);
    }
    dev->env_dist = NULL;
    sy_rt_envfilter_free(dev->env_filter);
    dev->env_filter = NULL;
}

sy_rt_result sy_rt_env_rebuild(sy_rt_device *dev)
{
    sy_rt_env_free(dev);
    dev->env_texture = dev->env_texture_staged;
    dev->env_intensity = dev->env_intensity_staged;
    const sy_rt_texture_data *t = sy_rt_pool_get(&dev->textures, dev->env_texture.id);
    if (!t) return SY_RT_OK;
    uint32_t w = t->width, h = t->height;
    size_t n = (size_t)w * h;
    sy_rt_env_dist *d = calloc(1, sizeof *d);
    float *lum = malloc(n * sizeof *lum);
    if (d) {
        d->width = w;
        d->height = h;
        d->marginal = malloc(((size_t)h + 1u) * sizeof *d->marginal);
        d->conditional = malloc((size_t)h * ((size_t)w + 1u) * sizeof *d->conditional);
        d->texel_pdf = malloc(n * sizeof *d->texel_pdf);
        d->guide_marginal = malloc((size_t)h * sizeof *d->guide_marginal);
        d->guide_conditional = malloc(n * sizeof *d->guide_conditional);
    }
    if (!d || !lum || !d->marginal || !d->conditional || !d->texel_pdf || !d->guide_marginal ||
        !d->guide_conditional) {
        free(lum);
        dev->env_dist = d;
        sy_rt_env_free(dev);
        return sy_rt_fail(dev, SY_RT_ERROR_OUT_OF_MEMORY, "commit: environment %ux%u: out of memory", w, h);
    }
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            float c[4];
            sy_rt_texture_sample(t, ((float)x + 0.5f) / (float)w, ((float)y + 0.5f) / (float)h, c);
            float l = v3_luminance(v3(c[0], c[1], c[2]));
            lum[(size_t)y * w + x] = isfinite(l) && l > 0.0f ? l : 0.0f;
        }
    /* Weight of a texel: the largest luminance of it and its 4 neighbours (bilinear lookups reach
     * them), times sin(theta) of the row, plus a small floor so that no direction has pdf 0. */
    double total = 0.0;
    double *rows = malloc((size_t)h * sizeof *rows);
    if (!rows) {
        free(lum);
        dev->env_dist = d;
        sy_rt_env_free(dev);
        return sy_rt_fail(dev, SY_RT_ERROR_OUT_OF_MEMORY, "commit: environment: out of memory");
    }
    double lsum = 0.0;
    for (size_t i = 0; i < n; ++i) lsum += lum[i];
    float floor_w = (float)(lsum / (double)n * 1e-3) + 1e-12f;
    double lum_sphere = 0.0, w_sphere = 0.0; /* the mean luminance, each row by its sin(theta) */
    for (uint32_t y = 0; y < h; ++y) {
        float s = sinf(PI_F * ((float)y + 0.5f) / (float)h);
        float *cdf = d->conditional + (size_t)y * (w + 1u);
        double acc = 0.0, row = 0.0;
        cdf[0] = 0.0f;
        for (uint32_t x = 0; x < w; ++x) {
            row += lum[(size_t)y * w + x];
            float m = lum[(size_t)y * w + x];
            m = fmaxf(m, lum[(size_t)y * w + (x + 1u) % w]);
            m = fmaxf(m, lum[(size_t)y * w + (x + w - 1u) % w]);
            if (y > 0) m = fmaxf(m, lum[(size_t)(y - 1u) * w + x]);
            if (y + 1u < h) m = fmaxf(m, lum[(size_t)(y + 1u) * w + x]);
            double wt = (double)(m + floor_w) * s;
            d->texel_pdf[(size_t)y * w + x] = (float)wt;
            acc += wt;
            cdf[x + 1u] = (float)acc;
        }
        for (uint32_t x = 1; x <= w; ++x) cdf[x] = acc > 0.0 ? (float)(cdf[x] / acc) : (float)x / (float)w;
        cdf[w] = 1.0f;
        rows[y] = acc;
        total += acc;
        double sd = sin(PI_F * ((double)y + 0.5) / (double)h);
        lum_sphere += row * sd;
        w_sphere += (double)w * sd;
    }
    d->mean_luminance = w_sphere > 0.0 ? (float)(lum_sphere / w_sphere) : 0.0f;
    double acc = 0.0;
    d->marginal[0] = 0.0f;
    for (uint32_t y = 0; y < h; ++y) {
        acc += rows[y];
        d->marginal[y + 1u] = (float)(acc / total);
    }
    d->marginal[h] = 1.0f;
    for (size_t i = 0; i < n; ++i) d->texel_pdf[i] = (float)(d->texel_pdf[i] / total);
    sy_rt_cdf_guide(d->marginal, h, d->guide_marginal);
    for (uint32_t y = 0; y < h; ++y)
        sy_rt_cdf_guide(d->conditional + (size_t)y * (w + 1u), w, d->guide_conditional + (size_t)y * w);
    free(rows);
    free(lum);
    dev->env_dist = d;
    return SY_RT_OK;
}

/* Lat-long lookup of a texture at u, v (sy_rt_latlong_uv) times intensity; non-finite or negative
 * radiance reads as 0. */
static sy_rt_v3 latlong_eval_uv(const sy_rt_texture_data *tex, float intensity, float u, float v)
{
    float c[4];
    sy_rt_texture_sample(tex, u, v, c);
    sy_rt_v3 r = v3_scale(v3(c[0], c[1], c[2]), intensity);
    if (!(isfinite(r.x) && isfinite(r.y) && isfinite(r.z))) return v3(0.0f, 0.0f, 0.0f);
    return v3(sy_rt_maxf(r.x, 0.0f), sy_rt_maxf(r.y, 0.0f), sy_rt_maxf(r.z, 0.0f));
}

static sy_rt_v3 latlong_eval(const sy_rt_texture_data *tex, float intensity, sy_rt_v3 d)
{
    float u, v;
    sy_rt_latlong_uv(d, &u, &v);
    return latlong_eval_uv(tex, intensity, u, v);
}

void sy_rt_env_get(const sy_rt_device *dev, sy_rt_env *env)
{
    memset(env, 0, sizeof *env);
    const sy_rt_texture_data *t = dev->env_dist ? sy_rt_pool_get(&dev->textures, dev->env_texture.id) : NULL;
    if (t && dev->env_intensity > 0.0f) {
        env->mode = 2;
        env->tex = t;
        env->intensity = dev->env_intensity;
        env->dist = dev->env_dist;
        env->filter = dev->env_filter;
        env->irradiance = PI_F * dev->env_dist->mean_luminance * dev->env_intensity;
        if (t->width == 1u && t->height == 1u) {
            /* A 1x1 texture reads its one texel whatever the direction: the four bilinear taps are
             * the same texel, so a + (b - a) fx is a exactly (and NaN for a non-finite texel, as
             * any lookup gives); one lookup here spares every ray its atan2 and acos. */
            env->constant = true;
            env->constant_radiance = latlong_eval(t, env->intensity, v3(0.0f, 0.0f, -1.0f));
        }
    }
}

sy_rt_v3 sy_rt_env_eval(const sy_rt_env *env, sy_rt_v3 d)
{
    if (env->mode != 2) return v3(0.0f, 0.0f, 0.0f);
    if (env->constant) return env->constant_radiance;
    return latlong_eval(env->tex, env->intensity, d);
}

sy_rt_v3 sy_rt_env_eval_uv(const sy_rt_env *env, float u, float v)
{
    if (env->mode != 2) return v3(0.0f, 0.0f, 0.0f);
    if (env->constant) return env->constant_radiance;
    return latlong_eval_uv(env->tex, env->intensity, u, v);
}

float sy_rt_background_eval(const sy_rt_device *dev, const sy_rt_v3 *d, sy_rt_v3 *rgb)
{
    const sy_rt_background *bg = &dev->background;
    *rgb = v3(0.0f, 0.0f, 0.0f);
    if (bg->mode == SY_RT_BACKGROUND_COLOR) {
        *rgb = v3_load(bg->color);
        return 1.0f;
    }
    if (bg->mode == SY_RT_BACKGROUND_TEXTURE) {
        const sy_rt_texture_data *t = sy_rt_pool_get(&dev->textures, bg->texture.id);
        if (t) *rgb = latlong_eval(t, bg->intensity, v3_normalize(*d));
        return 1.0f;
    }
    return 0.0f;
}

/* the solid-angle pdf of sy_rt_env_sample's direction d, of lat-long coordinates u, v (not read
 * for a 1x1 distribution) */
static float env_pdf_uv(const sy_rt_env_dist *e, sy_rt_v3 d, float u, float v)
{
    uint32_t x = 0u, y = 0u; /* a 1x1 distribution has one texel */
    if (e->width > 1u || e->height > 1u) {
        x = (uint32_t)(u * (float)e->width);
        y = (uint32_t)(v * (float)e->height);
        if (x >= e->width) x = e->width - 1u;
        if (y >= e->height) y = e->height - 1u;
    }
    float st = sy_rt_sin_of_cos(d.y); /* sin(theta) of d itself: the density in u, v is uniform */
    if (!(st > 0.0f)) return 0.0f;
    /* texel solid angle = (2 pi / w) (pi / h) sin(theta) */
    return e->texel_pdf[(size_t)y * e->width + x] * (float)e->width * (float)e->height / (2.0f * PI_F * PI_F * st);
}

float sy_rt_env_pdf(const sy_rt_env *env, sy_rt_v3 d)
{
    if (env->mode != 2) return 0.0f;
    const sy_rt_env_dist *e = env->dist;
    float u = 0.0f, v = 0.0f; /* a 1x1 distribution has one texel: no need for the direction's u, v */
    if (e->width > 1u || e->height > 1u) sy_rt_latlong_uv(d, &u, &v);
    return env_pdf_uv(e, d, u, v);
}

sy_rt_v3 sy_rt_env_eval_pdf(const sy_rt_env *env, sy_rt_v3 d, float *pdf)
{
    if (env->mode != 2) return *pdf = 0.0f, v3(0.0f, 0.0f, 0.0f);
    if (env->constant) return *pdf = sy_rt_env_pdf(env, d), env->constant_radiance;
    float u, v;
    sy_rt_latlong_uv(d, &u, &v);
    *pdf = env_pdf_uv(env->dist, d, u, v);
    return latlong_eval_uv(env->tex, env->intensity, u, v);
}

float sy_rt_env_sample(const sy_rt_env *env, float u1, float u2, sy_rt_v3 *d, sy_rt_v3 *radiance)
{
    if (env->mode != 2) return 0.0f;
    const sy_rt_env_dist *e = env->dist;
    uint32_t y = sy_rt_cdf_find(e->marginal, e->guide_marginal, e->height, u2);
    const float *row = e->conditional + (size_t)y * (e->width + 1u);
    uint32_t x = sy_rt_cdf_find(row, e->guide_conditional + (size_t)y * e->width, e->width, u1);
    float dy = e->marginal[y + 1u] - e->marginal[y], dx = row[x + 1u] - row[x];
    float fy = dy > 0.0f ? (u2 - e->marginal[y]) / dy : 0.5f, fx = dx > 0.0f ? (u1 - row[x]) / dx : 0.5f;
    float u = ((float)x + sy_rt_clampf(fx, 0.0f, 1.0f)) / (float)e->width;
    float v = ((float)y + sy_rt_clampf(fy, 0.0f, 1.0f)) / (float)e->height;
    float st;
    sy_rt_v3 dir = sy_rt_latlong_dir(u, v, &st);
    if (!(st > 0.0f)) return 0.0f;
    *d = dir;
    *radiance = sy_rt_env_eval_uv(env, u, v); /* at u, v itself: no round trip through dir */
    return e->texel_pdf[(size_t)y * e->width + x] * (float)e->width * (float)e->height / (2.0f * PI_F * PI_F * st);
}

bool sy_rt_punctual_incident(const sy_rt_punctual *l, sy_rt_v3 p, sy_rt_v3 *wi, sy_rt_v3 *e, float *tmax)
{
    if (l->type == SY_RT_LIGHT_DIRECTIONAL) {
        *wi = v3_scale(l->direction, -1.0f);
        *e = l->radiant;
        *tmax = INFINITY;
        return true;
    }
    sy_rt_v3 to = v3_sub(l->position, p);
    float d2 = v3_dot(to, to);
    if (!(d2 > 0.0f)) return false;
    float d = sqrtf(d2);
    *wi = v3_scale(to, 1.0f / d);
    float att = 1.0f / d2;
    if (l->range > 0.0f) {
        float x = d / l->range, w = sy_rt_clampf(1.0f - x * x * x * x, 0.0f, 1.0f);
        att *= w * w;
    }
    if (l->type == SY_RT_LIGHT_SPOT) {
        float a = sy_rt_clampf(-v3_dot(l->direction, *wi) * l->cone_scale + l->cone_offset, 0.0f, 1.0f);
        att *= a * a;
    }
    if (!(att > 0.0f)) return false;
    *e = v3_scale(l->radiant, att);
    *tmax = d - sy_rt_ray_eps(p);
    return true;
}

/* >>light tree glue */
static double lt_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

bool sy_rt_light_tree_wanted(const sy_rt_device *dev, sy_rt_light_tree_mode mode)
{
    uint64_t n = (uint64_t)dev->area_count + dev->punctual_count;
    if (n == 0 || mode == SY_RT_LIGHT_TREE_OFF) return false;
    return mode == SY_RT_LIGHT_TREE_ON || n >= SY_RT_LIGHT_TREE_AUTO_MIN;
}

const struct sy_rt_lighttree *sy_rt_light_tree_get(const sy_rt_device *dev, sy_rt_light_tree_mode mode)
{
    return dev->light_tree && !dev->light_tree_dirty && sy_rt_light_tree_wanted(dev, mode) ? dev->light_tree : NULL;
}

size_t sy_rt_light_tree_bytes(const sy_rt_device *dev) { return dev->light_tree ? dev->light_tree->bytes : 0u; }

void sy_rt_light_tree_free(sy_rt_device *dev)
{
    if (dev->light_tree) sy_rt_lighttree_free(dev->light_tree);
    free(dev->light_tree);
    dev->light_tree = NULL;
}

/* Whether textured emitter triangle a reads only black texels of its emissive texture: it emits
 * nothing, and the tree leaves it out (DamagedHelmet's whole mesh carries its emissive map, black
 * but for a few lamps: 525 of its 15,452 triangles stay, the render 0.88x the time at the same
 * error). */
static bool area_dark(const sy_rt_device *dev, const sy_rt_area_tri *a)
{
    if (!a->textured) return false;
    const sy_rt_texture_ref *ref = &sy_rt_material_lookup(dev, a->inst->material)->desc.emissive_texture;
    sy_rt_texture_data *tex = sy_rt_pool_get(&dev->textures, ref->texture.id);
    const sy_rt_mesh_data *m = a->inst->mesh;
    if (!tex) return false;
    const uint32_t *ix = m->indices + 3u * a->prim;
    float uv[3][2];
    for (int c = 0; c < 3; ++c) {
        float sets[2][2] = {{0.0f, 0.0f}, {0.0f, 0.0f}}; /* a missing set reads (0, 0), as sy_rt_surface_emission */
        for (int s = 0; s < 2; ++s)
            if (m->uv[s]) sets[s][0] = m->uv[s][2u * ix[c]], sets[s][1] = m->uv[s][2u * ix[c] + 1u];
        sy_rt_texture_ref_uv(ref, (const float(*)[2])sets, uv[c]);
    }
    return sy_rt_texture_region_zero(tex, (const float(*)[2])uv);
}

/* The tree's record of area triangle a and of punctual light l. */
static void area_record(const sy_rt_device *dev, const sy_rt_area_tri *a, sy_rt_lt_light *o)
{
    memset(o, 0, sizeof *o);
    o->dark = area_dark(dev, a);
    sy_rt_v3 p1 = v3_add(a->p0, a->e1), p2 = v3_add(a->p0, a->e2);
    o->b.lo[0] = fminf(a->p0.x, fminf(p1.x, p2.x)), o->b.hi[0] = fmaxf(a->p0.x, fmaxf(p1.x, p2.x));
    o->b.lo[1] = fminf(a->p0.y, fminf(p1.y, p2.y)), o->b.hi[1] = fmaxf(a->p0.y, fmaxf(p1.y, p2.y));
    o->b.lo[2] = fminf(a->p0.z, fminf(p1.z, p2.z)), o->b.hi[2] = fmaxf(a->p0.z, fmaxf(p1.z, p2.z));
    o->b.axis[0] = a->normal.x, o->b.axis[1] = a->normal.y, o->b.axis[2] = a->normal.z;
    o->b.theta_o = a->double_sided ? PI_F : 0.0f;
    o->b.theta_e = 0.5f * PI_F;
    float lum = v3_luminance(a->emission);
    if (!(lum > 0.0f)) lum = fmaxf(a->emission.x, fmaxf(a->emission.y, a->emission.z));
    o->b.power = lum * a->area;
}

/* Up to this many point and spot lights stand beside the tree's root, each weighed by its own
 * bounds at every pick (their cost: one importance each), not mixed into the triangles' nodes:
 * LightsPunctualLamp (five lamps among its lamp's glowing triangles), 256 spp, 24 seeds: mean
 * relMSE 0.025 -> 0.018, worst 0.165 -> 0.035 (docs/BACKENDS.md "Many lights"). More go into
 * the tree (sy bench lights' 10^3). */
#define LT_TOP_PUNCTUAL_MAX 8u

static void punctual_record(const sy_rt_punctual *l, bool few, sy_rt_lt_light *o)
{
    memset(o, 0, sizeof *o);
    o->top = few && l->type != SY_RT_LIGHT_DIRECTIONAL;
    float lum = v3_luminance(l->radiant);
    if (!(lum > 0.0f)) lum = fmaxf(l->radiant.x, fmaxf(l->radiant.y, l->radiant.z));
    o->b.power = lum;
    o->b.lo[0] = o->b.hi[0] = l->position.x;
    o->b.lo[1] = o->b.hi[1] = l->position.y;
    o->b.lo[2] = o->b.hi[2] = l->position.z;
    o->b.axis[0] = l->direction.x, o->b.axis[1] = l->direction.y, o->b.axis[2] = l->direction.z;
    if (l->type == SY_RT_LIGHT_DIRECTIONAL) {
        o->distant = true;
    } else if (l->type == SY_RT_LIGHT_SPOT) { /* attenuation > 0 inside the outer cone: cos > -offset / scale */
        o->b.theta_o = acosf(sy_rt_clampf(-l->cone_offset / l->cone_scale, -1.0f, 1.0f)) + 1e-3f;
        o->b.theta_e = 0.0f;
        if (o->b.theta_o >= PI_F) o->b.theta_o = PI_F, o->b.theta_e = 0.5f * PI_F;
    } else {
        o->b.axis[0] = 0.0f, o->b.axis[1] = 0.0f, o->b.axis[2] = 1.0f;
        o->b.theta_o = PI_F;
        o->b.theta_e = 0.5f * PI_F;
    }
}

sy_rt_result sy_rt_light_tree_ensure(sy_rt_device *dev, sy_rt_light_tree_mode mode)
{
    if (!sy_rt_light_tree_wanted(dev, mode) || (dev->light_tree && !dev->light_tree_dirty)) return SY_RT_OK;
    uint64_t n64 = (uint64_t)dev->area_count + dev->punctual_count;
    if (n64 > UINT32_MAX - 1u) return sy_rt_fail(dev, SY_RT_ERROR_LIMIT, "light tree: %llu lights exceed the limit",
                                                 (unsigned long long)n64);
    uint32_t n = (uint32_t)n64;
    sy_rt_lt_light *rec = malloc((size_t)n * sizeof *rec);
    if (!rec) return sy_rt_fail(dev, SY_RT_ERROR_OUT_OF_MEMORY, "light tree: out of memory (%u lights)", n);
    double t0 = lt_seconds();
    for (uint32_t i = 0; i < dev->area_count; ++i) area_record(dev, &dev->area[i], &rec[i]);
    bool few = dev->punctual_count <= LT_TOP_PUNCTUAL_MAX;
    for (uint32_t i = 0; i < dev->punctual_count; ++i)
        punctual_record(&dev->punctual[i], few, &rec[dev->area_count + i]);
    uint32_t changed = 0;
    if (dev->light_tree && sy_rt_lighttree_refit(dev->light_tree, rec, n, &changed)) {
        dev->light_tree_refit_seconds = lt_seconds() - t0;
        dev->light_tree_refit_changed = changed;
        dev->light_tree_refits++;
        dev->light_tree_dirty = false;
        free(rec);
        return SY_RT_OK;
    }
    sy_rt_light_tree_free(dev);
    sy_rt_lighttree *t = calloc(1, sizeof *t);
    if (!t) {
        free(rec);
        return sy_rt_fail(dev, SY_RT_ERROR_OUT_OF_MEMORY, "light tree: out of memory (%u lights)", n);
    }
    size_t left = 0;
    if (dev->max_memory > 0) {
        int64_t l = dev->max_memory - atomic_load(&((sy_rt_device *)dev)->embree_bytes);
        left = l > 0 ? (size_t)l : 1u;
    }
    bool oom = false;
    bool ok = sy_rt_lighttree_build(t, rec, n, left, &oom);
    free(rec);
    if (!ok) {
        size_t need = t->bytes;
        sy_rt_lighttree_free(t);
        free(t);
        if (oom) return sy_rt_fail(dev, SY_RT_ERROR_OUT_OF_MEMORY, "light tree: out of memory (%u lights)", n);
        return sy_rt_fail(dev, SY_RT_ERROR_OUT_OF_MEMORY,
                          "light tree: %u lights need %.1f MB, more than the %.1f MB left of the device's memory limit",
                          n, (double)need / 1048576.0, (double)left / 1048576.0);
    }
    dev->light_tree_build_seconds = lt_seconds() - t0;
    dev->light_tree_builds++;
    if (t->skipped) {
        char msg[200];
        uint32_t i = t->first_skipped;
        if (i < dev->area_count)
            snprintf(msg, sizeof msg, "light tree: emissive triangle %u of instance 0x%08x has no usable power: left out",
                     dev->area[i].prim, dev->area[i].inst->handle);
        else
            snprintf(msg, sizeof msg, "light tree: light 0x%08x has zero, negative or non-finite power: left out",
                     dev->punctual[i - dev->area_count].handle);
        dev->light_warnings += t->skipped;
        snprintf(dev->light_warning, sizeof dev->light_warning, "%s%s", msg, t->skipped > 1u ? " (and others)" : "");
    }
    dev->light_tree = t;
    dev->light_tree_dirty = false;
    return SY_RT_OK;
}
