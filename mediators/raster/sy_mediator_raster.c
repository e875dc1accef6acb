/* sy_mediator_raster.c — core scene -> OpenGL rasterizer adapter (see sy_mediator_raster.h).
 *
 * Sections: >>mirror callbacks (the scene mirror is mediators/sy_mirror)  >>sync  >>render
 * >>class */
#include "sy_mediator_raster.h"

#include "sy_gl.h"
#include "sy_mirror.h"

#include <stdio.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define ERRLEN 256

/* The scene mirror (textures, materials, meshes, lights, backgrounds, nodes and placements) is
 * mediators/sy_mirror; this adapter turns its callbacks into OpenGL back-end calls. */
typedef struct raster_state {
    sy_gl_device *dev;
    sy_mirror *mirror;
    sy_mediator_raster_counters counters;
    uint64_t frames_rendered;
    double last_sync_seconds, last_render_seconds;
} raster_state;

static sy_result gl_fail(sy_error *err, sy_gl_result r, const char *what, const char *msg)
{
    return sy_error_set(err, r == SY_GL_ERROR_OUT_OF_MEMORY ? SY_ERR_OUT_OF_MEMORY : SY_ERR_BACKEND, "raster: %s: %s", what, msg);
}

/* >>mirror callbacks */
static sy_gl_texture_ref texref(const raster_state *st, const sy_texture_ref *r)
{
    sy_gl_texture_ref o = {{sy_mirror_texture_handle(st->mirror, r->texture.id)}, r->texcoord, false, {0}};
    o.transformed = sy_texture_ref_matrix(r, o.transform);
    return o;
}

static sy_result cb_material(void *user, const sy_mirror_material_args *a, sy_error *err)
{
    raster_state *st = user;
    const sy_material_data *m = a->data;
    char e[ERRLEN];
    sy_gl_material_desc d;
    sy_gl_material_desc_init(&d);
    memcpy(d.base_color, m->base_color, sizeof d.base_color);
    d.base_color_texture = texref(st, &m->base_color_texture);
    d.metallic = m->metallic;
    d.roughness = m->roughness;
    d.metallic_roughness_texture = texref(st, &m->metallic_roughness_texture);
    for (int i = 0; i < 3; ++i) d.emissive[i] = m->emissive[i] * m->emissive_strength;
    d.emissive_texture = texref(st, &m->emissive_texture);
    d.normal_texture = texref(st, &m->normal_texture);
    d.normal_scale = m->normal_texture.scale;
    d.occlusion_texture = texref(st, &m->occlusion_texture);
    d.occlusion_strength = m->occlusion_texture.scale;
    d.transmission = m->transmission;
    d.ior = m->ior >= 1.0f ? m->ior : 1.5f;
    d.alpha_mode = (sy_gl_alpha_mode)m->alpha_mode;
    d.alpha_cutoff = m->alpha_cutoff;
    d.double_sided = m->double_sided != 0;
    d.unlit = m->unlit != 0;
    sy_gl_material h = {*a->handle};
    sy_gl_result r = h.id ? sy_gl_material_update(st->dev, h, &d, e, sizeof e)
                          : sy_gl_material_create(st->dev, &d, &h, e, sizeof e);
    *a->handle = h.id;
    return r == SY_GL_OK ? SY_OK : gl_fail(err, r, "material", e);
}

static sy_result cb_texture(void *user, const sy_mirror_texture_args *a, sy_error *err)
{
    raster_state *st = user;
    char e[ERRLEN];
    sy_gl_texture_desc d = {
        .width = a->info->width,
        .height = a->info->height,
        .channels = a->info->channels,
        .format = a->info->format == SY_PIXEL_U8_SRGB     ? SY_GL_TEXEL_UNORM8_SRGB
                  : a->info->format == SY_PIXEL_U8_LINEAR ? SY_GL_TEXEL_UNORM8
                                                          : SY_GL_TEXEL_FLOAT32,
        .pixels = a->pixels,
        .wrap_s = (sy_gl_wrap)a->sampler->wrap_s,
        .wrap_t = (sy_gl_wrap)a->sampler->wrap_t,
        .nearest = a->sampler->mag_filter == SY_FILTER_NEAREST,
    };
    sy_gl_texture h = {0};
    sy_gl_result r = sy_gl_texture_create(st->dev, &d, &h, e, sizeof e);
    *a->handle = h.id;
    return r == SY_GL_OK ? SY_OK : gl_fail(err, r, "texture", e);
}

