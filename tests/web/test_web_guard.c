/* test_web_guard.c — test_web's hardening parts (test_web.c lists what each checks): web_token
 * (the access token on 0.0.0.0), web_hostile (issue 32's findings), web_slowloris (an honest client
 * served under a slowloris attack), web_stillbudget (the per-client still budget). */
#include "web_test.h"
int test_token(void)
{
    sy_error err = {0};
    server s;
    if (web_start(&s, "0.0.0.0:0", "whitted", &err)) return 1;
    uint16_t port = sy_web_port(s.web);
    const char *url = sy_web_url(s.web), *t = strstr(url, "?token=");
    CHECK(t && strlen(t + 7) == 32);
    char token[64], path[128], cookie[128];
    snprintf(token, sizeof token, "%s", t + 7);
    http_answer a;
    CHECK(web_get(port, "/", NULL, &a) == 0);
    CHECK(a.status == 401 && strstr((char *)a.body, "token missing"));
    free(a.body);
    CHECK(web_get(port, "/api/frame.jpg?w=8&h=8&token=0123456789abcdef0123456789abcdef", NULL, &a) == 0);
    CHECK(a.status == 403 && strstr((char *)a.body, "token wrong"));
    free(a.body);
    CHECK(web_get(port, "/?token=short", NULL, &a) == 0 && a.status == 403);
    free(a.body);
    /* a token of 128 characters or more is wrong, not missing (issue 32) */
    char longtok[300] = "/?token=";
    memset(longtok + 8, 'a', 200);
    CHECK(web_get(port, longtok, NULL, &a) == 0);
    CHECK(a.status == 403 && strstr((char *)a.body, "token wrong"));
    free(a.body);
    snprintf(path, sizeof path, "/?token=%s", token);
    CHECK(web_get(port, path, NULL, &a) == 0);
    CHECK(a.status == 200 && strstr((char *)a.body, "sy-canvas"));
    CHECK(strcasestr(a.head, "set-cookie: sy_token=") && strstr(a.head, "HttpOnly"));
    free(a.body);
    snprintf(cookie, sizeof cookie, "Cookie: other=1; sy_token=%s\r\n", token);
    CHECK(web_get(port, "/api/frame.jpg?w=16&h=16", cookie, &a) == 0);
    CHECK(a.status == 200);
    free(a.body);
    /* WebSocket: without the token refused, with it accepted */
    sy_web_client *c = NULL;
    sy_web_client_opts o = {.host = "127.0.0.1", .port = port, .path = "/ws"};
    CHECK(sy_web_client_connect(&o, 10000, &c, &err) == SY_ERR_PROTOCOL);
    snprintf(path, sizeof path, "/ws?token=%s", token);
    o.path = path;
    CHECK_OK(sy_web_client_connect(&o, 10000, &c, &err), err);
    sy_web_client_close(c);
    return web_stop(&s);
}

/* Everything up to the peer's close: its HTTP status lines counted, the first status returned. */
static int read_all(int fd, int *answers, char *first, size_t first_len)
{
    char buf[1 << 16];
    size_t len = 0;
    ssize_t got;
    while ((got = recv(fd, buf + len, sizeof buf - 1 - len, 0)) > 0 && len + (size_t)got < sizeof buf - 1) len += (size_t)got;
    if (got > 0) len += (size_t)got;
    buf[len] = 0;
    close(fd);
    int n = 0;
    for (const char *p = buf; (p = strstr(p, "HTTP/1.1 ")) != NULL; p += 9) n++;
    if (answers) *answers = n;
    if (first) snprintf(first, first_len, "%.*s", (int)(len < first_len - 1 ? len : first_len - 1), buf);
    return len >= 12 ? atoi(buf + 9) : -1;
}

static int raw_status(uint16_t port, const char *req)
{
    int fd = web_send_request(port, NULL, req);
    return fd < 0 ? -1 : read_all(fd, NULL, NULL, 0);
}

