/* sy_mediator_rt_filter.c — the path tracer's display filters (backends/filters): their
 * configuration from the class's parameters, sy_mediator_rt_set_filter, and the filtered layer
 * from the accumulation's feature buffers (sy_mediator_rt_internal.h). */
#include "sy_mediator_rt_internal.h"

#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static const char *const pt_filter_names[PT_FILTER_KIND_COUNT] = {"none", "pixel", "atrous", "jbu", "adaptive",
                                                                   "radiance"};

/* >>display filters
 * The path tracer's layer can be filtered for display (backends/filters) from the accumulation's
 * feature buffers. Parameters (creation and sy_mediator_rt_set_filter): filter, threshold, sigma_s,
 * sigma_c, sigma_d, filter_kernel, filter_iterations, filter_start, atrous_iterations, jbu_factor,
 * temporal (temporal reuse on frames whose camera moved: sy_rti_temporal_layer below), temporal_motion
 * (and on frames whose instances moved, following them), temporal_deform (and deforming meshes). */
/* Every code a filter returns has core's number (the cast in sy_backend_fail). */
SY_BACKEND_SAME_CODE(SY_FILTER_ERROR_INVALID_ARGUMENT, SY_ERR_INVALID_ARGUMENT);
SY_BACKEND_SAME_CODE(SY_FILTER_ERROR_OUT_OF_MEMORY, SY_ERR_OUT_OF_MEMORY);

static sy_result filter_fail(sy_error *err, const sy_filter_report *fe)
{
    return sy_backend_fail(err, (int)fe->code, "pathtracer filter", NULL, fe->message);
}

void sy_rti_filter_cfg_default(pt_filter_cfg *c, uint32_t threads)
{
    memset(c, 0, sizeof *c);
    c->kind = PT_FILTER_NONE;
    c->temporal_motion = true;
    c->temporal_deform = true;
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
    sy_result r = sy_param_float(&sy_rti_pt_table, p, key, &x, err);
    if (r == SY_OK) *v = (float)x;
    return r;
}

static sy_result pt_u32(const sy_params *p, bool all, const char *key, uint32_t *v, sy_error *err)
{
    if (!all && !sy_params_get(p, key)) return SY_OK;
    long x = (long)*v;
    sy_result r = sy_param_int(&sy_rti_pt_table, p, key, &x, err);
    if (r == SY_OK) *v = (uint32_t)x;
    return r;
}

static sy_result pt_bool(const sy_params *p, bool all, const char *key, bool *v, sy_error *err)
{
    return !all && !sy_params_get(p, key) ? SY_OK : sy_param_bool(&sy_rti_pt_table, p, key, v, err);
}

