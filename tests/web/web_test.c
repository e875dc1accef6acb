/* web_test.c — the helpers the parts of test_web share (web_test.h): HTTP over plain sockets, the
 * demo scene's server with the test routes (and, for web_timeline, its shrink clip), the render
 * thread held in GET /api/block, the JPEG and frame checks. */
#include "web_test.h"
/* >>http over a plain socket */
/* A connection to the server from source (NULL: 127.0.0.1; 127.0.0.2 is another client). */
int web_connect_from(uint16_t port, const char *source)
{
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    if (fd < 0) return -1;
    struct sockaddr_in sa = {.sin_family = AF_INET, .sin_port = htons(port)};
    sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    struct timeval tv = {30, 0}; /* a guard against a hang, not a measurement */
    setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    if (source) {
        struct sockaddr_in src = {.sin_family = AF_INET};
        inet_pton(AF_INET, source, &src.sin_addr);
        if (bind(fd, (struct sockaddr *)&src, sizeof src) != 0) {
            close(fd);
            return -1;
        }
    }
    if (connect(fd, (struct sockaddr *)&sa, sizeof sa) != 0) {
        close(fd);
        return -1;
    }
    return fd;
}

const char *web_http_source; /* the source address of web_http() (NULL: 127.0.0.1) */

int web_http(uint16_t port, const char *request, const void *body, size_t body_len, http_answer *a)
{
    memset(a, 0, sizeof *a);
    int fd = web_connect_from(port, web_http_source);
    if (fd < 0) {
        if (fd >= 0) close(fd);
        return -1;
    }
    size_t n = strlen(request);
    if (send(fd, request, n, MSG_NOSIGNAL) != (ssize_t)n) {
        close(fd);
        return -1;
    }
    if (body_len) send(fd, body, body_len, MSG_NOSIGNAL); /* the server may refuse early: ignore */
    size_t cap = 1 << 16, len = 0;
    uint8_t *buf = malloc(cap);
    for (;;) {
        if (len + 4096 > cap) buf = realloc(buf, cap *= 2);
        ssize_t got = recv(fd, buf + len, cap - len - 1, 0);
        if (got <= 0) break;
        len += (size_t)got;
        buf[len] = 0;
        /* complete once the headers and Content-Length bytes are in */
        char *eoh = strstr((char *)buf, "\r\n\r\n");
        if (eoh) {
            char *cl = strcasestr((char *)buf, "content-length:");
            size_t hl = (size_t)(eoh + 4 - (char *)buf);
            if (cl && cl < eoh && len >= hl + strtoul(cl + 15, NULL, 10)) break;
        }
    }
    close(fd);
    buf[len] = 0;
    char *eoh = strstr((char *)buf, "\r\n\r\n");
    if (len < 12 || !eoh) {
        free(buf);
        return -1;
    }
    a->status = atoi((char *)buf + 9);
    size_t hl = (size_t)(eoh + 4 - (char *)buf);
    snprintf(a->head, sizeof a->head, "%.*s", (int)(hl < sizeof a->head ? hl : sizeof a->head - 1), (char *)buf);
    a->body_len = len - hl;
    a->body = malloc(a->body_len + 1);
    memcpy(a->body, buf + hl, a->body_len);
    a->body[a->body_len] = 0;
    free(buf);
    return 0;
}

int web_get(uint16_t port, const char *path, const char *extra, http_answer *a)
{
    char req[2048];
    /* as the page asks: its own Origin (stills need it) */
    snprintf(req, sizeof req, "GET %s HTTP/1.1\r\nHost: 127.0.0.1:%u\r\nOrigin: http://127.0.0.1:%u\r\n%sConnection: close\r\n\r\n",
             path, port, port, extra ? extra : "");
    return web_http(port, req, NULL, 0, a);
}

