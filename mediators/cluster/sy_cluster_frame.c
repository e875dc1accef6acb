/* sy_cluster_frame.c — the cluster modes and one frame of the client (sy_cluster_client_render):
 * change lists per connection (a new one = snapshot), work items per mode (strips, balanced
 * strips, sample ranges, wall tiles, eyes), rounds run in parallel with one thread per server and
 * failed work reassigned to the survivors, the blobs a server asks for, the cooperative merge and
 * the multi-display swap barrier. */
#include "sy_cluster_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ---- modes ---- */
static const char *mode_names[] = {"sort-first", "balanced", "cooperative", "multi-display", "stereo", "frames"};

bool sy_cluster_mode_parse(const char *name, uint32_t *out)
{
    for (uint32_t i = 0; i < 6; ++i)
        if (!strcmp(name, mode_names[i])) {
            *out = i;
            return true;
        }
    return false;
}

const char *sy_cluster_mode_name(uint32_t mode)
{
    return mode < 6 ? mode_names[mode] : "?";
}

/* ---- per-frame work ---- */
typedef struct work_item {
    uint32_t eye; /* index into the frame's views: 0 mono / left, 1 right */
    sy_cluster_rect rect;
    uint32_t sample_first, sample_count;
    int owner;
    bool done;
} work_item;

typedef struct frame_ctx {
    sy_cluster_client *c;
    const sy_cluster_frame *f;
    sy_camera_view views[2];
    uint32_t eye_ids[2];
    sy_layer *out;
    sy_layer *accum; /* cooperative: one full layer per connection */
    uint64_t *accum_samples;
    work_item *items;
    uint32_t item_count;
    uint32_t first_items; /* items of the first round (later ones reassign failed work) */
    double *server_seconds;
    /* cooperative pipelining */
    bool pipeline;        /* requests of the next frame may be sent ahead */
    uint32_t coop_span;   /* the frame's sample indices: the next frame's ranges are these + span */
    bool *ahead_hit;      /* per connection: its request sent ahead is this frame's (its answer is used) */
    bool *single;         /* per connection: exactly one item of the first round */
} frame_ctx;

typedef struct thread_arg {
    frame_ctx *fc;
    uint32_t conn;
    bool send_scene;
    bool failed;
} thread_arg;

/* Change lists name every blob by hash only; the blob is kept to answer the server's request.
 * (The store only retains the immutable blob: the cast drops the const of the borrowed pointer.) */
static bool blob_send_cb(void *user, const sy_blob *b)
{
    conn *k = user;
    sy_error e = {0};
    if (sy_blob_store_put(k->offered, (sy_blob *)b, &e) != SY_OK) k->offer_failed = true;
    return false;
}

/* The RENDER of work item it for server idx (conn k) in this frame (m's pointers borrow it and f). */
static void make_render(const frame_ctx *fc, const conn *k, uint32_t idx, const work_item *it, sy_cluster_msg *m)
{
    const sy_cluster_client *c = fc->c;
    const sy_cluster_frame *f = fc->f;
    memset(m, 0, sizeof *m);
    m->header.type = SY_CLUSTER_RENDER;
    __typeof__(m->u.render) *q = &m->u.render;
    q->frame = c->frame;
    q->job = (uint32_t)(it - fc->items);
    q->flags = (f->depth ? SY_CLUSTER_RENDER_DEPTH : 0) | (f->mode == SY_CLUSTER_MULTI_DISPLAY ? SY_CLUSTER_RENDER_PRESENT : 0) |
               (f->half ? SY_CLUSTER_RENDER_HALF : 0) | (f->restart ? SY_CLUSTER_RENDER_RESTART : 0);
    sy_clu_copy_str(q->backend, sizeof q->backend, k->backend[0] ? k->backend : f->backend);
    sy_clu_copy_str(q->params, sizeof q->params, f->params ? f->params : "");
    q->root_id = f->root_id;
    q->background_id = f->background_id;
    q->seed = f->seed;
    /* cooperative: a back-end that numbers samples by its own accumulation (and ignores
     * sample_first) still draws an independent stream per server when each server has its own
     * seed; the seed stays the same across frames, so the server keeps accumulating */
    if (f->mode == SY_CLUSTER_COOPERATIVE) q->seed = f->seed + idx * 2654435761u;
    q->eye = fc->eye_ids[it->eye];
    q->sample_first = it->sample_first;
    q->sample_count = it->sample_count;
    q->full_width = f->width;
    q->full_height = f->height;
    q->camera = fc->views[it->eye];
    q->tile_count = 1;
    q->tiles = (sy_cluster_rect *)&it->rect;
}

/* Cooperative pipelining: whether k's RENDER m is the one of its last frame, the frame before (frame
 * and sample_first aside: a frame asked again); records m as k's last either way. */
