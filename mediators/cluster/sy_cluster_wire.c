/* sy_cluster_wire.c — frames over a transport's byte stream, shared by the server and the client:
 * a message as one or more frames, sequence numbers, per-frame tags under the session key,
 * deadlines, and the reassembly of a received message within its budget and the memory the
 * receiver grants; plus the HMAC that the handshake's proofs and the session key are made of. */
#include "sy_cluster_internal.h"

#include <sodium.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* libsodium initialised (every server and client checks before it starts) */
bool sy_clu_crypto_ready(void)
{
    return sodium_init() >= 0;
}

/* HMAC-SHA512-256(key, label || a || b) */
void sy_clu_mac3(uint8_t out[32], const uint8_t *key, size_t key_len, const char *label, const uint8_t *a,
                 const uint8_t *b)
{
    crypto_auth_hmacsha512256_state st;
    crypto_auth_hmacsha512256_init(&st, key, key_len);
    crypto_auth_hmacsha512256_update(&st, (const unsigned char *)label, strlen(label));
    crypto_auth_hmacsha512256_update(&st, a, SY_CLUSTER_NONCE_SIZE);
    crypto_auth_hmacsha512256_update(&st, b, SY_CLUSTER_NONCE_SIZE);
    crypto_auth_hmacsha512256_final(&st, out);
}

/* >>wire: frames over a transport's byte stream (shared by the server and the client)
 *
 * A message travels as one frame or, when its body is larger than the receiver's frame limit, as
 * several frames of the same type (SY_CLUSTER_FLAG_MORE on all but the last). Every frame carries
 * its own sequence number and, once the session has a key, its own tag over header + body, so a
 * forged or replayed frame is refused as soon as it has arrived, before the next one is read.
 * The receiver reads the fixed 24-byte header first and checks it against its budget
 * (sy_cluster_frame_check) before it reads or allocates anything for the body. */

/* Frees a received message's body and returns its charged bytes. */
void sy_clu_rx_release(rx_msg *m, const wire_mem *mem)
{
    if (!m->fixed) free(m->body);
    if (m->charged && mem && mem->release) mem->release(mem->user, m->charged);
    memset(m, 0, sizeof *m);
}

/* error prefix: "WHO: " or nothing (the server logs the peer's address itself) */
#define WHO(who) ((who) ? (who) : ""), ((who) ? ": " : "")

static void frame_tag_parts(uint8_t out[32], const uint8_t key[32], const uint8_t *hdr, const uint8_t *body, size_t n)
{
    crypto_auth_hmacsha512256_state st;
    crypto_auth_hmacsha512256_init(&st, key, 32);
    crypto_auth_hmacsha512256_update(&st, hdr, SY_CLUSTER_HEADER_SIZE);
    if (n) crypto_auth_hmacsha512256_update(&st, body, n);
    crypto_auth_hmacsha512256_final(&st, out);
}

/* Moves all bytes of iov[0..n) in one direction; every operation must finish by deadline
 * (absolute sy_time_now() seconds; 0 = none). */
sy_result sy_clu_wire_io(wire *w, bool sending, sy_cluster_iov *iov, unsigned n, double deadline, const char *who,
                         sy_error *err)
{
    unsigned first = 0;
    while (first < n && iov[first].len == 0) first++;
    while (first < n) {
        size_t got = 0;
        char msg[160] = "";
        sy_stream_status st = w->st->ops->io(w->st, sending, iov + first, n - first, deadline, &got, msg, sizeof msg);
        if (st == SY_STREAM_OK && got == 0) st = SY_STREAM_CLOSED, snprintf(msg, sizeof msg, "connection shut");
        if (st != SY_STREAM_OK) {
            w->last_rv = (int)st;
            if (st == SY_STREAM_TIMEDOUT)
                return sy_error_set(err, SY_ERR_IO, "%s%s%s", WHO(who),
                                    sending ? "the peer did not take the data before the deadline"
                                            : "no data before the deadline");
            return sy_error_set(err, SY_ERR_IO, "%s%s%s: %s", WHO(who), sending ? "send failed" : "receive failed", msg);
        }
        while (got && first < n) {
            size_t k = got < iov[first].len ? got : iov[first].len;
            iov[first].buf = (uint8_t *)iov[first].buf + k;
            iov[first].len -= k;
            got -= k;
            if (!iov[first].len) first++;
        }
        while (first < n && iov[first].len == 0) first++;
    }
    return SY_OK;
}

