/* sy_gl_shadows.c — lights of a frame: the Lights and Areas uniform blocks and the shadow maps
 * (directional/spot arrays, point-light cubes, area-light maps) with their casters. */
#include "sy_gl_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* >>render */
void sy_gli_scene_bounds(const sy_gl_device *dev, float *c, float *radius)
{
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    float box[8][3];
    for (uint32_t i = 0; sy_gli_next_box(dev, &i, box);)
        for (int k = 0; k < 8; ++k)
            for (int a = 0; a < 3; ++a) lo[a] = fminf(lo[a], box[k][a]), hi[a] = fmaxf(hi[a], box[k][a]);
    if (!(lo[0] <= hi[0])) {
        c[0] = c[1] = c[2] = 0.0f;
        *radius = 1.0f;
        return;
    }
    float r2 = 0.0f;
    for (int a = 0; a < 3; ++a) {
        c[a] = 0.5f * (lo[a] + hi[a]);
        r2 += 0.25f * (hi[a] - lo[a]) * (hi[a] - lo[a]);
    }
    *radius = fmaxf(sqrtf(r2), 1e-3f);
}

/* Lights UBO (+ shadow matrices from the scene bounds). One upload. */
/* An emissive polygon wholly on the removed side of one of the frame's section planes lights
 * nothing, as in the ray tracers (an emitter point in a removed part is unseen there); one cut
 * through it keeps it whole (its light from the removed part stays: docs/BACKENDS.md). */
static bool area_removed(const sy_gl_device *dev, const sy_gl_area_light *a)
{
    for (uint32_t c = 0; c < dev->clip_count; ++c) {
        const float *q = dev->clip_planes[c];
        uint32_t k = 0;
        while (k < a->vertex_count &&
               q[0] * a->vertices[k][0] + q[1] * a->vertices[k][1] + q[2] * a->vertices[k][2] + q[3] < 0.0f)
            ++k;
        if (a->vertex_count && k == a->vertex_count) return true;
    }
    return false;
}

/* A polygon's emitted power up to a constant: luminance x area (x 2 when two-sided). */
static double area_flux(const sy_gl_area_light *a)
{
    if (a->vertex_count < 3) return 0.0;
    float e1[3], e2[3], nrm[3];
    for (int c = 0; c < 3; ++c) {
        e1[c] = a->vertices[1][c] - a->vertices[0][c];
        e2[c] = a->vertices[2][c] - a->vertices[0][c];
    }
    sy_gli_cross3(e1, e2, nrm);
    double area = sqrt((double)sy_gli_dot3f(nrm, nrm)) * (a->vertex_count == 4 ? 1.0 : 0.5);
    double lum = 0.2126 * a->radiance[0] + 0.7152 * a->radiance[1] + 0.0722 * a->radiance[2];
    return lum * area * (a->double_sided ? 2.0 : 1.0);
}

