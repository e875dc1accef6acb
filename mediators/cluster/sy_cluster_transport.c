/* sy_cluster_transport.c — the transport registry and the built-in nng transport (TCP, TLS over
 * TCP, IPC): nng byte streams driven by one aio per stream, with deadlines and a watchdog (see
 * sy_cluster_transport.h). */
#include "sy_cluster_transport.h"

#include <nng/nng.h>
#include <nng/supplemental/tls/tls.h>
#include <nng/transport/tcp/tcp.h>

#include <arpa/inet.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* A stream operation past its deadline by this much closes the stream (see nng_wait). */
#define WATCHDOG_MS 250u

/* >>registry */
#define TRANSPORTS_MAX 8
static pthread_mutex_t g_lock = PTHREAD_MUTEX_INITIALIZER;
static const sy_cluster_transport *g_transports[TRANSPORTS_MAX];
static uint32_t g_count;

sy_result sy_cluster_transport_register(const sy_cluster_transport *t, sy_error *err)
{
    if (!t || !t->scheme || !t->listen || !t->dial)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cluster transport: incomplete table");
    sy_result r = SY_OK;
    pthread_mutex_lock(&g_lock);
    for (uint32_t i = 0; i < g_count; ++i)
        if (!strcmp(g_transports[i]->scheme, t->scheme))
            r = g_transports[i] == t ? SY_OK
                                     : sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cluster transport '%s' is already registered",
                                                    t->scheme);
    if (r == SY_OK) {
        bool known = false;
        for (uint32_t i = 0; i < g_count; ++i) known = known || g_transports[i] == t;
        if (!known && g_count == TRANSPORTS_MAX) r = sy_error_set(err, SY_ERR_LIMIT, "cluster transport: registry full");
        else if (!known) g_transports[g_count++] = t;
    }
    pthread_mutex_unlock(&g_lock);
    return r;
}

static bool scheme_is(const char *url, const char *scheme)
{
    size_t n = strlen(scheme);
    return !strncmp(url, scheme, n) && !strncmp(url + n, "://", 3);
}

static const sy_cluster_transport nng_transport;

const sy_cluster_transport *sy_cluster_transport_for(const char *url)
{
    const sy_cluster_transport *t = NULL;
    pthread_mutex_lock(&g_lock);
    for (uint32_t i = 0; i < g_count && !t; ++i)
        if (g_transports[i]->matches ? g_transports[i]->matches(url) : scheme_is(url, g_transports[i]->scheme))
            t = g_transports[i];
    pthread_mutex_unlock(&g_lock);
    return t ? t : &nng_transport;
}

sy_result sy_cluster_listen(const char *url, const sy_cluster_listen_opts *o, sy_cluster_listener **out, sy_error *err)
{
    static const sy_cluster_listen_opts none = {0};
    *out = NULL;
    return sy_cluster_transport_for(url)->listen(url, o ? o : &none, out, err);
}

sy_result sy_cluster_dial(const char *url, const sy_cluster_dial_opts *o, sy_cluster_stream **out, sy_error *err)
{
    static const sy_cluster_dial_opts none = {0};
    *out = NULL;
    return sy_cluster_transport_for(url)->dial(url, o ? o : &none, out, err);
}

/* >>nng streams */
typedef struct nng_strm {
    sy_cluster_stream base;
    nng_stream *st;
    nng_stream_dialer *dialer; /* client streams: kept with the stream */
    nng_aio *aio;          /* completes through strm_done (busy, cond) */
    pthread_mutex_t lock;
    pthread_cond_t cond;   /* CLOCK_MONOTONIC */
    bool busy;
} nng_strm;

static void strm_done(void *arg)
{
    nng_strm *s = arg;
    pthread_mutex_lock(&s->lock);
    s->busy = false;
    pthread_cond_broadcast(&s->cond);
    pthread_mutex_unlock(&s->lock);
}

static bool sockaddr_is_loopback(const nng_sockaddr *sa)
{
    if (sa->s_family == NNG_AF_INET) return (ntohl(sa->s_in.sa_addr) >> 24) == 127;
    if (sa->s_family == NNG_AF_INET6) {
        static const uint8_t lo6[16] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1};
        return memcmp(sa->s_in6.sa_addr, lo6, 16) == 0;
    }
    return sa->s_family == NNG_AF_INPROC || sa->s_family == NNG_AF_IPC;
}

