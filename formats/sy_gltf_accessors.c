/* sy_gltf_accessors.c — reading glTF accessors out of their buffers (validated before:
 * sy_gltf_validate.c): components of every type (normalized or not) as floats or unsigned
 * integers, strides, sparse substitution, one element or the whole accessor. */
#include "sy_gltf_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

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
    return d->buffers[v->buffer].data + v->byte_offset + a->byte_offset + i * gltf_accessor_stride(d, a);
}

static const uint8_t *sparse_value_ptr(const sy_gltf_doc *d, const sy_gltf_shim_accessor *a, size_t k)
{
    const sy_gltf_shim_view *vv = &d->views[a->sparse_values_view];
    return d->buffers[vv->buffer].data + vv->byte_offset + (size_t)a->sparse_values_offset + k * gltf_element_size(a);
}

/* Sparse substitution k of accessor ai: the element it replaces (checked) and its replacement. */
static sy_result sparse_entry(loader *L, size_t ai, size_t k, size_t *target, const uint8_t **value)
{
    const sy_gltf_doc *d = L->doc;
    const sy_gltf_shim_accessor *a = &d->accessors[ai];
    const sy_gltf_shim_view *iv = &d->views[a->sparse_indices_view];
    size_t isz = gltf_component_size(a->sparse_indices_type);
    const uint8_t *ip = d->buffers[iv->buffer].data + iv->byte_offset + (size_t)a->sparse_indices_offset + k * isz;
    uint32_t idx = load_uint(ip, a->sparse_indices_type);
    if ((size_t)idx >= a->count)
        return gltf_fail(L, SY_ERR_PARSE, "accessors[%zu].sparse.indices[%zu]: index %u >= accessor count %zu", ai, k, (unsigned)idx, a->count);
    *target = idx;
    *value = sparse_value_ptr(d, a, k);
    return SY_OK;
}

/* Reads accessor ai as floats, out_comps per element (missing components: 0, except a 4th = 1).
 * *out is malloc()ed, count * out_comps floats. */
sy_result gltf_read_floats(loader *L, size_t ai, size_t out_comps, float **out)
{
    const sy_gltf_doc *d = L->doc;
    const sy_gltf_shim_accessor *a = &d->accessors[ai];
    sy_result r = SY_OK;
    *out = NULL;
    size_t n;
    if (!sy_size_mul(a->count, out_comps, &n)) return gltf_fail(L, SY_ERR_LIMIT, "accessors[%zu]: count %zu overflows", ai, a->count);
    float *f = gltf_xcalloc(L, n, sizeof(float), &r);
    if (!f) return r;
    size_t comps = (size_t)a->components < out_comps ? (size_t)a->components : out_comps;
    size_t cs = gltf_component_size(a->component_type);
    bool norm = a->normalized != 0;
    for (size_t i = 0; i < a->count; i++) {
        float *dst = f + i * out_comps;
        const uint8_t *p = element_ptr(d, a, i);
        for (size_t c = 0; c < comps; c++) dst[c] = p ? load_component(p + c * cs, a->component_type, norm) : 0.0f;
        if (out_comps == 4 && comps < 4) dst[3] = 1.0f;
    }
    for (size_t k = 0; a->sparse && r == SY_OK && k < (size_t)a->sparse_count; k++) {
        size_t t = 0; /* set by sparse_entry on success (GCC -O3 cannot tell) */
        const uint8_t *p = NULL;
        if ((r = sparse_entry(L, ai, k, &t, &p)) == SY_OK)
            for (size_t c = 0; c < comps; c++) f[t * out_comps + c] = load_component(p + c * cs, a->component_type, norm);
    }
    if (r == SY_OK) *out = f;
    else free(f);
    return r;
}

/* Element i of accessor ai (i < count) as out_comps floats, sparse substitution applied; allocates
 * nothing (for accessors whose count is bounded by no limit, such as animation outputs). */
sy_result gltf_read_element(loader *L, size_t ai, size_t i, size_t out_comps, float *dst)
{
    const sy_gltf_doc *d = L->doc;
    const sy_gltf_shim_accessor *a = &d->accessors[ai];
    size_t comps = (size_t)a->components < out_comps ? (size_t)a->components : out_comps;
    size_t cs = gltf_component_size(a->component_type);
    bool norm = a->normalized != 0;
    const uint8_t *p = element_ptr(d, a, i);
    for (size_t c = 0; c < out_comps; c++) dst[c] = c < comps && p ? load_component(p + c * cs, a->component_type, norm) : 0.0f;
    if (out_comps == 4 && comps < 4) dst[3] = 1.0f;
    if (a->sparse) {
        for (size_t k = 0; k < (size_t)a->sparse_count; k++) {
            size_t t = 0; /* set by sparse_entry on success (GCC -O3 cannot tell) */
            const uint8_t *q = NULL;
            sy_result r = sparse_entry(L, ai, k, &t, &q);
            if (r) return r;
            if (t != i) continue;
            for (size_t c = 0; c < comps; c++) dst[c] = load_component(q + c * cs, a->component_type, norm);
        }
    }
    return SY_OK;
}

sy_result gltf_read_uints(loader *L, size_t ai, uint32_t **out)
{
    const sy_gltf_doc *d = L->doc;
    const sy_gltf_shim_accessor *a = &d->accessors[ai];
    sy_result r = SY_OK;
    *out = NULL;
    uint32_t *u = gltf_xcalloc(L, a->count, sizeof(uint32_t), &r);
    if (!u) return r;
    for (size_t i = 0; i < a->count; i++) {
        const uint8_t *p = element_ptr(d, a, i);
        u[i] = p ? load_uint(p, a->component_type) : 0;
    }
    for (size_t k = 0; a->sparse && r == SY_OK && k < (size_t)a->sparse_count; k++) {
        size_t t = 0; /* set by sparse_entry on success (GCC -O3 cannot tell) */
        const uint8_t *p = NULL;
        if ((r = sparse_entry(L, ai, k, &t, &p)) == SY_OK) u[t] = load_uint(p, a->component_type);
    }
    if (r == SY_OK) *out = u;
    else free(u);
    return r;
}
