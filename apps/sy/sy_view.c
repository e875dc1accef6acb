/* sy_view.c — the interactive viewer: GLFW input/display thread + a render thread that owns the
 * scene (see sy_view.h). */
#include "sy_view.h"

#include "sy_anim.h"
#include "sy_bookmarks.h"
#include "sy_commit.h"
#include "sy_interactive.h"
#include "sy_log.h"
#include "sy_mediator_cluster.h"
#include "sy_png.h"
#include "sy_testpoint.h"

#define GLFW_INCLUDE_NONE
#include <GL/gl.h>
#include <GLFW/glfw3.h>

#include <ctype.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef struct view_cluster view_cluster;

typedef struct viewer {
    const sy_view_args *args;
    /* sy view --cluster, NULL = local: set before the threads start, dereferenced by the render
     * thread only (the window thread tests it for the title) */
    view_cluster *cluster;
    sy_context_pool *pool; /* created before the threads start; used by the render thread only */
    pthread_mutex_t mu;
    pthread_cond_t cv;
    /* input thread -> render thread (under mu) */
    sy_interactive_input in; /* the orbit and the display filter (sy_interactive.h) */
    uint64_t req_version;
    uint32_t backend; /* index into the registry */
    bool overlay;
    uint32_t stereo;
    uint32_t w, h;
    bool quit;
    bool playing;    /* space: the scene clock plays (the render thread advances it) */
    uint32_t steps;  /* '.': steps of 1/24 s asked for since the last frame */
    bool pick;          /* a click to pick and select at (pick_x, pick_y) (window pixels of the image) */
    bool pick_add;      /* shift-click: toggle the node in the selection instead of replacing it */
    double pick_x, pick_y;
    int vis_key;        /* 'H' hide the selection, 'I' isolate it, 'U' show every node; 0 none */
    /* section planes (the input thread edits them: C adds one facing the view through the last
     * picked point or the orbit's target, X removes the last, J / L or Page Down / Page Up or
     * Ctrl+wheel move the last along its normal, N flips it, K turns the caps on and off) */
    uint32_t clip_count;
    float clip_planes[SY_CLIP_PLANES_MAX][4];
    bool clip_cap;
    float cap_color[3];
    float step;          /* a plane move: 1/50 of the scene's bounding-box diagonal */
    bool have_pick;      /* the render thread's last pick hit (pick_pos: its world position) */
    float pick_pos[3];
    char clip_status[96];
    /* saved views: Ctrl+1..9 saves the view in slot N (to args->bookmarks), Shift+1..9 recalls it */
    sy_bookmark marks[SY_BOOKMARKS_MAX + 1];
    char mark_status[160];
    float fov;     /* the camera's vertical field of view (radians; 0: orthographic), saved with a view */
    float fov_req; /* a recalled view's field of view for the render thread to set on the camera (0: none) */
    bool redraw; /* a key changed what the frame shows besides the view (planes, caps, a status): render again */
    /* render thread -> input thread (under mu) */
    uint8_t *img;
    uint32_t img_w, img_h;
    uint64_t img_version;
    uint64_t img_req;       /* the req_version the image answers (scripted --keys wait for it) */
    double frame_ms, sync_ms;
    uint64_t spp;
    float img_scale;  /* the governor's resolution scale of the image (1 = full size) */
    bool animated;    /* the scene has animations (then anim_time is in the heads-up line) */
    double anim_time; /* the scene clock's time the image shows */
    bool img_moving;  /* a moving frame (reduced size): --frames counts only settled ones */
    float first_scale; /* the first frame answering img_req: its scale and whether it moved (the main */
    bool first_moving; /* thread may see only a later frame of the same request on a busy machine) */
    bool governed;    /* local rendering (the governor's scale is in the title) */
    char status[256];
    char filter_status[96];
    char sel_status[320]; /* the last pick, measurement and the selection, for the title */
    sy_error error;
    bool failed;
} viewer;

/* Render thread: applies the input's display filter to the back-end's context (sy_interactive.h)
 * and fills status (empty for a back-end without filters). Errors go to status, not fatal. */
static void view_filter(sy_interactive *ia, sy_context_pool *pool, const sy_view_args *a, const sy_mediator_class *cls,
                        const sy_interactive_input *in, bool enabled, char *status, size_t len)
{
    status[0] = 0;
    if (!(cls->caps & SY_CAP_FILTERS)) return;
    sy_filter_info fi;
    sy_error err = {0};
    if (sy_interactive_apply_filter(ia, pool, a->scene, a->spec.root.id, cls, in->filter, in->threshold,
                                    in->filter_version, enabled, &fi, &err) != SY_OK) {
        snprintf(status, len, " | filter: %.80s", err.message);
        return;
    }
    char chosen[32];
    sy_interactive_filter_name(in->filter, chosen);
    if (!enabled && strcmp(chosen, "none") != 0) /* the governor keeps it off while the view moves */
        snprintf(status, len, " | filter %s t=%g off while moving", chosen, (double)in->threshold);
    else if (strcmp(fi.name, "none") != 0)
        snprintf(status, len, " | filter %s t=%g %.1f ms%s", fi.name, (double)fi.threshold, fi.seconds * 1e3,
                 fi.nonfinite_pixels ? " | NaN/Inf pixels!" : "");
    else
        snprintf(status, len, " | filter none");
}

/* >>cluster (`sy view --cluster`): the viewport's back-end is the cluster mediator (registered
 * from the options before the window opens); the render thread renders through the same window
 * path as locally, with the servers' back-end named in the viewport parameters. Deadlines adapt in
 * the mediator (sy_mediator_cluster.h). */
struct view_cluster {
    sy_cluster_cli_opts opts;
    uint32_t mode, servers;
    sy_cluster_rect viewer_tile; /* multi-display: what the window shows ('viewer tile'; w 0 = the wall) */
    uint32_t wall_w, wall_h;     /* multi-display: the wall (-w x -h) */
    uint32_t passes;             /* frames since the last restart (camera, back-end, size changed) */
    sy_window *wall_win;         /* multi-display: one viewport on the viewer's camera, for its view */
    sy_viewport *wall_vp;
    pthread_mutex_t log_mu;
    char log[128];               /* the client's last log line (a server dropped, a reconnect) */
};

/* Client log lines (the render thread, and the main thread while connecting). */
static void view_cluster_log(void *user, const char *line)
{
    view_cluster *vc = user;
    const char *prefix = "sy cluster: "; /* the title has little room */
    const char *text = strncmp(line, prefix, strlen(prefix)) ? line : line + strlen(prefix);
    sy_log(SY_LOG_NOTE, "cluster.client", NULL, "%s", text);
    pthread_mutex_lock(&vc->log_mu);
    snprintf(vc->log, sizeof vc->log, "%s", text);
    pthread_mutex_unlock(&vc->log_mu);
}

/* The cluster viewport's parameters for the servers' back-end `backend`. */
static sy_result view_cluster_params(const view_cluster *vc, const char *backend, char *out, size_t len, sy_error *err)
{
    return sy_cluster_cli_params(&vc->opts, backend, vc->mode, NULL, out, len, err);
}

/* Registers the cluster class and connects (a context in the pool) before any window opens, so a bad
 * option, secret or address fails right away. */
