/* sy_scene_validate.c — validation in one place: every field of every object type is checked here
 * before a setter, a replica apply or a loader stores it (ranges, references, sizes, cycles). */
#include "sy_scene_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* >>validation (one place for every field of every type) */
static bool finite_n(const float *v, int n)
{
    for (int i = 0; i < n; ++i)
        if (!isfinite(v[i])) return false;
    return true;
}

static bool ref_ok(const sy_scene *s, uint32_t type, uint32_t id)
{
    return id == 0 || s->applying || sy_sc_lookup(s, type, id) != NULL;
}

static sy_result check_texref(const sy_scene *s, const sy_texture_ref *t, const char *what, sy_error *err)
{
    if (!ref_ok(s, SY_TYPE_TEXTURE, t->texture.id))
        return sy_error_set(err, SY_ERR_INVALID_HANDLE, "material %s: stale texture handle %#x", what, t->texture.id);
    if (t->texcoord > 1)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "material %s: texcoord set %u (0 or 1 supported)", what,
                            t->texcoord);
    if (!isfinite(t->scale) || !finite_n(t->offset, 2) || !isfinite(t->rotation) || !finite_n(t->uv_scale, 2))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "material %s: non-finite texture transform", what);
    return SY_OK;
}

static sy_result check_blob_elems(const sy_blob *b, size_t elem, uint32_t count, const char *what, uint32_t prim,
                                  sy_error *err)
{
    if (!b) return SY_OK;
    size_t need;
    if (!sy_size_mul(elem, count, &need) || sy_blob_size(b) != need)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                            "mesh primitive %u: %s holds %zu bytes, expected %u vertices x %zu bytes", prim, what,
                            sy_blob_size(b), count, elem);
    return SY_OK;
}

/* An X3D gradient: counts within SY_GRADIENT_MAX, finite non-negative colours, angles increasing
 * within (0, pi] (sky) and (0, pi/2] (ground), one angle fewer than colours. */
static sy_result check_gradient(const sy_gradient *g, sy_error *err)
{
    if (g->sky_count > SY_GRADIENT_MAX || g->ground_count > SY_GRADIENT_MAX)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "background: gradient has more than %u colours", SY_GRADIENT_MAX);
    if (g->ground_count && !g->sky_count)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "background: ground gradient without a sky colour");
    for (int part = 0; part < 2; ++part) {
        uint32_t n = part ? g->ground_count : g->sky_count;
        const float(*c)[3] = part ? g->ground_color : g->sky_color;
        const float *a = part ? g->ground_angle : g->sky_angle;
        float lim = part ? 1.5707964f : 3.1415927f, prev = 0.0f;
        const char *what = part ? "ground" : "sky";
        for (uint32_t i = 0; i < n; ++i)
            for (int k = 0; k < 3; ++k)
                if (!isfinite(c[i][k]) || c[i][k] < 0.0f)
                    return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "background: %s colour %u is not finite and >= 0",
                                        what, i);
        for (uint32_t i = 0; i + 1 < n; ++i) {
            if (!isfinite(a[i]) || a[i] <= prev || a[i] > lim)
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                                    "background: %s angle %u = %g must increase within (0, %g]", what, i, (double)a[i],
                                    (double)lim);
            prev = a[i];
        }
    }
    return SY_OK;
}

uint32_t sy_anim_path_target(uint32_t path)
{
    if (path <= SY_ANIM_WEIGHTS) return SY_TYPE_NODE;
    if (path <= SY_ANIM_ROUGHNESS) return SY_TYPE_MATERIAL;
    if (path <= SY_ANIM_LIGHT_INTENSITY) return SY_TYPE_LIGHT;
    return path == SY_ANIM_CAMERA_YFOV ? SY_TYPE_CAMERA : 0u;
}

uint32_t sy_anim_path_components(uint32_t path)
{
    static const uint8_t comps[SY_ANIM_PATH_COUNT] = {3, 4, 3, 0, 4, 3, 1, 3, 1, 1, 3, 1, 1};
    return path < SY_ANIM_PATH_COUNT ? comps[path] : 0u;
}

const char *sy_anim_path_name(uint32_t path)
{
    static const char *const names[SY_ANIM_PATH_COUNT] = {
        "translation", "rotation",  "scale",       "weights",         "base_color",      "diffuse",    "opacity",
        "emissive",    "metallic", "roughness", "light_color", "light_intensity", "camera_yfov"};
    return path < SY_ANIM_PATH_COUNT ? names[path] : "unknown";
}