void sy_gli_lights_upload(sy_gl_device *dev, frame_state *fs)
{
    float blk[LIGHTS_FLOATS];
    memset(blk, 0, sizeof blk);
    int32_t *ib = (int32_t *)(void *)blk;
    float c[3], R;
    sy_gli_scene_bounds(dev, c, &R);
    uint32_t n = 0, ns = 0;
    for (uint32_t i = 0; i < dev->lights.count; ++i) {
        const light_o *l = sy_gli_pool_at(&dev->lights, i);
        if (!l->h.id) continue;
        if (n == SY_GL_MAX_LIGHTS) {
            if (!dev->warned_lights)
                sy_gli_warn(dev, "raster: more than %d lights; the rest are ignored", SY_GL_MAX_LIGHTS);
            dev->warned_lights = true;
            break;
        }
        const sy_gl_light_desc *d = &l->d;
        float *o = blk + 88 + 16 * n;
        float dir[3] = {d->direction[0], d->direction[1], d->direction[2]};
        sy_gli_v3_norm(dir);
        memcpy(o, d->position, 3 * sizeof(float));
        o[3] = (float)d->type;
        memcpy(o + 4, dir, sizeof dir);
        o[7] = d->range;
        for (int k = 0; k < 3; ++k) o[8 + k] = d->color[k] * d->intensity;
        float ci = cosf(d->inner_cone_angle), co = cosf(d->outer_cone_angle);
        o[12] = 1.0f / fmaxf(0.001f, ci - co);
        o[13] = -co * o[12];
        o[14] = -1.0f;
        o[15] = -1.0f;
        if (d->type == SY_GL_LIGHT_POINT && !d->no_shadow && fs->cube_count < SY_GL_MAX_CUBE_SHADOWS) {
            /* a depth cube map around the light (GL's face order and orientation, seamless
             * filtering); the shader compares the window depth of the major axis */
            uint32_t slot = fs->cube_count++;
            float dc = sqrtf((d->position[0] - c[0]) * (d->position[0] - c[0]) +
                             (d->position[1] - c[1]) * (d->position[1] - c[1]) +
                             (d->position[2] - c[2]) * (d->position[2] - c[2]));
            float far = dc + R, nearp = fmaxf(1e-3f * far, 1e-4f);
            memcpy(fs->cube_pos[slot], d->position, sizeof fs->cube_pos[slot]);
            fs->cube_near[slot] = nearp;
            fs->cube_far[slot] = far;
            blk[LIGHTS_CUBE_PAR + 4 * slot] = nearp;
            blk[LIGHTS_CUBE_PAR + 4 * slot + 1] = far;
            blk[LIGHTS_CUBE_PAR + 4 * slot + 2] = 1.5f * 2.0f / (float)dev->cube_size; /* normal offset per unit distance */
            o[15] = (float)slot;
        }
        if (d->type != SY_GL_LIGHT_POINT && !d->no_shadow && ns < SY_GL_MAX_SHADOW_MAPS) {
            float view[16], proj[16];
            float S = (float)dev->shadow_size;
            if (d->type == SY_GL_LIGHT_DIRECTIONAL) {
                float eye[3] = {c[0] - dir[0] * 2.0f * R, c[1] - dir[1] * 2.0f * R, c[2] - dir[2] * 2.0f * R};
                sy_gli_look_along(eye, dir, view);
                sy_gli_projection(true, -R, R, -R, R, 0.5 * R, 3.5 * R, proj);
                blk[72 + 4 * ns] = 1.5f * 2.0f * R / S;
                blk[72 + 4 * ns + 1] = 0.0f;
            } else {
                float half = fminf(d->outer_cone_angle + 0.01f, 1.48f), t = tanf(half);
                float dc = sqrtf((d->position[0] - c[0]) * (d->position[0] - c[0]) +
                                 (d->position[1] - c[1]) * (d->position[1] - c[1]) +
                                 (d->position[2] - c[2]) * (d->position[2] - c[2]));
                double far = dc + R, nearp = fmax(1e-3 * far, 1e-4);
                sy_gli_look_along(d->position, dir, view);
                sy_gli_projection(false, -t, t, -t, t, nearp, far, proj);
                blk[72 + 4 * ns] = 1.5f * 2.0f * t / S;
                blk[72 + 4 * ns + 1] = 1.0f;
            }
            sy_gli_m4_mul(proj, view, fs->shadow_vp[ns]);
            memcpy(blk + 8 + 16 * ns, fs->shadow_vp[ns], 16 * sizeof(float));
            o[14] = (float)ns;
            ns++;
        }
        n++;
    }
    ib[0] = (int32_t)n;
    blk[4] = (float)(SY_GL_IBL_SPEC_LEVELS - 1); /* l_env.x: the roughness-1 mip of the specular cube */
    memcpy(blk + 5, dev->ambient, sizeof dev->ambient); /* l_env.yzw: the area lights' indirect radiance */
    /* emissive polygons: one shadow map each from its centre along its emitting normal (a 150 degree
     * frustum) while maps are left; penumbrae widen with the polygon's size (sy_gl.h) */
    float ab[AREAS_FLOATS];
    memset(ab, 0, sizeof ab);
    int32_t *aib = (int32_t *)(void *)ab;
    uint32_t ns_punctual = ns;
    uint32_t na = 0; /* the polygons uploaded: those not wholly on a removed side of a section plane */
    double flux_all = 0.0, flux_kept = 0.0; /* the indirect estimate follows the emitters kept */
    for (uint32_t i = 0; i < dev->area_count; ++i) {
        const sy_gl_area_light *a = &dev->areas[i];
        double fl = area_flux(a);
        flux_all += fl;
        if (area_removed(dev, a)) continue;
        flux_kept += fl;
        float *o = ab + 8 + 24 * na++, cen[3] = {0, 0, 0}, e1[3], e2[3], nrm[3];
        for (uint32_t k = 0; k < 4; ++k) {
            const float *v = a->vertices[k < a->vertex_count ? k : a->vertex_count - 1];
            memcpy(o + 4 * k, v, 3 * sizeof(float));
            if (k < a->vertex_count)
                for (int c = 0; c < 3; ++c) cen[c] += v[c] / (float)a->vertex_count;
        }
        o[3] = (float)a->vertex_count;
        memcpy(o + 16, a->radiance, 3 * sizeof(float));
        o[19] = a->double_sided ? 1.0f : 0.0f;
        memcpy(o + 20, cen, sizeof cen);
        o[23] = -1.0f;
        for (int c = 0; c < 3; ++c) {
            e1[c] = a->vertices[1][c] - a->vertices[0][c];
            e2[c] = a->vertices[2][c] - a->vertices[0][c];
        }
        sy_gli_cross3(e1, e2, nrm);
        float area2 = sqrtf(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]) * (a->vertex_count == 4 ? 1.0f : 0.5f);
        if (!a->double_sided) { /* a_dir: flux-weighted mean emission direction (two-sided: none) */
            float flux = (0.2126f * a->radiance[0] + 0.7152f * a->radiance[1] + 0.0722f * a->radiance[2]) * area2, l = sqrtf(sy_gli_dot3f(nrm, nrm));
            for (int c = 0; c < 3 && l > 0.0f; ++c) ab[4 + c] += flux * nrm[c] / l;
            ab[7] += flux;
        } else
            ab[7] += 2.0f * (0.2126f * a->radiance[0] + 0.7152f * a->radiance[1] + 0.0722f * a->radiance[2]) * area2;
        if (!(area2 > 0.0f) || ns >= SY_GL_MAX_SHADOW_MAPS) continue;
        sy_gli_v3_norm(nrm);
        float view[16], proj[16], t = tanf(75.0f * 3.14159265f / 180.0f), S = (float)dev->shadow_size;
        float dc = sqrtf((cen[0] - c[0]) * (cen[0] - c[0]) + (cen[1] - c[1]) * (cen[1] - c[1]) + (cen[2] - c[2]) * (cen[2] - c[2]));
        double far = dc + R, nearp = fmax(1e-3 * far, 1e-4);
        sy_gli_look_along(cen, nrm, view);
        sy_gli_projection(false, -t, t, -t, t, nearp, far, proj);
        sy_gli_m4_mul(proj, view, fs->shadow_vp[ns]);
        memcpy(blk + 8 + 16 * ns, fs->shadow_vp[ns], 16 * sizeof(float));
        blk[72 + 4 * ns] = 1.5f * 2.0f * t / S;
        blk[72 + 4 * ns + 1] = 1.0f;
        blk[72 + 4 * ns + 2] = 0.15f * sqrtf(area2) / t; /* penumbra radius (uv) x distance */
        blk[72 + 4 * ns + 3] = 2.0f * t;
        o[23] = (float)ns;
        ns++;
    }
    aib[0] = (int32_t)na;
    if (na < dev->area_count && flux_all > 0.0)
        for (int c = 0; c < 3; ++c) blk[5 + c] = (float)(blk[5 + c] * (flux_kept / flux_all));
    for (int c = 0; c < 3; ++c) ab[4 + c] = ab[7] > 0.0f ? ab[4 + c] / ab[7] : 0.0f;
    ab[7] = 0.0f;
    fs->shadow_count = ns;
    dev->light_count = n;
    dev->light_sig = 0;
    for (uint32_t i = 0; i < n && i < VAR_NL_MAX; ++i) { /* 0 none, 1 a 2D map, 2 + s cube slot s */
        const float *o = blk + 88 + 16 * i;
        uint64_t kind = o[14] >= 0.0f ? 1u : o[15] >= 0.0f ? 2u + (uint64_t)o[15] : 0u;
        /* 0 point, 1 point with a range, 2 spot, 3 directional (shade_light's lt) */
        uint64_t type = o[3] == (float)SY_GL_LIGHT_DIRECTIONAL ? 3u : o[3] == (float)SY_GL_LIGHT_SPOT ? 2u : o[7] > 0.0f ? 1u : 0u;
        dev->light_sig |= kind << (2 * i) | type << (48 + 2 * i);
    }
    /* a_count.y: the polygons up to the last with a shadow map (the shaders' first loop); z: the
     * shadow taps per polygon (shadow_area's loop bound, a uniform so that it is not unrolled) */
    aib[1] = 0;
    for (uint32_t i = 0; i < na; ++i)
        if (ab[8 + 24 * i + 23] >= 0.0f) aib[1] = (int32_t)i + 1;
    aib[2] = 8;
    dev->shadow_count = ns_punctual + fs->cube_count;
    dev->area_shadow_count = ns - ns_punctual;
    dev->gl->BindBuffer(GL_UNIFORM_BUFFER, dev->lights_ubo);
    dev->gl->BufferSubData(GL_UNIFORM_BUFFER, 0, sizeof blk, blk);
    sy_gli_count_buffer(dev, true, sizeof blk);
    if (dev->area_count || dev->areas_dirty) {
        dev->gl->BindBuffer(GL_UNIFORM_BUFFER, dev->areas_ubo);
        dev->gl->BufferSubData(GL_UNIFORM_BUFFER, 0, sizeof ab, ab);
        sy_gli_count_buffer(dev, true, sizeof ab);
        dev->areas_dirty = false;
    }
}

