/* sy_mediator_rt.c — core scene -> Embree back-end adapter (see sy_mediator_rt.h).
 *
 * Sections: >>mirror callbacks (the scene mirror is mediators/sy_mirror)  >>sync  >>render
 * >>class */
#include "sy_mediator_rt.h"

#include "sy_rt.h"
#include "sy_rt_bench.h"
#include "sy_rt_limit.h"
#include "sy_log.h"
#include "sy_mirror.h"

#include "sy_filter_adaptive.h"
#include "sy_filter_atrous.h"
#include "sy_filter_jbu.h"
#include "sy_filter_pixel.h"
#include "sy_radiance_hook.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define ERRLEN 256

/* Whitted's default anti-aliasing (spp, default 4 in whitted_params): 4 stratified camera rays per
 * pixel (one per quadrant, Sobol jittered), sharing the pixel's area-light budget (light_samples);
 * colour and alpha average them, a pixel is covered where any of them hits and its depth is the
 * mean of those hits, as in the path tracer and the raster's MSAA. spp=1 traces the pixel centre
 * alone. */

/* Path tracer: one accumulation per distinct request (camera, sizes, rectangle, background, seed);
 * a few are kept so that viewports sharing this context (stereo eyes, tiles) do not evict each
 * other. A slot restarts when the device published a change since its last pass. */
#define ACCUM_SLOTS 4
typedef struct accum_slot {
    sy_rt_accum *acc;
    sy_camera_view camera;
    uint32_t full_w, full_h, rect[4], bg, seed;
    uint64_t version;  /* device version the accumulation belongs to */
    uint64_t last_use;
    sy_filter_pixel *pixel;  /* pixel-filter state of this accumulation (display filter "pixel") */
    uint32_t pass_samples;   /* sample count of its last filter pass, 0 = none since the restart */
    sy_radiance_hook *radiance; /* radiance-filter state of this accumulation (display filter "radiance") */
} accum_slot;

/* Display filter of the path tracer (backends/filters), applied to the returned layer only: the
 * accumulation never sees it, so changing it never restarts sampling. */
typedef enum pt_filter_kind {
    PT_FILTER_NONE,
    PT_FILTER_PIXEL,
    PT_FILTER_ATROUS,
    PT_FILTER_JBU,
    PT_FILTER_ADAPTIVE,
    PT_FILTER_RADIANCE, /* not a display filter: it needs the path records of every 1-spp pass */
    PT_FILTER_KIND_COUNT
} pt_filter_kind;
static const char *const pt_filter_names[PT_FILTER_KIND_COUNT] = {"none", "pixel", "atrous", "jbu", "adaptive",
                                                                   "radiance"};

/* >>parameters: the classes' declared tables (sy_params.h), the one source of their names, ranges,
 * defaults and help; core checks given parameters against them before create. The path tracer's
 * display-filter options are SY_PARAM_LIVE (sy_context_set_filter). Enum orders: "filter" is
 * pt_filter_kind, "rf_kernel" sy_filter_rf_kernel, "filter_kernel" separable, brute. */
#define RT_COMMON_PARAMS(depth_default, depth_max, depth_help)                                                      \
    {"max_depth", SY_PARAM_INT, 1, depth_max, depth_default, NULL, depth_help, 0},                                  \
    {"light_samples", SY_PARAM_INT, 1, 1024, "16", NULL, "area-light samples per pixel, shared by its pixel samples", \
     0},                                                                                                             \
    {"threads", SY_PARAM_INT, 0, 1024, "0", NULL, "worker threads (0 = OpenMP's default: OMP_NUM_THREADS, else all cores)", 0},                             \
    {"specular", SY_PARAM_FLOAT, 0, 1, "1", NULL,                                                                   \
     "KHR_materials_specular factor of every material (0: dielectrics purely Lambertian)", 0},                       \
    {"max_memory_mb", SY_PARAM_INT, 0, 1 << 30, "0", NULL,                                                          \
     "MB Embree may hold (0: no limit of its own); a mesh whose BVH needs more than is left, or than the machine "  \
     "has available, is refused with both sizes", 0}
static const sy_param_decl whitted_params[] = {
    {"spp", SY_PARAM_INT, 1, 256, "4", NULL, "camera rays per pixel (stratified, jittered; 1 = the pixel centre)", 0},
    {"env_samples", SY_PARAM_INT, 1, 256, "4", NULL, "environment-light samples per shading point and pixel sample", 0},
    RT_COMMON_PARAMS("8", 64, "longest ray path: depth of mirror and glass recursion"),
};
static const sy_param_decl coverage_params[] = {
    RT_COMMON_PARAMS("8", 64, "longest ray path: depth of mirror and glass recursion"),
};
#define LIVE SY_PARAM_LIVE
static const sy_param_decl pathtracer_params[] = {
    RT_COMMON_PARAMS("64", 1024, "bounces per path"),
    {"filter", SY_PARAM_ENUM, 0, 0, "none", "none|pixel|atrous|jbu|adaptive|radiance", "display noise filter", LIVE},
    {"threshold", SY_PARAM_FLOAT, 0, 1e6, "0.01", NULL,
     "perceived-variance threshold of the pixel filter's blend, the adaptive preview and radiance's T_u", LIVE},
    {"sigma_s", SY_PARAM_FLOAT, 0, 1000, "8", NULL, "pixel filter: spatial sigma (pixels, > 0)", LIVE},
    {"sigma_c", SY_PARAM_FLOAT, 0, 1e6, "0.02", NULL, "pixel filter: virtual-flash colour sigma (> 0)", LIVE},
    {"sigma_d", SY_PARAM_FLOAT, 0, 1e9, "2", NULL, "pixel filter: depth sigma (scene units, > 0)", LIVE},
    {"filter_kernel", SY_PARAM_ENUM, 0, 0, "separable", "separable|brute", "pixel filter: kernel evaluation", LIVE},
    {"filter_iterations", SY_PARAM_INT, 1, 8, "3", NULL, "pixel filter: iterations", LIVE},
    {"filter_start", SY_PARAM_INT, 1, 1 << 30, "4", NULL,
     "pixel filter: first pass at this sample count (a power of two), then at every power of two", LIVE},
    {"atrous_iterations", SY_PARAM_INT, 1, 10, "5", NULL, "a-trous filter: iterations", LIVE},
    {"jbu_factor", SY_PARAM_INT, 1, 64, "4", NULL, "joint bilateral upsampling: downsampling factor", LIVE},
    {"rf_warmup_frames", SY_PARAM_INT, 0, 64, "4", NULL, "radiance filter: warm-up frames", LIVE},
    {"rf_warmup_radius", SY_PARAM_FLOAT, 0, 128, "8", NULL, "radiance filter: warm-up radius (pixels, > 0)", LIVE},
    {"rf_max_radius", SY_PARAM_FLOAT, 1, 128, "24", NULL, "radiance filter: largest radius (pixels)", LIVE},
    {"rf_kernel", SY_PARAM_ENUM, 0, 0, "epanechnikov", "epanechnikov|silverman|uniform|gaussian",
     "radiance filter: kernel", LIVE},
    {"rf_ao", SY_PARAM_BOOL, 0, 0, "1", NULL, "radiance filter: ambient-occlusion term", LIVE},
    {"rf_prism_thickness", SY_PARAM_FLOAT, 0, 100, "0.25", NULL,
     "radiance filter: prism half thickness / tangent extent (> 0)", LIVE},
    {"rf_grazing_epsilon", SY_PARAM_FLOAT, 0, 1, "0.1", NULL, "radiance filter: grazing-angle epsilon (> 0)", LIVE},
    {"rf_glossy_limit", SY_PARAM_FLOAT, 0, 1e9, "128", NULL, "radiance filter: glossy limit", LIVE},
    {"rf_specular_limit", SY_PARAM_FLOAT, 0, 1e9, "4096", NULL, "radiance filter: specular limit", LIVE},
    {"rf_unbiased", SY_PARAM_BOOL, 0, 0, "0", NULL,
     "radiance filter: show the plain path-traced mean in the correction phase", LIVE},
};
#undef LIVE
static const sy_param_table whitted_table = SY_PARAM_TABLE(whitted_params);
static const sy_param_table coverage_table = SY_PARAM_TABLE(coverage_params);
static const sy_param_table pt_table = SY_PARAM_TABLE(pathtracer_params);

typedef struct pt_filter_cfg {
    pt_filter_kind kind;
    sy_filter_pixel_params pixel;       /* threshold shared with adaptive */
    sy_filter_atrous_params atrous;
    sy_filter_jbu_params jbu;
    sy_filter_adaptive_params adaptive;
    sy_filter_radiance_params radiance; /* threshold T_u = the shared threshold */
} pt_filter_cfg;

/* The scene mirror (textures, materials, meshes, lights, backgrounds, nodes and placements) is
 * mediators/sy_mirror; this adapter turns its callbacks into Embree back-end calls. */
