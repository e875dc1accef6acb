/* sy_viewport.c — windows, viewports, stereo frusta and layer compositing (see sy_viewport.h). */
#include "sy_viewport.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct sy_viewport {
    sy_viewport_desc desc; /* backend/params point at the copies below */
    const sy_window *window; /* the owner (its size places the viewport's rectangle) */
    char *backend;
    char *params_text;
    sy_params params;
    bool active;
    bool has_view; /* sy_viewport_set_view: view replaces the camera node's world matrix */
    sy_mat4 view;
    uint32_t clip_count; /* sy_viewport_set_clip_planes */
    float clip_planes[SY_CLIP_PLANES_MAX][4];
    bool clip_cap; /* sy_viewport_set_clip_cap */
    float clip_cap_color[3];
};

struct sy_window {
    uint32_t width, height;
    sy_viewport **viewports;
    uint32_t count, capacity;
};

sy_result sy_window_create(uint32_t width, uint32_t height, sy_window **out, sy_error *err)
{
    *out = NULL;
    if (width == 0 || height == 0 || width > 65536 || height > 65536)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "window: bad size %ux%u", width, height);
    sy_window *w = calloc(1, sizeof *w);
    if (!w) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "window: out of memory");
    w->width = width;
    w->height = height;
    *out = w;
    return SY_OK;
}

static void viewport_free(sy_viewport *v)
{
    if (!v) return;
    free(v->backend);
    free(v->params_text);
    free(v);
}

void sy_window_destroy(sy_window *w)
{
    if (!w) return;
    for (uint32_t i = 0; i < w->count; ++i) viewport_free(w->viewports[i]);
    free(w->viewports);
    free(w);
}

sy_result sy_window_resize(sy_window *w, uint32_t width, uint32_t height, sy_error *err)
{
    if (width == 0 || height == 0 || width > 65536 || height > 65536)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "window: bad size %ux%u", width, height);
    w->width = width;
    w->height = height;
    return SY_OK;
}

void sy_window_size(const sy_window *w, uint32_t *width, uint32_t *height)
{
    *width = w->width;
    *height = w->height;
}

sy_result sy_viewport_set_backend(sy_viewport *v, const char *backend, const char *params, sy_error *err)
{
    if (!backend || !backend[0]) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "viewport: no back-end name");
    if (!sy_mediator_require(backend, err)) { /* fail now, keeping the current back-end, not at the next render */
        sy_error_prefix(err, "viewport");
        return SY_ERR_NOT_FOUND;
    }
    sy_params parsed;
    sy_result r = sy_params_parse(params, &parsed, err);
    if (r == SY_OK) r = sy_mediator_class_check_params(sy_mediator_find(backend), &parsed, err); /* now, too */
    if (r != SY_OK) return r;
    char *b = strdup(backend), *p = params ? strdup(params) : NULL;
    if (!b || (params && !p)) {
        free(b);
        free(p);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "viewport: out of memory");
    }
    free(v->backend);
    free(v->params_text);
    v->backend = b;
    v->params_text = p;
    v->params = parsed;
    v->desc.backend = v->backend;
    v->desc.params = v->params_text;
    return SY_OK;
}

sy_result sy_window_add_viewport(sy_window *w, const sy_viewport_desc *desc, sy_viewport **out, sy_error *err)
{
    if (out) *out = NULL;
    if (desc->eye > SY_EYE_RIGHT || desc->composite > SY_COMPOSITE_ALPHA_OVER)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "viewport: bad eye %u or composite mode %u", desc->eye,
                            desc->composite);
    sy_viewport *v = calloc(1, sizeof *v);
    if (!v) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "viewport: out of memory");
    v->desc = *desc;
    v->window = w;
    if (v->desc.eye_separation == 0.0f) v->desc.eye_separation = 0.065f;
    if (v->desc.zero_parallax == 0.0f) v->desc.zero_parallax = 2.0f;
    v->active = !desc->inactive;
    sy_result r = sy_viewport_set_backend(v, desc->backend, desc->params, err);
    if (r != SY_OK) {
        viewport_free(v);
        return r;
    }
    if (w->count == w->capacity) {
        uint32_t nc = w->capacity ? w->capacity * 2 : 4;
        sy_viewport **nv = realloc(w->viewports, sizeof *nv * nc);
        if (!nv) {
            viewport_free(v);
            return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "viewport: out of memory");
        }
        w->viewports = nv;
        w->capacity = nc;
    }
    w->viewports[w->count++] = v;
    if (out) *out = v;
    return SY_OK;
}