static const char *type_word(uint32_t t)
{
    return t == SY_TYPE_NODE ? "node" : t == SY_TYPE_MATERIAL ? "material" : t == SY_TYPE_LIGHT ? "light" : "camera";
}

/* An enumeration field (a uint32_t at v) of at most max; else "WHAT VALUE". */
static sy_result check_enum(const void *v, uint32_t max, const char *what, sy_error *err)
{
    uint32_t x = *(const uint32_t *)v;
    return x <= max ? SY_OK : sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s %u", what, x);
}

/* An animation blob of whole records of `elem` bytes, at most `max` of them (NULL = none). */
static sy_result check_records(const sy_blob *b, size_t elem, uint32_t max, uint32_t id, const char *what,
                                const void **records, size_t *count, sy_error *err)
{
    *records = NULL, *count = 0;
    if (!b) return SY_OK;
    size_t n = sy_blob_size(b);
    if (n % elem != 0)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "animation %#x: %s of %zu bytes is not whole %zu-byte records", id,
                            what, n, elem);
    if (n / elem > max)
        return sy_error_set(err, SY_ERR_LIMIT, "animation %#x: %zu %s (at most %u)", id, n / elem, what, max);
    *records = sy_blob_data(b), *count = n / elem;
    return SY_OK;
}

static sy_result check_animation_field(const sy_scene *s, uint32_t id, uint32_t f, const void *v, sy_error *err)
{
    if (f == SY_ANIMATION_CYCLE) {
        float c = *(const float *)v;
        if (!(c >= 0.0f && c <= SY_ANIM_MAX_CYCLE))
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "animation %#x: period %g s (0 to %g)", id, (double)c,
                                (double)SY_ANIM_MAX_CYCLE);
        return SY_OK;
    }
    if (f == SY_ANIMATION_LOOP) {
        uint32_t l = *(const uint32_t *)v;
        if (l > 1) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "animation %#x: loop %u (0 or 1)", id, l);
        return SY_OK;
    }
    const sy_blob *b = f == SY_ANIMATION_NAME ? NULL : *(sy_blob *const *)v;
    const void *rec;
    size_t n;
    sy_result r;
    switch (f) {
    case SY_ANIMATION_SAMPLERS: {
        if ((r = check_records(b, sizeof(sy_anim_sampler), SY_ANIM_MAX_SAMPLERS, id, "samplers", &rec, &n, err))) return r;
        const sy_anim_sampler *sm = rec;
        for (uint32_t i = 0; i < n; ++i) {
            if (sm[i].interpolation >= SY_INTERP_COUNT)
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "animation %#x sampler %u: unknown interpolation %u", id,
                                    i, sm[i].interpolation);
            if (sm[i].components < 1 || sm[i].components > SY_ANIM_MAX_COMPONENTS)
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "animation %#x sampler %u: %u components (1 to %u)", id,
                                    i, sm[i].components, SY_ANIM_MAX_COMPONENTS);
            if (sm[i].key_count < 1 || sm[i].key_count > SY_ANIM_MAX_KEYS)
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "animation %#x sampler %u: %u keys (1 to %u)", id, i,
                                    sm[i].key_count, SY_ANIM_MAX_KEYS);
        }
        return SY_OK;
    }
    case SY_ANIMATION_CHANNELS: {
        if ((r = check_records(b, sizeof(sy_anim_channel), SY_ANIM_MAX_CHANNELS, id, "channels", &rec, &n, err))) return r;
        const sy_anim_channel *ch = rec;
        for (uint32_t i = 0; i < n; ++i) {
            if (ch[i].path >= SY_ANIM_PATH_COUNT)
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "animation %#x channel %u: unknown path %u", id, i,
                                    ch[i].path);
            uint32_t tt = sy_anim_path_target(ch[i].path);
            if (ch[i].node == 0 || !ref_ok(s, tt, ch[i].node))
                return sy_error_set(err, SY_ERR_INVALID_HANDLE,
                                    "animation %#x channel %u: target %s %#x of its %s path is not a live %s", id, i,
                                    type_word(tt), ch[i].node, sy_anim_path_name(ch[i].path), type_word(tt));
        }
        return SY_OK;
    }
    case SY_ANIMATION_TIMES:
    case SY_ANIMATION_VALUES: {
        const char *what = f == SY_ANIMATION_TIMES ? "times" : "values";
        if ((r = check_records(b, sizeof(float), UINT32_MAX, id, what, &rec, &n, err))) return r;
        const float *x = rec;
        for (size_t i = 0; i < n; ++i)
            if (!isfinite(x[i]))
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "animation %#x: %s[%zu] is not finite", id, what, i);
        return SY_OK;
    }
    default: return SY_OK;
    }
}

