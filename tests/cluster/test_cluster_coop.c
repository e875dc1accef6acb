/* test_cluster_coop.c — cooperative cluster frames end to end with render servers as separate
 * processes on 127.0.0.1 (random free ports): the merge of two servers' samples equals the exact
 * mean of all samples (with the "coop_test" progressive double), the real path tracer's merged
 * frame has the error of the samples of both; cooperative pipelining (issue 39): the next frame's
 * requests reach the servers before it is asked for, merges stay exact after answers used and
 * dropped, a pipelined path tracer equals one without bit for bit (also after a camera move), and
 * a fake server answering the request sent ahead twice, for a round not asked for, or late is
 * dropped with the reason logged.
 *
 *   test_cluster_coop SERVER_EXE WORK_DIR [GROUP]   (GROUP: only the groups whose name holds it)
 * Every server is started with --max-lifetime and stopped with SIGTERM (SIGKILL after 5 s), and
 * every wait is bounded, so nothing outlives the test. */
#include "net_fixture.h"
#include "raw_peer.h"

#include <arpa/inet.h>
#include <math.h>
#include <netinet/in.h>
#include <poll.h>
#include <pthread.h>
#include <sys/socket.h>
#include <unistd.h>

static double rms_diff(const sy_layer *a, const sy_layer *b)
{
    double s = 0;
    size_t n = (size_t)a->width * a->height;
    for (size_t i = 0; i < n * 4; ++i) {
        if (i % 4 == 3) continue;
        double d = (double)a->rgba[i] - b->rgba[i];
        s += d * d;
    }
    return sqrt(s / (double)(n * 3));
}

static double mean_rgb(const sy_layer *a)
{
    double s = 0;
    size_t n = (size_t)a->width * a->height;
    for (size_t i = 0; i < n * 4; ++i)
        if (i % 4 != 3) s += a->rgba[i];
    return s / (double)(n * 3);
}


/* The first frame of the cooperative tests: a client of the first two servers (*c, the caller's)
 * renders backend from view at 8 samples a server (the frame in *f) into out (created here); the
 * two servers' samples make 16. */
static int cooperative_first(fixture *fx, server *s, const char *backend, const sy_camera_view *view, uint32_t timeout_ms,
                             sy_cluster_client **c, sy_cluster_frame *f, sy_layer *out, sy_cluster_frame_stats *st)
{
    sy_error e = {0};
    *c = connect_all(fx, s, 2, "s3cret", timeout_ms, &e);
    CHECK_MSG(*c != NULL, "%s", e.message);
    CHECK_OK(sy_layer_create(fx->w, fx->h, out, &e), e);
    *f = make_frame(fx, SY_CLUSTER_COOPERATIVE, backend, view);
    f->samples = 8;
    CHECK_OK(sy_cluster_client_render(*c, f, out, st, &e), e);
    CHECK(st->samples == 16);
    return 0;
}

/* The real path tracer: 2 servers x 8 samples merged vs local renders. Same mean within noise, and
 * the merged error against a 64-sample reference is that of 16 samples, not of 8. */
