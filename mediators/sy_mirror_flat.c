/* sy_mirror_flat.c — flat descriptions of mirrored textures, materials, primitives and lights (see
 * sy_mirror_flat.h): the one reading of the core fields that every back-end shares. */
#include "sy_mirror_flat.h"

#include "sy_post.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void sy_mirror_flat_texture_of(const sy_image_info *info, const sy_sampler *sampler, const void *pixels,
                               sy_mirror_flat_texture *out)
{
    *out = (sy_mirror_flat_texture){
        .width = info->width,
        .height = info->height,
        .channels = info->channels,
        .format = info->format == SY_PIXEL_U8_SRGB     ? SY_MIRROR_FLAT_UNORM8_SRGB
                  : info->format == SY_PIXEL_U8_LINEAR ? SY_MIRROR_FLAT_UNORM8
                                                       : SY_MIRROR_FLAT_FLOAT32,
        .pixels = pixels,
        .wrap_s = sampler->wrap_s,
        .wrap_t = sampler->wrap_t,
        .nearest = sampler->mag_filter == SY_FILTER_NEAREST,
    };
}

void sy_mirror_flat_texture_mean(const sy_mirror_flat_texture *t, float mean[3])
{
    size_t n = (size_t)t->width * t->height, ch = t->channels;
    double sum[3] = {0, 0, 0};
    if (t->format == SY_MIRROR_FLAT_FLOAT32) {
        const float *px = t->pixels;
        for (size_t i = 0; i < n; ++i)
            for (size_t c = 0; c < 3; ++c) {
                float v = px[i * ch + (ch <= 2 ? 0 : c)];
                if (isfinite(v)) sum[c] += v;
            }
    } else { /* 8 bits: count each code, then decode 256 values instead of one per texel */
        static const size_t zero[256];
        size_t count[3][256];
        for (size_t c = 0; c < 3; ++c) memcpy(count[c], zero, sizeof zero);
        const unsigned char *px = t->pixels;
        for (size_t i = 0; i < n; ++i)
            for (size_t c = 0; c < 3; ++c) count[c][px[i * ch + (ch <= 2 ? 0 : c)]]++;
        for (int v = 0; v < 256; ++v) {
            float x = v / 255.0f;
            if (t->format == SY_MIRROR_FLAT_UNORM8_SRGB) x = sy_srgb_decode(x);
            for (size_t c = 0; c < 3; ++c) sum[c] += (double)count[c][v] * x;
        }
    }
    for (int c = 0; c < 3; ++c) mean[c] = n ? (float)(sum[c] / (double)n) : 0.0f;
}

/* A factor the specifications bound to [0, 1] (core accepts any non-negative value). */
static float unit(float x) { return x < 0.0f ? 0.0f : x > 1.0f ? 1.0f : x; }

static sy_mirror_flat_texture_ref texref(const sy_texture_ref *r, sy_mirror_flat_handle_fn handle_of, const void *user)
{
    sy_mirror_flat_texture_ref o = {r->texture.id, r->texture.id ? handle_of(user, r->texture.id) : 0u, r->texcoord,
                                    false, {0}};
    o.transformed = sy_texture_ref_matrix(r, o.transform);
    return o;
}

