/* sy_bench_cluster_coop.c — `sy bench cluster`, cooperative path tracing: 2 servers against 1 in
 * interleaved rounds, the speed-up and the samples per server CPU-second (see sy_bench_cluster.h;
 * alone: --coop-only). */
#include "sy_bench_cluster.h"
#include "sy_bench.h"

#include <stdio.h>
#include <string.h>
#include <unistd.h>

/* CPU seconds (user + system) a process has used so far, from /proc/PID/stat; < 0 when unknown. */
static double proc_cpu_seconds(pid_t pid)
{
    char path[64], buf[1024];
    snprintf(path, sizeof path, "/proc/%d/stat", (int)pid);
    FILE *f = fopen(path, "r");
    if (!f) return -1.0;
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = 0;
    const char *p = strrchr(buf, ')'); /* the command name may hold spaces and parentheses */
    unsigned long ut = 0, st = 0;
    if (!p || sscanf(p + 1, " %*c %*d %*d %*d %*d %*d %*u %*u %*u %*u %*u %lu %lu", &ut, &st) != 2) return -1.0;
    return (double)(ut + st) / (double)sysconf(_SC_CLK_TCK);
}

/* One cooperative measurement: merged samples per pixel per second on the first n servers. */
typedef struct coop_run {
    double rate;       /* merged samples per pixel per second */
    double seconds;    /* wall time measured */
    double cpu[2];     /* each server's CPU seconds in that time (< 0: unknown) */
    uint64_t samples;  /* merged samples per pixel added in that time */
    uint32_t frames;
    uint32_t answers, pipelined; /* server answers in the timed frames; those requested ahead */
} coop_run;

/* Cooperative path tracing on the first n servers with a fresh client (snapshot + translation in a
 * warm-up frame and one more frame that are not counted: the timed frames are pipelined, each
 * server's next request sent before the client merges), spf samples per server and frame, frames
 * until at least min_seconds have passed (and at least 3). *spf == 0: calibrated here from a
 * 4-sample frame so that a frame takes about frame_s on one server, and returned for the other
 * runs. */
static sy_result coop_measure(sy_scene *scene, const sy_viewport_desc *vd, const sy_bench_cluster_server *srv, uint32_t n,
                              uint32_t w, uint32_t h, uint32_t *spf, double frame_s, double min_seconds, bool no_pipeline,
                              coop_run *out, sy_error *err)
{
    memset(out, 0, sizeof *out);
    const char *urls[2] = {srv[0].url, n > 1 ? srv[1].url : NULL};
    sy_cluster_client_opts co = {.urls = urls, .url_count = n, .timeout_ms = 120000, .no_pipeline = no_pipeline};
    sy_bench_cluster_rig rig;
    sy_result r = sy_bench_cluster_rig_open(scene, vd, &co, w, h, &rig, err);
    sy_cluster_frame f = {.mode = SY_CLUSTER_COOPERATIVE, .backend = "pathtracer", .root_id = vd->root.id,
                          .background_id = vd->background.id, .camera = rig.view, .width = w, .height = h,
                          .samples = *spf ? *spf : 4};
    sy_cluster_frame_stats st = {0};
    if (r == SY_OK) r = sy_cluster_client_render(rig.client, &f, &rig.img, &st, err); /* warm-up: snapshot + translation */
    uint32_t untimed = 1; /* a frame that asks what the last one asked: the client pipelines from the next on */
    if (r == SY_OK && !*spf) {
        double t = sy_time_now();
        r = sy_cluster_client_render(rig.client, &f, &rig.img, &st, err);
        t = sy_time_now() - t;
        double k = t > 0 ? frame_s / t : 256.0;
        *spf = k >= 256.0 ? 1024u : k <= 1.0 ? 4u : (uint32_t)(4.0 * k + 0.5);
        untimed = 2; /* the first at spf asks otherwise (its stale 4-sample answers are dropped) */
    }
    f.samples = *spf;
    /* untimed frames at spf, so that every timed frame is in the steady state (each server's next
     * request already sent when a frame returns, as in a long refinement) */
    for (uint32_t i = 0; i < untimed && r == SY_OK; ++i) r = sy_cluster_client_render(rig.client, &f, &rig.img, &st, err);
    uint64_t s0 = st.samples;
    double cpu0[2] = {proc_cpu_seconds(srv[0].pid), n > 1 ? proc_cpu_seconds(srv[1].pid) : -1.0};
    double t0 = sy_time_now();
    while (r == SY_OK && (out->frames < 3 || sy_time_now() - t0 < min_seconds)) {
        r = sy_cluster_client_render(rig.client, &f, &rig.img, &st, err);
        out->frames++;
        out->answers += st.servers_live;
        out->pipelined += st.pipelined;
        if (r == SY_OK && st.servers_live != n)
            r = sy_error_set(err, SY_ERR_IO, "bench: a server dropped out of the cooperative measurement");
    }
    out->seconds = sy_time_now() - t0;
    out->samples = st.samples - s0;
    out->rate = out->seconds > 0 ? (double)out->samples / out->seconds : 0;
    for (uint32_t i = 0; i < 2; ++i) {
        double now = i < n ? proc_cpu_seconds(srv[i].pid) : -1.0;
        out->cpu[i] = now >= 0 && cpu0[i] >= 0 ? now - cpu0[i] : -1.0;
    }
    sy_bench_cluster_rig_close(&rig);
    return r;
}

