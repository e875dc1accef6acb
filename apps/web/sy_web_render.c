/* sy_web_render.c — the sy_web server's render loop, on the thread in sy_web_run: live frames
 * through the frame-time governor, stills and routes' jobs between them, the display filter; the
 * frames and answers go to the network thread through the mailbox (sy_web_internal.h; docs/WEB.md,
 * "Threads"). */
#include "sy_web_internal.h"

#include "sy_interactive.h"
#include "sy_jpeg.h"
#include "sy_log.h"
#include "sy_mediator.h"
#include "sy_post.h"
#include "sy_viewport.h"
#include "sy_web_cost.h"
#include "sy_web_frame.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef struct render_state {
    sy_context_pool *pool;
    sy_window *win, *still_win;
    sy_viewport *vp, *still_vp;
    uint32_t backend_applied;
    uint64_t seq;
    uint8_t *last_px; /* the newest frame's pixels (RGBA8), for a video viewer that joins at rest */
    uint64_t last_px_seq;
    sy_interactive *ia; /* the governor, the view on the viewports, the display filter (sy_interactive.h) */
    float exposure;     /* stops, as the pages set it */
    bool changed;       /* what frames show changed beyond the camera (sy_interactive_view.changed) */
    /* the timeline (docs/WEB.md): the wall time the playing clock was last advanced at, whether it
     * played then, the scene time last applied (NAN: none yet: the scene shows what was loaded
     * until a page moves the clock), when the last periodic "clock" message was due */
    double clock_wall, clock_applied, clock_sent;
    uint32_t clip_applied; /* the clip (sy_web_internal.h) clock_applied was applied with */
    bool clock_was_playing, clock_failed;
    /* the last coded depth channel (docs/WEB.md, depth coding 2): a progressive back-end's
     * refinements of that view (same size, back-end and camera, samples counting up) reuse it, and
     * the network thread leaves it out for a viewer it was sent to already (SY_WEB_FRAME_SAME_DEPTH) */
    uint8_t *dz;
    size_t dz_len;
    float dz_min, dz_max;
    uint32_t dz_w, dz_h, dz_backend;
    sy_camera_view dz_view;
    uint64_t dz_samples, dz_key, dz_keys;
} render_state;

#define WEB_CLOCK_TICK 0.02  /* s: a playing clock is advanced (and a frame planned) at most this often */
#define WEB_CLOCK_REPORT 1.0 /* s: a playing clock's time is sent to the pages this often (they interpolate) */

/* Under w->mu: advances a playing clock to now and says whether the scene's time must change
 * (*t_out: the time to apply). A clock that stopped at an end, and a playing one every
 * WEB_CLOCK_REPORT, bump clock_version (sent to the pages with the next frame). *clip_out: the
 * clip it plays (an index into w->clips; clip_count: every clip). */
static bool clock_step(sy_web *w, render_state *rs, double *t_out, uint32_t *clip_out)
{
    if (!w->animated) return false;
    double now = sy_time_now();
    bool playing = w->clock.playing;
    if (playing && rs->clock_was_playing) sy_clock_advance(&w->clock, now - rs->clock_wall);
    if (playing && !rs->clock_was_playing) rs->clock_sent = now;
    if (playing && !w->clock.playing) w->clock_version++; /* stopped at an end (a clock that does not loop) */
    else if (w->clock.playing && now - rs->clock_sent >= WEB_CLOCK_REPORT) w->clock_version++, rs->clock_sent = now;
    rs->clock_wall = now;
    rs->clock_was_playing = w->clock.playing;
    *t_out = w->clock.time;
    *clip_out = w->clip;
    /* the loaded pose stays until a page touched the clock (clock_version 1: as created) */
    return w->clock_version > 1 && !(w->clock.time == rs->clock_applied && w->clip == rs->clip_applied);
}

/* Sets the scene's time and commits (the moved nodes reach every context as any change does). */
static void clock_apply(sy_web *w, render_state *rs, double t, uint32_t clip)
{
    sy_error e = {0};
    rs->clock_applied = t;
    rs->clip_applied = clip;
    sy_animation a = clip < w->clip_count ? w->clips[clip] : (sy_animation){0};
    if (sy_scene_set_time(w->d.scene, a, t, &e) == SY_OK) sy_scene_commit(w->d.scene, NULL, &e);
    if (e.message[0] && !rs->clock_failed) { /* logged once: every later time would say the same */
        rs->clock_failed = true;
        sy_log(SY_LOG_WARNING, "web", NULL, "the scene clock at %g s: %s", t, e.message);
    }
}