uint32_t sy_window_viewport_count(const sy_window *w) { return w->count; }
sy_viewport *sy_window_viewport(const sy_window *w, uint32_t i) { return i < w->count ? w->viewports[i] : NULL; }
void sy_viewport_set_active(sy_viewport *v, bool active) { v->active = active; }
bool sy_viewport_active(const sy_viewport *v) { return v->active; }
void sy_viewport_set_camera(sy_viewport *v, sy_node camera) { v->desc.camera = camera; }
const char *sy_viewport_backend(const sy_viewport *v) { return v->backend; }

void sy_viewport_set_view(sy_viewport *v, const sy_mat4 *camera_to_world)
{
    v->has_view = camera_to_world != NULL;
    if (camera_to_world) v->view = *camera_to_world;
}

void sy_viewport_set_background(sy_viewport *v, sy_background background)
{
    v->desc.background = background;
}

sy_background sy_viewport_background(const sy_viewport *v)
{
    return v->desc.background;
}

sy_result sy_viewport_set_clip_planes(sy_viewport *v, const float (*planes)[4], uint32_t count, sy_error *err)
{
    sy_result r = sy_clip_planes_check(planes, count, err);
    if (r != SY_OK) {
        sy_error_prefix(err, "viewport");
        return r;
    }
    if (count) memcpy(v->clip_planes, planes, (size_t)count * sizeof v->clip_planes[0]);
    v->clip_count = count;
    return SY_OK;
}

uint32_t sy_viewport_clip_planes(const sy_viewport *v, float (*planes)[4])
{
    if (planes && v->clip_count) memcpy(planes, v->clip_planes, (size_t)v->clip_count * sizeof v->clip_planes[0]);
    return v->clip_count;
}

sy_result sy_viewport_set_clip_cap(sy_viewport *v, const float rgb[3], sy_error *err)
{
    if (!rgb) {
        v->clip_cap = false;
        return SY_OK;
    }
    sy_result r = sy_clip_cap_check(rgb, err);
    if (r != SY_OK) {
        sy_error_prefix(err, "viewport");
        return r;
    }
    memcpy(v->clip_cap_color, rgb, sizeof v->clip_cap_color);
    v->clip_cap = true;
    return SY_OK;
}

bool sy_viewport_clip_cap(const sy_viewport *v, float rgb[3])
{
    if (v->clip_cap && rgb) memcpy(rgb, v->clip_cap_color, sizeof v->clip_cap_color);
    return v->clip_cap;
}

bool sy_viewport_view(const sy_viewport *v, sy_mat4 *camera_to_world)
{
    if (v->has_view && camera_to_world) *camera_to_world = v->view;
    return v->has_view;
}

static void viewport_rect(const sy_viewport *v, uint32_t ww, uint32_t wh, uint32_t r[4])
{
    r[0] = v->desc.x < ww ? v->desc.x : ww;
    r[1] = v->desc.y < wh ? v->desc.y : wh;
    r[2] = v->desc.width ? v->desc.width : ww;
    r[3] = v->desc.height ? v->desc.height : wh;
    if (r[2] > ww - r[0]) r[2] = ww - r[0];
    if (r[3] > wh - r[1]) r[3] = wh - r[1];
}