/* The rules between an animation's blobs (sy_objects.h): runs inside their blobs, times strictly
 * increasing, components by path, values in range, channels naming samplers. O(keys + channels). */
static sy_result check_animation(const sy_animation_data *d, uint32_t id, sy_error *err)
{
    uint32_t ns, nc;
    const sy_anim_sampler *sm = sy_animation_samplers(d, &ns);
    const sy_anim_channel *ch = sy_animation_channels(d, &nc);
    size_t nt = d->times ? sy_blob_size(d->times) / sizeof(float) : 0;
    size_t nv = d->values ? sy_blob_size(d->values) / sizeof(float) : 0;
    const float *t = nt ? sy_blob_data(d->times) : NULL, *v = nv ? sy_blob_data(d->values) : NULL;
    for (uint32_t i = 0; i < ns; ++i) {
        uint64_t per = sm[i].interpolation == SY_INTERP_CUBICSPLINE ? 3u : 1u;
        uint64_t need = (uint64_t)sm[i].key_count * sm[i].components * per;
        if ((uint64_t)sm[i].times_offset + sm[i].key_count > nt)
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                                "animation %#x sampler %u: %u key times from %u run past the %zu times", id, i,
                                sm[i].key_count, sm[i].times_offset, nt);
        if ((uint64_t)sm[i].values_offset + need > nv)
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                                "animation %#x sampler %u: %llu output values from %u (%u keys x %u components%s) run "
                                "past the %zu values",
                                id, i, (unsigned long long)need, sm[i].values_offset, sm[i].key_count,
                                sm[i].components, per == 3 ? " x 3 for CUBICSPLINE" : "", nv);
        const float *ti = t + sm[i].times_offset;
        for (uint32_t k = 1; k < sm[i].key_count; ++k)
            if (!(ti[k] > ti[k - 1]))
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                                    "animation %#x sampler %u: key time %u (%g) is not after key time %u (%g) (times "
                                    "must increase strictly)",
                                    id, i, k, (double)ti[k], k - 1, (double)ti[k - 1]);
    }
    /* the values of each sampler are checked once per kind of path that uses it (bit 1: translation
     * or scale, bit 2: rotation), so a clip of many channels sharing samplers costs its keys once */
    uint8_t *checked = ns ? calloc(ns, 1) : NULL;
    if (ns && !checked) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "animation %#x: out of memory", id);
    sy_result r = SY_OK;
    for (uint32_t c = 0; c < nc && r == SY_OK; ++c) {
        if (ch[c].sampler >= ns) {
            r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "animation %#x channel %u: sampler %u of %u", id, c,
                             ch[c].sampler, ns);
            break;
        }
        const sy_anim_sampler *a = &sm[ch[c].sampler];
        uint32_t want = sy_anim_path_components(ch[c].path);
        if (ch[c].path != SY_ANIM_WEIGHTS && a->components != want) {
            r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                             "animation %#x channel %u: sampler %u has %u components, the %s path takes %u", id, c,
                             ch[c].sampler, a->components, sy_anim_path_name(ch[c].path), want);
            break;
        }
        /* values in range: node translation and scale (bit 1), rotation (bit 2); the other paths'
         * values are checked by their object's setter when the clock sets them */
        uint8_t bit = ch[c].path == SY_ANIM_ROTATION                                   ? 2u
                      : ch[c].path == SY_ANIM_TRANSLATION || ch[c].path == SY_ANIM_SCALE ? 1u
                                                                                       : 0u;
        if (!bit || (checked[ch[c].sampler] & bit)) continue;
        checked[ch[c].sampler] |= bit;
        uint32_t per = a->interpolation == SY_INTERP_CUBICSPLINE ? 3u : 1u;
        const float *x = v + a->values_offset;
        for (uint32_t k = 0; k < a->key_count && r == SY_OK; ++k) {
            const float *key = x + ((size_t)k * per + (per == 3 ? 1u : 0u)) * a->components; /* the key's value */
            if (bit == 1) {
                for (uint32_t j = 0; j < per * 3u; ++j) /* every value and tangent of the key */
                    if (!sy_coords_in_range(x + ((size_t)k * per) * 3u + j, 1)) {
                        r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                                         "animation %#x channel %u: sampler %u key %u is beyond the coordinate range (%g)",
                                         id, c, ch[c].sampler, k, (double)SY_COORD_MAX);
                        break;
                    }
            } else if (!(key[0] * key[0] + key[1] * key[1] + key[2] * key[2] + key[3] * key[3] > 1e-12f)) {
                r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "animation %#x channel %u: sampler %u key %u is the zero quaternion",
                                 id, c, ch[c].sampler, k);
            }
        }
    }
    free(checked);
    return r;
}