/* Whether two frames' cameras are the same (matrix, window, projection). */
static bool same_camera(const sy_camera_view *a, const sy_camera_view *b)
{
    return !memcmp(&a->camera_to_world, &b->camera_to_world, sizeof a->camera_to_world) &&
           !memcmp(a->window, b->window, sizeof a->window) && a->projection == b->projection;
}

/* The display size the governor plans for: what the page asked, capped at max_width x max_height
 * keeping the aspect. */
static void display_size(const sy_web *w, uint32_t dw, uint32_t dh, uint32_t *ow, uint32_t *oh)
{
    double s = 1.0;
    if (dw > w->d.max_width) s = (double)w->d.max_width / dw;
    if (dh * s > w->d.max_height) s = (double)w->d.max_height / dh;
    *ow = dw, *oh = dh;
    if (s < 1.0) {
        *ow = (uint32_t)(dw * s + 0.5), *oh = (uint32_t)(dh * s + 0.5);
        if (!*ow) *ow = 1;
        if (!*oh) *oh = 1;
    }
}

/* Renders w x h with the current back-end into an 8-bit image (display chain: ACES + sRGB);
 * depth (may be NULL) receives the layer's depth plane (malloc, linear view depth). */
static sy_result render_rgba8(sy_web *w, render_state *rs, sy_window *win, uint32_t width, uint32_t height,
                              uint32_t samples, float preview, uint8_t **out, float **depth, sy_error *err)
{
    sy_post_desc post = sy_post_display();
    post.exposure_stops = rs->exposure;
    *out = NULL;
    if (depth) *depth = NULL;
    uint32_t cw = 0, ch = 0;
    sy_window_size(win, &cw, &ch);
    sy_result r = (cw != width || ch != height) ? sy_window_resize(win, width, height, err) : SY_OK;
    sy_layer img = {0};
    if (r == SY_OK) r = sy_layer_create(width, height, &img, err);
    sy_window_render_opts ro = {.sample_count = samples, .preview = preview, .post = post};
    if (r == SY_OK) r = sy_window_render(win, w->d.scene, rs->pool, &ro, &img, err);
    if (r == SY_OK && !(*out = sy_interactive_rgba8(&img, SY_RGBA8_OVER_BLACK))) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "web: out of memory");
    if (r == SY_OK && depth) *depth = img.depth, img.depth = NULL; /* taken over: sy_layer_destroy frees the rest */
    sy_layer_destroy(&img);
    return r;
}

static void finish_job(sy_web *w, web_job *j)
{
    pthread_mutex_lock(&w->mu);
    bool drop = j->abandoned;
    if (!drop) {
        j->state = JOB_FINISHED;
        j->next = w->finished;
        w->finished = j;
    }
    pthread_mutex_unlock(&w->mu);
    if (drop) sy_webi_job_free(j);
    else sy_webi_wake_network(w);
}

/* A failed job's answer: the status of its error and the message as text. */
static void job_error(web_job *j, sy_result r, const sy_error *err)
{
    free(j->resp.body);
    memset(&j->resp, 0, sizeof j->resp);
    j->resp.status = sy_webi_http_status_of(r);
    snprintf(j->resp.content_type, sizeof j->resp.content_type, "text/plain; charset=utf-8");
    char *m = malloc(strlen(err->message) + 2);
    if (m) {
        j->resp.body_len = (size_t)sprintf(m, "%s\n", err->message);
        j->resp.body = (uint8_t *)m;
    }
    sy_log(SY_LOG_WARNING, "web", j->peer, "%s %s: %s", j->method, j->path, err->message);
}

static void run_job(sy_web *w, web_job *j)
{
    sy_error err = {0};
    memset(&j->resp, 0, sizeof j->resp);
    sy_web_request req = {.method = j->method, .path = j->path, .query = j->query, .body = j->body,
                          .body_len = j->body_len, .peer = j->peer};
    sy_result r = j->route->fn(j->route->user, w->d.scene, &req, &j->resp, &err);
    if (r != SY_OK) job_error(j, r, &err);
    finish_job(w, j);
}

/* A still of the current view, after the live frame: answered 503 past its deadline; rendered in
 * passes of a few samples (progressive back-ends), each pass only while the requester is still
 * connected; the still's window is shrunk afterwards so its memory goes back. */
