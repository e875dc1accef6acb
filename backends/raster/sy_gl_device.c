/* sy_gl_device.c — the rasterizer device: create (context, programs, shared textures and
 * buffers), destroy, statistics and the window query. */
#include "sy_gl_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *sy_gl_device_error(const sy_gl_device *dev)
{
    return dev ? dev->report->message : "";
}

sy_gl_result sy_gl_device_create(const sy_gl_device_desc *desc, sy_gl_device **out)
{
    sy_gl_device_desc dd = {0};
    if (desc) dd = *desc;
    sy_gl_report create_report = {dd.error, dd.error_user, ""}; /* until the device exists */
    sy_gl_report *rep = &create_report;
    if (!out) return sy_gli_fail(rep, SY_GL_ERROR_INVALID_ARGUMENT, "GL device: out is NULL");
    *out = NULL;
    sy_gl_device *dev = calloc(1, sizeof *dev);
    if (!dev) return sy_gli_fail(rep, SY_GL_ERROR_OUT_OF_MEMORY, "GL device: out of memory");
    dev->report_store = create_report;
    rep = dev->report = &dev->report_store;
    dev->log = dd.log;
    dev->log_user = dd.log_user;
    dev->meshes.elem = sizeof(mesh_o);
    dev->textures.elem = sizeof(tex_o);
    dev->materials.elem = sizeof(mat_o);
    dev->instances.elem = sizeof(inst_o);
    dev->lights.elem = sizeof(light_o);
    sy_gl_result r = sy_gl_context_create(dd.provider, dd.window_width, dd.window_height, &dev->ctx, rep);
    if (r != SY_GL_OK) {
        free(dev);
        return r;
    }
    const sy_gl_fns *gl = dev->gl = sy_gl_context_fns(dev->ctx);
    const char *penv = getenv("SY_GL_PROFILE");
    dev->profile = penv && *penv && strcmp(penv, "0") != 0;
    dev->profile_var = -1;
    double prof[2];
    sy_gli_profile_mark(dev, true, prof);
    const char *renderer = (const char *)gl->GetString(GL_RENDERER);
    snprintf(dev->info, sizeof dev->info, "OpenGL %s on %s (%s)", (const char *)gl->GetString(GL_VERSION), renderer,
             sy_gl_provider_name(dd.provider));
    dev->throttle = renderer && (strstr(renderer, "llvmpipe") || strstr(renderer, "softpipe")); /* sy_gl_lod.c */
    GLint max_samples = 1, max_tex = 2048;
    gl->GetIntegerv(GL_MAX_SAMPLES, &max_samples);
    gl->GetIntegerv(GL_MAX_TEXTURE_SIZE, &max_tex);
    GLint max_units = 0;
    gl->GetIntegerv(GL_MAX_TEXTURE_IMAGE_UNITS, &max_units);
    dev->layer_units = max_units >= UNIT_COUNT; /* else the layers' textures are not read (GL 3.3 promises 16) */
    dev->msaa = dd.msaa > 1 ? dd.msaa : 1;
    if (dev->msaa > (uint32_t)max_samples) {
        sy_gli_warn(dev, "raster: %u MSAA samples requested, the GL context allows %d; using %d", dev->msaa, max_samples,
             max_samples);
        dev->msaa = (uint32_t)(max_samples > 1 ? max_samples : 1);
    }
    dev->max_tex = (uint32_t)max_tex;
    if (dd.max_texture_size && dd.max_texture_size < dev->max_tex) dev->max_tex = dd.max_texture_size;
    dev->shadow_auto = dd.shadow_map_size == 0;
    dev->shadow_size = dd.shadow_map_size ? dd.shadow_map_size : SHADOW_SIZE_AUTO_MIN;
    dev->lod_pixels = SY_GL_LOD_PIXELS_DEFAULT;
    if (dev->shadow_size > (uint32_t)max_tex) {
        sy_gli_warn(dev, "raster: shadow_map_size %u is above the GL context's texture limit; using %d", dev->shadow_size, max_tex);
        dev->shadow_size = (uint32_t)max_tex;
    }
    static const char *const defs[4] = {NULL, "#define SY_LEAN 1\n", "#define SY_MASK 1\n",
                                        "#define SY_MASK 1\n#define SY_LEAN 1\n"};
    /* the fullest main variant now, so that a shader the driver rejects fails here */
    if (!sy_gli_main_program(dev, VAR_TEX | VAR_NMAP | VAR_LIGHTS | VAR_ENV | VAR_AREA | VAR_SHADOW | VAR_ASHADOW | VAR_TRANS | VAR_MASK | VAR_PROBE, rep))
        r = SY_GL_ERROR_GL;
    for (int v = 0; v < 2 && r == SY_GL_OK; ++v)
        r = sy_gl_program_build(gl, v ? "shadow (alpha mask)" : "shadow", sy_gl_shadow_vs, sy_gl_shadow_fs, defs[2 * v],
                                &dev->ps[v].prog, rep);
    char rdefs[40];
    snprintf(rdefs, sizeof rdefs, "#define SY_SAMPLES %u\n", dev->msaa);
    if (r == SY_GL_OK) r = sy_gl_program_build(gl, "resolve", sy_gl_rect_vs, sy_gl_resolve_fs, rdefs, &dev->prog_resolve, rep);
    if (r == SY_GL_OK) r = sy_gl_program_build(gl, "floor", sy_gl_floor_vs, sy_gl_floor_fs, NULL, &dev->prog_floor, rep);
    if (r == SY_GL_OK)
        r = sy_gl_program_build(gl, "floor (trivial lit)", sy_gl_floor_vs, sy_gl_floor_fs, "#define SY_FLOOR_LIT 1\n",
                                &dev->prog_floor_lit, rep);
    if (r == SY_GL_OK) r = sy_gl_program_build(gl, "sky", sy_gl_fullscreen_vs, sy_gl_sky_fs, NULL, &dev->prog_sky, rep);
    dev->forward = dd.forward || dev->msaa < 2; /* the deferred pass is the MSAA resolve */
    for (int k = 0; k < 2 && r == SY_GL_OK && !dev->forward; ++k)
        r = sy_gl_program_build(gl, k ? "G-buffer (orthographic)" : "G-buffer", sy_gl_gbuf_vs, sy_gl_gbuf_fs,
                                k ? "#define SY_ORTHO 1\n" : NULL, &dev->ug[k].prog, rep);
    if (r == SY_GL_OK && !dev->forward) { /* the fullest shading pass now, so that a driver's rejection fails here */
        if (sy_gli_deferred_program(dev, VAR_LIGHTS | VAR_ENV | VAR_AREA | VAR_SHADOW | VAR_ASHADOW, rep) < 0)
            r = SY_GL_ERROR_GL;
    }
    if (r != SY_GL_OK) {
        sy_gl_device_destroy(dev);
        return r;
    }
    for (int v = 0; v < 2; ++v) {
        dev->ps[v].model = gl->GetUniformLocation(dev->ps[v].prog, "u_model");
        dev->ps[v].lightvp = gl->GetUniformLocation(dev->ps[v].prog, "u_lightvp");
        sy_gli_bind_samplers(gl, dev->ps[v].prog);
    }
    gl->UseProgram(dev->prog_resolve);
    gl->Uniform1i(gl->GetUniformLocation(dev->prog_resolve, "t_color"), 0);
    gl->Uniform1i(gl->GetUniformLocation(dev->prog_resolve, "t_depth"), 1);
    dev->resolve_rects = gl->GetUniformLocation(dev->prog_resolve, "u_rects");
    for (int k = 0; k < 2; ++k) {
        GLuint fp = k ? dev->prog_floor_lit : dev->prog_floor;
        dev->uf[k].model = gl->GetUniformLocation(fp, "u_model");
        dev->uf[k].view = gl->GetUniformLocation(fp, "u_view");
        dev->uf[k].proj = gl->GetUniformLocation(fp, "u_proj");
    }
    for (int k = 0; k < 2; ++k) {
        GLuint g = dev->ug[k].prog;
        if (!g) continue;
        dev->ug[k].normal_mat = gl->GetUniformLocation(g, "u_normal_mat");
        dev->ug[k].mvp = gl->GetUniformLocation(g, "u_mvp");
        dev->ug[k].model = gl->GetUniformLocation(g, "u_model");
        sy_gli_bind_clip_block(gl, g);
        dev->ug[k].ppu = gl->GetUniformLocation(g, "u_ppu");
        dev->ug[k].ortho_z = gl->GetUniformLocation(g, "u_ortho_z");
        dev->ug[k].has_normals = gl->GetUniformLocation(g, "u_has_normals");
        dev->ug[k].keys = gl->GetUniformLocation(g, "u_keys");
    }
    gl->UseProgram(dev->prog_sky);
    gl->Uniform1i(gl->GetUniformLocation(dev->prog_sky, "t_bg"), 0);
    dev->sky_inv_vp = gl->GetUniformLocation(dev->prog_sky, "u_inv_vp");
    dev->sky_size_int = gl->GetUniformLocation(dev->prog_sky, "u_size_int");

    sy_gli_standins_make(dev);
    sy_gl_material_desc md;
    sy_gl_material_desc_init(&md);
    mat_block mb;
    sy_gli_material_block(dev, &md, &mb);
    dev->mtab_limit = (uint32_t)max_tex < MTAB_MAX_ROWS ? (uint32_t)max_tex : MTAB_MAX_ROWS;
    if (!dev->forward && !sy_gli_mtab_set(dev, 0, &md)) {
        sy_gl_device_destroy(dev);
        return sy_gli_fail(rep, SY_GL_ERROR_OUT_OF_MEMORY, "GL device: out of memory");
    }
    gl->GenBuffers(1, &dev->default_ubo);
    gl->BindBuffer(GL_UNIFORM_BUFFER, dev->default_ubo);
    gl->BufferData(GL_UNIFORM_BUFFER, sizeof mb, &mb, GL_STATIC_DRAW);
    gl->GenBuffers(1, &dev->lights_ubo);
    gl->BindBuffer(GL_UNIFORM_BUFFER, dev->lights_ubo);
    gl->BufferData(GL_UNIFORM_BUFFER, LIGHTS_FLOATS * sizeof(float), NULL, GL_DYNAMIC_DRAW);
    gl->GenBuffers(1, &dev->areas_ubo);
    gl->BindBuffer(GL_UNIFORM_BUFFER, dev->areas_ubo);
    gl->BufferData(GL_UNIFORM_BUFFER, AREAS_FLOATS * sizeof(float), NULL, GL_DYNAMIC_DRAW);
    gl->GenVertexArrays(1, &dev->empty_vao);
    /* the shadow maps are made on the first frame with a shadowed light (sy_gli_shadow_maps_make) */
    dev->cube_size = dev->shadow_size / 2u > 16u ? dev->shadow_size / 2u : 16u;
    gl->Enable(GL_TEXTURE_CUBE_MAP_SEAMLESS); /* cube shadows and probes filter across faces */
    gl->GenFramebuffers(1, &dev->shadow_fbo);
    dev->lights_dirty = true;
    if ((r = sy_gli_gl_check(dev, "GL device setup", rep)) != SY_GL_OK) {
        sy_gl_device_destroy(dev);
        return r;
    }
    sy_gli_profile_mark(dev, false, prof);
    if (dev->profile) fprintf(stderr, "raster profile: device programs and tables %.3f s (cpu %.3f)\n", prof[0], prof[1]);
    *out = dev;
    return SY_GL_OK;
}

