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
        in->lod = sy_gli_choose_lod(dev, in, m, v, c, r, scale);
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

void sy_gli_view_bounds(view_setup *v)
{
    float vp[16], inv[16];
    sy_gli_m4_mul(v->proj, v->view, vp);
    sy_gli_frustum_planes(vp, v->planes);
    v->bounds_ok = sy_gli_m4_invert(vp, inv);
    for (int k = 0; k < 4 && v->bounds_ok; ++k) { /* normalised device (+-1, +-1, -1) back to the world */
        const float x = k & 1 ? 1.0f : -1.0f, y = k & 2 ? 1.0f : -1.0f;
        float p[4];
        for (int a = 0; a < 4; ++a) p[a] = inv[a] * x + inv[4 + a] * y - inv[8 + a] + inv[12 + a];
        if (!(fabsf(p[3]) > 0.0f)) v->bounds_ok = false;
        for (int a = 0; a < 3 && v->bounds_ok; ++a) v->near_pts[k][a] = p[a] / p[3];
    }
}

static float dot3(const float a[3], const float b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* The convex polygon in (n points) clipped to the half-space pl . x + pl[3] >= 0, into out (at most
 * n + 1 points); returns its point count. */
static int clip_polygon(const float (*in)[3], int n, const float pl[4], float (*out)[3])
{
    int k = 0;
    for (int i = 0; i < n; ++i) {
        const float *a = in[i], *b = in[(i + 1) % n];
        float da = dot3(pl, a) + pl[3], db = dot3(pl, b) + pl[3];
        if (da >= 0.0f) memcpy(out[k++], a, sizeof out[0]);
        if ((da >= 0.0f) != (db >= 0.0f)) {
            float t = da / (da - db);
            for (int c = 0; c < 3; ++c) out[k][c] = a[c] + t * (b[c] - a[c]);
            ++k;
        }
    }
    return k;
}

/* Whether p lies inside the parallelepiped box (corners as sy_gli_instance_box); a flat box holds
 * nothing. */
static bool inside_box(const float box[8][3], const float p[3])
{
    float e[3][3], d[3];
    for (int c = 0; c < 3; ++c) {
        e[0][c] = box[1][c] - box[0][c], e[1][c] = box[2][c] - box[0][c], e[2][c] = box[4][c] - box[0][c];
        d[c] = p[c] - box[0][c];
    }
    for (int a = 0; a < 3; ++a) {
        const float *u = e[(a + 1) % 3], *w = e[(a + 2) % 3];
        const float n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
        float len = dot3(e[a], n), t = dot3(d, n);
        if (!(len != 0.0f)) return false;
        if (len < 0.0f) len = -len, t = -t;
        if (!(t >= 0.0f && t <= len)) return false;
    }
    return true;
}

/* The nearest depth along v's forward axis of the part of the world box inside v's frustum, 0 when
 * no part is (within float rounding). A corner of box and frustum together lies on a face of the
 * box (clipped by the frustum's planes) or is a corner of the frustum, of which only the near
 * plane's can be the nearest. */
static float box_nearest_depth(const view_setup *v, const float box[8][3])
{
    float nearest = INFINITY;
    for (int a = 0; a < 3; ++a)
        for (int s = 0; s < 2; ++s) {
            const int b1 = 1 << ((a + 1) % 3), b2 = 1 << ((a + 2) % 3), o = s << a;
            const int idx[4] = {o, o | b1, o | b1 | b2, o | b2};
            float poly[2][4 + 6][3];
            int n = 4, cur = 0;
            for (int k = 0; k < 4; ++k) memcpy(poly[0][k], box[idx[k]], sizeof poly[0][0]);
            for (int pl = 0; pl < 6 && n > 0; ++pl) {
                if (!(dot3(v->planes[pl], v->planes[pl]) > 0.0f)) continue; /* an infinite far plane */
                n = clip_polygon((const float (*)[3])poly[cur], n, v->planes[pl], poly[1 - cur]);
                cur = 1 - cur;
            }
            for (int k = 0; k < n; ++k) {
                float d[3] = {poly[cur][k][0] - v->cam_pos[0], poly[cur][k][1] - v->cam_pos[1], poly[cur][k][2] - v->cam_pos[2]};
                nearest = fminf(nearest, dot3(d, v->cam_fwd));
            }
        }
    for (int k = 0; k < 4; ++k)
        if (inside_box(box, v->near_pts[k])) {
            float d[3] = {v->near_pts[k][0] - v->cam_pos[0], v->near_pts[k][1] - v->cam_pos[1], v->near_pts[k][2] - v->cam_pos[2]};
            nearest = fminf(nearest, dot3(d, v->cam_fwd));
        }
    return isfinite(nearest) && nearest > 0.0f ? nearest : 0.0f;
}

/* The coarsest level whose deviation, at px_per_m pixels per world unit, is within the budget. */
static uint32_t level_for(const sy_gl_device *dev, const mesh_o *m, float scale, float px_per_m)
{
    uint32_t lod = 0;
    if (!(px_per_m > 0.0f)) return 0;
    while (lod + 1 < m->lod_count && m->lod_error[lod + 1] * scale * px_per_m <= dev->lod_pixels) ++lod;
    return lod;
}

/* The sphere's nearest depth first (cheap); where that leaves a finer level than the coarsest, the
 * box's nearest visible point: a large mesh reaching towards or around the camera (a backdrop, a
 * floor under the eye) has its sphere's nearest point at or behind the eye, and drew every triangle
 * of level 0 (TransmissionTest's 43,779-triangle backdrop in each of 24 probe faces). */
uint32_t sy_gli_choose_lod(const sy_gl_device *dev, const inst_o *in, const mesh_o *m, const view_setup *v,
                           const float c[3], float r, float scale)
{
    if (m->lod_count < 2 || dev->lod_pixels <= 0.0f) return 0;
    uint32_t lod = level_for(dev, m, scale, sy_gli_sphere_px_per_unit(v, c, r));
    if (lod + 1 < m->lod_count && !v->ortho && v->bounds_ok && v->ppu > 0.0f) {
        float box[8][3];
        sy_gli_instance_box(in, m, box);
        float d = box_nearest_depth(v, box);
        if (d > 0.0f) {
            uint32_t l2 = level_for(dev, m, scale, v->ppu / d);
            if (l2 > lod) lod = l2;
        }
    }
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
