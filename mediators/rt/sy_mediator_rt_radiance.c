/* sy_mediator_rt_radiance.c — the radiance filter's render: 1-spp passes whose path records
 * feed the radiance filter (sy_radiance_hook.h) (sy_mediator_rt_internal.h). */
#include "sy_mediator_rt_internal.h"


/* >>radiance filter: not a display filter. Every sample of the request is its own 1-spp pass whose
 * path records (the path tracer's stored-sample hook) feed one frame of the radiance filter
 * (sy_radiance_hook.h); the accumulation still receives every sample, so "none" and the other
 * filters show the same samples, and a switch to "radiance" resumes from the accumulation. */
sy_result sy_rti_radiance_render(rt_state *st, const sy_render_request *req, const sy_rt_camera *cam,
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
        if ((r = sy_rti_filter_read_aovs(st, a, req, true, false, err)) != SY_OK) return r;
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
    for (uint32_t i = 0; i < count; ++i) {
        bool last = i + 1 == count;
        d->samples = 1;
        d->records = recs;
        sy_rt_result rr = sy_rt_render(st->dev, cam, d, last ? layer->rgba : NULL, last ? layer->depth : NULL);
        if (rr != SY_RT_OK) {
            sy_radiance_hook_reset(a->radiance);
            return sy_rti_fail(st, err, rr, "render");
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
