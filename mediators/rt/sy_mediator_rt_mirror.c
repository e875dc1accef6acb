/* sy_mediator_rt_mirror.c — the rt adapter's side of the scene mirror (mediators/sy_mirror):
 * its callbacks copy the flat descriptions of textures, materials, meshes, instances and lights
 * (mediators/sy_mirror_flat.h) into Embree back-end calls (what the device does not accept is
 * clamped with a warning), and a sync ends with the device's commit (sy_mediator_rt_internal.h). */
#include "sy_mediator_rt_internal.h"

#include "sy_log.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define RT_HANDLE_INDEX(h) ((h) & 0x3fffffu) /* backends/rt handles: 22-bit slot index */

/* Remembers which node an instance belongs to (node 0 forgets it), keyed by slot index + 1. */
static void inst_node_set(rt_state *st, uint32_t handle, uint32_t node, uint32_t placement)
{
    uint32_t key = RT_HANDLE_INDEX(handle) + 1;
    if (!node) {
        sy_mirror_map_del(&st->inst_node, key);
        sy_mirror_map_del(&st->inst_place, key);
        return;
    }
    uint32_t *n = sy_mirror_map_put(&st->inst_node, key);
    if (n) *n = node; /* out of memory: coverage then reports this instance as unknown (node 0) */
    uint32_t *p = sy_mirror_map_put(&st->inst_place, key);
    if (p) *p = placement;
}

uint32_t sy_rti_inst_placement_get(const rt_state *st, uint32_t handle)
{
    const uint32_t *p = handle ? sy_mirror_map_get(&st->inst_place, RT_HANDLE_INDEX(handle) + 1) : NULL;
    return p ? *p : 0;
}

/* Remembers whether an instance is selected (only selected ones are in the map). */
static void inst_sel_set(rt_state *st, uint32_t handle, bool selected)
{
    uint32_t key = RT_HANDLE_INDEX(handle) + 1;
    if (!selected) {
        sy_mirror_map_del(&st->inst_sel, key);
        return;
    }
    uint8_t *v = sy_mirror_map_put(&st->inst_sel, key);
    if (v) *v = 1; /* out of memory: the instance is drawn without the highlight */
}

bool sy_rti_inst_selected(const rt_state *st, uint32_t handle)
{
    return handle && sy_mirror_map_get(&st->inst_sel, RT_HANDLE_INDEX(handle) + 1) != NULL;
}

