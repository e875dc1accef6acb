/* sy_rt_material.c — materials of the ray-tracing back-end: sy_rt_material_desc_init, and create /
 * update / destroy with every value and texture reference checked; a change marks what the next
 * sy_rt_commit rebuilds (area lights for emission, alpha filters for masking, shadow flags). */
#include "sy_rt_scene.h"

#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#define FAIL(r, ...) sy_rt_fail(dev, (r), __VA_ARGS__)

void sy_rt_material_desc_init(sy_rt_material_desc *d)
{
    memset(d, 0, sizeof *d);
    d->base_color[0] = d->base_color[1] = d->base_color[2] = d->base_color[3] = 1.0f;
    d->metallic = 1.0f;
    d->roughness = 1.0f;
    d->normal_scale = 1.0f;
    d->specular = 1.0f;
    d->ior = 1.5f;
    d->alpha_mode = SY_RT_ALPHA_OPAQUE;
    d->alpha_cutoff = 0.5f;
    for (int k = 0; k < 3; ++k) d->specular_color[k] = d->attenuation_color[k] = 1.0f;
    d->iridescence_ior = 1.3f;
    d->clearcoat_normal_scale = 1.0f;
    d->iridescence_thickness[0] = 100.0f;
    d->iridescence_thickness[1] = 400.0f;
}

static sy_rt_result validate_texref(const sy_rt_device *dev, sy_rt_texture_ref t, const char *name)
{
    if (t.texture.id != 0 && !sy_rt_pool_get(&dev->textures, t.texture.id))
        return FAIL(SY_RT_ERROR_INVALID_HANDLE, "material: %s handle 0x%08x is stale", name, t.texture.id);
    if (t.texcoord > 1) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "material: %s.texcoord = %u, expected 0 or 1", name, t.texcoord);
    if (t.transformed)
        for (int k = 0; k < 6; ++k)
            if (!isfinite(t.transform[k]))
                return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "material: %s.transform[%d] is not finite", name, k);
    return SY_RT_OK;
}

static sy_rt_result validate_material(const sy_rt_device *dev, const sy_rt_material_desc *d)
{
    const struct { const char *name; float v, lo, hi; } ranges[] = {
        {"base_color[0]", d->base_color[0], 0.0f, INFINITY}, {"base_color[1]", d->base_color[1], 0.0f, INFINITY},
        {"base_color[2]", d->base_color[2], 0.0f, INFINITY}, {"base_color[3]", d->base_color[3], 0.0f, 1.0f},
        {"metallic", d->metallic, 0.0f, 1.0f}, {"roughness", d->roughness, 0.0f, 1.0f},
        {"emissive[0]", d->emissive[0], 0.0f, INFINITY}, {"emissive[1]", d->emissive[1], 0.0f, INFINITY},
        {"emissive[2]", d->emissive[2], 0.0f, INFINITY}, {"normal_scale", d->normal_scale, -INFINITY, INFINITY},
        {"specular", d->specular, 0.0f, 1.0f}, {"transmission", d->transmission, 0.0f, 1.0f},
        {"ior", d->ior, 1.0f, INFINITY}, {"alpha_cutoff", d->alpha_cutoff, 0.0f, 1.0f},
        {"specular_color[0]", d->specular_color[0], 0.0f, INFINITY}, {"specular_color[1]", d->specular_color[1], 0.0f, INFINITY},
        {"specular_color[2]", d->specular_color[2], 0.0f, INFINITY}, {"thickness", d->thickness, 0.0f, INFINITY},
        {"attenuation_distance", d->attenuation_distance, 0.0f, INFINITY},
        {"attenuation_color[0]", d->attenuation_color[0], 0.0f, 1.0f}, {"attenuation_color[1]", d->attenuation_color[1], 0.0f, 1.0f},
        {"attenuation_color[2]", d->attenuation_color[2], 0.0f, 1.0f}, {"clearcoat", d->clearcoat, 0.0f, 1.0f},
        {"clearcoat_roughness", d->clearcoat_roughness, 0.0f, 1.0f},
        {"sheen_color[0]", d->sheen_color[0], 0.0f, 1.0f}, {"sheen_color[1]", d->sheen_color[1], 0.0f, 1.0f},
        {"sheen_color[2]", d->sheen_color[2], 0.0f, 1.0f}, {"sheen_roughness", d->sheen_roughness, 0.0f, 1.0f},
        {"iridescence", d->iridescence, 0.0f, 1.0f}, {"iridescence_ior", d->iridescence_ior, 1.0f, INFINITY},
        {"iridescence_thickness[0]", d->iridescence_thickness[0], 0.0f, INFINITY},
        {"iridescence_thickness[1]", d->iridescence_thickness[1], 0.0f, INFINITY},
        {"clearcoat_normal_scale", d->clearcoat_normal_scale, -INFINITY, INFINITY}, {"anisotropy", d->anisotropy, 0.0f, 1.0f}, {"anisotropy_rotation", d->anisotropy_rotation, -1.0e6f, 1.0e6f},
    };
    for (size_t i = 0; i < sizeof ranges / sizeof ranges[0]; ++i)
        if (!isfinite(ranges[i].v) || ranges[i].v < ranges[i].lo || ranges[i].v > ranges[i].hi)
            return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "material: %s = %g is outside [%g, %g]", ranges[i].name,
                        (double)ranges[i].v, (double)ranges[i].lo, (double)ranges[i].hi);
    if ((unsigned)d->alpha_mode > SY_RT_ALPHA_BLEND)
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "material: unknown alpha_mode %d", (int)d->alpha_mode);
    sy_rt_result r;
    if ((r = validate_texref(dev, d->base_color_texture, "base_color_texture")) != SY_RT_OK) return r;
    if ((r = validate_texref(dev, d->metallic_roughness_texture, "metallic_roughness_texture")) != SY_RT_OK) return r;
    if ((r = validate_texref(dev, d->emissive_texture, "emissive_texture")) != SY_RT_OK) return r;
    if ((r = validate_texref(dev, d->transmission_texture, "transmission_texture")) != SY_RT_OK) return r;
    if ((r = validate_texref(dev, d->specular_texture, "specular_texture")) != SY_RT_OK) return r;
    if ((r = validate_texref(dev, d->specular_color_texture, "specular_color_texture")) != SY_RT_OK) return r;
    if ((r = validate_texref(dev, d->clearcoat_texture, "clearcoat_texture")) != SY_RT_OK) return r;
    if ((r = validate_texref(dev, d->clearcoat_roughness_texture, "clearcoat_roughness_texture")) != SY_RT_OK) return r;
    if ((r = validate_texref(dev, d->sheen_color_texture, "sheen_color_texture")) != SY_RT_OK) return r;
    if ((r = validate_texref(dev, d->sheen_roughness_texture, "sheen_roughness_texture")) != SY_RT_OK) return r;
    if ((r = validate_texref(dev, d->iridescence_texture, "iridescence_texture")) != SY_RT_OK) return r;
    if ((r = validate_texref(dev, d->iridescence_thickness_texture, "iridescence_thickness_texture")) != SY_RT_OK) return r;
    if ((r = validate_texref(dev, d->anisotropy_texture, "anisotropy_texture")) != SY_RT_OK) return r;
    if ((r = validate_texref(dev, d->clearcoat_normal_texture, "clearcoat_normal_texture")) != SY_RT_OK) return r;
    return validate_texref(dev, d->normal_texture, "normal_texture");
}