/* >>server on a thread of its own */
/* a GET route: answers the path, the query and how many nodes the scene has */
static sy_result route_info(void *user, sy_scene *scene, const sy_web_request *req, sy_web_response *resp, sy_error *err)
{
    (void)user, (void)scene;
    if (!strcmp(req->path, "/api/object/404")) return sy_error_set(err, SY_ERR_NOT_FOUND, "object 404 does not exist");
    char *t = malloc(600);
    resp->body_len = (size_t)snprintf(t, 600, "%s %s ?%s", req->method, req->path, req->query);
    resp->body = (uint8_t *)t;
    snprintf(resp->content_type, sizeof resp->content_type, "text/plain");
    return SY_OK;
}

/* a POST route: answers the body's length and its byte sum */
static sy_result route_echo(void *user, sy_scene *scene, const sy_web_request *req, sy_web_response *resp, sy_error *err)
{
    (void)user, (void)scene, (void)err;
    unsigned long sum = 0;
    for (size_t i = 0; i < req->body_len; ++i) sum += req->body[i];
    char *t = malloc(100);
    resp->body_len = (size_t)snprintf(t, 100, "%zu %lu", req->body_len, sum);
    resp->body = (uint8_t *)t;
    resp->status = 201;
    snprintf(resp->content_type, sizeof resp->content_type, "text/plain");
    return SY_OK;
}

static sy_result route_block(void *user, sy_scene *scene, const sy_web_request *req, sy_web_response *resp, sy_error *err);

/* the demo scene served on listen by backend from a thread of its own; 1 after printing why not */
bool web_read_only; /* web_readonly: the server web_start() makes is read-only */
const char *web_bookmarks; /* web_views: its saved views' file */
bool web_read_only_anim; /* web_timeline: the demo gets two clips (shrink, hold), the server plays shrink */

/* Two clips on the same nodes, as a character's walk and run (the Fox's): "shrink", each node of
 * the scene that shows a mesh, its scale from its own to 1 % of it over 0..2 s (LINEAR); then
 * "hold", the same nodes at their own scale over 0..4 s (it comes later: with every clip at once,
 * its keys win). *shrink: the first one. The samplers' data in static storage (the scene copies it). */
static sy_result add_shrink_clip(sy_scene *s, sy_animation *shrink, sy_error *e)
{
    enum { MAXN = 64 };
    static float times[2] = {0.0f, 2.0f}, hold_times[2] = {0.0f, 4.0f}, values[MAXN][6], hold[MAXN][6];
    sy_anim_sampler_desc hd[MAXN];
    sy_anim_sampler_desc sd[MAXN];
    sy_anim_channel ch[MAXN];
    uint32_t n = 0;
    for (uint32_t id = sy_scene_next(s, SY_TYPE_NODE, 0); id && n < MAXN; id = sy_scene_next(s, SY_TYPE_NODE, id)) {
        const sy_node_data *nd = sy_node_get(s, (sy_node){id});
        if (!nd->mesh.id || nd->transform.mode != SY_TRANSFORM_TRS) continue;
        for (int k = 0; k < 3; ++k) values[n][k] = nd->transform.scale[k], values[n][3 + k] = 0.01f * nd->transform.scale[k];
        for (int k = 0; k < 3; ++k) hold[n][k] = hold[n][3 + k] = nd->transform.scale[k];
        sd[n] = (sy_anim_sampler_desc){SY_INTERP_LINEAR, 3, 2, times, values[n]};
        hd[n] = (sy_anim_sampler_desc){SY_INTERP_LINEAR, 3, 2, hold_times, hold[n]};
        ch[n] = (sy_anim_channel){id, SY_ANIM_SCALE, n};
        ++n;
    }
    sy_animation a;
    sy_result r = sy_animation_create(s, "shrink", shrink, e);
    if (r == SY_OK) r = sy_animation_set_clip(s, *shrink, sd, n, ch, n, e);
    if (r == SY_OK) r = sy_animation_create(s, "hold", &a, e);
    if (r == SY_OK) r = sy_animation_set_clip(s, a, hd, n, ch, n, e);
    return r;
}

bool web_big_tree;
double web_budget_ms; /* web_warpfloor: a budget every frame overruns */

