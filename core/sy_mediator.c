/* sy_mediator.c — layers, camera views, the mediator registry, the checking of a class's
 * parameters, contexts and the context pool (see sy_mediator.h). */
#include "sy_mediator.h"

#include <math.h>
#include <stdio.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

/* >>layers */
sy_result sy_layer_create(uint32_t width, uint32_t height, sy_layer *out, sy_error *err)
{
    memset(out, 0, sizeof *out);
    size_t n, bytes4, bytes1;
    if (width == 0 || height == 0 || width > 65536 || height > 65536 || !sy_size_mul(width, height, &n) ||
        !sy_size_mul(n, 4 * sizeof(float), &bytes4) || !sy_size_mul(n, sizeof(float), &bytes1))
        return sy_error_set(err, SY_ERR_LIMIT, "layer: bad size %ux%u", width, height);
    out->rgba = malloc(bytes4);
    out->depth = malloc(bytes1);
    if (!out->rgba || !out->depth) {
        sy_layer_destroy(out);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "layer: out of memory for %ux%u", width, height);
    }
    out->width = width;
    out->height = height;
    sy_layer_clear(out);
    return SY_OK;
}

void sy_layer_destroy(sy_layer *l)
{
    if (!l) return;
    free(l->rgba);
    free(l->depth);
    memset(l, 0, sizeof *l);
}

void sy_layer_clear(sy_layer *l)
{
    size_t n = (size_t)l->width * l->height;
    memset(l->rgba, 0, n * 4 * sizeof(float));
    for (size_t i = 0; i < n; ++i) l->depth[i] = INFINITY;
}

size_t sy_layer_count_nonfinite(const sy_layer *l)
{
    size_t n = (size_t)l->width * l->height, bad = 0;
    for (size_t i = 0; i < n; ++i)
        if (!isfinite(l->rgba[4 * i]) || !isfinite(l->rgba[4 * i + 1]) || !isfinite(l->rgba[4 * i + 2]) ||
            !isfinite(l->rgba[4 * i + 3]))
            bad++;
    return bad;
}

/* >>camera views */
sy_camera_view sy_camera_view_make(const sy_camera_data *cam, const sy_mat4 *world, float image_aspect)
{
    sy_camera_view v;
    memset(&v, 0, sizeof v);
    v.camera_to_world = *world;
    v.projection = cam->projection;
    v.znear = cam->znear;
    v.zfar = cam->zfar;
    if (!(image_aspect > 0.0f)) image_aspect = 1.0f;
    if (cam->projection == SY_PROJECTION_ORTHOGRAPHIC) {
        float ym = cam->ymag > 0.0f ? cam->ymag : 1.0f;
        v.window[0] = -ym * image_aspect;
        v.window[1] = ym * image_aspect;
        v.window[2] = -ym;
        v.window[3] = ym;
    } else {
        float t = tanf(cam->yfov * 0.5f);
        v.window[0] = -t * image_aspect;
        v.window[1] = t * image_aspect;
        v.window[2] = -t;
        v.window[3] = t;
    }
    return v;
}

sy_camera_view sy_camera_view_frame_bounds(const sy_bounds *b, float image_aspect)
{
    float c[3] = {0, 0, 0}, r = 1.0f;
    if (!sy_bounds_is_empty(b)) {
        float ext2 = 0.0f;
        for (int i = 0; i < 3; ++i) {
            c[i] = 0.5f * (b->min[i] + b->max[i]);
            float e = 0.5f * (b->max[i] - b->min[i]);
            ext2 += e * e;
        }
        r = sqrtf(ext2);
        if (!(r > 1e-6f)) r = 1.0f;
    }
    sy_camera_data cam = *(const sy_camera_data *)sy_object_defaults(SY_TYPE_CAMERA);
    cam.yfov = 0.7853982f;
    float half = cam.yfov * 0.5f;
    if (image_aspect < 1.0f) half = atanf(tanf(half) * image_aspect); /* fit the narrower side */
    float dist = r / sinf(half) * 1.05f;
    /* look from the front, slightly above: direction (0, sin 20deg, cos 20deg) */
    float dir[3] = {0.0f, 0.34202f, 0.93969f};
    float eye[3] = {c[0] + dir[0] * dist, c[1] + dir[1] * dist, c[2] + dir[2] * dist};
    /* camera basis: z = dir (camera looks down -z), x = up x z normalised, y = z x x */
    float z[3] = {dir[0], dir[1], dir[2]};
    float x[3] = {z[2], 0.0f, -z[0]}; /* (0,1,0) x z */
    float xl = sqrtf(x[0] * x[0] + x[2] * x[2]);
    if (xl < 1e-6f) x[0] = 1.0f, x[2] = 0.0f, xl = 1.0f;
    x[0] /= xl, x[2] /= xl;
    float y[3] = {z[1] * x[2] - z[2] * x[1], z[2] * x[0] - z[0] * x[2], z[0] * x[1] - z[1] * x[0]};
    sy_mat4 m = {{x[0], x[1], x[2], 0, y[0], y[1], y[2], 0, z[0], z[1], z[2], 0, eye[0], eye[1], eye[2], 1}};
    cam.znear = dist - r > 1e-3f ? (dist - r) * 0.5f : 1e-3f;
    return sy_camera_view_make(&cam, &m, image_aspect);
}

