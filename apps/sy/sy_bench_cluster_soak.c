/* sy_bench_cluster_soak.c — `sy bench cluster --soak SECONDS`: one server and one client whose
 * camera moves every frame, for minutes; the server's memory, descriptors and threads must not grow
 * (see sy_bench_cluster.h; tests/soak/serve_soak.sh). */
#define _GNU_SOURCE /* M_PI */
#include "sy_bench_cluster.h"
#include "sy_bench_os.h"

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <unistd.h>

/* >>soak: one `sy serve` and one client that moves the camera every frame for a given time
 * (issue 32, item 6): the camera node orbits the scene (a change list per frame, as an application
 * that moves its camera node sends) and each frame is rendered from the moved camera. Every 10 s the server's
 * VmRSS, open descriptors (/proc/PID/fd) and threads are sampled; growth is measured from the
 * sample at the end of the warm-up (caches, context pool, render threads) to the end. Passes when
 * every frame sent came back (no error, no failed server) and each of the three grew by less
 * than 5 %. Not part of ctest (it runs for minutes): tests/soak/serve_soak.sh, docs/TESTING.md. */
typedef struct soak_sample {
    double t;
    long rss_kb, fds, threads, client_rss_kb;
} soak_sample;

static long proc_fd_count(pid_t pid)
{
    char path[64];
    snprintf(path, sizeof path, "/proc/%d/fd", (int)pid);
    DIR *d = opendir(path);
    if (!d) return -1;
    long n = 0;
    for (struct dirent *e; (e = readdir(d));)
        if (e->d_name[0] != '.') n++;
    closedir(d);
    return n;
}

static soak_sample soak_take(pid_t server, double t)
{
    soak_sample s = {t, sy_bench_proc_status_kb(server, "VmRSS"), proc_fd_count(server),
                     sy_bench_proc_status_kb(server, "Threads"),
                     sy_bench_proc_status_kb(getpid(), "VmRSS")};
    return s;
}

static double growth_pct(long a, long b)
{
    return a > 0 ? 100.0 * (double)(b - a) / (double)a : 0.0;
}

