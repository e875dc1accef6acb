/* sy_mediator_raster.c — core scene -> OpenGL rasterizer adapter (see sy_mediator_raster.h).
 *
 * Besides the mirror callbacks it translates the resolved look (sy_mirror_look) into the device's
 * background and environment light, and the emissive meshes into area lights:
 *  - it keeps, per back-end mesh, references to the primitive's position and index blobs (no copy:
 *    blobs are immutable and shared with the scene), per material its emission, and per instance
 *    its mesh, material and world matrix; when something emissive changes, the next render
 *    rebuilds the list of emissive triangles in world space (front face = counter-clockwise after
 *    the world transform; double-sided emitters emit from both faces), merging two consecutive
 *    coplanar triangles that share an edge into a convex quad (the Cornell ceiling panel is one
 *    quad);
 *  - textured emission: each triangle lights with the factor x the mean of its own part of the
 *    texture (block means kept per texture, TEX_BLOCKS a side at most, sampled at points spread
 *    over the triangle's texture coordinates), so a texture that glows in a few places (ToyCar's
 *    lamps) makes lights there and nowhere else; triangles whose part is black are no lights;
 *  - at most SY_GL_MAX_AREA_LIGHTS polygons are lights: beyond that the most powerful are kept and
 *    their radiance is scaled so that the total emitted power (radiance x area x sides) is kept
 *    (a big emissive mesh lights like a few of its polygons, with its total power).
 *
 * Sections: >>tables  >>mirror callbacks (the scene mirror is mediators/sy_mirror)  >>sync
 * >>look  >>area lights  >>render  >>class */
#include "sy_mediator_raster.h"

#include "sy_backend_status.h"
#include "sy_gl.h"
#include "sy_highlight.h"
#include "sy_log.h"
#include "sy_look.h"
#include "sy_mirror.h"
#include "sy_mirror_map.h"
#include "sy_pick_ray.h"

#include <stdio.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>


/* The scene mirror (textures, materials, meshes, lights, backgrounds, nodes and placements) is
 * mediators/sy_mirror; this adapter turns its callbacks into OpenGL back-end calls. */
/* >>tables: the records kept per back-end object or core id (maps of mediators/sy_mirror_map.h) */
typedef struct emesh { /* per back-end mesh: the primitive's blobs (references) */
    sy_blob *positions, *indices, *uv[2];
    uint32_t vertex_count, triangle_count;
} emesh;
typedef struct emat { /* per back-end material */
    float emission[3]; /* radiance: factor x strength (x the emissive texture's mean) */
    bool double_sided;
    float factor[3];   /* factor x strength: what a textured emitter's triangles scale their block means by */
    sy_mirror_flat_texture_ref tex; /* the emissive texture (id 0: none) */
} emat;
typedef struct einst { /* per back-end instance */
    uint32_t node; /* core node id (picks) */
    uint32_t mesh, material;
    float world[16];
    bool visible;
    bool selected; /* highlighted (sy_highlight.h) */
} einst;
typedef struct ealb { /* per back-end material: diffuse-ish albedo (base x base texture mean) */
    float albedo[3];
} ealb;
typedef struct etex { /* per core texture id: mean linear RGB, block means (malloc'd) */
    float mean[3];
    float *blocks; /* bw x bh x RGB (sy_mirror_flat_texture_means); NULL for an empty texture */
    uint32_t bw, bh, wrap_s, wrap_t;
} etex;
/* The block means' side at most: a 1024^2 emissive texture in blocks of 16^2 texels (48 KiB). */
#define TEX_BLOCKS 64u

typedef struct raster_state {
    sy_gl_device *dev;
    sy_mirror *mirror;
    sy_mediator_raster_counters counters;
    uint64_t frames_rendered;
    double last_sync_seconds, last_render_seconds;
    /* look */
    bool look_valid;
    sy_look look;
    uint32_t env_handle, bg_handle; /* as applied */
    sy_gl_texture studio, gradient;
    /* emissive meshes */
    sy_mirror_map meshes, mats, insts, texs, albs;
    bool areas_dirty;
    uint32_t selected_count; /* instances with einst.selected: a frame is highlighted while any is */
    uint32_t area_count;
    bool warned_area_cap;
    bool indirect; /* "indirect" parameter: the emitters' indirect light estimate (below); 0 = direct light only */
    char gl_msg[SY_ERROR_MESSAGE_MAX]; /* the message of the device's last failed call (gl_error) */
} raster_state;

/* Every code the device returns has core's number (the cast in sy_backend_fail). */
SY_BACKEND_SAME_CODE(SY_GL_ERROR_INVALID_ARGUMENT, SY_ERR_INVALID_ARGUMENT);
SY_BACKEND_SAME_CODE(SY_GL_ERROR_INVALID_HANDLE, SY_ERR_INVALID_HANDLE);
SY_BACKEND_SAME_CODE(SY_GL_ERROR_OUT_OF_MEMORY, SY_ERR_OUT_OF_MEMORY);
SY_BACKEND_SAME_CODE(SY_GL_ERROR_NO_CONTEXT, SY_ERR_UNSUPPORTED);
SY_BACKEND_SAME_CODE(SY_GL_ERROR_LIMIT, SY_ERR_LIMIT);
SY_BACKEND_SAME_CODE(SY_GL_ERROR_GL, SY_ERR_BACKEND);

/* A failed call on st's device as an sy_error: "raster: WHAT: MSG", MSG being what the device
 * reported through its error callback (gl_error). */
static sy_result gl_fail(const raster_state *st, sy_error *err, sy_gl_result r, const char *what)
{
    return sy_backend_fail(err, (int)r, "raster", what, st->gl_msg);
}

/* The device's error callback: runs on the thread of the call in progress, the only one using the
 * device, before that call returns. */
static void gl_error(void *user, sy_gl_result code, const char *message)
{
    (void)code;
    raster_state *st = user;
    snprintf(st->gl_msg, sizeof st->gl_msg, "%s", message);
}

/* >>mirror callbacks: the flat descriptions (sy_mirror_flat.h) copied into the device's; their
 * enumerations are numbered like the device's, so a cast translates */
SY_MIRROR_FLAT_SAME_NUMBERS(SY_GL);

SY_MIRROR_FLAT_TEXREF_FN(texref, sy_gl_texture_ref)

