/* sy_anim.c — the scene clock (sy_anim.h): glTF sampler evaluation (STEP, LINEAR with slerp,
 * CUBICSPLINE), sy_scene_set_time writing the results through the node setters, clip lookup and
 * the play state. Uses the public scene API only. */
#include "sy_anim.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* >>sampling */

/* The key interval of t in times[0 .. n-1] (n >= 1, increasing): *k with times[k] <= t <
 * times[k+1] and the fraction *u in [0, 1); clamped: *k = 0, *u = 0 before the first key and
 * *k = n - 1, *u = 0 at or after the last. Binary search: O(log n). */
static void find_key(const float *times, uint32_t n, double t, uint32_t *k, double *u)
{
    *u = 0.0;
    if (n < 2 || !(t > (double)times[0])) { /* also NaN: the first key */
        *k = 0;
        return;
    }
    if (t >= (double)times[n - 1]) {
        *k = n - 1;
        return;
    }
    uint32_t lo = 0, hi = n - 1; /* times[lo] < t < times[hi] or t == times[lo] */
    while (hi - lo > 1) {
        uint32_t mid = lo + (hi - lo) / 2;
        if ((double)times[mid] <= t) lo = mid;
        else hi = mid;
    }
    *k = lo;
    double td = (double)times[lo + 1] - (double)times[lo];
    *u = td > 0.0 ? (t - (double)times[lo]) / td : 0.0;
    if (!(*u >= 0.0)) *u = 0.0;
    if (*u > 1.0) *u = 1.0;
}

static void normalize_quat(float q[4])
{
    double l = sqrt((double)q[0] * q[0] + (double)q[1] * q[1] + (double)q[2] * q[2] + (double)q[3] * q[3]);
    if (!(l > 1e-20) || !isfinite(l)) {
        q[0] = q[1] = q[2] = 0.0f;
        q[3] = 1.0f;
        return;
    }
    for (int i = 0; i < 4; ++i) q[i] = (float)(q[i] / l);
}

/* glTF 2.0 appendix C, spherical linear interpolation: a = acos(|d|), s = sign(d),
 * q = sin(a (1 - u)) / sin(a) q0 + s sin(a u) / sin(a) q1 (linear when a is tiny), normalised. */
static void slerp(const float *q0, const float *q1, double u, float *out)
{
    double d = 0.0;
    for (int i = 0; i < 4; ++i) d += (double)q0[i] * q1[i];
    double sgn = d < 0.0 ? -1.0 : 1.0, ad = fabs(d);
    double w0, w1;
    if (ad > 0.9999995) { /* nearly the same rotation: sin(a) ~ 0 */
        w0 = 1.0 - u;
        w1 = u;
    } else {
        double a = acos(ad), sa = sin(a);
        w0 = sin(a * (1.0 - u)) / sa;
        w1 = sin(a * u) / sa;
    }
    for (int i = 0; i < 4; ++i) out[i] = (float)(w0 * q0[i] + sgn * w1 * q1[i]);
    normalize_quat(out);
}

sy_result sy_animation_sample(const sy_animation_data *d, uint32_t sampler, bool quaternion, double t, float *out,
                              uint32_t out_count, sy_error *err)
{
    uint32_t ns;
    const sy_anim_sampler *sm = sy_animation_samplers(d, &ns);
    if (sampler >= ns) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "animation: sampler %u of %u", sampler, ns);
    const sy_anim_sampler *a = &sm[sampler];
    size_t nt = d->times ? sy_blob_size(d->times) / sizeof(float) : 0;
    size_t nv = d->values ? sy_blob_size(d->values) / sizeof(float) : 0;
    uint32_t c = a->components, per = a->interpolation == SY_INTERP_CUBICSPLINE ? 3u : 1u;
    /* the bounds again, O(1): evaluation never reads outside the blobs whatever they hold */
    if (a->key_count == 0 || c == 0 || (uint64_t)a->times_offset + a->key_count > nt ||
        (uint64_t)a->values_offset + (uint64_t)a->key_count * c * per > nv || a->interpolation >= SY_INTERP_COUNT ||
        (quaternion && c != 4))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "animation: sampler %u does not fit its blobs", sampler);
    if (out_count < c)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "animation: sampler %u has %u components, room for %u", sampler,
                            c, out_count);
    const float *times = (const float *)sy_blob_data(d->times) + a->times_offset;
    const float *v = (const float *)sy_blob_data(d->values) + a->values_offset;
    uint32_t k;
    double u;
    find_key(times, a->key_count, t, &k, &u);
    /* value j of key i: v[(i * per + (cubic ? 1 : 0)) * c + j]; in-tangent +0, out-tangent +2 */
    const float *vk = v + ((size_t)k * per + (per == 3 ? 1u : 0u)) * c;
    bool between = k + 1 < a->key_count && u > 0.0;
    if (!between || a->interpolation == SY_INTERP_STEP) {
        memcpy(out, vk, sizeof(float) * c);
        if (quaternion) normalize_quat(out);
        return SY_OK;
    }
    const float *vk1 = v + ((size_t)(k + 1) * per + (per == 3 ? 1u : 0u)) * c;
    if (a->interpolation == SY_INTERP_LINEAR) {
        if (quaternion) slerp(vk, vk1, u, out);
        else
            for (uint32_t j = 0; j < c; ++j) out[j] = (float)((1.0 - u) * vk[j] + u * vk1[j]);
        return SY_OK;
    }
    /* CUBICSPLINE */
    double td = (double)times[k + 1] - (double)times[k];
    const float *bk = v + ((size_t)k * 3u + 2u) * c;        /* out-tangent of key k */
    const float *ak1 = v + ((size_t)(k + 1) * 3u + 0u) * c; /* in-tangent of key k + 1 */
    double s = u, s2 = s * s, s3 = s2 * s;
    double h00 = 2 * s3 - 3 * s2 + 1, h10 = s3 - 2 * s2 + s, h01 = -2 * s3 + 3 * s2, h11 = s3 - s2;
    for (uint32_t j = 0; j < c; ++j)
        out[j] = (float)(h00 * vk[j] + td * h10 * bk[j] + h01 * vk1[j] + td * h11 * ak1[j]);
    if (quaternion) normalize_quat(out);
    return SY_OK;
}

