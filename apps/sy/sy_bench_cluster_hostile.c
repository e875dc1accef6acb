/* sy_bench_cluster_hostile.c — `sy bench cluster`, hostile peers (issue 14): a server's memory and
 * a client's frame time while 72 connections that never authenticate trickle and flood it (see
 * sy_bench_cluster.h; alone: --hostile-only). */
#include "sy_bench_cluster.h"
#include "sy_bench_hostile.h"
#include "sy_bench_os.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <time.h>
#include <unistd.h>

/* >>hostile peers (issue 14): sy_bench_hostile.h */

/* Server srv's resident memory before, at the peak of and after 64 tricklers + 8 flooders (5 s),
 * and the frame time of a client of that server alone (320x180 sort-first) before and during. */
sy_result sy_bench_cluster_hostile(sy_scene *scene, const sy_demo_info *d, const char *backend,
                                   const sy_bench_cluster_server *srv, sy_error *err)
{
    enum { TRICKLERS = 64, FLOODERS = 8, W = 320, H = 180 };
    const char *urls[1] = {srv->url};
    sy_cluster_client_opts co = {.urls = urls, .url_count = 1, .timeout_ms = 60000};
    sy_cluster_client *c = NULL;
    sy_layer out = {0};
    sy_camera_view view = sy_camera_view_frame_bounds(&(sy_bounds){{-3, -1, -3}, {3, 3, 3}}, (float)W / H);
    sy_cluster_frame f = {.mode = SY_CLUSTER_SORT_FIRST, .backend = backend, .root_id = d->root.id,
                          .background_id = d->background.id, .camera = view, .width = W, .height = H};
    sy_result r = sy_cluster_client_create(scene, &co, &c, err);
    if (r == SY_OK) r = sy_layer_create(W, H, &out, err);
    if (r == SY_OK) r = sy_cluster_client_render(c, &f, &out, NULL, err); /* snapshot + translation */
    double quiet = 0;
    const int quiet_n = 20;
    for (int i = 0; i < quiet_n && r == SY_OK; ++i) {
        double t0 = sy_time_now();
        r = sy_cluster_client_render(c, &f, &out, NULL, err);
        quiet += sy_time_now() - t0;
    }
    const char *colon = strrchr(srv->url, ':');
    int port = colon ? atoi(colon + 1) : 0;
    long rss0 = sy_bench_proc_status_kb(srv->pid, "VmRSS"), peak = rss0;
    atomic_int stop = 0;
    sy_bench_hostile hp[TRICKLERS + FLOODERS];
    pthread_t th[TRICKLERS + FLOODERS];
    int started = r == SY_OK ? sy_bench_hostile_start(hp, th, TRICKLERS + FLOODERS, TRICKLERS, port, &stop, NULL) : 0;
    double t_start = sy_time_now(), busy = 0, worst = 0;
    int frames = 0;
    while (r == SY_OK && sy_time_now() - t_start < 5.0) {
        double t0 = sy_time_now();
        r = sy_cluster_client_render(c, &f, &out, NULL, err);
        double dt = sy_time_now() - t0;
        busy += dt;
        worst = dt > worst ? dt : worst;
        frames++;
        long kb = sy_bench_proc_status_kb(srv->pid, "VmRSS");
        if (kb > peak) peak = kb;
    }
    sy_bench_hostile_stop(th, started, &stop);
    sy_bench_sleep_ms(300);
    long rss1 = sy_bench_proc_status_kb(srv->pid, "VmRSS");
    uint64_t trickled = 0, flooded = 0;
    uint32_t conns = 0;
    for (int i = 0; i < started; ++i) {
        conns += hp[i].conns;
        if (hp[i].flood) flooded += hp[i].bytes;
        else trickled += hp[i].bytes;
    }
    if (r == SY_OK) {
        printf("  hostile peers on server 0 (%d announce 256 MiB and trickle 64 KiB / 100 ms, %d flood 8 MiB; none "
               "authenticates; %u connections, %.0f MiB trickled, %.0f MiB flooded in 5 s):\n",
               TRICKLERS, FLOODERS, conns, (double)trickled / 1048576.0, (double)flooded / 1048576.0);
        printf("    server VmRSS %.1f MiB before, %.1f MiB peak, %.1f MiB after (+%.1f MiB at the peak); client frame "
               "%ux%u %s: %.2f ms before, %.2f ms mean / %.2f ms worst during (%d frames)\n",
               rss0 / 1024.0, peak / 1024.0, rss1 / 1024.0, (peak - rss0) / 1024.0, W, H, backend,
               quiet / quiet_n * 1e3, frames ? busy / frames * 1e3 : 0.0, worst * 1e3, frames);
    }
    sy_layer_destroy(&out);
    sy_cluster_client_destroy(c);
    return r;
}
