/* test_web_http.c — test_web's HTTP parts (test_web.c lists what each checks): web_page (the page,
 * 404, a foreign Host), web_still (/api/frame.jpg), web_latest (/api/latest.jpg), web_routes (application routes, limits, broken
 * requests), web_clientfiles (/client/ serves the page's own files only). */
#include "web_test.h"
int test_page(uint16_t port)
{
    http_answer a;
    CHECK(web_get(port, "/", NULL, &a) == 0);
    CHECK(a.status == 200 && strcasestr(a.head, "content-type: text/html"));
    CHECK(strstr((char *)a.body, "id=\"sy-canvas\"") && strstr((char *)a.body, "\"view.js\""));
    free(a.body);
    /* the page's script, with its own Content-Type */
    CHECK(web_get(port, "/view.js", NULL, &a) == 0);
    CHECK(a.status == 200 && strcasestr(a.head, "content-type: text/javascript"));
    CHECK(strstr((char *)a.body, "window.syStats") != NULL);
    free(a.body);
    CHECK(web_get(port, "/nothing/here", NULL, &a) == 0 && a.status == 404);
    free(a.body);
    /* DNS rebinding: a page of evil.example resolving to 127.0.0.1 names its own host */
    char req[256];
    snprintf(req, sizeof req, "GET / HTTP/1.1\r\nHost: evil.example:%u\r\nConnection: close\r\n\r\n", port);
    CHECK(web_http(port, req, NULL, 0, &a) == 0 && a.status == 403);
    free(a.body);
    return 0;
}

int test_still(uint16_t port)
{
    http_answer a;
    CHECK(web_get(port, "/api/frame.jpg?w=96&h=40", NULL, &a) == 0);
    CHECK(a.status == 200 && strcasestr(a.head, "content-type: image/jpeg"));
    if (web_check_jpeg(a.body, a.body_len, 96, 40)) return 1;
    free(a.body);
    const char *bad[] = {"/api/frame.jpg", "/api/frame.jpg?w=0&h=10", "/api/frame.jpg?w=10&h=-3",
                         "/api/frame.jpg?w=10&h=99999999", "/api/frame.jpg?w=1e3&h=10", "/api/frame.jpg?w=10"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        CHECK(web_get(port, bad[i], NULL, &a) == 0);
        if (a.status != 400) fprintf(stderr, "%s: %d\n", bad[i], a.status);
        CHECK(a.status == 400 && (strstr((char *)a.body, "size") || strstr((char *)a.body, "missing")));
        free(a.body);
    }
    /* a page's own fetch (the screenshot button): no Origin on a same-origin GET, but
     * Sec-Fetch-Site: same-origin; cross-site or none: refused */
    const char *site[] = {"Sec-Fetch-Site: same-origin\r\n", "Sec-Fetch-Site: cross-site\r\n", "Sec-Fetch-Site: same-site\r\n", ""};
    for (int i = 0; i < 4; ++i) {
        char req[512];
        snprintf(req, sizeof req, "GET /api/frame.jpg?w=24&h=16 HTTP/1.1\r\nHost: 127.0.0.1:%u\r\n%sConnection: close\r\n\r\n", port, site[i]);
        CHECK(web_http(port, req, NULL, 0, &a) == 0);
        if (a.status != (i == 0 ? 200 : 403)) fprintf(stderr, "still with '%s': %d\n", site[i], a.status);
        CHECK(a.status == (i == 0 ? 200 : 403));
        free(a.body);
    }
    return 0;
}

/* /api/latest.jpg: the newest frame's JPEG, no rendering. Before any viewer it is the warm-up's
 * frame (a quarter of the largest display, 1920 x 1200 here: its 1.6 shape), published by the
 * render thread as it starts (polled for: 204 until then, at most 60 s); it shows the view, so
 * only the page's own origin (or Sec-Fetch-Site: same-origin) gets it. Then a viewer's first
 * frame on the socket has its display's shape. */
