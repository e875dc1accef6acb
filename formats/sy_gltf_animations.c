/* sy_gltf_animations.c — glTF animations into core animation objects (sy_objects.h; played by
 * sy_anim.h): every animation of the file becomes one sy_animation (file order, its name), with the
 * channels that target a loaded node's translation, rotation, scale or weights and the samplers they
 * use. KHR_animation_pointer channels whose pointer names a node's TRS or weights, a material's
 * baseColorFactor, emissiveFactor, metallicFactor or roughnessFactor, a KHR_lights_punctual light's
 * color or intensity, or a camera's perspective yfov map onto the same paths (sy_anim_path); any
 * other pointer is dropped with a warning naming the channel and the pointer. Sampler accessors are read like every other accessor (sy_gltf_accessors.c, after the one
 * validation pass), their counts checked and charged to the file's budget before anything is read.
 * A bad sampler or channel is dropped with a warning naming animations[i].samplers[j] /
 * .channels[k]; the rest of the clip stays. */
#include "sy_gltf_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A KHR_animation_pointer target: the JSON pointer's object index and the path it maps onto;
 * false (with *why) when the pointer names nothing the clock drives or nothing in this file. */
static bool pointer_target(const loader *L, const char *ptr, uint32_t *index, int32_t *path, const char **why)
{
    static const struct {
        const char *prefix, *suffix;
        int32_t path;
    } maps[] = {
        {"/nodes/", "/translation", SY_ANIM_TRANSLATION},
        {"/nodes/", "/rotation", SY_ANIM_ROTATION},
        {"/nodes/", "/scale", SY_ANIM_SCALE},
        {"/nodes/", "/weights", SY_ANIM_WEIGHTS},
        {"/materials/", "/pbrMetallicRoughness/baseColorFactor", SY_ANIM_BASE_COLOR},
        {"/materials/", "/pbrMetallicRoughness/metallicFactor", SY_ANIM_METALLIC},
        {"/materials/", "/pbrMetallicRoughness/roughnessFactor", SY_ANIM_ROUGHNESS},
        {"/materials/", "/emissiveFactor", SY_ANIM_EMISSIVE},
        {"/extensions/KHR_lights_punctual/lights/", "/color", SY_ANIM_LIGHT_COLOR},
        {"/extensions/KHR_lights_punctual/lights/", "/intensity", SY_ANIM_LIGHT_INTENSITY},
        {"/cameras/", "/perspective/yfov", SY_ANIM_CAMERA_YFOV},
    };
    *why = "is not one the scene clock drives (node TRS and weights, material base colour, emissive, metallic and "
           "roughness factors, light colour and intensity, camera yfov)";
    for (size_t i = 0; i < sizeof maps / sizeof maps[0]; i++) {
        size_t np = strlen(maps[i].prefix);
        if (strncmp(ptr, maps[i].prefix, np) != 0) continue;
        const char *p = ptr + np;
        if (*p < '0' || *p > '9' || (*p == '0' && p[1] >= '0' && p[1] <= '9')) continue;
        uint64_t v = 0;
        while (*p >= '0' && *p <= '9' && v <= UINT32_MAX) v = v * 10 + (uint64_t)(*p++ - '0');
        if (strcmp(p, maps[i].suffix) != 0) continue;
        const sy_gltf_doc *d = L->doc;
        uint32_t t = sy_anim_path_target((uint32_t)maps[i].path);
        size_t count = t == SY_TYPE_NODE ? d->node_count : t == SY_TYPE_MATERIAL ? d->material_count
                       : t == SY_TYPE_LIGHT  ? d->light_count : d->camera_count;
        if (v >= count) {
            *why = "names an object the file does not have";
            return false;
        }
        *index = (uint32_t)v;
        *path = maps[i].path;
        return true;
    }
    return false;
}