static void run_still(sy_web *w, render_state *rs, web_job *j, const sy_orbit *o)
{
    sy_error err = {0};
    sy_result r = SY_OK;
    memset(&j->resp, 0, sizeof j->resp);
    double waited = sy_time_now() * 1e3 - j->queued_ms;
    bool cancelled = sy_webi_job_abandoned(w, j), expired = !cancelled && waited > w->d.still_deadline_ms;
    if (expired) {
        r = sy_error_set(&err, SY_ERR_LIMIT, "the still waited %.0f ms behind the live view (deadline %u ms): try again",
                         waited, w->d.still_deadline_ms);
    } else if (!cancelled) {
        const sy_mediator_class *cls = sy_mediator_at(rs->backend_applied);
        uint32_t spp = cls && (cls->caps & SY_CAP_PROGRESSIVE) ? w->d.still_samples : 1;
        sy_layer img = {0};
        sy_orbit_matrix(o, &w->view);
        sy_viewport_set_view(rs->still_vp, &w->view); /* the view directly: the scene is not committed */
        r = sy_viewport_set_backend(rs->still_vp, (cls ? cls : sy_mediator_at(w->initial_backend))->name, NULL, &err);
        if (r == SY_OK) r = sy_window_resize(rs->still_win, j->w, j->h, &err);
        if (r == SY_OK) r = sy_layer_create(j->w, j->h, &img, &err);
        for (uint32_t done = 0; r == SY_OK && done < spp && !cancelled; ) {
            uint32_t n = spp - done > 4 ? 4 : spp - done;
            sy_post_desc post = sy_post_display();
            post.exposure_stops = rs->exposure;
            sy_window_render_opts ro = {.sample_count = n, .preview = 1.0f, .post = post};
            r = sy_window_render(rs->still_win, w->d.scene, rs->pool, &ro, &img, &err);
            done += n;
            cancelled = sy_webi_job_abandoned(w, j);
        }
        uint8_t *px = NULL;
        if (r == SY_OK && !cancelled && !(px = sy_interactive_rgba8(&img, SY_RGBA8_OVER_BLACK))) r = sy_error_set(&err, SY_ERR_OUT_OF_MEMORY, "web: out of memory");
        sy_layer_destroy(&img);
        if (px) r = sy_jpeg_encode_rgba8(px, j->w, j->h, 95, &j->resp.body, &j->resp.body_len, &err);
        free(px);
        sy_window_resize(rs->still_win, 64, 64, NULL);
        if (r == SY_OK && !cancelled) j->resp.status = 200, snprintf(j->resp.content_type, sizeof j->resp.content_type, "image/jpeg");
    }
    pthread_mutex_lock(&w->mu);
    w->still_running = NULL;
    if (cancelled) w->st.stills_cancelled++;
    else if (expired) w->st.stills_expired++;
    else if (r == SY_OK) w->st.stills_done++;
    pthread_mutex_unlock(&w->mu);
    if (cancelled) {
        sy_log(SY_LOG_NOTE, "web", j->peer, "a still of %ux%u cancelled: the requester left", j->w, j->h);
        finish_job(w, j); /* abandoned: freed there */
        return;
    }
    if (r != SY_OK) job_error(j, r, &err);
    if (expired) j->resp.status = 503;
    finish_job(w, j);
}

static void publish_frame(sy_web *w, web_frame *f)
{
    pthread_mutex_lock(&w->mu);
    web_frame *old = w->latest;
    w->latest = f;
    bool last = old && --old->refs == 0;
    pthread_mutex_unlock(&w->mu);
    if (last) sy_webi_frame_free(old);
    sy_webi_wake_network(w);
}

static void set_status(sy_web *w, const char *s)
{
    pthread_mutex_lock(&w->mu);
    if (strcmp(w->status, s) != 0) {
        snprintf(w->status, sizeof w->status, "%.*s", (int)sizeof w->status - 1, s);
        w->status_version++;
    }
    pthread_mutex_unlock(&w->mu);
    sy_webi_wake_network(w);
}

/* A frame cls rendered from orbit at fw x fh (px and depth taken, freed here) made into the newest
 * frame: JPEG (while a viewer takes it, or none said yet), the pixels for video viewers, the
 * camera the page warps it with, the depth channel (the view's coded one again for a
 * refinement), packed and published. gen: the input generation it answers; *ms: from t0 (the
 * render's start) to packed. */