/* "1.2.3.4:port" / "[::1]:port"; with_port false: the host alone (the key of the back-off table) */
static void sockaddr_str(const nng_sockaddr *sa, bool with_port, char *buf, size_t n)
{
    if (sa->s_family == NNG_AF_INET) {
        char a[INET_ADDRSTRLEN];
        struct in_addr ia = {sa->s_in.sa_addr};
        inet_ntop(AF_INET, &ia, a, sizeof a);
        if (with_port) snprintf(buf, n, "%s:%u", a, (unsigned)ntohs(sa->s_in.sa_port));
        else snprintf(buf, n, "%s", a);
    } else if (sa->s_family == NNG_AF_INET6) {
        char a[INET6_ADDRSTRLEN];
        inet_ntop(AF_INET6, sa->s_in6.sa_addr, a, sizeof a);
        if (with_port) snprintf(buf, n, "[%s]:%u", a, (unsigned)ntohs(sa->s_in6.sa_port));
        else snprintf(buf, n, "%s", a);
    } else snprintf(buf, n, "local peer");
}

static const sy_cluster_stream_ops nng_stream_ops;

/* Gives the record its connected stream and the peer's address (for the log and the back-off). */
static void strm_attach(nng_strm *s, nng_stream *st)
{
    s->st = st;
    nng_sockaddr sa;
    memset(&sa, 0, sizeof sa);
    if (nng_stream_get_addr(st, NNG_OPT_REMADDR, &sa) == 0) {
        sockaddr_str(&sa, true, s->base.peer, sizeof s->base.peer);
        sockaddr_str(&sa, false, s->base.host, sizeof s->base.host);
        s->base.loopback = sockaddr_is_loopback(&sa);
    } else {
        snprintf(s->base.peer, sizeof s->base.peer, "unknown peer");
        snprintf(s->base.host, sizeof s->base.host, "unknown peer");
    }
}

/* A stream record for st (NULL: connected later, strm_attach). NULL when out of memory; st is then
 * left to the caller. */
static nng_strm *strm_new(nng_stream *st)
{
    nng_strm *s = calloc(1, sizeof *s);
    if (!s) return NULL;
    pthread_condattr_t ca;
    pthread_condattr_init(&ca);
    pthread_condattr_setclock(&ca, CLOCK_MONOTONIC);
    pthread_mutex_init(&s->lock, NULL);
    pthread_cond_init(&s->cond, &ca);
    pthread_condattr_destroy(&ca);
    if (nng_aio_alloc(&s->aio, strm_done, s) != 0) {
        pthread_mutex_destroy(&s->lock);
        pthread_cond_destroy(&s->cond);
        free(s);
        return NULL;
    }
    s->base.ops = &nng_stream_ops;
    if (st) strm_attach(s, st);
    return s;
}

/* Runs the operation set up on s->aio to completion. The aio's own timeout ends it at the deadline;
 * in case the stream does not honour it (nng 1.5.2's TLS streams leave a receive pending forever once
 * the TCP connection under them has failed), the stream is closed WATCHDOG_MS after the deadline,
 * which completes every pending operation. */
static int strm_wait(nng_strm *s, double deadline)
{
    bool forced = false;
    pthread_mutex_lock(&s->lock);
    while (s->busy) {
        if (deadline <= 0) {
            pthread_cond_wait(&s->cond, &s->lock);
            continue;
        }
        double until = deadline + WATCHDOG_MS / 1000.0;
        struct timespec now;
        clock_gettime(CLOCK_MONOTONIC, &now);
        double left = until - sy_time_now();
        if (left <= 0) {
            forced = true;
            break;
        }
        long ns = now.tv_nsec + (long)((left - (double)(long)left) * 1e9);
        struct timespec ts = {now.tv_sec + (time_t)left + ns / 1000000000L, ns % 1000000000L};
        pthread_cond_timedwait(&s->cond, &s->lock, &ts);
    }
    pthread_mutex_unlock(&s->lock);
    if (forced && s->st) nng_stream_close(s->st); /* every pending operation completes (NNG_ECLOSED) */
    nng_aio_wait(s->aio);
    int rv = nng_aio_result(s->aio);
    return forced && rv ? NNG_ETIMEDOUT : rv;
}

static sy_stream_status status_of(int rv)
{
    if (rv == NNG_ETIMEDOUT) return SY_STREAM_TIMEDOUT;
    if (rv == NNG_ECLOSED || rv == NNG_ECONNSHUT || rv == NNG_ECONNRESET || rv == NNG_ECONNABORTED)
        return SY_STREAM_CLOSED;
    return SY_STREAM_FAILED;
}