typedef struct rt_state {
    sy_rt_device *dev;
    sy_mirror *mirror;
    uint32_t integrator;
    uint32_t max_depth, light_samples;
    uint32_t pixel_samples, env_samples; /* whitted: "spp", "env_samples" */
    float specular; /* "specular" parameter: KHR_materials_specular factor given to every material */
    /* the look (sy_look.h) applied to the device, with the back-end textures it resolved to */
    sy_look look;
    bool look_applied;
    uint32_t look_env_tex, look_bg_tex;
    sy_rt_texture studio;   /* the built-in studio environment, made on first use */
    sy_rt_texture gradient; /* the baked sky/ground gradient of the current look, 0 = none */
    sy_gradient gradient_baked;
    sy_mediator_rt_counters counters;
    uint64_t frames_rendered;
    accum_slot slots[ACCUM_SLOTS]; /* path tracer only */
    int last_slot;                 /* slot of the last render, -1 = none */
    uint64_t use_clock;
    uint32_t *inst_node;           /* back-end instance slot index -> core node id (coverage) */
    uint32_t inst_node_cap;
    pt_filter_cfg filter;          /* path tracer display filter */
    float *fbuf[SY_RT_AOV_COUNT + 1]; /* filter inputs: the AOV planes + world positions */
    size_t fbuf_px;                /* pixels the fbuf planes hold */
    sy_mediator_rt_filter_info finfo; /* last filtered frame */
} rt_state;

#define RT_HANDLE_INDEX(h) ((h) & 0x3fffffu) /* backends/rt handles: 22-bit slot index */

/* Remembers which node an instance belongs to (node 0 forgets it). */
static void inst_node_set(rt_state *st, uint32_t handle, uint32_t node)
{
    uint32_t i = RT_HANDLE_INDEX(handle);
    if (i >= st->inst_node_cap) {
        if (!node) return;
        uint32_t nc = st->inst_node_cap ? st->inst_node_cap : 256;
        while (nc <= i) nc *= 2;
        uint32_t *n = realloc(st->inst_node, sizeof *n * nc);
        if (!n) return; /* coverage then reports this instance as unknown (node 0) */
        memset(n + st->inst_node_cap, 0, sizeof *n * (nc - st->inst_node_cap));
        st->inst_node = n;
        st->inst_node_cap = nc;
    }
    st->inst_node[i] = node;
}

static uint32_t inst_node_get(const rt_state *st, uint32_t handle)
{
    uint32_t i = RT_HANDLE_INDEX(handle);
    return handle && i < st->inst_node_cap ? st->inst_node[i] : 0;
}

static sy_result rt_fail(sy_error *err, sy_rt_result r, const char *what, const char *msg)
{
    return sy_error_set(err, r == SY_RT_ERROR_OUT_OF_MEMORY ? SY_ERR_OUT_OF_MEMORY : SY_ERR_BACKEND, "%s: %s", what, msg);
}

/* >>mirror callbacks */
/* >>bad input: the core scene refuses non-finite and negative values; what it accepts but the
 * device does not (factors above 1, cone angles out of order) is clamped into the device's range
 * with a warning naming the object and the value, so that one odd value never fails a render. */
static void rt_warn(rt_state *st, const char *kind, uint32_t id, const char *field, double from, double to)
{
    st->counters.warnings++;
    snprintf(st->counters.last_warning, sizeof st->counters.last_warning, "rt mediator: %s %u: %s %g clamped to %g",
             kind, id, field, from, to);
    char item[64];
    snprintf(item, sizeof item, "%s %u", kind, id);
    sy_log(SY_LOG_WARNING, "rt", item, "%s %g clamped to %g (rt mediator)", field, from, to);
}

static float clamp_warn(rt_state *st, const char *kind, uint32_t id, const char *field, float v, float lo, float hi)
{
    float c = !(v >= lo) ? lo : v > hi ? hi : v; /* NaN -> lo */
    if (c != v) rt_warn(st, kind, id, field, (double)v, (double)c);
    return c;
}

static sy_rt_texture_ref texref(const rt_state *st, const sy_texture_ref *r)
{
    sy_rt_texture_ref o = {{sy_mirror_texture_handle(st->mirror, r->texture.id)}, r->texcoord, false, {0}};
    o.transformed = sy_texture_ref_matrix(r, o.transform);
    return o;
}

static sy_result cb_material(void *user, const sy_mirror_material_args *a, sy_error *err)
{
    rt_state *st = user;
    const sy_material_data *m = a->data;
    char e[ERRLEN];
    sy_rt_material_desc d;
    sy_rt_material_desc_init(&d);
    static const char *const bc[4] = {"base_color[0]", "base_color[1]", "base_color[2]", "base_color[3] (alpha)"};
    for (int i = 0; i < 4; ++i) d.base_color[i] = clamp_warn(st, "material", a->id, bc[i], m->base_color[i], 0.0f, i == 3 ? 1.0f : INFINITY);
    d.base_color_texture = texref(st, &m->base_color_texture);
    d.metallic = clamp_warn(st, "material", a->id, "metallic", m->metallic, 0.0f, 1.0f);
    d.roughness = clamp_warn(st, "material", a->id, "roughness", m->roughness, 0.0f, 1.0f);
    d.metallic_roughness_texture = texref(st, &m->metallic_roughness_texture);
    for (int i = 0; i < 3; ++i) {
        float e = m->emissive[i] * m->emissive_strength;
        d.emissive[i] = isfinite(e) && e >= 0.0f ? e : clamp_warn(st, "material", a->id, "emission", e, 0.0f, 3.0e38f);
    }
    d.emissive_texture = texref(st, &m->emissive_texture);
    d.normal_texture = texref(st, &m->normal_texture);
    d.normal_scale = m->normal_texture.scale;
    d.transmission = clamp_warn(st, "material", a->id, "transmission", m->transmission, 0.0f, 1.0f);
    d.ior = m->ior >= 1.0f ? m->ior : 1.5f;
    d.specular = st->specular;
    d.alpha_mode = (sy_rt_alpha_mode)m->alpha_mode;
    d.alpha_cutoff = clamp_warn(st, "material", a->id, "alpha_cutoff", m->alpha_cutoff, 0.0f, 1.0f);
    d.double_sided = m->double_sided != 0;
    d.unlit = m->unlit != 0;
    sy_rt_material h = {*a->handle};
    sy_rt_result r = h.id ? sy_rt_material_update(st->dev, h, &d, e, sizeof e)
                          : sy_rt_material_create(st->dev, &d, &h, e, sizeof e);
    *a->handle = h.id;
    return r == SY_RT_OK ? SY_OK : rt_fail(err, r, "material", e);
}

static sy_result cb_texture(void *user, const sy_mirror_texture_args *a, sy_error *err)
{
    rt_state *st = user;
    char e[ERRLEN];
    sy_rt_texture_desc d = {
        .width = a->info->width,
        .height = a->info->height,
        .channels = a->info->channels,
        .format = a->info->format == SY_PIXEL_U8_SRGB     ? SY_RT_TEXEL_UNORM8_SRGB
                  : a->info->format == SY_PIXEL_U8_LINEAR ? SY_RT_TEXEL_UNORM8
                                                          : SY_RT_TEXEL_FLOAT32,
        .pixels = a->pixels,
        .wrap_s = (sy_rt_wrap)a->sampler->wrap_s,
        .wrap_t = (sy_rt_wrap)a->sampler->wrap_t,
        .filter = a->sampler->mag_filter == SY_FILTER_NEAREST ? SY_RT_FILTER_NEAREST : SY_RT_FILTER_LINEAR,
    };
    sy_rt_texture h = {0};
    sy_rt_result r = sy_rt_texture_create(st->dev, &d, &h, e, sizeof e);
    *a->handle = h.id;
    return r == SY_RT_OK ? SY_OK : rt_fail(err, r, "texture", e);
}

/* The blobs a shared back-end mesh reads in place (sy_rt_mesh_desc.release): one reference each,
 * given back when the back-end lets the mesh go. Blobs are immutable and padded (SY_BLOB_PADDING),
 * so Embree may use them as its vertex and index buffers: no copy in the back-end. */
typedef struct rt_mesh_blobs {
    sy_blob *b[6];
} rt_mesh_blobs;

static void rt_mesh_blobs_release(void *user)
{
    rt_mesh_blobs *h = user;
    for (int k = 0; k < 6; ++k) sy_blob_release(h->b[k]);
    free(h);
}

static sy_result cb_primitive(void *user, const sy_mirror_primitive_args *a, sy_error *err)
{
    rt_state *st = user;
    char e[ERRLEN];
    const sy_primitive *p = a->primitive;
    rt_mesh_blobs *held = malloc(sizeof *held);
    if (!held) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "rt: mesh primitive: out of memory");
    sy_rt_mesh_desc d = {
        .positions = sy_blob_data(p->positions),
        .normals = sy_blob_data(p->normals),
        .uv = {sy_blob_data(p->texcoords0), sy_blob_data(p->texcoords1)},
        .colors = sy_blob_data(p->colors),
        .indices = sy_blob_data(p->indices),
        .vertex_count = sy_primitive_vertex_count(p),
        .triangle_count = sy_primitive_triangle_count(p),
        .release = rt_mesh_blobs_release,
        .release_user = held,
    };
    sy_blob *const used[6] = {p->positions, p->normals, p->texcoords0, p->texcoords1, p->colors, p->indices};
    for (int k = 0; k < 6; ++k) held->b[k] = sy_blob_retain(used[k]);
    sy_rt_mesh h = {0};
    sy_rt_result r = sy_rt_mesh_create(st->dev, &d, &h, e, sizeof e);
    if (r != SY_RT_OK) rt_mesh_blobs_release(held); /* a failed create keeps nothing */
    *a->handle = h.id;
    return r == SY_RT_OK ? SY_OK : rt_fail(err, r, "mesh primitive", e);
}

