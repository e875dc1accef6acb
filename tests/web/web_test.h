/* web_test.h — what the parts of the test_web executable share (tests/web/test_web.c lists the
 * parts, one ctest each): HTTP over plain sockets (so malformed and hostile requests can be sent as
 * they are), the demo scene served by sy_web from a thread of its own, the render thread held in a
 * route, JPEG and frame checks. Defined in web_test.c; single-threaded use by the test's main thread
 * (the server runs on its own thread and is reached only through sockets and sy_web's calls). Every
 * check is fatal (CHECK): a part's result is its return value, so sy_check.h's counters, one set per
 * file, are never summed. */
#ifndef SY_TEST_WEB_TEST_H
#define SY_TEST_WEB_TEST_H

#define _GNU_SOURCE /* strcasestr */
#include "../support/sy_check.h"
#include "sy_demo.h"
#include "sy_governor.h"
#include "sy_jpeg.h"
#include "sy_mediators.h"
#include "sy_web.h"
#include "sy_web_check.h"
#include "sy_web_client.h"
#include "sy_web_cost.h"
#include "sy_web_frame.h"
#include "sy_web_thread.h"
#include "sy_web_video.h"
#ifdef SY_WEB_HAVE_CULL
#include "sy_web_cull.h"
#endif

#include <arpa/inet.h>
#include <math.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <unistd.h>

/* >>http over a plain socket: one request, Connection: close, the whole answer read */
typedef struct http_answer {
    int status;
    char head[4096];
    uint8_t *body;
    size_t body_len;
} http_answer;
/* A connection to the server from source (NULL: 127.0.0.1; 127.0.0.2 is another client); -1 when
 * it fails. Receives time out after 30 s (a hang guard). */
int web_connect_from(uint16_t port, const char *source);
/* The source address of web_http() (NULL: 127.0.0.1). */
extern const char *web_http_source;
/* Sends request (and body_len bytes of body) on a connection of its own and reads the whole
 * answer into *a (a->body from malloc, the caller frees it); -1 when no answer came. */
int web_http(uint16_t port, const char *request, const void *body, size_t body_len, http_answer *a);
/* GET path as the page asks (its own Origin), extra header lines (ending in \r\n) or NULL. */
int web_get(uint16_t port, const char *path, const char *extra, http_answer *a);
/* A request sent on a connection of its own, answered later; the connection, or -1. */
int web_send_request(uint16_t port, const char *source, const char *req);

/* >>server on a thread of its own (the only one touching the scene while it runs) */
typedef struct server {
    sy_scene *scene;
    sy_web *web;
    sy_web_thread *th;
    sy_result r;
    sy_error err;
} server;
/* web_readonly, web_timeline: the server web_start() makes is read-only. */
extern bool web_read_only;
/* web_views: the saved views' file of the server web_start() makes (NULL: none). */
extern const char *web_bookmarks;
/* web_timeline: the demo gets a clip "shrink" (every mesh node's scale to 1 % over 2 s). */
extern bool web_read_only_anim;
/* web_tree: the demo's root gets a group "flat" of 12,000 children and a group "deep" of 20 groups
 * of 300 children each (18,022 nodes more). */
extern bool web_big_tree;
/* web_warpfloor: the governor's budget of the server web_start() makes (ms; 0: the default). */
extern double web_budget_ms;
/* The demo scene served on listen by backend from a thread of its own, with the test routes
 * GET /api/object/ (path and query), POST /api/echo (body length and byte sum) and GET /api/block
 * (below); 1 after printing why not. */
int web_start(server *s, const char *listen, const char *backend, sy_error *e);
/* web_start(s, "127.0.0.1:0", "whitted", e) and a viewer *c connected to its /ws (10 s at most);
 * 1 after printing why not (the caller stops the server). */
int web_start_viewer(server *s, sy_web_client **c, sy_error *e);
/* Stops the server's thread and frees it all; 1 when the server had failed. */
int web_stop(server *s);
/* Sends GET /api/block and waits until the render thread is in it; returns the connection. */
int web_hold_render_thread(uint16_t port);
/* Lets the held render thread go, reads its answer and closes fd. */
void web_release_render_thread(int fd);

/* >>checks (fatal: 1 after reporting) */
/* Decodes the JPEG and checks its size; not uniform: the channels' range is wide. */
int web_check_jpeg(const uint8_t *j, size_t n, uint32_t w, uint32_t h);
/* The viewer's next frame (60 s at most). */
int web_next_frame(sy_web_client *c, sy_web_frame_info *fi, uint8_t **j, size_t *n);

/* >>the parts, one ctest each (0 passed, 1 failed): test_web_http.c */
int test_page(uint16_t port);
int test_still(uint16_t port);
int test_latest(uint16_t port);
int test_routes(uint16_t port);
int test_client_files(void);
/* test_web_stream.c */
int test_stream(uint16_t port);
int test_progressive(void);
int test_frame(void);
int test_video_stream(uint16_t port);
int test_encode_cost(void);
int test_warp_floor(void);
int test_ahead(void);
/* The server's connections in this process (TCP sockets whose local port is port and that have a
 * peer): how many there are into *n, and how many of them have TCP_NODELAY into *nodelay. */
void web_server_sockets(uint16_t port, int *n, int *nodelay);
/* test_web_guard.c */
int test_token(void);
int test_hostile(uint16_t port);
int test_slowloris(server *s, uint16_t port);
int test_still_budget(server *s, uint16_t port);
/* test_web_scene.c */
int test_messages(void);
int test_scene(uint16_t port);
int test_timeline(void);
/* test_web_views.c */
int test_views(void);
/* a viewer of a server web_start_viewer() started (test_web.c sets web_read_only, web_big_tree) */
int test_readonly(sy_web_client *c);
int test_tree(sy_web_client *c);

#endif /* SY_TEST_WEB_TEST_H */