static sy_result cb_material(void *user, const sy_mirror_material_args *a, sy_error *err)
{
    raster_state *st = user;
    const sy_mirror_flat_material *m = a->flat;
    sy_gl_material_desc d;
    sy_gl_material_desc_init(&d);
    SY_MIRROR_FLAT_MATERIAL_COPY(&d, m, texref);
    memcpy(d.base_color, m->base_color, sizeof d.base_color);
    d.metallic = m->metallic;
    d.roughness = m->roughness;
    memcpy(d.emissive, m->emissive, sizeof d.emissive);
    d.occlusion_texture = texref(&m->occlusion_texture);
    d.occlusion_strength = m->occlusion_strength;
    d.transmission = m->transmission;
    d.alpha_mode = (sy_gl_alpha_mode)m->alpha_mode;
    d.alpha_cutoff = m->alpha_cutoff;
    d.specular = m->specular; /* the extensions (docs/BACKENDS.md, "Material extensions") */
    d.thickness_texture = texref(&m->thickness_texture);
    sy_gl_material h = {*a->handle};
    sy_gl_result r = h.id ? sy_gl_material_update(st->dev, h, &d)
                          : sy_gl_material_create(st->dev, &d, &h);
    *a->handle = h.id;
    if (r != SY_GL_OK) return gl_fail(st, err, r, "material");
    /* albedo for the indirect estimate (area lights) */
    ealb *al = sy_mirror_map_put(&st->albs, h.id);
    if (!al) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "raster: out of memory (material albedo)");
    const etex *bt = m->base_color_texture.id ? sy_mirror_map_get(&st->texs, m->base_color_texture.id) : NULL;
    for (int i = 0; i < 3; ++i) {
        float v = d.base_color[i] * (bt ? bt->mean[i] : 1.0f);
        al->albedo[i] = isfinite(v) ? fminf(fmaxf(v, 0.0f), 1.0f) : 0.0f;
    }
    /* emission as area light: factor x strength (x the emissive texture's mean) */
    emat em;
    memset(&em, 0, sizeof em); /* compared whole (memcmp) */
    em.double_sided = d.double_sided;
    const etex *et = m->emissive_texture.id ? sy_mirror_map_get(&st->texs, m->emissive_texture.id) : NULL;
    for (int i = 0; i < 3; ++i) {
        float v = d.emissive[i] * (m->emissive_texture.id ? (et ? et->mean[i] : 0.0f) : 1.0f);
        em.emission[i] = isfinite(v) && v > 0.0f ? v : 0.0f;
        em.factor[i] = isfinite(d.emissive[i]) && d.emissive[i] > 0.0f ? d.emissive[i] : 0.0f;
    }
    if (et && et->blocks) em.tex = m->emissive_texture;
    emat *old = sy_mirror_map_get(&st->mats, h.id);
    bool was = old && (old->emission[0] > 0 || old->emission[1] > 0 || old->emission[2] > 0);
    bool is = em.emission[0] > 0 || em.emission[1] > 0 || em.emission[2] > 0;
    if (is) {
        emat *slot = sy_mirror_map_put(&st->mats, h.id);
        if (!slot) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "raster: out of memory (emissive materials)");
        if (!was || memcmp(slot, &em, sizeof em)) st->areas_dirty = true;
        *slot = em;
    } else if (was) {
        sy_mirror_map_del(&st->mats, h.id);
        st->areas_dirty = true;
    }
    return SY_OK;
}

static sy_result cb_texture(void *user, const sy_mirror_texture_args *a, sy_error *err)
{
    raster_state *st = user;
    const sy_mirror_flat_texture *f = a->flat;
    sy_gl_texture_desc d = {.width = f->width, .height = f->height, .channels = f->channels,
                            .format = (sy_gl_texel_format)f->format, .pixels = f->pixels, .wrap_s = (sy_gl_wrap)f->wrap_s,
                            .wrap_t = (sy_gl_wrap)f->wrap_t, .nearest = f->nearest};
    sy_gl_texture h = {0};
    sy_gl_result r = sy_gl_texture_create(st->dev, &d, &h);
    *a->handle = h.id;
    if (r != SY_GL_OK) return gl_fail(st, err, r, "texture");
    /* mean linear RGB and block means (for textured emitters as area lights) */
    etex *t = sy_mirror_map_get(&st->texs, a->id);
    if (t) free(t->blocks), t->blocks = NULL, st->areas_dirty = true; /* new pixels: a textured emitter's lights follow */
    else if (!(t = sy_mirror_map_put(&st->texs, a->id)))
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "raster: out of memory (texture means)");
    t->bw = f->width < TEX_BLOCKS ? f->width : TEX_BLOCKS;
    t->bh = f->height < TEX_BLOCKS ? f->height : TEX_BLOCKS;
    t->wrap_s = f->wrap_s, t->wrap_t = f->wrap_t;
    t->blocks = t->bw && t->bh ? malloc(sizeof(float) * 3 * t->bw * t->bh) : NULL; /* none for an empty texture */
    if ((t->bw && t->bh && !t->blocks) || !sy_mirror_flat_texture_means(f, t->bw, t->bh, t->mean, t->blocks))
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "raster: out of memory (texture means)");
    return SY_OK;
}

static sy_result cb_primitive(void *user, const sy_mirror_primitive_args *a, sy_error *err)
{
    raster_state *st = user;
    const sy_primitive *p = a->primitive;
    const sy_mirror_flat_mesh *f = a->flat;
    sy_gl_mesh_desc d = {f->positions, f->normals, {f->uv[0], f->uv[1]}, f->colors, f->indices, f->vertex_count,
                         f->triangle_count, sy_mirror_flat_mesh_closed(f)};
    sy_gl_mesh h = {0};
    sy_gl_result r = sy_gl_mesh_create(st->dev, &d, &h);
    *a->handle = h.id;
    if (r != SY_GL_OK) return gl_fail(st, err, r, "mesh primitive");
    emesh *em = sy_mirror_map_put(&st->meshes, h.id);
    if (!em) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "raster: out of memory (mesh table)");
    em->positions = sy_blob_retain(p->positions);
    em->indices = sy_blob_retain(p->indices);
    em->uv[0] = sy_blob_retain(p->texcoords0);
    em->uv[1] = sy_blob_retain(p->texcoords1);
    em->vertex_count = d.vertex_count;
    em->triangle_count = d.triangle_count;
    return SY_OK;
}

/* A deformed pose of a primitive made by cb_primitive: its vertex buffer re-uploaded in place
 * (sy_gl_mesh_update); the area lights read the new positions. */