int test_latest(uint16_t port)
{
    http_answer a;
    int status = 0;
    for (int i = 0; i < 600 && status != 200; ++i) {
        CHECK(web_get(port, "/api/latest.jpg", NULL, &a) == 0);
        status = a.status;
        if (status != 200) free(a.body), usleep(100000);
        CHECK_MSG(status == 200 || status == 204, "GET /api/latest.jpg: %d", status);
    }
    CHECK_MSG(status == 200, "no latest frame after 60 s");
    CHECK(strcasestr(a.head, "content-type: image/jpeg") != NULL);
    sy_error err = {0};
    uint8_t *px = NULL;
    uint32_t jw = 0, jh = 0;
    CHECK_OK(sy_jpeg_decode_rgba8(a.body, a.body_len, 0, &px, &jw, &jh, &err), err);
    free(px);
    CHECK_MSG(jh > 0 && fabs((double)jw / jh - 1.6) < 0.032 && web_check_jpeg(a.body, a.body_len, jw, jh) == 0,
              "the latest frame is %ux%u, not the warm-up's of a 1920 x 1200 display", jw, jh);
    free(a.body);
    const char *site[] = {"Sec-Fetch-Site: same-origin\r\n", "Sec-Fetch-Site: cross-site\r\n", ""};
    for (int i = 0; i < 3; ++i) {
        char req[512];
        snprintf(req, sizeof req, "GET /api/latest.jpg HTTP/1.1\r\nHost: 127.0.0.1:%u\r\n%sConnection: close\r\n\r\n", port, site[i]);
        CHECK(web_http(port, req, NULL, 0, &a) == 0);
        CHECK_MSG(a.status == (i == 0 ? 200 : 403), "latest with '%s': %d", site[i], a.status);
        free(a.body);
    }
    /* a viewer's first frame has its display's shape: the warm-up frame (1.6) is never sent to
     * an 80 x 60 display (4:3), which waits for its own; a 960 x 600 one gets a 1.6 frame */
    static const uint32_t disp[2][2] = {{80, 60}, {960, 600}};
    for (int k = 0; k < 2; ++k) {
        char path[64];
        snprintf(path, sizeof path, "/ws?w=%u&h=%u&v=3", disp[k][0], disp[k][1]);
        sy_web_client_opts o = {.host = "127.0.0.1", .port = port, .path = path};
        sy_web_client *c = NULL;
        sy_web_frame_info fi;
        CHECK_OK(sy_web_client_connect(&o, 10000, &c, &err), err);
        CHECK_OK(sy_web_client_next_frame(c, 60000, &fi, NULL, NULL, &err), err);
        sy_web_client_close(c);
        CHECK_MSG(labs((long)fi.width * disp[k][1] - (long)fi.height * disp[k][0]) <= 2 * (long)disp[k][0],
                  "a %ux%u display's first frame is %ux%u", disp[k][0], disp[k][1], fi.width, fi.height);
    }
    return 0;
}

