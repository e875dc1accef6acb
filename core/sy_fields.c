/* sy_fields.c — field tables of every object type and the generic deep copy / free / compare
 * operations they drive (see sy_fields.h). The lowest module of core's scene: it calls neither the
 * change lists (sy_changes.c) nor the scene (sy_scene.c); both build on it. */
#include "sy_fields.h"

#include <stdlib.h>
#include <string.h>

/* >>tables */
#define F(T, member, k) {#member, (uint16_t)offsetof(T, member), (uint16_t)sizeof(((T *)0)->member), k}

static const sy_field_desc node_fields[SY_NODE_FIELD_COUNT] = {
    F(sy_node_data, name, SY_FK_STRING),    F(sy_node_data, transform, SY_FK_POD),
    F(sy_node_data, children, SY_FK_BLOB),  F(sy_node_data, mesh, SY_FK_POD),
    F(sy_node_data, light, SY_FK_POD),      F(sy_node_data, camera, SY_FK_POD),
    F(sy_node_data, flags, SY_FK_POD),      F(sy_node_data, weights, SY_FK_BLOB),
    F(sy_node_data, skin, SY_FK_BLOB),      F(sy_node_data, skeleton, SY_FK_POD),
};
static const sy_field_desc mesh_fields[SY_MESH_FIELD_COUNT] = {
    F(sy_mesh_data, name, SY_FK_STRING),
    F(sy_mesh_data, primitives, SY_FK_PRIMS),
    F(sy_mesh_data, weights, SY_FK_BLOB),
};
static const sy_field_desc material_fields[SY_MATERIAL_FIELD_COUNT] = {
    F(sy_material_data, name, SY_FK_STRING),
    F(sy_material_data, base_color, SY_FK_POD),
    F(sy_material_data, base_color_texture, SY_FK_POD),
    F(sy_material_data, metallic, SY_FK_POD),
    F(sy_material_data, roughness, SY_FK_POD),
    F(sy_material_data, metallic_roughness_texture, SY_FK_POD),
    F(sy_material_data, normal_texture, SY_FK_POD),
    F(sy_material_data, occlusion_texture, SY_FK_POD),
    F(sy_material_data, emissive, SY_FK_POD),
    F(sy_material_data, emissive_strength, SY_FK_POD),
    F(sy_material_data, emissive_texture, SY_FK_POD),
    F(sy_material_data, alpha_mode, SY_FK_POD),
    F(sy_material_data, alpha_cutoff, SY_FK_POD),
    F(sy_material_data, double_sided, SY_FK_POD),
    F(sy_material_data, transmission, SY_FK_POD),
    F(sy_material_data, transmission_texture, SY_FK_POD),
    F(sy_material_data, ior, SY_FK_POD),
    F(sy_material_data, unlit, SY_FK_POD),
    F(sy_material_data, specular, SY_FK_POD),
    F(sy_material_data, specular_texture, SY_FK_POD),
    F(sy_material_data, specular_color, SY_FK_POD),
    F(sy_material_data, specular_color_texture, SY_FK_POD),
    F(sy_material_data, clearcoat, SY_FK_POD),
    F(sy_material_data, clearcoat_texture, SY_FK_POD),
    F(sy_material_data, clearcoat_roughness, SY_FK_POD),
    F(sy_material_data, clearcoat_roughness_texture, SY_FK_POD),
    F(sy_material_data, clearcoat_normal_texture, SY_FK_POD),
    F(sy_material_data, sheen_color, SY_FK_POD),
    F(sy_material_data, sheen_color_texture, SY_FK_POD),
    F(sy_material_data, sheen_roughness, SY_FK_POD),
    F(sy_material_data, sheen_roughness_texture, SY_FK_POD),
    F(sy_material_data, thickness, SY_FK_POD),
    F(sy_material_data, thickness_texture, SY_FK_POD),
    F(sy_material_data, attenuation_distance, SY_FK_POD),
    F(sy_material_data, attenuation_color, SY_FK_POD),
    F(sy_material_data, iridescence, SY_FK_POD),
    F(sy_material_data, iridescence_texture, SY_FK_POD),
    F(sy_material_data, iridescence_ior, SY_FK_POD),
    F(sy_material_data, iridescence_thickness, SY_FK_POD),
    F(sy_material_data, iridescence_thickness_texture, SY_FK_POD),
    F(sy_material_data, anisotropy, SY_FK_POD),
    F(sy_material_data, anisotropy_rotation, SY_FK_POD),
    F(sy_material_data, anisotropy_texture, SY_FK_POD),
};
static const sy_field_desc texture_fields[SY_TEXTURE_FIELD_COUNT] = {
    F(sy_texture_data, name, SY_FK_STRING),
    F(sy_texture_data, info, SY_FK_POD),
    F(sy_texture_data, pixels, SY_FK_BLOB),
    F(sy_texture_data, sampler, SY_FK_POD),
};
static const sy_field_desc light_fields[SY_LIGHT_FIELD_COUNT] = {
    F(sy_light_data, name, SY_FK_STRING),      F(sy_light_data, type, SY_FK_POD),
    F(sy_light_data, color, SY_FK_POD),        F(sy_light_data, intensity, SY_FK_POD),
    F(sy_light_data, range, SY_FK_POD),        F(sy_light_data, inner_cone, SY_FK_POD),
    F(sy_light_data, outer_cone, SY_FK_POD),
};
static const sy_field_desc camera_fields[SY_CAMERA_FIELD_COUNT] = {
    F(sy_camera_data, name, SY_FK_STRING), F(sy_camera_data, projection, SY_FK_POD),
    F(sy_camera_data, yfov, SY_FK_POD),    F(sy_camera_data, aspect, SY_FK_POD),
    F(sy_camera_data, znear, SY_FK_POD),   F(sy_camera_data, zfar, SY_FK_POD),
    F(sy_camera_data, xmag, SY_FK_POD),    F(sy_camera_data, ymag, SY_FK_POD),
};
static const sy_field_desc background_fields[SY_BACKGROUND_FIELD_COUNT] = {
    F(sy_background_data, name, SY_FK_STRING),
    F(sy_background_data, color, SY_FK_POD),
    F(sy_background_data, environment, SY_FK_POD),
    F(sy_background_data, intensity, SY_FK_POD),
    F(sy_background_data, environment_visible, SY_FK_POD),
    F(sy_background_data, gradient, SY_FK_POD),
    F(sy_background_data, default_lighting, SY_FK_POD),
};
static const sy_field_desc animation_fields[SY_ANIMATION_FIELD_COUNT] = {
    F(sy_animation_data, name, SY_FK_STRING),    F(sy_animation_data, samplers, SY_FK_BLOB),
    F(sy_animation_data, channels, SY_FK_BLOB),  F(sy_animation_data, times, SY_FK_BLOB),
    F(sy_animation_data, values, SY_FK_BLOB),    F(sy_animation_data, cycle, SY_FK_POD),
    F(sy_animation_data, loop, SY_FK_POD),
};
#undef F