static sy_result publish_rendered(sy_web *w, render_state *rs, const sy_mediator_class *cls, uint32_t bi,
                                  const sy_orbit *orbit, uint32_t fw, uint32_t fh, uint8_t *px, float *depth,
                                  uint64_t gen, double t0, double *ms, sy_error *err)
{
    uint8_t *jpeg = NULL;
    size_t jlen = 0;
    /* video viewers get the pixels (each one's encoder runs as its frame is sent); JPEG is made
     * only while a viewer takes it (or none said yet) */
    pthread_mutex_lock(&w->mu);
    bool keep_px = w->video_viewers > 0, want_jpeg = w->jpeg_viewers > 0 || !w->video_viewers;
    pthread_mutex_unlock(&w->mu);
    sy_result r = SY_OK;
    if (want_jpeg) r = sy_jpeg_encode_rgba8(px, fw, fh, w->d.quality, &jpeg, &jlen, err);
    /* the render thread keeps the newest pixels (republish_with_pixels); the frame gets a copy */
    free(rs->last_px);
    rs->last_px = px, rs->last_px_seq = 0, px = NULL;
    if (r == SY_OK && keep_px && !(px = malloc((size_t)fw * fh * 4)))
        r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "web: out of memory for a frame of %ux%u", fw, fh);
    if (px) memcpy(px, rs->last_px, (size_t)fw * fh * 4);
    /* the frame's camera: what the page warps the frame with (docs/WEB.md, "Binary frames") */
    sy_web_frame_info fi = {.width = fw, .height = fh, .backend = bi, .orbit = *orbit,
                            .flags = (cls->caps & SY_CAP_PROGRESSIVE) ? SY_WEB_FRAME_PROGRESSIVE : 0};
    if (r == SY_OK) r = sy_viewport_camera_view(rs->vp, w->d.scene, fw, fh, &fi.view, err);
    fi.view.clip_count = 0;
    sy_mediator_stats st = {0};
    sy_context *ctx = NULL;
    if (r == SY_OK && sy_context_pool_get(rs->pool, w->d.scene, cls->name, NULL, w->d.root.id, &ctx, NULL) == SY_OK)
        sy_context_stats(ctx, &st);
    /* the depth channel: the view's coded one again for a refinement, else coded anew */
    bool reuse = r == SY_OK && depth && (fi.flags & SY_WEB_FRAME_PROGRESSIVE) && rs->dz && rs->dz_w == fw &&
                 rs->dz_h == fh && rs->dz_backend == bi && same_camera(&rs->dz_view, &fi.view) &&
                 st.samples > rs->dz_samples;
    if (r == SY_OK && !reuse) {
        free(rs->dz);
        rs->dz = NULL, rs->dz_len = 0, rs->dz_key = 0;
        if (depth &&
            (r = sy_web_frame_depth_code(depth, fw, fh, &rs->dz, &rs->dz_len, &rs->dz_min, &rs->dz_max, err)) == SY_OK)
            rs->dz_w = fw, rs->dz_h = fh, rs->dz_backend = bi, rs->dz_view = fi.view, rs->dz_key = ++rs->dz_keys;
    }
    rs->dz_samples = st.samples;
    uint8_t *buf = NULL;
    size_t len = 0;
    if (r == SY_OK)
        r = sy_web_frame_pack_coded(&fi, jpeg, jlen, rs->dz, rs->dz_len, rs->dz_min, rs->dz_max, LWS_PRE, &buf, &len, err);
    *ms = (sy_time_now() - t0) * 1e3; /* render, display chain, JPEG, depth */
    free(jpeg);
    free(depth);
    if (r != SY_OK) {
        free(px);
        return r;
    }
    web_frame *f = calloc(1, sizeof *f);
    if (!f) {
        free(buf);
        free(px);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "web: out of memory for a frame of %zu bytes", len);
    }
    /* the samples and the time are known only now: patched into the packed header */
    uint8_t *h = buf + LWS_PRE;
    uint32_t spp = (uint32_t)(st.samples > UINT32_MAX ? UINT32_MAX : st.samples);
    float fms = (float)*ms;
    uint64_t seq = ++rs->seq;
    memcpy(h + 16, &spp, 4); /* little-endian hosts (x86-64, arm64) */
    memcpy(h + 20, &fms, 4);
    memcpy(h + 24, &seq, 8);
    f->buf = buf;
    f->refs = 1, f->seq = seq, f->gen = gen, f->len = len;
    f->rgba = px, f->width = fw, f->height = fh, f->backend = bi;
    f->jpeg_len = fi.jpeg_len, f->depth_len = fi.depth_len, f->depth_key = fi.depth_len ? rs->dz_key : 0;
    rs->last_px_seq = seq;
    publish_frame(w, f);
    return SY_OK;
}

