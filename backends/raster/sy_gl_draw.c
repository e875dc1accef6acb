/* sy_gl_draw.c — one pass over the scene: render targets and views, frustum culling, the
 * forward pass (opaque near to far, masked, blended far to near), the deferred G-buffer and
 * shading pass, MSAA resolve and read-back into the shared layer conventions. */
#include "sy_gl_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int frame_lighting(const sy_gl_device *dev);

/* The whole target as one rectangle (sy_gl_rect_vs). */
static const float FULL_TARGET[1][4] = {{-1.0f, -1.0f, 1.0f, 1.0f}};

void sy_gli_targets_free(sy_gl_device *dev, targets *t)
{
    const sy_gl_fns *gl = dev->gl;
    GLuint fb[2] = {t->fbo, t->rfbo}, tx[4] = {t->color, t->depthlin, t->rcolor, t->rdepthlin};
    gl->DeleteFramebuffers(2, fb);
    gl->DeleteTextures(4, tx);
    gl->DeleteRenderbuffers(1, &t->depth_rb);
    memset(t, 0, sizeof *t);
}

void sy_gli_frame_end(sy_gl_device *dev)
{
    const uint64_t *now = (const uint64_t *)&dev->counts, *mark = (const uint64_t *)&dev->mark;
    uint64_t *fr = (uint64_t *)&dev->frame;
    for (size_t i = 0; i < sizeof dev->counts / sizeof(uint64_t); ++i) fr[i] = now[i] - mark[i];
    dev->mark = dev->counts;
}

sy_gl_result sy_gli_targets_ensure(sy_gl_device *dev, uint32_t w, uint32_t h, sy_gl_report *rep)
{
    targets *t = &dev->t;
    if (t->fbo && t->w == w && t->h == h && t->samples == dev->msaa) return SY_GL_OK;
    sy_gli_targets_free(dev, t);
    const sy_gl_fns *gl = dev->gl;
    t->w = w;
    t->h = h;
    t->samples = dev->msaa;
    GLenum target = t->samples > 1 ? GL_TEXTURE_2D_MULTISAMPLE : GL_TEXTURE_2D;
    gl->GenFramebuffers(1, &t->fbo);
    gl->BindFramebuffer(GL_FRAMEBUFFER, t->fbo);
    GLuint *texs[2] = {&t->color, &t->depthlin};
    GLenum fmts[2] = {GL_RGBA32F, GL_R32F};
    for (int i = 0; i < 2; ++i) {
        gl->GenTextures(1, texs[i]);
        gl->BindTexture(target, *texs[i]);
        if (t->samples > 1)
            gl->TexImage2DMultisample(target, (GLsizei)t->samples, fmts[i], (GLsizei)w, (GLsizei)h, GL_TRUE);
        else {
            gl->TexImage2D(target, 0, (GLint)fmts[i], (GLsizei)w, (GLsizei)h, 0, i ? GL_RED : GL_RGBA, GL_FLOAT, NULL);
            gl->TexParameteri(target, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
            gl->TexParameteri(target, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        }
        gl->FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0 + (GLenum)i, target, *texs[i], 0);
    }
    gl->GenRenderbuffers(1, &t->depth_rb);
    gl->BindRenderbuffer(GL_RENDERBUFFER, t->depth_rb);
    gl->RenderbufferStorageMultisample(GL_RENDERBUFFER, t->samples > 1 ? (GLsizei)t->samples : 0, GL_DEPTH_COMPONENT32F,
                                       (GLsizei)w, (GLsizei)h);
    gl->FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, t->depth_rb);
    GLenum st = gl->CheckFramebufferStatus(GL_FRAMEBUFFER);
    if (st != GL_FRAMEBUFFER_COMPLETE)
        return sy_gli_fail(rep, SY_GL_ERROR_GL, "render target %ux%u (%u samples): framebuffer incomplete (0x%04x)", w, h,
                    t->samples, (unsigned)st);
    if (t->samples > 1) {
        gl->GenFramebuffers(1, &t->rfbo);
        gl->BindFramebuffer(GL_FRAMEBUFFER, t->rfbo);
        GLuint *rt[2] = {&t->rcolor, &t->rdepthlin};
        for (int i = 0; i < 2; ++i) {
            gl->GenTextures(1, rt[i]);
            gl->BindTexture(GL_TEXTURE_2D, *rt[i]);
            gl->TexImage2D(GL_TEXTURE_2D, 0, (GLint)fmts[i], (GLsizei)w, (GLsizei)h, 0, i ? GL_RED : GL_RGBA, GL_FLOAT, NULL);
            gl->TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
            gl->TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
            gl->FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0 + (GLenum)i, GL_TEXTURE_2D, *rt[i], 0);
        }
        st = gl->CheckFramebufferStatus(GL_FRAMEBUFFER);
        if (st != GL_FRAMEBUFFER_COMPLETE)
            return sy_gli_fail(rep, SY_GL_ERROR_GL, "resolve target %ux%u: framebuffer incomplete (0x%04x)", w, h, (unsigned)st);
    }
    return sy_gli_gl_check(dev, "render targets", rep);
}

/* The nearest depth along fwd (from pos) of any corner of a visible instance's world box: a lower
 * bound of every drawn point's depth (0 when the scene is empty or a box reaches behind pos). */
static double nearest_depth(const sy_gl_device *dev, const float pos[3], const float fwd[3])
{
    double nearest = INFINITY;
    float box[8][3];
    for (uint32_t i = 0; nearest > 0.0 && sy_gli_next_box(dev, &i, box);)
        for (int k = 0; k < 8; ++k) {
            const float *w = box[k];
            double d = ((double)w[0] - pos[0]) * fwd[0] + ((double)w[1] - pos[1]) * fwd[1] + ((double)w[2] - pos[2]) * fwd[2];
            if (d < nearest) nearest = d;
        }
    return isfinite(nearest) && nearest > 0.0 ? nearest : 0.0;
}