sy_camera_view sy_camera_view_eye(const sy_camera_view *mono, uint32_t eye, float separation, float zero_parallax)
{
    sy_camera_view v = *mono;
    if (eye == SY_EYE_MONO) return v;
    float side = eye == SY_EYE_LEFT ? -0.5f : 0.5f;
    float shift = side * separation;
    const float *m = mono->camera_to_world.m;
    /* move the eye along the camera's local X axis */
    for (int i = 0; i < 3; ++i) v.camera_to_world.m[12 + i] += m[i] * shift;
    if (mono->projection == SY_PROJECTION_PERSPECTIVE && zero_parallax > 0.0f) {
        /* skew: the window seen from the shifted eye must cover the same rectangle at zero_parallax */
        float d = shift / zero_parallax;
        v.window[0] -= d;
        v.window[1] -= d;
    }
    return v;
}

sy_result sy_viewport_camera_view(const sy_viewport *v, const sy_scene *scene, uint32_t ww, uint32_t wh,
                                  sy_camera_view *out, sy_error *err)
{
    uint32_t r[4];
    viewport_rect(v, ww, wh, r);
    float aspect = r[3] ? (float)r[2] / (float)r[3] : 1.0f;
    sy_camera_view mono;
    if (v->desc.camera.id) {
        const sy_node_data *nd = sy_node_get(scene, v->desc.camera);
        const sy_camera_data *cd = nd ? sy_camera_get(scene, nd->camera) : NULL;
        if (!cd) return sy_error_set(err, SY_ERR_INVALID_HANDLE, "viewport: camera node %#x has no camera", v->desc.camera.id);
        sy_mat4 world = v->view;
        sy_result res = v->has_view ? SY_OK : sy_node_world_matrix(scene, v->desc.camera, &world, err);
        if (res != SY_OK) return res;
        mono = sy_camera_view_make(cd, &world, aspect);
    } else {
        sy_bounds b;
        if (v->desc.root.id) {
            sy_result res = sy_node_world_bounds(scene, v->desc.root, &b, err);
            if (res != SY_OK) return res;
        } else {
            b = sy_scene_world_bounds(scene);
        }
        mono = sy_camera_view_frame_bounds(&b, aspect);
        if (v->has_view) mono.camera_to_world = v->view;
    }
    *out = sy_camera_view_eye(&mono, v->desc.eye, v->desc.eye_separation, v->desc.zero_parallax);
    out->clip_count = v->clip_count;
    memcpy(out->clip_planes, v->clip_planes, sizeof out->clip_planes);
    out->clip_cap = v->clip_cap && v->clip_count;
    memcpy(out->clip_cap_color, v->clip_cap_color, sizeof out->clip_cap_color);
    sy_result res = sy_camera_view_check(out, err);
    if (res != SY_OK) {
        if (v->desc.camera.id) sy_error_prefix(err, "viewport: camera node %#x", v->desc.camera.id);
        else sy_error_prefix(err, "viewport: the view framing the scene");
    }
    return res;
}

/* One row per mode, the mode switch outside the pixel loops. */
static void composite_row(float *restrict d, float *restrict dd, const float *restrict s, const float *restrict sd,
                          uint32_t w, uint32_t mode)
{
    switch (mode) {
    case SY_COMPOSITE_DEPTH:
        for (uint32_t i = 0; i < w; ++i)
            if (sd[i] < dd[i]) {
                memcpy(d + 4 * i, s + 4 * i, 4 * sizeof(float));
                dd[i] = sd[i];
            }
        break;
    case SY_COMPOSITE_ALPHA_OVER:
        for (uint32_t i = 0; i < w; ++i) {
            float a = s[4 * i + 3];
            if (a == 0.0f && s[4 * i] == 0.0f && s[4 * i + 1] == 0.0f && s[4 * i + 2] == 0.0f) continue;
            float k = 1.0f - a;
            for (int c = 0; c < 4; ++c) d[4 * i + c] = s[4 * i + c] + d[4 * i + c] * k;
            if (a > 0.0f && sd[i] < dd[i]) dd[i] = sd[i];
        }
        break;
    default:
        memcpy(d, s, (size_t)w * 4 * sizeof(float));
        memcpy(dd, sd, (size_t)w * sizeof(float));
        break;
    }
}

