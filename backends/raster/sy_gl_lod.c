/* sy_gl_lod.c — levels of detail: the deviation of a simplified level from its mesh, measured when
 * the mesh is made (sy_gl_objects.c builds the levels), the level each instance draws per view (its
 * projected size against that deviation) and the draw of one level. */
#include "sy_gl_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The throttle (issue 39, memory on the user's path). llvmpipe bins the triangles of the draws into
 * scenes that its threads rasterise; while they are behind, it starts another scene instead of
 * waiting (up to 64 in Mesa 22), and a binned triangle takes about 270 bytes: a draw of 10^7 small
 * triangles (a large mesh at level 0, levels off or too close for a coarser one) held up to 450 MB
 * of scenes at once, the peak of the whole `sy render` (a 10^7-triangle grid with levels off: 121
 * bytes per triangle, 84 with the throttle). On a software rasterizer every THROTTLE_TRIANGLES
 * drawn get a fence (which also hands the scene to the threads), and before a new fence the one
 * THROTTLE_FENCES back is waited for, so at most that many chunks are binned and waiting; the
 * threads stay busy, and the frame was faster (fewer fresh pages). A GPU keeps its own queue:
 * there the waits would only leave it idle between chunks, so only llvmpipe and softpipe are
 * throttled (and only their draws are cut into chunks). */
static void throttle(sy_gl_device *dev, uint32_t tris)
{
    if (!dev->throttle || (dev->throttle_tris += tris) < THROTTLE_TRIANGLES) return;
    const sy_gl_fns *gl = dev->gl;
    dev->throttle_tris = 0;
    GLsync *slot = &dev->fences[dev->fence_next];
    if (*slot) { /* the wait ends when that chunk is rasterised (or the GL fails: nothing to hold then) */
        GLenum w;
        do w = gl->ClientWaitSync(*slot, GL_SYNC_FLUSH_COMMANDS_BIT, 1000000000u);
        while (w == GL_TIMEOUT_EXPIRED);
        gl->DeleteSync(*slot);
    }
    *slot = gl->FenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    dev->fence_next = (dev->fence_next + 1u) % THROTTLE_FENCES;
}

void sy_gli_throttle_free(sy_gl_device *dev)
{
    for (uint32_t i = 0; i < THROTTLE_FENCES; ++i)
        if (dev->fences[i]) dev->gl->DeleteSync(dev->fences[i]), dev->fences[i] = 0;
}

/* Draws level `lod` of the mesh (0 or out of range = the mesh itself); returns the triangles drawn.
 * On a software rasterizer in chunks of at most THROTTLE_TRIANGLES, throttled (above). */
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
    const uint32_t chunk = dev->throttle ? THROTTLE_TRIANGLES : tris;
    for (uint32_t first = 0; first < tris; first += chunk) {
        const uint32_t n = tris - first < chunk ? tris - first : chunk;
        if (m->indexed)
            gl->DrawElements(GL_TRIANGLES, (GLsizei)(3u * n), GL_UNSIGNED_INT,
                             (const void *)(((uintptr_t)m->lod_first[lod] + 3u * (uintptr_t)first) * sizeof(uint32_t)));
        else gl->DrawArrays(GL_TRIANGLES, (GLint)(3u * first), (GLsizei)(3u * n));
        throttle(dev, n);
    }
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

/* The coarsest level whose deviation (err: m->lod_error or m->lod_error_uv), at px_per_m pixels per
 * world unit, is within the budget. */
static uint32_t level_for(const sy_gl_device *dev, const mesh_o *m, const float *err, float scale, float px_per_m)
{
    uint32_t lod = 0;
    if (!(px_per_m > 0.0f)) return 0;
    while (lod + 1 < m->lod_count && err[lod + 1] * scale * px_per_m <= dev->lod_pixels) ++lod;
    return lod;
}

/* Whether instance in's material samples a texture (its uv0's slide shows). */
static bool textured(const sy_gl_device *dev, const inst_o *in)
{
    const mat_o *mt = sy_gli_pool_get(&dev->materials, in->material.id);
    return mt && sy_gli_material_textures(dev, mt) != 0;
}

