/* sy_gl_pick.c — what is under one pixel (sy_gl_pick): an ID pass over a 1x1 target. The pixel's
 * own window of the image plane (the sub-rectangle view every tile uses) is drawn with a trivial
 * program that writes the instance's handle and gl_PrimitiveID, each as two exact 16-bit halves
 * in a float target (the GL 3.3 entry points the device loads have no integer uniforms or
 * clears), with the depth test and no culling, every visible instance at its full level of detail
 * (level 0 is the mesh as given, so the primitive id is the mesh's triangle index). Alpha-masked
 * materials discard where base colour factor x base texture alpha x vertex alpha < cutoff, as the
 * ray tracers' alpha filter does, with the texture read at its full resolution (level 0, the
 * magnification filter) as the ray tracers read it: the main pass's mipmapped read moves the cut
 * by a texel or so where the alpha crosses the cutoff (AlphaBlendModeTest's 0.75 cutoff). */
#include "sy_gl_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PICK_ZOOM 64.0 /* how much narrower than the pixel the ID pass's window is (see sy_gl_pick) */

static const char *const pick_vs =
    "#version 330 core\n" SY_GL_CLIP_VS
    "layout(location=0) in vec3 a_pos; layout(location=2) in vec2 a_uv0; layout(location=3) in vec2 a_uv1;\n"
    "layout(location=4) in vec4 a_col;\n"
    "uniform mat4 u_model; uniform mat4 u_view; uniform mat4 u_proj; uniform int u_uvset; uniform vec3 u_xf0, u_xf1;\n"
    "out vec2 v_uv; out float v_alpha;\n"
    "void main() { vec3 t = vec3(u_uvset == 1 ? a_uv1 : a_uv0, 1.0); v_uv = vec2(dot(u_xf0, t), dot(u_xf1, t));\n"
    "  v_alpha = a_col.a; vec4 w = u_model * vec4(a_pos, 1.0); sy_clip(w.xyz); gl_Position = u_proj * (u_view * w); }\n";

static const char *const pick_fs =
    "#version 330 core\n"
    "in vec2 v_uv; in float v_alpha; layout(location=0) out vec4 o_id;\n"
    "uniform int u_id; uniform int u_mask; uniform int u_tex; uniform float u_alpha; uniform float u_cutoff;\n"
    "uniform sampler2D t_base;\n"
    "void main() {\n"
    "  if (u_mask != 0) { float a = u_alpha * v_alpha; if (u_tex != 0) a *= textureLod(t_base, v_uv, 0.0).a;\n"
    "    if (a < u_cutoff) discard; }\n"
    "  uint id = uint(u_id), p = uint(gl_PrimitiveID) + 1u;\n"
    "  o_id = vec4(float(id & 65535u), float(id >> 16u), float(p & 65535u), float(p >> 16u)); }\n";

void sy_gli_pick_free(sy_gl_device *dev)
{
    const sy_gl_fns *gl = dev->gl;
    if (dev->pick.prog) gl->DeleteProgram(dev->pick.prog);
    if (dev->pick.fbo) gl->DeleteFramebuffers(1, &dev->pick.fbo);
    if (dev->pick.color) gl->DeleteRenderbuffers(1, &dev->pick.color);
    if (dev->pick.depth) gl->DeleteRenderbuffers(1, &dev->pick.depth);
    if (dev->pick.ifbo) gl->DeleteFramebuffers(1, &dev->pick.ifbo);
    if (dev->pick.icolor) gl->DeleteRenderbuffers(1, &dev->pick.icolor);
    if (dev->pick.idepth) gl->DeleteRenderbuffers(1, &dev->pick.idepth);
    memset(&dev->pick, 0, sizeof dev->pick);
}