int test_routes(uint16_t port)
{
    http_answer a;
    CHECK(web_get(port, "/api/object/12?lod=2", NULL, &a) == 0);
    CHECK(a.status == 200 && !strcmp((char *)a.body, "GET /api/object/12 ?lod=2"));
    free(a.body);
    CHECK(web_get(port, "/api/object/404", NULL, &a) == 0);
    CHECK(a.status == 404 && strstr((char *)a.body, "object 404 does not exist"));
    free(a.body);
    char body[900], req[512];
    unsigned long sum = 0;
    for (size_t i = 0; i < sizeof body; ++i) body[i] = (char)('a' + i % 26), sum += (unsigned char)body[i];
    snprintf(req, sizeof req,
             "POST /api/echo HTTP/1.1\r\nHost: 127.0.0.1:%u\r\nContent-Type: application/json\r\nContent-Length: %zu\r\n"
             "Origin: http://127.0.0.1:%u\r\nConnection: close\r\n\r\n",
             port, sizeof body, port);
    CHECK(web_http(port, req, body, sizeof body, &a) == 0);
    char want[64];
    snprintf(want, sizeof want, "%zu %lu", sizeof body, sum);
    CHECK(a.status == 201 && !strcmp((char *)a.body, want));
    free(a.body);
    /* over the limit of 1000 bytes: 413 with the reason, from the Content-Length alone */
    static char big[5000];
    memset(big, 'x', sizeof big);
    snprintf(req, sizeof req,
             "POST /api/echo HTTP/1.1\r\nHost: 127.0.0.1:%u\r\nContent-Length: %zu\r\nConnection: close\r\n\r\n", port,
             sizeof big);
    CHECK(web_http(port, req, big, sizeof big, &a) == 0);
    CHECK(a.status == 413 && strstr((char *)a.body, "exceeds the limit"));
    free(a.body);
    /* a POST nobody serves */
    snprintf(req, sizeof req, "POST /api/nope HTTP/1.1\r\nHost: 127.0.0.1:%u\r\nContent-Length: 2\r\nConnection: close\r\n\r\n",
             port);
    CHECK(web_http(port, req, "{}", 2, &a) == 0 && a.status == 404);
    free(a.body);
    /* hostile requests: garbage, a header far over lws's limit, a path of 4000 bytes, a request cut
     * off; each may be answered with an error or closed, and the server keeps serving */
    static char huge[20000];
    memset(huge, 'A', sizeof huge - 1);
    const char *junk[] = {"\x01\x02garbage\r\n\r\n", "GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Big: ", "GET /", huge};
    for (size_t i = 0; i < sizeof junk / sizeof junk[0]; ++i) {
        char r2[24000];
        snprintf(r2, sizeof r2, "%s%s", junk[i], i == 1 ? huge : "");
        if (web_http(port, r2, NULL, 0, &a) == 0) {
            CHECK(a.status >= 400 || a.status == 0);
            free(a.body);
        }
    }
    char longpath[4200] = "/";
    memset(longpath + 1, 'p', 4000);
    if (web_get(port, longpath, NULL, &a) == 0) {
        CHECK(a.status >= 400);
        free(a.body);
    }
    /* the server still serves */
    CHECK(web_get(port, "/", NULL, &a) == 0 && a.status == 200);
    free(a.body);
    return 0;
}

/* /client/ serves the page's own files only: client.html, client.js, vendor/...; not the npm
 * folder the build installs beside them (issue 32: it was served whole). */
