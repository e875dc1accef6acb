/* sy_cluster_cli.c — `sy serve`, the `--cluster` options of `sy render` and `sy bench cluster`
 * (see sy_cluster_cli.h). The protocol and the modes live in core/sy_cluster.c. */
#define _GNU_SOURCE /* sched_setaffinity for the pinned benchmark servers */
#include "sy_cluster_cli.h"

#include "sy_demo.h"
#include "sy_exr.h"
#include "sy_file.h"
#include "sy_png.h"

#include <errno.h>
#include <fcntl.h>
#include <sched.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

static volatile int g_stop; /* set by SIGINT / SIGTERM in `sy serve` (the process's only server) */

static void on_signal(int sig)
{
    (void)sig;
    g_stop = 1;
}

static bool has_suffix(const char *s, const char *suffix)
{
    size_t n = strlen(s), m = strlen(suffix);
    return n >= m && strcasecmp(s + n - m, suffix) == 0;
}

static int cli_fail(const char *cmd, const sy_error *e)
{
    fprintf(stderr, "sy %s: error: %s\n", cmd, e->message);
    return 2;
}

/* ---- sy serve ---- */
typedef struct present_ctx {
    const char *output;
} present_ctx;

static sy_result present_tile(void *user, uint64_t frame, const sy_layer *tile, uint32_t x, uint32_t y, uint32_t fw,
                              uint32_t fh, sy_error *err)
{
    present_ctx *p = user;
    if (!p->output) {
        printf("frame %llu: tile %ux%u at %u,%u of %ux%u ready (no --output)\n", (unsigned long long)frame, tile->width,
               tile->height, x, y, fw, fh);
        fflush(stdout);
        return SY_OK;
    }
    if (has_suffix(p->output, ".exr"))
        return sy_exr_write_rgba(p->output, (int)tile->width, (int)tile->height, tile->rgba, tile->depth,
                                 SY_EXR_PIXEL_FLOAT, err);
    return sy_png_write(p->output, (int)tile->width, (int)tile->height, tile->rgba, NULL, err);
}

static sy_result write_port_file(const char *path, int port, sy_error *err)
{
    sy_atomic_file af = {0};
    sy_result r = sy_atomic_file_begin(path, &af, err);
    if (r) return r;
    if (fprintf(af.fp, "%d\n", port) < 0) {
        sy_atomic_file_abort(&af);
        return sy_error_set(err, SY_ERR_IO, "%s: write failed", path);
    }
    return sy_atomic_file_commit(&af, err);
}

