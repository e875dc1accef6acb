/* sy_web.c — the browser viewport's server (sy_web.h, docs/WEB.md): create and destroy, the
 * accessors and the counters. libwebsockets (HTTP + WebSocket) runs on a network thread,
 * rendering on the thread in sy_web_run, a mailbox between them; the modules, bottom-up, are listed
 * in sy_web_internal.h:
 *   sy_web_mailbox.c  what the two threads share (under mu)
 *   sy_web_http.c     page, stills, routes, token, body collection
 *   sy_web_ws.c       viewers: input messages in, newest frame out
 *   sy_web_render.c   the render loop (frames, stills, routes)
 *   sy_web.c          create / destroy */
#include "sy_web_internal.h"

#include "sy_jpeg.h"
#include "sy_log.h"
#include "sy_mediator.h"

#include <sodium.h>

#include <ctype.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static void lws_log_to_sy(int level, const char *line)
{
    /* lws 4.1 logs every adoption of a socket with its read buffer as an error: not one */
    if (strstr(line, "adopt_socket_readbuf")) return;
    size_t n = strlen(line);
    while (n && (line[n - 1] == '\n' || line[n - 1] == '\r')) n--;
    sy_log(level & LLL_ERR ? SY_LOG_ERROR : SY_LOG_WARNING, "web.lws", NULL, "%.*s", (int)n, line);
}

/* "HOST:PORT" or "[V6]:PORT" */
static sy_result parse_listen(const char *s, char *host, size_t hl, int *port, sy_error *err)
{
    const char *colon = s[0] == '[' ? strstr(s, "]:") : strrchr(s, ':');
    if (!colon) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "web: --listen '%s': expected HOST:PORT", s);
    size_t n = (size_t)(colon - s) + (s[0] == '[' ? 1 : 0);
    const char *h = s;
    if (s[0] == '[') h++, n -= 2;
    if (n == 0 || n >= hl) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "web: --listen '%s': bad host", s);
    memcpy(host, h, n);
    host[n] = 0;
    const char *ps = colon + (s[0] == '[' ? 2 : 1);
    char *end;
    errno = 0;
    long p = strtol(ps, &end, 10);
    if (errno || end == ps || *end || p < 0 || p > 65535)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "web: --listen '%s': port must be 0..65535", s);
    *port = (int)p;
    return SY_OK;
}

/* A clip's name for the page (a WebSocket text message must be UTF-8): valid UTF-8 sequences that
 * fit are kept, control characters and other bytes become '?'. */
static void clip_name(char *out, size_t cap, const char *name)
{
    const unsigned char *s = (const unsigned char *)name;
    size_t o = 0;
    while (*s && o + 1 < cap) {
        size_t n = *s < 0x80 ? 1 : (*s & 0xE0) == 0xC0 ? 2 : (*s & 0xF0) == 0xE0 ? 3 : (*s & 0xF8) == 0xF0 ? 4 : 0;
        bool ok = n == 1 ? *s >= 0x20 && *s != 0x7f : n > 1 && *s >= 0xC2 && *s <= 0xF4;
        for (size_t k = 1; ok && k < n; ++k) ok = (s[k] & 0xC0) == 0x80;
        if (ok && n == 3) ok = !(s[0] == 0xE0 && s[1] < 0xA0) && !(s[0] == 0xED && s[1] >= 0xA0); /* overlong, surrogates */
        if (ok && n == 4) ok = !(s[0] == 0xF0 && s[1] < 0x90) && !(s[0] == 0xF4 && s[1] >= 0x90);
        if (!ok || o + n >= cap) {
            if (ok) break; /* a whole character that does not fit: cut before it */
            out[o++] = '?';
            ++s;
            continue;
        }
        memcpy(out + o, s, n);
        o += n, s += n;
    }
    out[o] = 0;
}

/* The clips a page may choose (sy_web_internal.h): the scene's animations in slot order (the
 * indices sy_animation_find takes), their ranges, then every clip together; w->clip the one chosen
 * (want; {0}: every clip). A clip without keys has the empty range [0, 0]. */