/* One frame through the frame-time governor (core/sy_governor.h): plans it for the display size,
 * renders what the plan says, reports its time. ahead: the orbit the frame is rendered from (the
 * pages' orbit, in->orbit, moved on by their lead: docs/WEB.md, "Frames rendered ahead"); the
 * frame's header names in->orbit, its camera is ahead's, w->view stays in->orbit's (picks, saved
 * views). *again: plan again without waiting for input; *wait_ms > 0: plan again after that long
 * (the view is settling). */
static sy_result render_frame(sy_web *w, render_state *rs, const sy_interactive_input *in, const sy_orbit *ahead,
                              uint32_t bi, uint32_t dw, uint32_t dh, uint64_t gen, bool *again, double *wait_ms,
                              sy_error *err)
{
    *again = false, *wait_ms = 0;
    const sy_mediator_class *cls = sy_mediator_at(bi);
    if (!cls) return sy_error_set(err, SY_ERR_NOT_FOUND, "web: back-end %u is not registered", bi);
    uint32_t pw = 0, ph = 0;
    display_size(w, dw, dh, &pw, &ph);
    sy_result r = SY_OK;
    if (bi != rs->backend_applied) {
        r = sy_viewport_set_backend(rs->vp, cls->name, NULL, err);
        if (r == SY_OK) rs->backend_applied = bi;
    }
    if (r != SY_OK) return r;
    sy_governor_frame gf;
    sy_interactive_view iv = {.orbit = ahead, .viewports = &rs->vp, .viewport_count = 1, .backend = cls,
                              .caps = sy_mediator_class_caps(cls, NULL), .width = pw, .height = ph,
                              .filter_version = in->filter_version, .changed = rs->changed};
    rs->changed = false;
    /* the view set on the viewport directly: the application's scene is not committed */
    sy_interactive_plan(rs->ia, &iv, sy_time_now() * 1e3, &gf, &w->view);
    if (ahead != &in->orbit) sy_orbit_matrix(&in->orbit, &w->view); /* the pages' view, not the one ahead */
    if (gf.wait_ms > 0) { /* settling after a moving frame: the refining frame comes next */
        *wait_ms = gf.wait_ms;
        return SY_OK;
    }
    if (gf.idle || !gf.width || !gf.height) return SY_OK; /* refined: sleep until input */
    char fstatus[240] = "";
    sy_error ferr = {0};
    if (sy_interactive_apply_filter(rs->ia, rs->pool, w->d.scene, w->d.root.id, cls, in->filter, in->threshold,
                                    in->filter_version, gf.filter, NULL, &ferr) != SY_OK)
        snprintf(fstatus, sizeof fstatus, "filter: %.200s", ferr.message);
    uint8_t *px = NULL;
    float *depth = NULL;
    uint32_t contexts = sy_context_pool_size(rs->pool);
    pthread_mutex_lock(&w->mu);
    double encode_per_px = w->encode_per_px_ms;
    pthread_mutex_unlock(&w->mu);
    double t0 = sy_time_now(), ms = 0;
    r = render_rgba8(w, rs, rs->win, gf.width, gf.height, gf.samples, gf.preview, &px, &depth, err);
    if (r == SY_OK) r = publish_rendered(w, rs, cls, bi, &in->orbit, gf.width, gf.height, px, depth, gen, t0, &ms, err);
    else free(px), free(depth);
    if (r != SY_OK) return r;
    /* the governor is told the frame's whole cost: with what the viewers' encoders on the network
     * thread take for a frame of this size (sy_web_cost.h); a frame that translated the scene for
     * a new context says nothing about the next ones */
    sy_interactive_report(rs->ia, &gf, sy_web_frame_cost_ms(ms, encode_per_px, gf.width, gf.height),
                          sy_context_pool_size(rs->pool) != contexts);
    set_status(w, fstatus);
    *again = true; /* the governor says what comes next */
    return SY_OK;
}

/* A video viewer joined a view at rest (or took video after its first frames): the newest frame
 * again under a new number, with its pixels (the frame as it was: no new render, a progressive
 * back-end keeps its samples). */