static sy_result cb_primitive(void *user, const sy_mirror_primitive_args *a, sy_error *err)
{
    raster_state *st = user;
    char e[ERRLEN];
    const sy_primitive *p = a->primitive;
    sy_gl_mesh_desc d = {
        .positions = sy_blob_data(p->positions),
        .normals = sy_blob_data(p->normals),
        .uv = {sy_blob_data(p->texcoords0), sy_blob_data(p->texcoords1)},
        .colors = sy_blob_data(p->colors),
        .indices = sy_blob_data(p->indices),
        .vertex_count = sy_primitive_vertex_count(p),
        .triangle_count = sy_primitive_triangle_count(p),
    };
    sy_gl_mesh h = {0};
    sy_gl_result r = sy_gl_mesh_create(st->dev, &d, &h, e, sizeof e);
    *a->handle = h.id;
    return r == SY_GL_OK ? SY_OK : gl_fail(err, r, "mesh primitive", e);
}

static sy_result cb_instance(void *user, const sy_mirror_instance_args *a, sy_error *err)
{
    raster_state *st = user;
    char e[ERRLEN];
    sy_gl_instance h = {*a->handle};
    sy_gl_result r;
    if (!h.id) { /* the rasterizer draws everything per instance: a->baked does not apply */
        sy_gl_instance_desc d = {.mesh = {a->mesh}, .material = {a->material}, .hidden = !a->visible};
        memcpy(d.transform, a->world->m, sizeof d.transform);
        r = sy_gl_instance_create(st->dev, &d, &h, e, sizeof e);
        *a->handle = h.id;
        return r == SY_GL_OK ? SY_OK : gl_fail(err, r, "instance", e);
    }
    r = sy_gl_instance_set_transform(st->dev, h, a->world->m, e, sizeof e);
    if (r == SY_GL_OK) r = sy_gl_instance_set_visible(st->dev, h, a->visible);
    return r == SY_GL_OK ? SY_OK : gl_fail(err, r, "instance transform", e);
}

static sy_result cb_light(void *user, const sy_mirror_light_args *a, sy_error *err)
{
    raster_state *st = user;
    char e[ERRLEN];
    const sy_light_data *l = a->light;
    sy_gl_light_desc d;
    memset(&d, 0, sizeof d);
    d.type = l->type == SY_LIGHT_SPOT ? SY_GL_LIGHT_SPOT : l->type == SY_LIGHT_DIRECTIONAL ? SY_GL_LIGHT_DIRECTIONAL
                                                                                         : SY_GL_LIGHT_POINT;
    memcpy(d.color, l->color, sizeof d.color);
    d.intensity = l->intensity;
    d.range = l->range;
    d.inner_cone_angle = l->inner_cone;
    d.outer_cone_angle = l->outer_cone;
    memcpy(d.position, a->position, sizeof d.position);
    memcpy(d.direction, a->direction, sizeof d.direction);
    sy_gl_light h = {*a->handle};
    sy_gl_result r = h.id ? sy_gl_light_update(st->dev, h, &d, e, sizeof e) : sy_gl_light_create(st->dev, &d, &h, e, sizeof e);
    *a->handle = h.id;
    return r == SY_GL_OK ? SY_OK : gl_fail(err, r, "light", e);
}

static void cb_release(void *user, const sy_mirror_release_args *a)
{
    raster_state *st = user;
    switch (a->kind) {
    case SY_MIRROR_TEXTURE: sy_gl_texture_destroy(st->dev, (sy_gl_texture){a->handle}); break;
    case SY_MIRROR_MATERIAL: sy_gl_material_destroy(st->dev, (sy_gl_material){a->handle}); break;
    case SY_MIRROR_PRIMITIVE: sy_gl_mesh_destroy(st->dev, (sy_gl_mesh){a->handle}); break;
    case SY_MIRROR_INSTANCE: sy_gl_instance_destroy(st->dev, (sy_gl_instance){a->handle}); break;
    case SY_MIRROR_LIGHT: sy_gl_light_destroy(st->dev, (sy_gl_light){a->handle}); break;
    }
}

