/* sy_web_gate.c — sy web's listening socket and the connections before their request is whole
 * (see sy_web_gate.h): accept, budget, head deadline, raw-head checks, hand-over. */
#define _GNU_SOURCE /* accept4 */
#include "sy_web_gate.h"

#include "sy_web_check.h"

#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

typedef struct gate_conn {
    int fd;
    char addr[64];   /* the peer's address (no port) */
    double t0;       /* accepted, ms */
    uint8_t *buf;    /* the head so far (SY_WEB_MAX_HEAD bytes) */
    size_t len;
} gate_conn;

struct sy_web_gate {
    sy_web_gate_desc d;
    int listen_fd;
    int wake[2];
    uint16_t port;
    pthread_t th;
    bool started;
    gate_conn *conns; /* waiting, oldest first */
    uint32_t count;
    pthread_mutex_t mu;
    sy_web_gate_stats st; /* under mu */
};

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}

static void count(sy_web_gate *g, uint64_t *field)
{
    pthread_mutex_lock(&g->mu);
    (*field)++;
    g->st.pending = g->count;
    pthread_mutex_unlock(&g->mu);
}

static void drop(sy_web_gate *g, uint32_t i)
{
    close(g->conns[i].fd);
    free(g->conns[i].buf);
    memmove(&g->conns[i], &g->conns[i + 1], sizeof *g->conns * (g->count - i - 1));
    g->count--;
}

/* A short answer, best effort (the socket is non-blocking), then close. */
static void answer(sy_web_gate *g, uint32_t i, int status, const char *reason)
{
    char msg[400];
    const char *text = status == 400 ? "Bad Request" : status == 405 ? "Method Not Allowed" : status == 408 ? "Request Timeout"
                       : status == 411 ? "Length Required" : status == 413 ? "Payload Too Large"
                       : status == 414 ? "URI Too Long" : status == 431 ? "Request Header Fields Too Large"
                       : status == 501 ? "Not Implemented" : "Error";
    int n = snprintf(msg, sizeof msg,
                     "HTTP/1.1 %d %s\r\ncontent-type: text/plain; charset=utf-8\r\ncontent-length: %zu\r\n"
                     "connection: close\r\ncache-control: no-store\r\n\r\n%s\n",
                     status, text, strlen(reason) + 1, reason);
    if (n > 0) (void)!send(g->conns[i].fd, msg, (size_t)(n < (int)sizeof msg ? n : (int)sizeof msg - 1), MSG_NOSIGNAL);
    shutdown(g->conns[i].fd, SHUT_WR);
    drop(g, i);
}

/* The head as libwebsockets gets it: without Connection lines, plus "Connection: close" (an
 * upgrade's head is passed as it came). */
static uint8_t *rewrite(const gate_conn *c, const sy_web_head_info *h, size_t *out_len)
{
    if (h->upgrade) {
        uint8_t *b = malloc(c->len);
        if (b) memcpy(b, c->buf, c->len), *out_len = c->len;
        return b;
    }
    static const char close_line[] = "Connection: close\r\n";
    uint8_t *b = malloc(h->head_len + sizeof close_line);
    if (!b) return NULL;
    size_t o = 0, at = 0;
    const char *s = (const char *)c->buf;
    while (at < h->head_len - 2) { /* every line but the blank one */
        const char *e = memchr(s + at, '\n', h->head_len - at);
        size_t n = (size_t)(e - (s + at)) + 1;
        if (!(at > 0 && n > 11 && !strncasecmp(s + at, "connection:", 11))) memcpy(b + o, s + at, n), o += n;
        at += n;
    }
    memcpy(b + o, close_line, sizeof close_line - 1), o += sizeof close_line - 1;
    memcpy(b + o, "\r\n", 2), o += 2;
    *out_len = o;
    return b;
}

/* Looks at what conn i has sent (peeked: nothing is taken from the socket until the head is
 * whole; SO_RCVLOWAT makes poll wake only when more than that has arrived, or at the end) and
 * hands it over or refuses it when its head is whole. A GET (or an upgrade) is taken from the
 * socket and handed over as its rewritten head (anything sent after it, such as a pipelined
 * request, is dropped: the connection closes after the first answer); a POST is handed over
 * untouched, libwebsockets reads its head and body from the socket itself (lws 4.1 mishandles a
 * body after a head given as a read buffer). */