/* Finite floats in a blob (size a multiple of 4). */
static bool blob_finite(const sy_blob *b)
{
    const float *f = sy_blob_data(b);
    size_t n = sy_blob_size(b) / 4;
    for (size_t k = 0; k < n; ++k)
        if (!isfinite(f[k])) return false;
    return true;
}

/* Skin attributes and morph targets of a primitive of nv vertices (sy_objects.h, "Skins and morph
 * targets"): joints and weights together, 1 to SY_SKIN_MAX_INFLUENCES per vertex, weights finite;
 * target blobs whole targets, the same count in each, at most SY_MORPH_MAX_TARGETS, finite deltas
 * within SY_COORD_MAX. */
static sy_result check_deform(const sy_primitive *p, uint32_t nv, uint32_t i, sy_error *err)
{
    if (!p->joints != !p->weights)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "mesh primitive %u: joints without weights or weights without joints", i);
    if (p->joints) {
        size_t js = sy_blob_size(p->joints);
        if (nv == 0 || js % (4u * (size_t)nv) != 0 || js / (4u * (size_t)nv) < 1 ||
            js / (4u * (size_t)nv) > SY_SKIN_MAX_INFLUENCES || sy_blob_size(p->weights) != js)
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                                "mesh primitive %u: joints (%zu bytes) and weights (%zu bytes) are not 1 to %u influences "
                                "x %u vertices x 4 bytes",
                                i, js, sy_blob_size(p->weights), SY_SKIN_MAX_INFLUENCES, nv);
        if (!blob_finite(p->weights))
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "mesh primitive %u: a skin weight is not finite", i);
    }
    const sy_blob *tb[4] = {p->target_positions, p->target_normals, p->target_tangents, p->target_texcoords0};
    const char *tn[4] = {"target_positions", "target_normals", "target_tangents", "target_texcoords0"};
    if (p->target_texcoords0 && !p->texcoords0)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "mesh primitive %u: target_texcoords0 without texcoords0", i);
    size_t targets = 0;
    for (int k = 0; k < 4; ++k) {
        if (!tb[k]) continue;
        size_t sz = sy_blob_size(tb[k]), bytes = k == 3 ? 8u : 12u, per = bytes * (size_t)nv;
        if (nv == 0 || sz % per != 0 || sz / per == 0 || sz / per > SY_MORPH_MAX_TARGETS || (targets && sz / per != targets))
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                                "mesh primitive %u: %s holds %zu bytes, not 1 to %u whole targets of %u vertices x %zu "
                                "bytes (the same count in every target blob)",
                                i, tn[k], sz, SY_MORPH_MAX_TARGETS, nv, bytes);
        targets = sz / per;
        const float *f = sy_blob_data(tb[k]);
        for (size_t e = 0; e < sz / 4; ++e)
            if (!(fabsf(f[e]) <= SY_COORD_MAX))
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                                    "mesh primitive %u: %s value %zu (%g) is not finite or beyond the coordinate range", i,
                                    tn[k], e, (double)f[e]);
    }
    return SY_OK;
}

/* Morph weights: a float blob, at most SY_MORPH_MAX_TARGETS, finite. */
static sy_result check_weights(const sy_blob *b, const char *what, sy_error *err)
{
    if (!b) return SY_OK;
    if (sy_blob_size(b) % 4 != 0 || sy_blob_size(b) / 4 > SY_MORPH_MAX_TARGETS)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: morph weights of %zu bytes (whole floats, at most %u)", what,
                            sy_blob_size(b), SY_MORPH_MAX_TARGETS);
    if (!blob_finite(b)) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: a morph weight is not finite", what);
    return SY_OK;
}