static sy_result pt_enum(const sy_params *p, bool all, const char *key, uint32_t *v, sy_error *err)
{
    return !all && !sy_params_get(p, key) ? SY_OK : sy_param_enum(&sy_rti_pt_table, p, key, v, err);
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
sy_result sy_rti_filter_cfg_apply(pt_filter_cfg *base, const char *name, const sy_params *p_in, bool all, sy_error *err)
{
    static const sy_params empty;
    const sy_params *p = p_in ? p_in : &empty;
    pt_filter_cfg c = *base;
    sy_result r;
    uint32_t kind = (uint32_t)c.kind;
    if (name) {
        const sy_param_decl *d = sy_param_find(&sy_rti_pt_table, "filter");
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
        (r = pt_u32(p, all, "jbu_factor", &c.jbu.factor, err)) || (r = radiance_cfg_apply(&c.radiance, p, all, err)) ||
        (r = pt_bool(p, all, "temporal", &c.temporal, err)) ||
        (r = pt_bool(p, all, "temporal_motion", &c.temporal_motion, err)) ||
        (r = pt_bool(p, all, "temporal_deform", &c.temporal_deform, err)))
        return r;
    c.pixel.threshold = c.adaptive.threshold = c.radiance.threshold = threshold;
    c.pixel.kernel = fkernel ? SY_FILTER_PIXEL_BRUTE : SY_FILTER_PIXEL_SEPARABLE;
    /* the rf_* options are checked whatever the filter; T_u = threshold only matters for radiance */
    sy_filter_radiance_params rq = c.radiance;
    if (c.kind != PT_FILTER_RADIANCE && !(rq.threshold > 0.0f)) rq.threshold = 0.01f;
    sy_filter_report fe = {0};
    if (sy_filter_pixel_params_check(&c.pixel, &fe) || sy_filter_atrous_params_check(&c.atrous, &fe) ||
        sy_filter_jbu_params_check(&c.jbu, &fe) ||
        (c.kind == PT_FILTER_ADAPTIVE && sy_filter_adaptive_params_check(&c.adaptive, &fe)) ||
        sy_filter_radiance_params_check(&rq, &fe))
        return filter_fail(err, &fe);
    *base = c;
    return SY_OK;
}

/* Frees the deforming meshes' earlier poses (temporal reuse's per-vertex motion). */
static void deform_free(rt_state *st)
{
    for (uint32_t i = 0; i < st->temporal_deform.cap; ++i) {
        rt_deform_rec *d = sy_mirror_map_slot(&st->temporal_deform, i);
        if (d) free(d->prev);
    }
    sy_mirror_map_free(&st->temporal_deform);
    st->temporal_fresh = 0;
}

/* >>per-vertex motion
 * Before a deforming mesh's vertices are rewritten (cb_primitive_update), its pose at the last
 * render is copied from the device, once per render: on its first update since (while temporal,
 * temporal_motion and temporal_deform are on). Memory only for meshes that deform: a record not
 * refreshed over a render is freed at the end of the next (sy_rti_temporal_layer), and a record
 * keeps its buffer from one render to the next while its mesh deforms. Out of memory: the change
 * counts as one that is not a move (the history restarts under a still camera). */
void sy_rti_temporal_deform_record(rt_state *st, uint32_t mesh)
{
    if (!st->filter.temporal || !st->filter.temporal_motion || !st->filter.temporal_deform) return;
    rt_deform_rec *d = sy_mirror_map_get(&st->temporal_deform, mesh);
    if (d && d->fresh) return; /* deformed again since the last render: its pose then is kept */
    sy_rt_mesh_view v;
    if (sy_rt_mesh_get_view(st->dev, (sy_rt_mesh){mesh}, &v) != SY_RT_OK || !v.positions) return;
    if (!d && !(d = sy_mirror_map_put(&st->temporal_deform, mesh))) {
        st->sync_other = true;
        return;
    }
    if (d->vertex_count != v.vertex_count || !d->prev) {
        free(d->prev);
        d->vertex_count = v.vertex_count;
        if (!(d->prev = malloc((size_t)v.vertex_count * 3u * sizeof(float) + 1u))) {
            sy_mirror_map_del(&st->temporal_deform, mesh);
            st->sync_other = true;
            return;
        }
    }
    memcpy(d->prev, v.positions, (size_t)v.vertex_count * 3u * sizeof(float));
    d->fresh = true;
    st->temporal_fresh++;
}

/* After a render: records not refreshed since the render before go (their meshes stopped
 * deforming); the fresh ones become stale, their buffers kept for the next copy. */
static void deform_age(rt_state *st)
{
    if (!st->temporal_deform.live) return;
    for (uint32_t i = 0; i < st->temporal_deform.cap; ++i) {
        rt_deform_rec *d = sy_mirror_map_slot(&st->temporal_deform, i);
        if (!d) continue;
        if (d->fresh) {
            d->fresh = false;
            continue;
        }
        free(d->prev);
        sy_mirror_map_del(&st->temporal_deform, st->temporal_deform.keys[i]);
    }
    st->temporal_fresh = 0;
    if (!st->temporal_deform.live) sy_mirror_map_free(&st->temporal_deform);
}

sy_result sy_mediator_rt_set_filter(void *state, const char *name, const sy_params *opts, sy_error *err)
{
    rt_state *st = state;
    if (st->integrator != SY_RT_INTEGRATOR_PATHTRACER)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "set filter: only the pathtracer class has display filters");
    /* the same check core makes (sy_context_set_filter), for callers of this function */
    sy_result r = sy_params_check(&sy_rti_pt_table, opts, SY_PARAM_LIVE, "back-end 'pathtracer'", NULL, err);
    if (r != SY_OK) return r;
    pt_filter_cfg c = st->filter;
    r = sy_rti_filter_cfg_apply(&c, name, opts, false, err);
    if (r != SY_OK) return r;
    /* Only the threshold acts on the blend alone; anything else invalidates the filtered buffers,
     * which are recomputed at the next frame (the accumulation itself is never touched). */
    sy_filter_pixel_params a = st->filter.pixel, b = c.pixel;
    a.threshold = b.threshold = 0.0f;
    bool refilter = c.kind != st->filter.kind || memcmp(&a, &b, sizeof a) != 0;
    for (int i = 0; i < ACCUM_SLOTS; ++i) {
        accum_slot *s = &st->slots[i];
        if (!s->pixel) continue;
        sy_filter_report fe = {0};
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
    if (!c.temporal) { /* off: the next time it is turned on starts from nothing */
        sy_filter_temporal_reset(st->temporal);
        st->temporal_have_cam = false;
        sy_mirror_map_free(&st->temporal_from); /* and no moves are recorded while it is off */
    }
    if (!c.temporal || !c.temporal_motion || !c.temporal_deform) deform_free(st); /* nor earlier poses */
    st->filter = c;
    return SY_OK;
}

void sy_mediator_rt_filter_info_get(void *state, sy_mediator_rt_filter_info *out)
{
    rt_state *st = state;
    *out = st->finfo;
    out->name = pt_filter_names[st->filter.kind];
    out->threshold = st->filter.pixel.threshold;
    out->temporal = st->filter.temporal;
}

/* World positions of the first hits of rows [y0, y1) of the rectangle's pixels from the camera-axis
 * depth (the a-trous guide and the headlight of the pixel filter's range buffer); misses go 1e18
 * away. ucol: each column's window x (column_u). */
static void filter_positions(const sy_render_request *req, const float *ucol, const float *depth, float *pos,
                             uint32_t y0, uint32_t y1)
{
    const sy_camera_view *v = &req->camera;
    const float *m = v->camera_to_world.m;
    bool ortho = v->projection == SY_PROJECTION_ORTHOGRAPHIC;
    for (uint32_t y = y0; y < y1; ++y) {
        float w = v->window[3] - (v->window[3] - v->window[2]) * ((float)(req->rect_y + y) + 0.5f) / (float)req->full_height;
        for (uint32_t x = 0; x < req->rect_w; ++x) {
            size_t i = (size_t)y * req->rect_w + x;
            float u = ucol[x];
            float d = depth[i];
            if (!isfinite(d)) d = 1e18f;
            float c[3] = {ortho ? u : u * d, ortho ? w : w * d, -d};
            for (int k = 0; k < 3; ++k) pos[3 * i + k] = m[k] * c[0] + m[4 + k] * c[1] + m[8 + k] * c[2] + m[12 + k];
        }
    }
}

/* the window x of the rectangle's column centres (filter_positions) */
static void column_u(const sy_render_request *req, float *ucol)
{
    const sy_camera_view *v = &req->camera;
    for (uint32_t x = 0; x < req->rect_w; ++x)
        ucol[x] = v->window[0] + (v->window[1] - v->window[0]) * ((float)(req->rect_x + x) + 0.5f) / (float)req->full_width;
}

/* the rows of sy_rti_filter_read_aovs: the feature buffers in one pass, then the positions */
typedef struct read_rows_ctx {
    const sy_rt_accum *acc;
    const sy_render_request *req;
    float *out[SY_RT_AOV_COUNT];
    float *pos;        /* NULL: none */
    const float *ucol; /* column_u */
    _Atomic int failed;
} read_rows_ctx;

static void read_rows(void *vc, uint32_t y0, uint32_t y1)
{
    read_rows_ctx *c = vc;
    if (sy_rt_accum_read_rows(NULL, c->acc, y0, y1, c->out) != SY_RT_OK) {
        atomic_store(&c->failed, 1);
        return;
    }
    if (c->pos) filter_positions(c->req, c->ucol, c->out[SY_RT_AOV_DEPTH], c->pos, y0, y1);
}

/* Reads the slot's feature buffers (rect_w x rect_h) into st->fbuf (the filters' inputs): the variance
 * only with `variance`, the world positions (fbuf[SY_RT_AOV_COUNT]) with `positions`. One pass over
 * the accumulation, rows split over the filters' threads. */
sy_result sy_rti_filter_read_aovs(rt_state *st, const accum_slot *a, const sy_render_request *req, bool variance,
                                  bool positions, sy_error *err)
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
    uint32_t aw, ah;
    sy_rt_accum_size(a->acc, &aw, &ah);
    if (aw != req->rect_w || ah != req->rect_h) /* the slot is the request's rectangle (sy_rti_pt_slot) */
        return sy_error_set(err, SY_ERR_BACKEND, "pathtracer filter: feature buffers of %ux%u for a %ux%u rectangle",
                            aw, ah, req->rect_w, req->rect_h);
    if (positions && req->rect_w > st->fcol_cap) {
        free(st->fcol);
        st->fcol = malloc(req->rect_w * sizeof *st->fcol);
        st->fcol_cap = st->fcol ? req->rect_w : 0;
        if (!st->fcol)
            return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "pathtracer filter: out of memory for %ux%u", req->rect_w,
                                req->rect_h);
    }
    if (positions) column_u(req, st->fcol);
    read_rows_ctx c = {.acc = a->acc, .req = req, .pos = positions ? st->fbuf[SY_RT_AOV_COUNT] : NULL, .ucol = st->fcol};
    for (int k = 0; k < SY_RT_AOV_COUNT; ++k) c.out[k] = k == SY_RT_AOV_VARIANCE && !variance ? NULL : st->fbuf[k];
    atomic_init(&c.failed, 0);
    sy_filter_parallel_rows(st->filter.atrous.threads, ah, read_rows, &c);
    if (atomic_load(&c.failed)) /* not reached: the rows lie in the accumulation */
        return sy_error_set(err, SY_ERR_BACKEND, "pathtracer filter: feature buffers: rows outside the accumulation");
    return SY_OK;
}