/* Sends one message. frame: an untagged frame as sy_cluster_encode writes it (header + body; its
 * sequence number and flags are ignored). The body goes out in frames of at most max_frame bytes;
 * each operation must finish within progress_s seconds (0 = no limit) and by deadline. */
sy_result sy_clu_wire_send(wire *w, const uint8_t *frame, size_t size, size_t max_frame, double deadline,
                           double progress_s, const char *who, sy_error *err)
{
    if (size < SY_CLUSTER_HEADER_SIZE) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s%sempty frame", WHO(who));
    uint32_t type = (uint32_t)frame[6] | ((uint32_t)frame[7] << 8);
    const uint8_t *body = frame + SY_CLUSTER_HEADER_SIZE;
    size_t n = size - SY_CLUSTER_HEADER_SIZE, tag = w->tagged ? SY_CLUSTER_TAG_SIZE : 0;
    if (max_frame <= SY_CLUSTER_HEADER_SIZE + tag)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s%sframe limit %zu too small", WHO(who), max_frame);
    size_t per = max_frame - SY_CLUSTER_HEADER_SIZE - tag, off = 0;
    if (per > UINT32_MAX) per = UINT32_MAX;
    do {
        size_t c = n - off < per ? n - off : per;
        bool more = off + c < n;
        uint8_t hdr[SY_CLUSTER_HEADER_SIZE], t[SY_CLUSTER_TAG_SIZE];
        sy_cluster_header_write(hdr, type, (w->tagged ? SY_CLUSTER_FLAG_TAGGED : 0u) | (more ? SY_CLUSTER_FLAG_MORE : 0u),
                                (uint32_t)c, ++w->send_seq);
        if (w->tagged) frame_tag_parts(t, w->key, hdr, body + off, c);
        sy_cluster_iov iov[3] = {{hdr, sizeof hdr}, {(void *)(body + off), c}, {t, tag}};
        double d = deadline;
        if (progress_s > 0 && (d <= 0 || sy_time_now() + progress_s < d)) d = sy_time_now() + progress_s;
        sy_result r = sy_clu_wire_io(w, true, iov, 3, d, who, err);
        if (r) return r;
        off += c;
    } while (off < n);
    return SY_OK;
}

/* Receives one message within budget b. fixed (fixed_cap bytes) receives the body when given
 * (the handshake: nothing is allocated); otherwise the body grows frame by frame, each growth
 * reserved from mem first. The first header must arrive by deadline (0 = wait for ever); once it
 * has, every further operation must finish within progress_s (0 = by deadline). Sequence numbers
 * and tags are checked frame by frame. On failure w->last_rv tells a closed connection (sy_stream_status)
 * from a refused frame (0). */