/* Depth of every shadow caster into the attached depth target, seen through vp. Casters
 * as the ray tracers' shadow rays see them (backends/rt/sy_rt_shadow.c): opaque ones block;
 * alpha-masked ones block where the mask keeps them; alpha-blended ones let 1 - alpha through,
 * which a depth map can only threshold (opacity >= the cutoff, 0.5 unless set, blocks);
 * transmissive ones (transmission x (1 - metallic) >= 0.5) let their tinted transmittance through
 * and cast none; emitters are the lights and cast none either. */
static void draw_casters(sy_gl_device *dev, const float *vp)
{
    const sy_gl_fns *gl = dev->gl;
    gl->Clear(GL_DEPTH_BUFFER_BIT);
    for (int v = 0; v < 2; ++v) {
        gl->UseProgram(dev->ps[v].prog);
        dev->profile_var = -1;
        gl->UniformMatrix4fv(dev->ps[v].lightvp, 1, GL_FALSE, vp);
        for (uint32_t i = 0; i < dev->instances.count; ++i) {
            const inst_o *in = sy_gli_pool_at(&dev->instances, i);
            if (!in->h.id || !in->visible) continue;
            const mesh_o *m = sy_gli_pool_get(&dev->meshes, in->mesh.id);
            const mat_o *mt = sy_gli_pool_get(&dev->materials, in->material.id);
            int kind = mt ? sy_gli_caster_kind(&mt->d) : CASTER_OPAQUE;
            if (!m || kind == CASTER_NONE || (kind == CASTER_MASKED) != (v == 1)) continue;
            sy_gli_bind_material(dev, in->material, false);
            gl->UniformMatrix4fv(dev->ps[v].model, 1, GL_FALSE, in->model);
            sy_gli_draw_mesh_lod(dev, m, in->lod); /* the level of the last camera view */
        }
    }
}

