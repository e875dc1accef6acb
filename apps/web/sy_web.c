/* sy_web.c — the browser viewport's server: libwebsockets (HTTP + WebSocket) on a network thread,
 * rendering on the thread in sy_web_run, a mailbox between them (see sy_web.h, docs/WEB.md).
 *
 * >>mailbox    what the two threads share (under mu)
 * >>http       page, stills, routes, token, body collection
 * >>ws         viewers: input messages in, newest frame out
 * >>render     the render loop (frames, stills, routes)
 * >>lifecycle  create / destroy */
#include "sy_web.h"

#include "sy_governor.h"
#include "sy_jpeg.h"
#include "sy_log.h"
#include "sy_mediator.h"
#include "sy_orbit.h"
#include "sy_post.h"
#include "sy_viewport.h"
#include "sy_web_assets.h"
#include "sy_web_check.h"
#include "sy_web_gate.h"

#include <cjson/cJSON.h>
#include <libwebsockets.h>
#include <sodium.h>

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#define WEB_FRAME_MAGIC 0x31465953u /* "SYF1" little-endian */
#define WEB_FRAME_HEADER 40u
#define WEB_TOKEN_BYTES 16u
#define WEB_COOKIE "sy_token"

/* Display filters the F key cycles through (as sy view), on a back-end with SY_CAP_FILTERS. */
static const char *const web_filters[] = {"none", "pixel", "atrous", "jbu", "adaptive", "radiance"};
#define WEB_FILTER_COUNT (sizeof web_filters / sizeof web_filters[0])

/* >>mailbox */
typedef enum job_state { JOB_PENDING, JOB_RUNNING, JOB_FINISHED, JOB_DELIVERING } job_state;

/* A request answered on the render thread: a still or a route. Owned by the mailbox lists while
 * PENDING / RUNNING / FINISHED, by the HTTP connection while DELIVERING; a connection that closes
 * earlier marks it abandoned and whoever holds it next frees it. */
typedef struct web_job {
    struct web_job *next;
    job_state state;
    bool abandoned;
    struct lws *wsi;
    const sy_web_route *route; /* NULL: a still */
    uint32_t w, h;             /* still size */
    uint64_t pixels;           /* w x h */
    double queued_ms;          /* when the still was queued (sy_time_now, ms) */
    char method[8], path[256], query[512], peer[64];
    uint8_t *body;
    size_t body_len;
    sy_web_response resp;
} web_job;

/* The newest frame: LWS_PRE bytes of room, then the 40-byte header and the JPEG. Reference-counted:
 * the mailbox holds one reference, a connection sending it another (network thread). */
typedef struct web_frame {
    uint32_t refs; /* under mu */
    uint64_t seq, gen; /* gen: the input generation the frame answers */
    uint8_t *buf;
    size_t len; /* header + JPEG */
} web_frame;

typedef struct web_conn web_conn;

/* A connection the gate (sy_web_gate.h) hands over with its request: adopted by libwebsockets on
 * the network thread. */
typedef struct web_handoff {
    struct web_handoff *next;
    int fd;
    uint8_t *buf;
    size_t len;
} web_handoff;

struct sy_web {
    sy_web_desc d;
    sy_web_route *routes;
    char host[128];
    int port;
    char token[2 * WEB_TOKEN_BYTES + 1]; /* "" = none required */
    char url[300];
    bool loopback;
    sy_node cam_node;
    sy_orbit home;
    uint32_t initial_backend;
    struct lws_context *ctx;
    struct lws_vhost *vhost;
    sy_web_gate *gate;
    sy_web_policy policy; /* what sy_web_check_request allows */
    lws_retry_bo_t idle; /* the vhost's ping / hang-up policy (lws keeps a pointer) */
    uint32_t retry_ms;
    pthread_t net_thread;
    bool net_started;
    volatile int net_quit; /* read by the network thread */
    web_conn *conns;       /* WebSocket viewers (network thread only) */

    pthread_mutex_t mu;
    pthread_cond_t cv;
    /* --- under mu: network thread -> render thread --- */
    bool quit;
    sy_orbit orbit;
    uint64_t view_version; /* camera, back-end, filter or size changed */
    uint64_t input_gen;    /* inputs received, all clients */
    uint32_t backend;      /* registry index */
    uint32_t filter;
    float threshold;
    uint64_t filter_version;
    uint32_t display_w, display_h;
    uint32_t clients;
    web_job *pending, **pending_tail; /* routes */
    web_job *stills, **stills_tail;   /* stills: one after each live frame */
    web_job *still_running;
    web_handoff *handoffs;            /* gate -> network thread */
    sy_web_stats st;                  /* the still counters */
    /* --- under mu: render thread -> network thread --- */
    web_frame *latest;
    web_job *finished;
    char status[256]; /* the last back-end error or filter line, sent to the pages as JSON */
    uint64_t status_version;
};

static void frame_release(sy_web *w, web_frame *f)
{
    if (!f) return;
    pthread_mutex_lock(&w->mu);
    bool last = --f->refs == 0;
    pthread_mutex_unlock(&w->mu);
    if (last) {
        free(f->buf);
        free(f);
    }
}

static void job_free(web_job *j)
{
    if (!j) return;
    free(j->body);
    free(j->resp.body);
    free(j);
}

/* Render thread -> network thread: wake the service loop (it runs EVENT_WAIT_CANCELLED). */
static void wake_network(sy_web *w)
{
    if (w->ctx) lws_cancel_service(w->ctx);
}

/* Network thread -> render thread. */
static void post_job(sy_web *w, web_job *j)
{
    pthread_mutex_lock(&w->mu);
    j->state = JOB_PENDING;
    j->next = NULL;
    *w->pending_tail = j;
    w->pending_tail = &j->next;
    pthread_cond_signal(&w->cv);
    pthread_mutex_unlock(&w->mu);
}

static void post_still(sy_web *w, web_job *j)
{
    pthread_mutex_lock(&w->mu);
    j->state = JOB_PENDING;
    j->next = NULL;
    *w->stills_tail = j;
    w->stills_tail = &j->next;
    pthread_cond_signal(&w->cv);
    pthread_mutex_unlock(&w->mu);
}

static bool job_abandoned(sy_web *w, const web_job *j)
{
    pthread_mutex_lock(&w->mu);
    bool gone = j->abandoned;
    pthread_mutex_unlock(&w->mu);
    return gone;
}

/* >>http */
typedef struct http_pss {
    web_job *job;         /* a request answered on the render thread */
    uint8_t *resp;        /* or an immediate response: owned copy */
    size_t resp_len;
    int status;
    const char *ctype;
    const uint8_t *body;  /* what is being sent (resp, a job's body or a static asset) */
    size_t body_len, sent;
    bool headers_done, set_cookie, responding;
    bool close_after;     /* the request said Connection: close (the gate says so for every GET) */
    const sy_web_route *route; /* POST: the route the body is for */
    uint8_t *post;        /* POST: the body so far */
    size_t post_len;
    bool post_too_big;
    char path[256], query[512], peer[64];
} http_pss;