/* >>the clock into node fields */
/* Counts channel c of animation id (data d) as failed with r (e its reason); the first failure of
 * the call goes into *first and err, naming the animation and the channel. */
static void channel_failed(sy_anim_stats *st, sy_result *first, sy_result r, sy_error *err, uint32_t id,
                           const sy_animation_data *d, uint32_t c, const sy_error *e)
{
    st->failed++;
    if (*first != SY_OK) return;
    *first = r;
    sy_error_set(err, r, "animation %#x (%s) channel %u: %s", id, d->name ? d->name : "unnamed", c, e->message);
}

/* Channel ci (a material, light or camera path) at time t into its object's field with the object's
 * setter, which checks the value like any edit. SY_ERR_NOT_FOUND: the object is gone. */
static sy_result apply_property(sy_scene *s, const sy_animation_data *d, sy_anim_channel ci, double t, sy_error *e)
{
    float v[4];
    sy_result r = sy_animation_sample(d, ci.sampler, false, t, v, 4, e);
    if (r != SY_OK) return r;
    uint32_t type = sy_anim_path_target(ci.path);
    if (type == SY_TYPE_MATERIAL) {
        const sy_material_data *m = sy_object_get(s, SY_TYPE_MATERIAL, ci.node);
        if (!m) return SY_ERR_NOT_FOUND;
        float c[4];
        memcpy(c, m->base_color, sizeof c);
        switch (ci.path) {
        case SY_ANIM_BASE_COLOR: return sy_object_set_field(s, type, ci.node, SY_MATERIAL_BASE_COLOR, v, e);
        case SY_ANIM_DIFFUSE:
            memcpy(c, v, 3 * sizeof(float));
            return sy_object_set_field(s, type, ci.node, SY_MATERIAL_BASE_COLOR, c, e);
        case SY_ANIM_OPACITY:
            c[3] = v[0];
            return sy_object_set_field(s, type, ci.node, SY_MATERIAL_BASE_COLOR, c, e);
        case SY_ANIM_EMISSIVE: return sy_object_set_field(s, type, ci.node, SY_MATERIAL_EMISSIVE, v, e);
        case SY_ANIM_METALLIC: return sy_object_set_field(s, type, ci.node, SY_MATERIAL_METALLIC, v, e);
        default: return sy_object_set_field(s, type, ci.node, SY_MATERIAL_ROUGHNESS, v, e);
        }
    }
    if (!sy_object_get(s, type, ci.node)) return SY_ERR_NOT_FOUND;
    if (type == SY_TYPE_LIGHT)
        return sy_object_set_field(s, type, ci.node, ci.path == SY_ANIM_LIGHT_COLOR ? SY_LIGHT_COLOR : SY_LIGHT_INTENSITY, v, e);
    return sy_object_set_field(s, type, ci.node, SY_CAMERA_YFOV, v, e);
}