void web_server_sockets(uint16_t port, int *n, int *nodelay)
{
    *n = *nodelay = 0;
    for (int fd = 3; fd < 1024; ++fd) {
        struct sockaddr_storage a, p;
        socklen_t al = sizeof a, pl = sizeof p;
        int type = 0, on = 0;
        socklen_t tl = sizeof type, ol = sizeof on;
        if (getsockopt(fd, SOL_SOCKET, SO_TYPE, &type, &tl) != 0 || type != SOCK_STREAM) continue;
        if (getsockname(fd, (struct sockaddr *)&a, &al) != 0 || a.ss_family != AF_INET) continue;
        if (ntohs(((struct sockaddr_in *)&a)->sin_port) != port || getpeername(fd, (struct sockaddr *)&p, &pl) != 0) continue;
        (*n)++;
        if (getsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &on, &ol) == 0 && on) (*nodelay)++;
    }
}

/* A group named name under parent with count children named "name i", set at once. */
static sy_result add_group(sy_scene *s, sy_node parent, const char *name, uint32_t count, sy_error *e)
{
    sy_node g, *ch = malloc((count ? count : 1) * sizeof *ch);
    if (!ch) return sy_error_set(e, SY_ERR_OUT_OF_MEMORY, "big tree: out of memory");
    sy_result r = sy_node_create(s, name, &g, e);
    for (uint32_t i = 0; r == SY_OK && i < count; ++i) {
        char nm[64];
        snprintf(nm, sizeof nm, "%s %u", name, i);
        r = sy_node_create(s, nm, &ch[i], e);
    }
    if (r == SY_OK) r = sy_node_set_children(s, g, ch, count, e);
    if (r == SY_OK) r = sy_node_add_child(s, parent, g, e);
    free(ch);
    return r;
}

static sy_result add_big_tree(sy_scene *s, sy_node root, sy_error *e)
{
    sy_result r = add_group(s, root, "flat", 12000, e);
    sy_node deep;
    if (r == SY_OK) r = sy_node_create(s, "deep", &deep, e);
    if (r == SY_OK) r = sy_node_add_child(s, root, deep, e);
    for (uint32_t i = 0; r == SY_OK && i < 20; ++i) {
        char nm[32];
        snprintf(nm, sizeof nm, "leaf %u", i);
        r = add_group(s, deep, nm, 300, e);
    }
    return r;
}

int web_start(server *s, const char *listen, const char *backend, sy_error *e)
{
    memset(s, 0, sizeof *s);
    sy_demo_info demo;
    sy_animation shrink = {0};
    int failed = sy_scene_create(&s->scene, e) || sy_demo_build(s->scene, &demo, e) ||
                 (web_read_only_anim && add_shrink_clip(s->scene, &shrink, e)) ||
                 (web_big_tree && add_big_tree(s->scene, demo.root, e)) || sy_scene_commit(s->scene, NULL, e);
    if (!failed) {
        static const sy_web_route routes[] = {{"GET", "/api/object/", route_info, NULL},
                                              {"POST", "/api/echo", route_echo, NULL},
                                              {"GET", "/api/block", route_block, NULL}};
        sy_web_desc d = {.scene = s->scene, .root = demo.root, .camera = demo.camera, .background = demo.background,
                         .backend = backend, .listen = listen, .max_body = 1000, .max_message = 256, .max_clients = 3,
                         .routes = routes, .route_count = 3, .read_only = web_read_only, .bookmarks = web_bookmarks,
                         .still_max_pixels = 20000, /* small stills: fast on a loaded machine */
                         .budget_ms = web_budget_ms,
                         .clip = shrink}; /* web_timeline: the server's clock plays shrink alone */
        failed = sy_web_create(&d, &s->web, e) != SY_OK;
    }
    if (failed) {
        fprintf(stderr, "start: %s\n", e->message);
        return 1;
    }
    return sy_web_thread_start(s->web, &s->th, e) != SY_OK;
}

int web_start_viewer(server *s, sy_web_client **c, sy_error *e)
{
    if (web_start(s, "127.0.0.1:0", "whitted", e)) return 1;
    sy_web_client_opts o = {.host = "127.0.0.1", .port = sy_web_port(s->web), .path = "/ws"};
    CHECK_OK(sy_web_client_connect(&o, 10000, c, e), *e);
    return 0;
}