#define TEXREF_NONE {{0}, 0, 1.0f, {0.0f, 0.0f}, 0.0f, {1.0f, 1.0f}}
static const sy_node_data node_defaults = {
    .transform = {.mode = SY_TRANSFORM_TRS,
                  .rotation = {0, 0, 0, 1},
                  .scale = {1, 1, 1},
                  .matrix = {{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}},
    .flags = SY_NODE_VISIBLE,
};
static const sy_mesh_data mesh_defaults = {0};
static const sy_material_data material_defaults = {
    .base_color = {1, 1, 1, 1},
    .base_color_texture = TEXREF_NONE,
    .metallic = 1.0f,
    .roughness = 1.0f,
    .metallic_roughness_texture = TEXREF_NONE,
    .normal_texture = TEXREF_NONE,
    .occlusion_texture = TEXREF_NONE,
    .emissive_strength = 1.0f,
    .emissive_texture = TEXREF_NONE,
    .alpha_mode = SY_ALPHA_OPAQUE,
    .alpha_cutoff = 0.5f,
    .transmission_texture = TEXREF_NONE,
    .ior = 1.5f,
    .specular = 1.0f,
    .specular_texture = TEXREF_NONE,
    .specular_color = {1, 1, 1},
    .specular_color_texture = TEXREF_NONE,
    .clearcoat_texture = TEXREF_NONE,
    .clearcoat_roughness_texture = TEXREF_NONE,
    .clearcoat_normal_texture = TEXREF_NONE,
    .sheen_color_texture = TEXREF_NONE,
    .sheen_roughness_texture = TEXREF_NONE,
    .thickness_texture = TEXREF_NONE,
    .attenuation_color = {1, 1, 1},
    .iridescence_texture = TEXREF_NONE,
    .iridescence_ior = 1.3f,
    .iridescence_thickness = {100.0f, 400.0f},
    .iridescence_thickness_texture = TEXREF_NONE,
    .anisotropy_texture = TEXREF_NONE,
};
static const sy_texture_data texture_defaults = {
    .sampler = {SY_WRAP_REPEAT, SY_WRAP_REPEAT, SY_FILTER_LINEAR, SY_FILTER_LINEAR},
};
static const sy_light_data light_defaults = {
    .type = SY_LIGHT_POINT, .color = {1, 1, 1}, .intensity = 1.0f, .outer_cone = 0.78539816f};
static const sy_camera_data camera_defaults = {
    .projection = SY_PROJECTION_PERSPECTIVE, .yfov = 0.8f, .znear = 0.01f, .xmag = 1.0f, .ymag = 1.0f};
static const sy_background_data background_defaults = {
    .color = {0, 0, 0, 1}, .intensity = 1.0f, .environment_visible = 1, .default_lighting = 1};
static const sy_animation_data animation_defaults = {0};

#define T(name, D, fields, defaults) {name, sizeof(D), fields, sizeof fields / sizeof fields[0], &defaults}
static const sy_type_desc type_descs[SY_TYPE_COUNT] = {
    [SY_TYPE_TEXTURE] = T("texture", sy_texture_data, texture_fields, texture_defaults),
    [SY_TYPE_MATERIAL] = T("material", sy_material_data, material_fields, material_defaults),
    [SY_TYPE_MESH] = T("mesh", sy_mesh_data, mesh_fields, mesh_defaults),
    [SY_TYPE_LIGHT] = T("light", sy_light_data, light_fields, light_defaults),
    [SY_TYPE_CAMERA] = T("camera", sy_camera_data, camera_fields, camera_defaults),
    [SY_TYPE_BACKGROUND] = T("background", sy_background_data, background_fields, background_defaults),
    [SY_TYPE_NODE] = T("node", sy_node_data, node_fields, node_defaults),
    [SY_TYPE_ANIMATION] = T("animation", sy_animation_data, animation_fields, animation_defaults),
};
#undef T

const sy_type_desc *sy__type_desc(uint32_t type)
{
    if (type == SY_TYPE_NONE || type >= SY_TYPE_COUNT) return NULL;
    return &type_descs[type];
}

uint64_t sy__type_full_mask(uint32_t type)
{
    const sy_type_desc *td = sy__type_desc(type);
    if (!td) return 0;
    return ((1ull << td->field_count) - 1ull) | SY_BIT(SY_FIELD_ATTACHMENTS);
}

const char *sy_object_type_name(sy_object_type t)
{
    const sy_type_desc *td = sy__type_desc(t);
    return td ? td->name : "unknown";
}

const void *sy_object_defaults(sy_object_type t)
{
    const sy_type_desc *td = sy__type_desc(t);
    return td ? td->defaults : NULL;
}

/* >>animation blobs (read by validation, the setters and the clock) */
const sy_anim_sampler *sy_animation_samplers(const sy_animation_data *d, uint32_t *count_out)
{
    *count_out = d && d->samplers ? (uint32_t)(sy_blob_size(d->samplers) / sizeof(sy_anim_sampler)) : 0;
    return *count_out ? sy_blob_data(d->samplers) : NULL;
}

const sy_anim_channel *sy_animation_channels(const sy_animation_data *d, uint32_t *count_out)
{
    *count_out = d && d->channels ? (uint32_t)(sy_blob_size(d->channels) / sizeof(sy_anim_channel)) : 0;
    return *count_out ? sy_blob_data(d->channels) : NULL;
}

void sy_animation_time_range(const sy_animation_data *d, float *start_out, float *end_out)
{
    uint32_t n;
    const sy_anim_sampler *sm = sy_animation_samplers(d, &n);
    size_t nt = d && d->times ? sy_blob_size(d->times) / sizeof(float) : 0;
    const float *t = nt ? sy_blob_data(d->times) : NULL;
    float lo = 0.0f, hi = 0.0f;
    bool any = false;
    for (uint32_t i = 0; i < n; ++i) {
        if (!sm[i].key_count || (uint64_t)sm[i].times_offset + sm[i].key_count > nt) continue; /* refused when set */
        float a = t[sm[i].times_offset], b = t[sm[i].times_offset + sm[i].key_count - 1];
        if (!any || a < lo) lo = a;
        if (!any || b > hi) hi = b;
        any = true;
    }
    if (d && d->cycle > 0.0f) lo = 0.0f, hi = d->cycle; /* a period of its own (X3D TimeSensor) */
    if (start_out) *start_out = lo;
    if (end_out) *end_out = hi;
}

/* >>generic field operations */
void sy__primitive_release(sy_primitive *p)
{
    sy_blob *blobs[13] = {p->positions, p->texcoords0, p->texcoords1,      p->normals,          p->tangents,
                          p->colors,    p->indices,    p->joints,          p->weights,          p->target_positions,
                          p->target_normals, p->target_tangents, p->target_texcoords0};
    for (int i = 0; i < 13; ++i) sy_blob_release(blobs[i]);
    memset(p, 0, sizeof *p);
}

static void *field_ptr(const sy_type_desc *td, uint32_t f, const void *data)
{
    return (char *)data + td->fields[f].offset;
}

static void prims_free(sy_primitive_list *l)
{
    for (uint32_t i = 0; i < l->count; ++i) sy__primitive_release(&l->items[i]);
    free(l->items);
    l->items = NULL;
    l->count = 0;
}

static bool prims_copy(sy_primitive_list *dst, const sy_primitive_list *src)
{
    dst->items = NULL;
    dst->count = 0;
    if (src->count == 0) return true;
    dst->items = malloc(sizeof(sy_primitive) * src->count);
    if (!dst->items) return false;
    memcpy(dst->items, src->items, sizeof(sy_primitive) * src->count);
    for (uint32_t i = 0; i < src->count; ++i) {
        sy_primitive *p = &dst->items[i];
        sy_blob_retain(p->positions);
        sy_blob_retain(p->normals);
        sy_blob_retain(p->tangents);
        sy_blob_retain(p->texcoords0);
        sy_blob_retain(p->texcoords1);
        sy_blob_retain(p->colors);
        sy_blob_retain(p->indices);
        sy_blob_retain(p->joints);
        sy_blob_retain(p->weights);
        sy_blob_retain(p->target_positions);
        sy_blob_retain(p->target_normals);
        sy_blob_retain(p->target_tangents);
        sy_blob_retain(p->target_texcoords0);
    }
    dst->count = src->count;
    return true;
}

static bool blob_same(const sy_blob *a, const sy_blob *b)
{
    if (a == b) return true;
    if (!a || !b) return false;
    return sy_blob_size(a) == sy_blob_size(b) && sy_hash_equal(sy_blob_hash(a), sy_blob_hash(b));
}

static void field_free(const sy_type_desc *td, uint32_t f, void *data)
{
    void *p = field_ptr(td, f, data);
    switch (td->fields[f].kind) {
    case SY_FK_STRING:
        free(*(char **)p);
        *(char **)p = NULL;
        break;
    case SY_FK_BLOB:
        sy_blob_release(*(sy_blob **)p);
        *(sy_blob **)p = NULL;
        break;
    case SY_FK_PRIMS: prims_free((sy_primitive_list *)p); break;
    default: break;
    }
}

void *sy__data_new(uint32_t type)
{
    const sy_type_desc *td = sy__type_desc(type);
    if (!td) return NULL;
    void *d = malloc(td->data_size);
    if (d) memcpy(d, td->defaults, td->data_size); /* defaults own nothing */
    return d;
}

void sy__data_free(uint32_t type, void *data)
{
    const sy_type_desc *td = sy__type_desc(type);
    if (!td || !data) return;
    for (uint32_t f = 0; f < td->field_count; ++f) field_free(td, f, data);
    free(data);
}

bool sy__field_copy(uint32_t type, uint32_t f, void *dst, const void *src)
{
    const sy_type_desc *td = sy__type_desc(type);
    void *d = field_ptr(td, f, dst);
    const void *s = field_ptr(td, f, src);
    switch (td->fields[f].kind) {
    case SY_FK_STRING: {
        const char *str = *(char *const *)s;
        char *copy = NULL;
        if (str) {
            copy = strdup(str);
            if (!copy) return false;
        }
        free(*(char **)d);
        *(char **)d = copy;
        return true;
    }
    case SY_FK_BLOB: {
        sy_blob *b = sy_blob_retain(*(sy_blob *const *)s);
        sy_blob_release(*(sy_blob **)d);
        *(sy_blob **)d = b;
        return true;
    }
    case SY_FK_PRIMS: {
        sy_primitive_list copy;
        if (!prims_copy(&copy, (const sy_primitive_list *)s)) return false;
        prims_free((sy_primitive_list *)d);
        *(sy_primitive_list *)d = copy;
        return true;
    }
    default: memmove(d, s, td->fields[f].size); return true;
    }
}

bool sy__field_equal(uint32_t type, uint32_t f, const void *a, const void *b)
{
    const sy_type_desc *td = sy__type_desc(type);
    const void *pa = field_ptr(td, f, a);
    const void *pb = field_ptr(td, f, b);
    switch (td->fields[f].kind) {
    case SY_FK_STRING: {
        const char *sa = *(char *const *)pa, *sb = *(char *const *)pb;
        if (!sa || !sb) return sa == sb;
        return strcmp(sa, sb) == 0;
    }
    case SY_FK_BLOB: return blob_same(*(sy_blob *const *)pa, *(sy_blob *const *)pb);
    case SY_FK_PRIMS: {
        const sy_primitive_list *la = pa, *lb = pb;
        if (la->count != lb->count) return false;
        for (uint32_t i = 0; i < la->count; ++i) {
            const sy_primitive *x = &la->items[i], *y = &lb->items[i];
            if (!blob_same(x->positions, y->positions) || !blob_same(x->normals, y->normals) ||
                !blob_same(x->tangents, y->tangents) || !blob_same(x->texcoords0, y->texcoords0) ||
                !blob_same(x->texcoords1, y->texcoords1) || !blob_same(x->colors, y->colors) ||
                !blob_same(x->indices, y->indices) || !blob_same(x->joints, y->joints) ||
                !blob_same(x->weights, y->weights) || !blob_same(x->target_positions, y->target_positions) ||
                !blob_same(x->target_normals, y->target_normals) ||
                !blob_same(x->target_tangents, y->target_tangents) ||
                !blob_same(x->target_texcoords0, y->target_texcoords0) || x->material.id != y->material.id ||
                x->topology != y->topology || memcmp(&x->width, &y->width, sizeof x->width) != 0)
                return false;
        }
        return true;
    }
    default: return memcmp(pa, pb, td->fields[f].size) == 0;
    }
}

size_t sy__field_heap_bytes(uint32_t type, uint32_t f, const void *data)
{
    const sy_type_desc *td = sy__type_desc(type);
    const void *p = field_ptr(td, f, data);
    switch (td->fields[f].kind) {
    case SY_FK_STRING: {
        const char *s = *(char *const *)p;
        return s ? strlen(s) + 1 : 0;
    }
    case SY_FK_PRIMS: return ((const sy_primitive_list *)p)->count * sizeof(sy_primitive);
    default: return 0;
    }
}

/* >>attachments */
void sy__attachments_free(sy_attachment *a, uint32_t n)
{
    if (!a) return;
    for (uint32_t i = 0; i < n; ++i) {
        free(a[i].key);
        if (a[i].kind == SY_ATTACH_STRING) free(a[i].value.s);
        if (a[i].kind == SY_ATTACH_BLOB) sy_blob_release(a[i].value.blob);
    }
    free(a);
}

bool sy__attachments_copy(const sy_attachment *src, uint32_t n, sy_attachment **dst_out)
{
    *dst_out = NULL;
    if (n == 0) return true;
    sy_attachment *d = calloc(n, sizeof *d);
    if (!d) return false;
    for (uint32_t i = 0; i < n; ++i) {
        d[i].kind = src[i].kind;
        d[i].value = src[i].value;
        d[i].key = strdup(src[i].key ? src[i].key : "");
        bool ok = d[i].key != NULL;
        if (src[i].kind == SY_ATTACH_STRING) {
            d[i].value.s = strdup(src[i].value.s ? src[i].value.s : "");
            ok = ok && d[i].value.s;
        } else if (src[i].kind == SY_ATTACH_BLOB) {
            sy_blob_retain(d[i].value.blob);
        }
        if (!ok) {
            sy__attachments_free(d, i + 1);
            return false;
        }
    }
    *dst_out = d;
    return true;
}

bool sy__attachments_equal(const sy_attachment *a, uint32_t na, const sy_attachment *b, uint32_t nb)
{
    if (na != nb) return false;
    for (uint32_t i = 0; i < na; ++i) {
        if (strcmp(a[i].key, b[i].key) != 0 || a[i].kind != b[i].kind) return false;
        switch (a[i].kind) {
        case SY_ATTACH_INT:
            if (a[i].value.i != b[i].value.i) return false;
            break;
        case SY_ATTACH_FLOAT:
            if (memcmp(&a[i].value.f, &b[i].value.f, sizeof(double)) != 0) return false;
            break;
        case SY_ATTACH_VEC4:
            if (memcmp(a[i].value.v, b[i].value.v, sizeof a[i].value.v) != 0) return false;
            break;
        case SY_ATTACH_STRING:
            if (strcmp(a[i].value.s, b[i].value.s) != 0) return false;
            break;
        case SY_ATTACH_BLOB:
            if (!blob_same(a[i].value.blob, b[i].value.blob)) return false;
            break;
        default: return false;
        }
    }
    return true;
}