uint32_t sy_rti_inst_node_get(const rt_state *st, uint32_t handle)
{
    const uint32_t *n = handle ? sy_mirror_map_get(&st->inst_node, RT_HANDLE_INDEX(handle) + 1) : NULL;
    return n ? *n : 0;
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

/* the flat enumerations are numbered like the back-end's (sy_mirror_flat.h): a cast translates */
SY_MIRROR_FLAT_SAME_NUMBERS(SY_RT);

SY_MIRROR_FLAT_TEXREF_FN(texref, sy_rt_texture_ref)

static sy_result cb_material(void *user, const sy_mirror_material_args *a, sy_error *err)
{
    rt_state *st = user;
    st->sync_other = true; /* not a move (temporal reuse restarts under a still camera) */
    const sy_mirror_flat_material *m = a->flat;
    sy_rt_material_desc d;
    sy_rt_material_desc_init(&d);
    SY_MIRROR_FLAT_MATERIAL_COPY(&d, m, texref);
    static const char *const bc[4] = {"base_color[0]", "base_color[1]", "base_color[2]", "base_color[3] (alpha)"};
    for (int i = 0; i < 4; ++i) d.base_color[i] = clamp_warn(st, "material", a->id, bc[i], m->base_color[i], 0.0f, i == 3 ? 1.0f : INFINITY);
    d.metallic = clamp_warn(st, "material", a->id, "metallic", m->metallic, 0.0f, 1.0f);
    d.roughness = clamp_warn(st, "material", a->id, "roughness", m->roughness, 0.0f, 1.0f);
    for (int i = 0; i < 3; ++i) {
        float v = m->emissive[i];
        d.emissive[i] = isfinite(v) && v >= 0.0f ? v : clamp_warn(st, "material", a->id, "emission", v, 0.0f, 3.0e38f);
    }
    d.transmission = clamp_warn(st, "material", a->id, "transmission", m->transmission, 0.0f, 1.0f);
    d.specular = st->specular * m->specular; /* the mediator's "specular" parameter scales every material's */
    d.alpha_mode = (sy_rt_alpha_mode)m->alpha_mode;
    d.alpha_cutoff = clamp_warn(st, "material", a->id, "alpha_cutoff", m->alpha_cutoff, 0.0f, 1.0f);
    sy_rt_material h = {*a->handle};
    sy_rt_result r = h.id ? sy_rt_material_update(st->dev, h, &d)
                          : sy_rt_material_create(st->dev, &d, &h);
    *a->handle = h.id;
    return r == SY_RT_OK ? SY_OK : sy_rti_fail(st, err, r, "material");
}

static sy_result cb_texture(void *user, const sy_mirror_texture_args *a, sy_error *err)
{
    rt_state *st = user;
    st->sync_other = true;
    const sy_mirror_flat_texture *f = a->flat;
    sy_rt_texture_desc d = {f->width, f->height, f->channels, (sy_rt_texel_format)f->format, f->pixels,
                            (sy_rt_wrap)f->wrap_s, (sy_rt_wrap)f->wrap_t, f->nearest ? SY_RT_FILTER_NEAREST : SY_RT_FILTER_LINEAR};
    sy_rt_texture h = {0};
    sy_rt_result r = sy_rt_texture_create(st->dev, &d, &h);
    *a->handle = h.id;
    return r == SY_RT_OK ? SY_OK : sy_rti_fail(st, err, r, "texture");
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
    st->sync_other = true;
    if (st->motion == MOTION_ARMED) st->motion_other = true; /* made at the open: no pose at the close to move from */
    const sy_primitive *p = a->primitive;
    const sy_mirror_flat_mesh *f = a->flat;
    rt_mesh_blobs *held = malloc(sizeof *held);
    if (!held) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "rt: mesh primitive: out of memory");
    sy_rt_mesh_desc d = {f->positions, f->normals, {f->uv[0], f->uv[1]}, f->colors, f->indices, f->vertex_count,
                         f->triangle_count, rt_mesh_blobs_release, held, sy_mirror_flat_mesh_closed(f)};
    sy_blob *const used[6] = {p->positions, p->normals, p->texcoords0, p->texcoords1, p->colors, p->indices};
    for (int k = 0; k < 6; ++k) held->b[k] = sy_blob_retain(used[k]);
    sy_rt_mesh h = {0};
    sy_rt_result r = sy_rt_mesh_create(st->dev, &d, &h);
    if (r != SY_RT_OK) rt_mesh_blobs_release(held); /* a failed create keeps nothing */
    *a->handle = h.id;
    return r == SY_RT_OK ? SY_OK : sy_rti_fail(st, err, r, "mesh primitive");
}

/* A deformed pose of a primitive made by cb_primitive: its vertices rewritten and its BVH refitted
 * (sy_rt_mesh_update); the blobs cb_primitive holds stay until the mesh goes. In the sync at a
 * shutter's open (motion armed) the pose it had (the close's) becomes its pose at ray time 1 and the
 * new one its pose at time 0: Embree interpolates the vertices per ray (sy_rt_mesh_update_motion). */
static sy_result cb_primitive_update(void *user, const sy_mirror_primitive_args *a, sy_error *err)
{
    rt_state *st = user;
    sy_rt_mesh h = {*a->handle};
    sy_rti_temporal_deform_record(st, h.id); /* temporal reuse: its pose at the last render, before it changes */
    /* more than two steps: this sync's step (the close kept from the first deformation on) */
    sy_rt_result r = st->motion != MOTION_ARMED ? sy_rt_mesh_update(st->dev, h, a->flat->positions, a->flat->normals)
                     : st->motion_steps > 2u
                         ? sy_rt_mesh_update_steps(st->dev, h, st->motion_steps, st->motion_k, a->flat->positions, a->flat->normals)
                         : sy_rt_mesh_update_motion(st->dev, h, a->flat->positions, a->flat->normals);
    if (r == SY_RT_OK && st->motion == MOTION_ARMED) st->motion_meshes++;
    return r == SY_RT_OK ? SY_OK : sy_rti_fail(st, err, r, "mesh primitive update");
}