/* issue 32's findings, each failed before its fix (see the commit) */
int test_hostile(uint16_t port)
{
    char req[2048];
    http_answer a;
    /* DNS rebinding: the Host is parsed; a name that starts with 127. is no loopback address */
    const char *hosts_bad[] = {"127.attacker.example", "127.0.0.1.attacker.example", "localhost.attacker.example",
                               "127.0.0.1:80:80", "[::1]x", "127.1", "evil.example"};
    for (size_t i = 0; i < sizeof hosts_bad / sizeof *hosts_bad; ++i) {
        snprintf(req, sizeof req, "GET / HTTP/1.1\r\nHost: %s\r\nConnection: close\r\n\r\n", hosts_bad[i]);
        int st = raw_status(port, req);
        if (st != 403) fprintf(stderr, "Host: %s: %d\n", hosts_bad[i], st);
        CHECK(st == 403);
    }
    const char *hosts_good[] = {"localhost", "LocalHost:1", "127.0.0.1", "127.9.8.7:65535", "[::1]:8080"};
    for (size_t i = 0; i < sizeof hosts_good / sizeof *hosts_good; ++i) {
        snprintf(req, sizeof req, "GET / HTTP/1.1\r\nHost: %s\r\nConnection: close\r\n\r\n", hosts_good[i]);
        CHECK(raw_status(port, req) == 200);
    }
    /* ... also for the WebSocket upgrade (the Origin matching that Host) */
    snprintf(req, sizeof req,
             "GET /ws HTTP/1.1\r\nHost: 127.attacker.example:%u\r\nOrigin: http://127.attacker.example:%u\r\n"
             "Upgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
             "Sec-WebSocket-Version: 13\r\nSec-WebSocket-Protocol: sy-view\r\n\r\n", port, port);
    CHECK(raw_status(port, req) != 101);
    /* the upgrade only at /ws (this one is fine but for its path) */
    snprintf(req, sizeof req,
             "GET /elsewhere HTTP/1.1\r\nHost: 127.0.0.1:%u\r\nOrigin: http://127.0.0.1:%u\r\n"
             "Upgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
             "Sec-WebSocket-Version: 13\r\nSec-WebSocket-Protocol: sy-view\r\n\r\n", port, port);
    CHECK(raw_status(port, req) != 101);
    /* a cross-site "simple" POST: text/plain, or another Origin, or none, never reaches the route */
    const char *posts[] = {"Origin: http://127.0.0.1:%u\r\nContent-Type: text/plain\r\n",
                           "Origin: http://evil.example:%u\r\nContent-Type: application/json\r\n",
                           "Content-Type: application/json\r\nX-Port: %u\r\n"};
    const int want[] = {415, 403, 403};
    for (int i = 0; i < 3; ++i) {
        char extra[200];
        snprintf(extra, sizeof extra, posts[i], port);
        snprintf(req, sizeof req, "POST /api/echo HTTP/1.1\r\nHost: 127.0.0.1:%u\r\n%sContent-Length: 2\r\n\r\n{}", port, extra);
        int st = raw_status(port, req);
        if (st != want[i]) fprintf(stderr, "POST %d: %d\n", i, st);
        CHECK(st == want[i]);
    }
    /* stills: only for the page's origin; sides past the cap refused up front; the pixel budget */
    snprintf(req, sizeof req, "GET /api/frame.jpg?w=8&h=8 HTTP/1.1\r\nHost: 127.0.0.1:%u\r\n\r\n", port);
    CHECK(raw_status(port, req) == 403);
    CHECK(web_get(port, "/api/frame.jpg?w=8192&h=8192", NULL, &a) == 0 && a.status == 400 && strstr((char *)a.body, "1..3840"));
    free(a.body);
    CHECK(web_get(port, "/api/frame.jpg?w=200&h=101", NULL, &a) == 0 && a.status == 413 && strstr((char *)a.body, "budget"));
    free(a.body);
    /* a one-character header name: 400 at once (libwebsockets waited 10 s for the end of the head) */
    snprintf(req, sizeof req, "GET / HTTP/1.1\r\nHost: 127.0.0.1:%u\r\nConnection: close\r\nX: y\r\n\r\n", port);
    CHECK(raw_status(port, req) == 400);
    /* two pipelined GETs: the first answered with Connection: close, then a clean close */
    snprintf(req, sizeof req, "GET /api/object/1 HTTP/1.1\r\nHost: 127.0.0.1:%u\r\n\r\n"
             "GET /api/object/2 HTTP/1.1\r\nHost: 127.0.0.1:%u\r\n\r\n", port, port);
    int answers = 0;
    char head[400];
    int fd = web_send_request(port, NULL, req);
    CHECK(fd >= 0 && read_all(fd, &answers, head, sizeof head) == 200);
    if (answers != 1 || !strcasestr(head, "connection: close")) fprintf(stderr, "pipelined: %d answers\n%s\n", answers, head);
    CHECK(answers == 1 && strcasestr(head, "connection: close") && strstr(head, "/api/object/1"));
    /* a path of 256 bytes or more: 414, never the page */
    char path[400] = "/";
    memset(path + 1, 'a', 300);
    CHECK(web_get(port, path, NULL, &a) == 0 && a.status == 414);
    free(a.body);
    path[256] = 0; /* 256 bytes */
    CHECK(web_get(port, path, NULL, &a) == 0 && a.status == 414);
    free(a.body);
    /* a binary message announcing 50 MB: closed at once with 1009, before its payload is sent */
    snprintf(req, sizeof req,
             "GET /ws HTTP/1.1\r\nHost: 127.0.0.1:%u\r\nOrigin: http://127.0.0.1:%u\r\n"
             "Upgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
             "Sec-WebSocket-Version: 13\r\nSec-WebSocket-Protocol: sy-view\r\n\r\n", port, port);
    fd = web_send_request(port, NULL, req);
    CHECK(fd >= 0);
    uint8_t frame[14 + 1000] = {0x82, 0x80 | 127, 0, 0, 0, 0, 0x02, 0xfa, 0xf0, 0x80, 1, 2, 3, 4}; /* 50,000,000 */
    CHECK(send(fd, frame, sizeof frame, MSG_NOSIGNAL) == (ssize_t)sizeof frame);
    uint8_t buf[1 << 16];
    size_t len = 0;
    ssize_t got;
    while ((got = recv(fd, buf + len, sizeof buf - len, 0)) > 0) len += (size_t)got;
    close(fd);
    /* after the 101 and the hello: a close frame (0x88) whose code is 1009 */
    bool closed_1009 = false;
    for (size_t i = 0; i + 3 < len; ++i)
        if (buf[i] == 0x88 && (buf[i + 1] & 0x7f) >= 2 && buf[i + 2] == 0x03 && buf[i + 3] == 0xf1) closed_1009 = true;
    CHECK(strstr((char *)buf, " 101 ") && closed_1009);
    return 0;
}