/* >>registry (the one process-wide table) */
#define REGISTRY_MAX 32
static pthread_mutex_t g_registry_lock = PTHREAD_MUTEX_INITIALIZER;
static const sy_mediator_class *g_registry[REGISTRY_MAX];
static uint32_t g_registry_count;

sy_result sy_mediator_register(const sy_mediator_class *cls, sy_error *err)
{
    if (!cls || !cls->name || !cls->create || !cls->destroy || !cls->sync || !cls->render)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "mediator register: incomplete class");
    sy_result r = SY_OK;
    pthread_mutex_lock(&g_registry_lock);
    for (uint32_t i = 0; i < g_registry_count; ++i)
        if (strcmp(g_registry[i]->name, cls->name) == 0) {
            r = g_registry[i] == cls ? SY_OK
                                     : sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                                                    "mediator register: '%s' is already registered", cls->name);
            pthread_mutex_unlock(&g_registry_lock);
            return r;
        }
    if (g_registry_count == REGISTRY_MAX) r = sy_error_set(err, SY_ERR_LIMIT, "mediator register: registry full");
    else g_registry[g_registry_count++] = cls;
    pthread_mutex_unlock(&g_registry_lock);
    return r;
}

const sy_mediator_class *sy_mediator_find(const char *name)
{
    const sy_mediator_class *found = NULL;
    pthread_mutex_lock(&g_registry_lock);
    for (uint32_t i = 0; i < g_registry_count && !found; ++i)
        if (strcmp(g_registry[i]->name, name) == 0) found = g_registry[i];
    pthread_mutex_unlock(&g_registry_lock);
    return found;
}

const sy_mediator_class *sy_mediator_require(const char *name, sy_error *err)
{
    const sy_mediator_class *cls = sy_mediator_find(name);
    if (!cls) {
        char names[256] = "";
        for (uint32_t i = 0; i < sy_mediator_count(); ++i) {
            size_t l = strlen(names);
            snprintf(names + l, sizeof names - l, "%s%s", l ? ", " : "", sy_mediator_at(i)->name);
        }
        sy_error_set(err, SY_ERR_NOT_FOUND, "back-end '%s' is not registered (available: %s)", name,
                     names[0] ? names : "none");
    }
    return cls;
}

const sy_mediator_class *sy_mediator_default(void)
{
    const sy_mediator_class *best = NULL;
    pthread_mutex_lock(&g_registry_lock);
    for (uint32_t i = 0; i < g_registry_count; ++i)
        if (g_registry[i]->default_rank > 0 && (!best || g_registry[i]->default_rank > best->default_rank))
            best = g_registry[i];
    pthread_mutex_unlock(&g_registry_lock);
    return best;
}

const char *sy_mediator_default_name(void)
{
    const sy_mediator_class *c = sy_mediator_default();
    return c ? c->name : "";
}

const sy_mediator_class *sy_mediator_with_caps(uint32_t caps)
{
    const sy_mediator_class *found = NULL;
    pthread_mutex_lock(&g_registry_lock);
    for (uint32_t i = 0; i < g_registry_count && !found; ++i)
        if ((g_registry[i]->caps & caps) == caps) found = g_registry[i];
    pthread_mutex_unlock(&g_registry_lock);
    return found;
}

uint32_t sy_mediator_count(void)
{
    pthread_mutex_lock(&g_registry_lock);
    uint32_t n = g_registry_count;
    pthread_mutex_unlock(&g_registry_lock);
    return n;
}

