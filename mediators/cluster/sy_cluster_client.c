/* sy_cluster_client.c — the cluster client's connections (sy_cluster_client_*): dial and handshake
 * (HELLO / CHALLENGE / AUTH / WELCOME: the server proves the secret too), one request / reply
 * exchange under the deadline and the server's limits, create (every server dialled), destroy
 * (BYE). The per-frame work is sy_cluster_frame.c. */
#include "sy_cluster_internal.h"

#include <sodium.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void sy_clu_conn_close(conn *k)
{
    if (k->w.st) k->w.st->ops->free(k->w.st);
    sodium_memzero(k->w.key, sizeof k->w.key);
    memset(&k->w, 0, sizeof k->w);
    k->live = k->session_open = false;
    k->ahead.size = 0; /* a request sent ahead dies with the connection */
    k->last_req.size = 0;
}

void sy_clu_conn_drop(sy_cluster_client *c, conn *k, const char *what, const char *why)
{
    CWARN(c, "%s: %s: %s", k->url, what, why);
    sy_clu_conn_close(k);
    if (k->has_consumer) sy_scene_consumer_remove(c->scene, k->consumer);
    k->has_consumer = false;
}

/* Bytes a message body may have on this connection (what the server accepts). */
static uint64_t conn_body_limit(const conn *k)
{
    return k->session_open ? k->srv_max_message : SY_CLUSTER_HANDSHAKE_MAX_FRAME - SY_CLUSTER_HEADER_SIZE;
}

/* The deadline of a request sent now (or of an answer awaited from now). */
static double conn_deadline(const sy_cluster_client *c, const conn *k)
{
    return sy_time_now() + (k->session_open ? c->timeout_ms : c->connect_timeout_ms) / 1000.0;
}

/* Sends one encoded (untagged) message within the deadline, refusing one larger than the server
 * accepts. */
static sy_result conn_send(sy_cluster_client *c, conn *k, const sy_cluster_buf *b, double deadline, sy_error *err)
{
    (void)c;
    if (!k->w.st) return sy_error_set(err, SY_ERR_IO, "%s: not connected", k->url);
    if (b->size - SY_CLUSTER_HEADER_SIZE > conn_body_limit(k))
        return sy_error_set(err, SY_ERR_LIMIT, "%s: a %s of %zu bytes exceeds the server's message limit of %llu", k->url,
                            sy_cluster_msg_type_name((uint32_t)b->data[6] | ((uint32_t)b->data[7] << 8)),
                            b->size - SY_CLUSTER_HEADER_SIZE, (unsigned long long)conn_body_limit(k));
    uint64_t seq0 = k->w.send_seq;
    size_t max_frame = k->session_open ? k->srv_max_frame : SY_CLUSTER_HANDSHAKE_MAX_FRAME;
    sy_result r = sy_clu_wire_send(&k->w, b->data, b->size, max_frame, deadline, 0, k->url, err);
    uint64_t frames = k->w.send_seq - seq0; /* headers and tags of every frame, plus the body */
    if (frames)
        k->bytes_sent += b->size + (frames - 1) * SY_CLUSTER_HEADER_SIZE + (k->w.tagged ? frames * SY_CLUSTER_TAG_SIZE : 0);
    return r;
}

sy_result sy_clu_conn_send_ahead(sy_cluster_client *c, conn *k, uint64_t frame, uint32_t job, sy_error *err)
{
    k->ahead_frame = frame;
    k->ahead_job = job;
    sy_result r = conn_send(c, k, &k->ahead, conn_deadline(c, k), err);
    if (r) k->ahead.size = 0;
    return r;
}

sy_result sy_clu_conn_drain(sy_cluster_client *c, conn *k, sy_error *err)
{
    if (!k->ahead.size) return SY_OK;
    k->ahead.size = 0;
    sy_cluster_msg rep;
    uint8_t *raw = NULL;
    sy_result r = sy_clu_conn_recv(c, k, SY_CLUSTER_TILES, &rep, &raw, err);
    if (r) return r;
    if (rep.u.tiles.frame != k->ahead_frame || rep.u.tiles.job != k->ahead_job)
        r = sy_error_set(err, SY_ERR_PROTOCOL, "%s: answer for frame %llu job %u, while the request sent ahead was frame %llu job %u",
                         k->url, (unsigned long long)rep.u.tiles.frame, rep.u.tiles.job,
                         (unsigned long long)k->ahead_frame, k->ahead_job);
    else k->ahead_dropped++;
    sy_cluster_msg_free(&rep);
    free(raw);
    return r;
}

