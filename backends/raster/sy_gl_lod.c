/* sy_gl_lod.c — levels of detail per view: the level each instance draws (its projected size
 * against the mesh's simplification error) and the draw of one level. */
#include "sy_gl_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Draws level `lod` of the mesh (0 or out of range = the mesh itself); returns the triangles drawn. */
uint32_t sy_gli_draw_mesh_lod(sy_gl_device *dev, const mesh_o *m, uint32_t lod)
{
    const sy_gl_fns *gl = dev->gl;
    gl->BindVertexArray(m->vao);
    if (!m->has_attr[1]) gl->VertexAttrib4f(1, 0, 0, 1, 0);
    if (!m->has_attr[2]) gl->VertexAttrib4f(2, 0, 0, 0, 0);
    if (!m->has_attr[3]) gl->VertexAttrib4f(3, 0, 0, 0, 0);
    if (!m->has_attr[4]) gl->VertexAttrib4f(4, 1, 1, 1, 1);
    if (lod >= m->lod_count) lod = 0;
    uint32_t tris = m->lod_tris[lod];
    double t0 = sy_gli_profile_thread(dev);
    if (m->indexed)
        gl->DrawElements(GL_TRIANGLES, (GLsizei)(3u * tris), GL_UNSIGNED_INT,
                         (const void *)((uintptr_t)m->lod_first[lod] * sizeof(uint32_t)));
    else gl->DrawArrays(GL_TRIANGLES, 0, (GLsizei)(3u * tris));
    sy_gli_profile_draw(dev, t0, "mesh");
    dev->draws++;
    return tris;
}

const mat_o *sy_gli_bind_material(sy_gl_device *dev, sy_gl_material id, bool all_textures)
{
    const sy_gl_fns *gl = dev->gl;
    const mat_o *m = sy_gli_pool_get(&dev->materials, id.id);
    dev->profile_mat = id.id;
    gl->BindBufferBase(GL_UNIFORM_BUFFER, BIND_MATERIAL, m ? m->ubo : dev->default_ubo);
    /* the default material (none) binds the stand-ins: left unbound, a unit samples the GL's own
     * incomplete-texture stand-in, and llvmpipe compiles the program once more for it */
    const sy_gl_texture_ref *refs[5] = {NULL};
    if (m) {
        refs[0] = &m->d.base_color_texture, refs[1] = &m->d.metallic_roughness_texture, refs[2] = &m->d.normal_texture;
        refs[3] = &m->d.occlusion_texture, refs[4] = &m->d.emissive_texture;
    }
    for (int i = 0; i < (all_textures ? 5 : 1); ++i) {
        const tex_o *t = m ? sy_gli_pool_get(&dev->textures, refs[i]->texture.id) : NULL;
        gl->ActiveTexture(GL_TEXTURE0 + (GLenum)i);
        gl->BindTexture(GL_TEXTURE_2D, t ? t->tex : dev->standin[i]);
    }
    if (!all_textures || !dev->layer_units) return m;
    const sy_gl_texture_ref *lr[LAYER_TEXTURES] = {NULL};
    if (m) sy_gli_layer_refs(&m->d, lr);
    for (int i = 0; i < LAYER_TEXTURES; ++i) { /* the layers' (sy_gl_shaders_layers.c reads them where m_lt says) */
        const tex_o *t = m ? sy_gli_pool_get(&dev->textures, lr[i]->texture.id) : NULL;
        gl->ActiveTexture(GL_TEXTURE0 + UNIT_LAYER0 + (GLenum)i);
        gl->BindTexture(GL_TEXTURE_2D, t ? t->tex : dev->standin[5 + i]);
    }
    return m;
}

/* Every visible instance's level for view v (before the shadow maps, which reuse them). */
void sy_gli_choose_lods(sy_gl_device *dev, const view_setup *v)
{
    for (uint32_t i = 0; i < dev->instances.count; ++i) {
        inst_o *in = sy_gli_pool_at(&dev->instances, i);
        const mesh_o *m = in->h.id ? sy_gli_pool_get(&dev->meshes, in->mesh.id) : NULL;
        if (!m) continue;
        float c[3], scale, r = sy_gli_world_sphere(in, m, c, &scale);
        in->lod = sy_gli_choose_lod(dev, m, v, c, r, scale);
    }
}

void sy_gl_set_lod(sy_gl_device *dev, float pixels)
{
    if (dev) dev->lod_pixels = isfinite(pixels) && pixels > 0.0f ? pixels : 0.0f;
}

float sy_gli_sphere_px_per_unit(const view_setup *v, const float c[3], float r)
{
    if (!(v->ppu > 0.0f)) return 0.0f;
    if (v->ortho) return v->ppu;
    float d = (c[0] - v->cam_pos[0]) * v->cam_fwd[0] + (c[1] - v->cam_pos[1]) * v->cam_fwd[1] +
              (c[2] - v->cam_pos[2]) * v->cam_fwd[2] - r;
    return d > 1e-6f ? v->ppu / d : 0.0f;
}

/* The coarsest level whose deviation, projected at the sphere's nearest distance, stays within
 * dev->lod_pixels pixels (0 when the view's scale is unknown or the view is inside the sphere). */
uint32_t sy_gli_choose_lod(const sy_gl_device *dev, const mesh_o *m, const view_setup *v, const float c[3], float r,
                           float scale)
{
    if (m->lod_count < 2 || dev->lod_pixels <= 0.0f) return 0;
    float px_per_m = sy_gli_sphere_px_per_unit(v, c, r);
    if (!(px_per_m > 0.0f)) return 0;
    uint32_t lod = 0;
    while (lod + 1 < m->lod_count && m->lod_error[lod + 1] * scale * px_per_m <= dev->lod_pixels) ++lod;
    return lod;
}

/* An instance's projected bounding-sphere area (at most the target's) over the triangles of level
 * lod: how many pixels its forward shading would run on per triangle. Deferred shading pays off on
 * small triangles (DEFERRED_MAX_PX_PER_TRI). */
float sy_gli_pixels_per_triangle(const sy_gl_device *dev, const mesh_o *m, uint32_t lod, const view_setup *v,
                                 const float c[3], float r)
{
    float screen = (float)dev->t.w * (float)dev->t.h, px_per_m = sy_gli_sphere_px_per_unit(v, c, r);
    if (!(px_per_m > 0.0f)) return screen;
    float rp = r * px_per_m, area = 3.14159265f * rp * rp;
    if (!(area < screen)) area = screen;
    uint32_t tris = m->lod_tris[lod < m->lod_count ? lod : 0];
    return tris ? area / (float)tris : screen;
}