static const sy_mirror_callbacks raster_mirror_callbacks = {
    .texture_set = cb_texture,
    .material_set = cb_material,
    .primitive_set = cb_primitive,
    .instance_set = cb_instance,
    .light_set = cb_light,
    .release = cb_release,
};

/* >>sync */
static sy_result raster_sync(void *state, const sy_changes *changes, sy_error *err)
{
    raster_state *st = state;
    double t_sync = sy_time_now();
    sy_mirror_sync_stats ms;
    sy_result r = sy_mirror_sync(st->mirror, changes, &ms, err);
    st->counters.last_sync_placements = ms.placements;
    st->counters.last_sync_entries = ms.entries;
    sy_gl_stats gs;
    sy_gl_device_stats(st->dev, &gs);
    st->counters.meshes = gs.meshes;
    st->counters.instances = gs.instances;
    st->counters.materials = gs.materials;
    st->counters.textures = gs.textures;
    st->counters.lights = gs.lights;
    st->last_sync_seconds = sy_time_now() - t_sync;
    return r;
}

/* >>render */
static void camera_of(const sy_camera_view *v, sy_gl_camera *cam)
{
    memcpy(cam->camera_to_world, v->camera_to_world.m, sizeof cam->camera_to_world);
    cam->orthographic = v->projection == SY_PROJECTION_ORTHOGRAPHIC;
    memcpy(cam->window, v->window, sizeof cam->window);
    cam->near_clip = v->znear;
    cam->far_clip = v->zfar;
}

static void apply_background(raster_state *st, uint32_t background_id)
{
    const sy_mirror_background *b = sy_mirror_background_get(st->mirror, background_id);
    sy_gl_set_background(st->dev, b && b->color[3] > 0.0f, b ? b->color : NULL);
}

static sy_result check_layer(const sy_render_request *req, const sy_layer *layer, sy_error *err)
{
    if (layer->width != req->rect_w || layer->height != req->rect_h)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "raster: layer %ux%u does not match the request rectangle %ux%u",
                            layer->width, layer->height, req->rect_w, req->rect_h);
    return SY_OK;
}

static sy_result raster_render(void *state, const sy_render_request *req, sy_layer *layer, sy_error *err)
{
    raster_state *st = state;
    char e[ERRLEN];
    sy_result rr = check_layer(req, layer, err);
    if (rr != SY_OK) return rr;
    double t0 = sy_time_now();
    apply_background(st, req->background_id);
    sy_gl_camera cam;
    camera_of(&req->camera, &cam);
    sy_gl_render_desc d = {req->full_width, req->full_height, req->rect_x, req->rect_y, req->rect_w, req->rect_h};
    sy_gl_result r = sy_gl_render(st->dev, &cam, &d, layer->rgba, layer->depth, e, sizeof e);
    if (r != SY_GL_OK) return gl_fail(err, r, "render", e);
    if (req->progress) {
        sy_progress p = {1, 1};
        req->progress(req->progress_user, &p);
    }
    st->frames_rendered++;
    st->last_render_seconds = sy_time_now() - t0;
    return SY_OK;
}

sy_result sy_mediator_raster_render_floor(void *state, const sy_render_request *req, sy_layer *layer, sy_error *err)
{
    raster_state *st = state;
    char e[ERRLEN];
    sy_result rr = check_layer(req, layer, err);
    if (rr != SY_OK) return rr;
    apply_background(st, req->background_id);
    sy_gl_camera cam;
    camera_of(&req->camera, &cam);
    sy_gl_render_desc d = {req->full_width, req->full_height, req->rect_x, req->rect_y, req->rect_w, req->rect_h};
    sy_gl_result r = sy_gl_render_floor(st->dev, &cam, &d, layer->rgba, e, sizeof e);
    return r == SY_GL_OK ? SY_OK : gl_fail(err, r, "floor render", e);
}

/* >>class */
static void raster_destroy(void *state)
{
    raster_state *st = state;
    if (!st) return;
    sy_mirror_destroy(st->mirror); /* releases instances, lights and meshes while the device lives */
    sy_gl_device_destroy(st->dev);
    free(st);
}