static int test_cooperative_pathtracer(fixture *fx, server *s)
{
    if (!sy_mediator_find("pathtracer")) {
        printf("cooperative pathtracer: skipped (no 'pathtracer' back-end registered)\n");
        return 0;
    }
    sy_error e = {0};
    sy_layer ref = {0}, l8 = {0}, l16 = {0}, out = {0};
    sy_camera_view view;
    if (local_render_spp(fx, "pathtracer", SY_EYE_MONO, 64, 1000, &ref, &view)) return 1;
    if (local_render_spp(fx, "pathtracer", SY_EYE_MONO, 8, 7, &l8, NULL)) return 1;
    if (local_render_spp(fx, "pathtracer", SY_EYE_MONO, 16, 7, &l16, NULL)) return 1;
    sy_cluster_client *c = NULL;
    sy_cluster_frame f;
    sy_cluster_frame_stats st;
    CHECK(cooperative_first(fx, s, "pathtracer", &view, 60000, &c, &f, &out, &st) == 0);
    CHECK(sy_layer_count_nonfinite(&out) == 0);
    double mr = mean_rgb(&ref), mc = mean_rgb(&out);
    double e8 = rms_diff(&l8, &ref), e16 = rms_diff(&l16, &ref), ec = rms_diff(&out, &ref);
    printf("cooperative pathtracer: mean %.5f vs reference %.5f; rms error 8 spp %.5f, 16 spp %.5f, merged 2x8 %.5f\n",
           mc, mr, e8, e16, ec);
    CHECK_MSG(fabs(mc - mr) < 0.03 * mr + 1e-4, "merged mean %g vs %g", mc, mr);
    CHECK_MSG(ec < 0.5 * (e8 + e16) * 1.15 && ec < e8, "merged error %g is not that of 16 samples (8: %g, 16: %g)", ec,
              e8, e16);
    /* the next frame keeps accumulating on both servers: 32 samples, a smaller error */
    CHECK_OK(sy_cluster_client_render(c, &f, &out, &st, &e), e);
    double ec2 = rms_diff(&out, &ref);
    printf("cooperative pathtracer: second frame %llu samples, rms error %.5f\n", (unsigned long long)st.samples, ec2);
    CHECK(st.samples == 32 && ec2 < ec);
    /* pipelining keeps every merged image what it was (issue 39): a client that never sends ahead
     * renders the same frames on the same servers bit for bit, the third (pipelined here) and one
     * after a camera move, for which this client drops its answers of the old view */
    const char *urls[2] = {s[0].url, s[1].url};
    sy_cluster_client_opts co = {.urls = urls, .url_count = 2, .secret = (const uint8_t *)"s3cret", .secret_len = 6,
                                 .timeout_ms = 60000, .connect_timeout_ms = 3000, .no_pipeline = true};
    sy_cluster_client *c2 = NULL;
    sy_layer o2 = {0};
    sy_cluster_frame_stats s2;
    CHECK_OK(sy_cluster_client_create(fx->scene, &co, &c2, &e), e);
    CHECK_OK(sy_layer_create(fx->w, fx->h, &o2, &e), e);
    for (int i = 0; i < 3; ++i) CHECK_OK(sy_cluster_client_render(c2, &f, &o2, &s2, &e), e);
    CHECK_OK(sy_cluster_client_render(c, &f, &out, &st, &e), e);
    CHECK_MSG(st.pipelined == 2 && st.samples == 48 && s2.pipelined == 0 && s2.samples == 48,
              "frame 3: %u / %u answers requested ahead, %llu / %llu samples", st.pipelined, s2.pipelined,
              (unsigned long long)st.samples, (unsigned long long)s2.samples);
    CHECK_MSG(same_region(&out, 0, &o2, fx->w, fx->h), "pipelined frame 3 differs from the one without pipelining");
    f.camera.camera_to_world.m[12] += 0.05f;
    CHECK_OK(sy_cluster_client_render(c2, &f, &o2, &s2, &e), e);
    CHECK_OK(sy_cluster_client_render(c, &f, &out, &st, &e), e);
    CHECK_MSG(st.stale == 2 && st.pipelined == 0 && st.samples == 16 && s2.samples == 16,
              "after the move: %u stale answers, %llu / %llu samples", st.stale, (unsigned long long)st.samples,
              (unsigned long long)s2.samples);
    CHECK_MSG(same_region(&out, 0, &o2, fx->w, fx->h), "the frame after a move differs from the one without pipelining");
    sy_cluster_client_destroy(c2);
    sy_cluster_client_destroy(c);
    DESTROY_LAYERS(&ref, &l8, &l16, &out, &o2);
    return 0;
}

/* $COOP_DOUBLE_TRACE of the servers (set in main): the requests their "coop_test" contexts got */
static char g_coop_trace[600];