static sy_result web_clips(sy_web *w, sy_animation want, sy_error *err)
{
    const sy_scene *s = w->d.scene;
    uint32_t n = sy_scene_count(s, SY_TYPE_ANIMATION);
    w->clips = calloc(n + 1, sizeof *w->clips);
    w->clip_range = calloc(n + 1, sizeof *w->clip_range);
    w->clip_names = calloc(n + 1, sizeof *w->clip_names);
    if (!w->clips || !w->clip_range || !w->clip_names) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "web: out of memory");
    for (uint32_t id = sy_scene_next(s, SY_TYPE_ANIMATION, 0); id && w->clip_count < n; id = sy_scene_next(s, SY_TYPE_ANIMATION, id))
        w->clips[w->clip_count++] = (sy_animation){id};
    w->clip = w->clip_count;
    for (uint32_t i = 0; i <= w->clip_count; ++i) {
        double *rg = w->clip_range[i];
        if (sy_scene_time_range(s, w->clips[i], &rg[0], &rg[1], NULL) != SY_OK || !(rg[1] >= rg[0])) rg[0] = rg[1] = 0;
        if (i == w->clip_count) break;
        if (want.id && w->clips[i].id == want.id) w->clip = i;
        const sy_animation_data *ad = sy_animation_get(s, w->clips[i]);
        if (ad && ad->name && ad->name[0]) clip_name(w->clip_names[i], sizeof w->clip_names[i], ad->name);
        else snprintf(w->clip_names[i], sizeof w->clip_names[i], "clip %u", i);
    }
    if (want.id && w->clip == w->clip_count)
        return sy_error_set(err, SY_ERR_NOT_FOUND, "web: clip %u is not an animation of the scene", want.id);
    return SY_OK;
}

