/* sy_mediator_rt_render.c — one render request of the rt adapter (whitted, pathtracer,
 * coverage): look, accumulation, filters; the ray and limit benchmarks
 * (sy_mediator_rt_internal.h). */
#include "sy_mediator_rt_internal.h"

#include "sy_log.h"
#include "sy_rt_bench.h"
#include "sy_rt_limit.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

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

sy_result sy_mediator_rt_bench_rays(void *state, const sy_camera_view *view, uint32_t width, uint32_t height,
                                    uint32_t repeats, sy_mediator_rt_bench *out, sy_error *err)
{
    rt_state *st = state;
    sy_rt_camera cam;
    sy_rti_camera_of(view, &cam);
    sy_rt_bench_result b;
    sy_rt_result r = sy_rt_bench_rays(st->dev, &cam, width, height, repeats, &b);
    if (r != SY_RT_OK) return sy_rti_fail(st, err, r, "ray benchmark");
    out->ours_mrays = b.primary_mrays;
    out->raw_mrays = b.raw_mrays;
    out->overhead_percent = b.overhead_percent;
    out->threads = b.threads;
    return SY_OK;
}

/* Emitters the device's light sampling left out since the last look: one warning naming the
 * light (the device keeps the count and the last message). */
void sy_rti_log_light_warnings(rt_state *st)
{
    sy_rt_stats s;
    sy_rt_device_stats(st->dev, &s);
    if (s.light_warnings == st->light_warnings_seen) return;
    sy_log(SY_LOG_WARNING, "rt", NULL, "%s (%u emitter(s) left out so far)", s.light_warning, s.light_warnings);
    st->light_warnings_seen = s.light_warnings;
}

uint8_t *sy_rti_selection_flags(rt_state *st, const sy_rt_camera *cam, uint32_t full_w, uint32_t full_h,
                                sy_highlight_rect m)
{
    size_t n = (size_t)m.w * m.h;
    uint32_t *ids = malloc((n ? n : 1) * sizeof *ids);
    uint8_t *sel = malloc(n ? n : 1);
    sy_rt_render_desc d = {.image_width = full_w, .image_height = full_h, .x = m.x, .y = m.y, .width = m.w, .height = m.h};
    if (!ids || !sel || (n && sy_rt_coverage(st->dev, cam, &d, ids, NULL) != SY_RT_OK)) {
        free(ids);
        free(sel);
        return NULL;
    }
    for (size_t i = 0; i < n; ++i) sel[i] = sy_rti_inst_selected(st, ids[i]);
    free(ids);
    return sel;
}

static sy_result render_frame(rt_state *st, const sy_render_request *req, sy_layer *layer, sy_error *err);

/* A frame, then the selection highlight (sy_highlight.h) over it when an instance is selected:
 * the ID image of the pixel centres is one coverage pass over the rectangle and its margin. */
sy_result sy_rti_render(void *state, const sy_render_request *req, sy_layer *layer, sy_error *err)
{
    rt_state *st = state;
    sy_result r = render_frame(st, req, layer, err);
    if (r != SY_OK || st->integrator == SY_RT_INTEGRATOR_COVERAGE || !st->inst_sel.live) return r;
    sy_rt_camera cam;
    sy_rti_camera_of(&req->camera, &cam);
    sy_highlight_rect m = sy_highlight_margin(req->full_width, req->full_height, req->rect_x, req->rect_y, req->rect_w,
                                              req->rect_h);
    uint8_t *sel = sy_rti_selection_flags(st, &cam, req->full_width, req->full_height, m);
    if (!sel) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: selection highlight: out of memory or device failure",
                                  st->integrator == SY_RT_INTEGRATOR_PATHTRACER ? "pathtracer" : "whitted");
    sy_highlight_apply(layer->rgba, req->rect_x, req->rect_y, req->rect_w, req->rect_h, sel, m);
    free(sel);
    return SY_OK;
}