/* Queues an immediate response (copied) and asks for a writeable callback. */
static int respond(struct lws *wsi, http_pss *p, int status, const char *ctype, const void *body, size_t len)
{
    free(p->resp);
    p->resp = len ? malloc(len) : NULL;
    if (len && !p->resp) return -1;
    if (len) memcpy(p->resp, body, len);
    p->resp_len = len;
    p->status = status;
    p->ctype = ctype;
    p->body = p->resp;
    p->body_len = len;
    p->sent = 0;
    p->headers_done = false;
    p->responding = true;
    lws_callback_on_writable(wsi);
    return 0;
}

/* A short text/plain error with its reason. */
static int respond_text(struct lws *wsi, http_pss *p, int status, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static int respond_text(struct lws *wsi, http_pss *p, int status, const char *fmt, ...)
{
    char msg[600];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(msg, sizeof msg - 1, fmt, ap);
    va_end(ap);
    if (n < 0) n = 0;
    if ((size_t)n > sizeof msg - 2) n = (int)sizeof msg - 2;
    msg[n++] = '\n';
    return respond(wsi, p, status, "text/plain; charset=utf-8", msg, (size_t)n);
}

static int respond_token_page(struct lws *wsi, http_pss *p, int verdict)
{
    char page[700];
    int n = snprintf(page, sizeof page,
                     "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>sy web: %s</title></head>"
                     "<body style=\"font-family:sans-serif\"><h1>%s</h1><p>This sy web server listens on a network "
                     "address, so every request needs its access token. Open the URL that <code>sy web</code> printed "
                     "when it started (it ends in <code>?token=...</code>).</p></body></html>\n",
                     verdict == 0 ? "access token missing" : "access token wrong",
                     verdict == 0 ? "Access token missing" : "Access token wrong");
    return respond(wsi, p, verdict == 0 ? 401 : 403, "text/html; charset=utf-8", page, (size_t)n);
}

static int http_status_of(sy_result r)
{
    switch (r) {
    case SY_ERR_INVALID_ARGUMENT:
    case SY_ERR_PARSE:
    case SY_ERR_INVALID_HANDLE: return 400;
    case SY_ERR_NOT_FOUND: return 404;
    case SY_ERR_LIMIT: return 413;
    default: return 500;
    }
}

static web_job *new_job(struct lws *wsi, http_pss *p, const sy_web_route *route, const char *method)
{
    web_job *j = calloc(1, sizeof *j);
    if (!j) return NULL;
    j->wsi = wsi;
    j->route = route;
    snprintf(j->method, sizeof j->method, "%s", method);
    snprintf(j->path, sizeof j->path, "%s", p->path);
    snprintf(j->query, sizeof j->query, "%s", p->query);
    snprintf(j->peer, sizeof j->peer, "%s", p->peer);
    p->job = j;
    /* the render thread answers between frames; a stuck one costs the client at most a minute */
    lws_set_timeout(wsi, PENDING_TIMEOUT_HTTP_CONTENT, 60);
    return j;
}

/* The query arguments, decoded, '&'-separated. */
static void copy_query(struct lws *wsi, char *out, size_t len)
{
    out[0] = 0;
    size_t used = 0;
    char frag[256];
    for (int i = 0; used + 1 < len && lws_hdr_copy_fragment(wsi, frag, (int)sizeof frag, WSI_TOKEN_HTTP_URI_ARGS, i) > 0;
         ++i) {
        int n = snprintf(out + used, len - used, "%s%s", used ? "&" : "", frag);
        if (n < 0 || (size_t)n >= len - used) break;
        used += (size_t)n;
    }
}

/* A header's value: NULL when absent; "" (matching nothing) when longer than the buffer. */
static const char *hdr(struct lws *wsi, enum lws_token_indexes t, char *buf, int len)
{
    int n = lws_hdr_total_length(wsi, t);
    if (n <= 0) return NULL;
    if (n >= len || lws_hdr_copy(wsi, buf, len, t) < 0) buf[0] = 0;
    return buf;
}

/* The request's head as sy_web_check_request takes it (h points into b). */
typedef struct head_bufs {
    char path[SY_WEB_MAX_PATH], query[512], host[256], origin[256], ctype[128], cookie[1024], cl[32];
} head_bufs;

static void read_head(struct lws *wsi, head_bufs *b, sy_web_head *h)
{
    memset(h, 0, sizeof *h);
    bool post = lws_hdr_total_length(wsi, WSI_TOKEN_POST_URI) > 0;
    bool get = lws_hdr_total_length(wsi, WSI_TOKEN_GET_URI) > 0;
    enum lws_token_indexes ut = post ? WSI_TOKEN_POST_URI : WSI_TOKEN_GET_URI;
    int n = lws_hdr_total_length(wsi, ut);
    h->method = post ? "POST" : get ? "GET" : "OTHER";
    h->path_len = n > 0 ? (size_t)n : 0;
    b->path[0] = 0;
    if (h->path_len < sizeof b->path && lws_hdr_copy(wsi, b->path, (int)sizeof b->path, ut) < 0) b->path[0] = 0;
    h->path = b->path;
    copy_query(wsi, b->query, sizeof b->query);
    h->query = b->query;
    h->host = hdr(wsi, WSI_TOKEN_HOST, b->host, (int)sizeof b->host);
    h->origin = hdr(wsi, WSI_TOKEN_ORIGIN, b->origin, (int)sizeof b->origin);
    h->content_type = hdr(wsi, WSI_TOKEN_HTTP_CONTENT_TYPE, b->ctype, (int)sizeof b->ctype);
    h->cookie = hdr(wsi, WSI_TOKEN_HTTP_COOKIE, b->cookie, (int)sizeof b->cookie);
    h->upgrade = lws_hdr_total_length(wsi, WSI_TOKEN_UPGRADE) > 0;
    if (hdr(wsi, WSI_TOKEN_HTTP_CONTENT_LENGTH, b->cl, (int)sizeof b->cl))
        h->has_length = true, h->content_length = strtoull(b->cl, NULL, 10);
}

/* A still: within the per-client budget (its queued and rendering stills together) and the
 * queue's length, queued behind the live view. */
static int still_request(sy_web *w, struct lws *wsi, http_pss *p, uint32_t sw, uint32_t sh)
{
    uint64_t px = (uint64_t)sw * sh, mine = 0;
    uint32_t queued = 0;
    pthread_mutex_lock(&w->mu);
    for (const web_job *j = w->stills; j; j = j->next, ++queued)
        if (!strcmp(j->peer, p->peer)) mine += j->pixels;
    if (w->still_running && !strcmp(w->still_running->peer, p->peer)) mine += w->still_running->pixels;
    bool over = mine + px > w->policy.still_max_pixels, full = !over && queued >= 2 * w->d.max_clients;
    if (over || full) w->st.stills_refused++;
    pthread_mutex_unlock(&w->mu);
    if (over) {
        sy_log(SY_LOG_WARNING, "web", p->peer, "refused a still of %ux%u: this client's stills exceed the budget", sw, sh);
        return respond_text(wsi, p, 429, "this client's stills in progress (%llu pixels) and this one (%llu) exceed the "
                            "budget of %llu pixels per client: wait for the first",
                            (unsigned long long)mine, (unsigned long long)px, (unsigned long long)w->policy.still_max_pixels);
    }
    if (full) return respond_text(wsi, p, 503, "%u stills are queued: try again later", queued);
    web_job *j = new_job(wsi, p, NULL, "GET");
    if (!j) return -1;
    j->w = sw, j->h = sh, j->pixels = px, j->queued_ms = sy_time_now() * 1e3;
    post_still(w, j);
    return 0;
}

static int http_request(sy_web *w, struct lws *wsi, http_pss *p, const char *uri)
{
    memset(p, 0, sizeof *p);
    lws_get_peer_simple(wsi, p->peer, sizeof p->peer);
    (void)uri; /* relative to the mount; the request line's path is taken instead */
    head_bufs b;
    sy_web_head h;
    sy_web_verdict v;
    read_head(wsi, &b, &h);
    sy_web_check_request(&w->policy, &h, &v);
    snprintf(p->path, sizeof p->path, "%s", b.path);
    snprintf(p->query, sizeof p->query, "%s", b.query);
    bool post = !strcmp(h.method, "POST");
    char conn[64];
    if (hdr(wsi, WSI_TOKEN_CONNECTION, conn, (int)sizeof conn)) {
        for (char *c = conn; *c; ++c) *c = (char)tolower((unsigned char)*c);
        p->close_after = strstr(conn, "close") != NULL;
    }
    if (v.target == SY_WEB_TARGET_REFUSED) {
        sy_log(SY_LOG_WARNING, "web", p->peer, "refused %s %.100s: %s (%d)", h.method, b.path, v.reason, v.status);
        p->post_too_big = post; /* a body may follow: close after the answer */
        if (v.token_page) return respond_token_page(wsi, p, v.token);
        return respond_text(wsi, p, v.status, "%s", v.reason);
    }
    p->set_cookie = w->token[0] && v.token_in_query;
    switch (v.target) {
    case SY_WEB_TARGET_PAGE:
        p->status = 200, p->ctype = "text/html; charset=utf-8";
        p->body = (const uint8_t *)sy_web_asset_index_html, p->body_len = sy_web_asset_index_html_len;
        p->responding = true;
        lws_callback_on_writable(wsi);
        return 0;
    case SY_WEB_TARGET_STILL: return still_request(w, wsi, p, v.still_w, v.still_h);
    case SY_WEB_TARGET_ROUTE:
        if (post) {
            p->route = v.route; /* the body follows: HTTP_BODY, then HTTP_BODY_COMPLETION */
            return 0;
        } else {
            web_job *j = new_job(wsi, p, v.route, "GET");
            if (!j) return -1;
            post_job(w, j);
            return 0;
        }
    default: return respond_text(wsi, p, 400, "a WebSocket upgrade needs the sy-view subprotocol");
    }
}

static int http_body(sy_web *w, struct lws *wsi, http_pss *p, const void *in, size_t len)
{
    if (p->post_too_big || p->responding) return 0; /* already refused: drain */
    size_t n;
    if (!sy_size_add(p->post_len, len, &n) || n > w->d.max_body) {
        sy_log(SY_LOG_WARNING, "web", p->peer, "request body for %s exceeds %zu bytes", p->path, w->d.max_body);
        p->post_too_big = true;
        free(p->post);
        p->post = NULL;
        return respond_text(wsi, p, 413, "request body exceeds the limit of %zu bytes", w->d.max_body);
    }
    uint8_t *b = realloc(p->post, n ? n : 1);
    if (!b) return -1;
    memcpy(b + p->post_len, in, len);
    p->post = b;
    p->post_len = n;
    return 0;
}

static int http_body_complete(sy_web *w, struct lws *wsi, http_pss *p)
{
    if (p->post_too_big || p->responding || !p->route) return 0;
    web_job *j = new_job(wsi, p, p->route, "POST");
    if (!j) return -1;
    j->body = p->post, j->body_len = p->post_len;
    p->post = NULL, p->post_len = 0;
    post_job(w, j);
    return 0;
}

/* Writes the response: headers first, then the body in chunks of 64 KiB, one per writeable
 * callback, so a slow reader holds at most one chunk in lws's buffer. */
static int http_writeable(sy_web *w, struct lws *wsi, http_pss *p)
{
    if (!p->responding) return 0;
    if (!p->headers_done) {
        uint8_t buf[LWS_PRE + 1024], *start = buf + LWS_PRE, *q = start, *end = buf + sizeof buf - 1;
        if (lws_add_http_common_headers(wsi, (unsigned)p->status, p->ctype, (lws_filepos_t)p->body_len, &q, end) ||
            lws_add_http_header_by_name(wsi, (const unsigned char *)"cache-control:", (const unsigned char *)"no-store", 8,
                                        &q, end) ||
            lws_add_http_header_by_name(wsi, (const unsigned char *)"x-content-type-options:",
                                        (const unsigned char *)"nosniff", 7, &q, end))
            return -1;
        if ((p->close_after || p->post_too_big) &&
            lws_add_http_header_by_name(wsi, (const unsigned char *)"connection:", (const unsigned char *)"close", 5, &q, end))
            return -1;
        if (p->set_cookie) {
            char c[160];
            int n = snprintf(c, sizeof c, WEB_COOKIE "=%s; Path=/; HttpOnly; SameSite=Strict", w->token);
            if (lws_add_http_header_by_name(wsi, (const unsigned char *)"set-cookie:", (const unsigned char *)c, n, &q, end))
                return -1;
        }
        if (lws_finalize_write_http_header(wsi, start, &q, end)) return -1;
        p->headers_done = true;
        if (p->body_len) {
            lws_callback_on_writable(wsi);
            return 0;
        }
    } else if (p->sent < p->body_len) {
        size_t chunk = p->body_len - p->sent;
        if (chunk > 65536) chunk = 65536;
        uint8_t *buf = malloc(LWS_PRE + chunk);
        if (!buf) return -1;
        memcpy(buf + LWS_PRE, p->body + p->sent, chunk);
        bool last = p->sent + chunk == p->body_len;
        int n = lws_write(wsi, buf + LWS_PRE, chunk, last ? LWS_WRITE_HTTP_FINAL : LWS_WRITE_HTTP);
        free(buf);
        if (n < (int)chunk) return -1;
        p->sent += chunk;
        if (!last) {
            lws_callback_on_writable(wsi);
            return 0;
        }
    }
    /* done: the connection may carry the next request */
    p->responding = false;
    free(p->resp);
    p->resp = NULL;
    job_free(p->job);
    p->job = NULL;
    if (p->post_too_big) return -1; /* an unread body follows: close */
    return lws_http_transaction_completed(wsi) ? -1 : 0;
}

/* A finished job reached its connection: answer with its response. */
static void http_deliver(struct lws *wsi, http_pss *p)
{
    web_job *j = p->job;
    p->status = j->resp.status ? j->resp.status : 200;
    p->ctype = j->resp.content_type[0] ? j->resp.content_type : "application/octet-stream";
    p->body = j->resp.body;
    p->body_len = j->resp.body_len;
    p->sent = 0;
    p->headers_done = false;
    p->responding = true;
    lws_set_timeout(wsi, NO_PENDING_TIMEOUT, 0);
    lws_callback_on_writable(wsi);
}

static void http_closed(sy_web *w, http_pss *p)
{
    free(p->resp);
    p->resp = NULL;
    free(p->post);
    p->post = NULL;
    web_job *j = p->job;
    p->job = NULL;
    if (!j) return;
    pthread_mutex_lock(&w->mu);
    bool mine = j->state == JOB_DELIVERING;
    if (!mine) j->abandoned = true, j->wsi = NULL, w->st.requests_abandoned++;
    pthread_mutex_unlock(&w->mu);
    if (mine) job_free(j);
}

/* The render thread finished jobs: hand each to its connection. */
static void http_collect_finished(sy_web *w)
{
    pthread_mutex_lock(&w->mu);
    web_job *list = w->finished;
    w->finished = NULL;
    for (web_job *j = list; j; j = j->next)
        if (!j->abandoned) j->state = JOB_DELIVERING;
    pthread_mutex_unlock(&w->mu);
    while (list) {
        web_job *j = list;
        list = j->next;
        if (j->abandoned) {
            job_free(j);
            continue;
        }
        http_pss *p = lws_wsi_user(j->wsi);
        if (p && p->job == j) http_deliver(j->wsi, p);
    }
}

/* The gate's connections: libwebsockets takes each with the request bytes the gate read. */
static void http_adopt(sy_web *w)
{
    pthread_mutex_lock(&w->mu);
    web_handoff *list = w->handoffs;
    w->handoffs = NULL;
    pthread_mutex_unlock(&w->mu);
    while (list) {
        web_handoff *h = list;
        list = h->next;
        /* closes the socket itself when it fails; without bytes: lws reads the request itself */
        if (h->len) lws_adopt_socket_vhost_readbuf(w->vhost, h->fd, (const char *)h->buf, h->len);
        else lws_adopt_socket_vhost(w->vhost, h->fd);
        free(h->buf);
        free(h);
    }
}

/* The gate's thread: a connection whose request arrived whole. */
static void gate_deliver(void *user, int fd, uint8_t *bytes, size_t len)
{
    sy_web *w = user;
    web_handoff *h = malloc(sizeof *h);
    if (!h) {
        close(fd);
        free(bytes);
        return;
    }
    h->fd = fd, h->buf = bytes, h->len = len;
    pthread_mutex_lock(&w->mu);
    h->next = w->handoffs;
    w->handoffs = h;
    pthread_mutex_unlock(&w->mu);
    lws_cancel_service(w->ctx);
}

static int http_callback(struct lws *wsi, enum lws_callback_reasons reason, void *user, void *in, size_t len)
{
    struct lws_context *ctx = lws_get_context(wsi);
    sy_web *w = ctx ? lws_context_user(ctx) : NULL;
    http_pss *p = user;
    switch (reason) {
    case LWS_CALLBACK_HTTP: return http_request(w, wsi, p, in);
    case LWS_CALLBACK_HTTP_BODY: return http_body(w, wsi, p, in, len);
    case LWS_CALLBACK_HTTP_BODY_COMPLETION: return http_body_complete(w, wsi, p);
    case LWS_CALLBACK_HTTP_WRITEABLE: return http_writeable(w, wsi, p);
    case LWS_CALLBACK_CLOSED_HTTP:
        if (p) http_closed(w, p);
        return 0;
    case LWS_CALLBACK_EVENT_WAIT_CANCELLED:
        if (w) {
            http_adopt(w);
            http_collect_finished(w);
        }
        return 0;
    case LWS_CALLBACK_FILTER_PROTOCOL_CONNECTION: { /* an upgrade without the "sy-view" subprotocol */
        char peer[64] = "";
        lws_get_peer_simple(wsi, peer, sizeof peer);
        sy_log(SY_LOG_WARNING, "web", peer, "refused a WebSocket without the sy-view subprotocol");
        return 1;
    }
    default: return lws_callback_http_dummy(wsi, reason, user, in, len);
    }
}

/* >>ws */
static const struct lws_protocols web_protocols[];
struct web_conn {
    web_conn *next;
    struct lws *wsi;
    char peer[64];
    uint64_t sent_seq, sent_status;
    uint64_t last_id, last_gen, answered_id; /* the newest input id and the generation it got */
    bool hello_sent;
    uint32_t warned;    /* malformed messages logged */
    char *msg;          /* a text message being assembled (max_message bytes) */
    size_t msg_len;     /* its bytes so far (a binary message's are counted, not kept) */
    bool msg_binary;
};

/* A malformed message: logged with the client's address, the first 10 per connection (a flood
 * does not flood the log). */
static void ws_warn(web_conn *c, const char *what, const char *detail)
{
    if (c->warned >= 10) return;
    c->warned++;
    sy_log(SY_LOG_WARNING, "web", c->peer, "ignored a message: %s%s%.80s%s", what, detail ? ": " : "", detail ? detail : "",
           c->warned == 10 ? " (further ones from this client are not logged)" : "");
}

/* One input message (JSON text; docs/WEB.md; parsed by sy_web_parse_input). Malformed ones are
 * logged with the client's address and ignored. */
static void ws_message(sy_web *w, web_conn *c, const char *text, size_t len)
{
    sy_web_input in;
    sy_error err = {0};
    if (sy_web_parse_input(text, len, &in, &err) != SY_OK) {
        ws_warn(c, err.message, NULL);
        return;
    }
    pthread_mutex_lock(&w->mu);
    bool input = true;
    switch (in.type) {
    case SY_WEB_INPUT_SIZE:
        input = false;
        w->display_w = (uint32_t)in.a, w->display_h = (uint32_t)in.b;
        w->view_version++;
        break;
    case SY_WEB_INPUT_DRAG:
        if (in.button >= 1) sy_orbit_pan(&w->orbit, (float)in.a, (float)in.b);
        else sy_orbit_rotate(&w->orbit, (float)in.a, (float)in.b);
        break;
    case SY_WEB_INPUT_WHEEL: sy_orbit_zoom(&w->orbit, (float)in.a); break;
    case SY_WEB_INPUT_KEY:
        if (in.key >= '1' && in.key <= '9') {
            uint32_t i = (uint32_t)(in.key - '1');
            if (i < sy_mediator_count()) /* the cluster is no choice of its own: the initial back-end */
                w->backend = (sy_mediator_at(i)->caps & SY_CAP_REMOTE) ? w->initial_backend : i;
        } else if (in.key == 'f') {
            w->filter = (w->filter + 1) % (uint32_t)WEB_FILTER_COUNT, w->filter_version++;
        } else if (in.key == '[') {
            if (w->threshold > 1e-6f) w->threshold *= 0.5f;
            w->filter_version++;
        } else if (in.key == ']') {
            if (w->threshold < 1e3f) w->threshold *= 2.0f;
            w->filter_version++;
        } else if (in.key == 'r') {
            w->orbit = w->home;
        }
        break;
    }
    if (input) {
        w->view_version++;
        w->input_gen++;
        if (in.has_id) c->last_id = in.id, c->last_gen = w->input_gen;
    }
    pthread_cond_signal(&w->cv);
    pthread_mutex_unlock(&w->mu);
}

/* The hello: the back-ends of the registry in key order (docs/WEB.md). */
static int ws_send_text(struct lws *wsi, const char *s)
{
    size_t n = strlen(s);
    uint8_t *buf = malloc(LWS_PRE + n);
    if (!buf) return -1;
    memcpy(buf + LWS_PRE, s, n);
    int r = lws_write(wsi, buf + LWS_PRE, n, LWS_WRITE_TEXT);
    free(buf);
    return r < (int)n ? -1 : 0;
}

static int ws_send_hello(struct lws *wsi)
{
    cJSON *o = cJSON_CreateObject(), *arr = cJSON_AddArrayToObject(o, "backends");
    cJSON_AddStringToObject(o, "t", "hello");
    for (uint32_t i = 0; i < sy_mediator_count(); ++i) cJSON_AddItemToArray(arr, cJSON_CreateString(sy_mediator_at(i)->name));
    char *s = cJSON_PrintUnformatted(o);
    cJSON_Delete(o);
    if (!s) return -1;
    int r = ws_send_text(wsi, s);
    cJSON_free(s);
    return r;
}

static int ws_writeable(sy_web *w, web_conn *c)
{
    if (!c->hello_sent) {
        c->hello_sent = true;
        if (ws_send_hello(c->wsi)) return -1;
        lws_callback_on_writable(c->wsi);
        return 0;
    }
    pthread_mutex_lock(&w->mu);
    web_frame *f = w->latest;
    bool fresh = f && f->seq != c->sent_seq;
    if (fresh) f->refs++;
    char status[300] = "";
    if (w->status_version != c->sent_status) {
        c->sent_status = w->status_version;
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "t", "status");
        cJSON_AddStringToObject(o, "filter", web_filters[w->filter % WEB_FILTER_COUNT]);
        if (w->status[0]) cJSON_AddStringToObject(o, "error", w->status);
        char *s = cJSON_PrintUnformatted(o);
        if (s) snprintf(status, sizeof status, "%s", s);
        cJSON_free(s);
        cJSON_Delete(o);
    }
    pthread_mutex_unlock(&w->mu);
    if (status[0]) {
        if (fresh) frame_release(w, f);
        if (ws_send_text(c->wsi, status)) return -1;
        lws_callback_on_writable(c->wsi);
        return 0;
    }
    if (!fresh) return 0;
    /* the input this frame answers: the client's newest one that reached the mailbox before it */
    if (c->last_gen && c->last_gen <= f->gen) c->answered_id = c->last_id;
    uint64_t id = c->answered_id;
    memcpy(f->buf + LWS_PRE + 32, &id, 8); /* the buffer is shared: patched right before each write */
    size_t len = f->len;
    int n = lws_write(c->wsi, f->buf + LWS_PRE, len, LWS_WRITE_BINARY);
    c->sent_seq = f->seq;
    frame_release(w, f); /* f may be gone from here: the render thread may have replaced it */
    return n < (int)len ? -1 : 0;
}