void sy_mirror_flat_material_of(const sy_material_data *m, sy_mirror_flat_handle_fn handle_of, const void *user,
                                sy_mirror_flat_material *out)
{
    memset(out, 0, sizeof *out);
    memcpy(out->base_color, m->base_color, sizeof out->base_color);
    out->base_color_texture = texref(&m->base_color_texture, handle_of, user);
    out->metallic = m->metallic;
    out->roughness = m->roughness;
    out->metallic_roughness_texture = texref(&m->metallic_roughness_texture, handle_of, user);
    for (int i = 0; i < 3; ++i) out->emissive[i] = m->emissive[i] * m->emissive_strength;
    out->emissive_texture = texref(&m->emissive_texture, handle_of, user);
    out->normal_texture = texref(&m->normal_texture, handle_of, user);
    out->normal_scale = m->normal_texture.scale;
    out->occlusion_texture = texref(&m->occlusion_texture, handle_of, user);
    out->occlusion_strength = m->occlusion_texture.scale;
    out->transmission = unit(m->transmission);
    out->transmission_texture = texref(&m->transmission_texture, handle_of, user);
    out->ior = m->ior >= 1.0f ? m->ior : 1.5f;
    out->alpha_mode = m->alpha_mode;
    out->alpha_cutoff = m->alpha_cutoff;
    out->double_sided = m->double_sided != 0;
    out->unlit = m->unlit != 0;
    out->specular = unit(m->specular);
    out->specular_texture = texref(&m->specular_texture, handle_of, user);
    memcpy(out->specular_color, m->specular_color, sizeof out->specular_color);
    out->specular_color_texture = texref(&m->specular_color_texture, handle_of, user);
    out->clearcoat = unit(m->clearcoat);
    out->clearcoat_texture = texref(&m->clearcoat_texture, handle_of, user);
    out->clearcoat_roughness = unit(m->clearcoat_roughness);
    out->clearcoat_roughness_texture = texref(&m->clearcoat_roughness_texture, handle_of, user);
    out->clearcoat_normal_texture = texref(&m->clearcoat_normal_texture, handle_of, user);
    out->clearcoat_normal_scale = m->clearcoat_normal_texture.scale;
    for (int i = 0; i < 3; ++i) out->sheen_color[i] = unit(m->sheen_color[i]);
    out->sheen_color_texture = texref(&m->sheen_color_texture, handle_of, user);
    out->sheen_roughness = unit(m->sheen_roughness);
    out->sheen_roughness_texture = texref(&m->sheen_roughness_texture, handle_of, user);
    out->thickness = m->thickness;
    out->thickness_texture = texref(&m->thickness_texture, handle_of, user);
    out->attenuation_distance = m->attenuation_distance;
    for (int i = 0; i < 3; ++i) out->attenuation_color[i] = unit(m->attenuation_color[i]);
    out->iridescence = unit(m->iridescence);
    out->iridescence_texture = texref(&m->iridescence_texture, handle_of, user);
    out->iridescence_ior = m->iridescence_ior >= 1.0f ? m->iridescence_ior : 1.3f;
    out->iridescence_thickness[0] = m->iridescence_thickness[0];
    out->iridescence_thickness[1] = m->iridescence_thickness[1];
    out->iridescence_thickness_texture = texref(&m->iridescence_thickness_texture, handle_of, user);
    out->anisotropy = unit(m->anisotropy);
    out->anisotropy_rotation = m->anisotropy_rotation;
    out->anisotropy_texture = texref(&m->anisotropy_texture, handle_of, user);
}

void sy_mirror_flat_mesh_of(const sy_primitive *p, sy_mirror_flat_mesh *out)
{
    *out = (sy_mirror_flat_mesh){
        .positions = sy_blob_data(p->positions),
        .normals = sy_blob_data(p->normals),
        .uv = {sy_blob_data(p->texcoords0), sy_blob_data(p->texcoords1)},
        .colors = sy_blob_data(p->colors),
        .indices = sy_blob_data(p->indices),
        .vertex_count = sy_primitive_vertex_count(p),
        .triangle_count = sy_primitive_triangle_count(p),
    };
}

/* The slot of key in the open-addressed set of 2^bits keys (0 = empty): where it is, or the empty
 * slot where it would go. */
static size_t edge_slot(const uint64_t *set, unsigned bits, uint64_t key)
{
    size_t mask = ((size_t)1 << bits) - 1u, i = (size_t)((key * 0x9E3779B97F4A7C15ull) >> (64u - bits));
    while (set[i] && set[i] != key) i = (i + 1u) & mask;
    return i;
}

static uint32_t hash_pos(const float *p)
{
    uint32_t w[3];
    memcpy(w, p, sizeof w);
    uint64_t h = 0x9E3779B97F4A7C15ull;
    for (int k = 0; k < 3; ++k) { /* -0 welds to +0; a 64-bit mix of each word (splitmix64's finalizer) */
        h ^= w[k] == 0x80000000u ? 0u : w[k];
        h *= 0xBF58476D1CE4E5B9ull;
        h ^= h >> 31;
    }
    h *= 0x94D049BB133111EBull;
    return (uint32_t)(h >> 32);
}