static void serve(sy_web_gate *g, uint32_t i)
{
    gate_conn *c = &g->conns[i];
    if (!c->buf && !(c->buf = malloc(SY_WEB_MAX_HEAD))) return drop(g, i);
    ssize_t got = recv(c->fd, c->buf, SY_WEB_MAX_HEAD, MSG_PEEK);
    if (got < 0 && (errno == EAGAIN || errno == EINTR)) return;
    if (got <= 0 || (size_t)got == c->len) return drop(g, i); /* closed (nothing new: the end of the stream) */
    c->len = (size_t)got;
    sy_web_head_info h;
    sy_web_scan s = sy_web_head_scan((const char *)c->buf, c->len, &h);
    if (s == SY_WEB_SCAN_REFUSE) {
        answer(g, i, h.status, h.reason);
        count(g, &g->st.refused);
        return;
    }
    int lowat = s == SY_WEB_SCAN_MORE ? (int)c->len + 1 : 1;
    setsockopt(c->fd, SOL_SOCKET, SO_RCVLOWAT, &lowat, sizeof lowat);
    if (s == SY_WEB_SCAN_MORE) return;
    if (h.has_length && h.content_length > g->d.max_body) {
        char why[160];
        snprintf(why, sizeof why, "request body of %llu bytes exceeds the limit of %zu bytes",
                 (unsigned long long)h.content_length, g->d.max_body);
        answer(g, i, 413, why);
        count(g, &g->st.refused);
        return;
    }
    size_t n = 0;
    uint8_t *req = NULL;
    if (!h.post) {
        if (recv(c->fd, c->buf, c->len, 0) != (ssize_t)c->len || !(req = rewrite(c, &h, &n))) return drop(g, i);
    }
    int fd = c->fd;
    free(c->buf);
    memmove(&g->conns[i], &g->conns[i + 1], sizeof *g->conns * (g->count - i - 1));
    g->count--;
    g->d.deliver(g->d.user, fd, req, n);
    count(g, &g->st.delivered);
}

static void accept_one(sy_web_gate *g, int fd, const struct sockaddr_storage *sa)
{
    char addr[64] = "?";
    if (sa->ss_family == AF_INET) inet_ntop(AF_INET, &((const struct sockaddr_in *)sa)->sin_addr, addr, sizeof addr);
    else if (sa->ss_family == AF_INET6) inet_ntop(AF_INET6, &((const struct sockaddr_in6 *)sa)->sin6_addr, addr, sizeof addr);
    /* the budget: the oldest waiting connection of this address, else the oldest of all, makes room */
    uint32_t mine = 0, oldest_mine = UINT32_MAX;
    for (uint32_t i = 0; i < g->count; ++i)
        if (!strcmp(g->conns[i].addr, addr)) {
            if (oldest_mine == UINT32_MAX) oldest_mine = i;
            mine++;
        }
    if (mine >= g->d.max_pending_per_address) drop(g, oldest_mine), count(g, &g->st.evicted);
    else if (g->count >= g->d.max_pending) drop(g, 0), count(g, &g->st.evicted);
    gate_conn *c = &g->conns[g->count++];
    memset(c, 0, sizeof *c);
    c->fd = fd;
    c->t0 = now_ms();
    snprintf(c->addr, sizeof c->addr, "%s", addr);
    count(g, &g->st.accepted);
    serve(g, g->count - 1); /* a client that sent its request with the connect is served now */
}

static void *gate_main(void *p)
{
    sy_web_gate *g = p;
    struct pollfd *pf = malloc(sizeof *pf * (g->d.max_pending + 2));
    if (!pf) return NULL;
    for (;;) {
        double now = now_ms(), next = -1;
        /* the head deadline: answered 408 and closed */
        for (uint32_t i = 0; i < g->count;) {
            double left = g->conns[i].t0 + g->d.head_timeout_ms - now;
            if (left <= 0) {
                answer(g, i, 408, "the request did not arrive in time");
                count(g, &g->st.expired);
                continue;
            }
            if (next < 0 || left < next) next = left;
            ++i;
        }
        pf[0] = (struct pollfd){.fd = g->wake[0], .events = POLLIN};
        pf[1] = (struct pollfd){.fd = g->listen_fd, .events = POLLIN};
        uint32_t n = g->count;
        for (uint32_t i = 0; i < n; ++i) pf[2 + i] = (struct pollfd){.fd = g->conns[i].fd, .events = POLLIN};
        int r = poll(pf, n + 2, next < 0 ? -1 : (int)next + 1);
        if (r < 0 && errno != EINTR) break;
        if (pf[0].revents) break;
        /* the connections polled, newest first (serve and drop move the later ones) */
        for (uint32_t i = n; i-- > 0;)
            if (pf[2 + i].revents && i < g->count && g->conns[i].fd == pf[2 + i].fd) serve(g, i);
        if (pf[1].revents & POLLIN)
            for (int k = 0; k < 64; ++k) {
                struct sockaddr_storage sa;
                socklen_t sl = sizeof sa;
                int fd = accept4(g->listen_fd, (struct sockaddr *)&sa, &sl, SOCK_NONBLOCK | SOCK_CLOEXEC);
                if (fd < 0) break;
                /* no Nagle: libwebsockets writes a frame in 4 KiB pieces, and the last one waited
                 * for the ACK of the one before, which the viewer delays 40 ms (sy bench web at
                 * 640 x 400: 42 ms of every answer, 0.3 ms without) */
                int one = 1;
                setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
                accept_one(g, fd, &sa);
            }
    }
    free(pf);
    return NULL;
}

