/* test_web_stream.c — test_web's WebSocket stream parts (test_web.c lists what each checks):
 * web_stream (JPEG frames, input, limits, refused upgrades), web_progressive (the path tracer
 * refines and restarts), web_frame (the binary frame format), web_videostream (VP9 viewers),
 * web_encodecost (the governor counts the encoders' time). */
#include "web_test.h"
int test_stream(uint16_t port)
{
    sy_error err = {0};
    sy_web_client *c = NULL, *other = NULL;
    sy_web_client_opts o = {.host = "127.0.0.1", .port = port, .path = "/ws"};
    CHECK_OK(sy_web_client_connect(&o, 10000, &c, &err), err);
    CHECK_OK(sy_web_client_connect(&o, 10000, &other, &err), err); /* a second viewer that never reads */
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"size\",\"w\":80,\"h\":60,\"v\":3}", &err), err);
    sy_web_frame_info fi;
    uint8_t *j0 = NULL, *j1 = NULL;
    size_t n0 = 0, n1 = 0;
    /* the frame at the asked size, with its camera (the orbit's matrix) and a depth channel */
    float *depth = NULL;
    do {
        free(j0);
        free(depth);
        CHECK_OK(sy_web_client_next_frame_depth(c, 60000, &fi, &j0, &n0, &depth, &err), err);
    } while (fi.width != 80 || fi.height != 60);
    if (web_check_jpeg(j0, n0, 80, 60)) return 1;
    sy_mat4 om;
    sy_orbit_matrix(&fi.orbit, &om);
    for (int i = 0; i < 16; ++i) CHECK(fabsf(om.m[i] - fi.view.camera_to_world.m[i]) <= 1e-4f * (1 + fabsf(om.m[i])));
    CHECK(fi.view.window[0] < fi.view.window[1] && fi.view.window[2] < fi.view.window[3] && fi.view.znear > 0);
    size_t hits = 0;
    for (size_t i = 0; i < 80 * 60; ++i)
        if (isfinite(depth[i])) {
            hits++;
            CHECK(depth[i] >= fi.depth_min * 0.999f && depth[i] <= fi.depth_max * 1.001f);
        }
    CHECK(hits > 80 * 60 / 10 && fi.depth_min > 0); /* the demo fills much of the view */
    free(depth);
    /* the server's sockets send at once (TCP_NODELAY): without it the last piece of a frame over
     * 4 KiB waited 40 ms for the viewer's delayed ACK (sy bench web: 42 ms of every answer) */
    int socks = 0, nodelay = 0;
    web_server_sockets(port, &socks, &nodelay);
    CHECK_MSG(socks >= 2 && nodelay == socks, "%d of the server's %d connections have TCP_NODELAY", nodelay, socks);
    /* a page that reads frame format 2 (format 1: no "v" in its size message, the same path) is
     * told to reload and gets no frames, while this viewer's input gives it new ones */
    sy_web_client *old = NULL;
    CHECK_OK(sy_web_client_connect(&o, 10000, &old, &err), err);
    CHECK_OK(sy_web_client_send(old, "{\"t\":\"size\",\"w\":40,\"h\":30,\"v\":2}", &err), err);
    for (int k = 0; k < 3; ++k) {
        char m[96];
        snprintf(m, sizeof m, "{\"t\":\"drag\",\"dx\":%d,\"dy\":0,\"id\":%d}", k + 1, k + 1);
        CHECK_OK(sy_web_client_send(c, m, &err), err);
        do {
            if (web_next_frame(c, &fi, NULL, NULL)) return 1;
        } while (fi.input_id < (uint64_t)k + 1);
    }
    CHECK(sy_web_client_next_frame(old, 300, &fi, NULL, NULL, &err) == SY_ERR_IO);
    sy_web_client_close(old);
    /* malformed input: ignored (logged), the connection keeps working */
    const char *junk[] = {"not json", "[1,2]", "{\"t\":5}", "{\"t\":\"drag\",\"dx\":\"x\",\"dy\":1}",
                          "{\"t\":\"size\",\"w\":0,\"h\":10}", "{\"t\":\"warp\"}", "{\"t\":\"drag\",\"dx\":1e400,\"dy\":0}",
                          "{\"t\":\"key\",\"k\":\"ZZ\"}", "{\"t\":\"drag\",\"dx\":1,\"dy\":1,\"id\":-4}"};
    for (size_t i = 0; i < sizeof junk / sizeof junk[0]; ++i) CHECK_OK(sy_web_client_send(c, junk[i], &err), err);
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"drag\",\"dx\":60,\"dy\":-20,\"id\":7}", &err), err);
    do {
        free(j1);
        if (web_next_frame(c, &fi, &j1, &n1)) return 1;
    } while (fi.input_id < 7);
    /* a moving frame: the governor may render it smaller (the page scales it up) */
    CHECK(fi.input_id == 7 && fi.width >= 1 && fi.width <= 80 && fi.height <= 60);
    CHECK(n1 != n0 || memcmp(j0, j1, n0) != 0); /* the view turned */
    if (web_check_jpeg(j1, n1, fi.width, fi.height)) return 1;
    free(j0);
    free(j1);
    /* a message over the limit (256 bytes) closes that connection; the other viewer stays */
    char big[400];
    memset(big, ' ', sizeof big);
    memcpy(big, "{\"t\":\"size\"", 11);
    big[sizeof big - 2] = '}', big[sizeof big - 1] = 0;
    CHECK_OK(sy_web_client_send(other, big, &err), err);
    int closed = 0;
    for (int i = 0; i < 50 && !closed; ++i)
        closed = sy_web_client_next_frame(other, 200, &fi, NULL, NULL, &err) == SY_ERR_IO && strstr(err.message, "closed");
    CHECK(closed);
    sy_web_client_close(other);
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"wheel\",\"steps\":1,\"id\":8}", &err), err);
    do {
        if (web_next_frame(c, &fi, NULL, NULL)) return 1;
    } while (fi.input_id < 8);
    sy_web_client_close(c);
    /* a foreign Origin and a missing subprotocol are refused */
    sy_web_client_opts evil = o;
    evil.origin = "evil.example"; /* lws writes http:// before it */
    CHECK(sy_web_client_connect(&evil, 10000, &c, &err) == SY_ERR_PROTOCOL);
    char own[64];
    snprintf(own, sizeof own, "127.0.0.1:%u", port);
    evil.origin = own; /* the page's own origin is welcome */
    CHECK_OK(sy_web_client_connect(&evil, 10000, &c, &err), err);
    sy_web_client_close(c);
    /* the first size in the URL (the page's inline script): frames without a size message, the
     * first at most that size and of its aspect (the governor's), then the size itself */
    sy_web_client_opts sized = o;
    sized.path = "/ws?w=120&h=90&v=3";
    CHECK_OK(sy_web_client_connect(&sized, 10000, &c, &err), err);
    uint32_t firstw = 0, firsth = 0;
    do {
        CHECK_OK(sy_web_client_next_frame(c, 60000, &fi, NULL, NULL, &err), err);
        if (!firstw) firstw = fi.width, firsth = fi.height;
    } while (fi.width != 120 || fi.height != 90);
    CHECK_MSG(firstw <= 120 && firsth <= 90 && labs((long)firstw * 90 - (long)firsth * 120) <= 120, "first frame %ux%u", firstw, firsth);
    sy_web_client_close(c);
    char req[512];
    http_answer a;
    snprintf(req, sizeof req,
             "GET /ws HTTP/1.1\r\nHost: 127.0.0.1:%u\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
             "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n",
             port);
    int rc = web_http(port, req, NULL, 0, &a);
    CHECK(rc != 0 || a.status != 101);
    if (rc == 0) free(a.body);
    /* at most 3 viewers (max_clients): a fourth is refused (the server may still be closing the
     * connections above: each of the three is retried until it gets in; 3000 tries, about 300 s,
     * are only a hang guard: 50 were too few on a loaded machine) */
    sy_web_client *v[3] = {NULL, NULL, NULL};
    for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3000 && !v[i]; ++k)
            if (sy_web_client_connect(&o, 10000, &v[i], &err) != SY_OK) usleep(100000);
    CHECK(v[0] && v[1] && v[2]);
    CHECK(sy_web_client_connect(&o, 10000, &c, &err) == SY_ERR_PROTOCOL);
    for (int i = 0; i < 3; ++i) sy_web_client_close(v[i]);
    return 0;
}