sy_result sy_clu_conn_request(sy_cluster_client *c, conn *k, const sy_cluster_msg *req, sy_error *err)
{
    sy_result r = sy_clu_conn_drain(c, k, err);
    sy_cluster_buf buf = {0};
    if (r == SY_OK) r = sy_cluster_encode(req, 0, &buf, err);
    if (r == SY_OK) r = conn_send(c, k, &buf, conn_deadline(c, k), err);
    sy_cluster_buf_free(&buf);
    return r;
}

/* One request/reply exchange within timeout_ms (the handshake's deadline before the session is
 * open); an answer still owed to a request sent ahead is received and dropped first
 * (sy_clu_conn_drain). *reply borrows *raw (free it with free() after sy_cluster_msg_free). */
sy_result sy_clu_conn_call(sy_cluster_client *c, conn *k, sy_cluster_msg *req, const sy_cluster_buf *preencoded,
                           uint32_t expect, sy_cluster_msg *reply, uint8_t **raw, sy_error *err)
{
    *raw = NULL;
    memset(reply, 0, sizeof *reply);
    if (!k->w.st) return sy_error_set(err, SY_ERR_IO, "%s: not connected", k->url);
    sy_result r = sy_clu_conn_drain(c, k, err);
    if (r) return r;
    double deadline = conn_deadline(c, k);
    sy_cluster_buf buf = {0};
    const sy_cluster_buf *b = preencoded;
    if (!b) {
        r = sy_cluster_encode(req, 0, &buf, err);
        b = &buf;
    }
    if (r == SY_OK) r = conn_send(c, k, b, deadline, err);
    sy_cluster_buf_free(&buf);
    if (r) return r;
    return sy_clu_conn_recv_until(c, k, expect, deadline, reply, raw, err);
}

sy_result sy_clu_conn_recv(sy_cluster_client *c, conn *k, uint32_t expect, sy_cluster_msg *reply, uint8_t **raw,
                           sy_error *err)
{
    return sy_clu_conn_recv_until(c, k, expect, conn_deadline(c, k), reply, raw, err);
}

sy_result sy_clu_conn_recv_until(sy_cluster_client *c, conn *k, uint32_t expect, double deadline, sy_cluster_msg *reply,
                                 uint8_t **raw, sy_error *err)
{
    *raw = NULL;
    memset(reply, 0, sizeof *reply);
    if (!k->w.st) return sy_error_set(err, SY_ERR_IO, "%s: not connected", k->url);
    sy_result r;
    const sy_cluster_budget budget = k->session_open
                                         ? (sy_cluster_budget){c->max_frame, c->max_message, true, k->w.tagged}
                                         : (sy_cluster_budget){SY_CLUSTER_HANDSHAKE_MAX_FRAME,
                                                               SY_CLUSTER_HANDSHAKE_MAX_FRAME, false, false};
    rx_msg in;
    uint64_t rseq0 = k->w.recv_seq;
    r = sy_clu_wire_recv(&k->w, &budget, NULL, 0, NULL, deadline, 0, &in, k->url, err);
    if (r) {
        if (k->w.last_rv == SY_STREAM_TIMEDOUT) sy_error_set(err, SY_ERR_IO, "%s: no reply before the deadline", k->url);
        return r;
    }
    k->bytes_received += in.size + (k->w.recv_seq - rseq0) * SY_CLUSTER_HEADER_SIZE +
                         (k->w.tagged ? (k->w.recv_seq - rseq0) * SY_CLUSTER_TAG_SIZE : 0);
    sy_cluster_limits lim = {c->max_message};
    r = sy_cluster_decode_body(&in.h, in.body, in.size, &lim, reply, err);
    if (r) {
        sy_error_prefix(err, "%s", k->url);
    } else {
        if (reply->header.type == SY_CLUSTER_ERROR) {
            r = sy_error_set(err, SY_ERR_PROTOCOL, "%s: server rejected the request: %s", k->url, reply->u.error.reason);
        } else if (reply->header.type != expect &&
                   !(expect == SY_CLUSTER_SCENE_ACK && reply->header.type == SY_CLUSTER_BLOB_REQUEST)) {
            r = sy_error_set(err, SY_ERR_PROTOCOL, "%s: expected %s, got %s", k->url, sy_cluster_msg_type_name(expect),
                             sy_cluster_msg_type_name(reply->header.type));
        }
        if (r) sy_cluster_msg_free(reply);
    }
    if (r) free(in.body);
    else *raw = in.body;
    return r;
}