static bool steady_request(const sy_cluster_client *c, conn *k, const sy_cluster_msg *m)
{
    sy_cluster_msg n = *m;
    n.u.render.frame = 0;
    n.u.render.sample_first = 0;
    sy_cluster_buf b = {0}, old = k->last_req;
    sy_error e = {0};
    bool ok = sy_cluster_encode(&n, 0, &b, &e) == SY_OK;
    bool same = ok && old.size && k->last_req_frame + 1 == c->frame && b.size == old.size && !memcmp(b.data, old.data, b.size);
    if (!ok) sy_cluster_buf_free(&b);
    k->last_req = b;
    k->last_req_frame = c->frame;
    sy_cluster_buf_free(&old);
    return same;
}

/* Runs one item on k: its RENDER (or the answer to the same request sent ahead), checks the answer,
 * and decodes it. Cooperative, when k asked the same in the frame before (no SCENE, no RESTART):
 * the next frame's RENDER goes to k right after this frame's, before this answer is in, so k has
 * it queued when it finishes this round and renders it while the client decodes and merges (a
 * failure to send it is left in *ahead_err: this answer still counts, the connection is dropped
 * after). */
static sy_result run_item(frame_ctx *fc, conn *k, uint32_t idx, work_item *it, sy_error *ahead_err, sy_error *err)
{
    sy_cluster_client *c = fc->c;
    const sy_cluster_frame *f = fc->f;
    sy_cluster_msg m, rep;
    make_render(fc, k, idx, it, &m);
    const __typeof__(m.u.render) *q = &m.u.render;
    bool first_round = (uint32_t)(it - fc->items) < fc->first_items;
    /* not after a SCENE or a RESTART (a caller that sends either every frame would only ever drop
     * what was sent ahead) */
    bool ahead = first_round && f->mode == SY_CLUSTER_COOPERATIVE && fc->single && fc->single[idx] &&
                 steady_request(c, k, &m) && fc->pipeline && !k->scene_msg.size && !(q->flags & SY_CLUSTER_RENDER_RESTART);
    uint8_t *raw = NULL;
    sy_result r = SY_OK;
    if (first_round && fc->ahead_hit && fc->ahead_hit[idx] && k->ahead.size) {
        k->ahead.size = 0; /* sent during the last frame: its answer is this frame's */
        k->ahead_used++;
    } else {
        r = sy_clu_conn_request(c, k, &m, err); /* drops a stale answer first */
    }
    if (r == SY_OK && ahead) {
        sy_cluster_msg n = m;
        n.u.render.frame = c->frame + 1;
        n.u.render.sample_first = it->sample_first + fc->coop_span;
        k->ahead.size = 0;
        sy_result ra = sy_cluster_encode(&n, 0, &k->ahead, ahead_err);
        if (ra == SY_OK) ra = sy_clu_conn_send_ahead(c, k, c->frame + 1, n.u.render.job, ahead_err);
        if (ra != SY_OK) k->ahead.size = 0;
    }
    if (r == SY_OK) r = sy_clu_conn_recv(c, k, SY_CLUSTER_TILES, &rep, &raw, err);
    if (r) return r;
    const __typeof__(rep.u.tiles) *t = &rep.u.tiles;
    uint32_t expect_tiles = f->mode == SY_CLUSTER_MULTI_DISPLAY ? 0 : 1;
    if (t->frame != c->frame || t->job != q->job || t->tile_count != expect_tiles)
        r = sy_error_set(err, SY_ERR_PROTOCOL, "%s: reply for frame %llu job %u with %u tiles does not match the request",
                         k->url, (unsigned long long)t->frame, t->job, t->tile_count);
    if (!r && expect_tiles && memcmp(&t->tiles[0].rect, &it->rect, sizeof it->rect) != 0)
        r = sy_error_set(err, SY_ERR_PROTOCOL, "%s: tile rectangle differs from the request", k->url);
    if (!r && expect_tiles) {
        const sy_cluster_tile *tl = &t->tiles[0];
        if (f->mode == SY_CLUSTER_COOPERATIVE) {
            r = sy_cluster_tile_decode(tl, &fc->accum[idx], tl->rect.x, tl->rect.y, err);
            if (!r) fc->accum_samples[idx] = t->samples;
        } else {
            uint32_t ox = it->eye * f->width;
            r = sy_cluster_tile_decode(tl, fc->out, tl->rect.x + ox, tl->rect.y, err);
        }
    }
    if (!r) {
        fc->server_seconds[idx] += t->sync_seconds + t->render_seconds;
        k->last_seconds = t->render_seconds;
        k->last_rows = it->rect.h;
    }
    sy_cluster_msg_free(&rep);
    free(raw);
    return r;
}

/* Sends the frame's SCENE; while the server answers BLOB_REQUEST, sends the blobs it names (BLOBS
 * messages of at most a quarter of the message limit each, at least one blob) until SCENE_ACK. */