sy_result sy_bench_cluster_soak(sy_scene *scene, const sy_demo_info *d, const char *backend, double seconds,
                                double warmup, uint32_t w, uint32_t h, bool *passed, sy_error *err)
{
    *passed = false;
    sy_bench_cluster_server srv = {0};
    sy_bench_cluster_rig rig = {0};
    sy_mat4 m0;
    sy_result r = sy_bench_cluster_spawn_ex(-1, (int)seconds + 300, false, &srv, err);
    sy_viewport_desc vd = {.root = d->root, .camera = d->camera, .background = d->background, .backend = backend};
    const char *urls[1] = {srv.url};
    sy_cluster_client_opts co = {.urls = urls, .url_count = 1, .timeout_ms = 120000};
    if (r == SY_OK) r = sy_node_world_matrix(scene, d->camera, &m0, err); /* under an identity root: = local */
    if (r == SY_OK) r = sy_bench_cluster_rig_open(scene, &vd, &co, w, h, &rig, err);
    if (r != SY_OK) {
        sy_bench_cluster_rig_close(&rig);
        sy_bench_cluster_stop(&srv);
        return r;
    }
    printf("sy bench cluster --soak: `sy serve` (pid %d, %s) and one client on loopback, demo scene, %ux%u %s, the "
           "camera orbiting one step per frame (a change list + a RENDER each), %.0f s, warm-up %.0f s\n",
           (int)srv.pid, srv.url, w, h, backend, seconds, warmup);
    printf("  %8s %8s %12s %6s %8s %14s %14s\n", "t (s)", "frames", "server RSS", "fds", "threads", "client RSS",
           "frame ms mean");
    fflush(stdout);
    uint64_t sent = 0, received = 0, failed = 0, bytes_out = 0, bytes_in = 0;
    char first_error[SY_ERROR_MESSAGE_MAX + 32] = "";
    double t0 = sy_time_now(), next_sample = 0, busy = 0, worst = 0;
    uint64_t frames_at_sample = 0;
    double busy_at_sample = 0;
    soak_sample first = {0}, base = {0}, last = {0}, peak = {0};
    bool have_base = false;
    for (uint64_t i = 0;; ++i) {
        double t = sy_time_now() - t0;
        if (t >= next_sample || t >= seconds) {
            last = soak_take(srv.pid, t);
            if (i == 0) first = last;
            if (!have_base && t >= warmup) base = last, have_base = true;
            if (have_base) {
                if (last.rss_kb > peak.rss_kb) peak.rss_kb = last.rss_kb;
                if (last.fds > peak.fds) peak.fds = last.fds;
                if (last.threads > peak.threads) peak.threads = last.threads;
            }
            uint64_t nf = received - frames_at_sample;
            printf("  %8.0f %8llu %9.1f MiB %6ld %8ld %10.1f MiB %14.2f\n", t, (unsigned long long)received,
                   last.rss_kb / 1024.0, last.fds, last.threads, last.client_rss_kb / 1024.0,
                   nf ? (busy - busy_at_sample) / (double)nf * 1e3 : 0.0);
            fflush(stdout);
            frames_at_sample = received;
            busy_at_sample = busy;
            next_sample += 10.0;
            if (last.rss_kb < 0) {
                r = sy_error_set(err, SY_ERR_IO, "soak: the server (pid %d) is gone", (int)srv.pid);
                break;
            }
            if (t >= seconds) break;
        }
        /* the camera orbits the scene's vertical axis, 0.5 degree per frame */
        double a = (double)(i % 720) * (M_PI / 360.0);
        float q[4] = {0, (float)sin(a / 2), 0, (float)cos(a / 2)}, t3[3] = {0, 0, 0}, s3[3] = {1, 1, 1};
        sy_mat4 rot = sy_mat4_from_trs(t3, q, s3), m = sy_mat4_mul(&rot, &m0);
        sy_camera_view view = {0};
        r = sy_node_set_matrix(scene, d->camera, &m, err);
        if (r == SY_OK) r = sy_scene_commit(scene, NULL, err);
        if (r == SY_OK) r = sy_viewport_camera_view(rig.vp, scene, w, h, &view, err);
        if (r != SY_OK) break;
        sy_cluster_frame f = {.mode = SY_CLUSTER_SORT_FIRST, .backend = backend, .root_id = d->root.id,
                              .background_id = d->background.id, .camera = view, .width = w, .height = h};
        sy_cluster_frame_stats st = {0};
        sy_error fe = {0};
        double ft = sy_time_now();
        sent++;
        sy_result fr = sy_cluster_client_render(rig.client, &f, &rig.img, &st, &fe);
        ft = sy_time_now() - ft;
        if (fr == SY_OK && st.servers_failed == 0 && st.bytes_received > 0) {
            received++;
            busy += ft;
            if (ft > worst) worst = ft;
        } else {
            failed++;
            if (!first_error[0])
                snprintf(first_error, sizeof first_error, "frame %llu: %s", (unsigned long long)sent,
                         fr ? fe.message : "a server failed during the frame");
        }
        bytes_out += st.bytes_sent;
        bytes_in += st.bytes_received;
    }
    sy_bench_cluster_rig_close(&rig);
    sy_bench_cluster_stop(&srv);
    if (r != SY_OK) return r;
    double g_rss = growth_pct(base.rss_kb, last.rss_kb), g_fds = growth_pct(base.fds, last.fds),
           g_thr = growth_pct(base.threads, last.threads);
    printf("  frames: %llu sent, %llu received, %llu failed%s%s; %.1f MiB sent, %.1f MiB received; frame %.2f ms mean, "
           "%.2f ms worst\n",
           (unsigned long long)sent, (unsigned long long)received, (unsigned long long)failed,
           first_error[0] ? " (first: " : "", first_error[0] ? first_error : "", bytes_out / 1048576.0,
           bytes_in / 1048576.0, received ? busy / (double)received * 1e3 : 0.0, worst * 1e3);
    if (first_error[0]) printf(")\n");
    printf("  server at t=0 (client connected, before the first frame): RSS %.1f MiB, %ld fds, %ld threads\n", first.rss_kb / 1024.0,
           first.fds, first.threads);
    printf("  server after the warm-up (t=%.0f s) -> end (t=%.0f s), peak between: RSS %.1f -> %.1f MiB (%+.2f %%, peak "
           "%.1f), fds %ld -> %ld (%+.2f %%, peak %ld), threads %ld -> %ld (%+.2f %%, peak %ld)\n",
           base.t, last.t, base.rss_kb / 1024.0, last.rss_kb / 1024.0, g_rss, peak.rss_kb / 1024.0, base.fds, last.fds,
           g_fds, peak.fds, base.threads, last.threads, g_thr, peak.threads);
    *passed = have_base && failed == 0 && sent == received && g_rss < 5.0 && g_fds < 5.0 && g_thr < 5.0;
    printf("  %s: every frame delivered %s, growth under 5 %% %s\n", *passed ? "PASS" : "FAIL",
           failed == 0 && sent == received ? "yes" : "NO", g_rss < 5.0 && g_fds < 5.0 && g_thr < 5.0 ? "yes" : "NO");
    return SY_OK;
}