static void material_set(sy_rt_material_data *m, const sy_rt_material_desc *d)
{
    m->desc = *d;
    m->emissive = d->emissive[0] > 0.0f || d->emissive[1] > 0.0f || d->emissive[2] > 0.0f;
    m->masked = d->alpha_mode == SY_RT_ALPHA_MASK;
    m->textured = d->base_color_texture.texture.id || d->normal_texture.texture.id ||
                  d->metallic_roughness_texture.texture.id || d->emissive_texture.texture.id ||
                  d->transmission_texture.texture.id || d->specular_texture.texture.id ||
                  d->specular_color_texture.texture.id || d->clearcoat_texture.texture.id ||
                  d->clearcoat_roughness_texture.texture.id || d->sheen_color_texture.texture.id ||
                  d->sheen_roughness_texture.texture.id || d->iridescence_texture.texture.id ||
                  d->iridescence_thickness_texture.texture.id || d->anisotropy_texture.texture.id ||
                  d->clearcoat_normal_texture.texture.id;
    /* KHR_materials_volume: Beer-Lambert absorption inside a closed volume (thickness > 0) */
    m->volume = d->thickness > 0.0f && d->attenuation_distance > 0.0f && isfinite(d->attenuation_distance);
    for (int k = 0; k < 3; ++k)
        m->sigma[k] = m->volume ? -logf(sy_rt_maxf(d->attenuation_color[k], 1e-6f)) / d->attenuation_distance : 0.0f;
    m->volume = m->volume && (m->sigma[0] > 0.0f || m->sigma[1] > 0.0f || m->sigma[2] > 0.0f);
}

static sy_rt_result material_validate(const sy_rt_device *dev, const void *desc)
{
    return validate_material(dev, desc);
}

/* A new or changed material: the shadow flags are rebuilt at the next commit; a destroyed one
 * also rebuilds the area lights when it was emissive and the alpha filters when it was masked
 * (instances using it fall back to the default material, which is neither). */
static void material_mark(sy_rt_device *dev, const void *item, bool gone)
{
    const sy_rt_material_data *m = item;
    if (gone && m->emissive) dev->area_dirty = true;
    if (gone && m->masked) dev->filters_dirty = true;
    dev->dirty = dev->shadow_dirty = true;
}

/* An update also rebuilds the area lights when the emission changed and the alpha filters when
 * masking did. */
static void material_store(sy_rt_device *dev, void *item, const void *desc, bool fresh)
{
    sy_rt_material_data *m = item;
    const sy_rt_material_desc *d = desc;
    bool was_emissive = m->emissive, was_masked = m->masked;
    bool emission_changed = memcmp(m->desc.emissive, d->emissive, sizeof d->emissive) != 0 ||
                            m->desc.double_sided != d->double_sided;
    material_set(m, d);
    if (fresh) return;
    if (was_emissive != m->emissive || (m->emissive && emission_changed)) dev->area_dirty = true;
    if (was_masked != m->masked) dev->filters_dirty = true;
    material_mark(dev, m, false);
}

static const sy_rt_kind material_kind = {"material", offsetof(sy_rt_device, materials), sizeof(sy_rt_material_data),
                                         material_validate, material_store, material_mark};

SY_RT_KIND_CALLS(material, material_kind)