/* Whether the trace file holds the line (waits for it: 60 s, a hang guard). */
static bool trace_has(const char *path, const char *line)
{
    for (int i = 0; i < 1200; ++i) {
        FILE *f = fopen(path, "r");
        if (f) {
            static char buf[1 << 16];
            size_t n = fread(buf, 1, sizeof buf - 1, f);
            fclose(f);
            buf[n] = 0;
            for (const char *p = buf; (p = strstr(p, line)) != NULL; ++p)
                if (p == buf || p[-1] == '\n') return true;
        }
        sleep_ms(50);
    }
    return false;
}

/* Largest difference of out's red channel (every step-th pixel) from the mean of the double's
 * samples first .. first + n - 1. */
static double coop_merge_error(const fixture *fx, const sy_layer *out, uint32_t first, uint32_t n, uint32_t step)
{
    double maxerr = 0;
    for (uint32_t y = 0; y < fx->h; y += step)
        for (uint32_t x = 0; x < fx->w; x += step) {
            double sum = 0;
            for (uint32_t k = 0; k < n; ++k) sum += coop_double_sample(x, y, first + k);
            double d = fabs(out->rgba[((size_t)y * fx->w + x) * 4] - sum / n);
            if (d > maxerr) maxerr = d;
        }
    return maxerr;
}

static int test_cooperative(fixture *fx, server *s)
{
    sy_error e = {0};
    sy_layer out = {0};
    sy_camera_view view = sy_camera_view_frame_bounds(&(sy_bounds){{-1, -1, -1}, {1, 1, 1}}, 1.0f);
    sy_cluster_client *c = NULL;
    sy_cluster_frame f;
    sy_cluster_frame_stats st;
    CHECK(cooperative_first(fx, s, "coop_test", &view, 30000, &c, &f, &out, &st) == 0);
    /* the merged image is the mean over samples 0..15 of every pixel: disjoint ranges, exact weights */
    double maxerr = 0;
    for (uint32_t y = 0; y < fx->h; ++y)
        for (uint32_t x = 0; x < fx->w; ++x) {
            double sum = 0;
            for (uint32_t k = 0; k < 16; ++k) sum += coop_double_sample(x, y, k);
            double d = fabs(out.rgba[((size_t)y * fx->w + x) * 4] - sum / 16.0);
            if (d > maxerr) maxerr = d;
        }
    CHECK_MSG(maxerr < 1e-6, "cooperative merge off by %g", maxerr);
    /* a second frame adds new, disjoint samples (32 in all) */
    CHECK_OK(sy_cluster_client_render(c, &f, &out, &st, &e), e);
    CHECK(st.samples == 32);
    maxerr = 0;
    for (uint32_t y = 0; y < fx->h; y += 7)
        for (uint32_t x = 0; x < fx->w; x += 5) {
            double sum = 0;
            for (uint32_t k = 0; k < 32; ++k) sum += coop_double_sample(x, y, k);
            double d = fabs(out.rgba[((size_t)y * fx->w + x) * 4] - sum / 32.0);
            if (d > maxerr) maxerr = d;
        }
    CHECK_MSG(maxerr < 1e-6, "second cooperative frame off by %g", maxerr);
    CHECK(st.pipelined == 0 && st.stale == 0);
    /* pipelining (issue 39): frame 2 asked what frame 1 asked, so each server got frame 3's request
     * (samples 32..39 and 40..47) as soon as its frame-2 answer was in, before the client merged
     * frame 2: the servers render them before frame 3 is even asked for */
    CHECK_MSG(trace_has(g_coop_trace, "32 8\n") && trace_has(g_coop_trace, "40 8\n"),
              "the servers never got frame 3's requests ahead of the call (trace %s)", g_coop_trace);
    CHECK_OK(sy_cluster_client_render(c, &f, &out, &st, &e), e);
    CHECK_MSG(st.samples == 48 && st.pipelined == 2 && st.stale == 0, "frame 3: %llu samples, %u answers requested ahead, %u stale",
              (unsigned long long)st.samples, st.pipelined, st.stale);
    CHECK_MSG(coop_merge_error(fx, &out, 0, 48, 1) < 1e-6, "third (pipelined) cooperative frame off by %g",
              coop_merge_error(fx, &out, 0, 48, 1));
    /* a frame that asks otherwise (4 samples a server): the answers to frame 4's requests sent ahead
     * (samples 48..63) are dropped, never merged, and the new ranges start past them (64..71): the
     * double keeps every sample it drew (it never restarts, as a path tracer at an unchanged view),
     * so the merged image is the exact mean of 72 distinct samples */
    f.samples = 4;
    CHECK_OK(sy_cluster_client_render(c, &f, &out, &st, &e), e);
    CHECK_MSG(st.samples == 72 && st.pipelined == 0 && st.stale == 2, "frame 4: %llu samples, %u answers requested ahead, %u stale",
              (unsigned long long)st.samples, st.pipelined, st.stale);
    CHECK_MSG(coop_merge_error(fx, &out, 0, 72, 1) < 1e-6, "frame after the stale answers off by %g",
              coop_merge_error(fx, &out, 0, 72, 1));
    sy_cluster_client_destroy(c);
    sy_layer_destroy(&out);
    return 0;
}