static sy_result cb_instance(void *user, const sy_mirror_instance_args *a, sy_error *err)
{
    rt_state *st = user;
    char e[ERRLEN];
    sy_rt_instance h = {*a->handle};
    sy_rt_result r;
    if (!h.id) {
        sy_rt_instance_desc d = {.mesh = {a->mesh},
                                 .material = {a->material},
                                 .flags = (a->baked ? SY_RT_INSTANCE_BAKED : 0u) | (a->visible ? 0u : SY_RT_INSTANCE_HIDDEN)};
        memcpy(d.transform, a->world->m, sizeof d.transform);
        r = sy_rt_instance_create(st->dev, &d, &h, e, sizeof e);
        *a->handle = h.id;
        if (r == SY_RT_OK) inst_node_set(st, h.id, a->node);
        return r == SY_RT_OK ? SY_OK : rt_fail(err, r, "instance", e);
    }
    r = sy_rt_instance_set_transform(st->dev, h, a->world->m, e, sizeof e);
    if (r == SY_RT_OK) r = sy_rt_instance_set_visible(st->dev, h, a->visible, e, sizeof e);
    return r == SY_RT_OK ? SY_OK : rt_fail(err, r, "instance transform", e);
}

static sy_result cb_light(void *user, const sy_mirror_light_args *a, sy_error *err)
{
    rt_state *st = user;
    char e[ERRLEN];
    const sy_light_data *l = a->light;
    sy_rt_light_desc d;
    memset(&d, 0, sizeof d);
    d.type = l->type == SY_LIGHT_SPOT ? SY_RT_LIGHT_SPOT : l->type == SY_LIGHT_DIRECTIONAL ? SY_RT_LIGHT_DIRECTIONAL
                                                                                         : SY_RT_LIGHT_POINT;
    static const char *const cn[3] = {"color[0]", "color[1]", "color[2]"};
    for (int i = 0; i < 3; ++i) d.color[i] = clamp_warn(st, "light of node", a->node, cn[i], l->color[i], 0.0f, 3.0e38f);
    d.intensity = clamp_warn(st, "light of node", a->node, "intensity", l->intensity, 0.0f, 3.0e38f);
    d.range = clamp_warn(st, "light of node", a->node, "range", l->range, 0.0f, 3.0e38f);
    if (d.type == SY_RT_LIGHT_SPOT) {
        d.outer_cone_angle = clamp_warn(st, "light of node", a->node, "outer_cone", l->outer_cone, 0.0f, 1.5707963f);
        d.inner_cone_angle = clamp_warn(st, "light of node", a->node, "inner_cone", l->inner_cone, 0.0f, d.outer_cone_angle);
    }
    memcpy(d.position, a->position, sizeof d.position);
    memcpy(d.direction, a->direction, sizeof d.direction);
    sy_rt_light h = {*a->handle};
    sy_rt_result r = h.id ? sy_rt_light_update(st->dev, h, &d, e, sizeof e) : sy_rt_light_create(st->dev, &d, &h, e, sizeof e);
    *a->handle = h.id;
    return r == SY_RT_OK ? SY_OK : rt_fail(err, r, "light", e);
}

static void cb_release(void *user, const sy_mirror_release_args *a)
{
    rt_state *st = user;
    switch (a->kind) {
    case SY_MIRROR_TEXTURE: sy_rt_texture_destroy(st->dev, (sy_rt_texture){a->handle}, NULL, 0); break;
    case SY_MIRROR_MATERIAL: sy_rt_material_destroy(st->dev, (sy_rt_material){a->handle}, NULL, 0); break;
    case SY_MIRROR_PRIMITIVE: sy_rt_mesh_destroy(st->dev, (sy_rt_mesh){a->handle}, NULL, 0); break;
    case SY_MIRROR_INSTANCE:
        inst_node_set(st, a->handle, 0);
        sy_rt_instance_destroy(st->dev, (sy_rt_instance){a->handle}, NULL, 0);
        break;
    case SY_MIRROR_LIGHT: sy_rt_light_destroy(st->dev, (sy_rt_light){a->handle}, NULL, 0); break;
    }
}

static const sy_mirror_callbacks rt_mirror_callbacks = {
    .texture_set = cb_texture,
    .material_set = cb_material,
    .primitive_set = cb_primitive,
    .instance_set = cb_instance,
    .light_set = cb_light,
    .release = cb_release,
};

/* >>sync */
static sy_result rt_sync(void *state, const sy_changes *changes, sy_error *err)
{
    rt_state *st = state;
    sy_mirror_sync_stats ms;
    sy_result r = sy_mirror_sync(st->mirror, changes, &ms, err);
    st->counters.last_sync_placements = ms.placements;
    st->counters.last_sync_entries = ms.entries;
    /* The device tracks what is staged (sy_rt_commit is a no-op on a clean device), so every
     * successful sync ends with a commit: an uncommitted device refuses to render. */
    if (r == SY_OK) {
        char e[ERRLEN];
        sy_rt_result rr = sy_rt_commit(st->dev, e, sizeof e);
        if (rr != SY_RT_OK) r = rt_fail(err, rr, "commit", e);
    }
    sy_rt_stats s;
    sy_rt_device_stats(st->dev, &s);
    st->counters.instances = s.instances;
    st->counters.meshes = s.meshes;
    st->counters.materials = s.materials;
    st->counters.textures = s.textures;
    st->counters.lights = s.lights;
    st->counters.last_sync_top_commit_seconds = s.last_top_commit_seconds;
    return r;
}

/* >>render */
typedef struct progress_bridge {
    sy_progress_fn fn;
    void *user;
} progress_bridge;

static bool progress_cb(const sy_rt_progress *p, void *user)
{
    progress_bridge *b = user;
    sy_progress q = {p->tiles_done, p->tiles_total};
    b->fn(b->user, &q);
    return true;
}

static void camera_of(const sy_camera_view *v, sy_rt_camera *cam)
{
    memcpy(cam->camera_to_world, v->camera_to_world.m, sizeof cam->camera_to_world);
    cam->projection = v->projection == SY_PROJECTION_ORTHOGRAPHIC ? SY_RT_PROJECTION_ORTHOGRAPHIC
                                                                  : SY_RT_PROJECTION_PERSPECTIVE;
    memcpy(cam->window, v->window, sizeof cam->window);
    cam->near_clip = v->znear;
    cam->far_clip = v->zfar;
}

sy_result sy_mediator_rt_bench_rays(void *state, const sy_camera_view *view, uint32_t width, uint32_t height,
                                    uint32_t repeats, sy_mediator_rt_bench *out, sy_error *err)
{
    rt_state *st = state;
    char e[ERRLEN];
    sy_rt_camera cam;
    camera_of(view, &cam);
    sy_rt_bench_result b;
    sy_rt_result r = sy_rt_bench_rays(st->dev, &cam, width, height, repeats, &b, e, sizeof e);
    if (r != SY_RT_OK) return rt_fail(err, r, "ray benchmark", e);
    out->ours_mrays = b.primary_mrays;
    out->raw_mrays = b.raw_mrays;
    out->overhead_percent = b.overhead_percent;
    out->threads = b.threads;
    return SY_OK;
}

/* >>pathtracer accumulation */
static bool same_view(const sy_camera_view *a, const sy_camera_view *b)
{
    return !memcmp(a->camera_to_world.m, b->camera_to_world.m, sizeof a->camera_to_world.m) &&
           a->projection == b->projection && !memcmp(a->window, b->window, sizeof a->window) && a->znear == b->znear &&
           a->zfar == b->zfar;
}

/* Picks (or recycles) the accumulation slot of a request and restarts it when the scene, the
 * camera or anything else about the request changed; sets st->last_slot. */