static sy_result cb_instance(void *user, const sy_mirror_instance_args *a, sy_error *err)
{
    rt_state *st = user;
    sy_rt_instance h = {*a->handle};
    sy_rt_result r;
    if (!h.id) {
        sy_rt_instance_desc d = {.mesh = {a->mesh},
                                 .material = {a->material},
                                 .flags = (a->baked ? SY_RT_INSTANCE_BAKED : 0u) | (a->visible ? 0u : SY_RT_INSTANCE_HIDDEN)};
        memcpy(d.transform, a->world->m, sizeof d.transform);
        st->sync_other = true;
        r = sy_rt_instance_create(st->dev, &d, &h);
        *a->handle = h.id;
        if (r == SY_RT_OK) inst_node_set(st, h.id, a->node, a->placement), inst_sel_set(st, h.id, a->selected);
        return r == SY_RT_OK ? SY_OK : sy_rti_fail(st, err, r, "instance");
    }
    float close[16];
    bool had = sy_rt_instance_get_transform(st->dev, h, close) == SY_RT_OK;
    bool moving = st->motion == MOTION_ARMED && had && memcmp(close, a->world->m, sizeof close) != 0;
    if (had && st->filter.temporal && memcmp(close, a->world->m, sizeof close) != 0 &&
        !sy_mirror_map_get(&st->temporal_from, h.id)) {
        /* temporal reuse: its first move since the last render; where it was then (no memory for
         * it: a change that is not a move, the history restarts under a still camera) */
        rt_move_rec *mr = sy_mirror_map_put(&st->temporal_from, h.id);
        if (mr) memcpy(mr->prev, close, sizeof close);
        else st->sync_other = true;
    }
    if (moving && st->motion_steps > 2u) { /* curved motion: this step's placement, applied at the open */
        rt_motion_rec *rec = sy_mirror_map_get(&st->motion_rec, h.id);
        if (!rec) { /* its first move since the close: where it was until now is every later step */
            if (!(rec = sy_mirror_map_put(&st->motion_rec, h.id)))
                return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "motion: out of memory for the steps of %u instances",
                                    st->motion_rec.live + 1u);
            for (uint32_t k = st->motion_k + 1u; k < st->motion_steps; ++k) memcpy(rec->xf[k], close, sizeof close);
        }
        for (uint32_t k = 0; k <= st->motion_k; ++k) memcpy(rec->xf[k], a->world->m, sizeof close); /* until it moves again */
        moving = false;
    }
    r = sy_rt_instance_set_transform(st->dev, h, a->world->m);
    if (r == SY_RT_OK && moving) { /* motion blur: from here (the open) to where it was synced (the close) */
        r = sy_rt_instance_set_motion(st->dev, h, close);
        if (r == SY_RT_OK) st->motion_instances++;
    }
    if (r == SY_RT_OK) r = sy_rt_instance_set_visible(st->dev, h, a->visible);
    if (r == SY_RT_OK) inst_sel_set(st, h.id, a->selected);
    return r == SY_RT_OK ? SY_OK : sy_rti_fail(st, err, r, "instance transform");
}

static sy_result cb_light(void *user, const sy_mirror_light_args *a, sy_error *err)
{
    rt_state *st = user;
    st->sync_other = true;
    if (st->motion == MOTION_ARMED) st->motion_other = true; /* a light moved over the shutter: not interpolated */
    const sy_mirror_flat_light *l = a->flat;
    sy_rt_light_desc d;
    memset(&d, 0, sizeof d);
    d.type = (sy_rt_light_type)l->type;
    static const char *const cn[3] = {"color[0]", "color[1]", "color[2]"};
    for (int i = 0; i < 3; ++i) d.color[i] = clamp_warn(st, "light of node", a->node, cn[i], l->color[i], 0.0f, 3.0e38f);
    d.intensity = clamp_warn(st, "light of node", a->node, "intensity", l->intensity, 0.0f, 3.0e38f);
    d.range = clamp_warn(st, "light of node", a->node, "range", l->range, 0.0f, 3.0e38f);
    if (d.type == SY_RT_LIGHT_SPOT) {
        d.outer_cone_angle = clamp_warn(st, "light of node", a->node, "outer_cone", l->outer_cone, 0.0f, 1.5707963f);
        d.inner_cone_angle = clamp_warn(st, "light of node", a->node, "inner_cone", l->inner_cone, 0.0f, d.outer_cone_angle);
    }
    memcpy(d.position, l->position, sizeof d.position);
    memcpy(d.direction, l->direction, sizeof d.direction);
    sy_rt_light h = {*a->handle};
    sy_rt_result r = h.id ? sy_rt_light_update(st->dev, h, &d) : sy_rt_light_create(st->dev, &d, &h);
    *a->handle = h.id;
    return r == SY_RT_OK ? SY_OK : sy_rti_fail(st, err, r, "light");
}

