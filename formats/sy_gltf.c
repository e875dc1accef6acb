/* sy_gltf.c — glTF 2.0 loader: file reading, GLB container validation, one validation pass over the
 * parsed document (formats/sy_gltf_shim.h gives it as plain C structs), then conversion into core
 * scene objects through the public scene API, with rollback of everything created on failure.
 *
 * Sections: >>errors, >>container, >>validation, >>accessors, >>textures+materials, >>meshes,
 * >>cameras+lights, >>nodes, >>public. */
#include "sy_gltf.h"

#include "sy_budget.h"
#include "sy_file.h"
#include "sy_gltf_shim.h"
#include "sy_log.h"
#include "sy_mesh_util.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define GLTF_POINTS 0
#define GLTF_LINES 1
#define GLTF_LINE_LOOP 2
#define GLTF_LINE_STRIP 3
#define GLTF_TRIANGLES 4
#define GLTF_TRIANGLE_STRIP 5
#define GLTF_TRIANGLE_FAN 6

#define CT_BYTE 5120
#define CT_UBYTE 5121
#define CT_SHORT 5122
#define CT_USHORT 5123
#define CT_UINT 5125
#define CT_FLOAT 5126

#define GLB_MAGIC 0x46546C67u /* "glTF" */
#define GLB_JSON 0x4E4F534Au
#define GLB_BIN 0x004E4942u

enum { ROLE_COLOR = 0, ROLE_DATA = 1 };
#define SY_GLTF_PI 3.14159265358979323846

static const char *const k_supported[] = {
    "KHR_materials_emissive_strength", "KHR_materials_transmission", "KHR_materials_ior",
    "KHR_materials_unlit", "KHR_texture_transform", "KHR_lights_punctual",
    "KHR_mesh_quantization", "EXT_mesh_gpu_instancing", NULL,
};

typedef struct created_obj {
    uint32_t type, id;
} created_obj;

typedef struct loader {
    const char *path;
    sy_scene *scene;
    sy_gltf_options opt;
    const sy_gltf_doc *doc;
    sy_error err; /* local; copied to the caller's at the end */
    sy_gltf_info *info;
    created_obj *objs;
    size_t obj_count, obj_cap;
    /* glTF index -> created handle (0 = not created) */
    sy_material *materials;
    sy_mesh *meshes;
    sy_camera *cameras;
    sy_light *lights;
    sy_node *nodes;
    sy_texture *textures; /* 2 per glTF texture: colour, data */
    sy_blob **image_blobs;
    int32_t *parent;      /* per glTF node: parent index, -1 none */
    uint8_t *reached;     /* per glTF node: part of the loaded scene */
    uint32_t *mesh_triangles;
    sy_budget budget; /* the file's (sy_budget.h) */
    bool warned_skin, warned_morph, warned_anim;
} loader;

/* >>errors ------------------------------------------------------------------------------------ */

