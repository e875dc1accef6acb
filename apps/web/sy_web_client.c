/* sy_web_client.c — blocking WebSocket client of sy web's stream (see sy_web_client.h). */
#include "sy_web_client.h"

#include <libwebsockets.h>
#include <stdlib.h>
#include <string.h>

#define CLIENT_MAX_MESSAGE (64u << 20)
#define CLIENT_MAX_TEXTS 256u

typedef struct msg {
    struct msg *next;
    uint8_t *data;
    size_t len;
} msg;

struct sy_web_client {
    struct lws_context *ctx;
    struct lws *wsi;
    bool established, failed, closed;
    char fail_reason[200];
    uint8_t *cur; /* the binary message being assembled */
    size_t cur_len;
    bool cur_binary;
    msg *head, **tail; /* complete binary messages */
    msg *texts, **texts_tail; /* complete text messages (the newest CLIENT_MAX_TEXTS) */
    uint32_t text_count;
    char *out;         /* a text message waiting for the socket */
    size_t out_len;
    /* the last depth channel received (for the frames that say they have it: SY_WEB_FRAME_SAME_DEPTH),
     * with the size and range of its frame */
    uint8_t *depth;
    uint32_t depth_len, depth_w, depth_h;
    float depth_min, depth_max;
};

static int client_cb(struct lws *wsi, enum lws_callback_reasons reason, void *user, void *in, size_t len)
{
    (void)user;
    sy_web_client *c = lws_context_user(lws_get_context(wsi));
    switch (reason) {
    case LWS_CALLBACK_CLIENT_CONNECTION_ERROR:
        c->failed = true;
        snprintf(c->fail_reason, sizeof c->fail_reason, "%s", in ? (const char *)in : "connection error");
        c->wsi = NULL;
        return 0;
    case LWS_CALLBACK_CLIENT_ESTABLISHED: c->established = true; return 0;
    case LWS_CALLBACK_CLIENT_RECEIVE: {
        if (lws_is_first_fragment(wsi)) c->cur_len = 0, c->cur_binary = lws_frame_is_binary(wsi);
        if (len > CLIENT_MAX_MESSAGE - c->cur_len) return -1;
        uint8_t *b = realloc(c->cur, c->cur_len + len + 1);
        if (!b) return -1;
        c->cur = b;
        memcpy(c->cur + c->cur_len, in, len);
        c->cur_len += len;
        if (lws_is_final_fragment(wsi) && !lws_remaining_packet_payload(wsi)) {
            msg *m = malloc(sizeof *m);
            if (!m) return -1;
            c->cur[c->cur_len] = 0; /* text: a C string (room was allocated) */
            m->next = NULL, m->data = c->cur, m->len = c->cur_len;
            c->cur = NULL, c->cur_len = 0;
            if (c->cur_binary) {
                *c->tail = m;
                c->tail = &m->next;
            } else {
                *c->texts_tail = m;
                c->texts_tail = &m->next;
                if (++c->text_count > CLIENT_MAX_TEXTS) { /* nobody reads them: the oldest goes */
                    msg *o = c->texts;
                    c->texts = o->next;
                    free(o->data), free(o);
                    c->text_count--;
                }
            }
        }
        return 0;
    }
    case LWS_CALLBACK_CLIENT_WRITEABLE:
        if (c->out) {
            int n = lws_write(wsi, (unsigned char *)c->out + LWS_PRE, c->out_len, LWS_WRITE_TEXT);
            free(c->out);
            c->out = NULL;
            if (n < (int)c->out_len) return -1;
        }
        return 0;
    case LWS_CALLBACK_CLIENT_CLOSED:
    case LWS_CALLBACK_CLOSED: c->closed = true, c->wsi = NULL; return 0;
    default: return 0;
    }
}

static const struct lws_protocols client_protocols[] = {{"sy-view", client_cb, 0, 65536, 0, NULL, 0},
                                                        {NULL, NULL, 0, 0, 0, NULL, 0}};