static sy_result cb_primitive_update(void *user, const sy_mirror_primitive_args *a, sy_error *err)
{
    raster_state *st = user;
    const sy_mirror_flat_mesh *f = a->flat;
    sy_gl_mesh_desc d = {f->positions, f->normals, {f->uv[0], f->uv[1]}, f->colors, f->indices, f->vertex_count,
                         f->triangle_count, 0 /* not read: the topology stays */};
    sy_gl_result r = sy_gl_mesh_update(st->dev, (sy_gl_mesh){*a->handle}, &d);
    if (r != SY_GL_OK) return gl_fail(st, err, r, "mesh primitive update");
    emesh *em = sy_mirror_map_get(&st->meshes, *a->handle);
    if (em) {
        sy_blob_release(em->positions);
        em->positions = sy_blob_retain(a->primitive->positions);
        sy_blob_release(em->uv[0]); /* a morph may move texture coordinates too */
        em->uv[0] = sy_blob_retain(a->primitive->texcoords0);
    }
    st->areas_dirty = true; /* an emissive deformed mesh moves its area lights */
    return SY_OK;
}

static void emesh_release(emesh *em)
{
    sy_blob_release(em->positions);
    sy_blob_release(em->indices);
    sy_blob_release(em->uv[0]);
    sy_blob_release(em->uv[1]);
}

static bool material_emits(const raster_state *st, uint32_t material) { return sy_mirror_map_get(&st->mats, material) != NULL; }

/* Records the instance for the area-light list; marks it dirty when an emitter changed. */
static sy_result track_instance(raster_state *st, uint32_t handle, const sy_mirror_instance_args *a, sy_error *err)
{
    einst *in = sy_mirror_map_put(&st->insts, handle);
    if (!in) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "raster: out of memory (instance table)");
    if (material_emits(st, a->material) || (in->material && material_emits(st, in->material))) st->areas_dirty = true;
    in->node = a->node;
    if (a->mesh) in->mesh = a->mesh; /* updates (transform, visibility) carry no mesh */
    if (a->mesh) in->material = a->material;
    memcpy(in->world, a->world->m, sizeof in->world);
    in->visible = a->visible;
    if (in->selected != a->selected) st->selected_count += a->selected ? 1u : (uint32_t)-1;
    in->selected = a->selected;
    return SY_OK;
}

static sy_result cb_instance(void *user, const sy_mirror_instance_args *a, sy_error *err)
{
    raster_state *st = user;
    sy_gl_instance h = {*a->handle};
    sy_gl_result r;
    if (!h.id) { /* the rasterizer draws everything per instance: a->baked does not apply */
        sy_gl_instance_desc d = {.mesh = {a->mesh}, .material = {a->material}, .hidden = !a->visible};
        memcpy(d.transform, a->world->m, sizeof d.transform);
        r = sy_gl_instance_create(st->dev, &d, &h);
        *a->handle = h.id;
        if (r != SY_GL_OK) return gl_fail(st, err, r, "instance");
        return track_instance(st, h.id, a, err);
    }
    r = sy_gl_instance_set_transform(st->dev, h, a->world->m);
    if (r == SY_GL_OK) r = sy_gl_instance_set_visible(st->dev, h, a->visible);
    if (r != SY_GL_OK) return gl_fail(st, err, r, "instance transform");
    return track_instance(st, h.id, a, err);
}

static sy_result cb_light(void *user, const sy_mirror_light_args *a, sy_error *err)
{
    raster_state *st = user;
    const sy_mirror_flat_light *l = a->flat;
    sy_gl_light_desc d = {(sy_gl_light_type)l->type, {l->color[0], l->color[1], l->color[2]}, l->intensity,
                          {l->position[0], l->position[1], l->position[2]},
                          {l->direction[0], l->direction[1], l->direction[2]}, l->range, l->inner_cone, l->outer_cone, false};
    sy_gl_light h = {*a->handle};
    sy_gl_result r = h.id ? sy_gl_light_update(st->dev, h, &d) : sy_gl_light_create(st->dev, &d, &h);
    *a->handle = h.id;
    return r == SY_GL_OK ? SY_OK : gl_fail(st, err, r, "light");
}