int sy_cmd_serve(int argc, char **argv)
{
    sy_cluster_server_opts o = {0};
    const char *secret_file = NULL, *port_file = NULL;
    present_ctx pc = {0};
    for (int i = 0; i < argc; ++i) {
        const char *a = argv[i];
        bool has = i + 1 < argc;
        if (!strcmp(a, "--listen") && has) o.listen_url = argv[++i];
        else if (!strcmp(a, "--secret-file") && has) secret_file = argv[++i];
        else if (!strcmp(a, "--output") && has) pc.output = argv[++i];
        else if (!strcmp(a, "--port-file") && has) port_file = argv[++i];
        else if (!strcmp(a, "--tls-cert") && has) o.tls_cert_file = argv[++i];
        else if (!strcmp(a, "--tls-key") && has) o.tls_key_file = argv[++i];
        else if (!strcmp(a, "--name") && has) o.name = argv[++i];
        else if (!strcmp(a, "--max-sessions") && has) o.max_sessions = (uint32_t)strtoul(argv[++i], NULL, 10);
        else if (!strcmp(a, "--max-lifetime") && has) o.max_lifetime_s = strtod(argv[++i], NULL);
        else {
            fprintf(stderr,
                    "usage: sy serve [--listen tcp://HOST:PORT|tls+tcp://HOST:PORT] [--secret-file F] [--output OUT.exr|png]\n"
                    "                [--port-file F] [--tls-cert PEM --tls-key PEM] [--name NAME] [--max-sessions N]\n"
                    "                [--max-lifetime SECONDS]\n"
                    "  the secret comes from --secret-file or $SY_CLUSTER_SECRET; without one only loopback is allowed\n");
            return 1;
        }
    }
    if (pc.output && !has_suffix(pc.output, ".exr") && !has_suffix(pc.output, ".png")) {
        fprintf(stderr, "sy serve: error: %s: --output must end in .exr or .png\n", pc.output);
        return 1;
    }
    sy_error err = {0};
    uint8_t *secret = NULL;
    size_t secret_len = 0;
    if (sy_cluster_secret_load(secret_file, &secret, &secret_len, &err) != SY_OK) return cli_fail("serve", &err);
    o.secret = secret;
    o.secret_len = secret_len;
    o.present = present_tile;
    o.present_user = &pc;
    o.stop = &g_stop;
    signal(SIGINT, on_signal);
    signal(SIGTERM, on_signal);
    signal(SIGPIPE, SIG_IGN);
    sy_cluster_server *s = NULL;
    sy_result r = sy_cluster_server_create(&o, &s, &err);
    free(secret);
    if (r == SY_OK && port_file) r = write_port_file(port_file, sy_cluster_server_port(s), &err);
    if (r == SY_OK) r = sy_cluster_server_run(s, &err);
    sy_cluster_server_destroy(s);
    return r == SY_OK ? 0 : cli_fail("serve", &err);
}

/* ---- sy render --cluster ---- */
bool sy_cluster_cli_requested(int argc, char **argv)
{
    for (int i = 0; i + 1 < argc; ++i)
        if (!strcmp(argv[i], "--cluster")) return true;
    return false;
}

bool sy_cluster_cli_option(int argc, char **argv, int *i, sy_cluster_cli_opts *o, bool *bad)
{
    const char *a = argv[*i];
    bool has = *i + 1 < argc;
    const char *names[] = {"--cluster", "--cluster-mode", "--secret-file", "--tls-ca", "--timeout-ms", "--frames", "--spp"};
    int which = -1;
    for (int k = 0; k < 7; ++k)
        if (!strcmp(a, names[k])) which = k;
    if (which < 0) return false;
    if (!has) {
        *bad = true;
        return true;
    }
    const char *v = argv[++*i];
    char *end = NULL;
    unsigned long n = 0;
    if (which >= 4) {
        errno = 0;
        n = strtoul(v, &end, 10);
        if (errno || end == v || *end || n < 1 || n > 100000000ul) *bad = true;
    }
    switch (which) {
    case 0: o->cluster = v; break;
    case 1: {
        uint32_t m;
        if (!sy_cluster_mode_parse(v, &m)) *bad = true;
        o->mode = v;
        break;
    }
    case 2: o->secret_file = v; break;
    case 3: o->tls_ca = v; break;
    case 4: o->timeout_ms = (uint32_t)n; break;
    case 5: o->frames = (uint32_t)n; break;
    default: o->samples = (uint32_t)n; break;
    }
    return true;
}

/* A cluster configuration file (`--cluster FILE`), one directive per line, '#' comments:
 *   mode sort-first|balanced|cooperative|multi-display|stereo
 *   server URL [backend NAME] [tile X Y W H]
 * The tokens are stored in *text (owned by the caller) and pointed to from the arrays. */
