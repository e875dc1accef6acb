/* sy_cluster_server.c — the render server (sy_cluster_server_*, `sy serve`): create (limits,
 * secret, listener), run (the accepting thread, the job queue served by sy_cluster_serve.c, stop)
 * and destroy; every connection's record and reader thread (handshake, then its frames in and its
 * replies out), the table of unauthenticated connections (the oldest of the address holding the
 * most makes room) and reaping finished connections. */
#include "sy_cluster_internal.h"

#include <sodium.h>

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* Each connection's reader thread: 64 KiB of stack reserved (a few KiB touched); sanitizer frames
 * are larger. */
#if defined(__SANITIZE_ADDRESS__)
#define SY__ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SY__ASAN 1
#endif
#endif
#ifdef SY__ASAN
#define SY_CLUSTER_READER_STACK ((size_t)512 << 10)
#else
#define SY_CLUSTER_READER_STACK ((size_t)64 << 10)
#endif

static void *acceptor_main(void *arg);

sy_result sy_cluster_server_create(const sy_cluster_server_opts *opts, sy_cluster_server **out, sy_error *err)
{
    *out = NULL;
    if (!sy_clu_crypto_ready()) return sy_error_set(err, SY_ERR_BACKEND, "sy serve: libsodium failed to initialise");
    sy_cluster_server *s = calloc(1, sizeof *s);
    if (!s) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "sy serve: out of memory");
    s->o = *opts;
    const char *url = opts->listen_url ? opts->listen_url : SY_CLUSTER_DEFAULT_URL;
    sy_clu_copy_str(s->name, sizeof s->name, opts->name ? opts->name : "sy serve");
    s->max_sessions = opts->max_sessions ? opts->max_sessions : 16;
    s->max_frame = opts->max_frame ? opts->max_frame : SY_CLUSTER_DEFAULT_MAX_FRAME;
    s->max_message = opts->max_message ? opts->max_message : SY_CLUSTER_DEFAULT_MAX_MESSAGE;
    s->max_peer_memory = opts->max_peer_memory ? opts->max_peer_memory : SY_CLUSTER_DEFAULT_MAX_PEER_MEMORY;
    s->max_unauth = opts->max_unauthenticated ? opts->max_unauthenticated : SY_CLUSTER_DEFAULT_MAX_UNAUTHENTICATED;
    s->handshake_ms = opts->handshake_timeout_ms ? opts->handshake_timeout_ms : SY_CLUSTER_DEFAULT_HANDSHAKE_MS;
    if (s->max_frame < SY_CLUSTER_MIN_FRAME || s->max_frame > SY_CLUSTER_MAX_FRAME_LIMIT ||
        s->max_message < SY_CLUSTER_MIN_FRAME || s->max_message > SY_CLUSTER_MAX_MESSAGE_LIMIT ||
        s->max_peer_memory < SY_CLUSTER_MIN_FRAME) {
        free(s);
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                            "sy serve: frame limit %zu (64 KiB..1 GiB), message limit %zu (>= 64 KiB) or peer memory %zu "
                            "(>= 64 KiB) out of range",
                            opts->max_frame, opts->max_message, opts->max_peer_memory);
    }
    if (s->max_message > s->max_peer_memory) s->max_message = s->max_peer_memory; /* one message must fit */
    s->cache.budget = opts->blob_cache_bytes ? opts->blob_cache_bytes : SY_CLUSTER_DEFAULT_BLOB_CACHE;
    if (!s->o.max_objects) s->o.max_objects = SY_CLUSTER_DEFAULT_MAX_OBJECTS;
    if (!s->o.auth_backoff_ms) s->o.auth_backoff_ms = 250;
    s->unauth_scratch = calloc(s->max_unauth, sizeof *s->unauth_scratch);
    if (!s->unauth_scratch) {
        free(s);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "sy serve: out of memory");
    }
    pthread_mutex_init(&s->auth_lock, NULL);
    pthread_mutex_init(&s->lock, NULL);
    pthread_mutex_init(&s->qlock, NULL);
    pthread_mutex_init(&s->mem_lock, NULL);
    pthread_mutex_init(&s->log_lock, NULL);
    pthread_cond_init(&s->qcond, NULL);
    pthread_cond_init(&s->dcond, NULL);
    pthread_cond_init(&s->mem_cond, NULL);
    s->sync_ok = true;
    if (opts->secret_len) {
        s->secret = malloc(opts->secret_len);
        if (!s->secret) {
            sy_cluster_server_destroy(s);
            return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "sy serve: out of memory");
        }
        memcpy(s->secret, opts->secret, opts->secret_len);
    }
    s->o.secret = s->secret;
    char *cert = NULL, *key = NULL;
    sy_result lr = SY_OK;
    if (!strncmp(url, "tls+tcp://", 10) && opts->tls_cert_file && opts->tls_key_file) {
        lr = sy_clu_read_pem(opts->tls_cert_file, &cert, err);
        if (lr == SY_OK) lr = sy_clu_read_pem(opts->tls_key_file, &key, err);
    }
    sy_cluster_listen_opts lo = {cert, key};
    if (lr == SY_OK) lr = sy_cluster_listen(url, &lo, &s->listener, err);
    if (key) sodium_memzero(key, strlen(key));
    free(cert);
    free(key);
    if (lr != SY_OK) {
        sy_cluster_server_destroy(s);
        return lr;
    }
    if (!s->secret && !s->listener->loopback && !s->listener->trusted) {
        sy_cluster_server_destroy(s);
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                            "sy serve: %s is not a loopback address; a shared secret (--secret-file or "
                            "SY_CLUSTER_SECRET) is required to listen there",
                            url);
    }
    s->port = s->listener->port;
    *out = s;
    return SY_OK;
}