static void cb_release(void *user, const sy_mirror_release_args *a)
{
    raster_state *st = user;
    switch (a->kind) {
    case SY_MIRROR_TEXTURE: sy_gl_texture_destroy(st->dev, (sy_gl_texture){a->handle}); break;
    case SY_MIRROR_MATERIAL:
        if (sy_mirror_map_get(&st->mats, a->handle)) st->areas_dirty = true;
        sy_mirror_map_del(&st->mats, a->handle);
        sy_mirror_map_del(&st->albs, a->handle);
        sy_gl_material_destroy(st->dev, (sy_gl_material){a->handle});
        break;
    case SY_MIRROR_PRIMITIVE: {
        emesh *em = sy_mirror_map_get(&st->meshes, a->handle);
        if (em) {
            emesh_release(em);
            sy_mirror_map_del(&st->meshes, a->handle);
        }
        sy_gl_mesh_destroy(st->dev, (sy_gl_mesh){a->handle});
        break;
    }
    case SY_MIRROR_INSTANCE: {
        einst *in = sy_mirror_map_get(&st->insts, a->handle);
        if (in && material_emits(st, in->material)) st->areas_dirty = true;
        if (in && in->selected) st->selected_count--;
        sy_mirror_map_del(&st->insts, a->handle);
        sy_gl_instance_destroy(st->dev, (sy_gl_instance){a->handle});
        break;
    }
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
    .primitive_update = cb_primitive_update,
};

/* >>sync */
static sy_result raster_sync(void *state, const sy_changes *changes, sy_error *err)
{
    raster_state *st = state;
    double t_sync = sy_time_now();
    sy_mirror_sync_stats ms;
    sy_result r = sy_mirror_sync(st->mirror, changes, &ms, err);
    SY_MIRROR_SYNC_COUNTERS(st->counters, ms);
    st->counters.last_sync_upload_seconds = ms.update_seconds;
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
    SY_MIRROR_FLAT_VIEW_COPY(cam, v, SY_GL);
    cam->orthographic = v->projection == SY_PROJECTION_ORTHOGRAPHIC;
}

/* >>look: the resolved look -> the device's environment light and background. */
static sy_result float_texture(raster_state *st, uint32_t w, uint32_t h, const float *rgb, sy_gl_texture *out,
                               const char *what, sy_error *err)
{
    sy_gl_texture_desc d = {.width = w, .height = h, .channels = 3, .format = SY_GL_TEXEL_FLOAT32, .pixels = rgb,
                            .wrap_s = SY_GL_WRAP_REPEAT, .wrap_t = SY_GL_WRAP_CLAMP};
    sy_gl_result r = sy_gl_texture_create(st->dev, &d, out);
    return r == SY_GL_OK ? SY_OK : gl_fail(st, err, r, what);
}

static sy_result apply_look(raster_state *st, uint32_t background_id, sy_error *err)
{
    sy_look look;
    sy_mirror_look(st->mirror, background_id, &look);
    uint32_t tex = look.env_texture ? sy_mirror_texture_handle(st->mirror, look.env_texture) : 0;
    if (st->look_valid && sy_look_equal(&look, &st->look) && tex == st->env_handle) return SY_OK;
    sy_result r = SY_OK;
    /* environment light */
    uint32_t env = 0;
    if (look.env == SY_LOOK_ENV_TEXTURE) env = tex;
    else if (look.env == SY_LOOK_ENV_STUDIO) {
        if (!st->studio.id) {
            float *px = malloc(sizeof(float) * 3 * SY_LOOK_STUDIO_WIDTH * SY_LOOK_STUDIO_HEIGHT);
            if (!px) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "raster: out of memory (studio environment)");
            sy_look_studio_pixels(SY_LOOK_STUDIO_WIDTH, SY_LOOK_STUDIO_HEIGHT, px);
            r = float_texture(st, SY_LOOK_STUDIO_WIDTH, SY_LOOK_STUDIO_HEIGHT, px, &st->studio, "studio environment", err);
            free(px);
            if (r != SY_OK) return r;
        }
        env = st->studio.id;
    }
    sy_gl_set_environment(st->dev, (sy_gl_texture){env}, env ? look.env_intensity : 0.0f);
    /* background: camera rays only */
    bool gradient_same = st->look_valid && st->look.background == SY_LOOK_BG_GRADIENT &&
                         !memcmp(&st->look.gradient, &look.gradient, sizeof look.gradient) && st->gradient.id;
    if (look.background == SY_LOOK_BG_GRADIENT && !gradient_same) {
        enum { GW = 4, GH = 256 };
        float px[GW * GH * 3];
        sy_look_gradient_pixels(&look.gradient, GW, GH, px);
        if (st->gradient.id) sy_gl_texture_destroy(st->dev, st->gradient);
        st->gradient.id = 0;
        if ((r = float_texture(st, GW, GH, px, &st->gradient, "background gradient", err)) != SY_OK) return r;
    }
    switch (look.background) {
    case SY_LOOK_BG_COLOR: sy_gl_set_background(st->dev, SY_GL_BACKGROUND_COLOR, look.bg_color, (sy_gl_texture){0}, 1.0f); break;
    case SY_LOOK_BG_ENVIRONMENT:
        sy_gl_set_background(st->dev, tex ? SY_GL_BACKGROUND_TEXTURE : SY_GL_BACKGROUND_NONE, NULL, (sy_gl_texture){tex},
                             look.env_intensity);
        break;
    case SY_LOOK_BG_GRADIENT: sy_gl_set_background(st->dev, SY_GL_BACKGROUND_TEXTURE, NULL, st->gradient, 1.0f); break;
    default: sy_gl_set_background(st->dev, SY_GL_BACKGROUND_NONE, NULL, (sy_gl_texture){0}, 1.0f); break;
    }
    st->look = look;
    st->look_valid = true;
    st->env_handle = tex;
    return SY_OK;
}

/* >>area lights */
typedef struct poly {
    sy_gl_area_light l;
    float power; /* luminance x area x sides */
} poly;

static void xform(const float *m, const float *p, float *o)
{
    for (int a = 0; a < 3; ++a) o[a] = m[a] * p[0] + m[4 + a] * p[1] + m[8 + a] * p[2] + m[12 + a];
}
static bool same3(const float *a, const float *b) { return a[0] == b[0] && a[1] == b[1] && a[2] == b[2]; }
static float tri_area(const float t[3][3])
{
    float e1[3], e2[3], c[3];
    sy_vec3_sub(t[1], t[0], e1), sy_vec3_sub(t[2], t[0], e2), sy_vec3_cross(e1, e2, c);
    return 0.5f * sqrtf(sy_vec3_dot(c, c));
}

/* Tries to merge triangles A and B (world space, front = counter-clockwise) into a convex quad. */
static bool merge_quad(const float a[3][3], const float b[3][3], float q[4][3])
{
    float na[3], nb[3], e1[3], e2[3];
    sy_vec3_sub(a[1], a[0], e1), sy_vec3_sub(a[2], a[0], e2), sy_vec3_cross(e1, e2, na);
    sy_vec3_sub(b[1], b[0], e1), sy_vec3_sub(b[2], b[0], e2), sy_vec3_cross(e1, e2, nb);
    float la = sqrtf(sy_vec3_dot(na, na)), lb = sqrtf(sy_vec3_dot(nb, nb));
    if (!(la > 0.0f && lb > 0.0f) || sy_vec3_dot(na, nb) < 0.99999f * la * lb) return false;
    for (int k = 0; k < 3; ++k) { /* shared edge x = a[k] -> y = a[k+1] appears in B as y -> x */
        const float *x = a[k], *y = a[(k + 1) % 3], *z = a[(k + 2) % 3];
        for (int j = 0; j < 3; ++j)
            if (same3(b[j], y) && same3(b[(j + 1) % 3], x)) {
                const float *d = b[(j + 2) % 3];
                const float *v[4] = {x, d, y, z};
                for (int i = 0; i < 4; ++i) { /* convex: every corner turns the same way as the normal */
                    float u[3], w[3], c[3];
                    sy_vec3_sub(v[(i + 1) % 4], v[i], u), sy_vec3_sub(v[(i + 2) % 4], v[(i + 1) % 4], w), sy_vec3_cross(u, w, c);
                    if (sy_vec3_dot(c, na) <= 0.0f) return false;
                }
                for (int i = 0; i < 4; ++i) memcpy(q[i], v[i], sizeof q[i]);
                return true;
            }
    }
    return false;
}

static int cmp_power_desc(const void *a, const void *b)
{
    float x = ((const poly *)a)->power, y = ((const poly *)b)->power;
    return x < y ? 1 : x > y ? -1 : 0;
}