/* One read sampler: times and values (malloc()ed), components per value, or dropped (keys 0). */
typedef struct anim_sampler {
    float *times, *values;
    uint32_t keys, components, interpolation;
    int32_t used_as; /* index in the clip's sampler list, -1 unused */
    bool tried, ok;
} anim_sampler;

/* Reads and checks sampler j of animation ai for a channel of `path` (components from the path;
 * weights: from the counts). Local problems: a warning and *s->ok false. */
static sy_result read_sampler(loader *L, size_t ai, size_t j, int32_t path, anim_sampler *s)
{
    const sy_gltf_doc *d = L->doc;
    const sy_gltf_shim_anim_sampler *in = &d->animations[ai].samplers[j];
    sy_result r = SY_OK;
    s->tried = true;
    s->ok = false;
    if (in->interpolation < 0 || in->interpolation >= SY_INTERP_COUNT) {
        gltf_warn(L, "animations[%zu].samplers[%zu]: unknown interpolation; dropped", ai, j);
        return SY_OK;
    }
    if (in->input < 0 || (size_t)in->input >= d->accessor_count || in->output < 0 || (size_t)in->output >= d->accessor_count) {
        gltf_warn(L, "animations[%zu].samplers[%zu]: input %d or output %d is not an accessor; dropped", ai, j,
                  (int)in->input, (int)in->output);
        return SY_OK;
    }
    const sy_gltf_shim_accessor *ia = &d->accessors[in->input], *oa = &d->accessors[in->output];
    size_t per = in->interpolation == SY_INTERP_CUBICSPLINE ? 3 : 1;
    if (ia->components != 1 || ia->is_matrix || ia->count == 0 || ia->count > SY_ANIM_MAX_KEYS) {
        gltf_warn(L, "animations[%zu].samplers[%zu]: input accessor %d is not 1 to %u SCALAR times; dropped", ai, j,
                  (int)in->input, SY_ANIM_MAX_KEYS);
        return SY_OK;
    }
    size_t comps;
    if (path == SY_ANIM_WEIGHTS) { /* scalar outputs: keys x targets (x 3) */
        size_t per_key = ia->count * per;
        comps = oa->components == 1 && !oa->is_matrix && oa->count % per_key == 0 ? oa->count / per_key : 0;
        if (comps == 0 || comps > SY_ANIM_MAX_COMPONENTS) {
            gltf_warn(L, "animations[%zu].samplers[%zu]: %zu weight outputs for %zu keys%s is not 1 to %u targets; dropped",
                      ai, j, oa->count, ia->count, per == 3 ? " x 3 (CUBICSPLINE)" : "", SY_ANIM_MAX_COMPONENTS);
            return SY_OK;
        }
    } else {
        comps = sy_anim_path_components((uint32_t)path);
        if ((size_t)oa->components != comps || oa->is_matrix || oa->count != ia->count * per) {
            gltf_warn(L,
                      "animations[%zu].samplers[%zu]: output accessor %d has %zu elements of %d components, the %s "
                      "path needs %zu x %zu%s; dropped",
                      ai, j, (int)in->output, oa->count, (int)oa->components, sy_anim_path_name((uint32_t)path),
                      ia->count * per, comps, per == 3 ? " (CUBICSPLINE: 3 per key)" : "");
            return SY_OK;
        }
    }
    /* the bytes it becomes: the file's budget before reading */
    if ((r = sy_budget_charge(&L->budget, (uint64_t)ia->count + (uint64_t)ia->count * per * comps, sizeof(float),
                              &L->err, "animations[%zu].samplers[%zu]", ai, j)))
        return r;
    if ((r = gltf_read_floats(L, (size_t)in->input, 1, &s->times))) return r;
    if ((r = gltf_read_floats(L, (size_t)in->output, path == SY_ANIM_WEIGHTS ? 1 : comps, &s->values))) return r;
    for (size_t k = 0; k < ia->count; k++)
        if (!isfinite(s->times[k]) || (k && !(s->times[k] > s->times[k - 1]))) {
            gltf_warn(L, "animations[%zu].samplers[%zu]: input time %zu (%g) is %s; dropped", ai, j, k,
                      (double)s->times[k], isfinite(s->times[k]) ? "not after the one before (times must increase strictly)" : "not finite");
            return SY_OK;
        }
    size_t nv = ia->count * per * comps;
    for (size_t k = 0; k < nv; k++) {
        bool bad = !isfinite(s->values[k]);
        if (!bad && (path == SY_ANIM_TRANSLATION || path == SY_ANIM_SCALE)) bad = !sy_coords_in_range(&s->values[k], 1);
        if (bad) {
            gltf_warn(L,
                      "animations[%zu].samplers[%zu]: output element %zu component %zu (%g) is not finite or beyond the "
                      "coordinate range; dropped",
                      ai, j, k / comps, k % comps, (double)s->values[k]);
            return SY_OK;
        }
    }
    if (path == SY_ANIM_ROTATION)
        for (size_t k = 0; k < ia->count; k++) {
            const float *q = s->values + (k * per + (per == 3 ? 1 : 0)) * 4;
            if (!(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3] > 1e-12f)) {
                gltf_warn(L, "animations[%zu].samplers[%zu]: key %zu is the zero quaternion; dropped", ai, j, k);
                return SY_OK;
            }
        }
    s->keys = (uint32_t)ia->count;
    s->components = (uint32_t)comps;
    s->interpolation = (uint32_t)in->interpolation;
    s->ok = true;
    return SY_OK;
}

