/* sy_gltf_materials.c — glTF materials into sy_materials, with their textures (created on demand, one
 * sy_texture per glTF texture and colour role: sRGB for colours, linear for data; the decoded
 * images shared as blobs), samplers and KHR_texture_transform. */
#include "sy_gltf_internal.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

/* >>textures+materials ------------------------------------------------------------------------ */

enum { ROLE_COLOR = 0, ROLE_DATA = 1 };

static uint32_t map_wrap(loader *L, int32_t w, size_t si)
{
    switch (w) {
    case 10497: return SY_WRAP_REPEAT;
    case 33071: return SY_WRAP_CLAMP;
    case 33648: return SY_WRAP_MIRROR;
    default: gltf_warn(L, "samplers[%zu]: unknown wrap mode %d, using REPEAT", si, (int)w); return SY_WRAP_REPEAT;
    }
}

static uint32_t map_filter(int32_t f)
{
    /* NEAREST, NEAREST_MIPMAP_NEAREST, NEAREST_MIPMAP_LINEAR sample the nearest texel in a level. */
    return (f == 9728 || f == 9984 || f == 9986) ? SY_FILTER_NEAREST : SY_FILTER_LINEAR;
}

static sy_result get_texture(loader *L, const sy_gltf_shim_texinfo *ti, int role, size_t mi, const char *slot,
                             sy_texture_ref *ref)
{
    const sy_gltf_doc *d = L->doc;
    ref->texture = (sy_texture){0};
    ref->texcoord = 0;
    ref->offset[0] = ref->offset[1] = 0.0f;
    ref->rotation = 0.0f;
    ref->uv_scale[0] = ref->uv_scale[1] = 1.0f;
    if (!gltf_to_float(ti->scale, &ref->scale)) return gltf_fail(L, SY_ERR_PARSE, "materials[%zu].%s: non-finite scale", mi, slot);
    if (ti->index < 0) return SY_OK;
    int32_t tc = ti->has_transform && ti->transform_texcoord >= 0 ? ti->transform_texcoord : ti->texcoord;
    if (tc < 0 || tc > 1) {
        gltf_warn(L, "materials[%zu].%s: texCoord %d not supported, using 0", mi, slot, (int)tc);
        tc = 0;
    }
    ref->texcoord = (uint32_t)tc;
    if (ti->has_transform) {
        if (!gltf_to_float(ti->offset[0], &ref->offset[0]) || !gltf_to_float(ti->offset[1], &ref->offset[1]) ||
            !gltf_to_float(ti->rotation, &ref->rotation) || !gltf_to_float(ti->uv_scale[0], &ref->uv_scale[0]) ||
            !gltf_to_float(ti->uv_scale[1], &ref->uv_scale[1]))
            return gltf_fail(L, SY_ERR_PARSE, "materials[%zu].%s: non-finite KHR_texture_transform value", mi, slot);
    }
    size_t t = (size_t)ti->index;
    sy_texture *slot_handle = &L->textures[t * 2 + (size_t)role];
    if (slot_handle->id == 0) {
        const sy_gltf_shim_texture *tex = &d->textures[t];
        if (tex->source < 0) {
            gltf_warn(L, "textures[%zu] has no image source; ignored", t);
            return SY_OK;
        }
        const sy_gltf_shim_image *im = &d->images[tex->source];
        if (!im->pixels) return SY_OK; /* warned in validate_doc */
        sy_result r;
        if (!L->image_blobs[tex->source]) {
            size_t bytes = (size_t)im->width * im->height * im->channels; /* fits: the shim allocated it */
            if ((r = sy_blob_create_copy(im->pixels, bytes, &L->image_blobs[tex->source], &L->err)))
                return gltf_context(L, r, "images");
        }
        const char *name = gltf_nonempty(tex->name) ? tex->name : gltf_nonempty(im->name);
        sy_texture h;
        if ((r = gltf_create(L, SY_TYPE_TEXTURE, name, "textures", &h.id))) return r;
        sy_image_info info = {im->width, im->height, im->channels,
                              role == ROLE_COLOR ? SY_PIXEL_U8_SRGB : SY_PIXEL_U8_LINEAR};
        if ((r = sy_texture_set_image(L->scene, h, &info, L->image_blobs[tex->source], &L->err)))
            return gltf_context(L, r, "textures");
        sy_sampler smp = {SY_WRAP_REPEAT, SY_WRAP_REPEAT, SY_FILTER_LINEAR, SY_FILTER_LINEAR};
        if (tex->sampler >= 0) {
            const sy_gltf_shim_sampler *s = &d->samplers[tex->sampler];
            smp.wrap_s = map_wrap(L, s->wrap_s, (size_t)tex->sampler);
            smp.wrap_t = map_wrap(L, s->wrap_t, (size_t)tex->sampler);
            smp.min_filter = map_filter(s->min_filter);
            smp.mag_filter = map_filter(s->mag_filter);
        }
        if ((r = sy_texture_set_sampler(L->scene, h, &smp, &L->err))) return gltf_context(L, r, "textures");
        *slot_handle = h;
    }
    ref->texture = *slot_handle;
    return SY_OK;
}