sy_result sy_web_client_connect(const sy_web_client_opts *o, uint32_t timeout_ms, sy_web_client **out, sy_error *err)
{
    *out = NULL;
    sy_web_client *c = calloc(1, sizeof *c);
    if (!c) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "web client: out of memory");
    c->tail = &c->head;
    c->texts_tail = &c->texts;
    struct lws_context_creation_info ci;
    memset(&ci, 0, sizeof ci);
    ci.port = CONTEXT_PORT_NO_LISTEN;
    ci.protocols = client_protocols;
    ci.user = c;
    c->ctx = lws_create_context(&ci);
    if (!c->ctx) {
        free(c);
        return sy_error_set(err, SY_ERR_IO, "web client: libwebsockets could not start");
    }
    struct lws_client_connect_info cc;
    memset(&cc, 0, sizeof cc);
    cc.context = c->ctx;
    cc.address = o->host;
    cc.port = o->port;
    cc.path = o->path ? o->path : "/ws";
    char host[160];
    snprintf(host, sizeof host, "%s:%u", o->host, o->port);
    cc.host = host;
    cc.origin = o->origin ? o->origin : host; /* a page of the server itself, as a browser names it */
    cc.protocol = "sy-view";
    cc.local_protocol_name = "sy-view";
    cc.pwsi = &c->wsi;
    if (!lws_client_connect_via_info(&cc)) c->failed = true;
    double end = sy_time_now() + timeout_ms / 1000.0;
    while (!c->established && !c->failed && !c->closed && sy_time_now() < end) lws_service(c->ctx, 0);
    if (!c->established) {
        sy_result r = c->failed || c->closed
                          ? sy_error_set(err, SY_ERR_PROTOCOL, "web client: %s:%u%s: upgrade refused (%s)", o->host, o->port,
                                         cc.path, c->fail_reason[0] ? c->fail_reason : "closed")
                          : sy_error_set(err, SY_ERR_IO, "web client: %s:%u: no answer within %u ms", o->host, o->port,
                                         timeout_ms);
        sy_web_client_close(c);
        return r;
    }
    *out = c;
    return SY_OK;
}

sy_result sy_web_client_send(sy_web_client *c, const char *text, sy_error *err)
{
    if (!c->wsi) return sy_error_set(err, SY_ERR_IO, "web client: the connection is closed");
    size_t n = strlen(text);
    free(c->out);
    c->out = malloc(LWS_PRE + n);
    if (!c->out) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "web client: out of memory");
    memcpy(c->out + LWS_PRE, text, n);
    c->out_len = n;
    lws_callback_on_writable(c->wsi);
    double end = sy_time_now() + 5.0;
    while (c->out && c->wsi && sy_time_now() < end) lws_service(c->ctx, 0);
    if (c->out) return sy_error_set(err, SY_ERR_IO, "web client: could not send (connection closed or stalled)");
    return SY_OK;
}