/* the widths of the frames answering n drags sent one at a time by c (ids from *id on) into wd */
static int drag_widths(sy_web_client *c, uint64_t *id, int n, uint32_t *wd)
{
    sy_error err = {0};
    sy_web_frame_info fi;
    for (int k = 0; k < n; ++k) {
        char m[96];
        ++*id;
        snprintf(m, sizeof m, "{\"t\":\"drag\",\"dx\":2,\"dy\":0,\"id\":%llu}", (unsigned long long)*id);
        CHECK_OK(sy_web_client_send(c, m, &err), err);
        do {
            if (web_next_frame(c, &fi, NULL, NULL)) return 1;
        } while (fi.input_id < *id);
        wd[k] = fi.width;
    }
    return 0;
}

/* web_warpfloor: moving frames keep sy_web_desc.min_scale (SY_WEB_MIN_SCALE, 0.5) of the display
 * while every viewer's page warps, the governor's own floor (0.125) while one does not; a budget of
 * 0.01 ms, which every frame overruns, puts the governor at the floor */
int test_warp_floor(void)
{
    sy_error err = {0};
    server s;
    web_budget_ms = 0.01;
    if (web_start(&s, "127.0.0.1:0", "whitted", &err)) return 1;
    sy_web_client *c = NULL, *d = NULL;
    sy_web_client_opts o = {.host = "127.0.0.1", .port = sy_web_port(s.web), .path = "/ws"};
    CHECK_OK(sy_web_client_connect(&o, 10000, &c, &err), err);
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"size\",\"w\":160,\"h\":100,\"v\":3,\"warp\":true}", &err), err);
    sy_web_frame_info fi;
    do {
        CHECK_OK(sy_web_client_next_frame(c, 60000, &fi, NULL, NULL, &err), err);
    } while (fi.width != 160);
    uint64_t id = 0;
    uint32_t wd[6];
    if (drag_widths(c, &id, 6, wd)) return 1;
    printf("warpfloor: a warping viewer's moving frames %u %u %u %u %u %u of 160\n", wd[0], wd[1], wd[2], wd[3], wd[4], wd[5]);
    for (int k = 2; k < 6; ++k) CHECK_MSG(wd[k] == 80, "a warping viewer's moving frame %u wide, not 80", wd[k]);
    /* a second viewer that does not warp (no "warp"): the governor's floor for both */
    CHECK_OK(sy_web_client_connect(&o, 10000, &d, &err), err);
    CHECK_OK(sy_web_client_send(d, "{\"t\":\"size\",\"w\":160,\"h\":100,\"v\":3}", &err), err);
    if (drag_widths(c, &id, 6, wd)) return 1;
    printf("warpfloor: with a viewer that does not warp %u %u %u %u %u %u of 160\n", wd[0], wd[1], wd[2], wd[3], wd[4], wd[5]);
    for (int k = 3; k < 6; ++k) CHECK_MSG(wd[k] == 20, "with a viewer that does not warp: %u wide, not 20", wd[k]);
    /* "warp" that is no boolean: refused (logged), nothing changes; that viewer leaves: half again */
    CHECK_OK(sy_web_client_send(d, "{\"t\":\"size\",\"w\":160,\"h\":100,\"v\":3,\"warp\":1}", &err), err);
    if (drag_widths(c, &id, 4, wd)) return 1;
    CHECK_MSG(wd[3] == 20, "after a size with \"warp\":1 (refused): %u wide, not 20", wd[3]);
    sy_web_client_close(d);
    if (drag_widths(c, &id, 6, wd)) return 1;
    for (int k = 3; k < 6; ++k) CHECK_MSG(wd[k] == 80, "the viewer that did not warp gone: %u wide, not 80", wd[k]);
    sy_web_client_close(c);
    web_budget_ms = 0;
    return web_stop(&s);
}