sy_result sy_clu_send_scene(sy_cluster_client *c, conn *k, sy_error *err)
{
    sy_cluster_msg rep;
    uint8_t *raw = NULL;
    sy_result r = sy_clu_conn_call(c, k, NULL, &k->scene_msg, SY_CLUSTER_SCENE_ACK, &rep, &raw, err);
    for (uint32_t rounds = 0; r == SY_OK && rep.header.type == SY_CLUSTER_BLOB_REQUEST; ++rounds) {
        const __typeof__(rep.u.blobs) *q = &rep.u.blobs;
        sy_cluster_blob_ref *refs = calloc(q->count, sizeof *refs);
        sy_cluster_msg m;
        memset(&m, 0, sizeof m);
        m.header.type = SY_CLUSTER_BLOBS;
        m.u.blobs.frame = c->frame;
        m.u.blobs.blobs = refs;
        /* BLOBS messages of at most SY_CLUSTER_BLOBS_BATCH (or half the server's message limit), at
         * least one blob; the transport splits each into frames the server accepts */
        uint64_t bytes = 0, budget = k->srv_max_message / 2 < SY_CLUSTER_BLOBS_BATCH ? k->srv_max_message / 2
                                                                                    : SY_CLUSTER_BLOBS_BATCH;
        if (!refs) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "cluster: out of memory");
        else if (q->frame != c->frame || rounds > SY_CLUSTER_MAX_BLOBS)
            r = sy_error_set(err, SY_ERR_PROTOCOL, "%s: blob request for frame %llu during frame %llu", k->url,
                             (unsigned long long)q->frame, (unsigned long long)c->frame);
        for (uint32_t i = 0; r == SY_OK && i < q->count; ++i) {
            const sy_blob *b = k->offered ? sy_blob_store_get(k->offered, q->blobs[i].hash) : NULL;
            if (!b || sy_blob_size(b) != q->blobs[i].size) {
                r = sy_error_set(err, SY_ERR_PROTOCOL, "%s: server asked for blob %016llx%016llx, which the scene does not name",
                                 k->url, (unsigned long long)q->blobs[i].hash.hi, (unsigned long long)q->blobs[i].hash.lo);
                break;
            }
            if (m.u.blobs.count && bytes + sy_blob_size(b) > budget) break; /* the rest in the next BLOBS */
            refs[m.u.blobs.count++] = (sy_cluster_blob_ref){q->blobs[i].hash, sy_blob_size(b), sy_blob_data(b)};
            bytes += sy_blob_size(b);
        }
        sy_cluster_msg_free(&rep);
        free(raw);
        raw = NULL;
        if (r == SY_OK) {
            uint64_t before = k->bytes_sent;
            r = sy_clu_conn_call(c, k, &m, NULL, SY_CLUSTER_SCENE_ACK, &rep, &raw, err);
            k->blob_frames_bytes += k->bytes_sent - before;
            k->blob_payload_bytes += bytes;
        }
        free(refs);
    }
    if (r == SY_OK) {
        sy_cluster_msg_free(&rep);
        free(raw);
    }
    return r;
}

static void *conn_thread(void *p)
{
    thread_arg *a = p;
    frame_ctx *fc = a->fc;
    sy_cluster_client *c = fc->c;
    conn *k = &c->conns[a->conn];
    sy_error err = {0}, ahead_err = {0};
    sy_result r = SY_OK;
    if (a->send_scene && k->scene_msg.size) r = sy_clu_send_scene(c, k, &err); /* drops a stale answer first */
    for (uint32_t i = 0; r == SY_OK && i < fc->item_count; ++i) {
        work_item *it = &fc->items[i];
        if (it->owner != (int)a->conn || it->done) continue;
        r = run_item(fc, k, a->conn, it, &ahead_err, &err);
        if (r == SY_OK) it->done = true;
    }
    if (r == SY_OK && ahead_err.code) r = ahead_err.code, err = ahead_err; /* its answers count; dropped after */
    if (r) {
        a->failed = true;
        sy_clu_copy_str(k->error, sizeof k->error, err.message);
    }
    return NULL;
}

/* Runs every live connection's items in parallel; returns the number of connections that failed. */
static uint32_t run_round(frame_ctx *fc, bool send_scene)
{
    sy_cluster_client *c = fc->c;
    thread_arg args[SY_CLUSTER_MAX_SERVERS];
    pthread_t th[SY_CLUSTER_MAX_SERVERS];
    bool started[SY_CLUSTER_MAX_SERVERS] = {0};
    for (uint32_t i = 0; i < c->n; ++i) {
        args[i] = (thread_arg){fc, i, send_scene, false};
        if (!c->conns[i].live) continue;
        bool has_work = send_scene && c->conns[i].scene_msg.size;
        for (uint32_t j = 0; j < fc->item_count && !has_work; ++j)
            has_work = fc->items[j].owner == (int)i && !fc->items[j].done;
        if (!has_work) continue;
        started[i] = pthread_create(&th[i], NULL, conn_thread, &args[i]) == 0;
        if (!started[i]) conn_thread(&args[i]);
    }
    uint32_t failed = 0;
    for (uint32_t i = 0; i < c->n; ++i) {
        if (started[i]) pthread_join(th[i], NULL);
        if (args[i].failed) {
            sy_clu_conn_drop(c, &c->conns[i], "dropped for this frame", c->conns[i].error);
            failed++;
        }
    }
    return failed;
}

