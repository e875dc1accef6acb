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

bool sy_mirror_flat_texture_means(const sy_mirror_flat_texture *t, uint32_t gw, uint32_t gh, float mean[3], float *blocks)
{
    const size_t ch = t->channels, w = t->width, h = t->height, n = w * h, step[3] = {0, ch <= 2 ? 0 : 1, ch <= 2 ? 0 : 2};
    const bool is_float = t->format == SY_MIRROR_FLAT_FLOAT32;
    float lut[256]; /* 8-bit codes decoded once */
    for (int v = 0; v < 256; ++v) lut[v] = t->format == SY_MIRROR_FLAT_UNORM8_SRGB ? sy_srgb_decode(v / 255.0f) : v / 255.0f;
    /* the whole image's sum: float texels added in row order; 8-bit codes counted, then 256
     * values decoded instead of one per texel */
    double sum[3] = {0, 0, 0};
    static const size_t zero[256];
    size_t count[3][256];
    for (size_t c = 0; c < 3; ++c) memcpy(count[c], zero, sizeof zero);
    double *row_sums = calloc((size_t)gw * 3 + 3, sizeof *row_sums); /* the blocks of one block row */
    if (!row_sums) return false;
    for (uint32_t j = 0; j < gh; ++j) {
        const size_t y0 = j * h / gh, y1 = (j + 1u) * h / gh;
        memset(row_sums, 0, sizeof *row_sums * 3 * gw);
        for (size_t y = y0; y < y1; ++y) /* each image row once, left to right: row order */
            for (uint32_t i = 0; i < gw; ++i) {
                const size_t x0 = i * w / gw, x1 = (i + 1u) * w / gw, row = (y * w + x0) * ch, m = (x1 - x0) * ch;
                float bs[3] = {0, 0, 0}; /* a block row's part in float (width / gw + 1 texels of at most 1 each) */
                if (is_float) {
                    const float *px = (const float *)t->pixels + row;
                    for (size_t k = 0; k < m; k += ch)
                        for (int c = 0; c < 3; ++c) {
                            const float v = px[k + step[c]];
                            if (isfinite(v)) sum[c] += v, bs[c] += v;
                        }
                } else {
                    const unsigned char *px = (const unsigned char *)t->pixels + row;
                    for (size_t k = 0; k < m; k += ch)
                        for (int c = 0; c < 3; ++c) count[c][px[k + step[c]]]++, bs[c] += lut[px[k + step[c]]];
                }
                for (int c = 0; c < 3; ++c) row_sums[3u * i + (size_t)c] += bs[c];
            }
        for (uint32_t i = 0; i < gw; ++i) {
            const double texels = (double)(((i + 1u) * w / gw - i * w / gw) * (y1 - y0));
            for (int c = 0; c < 3; ++c)
                blocks[3 * ((size_t)j * gw + i) + (size_t)c] = texels > 0.0 ? (float)(row_sums[3u * i + (size_t)c] / texels) : 0.0f;
        }
    }
    free(row_sums);
    if (!is_float)
        for (int v = 0; v < 256; ++v)
            for (size_t c = 0; c < 3; ++c) sum[c] += (double)count[c][v] * lut[v];
    for (int c = 0; c < 3; ++c) mean[c] = n ? (float)(sum[c] / (double)n) : 0.0f;
    return true;
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

int sy_mirror_flat_mesh_closed(const sy_mirror_flat_mesh *m)
{
    return sy_mesh_closed(m->positions, m->vertex_count, m->indices, m->triangle_count);
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