/* the largest difference between a frame's camera and the orbit matrix of o */
static float camera_off(const sy_web_frame_info *fi, const sy_orbit *o)
{
    sy_mat4 m;
    sy_orbit_matrix(o, &m);
    float d = 0;
    for (int i = 0; i < 16; ++i) d = fmaxf(d, fabsf(m.m[i] - fi->view.camera_to_world.m[i]));
    return d;
}

/* frames from c until one whose camera is o's (within 1e-5): 0, else 1 after 40 frames */
static int frame_from(sy_web_client *c, const sy_orbit *o, sy_web_frame_info *fi)
{
    for (int k = 0; k < 40; ++k) {
        if (web_next_frame(c, fi, NULL, NULL)) return 1;
        if (camera_off(fi, o) < 1e-5f) return 0;
    }
    return 1;
}

/* web_ahead: a drag's lead renders its frame further along (the header's orbit is where the drags
 * put the camera, the frame's camera the orbit moved on by the lead); {"t":"lead","lead":[0,0]}
 * brings the exact view back; a wheel ends the lead; with a viewer whose page does not warp the
 * lead is not used; the viewer whose lead is in use leaving ends it (docs/WEB.md, "Frames rendered
 * ahead") */
int test_ahead(void)
{
    sy_error err = {0};
    server s;
    if (web_start(&s, "127.0.0.1:0", "whitted", &err)) return 1;
    sy_web_client *c = NULL, *d = NULL;
    sy_web_client_opts o = {.host = "127.0.0.1", .port = sy_web_port(s.web), .path = "/ws"};
    CHECK_OK(sy_web_client_connect(&o, 10000, &c, &err), err);
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"size\",\"w\":64,\"h\":40,\"v\":3,\"warp\":true}", &err), err);
    sy_web_frame_info fi;
    do {
        CHECK_OK(sy_web_client_next_frame(c, 60000, &fi, NULL, NULL, &err), err);
    } while (fi.width != 64);
    sy_orbit start = fi.orbit;
    CHECK_MSG(camera_off(&fi, &start) < 1e-5f, "a frame before any lead: its camera %g off its orbit's", camera_off(&fi, &start));
    /* a drag of 10 pixels with a lead of 30: the frame's orbit 10 on, its camera 40 on */
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"drag\",\"dx\":10,\"dy\":0,\"lead\":[30,0],\"id\":1}", &err), err);
    sy_orbit moved = start, ahead;
    sy_orbit_rotate(&moved, 10, 0);
    ahead = moved;
    sy_orbit_rotate(&ahead, 30, 0);
    do {
        if (web_next_frame(c, &fi, NULL, NULL)) return 1;
    } while (fi.input_id < 1);
    printf("ahead: the frame answering the drag: orbit yaw %.5f (the drag's %.5f), camera %.2g off the orbit "
           "led 30 pixels on, %.2g off the drag's\n", fi.orbit.yaw, moved.yaw, camera_off(&fi, &ahead), camera_off(&fi, &moved));
    CHECK_MSG(fi.orbit.yaw == moved.yaw && fi.orbit.pitch == moved.pitch, "the header's orbit (yaw %g) is not the drag's (%g)",
              fi.orbit.yaw, moved.yaw);
    CHECK_MSG(camera_off(&fi, &ahead) < 1e-5f, "the frame's camera is %g off the orbit led 30 pixels on", camera_off(&fi, &ahead));
    CHECK(camera_off(&fi, &moved) > 0.05f);
    /* the page rests: the exact view again, answering the same input */
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"lead\",\"lead\":[0,0]}", &err), err);
    CHECK_MSG(!frame_from(c, &moved, &fi), "no frame of the exact view after the lead ended");
    CHECK(fi.input_id == 1 && fi.orbit.yaw == moved.yaw);
    /* a lead alone moves the camera on, the orbit stays; a malformed one is refused (nothing changes) */
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"lead\",\"lead\":[20,0],\"b\":0}", &err), err);
    ahead = moved;
    sy_orbit_rotate(&ahead, 20, 0);
    CHECK_MSG(!frame_from(c, &ahead, &fi), "no frame led by a lead message");
    CHECK(fi.orbit.yaw == moved.yaw);
    /* a wheel: the camera moved otherwise, no lead until the next drag */
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"wheel\",\"steps\":1,\"id\":2}", &err), err);
    sy_orbit zoomed = moved;
    sy_orbit_zoom(&zoomed, 1);
    CHECK_MSG(!frame_from(c, &zoomed, &fi), "the lead outlived a wheel");
    /* a second viewer that does not warp: the lead is not used */
    CHECK_OK(sy_web_client_connect(&o, 10000, &d, &err), err);
    CHECK_OK(sy_web_client_send(d, "{\"t\":\"size\",\"w\":64,\"h\":40,\"v\":3}", &err), err);
    CHECK_OK(sy_web_client_next_frame(d, 60000, &fi, NULL, NULL, &err), err); /* sized: counted as a plain viewer */
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"drag\",\"dx\":-10,\"dy\":0,\"lead\":[-30,0],\"id\":3}", &err), err);
    sy_orbit back = zoomed;
    sy_orbit_rotate(&back, -10, 0);
    do {
        if (web_next_frame(c, &fi, NULL, NULL)) return 1;
    } while (fi.input_id < 3);
    CHECK_MSG(camera_off(&fi, &back) < 1e-5f, "with a viewer that does not warp: the camera %g off the drag's", camera_off(&fi, &back));
    sy_web_client_close(d);
    /* the viewer whose lead is in use leaves (it cannot say its hand rests): the exact view again */
    CHECK_OK(sy_web_client_connect(&o, 10000, &d, &err), err);
    CHECK_OK(sy_web_client_send(d, "{\"t\":\"size\",\"w\":64,\"h\":40,\"v\":3,\"warp\":true}", &err), err);
    CHECK_OK(sy_web_client_next_frame(d, 60000, &fi, NULL, NULL, &err), err);
    CHECK_OK(sy_web_client_send(d, "{\"t\":\"drag\",\"dx\":5,\"dy\":0,\"lead\":[25,0],\"id\":1}", &err), err);
    sy_orbit left = back;
    sy_orbit_rotate(&left, 5, 0);
    ahead = left;
    sy_orbit_rotate(&ahead, 25, 0);
    CHECK_MSG(!frame_from(c, &ahead, &fi), "no frame led by the second viewer's drag");
    sy_web_client_close(d);
    CHECK_MSG(!frame_from(c, &left, &fi), "the lead outlived the viewer that sent it");
    sy_web_client_close(c);
    return web_stop(&s);
}