/* Dials (within the connect timeout), then HELLO / CHALLENGE (/ AUTH / WELCOME). */
sy_result sy_clu_conn_connect(sy_cluster_client *c, conn *k, sy_error *err)
{
    sy_clu_conn_close(k);
    sy_cluster_dial_opts dopts = {c->o.tls_ca_file, c->connect_timeout_ms};
    sy_result dr = sy_cluster_dial(k->url, &dopts, &k->w.st, err);
    if (dr != SY_OK) {
        sy_clu_conn_close(k);
        return dr;
    }
    sy_cluster_msg m, rep;
    memset(&m, 0, sizeof m);
    m.header.type = SY_CLUSTER_HELLO;
    uint8_t cnonce[32];
    randombytes_buf(cnonce, 32);
    memcpy(m.u.hello.nonce, cnonce, 32);
    m.u.hello.max_frame = (uint32_t)c->max_frame;
    m.u.hello.max_message = c->max_message;
    snprintf(m.u.hello.name, sizeof m.u.hello.name, "sy client");
    uint8_t *raw = NULL;
    sy_result r = sy_clu_conn_call(c, k, &m, NULL, SY_CLUSTER_CHALLENGE, &rep, &raw, err);
    if (r == SY_OK) {
        bool need = rep.u.hello.flags & 1u;
        uint8_t snonce[32];
        memcpy(snonce, rep.u.hello.nonce, 32);
        k->srv_max_frame = rep.u.hello.max_frame;
        k->srv_max_message = rep.u.hello.max_message;
        sy_cluster_msg_free(&rep);
        free(raw);
        if (need && !c->secret)
            r = sy_error_set(err, SY_ERR_PROTOCOL, "%s: server requires a shared secret (SY_CLUSTER_SECRET or --secret-file)",
                             k->url);
        else if (!need && c->secret)
            r = sy_error_set(err, SY_ERR_PROTOCOL, "%s: server does not authenticate but a secret was given; refusing",
                             k->url);
        else if (need) {
            memset(&m, 0, sizeof m);
            m.header.type = SY_CLUSTER_AUTH;
            sy_clu_mac3(m.u.auth.mac, c->secret, c->o.secret_len, "SYCP-client", snonce, cnonce);
            r = sy_clu_conn_call(c, k, &m, NULL, SY_CLUSTER_WELCOME, &rep, &raw, err);
            if (r == SY_OK) {
                uint8_t expect[32];
                sy_clu_mac3(expect, c->secret, c->o.secret_len, "SYCP-server", cnonce, snonce);
                if (crypto_verify_32(expect, rep.u.auth.mac) != 0)
                    r = sy_error_set(err, SY_ERR_PROTOCOL, "%s: the server's proof does not match (wrong secret or impostor)",
                                     k->url);
                sy_cluster_msg_free(&rep);
                free(raw);
                sy_clu_mac3(k->w.key, c->secret, c->o.secret_len, "SYCP-session", cnonce, snonce);
                k->w.tagged = true;
            }
        }
    }
    if (r) {
        sy_clu_conn_close(k);
        return r;
    }
    k->session_open = true;
    k->live = true;
    k->fresh = true;
    return SY_OK;
}