static int ws_callback(struct lws *wsi, enum lws_callback_reasons reason, void *user, void *in, size_t len)
{
    struct lws_context *ctx = lws_get_context(wsi);
    sy_web *w = ctx ? lws_context_user(ctx) : NULL;
    web_conn *c = user;
    switch (reason) {
    case LWS_CALLBACK_FILTER_PROTOCOL_CONNECTION: {
        char peer[64] = "";
        lws_get_peer_simple(wsi, peer, sizeof peer);
        head_bufs b;
        sy_web_head h;
        sy_web_verdict v;
        read_head(wsi, &b, &h);
        h.upgrade = true;
        sy_web_check_request(&w->policy, &h, &v);
        if (v.target != SY_WEB_TARGET_STREAM) {
            sy_log(SY_LOG_WARNING, "web", peer, "refused a WebSocket: %s", v.target == SY_WEB_TARGET_REFUSED ? v.reason : "not /ws");
            return 1;
        }
        pthread_mutex_lock(&w->mu);
        bool full = w->clients >= w->d.max_clients;
        pthread_mutex_unlock(&w->mu);
        if (full) {
            sy_log(SY_LOG_WARNING, "web", peer, "refused a WebSocket: %u viewers already", w->d.max_clients);
            return 1;
        }
        return 0;
    }
    case LWS_CALLBACK_ESTABLISHED:
        memset(c, 0, sizeof *c);
        c->wsi = wsi;
        lws_get_peer_simple(wsi, c->peer, sizeof c->peer);
        c->msg = malloc(w->d.max_message);
        if (!c->msg) return -1;
        c->next = w->conns;
        w->conns = c;
        pthread_mutex_lock(&w->mu);
        w->clients++;
        w->view_version++; /* a new viewer gets a frame even when the view rests */
        pthread_cond_signal(&w->cv);
        pthread_mutex_unlock(&w->mu);
        sy_log(SY_LOG_NOTE, "web", c->peer, "viewer connected");
        lws_callback_on_writable(wsi);
        return 0;
    case LWS_CALLBACK_CLOSED:
        for (web_conn **pp = &w->conns; *pp; pp = &(*pp)->next)
            if (*pp == c) {
                *pp = c->next;
                pthread_mutex_lock(&w->mu);
                w->clients--;
                pthread_mutex_unlock(&w->mu);
                sy_log(SY_LOG_NOTE, "web", c->peer, "viewer left");
                break;
            }
        free(c->msg);
        c->msg = NULL;
        return 0;
    case LWS_CALLBACK_RECEIVE: {
        /* the message's size so far plus what its frame still announces: over the limit closes at
         * once (1009), before the rest is read */
        if (lws_is_first_fragment(wsi)) c->msg_len = 0, c->msg_binary = lws_frame_is_binary(wsi);
        size_t rest = lws_remaining_packet_payload(wsi);
        if (len > w->d.max_message - c->msg_len || rest > w->d.max_message - c->msg_len - len) {
            sy_log(SY_LOG_WARNING, "web", c->peer, "closed: a message over %zu bytes", w->d.max_message);
            lws_close_reason(wsi, LWS_CLOSE_STATUS_MESSAGE_TOO_LARGE, (unsigned char *)"message too large", 17);
            return -1;
        }
        if (!c->msg_binary) memcpy(c->msg + c->msg_len, in, len);
        c->msg_len += len;
        if (lws_is_final_fragment(wsi) && !rest) {
            if (c->msg_binary) ws_warn(c, "binary messages are not part of the protocol", NULL);
            else ws_message(w, c, c->msg, c->msg_len);
            c->msg_len = 0;
        }
        return 0;
    }
    case LWS_CALLBACK_SERVER_WRITEABLE: return ws_writeable(w, c);
    case LWS_CALLBACK_EVENT_WAIT_CANCELLED: /* a new frame or status: every viewer that can take it */
        if (w) lws_callback_on_writable_all_protocol(ctx, &web_protocols[1]);
        return 0;
    default: return 0;
    }
}