void sy_gl_device_destroy(sy_gl_device *dev)
{
    if (!dev) return;
    if (dev->ctx && sy_gl_context_make_current(dev->ctx) && dev->gl) {
        const sy_gl_fns *gl = dev->gl;
        for (uint32_t i = 0; i < dev->meshes.count; ++i) {
            mesh_o *m = sy_gli_pool_at(&dev->meshes, i);
            if (!m->h.id) continue;
            free(m->order);
            gl->DeleteBuffers(1, m->vbo);
            gl->DeleteBuffers(1, &m->ibo);
            gl->DeleteVertexArrays(1, &m->vao);
        }
        for (uint32_t i = 0; i < dev->textures.count; ++i) {
            tex_o *t = sy_gli_pool_at(&dev->textures, i);
            if (t->h.id) gl->DeleteTextures(1, &t->tex);
        }
        for (uint32_t i = 0; i < dev->materials.count; ++i) {
            mat_o *m = sy_gli_pool_at(&dev->materials, i);
            if (m->h.id) gl->DeleteBuffers(1, &m->ubo);
        }
        sy_gli_throttle_free(dev);
        sy_gli_targets_free(dev, &dev->t);
        sy_gli_pick_free(dev);
        if (dev->cap.prog) gl->DeleteProgram(dev->cap.prog);
        for (int v = 0; v < VAR_COUNT; ++v)
            if (dev->pm[v].prog) gl->DeleteProgram(dev->pm[v].prog);
        for (uint32_t i = 0; i < PM_SPARE; ++i)
            if (dev->pm_spare[i].prog) gl->DeleteProgram(dev->pm_spare[i].prog);
        GLuint progs[7] = {dev->ps[0].prog, dev->ps[1].prog, dev->prog_resolve, dev->prog_floor, dev->prog_sky,
                           dev->prog_floor_lit, dev->ug[0].prog};
        for (int i = 0; i < 7; ++i)
            if (progs[i]) gl->DeleteProgram(progs[i]);
        for (uint32_t i = 0; i < dev->dp_count; ++i) gl->DeleteProgram(dev->dp[i].prog);
        if (dev->ug[1].prog) gl->DeleteProgram(dev->ug[1].prog);
        if (dev->mtab) gl->DeleteTextures(1, &dev->mtab);
        sy_gl_ibl_free(gl, &dev->ibl);
        GLuint bufs[4] = {dev->default_ubo, dev->lights_ubo, dev->areas_ubo, dev->clip_ubo};
        gl->DeleteBuffers(dev->clip_ubo ? 4 : 3, bufs);
        gl->DeleteTextures(STANDINS, dev->standin);
        gl->DeleteTextures(1, &dev->shadow_tex);
        for (uint32_t c = 0; c < SY_GL_MAX_CUBE_SHADOWS; ++c)
            if (dev->cube_tex[c]) gl->DeleteTextures(1, &dev->cube_tex[c]);
        sy_gli_probes_free(dev);
        gl->DeleteFramebuffers(1, &dev->shadow_fbo);
        gl->DeleteVertexArrays(1, &dev->empty_vao);
    }
    sy_gl_context_destroy(dev->ctx);
    sy_gli_lod_cache_free(dev);
    free(dev->meshes.items);
    free(dev->textures.items);
    free(dev->materials.items);
    free(dev->instances.items);
    free(dev->lights.items);
    free(dev->scratch);
    free(dev->mtab_cpu);
    free(dev->rects);
    free(dev->tiles);
    free(dev->spans);
    free(dev->runs);
    free(dev);
}

void sy_gl_device_stats(const sy_gl_device *dev, sy_gl_stats *out)
{
    memset(out, 0, sizeof *out);
    out->meshes = dev->meshes.live;
    out->textures = dev->textures.live;
    out->materials = dev->materials.live;
    out->instances = dev->instances.live;
    out->lights = dev->lights.live;
    out->msaa_samples = dev->msaa;
    out->shadow_maps = dev->shadow_maps;
    out->triangles_drawn = dev->tris;
    out->draw_calls = dev->draws;
    out->instances_culled = dev->culled;
    out->deferred_draws = dev->deferred_draws;
    out->deferred_pixels = dev->deferred_pixels;
    out->programs_built = dev->programs_built;
    out->frame = dev->frame;
    out->total = dev->counts;
}

const char *sy_gl_device_info(const sy_gl_device *dev) { return dev->info; }

bool sy_gl_window_should_close(sy_gl_device *dev) { return sy_gl_context_should_close(dev->ctx); }

