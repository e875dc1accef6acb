/* sy_gltf_validate.c — everything the glTF loader checks before it creates a single object: the GLB
 * container (header and chunk table), the JSON's nesting depth, then one validation pass over the
 * parsed document (required extensions, buffer views, accessors and their sparse parts, every
 * cross-reference, node graph, cameras, images; formats/sy_gltf_shim.h gives it as plain C structs)
 * (cgltf's fixup-and-validate, STYLE.md). The element sizes it checks with are also the accessor
 * reader's (sy_gltf_accessors.c). */
#include "sy_gltf_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define GLB_MAGIC 0x46546C67u /* "glTF" */
#define GLB_JSON 0x4E4F534Au
#define GLB_BIN 0x004E4942u

#define SY_GLTF_PI 3.14159265358979323846

const char *const gltf_supported[] = {
    "KHR_materials_emissive_strength", "KHR_materials_transmission", "KHR_materials_ior",
    "KHR_materials_unlit", "KHR_materials_specular", "KHR_materials_clearcoat", "KHR_materials_sheen",
    "KHR_materials_volume", "KHR_materials_iridescence", "KHR_materials_anisotropy", "KHR_materials_variants",
    "KHR_texture_transform", "KHR_lights_punctual",
    "KHR_mesh_quantization", "EXT_mesh_gpu_instancing", "KHR_draco_mesh_compression",
    "EXT_meshopt_compression", "EXT_texture_webp", "KHR_animation_pointer", NULL,
};

/* >>container --------------------------------------------------------------------------------- */

static uint32_t rd_u32(const uint8_t *p)
{
    uint8_t b[4];
    memcpy(b, p, 4);
    return (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
}

/* Validates the GLB header and chunk table; every bound is checked as a subtraction from what is
 * known to remain, so nothing can overflow. */
sy_result gltf_check_glb(loader *L, const uint8_t *b, size_t size, const uint8_t **json, size_t *json_len)
{
    if (size < 12) return gltf_fail(L, SY_ERR_PARSE, "GLB header truncated: %zu bytes, need 12", size);
    uint32_t magic = rd_u32(b), version = rd_u32(b + 4), length = rd_u32(b + 8);
    if (magic != GLB_MAGIC)
        return gltf_fail(L, SY_ERR_PARSE, "not a GLB file: wrong magic 0x%08x (expected 'glTF')", (unsigned)magic);
    if (version != 2) return gltf_fail(L, SY_ERR_UNSUPPORTED, "GLB version %u is not supported (expected 2)", (unsigned)version);
    if ((size_t)length != size)
        return gltf_fail(L, SY_ERR_PARSE, "GLB total length %u does not equal the file size %zu", (unsigned)length, size);
    size_t off = 12;
    for (unsigned k = 0; off < size; k++) {
        size_t remaining = size - off;
        if (remaining < 8) return gltf_fail(L, SY_ERR_PARSE, "GLB chunk %u header truncated at byte %zu", k, off);
        uint32_t clen = rd_u32(b + off), ctype = rd_u32(b + off + 4);
        if ((size_t)clen > remaining - 8)
            return gltf_fail(L, SY_ERR_PARSE, "GLB chunk %u length %u exceeds the %zu bytes left in the file", k,
                             (unsigned)clen, remaining - 8);
        if (k == 0) {
            if (ctype != GLB_JSON)
                return gltf_fail(L, SY_ERR_PARSE, "GLB chunk 0 has type 0x%08x, expected JSON", (unsigned)ctype);
            if (clen == 0) return gltf_fail(L, SY_ERR_PARSE, "GLB JSON chunk is empty");
            *json = b + off + 8;
            *json_len = clen;
        } else if (k == 1) {
            if (ctype != GLB_BIN)
                return gltf_fail(L, SY_ERR_UNSUPPORTED, "GLB chunk 1 has type 0x%08x, expected BIN", (unsigned)ctype);
            if (clen % 4 != 0) return gltf_fail(L, SY_ERR_PARSE, "GLB BIN chunk length %u is not a multiple of 4", (unsigned)clen);
        } /* later chunks: ignored, as the specification requires */
        off += 8 + (size_t)clen;
    }
    if (!*json) return gltf_fail(L, SY_ERR_PARSE, "GLB has no JSON chunk");
    return SY_OK;
}

/* Rejects JSON nested deeper than the limit (the parser and tinygltf recurse on nesting). */
sy_result gltf_check_json_depth(loader *L, const uint8_t *s, size_t n)
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
                return gltf_fail(L, SY_ERR_LIMIT, "JSON nesting deeper than %u at byte %zu", (unsigned)L->opt.max_json_depth, i);
        } else if ((c == ']' || c == '}') && depth > 0) {
            depth--;
        }
    }
    return SY_OK;
}

