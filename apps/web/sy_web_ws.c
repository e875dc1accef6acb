/* sy_web_ws.c — the sy_web server's WebSocket viewers, on the network thread: input messages in
 * (to the mailbox), the hello, the status and the newest frame out; the protocol table and the
 * network thread's service loop (sy_web_internal.h; docs/WEB.md, "The WebSocket protocol"). */
#include "sy_web_internal.h"

#include "sy_log.h"
#include "sy_mediator.h"
#include "sy_jpeg.h"
#include "sy_web_frame.h"
#include "sy_web_cost.h"
#include "sy_web_video.h"

#include <cjson/cJSON.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define WS_IDS 64    /* inputs remembered per connection: which one a frame answers */
#define WS_DELAYED 64 /* --delay-ms: input messages held per connection (more are dropped) */
#define WS_QUEUED 16  /* --delay-ms: frames held per connection (the oldest is dropped beyond) */

/* --delay-ms (test only): an input message held until due, or a frame. */
typedef struct delayed_msg {
    double due; /* ms, sy_time_now */
    char *text;
    size_t len;
} delayed_msg;
typedef struct queued_frame {
    double due;
    web_frame *f; /* one reference */
    uint64_t answered;
} queued_frame;

/* A WebSocket viewer: the sy-view protocol's per-connection data (network thread only). */
struct web_conn {
    web_conn *next;
    struct lws *wsi;
    uint64_t serial;             /* names the connection in web_action / web_reply (never reused) */
    uint64_t sent_scene;         /* the scene_version last announced to it */
    char peer[64];
    uint64_t sent_seq, sent_status, queued_seq;
    uint64_t sent_clock;         /* the clock_version last sent to it ("clock" message) */
    uint64_t sent_views;         /* the views_version last sent to it ("views" message) */
    /* the client's newest inputs with the generation each got (a ring): a frame answers the newest
     * one whose generation it includes */
    uint64_t ids[WS_IDS], gens[WS_IDS];
    uint32_t ids_n, ids_next;
    uint64_t answered_id;
    bool hello_sent;
    bool sized;                  /* frames go to a viewer once it said its size (with "v": 3) */
    bool framed;                 /* it was given a frame (its first must have its display's shape) */
    bool old_page, refusal_sent; /* a page that does not read frame format 3 (no "v" in its size message, or a lower one) */
    uint32_t old_version;        /* the format it reads (1: no "v") */
    delayed_msg delayed[WS_DELAYED];
    uint32_t delayed_head, delayed_n;
    queued_frame queued[WS_QUEUED];
    uint32_t queued_head, queued_n;
    uint32_t warned;    /* malformed messages logged */
    char *msg;          /* a text message being assembled (max_message bytes) */
    size_t msg_len;     /* its bytes so far (a binary message's are counted, not kept) */
    bool msg_binary;
    /* the video stream (docs/WEB.md, "The video stream"): the codec this viewer is sent (JPEG: none
     * of those it decodes is available, or the budget is spent), its encoder, made at its first
     * video frame, and what it has sent */
    sy_web_codec codec;
    sy_web_video_encoder *enc;
    size_t reserved;          /* the encoder's share of WEB_VIDEO_BUDGET */
    bool want_key;            /* the next video frame is a keyframe (asked, or a new back-end) */
    uint64_t depth_key;       /* the depth channel this viewer was sent last (web_frame.depth_key) */
    sy_web_encode_cost cost;  /* under w->mu: what encoding its frames here costs (sy_web_cost.h), */
    double cost_in_sum;       /* and its share of w->encode_per_px_ms */
    uint32_t last_backend;
    int kind;                 /* counted in w->video_viewers (2), jpeg_viewers (1) or neither (0) */
    bool plain;               /* counted in w->plain_viewers: sized, and its page does not warp */
    uint64_t v_frames, v_keys, v_bytes;
    double v_psnr;            /* sum over v_frames */
};

/* Counts c as a video (2) or JPEG (1) viewer or neither (0): the render thread keeps the pixels
 * while a video viewer is there and makes JPEG while a JPEG viewer is. Call with w->mu held. */
static void set_kind(sy_web *w, web_conn *c, int kind)
{
    if (kind != c->kind) { /* its encoders' cost starts over (or leaves with it) */
        w->encode_per_px_ms -= c->cost_in_sum;
        if (w->encode_per_px_ms < 0) w->encode_per_px_ms = 0;
        c->cost_in_sum = 0, c->cost = (sy_web_encode_cost){0};
    }
    if (c->kind == 2) w->video_viewers--;
    if (c->kind == 1) w->jpeg_viewers--;
    c->kind = kind;
    if (kind == 2) w->video_viewers++;
    if (kind == 1) w->jpeg_viewers++;
}

/* Counts c among the sized viewers whose page does not warp (plain) or not: moving frames keep
 * sy_web_desc.min_scale of the display only while there is none. Call with w->mu held. */
static void set_plain(sy_web *w, web_conn *c, bool plain)
{
    if (c->plain) w->plain_viewers--;
    c->plain = plain;
    if (plain) w->plain_viewers++;
}