static sy_result parse_conf(const char *path, char **text, const char **urls, const char **backends,
                            sy_cluster_rect *tiles, uint32_t *n, const char **mode, sy_error *err)
{
    void *data = NULL;
    size_t size = 0;
    sy_result r = sy_file_read_all(path, 1u << 20, &data, &size, err);
    if (r) return r;
    char *buf = realloc(data, size + 1);
    if (!buf) {
        free(data);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", path);
    }
    buf[size] = 0;
    *text = buf;
    *n = 0;
    uint32_t line = 0;
    for (char *save = NULL, *ln = strtok_r(buf, "\n", &save); ln; ln = strtok_r(NULL, "\n", &save)) {
        line++;
        char *hash = strchr(ln, '#');
        if (hash) *hash = 0;
        char *tok[12];
        int nt = 0;
        for (char *s2 = NULL, *t = strtok_r(ln, " \t\r", &s2); t && nt < 12; t = strtok_r(NULL, " \t\r", &s2))
            tok[nt++] = t;
        if (nt == 0) continue;
        if (!strcmp(tok[0], "mode") && nt == 2) {
            uint32_t m;
            if (!sy_cluster_mode_parse(tok[1], &m))
                return sy_error_set(err, SY_ERR_PARSE, "%s:%u: unknown mode '%s'", path, line, tok[1]);
            *mode = tok[1];
        } else if (!strcmp(tok[0], "server") && nt >= 2) {
            if (*n == SY_CLUSTER_MAX_SERVERS)
                return sy_error_set(err, SY_ERR_LIMIT, "%s:%u: more than %u servers", path, line, SY_CLUSTER_MAX_SERVERS);
            urls[*n] = tok[1];
            backends[*n] = NULL;
            memset(&tiles[*n], 0, sizeof tiles[*n]);
            for (int i = 2; i < nt;) {
                if (!strcmp(tok[i], "backend") && i + 1 < nt) {
                    backends[*n] = tok[i + 1];
                    i += 2;
                } else if (!strcmp(tok[i], "tile") && i + 4 < nt) {
                    uint32_t v[4];
                    for (int k = 0; k < 4; ++k) {
                        char *end;
                        errno = 0;
                        unsigned long x = strtoul(tok[i + 1 + k], &end, 10);
                        if (errno || *end || end == tok[i + 1 + k] || x > 16384)
                            return sy_error_set(err, SY_ERR_PARSE, "%s:%u: tile values must be 0..16384", path, line);
                        v[k] = (uint32_t)x;
                    }
                    if (!v[2] || !v[3]) return sy_error_set(err, SY_ERR_PARSE, "%s:%u: empty tile", path, line);
                    tiles[*n] = (sy_cluster_rect){v[0], v[1], v[2], v[3]};
                    i += 5;
                } else {
                    return sy_error_set(err, SY_ERR_PARSE, "%s:%u: unknown server option '%s'", path, line, tok[i]);
                }
            }
            (*n)++;
        } else {
            return sy_error_set(err, SY_ERR_PARSE, "%s:%u: expected 'mode NAME' or 'server URL [backend NAME] [tile X Y W H]'",
                                path, line);
        }
    }
    if (*n == 0) return sy_error_set(err, SY_ERR_PARSE, "%s: no 'server' line", path);
    return SY_OK;
}