static sy_result pt_slot(rt_state *st, const sy_render_request *req, sy_error *err)
{
    sy_rt_stats ds;
    sy_rt_device_stats(st->dev, &ds);
    const uint32_t rect[4] = {req->rect_x, req->rect_y, req->rect_w, req->rect_h};
    int found = -1, lru = 0;
    for (int i = 0; i < ACCUM_SLOTS; ++i) {
        accum_slot *a = &st->slots[i];
        if (a->acc && a->full_w == req->full_width && a->full_h == req->full_height && !memcmp(a->rect, rect, sizeof rect) &&
            a->bg == req->background_id && a->seed == req->seed && same_view(&a->camera, &req->camera)) {
            found = i;
            break;
        }
        if (!a->acc || (st->slots[lru].acc && a->last_use < st->slots[lru].last_use)) lru = i;
    }
    accum_slot *a;
    if (found >= 0) {
        a = &st->slots[found];
        if (a->version != ds.version) { /* something visible changed since the last pass */
            sy_rt_accum_reset(a->acc);
            st->counters.accum_restarts++;
            sy_filter_pixel_reset(a->pixel);
            sy_radiance_hook_reset(a->radiance);
            a->pass_samples = 0;
        }
    } else {
        found = lru;
        a = &st->slots[found];
        uint32_t w = 0, h = 0;
        sy_rt_accum_size(a->acc, &w, &h);
        if (!a->acc || w != req->rect_w || h != req->rect_h) {
            char e[ERRLEN];
            sy_rt_accum_destroy(a->acc);
            a->acc = NULL;
            sy_rt_result r = sy_rt_accum_create(req->rect_w, req->rect_h, &a->acc, e, sizeof e);
            if (r != SY_RT_OK) return rt_fail(err, r, "accumulation buffer", e);
        } else {
            sy_rt_accum_reset(a->acc);
        }
        if (st->last_slot >= 0) st->counters.accum_restarts++;
        sy_filter_pixel_reset(a->pixel);
        sy_radiance_hook_reset(a->radiance);
        a->pass_samples = 0;
        a->camera = req->camera;
        a->full_w = req->full_width;
        a->full_h = req->full_height;
        memcpy(a->rect, rect, sizeof rect);
        a->bg = req->background_id;
        a->seed = req->seed;
    }
    a->version = ds.version;
    a->last_use = ++st->use_clock;
    st->last_slot = found;
    return SY_OK;
}

/* Coverage as an image: every object gets a stable colour from its node id (for viewing and
 * layering); rt_coverage (sy_context_coverage) gives the numbers. */
static sy_result coverage_render(rt_state *st, const sy_rt_camera *cam, const sy_rt_render_desc *d, sy_layer *layer,
                                 sy_error *err)
{
    char e[ERRLEN];
    size_t n = (size_t)d->width * d->height;
    uint32_t *ids = malloc(n * sizeof *ids);
    if (!ids) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "coverage: out of memory");
    sy_rt_result r = sy_rt_coverage(st->dev, cam, d, ids, layer->depth, e, sizeof e);
    if (r == SY_RT_OK)
        for (size_t i = 0; i < n; ++i) {
            uint32_t node = inst_node_get(st, ids[i]);
            float *c = layer->rgba + 4 * i;
            if (!ids[i]) {
                c[0] = c[1] = c[2] = c[3] = 0.0f;
                continue;
            }
            uint32_t hsh = node * 2654435761u;
            c[0] = 0.2f + 0.8f * (float)(hsh & 255u) / 255.0f;
            c[1] = 0.2f + 0.8f * (float)((hsh >> 8) & 255u) / 255.0f;
            c[2] = 0.2f + 0.8f * (float)((hsh >> 16) & 255u) / 255.0f;
            c[3] = 1.0f;
        }
    free(ids);
    return r == SY_RT_OK ? SY_OK : rt_fail(err, r, "coverage", e);
}

static int coverage_order(const void *pa, const void *pb)
{
    const sy_coverage_entry *a = pa, *b = pb;
    if (a->pixels != b->pixels) return a->pixels > b->pixels ? -1 : 1;
    return a->node_id < b->node_id ? -1 : a->node_id > b->node_id;
}

/* SY_CAP_COVERAGE (sy_context_coverage): works on any state of this adapter; the coverage class
 * offers it. */
static sy_result rt_coverage(void *state, const sy_camera_view *view, uint32_t width, uint32_t height,
                             sy_coverage_entry **entries_out, uint32_t *count_out, sy_error *err)
{
    rt_state *st = state;
    *entries_out = NULL;
    *count_out = 0;
    char e[ERRLEN];
    sy_rt_camera cam;
    camera_of(view, &cam);
    sy_rt_render_desc d = {.image_width = width, .image_height = height, .width = width, .height = height};
    size_t n;
    if (!sy_size_mul(width, height, &n) || n == 0) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "coverage: bad size %ux%u", width, height);
    uint32_t *ids = malloc(n * sizeof *ids);
    if (!ids) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "coverage: out of memory for %ux%u", width, height);
    sy_rt_result cr = sy_rt_commit(st->dev, e, sizeof e); /* no-op unless a failed sync left changes */
    if (cr != SY_RT_OK) {
        free(ids);
        return rt_fail(err, cr, "commit", e);
    }
    sy_rt_result r = sy_rt_coverage(st->dev, &cam, &d, ids, NULL, e, sizeof e);
    if (r != SY_RT_OK) {
        free(ids);
        return rt_fail(err, r, "coverage", e);
    }
    /* count pixels per node */
    for (size_t i = 0; i < n; ++i) ids[i] = inst_node_get(st, ids[i]);
    sy_coverage_entry *out = NULL;
    uint32_t m = 0, cap = 0;
    for (size_t i = 0; i < n; ++i) {
        if (!ids[i]) continue;
        uint32_t k = 0;
        /* few distinct objects per view in practice; a linear scan with move-to-front stays cheap */
        while (k < m && out[k].node_id != ids[i]) k++;
        if (k == m) {
            if (m == cap) {
                uint32_t nc = cap ? cap * 2 : 64;
                sy_coverage_entry *no = realloc(out, sizeof *no * nc);
                if (!no) {
                    free(out);
                    free(ids);
                    return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "coverage: out of memory");
                }
                out = no;
                cap = nc;
            }
            out[m].node_id = ids[i];
            out[m].pixels = 0;
            m++;
        }
        out[k].pixels++;
        if (k > 0) { /* move to front */
            sy_coverage_entry t = out[k];
            out[k] = out[0];
            out[0] = t;
        }
    }
    free(ids);
    if (m > 1) qsort(out, m, sizeof *out, coverage_order);
    *entries_out = out;
    *count_out = m;
    return SY_OK;
}

/* >>display filters
 * The path tracer's layer can be filtered for display (backends/filters) from the accumulation's
 * feature buffers. Parameters (creation and sy_mediator_rt_set_filter): filter, threshold, sigma_s,
 * sigma_c, sigma_d, filter_kernel, filter_iterations, filter_start, atrous_iterations, jbu_factor. */
static sy_result filter_fail(sy_error *err, const sy_filter_error *fe)
{
    return sy_error_set(err, fe->status == SY_FILTER_ERROR_OUT_OF_MEMORY ? SY_ERR_OUT_OF_MEMORY : SY_ERR_INVALID_ARGUMENT,
                        "pathtracer filter: %s", fe->message);
}

static void filter_cfg_default(pt_filter_cfg *c, uint32_t threads)
{
    memset(c, 0, sizeof *c);
    c->kind = PT_FILTER_NONE;
    sy_filter_pixel_params_default(&c->pixel);
    sy_filter_atrous_params_default(&c->atrous);
    sy_filter_jbu_params_default(&c->jbu);
    sy_filter_adaptive_params_default(&c->adaptive);
    c->adaptive.threshold = c->pixel.threshold;
    sy_filter_radiance_params_default(&c->radiance);
    c->radiance.threshold = c->pixel.threshold;
    if (threads > SY_FILTER_MAX_THREADS) threads = SY_FILTER_MAX_THREADS;
    c->pixel.threads = c->atrous.threads = c->jbu.threads = c->adaptive.threads = c->radiance.threads = threads;
}

/* One path-tracer key into *v through its table: the given value, else (all: at creation) the
 * declared default; otherwise an absent key keeps *v. */
static sy_result pt_float(const sy_params *p, bool all, const char *key, float *v, sy_error *err)
{
    if (!all && !sy_params_get(p, key)) return SY_OK;
    double x = *v;
    sy_result r = sy_param_float(&pt_table, p, key, &x, err);
    if (r == SY_OK) *v = (float)x;
    return r;
}

static sy_result pt_u32(const sy_params *p, bool all, const char *key, uint32_t *v, sy_error *err)
{
    if (!all && !sy_params_get(p, key)) return SY_OK;
    long x = (long)*v;
    sy_result r = sy_param_int(&pt_table, p, key, &x, err);
    if (r == SY_OK) *v = (uint32_t)x;
    return r;
}

static sy_result pt_bool(const sy_params *p, bool all, const char *key, bool *v, sy_error *err)
{
    return !all && !sy_params_get(p, key) ? SY_OK : sy_param_bool(&pt_table, p, key, v, err);
}

static sy_result pt_enum(const sy_params *p, bool all, const char *key, uint32_t *v, sy_error *err)
{
    return !all && !sy_params_get(p, key) ? SY_OK : sy_param_enum(&pt_table, p, key, v, err);
}