/* Gives every unfinished item to live connections (splitting strips among them). */
static sy_result reassign(frame_ctx *fc, uint32_t *reassigned, sy_error *err)
{
    sy_cluster_client *c = fc->c;
    uint32_t live[SY_CLUSTER_MAX_SERVERS], nl = 0;
    for (uint32_t i = 0; i < c->n; ++i)
        if (c->conns[i].live) live[nl++] = i;
    uint32_t pending = 0;
    for (uint32_t j = 0; j < fc->item_count; ++j) pending += !fc->items[j].done;
    if (!pending) return SY_OK;
    if (!nl) {
        char why[SY_ERROR_MESSAGE_MAX] = "";
        for (uint32_t i = 0; i < c->n; ++i)
            if (c->conns[i].error[0]) {
                sy_clu_copy_str(why, sizeof why, c->conns[i].error);
                break;
            }
        return sy_error_set(err, SY_ERR_IO, "cluster: every server failed this frame (%s)", why);
    }
    if (fc->f->mode == SY_CLUSTER_MULTI_DISPLAY) {
        /* a wall tile belongs to its display: it cannot be shown elsewhere */
        for (uint32_t j = 0; j < fc->item_count; ++j) fc->items[j].done = true;
        return SY_OK;
    }
    uint32_t cur = fc->item_count;
    work_item *items = realloc(fc->items, (cur + (size_t)pending * nl) * sizeof *items);
    if (!items) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "cluster: out of memory");
    fc->items = items;
    uint32_t rr = 0;
    for (uint32_t j = 0; j < cur; ++j) {
        work_item it = fc->items[j];
        if (it.done) continue;
        fc->items[j].done = true; /* replaced by the new items */
        (*reassigned)++;
        if (fc->f->mode == SY_CLUSTER_COOPERATIVE || it.rect.h < nl) {
            it.owner = (int)live[rr++ % nl];
            fc->items[fc->item_count++] = it;
            continue;
        }
        for (uint32_t s = 0; s < nl; ++s) {
            work_item sub = it;
            uint32_t y0 = it.rect.y + (uint32_t)((uint64_t)it.rect.h * s / nl);
            uint32_t y1 = it.rect.y + (uint32_t)((uint64_t)it.rect.h * (s + 1) / nl);
            sub.rect.y = y0;
            sub.rect.h = y1 - y0;
            sub.owner = (int)live[s];
            fc->items[fc->item_count++] = sub;
        }
    }
    return SY_OK;
}

/* Splits items larger than a request may be (SY_CLUSTER_MAX_REQUEST_PIXELS) into row bands for
 * the same server. Multi-display tiles are presented whole and are never split. */
static sy_result split_large_items(frame_ctx *fc, sy_error *err)
{
    uint32_t extra = 0;
    for (uint32_t j = 0; j < fc->item_count; ++j) {
        uint64_t px = (uint64_t)fc->items[j].rect.w * fc->items[j].rect.h;
        extra += (uint32_t)((px + SY_CLUSTER_MAX_REQUEST_PIXELS - 1) / SY_CLUSTER_MAX_REQUEST_PIXELS) - 1;
    }
    if (!extra) return SY_OK;
    work_item *items = realloc(fc->items, ((size_t)fc->item_count + extra) * sizeof *items);
    if (!items) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "cluster: out of memory");
    fc->items = items;
    uint32_t n = fc->item_count;
    for (uint32_t j = 0; j < n; ++j) {
        work_item it = fc->items[j];
        uint32_t rows = SY_CLUSTER_MAX_REQUEST_PIXELS / it.rect.w; /* w <= 16384, so rows >= 4096 */
        if ((uint64_t)it.rect.w * it.rect.h <= SY_CLUSTER_MAX_REQUEST_PIXELS) continue;
        fc->items[j].rect.h = rows;
        for (uint32_t y = rows; y < it.rect.h; y += rows) {
            work_item band = it;
            band.rect.y = it.rect.y + y;
            band.rect.h = it.rect.h - y < rows ? it.rect.h - y : rows;
            fc->items[fc->item_count++] = band;
        }
    }
    return SY_OK;
}

/* Splits rows [0, h) into n strips with the given weights (each at least one row when h >= n). */
static void split_rows(uint32_t h, uint32_t n, const double *w, uint32_t *starts)
{
    double total = 0;
    for (uint32_t i = 0; i < n; ++i) total += w[i];
    double acc = 0;
    starts[0] = 0;
    for (uint32_t i = 1; i < n; ++i) {
        acc += w[i - 1];
        uint32_t y = (uint32_t)llround((double)h * acc / total);
        if (y < starts[i - 1] + (h >= n ? 1 : 0)) y = starts[i - 1] + (h >= n ? 1 : 0);
        if (h >= n && y > h - (n - i)) y = h - (n - i);
        if (y > h) y = h;
        starts[i] = y;
    }
    starts[n] = h;
}

