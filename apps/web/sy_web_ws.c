/* sy_web_ws.c — the sy_web server's WebSocket viewers, on the network thread: input messages in
 * (to the mailbox), the hello, the status and the newest frame out; the protocol table and the
 * network thread's service loop (sy_web_internal.h; docs/WEB.md, "The WebSocket protocol"). */
#include "sy_web_internal.h"

#include "sy_log.h"
#include "sy_mediator.h"

#include <cjson/cJSON.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A WebSocket viewer: the sy-view protocol's per-connection data (network thread only). */
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
    case SY_WEB_INPUT_DRAG: sy_interactive_drag(&w->in, in.button >= 1 ? 1 : 0, (float)in.a, (float)in.b); break;
    case SY_WEB_INPUT_WHEEL: sy_interactive_wheel(&w->in, (float)in.a); break;
    case SY_WEB_INPUT_KEY:
        if (in.key >= '1' && in.key <= '9') {
            uint32_t i = (uint32_t)(in.key - '1');
            if (i < sy_mediator_count()) /* the cluster is no choice of its own: the initial back-end */
                w->backend = (sy_mediator_at(i)->caps & SY_CAP_REMOTE) ? w->initial_backend : i;
        } else {
            sy_interactive_key(&w->in, in.key); /* f, [, ], r (sy_interactive.h) */
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
        char fname[32];
        cJSON_AddStringToObject(o, "filter", sy_interactive_filter_name(w->in.filter, fname));
        if (w->status[0]) cJSON_AddStringToObject(o, "error", w->status);
        char *s = cJSON_PrintUnformatted(o);
        if (s) snprintf(status, sizeof status, "%s", s);
        cJSON_free(s);
        cJSON_Delete(o);
    }
    pthread_mutex_unlock(&w->mu);
    if (status[0]) {
        if (fresh) sy_webi_frame_release(w, f);
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
    sy_webi_frame_release(w, f); /* f may be gone from here: the render thread may have replaced it */
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
        sy_webi_read_head(wsi, &b, &h);
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
        if (w) lws_callback_on_writable_all_protocol(ctx, &sy_webi_protocols[1]);
        return 0;
    default: return 0;
    }
}

const struct lws_protocols sy_webi_protocols[] = {
    {"http", sy_webi_http_callback, sizeof(http_pss), 0, 0, NULL, 0},
    {"sy-view", ws_callback, sizeof(web_conn), 4096, 1, NULL, 0},
    {NULL, NULL, 0, 0, 0, NULL, 0},
};

/* The WebSocket is served at /ws; everything else goes to the http protocol's callback. */
const struct lws_http_mount sy_webi_mount = {
    .mountpoint = "/",
    .mountpoint_len = 1,
    .origin = "http",
    .origin_protocol = LWSMPRO_CALLBACK,
};

void *sy_webi_net_main(void *p)
{
    sy_web *w = p;
    while (!w->net_quit)
        if (lws_service(w->ctx, 0) < 0) break;
    return NULL;
}