static sy_stream_status strm_io(sy_cluster_stream *base, bool send, const sy_cluster_iov *iov, unsigned n,
                                double deadline, size_t *moved, char *msg, size_t msg_len)
{
    nng_strm *s = (nng_strm *)base;
    *moved = 0;
    nng_iov v[4];
    if (n > 4) n = 4;
    for (unsigned i = 0; i < n; ++i) v[i] = (nng_iov){iov[i].buf, iov[i].len};
    nng_duration ms = NNG_DURATION_INFINITE;
    if (deadline > 0) {
        double left = deadline - sy_time_now();
        ms = left <= 0.001 ? 1 : (nng_duration)(left * 1000.0 + 0.5);
    }
    int rv = nng_aio_set_iov(s->aio, n, v);
    if (rv == 0) {
        nng_aio_set_timeout(s->aio, ms);
        pthread_mutex_lock(&s->lock);
        s->busy = true;
        pthread_mutex_unlock(&s->lock);
        if (send) nng_stream_send(s->st, s->aio);
        else nng_stream_recv(s->st, s->aio);
        rv = strm_wait(s, deadline);
    }
    if (rv == 0) *moved = nng_aio_count(s->aio);
    if (rv == 0 && *moved == 0) rv = NNG_ECONNSHUT;
    if (rv) snprintf(msg, msg_len, "%s", nng_strerror(rv));
    return rv ? status_of(rv) : SY_STREAM_OK;
}

static void strm_close(sy_cluster_stream *base)
{
    nng_strm *s = (nng_strm *)base;
    if (s->st) nng_stream_close(s->st);
}

static void strm_free(sy_cluster_stream *base)
{
    nng_strm *s = (nng_strm *)base;
    if (!s) return;
    if (s->st) nng_stream_close(s->st);
    if (s->aio) nng_aio_free(s->aio); /* waits for a pending operation */
    if (s->st) nng_stream_free(s->st);
    if (s->dialer) nng_stream_dialer_free(s->dialer);
    pthread_mutex_destroy(&s->lock);
    pthread_cond_destroy(&s->cond);
    free(s);
}

static const sy_cluster_stream_ops nng_stream_ops = {strm_io, strm_close, strm_free};

/* >>nng listener */
typedef struct nng_lst {
    sy_cluster_listener base;
    nng_stream_listener *l;
    nng_tls_config *tls;
    nng_aio *aio;
} nng_lst;

static sy_stream_status lst_accept(sy_cluster_listener *base, sy_cluster_stream **out, char *msg, size_t msg_len)
{
    nng_lst *l = (nng_lst *)base;
    *out = NULL;
    nng_stream_listener_accept(l->l, l->aio);
    nng_aio_wait(l->aio);
    int rv = nng_aio_result(l->aio);
    if (rv == NNG_ECLOSED || rv == NNG_ECANCELED) return SY_STREAM_CLOSED;
    if (rv) {
        snprintf(msg, msg_len, "accept failed: %s", nng_strerror(rv));
        return SY_STREAM_FAILED;
    }
    nng_stream *st = nng_aio_get_output(l->aio, 0);
    nng_strm *s = strm_new(st);
    if (!s) {
        nng_stream_close(st);
        nng_stream_free(st);
        snprintf(msg, msg_len, "connection dropped: out of memory");
        return SY_STREAM_FAILED;
    }
    *out = &s->base;
    return SY_STREAM_OK;
}

static void lst_close(sy_cluster_listener *base) { nng_stream_listener_close(((nng_lst *)base)->l); }

static void lst_free(sy_cluster_listener *base)
{
    nng_lst *l = (nng_lst *)base;
    if (!l) return;
    if (l->l) nng_stream_listener_close(l->l);
    if (l->aio) nng_aio_free(l->aio);
    if (l->l) nng_stream_listener_free(l->l);
    if (l->tls) nng_tls_config_free(l->tls);
    free(l);
}

static const sy_cluster_listener_ops nng_listener_ops = {lst_accept, lst_close, lst_free};