sy_result sy_cluster_client_create(sy_scene *scene, const sy_cluster_client_opts *opts, sy_cluster_client **out,
                                   sy_error *err)
{
    *out = NULL;
    if (!sy_clu_crypto_ready()) return sy_error_set(err, SY_ERR_BACKEND, "cluster: libsodium failed to initialise");
    if (!opts->url_count || opts->url_count > SY_CLUSTER_MAX_SERVERS)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cluster: between 1 and %u server URLs needed, got %u",
                            SY_CLUSTER_MAX_SERVERS, opts->url_count);
    size_t max_frame = opts->max_frame ? opts->max_frame : SY_CLUSTER_DEFAULT_MAX_FRAME;
    size_t max_message = opts->max_message ? opts->max_message : SY_CLUSTER_DEFAULT_MAX_MESSAGE;
    if (max_frame < SY_CLUSTER_MIN_FRAME || max_frame > SY_CLUSTER_MAX_FRAME_LIMIT || max_message < SY_CLUSTER_MIN_FRAME ||
        max_message > SY_CLUSTER_MAX_MESSAGE_LIMIT)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                            "cluster: frame limit %zu (64 KiB..1 GiB) or message limit %zu (>= 64 KiB) out of range",
                            max_frame, max_message);
    sy_cluster_client *c = calloc(1, sizeof *c);
    if (!c) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "cluster: out of memory");
    c->o = *opts;
    c->scene = scene;
    c->n = opts->url_count;
    c->timeout_ms = opts->timeout_ms ? opts->timeout_ms : 60000;
    c->connect_timeout_ms = opts->connect_timeout_ms ? opts->connect_timeout_ms : 5000;
    c->max_frame = max_frame;
    c->max_message = max_message;
    c->conns = calloc(c->n, sizeof *c->conns);
    if (opts->secret_len) {
        c->secret = malloc(opts->secret_len);
        if (c->secret) memcpy(c->secret, opts->secret, opts->secret_len);
    }
    if (!c->conns || (opts->secret_len && !c->secret)) {
        sy_cluster_client_destroy(c);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "cluster: out of memory");
    }
    c->o.urls = NULL;
    if (opts->tls_ca_file) {
        c->tls_ca = strdup(opts->tls_ca_file);
        if (!c->tls_ca) {
            sy_cluster_client_destroy(c);
            return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "cluster: out of memory");
        }
    }
    c->o.tls_ca_file = c->tls_ca;
    uint32_t live = 0;
    sy_error first = {0};
    for (uint32_t i = 0; i < c->n; ++i) {
        conn *k = &c->conns[i];
        if (strlen(opts->urls[i]) >= sizeof k->url) {
            sy_cluster_client_destroy(c);
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cluster: URL %u is too long", i);
        }
        sy_clu_copy_str(k->url, sizeof k->url, opts->urls[i]);
        if (opts->backends && opts->backends[i]) {
            if (strlen(opts->backends[i]) >= sizeof k->backend) {
                sy_cluster_client_destroy(c);
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cluster: back-end name of server %u is too long", i);
            }
            sy_clu_copy_str(k->backend, sizeof k->backend, opts->backends[i]);
        }
        if (opts->wall_tiles) k->wall = opts->wall_tiles[i];
        sy_error e = {0};
        if (sy_clu_conn_connect(c, k, &e) == SY_OK) live++;
        else {
            CWARN(c, "%s", e.message);
            sy_clu_copy_str(k->error, sizeof k->error, e.message);
            if (!first.code) first = e;
        }
    }
    if (!live) {
        sy_cluster_client_destroy(c);
        return sy_error_set(err, first.code ? first.code : SY_ERR_IO, "cluster: no server reachable: %s", first.message);
    }
    *out = c;
    return SY_OK;
}

uint32_t sy_cluster_client_live(const sy_cluster_client *c)
{
    uint32_t n = 0;
    for (uint32_t i = 0; i < c->n; ++i) n += c->conns[i].live;
    return n;
}

void sy_cluster_client_set_timeout(sy_cluster_client *c, uint32_t timeout_ms)
{
    c->timeout_ms = timeout_ms ? timeout_ms : 60000;
}

void sy_cluster_client_destroy(sy_cluster_client *c)
{
    if (!c) return;
    /* a round sent ahead (cooperative pipelining) is finished and its answer dropped within the
     * frames' deadline (the servers render them in parallel), so the servers see BYE, not a
     * connection closed under a reply */
    for (uint32_t i = 0; c->conns && i < c->n; ++i) {
        sy_error e = {0};
        if (c->conns[i].live && c->conns[i].ahead.size && sy_clu_conn_drain(c, &c->conns[i], &e) != SY_OK)
            sy_clu_conn_close(&c->conns[i]);
    }
    c->timeout_ms = 1000;
    for (uint32_t i = 0; c->conns && i < c->n; ++i) {
        conn *k = &c->conns[i];
        if (k->live) {
            sy_cluster_msg m, rep;
            memset(&m, 0, sizeof m);
            m.header.type = SY_CLUSTER_BYE;
            uint8_t *raw = NULL;
            sy_error e = {0};
            if (sy_clu_conn_call(c, k, &m, NULL, SY_CLUSTER_BYE, &rep, &raw, &e) == SY_OK) {
                sy_cluster_msg_free(&rep);
                free(raw);
            }
        }
        sy_clu_conn_close(k);
        sy_cluster_buf_free(&k->scene_msg);
        sy_cluster_buf_free(&k->ahead);
        sy_cluster_buf_free(&k->last_req);
        sy_blob_store_destroy(k->offered);
        if (k->has_consumer) sy_scene_consumer_remove(c->scene, k->consumer);
    }
    free(c->tls_ca);
    if (c->secret) sodium_memzero(c->secret, c->o.secret_len);
    free(c->secret);
    free(c->conns);
    free(c);
}