sy_result sy_web_client_next_frame_depth(sy_web_client *c, uint32_t timeout_ms, sy_web_frame_info *info,
                                         uint8_t **jpeg, size_t *jpeg_len, float **depth, sy_error *err)
{
    if (jpeg) *jpeg = NULL;
    if (jpeg_len) *jpeg_len = 0;
    if (depth) *depth = NULL;
    double end = sy_time_now() + timeout_ms / 1000.0;
    for (double now = sy_time_now(); !c->head && c->wsi && now < end; now = sy_time_now()) {
        lws_set_timer_usecs(c->wsi, (lws_usec_t)((end - now) * 1e6) + 1000); /* lws_service ignores its timeout */
        lws_service(c->ctx, 0);
    }
    if (!c->head)
        return sy_error_set(err, SY_ERR_IO, "web client: no frame within %u ms%s", timeout_ms,
                            c->wsi ? "" : " (connection closed)");
    msg *m = c->head;
    c->head = m->next;
    if (!c->head) c->tail = &c->head;
    const uint8_t *jp = NULL, *dp = NULL;
    sy_result r = sy_web_frame_parse(m->data, m->len, info, &jp, &dp, err);
    if (r == SY_OK && jpeg) {
        *jpeg = malloc(info->jpeg_len + 1u);
        if (!*jpeg) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "web client: out of memory");
        else memcpy(*jpeg, jp, info->jpeg_len), *jpeg_len = info->jpeg_len;
    }
    if (r == SY_OK && info->depth_len) { /* kept for the frames that say they have it */
        uint8_t *keep = malloc(info->depth_len);
        if (!keep) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "web client: out of memory");
        else {
            memcpy(keep, dp, info->depth_len);
            free(c->depth);
            c->depth = keep, c->depth_len = info->depth_len, c->depth_w = info->width, c->depth_h = info->height;
            c->depth_min = info->depth_min, c->depth_max = info->depth_max;
        }
    }
    if (r == SY_OK && depth && (info->flags & SY_WEB_FRAME_SAME_DEPTH)) {
        if (!c->depth || c->depth_w != info->width || c->depth_h != info->height)
            r = sy_error_set(err, SY_ERR_PROTOCOL, "web client: a %ux%u frame says it has the last depth channel, which is %s",
                             info->width, info->height, c->depth ? "of another size" : "none");
        else {
            sy_web_frame_info g = *info;
            g.depth_len = c->depth_len, g.depth_min = c->depth_min, g.depth_max = c->depth_max;
            g.depth_coding = SY_WEB_DEPTH_GRID_LOG12;
            r = sy_web_frame_depth(&g, c->depth, depth, err);
        }
    } else if (r == SY_OK && depth)
        r = sy_web_frame_depth(info, dp, depth, err);
    free(m->data);
    free(m);
    return r;
}

sy_result sy_web_client_next_frame(sy_web_client *c, uint32_t timeout_ms, sy_web_frame_info *info, uint8_t **jpeg,
                                   size_t *jpeg_len, sy_error *err)
{
    return sy_web_client_next_frame_depth(c, timeout_ms, info, jpeg, jpeg_len, NULL, err);
}

sy_result sy_web_client_next_text(sy_web_client *c, uint32_t timeout_ms, const char *type, char **text, sy_error *err)
{
    *text = NULL;
    char want[80];
    snprintf(want, sizeof want, "\"t\":\"%.60s\"", type ? type : "");
    double end = sy_time_now() + timeout_ms / 1000.0;
    for (;;) {
        while (c->texts) { /* the oldest first; other types are dropped */
            msg *m = c->texts;
            c->texts = m->next;
            if (!c->texts) c->texts_tail = &c->texts;
            c->text_count--;
            if (!type || strstr((char *)m->data, want)) {
                *text = (char *)m->data;
                free(m);
                return SY_OK;
            }
            free(m->data), free(m);
        }
        double now = sy_time_now();
        if (!c->wsi || now >= end) break;
        /* lws_service waits for traffic (its timeout is ignored): a timer ends the wait at the deadline */
        lws_set_timer_usecs(c->wsi, (lws_usec_t)((end - now) * 1e6) + 1000);
        lws_service(c->ctx, 0);
    }
    return sy_error_set(err, SY_ERR_IO, "web client: no \"%s\" message within %u ms%s", type ? type : "text", timeout_ms,
                        c->wsi ? "" : " (connection closed)");
}

void sy_web_client_close(sy_web_client *c)
{
    if (!c) return;
    if (c->ctx) lws_context_destroy(c->ctx);
    free(c->depth);
    while (c->texts) {
        msg *m = c->texts;
        c->texts = m->next;
        free(m->data);
        free(m);
    }
    while (c->head) {
        msg *m = c->head;
        c->head = m->next;
        free(m->data);
        free(m);
    }
    free(c->cur);
    free(c->out);
    free(c);
}