/* The radiance filter's own keys (rf_*); ranges as sy_filter_radiance_params. */
static sy_result radiance_cfg_apply(sy_filter_radiance_params *rp, const sy_params *p, bool all, sy_error *err)
{
    sy_result r;
    uint32_t kernel = (uint32_t)rp->kernel;
    if ((r = pt_u32(p, all, "rf_warmup_frames", &rp->warmup_frames, err)) ||
        (r = pt_float(p, all, "rf_warmup_radius", &rp->warmup_radius, err)) ||
        (r = pt_float(p, all, "rf_max_radius", &rp->max_radius, err)) ||
        (r = pt_float(p, all, "rf_prism_thickness", &rp->prism_thickness, err)) ||
        (r = pt_float(p, all, "rf_grazing_epsilon", &rp->grazing_epsilon, err)) ||
        (r = pt_float(p, all, "rf_glossy_limit", &rp->glossy_limit, err)) ||
        (r = pt_float(p, all, "rf_specular_limit", &rp->specular_limit, err)) ||
        (r = pt_bool(p, all, "rf_ao", &rp->ambient_occlusion, err)) ||
        (r = pt_bool(p, all, "rf_unbiased", &rp->unbiased_switch, err)) ||
        (r = pt_enum(p, all, "rf_kernel", &kernel, err)))
        return r;
    rp->kernel = (sy_filter_rf_kernel)kernel;
    return SY_OK;
}

/* New configuration = *base with the filter `name` (NULL: p's "filter", absent: unchanged) and the
 * keys present in p (all, at creation: absent keys take their declared defaults; otherwise they
 * keep base's values). Validated as a whole; *base unchanged on error. */
static sy_result filter_cfg_apply(pt_filter_cfg *base, const char *name, const sy_params *p_in, bool all, sy_error *err)
{
    static const sy_params empty;
    const sy_params *p = p_in ? p_in : &empty;
    pt_filter_cfg c = *base;
    sy_result r;
    uint32_t kind = (uint32_t)c.kind;
    if (name) {
        const sy_param_decl *d = sy_param_find(&pt_table, "filter");
        int k = sy_param_enum_index(d, name);
        if (k < 0) return sy_param_check_value(d, name, "back-end 'pathtracer'", err); /* names the filters */
        kind = (uint32_t)k;
    } else if ((r = pt_enum(p, all, "filter", &kind, err)))
        return r;
    c.kind = (pt_filter_kind)kind;
    float threshold = c.pixel.threshold;
    uint32_t fkernel = c.pixel.kernel == SY_FILTER_PIXEL_BRUTE ? 1u : 0u;
    if ((r = pt_float(p, all, "threshold", &threshold, err)) || (r = pt_float(p, all, "sigma_s", &c.pixel.sigma_s, err)) ||
        (r = pt_float(p, all, "sigma_c", &c.pixel.sigma_c, err)) || (r = pt_float(p, all, "sigma_d", &c.pixel.sigma_d, err)) ||
        (r = pt_enum(p, all, "filter_kernel", &fkernel, err)) ||
        (r = pt_u32(p, all, "filter_iterations", &c.pixel.iterations, err)) ||
        (r = pt_u32(p, all, "filter_start", &c.pixel.schedule_start, err)) ||
        (r = pt_u32(p, all, "atrous_iterations", &c.atrous.iterations, err)) ||
        (r = pt_u32(p, all, "jbu_factor", &c.jbu.factor, err)) || (r = radiance_cfg_apply(&c.radiance, p, all, err)))
        return r;
    c.pixel.threshold = c.adaptive.threshold = c.radiance.threshold = threshold;
    c.pixel.kernel = fkernel ? SY_FILTER_PIXEL_BRUTE : SY_FILTER_PIXEL_SEPARABLE;
    /* the rf_* options are checked whatever the filter; T_u = threshold only matters for radiance */
    sy_filter_radiance_params rq = c.radiance;
    if (c.kind != PT_FILTER_RADIANCE && !(rq.threshold > 0.0f)) rq.threshold = 0.01f;
    sy_filter_error fe = {0};
    if (sy_filter_pixel_params_check(&c.pixel, &fe) || sy_filter_atrous_params_check(&c.atrous, &fe) ||
        sy_filter_jbu_params_check(&c.jbu, &fe) ||
        (c.kind == PT_FILTER_ADAPTIVE && sy_filter_adaptive_params_check(&c.adaptive, &fe)) ||
        sy_filter_radiance_params_check(&rq, &fe))
        return filter_fail(err, &fe);
    *base = c;
    return SY_OK;
}

sy_result sy_mediator_rt_set_filter(void *state, const char *name, const sy_params *opts, sy_error *err)
{
    rt_state *st = state;
    if (st->integrator != SY_RT_INTEGRATOR_PATHTRACER)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "set filter: only the pathtracer class has display filters");
    /* the same check core makes (sy_context_set_filter), for callers of this function */
    sy_result r = sy_params_check(&pt_table, opts, SY_PARAM_LIVE, "back-end 'pathtracer'", NULL, err);
    if (r != SY_OK) return r;
    pt_filter_cfg c = st->filter;
    r = filter_cfg_apply(&c, name, opts, false, err);
    if (r != SY_OK) return r;
    /* Only the threshold acts on the blend alone; anything else invalidates the filtered buffers,
     * which are recomputed at the next frame (the accumulation itself is never touched). */
    sy_filter_pixel_params a = st->filter.pixel, b = c.pixel;
    a.threshold = b.threshold = 0.0f;
    bool refilter = c.kind != st->filter.kind || memcmp(&a, &b, sizeof a) != 0;
    for (int i = 0; i < ACCUM_SLOTS; ++i) {
        accum_slot *s = &st->slots[i];
        if (!s->pixel) continue;
        sy_filter_error fe = {0};
        if (sy_filter_pixel_set_params(s->pixel, &c.pixel, &fe)) return filter_fail(err, &fe);
        if (refilter) {
            sy_filter_pixel_reset(s->pixel);
            s->pass_samples = 0;
        }
    }
    /* radiance: a switch to it or new options while it is on recreate the filter, which then
     * resumes from the accumulation (sy_radiance_hook.h); other filters leave its state alone */
    bool rf_changed = c.kind == PT_FILTER_RADIANCE &&
                      (c.kind != st->filter.kind || memcmp(&st->filter.radiance, &c.radiance, sizeof c.radiance) != 0);
    for (int i = 0; i < ACCUM_SLOTS && rf_changed; ++i)
        if (st->slots[i].radiance && (r = sy_radiance_hook_set_params(st->slots[i].radiance, &c.radiance, err)) != SY_OK)
            return r;
    st->filter = c;
    return SY_OK;
}

void sy_mediator_rt_filter_info_get(void *state, sy_mediator_rt_filter_info *out)
{
    rt_state *st = state;
    *out = st->finfo;
    out->name = pt_filter_names[st->filter.kind];
    out->threshold = st->filter.pixel.threshold;
}

/* World positions of the first hits of the rectangle's pixels from the camera-axis depth (the
 * a-trous guide and the headlight of the pixel filter's range buffer); misses go 1e18 away. */
static void filter_positions(const sy_render_request *req, const float *depth, float *pos)
{
    const sy_camera_view *v = &req->camera;
    const float *m = v->camera_to_world.m;
    bool ortho = v->projection == SY_PROJECTION_ORTHOGRAPHIC;
    for (uint32_t y = 0; y < req->rect_h; ++y)
        for (uint32_t x = 0; x < req->rect_w; ++x) {
            size_t i = (size_t)y * req->rect_w + x;
            float u = v->window[0] + (v->window[1] - v->window[0]) * ((float)(req->rect_x + x) + 0.5f) / (float)req->full_width;
            float w = v->window[3] - (v->window[3] - v->window[2]) * ((float)(req->rect_y + y) + 0.5f) / (float)req->full_height;
            float d = depth[i];
            if (!isfinite(d)) d = 1e18f;
            float c[3] = {ortho ? u : u * d, ortho ? w : w * d, -d};
            for (int k = 0; k < 3; ++k) pos[3 * i + k] = m[k] * c[0] + m[4 + k] * c[1] + m[8 + k] * c[2] + m[12 + k];
        }
}

/* Reads the slot's feature buffers (rect_w x rect_h) into st->fbuf (the filters' inputs). */
static sy_result filter_read_aovs(rt_state *st, const accum_slot *a, const sy_render_request *req, sy_error *err)
{
    size_t n = (size_t)req->rect_w * req->rect_h;
    if (n > st->fbuf_px) {
        for (int k = 0; k <= SY_RT_AOV_COUNT; ++k) {
            free(st->fbuf[k]);
            st->fbuf[k] = malloc(n * (k < SY_RT_AOV_COUNT ? sy_rt_aov_channels((sy_rt_aov)k) : 3u) * sizeof(float));
        }
        st->fbuf_px = n;
        for (int k = 0; k <= SY_RT_AOV_COUNT; ++k)
            if (!st->fbuf[k]) {
                st->fbuf_px = 0;
                return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "pathtracer filter: out of memory for %ux%u", req->rect_w,
                                    req->rect_h);
            }
    }
    char e[ERRLEN];
    for (int k = 0; k < SY_RT_AOV_COUNT; ++k) {
        sy_rt_result rr = sy_rt_accum_read(a->acc, (sy_rt_aov)k, st->fbuf[k], e, sizeof e);
        if (rr != SY_RT_OK) return rt_fail(err, rr, "pathtracer filter: feature buffers", e);
    }
    return SY_OK;
}