void sy_layer_composite(sy_layer *dst, const sy_layer *src, uint32_t x, uint32_t y, uint32_t mode)
{
    if (x >= dst->width || y >= dst->height) return;
    uint32_t w = src->width < dst->width - x ? src->width : dst->width - x;
    uint32_t h = src->height < dst->height - y ? src->height : dst->height - y;
    for (uint32_t j = 0; j < h; ++j) {
        size_t si = (size_t)j * src->width, di = (size_t)(y + j) * dst->width + x;
        composite_row(dst->rgba + 4 * di, dst->depth + di, src->rgba + 4 * si, src->depth + si, w, mode);
    }
}

sy_result sy_window_render(sy_window *w, sy_scene *scene, sy_context_pool *pool, const sy_window_render_opts *opts,
                           sy_layer *out, sy_error *err)
{
    static const sy_window_render_opts defaults;
    if (!opts) opts = &defaults;
    if (out->width != w->width || out->height != w->height)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "window render: layer %ux%u for a %ux%u window", out->width,
                            out->height, w->width, w->height);
    sy_layer_clear(out);
    sy_result r = SY_OK;
    for (uint32_t i = 0; i < w->count && r == SY_OK; ++i) {
        sy_viewport *v = w->viewports[i];
        if (!v->active) continue;
        uint32_t rect[4];
        viewport_rect(v, w->width, w->height, rect);
        if (!rect[2] || !rect[3]) continue;
        sy_context *ctx;
        r = sy_context_pool_get(pool, scene, v->backend, &v->params, v->desc.root.id, &ctx, err);
        if (r == SY_OK) r = sy_context_sync(ctx, err);
        sy_render_request req;
        memset(&req, 0, sizeof req);
        if (r == SY_OK) r = sy_viewport_camera_view(v, scene, w->width, w->height, &req.camera, err);
        if (r != SY_OK) break;
        req.full_width = rect[2];
        req.full_height = rect[3];
        req.rect_w = rect[2];
        req.rect_h = rect[3];
        req.sample_count = opts->sample_count;
        req.preview = opts->preview;
        req.background_id = v->desc.background.id;
        req.seed = opts->seed;
        req.progress = opts->progress;
        req.progress_user = opts->progress_user;
        sy_layer layer;
        r = sy_layer_create(rect[2], rect[3], &layer, err);
        if (r != SY_OK) break;
        r = sy_context_render(ctx, &req, &layer, err);
        if (r == SY_OK) {
            sy_layer_post_apply(&layer, &v->desc.post);
            sy_layer_composite(out, &layer, rect[0], rect[1], v->desc.composite);
        }
        sy_layer_destroy(&layer);
    }
    if (r == SY_OK) sy_layer_post_apply(out, &opts->post);
    return r;
}

/* >>picking: the ray through the pixel's centre, asked of the viewport's back-end (SY_CAP_PICK) */

/* The viewport's pixel under window point (x, y); false when (x, y) is outside its rectangle. */
static bool viewport_pixel(const uint32_t rect[4], double x, double y, uint32_t *px, uint32_t *py)
{
    double fx = floor(x) - (double)rect[0], fy = floor(y) - (double)rect[1];
    if (!(fx >= 0.0 && fy >= 0.0 && fx < (double)rect[2] && fy < (double)rect[3])) return false;
    *px = (uint32_t)fx;
    *py = (uint32_t)fy;
    return true;
}

/* Picks pixel (px, py) of an active viewport with a non-empty rectangle. */
/* A capped view's pick that met a closed mesh's back face after entering the kept region: moved to
 * the cap (sy_pick_result.cap_plane), the rule every back-end draws caps by. */