static sy_result view_cluster_open(const sy_view_args *a, sy_context_pool *pool, view_cluster **out, sy_error *err)
{
    view_cluster *vc = calloc(1, sizeof *vc);
    if (!vc) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "view: out of memory");
    pthread_mutex_init(&vc->log_mu, NULL);
    vc->opts = *a->cluster;
    vc->opts.log = view_cluster_log;
    vc->opts.log_user = vc;
    if (!vc->opts.connect_timeout_ms) vc->opts.connect_timeout_ms = 2000; /* a stalled server costs at most this */
    char params[1400];
    sy_result r = sy_cluster_cli_setup(&vc->opts, a->backend, NULL, params, sizeof params, &vc->mode, &vc->servers,
                                       &vc->viewer_tile, err);
    if (r == SY_OK && vc->mode == SY_CLUSTER_MULTI_DISPLAY && vc->viewer_tile.w) {
        const sy_cluster_rect *t = &vc->viewer_tile;
        if (t->x >= a->width || t->y >= a->height || t->w > a->width - t->x || t->h > a->height - t->y)
            r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "view: viewer tile %ux%u at %u,%u lies outside the %ux%u wall (-w, -h)",
                             t->w, t->h, t->x, t->y, a->width, a->height);
    }
    sy_params pp;
    sy_context *ctx = NULL;
    if (r == SY_OK) r = sy_params_parse(params, &pp, err);
    if (r == SY_OK) r = sy_context_pool_get(pool, a->scene, SY_MEDIATOR_CLUSTER_NAME, &pp, a->spec.root.id, &ctx, err);
    if (r) {
        pthread_mutex_destroy(&vc->log_mu);
        free(vc);
        return r;
    }
    vc->wall_w = a->width, vc->wall_h = a->height;
    *out = vc;
    return SY_OK;
}

static void view_cluster_close(view_cluster *vc)
{
    if (!vc) return;
    sy_window_destroy(vc->wall_win);
    pthread_mutex_destroy(&vc->log_mu);
    free(vc);
}

/* Multi-display: the window's own picture of the wall, rendered locally with the same back-end
 * (the whole wall, or the configured viewer tile: an exact crop, as the servers' tiles are). */
static sy_result view_cluster_local(view_cluster *vc, const sy_view_args *a, sy_context_pool *pool, const char *backend,
                                    const sy_compose_spec *spec, uint32_t fw, uint32_t fh, sy_layer *img, sy_error *err)
{
    sy_cluster_rect t = vc->viewer_tile.w ? vc->viewer_tile : (sy_cluster_rect){0, 0, fw, fh};
    sy_camera_view view = {0};
    sy_context *ctx = NULL;
    sy_result r = SY_OK;
    if (!vc->wall_vp) { /* made once: the camera node and the wall size do not change */
        sy_viewport_desc vd = {.root = a->spec.root, .camera = spec->camera, .backend = backend};
        r = sy_window_create(fw, fh, &vc->wall_win, err);
        if (r == SY_OK) r = sy_window_add_viewport(vc->wall_win, &vd, &vc->wall_vp, err);
        if (r != SY_OK) {
            sy_window_destroy(vc->wall_win);
            vc->wall_win = NULL, vc->wall_vp = NULL;
            return r;
        }
    }
    if (r == SY_OK) sy_viewport_set_view(vc->wall_vp, spec->view); /* the viewer's view, directly */
    if (r == SY_OK) r = sy_viewport_camera_view(vc->wall_vp, a->scene, fw, fh, &view, err);
    if (r == SY_OK) r = sy_context_pool_get(pool, a->scene, backend, NULL, a->spec.root.id, &ctx, err);
    if (r == SY_OK) r = sy_context_sync(ctx, err);
    if (r == SY_OK) r = sy_layer_create(t.w, t.h, img, err);
    sy_render_request req = {.camera = view, .full_width = fw, .full_height = fh, .rect_x = t.x, .rect_y = t.y,
                             .rect_w = t.w, .rect_h = t.h, .sample_count = 1, .background_id = a->spec.background.id};
    if (r == SY_OK) r = sy_context_render(ctx, &req, img, err);
    return r;
}

/* One cluster frame through the window path: spec names the cluster viewport; w x h is the window
 * (multi-display: the -w x -h wall, and *img is the window's local picture of it). Fills the
 * heads-up status, the merged samples per pixel and whether to keep refining. */
static sy_result view_cluster_frame(view_cluster *vc, const sy_view_args *a, sy_context_pool *pool, sy_compose_spec *spec,
                                    const char *backend, bool restart, uint32_t w, uint32_t h, sy_layer *img,
                                    sy_layer *right, uint64_t *spp, bool *refine, char *status, size_t len, sy_error *err)
{
    char params[1400];
    sy_result r = view_cluster_params(vc, backend, params, sizeof params, err);
    if (r) return r;
    spec->backend = SY_MEDIATOR_CLUSTER_NAME;
    spec->params = params;
    vc->passes = restart ? 0 : vc->passes + 1;
    sy_params pp;
    sy_context *ctx = NULL;
    if (r == SY_OK) r = sy_params_parse(params, &pp, err);
    if (r == SY_OK) r = sy_context_pool_get(pool, a->scene, SY_MEDIATOR_CLUSTER_NAME, &pp, a->spec.root.id, &ctx, err);
    bool progressive = r == SY_OK && (sy_context_caps(ctx) & SY_CAP_PROGRESSIVE);
    /* progressive: 1, 2, 4, 8, then 16 samples per server and frame after a restart (--spp: fixed) */
    uint32_t per = a->cluster->samples ? a->cluster->samples : 1u << (vc->passes < 4 ? vc->passes : 4);
    sy_window_render_opts ro = {.sample_count = progressive ? per * vc->servers : 0};
    bool wall = vc->mode == SY_CLUSTER_MULTI_DISPLAY;
    if (r == SY_OK) r = sy_compose_render(a->scene, pool, spec, wall ? vc->wall_w : w, wall ? vc->wall_h : h, &ro, img, right, err);
    if (r == SY_OK && wall) { /* the servers presented the wall; the window shows its own picture of it */
        sy_layer_destroy(img);
        r = view_cluster_local(vc, a, pool, backend, spec, vc->wall_w, vc->wall_h, img, err);
    }
    sy_cluster_frame_stats st = {0};
    if (ctx) sy_cluster_cli_last_frame(ctx, &st, NULL);
    sy_mediator_stats ms = {0};
    if (ctx) sy_context_stats(ctx, &ms);
    const char *mode = sy_cluster_cli_mode_name(vc->mode);
    if (r) {
        snprintf(status, len, "cluster %s: %u/%u servers alive", mode, st.servers_live, vc->servers);
        struct timespec pause = {0, 250000000}; /* every server down: retry a few times a second */
        nanosleep(&pause, NULL);
        return r;
    }
    *spp = progressive ? ms.samples : 1;
    *refine = progressive && *spp < 65536;
    int n = snprintf(status, len, "cluster %s: %s | %u/%u servers alive | slowest server %.1f ms", mode, backend,
                     st.servers_live, vc->servers, st.max_server_seconds * 1e3);
    pthread_mutex_lock(&vc->log_mu);
    if (n > 0 && (size_t)n < len && st.servers_live < vc->servers && vc->log[0])
        snprintf(status + n, len - (size_t)n, " | %s", vc->log);
    pthread_mutex_unlock(&vc->log_mu);
    return SY_OK;
}