const sy_mediator_class *sy_mediator_at(uint32_t i)
{
    pthread_mutex_lock(&g_registry_lock);
    const sy_mediator_class *c = i < g_registry_count ? g_registry[i] : NULL;
    pthread_mutex_unlock(&g_registry_lock);
    return c;
}

/* >>parameters: the one place a back-end's parameters are validated */
sy_result sy_mediator_class_check_params(const sy_mediator_class *cls, const sy_params *params, sy_error *err)
{
    char owner[64];
    snprintf(owner, sizeof owner, "back-end '%s'", cls->name);
    if (!cls->check_params) return sy_params_check(&cls->param_table, params, 0, owner, NULL, err);
    sy_params rest;
    sy_result r = sy_params_check(&cls->param_table, params, 0, owner, &rest, err);
    if (r == SY_OK && rest.count) r = cls->check_params(params, &rest, cls->user, err);
    return r;
}

size_t sy_mediator_class_format_params(const sy_mediator_class *cls, const char *indent, char *buf, size_t len)
{
    return sy_param_table_format(&cls->param_table, indent, buf, len);
}

/* >>contexts */
struct sy_context {
    int refs;
    const sy_mediator_class *cls;
    void *state;
    sy_scene *scene;
    uint32_t consumer;
    uint32_t root;
    sy_params params;
    double last_sync_seconds, last_render_seconds;
};

sy_result sy_context_create(sy_scene *scene, const char *backend, const sy_params *params, uint32_t root_node_id,
                            sy_context **out, sy_error *err)
{
    *out = NULL;
    const sy_mediator_class *cls = sy_mediator_require(backend, err);
    if (!cls) return SY_ERR_NOT_FOUND;
    sy_result r = sy_mediator_class_check_params(cls, params, err);
    if (r != SY_OK) return r;
    sy_context *c = calloc(1, sizeof *c);
    if (!c) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "context: out of memory");
    c->refs = 1;
    c->cls = cls;
    c->scene = scene;
    c->root = root_node_id;
    if (params) c->params = *params;
    sy_mediator_create_args args = {root_node_id, &c->params, cls->user};
    r = cls->create(&args, &c->state, err);
    if (r == SY_OK) r = sy_scene_consumer_add(scene, &c->consumer, err);
    if (r != SY_OK) {
        if (c->state) cls->destroy(c->state);
        free(c);
        return r;
    }
    *out = c;
    return SY_OK;
}

sy_context *sy_context_retain(sy_context *c)
{
    if (c) c->refs++;
    return c;
}

void sy_context_release(sy_context *c)
{
    if (!c || --c->refs > 0) return;
    sy_scene_consumer_remove(c->scene, c->consumer);
    c->cls->destroy(c->state);
    free(c);
}

sy_result sy_context_sync(sy_context *c, sy_error *err)
{
    double t0 = sy_time_now();
    sy_changes *ch = NULL;
    sy_result r = sy_scene_consumer_pull(c->scene, c->consumer, &ch, err);
    if (r == SY_OK && sy_changes_count(ch)) {
        r = c->cls->sync(c->state, ch, err);
        if (r != SY_OK) sy_error_prefix(err, "%s sync", c->cls->name);
    }
    sy_changes_release(ch);
    c->last_sync_seconds = sy_time_now() - t0;
    return r;
}

sy_result sy_clip_planes_check(const float (*planes)[4], uint32_t count, sy_error *err)
{
    if (count > SY_CLIP_PLANES_MAX)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%u section planes: at most %d", (unsigned)count,
                            SY_CLIP_PLANES_MAX);
    if (count && !planes) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%u section planes but none given", (unsigned)count);
    for (uint32_t i = 0; i < count; ++i) {
        const float *q = planes[i];
        for (int k = 0; k < 4; ++k)
            if (!sy_coords_in_range(&q[k], 1))
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                                    "section plane %u (%g, %g, %g, %g): %c = %g is not finite or beyond %g", (unsigned)i,
                                    (double)q[0], (double)q[1], (double)q[2], (double)q[3], "abcd"[k], (double)q[k],
                                    (double)SY_COORD_MAX);
        if (q[0] == 0.0f && q[1] == 0.0f && q[2] == 0.0f)
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                                "section plane %u (%g, %g, %g, %g): the normal (a, b, c) is zero", (unsigned)i,
                                (double)q[0], (double)q[1], (double)q[2], (double)q[3]);
    }
    return SY_OK;
}