/* The shadow maps' depth array, made on the first frame with a shadowed light: a scene without one
 * never allocates it (64 MiB zeroed by llvmpipe at the default 2048 texels, 0.2 s of a small first
 * frame). Its side is halved while the GL cannot hold it (the array of SY_GL_MAX_SHADOW_MAPS and a
 * point light's cube, made later, tried here): at 16384 texels the array alone is 4 GiB, and
 * llvmpipe refuses textures of 1 GiB and more with GL_OUT_OF_MEMORY. */
sy_gl_result sy_gli_shadow_maps_make(sy_gl_device *dev, sy_gl_report *rep)
{
    const sy_gl_fns *gl = dev->gl;
    sy_gl_result r = sy_gli_gl_check(dev, "before the shadow maps", rep);
    if (r != SY_GL_OK || dev->shadow_tex) return r;
    uint32_t asked = dev->shadow_size;
    for (;;) {
        dev->cube_size = dev->shadow_size / 2u > 16u ? dev->shadow_size / 2u : 16u;
        dev->shadow_tex = sy_gli_shadow_array(gl, dev->shadow_size, SY_GL_MAX_SHADOW_MAPS);
        GLenum e = gl->GetError();
        if (e == GL_NO_ERROR) {
            GLuint cube = sy_gli_shadow_cube(gl, dev->cube_size);
            e = gl->GetError();
            gl->DeleteTextures(1, &cube);
        }
        if (e != GL_OUT_OF_MEMORY || dev->shadow_size <= 16u) {
            if (e != GL_NO_ERROR) {
                gl->DeleteTextures(1, &dev->shadow_tex);
                dev->shadow_tex = 0;
                dev->shadow_size = asked;
                return sy_gli_fail(rep, e == GL_OUT_OF_MEMORY ? SY_GL_ERROR_OUT_OF_MEMORY : SY_GL_ERROR_GL,
                            "shadow maps of %u texels: OpenGL error 0x%04x", asked, (unsigned)e);
            }
            break;
        }
        gl->DeleteTextures(1, &dev->shadow_tex);
        dev->shadow_tex = 0;
        dev->shadow_size /= 2u;
    }
    if (dev->shadow_size != asked) {
        dev->shadow_auto = false; /* as large as the context holds: no larger frame asks again */
        sy_gli_warn(dev, "raster: shadow_map_size %u: the GL context cannot hold %d maps of that size; using %u", asked,
             SY_GL_MAX_SHADOW_MAPS, dev->shadow_size);
    }
    return SY_GL_OK;
}

