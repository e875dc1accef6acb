/* sy_cluster_serve.c — the render server's serving thread: one request at a time from the job
 * queue (sy_cluster_server_run). A session's replica scene and context pool; SCENE (change lists
 * applied to the replica, blobs taken from the cache or asked for), BLOBS (checked against their
 * hashes), RENDER (tiles encoded for the reply, or held for the swap barrier), SWAP and BYE; the
 * session table (the longest idle session makes room). */
#include "sy_cluster_internal.h"

#include "sy_anim.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void pending_drop(sy_cluster_server *s, session *se)
{
    free(se->pending);
    free(se->missing);
    sy_blob_store_destroy(se->pending_blobs);
    sy_clu_mem_release(s, se->pending_charged);
    se->pending = NULL;
    se->missing = NULL;
    se->pending_blobs = NULL;
    se->pending_size = se->missing_count = 0;
    se->pending_charged = 0;
}

void sy_clu_session_reset(sy_cluster_server *s, session *se)
{
    pending_drop(s, se);
    sy_layer_destroy(&se->present);
    sy_context_pool_destroy(se->pool);
    sy_scene_destroy(se->scene);
    char peer[80];
    memcpy(peer, se->peer, sizeof peer);
    memset(se, 0, sizeof *se);
    memcpy(se->peer, peer, sizeof peer);
}

static sy_result handle_render(sy_cluster_server *s, session *se, const sy_cluster_msg *m, sy_cluster_msg *reply,
                               sy_cluster_buf *payload, sy_error *err)
{
    const __typeof__(m->u.render) *q = &m->u.render;
    if (!se->scene) return sy_error_set(err, SY_ERR_PROTOCOL, "RENDER before any scene was sent");
    if (!sy_mediator_find(q->backend))
        return sy_error_set(err, SY_ERR_NOT_FOUND, "back-end '%s' is not registered on %s", q->backend, s->name);
    if ((q->flags & SY_CLUSTER_RENDER_PRESENT) && q->tile_count != 1)
        return sy_error_set(err, SY_ERR_PROTOCOL, "a present (multi-display) request needs exactly one tile");
    uint64_t pixels = 0;
    for (uint32_t i = 0; i < q->tile_count; ++i) pixels += (uint64_t)q->tiles[i].w * q->tiles[i].h;
    if (pixels > SY_CLUSTER_MAX_REQUEST_PIXELS)
        return sy_error_set(err, SY_ERR_LIMIT, "RENDER asks for %llu pixels, more than the %u a request may hold",
                            (unsigned long long)pixels, SY_CLUSTER_MAX_REQUEST_PIXELS);
    sy_params params;
    sy_result r = sy_params_parse(q->params, &params, err);
    sy_context *ctx = NULL;
    if (r == SY_OK) r = sy_context_pool_get(se->pool, se->scene, q->backend, &params, q->root_id, &ctx, err);
    double t0 = sy_time_now();
    if (r == SY_OK && (q->flags & SY_CLUSTER_RENDER_TIME)) {
        /* frames mode: the replica's scene clock (a pure function of the time: the replica's earlier
         * times leave nothing behind); committed even when a channel failed, so no edit is left pending */
        sy_animation clip = {q->clip_id};
        r = sy_scene_set_time(se->scene, clip, q->time, err);
        sy_error ce = {0};
        sy_result cr = sy_scene_commit(se->scene, NULL, &ce);
        if (r == SY_OK && cr != SY_OK) r = cr, *err = ce;
        if (r != SY_OK) sy_error_prefix(err, "RENDER at scene time %g", q->time);
    }
    if (r == SY_OK && (q->flags & SY_CLUSTER_RENDER_RESTART)) sy_context_restart(ctx);
    if (r == SY_OK) r = sy_context_sync(ctx, err);
    double t1 = sy_time_now();
    if (r) return r;
    sy_cluster_tile *tiles = calloc(q->tile_count, sizeof *tiles);
    size_t *offsets = calloc(q->tile_count, sizeof *offsets);
    if (!tiles || !offsets) {
        free(tiles);
        free(offsets);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "out of memory");
    }
    bool depth = (q->flags & SY_CLUSTER_RENDER_DEPTH) != 0;
    uint32_t encoding = (q->flags & SY_CLUSTER_RENDER_HALF) ? SY_CLUSTER_ENC_F16_SHUFFLE_ZSTD : SY_CLUSTER_ENC_F32_SHUFFLE_ZSTD;
    uint32_t vb = sy_cluster_encoding_bytes(encoding);
    sy_cluster_buf enc = {0};
    for (uint32_t i = 0; i < q->tile_count && r == SY_OK; ++i) {
        const sy_cluster_rect *tr = &q->tiles[i];
        sy_layer l = {0};
        r = sy_layer_create(tr->w, tr->h, &l, err);
        sy_render_request req = {.camera = q->camera,
                                 .full_width = q->full_width,
                                 .full_height = q->full_height,
                                 .rect_x = tr->x,
                                 .rect_y = tr->y,
                                 .rect_w = tr->w,
                                 .rect_h = tr->h,
                                 .sample_first = q->sample_first,
                                 .sample_count = q->sample_count,
                                 .background_id = q->background_id,
                                 .seed = q->seed};
        if (r == SY_OK) r = sy_context_render(ctx, &req, &l, err);
        if (r == SY_OK && (q->flags & SY_CLUSTER_RENDER_PRESENT)) {
            sy_layer_destroy(&se->present);
            se->present = l;
            memset(&l, 0, sizeof l);
            se->present_x = tr->x;
            se->present_y = tr->y;
            se->present_fw = q->full_width;
            se->present_fh = q->full_height;
            se->present_frame = q->frame;
            se->has_present = true;
        } else if (r == SY_OK) {
            r = sy_cluster_tile_encode_as(&l, depth, encoding, &enc, err);
            if (r == SY_OK) {
                size_t off = payload->size;
                size_t need = payload->size + enc.size;
                if (need > payload->cap) {
                    uint8_t *d = realloc(payload->data, need * 2);
                    if (!d) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "out of memory");
                    else payload->data = d, payload->cap = need * 2;
                }
                if (r == SY_OK) {
                    memcpy(payload->data + payload->size, enc.data, enc.size);
                    payload->size = need;
                    offsets[i] = off;
                    tiles[i] = (sy_cluster_tile){*tr, encoding, depth ? 5u : 4u,
                                                 (uint64_t)tr->w * tr->h * (depth ? 5u : 4u) * vb, NULL,
                                                 (uint32_t)enc.size};
                }
            }
        }
        sy_layer_destroy(&l);
    }
    sy_cluster_buf_free(&enc);
    double t2 = sy_time_now();
    if (r) {
        free(tiles);
        free(offsets);
        return r;
    }
    uint32_t n = (q->flags & SY_CLUSTER_RENDER_PRESENT) ? 0 : q->tile_count;
    for (uint32_t i = 0; i < n; ++i) tiles[i].data = payload->data + offsets[i];
    free(offsets);
    sy_mediator_stats st = {0};
    sy_context_stats(ctx, &st);
    reply->header.type = SY_CLUSTER_TILES;
    reply->u.tiles.frame = q->frame;
    reply->u.tiles.job = q->job;
    reply->u.tiles.sync_seconds = t1 - t0;
    reply->u.tiles.render_seconds = t2 - t1;
    reply->u.tiles.samples = (sy_context_caps(ctx) & SY_CAP_PROGRESSIVE) && st.samples ? st.samples
                                                                                           : (q->sample_count ? q->sample_count : 1);
    reply->u.tiles.tile_count = n;
    reply->u.tiles.tiles = tiles; /* freed by the caller */
    return SY_OK;
}

