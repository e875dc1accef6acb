/* sy_render_passes.c — a progressive back-end's passes and motion blur for `sy render`; see
 * sy_render_passes.h. */
#include "sy_render_passes.h"
#include "sy_signals.h"
#include "sy_testpoint.h"

#include "sy_log.h"
#include "sy_mediators.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* >>progressive (path tracer): sample budget, environment, feature buffers */
typedef struct pt_progress {
    double start;
    uint64_t done, total; /* samples per pixel; total 0 = time budget */
    double budget;
} pt_progress;

static void pt_progress_print(const pt_progress *p, bool final)
{
    double el = sy_time_now() - p->start, rate = el > 0 ? (double)p->done / el : 0;
    if (final) {
        fprintf(stderr, "\r%*s\r", 78, "");
    } else if (p->total) {
        double eta = rate > 0 ? (double)(p->total - p->done) / rate : 0;
        fprintf(stderr, "\rpathtracer: %llu/%llu samples, %.2f samples/s, %.1f s, ETA %.1f s   ",
                (unsigned long long)p->done, (unsigned long long)p->total, rate, el, eta);
    } else {
        fprintf(stderr, "\rpathtracer: %llu samples, %.2f samples/s, %.1f s, ETA %.1f s   ", (unsigned long long)p->done,
                rate, el, fmax(0.0, p->budget - el));
    }
    fflush(stderr);
}

/* Renders a progressive back-end in passes until the sample count or the time budget is reached,
 * through the same window composition as a single-pass render (overlays and stereo included).
 * *out / *out_right get the final images; *samples_out the samples per pixel accumulated by the
 * main back-end; *ctx_out its (pool-owned) context. A sequence restarts the accumulation before each
 * frame (sy_context_restart), so the passes are counted from 0. */
sy_result sy_cli_render_progressive(loaded *ld, const sy_compose_spec *spec, uint32_t w, uint32_t h, const sy_cli_pt_opts *po,
                                    sy_context_pool *pool, sy_layer *out, sy_layer *out_right, double *seconds,
                                    uint64_t *samples_out, sy_context **ctx_out, sy_error *err)
{
    sy_params pp;
    sy_result r = sy_params_parse(spec->params, &pp, err);
    uint64_t target = po->spp ? po->spp : (po->time_budget > 0 ? 0 : 64);
    pt_progress pr = {sy_time_now(), 0, target, po->time_budget};
    bool tty = sy_is_terminal(2);
    double t0 = sy_time_now(), last_print = 0;
    uint32_t chunk = 1;
    while (r == SY_OK) {
        uint64_t left = target ? target - pr.done : UINT32_MAX;
        uint32_t n = (uint32_t)(left < chunk ? left : chunk);
        double p0 = sy_time_now();
        sy_window_render_opts ro = {.sample_count = n, .seed = po->seed};
        sy_layer_destroy(out);
        sy_layer_destroy(out_right);
        r = sy_compose_render(ld->scene, pool, spec, w, h, &ro, out, out_right, err);
        if (r != SY_OK) break;
        pr.done += n;
        /* the samples the back-end actually holds (a cooperative cluster adds them in multiples of its
         * server count) */
        sy_context *mc = NULL;
        sy_mediator_stats ms = {0};
        if (sy_context_pool_get(pool, ld->scene, spec->backend, &pp, ld->root.id, &mc, err) == SY_OK) {
            sy_context_stats(mc, &ms);
            if (ms.samples > pr.done) pr.done = ms.samples;
        }
        double now = sy_time_now(), pass = (now - p0) / n;
        if (tty && now - last_print > 0.1) {
            pt_progress_print(&pr, false);
            last_print = now;
        }
        if (target && pr.done >= target) break;
        if (po->time_budget > 0 && now - t0 + pass > po->time_budget) break;
        sy_testpoint("pass"); /* a pass is done and the graceful interrupt armed (tests wait for it) */
        if (sy_signals_interrupted()) break; /* first Ctrl-C: keep what the finished passes gave */
        /* passes of about a quarter of a second: responsive progress, little overhead */
        double want = pass > 0 ? 0.25 / pass : 64;
        chunk = want < 1 ? 1 : want > 1024 ? 1024 : (uint32_t)want;
        if (po->time_budget > 0) {
            double rest = (po->time_budget - (now - t0)) / (pass > 0 ? pass : 1e-3);
            if (rest < chunk) chunk = rest < 1 ? 1 : (uint32_t)rest;
        }
    }
    *seconds = sy_time_now() - t0;
    if (tty) pt_progress_print(&pr, true);
    sy_context *ctx = NULL;
    if (r == SY_OK) r = sy_context_pool_get(pool, ld->scene, spec->backend, &pp, ld->root.id, &ctx, err);
    if (r == SY_OK) {
        sy_mediator_stats st = {0};
        sy_context_stats(ctx, &st);
        *samples_out = st.samples;
        *ctx_out = ctx;
    }
    return r;
}