sy_gl_result sy_gli_view_make(sy_gl_device *dev, const sy_gl_camera *cam, const sy_gl_render_desc *d, view_setup *v, sy_gl_report *rep)
{
    const float *w = cam->window;
    for (int i = 0; i < 4; ++i)
        if (!isfinite(w[i])) return sy_gli_fail(rep, SY_GL_ERROR_INVALID_ARGUMENT, "render: camera window[%d] is not finite", i);
    if (!(w[0] < w[1]) || !(w[2] < w[3]))
        return sy_gli_fail(rep, SY_GL_ERROR_INVALID_ARGUMENT, "render: camera window needs left < right and bottom < top");
    if (!isfinite(cam->near_clip) || cam->near_clip < 0.0f || !isfinite(cam->far_clip) || cam->far_clip < 0.0f ||
        (cam->far_clip > 0.0f && cam->far_clip <= cam->near_clip))
        return sy_gli_fail(rep, SY_GL_ERROR_INVALID_ARGUMENT, "render: clip range near %g far %g is invalid",
                    (double)cam->near_clip, (double)cam->far_clip);
    if (d->image_width == 0 || d->image_height == 0 || d->width == 0 || d->height == 0 ||
        d->x > d->image_width || d->width > d->image_width - d->x || d->y > d->image_height ||
        d->height > d->image_height - d->y)
        return sy_gli_fail(rep, SY_GL_ERROR_INVALID_ARGUMENT, "render: rectangle %u,%u %ux%u is outside the %ux%u image",
                    d->x, d->y, d->width, d->height, d->image_width, d->image_height);
    if (!sy_gli_m4_invert(cam->camera_to_world, v->view))
        return sy_gli_fail(rep, SY_GL_ERROR_INVALID_ARGUMENT, "render: camera matrix is not invertible");
    memcpy(v->cam_pos, cam->camera_to_world + 12, sizeof v->cam_pos);
    for (int i = 0; i < 3; ++i) v->cam_fwd[i] = -cam->camera_to_world[8 + i];
    sy_gli_v3_norm(v->cam_fwd);
    v->ortho = cam->orthographic;
    /* the sub-rectangle's own window of the full-image plane: pixel centres stay where they are */
    double l = w[0], r = w[1], b = w[2], t = w[3], W = d->image_width, H = d->image_height;
    double l2 = l + (r - l) * d->x / W, r2 = l + (r - l) * (d->x + d->width) / W;
    double t2 = t - (t - b) * d->y / H, b2 = t - (t - b) * (d->y + d->height) / H;
    float c[3], R;
    sy_gli_scene_bounds(dev, c, &R);
    double dist = 0.0;
    for (int i = 0; i < 3; ++i) dist += (double)(c[i] - v->cam_pos[i]) * v->cam_fwd[i];
    double n = cam->near_clip, f = cam->far_clip;
    if (!v->ortho && n <= 0.0) n = fmax(1e-5 * (fabs(dist) + R), 1e-6);
    if (v->ortho && f <= 0.0) f = fmax(dist + 2.0 * R, n + 1.0);
    /* the near plane as far out as the scene allows: a depth buffer's precision follows near /
     * depth, and a file's znear of 5.6e-5 (TransmissionTest) left 2.4e-3 units of depth resolution
     * at 1.5 units away, where its labels' two faces, 1.6e-3 apart, fought in stripes (the ray
     * tracers have no such limit). No visible instance's box reaches nearer than the nearest of
     * its corners along the view, so a near plane just before the nearest one clips nothing; an
     * instance around the eye keeps the camera's */
    if (!v->ortho) {
        double nearest = nearest_depth(dev, v->cam_pos, v->cam_fwd);
        if (nearest > n && (f <= 0.0 || nearest < f)) n = nearest * (1.0 - 1e-3); /* all beyond the far plane: kept */
    }
    sy_gli_projection(v->ortho, l2, r2, b2, t2, n, f, v->proj);
    v->ppu = (float)((double)d->height / (t2 - b2));
    sy_gli_view_bounds(v);
    return SY_GL_OK;
}

/* Fills the bound w x h target with a lat-long texture x intensity along each pixel's ray through
 * view v (depth test and writes off while it draws, depth writes on after). */
void sy_gli_draw_latlong(sy_gl_device *dev, const view_setup *v, const tex_o *tex, float intensity, uint32_t w,
                         uint32_t h)
{
    const sy_gl_fns *gl = dev->gl;
    float vp[16], inv[16];
    sy_gli_m4_mul(v->proj, v->view, vp);
    if (!sy_gli_m4_invert(vp, inv)) return;
    gl->Disable(GL_DEPTH_TEST);
    gl->DepthMask(GL_FALSE);
    gl->UseProgram(dev->prog_sky);
    gl->UniformMatrix4fv(dev->sky_inv_vp, 1, GL_FALSE, inv);
    const float si[4] = {(float)w, (float)h, intensity, 0.0f};
    gl->Uniform4fv(dev->sky_size_int, 1, si);
    gl->ActiveTexture(GL_TEXTURE0);
    gl->BindTexture(GL_TEXTURE_2D, tex->tex);
    gl->BindVertexArray(dev->empty_vao);
    gl->DrawArrays(GL_TRIANGLES, 0, 3);
    gl->DepthMask(GL_TRUE);
}