/* >>selection (render thread: it owns the scene): a click picks through the view's back-end (or
 * the first that can pick) and selects the node hit (shift: toggles it; nothing hit: clears the
 * selection); H hides the selected nodes, I isolates them (sy_scene_isolate), U shows every node.
 * The flags are scene changes, committed here: every context (and cluster server) sees them. */
static uint32_t selected_nodes(const sy_scene *s, sy_node *out, uint32_t max)
{
    uint32_t n = 0;
    for (uint32_t id = sy_scene_next(s, SY_TYPE_NODE, 0); id; id = sy_scene_next(s, SY_TYPE_NODE, id)) {
        const sy_node_data *d = sy_node_get(s, (sy_node){id});
        if (d && (d->flags & SY_NODE_SELECTED)) {
            if (n < max) out[n] = (sy_node){id};
            n++;
        }
    }
    return n;
}

static sy_result view_selection(sy_scene *scene, sy_context_pool *pool, const sy_compose_spec *spec, const char *backend,
                                uint32_t w, uint32_t h, bool pick, double px, double py, bool add, int key, char *status,
                                size_t len, sy_pick_result *picked, sy_error *err)
{
    picked->hit = false;
    enum { MAX_SEL = 4096 };
    sy_node *sel = malloc(MAX_SEL * sizeof *sel);
    if (!sel) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "view: selection: out of memory");
    uint32_t n = selected_nodes(scene, sel, MAX_SEL);
    if (n > MAX_SEL) n = MAX_SEL;
    sy_result r = SY_OK;
    if (pick) {
        const sy_mediator_class *cls = sy_mediator_find(backend);
        if (!cls || !(cls->caps & SY_CAP_PICK)) cls = sy_mediator_with_caps(SY_CAP_PICK);
        sy_window *win = NULL;
        sy_viewport *vp = NULL;
        sy_viewport_desc vd = {.root = spec->root, .camera = spec->camera, .backend = cls ? cls->name : backend};
        sy_pick_result p = {0};
        if (!cls) r = sy_error_set(err, SY_ERR_UNSUPPORTED, "view: no back-end can pick");
        if (r == SY_OK) r = sy_window_create(w, h, &win, err);
        if (r == SY_OK) r = sy_window_add_viewport(win, &vd, &vp, err);
        if (r == SY_OK) sy_viewport_set_view(vp, spec->view);
        if (r == SY_OK && spec->clip_count)
            r = sy_viewport_set_clip_planes(vp, (const float(*)[4])spec->clip_planes, spec->clip_count, err);
        if (r == SY_OK && spec->clip_cap) r = sy_viewport_set_clip_cap(vp, spec->clip_cap_color, err); /* picks on caps */
        if (r == SY_OK) r = sy_window_pick(win, scene, pool, px, py, &p, err);
        sy_window_destroy(win);
        if (r == SY_OK) *picked = p;
        bool was = false;
        for (uint32_t i = 0; r == SY_OK && i < n; ++i) {
            if (p.hit && sel[i].id == p.node_id) was = true;
            else if (!add) r = sy_node_set_selected(scene, sel[i], false, err);
        }
        if (r == SY_OK && p.hit) r = sy_node_set_selected(scene, (sy_node){p.node_id}, !(add && was), err);
        const sy_node_data *d = p.hit ? sy_node_get(scene, (sy_node){p.node_id}) : NULL;
        if (r == SY_OK)
            snprintf(status, len, " | picked %s%.60s%s (node %u, triangle %u)", d && d->name ? "'" : "",
                     d && d->name ? d->name : p.hit ? "unnamed" : "nothing", d && d->name ? "'" : "", p.node_id, p.triangle);

    } else if (key == 'H') {
        for (uint32_t i = 0; r == SY_OK && i < n; ++i) r = sy_node_set_visible(scene, sel[i], false, err);
        if (r == SY_OK) snprintf(status, len, " | hid %u node%s", n, n == 1 ? "" : "s");
    } else if (key == 'I') {
        r = n ? sy_scene_isolate(scene, sel, n, err) : SY_OK;
        if (r == SY_OK) snprintf(status, len, n ? " | isolated %u node%s" : " | nothing selected to isolate", n, n == 1 ? "" : "s");
    } else if (key == 'U') {
        r = sy_scene_isolate(scene, NULL, 0, err);
        if (r == SY_OK) snprintf(status, len, " | every node shown");
    }
    free(sel);
    if (r == SY_OK) r = sy_scene_commit(scene, NULL, err);
    if (r == SY_OK) {
        size_t k = strlen(status);
        uint32_t now = selected_nodes(scene, NULL, 0);
        if (k < len) snprintf(status + k, len - k, " | %u selected", now);
    }
    return r;
}

/* >>render thread */
/* Waits on the viewer's condition variable until ms_left ms passed (monotonic clock: view_run sets
 * the condition's clock). */
static void view_wait_ms(viewer *v, double ms_left)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    double ns = (double)ts.tv_nsec + ms_left * 1e6;
    ts.tv_sec += (time_t)(ns / 1e9);
    ts.tv_nsec = (long)fmod(ns, 1e9);
    pthread_cond_timedwait(&v->cv, &v->mu, &ts);
}

/* Local rendering goes through the frame-time governor (core/sy_governor.h): while the view moves
 * each frame renders at the size that fits the budget (the display scales the image up), then the
 * view refines (full size, progressive samples per frame within the budget) and the thread sleeps
 * until input. The cluster renders at full size and refines on its own schedule. */