sy_result sy_clip_cap_check(const float rgb[3], sy_error *err)
{
    if (!rgb) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "section cap colour: none given");
    for (int k = 0; k < 3; ++k)
        if (!(rgb[k] >= 0.0f && rgb[k] <= 1.0f)) /* NaN fails both */
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                                "section cap colour (%g, %g, %g): %c = %g is not a colour channel in [0, 1]",
                                (double)rgb[0], (double)rgb[1], (double)rgb[2], "rgb"[k], (double)rgb[k]);
    return SY_OK;
}

/* A view with section planes needs SY_CAP_CLIP of the context's class. */
static sy_result clip_supported(const sy_context *c, const sy_camera_view *v, sy_error *err)
{
    if (v->clip_count && !(sy_context_caps(c) & SY_CAP_CLIP))
        return sy_error_set(err, SY_ERR_UNSUPPORTED, "back-end %s cannot cut with section planes (no SY_CAP_CLIP)",
                            c->cls->name);
    return SY_OK;
}

sy_result sy_camera_view_check(const sy_camera_view *v, sy_error *err)
{
    const float *m = v->camera_to_world.m;
    if (!sy_coords_in_range(m, 16))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                            "camera at (%g %g %g) is beyond the coordinate range (at most %g in size)", (double)m[12],
                            (double)m[13], (double)m[14], (double)SY_COORD_MAX);
    for (int i = 0; i < 4; ++i)
        if (!isfinite(v->window[i]) || (v->projection == SY_PROJECTION_ORTHOGRAPHIC && !sy_coords_in_range(&v->window[i], 1)))
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "camera window[%d] = %g is not finite or beyond %g", i,
                                (double)v->window[i], (double)SY_COORD_MAX);
    if (!isfinite(v->znear) || !isfinite(v->zfar))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "camera clip range %g..%g is not finite", (double)v->znear,
                            (double)v->zfar);
    if (v->clip_cap && sy_clip_cap_check(v->clip_cap_color, err) != SY_OK) return SY_ERR_INVALID_ARGUMENT;
    return sy_clip_planes_check((const float(*)[4])v->clip_planes, v->clip_count, err);
}

sy_result sy_context_render(sy_context *c, const sy_render_request *req, sy_layer *layer, sy_error *err)
{
    sy_result rc = sy_camera_view_check(&req->camera, err);
    if (rc == SY_OK) rc = clip_supported(c, &req->camera, err);
    if (rc != SY_OK) {
        sy_error_prefix(err, "%s render", c->cls->name);
        return rc;
    }
    if (req->rect_w != layer->width || req->rect_h != layer->height || req->rect_w == 0 || req->rect_h == 0 ||
        req->rect_x > req->full_width || req->rect_w > req->full_width - req->rect_x ||
        req->rect_y > req->full_height || req->rect_h > req->full_height - req->rect_y)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                            "render: rectangle %ux%u+%u+%u does not fit the image %ux%u or the layer %ux%u", req->rect_w,
                            req->rect_h, req->rect_x, req->rect_y, req->full_width, req->full_height, layer->width,
                            layer->height);
    double t0 = sy_time_now();
    sy_result r = c->cls->render(c->state, req, layer, err);
    if (r != SY_OK) sy_error_prefix(err, "%s render", c->cls->name);
    c->last_render_seconds = sy_time_now() - t0;
    return r;
}

const sy_mediator_class *sy_context_class(const sy_context *c) { return c->cls; }
void *sy_context_state(const sy_context *c) { return c->state; }

void sy_context_restart(sy_context *c)
{
    if (c && c->cls->restart) c->cls->restart(c->state);
}

static sy_result motion_unsupported(const sy_context *c, sy_error *err)
{
    return sy_error_set(err, SY_ERR_UNSUPPORTED, "back-end '%s' has no motion blur in one render (SY_CAP_MOTION)",
                        c->cls->name);
}

sy_result sy_context_motion_begin(sy_context *c, uint32_t time_samples, sy_error *err)
{
    if (!(sy_context_caps(c) & SY_CAP_MOTION) || !c->cls->motion) return motion_unsupported(c, err);
    sy_result r = sy_context_sync(c, err);
    if (r == SY_OK) r = c->cls->motion(c->state, SY_MOTION_BEGIN, time_samples, NULL, err);
    if (r != SY_OK) sy_context_motion_end(c);
    return r;
}