/* The program and the 1x1 target, made on the first pick. */
static sy_gl_result pick_setup(sy_gl_device *dev, sy_gl_report *rep)
{
    const sy_gl_fns *gl = dev->gl;
    if (!dev->pick.prog) {
        sy_gl_result r = sy_gl_program_build(gl, "pick", pick_vs, pick_fs, NULL, &dev->pick.prog, rep);
        if (r != SY_GL_OK) return r;
        static const char *const names[PICK_UNIFORMS] = {"u_model", "u_view",  "u_proj", "u_uvset", "u_xf0", "u_xf1",
                                                         "u_id",    "u_mask",  "u_tex",  "u_alpha", "u_cutoff"};
        for (int i = 0; i < PICK_UNIFORMS; ++i) dev->pick.u[i] = gl->GetUniformLocation(dev->pick.prog, names[i]);
        gl->UseProgram(dev->pick.prog);
        gl->Uniform1i(gl->GetUniformLocation(dev->pick.prog, "t_base"), 0);
        sy_gli_bind_clip_block(gl, dev->pick.prog);
    }
    if (!dev->pick.fbo) {
        gl->GenFramebuffers(1, &dev->pick.fbo);
        gl->GenRenderbuffers(1, &dev->pick.color);
        gl->GenRenderbuffers(1, &dev->pick.depth);
        gl->BindRenderbuffer(GL_RENDERBUFFER, dev->pick.color);
        gl->RenderbufferStorageMultisample(GL_RENDERBUFFER, 0, GL_RGBA32F, 1, 1);
        gl->BindRenderbuffer(GL_RENDERBUFFER, dev->pick.depth);
        gl->RenderbufferStorageMultisample(GL_RENDERBUFFER, 0, GL_DEPTH_COMPONENT32F, 1, 1);
        gl->BindFramebuffer(GL_FRAMEBUFFER, dev->pick.fbo);
        gl->FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, dev->pick.color);
        gl->FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, dev->pick.depth);
        if (gl->CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
            return sy_gli_fail(rep, SY_GL_ERROR_GL, "pick: the 1x1 ID target is incomplete");
    }
    return SY_GL_OK;
}

/* The ID pass into fbo (w x h): every visible instance's handle and primitive + 1 (two 16-bit
 * halves each) at every sample, nearest first by the depth test. */
static void id_draw(sy_gl_device *dev, const view_setup *v, GLuint fbo, uint32_t w, uint32_t h)
{
    const sy_gl_fns *gl = dev->gl;
    gl->BindFramebuffer(GL_FRAMEBUFFER, fbo);
    static const GLenum bufs[1] = {GL_COLOR_ATTACHMENT0};
    gl->DrawBuffers(1, bufs);
    gl->Viewport(0, 0, (GLsizei)w, (GLsizei)h);
    gl->Disable(GL_BLEND);
    gl->Disable(GL_CULL_FACE);
    gl->Enable(GL_DEPTH_TEST);
    gl->DepthFunc(GL_LESS);
    gl->DepthMask(GL_TRUE);
    gl->ColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    const float zero[4] = {0, 0, 0, 0}, one = 1.0f;
    gl->ClearBufferfv(GL_COLOR, 0, zero);
    gl->ClearBufferfv(GL_DEPTH, 0, &one);
    gl->UseProgram(dev->pick.prog);
    dev->profile_var = -1;
    const GLint *u = dev->pick.u;
    gl->UniformMatrix4fv(u[1], 1, GL_FALSE, v->view);
    gl->UniformMatrix4fv(u[2], 1, GL_FALSE, v->proj);
    gl->ActiveTexture(GL_TEXTURE0);
    float vp[16], planes[6][4];
    sy_gli_m4_mul(v->proj, v->view, vp);
    sy_gli_frustum_planes(vp, planes);
    sy_gli_clip_enable(dev, true);
    for (uint32_t i = 0; i < dev->instances.count; ++i) {
        const inst_o *in = sy_gli_pool_at(&dev->instances, i);
        if (!in->h.id || !in->visible) continue;
        const mesh_o *m = sy_gli_pool_get(&dev->meshes, in->mesh.id);
        if (!m) continue;
        float c[3], scale, rad = sy_gli_world_sphere(in, m, c, &scale);
        if (sy_gli_sphere_outside(planes, c, rad)) continue;
        const mat_o *mt = sy_gli_pool_get(&dev->materials, in->material.id);
        const sy_gl_texture_ref *bt = mt ? &mt->d.base_color_texture : NULL;
        const tex_o *tex = bt ? sy_gli_pool_get(&dev->textures, bt->texture.id) : NULL;
        bool mask = mt && mt->d.alpha_mode == SY_GL_ALPHA_MASK;
        gl->Uniform1i(u[7], mask ? 1 : 0);
        if (mask) {
            gl->Uniform1f(u[9], mt->d.base_color[3]);
            gl->Uniform1f(u[10], mt->d.alpha_cutoff);
            gl->Uniform1i(u[8], tex ? 1 : 0);
            if (tex) {
                float xf0[3] = {1, 0, 0}, xf1[3] = {0, 1, 0};
                if (bt->transformed) memcpy(xf0, bt->transform, sizeof xf0), memcpy(xf1, bt->transform + 3, sizeof xf1);
                gl->Uniform3fv(u[4], 1, xf0);
                gl->Uniform3fv(u[5], 1, xf1);
                gl->Uniform1i(u[3], (int)bt->texcoord);
                gl->BindTexture(GL_TEXTURE_2D, tex->tex);
            }
        }
        gl->Uniform1i(u[6], (GLint)in->h.id);
        gl->UniformMatrix4fv(u[0], 1, GL_FALSE, in->model);
        sy_gli_draw_mesh_lod(dev, m, 0);
    }
    sy_gli_clip_enable(dev, false);
}

