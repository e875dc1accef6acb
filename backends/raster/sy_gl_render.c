/* sy_gl_render.c — a frame: scene probes (cube maps for mirror-like and glass instances) and the
 * frame entry points sy_gl_render and sy_gl_render_floor. */
#include "sy_gl_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Whether an instance's material is mirror-like or glass enough to need the scene around it. */
static bool wants_probe(const mat_o *mt)
{
    if (!mt || mt->d.roughness > PROBE_MAX_ROUGHNESS) return false;
    return mt->d.metallic >= 0.5f || mt->d.transmission * (1.0f - mt->d.metallic) >= 0.5f;
}

/* The instances that get a probe: the first SY_GL_MAX_PROBES visible mirror-like or glass ones
 * (pool indices into idx); returns how many. */
static uint32_t pick_probes(const sy_gl_device *dev, uint32_t idx[SY_GL_MAX_PROBES])
{
    uint32_t n = 0;
    for (uint32_t i = 0; i < dev->instances.count && n < SY_GL_MAX_PROBES; ++i) {
        const inst_o *in = sy_gli_pool_at(&dev->instances, i);
        if (!in->h.id || !in->visible || !sy_gli_pool_get(&dev->meshes, in->mesh.id)) continue;
        if (wants_probe(sy_gli_pool_get(&dev->materials, in->material.id))) idx[n++] = i;
    }
    return n;
}

/* The probes' side for view v of a w x h frame: the power of two at or above the largest projected
 * radius, in pixels, of a probed instance in view (a mirror sphere of radius R pixels spreads a
 * 90-degree face over about 1.3 R pixels at its centre), within [PROBE_SIZE_MIN, PROBE_SIZE_MAX]
 * and at most the power of two at or above half the frame's larger side; never below the side
 * they have (see SY_GL_MAX_PROBES). */
static uint32_t probe_size_for(const sy_gl_device *dev, const view_setup *v, uint32_t w, uint32_t h)
{
    uint32_t idx[SY_GL_MAX_PROBES], n = pick_probes(dev, idx), half = (w > h ? w : h) / 2u;
    float vp[16], planes[6][4], need = 0.0f;
    sy_gli_m4_mul(v->proj, v->view, vp);
    sy_gli_frustum_planes(vp, planes);
    for (uint32_t p = 0; p < n; ++p) {
        const inst_o *in = sy_gli_pool_at(&dev->instances, idx[p]);
        float c[3], scale, r = sy_gli_world_sphere(in, sy_gli_pool_get(&dev->meshes, in->mesh.id), c, &scale);
        if (sy_gli_sphere_outside(planes, c, r)) continue;
        float ppm = sy_gli_sphere_px_per_unit(v, c, r);
        float px = ppm > 0.0f ? r * ppm : (float)half; /* unknown scale, or the view inside: the frame's cap */
        if (px > need) need = px;
    }
    if (need > (float)half) need = (float)half;
    uint32_t s = PROBE_SIZE_MIN;
    while ((float)s < need && s < PROBE_SIZE_MAX) s *= 2u;
    return s > dev->probe_size ? s : dev->probe_size;
}

/* Frees the probes' cube maps and depth buffer (made again at the next render_probes). */
void sy_gli_probes_free(sy_gl_device *dev)
{
    const sy_gl_fns *gl = dev->gl;
    for (uint32_t p = 0; p < SY_GL_MAX_PROBES; ++p)
        if (dev->probes[p].cube) {
            gl->DeleteTextures(1, &dev->probes[p].cube);
            dev->probes[p].cube = 0;
        }
    if (dev->probe_fbo) gl->DeleteFramebuffers(1, &dev->probe_fbo);
    if (dev->probe_depth) gl->DeleteRenderbuffers(1, &dev->probe_depth);
    dev->probe_fbo = dev->probe_depth = 0;
}