/* the path tracer refines while the view rests (samples grow frame after frame) and restarts
 * when it moves (the frame answering a drag has fewer samples than the one before) */
int test_progressive(void)
{
    sy_error err = {0};
    server s;
    if (web_start(&s, "127.0.0.1:0", "pathtracer", &err)) return 1;
    sy_web_client *c = NULL;
    sy_web_client_opts o = {.host = "127.0.0.1", .port = sy_web_port(s.web), .path = "/ws"};
    CHECK_OK(sy_web_client_connect(&o, 10000, &c, &err), err);
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"size\",\"w\":48,\"h\":32,\"v\":3}", &err), err);
    sy_web_frame_info fi = {0};
    float *d0 = NULL;
    do {
        free(d0);
        d0 = NULL;
        CHECK_OK(sy_web_client_next_frame_depth(c, 60000, &fi, NULL, NULL, &d0, &err), err);
    } while (fi.width != 48);
    uint32_t prev = fi.samples, rising = 0, same_depth = 0;
    while (rising < 4) { /* four frames in a row, each with more samples */
        float *d = NULL;
        CHECK_OK(sy_web_client_next_frame_depth(c, 60000, &fi, NULL, NULL, &d, &err), err);
        CHECK(fi.width == 48 && fi.samples > prev);
        /* a refinement of the view leaves its depth channel out: the page has it already
         * (SY_WEB_FRAME_SAME_DEPTH); the client's last one decodes for it */
        if (fi.flags & SY_WEB_FRAME_SAME_DEPTH) {
            same_depth++;
            CHECK(!fi.depth_len && d0 && !memcmp(d, d0, sizeof(float) * 48 * 32));
        }
        free(d0);
        d0 = d;
        prev = fi.samples, rising++;
    }
    free(d0);
    CHECK(prev >= 5 && same_depth >= 3);
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"drag\",\"dx\":30,\"dy\":0,\"id\":1}", &err), err);
    do {
        if (web_next_frame(c, &fi, NULL, NULL)) return 1;
    } while (fi.input_id < 1);
    if (fi.samples >= prev) fprintf(stderr, "after the drag: %u samples, before %u\n", fi.samples, prev);
    CHECK(fi.samples < prev);
    sy_web_client_close(c);
    return web_stop(&s);
}