/* 100 reconnecting slowloris connections from 127.0.0.1 (each sends its head a byte at a time and
 * reconnects when the server closes it) while an honest client at 127.0.0.2 asks for the page 20
 * times: every GET is answered. */
typedef struct slowloris {
    uint16_t port;
    volatile int stop;
    uint64_t reconnects;
} slowloris;

static void *slowloris_main(void *p)
{
    slowloris *sl = p;
    enum { N = 100 };
    int fd[N];
    char head[128];
    int hn = snprintf(head, sizeof head, "GET / HTTP/1.1\r\nHost: 127.0.0.1:%u\r\nX-Slow: ", sl->port);
    for (int i = 0; i < N; ++i) fd[i] = -1;
    while (!sl->stop) {
        struct pollfd pf[N];
        for (int i = 0; i < N; ++i) {
            if (fd[i] < 0) {
                fd[i] = web_connect_from(sl->port, NULL);
                if (fd[i] >= 0) send(fd[i], head, (size_t)hn, MSG_NOSIGNAL | MSG_DONTWAIT);
                sl->reconnects++;
            }
            pf[i] = (struct pollfd){.fd = fd[i], .events = POLLIN};
        }
        poll(pf, N, 20); /* the attacker's pace: a byte per connection every 20 ms */
        for (int i = 0; i < N; ++i) {
            if (fd[i] < 0) continue;
            char b[256];
            if ((pf[i].revents && recv(fd[i], b, sizeof b, MSG_DONTWAIT) <= 0) || pf[i].revents & (POLLHUP | POLLERR) ||
                send(fd[i], "a", 1, MSG_NOSIGNAL | MSG_DONTWAIT) < 0) {
                close(fd[i]);
                fd[i] = -1;
            }
        }
    }
    for (int i = 0; i < N; ++i)
        if (fd[i] >= 0) close(fd[i]);
    return NULL;
}

