/* sy_bench_cluster.c — `sy bench cluster` (see sy_cluster_cli.h): its options, and its default
 * measurements on 2 servers (snapshot and change sizes, protocol overhead, request latency, the tile
 * codec, half tiles and the blob cache); the others have a file each (sy_bench_cluster.h). */
#define _GNU_SOURCE /* sched_setaffinity: the client keeps off the servers' cores */
#include "sy_bench_cluster.h"
#include "sy_cli.h"
#include "sy_cluster_cli.h"

#include "sy_log.h"

#include <sched.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

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

/* Protocol 2 figures: bytes of binary16 tiles vs float32 on the same frame and the half codec's
 * ratio on the frame's pixels; the snapshot a second client with the same model sends (the
 * servers' blob cache answers its hashes) vs the first client's. */
static sy_result bench_half_and_blob_cache(sy_scene *scene, const sy_cluster_client_opts *co, sy_cluster_client *c,
                                           const sy_cluster_frame *f, sy_layer *out,
                                           const sy_cluster_frame_stats *first, sy_error *err)
{
    sy_cluster_frame hf = *f;
    sy_cluster_frame_stats sf = {0}, sh = {0}, s2 = {0};
    sy_result r = sy_cluster_client_render(c, f, out, &sf, err);
    hf.half = true;
    if (r == SY_OK) r = sy_cluster_client_render(c, &hf, out, &sh, err);
    if (r == SY_OK)
        printf("  half tiles (--cluster-pixels half) %ux%u RGBA: %.2f MB back per frame vs %.2f MB float32 (%.2fx fewer)\n",
               f->width, f->height, (double)sh.bytes_received / 1e6, (double)sf.bytes_received / 1e6,
               (double)sf.bytes_received / (double)sh.bytes_received);
    sy_cluster_buf enc = {0};
    double te = sy_time_now();
    if (r == SY_OK) r = sy_cluster_tile_encode_as(out, true, SY_CLUSTER_ENC_F16_SHUFFLE_ZSTD, &enc, err);
    te = sy_time_now() - te;
    uint64_t raw16 = (uint64_t)out->width * out->height * 10;
    sy_cluster_tile t = {{0, 0, out->width, out->height}, SY_CLUSTER_ENC_F16_SHUFFLE_ZSTD, 5, raw16, enc.data,
                         (uint32_t)enc.size};
    double td = sy_time_now();
    if (r == SY_OK) r = sy_cluster_tile_decode(&t, out, 0, 0, err);
    td = sy_time_now() - td;
    if (r == SY_OK)
        printf("  tile codec RGBA+Z half: %.1f MB float32 -> %.1f MB binary16 -> %.2f MB zstd (%.1fx of float32, %.1fx "
               "of the half planes); encode %.0f MB/s, decode %.0f MB/s (float32-equivalent bytes, one core)\n",
               (double)raw16 * 2 / 1e6, (double)raw16 / 1e6, (double)enc.size / 1e6, (double)raw16 * 2 / (double)enc.size,
               (double)raw16 / (double)enc.size, (double)raw16 * 2 / te / 1e6, (double)raw16 * 2 / td / 1e6);
    sy_cluster_buf_free(&enc);
    sy_cluster_client *c2 = NULL;
    if (r == SY_OK) r = sy_cluster_client_create(scene, co, &c2, err);
    if (r == SY_OK) r = sy_cluster_client_render(c2, f, out, &s2, err);
    if (r == SY_OK)
        printf("  snapshot of a second client with the same model (per server): %llu bytes, %llu of them blob payloads; "
               "first client %llu bytes, %llu of them blob payloads (%.0fx less)\n",
               (unsigned long long)(s2.scene_bytes / 2), (unsigned long long)(s2.blob_bytes / 2),
               (unsigned long long)(first->scene_bytes / 2), (unsigned long long)(first->blob_bytes / 2),
               (double)first->scene_bytes / (double)(s2.scene_bytes ? s2.scene_bytes : 1));
    sy_cluster_client_destroy(c2);
    return r;
}
int sy_cmd_bench_cluster(int argc, char **argv)
{
    uint32_t w = 0, h = 0, rounds = 3; /* w, h: 0 until -w / -h give them */
    bool hostile_only = false, coop_only = false, scale = false; /* one measurement alone */
    double coop_frame = 1.6; /* cooperative: seconds per frame on one server (each frame costs ~15 ms of sync + merge) */
    uint32_t soak_s = 0, warmup_s = UINT32_MAX; /* --soak: seconds of camera changes against one server; --warmup: none given */
    const char *soak_backend = NULL;
    static const char usage_text[] = "usage: sy bench cluster [-w W] [-h H] [--repeats ROUNDS] [--hostile-only | --coop-only] "
                                     "[--coop-frame SECONDS] [--coop-no-pipeline | --coop-ab] | --scale\n"
                                     "       sy bench cluster --soak SECONDS [--warmup SECONDS] [-b BACKEND] [-w W] [-h H]"
                                     "   (exit 1 unless every frame came back and the server's RSS, fds and threads grew < 5 %)\n";
    enum { O_REPEATS = OPT_OWN_FIRST, O_HOSTILE, O_COOP, O_SCALE, O_COOP_FRAME, O_SOAK, O_WARMUP, O_COOP_NO_PIPE, O_COOP_AB };
    bool coop_no_pipeline = false; /* cooperative: each frame's requests only once it is asked for (as before issue 39) */
    bool coop_ab = false;          /* cooperative: pipelined and not, alternating in every round */
    const sy_cli_opt opts[] = {
        SY_CLI_OPT_UINT("repeats", O_REPEATS, &rounds, 1, 100),
        SY_CLI_OPT_FLAG("hostile-only", O_HOSTILE, &hostile_only),
        SY_CLI_OPT_FLAG("coop-only", O_COOP, &coop_only),
        SY_CLI_OPT_FLAG("scale", O_SCALE, &scale),
        SY_CLI_OPT_UINT("soak", O_SOAK, &soak_s, 1, 86400),
        SY_CLI_OPT_UINT("warmup", O_WARMUP, &warmup_s, 0, 86400),
        SY_CLI_OPT_TEXT("backend", 'b', &soak_backend),
        SY_CLI_OPT_TEXT(NULL, 'b', &soak_backend),
        SY_CLI_OPT_REAL("coop-frame", O_COOP_FRAME, &coop_frame, 0.05, 60),
        SY_CLI_OPT_FLAG("coop-no-pipeline", O_COOP_NO_PIPE, &coop_no_pipeline),
        SY_CLI_OPT_FLAG("coop-ab", O_COOP_AB, &coop_ab),
    };
    sy_cli_parser p = {SY_CLI_ARGS("bench cluster", argc, argv, opts), .w = &w, .h = &h, .min_size = 1, .usage = usage_text};
    if (sy_cli_parse(&p) != -1) return p.status;
    if (optind < argc) {
        fprintf(stderr, "sy bench cluster: error: unexpected argument '%s'\n%s", argv[optind], usage_text);
        return 2;
    }
    int coop_pipe = coop_ab ? SY_BENCH_COOP_AB : coop_no_pipeline ? SY_BENCH_COOP_NOT_PIPELINED : SY_BENCH_COOP_PIPELINED;
    bool size_given = w || h;
    if (!w) w = 1920;
    if (!h) h = 1080;
    double soak = soak_s, warmup = warmup_s == UINT32_MAX ? -1.0 : warmup_s;
    signal(SIGPIPE, SIG_IGN);
    sy_error err = {0};
    sy_scene *scene = NULL;
    sy_demo_info d;
    sy_bench_cluster_server srv[2] = {{0}};
    sy_bench_cluster_rig rig = {0};
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
    if (r == SY_OK && soak > 0) {
        const char *backend = soak_backend ? soak_backend : sy_mediator_default_name();
        bool passed = false;
        if (warmup < 0) warmup = soak / 10 < 60 ? soak / 10 : 60;
        if (warmup >= soak) {
            sy_scene_destroy(scene);
            fprintf(stderr, "sy bench cluster: error: --warmup must be shorter than --soak\n");
            return 2;
        }
        if (!sy_mediator_find(backend)) {
            sy_scene_destroy(scene);
            fprintf(stderr, "sy bench cluster: error: -b: no back-end '%s' in this build\n", backend);
            return 2;
        }
        r = sy_bench_cluster_soak(scene, &d, backend, soak, warmup, size_given ? w : 320, size_given ? h : 180, &passed,
                                  &err);
        sy_scene_destroy(scene);
        return r == SY_OK ? (passed ? 0 : 1) : sy_cli_fail(&err);
    }
    if (soak_backend || warmup >= 0) {
        sy_scene_destroy(scene);
        fprintf(stderr, "sy bench cluster: error: -b and --warmup go with --soak\n%s", usage_text);
        return 2;
    }
    if (r == SY_OK && scale) {
        r = sy_bench_cluster_scale(scene, &d, rounds < 3 ? 3 : rounds, &err);
        sy_scene_destroy(scene);
        return r == SY_OK ? 0 : sy_cli_fail(&err);
    }
    if (r == SY_OK) r = sy_bench_cluster_spawn(ncpu >= 2 ? 0 : -1, &srv[0], &err);
    if (r == SY_OK && hostile_only) {
        printf("sy bench cluster --hostile-only: demo scene, one server on loopback\n");
        r = sy_bench_cluster_hostile(scene, &d, sy_mediator_default_name(), &srv[0], &err);
        sy_bench_cluster_stop(&srv[0]);
        sy_scene_destroy(scene);
        return r == SY_OK ? 0 : sy_cli_fail(&err);
    }
    if (r == SY_OK) r = sy_bench_cluster_spawn(ncpu >= 2 ? 1 : -1, &srv[1], &err);
    if (r == SY_OK && ncpu >= 3) { /* the client keeps off the servers' cores where it can */
        cpu_set_t set;
        CPU_ZERO(&set);
        for (long i = 2; i < ncpu && i < CPU_SETSIZE; ++i) CPU_SET((int)i, &set);
        sched_setaffinity(0, sizeof set, &set);
    }
    const char *urls[2] = {srv[0].url, srv[1].url};
    sy_cluster_client_opts co = {.urls = urls, .url_count = 2, .timeout_ms = 120000};
    const char *backend = sy_mediator_default_name();
    sy_viewport_desc vd = {.root = d.root, .camera = d.camera, .background = d.background, .backend = backend};
    if (r == SY_OK && coop_only) {
        printf("sy bench cluster --coop-only: demo scene, 2 servers on loopback\n");
        r = sy_bench_cluster_coop(scene, &vd, srv, rounds, ncpu >= 2, coop_frame, coop_pipe, &err);
        sy_bench_cluster_stop(&srv[0]);
        sy_bench_cluster_stop(&srv[1]);
        sy_scene_destroy(scene);
        return r == SY_OK ? 0 : sy_cli_fail(&err);
    }
    if (r == SY_OK) r = sy_bench_cluster_rig_open(scene, &vd, &co, w, h, &rig, &err);
    sy_cluster_frame f = {.mode = SY_CLUSTER_SORT_FIRST, .backend = backend, .root_id = d.root.id,
                          .background_id = d.background.id, .camera = rig.view, .width = w, .height = h};
    sy_cluster_frame_stats s1 = {0}, s2 = {0};
    if (r == SY_OK) r = sy_cluster_client_render(rig.client, &f, &rig.img, &s1, &err);
    /* one transform change */
    if (r == SY_OK) {
        sy_mat4 m;
        r = sy_node_world_matrix(scene, d.camera, &m, &err);
        m.m[12] += 0.01f; /* the demo camera hangs under an identity root: world = local */
        if (r == SY_OK) r = sy_node_set_matrix(scene, d.camera, &m, &err);
    }
    if (r == SY_OK) r = sy_scene_commit(scene, NULL, &err);
    if (r == SY_OK) r = sy_cluster_client_render(rig.client, &f, &rig.img, &s2, &err);
    /* steady state: frames without changes */
    double over = 0, frame = 0, bytes = 0;
    const int reps = 5;
    for (int i = 0; i < reps && r == SY_OK; ++i) {
        sy_cluster_frame_stats s;
        r = sy_cluster_client_render(rig.client, &f, &rig.img, &s, &err);
        over += s.seconds - s.max_server_seconds;
        frame += s.seconds;
        bytes += (double)(s.bytes_sent + s.bytes_received);
    }
    if (r == SY_OK) {
        printf("sy bench cluster: demo scene, 2 servers on loopback (pinned to cores 0 and 1: %s; client on %s)\n",
               ncpu >= 2 ? "yes" : "no, 1 core", ncpu >= 3 ? "the other cores" : "any core");
        printf("  snapshot on the wire (first frame, per server): %llu bytes; serialised scene %zu bytes "
               "(%zu structure + %zu blob payload)\n",
               (unsigned long long)(s1.scene_bytes / 2), with_blobs, without, with_blobs - without);
        printf("  one-transform change on the wire (per server):  %llu bytes (target < 256)\n",
               (unsigned long long)(s2.scene_bytes / 2));
        printf("  sort-first %s %ux%u: frame %.4f s, protocol overhead %.4f s/frame (%.1f%% of the frame), "
               "%.2f MB on the wire per frame (zstd float tiles)\n",
               backend, w, h, frame / reps, over / reps, 100.0 * over / frame, bytes / reps / 1e6);
    }
    /* per-request latency L of the scaling model: tiny sort-first frames, where rendering and
     * pixels cost next to nothing; what the client spends beyond the slowest server */
    if (r == SY_OK) {
        sy_layer tiny = {0};
        sy_cluster_frame tf = f;
        tf.width = 64, tf.height = 36;
        double lat_min = 1e30, lat_sum = 0, frame_sum = 0;
        const int lat_n = 30;
        r = sy_layer_create(tf.width, tf.height, &tiny, &err);
        for (int i = -1; i < lat_n && r == SY_OK; ++i) { /* i = -1: warm-up (a new image size) */
            sy_cluster_frame_stats s;
            r = sy_cluster_client_render(rig.client, &tf, &tiny, &s, &err);
            double l = s.seconds - s.max_server_seconds;
            if (r == SY_OK && i >= 0) {
                lat_sum += l, frame_sum += s.seconds;
                if (l < lat_min) lat_min = l;
            }
        }
        if (r == SY_OK)
            printf("  request latency (64x36 sort-first frames, 2 servers in parallel, %d frames): L = %.2f ms min, %.2f ms "
                   "mean beyond the slowest server (whole frame %.2f ms mean)\n",
                   lat_n, lat_min * 1e3, lat_sum / lat_n * 1e3, frame_sum / lat_n * 1e3);
        sy_layer_destroy(&tiny);
    }
    /* codec constants for the scaling model (docs/CLUSTER.md): compression and decompression
     * throughput of the final frame's pixels (RGBA + depth float32) on this core */
    if (r == SY_OK) {
        sy_cluster_buf enc = {0};
        double te = sy_time_now();
        r = sy_cluster_tile_encode(&rig.img, true, &enc, &err);
        te = sy_time_now() - te;
        sy_cluster_tile t = {{0, 0, w, h}, SY_CLUSTER_ENC_F32_SHUFFLE_ZSTD, 5, (uint64_t)w * h * 20, enc.data,
                             (uint32_t)enc.size};
        double td = sy_time_now();
        if (r == SY_OK) r = sy_cluster_tile_decode(&t, &rig.img, 0, 0, &err);
        td = sy_time_now() - td;
        double raw = (double)w * h * 20;
        if (r == SY_OK)
            printf("  tile codec %ux%u RGBA+Z float: %.1f MB raw -> %.2f MB (%.1fx); encode %.0f MB/s, decode %.0f MB/s "
                   "(raw bytes, one core)\n",
                   w, h, raw / 1e6, (double)enc.size / 1e6, raw / (double)enc.size, raw / te / 1e6, raw / td / 1e6);
        sy_cluster_buf_free(&enc);
    }
    if (r == SY_OK) r = bench_half_and_blob_cache(scene, &co, rig.client, &f, &rig.img, &s1, &err);
    if (r == SY_OK) r = sy_bench_cluster_hostile(scene, &d, backend, &srv[0], &err);
    sy_bench_cluster_rig_close(&rig);
    /* cooperative path tracing: 2 pinned servers vs 1 */
    if (r == SY_OK && sy_mediator_find("pathtracer")) {
        r = sy_bench_cluster_coop(scene, &vd, srv, rounds, ncpu >= 2, coop_frame, coop_pipe, &err);
    } else if (r == SY_OK) {
        printf("  cooperative: skipped (no 'pathtracer' back-end registered in this build)\n");
    }
    sy_bench_cluster_stop(&srv[0]);
    sy_bench_cluster_stop(&srv[1]);
    sy_scene_destroy(scene);
    return r == SY_OK ? 0 : sy_cli_fail(&err);
}