/* Applies a complete SCENE (every blob it names is in blobs or inline). A snapshot replaces the
 * replica (and its contexts); a failure drops the replica, so the client must send a snapshot. */
static sy_result apply_scene(sy_cluster_server *s, session *se, const uint8_t *changes, uint32_t size, uint32_t flags,
                             uint64_t frame, sy_blob_store *blobs, sy_cluster_msg *reply, sy_error *err)
{
    sy_result r = SY_OK;
    if ((flags & SY_CLUSTER_SCENE_SNAPSHOT) || !se->scene) {
        sy_layer_destroy(&se->present);
        se->has_present = false;
        sy_context_pool_destroy(se->pool);
        sy_scene_destroy(se->scene);
        se->pool = NULL;
        se->scene = NULL;
        r = sy_scene_create(&se->scene, err);
        if (r == SY_OK) r = sy_context_pool_create(&se->pool, err);
        if (r) return r;
        sy_scene_set_apply_limit(se->scene, s->o.max_objects);
    }
    sy_changes *ch = NULL;
    r = sy_changes_deserialize(changes, size, blobs, NULL, &ch, err);
    /* the replica's pools grow by at most SY_CLUSTER_APPLY_SLACK_SLOTS + one slot per
     * SY_CLUSTER_APPLY_BYTES_PER_SLOT bytes of the list */
    if (r == SY_OK)
        r = sy_scene_apply_bounded(se->scene, ch, SY_CLUSTER_APPLY_SLACK_SLOTS + size / SY_CLUSTER_APPLY_BYTES_PER_SLOT,
                                   err);
    sy_changes_release(ch); /* before the commit copies the changes for the contexts: one copy at a time */
    if (r == SY_OK) r = sy_scene_commit(se->scene, NULL, err);
    if (r) {
        /* the replica may be partly updated: drop it, the client must start from a snapshot */
        sy_context_pool_destroy(se->pool);
        sy_scene_destroy(se->scene);
        se->pool = NULL;
        se->scene = NULL;
        sy_error_prefix(err, "scene for frame %llu rejected (replica dropped, send a snapshot)", (unsigned long long)frame);
        return r;
    }
    se->frame = frame;
    uint32_t objects = 0;
    for (uint32_t t = 0; t < SY_TYPE_COUNT; ++t) objects += sy_scene_count(se->scene, (sy_object_type)t);
    reply->header.type = SY_CLUSTER_SCENE_ACK;
    reply->u.ack.frame = se->frame;
    reply->u.ack.objects = objects;
    return SY_OK;
}

