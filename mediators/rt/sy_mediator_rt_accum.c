/* sy_mediator_rt_accum.c — the path tracer's accumulation slots: one accumulation per
 * distinct request, restarted when the device published a change (sy_mediator_rt_internal.h). */
#include "sy_mediator_rt_internal.h"

#include <string.h>

/* >>pathtracer accumulation */
bool sy_rti_same_view(const sy_camera_view *a, const sy_camera_view *b)
{
    return !memcmp(a->camera_to_world.m, b->camera_to_world.m, sizeof a->camera_to_world.m) &&
           a->projection == b->projection && !memcmp(a->window, b->window, sizeof a->window) && a->znear == b->znear &&
           a->zfar == b->zfar && a->clip_count == b->clip_count &&
           !memcmp(a->clip_planes, b->clip_planes, a->clip_count * sizeof a->clip_planes[0]) &&
           a->clip_cap == b->clip_cap && (!a->clip_cap || !memcmp(a->clip_cap_color, b->clip_cap_color, sizeof a->clip_cap_color));
}

/* Picks (or recycles) the accumulation slot of a request and restarts it when the scene, the
 * camera or anything else about the request changed; sets st->last_slot. */
sy_result sy_rti_pt_slot(rt_state *st, const sy_render_request *req, sy_error *err)
{
    sy_rt_stats ds;
    sy_rt_device_stats(st->dev, &ds);
    const uint32_t rect[4] = {req->rect_x, req->rect_y, req->rect_w, req->rect_h};
    int found = -1, lru = 0;
    for (int i = 0; i < ACCUM_SLOTS; ++i) {
        accum_slot *a = &st->slots[i];
        if (a->acc && a->full_w == req->full_width && a->full_h == req->full_height && !memcmp(a->rect, rect, sizeof rect) &&
            a->bg == req->background_id && a->seed == req->seed && sy_rti_same_view(&a->camera, &req->camera)) {
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
            sy_rt_accum_destroy(a->acc);
            a->acc = NULL;
            sy_rt_result r = sy_rt_accum_create(st->dev, req->rect_w, req->rect_h, &a->acc);
            if (r != SY_RT_OK) return sy_rti_fail(st, err, r, "accumulation buffer");
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

/* sy_context_restart (every class of the adapter): every slot's next request restarts it (no device
 * version is UINT64_MAX, so sy_rti_pt_slot takes it for a change and resets the accumulation, the
 * pixel filter and the radiance hook as after any visible change). */
void sy_rti_pt_restart(void *state)
{
    rt_state *st = state;
    for (int i = 0; i < ACCUM_SLOTS; ++i)
        if (st->slots[i].acc) st->slots[i].version = UINT64_MAX;
    /* and the moves of the next sync placed as a fresh device places them (sy_rt_settle): without
     * it a moved instance's hits differ from a fresh render's in the last bits; only out of memory
     * fails, and then the fast path still shows the scene right */
    (void)sy_rt_settle(st->dev);
}