static void pick_on_cap(const sy_scene *scene, const sy_camera_view *view, sy_pick_result *p)
{
    const float *m = view->camera_to_world.m, fwd[3] = {-m[8], -m[9], -m[10]}, eye[3] = {m[12], m[13], m[14]};
    float org[3], d[3]; /* the ray, with the hit at org + d */
    for (int k = 0; k < 3; ++k) {
        if (view->projection == SY_PROJECTION_ORTHOGRAPHIC) {
            float fl = sqrtf(fwd[0] * fwd[0] + fwd[1] * fwd[1] + fwd[2] * fwd[2]);
            d[k] = fl > 0.0f ? fwd[k] / fl * p->distance : 0.0f;
        } else {
            d[k] = p->position[k] - eye[k];
        }
        org[k] = p->position[k] - d[k];
    }
    float t_enter = -INFINITY, best[3] = {0, 0, 0};
    uint32_t plane = 0;
    for (uint32_t i = 0; i < view->clip_count && i < SY_CLIP_PLANES_MAX; ++i) {
        const float *q = view->clip_planes[i];
        float s0 = q[0] * org[0] + q[1] * org[1] + q[2] * org[2] + q[3], ds = q[0] * d[0] + q[1] * d[1] + q[2] * d[2];
        if (ds > 0.0f && -s0 / ds > t_enter) t_enter = -s0 / ds, plane = i + 1, memcpy(best, q, sizeof best);
    }
    if (!(t_enter > 0.0f && t_enter < 1.0f)) return;
    const sy_mesh_data *md = sy_mesh_get(scene, (sy_mesh){p->mesh_id});
    if (!md || p->primitive >= md->primitives.count) return;
    const sy_primitive *pr = &md->primitives.items[p->primitive];
    int closed = sy_mesh_closed(sy_blob_data(pr->positions), sy_primitive_vertex_count(pr), sy_blob_data(pr->indices),
                                sy_primitive_triangle_count(pr));
    float facing = (float)closed * (p->normal[0] * d[0] + p->normal[1] * d[1] + p->normal[2] * d[2]);
    if (!closed || !(facing > 0.0f)) return; /* not closed, or the outside seen */
    float nl = sqrtf(best[0] * best[0] + best[1] * best[1] + best[2] * best[2]), dl = 0.0f, depth = 0.0f;
    for (int k = 0; k < 3; ++k) {
        p->position[k] = org[k] + t_enter * d[k];
        p->normal[k] = -best[k] / nl; /* the cut face looks back at the eye */
        dl += d[k] * d[k];
    }
    float fl = sqrtf(fwd[0] * fwd[0] + fwd[1] * fwd[1] + fwd[2] * fwd[2]);
    for (int k = 0; k < 3; ++k) depth += (p->position[k] - eye[k]) * (fl > 0.0f ? fwd[k] / fl : 0.0f);
    p->distance = t_enter * sqrtf(dl);
    p->depth = depth;
    p->cap_plane = plane;
}

static sy_result viewport_pick_pixel(sy_viewport *v, sy_scene *scene, sy_context_pool *pool, const uint32_t rect[4],
                                     uint32_t px, uint32_t py, sy_pick_result *out, sy_error *err)
{
    sy_context *ctx;
    sy_result r = sy_context_pool_get(pool, scene, v->backend, &v->params, v->desc.root.id, &ctx, err);
    if (r == SY_OK) r = sy_context_sync(ctx, err);
    sy_camera_view view;
    if (r == SY_OK) r = sy_viewport_camera_view(v, scene, v->window->width, v->window->height, &view, err);
    out->eye = v->desc.eye;
    out->pixel_x = px;
    out->pixel_y = py;
    if (r == SY_OK) r = sy_context_pick(ctx, &view, rect[2], rect[3], px, py, out, err);
    if (r == SY_OK && out->hit && view.clip_cap && view.clip_count) pick_on_cap(scene, &view, out);
    return r;
}