/* ---- a fake render server for the pipelining tests: answers like a server (no secret, loopback),
 * with flat tiles, and misbehaves on the request of frame 3 as its mode says ---- */
enum { FAKE_TWICE = 1, FAKE_WRONG_ROUND = 2, FAKE_LATE = 3 };
typedef struct fake_server {
    int listen_fd, port, mode, late_ms;
    pthread_t th;
} fake_server;

static void *fake_main(void *p)
{
    fake_server *fs = p;
    struct pollfd pfd = {fs->listen_fd, POLLIN, 0};
    if (poll(&pfd, 1, 30000) != 1) return NULL; /* fake_stop closes the listening socket */
    int fd = accept(fs->listen_fd, NULL, NULL);
    close(fs->listen_fd); /* one connection: a redial is refused at once */
    fs->listen_fd = -1;
    if (fd < 0) return NULL;
    struct timeval tv = {30, 0};
    setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);
    uint64_t seq = 0, samples = 0;
    sy_layer l = {0};
    sy_cluster_buf enc = {0};
    sy_error e = {0};
    for (;;) {
        sy_cluster_msg m, rep;
        uint8_t *raw = NULL;
        if (raw_recv_msg(fd, 1u << 26, &m, &raw) != 0) break;
        memset(&rep, 0, sizeof rep);
        bool twice = false;
        if (m.header.type == SY_CLUSTER_HELLO) {
            rep.header.type = SY_CLUSTER_CHALLENGE; /* no secret: the session is open */
            rep.u.hello.max_frame = SY_CLUSTER_DEFAULT_MAX_FRAME;
            rep.u.hello.max_message = SY_CLUSTER_DEFAULT_MAX_MESSAGE;
            snprintf(rep.u.hello.name, sizeof rep.u.hello.name, "fake");
        } else if (m.header.type == SY_CLUSTER_SCENE) {
            rep.header.type = SY_CLUSTER_SCENE_ACK;
            rep.u.ack.frame = m.u.scene.frame;
        } else if (m.header.type == SY_CLUSTER_RENDER && m.u.render.tile_count == 1) {
            const sy_cluster_rect *r = &m.u.render.tiles[0];
            sy_layer_destroy(&l);
            enc.size = 0;
            if (sy_layer_create(r->w, r->h, &l, &e) != SY_OK) break;
            for (size_t i = 0; i < (size_t)r->w * r->h * 4; ++i) l.rgba[i] = 0.5f;
            for (size_t i = 0; i < (size_t)r->w * r->h; ++i) l.depth[i] = 2.0f;
            if (sy_cluster_tile_encode(&l, true, &enc, &e) != SY_OK) break;
            samples += m.u.render.sample_count;
            sy_cluster_tile t = {*r, SY_CLUSTER_ENC_F32_SHUFFLE_ZSTD, 5, (uint64_t)r->w * r->h * 5 * 4, enc.data,
                                 (uint32_t)enc.size};
            rep.header.type = SY_CLUSTER_TILES;
            rep.u.tiles.frame = m.u.render.frame;
            rep.u.tiles.job = m.u.render.job;
            rep.u.tiles.samples = samples;
            rep.u.tiles.tile_count = 1;
            rep.u.tiles.tiles = &t;
            if (m.u.render.frame == 3) {
                twice = fs->mode == FAKE_TWICE;
                if (fs->mode == FAKE_WRONG_ROUND) rep.u.tiles.frame = 99;
                if (fs->mode == FAKE_LATE) sleep_ms(fs->late_ms);
            }
            rep.header.seq = ++seq;
            int rc = raw_send_msg(fd, &rep);
            if (rc == 0 && twice) {
                rep.header.seq = ++seq;
                rc = raw_send_msg(fd, &rep);
            }
            sy_cluster_msg_free(&m);
            free(raw);
            if (rc) break;
            continue;
        } else if (m.header.type == SY_CLUSTER_BYE) {
            rep.header.type = SY_CLUSTER_BYE;
        } else {
            sy_cluster_msg_free(&m);
            free(raw);
            break;
        }
        bool bye = m.header.type == SY_CLUSTER_BYE;
        sy_cluster_msg_free(&m);
        free(raw);
        rep.header.seq = ++seq;
        if (raw_send_msg(fd, &rep) || bye) break;
    }
    sy_layer_destroy(&l);
    sy_cluster_buf_free(&enc);
    close(fd);
    return NULL;
}