static sy_result tr_nng_listen(const char *url, const sy_cluster_listen_opts *o, sy_cluster_listener **out, sy_error *err)
{
    nng_lst *l = calloc(1, sizeof *l);
    if (!l) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "sy serve: out of memory");
    l->base.ops = &nng_listener_ops;
    int rv = nng_aio_alloc(&l->aio, NULL, NULL);
    if (rv == 0) rv = nng_stream_listener_alloc(&l->l, url);
    if (rv != 0) {
        lst_free(&l->base);
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "sy serve: %s: %s", url, nng_strerror(rv));
    }
    if (!strncmp(url, "tls+tcp://", 10)) {
        if (!o->tls_cert_pem || !o->tls_key_pem) {
            lst_free(&l->base);
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "sy serve: %s: TLS needs --tls-cert and --tls-key", url);
        }
        rv = nng_tls_config_alloc(&l->tls, NNG_TLS_MODE_SERVER);
        if (rv == 0) rv = nng_tls_config_own_cert(l->tls, o->tls_cert_pem, o->tls_key_pem, NULL);
        if (rv == 0) rv = nng_stream_listener_set_ptr(l->l, NNG_OPT_TLS_CONFIG, l->tls);
        if (rv != 0) {
            lst_free(&l->base);
            return sy_error_set(err, rv == NNG_ENOTSUP ? SY_ERR_UNSUPPORTED : SY_ERR_INVALID_ARGUMENT,
                                "sy serve: TLS certificate / key: %s", nng_strerror(rv));
        }
    }
    nng_stream_listener_set_bool(l->l, NNG_OPT_TCP_NODELAY, true);
    if ((rv = nng_stream_listener_listen(l->l)) != 0) {
        lst_free(&l->base);
        return sy_error_set(err, SY_ERR_IO, "sy serve: cannot listen on %s: %s", url, nng_strerror(rv));
    }
    nng_sockaddr la;
    memset(&la, 0, sizeof la);
    nng_stream_listener_get_addr(l->l, NNG_OPT_LOCADDR, &la);
    l->base.loopback = sockaddr_is_loopback(&la);
    nng_stream_listener_get_int(l->l, NNG_OPT_TCP_BOUND_PORT, &l->base.port);
    *out = &l->base;
    return SY_OK;
}

/* >>nng dialer */
static sy_result tr_nng_dial(const char *url, const sy_cluster_dial_opts *o, sy_cluster_stream **out, sy_error *err)
{
    nng_stream_dialer *d = NULL;
    nng_strm *s = strm_new(NULL);
    int rv = s ? nng_stream_dialer_alloc(&d, url) : NNG_ENOMEM;
    if (rv) {
        if (s) strm_free(&s->base);
        return sy_error_set(err, rv == NNG_ENOMEM ? SY_ERR_OUT_OF_MEMORY : SY_ERR_INVALID_ARGUMENT, "%s: %s", url,
                            nng_strerror(rv));
    }
    if (!strncmp(url, "tls+tcp://", 10)) {
        if (!o->tls_ca_file) {
            nng_stream_dialer_free(d);
            strm_free(&s->base);
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: a TLS server needs --tls-ca", url);
        }
        /* the certificate must be valid for the host named in the URL */
        char host[256];
        const char *h = url + 10, *end = strrchr(h, ':');
        size_t hn = end ? (size_t)(end - h) : strlen(h);
        if (hn && h[0] == '[' && h[hn - 1] == ']') h++, hn -= 2;
        if (hn >= sizeof host) hn = sizeof host - 1;
        memcpy(host, h, hn);
        host[hn] = 0;
        nng_tls_config *cfg = NULL;
        if ((rv = nng_tls_config_alloc(&cfg, NNG_TLS_MODE_CLIENT)) != 0 || (rv = nng_tls_config_ca_file(cfg, o->tls_ca_file)) != 0 ||
            (rv = nng_tls_config_auth_mode(cfg, NNG_TLS_AUTH_MODE_REQUIRED)) != 0 ||
            (rv = nng_tls_config_server_name(cfg, host)) != 0 || (rv = nng_stream_dialer_set_ptr(d, NNG_OPT_TLS_CONFIG, cfg)) != 0) {
            if (cfg) nng_tls_config_free(cfg);
            nng_stream_dialer_free(d);
            strm_free(&s->base);
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: TLS with CA %s: %s", url, o->tls_ca_file, nng_strerror(rv));
        }
        nng_tls_config_free(cfg); /* the dialer holds its own reference */
    }
    nng_stream_dialer_set_bool(d, NNG_OPT_TCP_NODELAY, true);
    nng_aio_set_timeout(s->aio, o->timeout_ms ? (nng_duration)o->timeout_ms : NNG_DURATION_INFINITE);
    pthread_mutex_lock(&s->lock);
    s->busy = true;
    pthread_mutex_unlock(&s->lock);
    nng_stream_dialer_dial(d, s->aio);
    nng_aio_wait(s->aio); /* the dialer honours the timeout (no stream yet to close) */
    rv = nng_aio_result(s->aio);
    if (rv == 0) {
        strm_attach(s, nng_aio_get_output(s->aio, 0));
        s->dialer = d; /* kept with its stream */
    } else nng_stream_dialer_free(d);
    if (rv) {
        strm_free(&s->base);
        return sy_error_set(err, SY_ERR_IO, "%s: cannot connect: %s", url,
                            rv == NNG_ETIMEDOUT ? "no answer before the deadline" : nng_strerror(rv));
    }
    *out = &s->base;
    return SY_OK;
}

static const sy_cluster_transport nng_transport = {.scheme = "tcp", .listen = tr_nng_listen, .dial = tr_nng_dial};