static void cb_release(void *user, const sy_mirror_release_args *a)
{
    rt_state *st = user;
    st->sync_other = true;
    switch (a->kind) {
    case SY_MIRROR_TEXTURE: sy_rt_texture_destroy(st->dev, (sy_rt_texture){a->handle}); break;
    case SY_MIRROR_MATERIAL: sy_rt_material_destroy(st->dev, (sy_rt_material){a->handle}); break;
    case SY_MIRROR_PRIMITIVE: sy_rt_mesh_destroy(st->dev, (sy_rt_mesh){a->handle}); break;
    case SY_MIRROR_INSTANCE:
        inst_node_set(st, a->handle, 0, 0);
        inst_sel_set(st, a->handle, false);
        sy_mirror_map_del(&st->motion_rec, a->handle); /* gone before the open: no steps to give it */
        sy_mirror_map_del(&st->temporal_from, a->handle);
        sy_rt_instance_destroy(st->dev, (sy_rt_instance){a->handle});
        break;
    case SY_MIRROR_LIGHT: sy_rt_light_destroy(st->dev, (sy_rt_light){a->handle}); break;
    }
}

const sy_mirror_callbacks sy_rti_mirror_callbacks = {
    .texture_set = cb_texture,
    .material_set = cb_material,
    .primitive_set = cb_primitive,
    .instance_set = cb_instance,
    .light_set = cb_light,
    .release = cb_release,
    .primitive_update = cb_primitive_update,
};

/* >>motion blur (SY_CAP_MOTION) */
sy_result sy_rti_motion(void *state, sy_motion_phase phase, uint32_t time_samples, bool *native, sy_error *err)
{
    rt_state *st = state;
    switch (phase) {
    case SY_MOTION_BEGIN:
        st->motion = MOTION_ARMED;
        st->motion_samples = time_samples;
        st->motion_other = false;
        st->motion_instances = 0;
        st->motion_meshes = 0;
        st->motion_steps = 2;
        st->motion_k = 0;
        sy_mirror_map_free(&st->motion_rec);
        return SY_OK;
    case SY_MOTION_STEPS:
        if (st->motion != MOTION_ARMED || time_samples < 3u || time_samples > SY_MOTION_STEPS_MAX)
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "motion: %u time steps (3 .. %u, after begin)", time_samples,
                                SY_MOTION_STEPS_MAX);
        st->motion_steps = time_samples;
        st->motion_k = time_samples - 2u; /* the close (step steps - 1) is synced */
        return SY_OK;
    case SY_MOTION_STEP:
        if (st->motion != MOTION_ARMED || st->motion_k == 0)
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "motion: a time step past the open");
        st->motion_k--;
        return SY_OK;
    case SY_MOTION_OPENED:
        if (st->motion != MOTION_ARMED) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "motion: not begun");
        if (st->motion_steps > 2u && st->motion_k != 0)
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "motion: opened with %u time steps not synced", st->motion_k);
        /* curved motion: every instance that moved gets its steps (step 0, the open, is its transform) */
        for (uint32_t s = 0; st->motion_steps > 2u && s < st->motion_rec.cap; ++s) {
            rt_motion_rec *rec = sy_mirror_map_slot(&st->motion_rec, s);
            if (!rec) continue;
            sy_rt_result r = sy_rt_instance_set_motion_steps(st->dev, (sy_rt_instance){st->motion_rec.keys[s]},
                                                             st->motion_steps, rec->xf[1]);
            if (r != SY_RT_OK) return sy_rti_fail(st, err, r, "motion open");
            st->motion_instances++;
        }
        sy_mirror_map_free(&st->motion_rec);
        if (st->motion_steps > 2u) {
            sy_rt_result r = sy_rt_commit(st->dev);
            if (r != SY_RT_OK) return sy_rti_fail(st, err, r, "motion open");
        }
        st->motion = MOTION_ON;
        if (native) *native = !st->motion_other;
        return SY_OK;
    case SY_MOTION_END: {
        bool had = st->motion != MOTION_OFF;
        st->motion = MOTION_OFF;
        st->motion_samples = 0;
        st->motion_cam_count = 0;
        st->motion_steps = 2;
        sy_mirror_map_free(&st->motion_rec);
        if (!had) return SY_OK;
        sy_rt_result r = sy_rt_motion_clear(st->dev);
        if (r == SY_RT_OK) r = sy_rt_commit(st->dev); /* a device with staged changes refuses to render */
        return r == SY_RT_OK ? SY_OK : sy_rti_fail(st, err, r, "motion end");
    }
    }
    return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "motion: unknown phase %d", (int)phase);
}