/* >>motion blur (--shutter, --motion-blur): the mean of the scene over the shutter interval

 * One render per time sample of the shutter (sy_shutter_time: the midpoints of equal strata), the
 * scene clock set and committed before each (the moved nodes and deformed meshes reach every
 * back-end as ordinary changes, so every consumer's change lists stay consistent), each render with
 * its own sampling seed (independent noise), accumulated here for every back-end: the rasterizer's
 * and Whitted's images are the mean of the sub-frames; the path tracer's samples are split over the
 * time samples (spp / N each, the remainder to the first ones; a --time budget likewise) and weighted
 * by the samples each holds, so every pixel sample has one time and the times are stratified. The
 * depth plane keeps the nearest depth seen during the exposure. The scene is left at the frame's
 * time. *samples_out: the samples per pixel in all (progressive) or the time samples; sh->samples
 * becomes spp when a progressive back-end has fewer samples than time samples. */
static void restart_main(loaded *ld, sy_context_pool *pool, const sy_compose_spec *spec)
{
    sy_params rp;
    sy_context *rc = NULL;
    sy_error ignore = {0};
    if (sy_params_parse(spec->params, &rp, &ignore) == SY_OK &&
        sy_context_pool_get(pool, ld->scene, spec->backend, &rp, ld->root.id, &rc, &ignore) == SY_OK)
        sy_context_restart(rc);
}

static void blur_add(sy_layer *acc, const sy_layer *l, float weight)
{
    size_t n = (size_t)acc->width * acc->height;
    for (size_t k = 0; k < 4 * n; ++k) acc->rgba[k] += weight * l->rgba[k];
    for (size_t k = 0; k < n; ++k)
        if (l->depth[k] < acc->depth[k]) acc->depth[k] = l->depth[k];
}

/* >>--shutter-steps chosen from the motion (no --shutter-steps given): the largest angle that any node
 * an animation channel moves (translation, rotation or scale: its world matrix, so a parent's turn
 * counts for the node it carries, and every node below it turns as much) or the camera turns through
 * over the shutter, summed over MOTION_PROBES - 1 equal parts of it (the scene committed at each probe
 * time; a turn of more than half a revolution within one part is undercounted), in chords of at most
 * MOTION_CHORD_DEG degrees: steps = 1 + ceil(angle / MOTION_CHORD_DEG), 2 to SY_MOTION_STEPS_MAX. A
 * translation or a deformation turns nothing: 2, the linear protocol, bit for bit. A spinning wheel's
 * quarter turn: 9 steps, so it blurs along its arc. The scene is left at the last probe (the close):
 * the caller sets the times it renders. *angle_out: the angle in radians. */