/* Paths whose samplers read alike (components and value checks): one sampler may serve several. */
static int32_t sampler_kind(int32_t p)
{
    if (p == SY_ANIM_SCALE) return SY_ANIM_TRANSLATION;
    return p <= SY_ANIM_WEIGHTS ? p : 100 + (int32_t)sy_anim_path_components((uint32_t)p);
}

/* Animation ai into one sy_animation (L->info->animations[ai]). */
static sy_result create_animation(loader *L, size_t ai)
{
    const sy_gltf_doc *d = L->doc;
    const sy_gltf_shim_animation *an = &d->animations[ai];
    sy_result r = SY_OK;
    char where[48];
    snprintf(where, sizeof where, "animations[%zu]", ai);
    sy_animation h;
    if ((r = gltf_create(L, SY_TYPE_ANIMATION, gltf_nonempty(an->name), where, &h.id))) return r;
    L->info->animations[ai] = h;
    L->info->animation_count = (uint32_t)ai + 1;
    anim_sampler *sm = gltf_xcalloc(L, an->sampler_count + 1, sizeof *sm, &r);
    int32_t *sampler_path = sm ? gltf_xcalloc(L, an->sampler_count + 1, sizeof(int32_t), &r) : NULL;
    sy_anim_sampler_desc *descs = sampler_path ? gltf_xcalloc(L, an->sampler_count + 1, sizeof *descs, &r) : NULL;
    sy_anim_channel *chans = descs ? gltf_xcalloc(L, an->channel_count + 1, sizeof *chans, &r) : NULL;
    if (!chans) goto done;
    uint32_t nd = 0, nc = 0;
    for (size_t k = 0; k < an->channel_count; k++) {
        sy_gltf_shim_anim_channel cv = an->channels[k];
        const sy_gltf_shim_anim_channel *c = &cv;
        uint32_t target = 0; /* the material, light or camera of a pointer */
        if (c->path == 4) { /* KHR_animation_pointer */
            uint32_t index = 0;
            const char *why = "has no pointer";
            if (!c->pointer || !pointer_target(L, c->pointer, &index, &cv.path, &why)) {
                if (!L->pointers_dropped++) /* once: the rest are counted (gltf_create_animations) */
                    gltf_warn(L, "animations[%zu].channels[%zu]: KHR_animation_pointer '%s' %s; dropped", ai, k,
                              c->pointer ? c->pointer : "", why);
                continue;
            }
            uint32_t t = sy_anim_path_target((uint32_t)cv.path);
            if (t == SY_TYPE_NODE) cv.node = (int32_t)index;
            else target = t == SY_TYPE_MATERIAL ? L->materials[index].id : t == SY_TYPE_LIGHT ? L->lights[index].id
                                                                                             : L->cameras[index].id;
            if (t != SY_TYPE_NODE && !target) {
                gltf_warn(L, "animations[%zu].channels[%zu]: KHR_animation_pointer '%s' names an object that was not "
                          "loaded; dropped", ai, k, c->pointer);
                continue;
            }
        } else if (c->path < 0) {
            gltf_warn(L, "animations[%zu].channels[%zu]: unsupported target path; dropped", ai, k);
            continue;
        }
        if (!target && (c->node < 0 || (size_t)c->node >= d->node_count || !L->nodes[c->node].id)) {
            gltf_warn(L, "animations[%zu].channels[%zu]: target node %d %s; dropped", ai, k, (int)c->node,
                      c->node < 0 || (size_t)c->node >= d->node_count ? "does not exist" : "is not in the loaded scene");
            continue;
        }
        if (!target && c->path != SY_ANIM_WEIGHTS && d->nodes[c->node].matrix_count == 16) {
            gltf_warn(L, "animations[%zu].channels[%zu]: nodes[%d] has a matrix, which glTF forbids animating; dropped", ai, k,
                      (int)c->node);
            continue;
        }
        if (c->sampler < 0 || (size_t)c->sampler >= an->sampler_count) {
            gltf_warn(L, "animations[%zu].channels[%zu]: sampler %d does not exist; dropped", ai, k, (int)c->sampler);
            continue;
        }
        anim_sampler *s = &sm[c->sampler];
        if (s->tried && sampler_kind(sampler_path[c->sampler]) != sampler_kind(c->path)) {
            gltf_warn(L, "animations[%zu].channels[%zu]: samplers[%d] already drives a channel of the %s path; dropped", ai, k,
                      (int)c->sampler, sy_anim_path_name((uint32_t)sampler_path[c->sampler]));
            continue;
        }
        if (!s->tried) {
            sampler_path[c->sampler] = c->path;
            if ((r = read_sampler(L, ai, (size_t)c->sampler, c->path, s))) goto done;
            if (s->ok) {
                s->used_as = (int32_t)nd;
                descs[nd++] = (sy_anim_sampler_desc){s->interpolation, s->components, s->keys, s->times, s->values};
            }
        }
        if (!s->ok) {
            gltf_warn(L, "animations[%zu].channels[%zu]: its sampler %d was dropped; dropped", ai, k, (int)c->sampler);
            continue;
        }
        chans[nc++] = (sy_anim_channel){target ? target : L->nodes[c->node].id, (uint32_t)c->path, (uint32_t)s->used_as};
    }
    sy_error e = {0};
    if (nc && sy_animation_set_clip(L->scene, h, descs, nd, chans, nc, &e) != SY_OK)
        gltf_warn(L, "animations[%zu]: refused (%s); the clip stays empty", ai, e.message); /* checked above: not expected */
done:
    if (sm)
        for (size_t j = 0; j < an->sampler_count; j++) free(sm[j].times), free(sm[j].values);
    free(sm);
    free(sampler_path);
    free(descs);
    free(chans);
    return r;
}

sy_result gltf_create_animations(loader *L)
{
    const sy_gltf_doc *d = L->doc;
    sy_result r = SY_OK;
    if (!d->animation_count) return SY_OK;
    if (!(L->info->animations = gltf_xcalloc(L, d->animation_count, sizeof(sy_animation), &r))) return r;
    for (size_t i = 0; i < d->animation_count; i++)
        if ((r = create_animation(L, i))) return r;
    if (L->pointers_dropped > 1)
        gltf_warn(L, "animations: %u more KHR_animation_pointer channels dropped (pointers the scene clock does not drive)",
                  L->pointers_dropped - 1);
    return SY_OK;
}