static void republish_with_pixels(sy_web *w, render_state *rs)
{
    pthread_mutex_lock(&w->mu);
    web_frame *cur = w->latest;
    bool go = cur && rs->last_px && rs->last_px_seq == cur->seq;
    if (go) cur->refs++;
    pthread_mutex_unlock(&w->mu);
    if (!go) return;
    web_frame *f = calloc(1, sizeof *f);
    uint8_t *buf = f ? malloc(cur->len + LWS_PRE) : NULL, *px = buf ? malloc((size_t)cur->width * cur->height * 4) : NULL;
    if (!px) {
        free(f), free(buf);
        sy_webi_frame_release(w, cur);
        sy_log(SY_LOG_WARNING, "web", NULL, "out of memory for a frame's pixels: the video viewers wait for the next frame");
        return;
    }
    memcpy(buf, cur->buf, cur->len + LWS_PRE);
    memcpy(px, rs->last_px, (size_t)cur->width * cur->height * 4);
    *f = *cur;
    f->buf = buf, f->rgba = px, f->refs = 1, f->seq = ++rs->seq;
    memcpy(buf + LWS_PRE + 24, &f->seq, 8);
    rs->last_px_seq = f->seq;
    sy_webi_frame_release(w, cur);
    publish_frame(w, f);
}

/* The live frame (the governor says its size) and what a failed back-end tells the pages. */
static void render_live(sy_web *w, render_state *rs, const sy_interactive_input *in, const sy_orbit *ahead, uint32_t bi,
                        uint32_t dw, uint32_t dh, uint64_t gen, bool *again, double *wait_until)
{
    *again = false, *wait_until = 0;
    sy_error ferr = {0};
    double wait_ms = 0;
    if (render_frame(w, rs, in, ahead, bi, dw, dh, gen, again, &wait_ms, &ferr) == SY_OK) {
        if (wait_ms > 0) *wait_until = sy_time_now() * 1e3 + wait_ms;
    } else {
        /* a back-end that fails is reported to the pages; the others keep serving */
        char s[300];
        snprintf(s, sizeof s, "%s failed: %.240s", sy_mediator_at(bi) ? sy_mediator_at(bi)->name : "back-end",
                 ferr.message);
        sy_log(SY_LOG_WARNING, "web", NULL, "%s", s);
        set_status(w, s);
        *again = false;
    }
}

/* Before the first page: the initial back-end translates the scene with the governor's first frame
 * of the start view for the largest display (a quarter of -w x -h, the preview level), so that a
 * page's first picture costs one coarse frame, not the translation (DamagedHelmet with Whitted:
 * 4.8 s before anything showed), and what a back-end sizes by the frame is made too; then renders
 * that frame again and reports its time to the governor, so the page's first frame is planned
 * with a cost model (within the budget) rather than at the quarter size blind (the rasterizer's
 * 256 x 192 frame of DamagedHelmet took 2.1-3.2 s on the loaded 2-core machine). That second
 * frame is published as the newest frame: the first picture of a page that loads before any other
 * frame was made (docs/WEB.md, "The first picture"). Logged with its times; a failure is only
 * logged (the live frames report it to the pages). */
static void warm_up(sy_web *w, render_state *rs)
{
    pthread_mutex_lock(&w->mu);
    sy_orbit o = w->in.orbit;
    uint64_t fv = w->in.filter_version;
    pthread_mutex_unlock(&w->mu);
    const sy_mediator_class *cls = sy_mediator_at(rs->backend_applied);
    const char *name = cls ? cls->name : "?";
    sy_error err = {0};
    if (!cls) return;
    sy_interactive_view iv = {.orbit = &o, .viewports = &rs->vp, .viewport_count = 1, .backend = cls,
                              .caps = sy_mediator_class_caps(cls, NULL), .width = w->d.max_width,
                              .height = w->d.max_height, .filter_version = fv};
    sy_governor_frame gf;
    sy_interactive_plan(rs->ia, &iv, sy_time_now() * 1e3, &gf, &w->view);
    uint32_t fw = gf.width > 16 ? gf.width : 16, fh = gf.height > 16 ? gf.height : 16;
    double t0 = sy_time_now(), ms[2] = {0, 0};
    sy_result r = SY_OK;
    for (int k = 0; k < 2 && r == SY_OK; ++k) {
        uint8_t *px = NULL;
        float *depth = NULL; /* asked for as the live frames ask for it */
        double t = sy_time_now(), packed_ms = 0;
        r = render_rgba8(w, rs, rs->win, fw, fh, gf.samples ? gf.samples : 1, gf.preview > 0 ? gf.preview : 1.0f, &px,
                         &depth, &err);
        ms[k] = (sy_time_now() - t) * 1e3;
        /* the second: the newest frame until a page's own (sent at once to a page whose display
         * has its shape; /api/latest.jpg serves it while a page loads) */
        if (k == 1 && r == SY_OK)
            r = publish_rendered(w, rs, cls, rs->backend_applied, &o, fw, fh, px, depth, 0, t, &packed_ms, &err);
        else
            free(px), free(depth);
    }
    if (r != SY_OK) {
        sy_log(SY_LOG_WARNING, "web", NULL, "warming up %s: %s", name, err.message);
        return;
    }
    if (gf.width == fw && gf.height == fh) sy_interactive_report(rs->ia, &gf, ms[1], false);
    rs->changed = true; /* the page's first frame is a moving one, whatever its size */
    sy_log(SY_LOG_NOTE, "web", NULL, "ready: %s translated the scene in %.0f ms (a first frame of %ux%u: %.0f ms)", name,
           (sy_time_now() - t0) * 1e3 - ms[1], fw, fh, ms[1]);
}