/* (Re)renders the scene probes (see SY_GL_MAX_PROBES). */
static sy_gl_result render_probes(sy_gl_device *dev, sy_gl_report *rep)
{
    const sy_gl_fns *gl = dev->gl;
    uint32_t idx[SY_GL_MAX_PROBES];
    dev->probe_count = pick_probes(dev, idx);
    float centres[SY_GL_MAX_PROBES][3];
    for (uint32_t p = 0; p < dev->probe_count; ++p) {
        const inst_o *in = sy_gli_pool_at(&dev->instances, idx[p]);
        const mesh_o *m = sy_gli_pool_get(&dev->meshes, in->mesh.id);
        float *c = centres[p];
        for (int a = 0; a < 3; ++a) {
            c[a] = in->model[12 + a];
            for (int k = 0; k < 3; ++k) c[a] += in->model[4 * k + a] * 0.5f * (m->bmin[k] + m->bmax[k]);
        }
        dev->probes[p].inst = idx[p];
    }
    if (!dev->probe_count) return SY_GL_OK;
    const GLsizei ps = (GLsizei)dev->probe_size;
    if (!dev->probe_fbo) {
        gl->GenFramebuffers(1, &dev->probe_fbo);
        gl->GenRenderbuffers(1, &dev->probe_depth);
        gl->BindRenderbuffer(GL_RENDERBUFFER, dev->probe_depth);
        gl->RenderbufferStorageMultisample(GL_RENDERBUFFER, 0, GL_DEPTH_COMPONENT32F, ps, ps);
    }
    float sc[3], R;
    sy_gli_scene_bounds(dev, sc, &R);
    const tex_o *env = dev->env_ready ? sy_gli_pool_get(&dev->textures, dev->env_tex.id) : NULL;
    sy_gli_bind_frame_resources(dev);
    dev->in_probe_pass = true;
    sy_gl_result r = SY_GL_OK;
    for (uint32_t p = 0; p < dev->probe_count && r == SY_GL_OK; ++p) {
        if (!dev->probes[p].cube) {
            gl->GenTextures(1, &dev->probes[p].cube);
            gl->BindTexture(GL_TEXTURE_CUBE_MAP, dev->probes[p].cube);
            for (int f = 0; f < 6; ++f)
                gl->TexImage2D(GL_TEXTURE_CUBE_MAP_POSITIVE_X + (GLenum)f, 0, GL_RGBA16F, ps, ps, 0, GL_RGBA,
                               GL_FLOAT, NULL);
            gl->TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
            gl->TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
            gl->TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
            gl->TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
            gl->TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
        }
        const float *c = centres[p];
        float dc = sqrtf((c[0] - sc[0]) * (c[0] - sc[0]) + (c[1] - sc[1]) * (c[1] - sc[1]) + (c[2] - sc[2]) * (c[2] - sc[2]));
        double far = dc + R, nearp = fmax(1e-4 * far, 1e-5);
        for (int f = 0; f < 6 && r == SY_GL_OK; ++f) {
            view_setup v;
            memset(&v, 0, sizeof v);
            sy_gli_cube_face_view(c, f, v.view);
            sy_gli_projection(false, -1.0, 1.0, -1.0, 1.0, nearp, far, v.proj);
            /* a 90-degree face: ps pixels across 2 units of the image plane at distance 1; the
             * levels of detail follow (before, every face drew every mesh whole: MetalRoughSpheres'
             * four probes drew 10^6 triangles 24 times) */
            v.ppu = (float)ps / 2.0f;
            memcpy(v.cam_pos, c, sizeof v.cam_pos);
            memcpy(v.cam_fwd, sy_gli_cube_faces[f][2], sizeof v.cam_fwd);
            sy_gli_view_bounds(&v);
            gl->BindFramebuffer(GL_FRAMEBUFFER, dev->probe_fbo);
            gl->FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_CUBE_MAP_POSITIVE_X + (GLenum)f,
                                     dev->probes[p].cube, 0);
            gl->FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, dev->probe_depth);
            static const GLenum bufs[2] = {GL_COLOR_ATTACHMENT0, GL_NONE};
            gl->DrawBuffers(2, bufs);
            gl->Viewport(0, 0, ps, ps);
            gl->ColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
            gl->DepthMask(GL_TRUE);
            const float black[4] = {0, 0, 0, 1}, one = 1.0f;
            gl->ClearBufferfv(GL_COLOR, 0, black);
            gl->ClearBufferfv(GL_DEPTH, 0, &one);
            gl->Disable(GL_CULL_FACE);
            gl->Disable(GL_BLEND);
            if (env) /* rays that leave the scene see the environment (a light) */
                sy_gli_draw_latlong(dev, &v, env, dev->env_intensity, (uint32_t)ps, (uint32_t)ps);
            gl->Enable(GL_DEPTH_TEST);
            gl->DepthFunc(GL_LESS);
            dev->frame_no++; /* the variants take this face's camera */
            r = sy_gli_draw_scene(dev, &v, dev->probes[p].inst, rep);
        }
        if (r == SY_GL_OK) r = sy_gli_cube_mipmaps(dev, dev->probes[p].cube, dev->probe_fbo, (uint32_t)ps, rep);
    }
    dev->in_probe_pass = false;
    dev->frame_no++;
    if (r == SY_GL_OK) r = sy_gli_gl_check(dev, "scene probes", rep);
    return r;
}