/* The sphere's nearest depth first (cheap); where that leaves a finer level than the coarsest, the
 * box's nearest visible point: a large mesh reaching towards or around the camera (a backdrop, a
 * floor under the eye) has its sphere's nearest point at or behind the eye, and drew every triangle
 * of level 0 (TransmissionTest's 43,779-triangle backdrop in each of 24 probe faces). */
uint32_t sy_gli_choose_lod(const sy_gl_device *dev, const inst_o *in, const mesh_o *m, const view_setup *v,
                           const float c[3], float r, float scale)
{
    if (m->lod_count < 2 || dev->lod_pixels <= 0.0f) return 0;
    const float *err = textured(dev, in) ? m->lod_error_uv : m->lod_error;
    uint32_t lod = level_for(dev, m, err, scale, sy_gli_sphere_px_per_unit(v, c, r));
    if (lod + 1 < m->lod_count && !v->ortho && v->bounds_ok && v->ppu > 0.0f) {
        float box[8][3];
        sy_gli_instance_box(in, m, box);
        float d = box_nearest_depth(v, box);
        if (d > 0.0f) {
            uint32_t l2 = level_for(dev, m, err, scale, v->ppu / d);
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

/* >>level shading deviation (at creation, sy_gl_objects.c build_lods) */

/* The closest point of triangle (a, b, c) to p: its barycentric weights into w (Ericson, Real-Time
 * Collision Detection, 5.1.5); returns the squared distance. */
static float closest_on_triangle(const float p[3], const float a[3], const float b[3], const float c[3], float w[3])
{
    float ab[3], ac[3], ap[3];
    for (int k = 0; k < 3; ++k) ab[k] = b[k] - a[k], ac[k] = c[k] - a[k], ap[k] = p[k] - a[k];
    float d1 = dot3(ab, ap), d2 = dot3(ac, ap);
    if (d1 <= 0.0f && d2 <= 0.0f) w[0] = 1.0f, w[1] = w[2] = 0.0f;
    else {
        float bp[3], cp[3];
        for (int k = 0; k < 3; ++k) bp[k] = p[k] - b[k], cp[k] = p[k] - c[k];
        float d3 = dot3(ab, bp), d4 = dot3(ac, bp), d5 = dot3(ab, cp), d6 = dot3(ac, cp);
        float vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
        if (d3 >= 0.0f && d4 <= d3) w[1] = 1.0f, w[0] = w[2] = 0.0f;
        else if (d6 >= 0.0f && d5 <= d6) w[2] = 1.0f, w[0] = w[1] = 0.0f;
        else if (vc <= 0.0f && d1 >= 0.0f && d3 <= 0.0f) {
            float v = d1 / (d1 - d3);
            w[0] = 1.0f - v, w[1] = v, w[2] = 0.0f;
        } else if (vb <= 0.0f && d2 >= 0.0f && d6 <= 0.0f) {
            float v = d2 / (d2 - d6);
            w[0] = 1.0f - v, w[1] = 0.0f, w[2] = v;
        } else if (va <= 0.0f && (d4 - d3) >= 0.0f && (d5 - d6) >= 0.0f) {
            float v = (d4 - d3) / ((d4 - d3) + (d5 - d6));
            w[0] = 0.0f, w[1] = 1.0f - v, w[2] = v;
        } else {
            float den = va + vb + vc, v = den != 0.0f ? vb / den : 1.0f / 3.0f, u = den != 0.0f ? vc / den : 1.0f / 3.0f;
            w[0] = 1.0f - v - u, w[1] = v, w[2] = u;
        }
    }
    float q[3], dd = 0.0f;
    for (int k = 0; k < 3; ++k) {
        q[k] = w[0] * a[k] + w[1] * b[k] + w[2] * c[k];
        dd += (p[k] - q[k]) * (p[k] - q[k]);
    }
    return dd;
}

/* (b - a) x (c - a) of triangle t of d: its face normal times twice its area. */
static void tri_cross(const sy_gl_mesh_desc *d, const uint32_t *t, float n[3])
{
    const float *a = d->positions + 3u * t[0], *b = d->positions + 3u * t[1], *c = d->positions + 3u * t[2];
    float e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    n[0] = e1[1] * e2[2] - e1[2] * e2[1], n[1] = e1[2] * e2[0] - e1[0] * e2[2], n[2] = e1[0] * e2[1] - e1[1] * e2[0];
}

/* The normal of triangle t at weights w, not normalised: its vertex normals interpolated, or its
 * face normal when the mesh has none (the rasterizer's flat normals); false when it has no
 * direction. normal_at: the same, of unit length. */
static bool normal_dir(const sy_gl_mesh_desc *d, const uint32_t *t, const float w[3], float n[3])
{
    if (d->normals) {
        for (int k = 0; k < 3; ++k)
            n[k] = w[0] * d->normals[3u * t[0] + k] + w[1] * d->normals[3u * t[1] + k] + w[2] * d->normals[3u * t[2] + k];
    } else
        tri_cross(d, t, n);
    float l2 = dot3(n, n);
    return l2 > 0.0f && isfinite(l2);
}

static bool normal_at(const sy_gl_mesh_desc *d, const uint32_t *t, const float w[3], float n[3])
{
    if (!normal_dir(d, t, w, n)) return false;
    float l = sqrtf(dot3(n, n));
    for (int k = 0; k < 3; ++k) n[k] /= l;
    return true;
}

static float angle_between(const float a[3], const float b[3]) { return acosf(fminf(fmaxf(dot3(a, b), -1.0f), 1.0f)); }

static void uv_at(const sy_gl_mesh_desc *d, const uint32_t *t, const float w[3], float uv[2])
{
    for (int k = 0; k < 2; ++k) uv[k] = w[0] * d->uv[0][2u * t[0] + k] + w[1] * d->uv[0][2u * t[1] + k] + w[2] * d->uv[0][2u * t[2] + k];
}

/* Metres (object space) per unit of uv0 on triangle t of d: the square root of its area over its
 * area in uv0 (0 without uv0, or where either is 0: no uv term there). */
static float metres_per_uv(const sy_gl_mesh_desc *d, const uint32_t *t)
{
    if (!d->uv[0]) return 0.0f;
    float n[3];
    tri_cross(d, t, n);
    const float *u0 = d->uv[0] + 2u * t[0], *u1 = d->uv[0] + 2u * t[1], *u2 = d->uv[0] + 2u * t[2];
    float aw = sqrtf(dot3(n, n)), au = fabsf((u1[0] - u0[0]) * (u2[1] - u0[1]) - (u1[1] - u0[1]) * (u2[0] - u0[0]));
    float r = aw > 0.0f && au > 0.0f ? sqrtf(aw / au) : 0.0f;
    return isfinite(r) ? r : 0.0f;
}

bool sy_gli_normals_beyond_geometry(const sy_gl_mesh_desc *d)
{
    if (!d->normals || !d->indices) return false;
    float *acc = calloc((size_t)d->vertex_count * 3, sizeof *acc);
    if (!acc) return true; /* without memory: counted, the safe side */
    for (size_t t = 0; t < d->triangle_count; ++t) { /* area-weighted face normals at each vertex index */
        const uint32_t *i = d->indices + 3 * t;
        float n[3];
        tri_cross(d, i, n);
        for (int k = 0; k < 3; ++k)
            for (int j = 0; j < 3; ++j) acc[3u * i[k] + j] += n[j];
    }
    size_t off = 0, used = 0;
    for (size_t v = 0; v < d->vertex_count; ++v) {
        float *g = acc + 3 * v, l = sqrtf(dot3(g, g));
        const float *n = d->normals + 3 * v;
        float ln = sqrtf(dot3(n, n));
        if (!(l > 0.0f) || !(ln > 0.0f) || !isfinite(l) || !isfinite(ln)) continue;
        used++;
        off += dot3(g, n) < cosf(LOD_NORMAL_TURN) * l * ln;
    }
    free(acc);
    return off * 100u > used; /* more than 1 % of the vertices */
}

float sy_gli_level_shading_error(const sy_gl_mesh_desc *d, const float bmin[3], const float bmax[3], const uint32_t *level,
                                 size_t tris, float tol, bool normals_count, float *with_uv)
{
    *with_uv = INFINITY;
    if (!d->indices || !tris) return INFINITY;
    /* the grid: cubes of about four of the level's triangles' area each (surfaces are two-dimensional),
     * at most LOD_CHECK_CELLS of them */
    int g[3];
    float ext = 0.0f;
    double area = 0.0;
    for (int k = 0; k < 3; ++k) ext = fmaxf(ext, bmax[k] - bmin[k]);
    if (!(ext > 0.0f)) return 0.0f;
    for (size_t t = 0; t < tris; ++t) {
        float n[3];
        tri_cross(d, level + 3 * t, n);
        area += 0.5 * sqrt((double)dot3(n, n));
    }
    float cell = (float)sqrt(4.0 * area / (double)tris);
    size_t cells;
    for (;;) {
        if (!(cell > 1e-6f * ext)) cell = 1e-6f * ext;
        cells = 1;
        for (int k = 0; k < 3; ++k) {
            g[k] = (int)fminf(1024.0f, floorf((bmax[k] - bmin[k]) / cell) + 1.0f);
            cells *= (size_t)g[k];
        }
        if (cells <= LOD_CHECK_CELLS) break;
        cell *= 1.5f;
    }
    tol = fmaxf(tol, 1e-4f * ext);
    const float reach = fmaxf(4.0f * tol, 0.25f * cell); /* how far from a sample its level triangle is looked for */
    /* each triangle in every cell its box, grown by reach, touches (counting, then filling) */
    uint32_t *start = calloc(cells + 1, sizeof *start), *list = NULL;
    float sample_err = INFINITY;
    if (!start) return INFINITY;
    size_t total = 0;
    for (int pass = 0; pass < 2; ++pass) {
        for (size_t t = 0; t < tris && total <= LOD_CHECK_CELL_REFS * tris; ++t) {
            int lo[3], hi[3];
            for (int k = 0; k < 3; ++k) {
                float a = d->positions[3u * level[3 * t] + k], b = d->positions[3u * level[3 * t + 1] + k],
                      c = d->positions[3u * level[3 * t + 2] + k];
                lo[k] = (int)floorf((fminf(a, fminf(b, c)) - reach - bmin[k]) / cell);
                hi[k] = (int)floorf((fmaxf(a, fmaxf(b, c)) + reach - bmin[k]) / cell);
                lo[k] = lo[k] < 0 ? 0 : lo[k] >= g[k] ? g[k] - 1 : lo[k];
                hi[k] = hi[k] < 0 ? 0 : hi[k] >= g[k] ? g[k] - 1 : hi[k];
            }
            for (int z = lo[2]; z <= hi[2]; ++z)
                for (int y = lo[1]; y <= hi[1]; ++y)
                    for (int x = lo[0]; x <= hi[0]; ++x) {
                        size_t c = ((size_t)z * g[1] + y) * g[0] + x;
                        if (pass == 0) start[c + 1]++, total++;
                        else list[start[c]++] = (uint32_t)t;
                    }
        }
        if (pass == 0) {
            if (total > LOD_CHECK_CELL_REFS * tris) break; /* long slivers across the grid: no bound */
            for (size_t c = 0; c < cells; ++c) start[c + 1] += start[c];
            if (!(list = malloc(sizeof *list * (start[cells] ? start[cells] : 1)))) break;
        } else
            for (size_t c = cells; c > 0; --c) start[c] = start[c - 1]; /* the fill moved each start to its end */
    }
    if (list) {
        start[0] = 0;
        /* the samples: every triangle, or one at a hashed place in each of LOD_CHECK_SAMPLES equal
         * runs of the index list (a fixed stride fell on the same columns of every row of a grid) */
        const size_t n_all = d->triangle_count, n_s = n_all > LOD_CHECK_SAMPLES ? LOD_CHECK_SAMPLES : n_all;
        sample_err = 0.0f;
        float uv_err = 0.0f;
        for (size_t i = 0; i < n_s && isfinite(sample_err); ++i) {
            size_t s = i;
            if (n_s < n_all) {
                uint32_t h = (uint32_t)i * 2654435761u;
                h ^= h >> 15;
                s = (size_t)(((double)i + (double)h / 4294967296.0) * (double)n_all / (double)n_s);
                if (s >= n_all) s = n_all - 1;
            }
            const uint32_t *o = d->indices + 3 * s;
            float p[3], w3[3] = {1.0f / 3.0f, 1.0f / 3.0f, 1.0f / 3.0f}, n0[3];
            for (int k = 0; k < 3; ++k)
                p[k] = (d->positions[3u * o[0] + k] + d->positions[3u * o[1] + k] + d->positions[3u * o[2] + k]) / 3.0f;
            if (!normal_at(d, o, w3, n0)) continue; /* a degenerate triangle of the mesh shades nothing */
            const float s_uv = metres_per_uv(d, o);
            size_t c = 0;
            for (int k = 2; k >= 0; --k) {
                int i = (int)floorf((p[k] - bmin[k]) / cell);
                c = c * (size_t)g[k] + (size_t)(i < 0 ? 0 : i >= g[k] ? g[k] - 1 : i);
            }
            /* the level's surface at the sample: of its triangles within reach, those facing the
             * sample's way (a thin shell's two sides lie within reach of each other), the nearest
             * and those about as near (within tol: both sides of a uv seam or a crease), the one
             * whose normal and uv are closest to the sample's; the others where none faces its way.
             * The candidates are kept (up to LOD_CHECK_NEAR; beyond, the nearest replace the
             * farthest) and then weighed. */
            struct { float dist, w[3]; uint32_t tri; bool facing; } cand[LOD_CHECK_NEAR];
            uint32_t nc = 0;
            float best[2] = {INFINITY, INFINITY}, err = INFINITY, err_uv = INFINITY;
            for (uint32_t j = start[c]; j < start[c + 1]; ++j) {
                const uint32_t *t = level + 3u * list[j];
                float wj[3], n1[3], dd = closest_on_triangle(p, d->positions + 3u * t[0], d->positions + 3u * t[1],
                                                             d->positions + 3u * t[2], wj);
                if (!(dd <= reach * reach)) continue;
                float dist = sqrtf(dd);
                bool facing = normal_dir(d, t, wj, n1) && dot3(n0, n1) > 0.0f;
                best[facing] = fminf(best[facing], dist);
                uint32_t slot = nc;
                if (nc == LOD_CHECK_NEAR) { /* full: the farthest kept gives way to a nearer one */
                    slot = 0;
                    for (uint32_t i = 1; i < nc; ++i)
                        if (cand[i].dist > cand[slot].dist) slot = i;
                    if (cand[slot].dist <= dist) continue;
                } else
                    nc++;
                cand[slot].dist = dist, cand[slot].tri = list[j], cand[slot].facing = facing;
                memcpy(cand[slot].w, wj, sizeof wj);
            }
            const int set = isfinite(best[1]) ? 1 : 0;
            for (uint32_t i = 0; i < nc; ++i) {
                if ((set == 1 && !cand[i].facing) || cand[i].dist > best[set] + tol) continue;
                const uint32_t *t = level + 3u * cand[i].tri;
                float n1[3], e = cand[i].dist, edge = 0.0f;
                for (int k = 0; k < 3; ++k) {
                    const float *pa = d->positions + 3u * t[k], *pb = d->positions + 3u * t[(k + 1) % 3];
                    float v[3] = {pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]};
                    edge = fmaxf(edge, sqrtf(dot3(v, v)));
                }
                if (normals_count && normal_at(d, t, cand[i].w, n1)) e = fmaxf(e, angle_between(n0, n1) * 0.5f * edge);
                float eu = e;
                if (s_uv > 0.0f) {
                    float u0[2], u1[2];
                    uv_at(d, o, w3, u0);
                    uv_at(d, t, cand[i].w, u1);
                    eu = fmaxf(e, s_uv * sqrtf((u0[0] - u1[0]) * (u0[0] - u1[0]) + (u0[1] - u1[1]) * (u0[1] - u1[1])));
                }
                err = fminf(err, e), err_uv = fminf(err_uv, eu);
            }
            if (!isfinite(err)) { /* no level triangle within reach: no bound */
                sample_err = INFINITY;
                break;
            }
            if (err > sample_err) sample_err = err;
            if (err_uv > uv_err) uv_err = err_uv;
        }
        if (isfinite(sample_err)) *with_uv = uv_err;
    }
    free(start);
    free(list);
    return sample_err;
}