sy_result sy_web_create(const sy_web_desc *desc, sy_web **out, sy_error *err)
{
    *out = NULL;
    if (!desc || !desc->scene) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "web: no scene");
    const sy_node_data *cn = desc->camera.id ? sy_node_get(desc->scene, desc->camera) : NULL;
    if (!cn || !cn->camera.id) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "web: the scene has no camera");
    uint32_t bi = 0; /* the registry's default when none is named */
    sy_result rb = sy_interactive_backend_index(desc->backend, &bi, err);
    if (rb != SY_OK) {
        sy_error_prefix(err, "web");
        return rb;
    }
    const char *backend = sy_mediator_at(bi)->name;
    if (sodium_init() < 0) return sy_error_set(err, SY_ERR_BACKEND, "web: libsodium could not start");
    sy_web *w = calloc(1, sizeof *w);
    if (!w) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "web: out of memory");
    w->d = *desc;
    w->d.backend = backend;
    if (!w->d.max_width) w->d.max_width = 1920;
    if (!w->d.max_height) w->d.max_height = 1200;
    if (!w->d.max_clients) w->d.max_clients = 8;
    if (!w->d.max_body) w->d.max_body = 1u << 20;
    if (!w->d.max_message) w->d.max_message = 4096;
    if (!w->d.quality) w->d.quality = 80;
    if (!w->d.still_samples) w->d.still_samples = 16;
    if (!w->d.idle_timeout_s) w->d.idle_timeout_s = 30;
    if (!w->d.still_max_pixels) w->d.still_max_pixels = 2048u * 2048u;
    if (!w->d.still_deadline_ms) w->d.still_deadline_ms = 10000;
    if (!w->d.head_timeout_ms) w->d.head_timeout_ms = 5000;
    if (!w->d.max_pending) w->d.max_pending = 128;
    if (!w->d.min_scale) w->d.min_scale = SY_WEB_MIN_SCALE;
    w->initial_backend = w->backend = bi;
    pthread_mutex_init(&w->mu, NULL);
    /* the timeline: the range of desc->clip (every clip together: {0}), paused at its start (a page
     * plays it, or chooses another clip) */
    sy_result r = web_clips(w, desc->clip, err);
    double t0 = 0, t1 = 0;
    if (r == SY_OK) t0 = w->clip_range[w->clip][0], t1 = w->clip_range[w->clip][1];
    w->animated = r == SY_OK && w->clip_range[w->clip_count][1] > w->clip_range[w->clip_count][0]; /* any clip moves */
    w->clock = sy_clock_make(t0, t1);
    w->clock.playing = false;
    w->clock_version = w->animated ? 1 : 0;
    pthread_cond_init(&w->cv, NULL);
    w->pending_tail = &w->pending;
    w->stills_tail = &w->stills;
    w->actions_tail = &w->actions;
    w->replies_tail = &w->replies;
    if (r == SY_OK && (w->d.max_width > 16384 || w->d.max_height > 16384 || w->d.max_clients > 1000 || w->d.max_message < 64 ||
        w->d.max_message > (1u << 24) || w->d.quality < 1 || w->d.quality > 100 || w->d.idle_timeout_s > 3600 ||
        !(w->d.budget_ms >= 0 && w->d.budget_ms <= 1e5) || w->d.still_max_pixels > (uint64_t)SY_JPEG_MAX_SIDE * SY_JPEG_MAX_SIDE ||
        w->d.max_pending > 1024 || w->d.head_timeout_ms > 600000 || w->d.still_deadline_ms > 600000 || w->d.delay_ms > 10000 ||
        !(w->d.min_scale > 0.0f && w->d.min_scale <= 1.0f)))
        r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                         "web: a limit is out of range (frame <= 16384, clients <= 1000, message 64..16 MiB, quality "
                         "1..100, idle timeout <= 3600 s, budget 0..1e5 ms, still pixels <= 16384^2, pending "
                         "connections <= 1024, head timeout and still deadline <= 600 s, delay <= 10000 ms, min_scale "
                         "in (0, 1])");
    if (r == SY_OK) r = parse_listen(desc->listen ? desc->listen : "127.0.0.1:8080", w->host, sizeof w->host, &w->port, err);
    if (r == SY_OK && desc->route_count) {
        w->routes = calloc(desc->route_count, sizeof *w->routes);
        if (!w->routes) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "web: out of memory");
        for (uint32_t i = 0; r == SY_OK && i < desc->route_count; ++i) {
            w->routes[i] = desc->routes[i];
            if (!w->routes[i].fn || !w->routes[i].path || w->routes[i].path[0] != '/' || !w->routes[i].method ||
                (strcmp(w->routes[i].method, "GET") && strcmp(w->routes[i].method, "POST")))
                r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "web: route %u needs GET or POST, a path from / and a handler", i);
        }
        w->d.routes = w->routes;
    }
    /* the access token: required off loopback */
    w->loopback = sy_web_name_is_loopback(w->host);
    if (r == SY_OK && desc->token) {
        size_t n = strlen(desc->token);
        bool hex = n >= 16 && n < sizeof w->token;
        for (size_t i = 0; hex && i < n; ++i) hex = isxdigit((unsigned char)desc->token[i]) != 0;
        if (!hex) r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "web: the token must be 16..32 hex digits");
        else snprintf(w->token, sizeof w->token, "%s", desc->token);
    } else if (r == SY_OK && !w->loopback) {
        uint8_t raw[WEB_TOKEN_BYTES];
        randombytes_buf(raw, sizeof raw);
        sodium_bin2hex(w->token, sizeof w->token, raw, sizeof raw);
        sodium_memzero(raw, sizeof raw);
    }
    /* the view every page shares starts at the camera's pose; it is set on the server's viewports,
     * never in the scene (sy_interactive.h): the server adds nothing to the scene (a recalled saved
     * view's field of view is set on the camera: sy_web_views.c) */
    if (r == SY_OK && (r = sy_interactive_input_init(desc->scene, desc->root, desc->camera, 1.0f, desc->filter,
                                                     desc->threshold > 0 ? desc->threshold : 0.0f, &w->in, err)))
        sy_error_prefix(err, "web");
    if (r == SY_OK) sy_orbit_matrix(&w->in.orbit, &w->view);
    if (r == SY_OK) r = sy_webi_views_init(w, desc, err);
    if (r != SY_OK) {
        sy_web_destroy(w);
        return r;
    }
    /* libwebsockets: one context, one vhost on the address, the page and /ws */
    lws_set_log_level(getenv("SY_LWS_DEBUG") ? 0xff : LLL_ERR | LLL_WARN, lws_log_to_sy);
    struct lws_context_creation_info ci;
    memset(&ci, 0, sizeof ci);
    ci.options = LWS_SERVER_OPTION_EXPLICIT_VHOSTS | LWS_SERVER_OPTION_VALIDATE_UTF8;
    ci.user = w;
    /* the gate holds connections until their request is whole: lws sees only requests being
     * answered and viewers */
    ci.fd_limit_per_thread = 256 + 2 * w->d.max_clients;
    ci.max_http_header_data = SY_WEB_MAX_HEAD + 1024;
    ci.port = CONTEXT_PORT_NO_LISTEN;
    w->ctx = lws_create_context(&ci);
    if (!w->ctx) {
        sy_web_destroy(w);
        return sy_error_set(err, SY_ERR_IO, "web: libwebsockets could not start");
    }
    struct lws_context_creation_info vi;
    memset(&vi, 0, sizeof vi);
    vi.port = CONTEXT_PORT_NO_LISTEN_SERVER; /* the gate listens (sy_web_gate.h) */
    vi.protocols = sy_webi_protocols;
    vi.mounts = &sy_webi_mount;
    vi.vhost_name = "sy-web";
    vi.options = !strchr(w->host, ':') ? LWS_SERVER_OPTION_DISABLE_IPV6 : 0;
    vi.timeout_secs = 10;       /* handshakes, headers and bodies that stall */
    vi.keepalive_timeout = 10;  /* an idle HTTP keep-alive connection */
    vi.server_string = "sy web";
    /* WebSocket: a silent client is pinged, then closed */
    w->retry_ms = 1000;
    w->idle.retry_ms_table = &w->retry_ms;
    w->idle.retry_ms_table_count = 1;
    w->idle.secs_since_valid_ping = (uint16_t)w->d.idle_timeout_s;
    w->idle.secs_since_valid_hangup = (uint16_t)(2 * w->d.idle_timeout_s);
    vi.retry_and_idle_policy = &w->idle;
    w->vhost = lws_create_vhost(w->ctx, &vi);
    if (!w->vhost) {
        sy_web_destroy(w);
        return sy_error_set(err, SY_ERR_IO, "web: libwebsockets could not make its vhost");
    }
    /* what sy_web_check_request allows: stills at most 2 x the frame cap per side (within JPEG's) */
    uint32_t sw = 2 * w->d.max_width, sh = 2 * w->d.max_height;
    w->policy = (sy_web_policy){.token = w->token, .routes = w->routes, .route_count = w->d.route_count,
                                .max_body = w->d.max_body,
                                .still_max_w = sw < SY_JPEG_MAX_SIDE ? sw : SY_JPEG_MAX_SIDE,
                                .still_max_h = sh < SY_JPEG_MAX_SIDE ? sh : SY_JPEG_MAX_SIDE,
                                .still_max_pixels = w->d.still_max_pixels};
    if (pthread_create(&w->net_thread, NULL, sy_webi_net_main, w) != 0) {
        sy_web_destroy(w);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "web: cannot start the network thread");
    }
    w->net_started = true;
    sy_web_gate_desc gd = {.host = w->host, .port = w->port, .max_pending = w->d.max_pending,
                           .head_timeout_ms = w->d.head_timeout_ms, .max_body = w->d.max_body,
                           .deliver = sy_webi_gate_deliver, .user = w};
    r = sy_web_gate_create(&gd, &w->gate, err);
    if (r != SY_OK) {
        sy_web_destroy(w);
        return r;
    }
    w->port = sy_web_gate_port(w->gate);
    const char *shown = strchr(w->host, ':') ? "[" : "";
    snprintf(w->url, sizeof w->url, "http://%s%s%s:%d/%s%s", shown, w->host, shown[0] ? "]" : "", w->port,
             w->token[0] ? "?token=" : "", w->token);
    *out = w;
    return SY_OK;
}