static void video_summary(web_conn *c, const char *when)
{
    if (!c->v_frames) return;
    sy_log(SY_LOG_NOTE, "web", c->peer, "video %s%s: %llu frames (%llu keyframes), %.0f bytes per frame, PSNR %.2f dB",
           sy_web_codec_name(c->codec), when, (unsigned long long)c->v_frames, (unsigned long long)c->v_keys,
           (double)c->v_bytes / c->v_frames, c->v_psnr / c->v_frames);
}

/* The viewer's codec from its size message: the first name it lists that this build encodes, if
 * the encoders' budget has room for one more at the largest frame; names it does not know are
 * ignored with a log line; otherwise JPEG as before. Network thread. */
static void choose_codec(sy_web *w, web_conn *c, const sy_web_input *in)
{
    sy_web_codec pick = SY_WEB_CODEC_JPEG;
    for (uint32_t i = 0; i < in->codec_count; ++i) {
        sy_web_codec k;
        if (!sy_web_codec_from_name(in->codecs[i], strlen(in->codecs[i]), &k))
            sy_log(SY_LOG_WARNING, "web", c->peer, "ignored the codec \"%s\" the page listed: no such codec here", in->codecs[i]);
        else if (pick == SY_WEB_CODEC_JPEG && sy_web_codec_available(k))
            pick = k;
    }
    if (in->codecs_ignored)
        sy_log(SY_LOG_WARNING, "web", c->peer, "ignored %u codec entr%s of the size message (the first: %s; a codec is a name of 1..15 of a-z, 0-9 and .)",
               in->codecs_ignored, in->codecs_ignored == 1 ? "y" : "ies", in->codec_ignored);
    if (pick == c->codec) return;
    video_summary(c, " (switched)");
    sy_web_video_encoder_destroy(c->enc);
    c->enc = NULL;
    w->video_reserved -= c->reserved;
    c->reserved = 0;
    c->v_frames = c->v_keys = c->v_bytes = 0, c->v_psnr = 0;
    if (pick != SY_WEB_CODEC_JPEG) {
        size_t need = sy_web_video_encoder_bytes(w->d.max_width, w->d.max_height);
        if (w->video_reserved + need > WEB_VIDEO_BUDGET) {
            sy_log(SY_LOG_WARNING, "web", c->peer, "%s refused: the video encoders' budget (%zu MiB) is spent: JPEG",
                   sy_web_codec_name(pick), WEB_VIDEO_BUDGET >> 20);
            pick = SY_WEB_CODEC_JPEG;
        } else {
            w->video_reserved += need, c->reserved = need;
        }
    }
    c->codec = pick, c->want_key = true;
    if (pick != SY_WEB_CODEC_JPEG && c->sized) {
        /* a page that lists its codecs after its first size (view.js, once video.js knows them),
         * maybe while the view rests: the newest frame again, with its pixels, under a new number */
        pthread_mutex_lock(&w->mu);
        w->need_pixels = true;
        pthread_cond_signal(&w->cv);
        pthread_mutex_unlock(&w->mu);
    }
    sy_log(SY_LOG_NOTE, "web", c->peer, "the viewer is sent %s", sy_web_codec_name(pick));
}

/* A malformed message: logged with the client's address, the first 10 per connection (a flood
 * does not flood the log). */
static void ws_warn(web_conn *c, const char *what, const char *detail)
{
    if (c->warned >= 10) return;
    c->warned++;
    sy_log(SY_LOG_WARNING, "web", c->peer, "ignored a message: %s%s%.80s%s", what, detail ? ": " : "", detail ? detail : "",
           c->warned == 10 ? " (further ones from this client are not logged)" : "");
}

static void ws_message(sy_web *w, web_conn *c, const char *text, size_t len);

/* The first size message in the URL (/ws?w=W&h=H&v=V; docs/WEB.md, "The first picture"): the page
 * that cannot send it yet (its scripts still load) gets its first frame rendered meanwhile. Taken
 * as that message (sy_web_parse_input judges it); no or a malformed size: the page sends its own. */