/* shadow_map_size 0: the maps' side for a w x h frame (see SHADOW_SIZE_AUTO_MIN); a larger one than
 * the maps have frees them, so that the next shadowed frame makes and draws them again. */
void sy_gli_shadow_size_follow(sy_gl_device *dev, uint32_t w, uint32_t h)
{
    if (!dev->shadow_auto) return;
    uint32_t side = w > h ? w : h, s = SHADOW_SIZE_AUTO_MIN;
    while (s < 2u * side && s < SHADOW_SIZE_DEFAULT) s *= 2u;
    if (s > dev->max_tex) s = dev->max_tex;
    if (s <= dev->shadow_size) return;
    const sy_gl_fns *gl = dev->gl;
    if (dev->shadow_tex) gl->DeleteTextures(1, &dev->shadow_tex);
    dev->shadow_tex = 0;
    for (uint32_t c = 0; c < SY_GL_MAX_CUBE_SHADOWS; ++c)
        if (dev->cube_tex[c]) gl->DeleteTextures(1, &dev->cube_tex[c]);
    memset(dev->cube_tex, 0, sizeof dev->cube_tex);
    dev->shadow_size = s;
    dev->cube_size = s / 2u > 16u ? s / 2u : 16u;
    dev->lights_dirty = true;
}

void sy_gli_render_shadows(sy_gl_device *dev, const frame_state *fs)
{
    const sy_gl_fns *gl = dev->gl;
    gl->BindFramebuffer(GL_FRAMEBUFFER, dev->shadow_fbo);
    gl->DrawBuffer(GL_NONE);
    gl->ReadBuffer(GL_NONE);
    gl->Enable(GL_DEPTH_TEST);
    gl->DepthFunc(GL_LESS);
    gl->DepthMask(GL_TRUE);
    gl->Disable(GL_BLEND);
    gl->Enable(GL_POLYGON_OFFSET_FILL);
    gl->PolygonOffset(1.5f, 4.0f);
    gl->Viewport(0, 0, (GLsizei)dev->shadow_size, (GLsizei)dev->shadow_size);
    sy_gli_clip_enable(dev, true); /* the shadow maps see the cut model */
    for (uint32_t s = 0; s < fs->shadow_count; ++s) {
        gl->FramebufferTextureLayer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, dev->shadow_tex, 0, (GLint)s);
        draw_casters(dev, fs->shadow_vp[s]);
    }
    if (fs->cube_count) gl->Viewport(0, 0, (GLsizei)dev->cube_size, (GLsizei)dev->cube_size);
    for (uint32_t c = 0; c < fs->cube_count; ++c) {
        if (!dev->cube_tex[c]) dev->cube_tex[c] = sy_gli_shadow_cube(gl, dev->cube_size);
        float proj[16], view[16], vp[16];
        sy_gli_projection(false, -1.0, 1.0, -1.0, 1.0, fs->cube_near[c], fs->cube_far[c], proj);
        for (int f = 0; f < 6; ++f) {
            sy_gli_cube_face_view(fs->cube_pos[c], f, view);
            sy_gli_m4_mul(proj, view, vp);
            gl->FramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_CUBE_MAP_POSITIVE_X + (GLenum)f,
                                     dev->cube_tex[c], 0);
            draw_casters(dev, vp);
        }
    }
    sy_gli_clip_enable(dev, false);
    gl->Disable(GL_POLYGON_OFFSET_FILL);
    dev->shadow_maps = fs->shadow_count + 6u * fs->cube_count;
}