static int fake_start(fake_server *fs, int mode, int late_ms)
{
    memset(fs, 0, sizeof *fs);
    fs->mode = mode;
    fs->late_ms = late_ms;
    fs->listen_fd = socket(AF_INET, SOCK_STREAM, 0);
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_addr.s_addr = htonl(INADDR_LOOPBACK)};
    socklen_t len = sizeof a;
    CHECK(fs->listen_fd >= 0 && bind(fs->listen_fd, (struct sockaddr *)&a, sizeof a) == 0 && listen(fs->listen_fd, 4) == 0 &&
          getsockname(fs->listen_fd, (struct sockaddr *)&a, &len) == 0);
    fs->port = ntohs(a.sin_port);
    CHECK(pthread_create(&fs->th, NULL, fake_main, fs) == 0);
    return 0;
}

static void fake_stop(fake_server *fs)
{
    pthread_join(fs->th, NULL);
    if (fs->listen_fd >= 0) close(fs->listen_fd);
}

typedef struct log_capture {
    pthread_mutex_t lock;
    char text[8192];
} log_capture;

static void capture_line(void *user, const char *line)
{
    log_capture *lc = user;
    pthread_mutex_lock(&lc->lock);
    size_t n = strlen(lc->text);
    snprintf(lc->text + n, sizeof lc->text - n, "%s\n", line);
    pthread_mutex_unlock(&lc->lock);
}

/* Bad peers under pipelining (issue 39): a server that answers the request sent ahead twice, with
 * a round it was not asked for, or past the deadline is dropped with the reason logged, as without
 * pipelining, and the frame still comes back whole from the good server (s, no secret). */