sy_result sy_web_gate_create(const sy_web_gate_desc *d, sy_web_gate **out, sy_error *err)
{
    *out = NULL;
    sy_web_gate *g = calloc(1, sizeof *g);
    if (!g) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "web: out of memory");
    g->d = *d;
    if (!g->d.max_pending) g->d.max_pending = 128;
    if (!g->d.max_pending_per_address) g->d.max_pending_per_address = 32;
    if (!g->d.head_timeout_ms) g->d.head_timeout_ms = 5000;
    g->listen_fd = g->wake[0] = g->wake[1] = -1;
    pthread_mutex_init(&g->mu, NULL);
    g->conns = calloc(g->d.max_pending, sizeof *g->conns);
    struct addrinfo hints = {.ai_family = AF_UNSPEC, .ai_socktype = SOCK_STREAM, .ai_flags = AI_PASSIVE | AI_NUMERICSERV},
                    *ai = NULL;
    char port[16];
    snprintf(port, sizeof port, "%d", d->port);
    sy_result r = g->conns ? SY_OK : sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "web: out of memory");
    if (r == SY_OK && getaddrinfo(d->host, port, &hints, &ai) != 0)
        r = sy_error_set(err, SY_ERR_IO, "web: cannot listen on %s:%d (not an address of this machine)", d->host, d->port);
    if (r == SY_OK) {
        g->listen_fd = socket(ai->ai_family, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
        int one = 1;
        if (g->listen_fd >= 0) setsockopt(g->listen_fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
        if (g->listen_fd < 0 || bind(g->listen_fd, ai->ai_addr, ai->ai_addrlen) != 0 || listen(g->listen_fd, 128) != 0)
            r = sy_error_set(err, SY_ERR_IO, "web: cannot listen on %s:%d (%s)", d->host, d->port, strerror(errno));
    }
    if (ai) freeaddrinfo(ai);
    if (r == SY_OK) {
        struct sockaddr_storage sa;
        socklen_t sl = sizeof sa;
        getsockname(g->listen_fd, (struct sockaddr *)&sa, &sl);
        g->port = ntohs(sa.ss_family == AF_INET6 ? ((struct sockaddr_in6 *)&sa)->sin6_port : ((struct sockaddr_in *)&sa)->sin_port);
        if (pipe2(g->wake, O_CLOEXEC) != 0) r = sy_error_set(err, SY_ERR_IO, "web: cannot make a pipe: %s", strerror(errno));
    }
    if (r == SY_OK && pthread_create(&g->th, NULL, gate_main, g) != 0)
        r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "web: cannot start the gate thread");
    if (r != SY_OK) {
        sy_web_gate_destroy(g);
        return r;
    }
    g->started = true;
    *out = g;
    return SY_OK;
}

uint16_t sy_web_gate_port(const sy_web_gate *g) { return g->port; }

void sy_web_gate_stats_get(sy_web_gate *g, sy_web_gate_stats *out)
{
    pthread_mutex_lock(&g->mu);
    *out = g->st;
    pthread_mutex_unlock(&g->mu);
}

void sy_web_gate_destroy(sy_web_gate *g)
{
    if (!g) return;
    if (g->started) {
        (void)!write(g->wake[1], "q", 1);
        pthread_join(g->th, NULL);
    }
    while (g->count) drop(g, g->count - 1);
    if (g->listen_fd >= 0) close(g->listen_fd);
    if (g->wake[0] >= 0) close(g->wake[0]), close(g->wake[1]);
    free(g->conns);
    pthread_mutex_destroy(&g->mu);
    free(g);
}