static void *render_main(void *p)
{
    viewer *v = p;
    const sy_view_args *a = v->args;
    sy_context_pool *pool = v->pool;
    sy_error err = {0};
    uint64_t seen = 0, cl_seen = 0;
    bool again = false;     /* plan (or, cluster: render) again without waiting for input */
    double wait_until = 0;  /* ms (sy_time_now): the governor's settle wait, 0 = none */
    char fstatus[96] = "";
    sy_interactive *ia = NULL; /* the governor, the display filter (sy_interactive.h) */
    if (sy_interactive_create(&(sy_governor_desc){.budget_ms = a->budget_ms}, &ia, &err) != SY_OK) goto fail_unlocked;
    sy_interactive_set_temporal(ia, !a->no_temporal);
    /* what the last planned frame showed besides the view, back-end and size: a difference is a
     * view change for the governor */
    uint32_t prev_stereo = 0, prev_w = 0;
    bool prev_overlay = false;
    /* the scene clock (space plays and pauses, '.' steps 1/24 s): the render thread owns the scene,
     * so it sets the time and commits; the moved nodes reach the back-ends as any change does, and
     * a frame whose time moved is a changed view for the governor */
    double t_start = 0, t_end = 0, wall_last = 0;
    bool was_playing = false;
    bool animated = sy_scene_time_range(a->scene, a->clip, &t_start, &t_end, NULL) == SY_OK && t_end > t_start;
    sy_pick_result prev_pick = {0}; /* the last pick that hit: the measurement's first point */
    bool have_prev = false;
    sy_clock clock = sy_clock_make(t_start, t_end);
    clock.playing = false;
    for (;;) {
        pthread_mutex_lock(&v->mu);
        while (!v->quit && seen == v->req_version && !again) {
            if (wait_until <= 0) {
                pthread_cond_wait(&v->cv, &v->mu);
                continue;
            }
            double left = wait_until - sy_time_now() * 1e3;
            if (left <= 0) break;
            view_wait_ms(v, left);
        }
        if (v->quit) {
            pthread_mutex_unlock(&v->mu);
            break;
        }
        again = false;
        wait_until = 0;
        seen = v->req_version;
        sy_interactive_input in = v->in;
        uint32_t bi = v->backend, stereo = v->stereo, w = v->w, h = v->h;
        bool overlay = v->overlay, playing = v->playing && animated;
        uint32_t steps = animated ? v->steps : 0;
        v->steps = 0;
        bool pick = v->pick, pick_add = v->pick_add;
        double pick_x = v->pick_x, pick_y = v->pick_y;
        int vis_key = v->vis_key;
        v->pick = false, v->vis_key = 0;
        uint32_t clip_count = v->clip_count;
        float clip_planes[SY_CLIP_PLANES_MAX][4], cap_color[3];
        memcpy(clip_planes, v->clip_planes, sizeof clip_planes);
        memcpy(cap_color, v->cap_color, sizeof cap_color);
        bool clip_cap = v->clip_cap, redraw = v->redraw;
        float fov_req = v->fov_req;
        v->redraw = false, v->fov_req = 0.0f;
        pthread_mutex_unlock(&v->mu);
        if (fov_req > 0.0f) { /* a recalled view's field of view: the camera's, a scene change */
            if (sy_interactive_set_fov(a->scene, a->spec.camera, fov_req, &err) != SY_OK) goto fail_unlocked;
            redraw = true;
        }
        bool time_moved = false;
        if (playing || steps) {
            double now = sy_time_now();
            clock.playing = true;
            if (playing && was_playing) sy_clock_advance(&clock, now - wall_last);
            for (uint32_t k = 0; k < steps; ++k) {
                clock.playing = true;
                sy_clock_advance(&clock, 1.0 / 24.0);
            }
            wall_last = now;
            if (sy_scene_set_time(a->scene, a->clip, clock.time, &err) != SY_OK ||
                sy_scene_commit(a->scene, NULL, &err) != SY_OK)
                goto fail_unlocked;
            time_moved = true;
        }
        was_playing = playing;

        const sy_mediator_class *cls = sy_mediator_at(bi);
        if (!cls) cls = sy_mediator_at(0);
        if (cls->caps & SY_CAP_REMOTE) cls = sy_mediator_find(a->backend); /* the cluster is not a choice of its own */
        if (!cls) cls = sy_mediator_at(0);
        bool changed = stereo != prev_stereo || w != prev_w || overlay != prev_overlay || time_moved || redraw;
        prev_stereo = stereo, prev_w = w, prev_overlay = overlay;
        sy_mat4 view; /* the camera, set on the viewports directly: the scene is not committed */
        sy_orbit_matrix(&in.orbit, &view);
        sy_compose_spec spec = a->spec;
        spec.backend = cls->name;
        spec.params = NULL;
        spec.view = &view;
        spec.has_overlay = a->spec.has_overlay && overlay;
        spec.stereo = stereo;
        spec.clip_count = clip_count; /* the planes and caps the keys set (the viewports' own, not the scene's) */
        memcpy(spec.clip_planes, clip_planes, sizeof spec.clip_planes);
        spec.clip_cap = clip_cap;
        memcpy(spec.clip_cap_color, cap_color, sizeof spec.clip_cap_color);
        uint32_t ew = stereo == SY_STEREO_SBS ? (w / 2 ? w / 2 : 1) : w;
        if (pick || vis_key) { /* click: pick and select; H, I, U: visibility (mono picks: the left eye's half) */
            char sst[sizeof v->sel_status] = "";
            sy_error serr = {0};
            double sx = stereo == SY_STEREO_SBS && pick_x >= ew ? pick_x - ew : pick_x;
            sy_pick_result picked = {0};
            sy_result sr = view_selection(a->scene, pool, &spec, cls->name, ew, h, pick && sx < ew && pick_y < h, sx,
                                          pick_y, pick_add, vis_key, sst, sizeof sst, &picked, &serr);
            if (sr != SY_OK) snprintf(sst, sizeof sst, " | select: %.120s", serr.message);
            if (sr == SY_OK && picked.hit) { /* measurement: from the previous hit and the last section plane */
                size_t k = strlen(sst);
                double dist;
                if (k < sizeof sst)
                    k += (size_t)snprintf(sst + k, sizeof sst - k, " | at (%.4g, %.4g, %.4g)", (double)picked.position[0],
                                          (double)picked.position[1], (double)picked.position[2]);
                if (have_prev && sy_pick_distance(&prev_pick, &picked, &dist, NULL) == SY_OK && k < sizeof sst)
                    k += (size_t)snprintf(sst + k, sizeof sst - k, " | %.4g m from the last pick", dist);
                if (clip_count && k < sizeof sst &&
                    sy_plane_distance(clip_planes[clip_count - 1], picked.position, &dist, NULL) == SY_OK)
                    snprintf(sst + k, sizeof sst - k, " | %.4g m from plane %u", dist, clip_count);
                prev_pick = picked, have_prev = true;
            }
            pthread_mutex_lock(&v->mu);
            snprintf(v->sel_status, sizeof v->sel_status, "%s", sst);
            if (sr == SY_OK && pick) {
                v->have_pick = picked.hit;
                memcpy(v->pick_pos, picked.position, sizeof v->pick_pos);
            }
            pthread_mutex_unlock(&v->mu);
            changed = true;
        }
        sy_governor_frame gf = {.width = ew, .height = h, .scale = 1.0f, .samples = 1};
        if (!v->cluster) {
            /* a progressive back-end refines a resting mono view; stereo renders once at full size */
            uint32_t caps = sy_mediator_class_caps(cls, NULL);
            if (stereo != SY_STEREO_NONE) caps &= ~(uint32_t)SY_CAP_PROGRESSIVE;
            sy_interactive_view iv = {.orbit = &in.orbit, .backend = cls, .caps = caps, .width = ew, .height = h,
                                      .filter_version = in.filter_version, .changed = changed};
            sy_interactive_plan(ia, &iv, sy_time_now() * 1e3, &gf, NULL);
            if (gf.wait_ms > 0) { /* settling after a moving frame: the refining frame comes next */
                wait_until = sy_time_now() * 1e3 + gf.wait_ms;
                continue;
            }
            if (gf.idle) continue; /* refined: sleep until input */
        }
        sy_layer img = {0}, right = {0};
        double t0 = sy_time_now();
        uint64_t cl_spp = 0; /* sy view --cluster: view_cluster_frame's results */
        bool cl_refine = false;
        uint32_t contexts = sy_context_pool_size(pool);
        char cl_status[sizeof v->status] = "";
        sy_result r;
        if (v->cluster) {
            /* a restart: anything asked since the last frame (camera, back-end, size, stereo) */
            bool restart = seen != cl_seen || time_moved;
            cl_seen = seen;
            r = view_cluster_frame(v->cluster, a, pool, &spec, cls->name, restart, ew, h, &img, &right, &cl_spp,
                                   &cl_refine, cl_status, sizeof cl_status, &err);
        } else {
            view_filter(ia, pool, a, cls, &in, gf.filter, fstatus, sizeof fstatus);
            sy_window_render_opts ro = {.sample_count = gf.samples, .preview = gf.preview};
            r = sy_compose_render(a->scene, pool, &spec, gf.width, gf.height, &ro, &img, &right, &err);
        }
        double ms = (sy_time_now() - t0) * 1e3;
        sy_layer_destroy(&right);
        if (r != SY_OK) {
            /* a back-end that fails is reported; the viewer keeps running with the others */
            pthread_mutex_lock(&v->mu);
            snprintf(v->status, sizeof v->status, "%.60s%s%.24s failed: %.60s", cl_status, cl_status[0] ? " | " : "",
                     cls->name, err.message);
            v->img_version++;
            pthread_mutex_unlock(&v->mu);
            again = v->cluster != NULL; /* cluster: retry, the servers may come back */
            continue;
        }
        sy_post_desc post = sy_post_display();
        sy_layer_post_apply(&img, &post);
        uint8_t *bytes = sy_interactive_rgba8(&img, SY_RGBA8_STRAIGHT); /* straight alpha for display */
        /* the frame's whole time (render, tone mapping, conversion); a frame that translated the
         * scene for a new context says nothing about the next ones */
        ms = (sy_time_now() - t0) * 1e3;
        if (!v->cluster) sy_interactive_report(ia, &gf, ms, sy_context_pool_size(pool) != contexts);
        sy_context *ctx = NULL;
        sy_mediator_stats st = {0};
        if (v->cluster) st.samples = cl_spp; /* no local context in cluster mode */
        else if (sy_context_pool_get(pool, a->scene, cls->name, NULL, a->spec.root.id, &ctx, &err) == SY_OK)
            sy_context_stats(ctx, &st);
        pthread_mutex_lock(&v->mu);
        free(v->img);
        v->img = bytes;
        v->img_w = bytes ? img.width : 0;
        v->img_h = bytes ? img.height : 0;
        v->frame_ms = ms;
        v->sync_ms = st.last_sync_seconds * 1e3;
        v->spp = st.samples;
        v->img_scale = gf.scale;
        v->img_moving = gf.moving;
        v->animated = animated;
        v->anim_time = clock.time;
        v->governed = !v->cluster;
        snprintf(v->status, sizeof v->status, "%s", v->cluster ? cl_status : cls->name);
        snprintf(v->filter_status, sizeof v->filter_status, "%s", fstatus);
        v->img_version++;
        if (v->img_req != seen) v->first_scale = gf.scale, v->first_moving = gf.moving;
        v->img_req = seen;
        pthread_mutex_unlock(&v->mu);
        sy_layer_destroy(&img);
        /* local: plan again (the governor says what comes next); cluster: keep refining; playing:
         * the next frame's time */
        again = v->cluster ? cl_refine || playing : true;
    }
    sy_interactive_destroy(ia);
    return NULL;
fail_unlocked:
    sy_interactive_destroy(ia);
    pthread_mutex_lock(&v->mu);
    v->error = err;
    v->failed = true;
    v->img_version++;
    pthread_mutex_unlock(&v->mu);
    return NULL;
}

