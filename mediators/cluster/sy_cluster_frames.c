/* sy_cluster_frames.c — frames mode of the client (sy_cluster_client_render_frames): a sequence's
 * whole frames handed to the servers from a work queue (one thread per server takes the next frame
 * as soon as its last one is back), each RENDER setting the replica's scene clock and restarting
 * progressive accumulation; a server that fails gives its frame back to the queue, and a stalled
 * queue redials the servers down and runs another round. */
#include "sy_cluster_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { FRAME_TODO = 0, FRAME_RUNNING = 1, FRAME_DONE = 2 };

typedef struct frames_queue {
    sy_cluster_client *c;
    const sy_cluster_frames_job *job;
    pthread_mutex_t lock;          /* the fields below */
    pthread_cond_t cond;           /* a frame finished or went back to the queue */
    uint8_t *state;                /* FRAME_* per frame */
    uint32_t todo, running, done, round_done;
    bool abort;                    /* a delivery failed: stop taking frames */
    sy_result abort_r;
    sy_error abort_err;
    pthread_mutex_t deliver_lock;  /* job->done one call at a time */
    sy_cluster_frames_stats *st;
} frames_queue;

typedef struct frames_worker {
    frames_queue *q;
    uint32_t conn;
    bool failed;
} frames_worker;

/* Renders frame `index` whole on connection k into img (created here, w x h). */
static sy_result render_one(frames_queue *fq, conn *k, uint32_t index, sy_layer *img, sy_error *err)
{
    sy_cluster_client *c = fq->c;
    const sy_cluster_frames_job *job = fq->job;
    const sy_cluster_frame *f = &job->frame;
    sy_cluster_msg m, rep;
    memset(&m, 0, sizeof m);
    m.header.type = SY_CLUSTER_RENDER;
    __typeof__(m.u.render) *q = &m.u.render;
    sy_cluster_rect whole = {0, 0, f->width, f->height};
    q->frame = c->frame;
    q->job = index;
    q->flags = (f->depth ? SY_CLUSTER_RENDER_DEPTH : 0) | (f->half ? SY_CLUSTER_RENDER_HALF : 0) |
               SY_CLUSTER_RENDER_RESTART | (job->times ? SY_CLUSTER_RENDER_TIME : 0);
    sy_clu_copy_str(q->backend, sizeof q->backend, k->backend[0] ? k->backend : f->backend);
    sy_clu_copy_str(q->params, sizeof q->params, f->params ? f->params : "");
    q->root_id = f->root_id;
    q->background_id = f->background_id;
    q->seed = f->seed;
    q->eye = SY_EYE_MONO;
    q->sample_count = f->samples;
    q->full_width = f->width;
    q->full_height = f->height;
    q->camera = job->cameras[index];
    if (job->times) {
        q->time = job->times[index];
        q->clip_id = job->clip_id;
    }
    q->tile_count = 1;
    q->tiles = &whole;
    uint8_t *raw = NULL;
    sy_result r = sy_clu_conn_call(c, k, &m, NULL, SY_CLUSTER_TILES, &rep, &raw, err);
    if (r) return r;
    const __typeof__(rep.u.tiles) *t = &rep.u.tiles;
    if (t->frame != c->frame || t->job != index || t->tile_count != 1 ||
        memcmp(&t->tiles[0].rect, &whole, sizeof whole) != 0)
        r = sy_error_set(err, SY_ERR_PROTOCOL, "%s: reply for frame %llu job %u does not match the request (job %u)",
                         k->url, (unsigned long long)t->frame, t->job, index);
    if (r == SY_OK) r = sy_layer_create(f->width, f->height, img, err);
    if (r == SY_OK) r = sy_cluster_tile_decode(&t->tiles[0], img, 0, 0, err);
    sy_cluster_msg_free(&rep);
    free(raw);
    return r;
}

/* One server's thread: the round's SCENE, then frames from the queue until it is empty (waiting
 * while others still render: a failing one gives its frame back) or this server fails. */
static void *frames_worker_main(void *p)
{
    frames_worker *w = p;
    frames_queue *fq = w->q;
    sy_cluster_client *c = fq->c;
    conn *k = &c->conns[w->conn];
    sy_error err = {0};
    sy_result r = k->scene_msg.size ? sy_clu_send_scene(c, k, &err) : SY_OK;
    while (r == SY_OK) {
        pthread_mutex_lock(&fq->lock);
        while (!fq->abort && fq->todo == 0 && fq->running > 0) pthread_cond_wait(&fq->cond, &fq->lock);
        if (fq->abort || fq->todo == 0) {
            pthread_mutex_unlock(&fq->lock);
            break;
        }
        uint32_t idx = 0;
        while (fq->state[idx] != FRAME_TODO) idx++; /* the earliest frame left: output in order, mostly */
        fq->state[idx] = FRAME_RUNNING;
        fq->todo--;
        fq->running++;
        pthread_mutex_unlock(&fq->lock);
        sy_layer img = {0};
        r = render_one(fq, k, idx, &img, &err);
        sy_result dr = SY_OK;
        sy_error derr = {0};
        if (r == SY_OK) {
            pthread_mutex_lock(&fq->deliver_lock);
            dr = fq->job->done(fq->job->done_user, idx, &img, w->conn, &derr);
            pthread_mutex_unlock(&fq->deliver_lock);
        }
        sy_layer_destroy(&img);
        pthread_mutex_lock(&fq->lock);
        fq->running--;
        if (r != SY_OK) { /* back to the queue: another server renders it */
            fq->state[idx] = FRAME_TODO;
            fq->todo++;
            fq->st->requeued++;
        } else {
            fq->state[idx] = FRAME_DONE;
            fq->done++;
            fq->round_done++;
            fq->st->per_server[w->conn]++;
            if (dr != SY_OK && !fq->abort) {
                fq->abort = true;
                fq->abort_r = dr;
                fq->abort_err = derr;
            }
        }
        pthread_cond_broadcast(&fq->cond);
        pthread_mutex_unlock(&fq->lock);
    }
    if (r != SY_OK) {
        w->failed = true;
        sy_clu_copy_str(k->error, sizeof k->error, err.message);
    }
    return NULL;
}

