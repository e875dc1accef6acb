/* sy_web_http.c — the sy_web server's HTTP side, on the network thread: the page, stills, routes,
 * the access token and body collection; answers that the render thread prepares are handed back
 * here (sy_web_internal.h; docs/WEB.md). */
#include "sy_web_internal.h"

#include "sy_log.h"
#include "sy_web_assets.h"
#include "sy_web_frame.h"

#include <ctype.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define WEB_COOKIE "sy_token"

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

int sy_webi_http_status_of(sy_result r)
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


void sy_webi_read_head(struct lws *wsi, head_bufs *b, sy_web_head *h)
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
    static const char site[] = "sec-fetch-site:"; /* lws keeps unknown headers by their lower-case name */
    if (lws_hdr_custom_copy(wsi, b->site, (int)sizeof b->site, site, (int)sizeof site - 1) > 0) h->fetch_site = b->site;
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
    sy_webi_post_still(w, j);
    return 0;
}

/* The newest frame the viewers were sent, as its JPEG (the page's first picture while its
 * WebSocket opens: docs/WEB.md, "The first picture"); 204 (no content, not an error: the page
 * waits for its socket's frames) before the first frame or while only video viewers are sent
 * frames (no JPEG made). A copy of bytes already made: no rendering. */
static int latest_request(sy_web *w, struct lws *wsi, http_pss *p)
{
    pthread_mutex_lock(&w->mu);
    web_frame *f = w->latest;
    int r = f && f->jpeg_len ? respond(wsi, p, 200, "image/jpeg", f->buf + LWS_PRE + SY_WEB_FRAME_HEADER, f->jpeg_len)
                             : respond(wsi, p, 204, "image/jpeg", NULL, 0);
    pthread_mutex_unlock(&w->mu);
    return r;
}

static int http_request(sy_web *w, struct lws *wsi, http_pss *p, const char *uri)
{
    memset(p, 0, sizeof *p);
    lws_get_peer_simple(wsi, p->peer, sizeof p->peer);
    (void)uri; /* relative to the mount; the request line's path is taken instead */
    head_bufs b;
    sy_web_head h;
    sy_web_verdict v;
    sy_webi_read_head(wsi, &b, &h);
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
    case SY_WEB_TARGET_ASSET:
        p->status = 200, p->ctype = v.asset->content_type;
        p->body = v.asset->bytes, p->body_len = v.asset->len;
        p->responding = true;
        lws_callback_on_writable(wsi);
        return 0;
    case SY_WEB_TARGET_STILL: return still_request(w, wsi, p, v.still_w, v.still_h);
    case SY_WEB_TARGET_LATEST: return latest_request(w, wsi, p);
    case SY_WEB_TARGET_ROUTE:
        if (post) {
            p->route = v.route; /* the body follows: HTTP_BODY, then HTTP_BODY_COMPLETION */
            return 0;
        } else {
            web_job *j = new_job(wsi, p, v.route, "GET");
            if (!j) return -1;
            sy_webi_post_job(w, j);
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
    sy_webi_post_job(w, j);
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
    sy_webi_job_free(p->job);
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
    if (mine) sy_webi_job_free(j);
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
            sy_webi_job_free(j);
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
void sy_webi_gate_deliver(void *user, int fd, uint8_t *bytes, size_t len)
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

int sy_webi_http_callback(struct lws *wsi, enum lws_callback_reasons reason, void *user, void *in, size_t len)
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