/* >>input */
typedef struct input {
    viewer *v;
    double mx, my;
    double press_x, press_y; /* where the left button went down: a release there is a click (pick) */
    int drag; /* 0 none, 1 orbit, 2 pan */
    bool changed;
} input;

static void post_request(viewer *v)
{
    pthread_mutex_lock(&v->mu);
    v->req_version++;
    pthread_cond_signal(&v->cv);
    pthread_mutex_unlock(&v->mu);
}

/* Input thread, under v->mu: the heads-up text of the section planes. */
static void clip_status_update(viewer *v)
{
    if (!v->clip_count) {
        v->clip_status[0] = '\0';
        return;
    }
    const float *q = v->clip_planes[v->clip_count - 1];
    snprintf(v->clip_status, sizeof v->clip_status, " | %u plane%s%s, last (%.3g, %.3g, %.3g, %.4g)", v->clip_count,
             v->clip_count == 1 ? "" : "s", v->clip_cap ? " capped" : "", (double)q[0], (double)q[1], (double)q[2],
             (double)q[3]);
}

/* Input thread, under v->mu: the section plane keys (see viewer). true when key was one. */
static bool clip_key(viewer *v, int key)
{
    float *last = v->clip_count ? v->clip_planes[v->clip_count - 1] : NULL;
    if (key == GLFW_KEY_C) { /* a plane facing the view through the last pick (or the target): the near part goes */
        if (v->clip_count >= SY_CLIP_PLANES_MAX) {
            snprintf(v->mark_status, sizeof v->mark_status, " | at most %d section planes", SY_CLIP_PLANES_MAX);
            return true;
        }
        sy_mat4 m;
        sy_orbit_matrix(&v->in.orbit, &m);
        const float *p = v->have_pick ? v->pick_pos : v->in.orbit.target;
        float *q = v->clip_planes[v->clip_count];
        for (int k = 0; k < 3; ++k) q[k] = -m.m[8 + k]; /* the viewing direction (unit) */
        q[3] = -(q[0] * p[0] + q[1] * p[1] + q[2] * p[2]);
        if (sy_clip_planes_check((const float(*)[4])q, 1, NULL) == SY_OK) v->clip_count++;
    } else if (key == GLFW_KEY_X) {
        if (v->clip_count) v->clip_count--;
    } else if (key == GLFW_KEY_J || key == GLFW_KEY_L || key == GLFW_KEY_PAGE_DOWN || key == GLFW_KEY_PAGE_UP) {
        /* L / Page Up: the plane moves along its normal (more is cut away), J / Page Down: back */
        if (last) last[3] -= (key == GLFW_KEY_L || key == GLFW_KEY_PAGE_UP ? 1.0f : -1.0f) * v->step;
    } else if (key == GLFW_KEY_N) {
        for (int k = 0; last && k < 4; ++k) last[k] = -last[k];
    } else if (key == GLFW_KEY_K) {
        v->clip_cap = !v->clip_cap;
    } else {
        return false;
    }
    clip_status_update(v);
    return true;
}