#define MOTION_PROBES 17u
#define MOTION_CHORD_DEG 12.0
/* the rotation of a matrix's upper 3x3, each column normalised (scale removed); false for a degenerate one */
static bool rotation_of(const sy_mat4 *m, double r[9])
{
    for (int c = 0; c < 3; ++c) {
        double x = m->m[4 * c], y = m->m[4 * c + 1], z = m->m[4 * c + 2], l = sqrt(x * x + y * y + z * z);
        if (!(l > 1e-12) || !isfinite(l)) return false;
        r[3 * c] = x / l, r[3 * c + 1] = y / l, r[3 * c + 2] = z / l;
    }
    return true;
}
/* the angle of the rotation that takes a to b (radians, 0..pi) */
static double rotation_angle(const double a[9], const double b[9])
{
    double tr = 0; /* trace(b a^T) = the element-wise product's sum */
    for (int k = 0; k < 9; ++k) tr += a[k] * b[k];
    double c = (tr - 1.0) / 2.0;
    return acos(c > 1.0 ? 1.0 : c < -1.0 ? -1.0 : c);
}
static uint32_t motion_steps_auto(loaded *ld, const char *clip, double frame_time, const sy_shutter *sh,
                                  const sy_compose_spec *spec, uint32_t w, uint32_t h, double *angle_out)
{
    *angle_out = 0.0;
    size_t n = 0, cap = 0;
    uint32_t *nodes = NULL; /* the nodes that channels move (once per channel) */
    for (uint32_t id = sy_scene_next(ld->scene, SY_TYPE_ANIMATION, 0); id; id = sy_scene_next(ld->scene, SY_TYPE_ANIMATION, id)) {
        uint32_t nch = 0;
        const sy_anim_channel *ch = sy_animation_channels(sy_animation_get(ld->scene, (sy_animation){id}), &nch);
        for (uint32_t k = 0; k < nch; ++k) {
            if (sy_anim_path_target(ch[k].path) != SY_TYPE_NODE || ch[k].path == SY_ANIM_WEIGHTS) continue;
            if (n == cap) {
                size_t nc = cap ? 2 * cap : 16;
                uint32_t *g = realloc(nodes, nc * sizeof *g);
                if (!g) {
                    free(nodes);
                    return 2; /* out of memory: the linear protocol */
                }
                nodes = g, cap = nc;
            }
            nodes[n++] = ch[k].node;
        }
    }
    double *prev = n ? malloc(n * 10 * sizeof *prev) : NULL; /* per node: 9 rotation elements, 1 valid flag */
    double *swept = n ? calloc(n, sizeof *swept) : NULL;
    double cam_prev[9], cam_swept = 0.0;
    bool cam_valid = false;
    if (n && (!prev || !swept)) n = 0; /* out of memory: the camera alone */
    for (uint32_t p = 0; p < MOTION_PROBES; ++p) {
        sy_error e = {0};
        if (sy_cli_set_time(ld, clip, frame_time + sh->open + (sh->close - sh->open) * p / (MOTION_PROBES - 1u), &e)) break;
        for (size_t i = 0; i < n; ++i) {
            sy_mat4 m;
            double r[9];
            bool ok = sy_node_world_matrix(ld->scene, (sy_node){nodes[i]}, &m, &e) == SY_OK && rotation_of(&m, r);
            if (ok && p > 0 && prev[10 * i + 9] > 0) swept[i] += rotation_angle(&prev[10 * i], r);
            if (ok) memcpy(&prev[10 * i], r, sizeof r);
            prev[10 * i + 9] = ok;
        }
        sy_camera_view v;
        double r[9];
        bool ok = sy_compose_camera_view(ld->scene, spec, w, h, &v, &e) == SY_OK && rotation_of(&v.camera_to_world, r);
        if (ok && cam_valid) cam_swept += rotation_angle(cam_prev, r);
        if (ok) memcpy(cam_prev, r, sizeof r);
        cam_valid = ok;
    }
    double angle = cam_swept;
    for (size_t i = 0; i < n; ++i)
        if (swept[i] > angle) angle = swept[i];
    free(nodes);
    free(prev);
    free(swept);
    *angle_out = angle;
    double chords = ceil(angle * (180.0 / 3.14159265358979323846) / MOTION_CHORD_DEG - 1e-9);
    if (!(chords >= 1.0)) return 2;
    return chords + 1.0 >= SY_MOTION_STEPS_MAX ? SY_MOTION_STEPS_MAX : (uint32_t)chords + 1u;
}