static sy_result push_poly(poly **ps, size_t *n, size_t *cap, const float v[4][3], uint32_t nv, const float emission[3],
                           bool double_sided, sy_error *err)
{
    float e1[3], e2[3], c[3];
    sy_vec3_sub(v[1], v[0], e1), sy_vec3_sub(v[2], v[0], e2), sy_vec3_cross(e1, e2, c);
    float area = sqrtf(sy_vec3_dot(c, c)) * (nv == 4 ? 1.0f : 0.5f);
    if (!(area > 0.0f)) return SY_OK;
    if (*n == *cap) {
        size_t nc = *cap ? *cap * 2 : 64;
        poly *np = realloc(*ps, nc * sizeof *np);
        if (!np) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "raster: out of memory (area lights)");
        *ps = np, *cap = nc;
    }
    poly *p = &(*ps)[(*n)++];
    memset(p, 0, sizeof *p);
    memcpy(p->l.vertices, v, nv * sizeof v[0]);
    p->l.vertex_count = nv;
    memcpy(p->l.radiance, emission, sizeof p->l.radiance);
    p->l.double_sided = double_sided;
    p->power = (0.2126f * emission[0] + 0.7152f * emission[1] + 0.0722f * emission[2]) * area * (double_sided ? 2.0f : 1.0f);
    return SY_OK;
}

/* A texture coordinate wrapped as the sampler does (repeat 0, clamp 1, mirror 2) into [0, 1]. */
static float wrap_coord(float x, uint32_t wrap)
{
    if (!isfinite(x)) return 0.0f;
    if (wrap == 1u) return x < 0.0f ? 0.0f : x > 1.0f ? 1.0f : x;
    const float fl = floorf(x);
    float f = x - fl;
    if (wrap == 2u && fabsf(fmodf(fl, 2.0f)) == 1.0f) f = 1.0f - f; /* odd periods mirror (no integer cast: any finite x) */
    return f;
}

/* What the triangles of one emissive instance light with: its material, and where the material's
 * emission is textured, the texture's block means and the mesh's coordinates of the texture's set
 * (tx NULL: the material's emission for every triangle). */
typedef struct emit_src {
    const emat *em;
    const etex *tx;
    const float *uv;
} emit_src;

static emit_src emit_src_of(const raster_state *st, const emat *em, const emesh *me)
{
    emit_src e = {em, NULL, NULL};
    const etex *tx = em->tex.id ? sy_mirror_map_get(&st->texs, em->tex.id) : NULL;
    const sy_blob *uvb = me->uv[em->tex.texcoord < 2u ? em->tex.texcoord : 0u];
    if (tx && tx->blocks && uvb && sy_blob_size(uvb) >= sizeof(float) * 2u * (size_t)me->vertex_count)
        e.tx = tx, e.uv = sy_blob_data(uvb);
    return e;
}

/* The radiance of the triangle of vertices vi: the factor x the mean of the emissive texture's
 * block means at points spread over the triangle's texture coordinates (k x k stratified points,
 * k from the triangle's size in blocks, 2 .. 8); the material's emission without a texture. */
static void tri_emission(const emit_src *src, const uint32_t vi[3], float out[3])
{
    const emat *em = src->em;
    const etex *tx = src->tx;
    if (!tx) {
        memcpy(out, em->emission, 3 * sizeof(float));
        return;
    }
    float t[3][2];
    for (int k = 0; k < 3; ++k) {
        const float *q = src->uv + 2u * (size_t)vi[k];
        const float *m = em->tex.transform;
        t[k][0] = em->tex.transformed ? m[0] * q[0] + m[1] * q[1] + m[2] : q[0];
        t[k][1] = em->tex.transformed ? m[3] * q[0] + m[4] * q[1] + m[5] : q[1];
    }
    /* the triangle's extent in blocks: as many points per side, 2 .. 8 */
    float du = fmaxf(fabsf(t[1][0] - t[0][0]), fmaxf(fabsf(t[2][0] - t[0][0]), fabsf(t[2][0] - t[1][0]))) * (float)tx->bw;
    float dv = fmaxf(fabsf(t[1][1] - t[0][1]), fmaxf(fabsf(t[2][1] - t[0][1]), fabsf(t[2][1] - t[1][1]))) * (float)tx->bh;
    float ext = fmaxf(du, dv);
    int kk = !(ext < 8.0f) ? 8 : ext < 2.0f ? 2 : (int)ceilf(ext);
    double sum[3] = {0, 0, 0};
    for (int a = 0; a < kk; ++a)
        for (int b = 0; b < kk; ++b) { /* the unit square onto the triangle (square-root warp) */
            float su = sqrtf((a + 0.5f) / (float)kk), v = (b + 0.5f) / (float)kk;
            float w1 = su * (1.0f - v), w2 = su * v, w0 = 1.0f - w1 - w2;
            float u = w0 * t[0][0] + w1 * t[1][0] + w2 * t[2][0], vv = w0 * t[0][1] + w1 * t[1][1] + w2 * t[2][1];
            uint32_t bx = (uint32_t)(wrap_coord(u, tx->wrap_s) * (float)tx->bw), by = (uint32_t)(wrap_coord(vv, tx->wrap_t) * (float)tx->bh);
            if (bx >= tx->bw) bx = tx->bw - 1u;
            if (by >= tx->bh) by = tx->bh - 1u;
            const float *c = tx->blocks + 3u * ((size_t)by * tx->bw + bx);
            for (int ch = 0; ch < 3; ++ch) sum[ch] += c[ch];
        }
    for (int ch = 0; ch < 3; ++ch) {
        float v = em->factor[ch] * (float)(sum[ch] / (double)(kk * kk));
        out[ch] = isfinite(v) && v > 0.0f ? v : 0.0f;
    }
}

