/* sy_cluster_handshake.c — a connection's handshake on its reader thread: HELLO / CHALLENGE and,
 * when the server has a secret, AUTH / WELCOME (challenge-response, then the session key), under
 * the handshake deadline and a 1 KiB frame budget with nothing allocated; the per-address back-off
 * after failed authentications; ERROR replies that end a connection. */
#include "sy_cluster_internal.h"

#include <sodium.h>

#include <math.h>
#include <string.h>

static auth_fail *auth_find(auth_fail *t, const char *host)
{
    for (uint32_t i = 0; i < SY_CLUSTER_AUTH_TABLE; ++i)
        if (t[i].failures && !strcmp(t[i].host, host)) return &t[i];
    return NULL;
}

/* Seconds the host must still wait (0 = not refused). */
static double auth_refused_for(auth_fail *t, const char *host, double now)
{
    auth_fail *a = auth_find(t, host);
    return a && a->until > now ? a->until - now : 0;
}

/* Records a failure; returns the refusal window in seconds. */
static double auth_failed(auth_fail *t, const char *host, double now, uint32_t backoff_ms)
{
    auth_fail *a = auth_find(t, host);
    if (a && now - a->last > 600) a->failures = 0; /* ten quiet minutes: start over */
    if (!a) {
        a = &t[0];
        for (uint32_t i = 0; i < SY_CLUSTER_AUTH_TABLE; ++i) {
            if (!t[i].failures) {
                a = &t[i];
                break;
            }
            if (t[i].until < a->until) a = &t[i];
        }
        memset(a, 0, sizeof *a);
        sy_clu_copy_str(a->host, sizeof a->host, host);
    }
    a->failures++;
    double base = backoff_ms / 1000.0, cap = base > 60 ? base : 60;
    double wait = base * (double)(1u << (a->failures - 1 < 16 ? a->failures - 1 : 16));
    if (wait > cap) wait = cap;
    a->last = now;
    a->until = now + wait;
    return wait;
}

static void auth_succeeded(auth_fail *t, const char *host)
{
    auth_fail *a = auth_find(t, host);
    if (a) memset(a, 0, sizeof *a);
}

/* Sends an ERROR (untagged before the session is open) and ends the connection. An open session's
 * peer may still be sending the rest of a refused message: what it sends within 500 ms is read and
 * dropped first, so that it sees the ERROR instead of a reset connection. */
void sy_clu_peer_refuse(peer *p, sy_result code, const char *reason)
{
    sy_cluster_msg m;
    memset(&m, 0, sizeof m);
    m.header.type = SY_CLUSTER_ERROR;
    m.u.error.code = (uint32_t)code;
    sy_clu_copy_str(m.u.error.reason, sizeof m.u.error.reason, reason);
    sy_cluster_buf b = {0};
    sy_error e = {0};
    size_t max_frame = p->state == 2 ? p->peer_max_frame : SY_CLUSTER_HANDSHAKE_MAX_FRAME;
    if (sy_cluster_encode(&m, 0, &b, &e) == SY_OK)
        (void)sy_clu_wire_send(&p->w, b.data, b.size, max_frame, sy_time_now() + 1.0, 0, NULL, &e);
    sy_cluster_buf_free(&b);
    if (p->state == 2) {
        double until = sy_time_now() + 0.5;
        for (;;) {
            sy_cluster_iov iov = {p->hbuf, sizeof p->hbuf};
            if (sy_clu_wire_io(&p->w, false, &iov, 1, until, NULL, &e) != SY_OK) break; /* the deadline or the end */
        }
    }
}

/* HELLO (and AUTH when the server has a secret) on the reader thread, under the handshake
 * deadline and budget. Returns true when the session is open. */