/* Sets L->err to "<path>: <message>" and returns code. */
static sy_result fail(loader *L, sy_result code, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
static sy_result fail(loader *L, sy_result code, const char *fmt, ...)
{
    char msg[SY_ERROR_MESSAGE_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return sy_error_set(&L->err, code, "%s: %s", L->path, msg);
}

static void warn(loader *L, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
static void warn(loader *L, const char *fmt, ...)
{
    sy_gltf_info *info = L->info;
    info->warning_count++;
    if (info->stored_warning_count >= SY_GLTF_MAX_WARNINGS) return;
    if (!info->warnings) {
        info->warnings = calloc(SY_GLTF_MAX_WARNINGS, sizeof(char *));
        if (!info->warnings) return;
    }
    char msg[SY_ERROR_MESSAGE_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    size_t n = strlen(msg) + 1;
    char *s = malloc(n);
    if (!s) return;
    memcpy(s, msg, n);
    info->warnings[info->stored_warning_count++] = s;
}

/* Adds context to an error that a core call left in L->err. */
static sy_result context(loader *L, sy_result r, const char *what)
{
    sy_error_prefix(&L->err, "%s: %s", L->path, what);
    return r;
}

static sy_result track(loader *L, sy_object_type type, uint32_t id)
{
    if (L->obj_count == L->obj_cap) {
        size_t cap = L->obj_cap ? L->obj_cap * 2 : 64, bytes;
        if (!sy_size_mul(cap, sizeof(created_obj), &bytes)) return fail(L, SY_ERR_OUT_OF_MEMORY, "too many objects");
        created_obj *n = realloc(L->objs, bytes);
        if (!n) return fail(L, SY_ERR_OUT_OF_MEMORY, "out of memory");
        L->objs = n;
        L->obj_cap = cap;
    }
    L->objs[L->obj_count++] = (created_obj){(uint32_t)type, id};
    return SY_OK;
}

static void rollback(loader *L)
{
    for (size_t i = L->obj_count; i-- > 0;)
        sy_object_destroy(L->scene, (sy_object_type)L->objs[i].type, L->objs[i].id, NULL);
    L->obj_count = 0;
}

static void *xcalloc(loader *L, size_t n, size_t size, sy_result *r)
{
    size_t bytes;
    if (!sy_size_mul(n, size, &bytes)) {
        *r = fail(L, SY_ERR_LIMIT, "allocation of %zu x %zu bytes overflows", n, size);
        return NULL;
    }
    void *p = calloc(bytes ? bytes : 1, 1);
    if (!p) *r = fail(L, SY_ERR_OUT_OF_MEMORY, "cannot allocate %zu bytes", bytes);
    return p;
}

static bool to_float(double d, float *out)
{
    if (!isfinite(d) || d > 3.4e38 || d < -3.4e38) return false;
    *out = (float)d;
    return true;
}

static const char *nonempty(const char *s) { return (s && s[0]) ? s : NULL; }

/* >>container --------------------------------------------------------------------------------- */

static uint32_t rd_u32(const uint8_t *p)
{
    uint8_t b[4];
    memcpy(b, p, 4);
    return (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
}

/* Validates the GLB header and chunk table; every bound is checked as a subtraction from what is
 * known to remain, so nothing can overflow. */
static sy_result check_glb(loader *L, const uint8_t *b, size_t size, const uint8_t **json, size_t *json_len)
{
    if (size < 12) return fail(L, SY_ERR_PARSE, "GLB header truncated: %zu bytes, need 12", size);
    uint32_t magic = rd_u32(b), version = rd_u32(b + 4), length = rd_u32(b + 8);
    if (magic != GLB_MAGIC)
        return fail(L, SY_ERR_PARSE, "not a GLB file: wrong magic 0x%08x (expected 'glTF')", (unsigned)magic);
    if (version != 2) return fail(L, SY_ERR_UNSUPPORTED, "GLB version %u is not supported (expected 2)", (unsigned)version);
    if ((size_t)length != size)
        return fail(L, SY_ERR_PARSE, "GLB total length %u does not equal the file size %zu", (unsigned)length, size);
    size_t off = 12;
    for (unsigned k = 0; off < size; k++) {
        size_t remaining = size - off;
        if (remaining < 8) return fail(L, SY_ERR_PARSE, "GLB chunk %u header truncated at byte %zu", k, off);
        uint32_t clen = rd_u32(b + off), ctype = rd_u32(b + off + 4);
        if ((size_t)clen > remaining - 8)
            return fail(L, SY_ERR_PARSE, "GLB chunk %u length %u exceeds the %zu bytes left in the file", k,
                        (unsigned)clen, remaining - 8);
        if (k == 0) {
            if (ctype != GLB_JSON)
                return fail(L, SY_ERR_PARSE, "GLB chunk 0 has type 0x%08x, expected JSON", (unsigned)ctype);
            if (clen == 0) return fail(L, SY_ERR_PARSE, "GLB JSON chunk is empty");
            *json = b + off + 8;
            *json_len = clen;
        } else if (k == 1) {
            if (ctype != GLB_BIN)
                return fail(L, SY_ERR_UNSUPPORTED, "GLB chunk 1 has type 0x%08x, expected BIN", (unsigned)ctype);
            if (clen % 4 != 0) return fail(L, SY_ERR_PARSE, "GLB BIN chunk length %u is not a multiple of 4", (unsigned)clen);
        } /* later chunks: ignored, as the specification requires */
        off += 8 + (size_t)clen;
    }
    if (!*json) return fail(L, SY_ERR_PARSE, "GLB has no JSON chunk");
    return SY_OK;
}

/* Rejects JSON nested deeper than the limit (the parser and tinygltf recurse on nesting). */
static sy_result check_json_depth(loader *L, const uint8_t *s, size_t n)
{
    uint32_t depth = 0;
    bool in_str = false;
    for (size_t i = 0; i < n; i++) {
        uint8_t c = s[i];
        if (in_str) {
            if (c == '\\') i++;
            else if (c == '"') in_str = false;
        } else if (c == '"') {
            in_str = true;
        } else if (c == '[' || c == '{') {
            if (++depth > L->opt.max_json_depth)
                return fail(L, SY_ERR_LIMIT, "JSON nesting deeper than %u at byte %zu", (unsigned)L->opt.max_json_depth, i);
        } else if ((c == ']' || c == '}') && depth > 0) {
            depth--;
        }
    }
    return SY_OK;
}

/* >>validation -------------------------------------------------------------------------------- */

static size_t component_size(int32_t ct)
{
    switch (ct) {
    case CT_BYTE: case CT_UBYTE: return 1;
    case CT_SHORT: case CT_USHORT: return 2;
    case CT_UINT: case CT_FLOAT: return 4;
    default: return 0;
    }
}

/* Size of one element, with the 4-byte column alignment of matrices. */
static size_t element_size(const sy_gltf_shim_accessor *a)
{
    size_t cs = component_size(a->component_type);
    if (!a->is_matrix) return cs * (size_t)a->components;
    size_t rows = a->components == 4 ? 2 : a->components == 9 ? 3 : 4;
    size_t col = (rows * cs + 3) & ~(size_t)3;
    return col * rows;
}

static size_t accessor_stride(const sy_gltf_doc *d, const sy_gltf_shim_accessor *a)
{
    size_t st = d->views[a->buffer_view].byte_stride;
    return st ? st : element_size(a);
}

static sy_result check_index(loader *L, int64_t idx, size_t count, bool optional, const char *what_fmt, size_t i,
                             const char *field, const char *target)
{
    if (idx == -1 && optional) return SY_OK;
    if (idx < 0 || (uint64_t)idx >= count) {
        char where[128];
        snprintf(where, sizeof where, what_fmt, i);
        return fail(L, SY_ERR_PARSE, "%s: %s %lld out of range (%zu %s)", where, field, (long long)idx, count, target);
    }
    return SY_OK;
}

static sy_result validate_views(loader *L)
{
    const sy_gltf_doc *d = L->doc;
    for (size_t i = 0; i < d->view_count; i++) {
        const sy_gltf_shim_view *v = &d->views[i];
        sy_result r = check_index(L, v->buffer, d->buffer_count, false, "bufferViews[%zu]", i, "buffer", "buffers");
        if (r) return r;
        size_t bsize = d->buffers[v->buffer].size;
        if (v->byte_offset > bsize || v->byte_length > bsize - v->byte_offset)
            return fail(L, SY_ERR_PARSE, "bufferViews[%zu]: byteOffset %zu + byteLength %zu exceeds buffer %d length %zu",
                        i, v->byte_offset, v->byte_length, (int)v->buffer, bsize);
        if (v->byte_stride != 0 && v->byte_stride < 4)
            return fail(L, SY_ERR_PARSE, "bufferViews[%zu]: byteStride %zu is less than 4", i, v->byte_stride);
    }
    return SY_OK;
}

static sy_result validate_accessor(loader *L, size_t i)
{
    const sy_gltf_doc *d = L->doc;
    const sy_gltf_shim_accessor *a = &d->accessors[i];
    size_t cs = component_size(a->component_type);
    if (cs == 0) return fail(L, SY_ERR_PARSE, "accessors[%zu]: componentType %d is not a glTF 2.0 type", i, (int)a->component_type);
    if (a->components <= 0) return fail(L, SY_ERR_PARSE, "accessors[%zu]: unknown type", i);
    if (a->count == 0) return fail(L, SY_ERR_PARSE, "accessors[%zu]: count is 0 (minimum 1)", i);
    size_t elem = element_size(a);
    sy_result r = check_index(L, a->buffer_view, d->view_count, true, "accessors[%zu]", i, "bufferView", "bufferViews");
    if (r) return r;
    if (a->buffer_view >= 0) {
        const sy_gltf_shim_view *v = &d->views[a->buffer_view];
        if (v->byte_stride != 0 && v->byte_stride < elem)
            return fail(L, SY_ERR_PARSE, "accessors[%zu]: byteStride %zu of bufferView %d is smaller than the element size %zu",
                        i, v->byte_stride, (int)a->buffer_view, elem);
        size_t stride = accessor_stride(d, a), need;
        if (!sy_size_mad(stride, a->count - 1, elem, &need) || !sy_size_add(need, a->byte_offset, &need) ||
            need > v->byte_length)
            return fail(L, SY_ERR_PARSE,
                        "accessors[%zu]: byteOffset %zu + count %zu * stride %zu exceeds bufferView %d length %zu", i,
                        a->byte_offset, a->count, stride, (int)a->buffer_view, v->byte_length);
    }
    if (a->sparse) {
        if (a->sparse_count < 1 || (size_t)a->sparse_count > a->count)
            return fail(L, SY_ERR_PARSE, "accessors[%zu]: sparse count %d not in 1..%zu", i, (int)a->sparse_count, a->count);
        size_t sc = (size_t)a->sparse_count;
        size_t isz = a->sparse_indices_type == CT_UBYTE ? 1 : a->sparse_indices_type == CT_USHORT ? 2
                   : a->sparse_indices_type == CT_UINT ? 4 : 0;
        if (isz == 0)
            return fail(L, SY_ERR_PARSE, "accessors[%zu]: sparse indices componentType %d is not an unsigned integer type",
                        i, (int)a->sparse_indices_type);
        const struct { int32_t view, offset; size_t esize; const char *name; } parts[2] = {
            {a->sparse_indices_view, a->sparse_indices_offset, isz, "indices"},
            {a->sparse_values_view, a->sparse_values_offset, elem, "values"},
        };
        for (int k = 0; k < 2; k++) {
            char what[64];
            snprintf(what, sizeof what, "accessors[%%zu].sparse.%s", parts[k].name);
            r = check_index(L, parts[k].view, d->view_count, false, what, i, "bufferView", "bufferViews");
            if (r) return r;
            size_t need;
            const sy_gltf_shim_view *v = &d->views[parts[k].view];
            if (parts[k].offset < 0 || !sy_size_mad(sc, parts[k].esize, (size_t)parts[k].offset, &need) ||
                need > v->byte_length)
                return fail(L, SY_ERR_PARSE, "accessors[%zu].sparse.%s: byteOffset %d + count %zu * %zu bytes exceeds bufferView %d length %zu",
                            i, parts[k].name, (int)parts[k].offset, sc, parts[k].esize, (int)parts[k].view, v->byte_length);
        }
    }
    return SY_OK;
}

static sy_result validate_texinfo(loader *L, const sy_gltf_shim_texinfo *t, size_t mi, const char *slot)
{
    if (t->index == -1) return SY_OK;
    if (t->index < 0 || (size_t)t->index >= L->doc->texture_count)
        return fail(L, SY_ERR_PARSE, "materials[%zu].%s: texture %d out of range (%zu textures)", mi, slot, (int)t->index,
                    L->doc->texture_count);
    return SY_OK;
}

static bool all_finite(const double *v, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!isfinite(v[i]) || fabs(v[i]) > 3.4e38) return false;
    return true;
}

static sy_result validate_nodes(loader *L)
{
    const sy_gltf_doc *d = L->doc;
    sy_result r;
    for (size_t i = 0; i < d->node_count; i++) {
        const sy_gltf_shim_node *n = &d->nodes[i];
        if ((r = check_index(L, n->mesh, d->mesh_count, true, "nodes[%zu]", i, "mesh", "meshes")) ||
            (r = check_index(L, n->camera, d->camera_count, true, "nodes[%zu]", i, "camera", "cameras")) ||
            (r = check_index(L, n->light, d->light_count, true, "nodes[%zu]", i, "KHR_lights_punctual light", "lights")) ||
            (r = check_index(L, n->skin, d->skin_count, true, "nodes[%zu]", i, "skin", "skins")))
            return r;
        if (n->matrix_count != 0 && n->matrix_count != 16)
            return fail(L, SY_ERR_PARSE, "nodes[%zu]: matrix has %zu elements (expected 16)", i, n->matrix_count);
        if (n->translation_count != 0 && n->translation_count != 3)
            return fail(L, SY_ERR_PARSE, "nodes[%zu]: translation has %zu elements (expected 3)", i, n->translation_count);
        if (n->rotation_count != 0 && n->rotation_count != 4)
            return fail(L, SY_ERR_PARSE, "nodes[%zu]: rotation has %zu elements (expected 4)", i, n->rotation_count);
        if (n->scale_count != 0 && n->scale_count != 3)
            return fail(L, SY_ERR_PARSE, "nodes[%zu]: scale has %zu elements (expected 3)", i, n->scale_count);
        if (!all_finite(n->matrix, n->matrix_count) || !all_finite(n->translation, n->translation_count) ||
            !all_finite(n->rotation, n->rotation_count) || !all_finite(n->scale, n->scale_count))
            return fail(L, SY_ERR_PARSE, "nodes[%zu]: non-finite transform value", i);
        if (n->instancing) {
            if (n->mesh < 0) return fail(L, SY_ERR_PARSE, "nodes[%zu]: EXT_mesh_gpu_instancing without a mesh", i);
            const int32_t acc[3] = {n->inst_translation, n->inst_rotation, n->inst_scale};
            const int32_t comps[3] = {3, 4, 3};
            const char *names[3] = {"TRANSLATION", "ROTATION", "SCALE"};
            size_t count = 0;
            for (int k = 0; k < 3; k++) {
                if (acc[k] == -1) continue;
                if ((r = check_index(L, acc[k], d->accessor_count, false, "nodes[%zu].EXT_mesh_gpu_instancing", i, names[k], "accessors")))
                    return r;
                const sy_gltf_shim_accessor *a = &d->accessors[acc[k]];
                if (a->components != comps[k] || a->is_matrix)
                    return fail(L, SY_ERR_PARSE, "nodes[%zu].EXT_mesh_gpu_instancing: %s accessor %d must have %d components", i,
                                names[k], (int)acc[k], (int)comps[k]);
                if (count && a->count != count)
                    return fail(L, SY_ERR_PARSE, "nodes[%zu].EXT_mesh_gpu_instancing: accessor counts differ (%zu and %zu)", i,
                                count, a->count);
                count = a->count;
            }
            if (count == 0) return fail(L, SY_ERR_PARSE, "nodes[%zu].EXT_mesh_gpu_instancing: no attributes", i);
            if (count > L->opt.max_instances)
                return fail(L, SY_ERR_LIMIT, "nodes[%zu].EXT_mesh_gpu_instancing: %zu instances exceed the limit of %zu", i,
                            count, L->opt.max_instances);
        }
        for (size_t c = 0; c < n->child_count; c++) {
            int32_t ch = n->children[c];
            if (ch < 0 || (size_t)ch >= d->node_count)
                return fail(L, SY_ERR_PARSE, "nodes[%zu].children[%zu]: node %d out of range (%zu nodes)", i, c, (int)ch,
                            d->node_count);
            if (L->parent[ch] != -1)
                return fail(L, SY_ERR_PARSE, "nodes[%d] has two parents (nodes[%d] and nodes[%zu]): the node graph must be a forest",
                            (int)ch, (int)L->parent[ch], i);
            L->parent[ch] = (int32_t)i;
        }
    }
    /* With at most one parent per node, a cycle is a parent chain that returns to itself. Walk each
     * chain once, stamping nodes with the walk's id: O(nodes). */
    size_t nbytes;
    if (!sy_size_mul(d->node_count + 1, sizeof(uint32_t), &nbytes)) return fail(L, SY_ERR_LIMIT, "too many nodes");
    uint32_t *stamp = calloc(d->node_count + 1, sizeof(uint32_t));
    if (!stamp) return fail(L, SY_ERR_OUT_OF_MEMORY, "out of memory");
    for (size_t i = 0; i < d->node_count; i++) {
        int32_t k = (int32_t)i;
        while (k != -1 && stamp[k] == 0) {
            stamp[k] = (uint32_t)i + 1;
            k = L->parent[k];
        }
        if (k != -1 && stamp[k] == (uint32_t)i + 1) {
            free(stamp);
            return fail(L, SY_ERR_PARSE, "nodes[%d] is part of a cycle in the node hierarchy", (int)k);
        }
    }
    free(stamp);
    return SY_OK;
}

static sy_result validate_doc(loader *L)
{
    const sy_gltf_doc *d = L->doc;
    sy_result r;
    for (size_t i = 0; i < d->extensions_required_count; i++) {
        const char *e = d->extensions_required[i];
        bool ok = false;
        for (size_t k = 0; k_supported[k]; k++) ok = ok || strcmp(e, k_supported[k]) == 0;
        if (!ok)
            return fail(L, SY_ERR_UNSUPPORTED,
                        "extensionsRequired: '%s' is not supported (supported: KHR_materials_emissive_strength, "
                        "KHR_materials_transmission, KHR_materials_ior, KHR_materials_unlit, KHR_texture_transform, "
                        "KHR_lights_punctual, KHR_mesh_quantization, EXT_mesh_gpu_instancing)", e);
    }
    if ((r = validate_views(L))) return r;
    for (size_t i = 0; i < d->accessor_count; i++)
        if ((r = validate_accessor(L, i))) return r;
    for (size_t m = 0; m < d->mesh_count; m++) {
        for (size_t p = 0; p < d->meshes[m].primitive_count; p++) {
            const sy_gltf_shim_primitive *pr = &d->meshes[m].primitives[p];
            char where[96];
            snprintf(where, sizeof where, "meshes[%zu].primitives[%%zu]", m);
            if (pr->mode < 0 || pr->mode > GLTF_TRIANGLE_FAN)
                return fail(L, SY_ERR_PARSE, "meshes[%zu].primitives[%zu]: mode %d is not a glTF primitive mode", m, p, (int)pr->mode);
            const int32_t attrs[6] = {pr->position, pr->normal, pr->tangent, pr->texcoord0, pr->texcoord1, pr->color0};
            const char *names[6] = {"POSITION", "NORMAL", "TANGENT", "TEXCOORD_0", "TEXCOORD_1", "COLOR_0"};
            for (int k = 0; k < 6; k++)
                if ((r = check_index(L, attrs[k], d->accessor_count, true, where, p, names[k], "accessors"))) return r;
            if ((r = check_index(L, pr->indices, d->accessor_count, true, where, p, "indices", "accessors")) ||
                (r = check_index(L, pr->material, d->material_count, true, where, p, "material", "materials")))
                return r;
        }
    }
    for (size_t i = 0; i < d->material_count; i++) {
        const sy_gltf_shim_material *m = &d->materials[i];
        if ((r = validate_texinfo(L, &m->base_color_texture, i, "baseColorTexture")) ||
            (r = validate_texinfo(L, &m->metallic_roughness_texture, i, "metallicRoughnessTexture")) ||
            (r = validate_texinfo(L, &m->normal_texture, i, "normalTexture")) ||
            (r = validate_texinfo(L, &m->occlusion_texture, i, "occlusionTexture")) ||
            (r = validate_texinfo(L, &m->emissive_texture, i, "emissiveTexture")) ||
            (r = validate_texinfo(L, &m->transmission_texture, i, "transmissionTexture")))
            return r;
        if (strcmp(m->alpha_mode, "OPAQUE") && strcmp(m->alpha_mode, "MASK") && strcmp(m->alpha_mode, "BLEND"))
            return fail(L, SY_ERR_PARSE, "materials[%zu]: alphaMode '%s' is not OPAQUE, MASK or BLEND", i, m->alpha_mode);
        if ((m->base_color_count != 0 && m->base_color_count != 4) || (m->emissive_count != 0 && m->emissive_count != 3))
            return fail(L, SY_ERR_PARSE, "materials[%zu]: baseColorFactor needs 4 and emissiveFactor 3 numbers", i);
    }
    for (size_t i = 0; i < d->texture_count; i++) {
        if ((r = check_index(L, d->textures[i].source, d->image_count, true, "textures[%zu]", i, "source", "images")) ||
            (r = check_index(L, d->textures[i].sampler, d->sampler_count, true, "textures[%zu]", i, "sampler", "samplers")))
            return r;
    }
    for (size_t i = 0; i < d->image_count; i++) { /* a bad image is local: its textures go missing */
        const sy_gltf_shim_image *im = &d->images[i];
        if (!im->pixels) {
            if (im->uri[0]) warn(L, "images[%zu] ('%s'): %s; textures using it are missing", i, im->uri, im->problem);
            else warn(L, "images[%zu]: %s; textures using it are missing", i, im->problem);
        }
    }
    for (size_t i = 0; i < d->camera_count; i++) {
        const sy_gltf_shim_camera *c = &d->cameras[i];
        if (!strcmp(c->type, "perspective")) {
            if (!(isfinite(c->yfov) && c->yfov > 0 && c->yfov < SY_GLTF_PI))
                return fail(L, SY_ERR_PARSE, "cameras[%zu]: yfov %g is not in (0, pi)", i, c->yfov);
            if (!(isfinite(c->znear) && c->znear > 0))
                return fail(L, SY_ERR_PARSE, "cameras[%zu]: znear %g must be > 0", i, c->znear);
            if (!(isfinite(c->zfar) && (c->zfar == 0 || c->zfar > c->znear)))
                return fail(L, SY_ERR_PARSE, "cameras[%zu]: zfar %g must be > znear %g", i, c->zfar, c->znear);
            if (!(isfinite(c->aspect) && c->aspect >= 0))
                return fail(L, SY_ERR_PARSE, "cameras[%zu]: aspectRatio %g must be > 0", i, c->aspect);
        } else if (!strcmp(c->type, "orthographic")) {
            if (!(isfinite(c->xmag) && isfinite(c->ymag) && c->xmag != 0 && c->ymag != 0))
                return fail(L, SY_ERR_PARSE, "cameras[%zu]: xmag %g / ymag %g must be finite and non-zero", i, c->xmag, c->ymag);
            if (!(isfinite(c->oznear) && isfinite(c->ozfar) && c->oznear >= 0 && c->ozfar > c->oznear))
                return fail(L, SY_ERR_PARSE, "cameras[%zu]: orthographic zfar %g must be > znear %g >= 0", i, c->ozfar, c->oznear);
        } else {
            return fail(L, SY_ERR_PARSE, "cameras[%zu]: type '%s' is not perspective or orthographic", i, c->type);
        }
    }
    for (size_t i = 0; i < d->light_count; i++) {
        const sy_gltf_shim_light *l = &d->lights[i];
        if (strcmp(l->type, "point") && strcmp(l->type, "spot") && strcmp(l->type, "directional"))
            return fail(L, SY_ERR_PARSE, "KHR_lights_punctual.lights[%zu]: type '%s' is not point, spot or directional", i, l->type);
        if ((l->color_count != 0 && l->color_count != 3) || !all_finite(l->color, 3) || l->color[0] < 0 ||
            l->color[1] < 0 || l->color[2] < 0)
            return fail(L, SY_ERR_PARSE, "KHR_lights_punctual.lights[%zu]: color must be 3 finite values >= 0", i);
        if (!isfinite(l->intensity) || l->intensity < 0)
            return fail(L, SY_ERR_PARSE, "KHR_lights_punctual.lights[%zu]: intensity %g must be finite and >= 0", i,
                        l->intensity);
        if (!isfinite(l->range) || l->range < 0)
            return fail(L, SY_ERR_PARSE, "KHR_lights_punctual.lights[%zu]: range %g must be finite and >= 0", i, l->range);
        if (!isfinite(l->inner_cone) || !isfinite(l->outer_cone))
            return fail(L, SY_ERR_PARSE, "KHR_lights_punctual.lights[%zu]: spot cone angles must be finite", i);
    }
    if ((r = validate_nodes(L))) return r;
    for (size_t s = 0; s < d->scene_count; s++) {
        const sy_gltf_shim_scene *sc = &d->scenes[s];
        for (size_t k = 0; k < sc->node_count; k++) {
            int32_t n = sc->nodes[k];
            if (n < 0 || (size_t)n >= d->node_count)
                return fail(L, SY_ERR_PARSE, "scenes[%zu].nodes[%zu]: node %d out of range (%zu nodes)", s, k, (int)n, d->node_count);
            if (L->parent[n] != -1)
                return fail(L, SY_ERR_PARSE, "scenes[%zu].nodes[%zu]: nodes[%d] is not a root node (it is a child of nodes[%d])", s,
                            k, (int)n, (int)L->parent[n]);
            for (size_t j = 0; j < k; j++)
                if (sc->nodes[j] == n)
                    return fail(L, SY_ERR_PARSE, "scenes[%zu].nodes: nodes[%d] is listed twice as a root", s, (int)n);
        }
    }
    if (d->default_scene != -1 && (d->default_scene < 0 || (size_t)d->default_scene >= d->scene_count))
        return fail(L, SY_ERR_PARSE, "scene %d out of range (%zu scenes)", (int)d->default_scene, d->scene_count);
    return SY_OK;
}

/* >>accessors --------------------------------------------------------------------------------- */

static float load_component(const uint8_t *p, int32_t ct, bool normalized)
{
    switch (ct) {
    case CT_FLOAT: { float f; memcpy(&f, p, 4); return f; }
    case CT_UBYTE: return normalized ? (float)p[0] / 255.0f : (float)p[0];
    case CT_BYTE: { int8_t v; memcpy(&v, p, 1); return normalized ? fmaxf((float)v / 127.0f, -1.0f) : (float)v; }
    case CT_USHORT: { uint16_t v; memcpy(&v, p, 2); return normalized ? (float)v / 65535.0f : (float)v; }
    case CT_SHORT: { int16_t v; memcpy(&v, p, 2); return normalized ? fmaxf((float)v / 32767.0f, -1.0f) : (float)v; }
    case CT_UINT: { uint32_t v; memcpy(&v, p, 4); return normalized ? (float)((double)v / 4294967295.0) : (float)v; }
    default: return 0.0f;
    }
}

static uint32_t load_uint(const uint8_t *p, int32_t ct)
{
    switch (ct) {
    case CT_UBYTE: return p[0];
    case CT_USHORT: { uint16_t v; memcpy(&v, p, 2); return v; }
    case CT_UINT: { uint32_t v; memcpy(&v, p, 4); return v; }
    default: return UINT32_MAX;
    }
}

/* Pointer to element i of the accessor's own data, NULL when it has no bufferView (zeros). Bounds
 * were checked by validate_accessor. */
static const uint8_t *element_ptr(const sy_gltf_doc *d, const sy_gltf_shim_accessor *a, size_t i)
{
    if (a->buffer_view < 0) return NULL;
    const sy_gltf_shim_view *v = &d->views[a->buffer_view];
    return d->buffers[v->buffer].data + v->byte_offset + a->byte_offset + i * accessor_stride(d, a);
}

/* Sparse substitution: calls back with (target element, pointer to the replacement). */
static sy_result sparse_index(loader *L, size_t ai, size_t k, size_t *target)
{
    const sy_gltf_doc *d = L->doc;
    const sy_gltf_shim_accessor *a = &d->accessors[ai];
    const sy_gltf_shim_view *iv = &d->views[a->sparse_indices_view];
    size_t isz = component_size(a->sparse_indices_type);
    const uint8_t *ip = d->buffers[iv->buffer].data + iv->byte_offset + (size_t)a->sparse_indices_offset + k * isz;
    uint32_t idx = load_uint(ip, a->sparse_indices_type);
    if ((size_t)idx >= a->count)
        return fail(L, SY_ERR_PARSE, "accessors[%zu].sparse.indices[%zu]: index %u >= accessor count %zu", ai, k, (unsigned)idx, a->count);
    *target = idx;
    return SY_OK;
}

static const uint8_t *sparse_value_ptr(const sy_gltf_doc *d, const sy_gltf_shim_accessor *a, size_t k)
{
    const sy_gltf_shim_view *vv = &d->views[a->sparse_values_view];
    return d->buffers[vv->buffer].data + vv->byte_offset + (size_t)a->sparse_values_offset + k * element_size(a);
}

/* Reads accessor ai as floats, out_comps per element (missing components: 0, except a 4th = 1).
 * *out is malloc()ed, count * out_comps floats. */
static sy_result read_floats(loader *L, size_t ai, size_t out_comps, float **out)
{
    const sy_gltf_doc *d = L->doc;
    const sy_gltf_shim_accessor *a = &d->accessors[ai];
    sy_result r = SY_OK;
    *out = NULL;
    size_t n;
    if (!sy_size_mul(a->count, out_comps, &n)) return fail(L, SY_ERR_LIMIT, "accessors[%zu]: count %zu overflows", ai, a->count);
    float *f = xcalloc(L, n, sizeof(float), &r);
    if (!f) return r;
    size_t comps = (size_t)a->components < out_comps ? (size_t)a->components : out_comps;
    size_t cs = component_size(a->component_type);
    bool norm = a->normalized != 0;
    for (size_t i = 0; i < a->count; i++) {
        float *dst = f + i * out_comps;
        const uint8_t *p = element_ptr(d, a, i);
        for (size_t c = 0; c < comps; c++) dst[c] = p ? load_component(p + c * cs, a->component_type, norm) : 0.0f;
        if (out_comps == 4 && comps < 4) dst[3] = 1.0f;
    }
    if (a->sparse) {
        for (size_t k = 0; k < (size_t)a->sparse_count; k++) {
            size_t t;
            if ((r = sparse_index(L, ai, k, &t))) {
                free(f);
                return r;
            }
            const uint8_t *p = sparse_value_ptr(d, a, k);
            for (size_t c = 0; c < comps; c++) f[t * out_comps + c] = load_component(p + c * cs, a->component_type, norm);
        }
    }
    *out = f;
    return SY_OK;
}

/* Element i of accessor ai (i < count) as out_comps floats, sparse substitution applied; allocates
 * nothing (for accessors whose count is bounded by no limit, such as animation outputs). */
static sy_result read_element(loader *L, size_t ai, size_t i, size_t out_comps, float *dst)
{
    const sy_gltf_doc *d = L->doc;
    const sy_gltf_shim_accessor *a = &d->accessors[ai];
    size_t comps = (size_t)a->components < out_comps ? (size_t)a->components : out_comps;
    size_t cs = component_size(a->component_type);
    bool norm = a->normalized != 0;
    const uint8_t *p = element_ptr(d, a, i);
    for (size_t c = 0; c < out_comps; c++) dst[c] = c < comps && p ? load_component(p + c * cs, a->component_type, norm) : 0.0f;
    if (out_comps == 4 && comps < 4) dst[3] = 1.0f;
    if (a->sparse) {
        for (size_t k = 0; k < (size_t)a->sparse_count; k++) {
            size_t t;
            sy_result r = sparse_index(L, ai, k, &t);
            if (r) return r;
            if (t != i) continue;
            const uint8_t *q = sparse_value_ptr(d, a, k);
            for (size_t c = 0; c < comps; c++) dst[c] = load_component(q + c * cs, a->component_type, norm);
        }
    }
    return SY_OK;
}

static sy_result read_uints(loader *L, size_t ai, uint32_t **out)
{
    const sy_gltf_doc *d = L->doc;
    const sy_gltf_shim_accessor *a = &d->accessors[ai];
    sy_result r = SY_OK;
    *out = NULL;
    uint32_t *u = xcalloc(L, a->count, sizeof(uint32_t), &r);
    if (!u) return r;
    for (size_t i = 0; i < a->count; i++) {
        const uint8_t *p = element_ptr(d, a, i);
        u[i] = p ? load_uint(p, a->component_type) : 0;
    }
    if (a->sparse) {
        for (size_t k = 0; k < (size_t)a->sparse_count; k++) {
            size_t t;
            if ((r = sparse_index(L, ai, k, &t))) {
                free(u);
                return r;
            }
            u[t] = load_uint(sparse_value_ptr(d, a, k), a->component_type);
        }
    }
    *out = u;
    return SY_OK;
}

/* >>textures+materials ------------------------------------------------------------------------ */

static uint32_t map_wrap(loader *L, int32_t w, size_t si)
{
    switch (w) {
    case 10497: return SY_WRAP_REPEAT;
    case 33071: return SY_WRAP_CLAMP;
    case 33648: return SY_WRAP_MIRROR;
    default: warn(L, "samplers[%zu]: unknown wrap mode %d, using REPEAT", si, (int)w); return SY_WRAP_REPEAT;
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
    if (!to_float(ti->scale, &ref->scale)) return fail(L, SY_ERR_PARSE, "materials[%zu].%s: non-finite scale", mi, slot);
    if (ti->index < 0) return SY_OK;
    int32_t tc = ti->has_transform && ti->transform_texcoord >= 0 ? ti->transform_texcoord : ti->texcoord;
    if (tc < 0 || tc > 1) {
        warn(L, "materials[%zu].%s: texCoord %d not supported, using 0", mi, slot, (int)tc);
        tc = 0;
    }
    ref->texcoord = (uint32_t)tc;
    if (ti->has_transform) {
        if (!to_float(ti->offset[0], &ref->offset[0]) || !to_float(ti->offset[1], &ref->offset[1]) ||
            !to_float(ti->rotation, &ref->rotation) || !to_float(ti->uv_scale[0], &ref->uv_scale[0]) ||
            !to_float(ti->uv_scale[1], &ref->uv_scale[1]))
            return fail(L, SY_ERR_PARSE, "materials[%zu].%s: non-finite KHR_texture_transform value", mi, slot);
    }
    size_t t = (size_t)ti->index;
    sy_texture *slot_handle = &L->textures[t * 2 + (size_t)role];
    if (slot_handle->id == 0) {
        const sy_gltf_shim_texture *tex = &d->textures[t];
        if (tex->source < 0) {
            warn(L, "textures[%zu] has no image source; ignored", t);
            return SY_OK;
        }
        const sy_gltf_shim_image *im = &d->images[tex->source];
        if (!im->pixels) return SY_OK; /* warned in validate_doc */
        sy_result r;
        if (!L->image_blobs[tex->source]) {
            size_t bytes = (size_t)im->width * im->height * im->channels; /* fits: the shim allocated it */
            if ((r = sy_blob_create_copy(im->pixels, bytes, &L->image_blobs[tex->source], &L->err)))
                return context(L, r, "images");
        }
        const char *name = nonempty(tex->name) ? tex->name : nonempty(im->name);
        sy_texture h;
        if ((r = sy_texture_create(L->scene, name, &h, &L->err))) return context(L, r, "textures");
        if ((r = track(L, SY_TYPE_TEXTURE, h.id))) {
            sy_object_destroy(L->scene, SY_TYPE_TEXTURE, h.id, NULL);
            return r;
        }
        sy_image_info info = {im->width, im->height, im->channels,
                              role == ROLE_COLOR ? SY_PIXEL_U8_SRGB : SY_PIXEL_U8_LINEAR};
        if ((r = sy_texture_set_image(L->scene, h, &info, L->image_blobs[tex->source], &L->err)))
            return context(L, r, "textures");
        sy_sampler smp = {SY_WRAP_REPEAT, SY_WRAP_REPEAT, SY_FILTER_LINEAR, SY_FILTER_LINEAR};
        if (tex->sampler >= 0) {
            const sy_gltf_shim_sampler *s = &d->samplers[tex->sampler];
            smp.wrap_s = map_wrap(L, s->wrap_s, (size_t)tex->sampler);
            smp.wrap_t = map_wrap(L, s->wrap_t, (size_t)tex->sampler);
            smp.min_filter = map_filter(s->min_filter);
            smp.mag_filter = map_filter(s->mag_filter);
        }
        if ((r = sy_texture_set_sampler(L->scene, h, &smp, &L->err))) return context(L, r, "textures");
        *slot_handle = h;
    }
    ref->texture = *slot_handle;
    return SY_OK;
}

static sy_result create_material(loader *L, size_t i)
{
    const sy_gltf_shim_material *m = &L->doc->materials[i];
    sy_material_data md = *(const sy_material_data *)sy_object_defaults(SY_TYPE_MATERIAL);
    md.name = (char *)nonempty(m->name);
    bool ok = true;
    for (int k = 0; k < 4; k++) ok = ok && to_float(m->base_color[k], &md.base_color[k]);
    for (int k = 0; k < 3; k++) ok = ok && to_float(m->emissive[k], &md.emissive[k]);
    ok = ok && to_float(m->metallic, &md.metallic) && to_float(m->roughness, &md.roughness) &&
         to_float(m->emissive_strength, &md.emissive_strength) && to_float(m->alpha_cutoff, &md.alpha_cutoff) &&
         to_float(m->transmission, &md.transmission) && to_float(m->ior, &md.ior);
    if (!ok) return fail(L, SY_ERR_PARSE, "materials[%zu]: non-finite factor", i);
    sy_result r;
    if ((r = get_texture(L, &m->base_color_texture, ROLE_COLOR, i, "baseColorTexture", &md.base_color_texture)) ||
        (r = get_texture(L, &m->metallic_roughness_texture, ROLE_DATA, i, "metallicRoughnessTexture",
                         &md.metallic_roughness_texture)) ||
        (r = get_texture(L, &m->normal_texture, ROLE_DATA, i, "normalTexture", &md.normal_texture)) ||
        (r = get_texture(L, &m->occlusion_texture, ROLE_DATA, i, "occlusionTexture", &md.occlusion_texture)) ||
        (r = get_texture(L, &m->emissive_texture, ROLE_COLOR, i, "emissiveTexture", &md.emissive_texture)) ||
        (r = get_texture(L, &m->transmission_texture, ROLE_DATA, i, "transmissionTexture", &md.transmission_texture)))
        return r;
    md.alpha_mode = !strcmp(m->alpha_mode, "MASK") ? SY_ALPHA_MASK : !strcmp(m->alpha_mode, "BLEND") ? SY_ALPHA_BLEND
                                                                                                    : SY_ALPHA_OPAQUE;
    md.double_sided = m->double_sided ? 1u : 0u;
    md.unlit = m->unlit ? 1u : 0u;
    sy_material h;
    char where[48];
    snprintf(where, sizeof where, "materials[%zu]", i);
    if ((r = sy_material_create(L->scene, md.name, &h, &L->err))) return context(L, r, where);
    if ((r = track(L, SY_TYPE_MATERIAL, h.id))) {
        sy_object_destroy(L->scene, SY_TYPE_MATERIAL, h.id, NULL);
        return r;
    }
    if ((r = sy_material_set(L->scene, h, &md, &L->err))) return context(L, r, where);
    L->materials[i] = h;
    return SY_OK;
}

/* >>meshes ------------------------------------------------------------------------------------ */

/* Takes ownership of data (freed on failure too). */
static sy_result make_blob(loader *L, void *data, size_t bytes, sy_blob **out)
{
    sy_result r = sy_blob_create_take(data, bytes, out, &L->err);
    if (r) {
        free(data);
        return context(L, r, "blob");
    }
    return SY_OK;
}

static const char *mode_name(int32_t mode)
{
    static const char *const names[] = {"POINTS", "LINES", "LINE_LOOP", "LINE_STRIP"};
    return (mode >= 0 && mode <= GLTF_LINE_STRIP) ? names[mode] : "?";
}

/* Reads an attribute into a blob. comps: output components. */
static sy_result read_attribute(loader *L, int32_t ai, size_t vcount, size_t comps, size_t m, size_t p,
                                const char *name, sy_blob **out)
{
    *out = NULL;
    if (ai < 0) return SY_OK;
    const sy_gltf_shim_accessor *a = &L->doc->accessors[ai];
    bool type_ok = !a->is_matrix && ((size_t)a->components == comps ||
                                     (!strcmp(name, "COLOR_0") && a->components == 3));
    if (!type_ok)
        return fail(L, SY_ERR_PARSE, "meshes[%zu].primitives[%zu]: %s accessor %d has %d components, expected %zu", m, p, name,
                    (int)ai, (int)a->components, comps);
    if (a->count != vcount)
        return fail(L, SY_ERR_PARSE, "meshes[%zu].primitives[%zu]: %s accessor %d count %zu differs from POSITION count %zu", m,
                    p, name, (int)ai, a->count, vcount);
    float *f;
    sy_result r = read_floats(L, (size_t)ai, comps, &f);
    if (r) return r;
    size_t n = vcount * comps; /* read_floats checked the product */
    bool is_pos = !strcmp(name, "POSITION");
    bool fixed = false;
    for (size_t k = 0; k < n; k++) {
        if (isfinite(f[k])) continue;
        if (is_pos) {
            free(f);
            return fail(L, SY_ERR_PARSE, "accessors[%d] (POSITION of meshes[%zu].primitives[%zu]): non-finite value in vertex %zu",
                        (int)ai, m, p, k / comps);
        }
        f[k] = 0.0f;
        fixed = true;
    }
    if (fixed) warn(L, "accessors[%d] (%s of meshes[%zu].primitives[%zu]): non-finite values replaced by 0", (int)ai, name, m, p);
    return make_blob(L, f, n * sizeof(float), out);
}

static uint32_t add_sat(uint32_t a, uint32_t b) { return a > UINT32_MAX - b ? UINT32_MAX : a + b; }

static sy_result read_all_attributes(loader *L, const sy_gltf_shim_primitive *pr, size_t vcount, size_t m, size_t p,
                                     sy_primitive *out)
{
    sy_result r;
    if ((r = read_attribute(L, pr->position, vcount, 3, m, p, "POSITION", &out->positions)) ||
        (r = read_attribute(L, pr->normal, vcount, 3, m, p, "NORMAL", &out->normals)) ||
        (r = read_attribute(L, pr->tangent, vcount, 4, m, p, "TANGENT", &out->tangents)) ||
        (r = read_attribute(L, pr->texcoord0, vcount, 2, m, p, "TEXCOORD_0", &out->texcoords0)) ||
        (r = read_attribute(L, pr->texcoord1, vcount, 2, m, p, "TEXCOORD_1", &out->texcoords1)) ||
        (r = read_attribute(L, pr->color0, vcount, 4, m, p, "COLOR_0", &out->colors)))
        sy_primitive_release(out);
    return r;
}

/* POINTS, LINES, LINE_LOOP, LINE_STRIP: point and line primitives (loops and strips expanded to
 * index pairs). Takes ownership of idx (icount indices, or NULL: the vertices in order). Strokes
 * are drawn as tubes and balls with their own normals (sy_scene.h), so no flat normals are made. */
static sy_result convert_stroke(loader *L, size_t m, size_t p, sy_primitive *out, bool *used, uint32_t *idx,
                                size_t icount, size_t vcount)
{
    const sy_gltf_shim_primitive *pr = &L->doc->meshes[m].primitives[p];
    sy_result r = SY_OK;
    uint32_t *pairs = NULL;
    size_t elements = 0;
    if (pr->mode == GLTF_POINTS) {
        elements = icount;
        pairs = idx; /* NULL: non-indexed points */
        idx = NULL;
    } else if (pr->mode == GLTF_LINES) {
        elements = icount / 2;
        if (icount % 2)
            warn(L, "meshes[%zu].primitives[%zu]: LINES with %zu %s (odd); the last one ignored", m, p, icount,
                 idx ? "indices" : "vertices");
        if (idx) {
            pairs = idx;
            idx = NULL;
        } else if (icount % 2 && elements) {
            if (!(pairs = xcalloc(L, elements * 2, sizeof(uint32_t), &r))) return r;
            for (size_t k = 0; k < elements * 2; k++) pairs[k] = (uint32_t)k;
        }
    } else { /* LINE_LOOP closes back to the first vertex; LINE_STRIP does not */
        bool loop = pr->mode == GLTF_LINE_LOOP;
        elements = icount >= 2 ? icount - 1 + (loop && icount >= 3) : 0;
        if (elements > L->opt.max_indices / 2) {
            free(idx);
            return fail(L, SY_ERR_LIMIT, "meshes[%zu].primitives[%zu]: %zu line segments exceed the index limit of %zu", m,
                        p, elements, L->opt.max_indices);
        }
        if (elements && !(pairs = xcalloc(L, elements * 2, sizeof(uint32_t), &r))) {
            free(idx);
            return r;
        }
        for (size_t k = 0; k < elements; k++) {
            size_t a = k, b = (k + 1) % icount;
            pairs[2 * k] = idx ? idx[a] : (uint32_t)a;
            pairs[2 * k + 1] = idx ? idx[b] : (uint32_t)b;
        }
        free(idx);
        idx = NULL;
    }
    free(idx);
    if (elements == 0) {
        free(pairs);
        warn(L, "meshes[%zu].primitives[%zu]: %s without a complete %s; skipped", m, p, mode_name(pr->mode),
             pr->mode == GLTF_POINTS ? "point" : "segment");
        L->info->counts.skipped_primitives++;
        return SY_OK;
    }
    if (elements > UINT32_MAX / 2) {
        free(pairs);
        return fail(L, SY_ERR_LIMIT, "meshes[%zu].primitives[%zu]: too many elements", m, p);
    }
    size_t per = pr->mode == GLTF_POINTS ? 1 : 2;
    if (pairs && (r = make_blob(L, pairs, elements * per * sizeof(uint32_t), &out->indices))) return r;
    if ((r = read_all_attributes(L, pr, vcount, m, p, out))) return r;
    out->topology = per == 1 ? SY_TOPOLOGY_POINTS : SY_TOPOLOGY_LINES;
    out->material = pr->material >= 0 ? L->materials[pr->material] : (sy_material){0};
    if (per == 1) L->info->counts.points = add_sat(L->info->counts.points, (uint32_t)elements);
    else L->info->counts.line_segments = add_sat(L->info->counts.line_segments, (uint32_t)elements);
    *used = true;
    return SY_OK;
}

/* The file's budget for every primitive of every mesh, before any is decoded: the vertex attributes
 * as the scene stores them and the indices (one per vertex without an index accessor), for each
 * primitive even where primitives share accessors (the back-ends copy per primitive). Accessor
 * indices were validated (validate_doc). */
static sy_result charge_meshes(loader *L)
{
    const sy_gltf_doc *d = L->doc;
    sy_result r = SY_OK;
    for (size_t m = 0; m < d->mesh_count && r == SY_OK; m++)
        for (size_t p = 0; p < d->meshes[m].primitive_count && r == SY_OK; p++) {
            const sy_gltf_shim_primitive *pr = &d->meshes[m].primitives[p];
            if (pr->position < 0) continue;
            size_t vcount = d->accessors[pr->position].count;
            size_t ic = pr->indices >= 0 ? d->accessors[pr->indices].count : vcount;
            uint64_t per_vertex = 12u + (pr->normal >= 0 ? 12u : 0u) + (pr->tangent >= 0 ? 16u : 0u) +
                                  (pr->texcoord0 >= 0 ? 8u : 0u) + (pr->texcoord1 >= 0 ? 8u : 0u) +
                                  (pr->color0 >= 0 ? 16u : 0u);
            if ((r = sy_budget_charge(&L->budget, vcount, per_vertex, &L->err, "meshes[%zu].primitives[%zu]: %zu vertices", m, p, vcount)) == SY_OK)
                r = sy_budget_charge(&L->budget, ic, 4u, &L->err, "meshes[%zu].primitives[%zu]: %zu indices", m, p, ic);
        }
    return r;
}

static sy_result convert_primitive(loader *L, size_t m, size_t p, sy_primitive *out, bool *used, uint32_t *tris)
{
    const sy_gltf_doc *d = L->doc;
    const sy_gltf_shim_primitive *pr = &d->meshes[m].primitives[p];
    sy_result r;
    *used = false;
    *tris = 0;
    memset(out, 0, sizeof *out);
    if (pr->has_targets && !L->warned_morph) {
        L->warned_morph = true;
        warn(L, "meshes[%zu].primitives[%zu]: morph targets ignored", m, p);
    }
    if (pr->position < 0) {
        warn(L, "meshes[%zu].primitives[%zu]: no POSITION attribute; skipped", m, p);
        L->info->counts.skipped_primitives++;
        return SY_OK;
    }
    size_t vcount = d->accessors[pr->position].count;
    if (vcount > L->opt.max_vertices || vcount > UINT32_MAX)
        return fail(L, SY_ERR_LIMIT, "meshes[%zu].primitives[%zu]: %zu vertices exceed the limit of %zu", m, p, vcount,
                    L->opt.max_vertices);

    /* index list (before conversion) */
    uint32_t *idx = NULL;
    size_t icount = vcount;
    if (pr->indices >= 0) {
        const sy_gltf_shim_accessor *ia = &d->accessors[pr->indices];
        if (ia->components != 1 || ia->is_matrix ||
            (ia->component_type != CT_UBYTE && ia->component_type != CT_USHORT && ia->component_type != CT_UINT))
            return fail(L, SY_ERR_PARSE, "meshes[%zu].primitives[%zu]: indices accessor %d must be SCALAR of unsigned byte, short or int",
                        m, p, (int)pr->indices);
        icount = ia->count;
        if (icount > L->opt.max_indices)
            return fail(L, SY_ERR_LIMIT, "meshes[%zu].primitives[%zu]: %zu indices exceed the limit of %zu", m, p, icount,
                        L->opt.max_indices);
        if ((r = read_uints(L, (size_t)pr->indices, &idx))) return r;
        for (size_t k = 0; k < icount; k++) {
            if (idx[k] >= vcount) {
                unsigned bad = (unsigned)idx[k];
                free(idx);
                return fail(L, SY_ERR_PARSE, "meshes[%zu].primitives[%zu]: index %u at position %zu (accessor %d) >= vertex count %zu",
                            m, p, bad, k, (int)pr->indices, vcount);
            }
        }
    }

    if (pr->mode < GLTF_TRIANGLES) return convert_stroke(L, m, p, out, used, idx, icount, vcount);

    /* triangle list */
    uint32_t *tri = NULL;
    size_t tcount = 0; /* triangles */
    if (pr->mode == GLTF_TRIANGLES) {
        tcount = icount / 3;
        if (icount % 3)
            warn(L, "meshes[%zu].primitives[%zu]: %zu %s is not a multiple of 3; the last %zu ignored", m, p, icount,
                 idx ? "indices" : "vertices", icount % 3);
        if (idx) {
            tri = idx;
            idx = NULL;
        } else if (icount % 3) {
            tri = xcalloc(L, tcount * 3, sizeof(uint32_t), &r);
            if (!tri) return r;
            for (size_t k = 0; k < tcount * 3; k++) tri[k] = (uint32_t)k;
        }
    } else {
        tcount = icount >= 3 ? icount - 2 : 0;
        size_t n;
        if (!sy_size_mul(tcount, 3, &n) || n > L->opt.max_indices) {
            free(idx);
            return fail(L, SY_ERR_LIMIT, "meshes[%zu].primitives[%zu]: %zu triangles after strip/fan conversion exceed the index limit of %zu",
                        m, p, tcount, L->opt.max_indices);
        }
        if (tcount) {
            tri = xcalloc(L, n, sizeof(uint32_t), &r);
            if (!tri) {
                free(idx);
                return r;
            }
        }
        for (size_t k = 0; k < tcount; k++) {
            size_t a, b, c;
            if (pr->mode == GLTF_TRIANGLE_STRIP) { /* keeps the winding of every other triangle */
                a = k;
                b = k + 1 + (k % 2);
                c = k + 2 - (k % 2);
            } else { /* fan */
                a = k + 1;
                b = k + 2;
                c = 0;
            }
            tri[3 * k] = idx ? idx[a] : (uint32_t)a;
            tri[3 * k + 1] = idx ? idx[b] : (uint32_t)b;
            tri[3 * k + 2] = idx ? idx[c] : (uint32_t)c;
        }
        free(idx);
        idx = NULL;
    }
    if (tcount == 0) {
        free(tri);
        warn(L, "meshes[%zu].primitives[%zu]: no complete triangle; skipped", m, p);
        L->info->counts.skipped_primitives++;
        return SY_OK;
    }
    if (tcount > UINT32_MAX / 3) {
        free(tri);
        return fail(L, SY_ERR_LIMIT, "meshes[%zu].primitives[%zu]: too many triangles", m, p);
    }
    if (tri && (r = make_blob(L, tri, tcount * 3 * sizeof(uint32_t), &out->indices))) return r;

    if ((r = read_all_attributes(L, pr, vcount, m, p, out))) return r;
    /* glTF 2.0: without NORMAL the client computes flat normals; a normal map without TANGENT
     * needs generated tangents (sy_mesh_util: MikkTSpace-style angle-weighted accumulation). */
    if (!out->normals && (r = sy_prim_make_flat_normals(out, &L->err))) {
        sy_primitive_release(out);
        return fail(L, r, "meshes[%zu].primitives[%zu]: flat normals: %s", m, p, L->err.message);
    }
    if (!out->tangents && pr->material >= 0 && d->materials[pr->material].normal_texture.index >= 0) {
        const sy_gltf_shim_texinfo *nt = &d->materials[pr->material].normal_texture;
        int32_t tc = nt->transform_texcoord >= 0 ? nt->transform_texcoord : nt->texcoord;
        if (tc != 1) tc = 0;
        if (!(tc ? out->texcoords1 : out->texcoords0)) {
            warn(L, "meshes[%zu].primitives[%zu]: normal map without TEXCOORD_%d; tangents not generated", m, p, (int)tc);
        } else if ((r = sy_prim_generate_tangents(out, (uint32_t)tc, &L->err))) {
            sy_primitive_release(out);
            return fail(L, r, "meshes[%zu].primitives[%zu]: tangents: %s", m, p, L->err.message);
        }
    }
    out->material = pr->material >= 0 ? L->materials[pr->material] : (sy_material){0};
    *used = true;
    *tris = (uint32_t)tcount;
    return SY_OK;
}

static sy_result create_mesh(loader *L, size_t m)
{
    const sy_gltf_shim_mesh *mesh = &L->doc->meshes[m];
    sy_result r = SY_OK;
    sy_primitive *prims = xcalloc(L, mesh->primitive_count, sizeof(sy_primitive), &r);
    if (!prims) return r;
    uint32_t used_count = 0, triangles = 0;
    for (size_t p = 0; p < mesh->primitive_count; p++) {
        bool used;
        uint32_t t;
        if ((r = convert_primitive(L, m, p, &prims[used_count], &used, &t))) goto done;
        if (used) {
            used_count++;
            if (triangles > UINT32_MAX - t) {
                r = fail(L, SY_ERR_LIMIT, "meshes[%zu]: too many triangles", m);
                goto done;
            }
            triangles += t;
        }
    }
    char where[48];
    snprintf(where, sizeof where, "meshes[%zu]", m);
    sy_mesh h;
    if ((r = sy_mesh_create(L->scene, nonempty(mesh->name), &h, &L->err))) {
        r = context(L, r, where);
        goto done;
    }
    if ((r = track(L, SY_TYPE_MESH, h.id))) {
        sy_object_destroy(L->scene, SY_TYPE_MESH, h.id, NULL);
        goto done;
    }
    if (used_count && (r = sy_mesh_set_primitives(L->scene, h, prims, used_count, &L->err))) {
        r = context(L, r, where);
        goto done;
    }
    L->meshes[m] = h;
    L->mesh_triangles[m] = triangles;
done:
    for (uint32_t k = 0; k < used_count; k++) sy_primitive_release(&prims[k]);
    /* a primitive that failed half-way (released itself; harmless) - none when every one was made
     * and sy_mesh_set_primitives refused them (a position beyond SY_COORD_MAX, say) */
    if (r && used_count < mesh->primitive_count) sy_primitive_release(&prims[used_count]);
    free(prims);
    return r;
}

/* >>cameras+lights ---------------------------------------------------------------------------- */

static sy_result create_camera(loader *L, size_t i)
{
    const sy_gltf_shim_camera *c = &L->doc->cameras[i];
    sy_camera_data cd = *(const sy_camera_data *)sy_object_defaults(SY_TYPE_CAMERA);
    cd.name = (char *)nonempty(c->name);
    bool ok;
    if (!strcmp(c->type, "perspective")) {
        cd.projection = SY_PROJECTION_PERSPECTIVE;
        ok = to_float(c->yfov, &cd.yfov) && to_float(c->aspect, &cd.aspect) && to_float(c->znear, &cd.znear) &&
             to_float(c->zfar, &cd.zfar);
    } else {
        cd.projection = SY_PROJECTION_ORTHOGRAPHIC;
        ok = to_float(c->xmag, &cd.xmag) && to_float(c->ymag, &cd.ymag) && to_float(c->oznear, &cd.znear) &&
             to_float(c->ozfar, &cd.zfar);
    }
    if (!ok) return fail(L, SY_ERR_PARSE, "cameras[%zu]: value out of float range", i);
    char where[48];
    snprintf(where, sizeof where, "cameras[%zu]", i);
    sy_camera h;
    sy_result r;
    if ((r = sy_camera_create(L->scene, cd.name, &h, &L->err))) return context(L, r, where);
    if ((r = track(L, SY_TYPE_CAMERA, h.id))) {
        sy_object_destroy(L->scene, SY_TYPE_CAMERA, h.id, NULL);
        return r;
    }
    if ((r = sy_camera_set(L->scene, h, &cd, &L->err))) return context(L, r, where);
    L->cameras[i] = h;
    return SY_OK;
}

static sy_result create_light(loader *L, size_t i)
{
    const sy_gltf_shim_light *l = &L->doc->lights[i];
    sy_light_data ld = *(const sy_light_data *)sy_object_defaults(SY_TYPE_LIGHT);
    ld.name = (char *)nonempty(l->name);
    ld.type = !strcmp(l->type, "spot") ? SY_LIGHT_SPOT : !strcmp(l->type, "directional") ? SY_LIGHT_DIRECTIONAL : SY_LIGHT_POINT;
    bool ok = to_float(l->color[0], &ld.color[0]) && to_float(l->color[1], &ld.color[1]) &&
              to_float(l->color[2], &ld.color[2]) && to_float(l->intensity, &ld.intensity) &&
              to_float(l->range, &ld.range);
    if (ld.type == SY_LIGHT_SPOT) ok = ok && to_float(l->inner_cone, &ld.inner_cone) && to_float(l->outer_cone, &ld.outer_cone);
    if (!ok) return fail(L, SY_ERR_PARSE, "KHR_lights_punctual.lights[%zu]: value out of float range", i);
    char where[64];
    snprintf(where, sizeof where, "KHR_lights_punctual.lights[%zu]", i);
    sy_light h;
    sy_result r;
    if ((r = sy_light_create(L->scene, ld.name, &h, &L->err))) return context(L, r, where);
    if ((r = track(L, SY_TYPE_LIGHT, h.id))) {
        sy_object_destroy(L->scene, SY_TYPE_LIGHT, h.id, NULL);
        return r;
    }
    if ((r = sy_light_set(L->scene, h, &ld, &L->err))) return context(L, r, where);
    L->lights[i] = h;
    return SY_OK;
}

/* >>nodes ------------------------------------------------------------------------------------- */

static sy_result new_node(loader *L, const char *name, sy_node *out, const char *where)
{
    sy_result r;
    if ((r = sy_node_create(L->scene, name, out, &L->err))) return context(L, r, where);
    if ((r = track(L, SY_TYPE_NODE, out->id))) {
        sy_object_destroy(L->scene, SY_TYPE_NODE, out->id, NULL);
        return r;
    }
    if ((r = sy_node_set_flags(L->scene, *out, SY_NODE_VISIBLE, &L->err))) return context(L, r, where);
    return SY_OK;
}

static sy_result set_trs(loader *L, sy_node h, const float t[3], const float q_in[4], const float s[3], const char *where)
{
    float q[4] = {q_in[0], q_in[1], q_in[2], q_in[3]};
    double len = sqrt((double)q[0] * q[0] + (double)q[1] * q[1] + (double)q[2] * q[2] + (double)q[3] * q[3]);
    if (!(len > 1e-12) || !isfinite(len)) return fail(L, SY_ERR_PARSE, "%s: rotation quaternion has zero length", where);
    for (int k = 0; k < 4; k++) q[k] = (float)(q[k] / len);
    sy_result r = sy_node_set_trs(L->scene, h, t, q, s, &L->err);
    return r ? context(L, r, where) : SY_OK;
}

/* Instance nodes of EXT_mesh_gpu_instancing, created as children of the glTF node. */
static sy_result create_instances(loader *L, size_t ni, sy_node **out, size_t *count_out)
{
    const sy_gltf_shim_node *n = &L->doc->nodes[ni];
    const int32_t acc[3] = {n->inst_translation, n->inst_rotation, n->inst_scale};
    float *data[3] = {NULL, NULL, NULL};
    const size_t comps[3] = {3, 4, 3};
    size_t count = 0;
    sy_result r = SY_OK;
    *out = NULL;
    *count_out = 0;
    for (int k = 0; k < 3; k++) {
        if (acc[k] < 0) continue;
        count = L->doc->accessors[acc[k]].count;
        if ((r = read_floats(L, (size_t)acc[k], comps[k], &data[k]))) goto done;
    }
    sy_node *nodes = xcalloc(L, count, sizeof(sy_node), &r);
    if (!nodes) goto done;
    char where[80];
    snprintf(where, sizeof where, "nodes[%zu].EXT_mesh_gpu_instancing", ni);
    for (size_t i = 0; i < count; i++) {
        float t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
        if (data[0]) memcpy(t, data[0] + 3 * i, sizeof t);
        if (data[1]) memcpy(q, data[1] + 4 * i, sizeof q);
        if (data[2]) memcpy(s, data[2] + 3 * i, sizeof s);
        for (int k = 0; k < 3; k++)
            if (!isfinite(t[k]) || !isfinite(s[k])) {
                r = fail(L, SY_ERR_PARSE, "%s: non-finite value in instance %zu", where, i);
                goto fail_nodes;
            }
        if ((r = new_node(L, NULL, &nodes[i], where)) || (r = set_trs(L, nodes[i], t, q, s, where)))
            goto fail_nodes;
        if ((r = sy_node_set_mesh(L->scene, nodes[i], L->meshes[n->mesh], &L->err))) {
            r = context(L, r, where);
            goto fail_nodes;
        }
    }
    *out = nodes;
    *count_out = count;
    goto done;
fail_nodes:
    free(nodes);
done:
    for (int k = 0; k < 3; k++) free(data[k]);
    return r;
}

/* The first frame of animations[0]: for every channel targeting node ni's translation, rotation
 * or scale, the sampler's first output value (the value at its first keyframe; for CUBICSPLINE the
 * middle element of the first triple) replaces the node's static value. Bad channels are warned
 * and skipped (local). */
static sy_result first_frame(loader *L, size_t ni, float t[3], float q[4], float s[3], bool *animated)
{
    const sy_gltf_doc *d = L->doc;
    for (size_t c = 0; c < d->channel_count; c++) {
        const sy_gltf_shim_channel *ch = &d->channels[c];
        if (ch->node != (int32_t)ni || ch->path < 0) continue;
        size_t comps = ch->path == 1 ? 4 : 3;
        if (ch->output < 0 || (size_t)ch->output >= d->accessor_count) {
            warn(L, "animations[0].channels[%zu]: invalid sampler output; ignored", c);
            continue;
        }
        const sy_gltf_shim_accessor *a = &d->accessors[ch->output];
        size_t at = ch->cubic ? 1 : 0;
        if ((size_t)a->components != comps || a->is_matrix || a->count <= at) {
            warn(L, "animations[0].channels[%zu]: output accessor %d is not %zu-component with a first value; ignored",
                 c, (int)ch->output, comps);
            continue;
        }
        float x[4];
        sy_result r = read_element(L, (size_t)ch->output, at, comps, x); /* not the whole accessor: its count is unbounded */
        if (r) return r;
        bool finite = true;
        for (size_t k = 0; k < comps; k++) finite = finite && isfinite(x[k]);
        if (finite && comps == 4 && !(x[0] * x[0] + x[1] * x[1] + x[2] * x[2] + x[3] * x[3] > 1e-12f)) finite = false;
        if (!finite) {
            warn(L, "animations[0].channels[%zu]: non-finite first value (or zero quaternion); ignored", c);
        } else {
            float *dst = ch->path == 0 ? t : ch->path == 1 ? q : s;
            memcpy(dst, x, comps * sizeof(float));
            *animated = true;
        }
    }
    return SY_OK;
}

static sy_result create_nodes(loader *L, const int32_t *roots, size_t root_count, const char *root_name)
{
    const sy_gltf_doc *d = L->doc;
    sy_result r = SY_OK;
    /* reachability from the roots (iterative; the graph is a validated forest) */
    int32_t *stack = xcalloc(L, d->node_count + 1, sizeof(int32_t), &r);
    if (!stack) return r;
    size_t top = 0;
    for (size_t k = 0; k < root_count; k++) {
        if (L->reached[roots[k]]) continue;
        L->reached[roots[k]] = 1;
        stack[top++] = roots[k];
        while (top) {
            const sy_gltf_shim_node *n = &d->nodes[stack[--top]];
            for (size_t c = 0; c < n->child_count; c++)
                if (!L->reached[n->children[c]]) {
                    L->reached[n->children[c]] = 1;
                    stack[top++] = n->children[c];
                }
        }
    }
    free(stack);
    /* the budget's placements (a glTF graph is a forest: one per node, plus the instances) */
    size_t reached = 0, instances = 0;
    for (size_t i = 0; i < d->node_count; i++)
        if (L->reached[i]) {
            reached++;
            if (d->nodes[i].instancing) {
                const int32_t acc[3] = {d->nodes[i].inst_translation, d->nodes[i].inst_rotation, d->nodes[i].inst_scale};
                for (int k = 0; k < 3; k++)
                    if (acc[k] >= 0) {
                        instances += d->accessors[acc[k]].count;
                        break;
                    }
            }
        }
    if ((r = sy_budget_charge(&L->budget, (uint64_t)reached + instances, SY_BUDGET_PLACEMENT_BYTES, &L->err,
                              "%zu nodes and %zu EXT_mesh_gpu_instancing instances", reached, instances)))
        return r;

    sy_node **inst = xcalloc(L, d->node_count + 1, sizeof(sy_node *), &r);
    size_t *inst_count = inst ? xcalloc(L, d->node_count + 1, sizeof(size_t), &r) : NULL;
    sy_node *kids = NULL;
    if (!inst || !inst_count) goto done;
    for (size_t i = 0; i < d->node_count; i++) {
        if (!L->reached[i]) continue;
        const sy_gltf_shim_node *n = &d->nodes[i];
        char where[48];
        snprintf(where, sizeof where, "nodes[%zu]", i);
        sy_node h;
        if ((r = new_node(L, nonempty(n->name), &h, where))) goto done;
        L->nodes[i] = h;
        if (n->matrix_count == 16) {
            sy_mat4 mat;
            for (int k = 0; k < 16; k++) mat.m[k] = (float)n->matrix[k]; /* finite and in range: validated */
            if ((r = sy_node_set_matrix(L->scene, h, &mat, &L->err))) {
                r = context(L, r, where);
                goto done;
            }
        } else {
            float t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
            for (size_t k = 0; k < n->translation_count; k++) t[k] = (float)n->translation[k];
            for (size_t k = 0; k < n->rotation_count; k++) q[k] = (float)n->rotation[k];
            for (size_t k = 0; k < n->scale_count; k++) s[k] = (float)n->scale[k];
            bool animated = false;
            if ((r = first_frame(L, i, t, q, s, &animated))) goto done;
            if ((n->translation_count || n->rotation_count || n->scale_count || animated) &&
                (r = set_trs(L, h, t, q, s, where)))
                goto done;
        }
        if (n->mesh >= 0 && !n->instancing && (r = sy_node_set_mesh(L->scene, h, L->meshes[n->mesh], &L->err))) {
            r = context(L, r, where);
            goto done;
        }
        if (n->camera >= 0 && (r = sy_node_set_camera(L->scene, h, L->cameras[n->camera], &L->err))) {
            r = context(L, r, where);
            goto done;
        }
        if (n->light >= 0 && (r = sy_node_set_light(L->scene, h, L->lights[n->light], &L->err))) {
            r = context(L, r, where);
            goto done;
        }
        if (n->skin >= 0 && !L->warned_skin) {
            L->warned_skin = true;
            warn(L, "%s: skinning ignored (meshes are used in their bind pose)", where);
        }
        if (n->instancing && (r = create_instances(L, i, &inst[i], &inst_count[i]))) goto done;
    }
    /* children (all reached, hence created) */
    for (size_t i = 0; i < d->node_count; i++) {
        if (!L->reached[i]) continue;
        const sy_gltf_shim_node *n = &d->nodes[i];
        size_t total = n->child_count + inst_count[i];
        if (total == 0) continue;
        if (total > UINT32_MAX) {
            r = fail(L, SY_ERR_LIMIT, "nodes[%zu]: too many children", i);
            goto done;
        }
        kids = xcalloc(L, total, sizeof(sy_node), &r);
        if (!kids) goto done;
        for (size_t k = 0; k < inst_count[i]; k++) kids[k] = inst[i][k];
        for (size_t c = 0; c < n->child_count; c++) kids[inst_count[i] + c] = L->nodes[n->children[c]];
        if ((r = sy_node_set_children(L->scene, L->nodes[i], kids, (uint32_t)total, &L->err))) {
            char where[48];
            snprintf(where, sizeof where, "nodes[%zu]", i);
            r = context(L, r, where);
            goto done;
        }
        free(kids);
        kids = NULL;
    }
    /* the new root */
    sy_node root;
    if ((r = new_node(L, root_name, &root, "scene root"))) goto done;
    if (root_count > UINT32_MAX) {
        r = fail(L, SY_ERR_LIMIT, "too many root nodes");
        goto done;
    }
    kids = xcalloc(L, root_count, sizeof(sy_node), &r);
    if (!kids) goto done;
    for (size_t k = 0; k < root_count; k++) kids[k] = L->nodes[roots[k]];
    if (root_count && (r = sy_node_set_children(L->scene, root, kids, (uint32_t)root_count, &L->err))) {
        r = context(L, r, "scene root");
        goto done;
    }
    L->info->root = root;
    /* camera nodes in glTF node order */
    uint32_t ncam = 0;
    for (size_t i = 0; i < d->node_count; i++) ncam += (L->reached[i] && d->nodes[i].camera >= 0);
    if (ncam) {
        L->info->camera_nodes = xcalloc(L, ncam, sizeof(sy_node), &r);
        if (!L->info->camera_nodes) goto done;
        for (size_t i = 0; i < d->node_count; i++)
            if (L->reached[i] && d->nodes[i].camera >= 0) L->info->camera_nodes[L->info->camera_node_count++] = L->nodes[i];
    }
done:
    free(kids);
    if (inst)
        for (size_t i = 0; i < d->node_count; i++) free(inst[i]);
    free(inst);
    free(inst_count);
    return r;
}

/* >>public ------------------------------------------------------------------------------------ */

const char *const *sy_gltf_supported_extensions(void) { return k_supported; }

void sy_gltf_info_free(sy_gltf_info *info)
{
    if (!info) return;
    free(info->camera_nodes);
    for (uint32_t i = 0; i < info->stored_warning_count; i++) free(info->warnings[i]);
    free(info->warnings);
    memset(info, 0, sizeof *info);
}

static sy_gltf_options resolve_options(const sy_gltf_options *o)
{
    sy_gltf_options r = o ? *o : (sy_gltf_options){0};
    if (!r.max_file_bytes) r.max_file_bytes = (size_t)2 << 30;
    if (r.max_file_bytes > UINT32_MAX - 1u) r.max_file_bytes = UINT32_MAX - 1u; /* tinygltf takes unsigned lengths */
    if (!r.max_vertices) r.max_vertices = (size_t)1 << 28;
    if (!r.max_indices) r.max_indices = (size_t)1 << 28;
    if (!r.max_image_pixels) r.max_image_pixels = (uint64_t)1 << 26;
    if (!r.max_instances) r.max_instances = (size_t)1 << 20;
    if (!r.max_json_depth) r.max_json_depth = 64;
    if (!r.max_scene_bytes) r.max_scene_bytes = sy_budget_default_bytes();
    return r;
}

static sy_result load_doc(loader *L)
{
    const sy_gltf_doc *d = L->doc;
    sy_gltf_counts *c = &L->info->counts;
    sy_result r = SY_OK;
    c->nodes = (uint32_t)d->node_count;
    c->meshes = (uint32_t)d->mesh_count;
    c->materials = (uint32_t)d->material_count;
    c->textures = (uint32_t)d->texture_count;
    c->images = (uint32_t)d->image_count;
    c->lights = (uint32_t)d->light_count;
    c->cameras = (uint32_t)d->camera_count;
    for (size_t m = 0; m < d->mesh_count; m++) c->primitives += (uint32_t)d->meshes[m].primitive_count;

    if (!(L->parent = xcalloc(L, d->node_count + 1, sizeof(int32_t), &r))) return r;
    for (size_t i = 0; i < d->node_count; i++) L->parent[i] = -1;
    if ((r = validate_doc(L))) return r;

    if (!(L->reached = xcalloc(L, d->node_count + 1, 1, &r)) ||
        !(L->materials = xcalloc(L, d->material_count + 1, sizeof(sy_material), &r)) ||
        !(L->meshes = xcalloc(L, d->mesh_count + 1, sizeof(sy_mesh), &r)) ||
        !(L->mesh_triangles = xcalloc(L, d->mesh_count + 1, sizeof(uint32_t), &r)) ||
        !(L->cameras = xcalloc(L, d->camera_count + 1, sizeof(sy_camera), &r)) ||
        !(L->lights = xcalloc(L, d->light_count + 1, sizeof(sy_light), &r)) ||
        !(L->nodes = xcalloc(L, d->node_count + 1, sizeof(sy_node), &r)) ||
        !(L->textures = xcalloc(L, d->texture_count * 2 + 2, sizeof(sy_texture), &r)) ||
        !(L->image_blobs = xcalloc(L, d->image_count + 1, sizeof(sy_blob *), &r)))
        return r;
    if (d->animation_count)
        warn(L, "%zu animation(s): nodes are placed at the first frame of animations[0], the rest is ignored",
             d->animation_count);

    if ((r = charge_meshes(L))) return r;
    /* dependency order: textures (on demand) + materials, meshes, lights, cameras, nodes */
    for (size_t i = 0; i < d->material_count; i++)
        if ((r = create_material(L, i))) return r;
    for (size_t i = 0; i < d->mesh_count; i++) {
        if ((r = create_mesh(L, i))) return r;
        if (c->triangles > UINT32_MAX - L->mesh_triangles[i]) return fail(L, SY_ERR_LIMIT, "too many triangles");
        c->triangles += L->mesh_triangles[i];
    }
    for (size_t i = 0; i < d->light_count; i++)
        if ((r = create_light(L, i))) return r;
    for (size_t i = 0; i < d->camera_count; i++)
        if ((r = create_camera(L, i))) return r;

    /* which glTF scene */
    int32_t si = -1;
    if (L->opt.use_scene_index) {
        if (L->opt.scene_index < 0 || (size_t)L->opt.scene_index >= d->scene_count)
            return fail(L, SY_ERR_NOT_FOUND, "scene %d requested, the file has %zu scenes", (int)L->opt.scene_index, d->scene_count);
        si = L->opt.scene_index;
    } else if (d->default_scene >= 0) {
        si = d->default_scene;
    } else if (d->scene_count > 0) {
        si = 0;
    }
    L->info->scene_index = si;
    char name[64];
    if (si >= 0) {
        const sy_gltf_shim_scene *sc = &d->scenes[si];
        snprintf(name, sizeof name, "scene %d", (int)si);
        return create_nodes(L, sc->nodes, sc->node_count, nonempty(sc->name) ? sc->name : name);
    }
    int32_t *roots = xcalloc(L, d->node_count + 1, sizeof(int32_t), &r);
    if (!roots) return r;
    size_t nr = 0;
    for (size_t i = 0; i < d->node_count; i++)
        if (L->parent[i] == -1) roots[nr++] = (int32_t)i;
    r = create_nodes(L, roots, nr, "scene");
    free(roots);
    return r;
}

/* Shared by sy_gltf_load (mem NULL: reads path; external files relative to its directory) and
 * sy_gltf_load_memory (mem borrowed, path only names it in messages, base_dir given). */
/* What a successful load skipped or repaired, on the log (sy_log.h; module "gltf", item the file):
 * the stored warnings, then how many more there were. They stay in info->warnings as well. */
static void log_warnings(const char *path, const sy_gltf_info *info)
{
    for (uint32_t i = 0; i < info->stored_warning_count; i++) sy_log(SY_LOG_WARNING, "gltf", path, "%s", info->warnings[i]);
    if (info->warning_count > info->stored_warning_count)
        sy_log(SY_LOG_WARNING, "gltf", path, "%u more warnings not shown", info->warning_count - info->stored_warning_count);
}

static sy_result load_common(const char *path, const void *mem, size_t mem_size, const char *base_dir, sy_scene *scene,
                             const sy_gltf_options *opts, sy_gltf_info *info_out, sy_error *err)
{
    sy_gltf_info local_info;
    sy_gltf_info *info = info_out ? info_out : &local_info;
    memset(info, 0, sizeof *info);
    info->scene_index = -1;

    loader L;
    memset(&L, 0, sizeof L);
    L.path = path;
    L.scene = scene;
    L.opt = resolve_options(opts);
    L.info = info;
    L.budget = sy_budget_make(path, L.opt.max_scene_bytes);

    void *bytes = NULL;
    size_t size = 0;
    sy_gltf_doc *doc = NULL;
    sy_result r = SY_OK;
    if (!mem) {
        r = sy_file_read_all(path, L.opt.max_file_bytes, &bytes, &size, &L.err);
        if (r) goto out; /* the message names the path already */
    } else if (mem_size > L.opt.max_file_bytes) {
        r = fail(&L, SY_ERR_LIMIT, "%zu bytes exceed the file size limit of %zu", mem_size, L.opt.max_file_bytes);
        goto out;
    } else {
        size = mem_size;
    }

    const uint8_t *b = mem ? (const uint8_t *)mem : (const uint8_t *)bytes, *json = b;
    size_t json_len = size;
    size_t plen = strlen(path);
    bool ext_glb = plen >= 4 && (!strcmp(path + plen - 4, ".glb") || !strcmp(path + plen - 4, ".GLB"));
    bool binary = size >= 4 && memcmp(b, "glTF", 4) == 0;
    if (binary || ext_glb) {
        json = NULL;
        if ((r = check_glb(&L, b, size, &json, &json_len))) goto out;
        binary = true;
    }
    if (json_len == 0) {
        r = fail(&L, SY_ERR_PARSE, "empty file");
        goto out;
    }
    if ((r = check_json_depth(&L, json, json_len))) goto out;

    /* external files are relative to the file's directory */
    const char *slash = strrchr(path, '/');
    size_t dlen = mem ? strlen(base_dir) : slash ? (size_t)(slash - path) + 1 : 0;
    char *base = malloc(dlen + 1);
    if (!base) {
        r = fail(&L, SY_ERR_OUT_OF_MEMORY, "out of memory");
        goto out;
    }
    memcpy(base, mem ? base_dir : path, dlen);
    base[dlen] = '\0';
    sy_gltf_shim_limits lim = {L.opt.max_file_bytes, L.opt.max_image_pixels, L.opt.allowed_roots,
                               L.opt.allowed_root_count, k_supported, L.budget.limit};
    r = sy_gltf_shim_parse(b, size, binary, base, &lim, &doc, &L.err);
    free(base);
    /* the document holds its own copy of every buffer: the file's bytes go before the scene's blobs
     * are made (a 10^7-triangle .glb peaks at one copy of it less) */
    free(bytes);
    bytes = NULL;
    if (r) {
        sy_error_prefix(&L.err, "%s: %s", path, r == SY_ERR_PARSE ? "invalid glTF" : "cannot load");
        goto out;
    }
    if (doc->warnings[0]) warn(&L, "tinygltf: %s", doc->warnings);
    L.doc = doc;
    for (size_t i = 0; i < doc->image_count && r == SY_OK; i++) /* within the budget: the shim checked it */
        if (doc->images[i].pixels)
            r = sy_budget_charge(&L.budget, (uint64_t)doc->images[i].width * doc->images[i].height,
                                 doc->images[i].channels, &L.err, "images[%zu]", i);
    if (r) goto out;
    r = load_doc(&L);
    if (r) rollback(&L);

out:
    if (L.image_blobs)
        for (size_t i = 0; i < doc->image_count; i++) sy_blob_release(L.image_blobs[i]);
    free(L.image_blobs);
    free(L.materials);
    free(L.meshes);
    free(L.mesh_triangles);
    free(L.cameras);
    free(L.lights);
    free(L.nodes);
    free(L.textures);
    free(L.parent);
    free(L.reached);
    free(L.objs);
    sy_gltf_shim_free(doc);
    free(bytes);
    if (r) {
        sy_gltf_info_free(info);
        info->scene_index = -1;
        if (err) *err = L.err;
        return r;
    }
    log_warnings(path, info);
    if (!info_out) sy_gltf_info_free(&local_info);
    return SY_OK;
}

sy_result sy_gltf_load(const char *path, sy_scene *scene, const sy_gltf_options *opts, sy_gltf_info *info_out,
                       sy_error *err)
{
    if (!path || !scene) {
        if (info_out) {
            memset(info_out, 0, sizeof *info_out);
            info_out->scene_index = -1;
        }
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "sy_gltf_load: path and scene are required");
    }
    return load_common(path, NULL, 0, NULL, scene, opts, info_out, err);
}

sy_result sy_gltf_load_memory(const void *data, size_t size, const char *name, const char *base_dir, sy_scene *scene,
                              const sy_gltf_options *opts, sy_gltf_info *info_out, sy_error *err)
{
    if (!data || !name || !base_dir || !scene) {
        if (info_out) {
            memset(info_out, 0, sizeof *info_out);
            info_out->scene_index = -1;
        }
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "sy_gltf_load_memory: data, name, base_dir and scene are required");
    }
    return load_common(name, data, size, base_dir, scene, opts, info_out, err);
}

sy_result sy_gltf_find_camera(const sy_scene *scene, const sy_gltf_info *info, const char *selector, sy_node *out,
                              sy_error *err)
{
    if (!info || !selector || !out) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "sy_gltf_find_camera: missing argument");
    char *end = NULL;
    errno = 0;
    unsigned long idx = strtoul(selector, &end, 10);
    if (selector[0] >= '0' && selector[0] <= '9' && end && *end == '\0' && errno == 0) {
        if (idx < info->camera_node_count) {
            *out = info->camera_nodes[idx];
            return SY_OK;
        }
        return sy_error_set(err, SY_ERR_NOT_FOUND, "camera index %lu out of range (%u cameras)", idx,
                            (unsigned)info->camera_node_count);
    }
    char list[256] = "";
    for (uint32_t i = 0; i < info->camera_node_count; i++) {
        const sy_node_data *nd = sy_node_get(scene, info->camera_nodes[i]);
        const sy_camera_data *cd = nd ? sy_camera_get(scene, nd->camera) : NULL;
        if ((nd && nd->name && !strcmp(nd->name, selector)) || (cd && cd->name && !strcmp(cd->name, selector))) {
            *out = info->camera_nodes[i];
            return SY_OK;
        }
        size_t used = strlen(list);
        snprintf(list + used, sizeof list - used, "%s%u:%s", i ? ", " : "", (unsigned)i,
                 nd && nd->name ? nd->name : (cd && cd->name ? cd->name : "(unnamed)"));
    }
    return sy_error_set(err, SY_ERR_NOT_FOUND, "no camera named '%s' (available: %s)", selector,
                        info->camera_node_count ? list : "none");
}