static void size_from_url(sy_web *w, web_conn *c, struct lws *wsi)
{
    head_bufs b;
    sy_web_head h;
    sy_webi_read_head(wsi, &b, &h);
    const char *names[3] = {"w", "h", "v"}, *val[3];
    size_t n[3];
    for (int i = 0; i < 3; ++i) {
        if (!h.query || !sy_web_query_arg(h.query, names[i], &val[i], &n[i]) || n[i] < 1 || n[i] > 6) return;
        for (size_t k = 0; k < n[i]; ++k)
            if (val[i][k] < '0' || val[i][k] > '9') return;
    }
    char m[96];
    int len = snprintf(m, sizeof m, "{\"t\":\"size\",\"w\":%.*s,\"h\":%.*s,\"v\":%.*s}", (int)n[0], val[0], (int)n[1], val[1],
                       (int)n[2], val[2]);
    if (len > 0 && (size_t)len < sizeof m) ws_message(w, c, m, (size_t)len);
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
    if (w->d.read_only && sy_web_input_changes_scene(&in)) { /* viewers look, they do not change */
        ws_warn(c, "read-only server: refused a change (visibility, selection, planes, exposure, filter, environment or back-end)", NULL);
        return;
    }
    if (w->d.read_only && in.type == SY_WEB_INPUT_PICK) in.on = false; /* a pick tells, it does not select */
    if (in.type == SY_WEB_INPUT_KEYFRAME) { /* the page's decoder lost its place: the newest frame again, as a keyframe */
        c->want_key = true, c->sent_seq = c->queued_seq = 0;
        lws_callback_on_writable(c->wsi);
        return;
    }
    if (in.type == SY_WEB_INPUT_SIZE && in.version >= SY_WEB_FRAME_VERSION) choose_codec(w, c, &in);
    pthread_mutex_lock(&w->mu);
    bool input = true, clock_changed = false;
    switch (in.type) {
    case SY_WEB_INPUT_VIEW: { /* saved views (sy_web_views.c): a recall moves the camera, a save is written */
        web_view_done done = sy_webi_view_message(w, &in, c->peer);
        if (done != WEB_VIEW_RECALLED) {
            pthread_mutex_unlock(&w->mu);
            if (done == WEB_VIEW_SAVED) {
                sy_webi_views_write(w, c->peer);
                lws_callback_on_writable_all_protocol(lws_get_context(c->wsi), &sy_webi_protocols[1]); /* every page's list */
            }
            return;
        }
        break;
    }
    case SY_WEB_INPUT_PICK:
    case SY_WEB_INPUT_VISIBLE:
    case SY_WEB_INPUT_SELECT:
    case SY_WEB_INPUT_ISOLATE:
    case SY_WEB_INPUT_CLIP:
    case SY_WEB_INPUT_ENVIRONMENT:
    case SY_WEB_INPUT_TREE: { /* the render thread owns the scene: queued for it */
        web_action *a = w->action_count < WEB_ACTIONS_MAX ? calloc(1, sizeof *a) : NULL;
        if (!a) {
            pthread_mutex_unlock(&w->mu);
            ws_warn(c, "too many requests queued: dropped", NULL);
            return;
        }
        a->conn = c->serial, a->in = in;
        snprintf(a->peer, sizeof a->peer, "%s", c->peer);
        *w->actions_tail = a, w->actions_tail = &a->next, w->action_count++;
        input = false;
        break;
    }
    case SY_WEB_INPUT_EXPOSURE:
        input = false;
        w->exposure = (float)in.a;
        w->look_version++, w->view_version++;
        break;
    case SY_WEB_INPUT_FILTER: {
        input = false;
        uint32_t n = sy_interactive_filter_count(), i = 0;
        char name[32];
        while (i < n && strcmp(sy_interactive_filter_name(i, name), in.filter) != 0) i++;
        if (i == n) {
            pthread_mutex_unlock(&w->mu);
            ws_warn(c, "filter: no such display filter", in.filter);
            return;
        }
        w->in.filter = i, w->in.filter_version++;
        w->view_version++;
        break;
    }
    case SY_WEB_INPUT_TIME:
    case SY_WEB_INPUT_PLAY: /* the timeline (docs/WEB.md): a view change, allowed on a read-only server */
        input = false;
        if (!w->animated) {
            pthread_mutex_unlock(&w->mu);
            ws_warn(c, in.type == SY_WEB_INPUT_TIME ? "time: the scene has no animations" : "play: the scene has no animations", NULL);
            return;
        }
        if (in.type == SY_WEB_INPUT_TIME && !(in.a >= w->clock.start && in.a <= w->clock.end)) {
            char d[96];
            snprintf(d, sizeof d, "%g s is outside the scene's clips, %g .. %g s", in.a, w->clock.start, w->clock.end);
            pthread_mutex_unlock(&w->mu);
            ws_warn(c, "time", d);
            return;
        }
        if (in.type == SY_WEB_INPUT_TIME) w->clock.time = in.a;
        else w->clock.playing = in.on;
        w->clock_version++, w->view_version++;
        clock_changed = true;
        break;
    case SY_WEB_INPUT_ANIM: /* the clip the clock plays (docs/WEB.md, "The timeline"): a view change too */
        input = false;
        if (!w->animated || in.a >= (double)w->clip_count) {
            char d[96];
            snprintf(d, sizeof d, "clip %g: the scene has %u clip(s) (-1: every clip)", in.a, w->clip_count);
            pthread_mutex_unlock(&w->mu);
            ws_warn(c, w->animated ? "anim" : "anim: the scene has no animations", w->animated ? d : NULL);
            return;
        }
        w->clip = in.a < 0 ? w->clip_count : (uint32_t)in.a;
        w->clock.start = w->clock.time = w->clip_range[w->clip][0]; /* at the clip's start, playing on if it played */
        w->clock.end = w->clip_range[w->clip][1];
        w->clock_version++, w->view_version++;
        clock_changed = true;
        break;
    case SY_WEB_INPUT_SIZE:
        input = false;
        if (in.version < SY_WEB_FRAME_VERSION) { /* an old page: told to reload, never sent frames it cannot read */
            c->old_page = true, c->old_version = in.version ? in.version : 1u;
            pthread_mutex_unlock(&w->mu);
            char why[120];
            snprintf(why, sizeof why, "a page that reads frame format %u (this server sends %u): told to reload",
                     in.version ? in.version : 1u, SY_WEB_FRAME_VERSION);
            ws_warn(c, why, NULL);
            lws_callback_on_writable(c->wsi);
            return;
        }
        /* a viewer's first size, or another size: frames for it; the same size again (the page
         * lists its video codecs once it knows them) renders nothing new */
        if (!c->sized || w->display_w != (uint32_t)in.a || w->display_h != (uint32_t)in.b) w->view_version++;
        c->old_page = false, c->sized = true;
        set_kind(w, c, c->codec == SY_WEB_CODEC_JPEG ? 1 : 2);
        if (c->plain == in.warp) w->view_version++; /* the moving frames' floor may change */
        set_plain(w, c, !in.warp);
        w->display_w = (uint32_t)in.a, w->display_h = (uint32_t)in.b;
        break;
    case SY_WEB_INPUT_DRAG: sy_interactive_drag(&w->in, in.button >= 1 ? 1 : 0, (float)in.a, (float)in.b); break;
    case SY_WEB_INPUT_LEAD: /* the lead alone (the page rests: [0, 0]): a new frame only when it changed */
        input = false;
        if (w->lead[0] != (float)in.lead[0] || w->lead[1] != (float)in.lead[1] || w->lead_button != in.button)
            w->view_version++;
        break;
    case SY_WEB_INPUT_WHEEL: sy_interactive_wheel(&w->in, (float)in.a); break;
    case SY_WEB_INPUT_KEYFRAME: break; /* handled above */
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
    if (in.type == SY_WEB_INPUT_DRAG || in.type == SY_WEB_INPUT_LEAD) /* what frames lead by from now on */
        w->lead[0] = (float)in.lead[0], w->lead[1] = (float)in.lead[1], w->lead_button = in.button, w->lead_conn = c->serial;
    else if (input) /* the camera moved otherwise (wheel, keys, a saved view): no lead until the next drag */
        w->lead[0] = w->lead[1] = 0.0f;
    if (input) {
        w->view_version++;
        w->input_gen++;
        if (in.has_id) {
            c->ids[c->ids_next] = in.id, c->gens[c->ids_next] = w->input_gen;
            c->ids_next = (c->ids_next + 1) % WS_IDS;
            if (c->ids_n < WS_IDS) c->ids_n++;
        }
    }
    pthread_cond_signal(&w->cv);
    pthread_mutex_unlock(&w->mu);
    /* every page is told the clock's new state now, whether or not a frame follows (the same time
     * again renders nothing new) */
    if (clock_changed) lws_callback_on_writable_all_protocol(lws_get_context(c->wsi), &sy_webi_protocols[1]);
}

static void delay_timer(sy_web *w, web_conn *c);

/* --delay-ms (test only): the message is held delay_ms before it is applied; at most WS_DELAYED
 * per connection (copies of at most max_message bytes each), more are dropped and logged. */
static void delay_message(sy_web *w, web_conn *c)
{
    char *t = c->delayed_n < WS_DELAYED ? malloc(c->msg_len + 1) : NULL;
    if (!t) {
        ws_warn(c, "--delay-ms: too many messages held", NULL);
        return;
    }
    memcpy(t, c->msg, c->msg_len);
    delayed_msg *d = &c->delayed[(c->delayed_head + c->delayed_n++) % WS_DELAYED];
    d->text = t, d->len = c->msg_len, d->due = sy_time_now() * 1e3 + w->d.delay_ms;
    delay_timer(w, c);
}

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

/* The hello: the back-ends (key order), the display filters, whether the server is read-only, and
 * the exposure now (docs/WEB.md). */
static int ws_send_hello(sy_web *w, struct lws *wsi)
{
    cJSON *o = cJSON_CreateObject(), *arr = cJSON_AddArrayToObject(o, "backends");
    cJSON_AddStringToObject(o, "t", "hello");
    for (uint32_t i = 0; i < sy_mediator_count(); ++i) cJSON_AddItemToArray(arr, cJSON_CreateString(sy_mediator_at(i)->name));
    cJSON *caps = cJSON_AddArrayToObject(o, "caps"); /* per back-end: can it pick, cut */
    for (uint32_t i = 0; i < sy_mediator_count(); ++i) {
        cJSON *cc = cJSON_CreateObject();
        uint32_t k = sy_mediator_at(i)->caps;
        cJSON_AddBoolToObject(cc, "pick", (k & SY_CAP_PICK) != 0);
        cJSON_AddBoolToObject(cc, "clip", (k & SY_CAP_CLIP) != 0);
        cJSON_AddBoolToObject(cc, "filters", (k & SY_CAP_FILTERS) != 0);
        cJSON_AddItemToArray(caps, cc);
    }
    cJSON *fl = cJSON_AddArrayToObject(o, "filters");
    char name[32];
    for (uint32_t i = 0; i < sy_interactive_filter_count(); ++i)
        cJSON_AddItemToArray(fl, cJSON_CreateString(sy_interactive_filter_name(i, name)));
    cJSON *envs = cJSON_AddArrayToObject(o, "environments"); /* the menu's choices (sy_web_scene.c) */
    for (uint32_t i = 0; i < SY_WEB_ENVIRONMENTS; ++i) cJSON_AddItemToArray(envs, cJSON_CreateString(sy_webi_environment_names[i]));
    cJSON_AddBoolToObject(o, "read_only", w->d.read_only);
    if (w->animated) { /* the timeline's clip menu: names in the order "anim" indexes them (the clip list is fixed) */
        cJSON *cl = cJSON_AddArrayToObject(o, "clips");
        for (uint32_t i = 0; i < w->clip_count; ++i) cJSON_AddItemToArray(cl, cJSON_CreateString(w->clip_names[i]));
    }
    pthread_mutex_lock(&w->mu);
    cJSON_AddNumberToObject(o, "exposure", w->exposure);
    cJSON_AddStringToObject(o, "environment", sy_webi_environment_names[w->environment < SY_WEB_ENVIRONMENTS ? w->environment : 0]);
    pthread_mutex_unlock(&w->mu);
    char *s = cJSON_PrintUnformatted(o);
    cJSON_Delete(o);
    if (!s) return -1;
    int r = ws_send_text(wsi, s);
    cJSON_free(s);
    return r;
}

/* The newest input of c that frame generation gen includes (inputs arrive in order, so every
 * earlier one is included too); inputs older than the ring keep the last answer. */
static uint64_t answered_by(web_conn *c, uint64_t gen)
{
    for (uint32_t k = 0; k < c->ids_n; ++k) {
        uint32_t i = (c->ids_next + WS_IDS - 1 - k) % WS_IDS;
        if (c->gens[i] <= gen) {
            if (c->ids[i] > c->answered_id) c->answered_id = c->ids[i];
            break;
        }
    }
    return c->answered_id;
}

/* What encoding a frame of width x height for c took since t0 (sy_time_now): counted in the cost
 * the render thread reports to the governor (sy_web_cost.h). */
static void count_encode(sy_web *w, web_conn *c, double t0, uint32_t width, uint32_t height)
{
    double ms = (sy_time_now() - t0) * 1e3;
    pthread_mutex_lock(&w->mu);
    double d = sy_web_encode_cost_add(&c->cost, ms, (uint64_t)width * height);
    c->cost_in_sum += d, w->encode_per_px_ms += d;
    pthread_mutex_unlock(&w->mu);
}

/* A video viewer's frame: the header of f with the codec's frame in place of the JPEG, then the
 * depth channel (docs/WEB.md: payload coding at 184, quality at 188, keyframe flag). The encoder
 * sees exactly the frames this viewer is sent, in order, so each one predicts from the last. On
 * an encoder failure the viewer falls back to JPEG. */
static int send_video(sy_web *w, web_conn *c, web_frame *f, uint64_t id)
{
    sy_error err = {0};
    sy_result r = c->enc ? SY_OK
                         : sy_web_video_encoder_create(c->codec, sy_web_video_quantizer(w->d.quality), &c->enc, &err);
    const uint8_t *pkt = NULL;
    size_t plen = 0;
    bool key = false;
    double t0 = sy_time_now();
    if (r == SY_OK)
        r = sy_web_video_encode(c->enc, f->rgba, f->width, f->height, c->want_key || f->backend != c->last_backend, &pkt,
                                &plen, &key, &err);
    if (r == SY_OK) count_encode(w, c, t0, f->width, f->height);
    bool same_depth = f->depth_key && f->depth_key == c->depth_key; /* the page has it: left out */
    size_t dlen = same_depth ? 0 : f->depth_len;
    size_t total = SY_WEB_FRAME_HEADER + plen + dlen;
    uint8_t *buf = NULL;
    if (r == SY_OK && !(buf = malloc(LWS_PRE + total)))
        r = sy_error_set(&err, SY_ERR_OUT_OF_MEMORY, "web: out of memory for a frame of %zu bytes", total);
    if (r != SY_OK || !buf) {
        sy_log(SY_LOG_WARNING, "web", c->peer, "%s failed, the viewer is sent JPEG from now: %s", sy_web_codec_name(c->codec),
               err.message);
        video_summary(c, "");
        sy_web_video_encoder_destroy(c->enc);
        c->enc = NULL, c->codec = SY_WEB_CODEC_JPEG;
        w->video_reserved -= c->reserved, c->reserved = 0;
        pthread_mutex_lock(&w->mu);
        set_kind(w, c, 1);
        w->view_version++; /* a frame with JPEG for it */
        pthread_cond_signal(&w->cv);
        pthread_mutex_unlock(&w->mu);
        sy_webi_frame_release(w, f);
        return 0;
    }
    c->want_key = false, c->last_backend = f->backend;
    uint8_t *h = buf + LWS_PRE;
    memcpy(h, f->buf + LWS_PRE, SY_WEB_FRAME_HEADER);
    memcpy(h + SY_WEB_FRAME_HEADER, pkt, plen);
    memcpy(h + SY_WEB_FRAME_HEADER + plen, f->buf + LWS_PRE + SY_WEB_FRAME_HEADER + f->jpeg_len, dlen);
    sy_web_frame_info fi = {.jpeg_len = (uint32_t)plen, .codec = c->codec, .quality = (float)sy_web_video_encoder_psnr(c->enc),
                            .flags = key ? SY_WEB_FRAME_KEYFRAME : 0};
    sy_web_frame_set_payload(h, &fi);
    if (same_depth) sy_web_frame_drop_depth(h);
    c->depth_key = f->depth_key;
    memcpy(h + 32, &id, 8);
    sy_webi_frame_release(w, f);
    c->v_frames++, c->v_keys += key, c->v_bytes += plen, c->v_psnr += fi.quality;
    if (c->v_frames % 600 == 0) video_summary(c, " so far");
    int n = lws_write(c->wsi, h, total, LWS_WRITE_BINARY);
    free(buf);
    return n < (int)total ? -1 : 0;
}

static int send_frame(sy_web *w, web_conn *c, web_frame *f, uint64_t id)
{
    if (c->codec != SY_WEB_CODEC_JPEG && f->rgba) return send_video(w, c, f, id);
    if (c->codec != SY_WEB_CODEC_JPEG) { /* rendered before this viewer took video: JPEG now, the pixels asked for */
        pthread_mutex_lock(&w->mu);
        w->need_pixels = true;
        pthread_cond_signal(&w->cv);
        pthread_mutex_unlock(&w->mu);
    }
    if (!f->jpeg_len && f->rgba) { /* rendered while every viewer took video: its JPEG made here, for this viewer */
        uint8_t *jpeg = NULL;
        size_t jlen = 0;
        sy_error err = {0};
        size_t total = 0;
        uint8_t *buf = NULL;
        bool same_depth = f->depth_key && f->depth_key == c->depth_key;
        size_t dlen = same_depth ? 0 : f->depth_len;
        /* not counted in the governor's cost (count_encode): this happens only until the render
         * thread knows a JPEG viewer is there, then it makes the JPEG itself, in the frame's time */
        if (sy_jpeg_encode_rgba8(f->rgba, f->width, f->height, w->d.quality, &jpeg, &jlen, &err) == SY_OK &&
            (buf = malloc(LWS_PRE + (total = SY_WEB_FRAME_HEADER + jlen + dlen)))) {
            uint8_t *h = buf + LWS_PRE;
            memcpy(h, f->buf + LWS_PRE, SY_WEB_FRAME_HEADER);
            memcpy(h + SY_WEB_FRAME_HEADER, jpeg, jlen);
            memcpy(h + SY_WEB_FRAME_HEADER + jlen, f->buf + LWS_PRE + SY_WEB_FRAME_HEADER, dlen);
            sy_web_frame_info fi = {.jpeg_len = (uint32_t)jlen};
            sy_web_frame_set_payload(h, &fi);
            if (same_depth) sy_web_frame_drop_depth(h);
            c->depth_key = f->depth_key;
            memcpy(h + 32, &id, 8);
        } else {
            sy_log(SY_LOG_WARNING, "web", c->peer, "a JPEG for this viewer failed: %s", err.message[0] ? err.message : "out of memory");
        }
        free(jpeg);
        sy_webi_frame_release(w, f);
        if (!buf) return 0;
        int n = lws_write(c->wsi, buf + LWS_PRE, total, LWS_WRITE_BINARY);
        free(buf);
        return n < (int)total ? -1 : 0;
    }
    if (f->depth_key && f->depth_key == c->depth_key) { /* the page has this depth: header and JPEG alone */
        size_t total = SY_WEB_FRAME_HEADER + f->jpeg_len;
        uint8_t *buf = malloc(LWS_PRE + total);
        if (buf) {
            memcpy(buf + LWS_PRE, f->buf + LWS_PRE, total);
            sy_web_frame_drop_depth(buf + LWS_PRE);
            memcpy(buf + LWS_PRE + 32, &id, 8);
        }
        sy_webi_frame_release(w, f);
        if (!buf) return 0;
        int n = lws_write(c->wsi, buf + LWS_PRE, total, LWS_WRITE_BINARY);
        free(buf);
        return n < (int)total ? -1 : 0;
    }
    c->depth_key = f->depth_key;
    memcpy(f->buf + LWS_PRE + 32, &id, 8); /* the buffer is shared: patched right before each write */
    size_t len = f->len;
    int n = lws_write(c->wsi, f->buf + LWS_PRE, len, LWS_WRITE_BINARY);
    sy_webi_frame_release(w, f); /* f may be gone from here: the render thread may have replaced it */
    return n < (int)len ? -1 : 0;
}

/* --delay-ms: the next due time of c's held messages and frames (0: none), as a timer. */
static void delay_timer(sy_web *w, web_conn *c)
{
    double next = 0;
    if (c->delayed_n) next = c->delayed[c->delayed_head].due;
    if (c->queued_n && (!next || c->queued[c->queued_head].due < next)) next = c->queued[c->queued_head].due;
    (void)w;
    if (next > 0) {
        double us = (next - sy_time_now() * 1e3) * 1e3;
        lws_set_timer_usecs(c->wsi, us < 1000 ? 1000 : (lws_usec_t)us);
    }
}

static int ws_writeable(sy_web *w, web_conn *c)
{
    if (!c->hello_sent) {
        c->hello_sent = true;
        if (ws_send_hello(w, c->wsi)) return -1;
        lws_callback_on_writable(c->wsi);
        return 0;
    }
    if (c->old_page) { /* once: the old page shows it in its heads-up line */
        if (c->refusal_sent) return 0;
        c->refusal_sent = true;
        char m[200];
        snprintf(m, sizeof m, "{\"t\":\"status\",\"error\":\"this page is older than the server (it reads frame format %u, "
                              "the server sends format %u): reload it\"}", c->old_version, SY_WEB_FRAME_VERSION);
        return ws_send_text(c->wsi, m) ? -1 : 0;
    }
    /* answers to this page's picks and tree requests first, then "the scene changed" */
    pthread_mutex_lock(&w->mu);
    web_reply *rep = NULL;
    for (web_reply **pp = &w->replies; *pp; pp = &(*pp)->next)
        if ((*pp)->conn == c->serial) {
            rep = *pp;
            *pp = rep->next;
            if (!*pp) w->replies_tail = pp;
            w->reply_count--;
            break;
        }
    bool scene = !rep && w->scene_version != c->sent_scene;
    uint64_t sv = w->scene_version;
    if (scene) c->sent_scene = sv;
    pthread_mutex_unlock(&w->mu);
    if (rep || scene) {
        char m[64];
        if (scene) snprintf(m, sizeof m, "{\"t\":\"scene\",\"v\":%llu}", (unsigned long long)sv);
        int e = ws_send_text(c->wsi, rep ? rep->text : m);
        if (rep) free(rep->text), free(rep);
        if (e) return -1;
        lws_callback_on_writable(c->wsi);
        return 0;
    }
    pthread_mutex_lock(&w->mu);
    web_frame *f = w->latest;
    bool fresh = f && f->seq != (w->d.delay_ms ? c->queued_seq : c->sent_seq);
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
    char clock[200] = "";
    if (!status[0] && w->clock_version != c->sent_clock) { /* the timeline's state (docs/WEB.md, "The timeline"), after a status */
        c->sent_clock = w->clock_version;
        snprintf(clock, sizeof clock, "{\"t\":\"clock\",\"time\":%.9g,\"start\":%.9g,\"end\":%.9g,\"playing\":%s,"
                 "\"loop\":%s,\"speed\":%.9g,\"clip\":%d}", w->clock.time, w->clock.start, w->clock.end,
                 w->clock.playing ? "true" : "false", w->clock.loop ? "true" : "false", w->clock.speed,
                 w->clip < w->clip_count ? (int)w->clip : -1);
    }
    char *views = status[0] || clock[0] ? NULL : sy_webi_views_json(w, &c->sent_views); /* the saved views, after those */
    /* a viewer's first frame has its display's shape (within 2 %): the page shows a frame over its
     * whole canvas, so a frame made for another display (the warm-up's, another viewer's) waits
     * for the one the render thread makes for this display */
    double shape = fresh && !c->framed && w->display_w && f->height
                       ? (double)f->width * w->display_h / ((double)f->height * w->display_w) : 1.0;
    if (shape > 1.02 || shape < 1.0 / 1.02) fresh = false, f->refs--; /* w->latest holds its own reference */
    pthread_mutex_unlock(&w->mu);
    if (fresh && !c->sized) sy_webi_frame_release(w, f), fresh = false;
    if (views) {
        if (fresh) sy_webi_frame_release(w, f);
        int e = ws_send_text(c->wsi, views);
        cJSON_free(views);
        if (e) return -1;
        lws_callback_on_writable(c->wsi);
        return 0;
    }
    if (clock[0]) {
        if (fresh) sy_webi_frame_release(w, f);
        if (ws_send_text(c->wsi, clock)) return -1;
        lws_callback_on_writable(c->wsi);
        return 0;
    }
    if (status[0]) {
        if (fresh) sy_webi_frame_release(w, f);
        if (ws_send_text(c->wsi, status)) return -1;
        lws_callback_on_writable(c->wsi);
        return 0;
    }
    if (w->d.delay_ms) { /* held for delay_ms, then sent in order (the newest WS_QUEUED) */
        double now = sy_time_now() * 1e3;
        if (fresh) {
            if (c->queued_n == WS_QUEUED) {
                sy_webi_frame_release(w, c->queued[c->queued_head].f);
                c->queued_head = (c->queued_head + 1) % WS_QUEUED, c->queued_n--;
            }
            queued_frame *q = &c->queued[(c->queued_head + c->queued_n++) % WS_QUEUED];
            q->f = f, q->due = now + w->d.delay_ms, q->answered = answered_by(c, f->gen);
            c->queued_seq = f->seq;
        }
        if (c->queued_n && c->queued[c->queued_head].due <= now) {
            queued_frame q = c->queued[c->queued_head];
            c->queued_head = (c->queued_head + 1) % WS_QUEUED, c->queued_n--;
            c->sent_seq = q.f->seq, c->framed = true;
            if (send_frame(w, c, q.f, q.answered)) return -1;
            if (c->queued_n) lws_callback_on_writable(c->wsi);
        }
        delay_timer(w, c);
        return 0;
    }
    if (!fresh) return 0;
    /* the input this frame answers: the client's newest one that reached the mailbox before it */
    c->sent_seq = f->seq, c->framed = true;
    return send_frame(w, c, f, answered_by(c, f->gen));
}

/* Frees the answers not sent yet of connection `serial` (from 1), or with serial 0 those of every
 * connection that closed after asking (the render thread answered a request queued before the
 * close), so they never fill the answers' queue; w->mu held. */
static void drop_replies_locked(sy_web *w, uint64_t serial)
{
    for (web_reply **rp = &w->replies; *rp;) {
        web_reply *y = *rp;
        const web_conn *c = w->conns;
        while (!serial && c && c->serial != y->conn) c = c->next;
        if (serial ? y->conn != serial : c != NULL) {
            rp = &y->next;
            continue;
        }
        *rp = y->next;
        free(y->text), free(y);
        w->reply_count--;
    }
    w->replies_tail = &w->replies;
    while (*w->replies_tail) w->replies_tail = &(*w->replies_tail)->next;
}

static void drop_orphan_replies(sy_web *w)
{
    pthread_mutex_lock(&w->mu);
    drop_replies_locked(w, 0);
    pthread_mutex_unlock(&w->mu);
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
        c->serial = ++w->conn_serial;
        lws_get_peer_simple(wsi, c->peer, sizeof c->peer);
        c->msg = malloc(w->d.max_message);
        if (!c->msg) return -1;
        c->next = w->conns;
        w->conns = c;
        pthread_mutex_lock(&w->mu);
        c->sent_scene = w->scene_version;
        w->clients++;
        w->view_version++; /* a new viewer gets a frame even when the view rests */
        pthread_cond_signal(&w->cv);
        pthread_mutex_unlock(&w->mu);
        sy_log(SY_LOG_NOTE, "web", c->peer, "viewer connected");
        size_from_url(w, c, wsi);
        lws_callback_on_writable(wsi);
        return 0;
    case LWS_CALLBACK_CLOSED:
        for (web_conn **pp = &w->conns; *pp; pp = &(*pp)->next)
            if (*pp == c) {
                *pp = c->next;
                pthread_mutex_lock(&w->mu);
                w->clients--;
                drop_replies_locked(w, c->serial); /* its answers go with it (actions still queued answer nobody) */
                set_kind(w, c, 0);
                set_plain(w, c, false);
                if (w->lead_conn == c->serial && (w->lead[0] != 0.0f || w->lead[1] != 0.0f)) {
                    w->lead[0] = w->lead[1] = 0.0f; /* its page cannot say its hand rests: the exact view again */
                    w->view_version++;
                    pthread_cond_signal(&w->cv);
                }
                pthread_mutex_unlock(&w->mu);
                video_summary(c, "");
                sy_log(SY_LOG_NOTE, "web", c->peer, "viewer left");
                sy_web_video_encoder_destroy(c->enc);
                c->enc = NULL;
                w->video_reserved -= c->reserved, c->reserved = 0;
                break;
            }
        free(c->msg);
        c->msg = NULL;
        for (; c->delayed_n; c->delayed_n--, c->delayed_head = (c->delayed_head + 1) % WS_DELAYED)
            free(c->delayed[c->delayed_head].text);
        for (; c->queued_n; c->queued_n--, c->queued_head = (c->queued_head + 1) % WS_QUEUED)
            sy_webi_frame_release(w, c->queued[c->queued_head].f);
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
            else if (w->d.delay_ms) delay_message(w, c);
            else ws_message(w, c, c->msg, c->msg_len);
            c->msg_len = 0;
        }
        return 0;
    }
    case LWS_CALLBACK_SERVER_WRITEABLE: return ws_writeable(w, c);
    case LWS_CALLBACK_TIMER: /* --delay-ms: held messages and frames that are due */
        for (double now = sy_time_now() * 1e3; c->delayed_n && c->delayed[c->delayed_head].due <= now;) {
            delayed_msg *d = &c->delayed[c->delayed_head];
            ws_message(w, c, d->text, d->len);
            free(d->text);
            d->text = NULL;
            c->delayed_head = (c->delayed_head + 1) % WS_DELAYED, c->delayed_n--;
        }
        if (c->queued_n) lws_callback_on_writable(wsi);
        delay_timer(w, c);
        return 0;
    case LWS_CALLBACK_EVENT_WAIT_CANCELLED: /* a new frame, status or answer: every viewer that can take it */
        if (w) {
            drop_orphan_replies(w);
            lws_callback_on_writable_all_protocol(ctx, &sy_webi_protocols[1]);
        }
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