/* Input thread, under v->mu: Ctrl+N saves the view in slot N (and the file), Shift+N recalls it. */
static void bookmark_key(viewer *v, int slot, bool save)
{
    sy_bookmark *b = &v->marks[slot];
    if (save) {
        *b = sy_bookmark_of_orbit(&v->in.orbit);
        b->fov = v->fov; /* the field of view too (0: an orthographic camera's: none) */
        sy_error e = {0};
        if (v->args->bookmarks && sy_bookmarks_save(v->args->bookmarks, v->marks, &e) != SY_OK)
            snprintf(v->mark_status, sizeof v->mark_status, " | view %d kept here only: %.100s", slot, e.message);
        else
            snprintf(v->mark_status, sizeof v->mark_status, " | saved view %d%s%.100s", slot, v->args->bookmarks ? " to " : "",
                     v->args->bookmarks ? v->args->bookmarks : "");
    } else if (!b->set) {
        snprintf(v->mark_status, sizeof v->mark_status, " | no view saved in %d (Ctrl+%d saves one)", slot, slot);
    } else {
        v->in.orbit = sy_orbit_of_bookmark(b);
        if (b->fov > 0.0f && v->fov > 0.0f && b->fov != v->fov) v->fov_req = v->fov = b->fov; /* the render thread sets it */
        snprintf(v->mark_status, sizeof v->mark_status, " | view %d", slot);
    }
}

static void on_key(GLFWwindow *w, int key, int scancode, int action, int mods)
{
    (void)scancode;
    input *in = glfwGetWindowUserPointer(w);
    viewer *v = in->v;
    if (action != GLFW_PRESS) return;
    if (key == GLFW_KEY_ESCAPE) glfwSetWindowShouldClose(w, GLFW_TRUE);
    else if (key >= GLFW_KEY_1 && key <= GLFW_KEY_9 && (mods & (GLFW_MOD_CONTROL | GLFW_MOD_SHIFT))) {
        pthread_mutex_lock(&v->mu);
        bookmark_key(v, key - GLFW_KEY_0, (mods & GLFW_MOD_CONTROL) != 0);
        v->redraw = true;
        v->req_version++;
        pthread_cond_signal(&v->cv);
        pthread_mutex_unlock(&v->mu);
    } else if (key == GLFW_KEY_C || key == GLFW_KEY_X || key == GLFW_KEY_J || key == GLFW_KEY_L || key == GLFW_KEY_N ||
               key == GLFW_KEY_K || key == GLFW_KEY_PAGE_UP || key == GLFW_KEY_PAGE_DOWN) {
        pthread_mutex_lock(&v->mu);
        clip_key(v, key);
        v->redraw = true;
        v->req_version++;
        pthread_cond_signal(&v->cv);
        pthread_mutex_unlock(&v->mu);
    } else if (key >= GLFW_KEY_1 && key <= GLFW_KEY_9 && (uint32_t)(key - GLFW_KEY_1) < sy_mediator_count()) {
        pthread_mutex_lock(&v->mu);
        v->backend = (uint32_t)(key - GLFW_KEY_1);
        v->req_version++;
        pthread_cond_signal(&v->cv);
        pthread_mutex_unlock(&v->mu);
    } else if (key == GLFW_KEY_O || key == GLFW_KEY_T) {
        pthread_mutex_lock(&v->mu);
        if (key == GLFW_KEY_O) v->overlay = !v->overlay;
        else v->stereo = v->stereo == SY_STEREO_NONE ? SY_STEREO_SBS : v->stereo == SY_STEREO_SBS ? SY_STEREO_ANAGLYPH
                                                                                                   : SY_STEREO_NONE;
        v->req_version++;
        pthread_cond_signal(&v->cv);
        pthread_mutex_unlock(&v->mu);
    } else if (key == GLFW_KEY_SPACE || key == GLFW_KEY_PERIOD) { /* the scene clock: play / pause, one step */
        pthread_mutex_lock(&v->mu);
        if (key == GLFW_KEY_SPACE) v->playing = !v->playing;
        else if (v->steps < 1000u) v->steps++;
        v->req_version++;
        pthread_cond_signal(&v->cv);
        pthread_mutex_unlock(&v->mu);
    } else if (key == GLFW_KEY_H || key == GLFW_KEY_I || key == GLFW_KEY_U) { /* hide / isolate / show all */
        pthread_mutex_lock(&v->mu);
        v->vis_key = key; /* GLFW's codes of letters are their capitals */
        v->req_version++;
        pthread_cond_signal(&v->cv);
        pthread_mutex_unlock(&v->mu);
    } else if (key == GLFW_KEY_F || key == GLFW_KEY_LEFT_BRACKET || key == GLFW_KEY_RIGHT_BRACKET || key == GLFW_KEY_R) {
        /* the display filter: F cycles it, [ ] halve / double the threshold (live: the render thread
         * applies it to its context, the accumulation keeps its samples); R: the camera home */
        pthread_mutex_lock(&v->mu);
        sy_interactive_key(&v->in, key); /* GLFW's codes of these keys are their characters */
        v->req_version++;
        pthread_cond_signal(&v->cv);
        pthread_mutex_unlock(&v->mu);
    }
}

static void on_button(GLFWwindow *w, int button, int action, int mods)
{
    input *in = glfwGetWindowUserPointer(w);
    glfwGetCursorPos(w, &in->mx, &in->my);
    if (action == GLFW_RELEASE && in->drag == 1 && fabs(in->mx - in->press_x) < 3 && fabs(in->my - in->press_y) < 3) {
        /* a click (the button went up where it went down): pick and select, in image pixels */
        int ww, wh, fw, fh;
        glfwGetWindowSize(w, &ww, &wh);
        glfwGetFramebufferSize(w, &fw, &fh);
        viewer *v = in->v;
        pthread_mutex_lock(&v->mu);
        v->pick = true;
        v->pick_add = (mods & GLFW_MOD_SHIFT) != 0;
        v->pick_x = ww > 0 ? in->mx * fw / ww : in->mx;
        v->pick_y = wh > 0 ? in->my * fh / wh : in->my;
        v->req_version++;
        pthread_cond_signal(&v->cv);
        pthread_mutex_unlock(&v->mu);
    }
    if (action == GLFW_PRESS) in->press_x = in->mx, in->press_y = in->my;
    if (action == GLFW_RELEASE) in->drag = 0;
    else in->drag = button == GLFW_MOUSE_BUTTON_LEFT ? 1 : 2;
}

static void on_cursor(GLFWwindow *w, double x, double y)
{
    input *in = glfwGetWindowUserPointer(w);
    double dx = x - in->mx, dy = y - in->my;
    in->mx = x, in->my = y;
    if (!in->drag) return;
    pthread_mutex_lock(&in->v->mu);
    sy_interactive_drag(&in->v->in, in->drag == 1 ? 0 : 1, (float)dx, (float)dy);
    pthread_mutex_unlock(&in->v->mu);
    in->changed = true;
}

static void on_scroll(GLFWwindow *w, double dx, double dy)
{
    (void)dx;
    input *in = glfwGetWindowUserPointer(w);
    viewer *v = in->v;
    pthread_mutex_lock(&v->mu);
    if ((glfwGetKey(w, GLFW_KEY_LEFT_CONTROL) == GLFW_PRESS || glfwGetKey(w, GLFW_KEY_RIGHT_CONTROL) == GLFW_PRESS) &&
        v->clip_count) { /* Ctrl+wheel: the last section plane moves along its normal */
        if (isfinite(dy)) v->clip_planes[v->clip_count - 1][3] -= (float)dy * v->step;
        clip_status_update(v);
        v->redraw = true;
    } else {
        sy_interactive_wheel(&v->in, (float)dy);
    }
    pthread_mutex_unlock(&v->mu);
    in->changed = true;
}