static sy_result apply_clip(sy_scene *s, uint32_t id, double t, sy_anim_stats *st, sy_result first, sy_error *err)
{
    const sy_animation_data *d = sy_object_get(s, SY_TYPE_ANIMATION, id);
    if (d->loop) { /* a looping clip plays scene time t at t mod its period */
        float lo, hi;
        sy_animation_time_range(d, &lo, &hi);
        double period = d->cycle > 0.0f ? (double)d->cycle : (double)hi - (double)lo;
        if (period > 0.0) {
            double f = fmod(t - lo, period);
            t = lo + (f < 0.0 ? f + period : f);
        }
    }
    uint32_t nc;
    const sy_anim_channel *ch = sy_animation_channels(d, &nc);
    st->clips++;
    for (uint32_t c = 0; c < nc; ++c) {
        const sy_anim_channel ci = ch[c];
        if (ci.path >= SY_ANIM_PATH_COUNT) continue; /* refused by the setters; never stored */
        if (sy_anim_path_target(ci.path) != SY_TYPE_NODE) { /* a material, light or camera field */
            sy_error e = {0};
            sy_result r = apply_property(s, d, ci, t, &e);
            if (r == SY_ERR_NOT_FOUND) st->skipped_stale++;
            else if (r != SY_OK) channel_failed(st, &first, r, err, id, d, c, &e);
            else st->properties++;
            continue;
        }
        const sy_node_data *nd = sy_node_get(s, (sy_node){ci.node});
        if (!nd) {
            st->skipped_stale++;
            continue;
        }
        if (ci.path == SY_ANIM_WEIGHTS) { /* one component per morph target, into the node's weights */
            uint32_t ns;
            const sy_anim_sampler *sm = sy_animation_samplers(d, &ns);
            float w[SY_ANIM_MAX_COMPONENTS];
            uint32_t nw = ci.sampler < ns ? sm[ci.sampler].components : 0u;
            sy_error e = {0};
            sy_result r = nw && nw <= SY_ANIM_MAX_COMPONENTS
                              ? sy_animation_sample(d, ci.sampler, false, t, w, SY_ANIM_MAX_COMPONENTS, &e)
                              : sy_error_set(&e, SY_ERR_INVALID_ARGUMENT, "sampler %u has no weights", ci.sampler);
            if (r == SY_OK) r = sy_node_set_weights(s, (sy_node){ci.node}, w, nw, &e);
            if (r != SY_OK) {
                channel_failed(st, &first, r, err, id, d, c, &e);
                continue;
            }
            st->weights++;
            continue;
        }
        if (nd->transform.mode != SY_TRANSFORM_TRS) {
            st->skipped_matrix++;
            continue;
        }
        sy_transform tr = nd->transform;
        float *dst = ci.path == SY_ANIM_TRANSLATION ? tr.translation : ci.path == SY_ANIM_ROTATION ? tr.rotation : tr.scale;
        sy_error e = {0};
        sy_result r = sy_animation_sample(d, ci.sampler, ci.path == SY_ANIM_ROTATION, t, dst,
                                          ci.path == SY_ANIM_ROTATION ? 4u : 3u, &e);
        if (r == SY_OK) r = sy_object_set_field(s, SY_TYPE_NODE, ci.node, SY_NODE_TRANSFORM, &tr, &e);
        if (r != SY_OK) {
            channel_failed(st, &first, r, err, id, d, c, &e);
            continue;
        }
        st->channels++;
    }
    return first;
}

sy_result sy_scene_set_time_ex(sy_scene *s, sy_animation clip, double seconds, sy_anim_stats *stats, sy_error *err)
{
    sy_anim_stats local;
    if (!stats) stats = &local;
    memset(stats, 0, sizeof *stats);
    if (!s) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "set time: no scene");
    if (!isfinite(seconds)) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "set time: %g seconds is not finite", seconds);
    if (clip.id) {
        if (!sy_animation_get(s, clip))
            return sy_error_set(err, SY_ERR_INVALID_HANDLE, "set time: stale animation handle %#x", clip.id);
        return apply_clip(s, clip.id, seconds, stats, SY_OK, err);
    }
    sy_result first = SY_OK;
    for (uint32_t id = sy_scene_next(s, SY_TYPE_ANIMATION, 0); id; id = sy_scene_next(s, SY_TYPE_ANIMATION, id))
        first = apply_clip(s, id, seconds, stats, first, err);
    return first;
}

sy_result sy_scene_set_time(sy_scene *s, sy_animation clip, double seconds, sy_error *err)
{
    return sy_scene_set_time_ex(s, clip, seconds, NULL, err);
}