int sy_cluster_server_port(const sy_cluster_server *s)
{
    return s->port;
}

size_t sy_cluster_server_peer_memory(const sy_cluster_server *s, size_t *peak_out)
{
    pthread_mutex_lock((pthread_mutex_t *)&s->mem_lock);
    size_t used = s->mem_used;
    if (peak_out) *peak_out = s->mem_peak;
    pthread_mutex_unlock((pthread_mutex_t *)&s->mem_lock);
    return used;
}

static void peer_free(sy_cluster_server *s, peer *p);

void sy_cluster_server_destroy(sy_cluster_server *s)
{
    if (!s) return;
    if (s->listener) {
        s->listener->ops->close(s->listener);
        if (s->acceptor_started) pthread_join(s->acceptor, NULL);
        s->listener->ops->free(s->listener);
    }
    /* sy_cluster_server_run has ended every connection; a server that never ran has none */
    while (s->peers) {
        peer *p = s->peers;
        s->peers = p->next;
        peer_free(s, p);
    }
    sy_clu_cache_free(&s->cache);
    free(s->unauth_scratch);
    if (s->secret) sodium_memzero(s->secret, s->o.secret_len);
    free(s->secret);
    if (s->sync_ok) {
        pthread_mutex_destroy(&s->auth_lock);
        pthread_mutex_destroy(&s->lock);
        pthread_mutex_destroy(&s->qlock);
        pthread_mutex_destroy(&s->mem_lock);
        pthread_mutex_destroy(&s->log_lock);
        pthread_cond_destroy(&s->qcond);
        pthread_cond_destroy(&s->dcond);
        pthread_cond_destroy(&s->mem_cond);
    }
    free(s);
}