static void fly(GLFWwindow *w, input *in, float dt)
{
    float mv[3] = {0, 0, 0};
    if (glfwGetKey(w, GLFW_KEY_W) == GLFW_PRESS) mv[2] -= 1;
    if (glfwGetKey(w, GLFW_KEY_S) == GLFW_PRESS) mv[2] += 1;
    if (glfwGetKey(w, GLFW_KEY_A) == GLFW_PRESS) mv[0] -= 1;
    if (glfwGetKey(w, GLFW_KEY_D) == GLFW_PRESS) mv[0] += 1;
    if (glfwGetKey(w, GLFW_KEY_E) == GLFW_PRESS) mv[1] += 1;
    if (glfwGetKey(w, GLFW_KEY_Q) == GLFW_PRESS) mv[1] -= 1;
    if (mv[0] == 0 && mv[1] == 0 && mv[2] == 0) return;
    pthread_mutex_lock(&in->v->mu);
    if (sy_interactive_fly(&in->v->in, mv, dt)) in->changed = true;
    pthread_mutex_unlock(&in->v->mu);
}

static sy_result write_screenshot(const char *path, int w, int h, sy_error *err)
{
    size_t n = (size_t)w * h;
    uint8_t *px = malloc(n * 4);
    float *f = malloc(n * 4 * sizeof(float));
    sy_result r = SY_OK;
    if (!px || !f) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "screenshot: out of memory");
    if (r == SY_OK) {
        glPixelStorei(GL_PACK_ALIGNMENT, 1);
        glReadBuffer(GL_BACK);
        glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, px);
        for (int y = 0; y < h; ++y) /* GL rows are bottom-up; the window shows sRGB bytes */
            for (int x = 0; x < w * 4; ++x) {
                float b = px[(size_t)(h - 1 - y) * w * 4 + x] / 255.0f;
                f[(size_t)y * w * 4 + x] = (x & 3) == 3 ? 1.0f : sy_srgb_decode(b);
            }
        r = sy_png_write(path, w, h, f, NULL, err);
    }
    free(px);
    free(f);
    return r;
}