/* >>validation -------------------------------------------------------------------------------- */

size_t gltf_component_size(int32_t ct)
{
    switch (ct) {
    case CT_BYTE: case CT_UBYTE: return 1;
    case CT_SHORT: case CT_USHORT: return 2;
    case CT_UINT: case CT_FLOAT: return 4;
    default: return 0;
    }
}

/* Size of one element, with the 4-byte column alignment of matrices. */
size_t gltf_element_size(const sy_gltf_shim_accessor *a)
{
    size_t cs = gltf_component_size(a->component_type);
    if (!a->is_matrix) return cs * (size_t)a->components;
    size_t rows = a->components == 4 ? 2 : a->components == 9 ? 3 : 4;
    size_t col = (rows * cs + 3) & ~(size_t)3;
    return col * rows;
}

size_t gltf_accessor_stride(const sy_gltf_doc *d, const sy_gltf_shim_accessor *a)
{
    size_t st = d->views[a->buffer_view].byte_stride;
    return st ? st : gltf_element_size(a);
}

static sy_result check_index(loader *L, int64_t idx, size_t count, bool optional, const char *what_fmt, size_t i,
                             const char *field, const char *target)
{
    if (idx == -1 && optional) return SY_OK;
    if (idx < 0 || (uint64_t)idx >= count) {
        char where[128];
        snprintf(where, sizeof where, what_fmt, i);
        return gltf_fail(L, SY_ERR_PARSE, "%s: %s %lld out of range (%zu %s)", where, field, (long long)idx, count, target);
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
            return gltf_fail(L, SY_ERR_PARSE, "bufferViews[%zu]: byteOffset %zu + byteLength %zu exceeds buffer %d length %zu",
                             i, v->byte_offset, v->byte_length, (int)v->buffer, bsize);
        if (v->byte_stride != 0 && v->byte_stride < 4)
            return gltf_fail(L, SY_ERR_PARSE, "bufferViews[%zu]: byteStride %zu is less than 4", i, v->byte_stride);
    }
    return SY_OK;
}

static sy_result validate_accessor(loader *L, size_t i)
{
    const sy_gltf_doc *d = L->doc;
    const sy_gltf_shim_accessor *a = &d->accessors[i];
    size_t cs = gltf_component_size(a->component_type);
    if (cs == 0) return gltf_fail(L, SY_ERR_PARSE, "accessors[%zu]: componentType %d is not a glTF 2.0 type", i, (int)a->component_type);
    if (a->components <= 0) return gltf_fail(L, SY_ERR_PARSE, "accessors[%zu]: unknown type", i);
    if (a->count == 0) return gltf_fail(L, SY_ERR_PARSE, "accessors[%zu]: count is 0 (minimum 1)", i);
    size_t elem = gltf_element_size(a);
    sy_result r = check_index(L, a->buffer_view, d->view_count, true, "accessors[%zu]", i, "bufferView", "bufferViews");
    if (r) return r;
    if (a->buffer_view >= 0) {
        const sy_gltf_shim_view *v = &d->views[a->buffer_view];
        if (v->byte_stride != 0 && v->byte_stride < elem)
            return gltf_fail(L, SY_ERR_PARSE, "accessors[%zu]: byteStride %zu of bufferView %d is smaller than the element size %zu",
                             i, v->byte_stride, (int)a->buffer_view, elem);
        size_t stride = gltf_accessor_stride(d, a), need;
        if (!sy_size_mad(stride, a->count - 1, elem, &need) || !sy_size_add(need, a->byte_offset, &need) ||
            need > v->byte_length)
            return gltf_fail(L, SY_ERR_PARSE,
                             "accessors[%zu]: byteOffset %zu + count %zu * stride %zu exceeds bufferView %d length %zu", i,
                             a->byte_offset, a->count, stride, (int)a->buffer_view, v->byte_length);
    }
    if (a->sparse) {
        if (a->sparse_count < 1 || (size_t)a->sparse_count > a->count)
            return gltf_fail(L, SY_ERR_PARSE, "accessors[%zu]: sparse count %d not in 1..%zu", i, (int)a->sparse_count, a->count);
        size_t sc = (size_t)a->sparse_count;
        size_t isz = a->sparse_indices_type == CT_UBYTE ? 1 : a->sparse_indices_type == CT_USHORT ? 2
                   : a->sparse_indices_type == CT_UINT ? 4 : 0;
        if (isz == 0)
            return gltf_fail(L, SY_ERR_PARSE, "accessors[%zu]: sparse indices componentType %d is not an unsigned integer type",
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
                return gltf_fail(L, SY_ERR_PARSE, "accessors[%zu].sparse.%s: byteOffset %d + count %zu * %zu bytes exceeds bufferView %d length %zu",
                                 i, parts[k].name, (int)parts[k].offset, sc, parts[k].esize, (int)parts[k].view, v->byte_length);
        }
    }
    return SY_OK;
}