int test_client_files(void)
{
#ifdef SY_WEB_HAVE_CULL
    sy_error err = {0};
    char dir[] = "/tmp/sy_web_client_XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    const char *files[] = {"client.html", "client.js", "vendor/three/three.module.js", "npm/package.json",
                           "npm/node_modules/three/package.json", "other.txt"};
    char path[512];
    snprintf(path, sizeof path, "%s/vendor", dir), mkdir(path, 0700);
    snprintf(path, sizeof path, "%s/vendor/three", dir), mkdir(path, 0700);
    snprintf(path, sizeof path, "%s/npm", dir), mkdir(path, 0700);
    snprintf(path, sizeof path, "%s/npm/node_modules", dir), mkdir(path, 0700);
    snprintf(path, sizeof path, "%s/npm/node_modules/three", dir), mkdir(path, 0700);
    for (size_t i = 0; i < sizeof files / sizeof *files; ++i) {
        snprintf(path, sizeof path, "%s/%s", dir, files[i]);
        FILE *f = fopen(path, "w");
        CHECK(f != NULL);
        fputs(files[i], f);
        fclose(f);
    }
    server s = {0};
    sy_demo_info demo;
    CHECK_OK(sy_scene_create(&s.scene, &err), err);
    CHECK_OK(sy_demo_build(s.scene, &demo, &err), err);
    CHECK_OK(sy_scene_commit(s.scene, NULL, &err), err);
    sy_web_cull *cull = NULL;
    sy_web_route routes[SY_WEB_CULL_MAX_ROUTES];
    uint32_t n = 0;
    CHECK_OK(sy_web_cull_create(s.scene, demo.root, dir, &cull, routes, &n, &err), err);
    sy_web_desc d = {.scene = s.scene, .root = demo.root, .camera = demo.camera, .backend = "whitted",
                     .listen = "127.0.0.1:0", .routes = routes, .route_count = n};
    CHECK_OK(sy_web_create(&d, &s.web, &err), err);
    sy_web_cull_attach(cull, s.web);
    CHECK_OK(sy_web_thread_start(s.web, &s.th, &err), err);
    uint16_t port = sy_web_port(s.web);
    const int want[] = {200, 200, 200, 404, 404, 404};
    for (size_t i = 0; i < sizeof files / sizeof *files; ++i) {
        http_answer a;
        snprintf(path, sizeof path, "/client/%s", files[i]);
        CHECK(web_get(port, path, NULL, &a) == 0);
        if (a.status != want[i]) fprintf(stderr, "%s: %d\n", path, a.status);
        CHECK(a.status == want[i]);
        if (want[i] == 200) CHECK(!strcmp((char *)a.body, files[i]));
        free(a.body);
    }
    /* the look: what lights the view (/api/view) and its environment's image (/api/environment).
     * The demo brings lights: no environment (404); the menu's studio: the world the server made,
     * a float texture of the studio, served as float RGB of the size the look names, its top row
     * (the sky) brighter than its bottom row (the floor) */
    http_answer a;
    CHECK(web_get(port, "/api/view", NULL, &a) == 0 && a.status == 200);
    const char *look = a.body ? strstr((char *)a.body, "\"look\":{") : NULL;
    CHECK_MSG(look && strstr(look, "\"environment\":\"none\"") && strstr(look, "\"tonemap\":\"aces\"") &&
              strstr(look, "\"exposure\":0"), "%s", (char *)a.body);
    free(a.body);
    CHECK(web_get(port, "/api/environment", NULL, &a) == 0 && a.status == 404);
    free(a.body);
    sy_web_client *c = NULL;
    sy_web_client_opts o = {.host = "127.0.0.1", .port = port, .path = "/ws"};
    char *t = NULL;
    CHECK_OK(sy_web_client_connect(&o, 10000, &c, &err), err);
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"environment\",\"name\":\"studio\"}", &err), err);
    CHECK_OK(sy_web_client_next_text(c, 20000, "scene", &t, &err), err);
    free(t);
    CHECK(web_get(port, "/api/view", NULL, &a) == 0 && a.status == 200);
    look = a.body ? strstr((char *)a.body, "\"look\":{") : NULL;
    CHECK_MSG(look && strstr(look, "\"environment\":\"texture\"") && strstr(look, "\"width\":256") &&
              strstr(look, "\"height\":128") && strstr(look, "\"intensity\":1,"), "%s", (char *)a.body);
    free(a.body);
    CHECK(web_get(port, "/api/environment", NULL, &a) == 0 && a.status == 200 && a.body_len == 256u * 128u * 3u * sizeof(float));
    const float *env = (const float *)a.body;
    double top = 0, bottom = 0;
    for (int i = 0; i < 256 * 3; ++i) top += env[i], bottom += env[127 * 256 * 3 + i];
    CHECK_MSG(top > 1.5 * bottom && bottom > 0, "rows: top %g, bottom %g", top, bottom);
    free(a.body);
    sy_web_client_close(c);
    /* the culler after the server, before the scene */
    s.r = sy_web_thread_join(s.th, &s.err);
    sy_web_destroy(s.web);
    sy_web_cull_destroy(cull);
    sy_scene_destroy(s.scene);
    int r = s.r != SY_OK;
    for (size_t i = sizeof files / sizeof *files; i-- > 0;) {
        snprintf(path, sizeof path, "%s/%s", dir, files[i]);
        remove(path);
    }
    const char *dirs[] = {"npm/node_modules/three", "npm/node_modules", "npm", "vendor/three", "vendor", ""};
    for (size_t i = 0; i < sizeof dirs / sizeof *dirs; ++i) {
        snprintf(path, sizeof path, "%s/%s", dir, dirs[i]);
        rmdir(path);
    }
    return r;
#else
    printf("skip: this sy_web has no culling service (the Embree back-ends)\n");
    return 77;
#endif
}