static sy_result rebuild_area_lights(raster_state *st, sy_error *err)
{
    poly *ps = NULL;
    size_t n = 0, cap = 0;
    sy_result r = SY_OK;
    for (uint32_t s = 0; s < st->insts.cap && r == SY_OK; ++s) {
        const einst *in = sy_mirror_map_slot(&st->insts, s);
        if (!in) continue;
        const emat *em = sy_mirror_map_get(&st->mats, in->material);
        const emesh *me = sy_mirror_map_get(&st->meshes, in->mesh);
        if (!in->visible || !em || !me || !me->positions) continue;
        const float *pos = sy_blob_data(me->positions);
        const uint32_t *idx = me->indices ? sy_blob_data(me->indices) : NULL;
        const float *m = in->world;
        float det = m[0] * (m[5] * m[10] - m[9] * m[6]) - m[4] * (m[1] * m[10] - m[9] * m[2]) + m[8] * (m[1] * m[6] - m[5] * m[2]);
        float tri[3][3], tri_e[3];
        bool pending = false;
        const emit_src src = emit_src_of(st, em, me);
        for (uint32_t t = 0; t < me->triangle_count && r == SY_OK; ++t) {
            float w[3][3], e[3];
            uint32_t vi[3];
            for (int k = 0; k < 3; ++k) {
                vi[k] = idx ? idx[3 * t + k] : 3 * t + k;
                if (vi[k] >= me->vertex_count) vi[k] = 0;
                xform(m, pos + 3 * (size_t)vi[k], w[det < 0.0f ? 2 - k : k]); /* mirrored: keep the front face */
            }
            tri_emission(&src, vi, e);
            const bool emits = e[0] > 0.0f || e[1] > 0.0f || e[2] > 0.0f;
            if (pending) {
                float q[4][3];
                if (emits && merge_quad(tri, w, q)) { /* one light of the pair's area-weighted radiance */
                    float a0 = tri_area(tri), a1 = tri_area(w), qe[3];
                    for (int c = 0; c < 3; ++c) qe[c] = a0 + a1 > 0.0f ? (tri_e[c] * a0 + e[c] * a1) / (a0 + a1) : e[c];
                    r = push_poly(&ps, &n, &cap, q, 4, qe, em->double_sided, err);
                    pending = false;
                    continue;
                }
                float v4[4][3];
                memcpy(v4, tri, sizeof tri);
                r = push_poly(&ps, &n, &cap, v4, 3, tri_e, em->double_sided, err);
                pending = false;
            }
            if (!emits) continue; /* its part of the texture is black */
            memcpy(tri, w, sizeof w);
            memcpy(tri_e, e, sizeof e);
            pending = true;
        }
        if (pending && r == SY_OK) {
            float v4[4][3];
            memcpy(v4, tri, sizeof tri);
            r = push_poly(&ps, &n, &cap, v4, 3, tri_e, em->double_sided, err);
        }
    }
    /* the indirect light of the emitters as one uniform radiance (the "ambient term" of progressive
     * radiosity, Cohen et al. 1988): emitted flux phi, total surface area A, area-weighted albedo rho,
     * captured fraction c = min(1, A / area of the scene's bounding box): mean indirect irradiance
     * c phi / A x (c rho + (c rho)^2) (two bounces: the infinite series c rho / (1 - c rho)
     * overestimates open scenes such as the Cornell box, whose light escapes through the open
     * side); the radiance is that / pi. Emitters are not counted as receivers. Computed when
     * emitters change (not when only other geometry moves). */
    float ambient[3] = {0, 0, 0};
    if (r == SY_OK && n && st->indirect) {
        double phi[3] = {0, 0, 0}, area = 0.0, rho[3] = {0, 0, 0}, lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (size_t i = 0; i < n; ++i) {
            float lumv = 0.2126f * ps[i].l.radiance[0] + 0.7152f * ps[i].l.radiance[1] + 0.0722f * ps[i].l.radiance[2];
            double a = lumv > 0.0f ? ps[i].power / lumv : 0.0; /* area x sides */
            for (int c = 0; c < 3; ++c) phi[c] += 3.14159265 * ps[i].l.radiance[c] * a;
        }
        for (uint32_t s = 0; s < st->insts.cap; ++s) {
            const einst *in = sy_mirror_map_slot(&st->insts, s);
            if (!in) continue;
            const emesh *me = sy_mirror_map_get(&st->meshes, in->mesh);
            if (!in->visible || !me || !me->positions || sy_mirror_map_get(&st->mats, in->material)) continue;
            const ealb *al = sy_mirror_map_get(&st->albs, in->material);
            const float alb_def[3] = {1, 1, 1}, *alb = al ? al->albedo : alb_def;
            const float *pos = sy_blob_data(me->positions);
            const uint32_t *idx = me->indices ? sy_blob_data(me->indices) : NULL;
            double ia = 0.0;
            for (uint32_t t = 0; t < me->triangle_count; ++t) {
                float w[3][3], e1[3], e2[3], c[3];
                for (int k = 0; k < 3; ++k) {
                    uint32_t vi = idx ? idx[3 * t + k] : 3 * t + k;
                    if (vi >= me->vertex_count) vi = 0;
                    xform(in->world, pos + 3 * (size_t)vi, w[k]);
                    for (int a = 0; a < 3; ++a) lo[a] = fmin(lo[a], w[k][a]), hi[a] = fmax(hi[a], w[k][a]);
                }
                sy_vec3_sub(w[1], w[0], e1), sy_vec3_sub(w[2], w[0], e2), sy_vec3_cross(e1, e2, c);
                ia += 0.5 * sqrt(sy_vec3_dot(c, c));
            }
            area += ia;
            for (int c = 0; c < 3; ++c) rho[c] += ia * alb[c];
        }
        if (area > 0.0) {
            double ex[3] = {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
            double box = 2.0 * (ex[0] * ex[1] + ex[1] * ex[2] + ex[2] * ex[0]);
            double cap_f = box > 0.0 ? fmin(1.0, area / box) : 0.0;
            for (int c = 0; c < 3; ++c) {
                double cr = fmin(cap_f * rho[c] / area, 0.95);
                ambient[c] = (float)(cap_f * phi[c] / area * (cr + cr * cr) / 3.14159265);
            }
        }
    }
    if (r == SY_OK) sy_gl_set_ambient(st->dev, ambient);
    if (r == SY_OK && n > SY_GL_MAX_AREA_LIGHTS) {
        double total = 0.0, kept = 0.0;
        for (size_t i = 0; i < n; ++i) total += ps[i].power;
        qsort(ps, n, sizeof *ps, cmp_power_desc);
        for (size_t i = 0; i < SY_GL_MAX_AREA_LIGHTS; ++i) kept += ps[i].power;
        float scale = kept > 0.0 ? (float)(total / kept) : 1.0f;
        for (size_t i = 0; i < SY_GL_MAX_AREA_LIGHTS; ++i)
            for (int c = 0; c < 3; ++c) ps[i].l.radiance[c] *= scale;
        if (!st->warned_area_cap) {
            sy_log(SY_LOG_NOTE, "raster", NULL,
                   "raster: %zu emissive polygons; the %d most powerful light the scene (radiance x %.3g keeps the total power)",
                   n, SY_GL_MAX_AREA_LIGHTS, (double)scale);
            st->warned_area_cap = true;
        }
        n = SY_GL_MAX_AREA_LIGHTS;
    }
    if (r == SY_OK) {
        sy_gl_area_light ls[SY_GL_MAX_AREA_LIGHTS];
        for (size_t i = 0; i < n; ++i) ls[i] = ps[i].l;
        sy_gl_result gr = sy_gl_set_area_lights(st->dev, ls, (uint32_t)n);
        if (gr != SY_GL_OK) r = gl_fail(st, err, gr, "area lights");
        else st->area_count = (uint32_t)n;
    }
    free(ps);
    if (r == SY_OK) st->areas_dirty = false;
    return r;
}

static sy_result check_layer(const sy_render_request *req, const sy_layer *layer, sy_error *err)
{
    if (layer->width != req->rect_w || layer->height != req->rect_h)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "raster: layer %ux%u does not match the request rectangle %ux%u",
                            layer->width, layer->height, req->rect_w, req->rect_h);
    return SY_OK;
}