/* What every frame starts with: the context sy_gli_current, the view, the targets, zeroed counters. */
static sy_gl_result frame_setup(sy_gl_device *dev, const sy_gl_camera *cam, const sy_gl_render_desc *d, view_setup *v, sy_gl_report *rep)
{
    sy_gl_result r = sy_gli_current(dev, rep);
    if (r == SY_GL_OK) r = sy_gli_view_make(dev, cam, d, v, rep);
    if (r == SY_GL_OK) sy_gli_clip_set(dev, cam);
    if (r == SY_GL_OK) r = sy_gli_targets_ensure(dev, d->width, d->height, rep);
    dev->tris = dev->draws = 0;
    return r;
}

sy_gl_result sy_gl_render(sy_gl_device *dev, const sy_gl_camera *cam, const sy_gl_render_desc *d, float *rgba,
                          float *depth)
{
    sy_gl_report *rep = dev ? dev->report : NULL;
    view_setup v;
    sy_gl_result r = frame_setup(dev, cam, d, &v, rep);
    if (r != SY_GL_OK) return r;
    const sy_gl_fns *gl = dev->gl;
    double prof[6][2]; /* environment, shadows, probes, main, read-back (wall, CPU); the frame */
    sy_gli_profile_mark(dev, true, prof[0]);
    dev->frame_no++;
    sy_gli_shadow_size_follow(dev, d->width, d->height);
    uint32_t env_side = sy_gl_ibl_side(d->width, d->height);
    if (env_side > dev->env_side) { /* a larger frame than any before: a sharper specular cube */
        dev->env_side = env_side;
        if (dev->env_ready) dev->env_dirty = true;
    }
    static frame_state fs_zero;
    frame_state fs = fs_zero;
    if (dev->env_dirty) {
        const tex_o *et = sy_gli_pool_get(&dev->textures, dev->env_tex.id);
        dev->env_ready = false;
        if (et) {
            dev->profile_var = -1;
            double t0 = sy_gli_profile_thread(dev);
            r = sy_gl_ibl_tables(gl, &dev->ibl, rep);
            sy_gli_profile_draw(dev, t0, "BRDF and LTC tables");
            t0 = sy_gli_profile_thread(dev);
            if (r == SY_GL_OK)
                r = sy_gl_ibl_prefilter(gl, &dev->ibl, et->tex, et->width, et->height, dev->env_intensity, dev->env_side, rep);
            sy_gli_profile_draw(dev, t0, "environment prefilter");
            if (r != SY_GL_OK) return r;
            dev->env_ready = true;
        }
        dev->env_dirty = false;
        dev->probes_dirty = true;
    }
    if (dev->area_count && (r = sy_gl_ibl_tables(gl, &dev->ibl, rep)) != SY_GL_OK) return r;
    sy_gli_profile_mark(dev, false, prof[0]);
    if (dev->lights_dirty) {
        sy_gli_choose_lods(dev, &v); /* shadow maps draw the levels this view picks */
        sy_gli_lights_upload(dev, &fs);
        if ((fs.shadow_count || fs.cube_count) && !dev->shadow_tex) { /* the maps' size is known now */
            if ((r = sy_gli_shadow_maps_make(dev, rep)) != SY_GL_OK) return r;
            fs = fs_zero;
            sy_gli_lights_upload(dev, &fs);
        }
        if (fs.shadow_count || fs.cube_count) sy_gli_render_shadows(dev, &fs);
        else dev->shadow_maps = 0;
        dev->lights_dirty = false;
        dev->probes_dirty = true;
    }
    sy_gli_profile_mark(dev, false, prof[1]);
    sy_gli_frame_features(dev);
    /* the layers read the sheen albedo from the BRDF table, with punctual lights alone too */
    if ((dev->shared_features & VAR_LAYERS) && (r = sy_gl_ibl_tables(gl, &dev->ibl, rep)) != SY_GL_OK) return r;
    uint32_t psize = probe_size_for(dev, &v, d->width, d->height);
    if (psize != dev->probe_size) { /* a probed instance larger in view than before: sharper probes */
        sy_gli_probes_free(dev);
        dev->probe_size = psize;
        dev->probes_dirty = true;
    }
    if (dev->probes_dirty) {
        if ((r = render_probes(dev, rep)) != SY_GL_OK) return r;
        dev->probes_dirty = false;
    }
    sy_gli_profile_mark(dev, false, prof[2]);
    const uint64_t probe_tris = dev->tris; /* (shadow maps do not count theirs) */
    sy_gli_begin_target(dev, &v);
    sy_gli_bind_frame_resources(dev);
    r = sy_gli_draw_scene(dev, &v, UINT32_MAX, rep);
    sy_gli_profile_mark(dev, false, prof[3]);
    if (r == SY_GL_OK) r = sy_gli_finish_target(dev, &v, rgba, depth, rep);
    sy_gli_profile_mark(dev, false, prof[4]);
    sy_gli_frame_end(dev);
    if (dev->profile) {
        prof[5][0] = prof[5][1] = 0.0;
        for (int i = 0; i < 5; ++i) prof[5][0] += prof[i][0], prof[5][1] += prof[i][1];
        fprintf(stderr,
                "raster profile: frame %.3f s (cpu %.3f): environment %.3f (%.3f), shadows %.3f (%.3f), probes %u %.3f "
                "(%.3f), main %.3f (%.3f), resolve and read-back %.3f (%.3f); triangles drawn: probes %llu, main %llu\n",
                prof[5][0], prof[5][1], prof[0][0], prof[0][1], prof[1][0], prof[1][1], dev->probe_count, prof[2][0],
                prof[2][1], prof[3][0], prof[3][1], prof[4][0], prof[4][1], (unsigned long long)probe_tris,
                (unsigned long long)(dev->tris - probe_tris));
    }
    return r;
}