sy_result sy_context_motion_begin_steps(sy_context *c, uint32_t time_samples, uint32_t steps, sy_error *err)
{
    if (steps < 2u || steps > SY_MOTION_STEPS_MAX)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "motion: %u time steps (2 .. %u)", steps, SY_MOTION_STEPS_MAX);
    sy_result r = sy_context_motion_begin(c, time_samples, err);
    if (r == SY_OK && steps > 2u) {
        r = c->cls->motion(c->state, SY_MOTION_STEPS, steps, NULL, err);
        if (r != SY_OK) sy_context_motion_end(c);
    }
    return r;
}

sy_result sy_context_motion_step(sy_context *c, sy_error *err)
{
    if (!(sy_context_caps(c) & SY_CAP_MOTION) || !c->cls->motion) return motion_unsupported(c, err);
    sy_result r = sy_context_sync(c, err);
    if (r == SY_OK) r = c->cls->motion(c->state, SY_MOTION_STEP, 0, NULL, err);
    if (r != SY_OK) sy_context_motion_end(c);
    return r;
}

sy_result sy_context_motion_open(sy_context *c, bool *native, sy_error *err)
{
    bool nat = false;
    if (native) *native = false;
    if (!(sy_context_caps(c) & SY_CAP_MOTION) || !c->cls->motion) return motion_unsupported(c, err);
    sy_result r = sy_context_sync(c, err);
    if (r == SY_OK) r = c->cls->motion(c->state, SY_MOTION_OPENED, 0, &nat, err);
    if (r != SY_OK) sy_context_motion_end(c);
    else if (native) *native = nat;
    return r;
}

sy_result sy_context_motion_camera(sy_context *c, const sy_camera_view *open, uint32_t steps,
                                  const sy_camera_view *later, sy_error *err)
{
    if (!(sy_context_caps(c) & SY_CAP_MOTION) || !c->cls->motion || !c->cls->motion_camera)
        return sy_error_set(err, SY_ERR_UNSUPPORTED, "back-end '%s' does not interpolate a moving camera over the shutter",
                            c->cls->name);
    if (steps < 2u || steps > SY_MOTION_STEPS_MAX)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "motion camera: %u steps (2 .. %u)", steps, SY_MOTION_STEPS_MAX);
    return c->cls->motion_camera(c->state, open, steps, later, err);
}

void sy_context_motion_end(sy_context *c)
{
    sy_error ignore = {0};
    if (c && c->cls->motion && (sy_context_caps(c) & SY_CAP_MOTION))
        (void)c->cls->motion(c->state, SY_MOTION_END, 0, NULL, &ignore);
}

void sy_context_stats(const sy_context *c, sy_mediator_stats *out)
{
    memset(out, 0, sizeof *out);
    if (c->cls->stats) c->cls->stats(c->state, out);
    out->last_sync_seconds = c->last_sync_seconds;
    out->last_render_seconds = c->last_render_seconds;
}

/* >>pool */
struct sy_context_pool {
    sy_context **items;
    uint32_t count, capacity;
};

sy_result sy_context_pool_create(sy_context_pool **out, sy_error *err)
{
    *out = calloc(1, sizeof **out);
    return *out ? SY_OK : sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "context pool: out of memory");
}

void sy_context_pool_destroy(sy_context_pool *p)
{
    if (!p) return;
    for (uint32_t i = 0; i < p->count; ++i) sy_context_release(p->items[i]);
    free(p->items);
    free(p);
}

sy_result sy_context_pool_get(sy_context_pool *p, sy_scene *scene, const char *backend, const sy_params *params,
                              uint32_t root_node_id, sy_context **out, sy_error *err)
{
    static const sy_params empty;
    if (!params) params = &empty;
    for (uint32_t i = 0; i < p->count; ++i) {
        sy_context *c = p->items[i];
        if (c->scene == scene && c->root == root_node_id && strcmp(c->cls->name, backend) == 0 &&
            sy_params_equal(&c->params, params)) {
            *out = c;
            return SY_OK;
        }
    }
    if (p->count == p->capacity) {
        uint32_t nc = p->capacity ? p->capacity * 2 : 4;
        sy_context **ni = realloc(p->items, sizeof *ni * nc);
        if (!ni) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "context pool: out of memory");
        p->items = ni;
        p->capacity = nc;
    }
    sy_result r = sy_context_create(scene, backend, params, root_node_id, out, err);
    if (r == SY_OK) p->items[p->count++] = *out;
    return r;
}