/* The selection highlight (sy_highlight.h): the ID image of the rectangle and its margin (the
 * pick's ID pass, sy_gl_ids), the selected instances' pixels tinted and outlined. */
static sy_result highlight(raster_state *st, const sy_gl_camera *cam, const sy_render_request *req, sy_layer *layer,
                           sy_error *err)
{
    sy_highlight_rect m = sy_highlight_margin(req->full_width, req->full_height, req->rect_x, req->rect_y, req->rect_w,
                                              req->rect_h);
    size_t n = (size_t)m.w * m.h;
    uint32_t *ids = malloc((n ? n : 1) * sizeof *ids);
    uint8_t *sel = malloc(n ? n : 1);
    if (!ids || !sel) {
        free(ids), free(sel);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "raster: selection highlight: out of memory (%ux%u)", m.w, m.h);
    }
    sy_gl_render_desc d = {req->full_width, req->full_height, m.x, m.y, m.w, m.h};
    sy_gl_result r = n ? sy_gl_ids(st->dev, cam, &d, ids) : SY_GL_OK;
    if (r != SY_GL_OK) {
        free(ids), free(sel);
        return gl_fail(st, err, r, "selection highlight");
    }
    for (size_t i = 0; i < n; ++i) {
        const einst *in = ids[i] ? sy_mirror_map_get(&st->insts, ids[i]) : NULL;
        sel[i] = in && in->selected;
    }
    sy_highlight_apply(layer->rgba, req->rect_x, req->rect_y, req->rect_w, req->rect_h, sel, m);
    free(ids), free(sel);
    return SY_OK;
}

static sy_result raster_render(void *state, const sy_render_request *req, sy_layer *layer, sy_error *err)
{
    raster_state *st = state;
    sy_result rr = check_layer(req, layer, err);
    if (rr != SY_OK) return rr;
    double t0 = sy_time_now();
    if ((rr = apply_look(st, req->background_id, err)) != SY_OK) return rr;
    if (st->areas_dirty && (rr = rebuild_area_lights(st, err)) != SY_OK) return rr;
    sy_gl_camera cam;
    camera_of(&req->camera, &cam);
    sy_gl_render_desc d = {req->full_width, req->full_height, req->rect_x, req->rect_y, req->rect_w, req->rect_h};
    sy_gl_result r = sy_gl_render(st->dev, &cam, &d, layer->rgba, layer->depth);
    if (r != SY_GL_OK) return gl_fail(st, err, r, "render");
    if (st->selected_count && (rr = highlight(st, &cam, req, layer, err)) != SY_OK) return rr;
    if (req->progress) {
        sy_progress p = {1, 1};
        req->progress(req->progress_user, &p);
    }
    st->frames_rendered++;
    st->last_render_seconds = sy_time_now() - t0;
    return SY_OK;
}

sy_result sy_mediator_raster_render_floor(void *state, const sy_render_request *req, bool lit, sy_layer *layer,
                                          sy_error *err)
{
    raster_state *st = state;
    sy_result rr = check_layer(req, layer, err);
    if (rr != SY_OK) return rr;
    if ((rr = apply_look(st, req->background_id, err)) != SY_OK) return rr;
    sy_gl_camera cam;
    camera_of(&req->camera, &cam);
    sy_gl_render_desc d = {req->full_width, req->full_height, req->rect_x, req->rect_y, req->rect_w, req->rect_h};
    sy_gl_result r = sy_gl_render_floor(st->dev, &cam, &d, lit, layer->rgba, layer->depth);
    return r == SY_GL_OK ? SY_OK : gl_fail(st, err, r, "floor render");
}

/* SY_CAP_PICK: the device's ID pass names the instance and the triangle (sy_gl_pick); the node,
 * placement, mesh, primitive and material come from the mirror, the triangle's vertices from the
 * primitive's blobs this mediator keeps, the numbers from sy_pick_ray.h (the same arithmetic as the
 * ray tracers' picks). */
static sy_result raster_pick(void *state, const sy_camera_view *view, uint32_t width, uint32_t height, uint32_t x,
                             uint32_t y, sy_pick_result *out, sy_error *err)
{
    raster_state *st = state;
    sy_gl_camera cam;
    camera_of(view, &cam);
    sy_gl_pick_hit h;
    sy_gl_result r = sy_gl_pick(st->dev, &cam, width, height, x, y, &h);
    if (r != SY_GL_OK) return gl_fail(st, err, r, "pick");
    const einst *in = h.instance.id ? sy_mirror_map_get(&st->insts, h.instance.id) : NULL;
    const emesh *em = in ? sy_mirror_map_get(&st->meshes, in->mesh) : NULL;
    sy_mirror_instance_info info;
    if (!em || h.triangle >= em->triangle_count || !sy_mirror_instance_find(st->mirror, in->node, h.instance.id, &info))
        return SY_OK;
    const float *pos = sy_blob_data(em->positions);
    const uint32_t *idx = em->indices ? sy_blob_data(em->indices) : NULL;
    float p[3][3];
    for (int k = 0; k < 3; ++k) {
        uint32_t v = idx ? idx[3u * h.triangle + (uint32_t)k] : 3u * h.triangle + (uint32_t)k;
        if (v >= em->vertex_count) return SY_OK; /* the scene validated the indices; never here */
        memcpy(p[k], pos + 3u * v, sizeof p[k]);
    }
    sy_pick_name(out, &info, h.triangle);
    sy_pick_triangle(view, width, height, x, y, in->world, (const float(*)[3])p, out);
    return SY_OK;
}