/* Filters the layer the path tracer just wrote (rectangle of the slot st->last_slot). */
static sy_result filter_layer(rt_state *st, const sy_render_request *req, sy_layer *layer, sy_error *err)
{
    accum_slot *a = &st->slots[st->last_slot];
    sy_result rd = filter_read_aovs(st, a, req, err);
    if (rd != SY_OK) return rd;
    filter_positions(req, st->fbuf[SY_RT_AOV_DEPTH], st->fbuf[SY_RT_AOV_COUNT]);
    uint32_t samples = sy_rt_accum_samples(a->acc);
    const float *m = req->camera.camera_to_world.m;
    sy_filter_frame f = {
        .width = req->rect_w,
        .height = req->rect_h,
        .color_channels = 4,
        .variance_channels = 3,
        .color = st->fbuf[SY_RT_AOV_COLOR],
        .variance = st->fbuf[SY_RT_AOV_VARIANCE],
        .albedo = st->fbuf[SY_RT_AOV_ALBEDO],
        .normal = st->fbuf[SY_RT_AOV_NORMAL],
        .depth = st->fbuf[SY_RT_AOV_DEPTH],
        .position = st->fbuf[SY_RT_AOV_COUNT],
        .direct = st->fbuf[SY_RT_AOV_DIRECT],
        .indirect = st->fbuf[SY_RT_AOV_INDIRECT],
        .spp_uniform = (float)samples,
        .has_camera = req->camera.projection != SY_PROJECTION_ORTHOGRAPHIC,
        .camera_position = {m[12], m[13], m[14]},
    };
    sy_filter_stats fs = {0};
    sy_filter_error fe = {0};
    sy_filter_status s = SY_FILTER_OK;
    switch (st->filter.kind) {
    case PT_FILTER_PIXEL: {
        if (!a->pixel && (s = sy_filter_pixel_create(&st->filter.pixel, &a->pixel, &fe))) break;
        /* a pass whenever the count reached the next power of two of the schedule (a render may
         * add several samples at once and step over 2^i) */
        uint64_t next = st->filter.pixel.schedule_start;
        while (next <= a->pass_samples) next *= 2;
        s = sy_filter_pixel_run(a->pixel, &f, samples, samples >= next, layer->rgba, &fs, &fe);
        if (!s && fs.filter_pass) a->pass_samples = samples;
        break;
    }
    case PT_FILTER_ATROUS: s = sy_filter_atrous(&st->filter.atrous, &f, layer->rgba, &fs, &fe); break;
    case PT_FILTER_JBU: s = sy_filter_jbu(&st->filter.jbu, &f, layer->rgba, &fs, &fe); break;
    case PT_FILTER_ADAPTIVE: s = sy_filter_adaptive(&st->filter.adaptive, &f, layer->rgba, NULL, &fs, &fe); break;
    default: break;
    }
    if (s) return filter_fail(err, &fe);
    st->finfo.nonfinite_pixels = fs.nonfinite_samples;
    st->finfo.nonfinite_samples = sy_rt_accum_nonfinite(a->acc);
    st->finfo.seconds = fs.seconds;
    st->finfo.filter_pass = fs.filter_pass;
    st->finfo.mean_blend = fs.mean_blend;
    st->finfo.last_pass_samples = a->pass_samples;
    st->finfo.frames++;
    return SY_OK;
}

/* >>radiance filter: not a display filter. Every sample of the request is its own 1-spp pass whose
 * path records (the path tracer's stored-sample hook) feed one frame of the radiance filter
 * (sy_radiance_hook.h); the accumulation still receives every sample, so "none" and the other
 * filters show the same samples, and a switch to "radiance" resumes from the accumulation. */
static sy_result radiance_render(rt_state *st, const sy_render_request *req, const sy_rt_camera *cam,
                                 sy_rt_render_desc *d, sy_layer *layer, sy_error *err)
{
    accum_slot *a = &st->slots[st->last_slot];
    sy_result r;
    if (!a->radiance && (r = sy_radiance_hook_create(&st->filter.radiance, &a->radiance, err)) != SY_OK) return r;
    sy_rt_pt_record *recs;
    if ((r = sy_radiance_hook_records(a->radiance, req->rect_w, req->rect_h, &recs, err)) != SY_OK) return r;
    const sy_camera_view *v = &req->camera;
    bool ortho = v->projection == SY_PROJECTION_ORTHOGRAPHIC;
    sy_radiance_hook_frame_desc fd = {.pixel_angle = (v->window[3] - v->window[2]) / (float)req->full_height,
                                      .orthographic = ortho};
    uint32_t prior = sy_rt_accum_samples(a->acc);
    if (sy_radiance_hook_frame_index(a->radiance) == 0 && prior > 0) { /* resume on the accumulation */
        if ((r = filter_read_aovs(st, a, req, err)) != SY_OK) return r;
        fd.prior_samples = prior;
        fd.prior_color = st->fbuf[SY_RT_AOV_COLOR];
        fd.prior_color_channels = 4;
        fd.prior_variance = st->fbuf[SY_RT_AOV_VARIANCE];
        fd.prior_direct = st->fbuf[SY_RT_AOV_DIRECT];
    }
    uint32_t count = d->samples;
    double secs = 0.0;
    uint64_t bad = 0, rays = 0;
    sy_filter_stats fs = {0};
    char e[ERRLEN];
    for (uint32_t i = 0; i < count; ++i) {
        bool last = i + 1 == count;
        d->samples = 1;
        d->records = recs;
        sy_rt_result rr = sy_rt_render(st->dev, cam, d, last ? layer->rgba : NULL, last ? layer->depth : NULL, e, sizeof e);
        if (rr != SY_RT_OK) {
            sy_radiance_hook_reset(a->radiance);
            return rt_fail(err, rr, "render", e);
        }
        rays += sy_rt_accum_last_rays(d->accum);
        if ((r = sy_radiance_hook_frame(a->radiance, &fd, last ? layer->rgba : NULL, &fs, err)) != SY_OK) return r;
        fd.prior_samples = 0;
        secs += fs.seconds;
        bad += fs.nonfinite_samples;
    }
    st->counters.last_render_rays = rays;
    st->frames_rendered++;
    st->finfo.nonfinite_pixels = bad;
    st->finfo.nonfinite_samples = sy_rt_accum_nonfinite(a->acc);
    st->finfo.seconds = secs;
    st->finfo.filter_pass = true;
    st->finfo.mean_blend = fs.mean_blend; /* share of pixels in the correction phase (plain PT) */
    st->finfo.last_pass_samples = sy_rt_accum_samples(a->acc);
    st->finfo.frames += count;
    return SY_OK;
}

/* >>look: the resolved look (sy_look.h) of the request's world, applied to the device when it (or
 * the back-end texture it resolves to) changed. The device's commit bumps its version, so
 * progressive accumulations restart. */
#define GRADIENT_W 4u
#define GRADIENT_H 256u

static sy_result studio_texture(rt_state *st, uint32_t *handle, sy_error *err)
{
    if (!st->studio.id) {
        const size_t n = (size_t)SY_LOOK_STUDIO_WIDTH * SY_LOOK_STUDIO_HEIGHT * 3u;
        float *px = malloc(n * sizeof *px);
        if (!px) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "studio environment: out of memory");
        sy_look_studio_pixels(SY_LOOK_STUDIO_WIDTH, SY_LOOK_STUDIO_HEIGHT, px);
        sy_rt_texture_desc d = {.width = SY_LOOK_STUDIO_WIDTH, .height = SY_LOOK_STUDIO_HEIGHT, .channels = 3,
                                .format = SY_RT_TEXEL_FLOAT32, .pixels = px, .wrap_s = SY_RT_WRAP_REPEAT,
                                .wrap_t = SY_RT_WRAP_CLAMP, .filter = SY_RT_FILTER_LINEAR};
        char e[ERRLEN];
        sy_rt_result r = sy_rt_texture_create(st->dev, &d, &st->studio, e, sizeof e);
        free(px);
        if (r != SY_RT_OK) return rt_fail(err, r, "studio environment", e);
    }
    *handle = st->studio.id;
    return SY_OK;
}

static sy_result gradient_texture(rt_state *st, const sy_gradient *g, uint32_t *handle, sy_error *err)
{
    if (!st->gradient.id || memcmp(&st->gradient_baked, g, sizeof *g)) {
        float *px = malloc((size_t)GRADIENT_W * GRADIENT_H * 3u * sizeof *px);
        if (!px) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "background gradient: out of memory");
        sy_look_gradient_pixels(g, GRADIENT_W, GRADIENT_H, px);
        sy_rt_texture_desc d = {.width = GRADIENT_W, .height = GRADIENT_H, .channels = 3, .format = SY_RT_TEXEL_FLOAT32,
                                .pixels = px, .wrap_s = SY_RT_WRAP_REPEAT, .wrap_t = SY_RT_WRAP_CLAMP,
                                .filter = SY_RT_FILTER_LINEAR};
        char e[ERRLEN];
        sy_rt_texture t = {0};
        sy_rt_result r = sy_rt_texture_create(st->dev, &d, &t, e, sizeof e);
        free(px);
        if (r != SY_RT_OK) return rt_fail(err, r, "background gradient", e);
        /* the device's background still names the old one until the look is applied (it stays
         * valid: a destroyed background texture draws black, and the new look replaces it now) */
        if (st->gradient.id) sy_rt_texture_destroy(st->dev, st->gradient, NULL, 0);
        st->gradient = t;
        st->gradient_baked = *g;
    }
    *handle = st->gradient.id;
    return SY_OK;
}

