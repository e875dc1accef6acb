/* sy_mediator_rt.c — core scene -> Embree back-end adapter (see sy_mediator_rt.h): its classes
 * (whitted, pathtracer, coverage): create, destroy, stats, AOVs, counters and registration. The
 * modules under it, bottom-up, are listed in sy_mediator_rt_internal.h:
 *   sy_mediator_rt_base.c      parameter tables, error and camera translation
 *   sy_mediator_rt_mirror.c    >>mirror callbacks (the scene mirror is mediators/sy_mirror), >>sync
 *   sy_mediator_rt_coverage.c  coverage
 *   sy_mediator_rt_accum.c     >>pathtracer accumulation
 *   sy_mediator_rt_filter.c    >>display filters
 *   sy_mediator_rt_radiance.c  >>radiance filter
 *   sy_mediator_rt_look.c      >>look
 *   sy_mediator_rt_render.c    >>render
 *   sy_mediator_rt.c           >>class */
#include "sy_mediator_rt_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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
    free(st->fcol);
    sy_rti_temporal_free(st);
    sy_rt_device_destroy(st->dev);
    sy_mirror_map_free(&st->inst_node);
    sy_mirror_map_free(&st->motion_rec);
    sy_mirror_map_free(&st->inst_sel);
    sy_mirror_map_free(&st->inst_place);
    free(st);
}

