/* raw_peer.h — plain-socket cluster peers for the tests: connect to a 127.0.0.1 port, write
 * frames or arbitrary bytes, read (and reassemble) the server's frames of an untagged session.
 * Header-only (static functions); every call is bounded by the socket timeouts set at connect.
 * Used by test_cluster_net.c (messages a client library would never send), test_cluster_coop.c
 * (a fake server that misbehaves under pipelining) and
 * test_cluster_hostile.c (hostile connections). Thread-safety: one fd per thread. */
#ifndef SY_TEST_RAW_PEER_H
#define SY_TEST_RAW_PEER_H

#include "sy_cluster.h"

#include "../../apps/sy/sy_bench_os.h" /* sy_bench_loopback_connect */

#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <time.h>
#include <unistd.h>

/* A TCP connection to 127.0.0.1:port with send / receive timeouts; -1 on failure (from another
 * loopback address: sy_bench_loopback_connect). */
static inline int raw_connect(int port, int timeout_ms)
{
    return sy_bench_loopback_connect(NULL, port, timeout_ms);
}

/* All n bytes through send (writing) or recv; false when the peer closed or the socket timed out
 * first. */
static inline bool raw_transfer_all(int fd, uint8_t *p, size_t n, bool writing)
{
    while (n) {
        ssize_t k = writing ? send(fd, p, n, MSG_NOSIGNAL) : recv(fd, p, n, 0);
        if (k <= 0) {
            if (k < 0 && errno == EINTR) continue;
            return false;
        }
        p += k;
        n -= (size_t)k;
    }
    return true;
}

static inline bool raw_write_all(int fd, const void *data, size_t n)
{
    return raw_transfer_all(fd, (uint8_t *)data, n, true); /* send only reads through p */
}

static inline bool raw_read_all(int fd, void *data, size_t n)
{
    return raw_transfer_all(fd, data, n, false);
}

/* Encodes m as one untagged frame (its header.seq as given) and writes it; 0 on success. */
static inline int raw_send_msg(int fd, const sy_cluster_msg *m)
{
    sy_error e = {0};
    sy_cluster_buf b = {0};
    int rc = sy_cluster_encode(m, 0, &b, &e) == SY_OK && raw_write_all(fd, b.data, b.size) ? 0 : -1;
    if (rc) fprintf(stderr, "raw_send_msg: %s\n", e.message[0] ? e.message : strerror(errno));
    sy_cluster_buf_free(&b);
    return rc;
}

#if SY_CLUSTER_VERSION >= 3 /* (test_cluster_hostile builds against protocol 2 too, with nng for sessions) */
/* Reads one message of an untagged session (frames reassembled, at most max_body bytes) and
 * decodes it into *out, which borrows *raw (free() it after sy_cluster_msg_free). Returns 0, -1
 * when the connection closed or timed out first, -2 when the reply does not decode. */
static inline int raw_recv_msg(int fd, size_t max_body, sy_cluster_msg *out, uint8_t **raw)
{
    *raw = NULL;
    memset(out, 0, sizeof *out);
    uint8_t *body = NULL;
    size_t size = 0;
    sy_cluster_header first;
    memset(&first, 0, sizeof first);
    for (;;) {
        uint8_t hdr[SY_CLUSTER_HEADER_SIZE];
        sy_cluster_header h;
        sy_error e = {0};
        if (!raw_read_all(fd, hdr, sizeof hdr)) break;
        if (sy_cluster_parse_header(hdr, &h, &e) != SY_OK || h.body_size > max_body - size) {
            free(body);
            return -2;
        }
        size_t tag = (h.flags & SY_CLUSTER_FLAG_TAGGED) ? SY_CLUSTER_TAG_SIZE : 0;
        uint8_t *nb = realloc(body, size + h.body_size + tag + 1);
        if (!nb) break;
        body = nb;
        if (!raw_read_all(fd, body + size, h.body_size + tag)) break;
        if (!size && !first.type) first = h;
        size += h.body_size;
        if (!(h.flags & SY_CLUSTER_FLAG_MORE)) {
            sy_error e2 = {0};
            first.flags &= ~(uint32_t)SY_CLUSTER_FLAG_MORE;
            if (sy_cluster_decode_body(&first, body, size, NULL, out, &e2) != SY_OK) {
                free(body);
                return -2;
            }
            *raw = body;
            return 0;
        }
    }
    free(body);
    return -1;
}

#endif

/* true when the peer ends the connection (EOF or reset) within ms; what it sends before is read
 * and dropped. */
static inline bool raw_closed_within(int fd, int ms)
{
    struct timespec t0;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (;;) {
        struct timespec t1;
        clock_gettime(CLOCK_MONOTONIC, &t1);
        int left = ms - (int)((t1.tv_sec - t0.tv_sec) * 1000 + (t1.tv_nsec - t0.tv_nsec) / 1000000);
        if (left <= 0) return false;
        struct pollfd pf = {fd, POLLIN, 0};
        int pr = poll(&pf, 1, left);
        if (pr < 0 && errno == EINTR) continue;
        if (pr <= 0) return false;
        uint8_t buf[4096];
        ssize_t k = recv(fd, buf, sizeof buf, MSG_DONTWAIT);
        if (k == 0 || (k < 0 && errno != EAGAIN && errno != EINTR)) return true;
    }
}

#if SY_CLUSTER_VERSION >= 3
/* The HELLO a raw client sends first (sequence 1, untagged). */
static inline sy_cluster_msg raw_hello(void)
{
    sy_cluster_msg m;
    memset(&m, 0, sizeof m);
    m.header.type = SY_CLUSTER_HELLO;
    m.header.seq = 1;
    m.u.hello.max_frame = (uint32_t)SY_CLUSTER_DEFAULT_MAX_FRAME;
    m.u.hello.max_message = SY_CLUSTER_DEFAULT_MAX_MESSAGE;
    strcpy(m.u.hello.name, "raw test");
    return m;
}
#endif

/* A RENDER of *tile (the caller's, 4x4 pixels at the origin) of an 8x8 frame by whitted, the camera
 * framing the cube [-1, 1]^3, sequence seq: a request a server checks before it renders anything. */
static inline sy_cluster_msg raw_small_render(sy_cluster_rect *tile, uint32_t seq)
{
    sy_cluster_msg r;
    memset(&r, 0, sizeof r);
    *tile = (sy_cluster_rect){0, 0, 4, 4};
    r.header.type = SY_CLUSTER_RENDER;
    r.header.seq = seq;
    strcpy(r.u.render.backend, "whitted");
    r.u.render.full_width = r.u.render.full_height = 8;
    r.u.render.camera = sy_camera_view_frame_bounds(&(sy_bounds){{-1, -1, -1}, {1, 1, 1}}, 1.0f);
    r.u.render.tile_count = 1;
    r.u.render.tiles = tile;
    return r;
}

#endif /* SY_TEST_RAW_PEER_H */