static void *peer_main(void *arg)
{
    peer *p = arg;
    sy_cluster_server *s = p->s;
    bool open = sy_clu_peer_handshake(p);
    if (open) {
        /* sessions that never send a request are not registered (and evicted) by the serving
         * thread: at most twice max_sessions may be open at all */
        pthread_mutex_lock(&s->lock);
        if (p->counted_unauth) s->unauth--;
        p->counted_unauth = false;
        uint32_t n = s->open_sessions;
        open = n < 2 * s->max_sessions;
        if (open) s->open_sessions++, p->counted_open = true;
        pthread_mutex_unlock(&s->lock);
        if (!open) {
            char why[160];
            snprintf(why, sizeof why, "server busy: %u sessions are open (--max-sessions %u)", n, s->max_sessions);
            SWARN(s, "%s: rejected: %s (connection closed)", p->addr, why);
            sy_clu_peer_refuse(p, SY_ERR_LIMIT, why);
        }
    }
    const sy_cluster_budget fb = {s->max_frame, s->max_message, true, p->w.tagged};
    const wire_mem mem = {sy_clu_mem_reserve_wait, sy_clu_mem_release, s};
    while (open) {
        sy_error err = {0};
        sy_result r = sy_clu_wire_recv(&p->w, &fb, NULL, 0, &mem, 0, SY_CLUSTER_PROGRESS_MS / 1000.0, &p->in, NULL, &err);
        if (r) {
            if (sy_clu_wire_closed(&p->w)) SLOG(s, "%s: disconnected", p->addr);
            else if (p->w.last_rv) SWARN(s, "%s: connection failed: %s (connection closed)", p->addr, err.message);
            else {
                SWARN(s, "%s: rejected: %s (connection closed)", p->addr, err.message);
                sy_clu_peer_refuse(p, r, err.message);
            }
            break;
        }
        pthread_mutex_lock(&s->qlock);
        bool stop = s->stopping;
        if (!stop) {
            p->done = false;
            p->qnext = NULL;
            if (s->qtail) s->qtail->qnext = p;
            else s->qhead = p;
            s->qtail = p;
            pthread_cond_signal(&s->qcond);
            while (!p->done) pthread_cond_wait(&s->dcond, &s->qlock);
            stop = s->stopping;
        }
        pthread_mutex_unlock(&s->qlock);
        sy_clu_rx_release(&p->in, &mem);
        if (!stop && p->reply.size) {
            r = sy_clu_wire_send(&p->w, p->reply.data, p->reply.size, p->peer_max_frame, 0, SY_CLUSTER_SEND_MS / 1000.0, NULL,
                          &err);
            if (r) SWARN(s, "%s: reply not sent: %s (connection closed)", p->addr, err.message);
        }
        sy_clu_mem_release(s, p->reply_charged);
        p->reply_charged = 0;
        sy_cluster_buf_free(&p->reply);
        if (stop || r || p->close_after) break;
    }
    p->w.st->ops->close(p->w.st);
    pthread_mutex_lock(&s->lock);
    if (p->counted_unauth) s->unauth--;
    if (p->counted_open) s->open_sessions--;
    if (p->displaced) s->displacing--;
    p->counted_unauth = p->counted_open = p->displaced = false;
    p->dead = true;
    pthread_mutex_unlock(&s->lock);
    pthread_mutex_lock(&s->qlock);
    pthread_cond_signal(&s->qcond); /* the serving thread reaps */
    pthread_mutex_unlock(&s->qlock);
    return NULL;
}

/* Frees a connection whose reader thread has ended (or never started). Serving thread. */
static void peer_free(sy_cluster_server *s, peer *p)
{
    if (p->registered) s->session_count--;
    sy_clu_session_reset(s, &p->se);
    sy_clu_rx_release(&p->in, &(wire_mem){sy_clu_mem_reserve_wait, sy_clu_mem_release, s});
    sy_clu_mem_release(s, p->reply_charged);
    sy_cluster_buf_free(&p->reply);
    if (p->w.st) p->w.st->ops->free(p->w.st);
    sodium_memzero(p->w.key, sizeof p->w.key);
    free(p);
}

/* Joins and frees every connection whose reader thread has finished. Serving thread. */
static void reap_peers(sy_cluster_server *s)
{
    for (;;) {
        peer *dead = NULL;
        pthread_mutex_lock(&s->lock);
        for (peer **pp = &s->peers; *pp; pp = &(*pp)->next)
            if ((*pp)->dead) {
                dead = *pp;
                *pp = dead->next;
                s->npeers--;
                break;
            }
        pthread_mutex_unlock(&s->lock);
        if (!dead) return;
        pthread_join(dead->thread, NULL);
        peer_free(s, dead);
    }
}

/* Orders unauthenticated connections by host, then by age (oldest first). */
static int unauth_order(const void *a, const void *b)
{
    const peer *p = *(peer *const *)a, *q = *(peer *const *)b;
    int c = strcmp(p->host, q->host);
    if (c) return c;
    return (p->accepted > q->accepted) - (p->accepted < q->accepted);
}

/* The table of unauthenticated connections is full: picks the connection to close for a newer
 * one: the oldest connection of the address that holds the most (ties: the address whose oldest
 * is oldest). So a flood from one address displaces only its own connections while another
 * address holds fewer, and a client that completes its handshake promptly is never the oldest
 * for long. NULL when none (the displaced ones have not ended yet). Caller holds s->lock. */