static sy_result rt_create_common(const sy_mediator_create_args *args, uint32_t integrator, void **state_out,
                                  sy_error *err)
{
    *state_out = NULL;
    const sy_param_table *t = integrator == SY_RT_INTEGRATOR_WHITTED      ? &sy_rti_whitted_table
                              : integrator == SY_RT_INTEGRATOR_PATHTRACER ? &sy_rti_pt_table
                                                                          : &sy_rti_coverage_table;
    long max_depth = 8, light_samples = 16, threads = 0, spp = 1, env_samples = 4, max_memory_mb = 0; /* spp, env: Whitted's */
    double specular = 1.0;
    uint32_t light_tree = 0;
    sy_result r;
    if (integrator != SY_RT_INTEGRATOR_COVERAGE && (r = sy_param_enum(t, args->params, "light_tree", &light_tree, err)))
        return r;
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
    st->inst_node = SY_MIRROR_MAP_INIT(uint32_t);
    st->motion_rec = SY_MIRROR_MAP_INIT(rt_motion_rec);
    st->motion_steps = 2;
    st->inst_sel = SY_MIRROR_MAP_INIT(uint8_t);
    st->inst_place = SY_MIRROR_MAP_INIT(uint32_t);
    st->temporal_from = SY_MIRROR_MAP_INIT(rt_move_rec);
    st->temporal_deform = SY_MIRROR_MAP_INIT(rt_deform_rec);
    sy_rt_device_desc dd = sy_rti_device_desc(st, (uint32_t)threads, (uint64_t)max_memory_mb << 20);
    sy_rt_result rr = sy_rt_device_create(&dd, &st->dev);
    if (rr != SY_RT_OK) {
        r = sy_rti_fail(st, err, rr, "Embree device");
        free(st);
        return r;
    }
    sy_mirror_desc md = {"rt mediator", args->root_node_id, &sy_rti_mirror_callbacks, st};
    if ((r = sy_mirror_create(&md, &st->mirror, err)) != SY_OK) {
        sy_rt_device_destroy(st->dev);
        free(st);
        return r;
    }
    st->integrator = integrator;
    st->max_depth = (uint32_t)max_depth;
    st->light_samples = (uint32_t)light_samples;
    st->light_tree = light_tree;
    st->pixel_samples = (uint32_t)spp;
    st->env_samples = (uint32_t)env_samples;
    st->specular = (float)specular;
    st->last_slot = -1;
    sy_rti_filter_cfg_default(&st->filter, (uint32_t)threads);
    if (integrator == SY_RT_INTEGRATOR_PATHTRACER && (r = sy_rti_filter_cfg_apply(&st->filter, NULL, args->params, true, err)) != SY_OK) {
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
        if (!buf) {
            sy_mediator_rt_aovs_free(out);
            return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "AOVs: out of memory (%ux%u)", out->width, out->height);
        }
        out->planes[k] = buf;
        sy_rt_result r = sy_rt_accum_read(st->dev, acc, (sy_rt_aov)k, buf);
        if (r != SY_RT_OK) {
            sy_mediator_rt_aovs_free(out);
            return sy_rti_fail(st, err, r, "AOVs");
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

/* The ID planes of the last accumulation's rectangle: "object_id" (the node id, 0 where nothing is
 * hit) and "instance_id" (which of the node's placements) of the nearest visible surface through
 * each pixel's centre: the ray and the numbers of a pick (sy_context_pick). */
static sy_result pathtracer_id_aovs(rt_state *st, sy_aovs *out, sy_error *err)
{
    const sy_rt_render_desc *ld = &st->last_desc;
    if (out->count + 2 > SY_AOVS_MAX || ld->width != out->width || ld->height != out->height) return SY_OK;
    size_t n = (size_t)out->width * out->height;
    uint32_t *ids = malloc((n ? n : 1) * sizeof *ids);
    float *obj = malloc((n ? n : 1) * sizeof *obj), *ins = malloc((n ? n : 1) * sizeof *ins);
    sy_rt_render_desc d = {.image_width = ld->image_width, .image_height = ld->image_height, .x = ld->x, .y = ld->y,
                           .width = ld->width, .height = ld->height};
    sy_rt_result r = ids && obj && ins ? sy_rt_coverage(st->dev, &st->last_cam, &d, ids, NULL) : SY_RT_ERROR_OUT_OF_MEMORY;
    if (r != SY_RT_OK) {
        free(ids), free(obj), free(ins);
        sy_aovs_free(out);
        return r == SY_RT_ERROR_OUT_OF_MEMORY ? sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "AOVs: ID planes: out of memory")
                                              : sy_rti_fail(st, err, r, "AOVs: ID planes");
    }
    for (size_t i = 0; i < n; ++i) {
        obj[i] = (float)sy_rti_inst_node_get(st, ids[i]);
        ins[i] = (float)sy_rti_inst_placement_get(st, ids[i]);
    }
    free(ids);
    out->planes[out->count++] = (sy_aov_plane){"object_id", 1, obj};
    out->planes[out->count++] = (sy_aov_plane){"instance_id", 1, ins};
    return SY_OK;
}

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
    return pathtracer_id_aovs(state, out, err);
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

/* A class of this adapter: its name, parameter table and create (the integrator it sets up); what
 * the three share: one device, one mirror, one way to sync, render, pick and restart. */
#define RT_CLASS(NAME, PARAMS, CREATE)                                                                                 \
    .name = NAME, .param_table = SY_PARAM_TABLE(PARAMS), .create = CREATE, .destroy = rt_destroy,                    \
    .sync = sy_rti_sync, .render = sy_rti_render, .stats = rt_stats, .pick = sy_rti_pick, .restart = sy_rti_pt_restart

static const sy_mediator_class pathtracer_class = {
    RT_CLASS("pathtracer", sy_rti_pathtracer_params, pathtracer_create),
    .caps = SY_CAP_PROGRESSIVE | SY_CAP_DEPTH | SY_CAP_TILES | SY_CAP_SAMPLE_RANGES | SY_CAP_AOVS | SY_CAP_FILTERS | SY_CAP_PICK | SY_CAP_CLIP | SY_CAP_MOTION,
    .aovs = pathtracer_aovs,
    .set_filter = sy_mediator_rt_set_filter,
    .filter_info = pathtracer_filter_info,
    .motion = sy_rti_motion,
    .motion_camera = sy_rti_motion_camera,
};

const sy_mediator_class *sy_mediator_rt_pathtracer_class(void) { return &pathtracer_class; }

static const sy_mediator_class whitted_class = {
    RT_CLASS("whitted", sy_rti_whitted_params, whitted_create),
    .caps = SY_CAP_DEPTH | SY_CAP_TILES | SY_CAP_PREVIEW | SY_CAP_PICK | SY_CAP_CLIP | SY_CAP_MOTION,
    .default_rank = 10, /* the default back-end without the rasterizer */
    .motion = sy_rti_motion,
    .motion_camera = sy_rti_motion_camera,
};

const sy_mediator_class *sy_mediator_rt_whitted_class(void) { return &whitted_class; }

static sy_result coverage_create(const sy_mediator_create_args *args, void **state_out, sy_error *err)
{
    return rt_create_common(args, SY_RT_INTEGRATOR_COVERAGE, state_out, err);
}

static const sy_mediator_class coverage_class = {
    RT_CLASS("coverage", sy_rti_coverage_params, coverage_create),
    .caps = SY_CAP_DEPTH | SY_CAP_TILES | SY_CAP_ANALYSIS | SY_CAP_COVERAGE | SY_CAP_PICK | SY_CAP_CLIP,
    .coverage = sy_rti_coverage,
};

const sy_mediator_class *sy_mediator_rt_coverage_class(void) { return &coverage_class; }

void sy_mediator_rt_set_top_fast(void *state, bool on)
{
    rt_state *st = state;
    sy_rt_set_top_fast(st->dev, on);
}

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
    out->light_tree_lights = rs.light_tree_lights;
    out->light_tree_bytes = rs.light_tree_bytes;
    out->light_tree_build_seconds = rs.light_tree_build_seconds;
    out->light_tree_refit_seconds = rs.light_tree_refit_seconds;
    out->light_tree_refit_changed = rs.light_tree_refit_changed;
    out->light_tree_builds = rs.light_tree_builds;
    out->light_tree_refits = rs.light_tree_refits;
}

sy_result sy_mediator_rt_register(sy_error *err)
{
    sy_result r = sy_mediator_register(&whitted_class, err);
    if (r == SY_OK) r = sy_mediator_register(&pathtracer_class, err);
    if (r == SY_OK) r = sy_mediator_register(&coverage_class, err);
    return r;
}