static sy_result check_job(const sy_cluster_frames_job *job, sy_error *err)
{
    const sy_cluster_frame *f = &job->frame;
    if (!job->count || !job->cameras || !job->done || !f->backend)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cluster frames: no frames, cameras, back-end or delivery");
    if (f->width < 1 || f->height < 1 || f->width > SY_CLUSTER_MAX_IMAGE || f->height > SY_CLUSTER_MAX_IMAGE ||
        (uint64_t)f->width * f->height > SY_CLUSTER_MAX_REQUEST_PIXELS)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cluster frames: a frame of %ux%u is not one request (at most "
                            "%u pixels)", f->width, f->height, SY_CLUSTER_MAX_REQUEST_PIXELS);
    if (f->samples > SY_CLUSTER_MAX_SAMPLES)
        return sy_error_set(err, SY_ERR_LIMIT, "cluster frames: %u samples per frame (at most %u)", f->samples,
                            SY_CLUSTER_MAX_SAMPLES);
    for (uint32_t i = 0; i < job->count; ++i) {
        sy_result cr = sy_cluster_camera_check(&job->cameras[i], err);
        if (cr != SY_OK) {
            sy_error_prefix(err, "cluster frames: frame %u", i);
            return cr;
        }
        if (job->times && !(job->times[i] >= 0.0 && job->times[i] <= SY_CLUSTER_MAX_TIME))
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cluster frames: frame %u: time %g outside 0..1e9 s", i,
                                job->times[i]);
    }
    return SY_OK;
}

sy_result sy_cluster_client_render_frames(sy_cluster_client *c, const sy_cluster_frames_job *job,
                                          sy_cluster_frames_stats *stats, sy_error *err)
{
    double t0 = sy_time_now();
    sy_cluster_frames_stats st;
    memset(&st, 0, sizeof st);
    sy_result r = check_job(job, err);
    if (r != SY_OK) return r;
    uint64_t sent0 = 0, recv0 = 0;
    for (uint32_t i = 0; i < c->n; ++i) sent0 += c->conns[i].bytes_sent, recv0 += c->conns[i].bytes_received;
    frames_queue fq = {.c = c, .job = job, .st = &st, .todo = job->count};
    fq.state = calloc(job->count, 1);
    if (!fq.state) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "cluster frames: out of memory");
    pthread_mutex_init(&fq.lock, NULL);
    pthread_mutex_init(&fq.deliver_lock, NULL);
    pthread_cond_init(&fq.cond, NULL);
    /* rounds: while frames are left and the last round delivered some; each round redials the
     * servers down (a snapshot for them) and syncs the scene's changes */
    for (;;) {
        c->frame++;
        st.rounds++;
        uint64_t scene_bytes = 0;
        r = sy_clu_sync_servers(c, &scene_bytes, err);
        if (r != SY_OK) break;
        frames_worker w[SY_CLUSTER_MAX_SERVERS];
        pthread_t th[SY_CLUSTER_MAX_SERVERS];
        bool started[SY_CLUSTER_MAX_SERVERS] = {0};
        uint32_t nl = 0;
        fq.round_done = 0;
        for (uint32_t i = 0; i < c->n; ++i) {
            w[i] = (frames_worker){&fq, i, false};
            if (!c->conns[i].live) continue;
            nl++;
            started[i] = pthread_create(&th[i], NULL, frames_worker_main, &w[i]) == 0;
            if (!started[i]) frames_worker_main(&w[i]); /* no thread: this server alone, here */
        }
        for (uint32_t i = 0; i < c->n; ++i) {
            if (started[i]) pthread_join(th[i], NULL);
            if (w[i].failed) {
                sy_clu_conn_drop(c, &c->conns[i], "dropped (frames mode; its frame goes back to the queue)",
                                 c->conns[i].error);
                st.servers_failed++;
            }
        }
        if (fq.abort) {
            r = fq.abort_r;
            *err = fq.abort_err;
            break;
        }
        if (fq.done == job->count) break;
        if (!nl || !fq.round_done) {
            char why[SY_ERROR_MESSAGE_MAX] = "no server is reachable";
            for (uint32_t i = 0; i < c->n; ++i)
                if (c->conns[i].error[0]) {
                    sy_clu_copy_str(why, sizeof why, c->conns[i].error);
                    break;
                }
            r = sy_error_set(err, SY_ERR_IO, "cluster frames: %u of %u frames not rendered: every server failed (%s)",
                             job->count - fq.done, job->count, why);
            break;
        }
    }
    pthread_cond_destroy(&fq.cond);
    pthread_mutex_destroy(&fq.deliver_lock);
    pthread_mutex_destroy(&fq.lock);
    free(fq.state);
    st.frames = fq.done;
    for (uint32_t i = 0; i < c->n; ++i) {
        st.bytes_sent += c->conns[i].bytes_sent, st.bytes_received += c->conns[i].bytes_received;
        sy_blob_store_destroy(c->conns[i].offered); /* the round's blobs are on the servers now */
        c->conns[i].offered = NULL;
    }
    st.bytes_sent -= sent0;
    st.bytes_received -= recv0;
    st.seconds = sy_time_now() - t0;
    if (stats) *stats = st;
    return r;
}