static void log_warning(void *user, const char *msg)
{
    raster_state *st = user;
    st->counters.warnings++;
    snprintf(st->counters.last_warning, sizeof st->counters.last_warning, "%s", msg);
    fprintf(stderr, "sy: warning: %s\n", msg);
}

static sy_result raster_create(const sy_mediator_create_args *args, void **state_out, sy_error *err)
{
    *state_out = NULL;
    long msaa, shadow, max_tex, ww, wh;
    sy_result r;
    sy_gl_provider provider = SY_GL_PROVIDER_OSMESA;
    const char *gl = sy_params_get(args->params, "gl");
    if (gl && !sy_gl_provider_parse(gl, &provider))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "raster: parameter gl=%s: expected osmesa, egl or glfw", gl);
    if ((r = sy_params_get_int(args->params, "msaa", 4, 1, 32, &msaa, err)) ||
        (r = sy_params_get_int(args->params, "shadow_map_size", 2048, 16, 16384, &shadow, err)) ||
        (r = sy_params_get_int(args->params, "max_texture_size", 0, 0, 1 << 20, &max_tex, err)) ||
        (r = sy_params_get_int(args->params, "window_width", 640, 1, 16384, &ww, err)) ||
        (r = sy_params_get_int(args->params, "window_height", 480, 1, 16384, &wh, err)))
        return r;
    raster_state *st = calloc(1, sizeof *st);
    if (!st) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "raster mediator: out of memory");
    char e[ERRLEN];
    sy_gl_device_desc dd = {.provider = provider,
                            .msaa = (uint32_t)msaa,
                            .shadow_map_size = (uint32_t)shadow,
                            .max_texture_size = (uint32_t)max_tex,
                            .window_width = (uint32_t)ww,
                            .window_height = (uint32_t)wh,
                            .log = log_warning,
                            .log_user = st};
    sy_gl_result gr = sy_gl_device_create(&dd, &st->dev, e, sizeof e);
    if (gr != SY_GL_OK) {
        free(st);
        return sy_error_set(err, gr == SY_GL_ERROR_NO_CONTEXT ? SY_ERR_UNSUPPORTED : SY_ERR_BACKEND, "raster: %s", e);
    }
    sy_mirror_desc md = {"raster mediator", args->root_node_id, &raster_mirror_callbacks, st};
    if ((r = sy_mirror_create(&md, &st->mirror, err)) != SY_OK) {
        sy_gl_device_destroy(st->dev);
        free(st);
        return r;
    }
    *state_out = st;
    return SY_OK;
}

static void raster_stats(void *state, sy_mediator_stats *out)
{
    raster_state *st = state;
    out->samples = st->frames_rendered ? 1 : 0;
    out->last_sync_seconds = st->last_sync_seconds;
    out->last_render_seconds = st->last_render_seconds;
}

static const sy_mediator_class raster_class = {
    .name = "raster",
    .caps = SY_CAP_DEPTH | SY_CAP_TILES,
    .create = raster_create,
    .destroy = raster_destroy,
    .sync = raster_sync,
    .render = raster_render,
    .stats = raster_stats,
};

const sy_mediator_class *sy_mediator_raster_class(void) { return &raster_class; }

void sy_mediator_raster_counters_get(void *state, sy_mediator_raster_counters *out)
{
    raster_state *st = state;
    *out = st->counters;
    sy_gl_stats gs;
    sy_gl_device_stats(st->dev, &gs);
    out->vertex_buffer_uploads = gs.frame.vertex_buffer_uploads;
    out->vertex_bytes = gs.frame.vertex_bytes;
    out->uniform_buffer_uploads = gs.frame.uniform_buffer_uploads;
    out->texture_uploads = gs.frame.texture_uploads;
    out->model_matrix_updates = gs.frame.model_matrix_updates;
    out->total_vertex_buffer_uploads = gs.total.vertex_buffer_uploads;
    out->total_texture_uploads = gs.total.texture_uploads;
    out->msaa_samples = gs.msaa_samples;
    out->shadow_maps = gs.shadow_maps;
    out->draw_calls = gs.draw_calls;
    out->triangles_drawn = gs.triangles_drawn;
}

const char *sy_mediator_raster_info(void *state) { return sy_gl_device_info(((raster_state *)state)->dev); }