static sy_result pick_args(double x, double y, sy_pick_result *out, sy_error *err)
{
    memset(out, 0, sizeof *out);
    out->viewport = UINT32_MAX;
    if (!isfinite(x) || !isfinite(y))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "pick: pixel coordinates (%g, %g) are not finite", x, y);
    return SY_OK;
}

sy_result sy_viewport_pick(sy_viewport *v, sy_scene *scene, sy_context_pool *pool, double x, double y,
                           sy_pick_result *out, sy_error *err)
{
    sy_result r = pick_args(x, y, out, err);
    if (r != SY_OK) return r;
    uint32_t rect[4], px, py;
    viewport_rect(v, v->window->width, v->window->height, rect);
    if (!viewport_pixel(rect, x, y, &px, &py))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                            "pick: window pixel (%g, %g) is outside the viewport's rectangle %ux%u at (%u, %u)", x, y,
                            rect[2], rect[3], rect[0], rect[1]);
    const sy_window *w = v->window;
    for (uint32_t i = 0; i < w->count; ++i)
        if (w->viewports[i] == v) out->viewport = i;
    return viewport_pick_pixel(v, scene, pool, rect, px, py, out, err);
}

sy_result sy_window_pick(sy_window *w, sy_scene *scene, sy_context_pool *pool, double x, double y,
                         sy_pick_result *out, sy_error *err)
{
    sy_result r = pick_args(x, y, out, err);
    if (r != SY_OK) return r;
    if (!(x >= 0.0 && y >= 0.0 && x < (double)w->width && y < (double)w->height))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "pick: pixel (%g, %g) is outside the %ux%u window", x, y,
                            w->width, w->height);
    /* back to front, as sy_window_render composites: a replacing layer replaces the answer, a
     * depth-composited one wins where it is nearer, an alpha-over one where it drew something */
    for (uint32_t i = 0; i < w->count; ++i) {
        sy_viewport *v = w->viewports[i];
        uint32_t rect[4], px, py;
        viewport_rect(v, w->width, w->height, rect);
        if (!v->active || !viewport_pixel(rect, x, y, &px, &py)) continue;
        sy_pick_result here;
        memset(&here, 0, sizeof here);
        here.viewport = i;
        r = viewport_pick_pixel(v, scene, pool, rect, px, py, &here, err);
        if (r != SY_OK) return r;
        bool take;
        switch (v->desc.composite) {
        case SY_COMPOSITE_DEPTH: take = here.hit && (!out->hit || here.depth < out->depth); break;
        case SY_COMPOSITE_ALPHA_OVER: take = here.hit; break;
        default: take = true; break;
        }
        if (take) *out = here;
    }
    return SY_OK;
}

sy_result sy_pick_distance(const sy_pick_result *a, const sy_pick_result *b, double *out, sy_error *err)
{
    if (!a || !b || !out) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "pick distance: NULL argument");
    if (!a->hit || !b->hit)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "pick distance: the %s pick hit nothing", !a->hit ? "first" : "second");
    double s = 0.0;
    for (int k = 0; k < 3; ++k) {
        double d = (double)b->position[k] - (double)a->position[k];
        s += d * d;
    }
    *out = sqrt(s);
    return SY_OK;
}

sy_result sy_plane_distance(const float plane[4], const float p[3], double *out, sy_error *err)
{
    if (!plane || !p || !out) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "plane distance: NULL argument");
    sy_result r = sy_clip_planes_check((const float(*)[4])plane, 1, err);
    if (r != SY_OK) return r;
    if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2]))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "plane distance: the point (%g, %g, %g) is not finite",
                            (double)p[0], (double)p[1], (double)p[2]);
    double n = sqrt((double)plane[0] * plane[0] + (double)plane[1] * plane[1] + (double)plane[2] * plane[2]);
    *out = ((double)plane[0] * p[0] + (double)plane[1] * p[1] + (double)plane[2] * p[2] + plane[3]) / n;
    return SY_OK;
}