typedef struct ref_scan {
    blob_cache *cache;
    session *se;
    uint32_t cap;
    bool oom;
} ref_scan;

/* sy_changes_blob_refs callback: a blob named by hash is taken from the cache or requested */
static void scan_ref(void *user, sy_hash128 h, uint64_t size)
{
    ref_scan *rs = user;
    session *se = rs->se;
    sy_blob *b = sy_clu_cache_get(rs->cache, h);
    if (b && sy_blob_size(b) == size) {
        sy_error e = {0};
        if (sy_blob_store_put(se->pending_blobs, b, &e) != SY_OK) rs->oom = true;
        return;
    }
    if (se->missing_count == rs->cap) {
        uint32_t nc = rs->cap ? rs->cap * 2 : 64;
        sy_cluster_blob_ref *m = realloc(se->missing, nc * sizeof *m);
        if (!m) {
            rs->oom = true;
            return;
        }
        se->missing = m;
        rs->cap = nc;
    }
    se->missing[se->missing_count++] = (sy_cluster_blob_ref){h, size, NULL};
}

/* Asks for the blobs still missing (at most SY_CLUSTER_MAX_BLOBS per request). */
static void request_missing(session *se, sy_cluster_msg *reply)
{
    reply->header.type = SY_CLUSTER_BLOB_REQUEST;
    reply->u.blobs.frame = se->pending_frame;
    reply->u.blobs.count = se->missing_count < SY_CLUSTER_MAX_BLOBS ? se->missing_count : SY_CLUSTER_MAX_BLOBS;
    reply->u.blobs.blobs = se->missing; /* borrowed: the reply is encoded before the session changes */
}

static sy_result handle_scene(sy_cluster_server *s, session *se, const sy_cluster_msg *m, sy_cluster_msg *reply,
                              sy_error *err)
{
    bool snap = (m->u.scene.flags & SY_CLUSTER_SCENE_SNAPSHOT) != 0;
    pending_drop(s, se); /* a new SCENE replaces one still waiting for blobs */
    if (!snap && !se->scene) return sy_error_set(err, SY_ERR_PROTOCOL, "the first SCENE must be a snapshot");
    sy_result r = sy_blob_store_create(&se->pending_blobs, err);
    ref_scan rs = {&s->cache, se, 0, false};
    if (r == SY_OK) r = sy_changes_blob_refs(m->u.scene.changes, m->u.scene.changes_size, NULL, scan_ref, &rs, err);
    if (r == SY_OK && rs.oom) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "out of memory for the blob list");
    if (r == SY_OK && se->missing_count) { /* keep the list until the blobs arrive */
        size_t keep = m->u.scene.changes_size ? m->u.scene.changes_size : 1;
        if (!sy_clu_mem_try(s, keep))
            r = sy_error_set(err, SY_ERR_LIMIT,
                             "server busy: no room to keep a %u-byte scene while its blobs arrive (peers' messages "
                             "may hold %zu KiB in all)",
                             m->u.scene.changes_size, s->max_peer_memory >> 10);
        else if (!(se->pending = malloc(keep))) {
            sy_clu_mem_release(s, keep);
            r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "out of memory for a pending scene");
        } else {
            se->pending_charged = keep;
            memcpy(se->pending, m->u.scene.changes, m->u.scene.changes_size);
            se->pending_size = m->u.scene.changes_size;
            se->pending_flags = m->u.scene.flags;
            se->pending_frame = m->u.scene.frame;
            uint64_t bytes = 0;
            for (uint32_t i = 0; i < se->missing_count; ++i) bytes += se->missing[i].size;
            SLOG(s, "%s: frame %llu: asking for %u blob(s), %llu bytes, not in the cache (%zu blobs, %zu bytes cached)",
                 se->peer, (unsigned long long)se->pending_frame, se->missing_count, (unsigned long long)bytes,
                 s->cache.count, s->cache.bytes);
            request_missing(se, reply);
            return SY_OK;
        }
    }
    if (r == SY_OK)
        r = apply_scene(s, se, m->u.scene.changes, m->u.scene.changes_size, m->u.scene.flags, m->u.scene.frame,
                        se->pending_blobs, reply, err);
    else sy_error_prefix(err, "scene for frame %llu rejected", (unsigned long long)m->u.scene.frame);
    pending_drop(s, se);
    return r;
}