#define SLOT(member, color, name) {offsetof(sy_gltf_shim_material, member), offsetof(sy_material_data, member), color, name}
const gltf_texture_slot gltf_texture_slots[] = {
    SLOT(base_color_texture, true, "baseColorTexture"),
    SLOT(metallic_roughness_texture, false, "metallicRoughnessTexture"),
    SLOT(normal_texture, false, "normalTexture"),
    SLOT(occlusion_texture, false, "occlusionTexture"),
    SLOT(emissive_texture, true, "emissiveTexture"),
    SLOT(transmission_texture, false, "KHR_materials_transmission.transmissionTexture"),
    SLOT(specular_texture, false, "KHR_materials_specular.specularTexture"),
    SLOT(specular_color_texture, true, "KHR_materials_specular.specularColorTexture"),
    SLOT(clearcoat_texture, false, "KHR_materials_clearcoat.clearcoatTexture"),
    SLOT(clearcoat_roughness_texture, false, "KHR_materials_clearcoat.clearcoatRoughnessTexture"),
    SLOT(clearcoat_normal_texture, false, "KHR_materials_clearcoat.clearcoatNormalTexture"),
    SLOT(sheen_color_texture, true, "KHR_materials_sheen.sheenColorTexture"),
    SLOT(sheen_roughness_texture, false, "KHR_materials_sheen.sheenRoughnessTexture"),
    SLOT(thickness_texture, false, "KHR_materials_volume.thicknessTexture"),
    SLOT(iridescence_texture, false, "KHR_materials_iridescence.iridescenceTexture"),
    SLOT(iridescence_thickness_texture, false, "KHR_materials_iridescence.iridescenceThicknessTexture"),
    SLOT(anisotropy_texture, false, "KHR_materials_anisotropy.anisotropyTexture"),
};
#undef SLOT
const size_t gltf_texture_slot_count = sizeof gltf_texture_slots / sizeof gltf_texture_slots[0];
_Static_assert(sizeof gltf_texture_slots / sizeof gltf_texture_slots[0] == SY_MATERIAL_TEXTURE_SLOTS,
               "every core texture slot is read from glTF");

/* The factors of the material extensions with the ranges their specifications give: a value outside
 * is clamped with a warning (the back-ends see the same clamped value). */
typedef struct factor {
    size_t shim, core; /* offsets of double[n] and float[n] */
    int n;
    float lo, hi;
    const char *name;
} factor;
#define FACTOR(member, n, lo, hi, name) {offsetof(sy_gltf_shim_material, member), offsetof(sy_material_data, member), n, lo, hi, name}
static const factor factors[] = {
    FACTOR(specular, 1, 0.0f, 1.0f, "KHR_materials_specular.specularFactor"),
    FACTOR(specular_color, 3, 0.0f, INFINITY, "KHR_materials_specular.specularColorFactor"),
    FACTOR(clearcoat, 1, 0.0f, 1.0f, "KHR_materials_clearcoat.clearcoatFactor"),
    FACTOR(clearcoat_roughness, 1, 0.0f, 1.0f, "KHR_materials_clearcoat.clearcoatRoughnessFactor"),
    FACTOR(sheen_color, 3, 0.0f, 1.0f, "KHR_materials_sheen.sheenColorFactor"),
    FACTOR(sheen_roughness, 1, 0.0f, 1.0f, "KHR_materials_sheen.sheenRoughnessFactor"),
    FACTOR(thickness, 1, 0.0f, INFINITY, "KHR_materials_volume.thicknessFactor"),
    FACTOR(attenuation_distance, 1, 0.0f, INFINITY, "KHR_materials_volume.attenuationDistance"),
    FACTOR(attenuation_color, 3, 0.0f, 1.0f, "KHR_materials_volume.attenuationColor"),
    FACTOR(iridescence, 1, 0.0f, 1.0f, "KHR_materials_iridescence.iridescenceFactor"),
    FACTOR(iridescence_ior, 1, 1.0f, INFINITY, "KHR_materials_iridescence.iridescenceIor"),
    FACTOR(iridescence_thickness, 2, 0.0f, INFINITY, "KHR_materials_iridescence.iridescenceThickness{Minimum,Maximum}"),
    FACTOR(anisotropy, 1, 0.0f, 1.0f, "KHR_materials_anisotropy.anisotropyStrength"),
    FACTOR(anisotropy_rotation, 1, -INFINITY, INFINITY, "KHR_materials_anisotropy.anisotropyRotation"),
};
#undef FACTOR