/* The view of each of the n_eyes eyes (1: the mono view; 2: the left and the right eye) of spec's main
 * viewport at w x h, the scene as committed now, into out[0 .. n_eyes - 1]. */
static bool eye_views(const loaded *ld, const sy_compose_spec *spec, uint32_t n_eyes, uint32_t w, uint32_t h,
                      sy_camera_view *out, sy_error *e)
{
    if (n_eyes == 1u) return sy_compose_eye_view(ld->scene, spec, SY_EYE_MONO, w, h, &out[0], e) == SY_OK;
    return sy_compose_eye_view(ld->scene, spec, SY_EYE_LEFT, w, h, &out[0], e) == SY_OK &&
           sy_compose_eye_view(ld->scene, spec, SY_EYE_RIGHT, w, h, &out[1], e) == SY_OK;
}

/* Motion blur in one render (back-ends with SY_CAP_MOTION: whitted, pathtracer): the scene committed
 * at the shutter's close, synced, then at its open, synced (sy_context_motion_begin / _open): every
 * instance moved in between is interpolated linearly from open to close by each ray's own time. True
 * with *ctx_out the main context in motion (the caller renders once, then sy_context_motion_end);
 * Deformed meshes (skins, morph targets) are interpolated too, vertex by vertex, and a camera that
 * moves (*motion_camera true: sy_context_motion_camera, each camera ray at its time). False when the
 * back-end lacks it, or (a note says why) the scene also moves lights, makes meshes anew, or moves the
 * camera of a back-end that cannot move it: then the motion is ended and the caller blurs by
 * sub-frames. A stereo render's eyes move each with its own views (one moving camera per eye).
 * steps: the shutter's time steps (--shutter-steps), 0 = chosen from the motion (motion_steps_auto). */
static bool motion_native_begin(loaded *ld, const char *clip, double frame_time, const sy_shutter *sh,
                                uint32_t steps, const sy_compose_spec *spec, uint32_t w, uint32_t h,
                                sy_context_pool *pool, sy_context **ctx_out, bool *motion_camera)
{
    sy_params rp;
    sy_context *c = NULL;
    sy_error e = {0};
    if (sy_params_parse(spec->params, &rp, &e) != SY_OK ||
        sy_context_pool_get(pool, ld->scene, spec->backend, &rp, ld->root.id, &c, &e) != SY_OK ||
        !(sy_context_caps(c) & SY_CAP_MOTION))
        return false;
    sy_context_restart(c); /* placed as a fresh build places them, accumulation from sample 0 */
    if (!steps) { /* no --shutter-steps: from the angle the motion turns through */
        double angle = 0.0;
        steps = motion_steps_auto(ld, clip, frame_time, sh, spec, w, h, &angle);
        sy_log(steps > 2u ? SY_LOG_NOTE : SY_LOG_DEBUG, "sy", NULL,
               "motion blur: %u time steps (the largest turn over the shutter is %.3g degrees; a step per %g degrees at "
               "most; --shutter-steps N sets them)", steps, angle * (180.0 / 3.14159265358979323846), MOTION_CHORD_DEG);
    }
    bool native = false, camera_moves = false, camera_stays = false;
    /* the camera of each eye (mono: one; stereo: left and right, each its own view) at the open and
     * at each later step (v_later[eye][steps - 2]: the close): each camera ray at its own time between
     * them */
    uint32_t n_eyes = spec->stereo == SY_STEREO_NONE ? 1u : 2u;
    sy_camera_view v_open[2], v_later[2][SY_MOTION_STEPS_MAX];
    memset(v_open, 0, sizeof v_open);
    memset(v_later, 0, sizeof v_later);
    sy_camera_view at[2];
    memset(at, 0, sizeof at);
    sy_error ce = {0};
    /* --shutter-steps N: the steps between, from the close towards the open (curved motion) */
    bool stepped = sy_cli_set_time(ld, clip, frame_time + sh->close, &e) == 0 && eye_views(ld, spec, n_eyes, w, h, at, &e) &&
                   sy_context_motion_begin_steps(c, sh->samples, steps, &e) == SY_OK;
    for (uint32_t i = 0; stepped && i < n_eyes; ++i) v_later[i][steps - 2u] = at[i];
    for (uint32_t k = steps - 2u; stepped && k >= 1u; --k) {
        stepped = sy_cli_set_time(ld, clip, frame_time + sh->open + (sh->close - sh->open) * k / (steps - 1u), &e) == 0 &&
                  eye_views(ld, spec, n_eyes, w, h, at, &e) && sy_context_motion_step(c, &e) == SY_OK;
        for (uint32_t i = 0; stepped && i < n_eyes; ++i) v_later[i][k - 1u] = at[i];
    }
    if (stepped && sy_cli_set_time(ld, clip, frame_time + sh->open, &e) == 0 &&
        eye_views(ld, spec, n_eyes, w, h, v_open, &e) &&
        sy_context_motion_open(c, &native, &e) == SY_OK && native) {
        for (uint32_t i = 0; i < n_eyes; ++i)
            for (uint32_t k = 0; k + 1u < steps; ++k) camera_moves |= memcmp(&v_later[i][k], &v_open[i], sizeof v_open[i]) != 0;
        /* a moving camera: the back-end builds each camera ray at its time, each eye's from its own
         * views (the request of each eye's viewport has its eye's open view) */
        bool given = true;
        for (uint32_t i = 0; camera_moves && given && i < n_eyes; ++i)
            given = sy_context_motion_camera(c, &v_open[i], steps, v_later[i], &ce) == SY_OK;
        if (given) {
            *motion_camera = camera_moves;
            *ctx_out = c;
            return true;
        }
        camera_stays = true;
    }
    sy_context_motion_end(c);
    sy_context_restart(c);
    sy_log(SY_LOG_NOTE, "sy", NULL, "motion blur: %s; blurring by sub-frames instead",
           e.message[0] ? e.message
           : camera_stays ? (ce.message[0] ? ce.message : "the camera moves over the shutter")
                          : "the scene moves lights or makes meshes anew over the shutter, which the back-end does not interpolate");
    return false;
}