bool sy_clu_peer_handshake(peer *p)
{
    sy_cluster_server *s = p->s;
    double deadline = p->accepted + s->handshake_ms / 1000.0;
    const sy_cluster_budget hb = {SY_CLUSTER_HANDSHAKE_MAX_FRAME, SY_CLUSTER_HANDSHAKE_MAX_FRAME, false, false};
    while (p->state != 2) {
        sy_error err = {0};
        rx_msg in;
        sy_result r = sy_clu_wire_recv(&p->w, &hb, p->hbuf, sizeof p->hbuf, NULL, deadline, 0, &in, NULL, &err);
        if (r) {
            if (p->w.last_rv == SY_STREAM_TIMEDOUT)
                sy_clu_slog_noise(s, SY_LOG_WARNING, "%s: closed: no %s within the %u ms handshake deadline", p->addr,
                           p->state == 0 ? "HELLO" : "AUTH", s->handshake_ms);
            else if (sy_clu_wire_closed(&p->w))
                sy_clu_slog_noise(s, SY_LOG_WARNING, "%s: disconnected during the handshake", p->addr);
            else if (p->w.last_rv) /* the connection failed (e.g. TLS): nothing can be sent */
                sy_clu_slog_noise(s, SY_LOG_WARNING, "%s: connection failed during the handshake: %s", p->addr, err.message);
            else {
                sy_clu_slog_noise(s, SY_LOG_WARNING, "%s: rejected: %s (before authentication; connection closed)", p->addr, err.message);
                sy_clu_peer_refuse(p, r, err.message);
            }
            return false;
        }
        sy_cluster_msg m, reply;
        memset(&reply, 0, sizeof reply);
        sy_cluster_limits lim = {SY_CLUSTER_HANDSHAKE_MAX_FRAME};
        r = sy_cluster_decode_body(&in.h, in.body, in.size, &lim, &m, &err);
        bool refused = r != SY_OK;
        uint32_t t = refused ? 0 : m.header.type;
        if (r == SY_OK) {
            if (t == SY_CLUSTER_HELLO && p->state == 0) {
                double wait = 0;
                if (s->secret) {
                    pthread_mutex_lock(&s->auth_lock);
                    wait = auth_refused_for(s->auth, p->host, sy_time_now());
                    pthread_mutex_unlock(&s->auth_lock);
                }
                if (!s->secret && !p->loopback) {
                    r = sy_error_set(&err, SY_ERR_PROTOCOL, "server has no secret and accepts loopback peers only");
                } else if (wait > 0) {
                    r = sy_error_set(&err, SY_ERR_PROTOCOL,
                                     "throttled: too many failed authentications from %s, retry in %.0f ms", p->host,
                                     ceil(wait * 1000));
                } else {
                    memcpy(p->cnonce, m.u.hello.nonce, 32);
                    randombytes_buf(p->snonce, 32);
                    p->peer_max_frame = m.u.hello.max_frame;
                    reply.header.type = SY_CLUSTER_CHALLENGE;
                    memcpy(reply.u.hello.nonce, p->snonce, 32);
                    reply.u.hello.flags = s->secret ? 1u : 0u;
                    reply.u.hello.max_frame = (uint32_t)s->max_frame;
                    reply.u.hello.max_message = s->max_message;
                    sy_clu_copy_str(reply.u.hello.name, sizeof reply.u.hello.name, s->name);
                    char name[SY_CLUSTER_NAME_MAX]; /* the peer's words in our log: printable only */
                    sy_clu_copy_str(name, sizeof name, m.u.hello.name);
                    for (char *c = name; *c; ++c)
                        if ((unsigned char)*c < 0x20 || (unsigned char)*c == 0x7f) *c = '?';
                    sy_clu_slog_noise(s, SY_LOG_NOTE, "%s: hello from '%s'%s", p->addr, name, s->secret ? "" : " (no secret, loopback)");
                }
            } else if (t == SY_CLUSTER_AUTH && p->state == 1) {
                uint8_t expect[32];
                sy_clu_mac3(expect, s->secret, s->o.secret_len, "SYCP-client", p->snonce, p->cnonce);
                if (crypto_verify_32(expect, m.u.auth.mac) != 0) {
                    pthread_mutex_lock(&s->auth_lock);
                    double wait = auth_failed(s->auth, p->host, sy_time_now(), s->o.auth_backoff_ms);
                    pthread_mutex_unlock(&s->auth_lock);
                    r = sy_error_set(&err, SY_ERR_PROTOCOL, "authentication failed: wrong secret (%s refused for %.0f ms)",
                                     p->host, wait * 1000);
                } else {
                    pthread_mutex_lock(&s->auth_lock);
                    auth_succeeded(s->auth, p->host);
                    pthread_mutex_unlock(&s->auth_lock);
                    reply.header.type = SY_CLUSTER_WELCOME;
                    sy_clu_mac3(reply.u.auth.mac, s->secret, s->o.secret_len, "SYCP-server", p->cnonce, p->snonce);
                }
            } else {
                r = sy_error_set(&err, SY_ERR_PROTOCOL, "%s before authentication", sy_cluster_msg_type_name(t));
            }
            sy_cluster_msg_free(&m);
        }
        if (r) {
            /* a wrong secret is worth every line (the back-off bounds them per address); garbage,
             * out-of-order and throttled HELLOs are rate-limited like any unauthenticated noise */
            if (t == SY_CLUSTER_AUTH) SWARN(s, "%s: rejected: %s (connection closed)", p->addr, err.message);
            else sy_clu_slog_noise(s, SY_LOG_WARNING, "%s: rejected: %s (connection closed)", p->addr, err.message);
            sy_clu_peer_refuse(p, r, err.message);
            return false;
        }
        sy_cluster_buf b = {0};
        r = sy_cluster_encode(&reply, 0, &b, &err);
        if (r == SY_OK) r = sy_clu_wire_send(&p->w, b.data, b.size, SY_CLUSTER_HANDSHAKE_MAX_FRAME, deadline, 0, NULL, &err);
        sy_cluster_buf_free(&b);
        if (r) {
            sy_clu_slog_noise(s, SY_LOG_WARNING, "%s: handshake reply not sent: %s", p->addr, err.message);
            return false;
        }
        if (reply.header.type == SY_CLUSTER_CHALLENGE) p->state = s->secret ? 1 : 2;
        if (reply.header.type == SY_CLUSTER_WELCOME) {
            /* from now on both directions carry tags under the session key */
            sy_clu_mac3(p->w.key, s->secret, s->o.secret_len, "SYCP-session", p->cnonce, p->snonce);
            p->w.tagged = true;
            p->state = 2;
            SLOG(s, "%s: authenticated", p->addr);
        }
    }
    return true;
}