/* Filters the layer the path tracer just wrote (rectangle of the slot st->last_slot). */
/* The slot's AOVs read into the scratch planes, world positions made from depth, and the filter
 * frame over them (every filter, the temporal stage included, reads what it needs of it). */
static sy_result read_frame(rt_state *st, accum_slot *a, const sy_render_request *req, uint32_t samples, bool variance,
                            sy_filter_frame *f, sy_error *err)
{
    sy_result rd = sy_rti_filter_read_aovs(st, a, req, variance, true, err);
    if (rd != SY_OK) return rd;
    const float *m = req->camera.camera_to_world.m;
    *f = (sy_filter_frame){
        .width = req->rect_w,
        .height = req->rect_h,
        .color_channels = 4,
        .variance_channels = 3,
        .color = st->fbuf[SY_RT_AOV_COLOR],
        .variance = variance ? st->fbuf[SY_RT_AOV_VARIANCE] : NULL,
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
    return SY_OK;
}

sy_result sy_rti_filter_layer(rt_state *st, const sy_render_request *req, sy_layer *layer, sy_error *err)
{
    accum_slot *a = &st->slots[st->last_slot];
    uint32_t samples = sy_rt_accum_samples(a->acc);
    sy_filter_frame f;
    sy_result rd = read_frame(st, a, req, samples, true, &f, err);
    if (rd != SY_OK) return rd;
    sy_filter_stats fs = {0};
    sy_filter_report fe = {0};
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

void sy_rti_temporal_rest(rt_state *st, const sy_render_request *req, sy_layer *layer)
{
    if (!st->temporal_rest || !st->temporal) return;
    uint32_t n = sy_rt_accum_samples(st->slots[st->last_slot].acc);
    st->finfo.temporal_rest_last =
        sy_filter_temporal_rest(st->temporal, req->rect_w, req->rect_h, layer->rgba, n, layer->rgba);
}

/* >>temporal reuse
 * The camera of a render request as sy_filter_temporal's world_to_pixel: a homogeneous world point
 * to (x w, y w, *, w) with (x, y) continuous pixel coordinates of the request's rectangle (row 0 at
 * the top) and w the camera-axis distance (perspective) or 1 (orthographic). false when the camera
 * matrix cannot be inverted or the window is empty. */
static bool world_to_pixel(const sy_render_request *req, float out[16])
{
    const sy_camera_view *v = &req->camera;
    sy_mat4 inv;
    if (!sy_mat4_invert(&v->camera_to_world, &inv)) return false;
    float ww = v->window[1] - v->window[0], wh = v->window[3] - v->window[2];
    if (!(ww != 0.0f && wh != 0.0f)) return false;
    float sx = (float)req->full_width / ww, sy = (float)req->full_height / wh;
    float k0 = -v->window[0] * sx - (float)req->rect_x, k1 = v->window[3] * sy - (float)req->rect_y;
    bool ortho = v->projection == SY_PROJECTION_ORTHOGRAPHIC;
    for (int col = 0; col < 4; ++col) {
        const float *V = inv.m + 4 * col; /* V[r] = row r of the world-to-camera matrix, this column */
        float wv = ortho ? (col == 3 ? 1.0f : 0.0f) : -V[2];
        out[4 * col + 0] = sx * V[0] + k0 * wv;
        out[4 * col + 1] = -sy * V[1] + k1 * wv;
        out[4 * col + 2] = V[2];
        out[4 * col + 3] = wv;
    }
    for (int k = 0; k < 16; ++k)
        if (!isfinite(out[k])) return false;
    return true;
}

/* Whether the device changed since the last render only by moves (sy_rti_sync's run of versions
 * move_from .. move_to), and temporal_motion follows them. */
static bool objects_moved(const rt_state *st)
{
    sy_rt_stats ds;
    sy_rt_device_stats(st->dev, &ds);
    return st->filter.temporal_motion && st->temporal_have_cam && ds.version != st->temporal_version &&
           ds.version == st->move_to && st->temporal_version >= st->move_from;
}

bool sy_rti_temporal_moving(const rt_state *st, const sy_render_request *req)
{
    if (!st->filter.temporal || !st->temporal_have_cam) return false;
    return !sy_rti_same_view(&st->temporal_cam, &req->camera) || objects_moved(st);
}

/* >>object motion
 * The per-pixel motion of this render's first hits (sy_filter_frame.motion, q = p + motion): which
 * instance each pixel centre's camera ray hits (sy_rt_coverage: one ray per pixel, the ray of the ID
 * AOVs), and for an instance moved since the last render (st->temporal_from, recorded by the sync)
 * motion = M_prev M_now^-1 p - p at the pixel's world position p (the filter's, from the mean
 * depth). A deformed (skinned, morphed) mesh's pixels (temporal_deform; its pose at the last render
 * in st->temporal_deform, >>per-vertex motion above): the same rays give the triangle and its
 * barycentrics (sy_rt_coverage_hits, only for renders with such meshes: the rigid case keeps the
 * cheaper ids), and motion = M_prev x_prev - M_now x_now, x_prev and x_now the hit's barycentric
 * point on the triangle's earlier and present vertices (M_prev = M_now when the instance did not
 * move). Instances neither moved nor deformed, and misses, get 0; with temporal_deform=0 deformed
 * meshes get 0 too (their history rejected where the surface left the depth or normal tolerance,
 * clamped elsewhere). An instance whose matrix cannot be inverted gets NaN (no history) at its
 * rigidly moved pixels. *any false (no motion plane: the camera's motion alone) when nothing moved;
 * *pixels counts the pixels that moved, *deformed those of them given per-vertex motion. */
typedef struct motion_run { /* what the pixels of one instance share (looked up when the id changes) */
    const rt_move_rec *mr;     /* moved since the last render, or NULL */
    const rt_deform_rec *dr;   /* its mesh deformed since the last render, or NULL */
    sy_rt_mesh_view now;       /* dr: the mesh's present vertices */
    sy_mat4 xf, prev;          /* dr: its matrix now and at the last render */
} motion_run;

static void motion_run_get(rt_state *st, uint32_t id, bool deform, motion_run *run)
{
    run->dr = NULL;
    rt_move_rec *r = id ? sy_mirror_map_get(&st->temporal_from, id) : NULL;
    if (r && !r->ready) { /* to_prev = prev now^-1, NaN when now has no inverse */
        sy_mat4 now, inv, prev;
        r->ready = true;
        if (sy_rt_instance_get_transform(st->dev, (sy_rt_instance){id}, now.m) == SY_RT_OK && sy_mat4_invert(&now, &inv)) {
            memcpy(prev.m, r->prev, sizeof prev.m);
            r->to_prev = sy_mat4_mul(&prev, &inv);
        } else {
            for (int k = 0; k < 16; ++k) r->to_prev.m[k] = NAN;
        }
    }
    run->mr = r;
    sy_rt_mesh mesh;
    if (!deform || !id || sy_rt_instance_get_mesh(st->dev, (sy_rt_instance){id}, &mesh) != SY_RT_OK) return;
    const rt_deform_rec *d = sy_mirror_map_get(&st->temporal_deform, mesh.id);
    if (!d || !d->fresh || sy_rt_mesh_get_view(st->dev, mesh, &run->now) != SY_RT_OK ||
        run->now.vertex_count != d->vertex_count ||
        sy_rt_instance_get_transform(st->dev, (sy_rt_instance){id}, run->xf.m) != SY_RT_OK)
        return;
    if (r) memcpy(run->prev.m, r->prev, sizeof run->prev.m);
    else run->prev = run->xf;
    run->dr = d;
}

/* x = M (b0 p[i0] + u p[i1] + v p[i2]) */
static inline void bary_point(const sy_mat4 *m, const float *p, const uint32_t *ix, float u, float v, float x[3])
{
    float b0 = 1.0f - u - v, o[3];
    const float *a = p + 3u * ix[0], *b = p + 3u * ix[1], *c = p + 3u * ix[2];
    for (int k = 0; k < 3; ++k) o[k] = b0 * a[k] + u * b[k] + v * c[k];
    sy_mat4_transform_point(m, o, x);
}

static sy_result object_motion(rt_state *st, const sy_render_request *req, const float *pos, bool *any,
                               uint64_t *pixels, uint64_t *deformed, sy_error *err)
{
    *any = false, *pixels = 0, *deformed = 0;
    bool deform = st->filter.temporal_deform && st->temporal_fresh > 0;
    if (!st->filter.temporal_motion || (!st->temporal_from.live && !deform)) return SY_OK;
    size_t n = (size_t)req->rect_w * req->rect_h;
    if (n > st->motion_px) {
        free(st->motion_ids), free(st->motion_buf);
        st->motion_ids = malloc(n * sizeof *st->motion_ids);
        st->motion_buf = malloc(n * 3 * sizeof *st->motion_buf);
        st->motion_px = st->motion_ids && st->motion_buf ? n : 0;
        if (!st->motion_px)
            return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "pathtracer temporal: out of memory for the motion of %ux%u",
                                req->rect_w, req->rect_h);
    }
    if (deform && n > st->motion_hits_px) {
        free(st->motion_hits);
        st->motion_hits = malloc(n * sizeof *st->motion_hits);
        st->motion_hits_px = st->motion_hits ? n : 0;
        if (!st->motion_hits)
            return sy_error_set(err, SY_ERR_OUT_OF_MEMORY,
                                "pathtracer temporal: out of memory for the deformed meshes' motion of %ux%u", req->rect_w,
                                req->rect_h);
    }
    const sy_rt_render_desc *ld = &st->last_desc; /* this render's camera and rectangle */
    sy_rt_render_desc d = {.image_width = ld->image_width, .image_height = ld->image_height, .x = ld->x, .y = ld->y,
                           .width = ld->width, .height = ld->height};
    const sy_rt_coverage_hit *hits = deform ? st->motion_hits : NULL;
    double t0 = sy_time_now();
    sy_rt_result rr = deform ? sy_rt_coverage_hits(st->dev, &st->last_cam, &d, st->motion_hits)
                             : sy_rt_coverage(st->dev, &st->last_cam, &d, st->motion_ids, NULL);
    if (rr != SY_RT_OK) return sy_rti_fail(st, err, rr, "pathtracer temporal: object motion");
    st->finfo.temporal_motion_trace_seconds = sy_time_now() - t0;
    float *mv = st->motion_buf;
    uint32_t last_id = 0;
    motion_run run = {0};
    for (size_t i = 0; i < n; ++i) {
        uint32_t id = hits ? hits[i].instance : st->motion_ids[i];
        if (id != last_id) {
            last_id = id;
            motion_run_get(st, id, deform, &run);
        }
        float *o = mv + 3 * i;
        if (run.dr) { /* per vertex: the hit point at the earlier pose, through the earlier matrix */
            const sy_rt_coverage_hit *h = &hits[i];
            if (h->triangle < run.now.triangle_count) {
                const uint32_t *ix = run.now.indices + 3u * h->triangle;
                float a[3], b[3];
                bary_point(&run.prev, run.dr->prev, ix, h->u, h->v, a);
                bary_point(&run.xf, run.now.positions, ix, h->u, h->v, b);
                for (int k = 0; k < 3; ++k) o[k] = a[k] - b[k];
            } else {
                o[0] = o[1] = o[2] = 0.0f;
            }
            if (o[0] != 0.0f || o[1] != 0.0f || o[2] != 0.0f) ++*pixels, ++*deformed;
            continue;
        }
        if (!run.mr) {
            o[0] = o[1] = o[2] = 0.0f;
            continue;
        }
        const float *p = pos + 3 * i;
        sy_mat4_transform_point(&run.mr->to_prev, p, o);
        for (int k = 0; k < 3; ++k) o[k] -= p[k];
        if (o[0] != 0.0f || o[1] != 0.0f || o[2] != 0.0f) ++*pixels;
    }
    *any = true;
    return SY_OK;
}

static sy_result temporal_frame(rt_state *st, const sy_render_request *req, uint32_t samples, bool moved,
                                sy_layer *layer, bool *done, sy_error *err);

void sy_rti_temporal_free(rt_state *st)
{
    sy_filter_temporal_destroy(st->temporal);
    sy_mirror_map_free(&st->temporal_from);
    deform_free(st);
    free(st->motion_ids);
    free(st->motion_buf);
    free(st->motion_hits);
}

sy_result sy_rti_temporal_layer(rt_state *st, const sy_render_request *req, uint32_t samples, sy_layer *layer,
                                bool *done, sy_error *err)
{
    *done = false;
    st->finfo.temporal_last = false, st->finfo.temporal_rest_last = false;
    st->temporal_rest = false;
    st->finfo.temporal_motion_seconds = 0.0, st->finfo.temporal_moving_pixels = 0;
    st->finfo.temporal_deformed_pixels = 0, st->finfo.temporal_motion_trace_seconds = 0.0;
    if (!st->filter.temporal) return SY_OK;
    bool objects = objects_moved(st);
    bool moved = st->temporal_have_cam && (!sy_rti_same_view(&st->temporal_cam, &req->camera) || objects);
    st->temporal_cam = req->camera;
    st->temporal_have_cam = true;
    sy_rt_stats ds;
    sy_rt_device_stats(st->dev, &ds);
    st->temporal_version = ds.version;
    sy_result r = temporal_frame(st, req, samples, moved, layer, done, err);
    /* this render's transforms are the next one's previous ones */
    if (st->temporal_from.live) sy_mirror_map_free(&st->temporal_from);
    deform_age(st); /* and its deformed poses the next one's earlier ones */
    return r;
}

static double seconds_between(const struct timespec *a, const struct timespec *b)
{
    return (double)(b->tv_sec - a->tv_sec) + 1e-9 * (double)(b->tv_nsec - a->tv_nsec);
}

static sy_result temporal_frame(rt_state *st, const sy_render_request *req, uint32_t samples, bool moved,
                                sy_layer *layer, bool *done, sy_error *err)
{
    accum_slot *a = &st->slots[st->last_slot];
    if (!moved && st->temporal) {
        /* a still camera: an accumulation that continues blends with the last estimate; one that
         * restarted (the scene changed under the camera) makes the history and estimate stale */
        if (sy_rt_accum_samples(a->acc) > samples) st->temporal_rest = true;
        else sy_filter_temporal_reset(st->temporal);
    }
    /* a still camera, or an accumulation that kept earlier samples: the accumulation as it is */
    if (!moved || sy_rt_accum_samples(a->acc) > samples) return SY_OK;
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    float m[16];
    if (!world_to_pixel(req, m)) { /* a degenerate camera: nothing to reproject with */
        sy_filter_temporal_reset(st->temporal);
        return SY_OK;
    }
    sy_filter_report fe = {0};
    if (!st->temporal) {
        sy_filter_temporal_params p;
        sy_filter_temporal_params_default(&p);
        p.threads = st->filter.atrous.threads;
        if (sy_filter_temporal_create(&p, &st->temporal, &fe)) return filter_fail(err, &fe);
    }
    sy_filter_frame f;
    struct timespec tr0, tm0, tm1;
    clock_gettime(CLOCK_MONOTONIC, &tr0);
    sy_result rd = read_frame(st, a, req, samples, false, &f, err); /* the stage reads no variance */
    if (rd != SY_OK) return rd;
    clock_gettime(CLOCK_MONOTONIC, &tm0);
    st->finfo.temporal_read_seconds = seconds_between(&tr0, &tm0);
    bool any = false;
    uint64_t moving = 0, deformed = 0;
    if ((rd = object_motion(st, req, f.position, &any, &moving, &deformed, err)) != SY_OK) return rd;
    if (any) f.motion = st->motion_buf;
    clock_gettime(CLOCK_MONOTONIC, &tm1);
    st->finfo.temporal_motion_seconds = any ? seconds_between(&tm0, &tm1) : 0.0;
    st->finfo.temporal_moving_pixels = moving;
    st->finfo.temporal_deformed_pixels = deformed;
    sy_filter_temporal_stats ts = {0};
    if (sy_filter_temporal_run(st->temporal, &f, m, layer->rgba, &ts, &fe)) return filter_fail(err, &fe);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    uint64_t hits = ts.reprojected + ts.disoccluded;
    st->finfo.temporal_last = true;
    st->finfo.temporal_frames++;
    st->finfo.temporal_seconds = seconds_between(&t0, &t1);
    st->finfo.temporal_filter_cpu_seconds = ts.cpu_seconds;
    st->finfo.temporal_filter_seconds = ts.seconds;
    memcpy(st->finfo.temporal_phase_seconds, ts.phase_seconds, sizeof ts.phase_seconds);
    st->finfo.temporal_reused = hits ? (double)ts.reprojected / (double)hits : 0.0;
    *done = true;
    return SY_OK;
}