void sy_web_view(const sy_web *w, sy_mat4 *camera_to_world, sy_node *camera)
{
    *camera_to_world = w->view;
    if (camera) *camera = w->d.camera;
}

void sy_web_look(const sy_web *w, sy_background *world, float *exposure_stops)
{
    pthread_mutex_t *mu = (pthread_mutex_t *)&w->mu; /* the lock only: nothing of w changes */
    pthread_mutex_lock(mu);
    uint32_t env = w->environment;
    *exposure_stops = w->exposure;
    pthread_mutex_unlock(mu);
    *world = env > 0 && env < SY_WEB_ENVIRONMENTS ? w->env_made[env] : w->d.background; /* env_made: the render thread's */
}

uint16_t sy_web_port(const sy_web *w) { return (uint16_t)w->port; }

const char *sy_web_url(const sy_web *w) { return w->url; }

void sy_web_stats_get(sy_web *w, sy_web_stats *out)
{
    memset(out, 0, sizeof *out);
    sy_web_gate_stats g = {0};
    if (w->gate) sy_web_gate_stats_get(w->gate, &g);
    pthread_mutex_lock(&w->mu);
    *out = w->st;
    for (const web_job *j = w->stills; j; j = j->next) out->stills_queued++;
    pthread_mutex_unlock(&w->mu);
    out->accepted = g.accepted, out->delivered = g.delivered, out->refused = g.refused;
    out->evicted = g.evicted, out->expired = g.expired, out->pending = g.pending;
}

/* Frees a list of jobs linked by next. */
static void free_jobs(web_job *j)
{
    while (j) {
        web_job *next = j->next;
        sy_webi_job_free(j);
        j = next;
    }
}

void sy_web_destroy(sy_web *w)
{
    if (!w) return;
    sy_web_gate_destroy(w->gate); /* no more connections handed over */
    if (w->net_started) {
        w->net_quit = 1;
        lws_cancel_service(w->ctx);
        pthread_join(w->net_thread, NULL);
    }
    if (w->ctx) lws_context_destroy(w->ctx); /* closes every connection (their CLOSED callbacks run here) */
    free_jobs(w->finished);
    free_jobs(w->pending);
    free_jobs(w->stills);
    for (web_action *a = w->actions, *n; a; a = n) n = a->next, free(a);
    for (web_reply *y = w->replies, *n; y; y = n) n = y->next, free(y->text), free(y);
    while (w->handoffs) {
        web_handoff *h = w->handoffs;
        w->handoffs = h->next;
        close(h->fd);
        free(h->buf);
        free(h);
    }
    if (w->latest) {
        sy_webi_frame_free(w->latest);
    }
    free(w->routes);
    free(w->clips);
    free(w->bookmarks);
    free(w->clip_range);
    free(w->clip_names);
    pthread_mutex_destroy(&w->mu);
    pthread_cond_destroy(&w->cv);
    sodium_memzero(w->token, sizeof w->token);
    free(w);
}