sy_result sy_cluster_cli_render(const sy_cluster_cli_opts *o, sy_scene *scene, const sy_viewport_desc *vd, uint32_t w,
                                uint32_t h, sy_layer *out, double *seconds, sy_error *err)
{
    const char *urls[SY_CLUSTER_MAX_SERVERS], *backends[SY_CLUSTER_MAX_SERVERS] = {0}, *conf_mode = NULL;
    sy_cluster_rect tiles[SY_CLUSTER_MAX_SERVERS];
    memset(tiles, 0, sizeof tiles);
    uint32_t n = 0;
    char *list = NULL;
    if (!strstr(o->cluster, "://")) { /* a configuration file */
        sy_result cr = parse_conf(o->cluster, &list, urls, backends, tiles, &n, &conf_mode, err);
        if (cr) {
            free(list);
            return cr;
        }
    } else { /* a comma-separated URL list */
        list = strdup(o->cluster);
        if (!list) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "out of memory");
        for (char *save = NULL, *t = strtok_r(list, ",", &save); t; t = strtok_r(NULL, ",", &save)) {
            if (n == SY_CLUSTER_MAX_SERVERS) {
                free(list);
                return sy_error_set(err, SY_ERR_LIMIT, "--cluster: more than %u servers", SY_CLUSTER_MAX_SERVERS);
            }
            urls[n++] = t;
        }
    }
    uint32_t mode = SY_CLUSTER_SORT_FIRST;
    const char *mode_name = o->mode ? o->mode : conf_mode;
    if (mode_name && !sy_cluster_mode_parse(mode_name, &mode)) {
        free(list);
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "unknown --cluster-mode '%s'", mode_name);
    }
    uint8_t *secret = NULL;
    size_t secret_len = 0;
    sy_result r = sy_cluster_secret_load(o->secret_file, &secret, &secret_len, err);
    sy_window *win = NULL;
    sy_viewport *vp = NULL;
    sy_cluster_client *c = NULL;
    sy_camera_view view;
    if (r == SY_OK) r = sy_window_create(w, h, &win, err);
    if (r == SY_OK) r = sy_window_add_viewport(win, vd, &vp, err);
    if (r == SY_OK) r = sy_viewport_camera_view(vp, scene, w, h, &view, err);
    sy_cluster_client_opts co = {.urls = urls,
                                 .url_count = n,
                                 .secret = secret,
                                 .secret_len = secret_len,
                                 .tls_ca_file = o->tls_ca,
                                 .timeout_ms = o->timeout_ms,
                                 .backends = backends,
                                 .wall_tiles = tiles};
    if (r == SY_OK) r = sy_cluster_client_create(scene, &co, &c, err);
    if (r == SY_OK && mode != SY_CLUSTER_MULTI_DISPLAY)
        r = sy_layer_create(mode == SY_CLUSTER_STEREO ? 2 * w : w, h, out, err);
    sy_cluster_frame f = {.mode = mode,
                          .backend = vd->backend,
                          .params = vd->params,
                          .root_id = vd->root.id,
                          .background_id = vd->background.id,
                          .camera = view,
                          .width = w,
                          .height = h,
                          .samples = o->samples,
                          .depth = true,
                          .eye_separation = vd->eye_separation,
                          .zero_parallax = vd->zero_parallax};
    double t0 = sy_time_now();
    uint32_t frames = o->frames ? o->frames : 1;
    for (uint32_t i = 0; i < frames && r == SY_OK; ++i) {
        sy_cluster_frame_stats st;
        r = sy_cluster_client_render(c, &f, out, &st, err);
        if (r == SY_OK)
            fprintf(stderr,
                    "sy render: cluster frame %u (%s): %u/%u servers, %u failed, %u reassigned, %.3f s, "
                    "%llu bytes sent (%llu scene), %llu received\n",
                    i + 1, sy_cluster_mode_name(mode), st.servers_live, n, st.servers_failed, st.reassigned, st.seconds,
                    (unsigned long long)st.bytes_sent, (unsigned long long)st.scene_bytes,
                    (unsigned long long)st.bytes_received);
        if (r == SY_OK && mode == SY_CLUSTER_COOPERATIVE)
            fprintf(stderr, "sy render: merged %llu samples per pixel\n", (unsigned long long)st.samples);
    }
    *seconds = sy_time_now() - t0;
    sy_cluster_client_destroy(c);
    sy_window_destroy(win);
    free(secret);
    free(list);
    return r;
}

/* ---- sy bench cluster ---- */
typedef struct child_server {
    pid_t pid;
    char url[64];
} child_server;