static sy_result apply_look(rt_state *st, uint32_t background_id, sy_error *err)
{
    sy_look look;
    sy_mirror_look(st->mirror, background_id, &look);
    uint32_t env_tex = 0, bg_tex = 0;
    sy_result r = SY_OK;
    if (look.env == SY_LOOK_ENV_TEXTURE) env_tex = sy_mirror_texture_handle(st->mirror, look.env_texture);
    else if (look.env == SY_LOOK_ENV_STUDIO) r = studio_texture(st, &env_tex, err);
    if (r != SY_OK) return r;
    if (look.background == SY_LOOK_BG_ENVIRONMENT) bg_tex = env_tex;
    else if (look.background == SY_LOOK_BG_GRADIENT && (r = gradient_texture(st, &look.gradient, &bg_tex, err)) != SY_OK)
        return r;
    if (st->look_applied && sy_look_equal(&st->look, &look) && st->look_env_tex == env_tex && st->look_bg_tex == bg_tex)
        return SY_OK;
    sy_rt_background bg = {.mode = SY_RT_BACKGROUND_NONE};
    if (look.background == SY_LOOK_BG_COLOR) {
        /* premultiplied; the device's colour background is opaque (alpha 1) */
        bg.mode = SY_RT_BACKGROUND_COLOR;
        memcpy(bg.color, look.bg_color, sizeof bg.color);
    } else if (bg_tex) {
        bg.mode = SY_RT_BACKGROUND_TEXTURE;
        bg.texture.id = bg_tex;
        bg.intensity = look.background == SY_LOOK_BG_ENVIRONMENT ? look.env_intensity : 1.0f;
    }
    char e[ERRLEN];
    sy_rt_result rr = sy_rt_set_background(st->dev, &bg, e, sizeof e);
    if (rr == SY_RT_OK) rr = sy_rt_set_environment(st->dev, (sy_rt_texture){env_tex}, look.env_intensity, e, sizeof e);
    if (rr == SY_RT_OK) rr = sy_rt_commit(st->dev, e, sizeof e);
    if (rr != SY_RT_OK) {
        st->look_applied = false;
        return rt_fail(err, rr, "look (background, environment)", e);
    }
    st->look = look;
    st->look_env_tex = env_tex;
    st->look_bg_tex = bg_tex;
    st->look_applied = true;
    return SY_OK;
}

static sy_result rt_render(void *state, const sy_render_request *req, sy_layer *layer, sy_error *err)
{
    rt_state *st = state;
    char e[ERRLEN];
    sy_result lr = apply_look(st, req->background_id, err);
    if (lr != SY_OK) return lr;
    sy_rt_camera cam;
    camera_of(&req->camera, &cam);
    progress_bridge pb = {req->progress, req->progress_user};
    sy_rt_render_desc d = {
        .integrator = (sy_rt_integrator)st->integrator,
        .image_width = req->full_width,
        .image_height = req->full_height,
        .x = req->rect_x,
        .y = req->rect_y,
        .width = req->rect_w,
        .height = req->rect_h,
        .max_depth = st->max_depth,
        .area_light_samples = st->light_samples,
        .seed = req->seed,
        .pixel_samples = st->pixel_samples,
        .env_light_samples = st->env_samples,
        .progress = req->progress ? progress_cb : NULL,
        .progress_user_data = &pb,
    };
    if (st->integrator == SY_RT_INTEGRATOR_WHITTED && req->preview > 0.0f && req->preview < 1.0f) {
        /* an interactive preview (SY_CAP_PREVIEW): the share `preview` of the camera rays and of the
         * area- and environment-light samples per pixel, at least one each (spp=1 is the pixel centre) */
        d.pixel_samples = (uint32_t)fmaxf(1.0f, floorf((float)st->pixel_samples * req->preview + 0.5f));
        d.area_light_samples = (uint32_t)fmaxf(1.0f, floorf((float)st->light_samples * req->preview + 0.5f));
        d.env_light_samples = (uint32_t)fmaxf(1.0f, floorf((float)st->env_samples * req->preview + 0.5f));
    }
    if (st->integrator == SY_RT_INTEGRATOR_COVERAGE) return coverage_render(st, &cam, &d, layer, err);
    if (st->integrator == SY_RT_INTEGRATOR_PATHTRACER) {
        sy_result pr = pt_slot(st, req, err);
        if (pr != SY_OK) return pr;
        d.accum = st->slots[st->last_slot].acc;
        d.samples = req->sample_count ? req->sample_count : 1u;
        if (st->filter.kind == PT_FILTER_RADIANCE) return radiance_render(st, req, &cam, &d, layer, err);
    }
    sy_rt_result r = sy_rt_render(st->dev, &cam, &d, layer->rgba, layer->depth, e, sizeof e);
    if (r != SY_RT_OK) return rt_fail(err, r, "render", e);
    if (d.accum) st->counters.last_render_rays = sy_rt_accum_last_rays(d.accum);
    st->frames_rendered++;
    if (d.accum && st->filter.kind != PT_FILTER_NONE) return filter_layer(st, req, layer, err);
    return SY_OK;
}

sy_result sy_mediator_rt_bench_limit(void *state, const sy_camera_view *view, uint32_t background_id, uint32_t width,
                                     uint32_t height, uint32_t samples, uint32_t repeats, sy_mediator_rt_limit *out,
                                     sy_error *err)
{
    rt_state *st = state;
    if (st->integrator != SY_RT_INTEGRATOR_PATHTRACER)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "rt bench limit: the context must be a pathtracer context");
    sy_result lr = apply_look(st, background_id, err);
    if (lr != SY_OK) return lr;
    char e[ERRLEN];
    sy_rt_camera cam;
    camera_of(view, &cam);
    sy_rt_accum *acc = NULL;
    sy_rt_result r = sy_rt_accum_create(width, height, &acc, e, sizeof e);
    sy_rt_render_desc d = {.integrator = SY_RT_INTEGRATOR_PATHTRACER, .image_width = width, .image_height = height,
                           .width = width, .height = height, .max_depth = st->max_depth, .seed = 1u, .accum = acc,
                           .samples = samples};
    sy_rt_limit_result lim;
    if (r == SY_RT_OK) r = sy_rt_bench_limit(st->dev, &cam, &d, repeats, &lim, e, sizeof e);
    sy_rt_accum_destroy(acc);
    if (r != SY_RT_OK) return rt_fail(err, r, "limit benchmark", e);
    _Static_assert(SY_MEDIATOR_RT_LIMIT_FORMS == SY_RT_FORM_COUNT, "one entry per replay form");
    memset(out, 0, sizeof *out);
    out->width = lim.width, out->height = lim.height, out->samples = lim.samples, out->repeats = lim.repeats;
    out->threads = lim.threads;
    out->rays = lim.rays, out->extension_rays = lim.extension_rays, out->shadow_rays = lim.shadow_rays;
    out->intersect_queries = lim.intersect_queries, out->occluded_queries = lim.occluded_queries;
    memcpy(out->frame_seconds, lim.frame_seconds, sizeof out->frame_seconds);
    memcpy(out->form_seconds, lim.form_seconds, sizeof out->form_seconds);
    memcpy(out->share, lim.share, sizeof out->share);
    for (int f = 0; f < SY_RT_FORM_COUNT; ++f) {
        out->mismatches[f] = lim.mismatches[f];
        out->native[f] = lim.native[f];
        out->form_names[f] = sy_rt_ray_form_name((sy_rt_ray_form)f);
    }
    return SY_OK;
}

/* >>class */
static void rt_destroy(void *state)
{
    rt_state *st = state;
    if (!st) return;
    sy_mirror_destroy(st->mirror); /* releases instances, lights and meshes while the device lives */
    for (int i = 0; i < ACCUM_SLOTS; ++i) {
        sy_rt_accum_destroy(st->slots[i].acc);
        sy_filter_pixel_destroy(st->slots[i].pixel);
        sy_radiance_hook_destroy(st->slots[i].radiance);
    }
    for (int k = 0; k <= SY_RT_AOV_COUNT; ++k) free(st->fbuf[k]);
    sy_rt_device_destroy(st->dev);
    free(st->inst_node);
    free(st);
}