static sy_result validate_texinfo(loader *L, const sy_gltf_shim_texinfo *t, size_t mi, const char *slot)
{
    if (t->index == -1) return SY_OK;
    if (t->index < 0 || (size_t)t->index >= L->doc->texture_count)
        return gltf_fail(L, SY_ERR_PARSE, "materials[%zu].%s: texture %d out of range (%zu textures)", mi, slot, (int)t->index,
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
            return gltf_fail(L, SY_ERR_PARSE, "nodes[%zu]: matrix has %zu elements (expected 16)", i, n->matrix_count);
        if (n->translation_count != 0 && n->translation_count != 3)
            return gltf_fail(L, SY_ERR_PARSE, "nodes[%zu]: translation has %zu elements (expected 3)", i, n->translation_count);
        if (n->rotation_count != 0 && n->rotation_count != 4)
            return gltf_fail(L, SY_ERR_PARSE, "nodes[%zu]: rotation has %zu elements (expected 4)", i, n->rotation_count);
        if (n->scale_count != 0 && n->scale_count != 3)
            return gltf_fail(L, SY_ERR_PARSE, "nodes[%zu]: scale has %zu elements (expected 3)", i, n->scale_count);
        if (!all_finite(n->matrix, n->matrix_count) || !all_finite(n->translation, n->translation_count) ||
            !all_finite(n->rotation, n->rotation_count) || !all_finite(n->scale, n->scale_count))
            return gltf_fail(L, SY_ERR_PARSE, "nodes[%zu]: non-finite transform value", i);
        if (n->instancing) {
            if (n->mesh < 0) return gltf_fail(L, SY_ERR_PARSE, "nodes[%zu]: EXT_mesh_gpu_instancing without a mesh", i);
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
                    return gltf_fail(L, SY_ERR_PARSE, "nodes[%zu].EXT_mesh_gpu_instancing: %s accessor %d must have %d components", i,
                                     names[k], (int)acc[k], (int)comps[k]);
                if (count && a->count != count)
                    return gltf_fail(L, SY_ERR_PARSE, "nodes[%zu].EXT_mesh_gpu_instancing: accessor counts differ (%zu and %zu)", i,
                                     count, a->count);
                count = a->count;
            }
            if (count == 0) return gltf_fail(L, SY_ERR_PARSE, "nodes[%zu].EXT_mesh_gpu_instancing: no attributes", i);
            if (count > L->opt.max_instances)
                return gltf_fail(L, SY_ERR_LIMIT, "nodes[%zu].EXT_mesh_gpu_instancing: %zu instances exceed the limit of %zu", i,
                                 count, L->opt.max_instances);
        }
        for (size_t c = 0; c < n->child_count; c++) {
            int32_t ch = n->children[c];
            if (ch < 0 || (size_t)ch >= d->node_count)
                return gltf_fail(L, SY_ERR_PARSE, "nodes[%zu].children[%zu]: node %d out of range (%zu nodes)", i, c, (int)ch,
                                 d->node_count);
            if (L->parent[ch] != -1)
                return gltf_fail(L, SY_ERR_PARSE, "nodes[%d] has two parents (nodes[%d] and nodes[%zu]): the node graph must be a forest",
                                 (int)ch, (int)L->parent[ch], i);
            L->parent[ch] = (int32_t)i;
        }
    }
    /* With at most one parent per node, a cycle is a parent chain that returns to itself. Walk each
     * chain once, stamping nodes with the walk's id: O(nodes). */
    size_t nbytes;
    if (!sy_size_mul(d->node_count + 1, sizeof(uint32_t), &nbytes)) return gltf_fail(L, SY_ERR_LIMIT, "too many nodes");
    uint32_t *stamp = calloc(d->node_count + 1, sizeof(uint32_t));
    if (!stamp) return gltf_fail(L, SY_ERR_OUT_OF_MEMORY, "out of memory");
    for (size_t i = 0; i < d->node_count; i++) {
        int32_t k = (int32_t)i;
        while (k != -1 && stamp[k] == 0) {
            stamp[k] = (uint32_t)i + 1;
            k = L->parent[k];
        }
        if (k != -1 && stamp[k] == (uint32_t)i + 1) {
            free(stamp);
            return gltf_fail(L, SY_ERR_PARSE, "nodes[%d] is part of a cycle in the node hierarchy", (int)k);
        }
    }
    free(stamp);
    return SY_OK;
}