/* web_frame: sy_web_frame_pack / _parse / _depth on a made-up frame, and hostile variants */
int test_frame(void)
{
    sy_error err = {0};
    enum { W = 37, H = 23 };
    float depth[W * H];
    for (int i = 0; i < W * H; ++i) depth[i] = (i % 7 == 3) ? INFINITY : 0.5f + 0.37f * (float)(i % 211);
    depth[5] = -1.0f, depth[6] = NAN; /* nothing, too */
    const uint8_t jpeg[5] = {1, 2, 3, 4, 5};
    sy_web_frame_info fi = {.width = W, .height = H, .backend = 2, .samples = 9, .render_ms = 12.5f, .seq = 77,
                            .input_id = 5, .flags = SY_WEB_FRAME_PROGRESSIVE,
                            .orbit = {.target = {1, 2, 3}, .yaw = 0.5f, .pitch = -0.25f, .dist = 4}};
    sy_orbit_matrix(&fi.orbit, &fi.view.camera_to_world);
    fi.view.window[0] = -0.6f, fi.view.window[1] = 0.6f, fi.view.window[2] = -0.4f, fi.view.window[3] = 0.4f;
    fi.view.znear = 0.01f, fi.view.zfar = 100.0f;
    uint8_t *buf = NULL;
    size_t len = 0;
    CHECK_OK(sy_web_frame_pack(&fi, jpeg, sizeof jpeg, depth, 16, &buf, &len, &err), err);
    CHECK(len == SY_WEB_FRAME_HEADER + sizeof jpeg + fi.depth_len && fi.depth_len > 0);
    CHECK(fi.depth_coding == SY_WEB_DEPTH_GRID_LOG12);
    /* the grid: every fourth pixel and the last column and row */
#define ON_GRID(x, y) (((x) % 4 == 0 || (x) == W - 1) && ((y) % 4 == 0 || (y) == H - 1))
    float lo = INFINITY, hi = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            if (ON_GRID(x, y) && isfinite(depth[y * W + x]) && depth[y * W + x] > 0)
                lo = fminf(lo, depth[y * W + x]), hi = fmaxf(hi, depth[y * W + x]);
    CHECK(fi.depth_min == lo && fi.depth_max == hi);
    sy_web_frame_info g;
    const uint8_t *jp = NULL, *dp = NULL;
    CHECK_OK(sy_web_frame_parse(buf + 16, len, &g, &jp, &dp, &err), err);
    CHECK(g.width == W && g.height == H && g.backend == 2 && g.samples == 9 && g.render_ms == 12.5f && g.seq == 77 &&
          g.input_id == 5 && g.flags == SY_WEB_FRAME_PROGRESSIVE && g.jpeg_len == sizeof jpeg && !memcmp(jp, jpeg, sizeof jpeg));
    CHECK(!memcmp(&g.view.camera_to_world, &fi.view.camera_to_world, sizeof g.view.camera_to_world) &&
          g.view.window[1] == 0.6f && g.view.znear == 0.01f && g.view.zfar == 100.0f && g.orbit.target[2] == 3 &&
          g.orbit.yaw == 0.5f && g.orbit.pitch == -0.25f && g.orbit.dist == 4);
    float *d = NULL;
    CHECK_OK(sy_web_frame_depth(&g, dp, &d, &err), err);
    double step = log(g.depth_max / g.depth_min) / 4094, worst = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            int i = y * W + x;
            if (ON_GRID(x, y)) { /* a grid point: its own value, within half a 12-bit step */
                bool hit = isfinite(depth[i]) && depth[i] > 0;
                CHECK(hit == isfinite(d[i]));
                if (hit) worst = fmax(worst, fabs(log(d[i] / depth[i])));
            } else { /* between: from the grid points around it, so within the range */
                CHECK(!isfinite(d[i]) || (d[i] >= g.depth_min * 0.999f && d[i] <= g.depth_max * 1.001f));
            }
        }
    CHECK(worst <= 0.51 * step + 1e-6); /* half a quantisation step (relative) */
    free(d);
    /* a smooth surface (a tilted plane) codes to far fewer bytes than its 2 bytes per grid value,
     * and every pixel between grid points comes back within two steps (1 / depth is linear in x
     * and y on a plane: the interpolation is exact but for the quantisation) */
    {
        enum { PW = 322, PH = 181 };
        float *plane = malloc(sizeof(float) * PW * PH);
        for (int y = 0; y < PH; ++y)
            for (int x = 0; x < PW; ++x) plane[y * PW + x] = 2.0f / (0.3f + 0.002f * (float)y + 0.0007f * (float)x);
        sy_web_frame_info pf = {.width = PW, .height = PH, .seq = 1};
        uint8_t *pb = NULL;
        size_t pl = 0;
        CHECK_OK(sy_web_frame_pack(&pf, jpeg, sizeof jpeg, plane, 0, &pb, &pl, &err), err);
        size_t grid = (size_t)((PW - 1 + 3) / 4 + 1) * ((PH - 1 + 3) / 4 + 1);
        printf("web_frame: a tilted plane of %dx%d codes to %u depth bytes (%zu grid values)\n", PW, PH, pf.depth_len, grid);
        CHECK(pf.depth_len > 0 && pf.depth_len < grid / 4);
        float *pd = NULL;
        CHECK_OK(sy_web_frame_parse(pb, pl, &g, NULL, &dp, &err), err);
        CHECK_OK(sy_web_frame_depth(&g, dp, &pd, &err), err);
        double pstep = log(g.depth_max / g.depth_min) / 4094, pworst = 0;
        for (int i = 0; i < PW * PH; ++i) pworst = fmax(pworst, fabs(log(pd[i] / plane[i])));
        printf("web_frame: the plane's worst relative error %.2g (%.2f steps)\n", pworst, pworst / pstep);
        CHECK(pworst <= 2 * pstep);
        free(pd);
        free(pb);
        free(plane);
    }
    /* a frame that says it has the last depth channel: header and payload only; with depth bytes: refused */
    {
        uint8_t *h2 = malloc(len);
        memcpy(h2, buf + 16, len);
        sy_web_frame_drop_depth(h2);
        CHECK_OK(sy_web_frame_parse(h2, SY_WEB_FRAME_HEADER + sizeof jpeg, &g, NULL, &dp, &err), err);
        CHECK((g.flags & SY_WEB_FRAME_SAME_DEPTH) && !g.depth_len && !dp);
        uint32_t dl = fi.depth_len;
        memcpy(h2 + 48, &dl, 4);
        CHECK(sy_web_frame_parse(h2, len, &g, NULL, &dp, &err) == SY_ERR_PROTOCOL && strstr(err.message, "last one"));
        free(h2);
    }
    /* hostile: truncated, foreign magic, format 1, a size that does not add up, depth of another size */
    CHECK(sy_web_frame_parse(buf + 16, len - 1, &g, NULL, NULL, &err) == SY_ERR_PROTOCOL);
    CHECK(sy_web_frame_parse(buf + 16, 100, &g, NULL, NULL, &err) == SY_ERR_PROTOCOL);
    uint8_t *bad = malloc(len);
    memcpy(bad, buf + 16, len);
    bad[3] = '2';
    CHECK(sy_web_frame_parse(bad, len, &g, NULL, NULL, &err) == SY_ERR_PROTOCOL && strstr(err.message, "format 2"));
    bad[0] = 'X', bad[3] = '3';
    CHECK(sy_web_frame_parse(bad, len, &g, NULL, NULL, &err) == SY_ERR_PROTOCOL);
    memcpy(bad, buf + 16, len);
    uint32_t w2 = W + 1;
    memcpy(bad + 4, &w2, 4); /* the depth no longer matches the size */
    CHECK_OK(sy_web_frame_parse(bad, len, &g, NULL, &dp, &err), err);
    CHECK(sy_web_frame_depth(&g, dp, &d, &err) == SY_ERR_PROTOCOL && !d);
    memcpy(bad, buf + 16, len);
    float nan = NAN, neg = -1.0f;
    memcpy(bad + 56, &neg, 4); /* a depth range that is no range: refused before decoding */
    CHECK(sy_web_frame_parse(bad, len, &g, NULL, &dp, &err) == SY_ERR_PROTOCOL && strstr(err.message, "depth range"));
    memcpy(bad + 56, &nan, 4);
    CHECK(sy_web_frame_parse(bad, len, &g, NULL, &dp, &err) == SY_ERR_PROTOCOL);
    memcpy(bad, buf + 16, len);
    uint32_t huge = 8192;
    memcpy(bad + 4, &huge, 4), memcpy(bad + 8, &huge, 4); /* 64 M pixels from a few hundred bytes: refused before allocating */
    CHECK_OK(sy_web_frame_parse(bad, len, &g, NULL, &dp, &err), err);
    CHECK(sy_web_frame_depth(&g, dp, &d, &err) == SY_ERR_PROTOCOL && strstr(err.message, "cannot hold"));
    free(bad);
    free(buf);
    return 0;
}