static sy_result rt_create_common(const sy_mediator_create_args *args, uint32_t integrator, void **state_out,
                                  sy_error *err)
{
    *state_out = NULL;
    const sy_param_table *t = integrator == SY_RT_INTEGRATOR_WHITTED      ? &whitted_table
                              : integrator == SY_RT_INTEGRATOR_PATHTRACER ? &pt_table
                                                                          : &coverage_table;
    long max_depth = 8, light_samples = 16, threads = 0, spp = 1, env_samples = 4, max_memory_mb = 0; /* spp, env: Whitted's */
    double specular = 1.0;
    sy_result r;
    if (integrator == SY_RT_INTEGRATOR_WHITTED && ((r = sy_param_int(t, args->params, "spp", &spp, err)) ||
                                                   (r = sy_param_int(t, args->params, "env_samples", &env_samples, err))))
        return r;
    if ((r = sy_param_int(t, args->params, "max_depth", &max_depth, err)) ||
        (r = sy_param_int(t, args->params, "light_samples", &light_samples, err)) ||
        (r = sy_param_int(t, args->params, "threads", &threads, err)) ||
        (r = sy_param_float(t, args->params, "specular", &specular, err)) ||
        (r = sy_param_int(t, args->params, "max_memory_mb", &max_memory_mb, err)))
        return r;
    rt_state *st = calloc(1, sizeof *st);
    if (!st) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "rt mediator: out of memory");
    char e[ERRLEN];
    sy_rt_device_desc dd = {(uint32_t)threads, (uint64_t)max_memory_mb << 20};
    sy_rt_result rr = sy_rt_device_create(&dd, &st->dev, e, sizeof e);
    if (rr != SY_RT_OK) {
        free(st);
        return rt_fail(err, rr, "Embree device", e);
    }
    sy_mirror_desc md = {"rt mediator", args->root_node_id, &rt_mirror_callbacks, st};
    if ((r = sy_mirror_create(&md, &st->mirror, err)) != SY_OK) {
        sy_rt_device_destroy(st->dev);
        free(st);
        return r;
    }
    st->integrator = integrator;
    st->max_depth = (uint32_t)max_depth;
    st->light_samples = (uint32_t)light_samples;
    st->pixel_samples = (uint32_t)spp;
    st->env_samples = (uint32_t)env_samples;
    st->specular = (float)specular;
    st->last_slot = -1;
    filter_cfg_default(&st->filter, (uint32_t)threads);
    if (integrator == SY_RT_INTEGRATOR_PATHTRACER && (r = filter_cfg_apply(&st->filter, NULL, args->params, true, err)) != SY_OK) {
        rt_destroy(st);
        return r;
    }
    *state_out = st;
    return SY_OK;
}

static sy_result whitted_create(const sy_mediator_create_args *args, void **state_out, sy_error *err)
{
    return rt_create_common(args, SY_RT_INTEGRATOR_WHITTED, state_out, err);
}

static void rt_stats(void *state, sy_mediator_stats *out)
{
    rt_state *st = state;
    /* Whitted: its camera rays per pixel (spp); the path tracer: its accumulation */
    out->samples = st->frames_rendered ? (st->integrator == SY_RT_INTEGRATOR_WHITTED ? st->pixel_samples : 1) : 0;
    if (st->integrator == SY_RT_INTEGRATOR_PATHTRACER)
        out->samples = st->last_slot >= 0 ? sy_rt_accum_samples(st->slots[st->last_slot].acc) : 0;
}

static sy_result pathtracer_create(const sy_mediator_create_args *args, void **state_out, sy_error *err)
{
    return rt_create_common(args, SY_RT_INTEGRATOR_PATHTRACER, state_out, err);
}


sy_result sy_mediator_rt_aovs_get(void *state, sy_mediator_rt_aovs *out, sy_error *err)
{
    rt_state *st = state;
    memset(out, 0, sizeof *out);
    if (st->integrator != SY_RT_INTEGRATOR_PATHTRACER || st->last_slot < 0)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "AOVs: this context has no path-traced render yet");
    const sy_rt_accum *acc = st->slots[st->last_slot].acc;
    sy_rt_accum_size(acc, &out->width, &out->height);
    out->samples = sy_rt_accum_samples(acc);
    out->nonfinite_samples = sy_rt_accum_nonfinite(acc);
    size_t px = (size_t)out->width * out->height;
    for (int k = 0; k < SY_RT_AOV_COUNT; ++k) {
        float *buf = malloc(px * sy_rt_aov_channels((sy_rt_aov)k) * sizeof(float));
        char e[ERRLEN];
        if (!buf) {
            sy_mediator_rt_aovs_free(out);
            return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "AOVs: out of memory (%ux%u)", out->width, out->height);
        }
        out->planes[k] = buf;
        sy_rt_result r = sy_rt_accum_read(acc, (sy_rt_aov)k, buf, e, sizeof e);
        if (r != SY_RT_OK) {
            sy_mediator_rt_aovs_free(out);
            return rt_fail(err, r, "AOVs", e);
        }
    }
    return SY_OK;
}

void sy_mediator_rt_aovs_free(sy_mediator_rt_aovs *a)
{
    for (int k = 0; k < SY_MEDIATOR_RT_AOV_COUNT; ++k) free(a->planes[k]);
    memset(a, 0, sizeof *a);
}

const char *sy_mediator_rt_aov_name(uint32_t index) { return sy_rt_aov_name((sy_rt_aov)index); }
uint32_t sy_mediator_rt_aov_channels(uint32_t index) { return sy_rt_aov_channels((sy_rt_aov)index); }

/* The generic feature-buffer and filter hooks of the path tracer's class (sy_context_aovs, ...). */
static sy_result pathtracer_aovs(void *state, sy_aovs *out, sy_error *err)
{
    sy_mediator_rt_aovs a;
    memset(out, 0, sizeof *out);
    sy_result r = sy_mediator_rt_aovs_get(state, &a, err);
    if (r != SY_OK) return r;
    out->width = a.width, out->height = a.height;
    out->samples = a.samples, out->nonfinite_samples = a.nonfinite_samples;
    for (uint32_t k = 0; k < SY_MEDIATOR_RT_AOV_COUNT && k < SY_AOVS_MAX; ++k) {
        out->planes[k] = (sy_aov_plane){sy_mediator_rt_aov_name(k), sy_mediator_rt_aov_channels(k), a.planes[k]};
        a.planes[k] = NULL; /* moved */
        out->count = k + 1;
    }
    return SY_OK;
}

static void pathtracer_filter_info(void *state, sy_filter_info *out)
{
    sy_mediator_rt_filter_info fi;
    sy_mediator_rt_filter_info_get(state, &fi);
    snprintf(out->name, sizeof out->name, "%s", fi.name ? fi.name : "none");
    out->threshold = fi.threshold;
    out->frames = fi.frames;
    out->nonfinite_pixels = fi.nonfinite_pixels;
    out->nonfinite_samples = fi.nonfinite_samples;
    out->seconds = fi.seconds;
    out->last_pass_samples = fi.last_pass_samples;
    out->mean_blend = fi.mean_blend;
}

static const sy_mediator_class pathtracer_class = {
    .name = "pathtracer",
    .param_table = SY_PARAM_TABLE(pathtracer_params),
    .caps = SY_CAP_PROGRESSIVE | SY_CAP_DEPTH | SY_CAP_TILES | SY_CAP_SAMPLE_RANGES | SY_CAP_AOVS | SY_CAP_FILTERS,
    .create = pathtracer_create,
    .destroy = rt_destroy,
    .sync = rt_sync,
    .render = rt_render,
    .stats = rt_stats,
    .aovs = pathtracer_aovs,
    .set_filter = sy_mediator_rt_set_filter,
    .filter_info = pathtracer_filter_info,
};

const sy_mediator_class *sy_mediator_rt_pathtracer_class(void) { return &pathtracer_class; }

static const sy_mediator_class whitted_class = {
    .name = "whitted",
    .param_table = SY_PARAM_TABLE(whitted_params),
    .caps = SY_CAP_DEPTH | SY_CAP_TILES | SY_CAP_PREVIEW,
    .create = whitted_create,
    .destroy = rt_destroy,
    .sync = rt_sync,
    .render = rt_render,
    .stats = rt_stats,
    .default_rank = 10, /* the default back-end without the rasterizer */
};

const sy_mediator_class *sy_mediator_rt_whitted_class(void) { return &whitted_class; }

static sy_result coverage_create(const sy_mediator_create_args *args, void **state_out, sy_error *err)
{
    return rt_create_common(args, SY_RT_INTEGRATOR_COVERAGE, state_out, err);
}

static const sy_mediator_class coverage_class = {
    .name = "coverage",
    .param_table = SY_PARAM_TABLE(coverage_params),
    .caps = SY_CAP_DEPTH | SY_CAP_TILES | SY_CAP_ANALYSIS | SY_CAP_COVERAGE,
    .create = coverage_create,
    .destroy = rt_destroy,
    .sync = rt_sync,
    .render = rt_render,
    .stats = rt_stats,
    .coverage = rt_coverage,
};

const sy_mediator_class *sy_mediator_rt_coverage_class(void) { return &coverage_class; }

void sy_mediator_rt_counters_get(void *state, sy_mediator_rt_counters *out)
{
    rt_state *st = state;
    *out = st->counters;
    sy_rt_stats rs;
    sy_rt_device_stats(st->dev, &rs);
    out->mesh_bytes = rs.mesh_bytes;
    out->shared_bytes = rs.shared_bytes;
    out->embree_bytes = rs.embree_bytes;
    out->embree_peak_bytes = rs.embree_peak_bytes;
}

sy_result sy_mediator_rt_register(sy_error *err)
{
    sy_result r = sy_mediator_register(&whitted_class, err);
    if (r == SY_OK) r = sy_mediator_register(&pathtracer_class, err);
    if (r == SY_OK) r = sy_mediator_register(&coverage_class, err);
    return r;
}
