/* sy_rt_punctual.c — punctual lights (point, spot, directional) of the ray-tracing back-end: create /
 * update / destroy with their values checked, and the array the integrators read, rebuilt at
 * sy_rt_commit (sy_rt_punctual_rebuild). Calls only sy_rt_base. */
#include "sy_rt_scene.h"

#include <stddef.h>
#include <stdlib.h>

#define FAIL(r, ...) sy_rt_fail(dev, (r), __VA_ARGS__)

static sy_rt_result validate_light(const sy_rt_device *dev, const sy_rt_light_desc *d)
{
    if (d->type != SY_RT_LIGHT_POINT && d->type != SY_RT_LIGHT_SPOT && d->type != SY_RT_LIGHT_DIRECTIONAL)
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "light: unknown type %d", (int)d->type);
    const float *vals[] = {d->color, d->position, d->direction};
    const char *names[] = {"color", "position", "direction"};
    for (int a = 0; a < 3; ++a)
        for (int k = 0; k < 3; ++k)
            if (!isfinite(vals[a][k]))
                return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "light: %s[%d] is not finite", names[a], k);
    for (int k = 0; k < 3; ++k)
        if (d->color[k] < 0.0f) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "light: color[%d] is negative", k);
    for (int k = 0; k < 3; ++k)
        if (fabsf(d->position[k]) > SY_RT_COORD_MAX)
            return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "light: position[%d] = %g is beyond SY_RT_COORD_MAX (%g)", k,
                        (double)d->position[k], (double)SY_RT_COORD_MAX);
    if (!isfinite(d->intensity) || d->intensity < 0.0f)
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "light: intensity %g is not a finite non-negative value", (double)d->intensity);
    if (!isfinite(d->range) || d->range < 0.0f)
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "light: range %g is not finite and >= 0", (double)d->range);
    if (d->type != SY_RT_LIGHT_POINT && v3_is_zero(v3_load(d->direction)))
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "light: direction is zero");
    if (d->type == SY_RT_LIGHT_SPOT &&
        !(d->inner_cone_angle >= 0.0f && d->inner_cone_angle <= d->outer_cone_angle && d->outer_cone_angle <= 1.5707964f))
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "light: spot cone angles need 0 <= inner (%g) <= outer (%g) <= pi/2",
                    (double)d->inner_cone_angle, (double)d->outer_cone_angle);
    return SY_RT_OK;
}

static sy_rt_result light_validate(const sy_rt_device *dev, const void *desc)
{
    return validate_light(dev, desc);
}

/* A new, changed or destroyed light: the punctual array is rebuilt at the next commit. */
static void light_mark(sy_rt_device *dev, const void *item, bool gone)
{
    (void)item, (void)gone;
    dev->dirty = dev->punctual_dirty = true;
}

static void light_set(sy_rt_device *dev, void *item, const void *desc, bool fresh)
{
    ((sy_rt_light_data *)item)->desc = *(const sy_rt_light_desc *)desc;
    if (!fresh) light_mark(dev, item, false);
}

static const sy_rt_kind light_kind = {"light", offsetof(sy_rt_device, lights), sizeof(sy_rt_light_data), light_validate,
                                      light_set, light_mark};

SY_RT_KIND_CALLS(light, light_kind)

sy_rt_result sy_rt_punctual_rebuild(sy_rt_device *dev)
{
    free(dev->punctual);
    dev->punctual = NULL;
    dev->punctual_count = 0;
    dev->light_tree_dirty = true;
    uint32_t n = dev->lights.live;
    if (n == 0) return SY_RT_OK;
    dev->punctual = malloc((size_t)n * sizeof *dev->punctual);
    if (!dev->punctual) return FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "commit: cannot allocate %u lights", n);
    for (uint32_t i = 0; i < dev->lights.count; ++i) {
        const sy_rt_light_data *l = dev->lights.items[i];
        if (!l) continue;
        const sy_rt_light_desc *d = &l->desc;
        sy_rt_punctual *p = &dev->punctual[dev->punctual_count++];
        p->handle = (dev->lights.gens[i] << SY_RT_INDEX_BITS) | (i + 1u);
        p->type = d->type;
        p->radiant = v3_scale(v3_load(d->color), d->intensity);
        p->position = v3_load(d->position);
        p->direction = v3_normalize(v3_load(d->direction));
        p->range = d->range;
        /* KHR_lights_punctual reference falloff between the outer and inner cone. */
        float cos_outer = cosf(d->outer_cone_angle), cos_inner = cosf(d->inner_cone_angle);
        p->cone_scale = 1.0f / fmaxf(0.001f, cos_inner - cos_outer);
        p->cone_offset = -cos_outer * p->cone_scale;
    }
    return SY_RT_OK;
}