static sy_result check_primitive(const sy_scene *s, const sy_primitive *p, uint32_t i, sy_error *err)
{
    if (!p->positions) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "mesh primitive %u: no positions", i);
    size_t psize = sy_blob_size(p->positions);
    if (psize % 12 != 0 || psize / 12 > UINT32_MAX)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "mesh primitive %u: positions size %zu not a multiple of 12",
                            i, psize);
    uint32_t nv = (uint32_t)(psize / 12);
    const float *pos = sy_blob_data(p->positions);
    for (uint32_t v = 0; v < nv * 3; ++v)
        if (!(fabsf(pos[v]) <= SY_COORD_MAX))
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                                "mesh primitive %u: vertex %u has a position %s (%g; at most %g in size)", i, v / 3,
                                isfinite(pos[v]) ? "beyond the coordinate range" : "that is not finite",
                                (double)pos[v], (double)SY_COORD_MAX);
    sy_result r;
    if ((r = check_blob_elems(p->normals, 12, nv, "normals", i, err)) ||
        (r = check_blob_elems(p->tangents, 16, nv, "tangents", i, err)) ||
        (r = check_blob_elems(p->texcoords0, 8, nv, "texcoords0", i, err)) ||
        (r = check_blob_elems(p->texcoords1, 8, nv, "texcoords1", i, err)) ||
        (r = check_blob_elems(p->colors, 16, nv, "colors", i, err)))
        return r;
    if ((r = check_deform(p, nv, i, err))) return r;
    if (p->topology >= SY_TOPOLOGY_COUNT)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "mesh primitive %u: unknown topology %u", i, p->topology);
    if (!isfinite(p->width) || p->width < 0.0f)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "mesh primitive %u: stroke width %g is not finite and >= 0", i,
                            (double)p->width);
    /* elements: triangles take index triples, lines pairs, points any count */
    uint32_t per = p->topology == SY_TOPOLOGY_TRIANGLES ? 3u : p->topology == SY_TOPOLOGY_LINES ? 2u : 1u;
    const char *whole = per == 3 ? "whole triangles" : "whole line segments (index pairs)";
    if (p->indices) {
        size_t isize = sy_blob_size(p->indices);
        if (isize % (4u * per) != 0)
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "mesh primitive %u: index data %zu bytes is not %s", i,
                                isize, per == 1 ? "whole uint32 indices" : whole);
        const uint32_t *idx = sy_blob_data(p->indices);
        for (size_t k = 0; k < isize / 4; ++k)
            if (idx[k] >= nv)
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                                    "mesh primitive %u: index %zu = %u is past the vertex count %u", i, k, idx[k], nv);
    } else if (nv % per != 0) {
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "mesh primitive %u: %u vertices without indices is not %s", i,
                            nv, whole);
    }
    if (!ref_ok(s, SY_TYPE_MATERIAL, p->material.id))
        return sy_error_set(err, SY_ERR_INVALID_HANDLE, "mesh primitive %u: stale material handle", i);
    return SY_OK;
}