/* Steps 1 and 2 of a frame (sy_clu_sync_servers in sy_cluster_internal.h). */
sy_result sy_clu_sync_servers(sy_cluster_client *c, uint64_t *scene_bytes, sy_error *err)
{
    /* 1. reconnect servers that are down (they will get a snapshot) */
    for (uint32_t i = 0; i < c->n; ++i) {
        conn *k = &c->conns[i];
        k->fresh = false;
        if (!k->live) {
            sy_error e = {0};
            if (sy_clu_conn_connect(c, k, &e) == SY_OK) CLOG(c, "%s: (re)connected, sending a snapshot", k->url);
            else sy_clu_copy_str(k->error, sizeof k->error, e.message);
        }
    }
    /* 2. change lists: every live connection pulls from its own consumer (a new one = snapshot) */
    sy_result r = SY_OK;
    for (uint32_t i = 0; i < c->n && r == SY_OK; ++i) {
        conn *k = &c->conns[i];
        k->scene_msg.size = 0;
        if (!k->live) continue;
        bool snapshot = false;
        if (!k->has_consumer) {
            r = sy_scene_consumer_add(c->scene, &k->consumer, err);
            if (r) break;
            k->has_consumer = true;
            snapshot = true;
        }
        sy_changes *ch = NULL;
        r = sy_scene_consumer_pull(c->scene, k->consumer, &ch, err);
        if (r) break;
        snapshot = snapshot || sy_changes_is_snapshot(ch);
        sy_blob_store_destroy(k->offered);
        k->offered = NULL;
        k->offer_failed = false;
        if (snapshot || sy_changes_count(ch) > 0) {
            void *data = NULL;
            size_t size = 0;
            r = sy_blob_store_create(&k->offered, err);
            if (r == SY_OK) r = sy_changes_serialize(ch, blob_send_cb, k, &data, &size, err);
            if (r == SY_OK && k->offer_failed) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "cluster: out of memory");
            if (r == SY_OK && size > UINT32_MAX - 1024)
                r = sy_error_set(err, SY_ERR_LIMIT, "cluster: change list of %zu bytes is too large", size);
            if (r == SY_OK) {
                sy_cluster_msg m;
                memset(&m, 0, sizeof m);
                m.header.type = SY_CLUSTER_SCENE;
                m.u.scene.frame = c->frame;
                m.u.scene.flags = snapshot ? SY_CLUSTER_SCENE_SNAPSHOT : 0;
                m.u.scene.changes = data;
                m.u.scene.changes_size = (uint32_t)size;
                k->scene_msg.size = 0;
                r = sy_cluster_encode(&m, 0, &k->scene_msg, err); /* tagged frame by frame when sent */
                *scene_bytes += k->scene_msg.size;
            }
            free(data);
        }
        sy_changes_release(ch);
    }
    return r;
}

/* Cooperative pipelining, before the rounds: which servers' requests sent ahead are this frame's
 * (byte for byte: the answer is used); when one is not (the frame asks otherwise: view, samples,
 * parameters, servers), this frame's sample ranges start past those the stale requests took, so
 * ranges never repeat on a server that kept the stale samples (same view), and every request sent
 * ahead is dropped. Marks the servers with exactly one item (only they send ahead). */
static sy_result coop_pipeline_plan(frame_ctx *fc, sy_error *err)
{
    sy_cluster_client *c = fc->c;
    fc->ahead_hit = calloc(c->n, sizeof *fc->ahead_hit);
    fc->single = calloc(c->n, sizeof *fc->single);
    if (!fc->ahead_hit || !fc->single) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "cluster: out of memory");
    uint32_t items[SY_CLUSTER_MAX_SERVERS] = {0};
    uint32_t first = UINT32_MAX, end = 0;
    for (uint32_t j = 0; j < fc->item_count; ++j) {
        const work_item *it = &fc->items[j];
        items[it->owner]++;
        if (it->sample_first < first) first = it->sample_first;
        if (it->sample_first + it->sample_count > end) end = it->sample_first + it->sample_count;
    }
    fc->coop_span = first < end ? end - first : 0;
    bool any = false, all = true;
    for (uint32_t i = 0; i < c->n; ++i) {
        fc->single[i] = items[i] == 1;
        any = any || c->conns[i].ahead.size;
    }
    fc->pipeline = !c->o.no_pipeline;
    if (!any) return SY_OK;
    sy_cluster_buf b = {0};
    for (uint32_t j = 0; j < fc->item_count && all; ++j) {
        const work_item *it = &fc->items[j];
        conn *k = &c->conns[it->owner];
        if (!k->ahead.size || !fc->single[it->owner]) continue;
        sy_cluster_msg m;
        make_render(fc, k, (uint32_t)it->owner, it, &m);
        b.size = 0;
        sy_result r = sy_cluster_encode(&m, 0, &b, err);
        if (r) {
            sy_cluster_buf_free(&b);
            return r;
        }
        /* a SCENE goes first (the stale answer is dropped before it): not this frame's */
        fc->ahead_hit[it->owner] = !k->scene_msg.size && b.size == k->ahead.size && !memcmp(b.data, k->ahead.data, b.size);
    }
    sy_cluster_buf_free(&b);
    for (uint32_t i = 0; i < c->n; ++i) all = all && (!c->conns[i].ahead.size || fc->ahead_hit[i]);
    if (all) return SY_OK;
    memset(fc->ahead_hit, 0, c->n * sizeof *fc->ahead_hit); /* every answer sent ahead is stale */
    if (c->coop_ahead_end > first && fc->coop_span) {
        uint32_t shift = c->coop_ahead_end - first;
        if (end > UINT32_MAX - SY_CLUSTER_MAX_SAMPLES - shift)
            return sy_error_set(err, SY_ERR_LIMIT, "cluster: the cooperative sample index would overflow");
        for (uint32_t j = 0; j < fc->item_count; ++j) fc->items[j].sample_first += shift;
        c->coop_next = end + shift;
    }
    return SY_OK;
}