int sy_mirror_flat_mesh_closed(const sy_mirror_flat_mesh *m)
{
    if (!m->positions || !m->triangle_count || m->triangle_count > SY_MIRROR_FLAT_CLOSED_MAX || !m->vertex_count) return 0;
    const uint32_t nv = m->vertex_count, nt = m->triangle_count;
    uint32_t cap = 1;
    while (cap < 2u * nv) cap <<= 1;
    uint32_t *slot = malloc((size_t)cap * sizeof *slot), *weld = malloc((size_t)nv * sizeof *weld);
    unsigned bits = 4; /* the directed edges' hash set: at least twice their count */
    while (((size_t)1 << bits) < 6u * (size_t)nt) bits++;
    uint64_t *edge = calloc((size_t)1 << bits, sizeof *edge);
    bool closed = slot && weld && edge;
    double vol = 0.0; /* six times the signed volume */
    if (closed) {
        memset(slot, 0xff, (size_t)cap * sizeof *slot);
        for (uint32_t v = 0; v < nv; ++v) { /* weld by exact position: the first vertex at a point names it */
            const float *p = m->positions + 3u * v;
            uint32_t h = hash_pos(p) & (cap - 1);
            for (;; h = (h + 1) & (cap - 1)) {
                if (slot[h] == UINT32_MAX) {
                    slot[h] = v;
                    weld[v] = v;
                    break;
                }
                const float *q = m->positions + 3u * slot[h];
                if (p[0] == q[0] && p[1] == q[1] && p[2] == q[2]) {
                    weld[v] = slot[h];
                    break;
                }
            }
        }
        size_t ne = 0; /* each directed edge once (a key is never 0: its ends differ) */
        for (uint32_t t = 0; t < nt && closed; ++t) {
            uint32_t i[3];
            for (int k = 0; k < 3; ++k) {
                uint32_t x = m->indices ? m->indices[3u * t + k] : 3u * t + k;
                if (x >= nv) closed = false;
                i[k] = closed ? weld[x] : 0;
            }
            if (i[0] == i[1] || i[1] == i[2] || i[2] == i[0]) continue; /* degenerate: no area, no edges */
            for (int k = 0; k < 3 && closed; ++k) {
                uint64_t key = (uint64_t)i[k] << 32 | i[(k + 1) % 3];
                size_t at = edge_slot(edge, bits, key);
                if (edge[at]) closed = false; /* an edge used twice the same way */
                edge[at] = key;
                ne++;
            }
            const float *p0 = m->positions + 3u * i[0], *p1 = m->positions + 3u * i[1], *p2 = m->positions + 3u * i[2];
            vol += p0[0] * ((double)p1[1] * p2[2] - (double)p1[2] * p2[1]) +
                   p0[1] * ((double)p1[2] * p2[0] - (double)p1[0] * p2[2]) +
                   p0[2] * ((double)p1[0] * p2[1] - (double)p1[1] * p2[0]);
        }
        closed = closed && ne > 0;
        for (size_t e = 0; closed && e < ((size_t)1 << bits); ++e) /* and its reverse present */
            if (edge[e] && !edge[edge_slot(edge, bits, edge[e] << 32 | edge[e] >> 32)]) closed = false;
    }
    free(slot);
    free(weld);
    free(edge);
    return !closed || !(vol != 0.0) ? 0 : vol > 0.0 ? 1 : -1;
}

void sy_mirror_flat_light_of(const sy_light_data *l, const float position[3], const float direction[3],
                             sy_mirror_flat_light *out)
{
    *out = (sy_mirror_flat_light){
        .type = l->type == SY_LIGHT_SPOT          ? SY_MIRROR_FLAT_SPOT
                : l->type == SY_LIGHT_DIRECTIONAL ? SY_MIRROR_FLAT_DIRECTIONAL
                                                  : SY_MIRROR_FLAT_POINT,
        .intensity = l->intensity,
        .range = l->range,
        .inner_cone = l->inner_cone,
        .outer_cone = l->outer_cone,
    };
    memcpy(out->color, l->color, sizeof out->color);
    memcpy(out->position, position, sizeof out->position);
    memcpy(out->direction, direction, sizeof out->direction);
}