/* BLOBS: every payload must be one the server asked for and match its hash; then the pending
 * SCENE applies (or the rest is asked for). Any mismatch drops the pending SCENE. */
static sy_result handle_blobs(sy_cluster_server *s, session *se, const sy_cluster_msg *m, sy_cluster_msg *reply,
                              sy_error *err)
{
    const __typeof__(m->u.blobs) *q = &m->u.blobs;
    sy_result r = SY_OK;
    if (!se->pending) return sy_error_set(err, SY_ERR_PROTOCOL, "BLOBS without a SCENE waiting for them");
    if (q->frame != se->pending_frame)
        r = sy_error_set(err, SY_ERR_PROTOCOL, "BLOBS for frame %llu, the pending scene is for frame %llu",
                         (unsigned long long)q->frame, (unsigned long long)se->pending_frame);
    for (uint32_t i = 0; i < q->count && r == SY_OK; ++i) {
        const sy_cluster_blob_ref *b = &q->blobs[i];
        uint32_t k = 0;
        while (k < se->missing_count && !sy_hash_equal(se->missing[k].hash, b->hash)) k++;
        if (k == se->missing_count)
            r = sy_error_set(err, SY_ERR_PROTOCOL, "blob %016llx%016llx was not requested (or sent twice)",
                             (unsigned long long)b->hash.hi, (unsigned long long)b->hash.lo);
        else if (b->size != se->missing[k].size)
            r = sy_error_set(err, SY_ERR_PROTOCOL, "blob %016llx%016llx has %llu bytes, the scene names %llu",
                             (unsigned long long)b->hash.hi, (unsigned long long)b->hash.lo,
                             (unsigned long long)b->size, (unsigned long long)se->missing[k].size);
        else if (!sy_hash_equal(sy_hash_bytes(b->data, (size_t)b->size), b->hash))
            r = sy_error_set(err, SY_ERR_PROTOCOL, "blob %016llx%016llx: payload does not match its hash",
                             (unsigned long long)b->hash.hi, (unsigned long long)b->hash.lo);
        sy_blob *blob = NULL;
        if (r == SY_OK) r = sy_blob_create_copy(b->data, (size_t)b->size, &blob, err);
        if (r == SY_OK) r = sy_blob_store_put(se->pending_blobs, blob, err);
        if (r == SY_OK) {
            sy_clu_cache_put(&s->cache, blob);
            se->missing[k] = se->missing[--se->missing_count];
        }
        sy_blob_release(blob);
    }
    if (r == SY_OK && se->missing_count) {
        request_missing(se, reply);
        return SY_OK;
    }
    if (r == SY_OK)
        r = apply_scene(s, se, se->pending, se->pending_size, se->pending_flags, se->pending_frame, se->pending_blobs,
                        reply, err);
    else sy_error_prefix(err, "scene for frame %llu rejected", (unsigned long long)se->pending_frame);
    pending_drop(s, se);
    return r;
}

/* >>serving: one request at a time, on the thread that runs sy_cluster_server_run */

/* The first request of an open session registers it; beyond max_sessions the longest idle session
 * is ended (its connection closed, its replica dropped). */
static void session_register(sy_cluster_server *s, peer *p)
{
    if (p->registered) return;
    if (s->session_count >= s->max_sessions) {
        peer *victim = NULL;
        pthread_mutex_lock(&s->lock);
        for (peer *q = s->peers; q; q = q->next)
            if (q != p && q->registered && !q->evicted && (!victim || q->se.last_active < victim->se.last_active))
                victim = q;
        if (victim) victim->w.st->ops->close(victim->w.st); /* its reader thread ends; reap_peers frees it */
        pthread_mutex_unlock(&s->lock);
        if (victim) {
            SLOG(s, "%s: session ended to make room for %s (idle longest; %u sessions max)", victim->se.peer, p->addr,
                 s->max_sessions);
            sy_clu_session_reset(s, &victim->se);
            victim->evicted = true;
            victim->registered = false;
            s->session_count--;
        }
    }
    p->registered = true;
    s->session_count++;
}