sy_result sy_scene_time_range(const sy_scene *s, sy_animation clip, double *start_out, double *end_out, sy_error *err)
{
    double lo = 0.0, hi = 0.0;
    bool any = false;
    if (clip.id && !sy_animation_get(s, clip)) {
        if (start_out) *start_out = 0.0;
        if (end_out) *end_out = 0.0;
        return sy_error_set(err, SY_ERR_INVALID_HANDLE, "time range: stale animation handle %#x", clip.id);
    }
    for (uint32_t id = clip.id ? clip.id : sy_scene_next(s, SY_TYPE_ANIMATION, 0); id;
         id = clip.id ? 0 : sy_scene_next(s, SY_TYPE_ANIMATION, id)) {
        const sy_animation_data *d = sy_object_get(s, SY_TYPE_ANIMATION, id);
        uint32_t ns;
        if (!sy_animation_samplers(d, &ns)) continue;
        float a, b;
        sy_animation_time_range(d, &a, &b);
        if (!any || a < lo) lo = a;
        if (!any || b > hi) hi = b;
        any = true;
    }
    if (start_out) *start_out = lo;
    if (end_out) *end_out = hi;
    return SY_OK;
}

sy_result sy_animation_find(const sy_scene *s, const char *selector, sy_animation *out, sy_error *err)
{
    out->id = 0;
    if (!selector || !selector[0]) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "animation: empty selector");
    bool numeric = true;
    for (const char *p = selector; *p && numeric; ++p) numeric = *p >= '0' && *p <= '9';
    unsigned long want = 0;
    if (numeric) {
        errno = 0;
        want = strtoul(selector, NULL, 10);
        if (errno) numeric = false;
    }
    char list[256] = "";
    uint32_t i = 0;
    for (uint32_t id = sy_scene_next(s, SY_TYPE_ANIMATION, 0); id; id = sy_scene_next(s, SY_TYPE_ANIMATION, id), ++i) {
        const sy_animation_data *d = sy_object_get(s, SY_TYPE_ANIMATION, id);
        if ((numeric && want == i) || (!numeric && d->name && strcmp(d->name, selector) == 0)) {
            out->id = id;
            return SY_OK;
        }
        size_t used = strlen(list);
        if (used < sizeof list - 1)
            snprintf(list + used, sizeof list - used, "%s%u:%s", i ? ", " : "", i, d->name ? d->name : "(unnamed)");
    }
    return sy_error_set(err, SY_ERR_NOT_FOUND, "no animation %s '%s' (available: %s)", numeric ? "at index" : "named",
                        selector, i ? list : "none");
}

/* >>play state */
sy_clock sy_clock_make(double start, double end)
{
    if (!isfinite(start)) start = 0.0;
    if (!isfinite(end) || end < start) end = start;
    return (sy_clock){.time = start, .start = start, .end = end, .speed = 1.0, .playing = true, .loop = true};
}

double sy_clock_advance(sy_clock *c, double dt)
{
    if (!c->playing || !isfinite(dt) || !isfinite(c->speed)) return c->time;
    double t = c->time + dt * c->speed, len = c->end - c->start;
    if (t >= c->start && t <= c->end) {
        c->time = t;
    } else if (c->loop && len > 0.0) {
        double f = fmod(t - c->start, len);
        if (f < 0.0) f += len;
        c->time = c->start + f;
    } else {
        c->time = t < c->start ? c->start : c->end;
        if (!c->loop) c->playing = false;
    }
    return c->time;
}

/* >>shutter (motion blur) */

static bool shutter_number(const char *b, const char *e, double *out)
{
    char buf[64];
    size_t n = (size_t)(e - b);
    if (n == 0 || n >= sizeof buf) return false;
    memcpy(buf, b, n);
    buf[n] = 0;
    char *end = NULL;
    errno = 0;
    double v = strtod(buf, &end);
    if (end == buf || *end || errno == ERANGE || !isfinite(v)) return false;
    *out = v;
    return true;
}

sy_result sy_shutter_parse(const char *text, sy_shutter *out, sy_error *err)
{
    if (!text || !out) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "shutter: no text");
    const char *comma = strchr(text, ',');
    double open = 0.0, close = 0.0;
    bool ok = comma ? shutter_number(text, comma, &open) && shutter_number(comma + 1, comma + 1 + strlen(comma + 1), &close)
                    : shutter_number(text, text + strlen(text), &close);
    if (!ok)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "shutter '%s': want OPEN,CLOSE or S, finite seconds", text);
    if (!(open >= 0.0) || !(close >= 0.0) || open > SY_SHUTTER_MAX || close > SY_SHUTTER_MAX)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "shutter '%s': times must lie in [0, %g] seconds", text,
                            SY_SHUTTER_MAX);
    if (open > close)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "shutter '%s': it opens (%g s) after it closes (%g s)", text,
                            open, close);
    out->open = open;
    out->close = close;
    return SY_OK;
}

bool sy_shutter_blurs(const sy_shutter *s)
{
    return s && s->samples > 1 && s->close > s->open;
}

double sy_shutter_time(const sy_shutter *s, double frame_time, uint32_t i)
{
    uint32_t n = s->samples ? s->samples : 1;
    return frame_time + s->open + ((double)i + 0.5) / (double)n * (s->close - s->open);
}