static sy_result view_run(const sy_view_args *args, sy_context_pool *pool, view_cluster *cluster, sy_error *err)
{
    /* the orbit at the camera's pose, the initial display filter and threshold: checked before any
     * window opens (sy_interactive.h) */
    sy_interactive_input in0;
    sy_result r = sy_interactive_input_init(args->scene, args->spec.root, args->spec.camera,
                                            (float)args->width / (float)args->height, args->filter, args->threshold, &in0,
                                            err);
    if (r != SY_OK) {
        sy_error_prefix(err, "view");
        return r;
    }
    for (const char *k = args->keys; k && *k; ++k) {
        if ((*k == '^' || *k == '~') && isalnum((unsigned char)k[1])) continue; /* Ctrl, Shift with the next key */
        if (!isalnum((unsigned char)*k) && *k != '[' && *k != ']' && *k != ' ' && *k != '.' && *k != '*')
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                                "view: --keys: '%c' is not a key (letters, digits, [ ], space, . and * for a click; ^ "
                                "or ~ before a letter or digit: with Ctrl or Shift)", *k);
    }
    if (!glfwInit()) {
        const char *desc = NULL;
        glfwGetError(&desc);
        return sy_error_set(err, SY_ERR_BACKEND, "view: GLFW could not start (%s); is there a display? try xvfb-run",
                            desc ? desc : "no reason given");
    }
    GLFWwindow *win = glfwCreateWindow((int)args->width, (int)args->height, "sy view", NULL, NULL);
    if (!win) {
        const char *desc = NULL;
        glfwGetError(&desc);
        glfwTerminate();
        return sy_error_set(err, SY_ERR_BACKEND, "view: cannot open a window: %s", desc ? desc : "unknown reason");
    }
    glfwMakeContextCurrent(win);
    glfwSwapInterval(1);

    viewer v;
    memset(&v, 0, sizeof v);
    v.args = args;
    v.cluster = cluster;
    v.pool = pool;
    pthread_mutex_init(&v.mu, NULL);
    pthread_condattr_t ca; /* the render thread's timed waits use the monotonic clock */
    pthread_condattr_init(&ca);
    pthread_condattr_setclock(&ca, CLOCK_MONOTONIC);
    pthread_cond_init(&v.cv, &ca);
    pthread_condattr_destroy(&ca);
    sy_interactive_backend_index(args->backend, &v.backend, NULL); /* NULL: the registry's default */
    v.overlay = true;
    v.clip_count = args->spec.clip_count; /* --clip, --clip-cap: the start planes (the keys change them) */
    memcpy(v.clip_planes, args->spec.clip_planes, sizeof v.clip_planes);
    v.clip_cap = args->spec.clip_cap;
    if (args->spec.clip_cap) memcpy(v.cap_color, args->spec.clip_cap_color, sizeof v.cap_color);
    else v.cap_color[0] = 0.8f, v.cap_color[1] = 0.25f, v.cap_color[2] = 0.02f; /* K's default: orange */
    {
        sy_bounds b = sy_scene_world_bounds(args->scene);
        float diag = 1.0f;
        if (!sy_bounds_is_empty(&b)) {
            float dx = b.max[0] - b.min[0], dy = b.max[1] - b.min[1], dz = b.max[2] - b.min[2];
            diag = sqrtf(dx * dx + dy * dy + dz * dz);
        }
        v.step = isfinite(diag) && diag > 0.0f ? diag / 50.0f : 0.02f;
    }
    clip_status_update(&v);
    if (args->bookmarks) { /* the saved views (a missing file: none yet) */
        sy_error be = {0};
        sy_result br = sy_bookmarks_load(args->bookmarks, v.marks, &be);
        if (br != SY_OK && br != SY_ERR_NOT_FOUND) sy_log(SY_LOG_WARNING, "sy", NULL, "view: %s (starting without saved views)", be.message);
    }
    if (cluster && cluster->mode == SY_CLUSTER_STEREO) v.stereo = SY_STEREO_SBS; /* --cluster-mode stereo */

    /* the camera: the application's camera node gives the projection, the orbit the view (set on
     * the viewports directly: the scene is never committed) */
    input in = {.v = &v};
    const sy_node_data *cn = args->spec.camera.id ? sy_node_get(args->scene, args->spec.camera) : NULL;
    if (!cn || !cn->camera.id) {
        glfwDestroyWindow(win);
        glfwTerminate();
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "view: the scene has no camera");
    }
    v.in = in0;
    v.fov = sy_interactive_fov(args->scene, args->spec.camera);
    int fbw, fbh;
    glfwGetFramebufferSize(win, &fbw, &fbh);
    v.w = (uint32_t)fbw, v.h = (uint32_t)fbh;
    v.req_version = 1;

    pthread_t th;
    if (pthread_create(&th, NULL, render_main, &v) != 0) {
        glfwDestroyWindow(win);
        glfwTerminate();
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "view: cannot start the render thread");
    }
    glfwSetWindowUserPointer(win, &in);
    glfwSetKeyCallback(win, on_key);
    glfwSetMouseButtonCallback(win, on_button);
    glfwSetCursorPosCallback(win, on_cursor);
    glfwSetScrollCallback(win, on_scroll);

    uint64_t shown = 0, displayed = 0;
    double last = glfwGetTime();
    uint8_t *img = NULL;
    uint32_t iw = 0, ih = 0;
    char title[2048] = "sy view"; /* the longest status parts together: 1,415 bytes */
    const char *keys = args->keys; /* scripted key presses, one per answered frame */
    char key_last = 0;
    uint64_t key_req = 0;
    while (!glfwWindowShouldClose(win)) {
        glfwWaitEventsTimeout(1.0 / 60.0);
        double now = glfwGetTime();
        fly(win, &in, (float)(now - last));
        last = now;
        glfwGetFramebufferSize(win, &fbw, &fbh);
        pthread_mutex_lock(&v.mu);
        if ((uint32_t)fbw != v.w || (uint32_t)fbh != v.h) {
            v.w = fbw > 0 ? (uint32_t)fbw : 1, v.h = fbh > 0 ? (uint32_t)fbh : 1;
            v.req_version++;
            pthread_cond_signal(&v.cv);
        }
        bool fresh = v.img_version != shown;
        if (fresh) {
            shown = v.img_version;
            if (v.img) {
                free(img);
                img = malloc((size_t)v.img_w * v.img_h * 4);
                if (img) memcpy(img, v.img, (size_t)v.img_w * v.img_h * 4);
                iw = img ? v.img_w : 0, ih = img ? v.img_h : 0;
            }
            char sync[32] = "", scale[40] = ""; /* cluster mode: the servers sync (their time is in the status) */
            if (!v.cluster) snprintf(sync, sizeof sync, " | sync %.2f ms", v.sync_ms);
            if (v.governed) /* the governor's resolution scale: reduced while the view moves */
                snprintf(scale, sizeof scale, " | scale %.2f%s", (double)v.img_scale, v.img_moving ? " moving" : "");
            char clock_s[48] = ""; /* the scene clock, when the scene moves */
            if (v.animated) snprintf(clock_s, sizeof clock_s, " | t %.3f s %s", v.anim_time, v.playing ? "playing" : "paused");
            snprintf(title, sizeof title, "sy view | %s | frame %.1f ms%s | %llu spp%s%s%s%s%s%s%s", v.status, v.frame_ms,
                     scale, (unsigned long long)v.spp, sync,
                     v.stereo == SY_STEREO_SBS ? " | stereo sbs" : v.stereo == SY_STEREO_ANAGLYPH ? " | anaglyph" : "",
                     v.filter_status, clock_s, v.sel_status, v.clip_status, v.mark_status);
            glfwSetWindowTitle(win, title);
        }
        /* a frame counts for --frames once settled, or any frame while the scene clock plays (it never settles) */
        bool failed = v.failed, answered = fresh && v.img_req >= key_req, settled = !v.img_moving || v.playing;
        float first_scale = v.first_scale;
        bool first_moving = v.first_moving, governed = v.governed;
        pthread_mutex_unlock(&v.mu);
        if (failed) break;
        if (answered && key_last) { /* scripted --keys: the heads-up line once the key took effect */
            if (governed) /* the frame that first answered the key (this one, or an earlier one not shown) */
                printf("sy view: key %c first answered by: scale %.2f%s\n", key_last, (double)first_scale,
                       first_moving ? " moving" : "");
            printf("sy view: after key %c: %s\n", key_last, title);
            key_last = 0;
        }
        if (answered && keys && *keys) { /* the next scripted key, through the keyboard handler */
            int kmods = *keys == '^' ? GLFW_MOD_CONTROL : *keys == '~' ? GLFW_MOD_SHIFT : 0;
            if (kmods) keys++;
            key_last = *keys++;
            if (key_last == '*') { /* a scripted click at the window's centre: pick and select there */
                pthread_mutex_lock(&v.mu);
                v.pick = true, v.pick_add = false, v.pick_x = fbw / 2.0, v.pick_y = fbh / 2.0;
                v.req_version++;
                pthread_cond_signal(&v.cv);
                pthread_mutex_unlock(&v.mu);
            } else {
                on_key(win, toupper((unsigned char)key_last), 0, GLFW_PRESS, kmods);
            }
            /* a new frame answers every scripted key, even one that changes nothing the render sees
             * (an unbound letter, H with nothing selected): a back-end that settles (raster) draws no
             * frame by itself, and the script waited for one forever */
            pthread_mutex_lock(&v.mu);
            v.redraw = true;
            key_req = ++v.req_version;
            pthread_cond_signal(&v.cv);
            pthread_mutex_unlock(&v.mu);
        }
        if (in.changed) {
            in.changed = false;
            post_request(&v);
        }
        glViewport(0, 0, fbw, fbh);
        glClearColor(0, 0, 0, 1);
        glClear(GL_COLOR_BUFFER_BIT);
        if (img && iw && ih) {
            glRasterPos2f(-1.0f, 1.0f);
            glPixelZoom((float)fbw / (float)iw, -(float)fbh / (float)ih);
            glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
            glDrawPixels((GLsizei)iw, (GLsizei)ih, GL_RGBA, GL_UNSIGNED_BYTE, img);
        }
        if (img && settled && !key_last && !(keys && *keys)) { /* settled frames shown (after scripted keys) */
            displayed++;
            sy_testpoint("frame"); /* tests wait for a shown frame (sy_testpoint.h) */
        }
        if (args->frames && displayed >= args->frames) {
            if (args->screenshot) r = write_screenshot(args->screenshot, fbw, fbh, err);
            if (!glfwWindowShouldClose(win)) printf("%s\n", title); /* automated runs: the last heads-up line */
            fflush(stdout); /* before any exit-time check (a sanitizer's) can end the process */
            glfwSetWindowShouldClose(win, GLFW_TRUE);
        }
        glfwSwapBuffers(win);
    }
    pthread_mutex_lock(&v.mu);
    v.quit = true;
    pthread_cond_signal(&v.cv);
    pthread_mutex_unlock(&v.mu);
    pthread_join(th, NULL);
    if (v.failed && r == SY_OK) {
        *err = v.error;
        r = v.error.code ? v.error.code : SY_ERR_BACKEND;
    }
    free(img);
    free(v.img);
    pthread_mutex_destroy(&v.mu);
    pthread_cond_destroy(&v.cv);
    glfwDestroyWindow(win);
    glfwTerminate();
    return r;
}

sy_result sy_view_run(const sy_view_args *args, sy_error *err)
{
    sy_context_pool *pool = NULL;
    view_cluster *vc = NULL; /* sy view --cluster: connected before the window opens */
    sy_result r = sy_context_pool_create(&pool, err);
    if (r == SY_OK && args->cluster) r = view_cluster_open(args, pool, &vc, err);
    sy_view_args a = *args;
    if (vc && vc->mode == SY_CLUSTER_MULTI_DISPLAY && vc->viewer_tile.w) /* a window of the tile's size */
        a.width = vc->viewer_tile.w, a.height = vc->viewer_tile.h;
    if (r == SY_OK) r = view_run(&a, pool, vc, err);
    sy_context_pool_destroy(pool); /* the cluster contexts say BYE to their servers */
    view_cluster_close(vc);
    return r;
}