static peer *unauth_victim(sy_cluster_server *s, uint32_t *same_host)
{
    uint32_t n = 0;
    for (peer *p = s->peers; p && n < s->max_unauth; p = p->next)
        if (p->counted_unauth && !p->displaced) s->unauth_scratch[n++] = p;
    if (!n) return NULL;
    qsort(s->unauth_scratch, n, sizeof *s->unauth_scratch, unauth_order);
    peer *best = NULL;
    uint32_t best_run = 0;
    for (uint32_t i = 0; i < n;) {
        uint32_t j = i + 1;
        while (j < n && !strcmp(s->unauth_scratch[j]->host, s->unauth_scratch[i]->host)) ++j;
        peer *oldest = s->unauth_scratch[i];
        if (j - i > best_run || (j - i == best_run && oldest->accepted < best->accepted)) best = oldest, best_run = j - i;
        i = j;
    }
    *same_host = best_run;
    return best;
}

/* A new connection: when max_unauthenticated connections are waiting for their handshake, the
 * oldest of the address holding the most is closed to make room (unauth_victim), so idle
 * connections reopened by one peer cannot lock honest clients out; refused at once only while
 * max_unauthenticated displaced connections are still closing. Then a record and a reader thread
 * with a small stack. */
static void peer_start(sy_cluster_server *s, sy_cluster_stream *st)
{
    pthread_mutex_lock(&s->lock);
    uint32_t unauth = s->unauth, same_host = 0, closing = s->displacing;
    char victim_addr[80] = "";
    bool room = unauth < s->max_unauth;
    if (!room && closing < s->max_unauth) {
        peer *v = unauth_victim(s, &same_host);
        if (v) {
            sy_clu_copy_str(victim_addr, sizeof victim_addr, v->addr);
            v->counted_unauth = false;
            v->displaced = true;
            s->unauth--;
            s->displacing++;
            v->w.st->ops->close(v->w.st); /* its reader thread ends (the record stays listed until then) */
            room = true;
        }
    }
    if (room) s->unauth++;
    pthread_mutex_unlock(&s->lock);
    if (victim_addr[0])
        sy_clu_slog_noise(s, SY_LOG_WARNING, "%s: closed before authentication to make room for %s: the oldest of the %u "
                      "unauthenticated connections from its address (%u open, limit %u, --max-unauthenticated)",
                   victim_addr, st->peer, same_host, unauth, s->max_unauth);
    if (!room) {
        sy_clu_slog_noise(s, SY_LOG_WARNING, "%s: connection refused: %u unauthenticated connections are open (limit %u, "
                      "--max-unauthenticated) and %u more are closing", st->peer, unauth, s->max_unauth, closing);
        st->ops->free(st);
        return;
    }
    peer *p = calloc(1, sizeof *p);
    int rv = p ? 0 : ENOMEM;
    if (rv == 0) {
        p->s = s;
        p->w.st = st;
        p->accepted = sy_time_now();
        p->counted_unauth = true;
        p->loopback = st->loopback;
        sy_clu_copy_str(p->addr, sizeof p->addr, st->peer);
        sy_clu_copy_str(p->se.peer, sizeof p->se.peer, st->peer);
        sy_clu_copy_str(p->host, sizeof p->host, st->host);
        pthread_attr_t at;
        pthread_attr_init(&at);
        pthread_attr_setstacksize(&at, SY_CLUSTER_READER_STACK);
        pthread_mutex_lock(&s->lock); /* listed before it runs: its exit finds itself */
        rv = pthread_create(&p->thread, &at, peer_main, p);
        if (rv == 0) {
            p->next = s->peers;
            s->peers = p;
            s->npeers++;
        }
        pthread_mutex_unlock(&s->lock);
        pthread_attr_destroy(&at);
        if (rv == 0) return;
    }
    sy_clu_slog_noise(s, SY_LOG_WARNING, "%s: connection dropped: %s", st->peer, rv == ENOMEM ? "out of memory" : strerror(rv));
    pthread_mutex_lock(&s->lock);
    s->unauth--;
    pthread_mutex_unlock(&s->lock);
    free(p);
    st->ops->free(st);
}