sy_result sy_cluster_client_render(sy_cluster_client *c, const sy_cluster_frame *f, sy_layer *out,
                                   sy_cluster_frame_stats *stats, sy_error *err)
{
    double t0 = sy_time_now();
    sy_cluster_frame_stats st;
    memset(&st, 0, sizeof st);
    if (f->mode == SY_CLUSTER_FRAMES)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cluster render: frames mode renders sequences "
                            "(sy_cluster_client_render_frames)");
    if (f->mode > SY_CLUSTER_STEREO || !f->backend || f->width < 1 || f->height < 1 ||
        f->width > SY_CLUSTER_MAX_IMAGE || f->height > SY_CLUSTER_MAX_IMAGE)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cluster render: bad mode, back-end or image size");
    uint32_t out_w = f->mode == SY_CLUSTER_STEREO ? 2 * f->width : f->width;
    if (f->mode != SY_CLUSTER_MULTI_DISPLAY && (!out || out->width != out_w || out->height != f->height))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cluster render: output layer must be %ux%u", out_w, f->height);
    sy_result cr = sy_cluster_camera_check(&f->camera, err); /* refused here, before any server is involved */
    if (cr != SY_OK) {
        sy_error_prefix(err, "cluster render");
        return cr;
    }
    c->frame++;
    uint64_t sent0 = 0, recv0 = 0;
    uint64_t blobf0 = 0, blobp0 = 0, used0 = 0, dropped0 = 0;
    for (uint32_t i = 0; i < c->n; ++i) {
        sent0 += c->conns[i].bytes_sent, recv0 += c->conns[i].bytes_received;
        blobf0 += c->conns[i].blob_frames_bytes, blobp0 += c->conns[i].blob_payload_bytes;
        used0 += c->conns[i].ahead_used, dropped0 += c->conns[i].ahead_dropped;
    }
    sy_result r = sy_clu_sync_servers(c, &st.scene_bytes, err);
    if (r) return r;
    /* 3. work items */
    uint32_t live[SY_CLUSTER_MAX_SERVERS], nl = 0;
    for (uint32_t i = 0; i < c->n; ++i)
        if (c->conns[i].live) live[nl++] = i;
    if (!nl) return sy_error_set(err, SY_ERR_IO, "cluster: no server is reachable (%s)", c->conns[0].error);
    frame_ctx fc = {.c = c, .f = f, .out = out};
    fc.views[0] = f->camera;
    fc.eye_ids[0] = SY_EYE_MONO;
    if (f->mode == SY_CLUSTER_STEREO) {
        float sep = f->eye_separation > 0 ? f->eye_separation : 0.065f, zp = f->zero_parallax > 0 ? f->zero_parallax : 2.0f;
        fc.views[0] = sy_camera_view_eye(&f->camera, SY_EYE_LEFT, sep, zp);
        fc.views[1] = sy_camera_view_eye(&f->camera, SY_EYE_RIGHT, sep, zp);
        fc.eye_ids[0] = SY_EYE_LEFT;
        fc.eye_ids[1] = SY_EYE_RIGHT;
    }
    fc.items = calloc((size_t)nl * 2 + 2, sizeof *fc.items);
    fc.server_seconds = calloc(c->n, sizeof *fc.server_seconds);
    if (f->mode == SY_CLUSTER_COOPERATIVE) {
        fc.accum = calloc(c->n, sizeof *fc.accum);
        fc.accum_samples = calloc(c->n, sizeof *fc.accum_samples);
    }
    if (!fc.items || !fc.server_seconds || (f->mode == SY_CLUSTER_COOPERATIVE && (!fc.accum || !fc.accum_samples)))
        r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "cluster: out of memory");
    uint32_t spp = f->samples ? f->samples : (f->mode == SY_CLUSTER_COOPERATIVE ? 16 : 0);
    if (r == SY_OK) {
        if (f->mode == SY_CLUSTER_COOPERATIVE) {
            /* samples_total: split across the live servers (the first ones take one more); else spp each */
            uint64_t total = f->samples_total ? f->samples_total : (uint64_t)nl * spp, first = c->coop_next;
            for (uint32_t s = 0; s < nl && r == SY_OK; ++s) {
                uint32_t mine = f->samples_total ? (uint32_t)(total / nl + (s < total % nl)) : spp;
                if (!mine) continue; /* fewer samples than servers */
                r = sy_layer_create(f->width, f->height, &fc.accum[live[s]], err);
                fc.items[fc.item_count++] =
                    (work_item){0, {0, 0, f->width, f->height}, (uint32_t)first, mine, (int)live[s], false};
                first += mine;
            }
            if (first > UINT32_MAX - SY_CLUSTER_MAX_SAMPLES)
                r = sy_error_set(err, SY_ERR_LIMIT, "cluster: the cooperative sample index would overflow");
            c->coop_next = (uint32_t)first;
        } else if (f->mode == SY_CLUSTER_STEREO) {
            uint32_t groups = nl >= 2 ? 2 : 1;
            for (uint32_t eye = 0; eye < 2; ++eye) {
                uint32_t members[SY_CLUSTER_MAX_SERVERS], nm = 0;
                for (uint32_t s = 0; s < nl; ++s)
                    if (groups == 1 || s % 2 == eye) members[nm++] = live[s];
                double w[SY_CLUSTER_MAX_SERVERS];
                uint32_t starts[SY_CLUSTER_MAX_SERVERS + 1];
                for (uint32_t s = 0; s < nm; ++s) w[s] = 1;
                uint32_t parts = nm < f->height ? nm : f->height;
                split_rows(f->height, parts, w, starts);
                for (uint32_t s = 0; s < parts; ++s)
                    fc.items[fc.item_count++] =
                        (work_item){eye, {0, starts[s], f->width, starts[s + 1] - starts[s]}, 0, spp, (int)members[s], false};
            }
        } else if (f->mode == SY_CLUSTER_MULTI_DISPLAY) {
            /* a wall: server i owns its configured tile, else column i of n */
            for (uint32_t i = 0; i < c->n && r == SY_OK; ++i) {
                uint32_t x0 = (uint32_t)((uint64_t)f->width * i / c->n), x1 = (uint32_t)((uint64_t)f->width * (i + 1) / c->n);
                sy_cluster_rect t = {x0, 0, x1 - x0, f->height}, wt = c->conns[i].wall;
                if (wt.w) {
                    if (wt.h == 0 || wt.x >= f->width || wt.y >= f->height || wt.w > f->width - wt.x ||
                        wt.h > f->height - wt.y)
                        r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                                         "cluster: wall tile %ux%u at %u,%u of %s lies outside the %ux%u wall", wt.w, wt.h,
                                         wt.x, wt.y, c->conns[i].url, f->width, f->height);
                    t = wt;
                }
                if (r == SY_OK && t.w > 0 && c->conns[i].live)
                    fc.items[fc.item_count++] = (work_item){0, t, 0, spp, (int)i, false};
            }
        } else {
            double w[SY_CLUSTER_MAX_SERVERS];
            uint32_t starts[SY_CLUSTER_MAX_SERVERS + 1];
            for (uint32_t s = 0; s < nl; ++s) {
                conn *k = &c->conns[live[s]];
                w[s] = 1.0;
                if (f->mode == SY_CLUSTER_BALANCED && k->last_seconds > 0 && k->last_rows > 0)
                    w[s] = (double)k->last_rows / k->last_seconds; /* rows per second */
            }
            if (f->mode == SY_CLUSTER_BALANCED) {
                bool all = true;
                for (uint32_t s = 0; s < nl; ++s) all = all && c->conns[live[s]].last_seconds > 0;
                if (!all)
                    for (uint32_t s = 0; s < nl; ++s) w[s] = 1.0;
            }
            uint32_t parts = nl < f->height ? nl : f->height;
            split_rows(f->height, parts, w, starts);
            for (uint32_t s = 0; s < parts; ++s)
                if (starts[s + 1] > starts[s])
                    fc.items[fc.item_count++] =
                        (work_item){0, {0, starts[s], f->width, starts[s + 1] - starts[s]}, 0, spp, (int)live[s], false};
        }
    }
    if (r == SY_OK && f->mode != SY_CLUSTER_MULTI_DISPLAY) r = split_large_items(&fc, err);
    fc.first_items = fc.item_count;
    if (r == SY_OK && f->mode == SY_CLUSTER_COOPERATIVE) r = coop_pipeline_plan(&fc, err);
    /* 4. rounds: scene + work, then failed work to the survivors, until done */
    bool first = true;
    for (uint32_t round = 0; r == SY_OK && round <= c->n; ++round) {
        st.servers_failed += run_round(&fc, first);
        first = false;
        r = reassign(&fc, &st.reassigned, err);
        bool left = false;
        for (uint32_t j = 0; j < fc.item_count; ++j) left = left || !fc.items[j].done;
        if (!left) break;
        if (round == c->n) r = sy_error_set(err, SY_ERR_IO, "cluster: work left after %u rounds", round + 1);
    }
    /* 5. cooperative: merge the accumulations weighted by their sample counts */
    if (r == SY_OK && f->mode == SY_CLUSTER_COOPERATIVE) {
        uint64_t total = 0;
        for (uint32_t i = 0; i < c->n; ++i)
            if (fc.accum[i].rgba && fc.accum_samples[i]) total += fc.accum_samples[i];
        if (!total) r = sy_error_set(err, SY_ERR_IO, "cluster: no server returned samples");
        size_t px = (size_t)f->width * f->height;
        for (size_t p = 0; r == SY_OK && p < px; ++p) {
            /* depth as a local render keeps it: the mean over the samples that hit (each server's
             * mean weighted by its samples times its coverage, alpha), +INFINITY where none hit */
            double acc[4] = {0, 0, 0, 0}, dsum = 0, dwgt = 0;
            for (uint32_t i = 0; i < c->n; ++i) {
                if (!fc.accum[i].rgba || !fc.accum_samples[i]) continue;
                double wgt = (double)fc.accum_samples[i];
                for (int ch = 0; ch < 4; ++ch) acc[ch] += wgt * fc.accum[i].rgba[p * 4 + ch];
                float d = fc.accum[i].depth[p];
                if (isfinite(d)) {
                    double a = fc.accum[i].rgba[p * 4 + 3], dw = wgt * (a > 1e-6 ? a : 1e-6);
                    dsum += dw * d, dwgt += dw;
                }
            }
            for (int ch = 0; ch < 4; ++ch) out->rgba[p * 4 + ch] = (float)(acc[ch] / (double)total);
            if (out->depth) out->depth[p] = dwgt > 0 ? (float)(dsum / dwgt) : INFINITY;
        }
        st.samples = total;
    }
    /* 6. multi-display: the swap barrier, once every display holds its tile */
    if (r == SY_OK && f->mode == SY_CLUSTER_MULTI_DISPLAY) {
        for (uint32_t i = 0; i < c->n; ++i) {
            conn *k = &c->conns[i];
            if (!k->live) continue;
            sy_cluster_msg m, rep;
            memset(&m, 0, sizeof m);
            m.header.type = SY_CLUSTER_SWAP;
            m.u.ack.frame = c->frame;
            uint8_t *raw = NULL;
            sy_error e = {0};
            if (sy_clu_conn_call(c, k, &m, NULL, SY_CLUSTER_SWAP_ACK, &rep, &raw, &e) == SY_OK) {
                sy_cluster_msg_free(&rep);
                free(raw);
            } else {
                sy_clu_conn_drop(c, k, "swap failed", e.message);
                st.servers_failed++;
            }
        }
    }
    for (uint32_t i = 0; i < c->n; ++i) {
        if (fc.server_seconds && fc.server_seconds[i] > st.max_server_seconds) st.max_server_seconds = fc.server_seconds[i];
        if (fc.accum) sy_layer_destroy(&fc.accum[i]);
        st.bytes_sent += c->conns[i].bytes_sent;
        st.bytes_received += c->conns[i].bytes_received;
        st.scene_bytes += c->conns[i].blob_frames_bytes;
        st.blob_bytes += c->conns[i].blob_payload_bytes;
        st.pipelined += (uint32_t)c->conns[i].ahead_used;
        st.stale += (uint32_t)c->conns[i].ahead_dropped;
        sy_blob_store_destroy(c->conns[i].offered); /* the frame's blobs are on the servers now */
        c->conns[i].offered = NULL;
    }
    st.bytes_sent -= sent0;
    st.bytes_received -= recv0;
    st.scene_bytes -= blobf0;
    st.blob_bytes -= blobp0;
    st.pipelined -= (uint32_t)used0;
    st.stale -= (uint32_t)dropped0;
    /* the sample ranges the requests sent ahead took: a next frame that asks otherwise starts past them */
    for (uint32_t i = 0; i < c->n; ++i)
        if (c->conns[i].ahead.size) c->coop_ahead_end = c->coop_next + fc.coop_span;
    free(fc.ahead_hit);
    free(fc.single);
    free(fc.accum);
    free(fc.accum_samples);
    free(fc.items);
    free(fc.server_seconds);
    st.servers_live = sy_cluster_client_live(c);
    st.seconds = sy_time_now() - t0;
    if (stats) *stats = st;
    return r;
}