/* the next frame of c at w x h (others skipped), its payload and depth */
static int next_sized(sy_web_client *c, uint32_t w, uint32_t h, sy_web_frame_info *fi, uint8_t **pay, size_t *n)
{
    sy_error err = {0};
    for (int k = 0; k < 200; ++k) {
        free(*pay);
        *pay = NULL;
        CHECK_OK(sy_web_client_next_frame(c, 60000, fi, pay, n, &err), err);
        if (fi->width == w && fi->height == h) return 0;
    }
    CHECK_MSG(false, "no %ux%u frame in 200", w, h);
    return 1;
}

static double mad_rgba(const uint8_t *a, const uint8_t *b, size_t n)
{
    double s = 0;
    for (size_t i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k) s += abs((int)a[4 * i + k] - (int)b[4 * i + k]);
    return s / (3.0 * n);
}

#define W_V 128
#define H_V 96
#define SW "128"
#define SH "96"
int test_video_stream(uint16_t port)
{
    sy_error err = {0};
    sy_web_client *v = NULL, *j = NULL, *b = NULL;
    sy_web_client_opts o = {.host = "127.0.0.1", .port = port, .path = "/ws"};
    CHECK_OK(sy_web_client_connect(&o, 10000, &v, &err), err);
    CHECK_OK(sy_web_client_connect(&o, 10000, &j, &err), err);
    /* the video viewer first: the JPEG viewer may then be sent a frame made for video only (its
     * JPEG made on the network thread) */
    CHECK_OK(sy_web_client_send(v, "{\"t\":\"size\",\"w\":" SW ",\"h\":" SH ",\"v\":3,\"codecs\":[\"vp10\",\"VP9\",5,\"vp9\",\"vp8\"]}", &err), err);
    sy_web_frame_info fi;
    uint8_t *pay = NULL, *jp = NULL, *jpx = NULL;
    size_t n = 0, jn = 0;
    /* JPEG frames may come first (made before the viewer chose): then its first VP9 frame */
    do {
        if (next_sized(v, W_V, H_V, &fi, &pay, &n)) return 1;
    } while (fi.codec == SY_WEB_CODEC_JPEG);
    CHECK(fi.codec == SY_WEB_CODEC_VP9);
    CHECK_MSG(fi.flags & SY_WEB_FRAME_KEYFRAME, "the first VP9 frame is no keyframe (flags %u)", fi.flags);
    CHECK_MSG(fi.quality > 25 && fi.quality < 100, "PSNR %g", (double)fi.quality);
    CHECK(fi.depth_len > 0);
    CHECK_OK(sy_web_client_send(j, "{\"t\":\"size\",\"w\":" SW ",\"h\":" SH ",\"v\":3}", &err), err);
    sy_web_video_decoder *d = NULL;
    CHECK_OK(sy_web_video_decoder_create(SY_WEB_CODEC_VP9, &d, &err), err);
    const uint8_t *px = NULL;
    uint32_t dw = 0, dh = 0;
    CHECK_OK(sy_web_video_decode(d, pay, n, &px, &dw, &dh, &err), err);
    CHECK(dw == W_V && dh == H_V);
    /* the JPEG viewer's picture of the same (resting) view */
    if (next_sized(j, W_V, H_V, &fi, &jp, &jn)) return 1;
    CHECK(fi.codec == SY_WEB_CODEC_JPEG);
    CHECK_OK(sy_jpeg_decode_rgba8(jp, jn, 0, &jpx, &dw, &dh, &err), err);
    double mad = mad_rgba(px, jpx, W_V * H_V);
    printf("VP9 %zu bytes against JPEG %zu, mean abs diff %.2f\n", n, jn, mad);
    CHECK_MSG(mad < 6, "VP9 and JPEG pictures differ by %.2f", mad);
    free(jpx);
    /* a keyframe when asked */
    CHECK_OK(sy_web_client_send(v, "{\"t\":\"keyframe\"}", &err), err);
    if (next_sized(v, W_V, H_V, &fi, &pay, &n)) return 1;
    CHECK(fi.codec == SY_WEB_CODEC_VP9 && (fi.flags & SY_WEB_FRAME_KEYFRAME));
    CHECK_OK(sy_web_video_decode(d, pay, n, &px, &dw, &dh, &err), err);
    /* a drag: every frame up to the one answering it decodes in order, delta frames among them */
    CHECK_OK(sy_web_client_send(v, "{\"t\":\"drag\",\"dx\":12,\"dy\":0,\"id\":1}", &err), err);
    int deltas = 0, frames = 0;
    do {
        free(pay);
        pay = NULL;
        CHECK_OK(sy_web_client_next_frame(v, 60000, &fi, &pay, &n, &err), err);
        CHECK(fi.codec == SY_WEB_CODEC_VP9);
        CHECK_OK(sy_web_video_decode(d, pay, n, &px, &dw, &dh, &err), err);
        CHECK(dw == fi.width && dh == fi.height);
        deltas += !(fi.flags & SY_WEB_FRAME_KEYFRAME), frames++;
    } while (fi.input_id < 1 || fi.width != W_V);
    printf("the drag: %d frames, %d of them delta frames\n", frames, deltas);
    sy_web_video_decoder_destroy(d);
    /* codecs that are no array, or only unknown names: JPEG */
    static const char *const jpeg_only[] = {"{\"t\":\"size\",\"w\":" SW ",\"h\":" SH ",\"v\":3,\"codecs\":\"vp8\"}",
                                            "{\"t\":\"size\",\"w\":" SW ",\"h\":" SH ",\"v\":3,\"codecs\":[\"vp8x\",\"h264\"]}"};
    sy_web_client_close(v);
    sy_web_client_close(j);
    v = j = NULL;
    for (int k = 0; k < 2; ++k) {
        /* max_clients is 3: retried while the server still closes the connections before (a hang guard only) */
        b = NULL;
        for (int t = 0; t < 3000 && !b; ++t)
            if (sy_web_client_connect(&o, 10000, &b, &err) != SY_OK) usleep(100000);
        CHECK_MSG(b, "no viewer connection: %s", err.message);
        CHECK_OK(sy_web_client_send(b, jpeg_only[k], &err), err);
        if (next_sized(b, W_V, H_V, &fi, &pay, &n)) return 1;
        CHECK_MSG(fi.codec == SY_WEB_CODEC_JPEG, "%s: codec %d", jpeg_only[k], fi.codec);
        if (web_check_jpeg(pay, n, W_V, H_V)) return 1;
        sy_web_client_close(b);
    }
    free(pay);
    free(jp);
    sy_web_client_close(v);
    sy_web_client_close(j);
    return 0;
}