/* Serves the message in p->in; leaves the encoded (untagged) reply in p->reply. */
void sy_clu_serve_job(sy_cluster_server *s, peer *p)
{
    p->reply.size = 0;
    p->close_after = false;
    if (p->evicted) {
        p->close_after = true;
        return;
    }
    session_register(s, p);
    session *se = &p->se;
    se->last_active = sy_time_now();
    sy_error err = {0};
    sy_cluster_msg m, reply;
    memset(&reply, 0, sizeof reply);
    sy_cluster_buf payload = {0};
    sy_cluster_limits lim = {s->max_message};
    sy_result r = sy_cluster_decode_body(&p->in.h, p->in.body, p->in.size, &lim, &m, &err);
    if (r == SY_OK) {
        uint32_t t = m.header.type;
        if (t == SY_CLUSTER_HELLO || t == SY_CLUSTER_AUTH) {
            r = sy_error_set(&err, SY_ERR_PROTOCOL, "%s in the middle of a session", sy_cluster_msg_type_name(t));
            p->close_after = true;
        } else if (t == SY_CLUSTER_SCENE) {
            r = handle_scene(s, se, &m, &reply, &err);
        } else if (t == SY_CLUSTER_BLOBS) {
            r = handle_blobs(s, se, &m, &reply, &err);
        } else if (t == SY_CLUSTER_RENDER) {
            r = handle_render(s, se, &m, &reply, &payload, &err);
        } else if (t == SY_CLUSTER_SWAP) {
            if (!se->has_present || se->present_frame != m.u.ack.frame)
                r = sy_error_set(&err, SY_ERR_PROTOCOL, "SWAP for frame %llu without a rendered tile",
                                 (unsigned long long)m.u.ack.frame);
            else if (s->o.present)
                r = s->o.present(s->o.present_user, se->present_frame, &se->present, se->present_x, se->present_y,
                                 se->present_fw, se->present_fh, &err);
            if (r == SY_OK) {
                reply.header.type = SY_CLUSTER_SWAP_ACK;
                reply.u.ack.frame = m.u.ack.frame;
            }
        } else if (t == SY_CLUSTER_BYE) {
            reply.header.type = SY_CLUSTER_BYE;
            p->close_after = true;
            SLOG(s, "%s: bye", se->peer);
        } else {
            r = sy_error_set(&err, SY_ERR_PROTOCOL, "unexpected %s from a client", sy_cluster_msg_type_name(t));
        }
        sy_cluster_msg_free(&m);
    }
    if (r) {
        SWARN(s, "%s: rejected: %s%s", se->peer, err.message, p->close_after ? " (connection closed)" : "");
        memset(&reply, 0, sizeof reply);
        reply.header.type = SY_CLUSTER_ERROR;
        reply.u.error.code = (uint32_t)r;
        sy_clu_copy_str(reply.u.error.reason, sizeof reply.u.error.reason, err.message);
    }
    sy_error e2 = {0};
    if (sy_cluster_encode(&reply, 0, &p->reply, &e2) != SY_OK) {
        SWARN(s, "%s: cannot encode the reply: %s", se->peer, e2.message);
        p->reply.size = 0;
        p->close_after = true;
    }
    if (reply.header.type == SY_CLUSTER_TILES) free(reply.u.tiles.tiles);
    sy_cluster_buf_free(&payload);
    /* the encoded reply counts against the peer memory ceiling until it has been sent */
    if (p->reply.size && !sy_clu_mem_try(s, p->reply.cap)) {
        size_t want = p->reply.cap;
        sy_cluster_buf_free(&p->reply);
        memset(&reply, 0, sizeof reply);
        reply.header.type = SY_CLUSTER_ERROR;
        reply.u.error.code = SY_ERR_LIMIT;
        snprintf(reply.u.error.reason, sizeof reply.u.error.reason,
                 "server busy: a reply of %zu KiB does not fit the memory left for peers' messages (%zu KiB ceiling)",
                 want >> 10, s->max_peer_memory >> 10);
        SWARN(s, "%s: rejected: %s", se->peer, reply.u.error.reason);
        if (sy_cluster_encode(&reply, 0, &p->reply, &e2) != SY_OK) p->reply.size = 0;
        p->reply_charged = 0; /* a few hundred bytes, not charged */
    } else {
        p->reply_charged = p->reply.size ? p->reply.cap : 0;
    }
}