/* >>class */
static void raster_destroy(void *state)
{
    raster_state *st = state;
    if (!st) return;
    sy_mirror_destroy(st->mirror); /* releases instances, lights and meshes while the device lives */
    sy_gl_device_destroy(st->dev);
    for (uint32_t i = 0; i < st->meshes.cap; ++i) {
        emesh *em = sy_mirror_map_slot(&st->meshes, i);
        if (em) emesh_release(em);
    }
    for (uint32_t i = 0; i < st->texs.cap; ++i) {
        etex *t = sy_mirror_map_slot(&st->texs, i);
        if (t) free(t->blocks);
    }
    sy_mirror_map_free(&st->meshes);
    sy_mirror_map_free(&st->mats);
    sy_mirror_map_free(&st->insts);
    sy_mirror_map_free(&st->texs);
    sy_mirror_map_free(&st->albs);
    free(st);
}

static void log_warning(void *user, const char *msg)
{
    raster_state *st = user;
    st->counters.warnings++;
    snprintf(st->counters.last_warning, sizeof st->counters.last_warning, "%s", msg);
    sy_backend_warn("raster", msg); /* the GL back-end's own callback, forwarded */
}

/* The raster's parameters: the one source of their names, ranges, defaults and help (sy_params.h). */
static const sy_param_decl raster_params[] = {
    {"gl", SY_PARAM_ENUM, 0, 0, "osmesa", "osmesa|egl|glfw", "OpenGL context provider (glfw: a window)", 0},
    {"msaa", SY_PARAM_INT, 1, 32, "4", NULL, "multisample anti-aliasing samples (clamped to the context's limit)", 0},
    {"shadow_map_size", SY_PARAM_INT, 0, 16384, "0", NULL,
     "shadow map resolution, texels per side (16..16384; 0: follows the frame, twice its larger side, 256 to 2048)", 0},
    {"max_texture_size", SY_PARAM_INT, 0, 1 << 20, "0", NULL, "largest texture side; larger are downscaled (0 = the GL limit)",
     0},
    {"window_width", SY_PARAM_INT, 1, 16384, "640", NULL, "gl=glfw: window width", 0},
    {"window_height", SY_PARAM_INT, 1, 16384, "480", NULL, "gl=glfw: window height", 0},
    {"indirect", SY_PARAM_BOOL, 0, 0, "1", NULL, "emitters' indirect light as an ambient estimate (0: direct light only)", 0},
    {"deferred", SY_PARAM_BOOL, 0, 0, "1", NULL,
     "with MSAA, shade opaque untextured surfaces once per pixel after the geometry pass (0: all forward)", 0},
    {"lod", SY_PARAM_FLOAT, 0, 64, "0.5", NULL,
     "levels of detail of large meshes: the largest silhouette deviation allowed, in pixels (0: always the full mesh)", 0},
};
static const sy_param_table raster_table = SY_PARAM_TABLE(raster_params);

static sy_result raster_create(const sy_mediator_create_args *args, void **state_out, sy_error *err)
{
    *state_out = NULL;
    long msaa = 4, shadow = 0, max_tex = 0, ww = 640, wh = 480;
    double lod = SY_GL_LOD_PIXELS_DEFAULT;
    bool indirect = true, deferred = true;
    sy_result r;
    const sy_param_table *t = &raster_table;
    const char *gl = "osmesa";
    sy_gl_provider provider = SY_GL_PROVIDER_OSMESA;
    if ((r = sy_param_string(t, args->params, "gl", &gl, err)) || (r = sy_param_int(t, args->params, "msaa", &msaa, err)) ||
        (r = sy_param_int(t, args->params, "shadow_map_size", &shadow, err)) ||
        (r = sy_param_int(t, args->params, "max_texture_size", &max_tex, err)) ||
        (r = sy_param_int(t, args->params, "window_width", &ww, err)) ||
        (r = sy_param_int(t, args->params, "window_height", &wh, err)) ||
        (r = sy_param_bool(t, args->params, "indirect", &indirect, err)) ||
        (r = sy_param_bool(t, args->params, "deferred", &deferred, err)) ||
        (r = sy_param_float(t, args->params, "lod", &lod, err)))
        return r;
    if (shadow > 0 && shadow < 16)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                            "raster: parameter shadow_map_size=%ld: expected 0 (follow the frame) or 16..16384", shadow);
    if (!sy_gl_provider_parse(gl, &provider)) /* the table's enum lists the same names */
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "raster: parameter gl=%s: expected osmesa, egl or glfw", gl);
    raster_state *st = calloc(1, sizeof *st);
    if (!st) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "raster mediator: out of memory");
    st->meshes = SY_MIRROR_MAP_INIT(emesh);
    st->mats = SY_MIRROR_MAP_INIT(emat);
    st->insts = SY_MIRROR_MAP_INIT(einst);
    st->texs = SY_MIRROR_MAP_INIT(etex);
    st->albs = SY_MIRROR_MAP_INIT(ealb);
    st->indirect = indirect;
    sy_gl_device_desc dd = {.provider = provider,
                            .msaa = (uint32_t)msaa,
                            .shadow_map_size = (uint32_t)shadow,
                            .max_texture_size = (uint32_t)max_tex,
                            .window_width = (uint32_t)ww,
                            .window_height = (uint32_t)wh,
                            .log = log_warning,
                            .log_user = st,
                            .error = gl_error,
                            .error_user = st,
                            .forward = !deferred};
    sy_gl_result gr = sy_gl_device_create(&dd, &st->dev);
    if (gr != SY_GL_OK) {
        r = sy_backend_fail(err, (int)gr, "raster", NULL, st->gl_msg);
        free(st);
        return r;
    }
    sy_gl_set_lod(st->dev, (float)lod);
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
    .param_table = SY_PARAM_TABLE(raster_params),
    .caps = SY_CAP_DEPTH | SY_CAP_TILES | SY_CAP_PICK | SY_CAP_CLIP,
    .create = raster_create,
    .destroy = raster_destroy,
    .sync = raster_sync,
    .render = raster_render,
    .stats = raster_stats,
    .default_rank = 20, /* the default back-end where it is built: the complete look, fastest */
    .pick = raster_pick,
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
    out->instances_culled = gs.instances_culled;
    out->deferred_draws = gs.deferred_draws;
    out->deferred_pixels = gs.deferred_pixels;
}

const char *sy_mediator_raster_info(void *state) { return sy_gl_device_info(((raster_state *)state)->dev); }

sy_result sy_mediator_raster_register(sy_error *err) { return sy_mediator_register(&raster_class, err); }