sy_gl_result sy_gl_pick(sy_gl_device *dev, const sy_gl_camera *cam, uint32_t image_width, uint32_t image_height,
                        uint32_t x, uint32_t y, sy_gl_pick_hit *out)
{
    sy_gl_report *rep = dev ? dev->report : NULL;
    if (!dev || !cam || !out) return sy_gli_fail(rep, SY_GL_ERROR_INVALID_ARGUMENT, "pick: NULL argument");
    memset(out, 0, sizeof *out);
    if (x >= image_width || y >= image_height)
        return sy_gli_fail(rep, SY_GL_ERROR_INVALID_ARGUMENT, "pick: pixel (%u, %u) is outside the %ux%u image", x, y,
                           image_width, image_height);
    sy_gl_result r = sy_gli_current(dev, rep);
    if (r == SY_GL_OK) sy_gli_clip_set(dev, cam);
    /* the 1x1 target is a window PICK_ZOOM times narrower than the pixel, centred on its centre:
     * the same ray, with the rasterizer's sub-pixel snapping PICK_ZOOM times finer, so a centre
     * near a shared edge goes to the triangle the ray meets (with the pixel's own window, one in
     * a hundred pixels of MetalRoughSpheresNoTextures' small triangles went to the neighbour) */
    sy_gl_camera zc = *cam;
    const float *w = cam->window;
    double cx = w[0] + ((double)w[1] - w[0]) * (x + 0.5) / image_width;
    double cy = w[3] - ((double)w[3] - w[2]) * (y + 0.5) / image_height;
    double hx = ((double)w[1] - w[0]) / image_width * 0.5 / PICK_ZOOM;
    double hy = ((double)w[3] - w[2]) / image_height * 0.5 / PICK_ZOOM;
    zc.window[0] = (float)(cx - hx), zc.window[1] = (float)(cx + hx);
    zc.window[2] = (float)(cy - hy), zc.window[3] = (float)(cy + hy);
    const sy_gl_render_desc d = {1, 1, 0, 0, 1, 1};
    view_setup v;
    if (r == SY_GL_OK && !(zc.window[0] < zc.window[1] && zc.window[2] < zc.window[3])) { /* below float steps */
        zc.window[0] = (float)cx - fmaxf(fabsf((float)cx), 1.0f) * 1e-6f, zc.window[1] = (float)cx + fmaxf(fabsf((float)cx), 1.0f) * 1e-6f;
        zc.window[2] = (float)cy - fmaxf(fabsf((float)cy), 1.0f) * 1e-6f, zc.window[3] = (float)cy + fmaxf(fabsf((float)cy), 1.0f) * 1e-6f;
    }
    if (r == SY_GL_OK) r = sy_gli_view_make(dev, &zc, &d, &v, rep);
    if (r == SY_GL_OK) r = pick_setup(dev, rep);
    if (r != SY_GL_OK) return r;
    id_draw(dev, &v, dev->pick.fbo, 1, 1);
    const sy_gl_fns *gl = dev->gl;
    float px[4] = {0, 0, 0, 0};
    gl->ReadBuffer(GL_COLOR_ATTACHMENT0);
    gl->PixelStorei(GL_PACK_ALIGNMENT, 1);
    gl->ReadPixels(0, 0, 1, 1, GL_RGBA, GL_FLOAT, px);
    r = sy_gli_gl_check(dev, "pick", rep);
    if (r != SY_GL_OK) return r;
    uint32_t prim = (uint32_t)px[2] | ((uint32_t)px[3] << 16);
    if (!prim) return SY_GL_OK;
    uint32_t id = (uint32_t)px[0] | ((uint32_t)px[1] << 16);
    const inst_o *in = sy_gli_pool_get(&dev->instances, id);
    const mesh_o *m = in ? sy_gli_pool_get(&dev->meshes, in->mesh.id) : NULL;
    if (!m || prim - 1u >= m->triangle_count) return SY_GL_OK; /* cannot happen: the pass drew these */
    out->instance.id = id;
    out->triangle = prim - 1u;
    return SY_GL_OK;
}