static sy_result get_factors(loader *L, const sy_gltf_shim_material *m, size_t mi, sy_material_data *md)
{
    for (size_t k = 0; k < sizeof factors / sizeof factors[0]; k++) {
        const factor *f = &factors[k];
        const double *src = (const double *)((const char *)m + f->shim);
        float *dst = (float *)((char *)md + f->core);
        for (int c = 0; c < f->n; c++) {
            if (!gltf_to_float(src[c], &dst[c]))
                return gltf_fail(L, SY_ERR_PARSE, "materials[%zu].%s: non-finite value", mi, f->name);
            if (dst[c] < f->lo || dst[c] > f->hi) {
                float v = dst[c] < f->lo ? f->lo : f->hi;
                gltf_warn(L, "materials[%zu].%s: %g is outside [%g, %g]; clamped to %g%s", mi, f->name, (double)dst[c],
                          (double)f->lo, (double)f->hi, (double)v,
                          f->core == offsetof(sy_material_data, attenuation_distance) ? " (infinite: no absorption)" : "");
                dst[c] = v;
            }
        }
    }
    /* glTF: attenuationDistance > 0, absent = infinite; core (and the shim for an absent one): 0 = infinite */
    if (m->attenuation_distance <= 0.0 && m->thickness > 0.0 && m->attenuation_color[0] + m->attenuation_color[1] + m->attenuation_color[2] < 3.0)
        gltf_warn(L, "materials[%zu].KHR_materials_volume: an attenuationColor without a positive attenuationDistance "
                  "absorbs nothing", mi);
    if (md->iridescence_thickness[0] > md->iridescence_thickness[1])
        gltf_warn(L, "materials[%zu].KHR_materials_iridescence: thickness minimum %g above maximum %g (kept: the "
                  "thickness texture then runs from thick to thin)", mi, (double)md->iridescence_thickness[0],
                  (double)md->iridescence_thickness[1]);
    return SY_OK;
}

sy_result gltf_create_material(loader *L, size_t i)
{
    const sy_gltf_shim_material *m = &L->doc->materials[i];
    sy_material_data md = *(const sy_material_data *)sy_object_defaults(SY_TYPE_MATERIAL);
    md.name = (char *)gltf_nonempty(m->name);
    bool ok = true;
    for (int k = 0; k < 4; k++) ok = ok && gltf_to_float(m->base_color[k], &md.base_color[k]);
    for (int k = 0; k < 3; k++) ok = ok && gltf_to_float(m->emissive[k], &md.emissive[k]);
    ok = ok && gltf_to_float(m->metallic, &md.metallic) && gltf_to_float(m->roughness, &md.roughness) &&
         gltf_to_float(m->emissive_strength, &md.emissive_strength) && gltf_to_float(m->alpha_cutoff, &md.alpha_cutoff) &&
         gltf_to_float(m->transmission, &md.transmission) && gltf_to_float(m->ior, &md.ior);
    if (!ok) return gltf_fail(L, SY_ERR_PARSE, "materials[%zu]: non-finite factor", i);
    sy_result r;
    if ((r = get_factors(L, m, i, &md))) return r;
    for (size_t k = 0; k < gltf_texture_slot_count; k++) {
        const gltf_texture_slot *ts = &gltf_texture_slots[k];
        if ((r = get_texture(L, (const sy_gltf_shim_texinfo *)((const char *)m + ts->shim), ts->color ? ROLE_COLOR : ROLE_DATA,
                             i, ts->name, (sy_texture_ref *)((char *)&md + ts->core))))
            return r;
    }
    md.alpha_mode = !strcmp(m->alpha_mode, "MASK") ? SY_ALPHA_MASK : !strcmp(m->alpha_mode, "BLEND") ? SY_ALPHA_BLEND
                                                                                                    : SY_ALPHA_OPAQUE;
    md.double_sided = m->double_sided ? 1u : 0u;
    md.unlit = m->unlit ? 1u : 0u;
    sy_material h;
    char where[48];
    snprintf(where, sizeof where, "materials[%zu]", i);
    if ((r = gltf_create(L, SY_TYPE_MATERIAL, md.name, where, &h.id))) return r;
    if ((r = sy_material_set(L->scene, h, &md, &L->err))) return gltf_context(L, r, where);
    L->materials[i] = h;
    return SY_OK;
}