static const struct lws_protocols web_protocols[] = {
    {"http", http_callback, sizeof(http_pss), 0, 0, NULL, 0},
    {"sy-view", ws_callback, sizeof(web_conn), 4096, 1, NULL, 0},
    {NULL, NULL, 0, 0, 0, NULL, 0},
};

/* The WebSocket is served at /ws; everything else goes to the http protocol's callback. */
static const struct lws_http_mount web_mount = {
    .mountpoint = "/",
    .mountpoint_len = 1,
    .origin = "http",
    .origin_protocol = LWSMPRO_CALLBACK,
};

static void *net_main(void *p)
{
    sy_web *w = p;
    while (!w->net_quit)
        if (lws_service(w->ctx, 0) < 0) break;
    return NULL;
}

/* >>render */
typedef struct render_state {
    sy_context_pool *pool;
    sy_window *win, *still_win;
    sy_viewport *vp, *still_vp;
    sy_mat4 cam_applied;
    bool cam_valid;
    uint32_t backend_applied;
    const sy_context *filter_ctx; /* the pool context the filter was last set on (borrowed) */
    uint64_t filter_applied;
    bool filter_enabled;
    uint64_t seq;
    sy_governor *gov;
    uint32_t prev_bi, prev_w, prev_h; /* what the last planned frame showed: a difference is a change */
    uint64_t prev_filter_version;
} render_state;

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