int test_slowloris(server *s, uint16_t port)
{
    slowloris sl = {.port = port};
    pthread_t th;
    CHECK(pthread_create(&th, NULL, slowloris_main, &sl) == 0);
    /* the attack is on once the server holds a full budget for that address and evicts */
    sy_web_stats st;
    do {
        usleep(1000); /* polls the server's state */
        sy_web_stats_get(s->web, &st);
    } while (st.evicted < 100);
    int answered = 0;
    web_http_source = "127.0.0.2";
    for (int i = 0; i < 20; ++i) {
        http_answer a;
        if (web_get(port, "/", NULL, &a) == 0) {
            answered += a.status == 200;
            free(a.body);
        }
    }
    web_http_source = NULL;
    sy_web_stats_get(s->web, &st);
    sl.stop = 1;
    pthread_join(th, NULL);
    printf("slowloris: honest GETs answered %d/20 (attacker reconnects %llu; server: accepted %llu, evicted %llu, "
           "expired %llu, waiting %u)\n",
           answered, (unsigned long long)sl.reconnects, (unsigned long long)st.accepted, (unsigned long long)st.evicted,
           (unsigned long long)st.expired, st.pending);
    CHECK(answered == 20);
    return 0;
}

/* The still budget: a client's queued and rendering stills together; another client is served;
 * a still whose requester left is not rendered. The render thread is held in /api/block so the
 * stills wait in the queue, whatever the machine's speed. */
static void wait_queued(server *s, uint32_t n)
{
    sy_web_stats st;
    for (;;) {
        sy_web_stats_get(s->web, &st);
        if (st.stills_queued == n) return;
        usleep(1000); /* polls the server's state */
    }
}

int test_still_budget(server *s, uint16_t port)
{
    char req[300];
    const char *fmt = "GET /api/frame.jpg?w=%u&h=%u HTTP/1.1\r\nHost: 127.0.0.1:%u\r\nOrigin: http://127.0.0.1:%u\r\n\r\n";
    sy_web_stats st;
    sy_web_stats_get(s->web, &st);
    uint64_t abandoned = st.requests_abandoned, cancelled = st.stills_cancelled, done = st.stills_done;
    int hold = web_hold_render_thread(port);
    CHECK(hold >= 0);
    snprintf(req, sizeof req, fmt, 100, 100, port, port);
    int first = web_send_request(port, NULL, req); /* 10000 pixels of this client's 20000 */
    CHECK(first >= 0);
    wait_queued(s, 1);
    /* 12000 more from the same client: over its budget while the first waits */
    http_answer a;
    CHECK(web_get(port, "/api/frame.jpg?w=120&h=100", NULL, &a) == 0);
    CHECK(a.status == 429 && strstr((char *)a.body, "budget"));
    free(a.body);
    /* another client has a budget of its own */
    snprintf(req, sizeof req, fmt, 141, 141, port, port);
    int second = web_send_request(port, "127.0.0.2", req);
    CHECK(second >= 0);
    wait_queued(s, 2);
    /* a third client leaves before its still is rendered: it is not rendered */
    snprintf(req, sizeof req, fmt, 64, 48, port, port);
    int gone = web_send_request(port, "127.0.0.3", req);
    CHECK(gone >= 0);
    wait_queued(s, 3);
    close(gone);
    do {
        usleep(1000); /* polls the server's state */
        sy_web_stats_get(s->web, &st);
    } while (st.requests_abandoned == abandoned);
    web_release_render_thread(hold);
    char head[300];
    int st1 = read_all(first, NULL, head, sizeof head);
    if (st1 != 200) fprintf(stderr, "first still: %s\n", head);
    CHECK(st1 == 200);
    int st2 = read_all(second, NULL, head, sizeof head);
    if (st2 != 200) fprintf(stderr, "second still: %s\n", head);
    CHECK(st2 == 200);
    do {
        usleep(1000);
        sy_web_stats_get(s->web, &st);
    } while (st.stills_cancelled + st.stills_done < cancelled + done + 3);
    CHECK(st.stills_cancelled == cancelled + 1 && st.stills_done == done + 2);
    return 0;
}