sy_result sy_web_run(sy_web *w, volatile int *stop, sy_error *err)
{
    render_state rs = {.clock_applied = NAN};
    sy_viewport_desc vd = {.root = w->d.root, .camera = w->d.camera, .background = w->d.background,
                           .backend = sy_mediator_at(w->initial_backend)->name};
    sy_result r = sy_context_pool_create(&rs.pool, err);
    if (r == SY_OK) r = sy_window_create(64, 64, &rs.win, err);
    if (r == SY_OK) r = sy_window_add_viewport(rs.win, &vd, &rs.vp, err);
    if (r == SY_OK) r = sy_window_create(64, 64, &rs.still_win, err);
    if (r == SY_OK) r = sy_window_add_viewport(rs.still_win, &vd, &rs.still_vp, err);
    if (r == SY_OK)
        r = sy_interactive_create(&(sy_governor_desc){.budget_ms = w->d.budget_ms}, &rs.ia, err);
    if (r == SY_OK) sy_interactive_set_temporal(rs.ia, !w->d.no_temporal);
    rs.backend_applied = w->initial_backend;
    if (r == SY_OK) warm_up(w, &rs);
    uint64_t seen = 0, seen_look = 0;
    bool again = false;    /* plan again without waiting for input */
    double wait_until = 0; /* ms (sy_time_now): the governor's settle wait, 0 = none */
    while (r == SY_OK) {
        pthread_mutex_lock(&w->mu);
        for (;;) {
            if (w->quit || (stop && *stop) || w->pending || w->stills || w->actions || w->need_pixels) break;
            /* frames once a page said its size (the page does as it connects) */
            bool due = again || (wait_until > 0 && sy_time_now() * 1e3 >= wait_until);
            /* a playing scene clock: a frame every WEB_CLOCK_TICK at most */
            double tick_ms = w->clock.playing && w->animated ? (rs.clock_wall + WEB_CLOCK_TICK - sy_time_now()) * 1e3 : 1e9;
            if (w->clients && w->display_w && (w->view_version != seen || due || tick_ms <= 0)) break;
            double nap_ms = 100; /* polls *stop ten times a second */
            if (tick_ms < nap_ms) nap_ms = tick_ms;
            if (wait_until > 0 && wait_until - sy_time_now() * 1e3 < nap_ms) nap_ms = wait_until - sy_time_now() * 1e3;
            if (nap_ms < 0.1) nap_ms = 0.1;
            struct timespec ts;
            clock_gettime(CLOCK_REALTIME, &ts);
            ts.tv_nsec += (long)(nap_ms * 1e6);
            if (ts.tv_nsec >= 1000000000) ts.tv_sec++, ts.tv_nsec -= 1000000000;
            pthread_cond_timedwait(&w->cv, &w->mu, &ts);
        }
        if (w->quit || (stop && *stop)) {
            pthread_mutex_unlock(&w->mu);
            break;
        }
        web_job *jobs = w->pending;
        w->pending = NULL, w->pending_tail = &w->pending;
        for (web_job *j = jobs; j; j = j->next) j->state = JOB_RUNNING;
        web_action *actions = w->actions;
        w->actions = NULL, w->actions_tail = &w->actions, w->action_count = 0;
        if (w->look_version != seen_look) rs.changed = true, seen_look = w->look_version;
        rs.exposure = w->exposure;
        double clock_t = 0;
        uint32_t clock_clip = 0;
        bool clock_moved = clock_step(w, &rs, &clock_t, &clock_clip);
        sy_interactive_input in = w->in;
        bool moved = w->view_version != seen;
        seen = w->view_version;
        uint32_t bi = w->backend, dw = w->display_w, dh = w->display_h;
        uint64_t gen = w->input_gen;
        bool clients = w->clients > 0 && w->display_w > 0;
        /* moving frames keep d.min_scale of the display while every viewer's page warps (it answers
         * inputs itself: detail counts for more than rate), else the governor's own floor */
        float floor_scale = w->plain_viewers ? 0.0f : w->d.min_scale;
        /* frames rendered ahead by the last drag's lead (docs/WEB.md), while every viewer warps (a
         * page that does not would show a view its hand has not reached) */
        float lead[2] = {w->lead[0], w->lead[1]};
        int lead_button = w->lead_button >= 1 ? 1 : 0;
        bool ahead = !w->plain_viewers && (lead[0] != 0.0f || lead[1] != 0.0f);
        bool need_pixels = w->need_pixels;
        w->need_pixels = false;
        float fov_req = w->fov_req; /* a recalled view's field of view (sy_web_views.c) */
        w->fov_req = 0.0f;
        pthread_mutex_unlock(&w->mu);
        if (fov_req > 0.0f && sy_webi_views_set_fov(w, fov_req)) rs.changed = moved = true;
        if (clock_moved) { /* the scene at the clock's time: what frames show changed */
            clock_apply(w, &rs, clock_t, clock_clip);
            rs.changed = moved = true;
        }
        while (jobs) { /* stills and routes first: they wait on an HTTP connection */
            web_job *j = jobs;
            jobs = j->next;
            pthread_mutex_lock(&w->mu);
            bool gone = j->abandoned;
            pthread_mutex_unlock(&w->mu);
            if (gone) sy_webi_job_free(j);
            else run_job(w, j);
        }
        if (actions) { /* pages' picks, visibility, selection, planes, tree: before the frame they change */
            sy_web_scene_ctx sc = {.w = w, .pool = rs.pool, .win = rs.win, .vp = rs.vp, .still_vp = rs.still_vp,
                                   .backend = rs.backend_applied};
            if (sy_webi_scene_actions(&sc, actions)) rs.changed = moved = true;
        }
        bool due = again || (wait_until > 0 && sy_time_now() * 1e3 >= wait_until);
        sy_interactive_set_min_scale(rs.ia, floor_scale);
        sy_interactive_input led = in;
        if (ahead) sy_interactive_drag(&led, lead_button, lead[0], lead[1]);
        if (clients && (moved || due))
            render_live(w, &rs, &in, ahead ? &led.orbit : &in.orbit, bi, dw, dh, gen, &again, &wait_until);
        /* after render_live, which may have rendered nothing (a view at rest) */
        if (need_pixels) republish_with_pixels(w, &rs);
        /* then one still: stills wait behind the live view */
        pthread_mutex_lock(&w->mu);
        web_job *still = w->stills;
        if (still) {
            w->stills = still->next;
            if (!w->stills) w->stills_tail = &w->stills;
            still->state = JOB_RUNNING;
            w->still_running = still;
        }
        pthread_mutex_unlock(&w->mu);
        if (still) run_still(w, &rs, still, &in.orbit);
    }
    /* jobs still queued are answered 503 */
    pthread_mutex_lock(&w->mu);
    web_job *left = w->pending;
    w->pending = NULL, w->pending_tail = &w->pending;
    if (left) {
        web_job **t = &left;
        while (*t) t = &(*t)->next;
        *t = w->stills;
    } else {
        left = w->stills;
    }
    w->stills = NULL, w->stills_tail = &w->stills;
    pthread_mutex_unlock(&w->mu);
    while (left) {
        web_job *j = left;
        left = j->next;
        j->resp.status = 503;
        snprintf(j->resp.content_type, sizeof j->resp.content_type, "text/plain; charset=utf-8");
        finish_job(w, j);
    }
    free(rs.last_px);
    free(rs.dz);
    sy_interactive_destroy(rs.ia);
    sy_window_destroy(rs.win);
    sy_window_destroy(rs.still_win);
    sy_context_pool_destroy(rs.pool);
    return r;
}

void sy_web_stop(sy_web *w)
{
    pthread_mutex_lock(&w->mu);
    w->quit = true;
    pthread_cond_signal(&w->cv);
    pthread_mutex_unlock(&w->mu);
}