sy_result sy_rti_motion_camera(void *state, const sy_camera_view *open, uint32_t steps, const sy_camera_view *later,
                               sy_error *err)
{
    rt_state *st = state;
    if (st->motion != MOTION_ON) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "motion camera: the motion is not open");
    if (steps < 2u || steps > SY_MOTION_STEPS_MAX)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "motion camera: %u steps (2 .. %u)", steps, SY_MOTION_STEPS_MAX);
    uint32_t i = 0; /* the same open camera again: replaced; another: one more (a stereo render's eyes) */
    while (i < st->motion_cam_count && !sy_rti_same_view(&st->motion_cams[i].open, open)) ++i;
    if (i == SY_MOTION_CAMERAS_MAX)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "motion camera: more than %u moving cameras", SY_MOTION_CAMERAS_MAX);
    struct rt_motion_cam *mc = &st->motion_cams[i];
    mc->open = *open;
    mc->steps = steps;
    for (uint32_t k = 0; k + 2u < steps; ++k) sy_rti_camera_of(&later[k], &mc->mid[k]);
    sy_rti_camera_of(&later[steps - 2u], &mc->close); /* checked by the render (sy_rt_frame_init) */
    if (i == st->motion_cam_count) st->motion_cam_count++;
    return SY_OK;
}

/* >>sync */
sy_result sy_rti_sync(void *state, const sy_changes *changes, sy_error *err)
{
    rt_state *st = state;
    sy_rt_stats s;
    sy_rt_device_stats(st->dev, &s);
    uint64_t v0 = s.version;
    st->sync_other = false;
    sy_mirror_sync_stats ms;
    sy_result r = sy_mirror_sync(st->mirror, changes, &ms, err);
    SY_MIRROR_SYNC_COUNTERS(st->counters, ms);
    st->counters.last_sync_refit_seconds = ms.update_seconds;
    /* The device tracks what is staged (sy_rt_commit is a no-op on a clean device), so every
     * successful sync ends with a commit: an uncommitted device refuses to render. */
    if (r == SY_OK) {
        sy_rt_result rr = sy_rt_commit(st->dev);
        if (rr != SY_RT_OK) r = sy_rti_fail(st, err, rr, "commit");
    }
    sy_rt_device_stats(st->dev, &s);
    /* temporal reuse: a sync that published moves only (instance transforms or visibility, deformed
     * vertices) extends the run of such versions, or starts one; anything else ends it */
    if (s.version != v0) {
        if (r != SY_OK || st->sync_other) st->move_from = st->move_to = 0;
        else {
            if (st->move_to != v0) st->move_from = v0;
            st->move_to = s.version;
        }
    }
    st->counters.instances = s.instances;
    st->counters.meshes = s.meshes;
    st->counters.materials = s.materials;
    st->counters.textures = s.textures;
    st->counters.lights = s.lights;
    st->counters.last_sync_top_commit_seconds = s.last_top_commit_seconds;
    return r;
}