sy_result sy_clu_wire_recv(wire *w, const sy_cluster_budget *b, uint8_t *fixed, size_t fixed_cap, const wire_mem *mem,
                           double deadline, double progress_s, rx_msg *out, const char *who, sy_error *err)
{
    memset(out, 0, sizeof *out);
    out->fixed = fixed != NULL;
    out->body = fixed;
    out->cap = fixed ? fixed_cap : 0;
    size_t so_far = 0;
    uint32_t type = 0;
    sy_result r = SY_OK;
    w->last_rv = 0;
    for (;;) {
        uint8_t hdr[SY_CLUSTER_HEADER_SIZE];
        double d = deadline;
        if (type && progress_s > 0 && (d <= 0 || sy_time_now() + progress_s < d)) d = sy_time_now() + progress_s;
        sy_cluster_iov iov[2] = {{hdr, sizeof hdr}, {NULL, 0}};
        r = sy_clu_wire_io(w, false, iov, 1, d, who, err);
        if (r) goto fail;
        if (progress_s > 0 && (deadline <= 0 || sy_time_now() + progress_s < deadline))
            d = sy_time_now() + progress_s;
        else d = deadline;
        sy_cluster_header h;
        size_t follow = 0;
        r = sy_cluster_parse_header(hdr, &h, err);
        if (r == SY_OK) r = sy_cluster_frame_check(&h, b, so_far, type, &follow, err);
        if (r == SY_OK && h.seq != w->recv_seq + 1)
            r = sy_error_set(err, SY_ERR_PROTOCOL, "cluster %s: sequence number %llu, expected %llu (replay or loss)",
                             sy_cluster_msg_type_name(h.type), (unsigned long long)h.seq,
                             (unsigned long long)(w->recv_seq + 1));
        if (r) {
            if (who) sy_error_prefix(err, "%s", who);
            goto fail;
        }
        size_t need = so_far + h.body_size; /* <= b->max_message: checked */
        if (need > out->cap) {
            if (out->fixed) { /* cannot happen when the budget fits the buffer */
                r = sy_error_set(err, SY_ERR_LIMIT, "%s%sframe of %u bytes does not fit the %zu-byte buffer", WHO(who),
                                 h.body_size, fixed_cap);
                goto fail;
            }
            size_t ncap = need;
            if (h.flags & SY_CLUSTER_FLAG_MORE) { /* more frames follow: grow geometrically, within the limit */
                size_t dbl = out->cap > b->max_message / 2 ? b->max_message : out->cap * 2;
                if (dbl > ncap) ncap = dbl;
            }
            size_t extra = ncap - out->cap;
            if (mem && mem->reserve && !mem->reserve(mem->user, extra, err)) {
                r = SY_ERR_LIMIT;
                sy_error_prefix(err, "%s%s%s frame of %u bytes", WHO(who), sy_cluster_msg_type_name(h.type), h.body_size);
                goto fail;
            }
            uint8_t *nb = realloc(out->body, ncap ? ncap : 1);
            if (!nb) {
                if (mem && mem->release) mem->release(mem->user, extra);
                r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s%sout of memory for a %zu-byte message", WHO(who), ncap);
                goto fail;
            }
            out->body = nb;
            out->cap = ncap;
            if (mem && mem->reserve) out->charged += extra;
        }
        uint8_t tag[SY_CLUSTER_TAG_SIZE];
        size_t tag_len = follow - h.body_size;
        sy_cluster_iov biov[2] = {{out->body ? out->body + so_far : NULL, h.body_size}, {tag, tag_len}};
        r = sy_clu_wire_io(w, false, biov, 2, d, who, err);
        if (r) goto fail;
        if (tag_len) {
            uint8_t expect[SY_CLUSTER_TAG_SIZE];
            frame_tag_parts(expect, w->key, hdr, out->body ? out->body + so_far : NULL, h.body_size);
            if (crypto_verify_32(expect, tag) != 0) {
                r = sy_error_set(err, SY_ERR_PROTOCOL, "%s%scluster %s: authentication tag does not match", WHO(who),
                                 sy_cluster_msg_type_name(h.type));
                goto fail;
            }
        }
        w->recv_seq = h.seq;
        if (!type) out->h = h;
        type = h.type;
        so_far = need;
        if (!(h.flags & SY_CLUSTER_FLAG_MORE)) break;
    }
    out->size = so_far;
    out->h.body_size = so_far > UINT32_MAX ? UINT32_MAX : (uint32_t)so_far;
    out->h.flags &= ~(uint32_t)SY_CLUSTER_FLAG_MORE;
    return SY_OK;
fail:
    sy_clu_rx_release(out, mem);
    return r;
}