/* Starts `sy serve` on a free loopback port, pinned to cpu (or unpinned when cpu < 0). */
static sy_result spawn_server(int cpu, child_server *out, sy_error *err)
{
    char port_file[] = "/tmp/sy_bench_portXXXXXX";
    int fd = mkstemp(port_file);
    if (fd < 0) return sy_error_set(err, SY_ERR_IO, "bench: mkstemp: %s", strerror(errno));
    close(fd);
    unlink(port_file);
    pid_t pid = fork();
    if (pid < 0) return sy_error_set(err, SY_ERR_IO, "bench: fork: %s", strerror(errno));
    if (pid == 0) {
        if (cpu >= 0) {
            cpu_set_t set;
            CPU_ZERO(&set);
            CPU_SET(cpu, &set);
            sched_setaffinity(0, sizeof set, &set);
        }
        int devnull = open("/dev/null", 1);
        if (devnull >= 0) dup2(devnull, 2);
        execl("/proc/self/exe", "sy", "serve", "--listen", "tcp://127.0.0.1:0", "--port-file", port_file,
              "--max-lifetime", "600", (char *)NULL);
        _exit(127);
    }
    for (int tries = 0; tries < 200; ++tries) { /* bounded: 10 s */
        FILE *f = fopen(port_file, "r");
        int port = 0;
        if (f) {
            if (fscanf(f, "%d", &port) != 1) port = 0;
            fclose(f);
        }
        if (port > 0) {
            unlink(port_file);
            out->pid = pid;
            snprintf(out->url, sizeof out->url, "tcp://127.0.0.1:%d", port);
            return SY_OK;
        }
        usleep(50000);
    }
    kill(pid, SIGTERM);
    waitpid(pid, NULL, 0);
    return sy_error_set(err, SY_ERR_IO, "bench: the server did not start within 10 s");
}

static void stop_server(child_server *s)
{
    if (s->pid > 0) {
        kill(s->pid, SIGTERM);
        waitpid(s->pid, NULL, 0);
        s->pid = 0;
    }
}

static bool count_all(void *user, const sy_blob *b)
{
    (void)user;
    (void)b;
    return true;
}
static bool count_none(void *user, const sy_blob *b)
{
    (void)user;
    (void)b;
    return false;
}

/* samples per second of cooperative path tracing with the given servers */
static sy_result coop_rate(sy_scene *scene, const sy_viewport_desc *vd, child_server *srv, uint32_t n, uint32_t w,
                           uint32_t h, double *rate, sy_error *err)
{
    const char *urls[2] = {srv[0].url, n > 1 ? srv[1].url : NULL};
    sy_cluster_client_opts co = {.urls = urls, .url_count = n, .timeout_ms = 120000};
    sy_cluster_client *c = NULL;
    sy_window *win = NULL;
    sy_viewport *vp = NULL;
    sy_camera_view view;
    sy_layer out = {0};
    sy_result r = sy_window_create(w, h, &win, err);
    if (r == SY_OK) r = sy_window_add_viewport(win, vd, &vp, err);
    if (r == SY_OK) r = sy_viewport_camera_view(vp, scene, w, h, &view, err);
    if (r == SY_OK) r = sy_cluster_client_create(scene, &co, &c, err);
    if (r == SY_OK) r = sy_layer_create(w, h, &out, err);
    sy_cluster_frame f = {.mode = SY_CLUSTER_COOPERATIVE, .backend = "pathtracer", .root_id = vd->root.id,
                          .camera = view, .width = w, .height = h, .samples = 4};
    sy_cluster_frame_stats st;
    if (r == SY_OK) r = sy_cluster_client_render(c, &f, &out, &st, err); /* warm-up: snapshot + translation */
    uint64_t samples = 0;
    double t0 = sy_time_now(), server = 0;
    for (int i = 0; i < 3 && r == SY_OK; ++i) {
        r = sy_cluster_client_render(c, &f, &out, &st, err);
        samples += (uint64_t)f.samples * n;
        server += st.max_server_seconds;
    }
    double secs = sy_time_now() - t0;
    *rate = (double)samples / secs;
    if (r == SY_OK)
        printf("    %u server(s): %llu samples per pixel in %.3f s (slowest server busy %.3f s)\n", n,
               (unsigned long long)samples, secs, server);
    sy_layer_destroy(&out);
    sy_cluster_client_destroy(c);
    sy_window_destroy(win);
    return r;
}