/* Moving frames of a 640 x 360 view through the governor as the server drives it: a render stub
 * (2 ms + 4e-5 ms per pixel: 11.2 ms at full size) and an encoder stub on the "network thread"
 * (per_px ms per pixel, 0: none) whose cost is known after the frame was sent (sy_web_cost.h)
 * and added to the next frames' reports; simulated clock, no time measured. The last frame's width. */
static uint32_t governed_width(double per_px, double *total_ms)
{
    sy_error err = {0};
    sy_governor *g = NULL;
    if (sy_governor_create(NULL, &g, &err) != SY_OK) return 0;
    sy_web_encode_cost enc = {0};
    sy_governor_frame f = {0};
    double now = 0, sum = 0;
    for (int i = 0; i < 60; ++i) {
        sy_governor_plan(g, 640, 360, 0, true, now, &f);
        double px = (double)f.width * f.height, render = 2.0 + 4e-5 * px, encode = per_px * px;
        sy_governor_report(g, &f, sy_web_frame_cost_ms(render, enc.per_px_ms, f.width, f.height));
        if (per_px > 0) sy_web_encode_cost_add(&enc, encode, (uint64_t)px); /* measured as it is sent */
        sum = render + encode;
        now += sum + 1.0;
    }
    sy_governor_destroy(g);
    *total_ms = sum;
    return f.width;
}