/* sy_gl_ids' w x h target, (re)made when the size changes. */
static sy_gl_result ids_target(sy_gl_device *dev, uint32_t w, uint32_t h, sy_gl_report *rep)
{
    const sy_gl_fns *gl = dev->gl;
    if (dev->pick.ifbo && dev->pick.iw == w && dev->pick.ih == h) return SY_GL_OK;
    if (!dev->pick.ifbo) {
        gl->GenFramebuffers(1, &dev->pick.ifbo);
        gl->GenRenderbuffers(1, &dev->pick.icolor);
        gl->GenRenderbuffers(1, &dev->pick.idepth);
    }
    gl->BindRenderbuffer(GL_RENDERBUFFER, dev->pick.icolor);
    gl->RenderbufferStorageMultisample(GL_RENDERBUFFER, 0, GL_RGBA32F, (GLsizei)w, (GLsizei)h);
    gl->BindRenderbuffer(GL_RENDERBUFFER, dev->pick.idepth);
    gl->RenderbufferStorageMultisample(GL_RENDERBUFFER, 0, GL_DEPTH_COMPONENT32F, (GLsizei)w, (GLsizei)h);
    gl->BindFramebuffer(GL_FRAMEBUFFER, dev->pick.ifbo);
    gl->FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, dev->pick.icolor);
    gl->FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, dev->pick.idepth);
    if (gl->CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        return sy_gli_fail(rep, SY_GL_ERROR_GL, "ids: the %ux%u ID target is incomplete", w, h);
    dev->pick.iw = w, dev->pick.ih = h;
    return SY_GL_OK;
}

sy_gl_result sy_gl_ids(sy_gl_device *dev, const sy_gl_camera *cam, const sy_gl_render_desc *desc, uint32_t *ids)
{
    sy_gl_report *rep = dev ? dev->report : NULL;
    if (!dev || !cam || !desc || !ids) return sy_gli_fail(rep, SY_GL_ERROR_INVALID_ARGUMENT, "ids: NULL argument");
    uint32_t w = desc->width, h = desc->height;
    if (!w || !h || w > 16384 || h > 16384 || desc->x > desc->image_width || desc->y > desc->image_height ||
        w > desc->image_width - desc->x || h > desc->image_height - desc->y)
        return sy_gli_fail(rep, SY_GL_ERROR_INVALID_ARGUMENT, "ids: rectangle %ux%u at (%u, %u) is not inside the %ux%u image",
                           w, h, desc->x, desc->y, desc->image_width, desc->image_height);
    float *px = malloc((size_t)w * h * 4 * sizeof *px);
    if (!px) return sy_gli_fail(rep, SY_GL_ERROR_OUT_OF_MEMORY, "ids: out of memory (%ux%u)", w, h);
    sy_gl_result r = sy_gli_current(dev, rep);
    if (r == SY_GL_OK) sy_gli_clip_set(dev, cam);
    view_setup v;
    if (r == SY_GL_OK) r = sy_gli_view_make(dev, cam, desc, &v, rep);
    if (r == SY_GL_OK) r = pick_setup(dev, rep);
    if (r == SY_GL_OK) r = ids_target(dev, w, h, rep);
    if (r != SY_GL_OK) {
        free(px);
        return r;
    }
    id_draw(dev, &v, dev->pick.ifbo, w, h);
    const sy_gl_fns *gl = dev->gl;
    gl->ReadBuffer(GL_COLOR_ATTACHMENT0);
    gl->PixelStorei(GL_PACK_ALIGNMENT, 1);
    gl->ReadPixels(0, 0, (GLsizei)w, (GLsizei)h, GL_RGBA, GL_FLOAT, px);
    r = sy_gli_gl_check(dev, "ids", rep);
    for (uint32_t j = 0; j < h && r == SY_GL_OK; ++j) /* GL rows go bottom up */
        for (uint32_t i = 0; i < w; ++i) {
            const float *p = px + 4 * ((size_t)(h - 1 - j) * w + i);
            uint32_t prim = (uint32_t)p[2] | ((uint32_t)p[3] << 16);
            ids[(size_t)j * w + i] = prim ? (uint32_t)p[0] | ((uint32_t)p[1] << 16) : 0u;
        }
    free(px);
    return r;
}