sy_result sy_cli_render_blurred(loaded *ld, const char *clip, double frame_time, sy_shutter *sh,
                                const sy_compose_spec *spec, uint32_t w, uint32_t h, const sy_cli_pt_opts *po,
                                sy_context_pool *pool, const sy_window_render_opts *ro, sy_layer *out,
                                sy_layer *out_right, double *seconds, uint64_t *samples_out, sy_context **ctx_out,
                                bool sub_frames, uint32_t steps, bool *native_out, sy_error *err)
{
    double t0 = sy_time_now();
    sy_context *mc = NULL;
    *native_out = false;
    bool moving_camera = false;
    if (!sub_frames && motion_native_begin(ld, clip, frame_time, sh, steps, spec, w, h, pool, &mc, &moving_camera)) {
        char each[64];
        if (po) snprintf(each, sizeof each, "each pixel sample");
        else snprintf(each, sizeof each, "each of at least %u samples per pixel", sh->samples);
        sy_log(SY_LOG_NOTE, "sy", NULL, "motion blur: one render, %s at its own time of the shutter %g..%g s after %g s "
               "(moving objects%s and deforming meshes interpolated per ray; --sub-frames: the mean of sub-frames instead)", each, sh->open,
               sh->close, frame_time, moving_camera ? ", the moving camera" : "");
        sy_result r;
        uint64_t total = 0;
        if (po) {
            double secs = 0;
            r = sy_cli_render_progressive(ld, spec, w, h, po, pool, out, out_right, &secs, &total, ctx_out, err);
        } else {
            r = sy_compose_render(ld->scene, pool, spec, w, h, ro, out, out_right, err);
            total = sh->samples;
        }
        sy_context_motion_end(mc);
        sy_context_restart(mc);
        if (r == SY_OK) { /* back to the frame's time: what the image's metadata describes */
            sy_error se = {0};
            if (sy_cli_set_time(ld, clip, frame_time, &se)) r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s", se.message);
        }
        if (r != SY_OK) {
            sy_layer_destroy(out);
            sy_layer_destroy(out_right);
        }
        *samples_out = total;
        *native_out = true;
        *seconds = sy_time_now() - t0;
        return r;
    }
    uint32_t n = sh->samples;
    uint64_t spp = po ? (po->spp ? po->spp : (po->time_budget > 0 ? 0 : 64)) : 0;
    if (spp && spp < n) n = sh->samples = (uint32_t)spp; /* at least one sample per time (the metadata says so) */
    sy_log(SY_LOG_NOTE, "sy", NULL, "motion blur: the mean of %u sub-frames at times %g .. %g s (shutter %g..%g s after "
           "%g s)%s", n, sy_shutter_time(&(sy_shutter){sh->open, sh->close, n}, frame_time, 0),
           sy_shutter_time(&(sy_shutter){sh->open, sh->close, n}, frame_time, n - 1), sh->open, sh->close, frame_time,
           po ? ", the samples split between them" : ", accumulated");
    sy_layer acc = {0}, acc_right = {0}, sub = {0}, sub_right = {0};
    double weight_sum = 0.0;
    uint64_t total = 0;
    sy_result r = SY_OK;
    sy_shutter s = *sh;
    s.samples = n;
    for (uint32_t i = 0; i < n && r == SY_OK; ++i) {
        sy_error se = {0};
        int st = sy_cli_set_time(ld, clip, sy_shutter_time(&s, frame_time, i), &se);
        if (st) {
            r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s",
                             se.message[0] ? se.message : "motion blur: setting the scene's time failed");
            break;
        }
        sy_layer_destroy(&sub);
        sy_layer_destroy(&sub_right);
        double weight = 1.0;
        if (po) {
            sy_cli_pt_opts pi = *po;
            pi.seed = po->seed + i;
            if (spp) pi.spp = (uint32_t)(spp / n + (i < spp % n ? 1 : 0));
            if (po->time_budget > 0) pi.time_budget = po->time_budget / n;
            restart_main(ld, pool, spec);
            double secs = 0;
            uint64_t smp = 0;
            r = sy_cli_render_progressive(ld, spec, w, h, &pi, pool, &sub, &sub_right, &secs, &smp, ctx_out, err);
            weight = (double)smp;
            total += smp;
        } else {
            sy_window_render_opts o = *ro;
            o.seed = ro->seed + i;
            r = sy_compose_render(ld->scene, pool, spec, w, h, &o, &sub, &sub_right, err);
            total++;
        }
        if (r != SY_OK) break;
        if (!acc.rgba && (r = sy_layer_create(sub.width, sub.height, &acc, err)) != SY_OK) break;
        if (sub_right.rgba && !acc_right.rgba &&
            (r = sy_layer_create(sub_right.width, sub_right.height, &acc_right, err)) != SY_OK)
            break;
        blur_add(&acc, &sub, (float)weight);
        if (sub_right.rgba) blur_add(&acc_right, &sub_right, (float)weight);
        weight_sum += weight;
        if (sy_signals_interrupted()) break; /* keep the time samples done */
    }
    sy_layer_destroy(&sub);
    sy_layer_destroy(&sub_right);
    if (r == SY_OK && weight_sum > 0) {
        float inv = (float)(1.0 / weight_sum);
        for (size_t k = 0; k < 4 * (size_t)acc.width * acc.height; ++k) acc.rgba[k] *= inv;
        for (size_t k = 0; acc_right.rgba && k < 4 * (size_t)acc_right.width * acc_right.height; ++k)
            acc_right.rgba[k] *= inv;
    }
    if (r == SY_OK) { /* back to the frame's time: what the image's metadata describes */
        sy_error se = {0};
        if (sy_cli_set_time(ld, clip, frame_time, &se)) r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s", se.message);
    }
    if (r != SY_OK) {
        sy_layer_destroy(&acc);
        sy_layer_destroy(&acc_right);
    } else {
        *out = acc;
        *out_right = acc_right;
        *samples_out = total;
    }
    *seconds = sy_time_now() - t0;
    return r;
}