static void *acceptor_main(void *arg)
{
    sy_cluster_server *s = arg;
    for (;;) {
        sy_cluster_stream *st = NULL;
        char msg[160] = "";
        sy_stream_status rv = s->listener->ops->accept(s->listener, &st, msg, sizeof msg);
        if (rv == SY_STREAM_CLOSED) break;
        if (rv != SY_STREAM_OK) {
            sy_clu_slog_noise(s, SY_LOG_WARNING, "%s", msg);
            struct timespec ts = {0, 20000000L}; /* e.g. out of descriptors: do not spin */
            nanosleep(&ts, NULL);
            continue;
        }
        peer_start(s, st);
    }
    return NULL;
}

sy_result sy_cluster_server_run(sy_cluster_server *s, sy_error *err)
{
    double start = sy_time_now();
    SLOG(s, "listening on %s (port %d)%s; blob cache %zu MiB; frames <= %zu KiB, messages <= %zu MiB, peers' "
            "messages <= %zu MiB in all; <= %u unauthenticated connections, handshake deadline %u ms",
         s->o.listen_url ? s->o.listen_url : SY_CLUSTER_DEFAULT_URL, s->port,
         s->secret ? ", shared-secret authentication" : ", no secret: loopback peers only", s->cache.budget >> 20,
         s->max_frame >> 10, s->max_message >> 20, s->max_peer_memory >> 20, s->max_unauth, s->handshake_ms);
    pthread_mutex_lock(&s->qlock);
    s->stopping = false;
    pthread_mutex_unlock(&s->qlock);
    if (!s->acceptor_started) {
        if (pthread_create(&s->acceptor, NULL, acceptor_main, s) != 0)
            return sy_error_set(err, SY_ERR_IO, "sy serve: cannot start the accepting thread");
        s->acceptor_started = true;
    }
    for (;;) {
        if (s->o.stop && *s->o.stop) break;
        if (s->o.max_lifetime_s > 0 && sy_time_now() - start > s->o.max_lifetime_s) {
            SLOG(s, "maximum lifetime of %.0f s reached, stopping", s->o.max_lifetime_s);
            break;
        }
        reap_peers(s);
        pthread_mutex_lock(&s->qlock);
        if (!s->qhead) {
            struct timespec ts;
            clock_gettime(CLOCK_REALTIME, &ts);
            ts.tv_nsec += 100000000L;
            if (ts.tv_nsec >= 1000000000L) ts.tv_sec++, ts.tv_nsec -= 1000000000L;
            pthread_cond_timedwait(&s->qcond, &s->qlock, &ts);
        }
        peer *job = s->qhead;
        if (job) {
            s->qhead = job->qnext;
            if (!s->qhead) s->qtail = NULL;
        }
        pthread_mutex_unlock(&s->qlock);
        if (!job) continue;
        sy_clu_serve_job(s, job);
        pthread_mutex_lock(&s->qlock);
        job->done = true;
        pthread_cond_broadcast(&s->dcond);
        pthread_mutex_unlock(&s->qlock);
    }
    /* stop: no new connections, every connection closed, every reader thread joined */
    s->listener->ops->close(s->listener);
    if (s->acceptor_started) pthread_join(s->acceptor, NULL);
    s->acceptor_started = false;
    pthread_mutex_lock(&s->qlock);
    s->stopping = true;
    for (peer *j = s->qhead; j; j = j->qnext) {
        j->reply.size = 0;
        j->done = true;
    }
    s->qhead = s->qtail = NULL;
    pthread_cond_broadcast(&s->dcond);
    pthread_mutex_unlock(&s->qlock);
    pthread_mutex_lock(&s->mem_lock);
    s->mem_stopping = true;
    pthread_cond_broadcast(&s->mem_cond);
    pthread_mutex_unlock(&s->mem_lock);
    pthread_mutex_lock(&s->lock);
    for (peer *p = s->peers; p; p = p->next) p->w.st->ops->close(p->w.st);
    pthread_mutex_unlock(&s->lock);
    for (;;) {
        reap_peers(s);
        pthread_mutex_lock(&s->lock);
        bool left = s->peers != NULL;
        pthread_mutex_unlock(&s->lock);
        if (!left) break;
        struct timespec ts = {0, 5000000L};
        nanosleep(&ts, NULL);
    }
    return SY_OK;
}