sy_result gltf_validate_doc(loader *L)
{
    const sy_gltf_doc *d = L->doc;
    sy_result r;
    for (size_t i = 0; i < d->extensions_required_count; i++) {
        const char *e = d->extensions_required[i];
        bool ok = false;
        for (size_t k = 0; gltf_supported[k]; k++) ok = ok || strcmp(e, gltf_supported[k]) == 0;
        if (!ok && !strcmp(e, "KHR_texture_basisu"))
            return gltf_fail(L, SY_ERR_UNSUPPORTED,
                             "extensionsRequired: 'KHR_texture_basisu' is not supported: no Debian package decodes "
                             "Basis Universal (KTX2) textures; a file that only uses it loads its PNG / JPEG fallbacks");
        if (!ok) {
            char list[768];
            size_t used = 0;
            list[0] = '\0';
            for (size_t k = 0; gltf_supported[k] && used < sizeof list; k++) {
                int n = snprintf(list + used, sizeof list - used, "%s%s", k ? ", " : "", gltf_supported[k]);
                if (n < 0) break;
                used += (size_t)n;
            }
            return gltf_fail(L, SY_ERR_UNSUPPORTED, "extensionsRequired: '%s' is not supported (supported: %s)", e, list);
        }
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
                return gltf_fail(L, SY_ERR_PARSE, "meshes[%zu].primitives[%zu]: mode %d is not a glTF primitive mode", m, p, (int)pr->mode);
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
        for (size_t k = 0; k < gltf_texture_slot_count; k++) {
            const gltf_texture_slot *ts = &gltf_texture_slots[k];
            if ((r = validate_texinfo(L, (const sy_gltf_shim_texinfo *)((const char *)m + ts->shim), i, ts->name)))
                return r;
        }
        if (strcmp(m->alpha_mode, "OPAQUE") && strcmp(m->alpha_mode, "MASK") && strcmp(m->alpha_mode, "BLEND"))
            return gltf_fail(L, SY_ERR_PARSE, "materials[%zu]: alphaMode '%s' is not OPAQUE, MASK or BLEND", i, m->alpha_mode);
        if ((m->base_color_count != 0 && m->base_color_count != 4) || (m->emissive_count != 0 && m->emissive_count != 3))
            return gltf_fail(L, SY_ERR_PARSE, "materials[%zu]: baseColorFactor needs 4 and emissiveFactor 3 numbers", i);
    }
    for (size_t i = 0; i < d->variant_use_count; i++) {
        const sy_gltf_shim_variant_use *u = &d->variant_uses[i];
        if (u->material < 0 || (size_t)u->material >= d->material_count || u->variant < 0 ||
            (size_t)u->variant >= d->variant_count)
            return gltf_fail(L, SY_ERR_PARSE,
                             "meshes[%d].primitives[%d].KHR_materials_variants: a mapping names material %d and variant %d "
                             "(%zu materials, %zu variants)",
                             (int)u->mesh, (int)u->primitive, (int)u->material, (int)u->variant, d->material_count,
                             d->variant_count);
    }
    for (size_t i = 0; i < d->texture_count; i++) {
        if ((r = check_index(L, d->textures[i].source, d->image_count, true, "textures[%zu]", i, "source", "images")) ||
            (r = check_index(L, d->textures[i].sampler, d->sampler_count, true, "textures[%zu]", i, "sampler", "samplers")))
            return r;
    }
    for (size_t i = 0; i < d->image_count; i++) { /* a bad image is local: its textures go missing */
        const sy_gltf_shim_image *im = &d->images[i];
        if (!im->pixels) {
            if (im->uri[0]) gltf_warn(L, "images[%zu] ('%s'): %s; textures using it are missing", i, im->uri, im->problem);
            else gltf_warn(L, "images[%zu]: %s; textures using it are missing", i, im->problem);
        }
    }
    for (size_t i = 0; i < d->camera_count; i++) {
        const sy_gltf_shim_camera *c = &d->cameras[i];
        if (!strcmp(c->type, "perspective")) {
            if (!(isfinite(c->yfov) && c->yfov > 0 && c->yfov < SY_GLTF_PI))
                return gltf_fail(L, SY_ERR_PARSE, "cameras[%zu]: yfov %g is not in (0, pi)", i, c->yfov);
            if (!(isfinite(c->znear) && c->znear > 0))
                return gltf_fail(L, SY_ERR_PARSE, "cameras[%zu]: znear %g must be > 0", i, c->znear);
            if (!(isfinite(c->zfar) && (c->zfar == 0 || c->zfar > c->znear)))
                return gltf_fail(L, SY_ERR_PARSE, "cameras[%zu]: zfar %g must be > znear %g", i, c->zfar, c->znear);
            if (!(isfinite(c->aspect) && c->aspect >= 0))
                return gltf_fail(L, SY_ERR_PARSE, "cameras[%zu]: aspectRatio %g must be > 0", i, c->aspect);
        } else if (!strcmp(c->type, "orthographic")) {
            if (!(isfinite(c->xmag) && isfinite(c->ymag) && c->xmag != 0 && c->ymag != 0))
                return gltf_fail(L, SY_ERR_PARSE, "cameras[%zu]: xmag %g / ymag %g must be finite and non-zero", i, c->xmag, c->ymag);
            if (!(isfinite(c->oznear) && isfinite(c->ozfar) && c->oznear >= 0 && c->ozfar > c->oznear))
                return gltf_fail(L, SY_ERR_PARSE, "cameras[%zu]: orthographic zfar %g must be > znear %g >= 0", i, c->ozfar, c->oznear);
        } else {
            return gltf_fail(L, SY_ERR_PARSE, "cameras[%zu]: type '%s' is not perspective or orthographic", i, c->type);
        }
    }
    for (size_t i = 0; i < d->light_count; i++) {
        const sy_gltf_shim_light *l = &d->lights[i];
        if (strcmp(l->type, "point") && strcmp(l->type, "spot") && strcmp(l->type, "directional"))
            return gltf_fail(L, SY_ERR_PARSE, "KHR_lights_punctual.lights[%zu]: type '%s' is not point, spot or directional", i, l->type);
        if ((l->color_count != 0 && l->color_count != 3) || !all_finite(l->color, 3) || l->color[0] < 0 ||
            l->color[1] < 0 || l->color[2] < 0)
            return gltf_fail(L, SY_ERR_PARSE, "KHR_lights_punctual.lights[%zu]: color must be 3 finite values >= 0", i);
        if (!isfinite(l->intensity) || l->intensity < 0)
            return gltf_fail(L, SY_ERR_PARSE, "KHR_lights_punctual.lights[%zu]: intensity %g must be finite and >= 0", i,
                             l->intensity);
        if (!isfinite(l->range) || l->range < 0)
            return gltf_fail(L, SY_ERR_PARSE, "KHR_lights_punctual.lights[%zu]: range %g must be finite and >= 0", i, l->range);
        if (!isfinite(l->inner_cone) || !isfinite(l->outer_cone))
            return gltf_fail(L, SY_ERR_PARSE, "KHR_lights_punctual.lights[%zu]: spot cone angles must be finite", i);
    }
    if ((r = validate_nodes(L))) return r;
    for (size_t s = 0; s < d->scene_count; s++) {
        const sy_gltf_shim_scene *sc = &d->scenes[s];
        for (size_t k = 0; k < sc->node_count; k++) {
            int32_t n = sc->nodes[k];
            if (n < 0 || (size_t)n >= d->node_count)
                return gltf_fail(L, SY_ERR_PARSE, "scenes[%zu].nodes[%zu]: node %d out of range (%zu nodes)", s, k, (int)n, d->node_count);
            if (L->parent[n] != -1)
                return gltf_fail(L, SY_ERR_PARSE, "scenes[%zu].nodes[%zu]: nodes[%d] is not a root node (it is a child of nodes[%d])", s,
                                 k, (int)n, (int)L->parent[n]);
            for (size_t j = 0; j < k; j++)
                if (sc->nodes[j] == n)
                    return gltf_fail(L, SY_ERR_PARSE, "scenes[%zu].nodes: nodes[%d] is listed twice as a root", s, (int)n);
        }
    }
    if (d->default_scene != -1 && (d->default_scene < 0 || (size_t)d->default_scene >= d->scene_count))
        return gltf_fail(L, SY_ERR_PARSE, "scene %d out of range (%zu scenes)", (int)d->default_scene, d->scene_count);
    return SY_OK;
}