void sy_gli_begin_target(sy_gl_device *dev, const view_setup *v)
{
    const sy_gl_fns *gl = dev->gl;
    gl->BindFramebuffer(GL_FRAMEBUFFER, dev->t.fbo);
    static const GLenum bufs[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    gl->DrawBuffers(2, bufs);
    gl->Viewport(0, 0, (GLsizei)dev->t.w, (GLsizei)dev->t.h);
    gl->ColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    gl->DepthMask(GL_TRUE);
    float bg[4] = {0, 0, 0, 0};
    if (dev->bg_mode == SY_GL_BACKGROUND_COLOR) memcpy(bg, dev->bg_color, sizeof bg);
    const float inf[4] = {INFINITY, 0, 0, 0}, one = 1.0f;
    gl->ClearBufferfv(GL_COLOR, 0, bg);
    gl->ClearBufferfv(GL_COLOR, 1, inf);
    gl->ClearBufferfv(GL_DEPTH, 0, &one);
    const tex_o *sky = dev->bg_mode == SY_GL_BACKGROUND_TEXTURE ? sy_gli_pool_get(&dev->textures, dev->bg_tex.id) : NULL;
    if (sky && v) /* the sky: camera rays that hit nothing see the texture */
        sy_gli_draw_latlong(dev, v, sky, dev->bg_intensity, dev->t.w, dev->t.h);
    gl->Enable(GL_DEPTH_TEST);
    gl->DepthFunc(GL_LESS);
    gl->Disable(GL_CULL_FACE); /* the ray tracers see both sides of every triangle */
    gl->Disable(GL_BLEND);
    if (dev->t.samples > 1) gl->Enable(GL_MULTISAMPLE);
}

/* What takes a w x h target's window position and view depth back to view space (sy_gl_gbuf_fs):
 * proj[0], proj[5] and the offsets that undo the sy_gli_projection's x and y; 2 / size. */
static void view_unproject(const view_setup *v, uint32_t w, uint32_t h, float unproj[4], float px[2])
{
    const float *p = v->proj;
    unproj[0] = p[0], unproj[1] = p[5];
    unproj[2] = v->ortho ? -p[12] : p[8], unproj[3] = v->ortho ? -p[13] : p[9];
    px[0] = 2.0f / (float)w, px[1] = 2.0f / (float)h;
}

/* Draws rectangles (NDC) with the bound program (sy_gl_rect_vs; loc: its u_rects), in batches. */
static void draw_rects(sy_gl_device *dev, GLint loc, const float (*r)[4], uint32_t n)
{
    const sy_gl_fns *gl = dev->gl;
    gl->BindVertexArray(dev->empty_vao);
    for (uint32_t i = 0; i < n; i += SY_GL_MAX_RECTS) {
        const uint32_t b = n - i < SY_GL_MAX_RECTS ? n - i : SY_GL_MAX_RECTS;
        gl->Uniform4fv(loc, (GLsizei)b, r[i]);
        double t0 = sy_gli_profile_thread(dev);
        gl->DrawArrays(GL_TRIANGLES, 0, (GLsizei)(6 * b));
        sy_gli_profile_draw(dev, t0, "rectangles (deferred or resolve)");
    }
}

/* The plain MSAA resolve (sy_gl_resolve_fs) of the target's samples in rectangles r[0, n) into the
 * bound resolve target. */
static void resolve_pass(sy_gl_device *dev, const float (*r)[4], uint32_t n)
{
    const sy_gl_fns *gl = dev->gl;
    gl->UseProgram(dev->prog_resolve);
    dev->profile_var = -1;
    gl->ActiveTexture(GL_TEXTURE0);
    gl->BindTexture(GL_TEXTURE_2D_MULTISAMPLE, dev->t.color);
    gl->ActiveTexture(GL_TEXTURE1);
    gl->BindTexture(GL_TEXTURE_2D_MULTISAMPLE, dev->t.depthlin);
    draw_rects(dev, dev->resolve_rects, r, n);
}

/* Splits the target into the tiles (RECT_TILE pixels square) that the rectangles of rect_add touch
 * and the rest, each as rectangles in NDC (runs of tiles along a row, each extending an equal run
 * of the row below): dev->spans[0, *n_shade) and [*n_shade, *n_shade + *n_rest). Together they
 * cover every pixel once; *shade_px: the pixels of the first list. False without memory. */
static bool rect_tiles(sy_gl_device *dev, uint32_t *n_shade, uint32_t *n_rest, uint64_t *shade_px)
{
    const uint32_t tw = (dev->t.w + RECT_TILE - 1) / RECT_TILE, th = (dev->t.h + RECT_TILE - 1) / RECT_TILE;
    const size_t n = (size_t)tw * th;
    if (dev->tiles_cap < n) {
        free(dev->tiles);
        free(dev->spans);
        free(dev->runs);
        dev->tiles = malloc(n);
        dev->spans = malloc(sizeof *dev->spans * n); /* at most one rectangle per tile */
        dev->runs = malloc(sizeof *dev->runs * 2 * n); /* n >= tw, whatever the shape */
        dev->tiles_cap = dev->tiles && dev->spans && dev->runs ? n : 0;
        if (!dev->tiles_cap) return false;
    }
    memset(dev->tiles, 0, n);
    for (uint32_t i = 0; i < dev->rect_count; ++i) {
        const uint32_t *r = dev->rects[i], x0 = r[0] / RECT_TILE, x1 = (r[2] + RECT_TILE - 1) / RECT_TILE;
        for (uint32_t y = r[1] / RECT_TILE; y < (r[3] + RECT_TILE - 1) / RECT_TILE; ++y)
            memset(dev->tiles + (size_t)y * tw + x0, 1, x1 - x0);
    }
    const float sx = 2.0f / (float)dev->t.w, sy = 2.0f / (float)dev->t.h;
    /* runs[x]: 1 + the rectangle whose run starts at tile column x, runs[tw + x] its end column */
    uint32_t *start = dev->runs, *end = dev->runs + tw, count = 0;
    *shade_px = 0;
    for (int want = 1; want >= 0; --want) {
        const uint32_t first = count;
        memset(start, 0, sizeof *start * tw);
        for (uint32_t y = 0; y < th; ++y) {
            const uint8_t *row = dev->tiles + (size_t)y * tw;
            const uint32_t py1 = (y + 1) * RECT_TILE < dev->t.h ? (y + 1) * RECT_TILE : dev->t.h;
            const float y0 = (float)(y * RECT_TILE) * sy - 1.0f, y1 = (float)py1 * sy - 1.0f;
            for (uint32_t x = 0, e; x < tw; x = e) {
                for (e = x + 1; e < tw && row[e] == row[x]; ++e) {}
                if (row[x] != want) continue;
                const uint32_t px1 = e * RECT_TILE < dev->t.w ? e * RECT_TILE : dev->t.w;
                if (want) *shade_px += (uint64_t)(px1 - x * RECT_TILE) * (py1 - y * RECT_TILE);
                float *o = start[x] ? dev->spans[start[x] - 1] : NULL;
                if (o && end[x] == e && o[3] == y0) o[3] = y1; /* the same run on the row below: taller */
                else {
                    o = dev->spans[count++];
                    o[0] = (float)(x * RECT_TILE) * sx - 1.0f, o[1] = y0;
                    o[2] = (float)px1 * sx - 1.0f, o[3] = y1;
                    start[x] = count, end[x] = e;
                }
            }
        }
        if (want) *n_shade = count - first;
        else *n_rest = count - first;
    }
    return true;
}

/* The deferred shading pass (sy_gl_deferred_fs) into the bound resolve target. It runs only on the
 * tiles that the rectangles of rect_add touch (no G-buffer sample lies outside them), the plain
 * resolve on the others. On llvmpipe a pixel vector of the deferred pass costs nearly as much
 * where it has nothing to shade as where it has (a loop body runs at least once, masked; an if
 * runs both sides): over the whole target it cost the generated bench scene (14 % of its pixels
 * covered) about 0.1x of its frame in pixels with nothing to shade (issue 19). */
static sy_gl_result deferred_pass(sy_gl_device *dev, const view_setup *v, sy_gl_report *rep)
{
    const sy_gl_fns *gl = dev->gl;
    const targets *t = &dev->t;
    int k = sy_gli_deferred_program(dev, frame_lighting(dev), rep);
    if (k < 0) return SY_GL_ERROR_GL;
    float inv_view[16];
    if (!sy_gli_m4_invert(v->view, inv_view)) return sy_gli_fail(rep, SY_GL_ERROR_INVALID_ARGUMENT, "render: view not invertible");
    float unproj[4], px[2];
    view_unproject(v, t->w, t->h, unproj, px);
    uint32_t n_shade = 1, n_rest = 0;
    const float(*shade)[4] = FULL_TARGET;
    if (!dev->rect_all && rect_tiles(dev, &n_shade, &n_rest, &dev->deferred_pixels)) shade = dev->spans;
    else n_shade = 1, n_rest = 0, dev->deferred_pixels = (uint64_t)t->w * t->h;
    if (n_shade) {
        gl->UseProgram(dev->dp[k].prog);
        dev->profile_var = -1;
        gl->Uniform4fv(dev->dp[k].unproj, 1, unproj);
        gl->UniformMatrix4fv(dev->dp[k].inv_view, 1, GL_FALSE, inv_view);
        gl->Uniform2fv(dev->dp[k].px, 1, px);
        gl->Uniform3fv(dev->dp[k].cam_pos, 1, v->cam_pos);
        gl->Uniform3fv(dev->dp[k].cam_fwd, 1, v->cam_fwd);
        gl->Uniform1i(dev->dp[k].ortho, v->ortho);
        sy_gli_bind_frame_resources(dev);
        sy_gli_mtab_upload(dev);
        gl->ActiveTexture(GL_TEXTURE0 + UNIT_GCOL);
        gl->BindTexture(GL_TEXTURE_2D_MULTISAMPLE, t->color);
        gl->ActiveTexture(GL_TEXTURE0 + UNIT_GDEPTH);
        gl->BindTexture(GL_TEXTURE_2D_MULTISAMPLE, t->depthlin);
        draw_rects(dev, dev->dp[k].rects, shade, n_shade);
    }
    if (n_rest) resolve_pass(dev, dev->spans + n_shade, n_rest);
    return SY_GL_OK;
}

/* Resolves (MSAA; shading the G-buffer when the main pass of view v drew into it) and reads the
 * target back into the caller's arrays, flipping rows. */
sy_gl_result sy_gli_finish_target(sy_gl_device *dev, const view_setup *v, float *rgba, float *depth, sy_gl_report *rep)
{
    const sy_gl_fns *gl = dev->gl;
    targets *t = &dev->t;
    GLuint read_fbo = t->fbo;
    if (t->samples > 1 && v && dev->deferred_draws) {
        gl->BindFramebuffer(GL_FRAMEBUFFER, t->rfbo);
        static const GLenum bufs[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
        gl->DrawBuffers(2, bufs);
        gl->Disable(GL_DEPTH_TEST);
        gl->Disable(GL_BLEND);
        sy_gl_result r = deferred_pass(dev, v, rep);
        if (r != SY_GL_OK) return r;
        read_fbo = t->rfbo;
    } else if (t->samples > 1) {
        gl->BindFramebuffer(GL_FRAMEBUFFER, t->rfbo);
        static const GLenum bufs[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
        gl->DrawBuffers(2, bufs);
        gl->Disable(GL_DEPTH_TEST);
        gl->Disable(GL_BLEND);
        resolve_pass(dev, FULL_TARGET, 1);
        read_fbo = t->rfbo;
    }
    size_t n = (size_t)t->w * t->h;
    if (dev->scratch_len < n * 4) {
        float *s = realloc(dev->scratch, n * 4 * sizeof *s);
        if (!s) return sy_gli_fail(rep, SY_GL_ERROR_OUT_OF_MEMORY, "render: out of memory for read-back");
        dev->scratch = s;
        dev->scratch_len = n * 4;
    }
    gl->BindFramebuffer(GL_FRAMEBUFFER, read_fbo);
    gl->PixelStorei(GL_PACK_ALIGNMENT, 4);
    gl->ReadBuffer(GL_COLOR_ATTACHMENT0);
    gl->ReadPixels(0, 0, (GLsizei)t->w, (GLsizei)t->h, GL_RGBA, GL_FLOAT, dev->scratch);
    size_t row = (size_t)t->w * 4;
    for (uint32_t y = 0; y < t->h; ++y) memcpy(rgba + row * y, dev->scratch + row * (t->h - 1 - y), row * sizeof(float));
    if (depth) {
        gl->ReadBuffer(GL_COLOR_ATTACHMENT1);
        gl->ReadPixels(0, 0, (GLsizei)t->w, (GLsizei)t->h, GL_RED, GL_FLOAT, dev->scratch);
        for (uint32_t y = 0; y < t->h; ++y)
            memcpy(depth + (size_t)t->w * y, dev->scratch + (size_t)t->w * (t->h - 1 - y), t->w * sizeof(float));
    }
    sy_gl_result r = sy_gli_gl_check(dev, "render read-back", rep);
    if (r != SY_GL_OK) return r;
    sy_gl_context_present(dev->ctx, read_fbo, t->w, t->h);
    return SY_GL_OK;
}

/* The variant bits of this frame's lighting. The probe faces (32 texels a side at 200x150, seen
 * blurred by rough reflections and refraction) light without the area lights' shadow maps: eight
 * taps per polygon cost TransmissionTest's 24 faces 0.07 s of its 0.5 s; its image moved by an rmse
 * of 8e-6 (issue 32). */
static int frame_lighting(const sy_gl_device *dev)
{
    int v = 0;
    if (dev->light_count) v |= VAR_LIGHTS;
    if (dev->light_count && dev->light_count <= VAR_NL_MAX) v |= (int)dev->light_count << VAR_NL_SHIFT;
    if (dev->env_ready) v |= VAR_ENV;
    if (dev->area_count) v |= VAR_AREA;
    if (dev->shadow_count) v |= VAR_SHADOW;
    if (dev->area_shadow_count && !dev->in_probe_pass) v |= VAR_ASHADOW;
    return v;
}

/* The material's variant bits that the shaders turn on and off per draw by the material's own
 * uniforms (m_tex, m_tex2, the transmission factor, the layers' factors): textures, normal map,
 * transmission, layers (the material extensions: their defaults shade as without them). */
static int material_features(const sy_gl_device *dev, const mat_o *mt)
{
    int v = 0;
    const sy_gl_texture_ref *refs[5] = {&mt->d.base_color_texture, &mt->d.metallic_roughness_texture,
                                        &mt->d.normal_texture, &mt->d.occlusion_texture, &mt->d.emissive_texture};
    for (int i = 0; i < 5; ++i)
        if (sy_gli_pool_get(&dev->textures, refs[i]->texture.id)) v |= i == UNIT_NRM ? VAR_TEX | VAR_NMAP : VAR_TEX;
    /* a metallic-roughness texture scales metallic per texel: a metal factor of 1 still transmits
     * where the texture says dielectric (TransmissionTest's striped "Metal" spheres) */
    bool mr_tex = sy_gli_pool_get(&dev->textures, mt->d.metallic_roughness_texture.texture.id) != NULL;
    if (mt->d.transmission > 0.0f && (mt->d.metallic < 1.0f || mr_tex)) {
        v |= VAR_TRANS;
        if (dev->layer_units && sy_gli_pool_get(&dev->textures, mt->d.transmission_texture.texture.id)) v |= VAR_TEX;
    }
    if (sy_gli_material_layered(dev, &mt->d)) {
        v |= VAR_LAYERS;
        if (mt->d.anisotropy > 0.0f) v |= VAR_TEX; /* its direction follows the uv tangent */
        const sy_gl_texture_ref *lr[LAYER_TEXTURES];
        sy_gli_layer_refs(&mt->d, lr);
        for (int i = 0; i < LAYER_TEXTURES && dev->layer_units; ++i)
            if (sy_gli_pool_get(&dev->textures, lr[i]->texture.id)) v |= VAR_TEX;
    }
    return v;
}

/* The texture slots material mt samples (the layers' and the five base ones, where its material
 * block's uv set is not -1: sy_gli_material_block) and whether it has iridescence or anisotropy
 * (dev->material_sig). Any material counts, layered or not: a program of the frame's shared
 * features draws every material, and reads the textures its block names. */
static uint32_t texture_features(const sy_gl_device *dev, const mat_o *mt)
{
    uint32_t s = sy_gli_material_textures(dev, mt);
    if (mt->d.iridescence > 0.0f) s |= MSIG_IRID;
    if (mt->d.anisotropy > 0.0f) s |= MSIG_ANISO;
    return s;
}

/* The material_features of every visible instance, once per frame (sy_gl_render): every forward
 * draw of the frame, probe faces included, takes them (draw_instance). Likewise the mesh
 * attributes: in a frame with any visible mesh that has a second uv set or colours (not
 * VAR_LEAN), every forward draw reads them; a lean mesh's draw gives them the constants the
 * shaders take for absent attributes (uv 0, colour 1: sy_gli_draw_mesh_lod), so it shades as
 * before, and llvmpipe compiles one program instead of a lean and a full one (issue 32:
 * TextureTransformMultiTest's layered variant, about 1 s of LLVM each). In the same pass: the
 * sampling the stand-ins follow (sy_gli_standins_follow), and the texture slots in use (texture_features). */
void sy_gli_frame_features(sy_gl_device *dev)
{
    int shared = 0;
    bool full = false, masked = false;
    uint32_t want[STANDINS], material_sig = 0;
    for (int k = 0; k < STANDINS; ++k) want[k] = STANDIN_ANY;
    const mat_o *last = NULL;
    for (uint32_t i = 0; i < dev->instances.count; ++i) {
        const inst_o *in = sy_gli_pool_at(&dev->instances, i);
        if (!in->h.id || !in->visible) continue;
        const mat_o *mt = sy_gli_pool_get(&dev->materials, in->material.id);
        if (mt && mt != last) {
            shared |= material_features(dev, last = mt);
            masked |= mt->d.alpha_mode == SY_GL_ALPHA_MASK;
            material_sig |= texture_features(dev, mt);
            sy_gli_standins_want(dev, mt, want);
        }
        const mesh_o *m = full ? NULL : sy_gli_pool_get(&dev->meshes, in->mesh.id);
        if (m && !sy_gli_mesh_lean(m)) full = true;
    }
    dev->shared_features = shared;
    dev->shared_full = full;
    dev->shared_masked = masked;
    dev->material_sig = material_sig;
    sy_gli_standins_follow(dev, want);
}

/* The variant bits for one draw: mesh attributes, material textures and mode, frame lighting,
 * whether the instance has a scene probe. */
static int draw_variant(const sy_gl_device *dev, const mesh_o *m, const mat_o *mt, bool probe)
{
    int v = frame_lighting(dev) | (sy_gli_mesh_lean(m) ? VAR_LEAN : 0);
    if (probe) v |= VAR_PROBE;
    if (!mt) return sy_gli_variant_normalize(v);
    if (mt->d.alpha_mode == SY_GL_ALPHA_MASK) v |= VAR_MASK;
    return sy_gli_variant_normalize(v | material_features(dev, mt));
}

/* Binds the variant's program (building it on first use) and, once per frame, its view uniforms. */
static sy_gl_result use_variant(sy_gl_device *dev, draw_ctx *dc, int pv, sy_gl_report *rep)
{
    if (pv == dc->bound) return SY_GL_OK;
    const sy_gl_fns *gl = dev->gl;
    GLuint p = sy_gli_main_program(dev, pv, rep);
    if (!p) return SY_GL_ERROR_GL;
    gl->UseProgram(p);
    dc->bound = pv;
    dev->profile_var = pv;
    if (dev->pm[pv].frame != dev->frame_no) {
        dev->pm[pv].frame = dev->frame_no;
        gl->Uniform3fv(dev->pm[pv].cam_pos, 1, dc->v->cam_pos);
        gl->Uniform3fv(dev->pm[pv].cam_fwd, 1, dc->v->cam_fwd);
        gl->Uniform1i(dev->pm[pv].ortho, dc->v->ortho);
        gl->Uniform3fv(dev->pm[pv].ortho_z, 1, dc->ortho_z);
    }
    return SY_GL_OK;
}

/* The probe of instance pool index i, or -1 (none, or while the probes themselves are drawn). */
static int probe_of(const sy_gl_device *dev, uint32_t i)
{
    if (dev->in_probe_pass) return -1;
    for (uint32_t p = 0; p < dev->probe_count; ++p)
        if (dev->probes[p].inst == i) return (int)p;
    return -1;
}

/* Whether a draw of variant pv with material mt (NULL: the default) can be shaded deferred: an
 * opaque, untextured, non-transmissive material in the table, on a mesh without colours or a
 * second uv set, without a scene probe. */
static bool deferrable(const sy_gl_device *dev, const inst_o *in, int pv, const mat_o *mt)
{
    if (!(in->px_per_tri <= DEFERRED_MAX_PX_PER_TRI)) return false;
    if ((pv & (VAR_TEX | VAR_MASK | VAR_TRANS | VAR_PROBE | VAR_LAYERS)) || !(pv & VAR_LEAN)) return false;
    if (mt && mt->d.alpha_mode != SY_GL_ALPHA_OPAQUE) return false;
    return (mt ? mt->h.id & IDX_MASK : 0u) < dev->mtab_cpu_rows;
}

/* Records where an instance drawn into the G-buffer with clip matrix mvp can have samples: the
 * pixels its mesh's bounding box touches (every level of detail lies within it), grown by one
 * pixel against rounding (GL transforms in single precision). The sy_gli_projection of a box whose
 * corners are all in front of the eye (w > 0) lies within the projected corners' bounds. A box
 * reaching behind the eye (which the deferred choice already sends forward: its bounding sphere
 * reaches the eye, see sy_gli_pixels_per_triangle), a non-finite corner, or no memory for the list:
 * everywhere. */
static void rect_add(sy_gl_device *dev, const float mvp[16], const mesh_o *m)
{
    if (dev->rect_all) return;
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (int k = 0; k < 8; ++k) {
        const double p[3] = {k & 1 ? m->bmax[0] : m->bmin[0], k & 2 ? m->bmax[1] : m->bmin[1],
                             k & 4 ? m->bmax[2] : m->bmin[2]};
        double c[4];
        for (int a = 0; a < 4; ++a) c[a] = mvp[a] * p[0] + mvp[4 + a] * p[1] + mvp[8 + a] * p[2] + mvp[12 + a];
        if (!(c[3] > 0.0)) {
            dev->rect_all = true;
            return;
        }
        for (int a = 0; a < 2; ++a) {
            double x = c[a] / c[3];
            lo[a] = fmin(lo[a], x), hi[a] = fmax(hi[a], x);
        }
    }
    const double size[2] = {dev->t.w, dev->t.h};
    uint32_t r[4];
    for (int a = 0; a < 2; ++a) { /* to pixels, grown by one, clamped to the target */
        if (!isfinite(lo[a]) || !isfinite(hi[a])) {
            dev->rect_all = true;
            return;
        }
        double x0 = floor((lo[a] * 0.5 + 0.5) * size[a]) - 1.0, x1 = ceil((hi[a] * 0.5 + 0.5) * size[a]) + 1.0;
        x0 = fmax(x0, 0.0), x1 = fmin(x1, size[a]);
        if (!(x0 < x1)) return; /* off the target */
        r[a] = (uint32_t)x0, r[2 + a] = (uint32_t)x1;
    }
    if (dev->rect_count == dev->rect_cap) {
        uint32_t cap = dev->rect_cap ? 2 * dev->rect_cap : 64;
        void *n = cap > dev->rect_cap ? realloc(dev->rects, sizeof *dev->rects * cap) : NULL;
        if (!n) {
            dev->rect_all = true;
            return;
        }
        dev->rects = n;
        dev->rect_cap = cap;
    }
    memcpy(dev->rects[dev->rect_count++], r, sizeof r);
}

/* One instance into the G-buffer (sy_gl_gbuf_fs). */
static void draw_gbuf(sy_gl_device *dev, draw_ctx *dc, const inst_o *in, const mesh_o *m, const mat_o *mt)
{
    const sy_gl_fns *gl = dev->gl;
    const int k = dc->v->ortho ? 1 : 0;
    if (dc->bound != BOUND_GBUF) {
        gl->UseProgram(dev->ug[k].prog);
        dc->bound = BOUND_GBUF;
        dev->profile_var = -1;
        if (!dc->gbuf_view_set) {
            float unproj[4], px[2];
            view_unproject(dc->v, dev->t.w, dev->t.h, unproj, px);
            /* the view plane's X = (gl_FragCoord.xy px - 1 + unproj.zw) / unproj.xy: pixels per unit */
            const float ppu[2] = {unproj[0] / px[0], unproj[1] / px[1]};
            gl->Uniform2fv(dev->ug[k].ppu, 1, ppu);
            gl->Uniform3fv(dev->ug[k].ortho_z, 1, dc->ortho_z);
            dc->gbuf_view_set = true;
        }
    }
    float mvp[16];
    sy_gli_m4_mul(dc->viewproj, in->model, mvp);
    gl->UniformMatrix4fv(dev->ug[k].mvp, 1, GL_FALSE, mvp);
    gl->UniformMatrix4fv(dev->ug[k].model, 1, GL_FALSE, in->model);
    gl->UniformMatrix3fv(dev->ug[k].normal_mat, 1, GL_FALSE, in->normal_mat);
    gl->Uniform1i(dev->ug[k].has_normals, m->has_normals);
    /* the key without geo (sy_gl_gbuf_fs): 4 x material row + front, plus 1 */
    const float key = (float)(1u + 4u * (mt ? mt->h.id & IDX_MASK : 0u)), keys[2] = {key + !in->mirror, key + in->mirror};
    gl->Uniform2fv(dev->ug[k].keys, 1, keys);
    dev->tris += sy_gli_draw_mesh_lod(dev, m, in->lod);
    dev->deferred_draws++;
    rect_add(dev, mvp, m);
}

/* Culls the faces of a closed opaque surface that face away from the eye (mesh_o.lod_closed): the
 * ray tracers see both sides of every triangle, but those of a closed surface wholly in front of
 * the near plane lie behind its other faces. llvmpipe shades every fragment a multisampled draw
 * covers, those that fail the depth test included (its per-sample depth test masks the fragments
 * without skipping the shader, unlike the single-sampled path): TransmissionTest's glass spheres
 * shaded their far halves (16 area lights each) for nothing, 0.3 s of its 1.2 s main pass
 * (issue 32). Masked and blended materials show their far faces; a surface the near plane or a
 * section plane cuts shows its inside. */
static void cull_hidden_faces(sy_gl_device *dev, draw_ctx *dc, const inst_o *in, const mesh_o *m, const mat_o *mt)
{
    unsigned want = 0;
    int8_t closed = m->lod_closed[in->lod < m->lod_count ? in->lod : 0];
    if (closed && !dev->clip_count && (!mt || mt->d.alpha_mode == SY_GL_ALPHA_OPAQUE)) { /* a cut one shows its inside */
        float c[3], scale, r = sy_gli_world_sphere(in, m, c, &scale);
        const float *V = dc->v->view;
        float depth = -(V[2] * c[0] + V[6] * c[1] + V[10] * c[2] + V[14]);
        if (depth - r > dc->near + 1e-4f * fabsf(depth) && isfinite(depth - r))
            want = (closed > 0) != in->mirror ? GL_BACK : GL_FRONT;
    }
    if (want == dc->cull) return;
    const sy_gl_fns *gl = dev->gl;
    if (!want) gl->Disable(GL_CULL_FACE);
    else {
        if (!dc->cull) gl->Enable(GL_CULL_FACE);
        gl->CullFace(want);
    }
    dc->cull = want;
}

static sy_gl_result draw_instance(sy_gl_device *dev, draw_ctx *dc, uint32_t index, const inst_o *in, const mesh_o *m,
                                  const mat_o *mt, sy_gl_report *rep)
{
    const sy_gl_fns *gl = dev->gl;
    cull_hidden_faces(dev, dc, in, m, mt);
    int probe = probe_of(dev, index);
    int pv = draw_variant(dev, m, mt, probe >= 0);
    if (dc->deferred && deferrable(dev, in, pv, mt)) {
        draw_gbuf(dev, dc, in, m, mt);
        return SY_GL_OK;
    }
    /* Every forward draw of the frame takes the features any visible material has: llvmpipe
     * compiles each program on its first draw in each pipeline state (about 0.2-0.5 s of LLVM for a
     * lit one), and a program that samples textures, maps normals or transmits only where the
     * material's uniforms say so draws the others as they were. TransmissionTest's first frame
     * compiled 11 main-pass shaders before, 6 with shared features, 4 since a draw without a probe
     * of its own reads the environment through the probe's unit (sy_gli_draw_scene; issue 32: 8.7 ->
     * 5.3 s cold at 200x150 on llvmpipe, 1.7 -> 1.8 s warm). */
    pv = sy_gli_variant_normalize((pv | dc->shared) & ~(dev->shared_full ? VAR_LEAN : 0));
    /* probe faces: one program for masked and other materials (only a masked material's alpha
     * discards: the main shader's SY_MASK test), so llvmpipe compiles one for the probes, not two
     * (0.3-0.45 s each for TransmissionTest's; issue 32); a face of 16-256 texels loses little to
     * the late depth test that discard brings */
    if (dev->in_probe_pass && dev->shared_masked) pv |= VAR_MASK;
    /* probe faces (16-256 px, seen blurred) shade without normal maps and material layers: a
     * smaller program that llvmpipe compiles in about half the time (docs/BACKENDS.md) */
    if (dev->in_probe_pass) pv = sy_gli_variant_normalize(pv & ~(VAR_NMAP | VAR_LAYERS));
    sy_gl_result r = use_variant(dev, dc, pv, rep);
    if (r != SY_GL_OK) return r;
    if (pv & VAR_PROBE) { /* its own probe (the 1-texel mip for roughness 1), or the environment's cube */
        gl->ActiveTexture(GL_TEXTURE0 + UNIT_PROBE);
        gl->BindTexture(GL_TEXTURE_CUBE_MAP, probe >= 0 ? dev->probes[probe].cube : dev->ibl.spec_cube);
        gl->Uniform1f(dev->pm[pv].probe_lod,
                      probe >= 0 ? log2f((float)dev->probe_size) : (float)(SY_GL_IBL_SPEC_LEVELS - 1));
    }
    sy_gli_bind_material(dev, in->material, (pv & VAR_TEX) != 0);
    float mvp[16];
    sy_gli_m4_mul(dc->viewproj, in->model, mvp);
    gl->UniformMatrix4fv(dev->pm[pv].mvp, 1, GL_FALSE, mvp);
    if (pv & (VAR_LIGHTS | VAR_ENV | VAR_AREA | VAR_PROBE)) {
        gl->UniformMatrix4fv(dev->pm[pv].model, 1, GL_FALSE, in->model);
        gl->UniformMatrix3fv(dev->pm[pv].normal_mat, 1, GL_FALSE, in->normal_mat);
        gl->Uniform1i(dev->pm[pv].has_normals, m->has_normals);
    }
    gl->Uniform1i(dev->pm[pv].mirror, in->mirror);
    dev->tris += sy_gli_draw_mesh_lod(dev, m, in->lod);
    return SY_GL_OK;
}

/* Section caps (sy_gl_camera.clip_cap), the rule of the ray tracers' sy_rt_clip_cap so that every
 * back-end caps the same pixels: where the nearest kept surface of a pixel is a back face of a
 * closed mesh (the back faces drawn again with the depth test LEQUAL against the main pass's depth,
 * which holds them where nothing kept is in front: the main pass culls no closed surface while the
 * view cuts) and the pixel's ray entered the kept region before it (else the eye is inside the
 * solid: discarded), the pixel shows the cap colour, and its linear depth is the entry point's on
 * the plane the ray crossed. The depth buffer keeps the back face's depth (a blended surface
 * between the cap and that face is hidden). */
static const char *const cap_vs =
    "#version 330 core\n" SY_GL_CLIP_VS
    "layout(location=0) in vec3 a_pos; uniform mat4 u_model; uniform mat4 u_mvp; out vec3 v_world;\n"
    "void main() { vec4 w = u_model * vec4(a_pos, 1.0); v_world = w.xyz; sy_clip(w.xyz);\n"
    "  gl_Position = u_mvp * vec4(a_pos, 1.0); }\n"; /* as the main pass: the same depth */
static const char *const cap_fs =
    "#version 330 core\n"
    "layout(std140) uniform Clip { vec4 c_planes[6]; };\n"
    "in vec3 v_world; layout(location=0) out vec4 o_color; layout(location=1) out float o_depth;\n"
    "uniform mat4 u_viewproj; uniform vec3 u_cam_pos, u_cam_fwd, u_color; uniform int u_ortho;\n"
    "void main() {\n"
    "  vec3 org = u_cam_pos, dir = v_world - u_cam_pos; float t_hit = 1.0;\n"
    "  if (u_ortho != 0) { float d = dot(dir, u_cam_fwd); dir = u_cam_fwd; org = v_world - d * dir; t_hit = d; }\n"
    "  float te = -1e30;\n"
    "  for (int i = 0; i < 6; ++i) { float ds = dot(c_planes[i].xyz, dir);\n"
    "    if (ds > 0.0) te = max(te, -(dot(c_planes[i].xyz, org) + c_planes[i].w) / ds); }\n"
    "  if (!(te > 0.0 && te < t_hit)) discard;\n"
    "  vec3 c = org + te * dir; vec4 p = u_viewproj * vec4(c, 1.0);\n"
    "  if (p.z < -p.w) discard;\n" /* the entry point in front of the near plane: the camera's own cut */
    "  o_color = vec4(u_color, 1.0); o_depth = dot(c - u_cam_pos, u_cam_fwd); }\n";

static sy_gl_result cap_pass(sy_gl_device *dev, draw_ctx *dc, sy_gl_report *rep)
{
    const sy_gl_fns *gl = dev->gl;
    if (!dev->cap.prog) {
        sy_gl_result r = sy_gl_program_build(gl, "section cap", cap_vs, cap_fs, NULL, &dev->cap.prog, rep);
        if (r != SY_GL_OK) return r;
        dev->cap.model = gl->GetUniformLocation(dev->cap.prog, "u_model");
        dev->cap.mvp = gl->GetUniformLocation(dev->cap.prog, "u_mvp");
        dev->cap.viewproj = gl->GetUniformLocation(dev->cap.prog, "u_viewproj");
        dev->cap.cam_pos = gl->GetUniformLocation(dev->cap.prog, "u_cam_pos");
        dev->cap.cam_fwd = gl->GetUniformLocation(dev->cap.prog, "u_cam_fwd");
        dev->cap.ortho = gl->GetUniformLocation(dev->cap.prog, "u_ortho");
        dev->cap.color = gl->GetUniformLocation(dev->cap.prog, "u_color");
        sy_gli_bind_clip_block(gl, dev->cap.prog);
    }
    gl->UseProgram(dev->cap.prog);
    dc->bound = -1;
    dev->profile_var = -1;
    gl->UniformMatrix4fv(dev->cap.viewproj, 1, GL_FALSE, dc->viewproj);
    gl->Uniform3fv(dev->cap.cam_pos, 1, dc->v->cam_pos);
    gl->Uniform3fv(dev->cap.cam_fwd, 1, dc->v->cam_fwd);
    gl->Uniform1i(dev->cap.ortho, dc->v->ortho);
    gl->Uniform3fv(dev->cap.color, 1, dev->clip_cap_color);
    gl->Enable(GL_CULL_FACE);
    gl->DepthFunc(GL_LEQUAL);
    gl->DepthMask(GL_FALSE);
    for (uint32_t i = 0; i < dev->instances.count; ++i) {
        const inst_o *in = sy_gli_pool_at(&dev->instances, i);
        if (!in->h.id || !in->visible) continue;
        const mesh_o *m = sy_gli_pool_get(&dev->meshes, in->mesh.id);
        if (!m || !m->cap_closed) continue;
        gl->CullFace((m->cap_closed > 0) != in->mirror ? GL_FRONT : GL_BACK); /* the back faces only */
        float mvp[16];
        sy_gli_m4_mul(dc->viewproj, in->model, mvp);
        gl->UniformMatrix4fv(dev->cap.model, 1, GL_FALSE, in->model);
        gl->UniformMatrix4fv(dev->cap.mvp, 1, GL_FALSE, mvp);
        dev->tris += sy_gli_draw_mesh_lod(dev, m, in->lod); /* the level the main pass drew */
    }
    gl->DepthMask(GL_TRUE);
    gl->DepthFunc(GL_LESS);
    gl->Disable(GL_CULL_FACE);
    dc->cull = 0;
    return SY_GL_OK;
}

/* Distance of an instance's bounding-box centre along the view direction. */
static float view_distance(const inst_o *in, const mesh_o *m, const view_setup *v)
{
    float z = 0.0f;
    for (int a = 0; a < 3; ++a) {
        float wv = in->model[12 + a];
        for (int k = 0; k < 3; ++k) wv += in->model[4 * k + a] * 0.5f * (m->bmin[k] + m->bmax[k]);
        z += (wv - v->cam_pos[a]) * v->cam_fwd[a];
    }
    return z;
}

/* The textures and uniform blocks every main-pass variant reads. */
void sy_gli_bind_frame_resources(sy_gl_device *dev)
{
    const sy_gl_fns *gl = dev->gl;
    gl->BindBufferBase(GL_UNIFORM_BUFFER, BIND_LIGHTS, dev->lights_ubo);
    gl->BindBufferBase(GL_UNIFORM_BUFFER, BIND_AREAS, dev->areas_ubo);
    gl->ActiveTexture(GL_TEXTURE0 + UNIT_SHADOW);
    gl->BindTexture(GL_TEXTURE_2D_ARRAY, dev->shadow_tex);
    for (uint32_t c = 0; c < SY_GL_MAX_CUBE_SHADOWS; ++c) {
        gl->ActiveTexture(GL_TEXTURE0 + UNIT_CUBE_SHADOW0 + (GLenum)c);
        gl->BindTexture(GL_TEXTURE_CUBE_MAP, dev->cube_tex[c]);
    }
    gl->ActiveTexture(GL_TEXTURE0 + UNIT_ENV_SPEC);
    gl->BindTexture(GL_TEXTURE_CUBE_MAP, dev->ibl.spec_cube);
    gl->ActiveTexture(GL_TEXTURE0 + UNIT_ENV_IRR);
    gl->BindTexture(GL_TEXTURE_CUBE_MAP, dev->ibl.irr_cube);
    GLuint tables[3] = {dev->ibl.brdf_lut, dev->ibl.ltc1, dev->ibl.ltc2};
    for (int i = 0; i < 3; ++i) {
        gl->ActiveTexture(GL_TEXTURE0 + UNIT_BRDF + (GLenum)i);
        gl->BindTexture(GL_TEXTURE_2D, tables[i]);
    }
}

static int cmp_far_first(const void *a, const void *b)
{
    const float *x = a, *y = b;
    return x[0] < y[0] ? 1 : x[0] > y[0] ? -1 : 0;
}

static int cmp_near_first(const void *a, const void *b) { return -cmp_far_first(a, b); }

/* Draws every visible instance but `skip` (a pool index, UINT32_MAX for none) into the bound
 * target: opaque near to far (early depth tests reject hidden fragments before shading), then
 * alpha-masked (the discard variant) near to far, then blended far to near with depth writes off.
 * Each list holds (view distance, instance index) pairs. */
sy_gl_result sy_gli_draw_scene(sy_gl_device *dev, const view_setup *v, uint32_t skip, sy_gl_report *rep)
{
    const sy_gl_fns *gl = dev->gl;
    sy_gl_result r = SY_GL_OK;
    draw_ctx dc = {.v = v, .ortho_z = {v->proj[10], v->proj[14], 0.0f}, .bound = -1};
    sy_gli_m4_mul(v->proj, v->view, dc.viewproj);
    /* the near plane's distance: z_ndc = -1 (perspective: proj[14] / (proj[10] - 1), an infinite far
     * plane included; orthographic: (1 + proj[14]) / proj[10]) */
    dc.near = v->ortho ? (1.0f + v->proj[14]) / v->proj[10] : v->proj[14] / (v->proj[10] - 1.0f);
    uint32_t cap = dev->instances.count ? dev->instances.count : 1, nl[3] = {0, 0, 0};
    float *lists = malloc(sizeof(float) * 2 * 3 * cap);
    if (!lists) return sy_gli_fail(rep, SY_GL_ERROR_OUT_OF_MEMORY, "render: out of memory");
    float planes[6][4];
    sy_gli_frustum_planes(dc.viewproj, planes);
    if (skip == UINT32_MAX) {
        dev->culled = dev->deferred_draws = dev->deferred_pixels = 0;
        dev->rect_count = 0;
        dev->rect_all = false;
    }
    /* with an environment, a draw without a probe of its own reads the prefiltered environment
     * through the probe's unit (draw_instance): one program for both, in the probe pass too */
    dc.shared = dev->shared_features | (dev->env_ready && dev->probe_count ? VAR_PROBE : 0);
    for (uint32_t i = 0; i < dev->instances.count; ++i) {
        inst_o *in = sy_gli_pool_at(&dev->instances, i);
        if (!in->h.id || !in->visible || i == skip) continue;
        const mesh_o *m = sy_gli_pool_get(&dev->meshes, in->mesh.id);
        if (!m) continue;
        float c[3], scale, r = sy_gli_world_sphere(in, m, c, &scale);
        if (sy_gli_sphere_outside(planes, c, r)) { /* outside the view: not drawn */
            if (skip == UINT32_MAX) dev->culled++;
            continue;
        }
        in->lod = sy_gli_choose_lod(dev, in, m, v, c, r, scale);
        in->px_per_tri = sy_gli_pixels_per_triangle(dev, m, in->lod, v, c, r);
        const mat_o *mt = sy_gli_pool_get(&dev->materials, in->material.id);
        sy_gl_alpha_mode mode = mt ? mt->d.alpha_mode : SY_GL_ALPHA_OPAQUE;
        int li = mode == SY_GL_ALPHA_BLEND ? 2 : mode == SY_GL_ALPHA_MASK ? 1 : 0;
        float *e = lists + 2 * ((size_t)li * cap + nl[li]++);
        e[0] = view_distance(in, m, v);
        memcpy(&e[1], &i, sizeof i);
    }
    /* deferred shading in the main pass of a frame without blended instances (they would blend
     * over G-buffer samples) */
    /* section caps: in the main pass, forward (a flat colour, not a G-buffer material), after the
     * opaque and masked draws and before the blended ones */
    const bool caps = dev->clip_cap && dev->clip_count && !dev->in_probe_pass && skip == UINT32_MAX;
    dc.deferred = !dev->forward && !dev->in_probe_pass && skip == UINT32_MAX && nl[2] == 0 && !caps;
    sy_gli_clip_enable(dev, true);
    for (int li = 0; li < 3 && r == SY_GL_OK; ++li) {
        if (li == 2 && caps) r = cap_pass(dev, &dc, rep);
        if (r != SY_GL_OK) break;
        float *list = lists + 2 * (size_t)li * cap;
        qsort(list, nl[li], 2 * sizeof(float), li == 2 ? cmp_far_first : cmp_near_first);
        if (li == 2 && nl[li]) {
            gl->Enable(GL_BLEND);
            gl->Disablei(GL_BLEND, 1); /* linear depth: the last (nearest) blended surface wins */
            gl->BlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA); /* premultiplied over */
            gl->DepthMask(GL_FALSE);
        }
        for (uint32_t k = 0; k < nl[li] && r == SY_GL_OK; ++k) {
            uint32_t i;
            memcpy(&i, &list[2 * k + 1], sizeof i);
            const inst_o *in = sy_gli_pool_at(&dev->instances, i);
            r = draw_instance(dev, &dc, i, in, sy_gli_pool_get(&dev->meshes, in->mesh.id),
                              sy_gli_pool_get(&dev->materials, in->material.id), rep);
        }
        if (dc.cull) { /* blended draws show their far faces; later passes expect no culling */
            gl->Disable(GL_CULL_FACE);
            dc.cull = 0;
        }
        if (li == 2 && nl[li]) {
            gl->DepthMask(GL_TRUE);
            gl->Disable(GL_BLEND);
        }
    }
    sy_gli_clip_enable(dev, false);
    free(lists);
    return r;
}