/* encodecost: the governor counts the encoders' time: with a slow encoder stub (1.5e-4 ms per
 * pixel: 34.6 ms at 640 x 360) it picks a smaller moving frame than without, one whose render and
 * encode fit the budget (33 ms); the cost per pixel is a weighted mean; --quality maps to the
 * video quantizer */
int test_encode_cost(void)
{
    double fast_ms = 0, slow_ms = 0, bad_ms = 0;
    uint32_t fast = governed_width(0, &fast_ms), slow = governed_width(1.5e-4, &slow_ms);
    /* the same slow encoder left out of the reports (before this change): the frames overrun */
    sy_governor *g = NULL;
    sy_error err = {0};
    CHECK_OK(sy_governor_create(NULL, &g, &err), err);
    sy_governor_frame f = {0};
    double now = 0;
    for (int i = 0; i < 60; ++i) {
        sy_governor_plan(g, 640, 360, 0, true, now, &f);
        double px = (double)f.width * f.height, render = 2.0 + 4e-5 * px;
        sy_governor_report(g, &f, render);
        bad_ms = render + 1.5e-4 * px;
        now += bad_ms + 1.0;
    }
    sy_governor_destroy(g);
    printf("encodecost: without an encoder %u px wide (%.1f ms a frame); a slow encoder counted: %u px (%.1f ms), "
           "not counted: %u px (%.1f ms)\n",
           fast, fast_ms, slow, slow_ms, f.width, bad_ms);
    CHECK(fast == 640 && slow > 0 && slow < fast && slow < f.width);
    CHECK(slow_ms <= 33.0 && bad_ms > 33.0);
    sy_web_encode_cost c = {0};
    CHECK(sy_web_encode_cost_add(&c, 10.0, 1000) == 0.01 && c.frames == 1);
    sy_web_encode_cost_add(&c, 20.0, 1000);
    CHECK(fabs(c.per_px_ms - (0.01 + SY_WEB_COST_WEIGHT * 0.01)) < 1e-12 && c.frames == 2);
    CHECK(sy_web_encode_cost_add(&c, NAN, 1000) == 0 && sy_web_encode_cost_add(&c, 5, 0) == 0 && c.frames == 2);
    CHECK(sy_web_frame_cost_ms(5.0, 0.001, 100, 10) == 6.0 && sy_web_frame_cost_ms(5.0, NAN, 100, 10) == 5.0);
    CHECK(sy_web_video_quantizer(80) == SY_WEB_VIDEO_QUANTIZER && sy_web_video_quantizer(95) == 12 &&
          sy_web_video_quantizer(100) == 4 && sy_web_video_quantizer(1) == 63 && sy_web_video_quantizer(60) == 63);
    return 0;
}