sy_gl_result sy_gl_render_floor(sy_gl_device *dev, const sy_gl_camera *cam, const sy_gl_render_desc *d, bool lit,
                                float *rgba, float *depth)
{
    sy_gl_report *rep = dev ? dev->report : NULL;
    view_setup v;
    sy_gl_result r = frame_setup(dev, cam, d, &v, rep);
    if (r != SY_GL_OK) return r;
    const sy_gl_fns *gl = dev->gl;
    sy_gli_begin_target(dev, NULL);
    const int k = lit ? 1 : 0;
    gl->UseProgram(lit ? dev->prog_floor_lit : dev->prog_floor);
    dev->profile_var = -1;
    gl->UniformMatrix4fv(dev->uf[k].view, 1, GL_FALSE, v.view);
    gl->UniformMatrix4fv(dev->uf[k].proj, 1, GL_FALSE, v.proj);
    float vp[16], planes[6][4];
    sy_gli_m4_mul(v.proj, v.view, vp);
    sy_gli_frustum_planes(vp, planes);
    for (uint32_t i = 0; i < dev->instances.count; ++i) { /* the same culling and levels as sy_gl_render */
        inst_o *in = sy_gli_pool_at(&dev->instances, i);
        if (!in->h.id || !in->visible) continue;
        const mesh_o *m = sy_gli_pool_get(&dev->meshes, in->mesh.id);
        if (!m) continue;
        float c[3], scale, r = sy_gli_world_sphere(in, m, c, &scale);
        if (sy_gli_sphere_outside(planes, c, r)) continue;
        in->lod = sy_gli_choose_lod(dev, in, m, &v, c, r, scale);
        gl->UniformMatrix4fv(dev->uf[k].model, 1, GL_FALSE, in->model);
        dev->tris += sy_gli_draw_mesh_lod(dev, m, in->lod);
    }
    r = sy_gli_finish_target(dev, NULL, rgba, depth, rep);
    sy_gli_frame_end(dev);
    return r;
}