/* Premultiplied linear RGBA after the display chain -> 8-bit (composited over black). */
static uint8_t *layer_to_rgba8(const sy_layer *img)
{
    size_t n = (size_t)img->width * img->height;
    uint8_t *px = malloc(n * 4);
    if (!px) return NULL;
    for (size_t i = 0; i < n * 4; ++i) {
        float x = (i & 3) == 3 ? 1.0f : img->rgba[i];
        px[i] = sy_unorm8(x);
    }
    return px;
}

static sy_result apply_camera(sy_web *w, render_state *rs, const sy_orbit *o, sy_error *err)
{
    sy_mat4 m;
    sy_orbit_matrix(o, &m);
    if (rs->cam_valid && !memcmp(&m, &rs->cam_applied, sizeof m)) return SY_OK;
    sy_result r = sy_node_set_matrix(w->d.scene, w->cam_node, &m, err);
    if (r == SY_OK) r = sy_scene_commit(w->d.scene, NULL, err);
    if (r == SY_OK) rs->cam_applied = m, rs->cam_valid = true;
    return r;
}

/* Renders w x h with the current back-end into an 8-bit image (display chain: ACES + sRGB). */
static sy_result render_rgba8(sy_web *w, render_state *rs, sy_window *win, uint32_t width, uint32_t height,
                              uint32_t samples, float preview, uint8_t **out, sy_error *err)
{
    *out = NULL;
    uint32_t cw = 0, ch = 0;
    sy_window_size(win, &cw, &ch);
    sy_result r = (cw != width || ch != height) ? sy_window_resize(win, width, height, err) : SY_OK;
    sy_layer img = {0};
    if (r == SY_OK) r = sy_layer_create(width, height, &img, err);
    sy_window_render_opts ro = {.sample_count = samples, .preview = preview,
                                .post = sy_post_display()};
    if (r == SY_OK) r = sy_window_render(win, w->d.scene, rs->pool, &ro, &img, err);
    if (r == SY_OK && !(*out = layer_to_rgba8(&img))) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "web: out of memory");
    sy_layer_destroy(&img);
    return r;
}