static sy_result render_frame(rt_state *st, const sy_render_request *req, sy_layer *layer, sy_error *err)
{
    sy_result lr = sy_rti_apply_look(st, req->background_id, err);
    if (lr != SY_OK) return lr;
    sy_rt_camera cam;
    sy_rti_camera_of(&req->camera, &cam);
    progress_bridge pb = {req->progress, req->progress_user};
    /* a camera moving over the shutter: each camera ray at its own time (the request's camera is the
     * open of one of the moving cameras given: the mono view or a stereo eye) */
    const struct rt_motion_cam *mc = NULL;
    for (uint32_t i = 0; st->motion == MOTION_ON && i < st->motion_cam_count && !mc; ++i)
        if (sy_rti_same_view(&req->camera, &st->motion_cams[i].open)) mc = &st->motion_cams[i];
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
        .time_samples = st->motion_samples,
        .light_tree = (sy_rt_light_tree_mode)st->light_tree,
        .progress = req->progress ? progress_cb : NULL,
        .progress_user_data = &pb,
        .camera_close = mc ? &mc->close : NULL,
        .camera_mid = mc ? mc->mid : NULL,
        .camera_steps = mc ? mc->steps : 0,
    };
    if (st->integrator == SY_RT_INTEGRATOR_WHITTED && req->preview > 0.0f && req->preview < 1.0f) {
        /* an interactive preview (SY_CAP_PREVIEW): the share `preview` of the camera rays and of the
         * area- and environment-light samples per pixel, at least one each (spp=1 is the pixel centre) */
        d.pixel_samples = (uint32_t)fmaxf(1.0f, floorf((float)st->pixel_samples * req->preview + 0.5f));
        /* (light_samples 0, the default: a share of the closed form's 8) */
        d.area_light_samples = (uint32_t)fmaxf(1.0f, floorf((float)(st->light_samples ? st->light_samples : 8u) * req->preview + 0.5f));
        d.env_light_samples = (uint32_t)fmaxf(1.0f, floorf((float)st->env_samples * req->preview + 0.5f));
    }
    if (st->integrator == SY_RT_INTEGRATOR_COVERAGE) return sy_rti_coverage_render(st, &cam, &d, layer, err);
    if (st->integrator == SY_RT_INTEGRATOR_PATHTRACER) {
        sy_result pr = sy_rti_pt_slot(st, req, err);
        if (pr != SY_OK) return pr;
        d.accum = st->slots[st->last_slot].acc;
        d.samples = req->sample_count ? req->sample_count : 1u;
        /* temporal reuse: a moving frame (restarted accumulation, camera or objects moved) samples with a seed
         * of its own, so that the frames' noise is independent and the history averages it (with
         * one seed the noise pattern would stay on the screen and nothing would average out) */
        if (sy_rt_accum_samples(d.accum) == 0 && sy_rti_temporal_moving(st, req))
            d.seed = req->seed ^ (0x9E3779B9u * (uint32_t)(st->finfo.temporal_frames + 1));
        st->last_cam = cam, st->last_desc = d; /* the ID AOVs of this accumulation */
        if (st->filter.kind == PT_FILTER_RADIANCE) return sy_rti_radiance_render(st, req, &cam, &d, layer, err);
    }
    sy_rt_result r = sy_rt_render(st->dev, &cam, &d, layer->rgba, layer->depth);
    if (r != SY_RT_OK) return sy_rti_fail(st, err, r, "render");
    sy_rti_log_light_warnings(st);
    if (d.accum) st->counters.last_render_rays = sy_rt_accum_last_rays(d.accum);
    st->frames_rendered++;
    if (d.accum) { /* temporal reuse on a moving frame replaces the display filter */
        bool done = false;
        sy_result tr = sy_rti_temporal_layer(st, req, d.samples, layer, &done, err);
        if (tr != SY_OK || done) return tr;
    }
    if (d.accum && st->filter.kind != PT_FILTER_NONE) {
        sy_result fr = sy_rti_filter_layer(st, req, layer, err);
        if (fr != SY_OK) return fr;
    }
    if (d.accum) sy_rti_temporal_rest(st, req, layer); /* a resting camera after moving frames */
    return SY_OK;
}

sy_result sy_mediator_rt_bench_limit(void *state, const sy_camera_view *view, uint32_t background_id, uint32_t width,
                                     uint32_t height, uint32_t samples, uint32_t repeats, sy_mediator_rt_limit *out,
                                     sy_error *err)
{
    rt_state *st = state;
    if (st->integrator != SY_RT_INTEGRATOR_PATHTRACER)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "rt bench limit: the context must be a pathtracer context");
    sy_result lr = sy_rti_apply_look(st, background_id, err);
    if (lr != SY_OK) return lr;
    sy_rt_camera cam;
    sy_rti_camera_of(view, &cam);
    sy_rt_accum *acc = NULL;
    sy_rt_result r = sy_rt_accum_create(st->dev, width, height, &acc);
    sy_rt_render_desc d = {.integrator = SY_RT_INTEGRATOR_PATHTRACER, .image_width = width, .image_height = height,
                           .width = width, .height = height, .max_depth = st->max_depth, .seed = 1u, .accum = acc,
                           .samples = samples};
    sy_rt_limit_result lim;
    if (r == SY_RT_OK) r = sy_rt_bench_limit(st->dev, &cam, &d, repeats, &lim);
    sy_rt_accum_destroy(acc);
    if (r != SY_RT_OK) return sy_rti_fail(st, err, r, "limit benchmark");
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
    _Static_assert(SY_MEDIATOR_RT_LIMIT_STAGES == SY_RT_STAGE_COUNT, "one entry per stage");
    for (int k = 0; k < SY_RT_STAGE_COUNT; ++k) {
        out->stage_share[k] = lim.stage_share[k];
        out->stage_ns_per_sample[k] = lim.stage_ns_per_sample[k];
        out->stage_names[k] = sy_rt_stage_name((sy_rt_stage)k);
    }
    out->stage_traversal = SY_RT_STAGE_TRAVERSAL, out->stage_shadow = SY_RT_STAGE_SHADOW;
    out->timed_frame_seconds = lim.timed_frame_seconds;
    out->lap_ticks = lim.lap_ticks, out->lap_ticks_tight = lim.lap_ticks_tight;
    out->stage_laps = lim.stage_laps, out->stage_dropped = lim.stage_dropped;
    return SY_OK;
}