/* Cooperative path tracing, 2 servers pinned to one core each vs 1 server: `rounds` interleaved
 * rounds (the order alternates, so a drift in the machine's load hits both sides alike); the
 * speed-up is the median of the rounds' 2-server rate / 1-server rate, each round's ratio printed
 * beside it. Each server's CPU time shows how much of its core it got: on a machine shared with
 * other work the wall-clock ratio drops, while samples per server CPU-second (the cost of
 * cooperating: the sample split, transfers, merging, waiting for the other server) stay
 * comparable. pipe: SY_BENCH_COOP_PIPELINED, _NOT_PIPELINED (--coop-no-pipeline), or _AB
 * (--coop-ab: both in every round, their order alternating too, and the pipelined rate over the
 * other per server count). */
sy_result sy_bench_cluster_coop(sy_scene *scene, const sy_viewport_desc *vd, const sy_bench_cluster_server *srv,
                                uint32_t rounds, bool pinned, double frame_s, int pipe, sy_error *err)
{
    const uint32_t w = 320, h = 180;
    const double min_seconds = frame_s * 3.75 > 1.5 ? frame_s * 3.75 : 1.5;
    uint32_t spf = 0;
    enum { MAX_ROUNDS = 64 };
    /* per variant (0 pipelined, 1 not) and round: speed-up, spp/s (1 / 2 servers), spp per CPU-s */
    double ratio[2][MAX_ROUNDS], rate[2][2][MAX_ROUNDS], eff[2][2][MAX_ROUNDS], gain[2][MAX_ROUNDS];
    uint32_t nr = 0, ne[2] = {0, 0};
    if (rounds > MAX_ROUNDS) rounds = MAX_ROUNDS;
    bool ab = pipe == SY_BENCH_COOP_AB;
    uint32_t nv = ab ? 2 : 1, v0 = pipe == SY_BENCH_COOP_NOT_PIPELINED ? 1 : 0;
    static const char *vname[2] = {"pipelined", "not pipelined"};
    sy_result r = SY_OK;
    printf("  cooperative pathtracer %ux%u, servers %s, %u interleaved rounds of >= %.1f s per side, frames of about "
           "%.2f s on one server, %s:\n",
           w, h, pinned ? "pinned to cores 0 and 1" : "not pinned (1 core)", rounds, min_seconds, frame_s,
           ab ? "pipelined and not (--coop-ab, alternating)" : v0 ? "not pipelined (--coop-no-pipeline)" : "pipelined");
    for (uint32_t round = 0; round < rounds && r == SY_OK; ++round) {
        coop_run run[2][2];
        for (uint32_t j = 0; j < nv && r == SY_OK; ++j) {
            uint32_t v = ab ? ((round >> 1 & 1) ? 1 - j : j) : v0; /* A B / A B / B A / B A ... */
            for (uint32_t k = 0; k < 2 && r == SY_OK; ++k) {
                uint32_t n = (round & 1) ? 2 - k : 1 + k; /* 1,2 / 2,1 / 1,2 ... */
                r = coop_measure(scene, vd, srv, n, w, h, &spf, frame_s, min_seconds, v == 1, &run[v][n - 1], err);
            }
        }
        if (r != SY_OK) break;
        for (uint32_t j = 0; j < nv; ++j) {
            uint32_t v = ab ? j : v0;
            coop_run *rv = run[v];
            rate[v][0][nr] = rv[0].rate, rate[v][1][nr] = rv[1].rate;
            ratio[v][nr] = rv[0].rate > 0 ? rv[1].rate / rv[0].rate : 0.0;
            double cpu1 = rv[0].cpu[0], cpu2 = rv[1].cpu[0] + rv[1].cpu[1];
            if (rv[0].cpu[0] >= 0 && rv[1].cpu[0] >= 0 && rv[1].cpu[1] >= 0 && cpu1 > 0 && cpu2 > 0) {
                eff[v][0][ne[v]] = (double)rv[0].samples / cpu1, eff[v][1][ne[v]] = (double)rv[1].samples / cpu2;
                ne[v]++;
            }
            printf("    round %u%s%s (%u spp per server and frame): 1 server %.1f spp/s (busy %.2f s CPU of %.2f s); "
                   "2 servers %.1f spp/s (busy %.2f + %.2f s CPU of %.2f s): %.2fx; answers requested ahead %u/%u\n",
                   round + 1, ab ? ", " : "", ab ? vname[v] : "", spf, rv[0].rate, rv[0].cpu[0], rv[0].seconds, rv[1].rate,
                   rv[1].cpu[0], rv[1].cpu[1], rv[1].seconds, ratio[v][nr], rv[0].pipelined + rv[1].pipelined,
                   rv[0].answers + rv[1].answers);
        }
        if (ab)
            for (uint32_t n = 0; n < 2; ++n) gain[n][nr] = run[1][n].rate > 0 ? run[0][n].rate / run[1][n].rate : 0.0;
        nr++;
    }
    for (uint32_t j = 0; j < nv && r == SY_OK && nr; ++j) {
        uint32_t v = ab ? j : v0;
        sy_bench_spread sr = sy_bench_spread_of(ratio[v], nr), s1 = sy_bench_spread_of(rate[v][0], nr),
                        s2 = sy_bench_spread_of(rate[v][1], nr);
        printf("  cooperative speed-up%s%s (median of %u rounds, min..max): %.2fx (%.2f..%.2f; target >= 1.95x); "
               "1 server %.1f spp/s, 2 servers %.1f spp/s (medians)\n",
               ab ? ", " : "", ab ? vname[v] : "", nr, sr.median, sr.min, sr.max, s1.median, s2.median);
        if (ne[v]) {
            sy_bench_spread e1 = sy_bench_spread_of(eff[v][0], ne[v]), e2 = sy_bench_spread_of(eff[v][1], ne[v]);
            printf("  per server CPU-second%s%s (median of %u): 1 server %.1f spp, 2 servers %.1f spp (%.0f%% efficiency): "
                   "2 x %.2f = %.2fx with each server's core to itself\n",
                   ab ? ", " : "", ab ? vname[v] : "", ne[v], e1.median, e2.median, 100.0 * e2.median / e1.median,
                   e2.median / e1.median, 2.0 * e2.median / e1.median);
        }
    }
    if (ab && r == SY_OK && nr) {
        sy_bench_spread g1 = sy_bench_spread_of(gain[0], nr), g2 = sy_bench_spread_of(gain[1], nr);
        printf("  pipelined over not pipelined, spp/s in the same round (median, min..max): 1 server %.3fx (%.3f..%.3f), "
               "2 servers %.3fx (%.3f..%.3f)\n",
               g1.median, g1.min, g1.max, g2.median, g2.min, g2.max);
    }
    return r;
}