sy_result sy_sc_validate_field(sy_scene *s, uint32_t type, uint32_t id, uint32_t f, const void *v, sy_error *err)
{
    switch (type) {
    case SY_TYPE_NODE:
        switch (f) {
        case SY_NODE_TRANSFORM: {
            const sy_transform *t = v;
            if (t->mode > SY_TRANSFORM_MATRIX)
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "node: unknown transform mode %u", t->mode);
            if (!finite_n(t->translation, 3) || !finite_n(t->rotation, 4) || !finite_n(t->scale, 3) ||
                !sy_mat4_is_finite(&t->matrix))
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "node: non-finite transform");
            /* SY_COORD_MAX (sy_math.h): translations, scales and every matrix element */
            if (!sy_coords_in_range(t->translation, 3) || !sy_coords_in_range(t->scale, 3) ||
                !sy_coords_in_range(t->matrix.m, 16))
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                                    "node: transform beyond the coordinate range (translation (%g %g %g), scale "
                                    "(%g %g %g); at most %g in size)",
                                    (double)t->matrix.m[12], (double)t->matrix.m[13], (double)t->matrix.m[14],
                                    (double)t->scale[0], (double)t->scale[1], (double)t->scale[2],
                                    (double)SY_COORD_MAX);
            return SY_OK;
        }
        case SY_NODE_CHILDREN: {
            const sy_blob *b = *(sy_blob *const *)v;
            if (!b) return SY_OK;
            if (sy_blob_size(b) % 4 != 0)
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "node: child list of %zu bytes", sy_blob_size(b));
            uint32_t n = (uint32_t)(sy_blob_size(b) / 4);
            const uint32_t *ch = sy_blob_data(b);
            for (uint32_t i = 0; i < n; ++i) {
                if (ch[i] == 0 || (!s->applying && !sy_sc_lookup(s, SY_TYPE_NODE, ch[i])))
                    return sy_error_set(err, SY_ERR_INVALID_HANDLE, "node: child %u is a stale handle %#x", i, ch[i]);
                if (ch[i] == id)
                    return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "node: child %u is the node itself", i);
            }
            /* duplicates by sorting a copy (n log n: child lists of a million instances stay cheap) */
            if (n > 1) {
                uint32_t *sorted = malloc(sizeof *sorted * n);
                if (!sorted) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "node: %u children: out of memory", n);
                memcpy(sorted, ch, sizeof *sorted * n);
                qsort(sorted, n, sizeof *sorted, sy_sc_cmp_u32);
                uint32_t dup = 0;
                for (uint32_t i = 1; i < n && !dup; ++i)
                    if (sorted[i] == sorted[i - 1]) dup = sorted[i];
                free(sorted);
                if (dup) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "node: child %#x listed twice", dup);
            }
            if (!s->applying && sy_sc_reaches(s, ch, n, id))
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                                    "node: a child is the node's ancestor (the graph would have a cycle)");
            return SY_OK;
        }
        case SY_NODE_MESH:
            return ref_ok(s, SY_TYPE_MESH, ((const sy_mesh *)v)->id)
                       ? SY_OK
                       : sy_error_set(err, SY_ERR_INVALID_HANDLE, "node: stale mesh handle");
        case SY_NODE_LIGHT:
            return ref_ok(s, SY_TYPE_LIGHT, ((const sy_light *)v)->id)
                       ? SY_OK
                       : sy_error_set(err, SY_ERR_INVALID_HANDLE, "node: stale light handle");
        case SY_NODE_CAMERA:
            return ref_ok(s, SY_TYPE_CAMERA, ((const sy_camera *)v)->id)
                       ? SY_OK
                       : sy_error_set(err, SY_ERR_INVALID_HANDLE, "node: stale camera handle");
        case SY_NODE_FLAGS:
            if (*(const uint32_t *)v & ~(uint32_t)(SY_NODE_VISIBLE | SY_NODE_STATIC | SY_NODE_ANIMATED | SY_NODE_SELECTED))
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "node: unknown flags %#x", *(const uint32_t *)v);
            return SY_OK;
        case SY_NODE_WEIGHTS: return check_weights(*(sy_blob *const *)v, "node", err);
        case SY_NODE_SKIN: {
            const sy_blob *b = *(sy_blob *const *)v;
            if (!b) return SY_OK;
            if (sy_blob_size(b) % sizeof(sy_skin_joint) != 0 || sy_blob_size(b) / sizeof(sy_skin_joint) > SY_SKIN_MAX_JOINTS)
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "node: skin of %zu bytes (whole joints of %zu bytes, at most %u)",
                                    sy_blob_size(b), sizeof(sy_skin_joint), SY_SKIN_MAX_JOINTS);
            uint32_t n = (uint32_t)(sy_blob_size(b) / sizeof(sy_skin_joint));
            const sy_skin_joint *j = sy_blob_data(b);
            for (uint32_t k = 0; k < n; ++k) {
                if (j[k].node == 0 || !ref_ok(s, SY_TYPE_NODE, j[k].node))
                    return sy_error_set(err, SY_ERR_INVALID_HANDLE, "node: skin joint %u is a stale handle %#x", k, j[k].node);
                if (!sy_mat4_is_finite(&j[k].inverse_bind) || !sy_coords_in_range(j[k].inverse_bind.m, 16))
                    return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                                        "node: skin joint %u has an inverse bind matrix that is not finite or beyond the "
                                        "coordinate range",
                                        k);
            }
            return SY_OK;
        }
        case SY_NODE_SKELETON:
            return ref_ok(s, SY_TYPE_NODE, ((const sy_node *)v)->id)
                       ? SY_OK
                       : sy_error_set(err, SY_ERR_INVALID_HANDLE, "node: stale skeleton handle");
        default: return SY_OK;
        }
    case SY_TYPE_MESH:
        if (f == SY_MESH_WEIGHTS) return check_weights(*(sy_blob *const *)v, "mesh", err);
        if (f == SY_MESH_PRIMITIVES) {
            const sy_primitive_list *l = v;
            if (l->count && !l->items) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "mesh: NULL primitives");
            for (uint32_t i = 0; i < l->count; ++i) {
                sy_result r = check_primitive(s, &l->items[i], i, err);
                if (r) return r;
            }
        }
        return SY_OK;
    case SY_TYPE_MATERIAL: {
        const sy_field_desc *fd = &sy__type_desc(type)->fields[f];
        switch (f) {
        case SY_MATERIAL_NAME: return SY_OK;
        case SY_MATERIAL_BASE_COLOR_TEXTURE:
        case SY_MATERIAL_METALLIC_ROUGHNESS_TEXTURE:
        case SY_MATERIAL_NORMAL_TEXTURE:
        case SY_MATERIAL_OCCLUSION_TEXTURE:
        case SY_MATERIAL_EMISSIVE_TEXTURE:
        case SY_MATERIAL_TRANSMISSION_TEXTURE:
        case SY_MATERIAL_SPECULAR_TEXTURE:
        case SY_MATERIAL_SPECULAR_COLOR_TEXTURE:
        case SY_MATERIAL_CLEARCOAT_TEXTURE:
        case SY_MATERIAL_CLEARCOAT_ROUGHNESS_TEXTURE:
        case SY_MATERIAL_CLEARCOAT_NORMAL_TEXTURE:
        case SY_MATERIAL_SHEEN_COLOR_TEXTURE:
        case SY_MATERIAL_SHEEN_ROUGHNESS_TEXTURE:
        case SY_MATERIAL_THICKNESS_TEXTURE:
        case SY_MATERIAL_IRIDESCENCE_TEXTURE:
        case SY_MATERIAL_IRIDESCENCE_THICKNESS_TEXTURE:
        case SY_MATERIAL_ANISOTROPY_TEXTURE: return check_texref(s, v, fd->name, err);
        case SY_MATERIAL_ANISOTROPY_ROTATION: /* an angle: any finite value */
            return isfinite(*(const float *)v)
                       ? SY_OK
                       : sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "material: anisotropy_rotation is not finite");
        case SY_MATERIAL_ALPHA_MODE:
            return *(const uint32_t *)v <= SY_ALPHA_BLEND
                       ? SY_OK
                       : sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "material: unknown alpha mode %u",
                                      *(const uint32_t *)v);
        case SY_MATERIAL_DOUBLE_SIDED:
        case SY_MATERIAL_UNLIT:
            return *(const uint32_t *)v <= 1
                       ? SY_OK
                       : sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "material: %s must be 0 or 1", fd->name);
        default: {
            const float *fv = v;
            int n = (int)(fd->size / sizeof(float));
            for (int i = 0; i < n; ++i) {
                if (!isfinite(fv[i]))
                    return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "material: %s is not finite", fd->name);
                if (fv[i] < 0.0f)
                    return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "material: %s is negative (%g)", fd->name,
                                        (double)fv[i]);
            }
            if ((f == SY_MATERIAL_IOR || f == SY_MATERIAL_IRIDESCENCE_IOR) && fv[0] < 1.0f && fv[0] != 0.0f)
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "material: %s %g below 1", fd->name, (double)fv[0]);
            return SY_OK;
        }
        }
    }
    case SY_TYPE_TEXTURE:
        if (f == SY_TEXTURE_INFO) {
            const sy_image_info *in = v;
            if (in->channels > 4 || in->format > SY_PIXEL_F32)
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "texture: %u channels, format %u", in->channels,
                                    in->format);
            /* an image with a size: every back-end refuses 0 channels, and no mediator can read pixels
             * of an unknown format (all zero = no image yet, the default) */
            if (in->width && in->height && in->channels == 0)
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "texture %#x: a %ux%u image with 0 channels (1 to 4)",
                                    id, in->width, in->height);
            if (in->width && in->height && in->format == 0)
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                                    "texture %#x: a %ux%u image without a pixel format (SY_PIXEL_U8_SRGB, _U8_LINEAR or _F32)",
                                    id, in->width, in->height);
        } else if (f == SY_TEXTURE_SAMPLER) {
            const sy_sampler *sm = v;
            if (sm->wrap_s > SY_WRAP_MIRROR || sm->wrap_t > SY_WRAP_MIRROR || sm->min_filter > SY_FILTER_NEAREST ||
                sm->mag_filter > SY_FILTER_NEAREST)
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "texture: unknown sampler mode");
        }
        return SY_OK;
    case SY_TYPE_LIGHT:
        if (f == SY_LIGHT_NAME) return SY_OK;
        if (f == SY_LIGHT_TYPE) return check_enum(v, SY_LIGHT_DIRECTIONAL, "light: unknown type", err);
        {
            const float *fv = v;
            int n = f == SY_LIGHT_COLOR ? 3 : 1;
            for (int i = 0; i < n; ++i)
                if (!isfinite(fv[i]) || fv[i] < 0.0f)
                    return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "light: %s must be finite and >= 0",
                                        sy__type_desc(type)->fields[f].name);
            if (f == SY_LIGHT_RANGE && !sy_coords_in_range(fv, 1))
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "light: range %g is beyond the coordinate range (%g)",
                                    (double)fv[0], (double)SY_COORD_MAX);
            /* KHR_lights_punctual: 0 <= inner < outer <= pi/2 (inner >= outer is read as a hard edge:
             * every back-end gets the light through the mirror, which orders them) */
            if ((f == SY_LIGHT_INNER_CONE || f == SY_LIGHT_OUTER_CONE) && fv[0] > 1.5707964f)
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "light: %s %g is beyond pi/2",
                                    sy__type_desc(type)->fields[f].name, (double)fv[0]);
        }
        return SY_OK;
    case SY_TYPE_CAMERA:
        if (f == SY_CAMERA_NAME) return SY_OK;
        if (f == SY_CAMERA_PROJECTION) return check_enum(v, SY_PROJECTION_ORTHOGRAPHIC, "camera: unknown projection", err);
        {
            float x = *(const float *)v;
            const char *fn = sy__type_desc(type)->fields[f].name;
            if (!isfinite(x) || x < 0.0f)
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "camera: %s must be finite and >= 0", fn);
            if (f == SY_CAMERA_YFOV && (x <= 0.0f || x >= 3.14159f))
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "camera: yfov %g outside (0, pi)", (double)x);
            if (f == SY_CAMERA_ZNEAR && x <= 0.0f)
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "camera: znear must be > 0");
            if ((f == SY_CAMERA_ZNEAR || f == SY_CAMERA_ZFAR || f == SY_CAMERA_XMAG || f == SY_CAMERA_YMAG) &&
                x > SY_COORD_MAX)
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "camera: %s %g is beyond the coordinate range (%g)",
                                    fn, (double)x, (double)SY_COORD_MAX);
        }
        return SY_OK;
    case SY_TYPE_BACKGROUND:
        if (f == SY_BACKGROUND_COLOR && !finite_n(v, 4))
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "background: non-finite colour");
        if (f == SY_BACKGROUND_INTENSITY && (!isfinite(*(const float *)v) || *(const float *)v < 0.0f))
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "background: intensity must be finite and >= 0");
        if (f == SY_BACKGROUND_ENVIRONMENT && !ref_ok(s, SY_TYPE_TEXTURE, ((const sy_texture *)v)->id))
            return sy_error_set(err, SY_ERR_INVALID_HANDLE, "background: stale environment texture");
        if ((f == SY_BACKGROUND_ENVIRONMENT_VISIBLE || f == SY_BACKGROUND_DEFAULT_LIGHTING) && *(const uint32_t *)v > 1)
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "background: %s must be 0 or 1",
                                sy__type_desc(type)->fields[f].name);
        if (f == SY_BACKGROUND_GRADIENT) return check_gradient(v, err);
        return SY_OK;
    case SY_TYPE_ANIMATION: return check_animation_field(s, id, f, v, err);
    default: return SY_OK;
    }
}

/* Rules between fields of one object, checked on the object as a change leaves it (after every field
 * of a whole set or of a replica's entry, so the order fields are set in does not matter). */
sy_result sy_sc_validate_object(const sy_scene *s, uint32_t type, uint32_t id, const void *data, sy_error *err)
{
    (void)s;
    if (type == SY_TYPE_ANIMATION) return check_animation(data, id, err);
    if (type == SY_TYPE_CAMERA) {
        const sy_camera_data *c = data;
        /* every back-end refuses to render a clip range whose far plane is not beyond its near one */
        if (c->zfar != 0.0f && !(c->zfar > c->znear))
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                                "camera %#x: zfar %g is not beyond znear %g (zfar is 0 = infinite, or > znear)", id,
                                (double)c->zfar, (double)c->znear);
    }
    return SY_OK;
}