/* The path tracer's display filter (as sy view): applied when it changed or the context is new. */
static void apply_filter(sy_web *w, render_state *rs, const sy_mediator_class *cls, uint32_t filter, float threshold,
                         uint64_t version, bool enabled, char *status, size_t len)
{
    status[0] = 0;
    if (!(cls->caps & SY_CAP_FILTERS)) return;
    sy_context *ctx = NULL;
    sy_error err = {0};
    if (sy_context_pool_get(rs->pool, w->d.scene, cls->name, NULL, w->d.root.id, &ctx, &err) != SY_OK) {
        snprintf(status, len, "filter: %.200s", err.message);
        return;
    }
    if (ctx == rs->filter_ctx && version == rs->filter_applied && enabled == rs->filter_enabled) return;
    sy_params opts = {0};
    char t[32];
    snprintf(t, sizeof t, "%g", (double)threshold);
    if (sy_params_set(&opts, "threshold", t, &err) != SY_OK ||
        sy_context_set_filter(ctx, enabled ? web_filters[filter % WEB_FILTER_COUNT] : "none", &opts, &err) != SY_OK) {
        snprintf(status, len, "filter: %.200s", err.message);
        return;
    }
    rs->filter_ctx = ctx;
    rs->filter_applied = version;
    rs->filter_enabled = enabled; /* the governor keeps the filter off while the view moves */
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
    if (drop) job_free(j);
    else wake_network(w);
}