uint32_t sy_context_pool_size(const sy_context_pool *p) { return p->count; }

uint32_t sy_mediator_class_caps(const sy_mediator_class *cls, const sy_params *params)
{
    sy_params none = {0};
    return cls->caps_of ? cls->caps_of(params ? params : &none, cls->user) : cls->caps;
}

uint32_t sy_context_caps(const sy_context *c) { return sy_mediator_class_caps(c->cls, &c->params); }

void sy_aovs_free(sy_aovs *a)
{
    if (!a) return;
    for (uint32_t i = 0; i < a->count && i < SY_AOVS_MAX; ++i) free(a->planes[i].data);
    memset(a, 0, sizeof *a);
}

sy_result sy_context_aovs(sy_context *c, sy_aovs *out, sy_error *err)
{
    memset(out, 0, sizeof *out);
    if (!(sy_context_caps(c) & SY_CAP_AOVS) || !c->cls->aovs)
        return sy_error_set(err, SY_ERR_UNSUPPORTED, "back-end %s keeps no feature buffers (AOVs)", c->cls->name);
    return c->cls->aovs(c->state, out, err);
}

sy_result sy_context_set_filter(sy_context *c, const char *name, const sy_params *opts, sy_error *err)
{
    if (!(sy_context_caps(c) & SY_CAP_FILTERS) || !c->cls->set_filter)
        return sy_error_set(err, SY_ERR_UNSUPPORTED, "back-end %s has no display filters", c->cls->name);
    char owner[64];
    snprintf(owner, sizeof owner, "back-end '%s'", c->cls->name);
    sy_result r = sy_params_check(&c->cls->param_table, opts, SY_PARAM_LIVE, owner, NULL, err);
    return r != SY_OK ? r : c->cls->set_filter(c->state, name, opts, err);
}

void sy_context_filter_info(const sy_context *c, sy_filter_info *out)
{
    memset(out, 0, sizeof *out);
    snprintf(out->name, sizeof out->name, "none");
    if ((sy_context_caps(c) & SY_CAP_FILTERS) && c->cls->filter_info) c->cls->filter_info(c->state, out);
}

sy_result sy_context_coverage(sy_context *c, const sy_camera_view *view, uint32_t width, uint32_t height,
                              sy_coverage_entry **entries_out, uint32_t *count_out, sy_error *err)
{
    *entries_out = NULL;
    *count_out = 0;
    if (!(sy_context_caps(c) & SY_CAP_COVERAGE) || !c->cls->coverage)
        return sy_error_set(err, SY_ERR_UNSUPPORTED, "back-end %s counts no per-node coverage", c->cls->name);
    sy_result r = sy_camera_view_check(view, err);
    if (r == SY_OK) r = clip_supported(c, view, err);
    if (r != SY_OK) return r;
    return c->cls->coverage(c->state, view, width, height, entries_out, count_out, err);
}

sy_result sy_context_pick(sy_context *c, const sy_camera_view *view, uint32_t width, uint32_t height, uint32_t x,
                          uint32_t y, sy_pick_result *out, sy_error *err)
{
    out->hit = false;
    out->node_id = out->placement = out->mesh_id = out->primitive = out->triangle = out->material_id = 0;
    memset(out->barycentrics, 0, sizeof out->barycentrics);
    memset(out->position, 0, sizeof out->position);
    memset(out->normal, 0, sizeof out->normal);
    out->distance = out->depth = 0.0f;
    if (!(sy_context_caps(c) & SY_CAP_PICK) || !c->cls->pick)
        return sy_error_set(err, SY_ERR_UNSUPPORTED, "back-end %s cannot pick (no SY_CAP_PICK)", c->cls->name);
    if (width == 0 || height == 0 || x >= width || y >= height)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "pick: pixel (%u, %u) is outside the %ux%u image", x, y,
                            width, height);
    sy_result r = sy_camera_view_check(view, err);
    if (r == SY_OK) r = clip_supported(c, view, err);
    if (r != SY_OK) return r;
    r = c->cls->pick(c->state, view, width, height, x, y, out, err);
    if (r != SY_OK || !out->hit) { /* a miss (or a failure) answers nothing but "no hit" */
        uint32_t vp = out->viewport, eye = out->eye, px = out->pixel_x, py = out->pixel_y;
        memset(out, 0, sizeof *out);
        out->viewport = vp, out->eye = eye, out->pixel_x = px, out->pixel_y = py;
    }
    return r;
}