int web_stop(server *s)
{
    s->r = sy_web_thread_join(s->th, &s->err);
    sy_web_destroy(s->web);
    sy_scene_destroy(s->scene);
    if (s->r != SY_OK) fprintf(stderr, "server: %s\n", s->err.message);
    return s->r != SY_OK;
}

/* decodes and checks the size; not uniform: the channels' range is wide */
int web_check_jpeg(const uint8_t *j, size_t n, uint32_t w, uint32_t h)
{
    sy_error err = {0};
    uint8_t *px = NULL;
    uint32_t jw = 0, jh = 0;
    CHECK_OK(sy_jpeg_decode_rgba8(j, n, 0, &px, &jw, &jh, &err), err);
    int lo = 255, hi = 0;
    for (size_t i = 0; i < (size_t)jw * jh * 4; ++i)
        if ((i & 3) != 3) lo = px[i] < lo ? px[i] : lo, hi = px[i] > hi ? px[i] : hi;
    free(px);
    if (jw != w || jh != h || hi - lo < 40) fprintf(stderr, "jpeg %ux%u (want %ux%u), values %d..%d\n", jw, jh, w, h, lo, hi);
    CHECK(jw == w && jh == h);
    CHECK(hi - lo >= 40);
    return 0;
}

int web_next_frame(sy_web_client *c, sy_web_frame_info *fi, uint8_t **j, size_t *n)
{
    sy_error err = {0};
    CHECK_OK(sy_web_client_next_frame(c, 60000, fi, j, n, &err), err);
    return 0;
}

/* >>the render thread held in a route (GET /api/block) until the test releases it: stills queue
 * behind it deterministically */
static pthread_mutex_t block_mu = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t block_cv = PTHREAD_COND_INITIALIZER;
static int block_state; /* 0 free, 1 a handler is held, 2 released */

static sy_result route_block(void *user, sy_scene *scene, const sy_web_request *req, sy_web_response *resp, sy_error *err)
{
    (void)user, (void)scene, (void)req, (void)err;
    pthread_mutex_lock(&block_mu);
    block_state = 1;
    pthread_cond_broadcast(&block_cv);
    while (block_state != 2) pthread_cond_wait(&block_cv, &block_mu);
    block_state = 0;
    pthread_mutex_unlock(&block_mu);
    resp->body = (uint8_t *)strdup("released");
    resp->body_len = 8;
    snprintf(resp->content_type, sizeof resp->content_type, "text/plain");
    return SY_OK;
}

/* Sends GET /api/block and waits until the render thread is in it; returns the connection. */
int web_hold_render_thread(uint16_t port)
{
    int fd = web_connect_from(port, NULL);
    char req[200];
    int n = snprintf(req, sizeof req, "GET /api/block HTTP/1.1\r\nHost: 127.0.0.1:%u\r\n\r\n", port);
    if (fd < 0 || send(fd, req, (size_t)n, MSG_NOSIGNAL) != n) return -1;
    pthread_mutex_lock(&block_mu);
    while (block_state != 1) pthread_cond_wait(&block_cv, &block_mu);
    pthread_mutex_unlock(&block_mu);
    return fd;
}

void web_release_render_thread(int fd)
{
    pthread_mutex_lock(&block_mu);
    block_state = 2;
    pthread_cond_broadcast(&block_cv);
    pthread_mutex_unlock(&block_mu);
    char buf[512];
    while (recv(fd, buf, sizeof buf, 0) > 0) {} /* the answer, then the close */
    close(fd);
}

/* A request sent on a connection of its own, answered later (read_answer). */
int web_send_request(uint16_t port, const char *source, const char *req)
{
    int fd = web_connect_from(port, source);
    size_t n = strlen(req);
    if (fd >= 0 && send(fd, req, n, MSG_NOSIGNAL) != (ssize_t)n) close(fd), fd = -1;
    return fd;
}