static int test_pipeline_bad_peers(fixture *fx, server *all)
{
    server *good = &all[2];
    static const struct {
        int mode;
        const char *why;
        uint32_t fails_in; /* the frame in which the fake is dropped */
    } cases[] = {{FAKE_TWICE, "reply for frame 3 job 1 with 1 tiles does not match the request", 4},
                 {FAKE_WRONG_ROUND, "reply for frame 99 job 1 with 1 tiles does not match the request", 3},
                 {FAKE_LATE, "no reply before the deadline", 3}};
    sy_camera_view view = sy_camera_view_frame_bounds(&(sy_bounds){{-1, -1, -1}, {1, 1, 1}}, 1.0f);
    for (size_t ci = 0; ci < sizeof cases / sizeof cases[0]; ++ci) {
        fake_server fs;
        if (fake_start(&fs, cases[ci].mode, 2500)) return 1;
        char fake_url[64];
        snprintf(fake_url, sizeof fake_url, "tcp://127.0.0.1:%d", fs.port);
        const char *urls[2] = {good->url, fake_url};
        static log_capture lc = {PTHREAD_MUTEX_INITIALIZER, ""};
        lc.text[0] = 0;
        sy_cluster_client_opts co = {.urls = urls, .url_count = 2, .timeout_ms = 1000, .connect_timeout_ms = 3000,
                                     .log = capture_line, .log_user = &lc};
        sy_cluster_client *c = NULL;
        sy_error e = {0};
        CHECK_OK(sy_cluster_client_create(fx->scene, &co, &c, &e), e);
        sy_cluster_frame f = make_frame(fx, SY_CLUSTER_COOPERATIVE, "coop_test", &view);
        f.samples = 4;
        sy_layer out = {0};
        CHECK_OK(sy_layer_create(fx->w, fx->h, &out, &e), e);
        for (uint32_t frame = 1; frame <= 4; ++frame) {
            sy_cluster_frame_stats st;
            sy_cluster_client_set_timeout(c, frame == 1 ? 30000 : 1000); /* the first: snapshot + translation */
            CHECK_OK(sy_cluster_client_render(c, &f, &out, &st, &e), e);
            bool dropped_now = frame == cases[ci].fails_in;
            CHECK_MSG(st.servers_failed == (dropped_now ? 1u : 0u),
                      "mode %d frame %u: %u servers failed", cases[ci].mode, frame, st.servers_failed);
            CHECK_MSG(st.servers_live == (frame < cases[ci].fails_in ? 2u : 1u) || frame > cases[ci].fails_in,
                      "mode %d frame %u: %u servers live", cases[ci].mode, frame, st.servers_live);
            if (frame == 3) CHECK_MSG(st.pipelined >= 1, "mode %d: frame 3 used no answer requested ahead", cases[ci].mode);
        }
        pthread_mutex_lock(&lc.lock);
        bool logged = strstr(lc.text, cases[ci].why) != NULL;
        pthread_mutex_unlock(&lc.lock);
        CHECK_MSG(logged, "mode %d: the log does not say '%s':\n%s", cases[ci].mode, cases[ci].why, lc.text);
        sy_cluster_client_destroy(c);
        sy_layer_destroy(&out);
        fake_stop(&fs);
    }
    return 0;
}

/* s[0], s[1]: the secret "s3cret"; s[2]: no secret (the good peer beside the fakes) */
static int start_servers(server *s)
{
    return start_server("s3cret", 0, &s[0]) || start_server("s3cret", 0, &s[1]) ||
           start_server_args(NULL, 0, (const char *const[]){"--handshake-timeout-ms", "1000", NULL}, &s[2]);
}

static void trace_to_work_dir(void)
{
    snprintf(g_coop_trace, sizeof g_coop_trace, "%s/coop_trace.txt", g_dir);
    unlink(g_coop_trace);
    setenv("COOP_DOUBLE_TRACE", g_coop_trace, 1); /* the servers' "coop_test" contexts log their requests */
}

int main(int argc, char **argv)
{
    static const net_group groups[] = {{"cooperative merge", test_cooperative},
                                       {"cooperative pathtracer", test_cooperative_pathtracer},
                                       {"pipelining beside bad peers", test_pipeline_bad_peers}};
    return net_fixture_main(argc, argv, "test_cluster_coop", trace_to_work_dir, start_servers, groups,
                            sizeof groups / sizeof groups[0]);
}