int sy_cmd_bench_cluster(int argc, char **argv)
{
    uint32_t w = 1920, h = 1080;
    for (int i = 0; i < argc; ++i) {
        if (!strcmp(argv[i], "-w") && i + 1 < argc) w = (uint32_t)strtoul(argv[++i], NULL, 10);
        else if (!strcmp(argv[i], "-h") && i + 1 < argc) h = (uint32_t)strtoul(argv[++i], NULL, 10);
        else {
            fprintf(stderr, "usage: sy bench cluster [-w W] [-h H]\n");
            return 1;
        }
    }
    if (w < 1 || h < 1 || w > 16384 || h > 16384) return 1;
    signal(SIGPIPE, SIG_IGN);
    sy_error err = {0};
    sy_scene *scene = NULL;
    sy_demo_info d;
    child_server srv[2] = {{0}};
    sy_cluster_client *c = NULL;
    sy_window *win = NULL;
    sy_viewport *vp = NULL;
    sy_layer out = {0};
    sy_changes *snap = NULL;
    long ncpu = sysconf(_SC_NPROCESSORS_ONLN);
    sy_result r = sy_scene_create(&scene, &err);
    if (r == SY_OK) r = sy_demo_build(scene, &d, &err);
    if (r == SY_OK) r = sy_scene_commit(scene, NULL, &err);
    /* snapshot size vs the scene's own data */
    void *buf = NULL;
    size_t with_blobs = 0, without = 0;
    if (r == SY_OK) r = sy_scene_snapshot(scene, &snap, &err);
    if (r == SY_OK) r = sy_changes_serialize(snap, count_all, NULL, &buf, &with_blobs, &err);
    free(buf);
    buf = NULL;
    if (r == SY_OK) r = sy_changes_serialize(snap, count_none, NULL, &buf, &without, &err);
    free(buf);
    sy_changes_release(snap);
    if (r == SY_OK) r = spawn_server(ncpu >= 2 ? 0 : -1, &srv[0], &err);
    if (r == SY_OK) r = spawn_server(ncpu >= 2 ? 1 : -1, &srv[1], &err);
    const char *urls[2] = {srv[0].url, srv[1].url};
    sy_cluster_client_opts co = {.urls = urls, .url_count = 2, .timeout_ms = 120000};
    const char *backend = sy_mediator_find("raster") ? "raster" : "whitted";
    sy_viewport_desc vd = {.root = d.root, .camera = d.camera, .background = d.background, .backend = backend};
    sy_camera_view view;
    if (r == SY_OK) r = sy_window_create(w, h, &win, &err);
    if (r == SY_OK) r = sy_window_add_viewport(win, &vd, &vp, &err);
    if (r == SY_OK) r = sy_viewport_camera_view(vp, scene, w, h, &view, &err);
    if (r == SY_OK) r = sy_cluster_client_create(scene, &co, &c, &err);
    if (r == SY_OK) r = sy_layer_create(w, h, &out, &err);
    sy_cluster_frame f = {.mode = SY_CLUSTER_SORT_FIRST, .backend = backend, .root_id = d.root.id,
                          .background_id = d.background.id, .camera = view, .width = w, .height = h};
    sy_cluster_frame_stats s1 = {0}, s2 = {0};
    if (r == SY_OK) r = sy_cluster_client_render(c, &f, &out, &s1, &err);
    /* one transform change */
    if (r == SY_OK) {
        sy_mat4 m;
        r = sy_node_world_matrix(scene, d.camera, &m, &err);
        m.m[12] += 0.01f; /* the demo camera hangs under an identity root: world = local */
        if (r == SY_OK) r = sy_node_set_matrix(scene, d.camera, &m, &err);
    }
    if (r == SY_OK) r = sy_scene_commit(scene, NULL, &err);
    if (r == SY_OK) r = sy_cluster_client_render(c, &f, &out, &s2, &err);
    /* steady state: frames without changes */
    double over = 0, frame = 0, bytes = 0;
    const int reps = 5;
    for (int i = 0; i < reps && r == SY_OK; ++i) {
        sy_cluster_frame_stats s;
        r = sy_cluster_client_render(c, &f, &out, &s, &err);
        over += s.seconds - s.max_server_seconds;
        frame += s.seconds;
        bytes += (double)(s.bytes_sent + s.bytes_received);
    }
    if (r == SY_OK) {
        printf("sy bench cluster: demo scene, 2 servers on loopback (pinned to cores 0 and 1: %s)\n",
               ncpu >= 2 ? "yes" : "no, 1 core");
        printf("  snapshot on the wire (first frame, per server): %llu bytes; serialised scene %zu bytes "
               "(%zu structure + %zu blob payload)\n",
               (unsigned long long)(s1.scene_bytes / 2), with_blobs, without, with_blobs - without);
        printf("  one-transform change on the wire (per server):  %llu bytes (target < 256)\n",
               (unsigned long long)(s2.scene_bytes / 2));
        printf("  sort-first %s %ux%u: frame %.4f s, protocol overhead %.4f s/frame (%.1f%% of the frame), "
               "%.2f MB on the wire per frame (zstd float tiles)\n",
               backend, w, h, frame / reps, over / reps, 100.0 * over / frame, bytes / reps / 1e6);
    }
    /* codec constants for the scaling model (docs/ARCHITECTURE.md): compression and decompression
     * throughput of the final frame's pixels (RGBA + depth float32) on this core */
    if (r == SY_OK) {
        sy_cluster_buf enc = {0};
        double te = sy_time_now();
        r = sy_cluster_tile_encode(&out, true, &enc, &err);
        te = sy_time_now() - te;
        sy_cluster_tile t = {{0, 0, w, h}, SY_CLUSTER_ENC_F32_SHUFFLE_ZSTD, 5, (uint64_t)w * h * 20, enc.data,
                             (uint32_t)enc.size};
        double td = sy_time_now();
        if (r == SY_OK) r = sy_cluster_tile_decode(&t, &out, 0, 0, &err);
        td = sy_time_now() - td;
        double raw = (double)w * h * 20;
        if (r == SY_OK)
            printf("  tile codec %ux%u RGBA+Z float: %.1f MB raw -> %.2f MB (%.1fx); encode %.0f MB/s, decode %.0f MB/s "
                   "(raw bytes, one core)\n",
                   w, h, raw / 1e6, (double)enc.size / 1e6, raw / (double)enc.size, raw / te / 1e6, raw / td / 1e6);
        sy_cluster_buf_free(&enc);
    }
    sy_layer_destroy(&out);
    sy_cluster_client_destroy(c);
    c = NULL;
    /* cooperative path tracing: 2 pinned servers vs 1 */
    if (r == SY_OK && sy_mediator_find("pathtracer")) {
        double one = 0, two = 0;
        r = coop_rate(scene, &vd, srv, 1, 320, 180, &one, &err);
        if (r == SY_OK) r = coop_rate(scene, &vd, srv, 2, 320, 180, &two, &err);
        if (r == SY_OK)
            printf("  cooperative pathtracer 320x180: 1 server %.1f samples/s, 2 servers %.1f samples/s: %.2fx "
                   "(target >= 1.8x)\n",
                   one, two, two / one);
    } else if (r == SY_OK) {
        printf("  cooperative: skipped (no 'pathtracer' back-end registered in this build)\n");
    }
    stop_server(&srv[0]);
    stop_server(&srv[1]);
    sy_window_destroy(win);
    sy_scene_destroy(scene);
    return r == SY_OK ? 0 : cli_fail("bench cluster", &err);
}