/* A failed job's answer: the status of its error and the message as text. */
static void job_error(web_job *j, sy_result r, const sy_error *err)
{
    free(j->resp.body);
    memset(&j->resp, 0, sizeof j->resp);
    j->resp.status = http_status_of(r);
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
    bool cancelled = job_abandoned(w, j), expired = !cancelled && waited > w->d.still_deadline_ms;
    if (expired) {
        r = sy_error_set(&err, SY_ERR_LIMIT, "the still waited %.0f ms behind the live view (deadline %u ms): try again",
                         waited, w->d.still_deadline_ms);
    } else if (!cancelled) {
        const sy_mediator_class *cls = sy_mediator_at(rs->backend_applied);
        uint32_t spp = cls && (cls->caps & SY_CAP_PROGRESSIVE) ? w->d.still_samples : 1;
        sy_layer img = {0};
        r = apply_camera(w, rs, o, &err);
        if (r == SY_OK) r = sy_viewport_set_backend(rs->still_vp, (cls ? cls : sy_mediator_at(w->initial_backend))->name, NULL, &err);
        if (r == SY_OK) r = sy_window_resize(rs->still_win, j->w, j->h, &err);
        if (r == SY_OK) r = sy_layer_create(j->w, j->h, &img, &err);
        for (uint32_t done = 0; r == SY_OK && done < spp && !cancelled; ) {
            uint32_t n = spp - done > 4 ? 4 : spp - done;
            sy_window_render_opts ro = {.sample_count = n, .preview = 1.0f, .post = sy_post_display()};
            r = sy_window_render(rs->still_win, w->d.scene, rs->pool, &ro, &img, &err);
            done += n;
            cancelled = job_abandoned(w, j);
        }
        uint8_t *px = NULL;
        if (r == SY_OK && !cancelled && !(px = layer_to_rgba8(&img))) r = sy_error_set(&err, SY_ERR_OUT_OF_MEMORY, "web: out of memory");
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
    if (last) {
        free(old->buf);
        free(old);
    }
    wake_network(w);
}

static void set_status(sy_web *w, const char *s)
{
    pthread_mutex_lock(&w->mu);
    if (strcmp(w->status, s) != 0) {
        snprintf(w->status, sizeof w->status, "%.*s", (int)sizeof w->status - 1, s);
        w->status_version++;
    }
    pthread_mutex_unlock(&w->mu);
    wake_network(w);
}

/* One frame through the frame-time governor (core/sy_governor.h): plans it for the display size,
 * renders what the plan says, reports its time. *again: plan again without waiting for input;
 * *wait_ms > 0: plan again after that long (the view is settling). */
static sy_result render_frame(sy_web *w, render_state *rs, const sy_orbit *o, uint32_t bi, uint32_t dw, uint32_t dh,
                              uint64_t gen, uint32_t filter, float threshold, uint64_t filter_version, bool *again,
                              double *wait_ms, sy_error *err)
{
    *again = false, *wait_ms = 0;
    const sy_mediator_class *cls = sy_mediator_at(bi);
    if (!cls) return sy_error_set(err, SY_ERR_NOT_FOUND, "web: back-end %u is not registered", bi);
    uint32_t pw = 0, ph = 0;
    display_size(w, dw, dh, &pw, &ph);
    sy_mat4 m;
    sy_orbit_matrix(o, &m);
    bool changed = !rs->cam_valid || memcmp(&m, &rs->cam_applied, sizeof m) != 0 || bi != rs->prev_bi ||
                   pw != rs->prev_w || ph != rs->prev_h;
    sy_result r = apply_camera(w, rs, o, err);
    if (r == SY_OK && bi != rs->backend_applied) {
        r = sy_viewport_set_backend(rs->vp, cls->name, NULL, err);
        if (r == SY_OK) rs->backend_applied = bi;
    }
    if (r != SY_OK) return r;
    if (bi != rs->prev_bi) sy_governor_reset(rs->gov); /* another back-end: another cost */
    if (filter_version != rs->prev_filter_version) sy_governor_redraw(rs->gov); /* shown again, same samples */
    rs->prev_bi = bi, rs->prev_w = pw, rs->prev_h = ph, rs->prev_filter_version = filter_version;
    sy_governor_frame gf;
    sy_governor_plan(rs->gov, pw, ph, sy_mediator_class_caps(cls, NULL), changed, sy_time_now() * 1e3, &gf);
    if (gf.wait_ms > 0) { /* settling after a moving frame: the refining frame comes next */
        *wait_ms = gf.wait_ms;
        return SY_OK;
    }
    if (gf.idle || !gf.width || !gf.height) return SY_OK; /* refined: sleep until input */
    char fstatus[240];
    apply_filter(w, rs, cls, filter, threshold, filter_version, gf.filter, fstatus, sizeof fstatus);
    uint8_t *px = NULL, *jpeg = NULL;
    size_t jlen = 0;
    uint32_t contexts = sy_context_pool_size(rs->pool);
    double t0 = sy_time_now();
    r = render_rgba8(w, rs, rs->win, gf.width, gf.height, gf.samples, gf.preview, &px, err);
    if (r == SY_OK) r = sy_jpeg_encode_rgba8(px, gf.width, gf.height, w->d.quality, &jpeg, &jlen, err);
    double ms = (sy_time_now() - t0) * 1e3; /* render, display chain, JPEG: the frame's whole cost */
    free(px);
    if (r != SY_OK) return r;
    /* a frame that translated the scene for a new context says nothing about the next ones */
    if (sy_context_pool_size(rs->pool) == contexts) sy_governor_report(rs->gov, &gf, ms);
    sy_mediator_stats st = {0};
    sy_context *ctx = NULL;
    if (sy_context_pool_get(rs->pool, w->d.scene, cls->name, NULL, w->d.root.id, &ctx, NULL) == SY_OK)
        sy_context_stats(ctx, &st);
    web_frame *f = calloc(1, sizeof *f);
    size_t len = WEB_FRAME_HEADER + jlen;
    if (f) f->buf = malloc(LWS_PRE + len);
    if (!f || !f->buf) {
        free(f);
        free(jpeg);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "web: out of memory for a frame of %zu bytes", len);
    }
    uint8_t *h = f->buf + LWS_PRE;
    uint32_t u[5] = {WEB_FRAME_MAGIC, gf.width, gf.height, bi,
                     (uint32_t)(st.samples > UINT32_MAX ? UINT32_MAX : st.samples)};
    float fms = (float)ms;
    uint64_t seq = ++rs->seq, zero = 0;
    memcpy(h, u, sizeof u); /* little-endian hosts (x86-64, arm64) */
    memcpy(h + 20, &fms, 4);
    memcpy(h + 24, &seq, 8);
    memcpy(h + 32, &zero, 8);
    memcpy(h + WEB_FRAME_HEADER, jpeg, jlen);
    free(jpeg);
    f->refs = 1, f->seq = seq, f->gen = gen, f->len = len;
    publish_frame(w, f);
    set_status(w, fstatus);
    *again = true; /* the governor says what comes next */
    return SY_OK;
}

/* The live frame (the governor says its size) and what a failed back-end tells the pages. */
static void render_live(sy_web *w, render_state *rs, const sy_orbit *o, uint32_t bi, uint32_t dw, uint32_t dh, uint64_t gen,
                        uint32_t filter, float threshold, uint64_t fv, bool *again, double *wait_until)
{
    *again = false, *wait_until = 0;
    sy_error ferr = {0};
    double wait_ms = 0;
    if (render_frame(w, rs, o, bi, dw, dh, gen, filter, threshold, fv, again, &wait_ms, &ferr) == SY_OK) {
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

sy_result sy_web_run(sy_web *w, volatile int *stop, sy_error *err)
{
    render_state rs = {0};
    sy_viewport_desc vd = {.root = w->d.root, .camera = w->cam_node, .background = w->d.background,
                           .backend = sy_mediator_at(w->initial_backend)->name};
    sy_result r = sy_context_pool_create(&rs.pool, err);
    if (r == SY_OK) r = sy_window_create(64, 64, &rs.win, err);
    if (r == SY_OK) r = sy_window_add_viewport(rs.win, &vd, &rs.vp, err);
    if (r == SY_OK) r = sy_window_create(64, 64, &rs.still_win, err);
    if (r == SY_OK) r = sy_window_add_viewport(rs.still_win, &vd, &rs.still_vp, err);
    if (r == SY_OK) r = sy_governor_create(&(sy_governor_desc){.budget_ms = w->d.budget_ms}, &rs.gov, err);
    rs.backend_applied = w->initial_backend;
    rs.prev_bi = UINT32_MAX;
    uint64_t seen = 0;
    bool again = false;    /* plan again without waiting for input */
    double wait_until = 0; /* ms (sy_time_now): the governor's settle wait, 0 = none */
    while (r == SY_OK) {
        pthread_mutex_lock(&w->mu);
        for (;;) {
            if (w->quit || (stop && *stop) || w->pending || w->stills) break;
            /* frames once a page said its size (the page does as it connects) */
            bool due = again || (wait_until > 0 && sy_time_now() * 1e3 >= wait_until);
            if (w->clients && w->display_w && (w->view_version != seen || due)) break;
            double nap_ms = 100; /* polls *stop ten times a second */
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
        sy_orbit o = w->orbit;
        bool moved = w->view_version != seen;
        seen = w->view_version;
        uint32_t bi = w->backend, dw = w->display_w, dh = w->display_h, filter = w->filter;
        float threshold = w->threshold;
        uint64_t fv = w->filter_version, gen = w->input_gen;
        bool clients = w->clients > 0 && w->display_w > 0;
        pthread_mutex_unlock(&w->mu);
        while (jobs) { /* stills and routes first: they wait on an HTTP connection */
            web_job *j = jobs;
            jobs = j->next;
            pthread_mutex_lock(&w->mu);
            bool gone = j->abandoned;
            pthread_mutex_unlock(&w->mu);
            if (gone) job_free(j);
            else run_job(w, j);
        }
        bool due = again || (wait_until > 0 && sy_time_now() * 1e3 >= wait_until);
        if (clients && (moved || due)) render_live(w, &rs, &o, bi, dw, dh, gen, filter, threshold, fv, &again, &wait_until);
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
        if (still) run_still(w, &rs, still, &o);
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
    sy_governor_destroy(rs.gov);
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

/* >>lifecycle */
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

sy_result sy_web_create(const sy_web_desc *desc, sy_web **out, sy_error *err)
{
    *out = NULL;
    if (!desc || !desc->scene) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "web: no scene");
    const sy_node_data *cn = desc->camera.id ? sy_node_get(desc->scene, desc->camera) : NULL;
    if (!cn || !cn->camera.id) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "web: the scene has no camera");
    const char *backend = desc->backend ? desc->backend : sy_mediator_default_name();
    int bi = -1;
    for (uint32_t i = 0; i < sy_mediator_count(); ++i)
        if (!strcmp(sy_mediator_at(i)->name, backend)) bi = (int)i;
    if (bi < 0) return sy_error_set(err, SY_ERR_NOT_FOUND, "web: back-end '%s' is not registered (see sy backends)", backend);
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
    w->initial_backend = w->backend = (uint32_t)bi;
    w->threshold = desc->threshold > 0 ? desc->threshold : 0.01f;
    pthread_mutex_init(&w->mu, NULL);
    pthread_cond_init(&w->cv, NULL);
    w->pending_tail = &w->pending;
    w->stills_tail = &w->stills;
    sy_result r = SY_OK;
    if (w->d.max_width > 16384 || w->d.max_height > 16384 || w->d.max_clients > 1000 || w->d.max_message < 64 ||
        w->d.max_message > (1u << 24) || w->d.quality < 1 || w->d.quality > 100 || w->d.idle_timeout_s > 3600 ||
        !(w->d.budget_ms >= 0 && w->d.budget_ms <= 1e5) || w->d.still_max_pixels > (uint64_t)SY_JPEG_MAX_SIDE * SY_JPEG_MAX_SIDE ||
        w->d.max_pending > 1024 || w->d.head_timeout_ms > 600000 || w->d.still_deadline_ms > 600000)
        r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                         "web: a limit is out of range (frame <= 16384, clients <= 1000, message 64..16 MiB, quality "
                         "1..100, idle timeout <= 3600 s, budget 0..1e5 ms, still pixels <= 16384^2, pending "
                         "connections <= 1024, head timeout and still deadline <= 600 s)");
    if (r == SY_OK && desc->filter) {
        while (w->filter < WEB_FILTER_COUNT && strcmp(web_filters[w->filter], desc->filter) != 0) w->filter++;
        if (w->filter == WEB_FILTER_COUNT)
            r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                             "web: unknown filter '%s' (expected none, pixel, atrous, jbu, adaptive or radiance)",
                             desc->filter);
    }
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
    /* the server's camera node: the scene camera's object, top level, starting at its world pose */
    sy_mat4 world = sy_mat4_identity();
    sy_bounds b;
    if (r == SY_OK) {
        if (sy_node_world_bounds(desc->scene, desc->root.id ? desc->root : (sy_node){0}, &b, NULL) != SY_OK)
            b = sy_scene_world_bounds(desc->scene);
        sy_node_world_matrix(desc->scene, desc->camera, &world, NULL);
        sy_orbit_from_matrix(&world, &b, &w->orbit);
        w->home = w->orbit;
        r = sy_node_create(desc->scene, "web camera", &w->cam_node, err);
    }
    if (r == SY_OK) r = sy_node_set_camera(desc->scene, w->cam_node, cn->camera, err);
    if (r == SY_OK) {
        sy_mat4 m;
        sy_orbit_matrix(&w->orbit, &m);
        r = sy_node_set_matrix(desc->scene, w->cam_node, &m, err);
    }
    if (r == SY_OK) r = sy_scene_commit(desc->scene, NULL, err);
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
    vi.protocols = web_protocols;
    vi.mounts = &web_mount;
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
    if (pthread_create(&w->net_thread, NULL, net_main, w) != 0) {
        sy_web_destroy(w);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "web: cannot start the network thread");
    }
    w->net_started = true;
    sy_web_gate_desc gd = {.host = w->host, .port = w->port, .max_pending = w->d.max_pending,
                           .head_timeout_ms = w->d.head_timeout_ms, .max_body = w->d.max_body,
                           .deliver = gate_deliver, .user = w};
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

sy_node sy_web_camera(const sy_web *w) { return w ? w->cam_node : (sy_node){0}; }

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
    while (w->finished) {
        web_job *j = w->finished;
        w->finished = j->next;
        job_free(j);
    }
    while (w->pending) {
        web_job *j = w->pending;
        w->pending = j->next;
        job_free(j);
    }
    while (w->stills) {
        web_job *j = w->stills;
        w->stills = j->next;
        job_free(j);
    }
    while (w->handoffs) {
        web_handoff *h = w->handoffs;
        w->handoffs = h->next;
        close(h->fd);
        free(h->buf);
        free(h);
    }
    if (w->latest) {
        free(w->latest->buf);
        free(w->latest);
    }
    if (w->cam_node.id) {
        sy_object_destroy(w->d.scene, SY_TYPE_NODE, w->cam_node.id, NULL);
        sy_scene_commit(w->d.scene, NULL, NULL);
    }
    free(w->routes);
    pthread_mutex_destroy(&w->mu);
    pthread_cond_destroy(&w->cv);
    sodium_memzero(w->token, sizeof w->token);
    free(w);
}
