/* sy_bench_cluster_scale.c — `sy bench cluster --scale`: the protocol's cost per frame and the bytes
 * on the wire with 1-3 servers in each mode, against the scaling model of docs/CLUSTER.md (see
 * sy_bench_cluster.h). */
#include "sy_bench_cluster.h"
#include "sy_bench.h"

#include <math.h>
#include <stdio.h>
#include <unistd.h>

/* >>scale: per-frame protocol cost and bytes on the wire, 1-3 servers, sort-first / balanced /
 * cooperative at 1080p and 4K, against the scaling model of docs/CLUSTER.md ("Scaling model").
 * Every server renders on one core (raster: LP_NUM_THREADS=1; path tracer: threads=1), so 2
 * servers use this machine's 2 cores and 3 are oversubscribed (stated in the output). The protocol
 * cost of a frame is the client's time beyond the slowest server's sync + render:
 *   sort-first, balanced:  overhead(N) = L + ceil(N/C) * (P/N) * r / D,  bytes back = P * c
 *     (the strips decode on their own threads while the slowest one still renders: the last
 *     strip's decode is what remains)
 *   cooperative:           overhead(N) = L + ceil(N/C) * P * r / D + N * P * m,  bytes back = N * P * c
 *     (every server returns the whole image; the merge costs m per pixel and server)
 * L from tiny frames, c and D from the 1-server frame of each mode and size (its image encoded and
 * decoded here), m calibrated on the 1-server cooperative frame; N = 2 and 3 check the model. The
 * loopback's bandwidth is taken as infinite (P * c / B adds on a real network). */
typedef struct scale_point {
    double frame, overhead, server; /* medians, seconds */
    double bytes_back, bytes_out;   /* per frame */
} scale_point;

static sy_result scale_measure(sy_scene *scene, const sy_demo_info *d, const sy_bench_cluster_server *srv, uint32_t n, uint32_t mode,
                               uint32_t w, uint32_t h, uint32_t frames, scale_point *out, sy_layer *img_out, sy_error *err)
{
    const char *urls[3] = {srv[0].url, srv[1].url, srv[2].url};
    sy_cluster_client_opts co = {.urls = urls, .url_count = n, .timeout_ms = 600000};
    bool coop = mode == SY_CLUSTER_COOPERATIVE;
    bool raster = sy_mediator_find("raster") != NULL; /* the picture back-ends measured: raster, else whitted */
    const char *backend = coop ? "pathtracer" : raster ? "raster" : "whitted";
    const char *params = coop ? "threads=1" : raster ? NULL : "spp=1,threads=1"; /* one core per server */
    sy_viewport_desc vd = {.root = d->root, .camera = d->camera, .background = d->background, .backend = backend};
    sy_bench_cluster_rig rig;
    sy_result r = sy_bench_cluster_rig_open(scene, &vd, &co, w, h, &rig, err);
    sy_cluster_frame f = {.mode = mode, .backend = backend, .params = params,
                          .root_id = d->root.id, .background_id = d->background.id, .camera = rig.view, .width = w,
                          .height = h, .samples = 1, .samples_total = coop ? n : 0, .depth = true};
    sy_cluster_frame_stats st;
    if (r == SY_OK) r = sy_cluster_client_render(rig.client, &f, &rig.img, &st, err); /* warm-up: snapshot + translation */
    double fr[16], ov[16], sv[16], back[16], sent[16];
    if (frames > 16) frames = 16;
    for (uint32_t i = 0; i < frames && r == SY_OK; ++i) {
        r = sy_cluster_client_render(rig.client, &f, &rig.img, &st, err);
        fr[i] = st.seconds, sv[i] = st.max_server_seconds, ov[i] = st.seconds - st.max_server_seconds;
        back[i] = (double)st.bytes_received, sent[i] = (double)st.bytes_sent;
        if (r == SY_OK && st.servers_live != n) r = sy_error_set(err, SY_ERR_IO, "bench: a server dropped out");
    }
    if (r == SY_OK) {
        out->frame = sy_bench_spread_of(fr, frames).median;
        out->overhead = sy_bench_spread_of(ov, frames).median;
        out->server = sy_bench_spread_of(sv, frames).median;
        out->bytes_back = sy_bench_spread_of(back, frames).median;
        out->bytes_out = sy_bench_spread_of(sent, frames).median;
    }
    if (r == SY_OK && img_out) {
        *img_out = rig.img;
        rig.img = (sy_layer){0};
    }
    sy_bench_cluster_rig_close(&rig);
    return r;
}

/* Decode rate (raw bytes per second, one core) and wire bytes per pixel of an image's tile. */
static sy_result codec_of(const sy_layer *img, double *D, double *c, sy_error *err)
{
    sy_cluster_buf enc = {0};
    sy_layer back = {0};
    sy_result r = sy_cluster_tile_encode(img, true, &enc, err);
    if (r == SY_OK) r = sy_layer_create(img->width, img->height, &back, err);
    double P = (double)img->width * img->height, best = 1e30;
    for (int k = 0; k < 3 && r == SY_OK; ++k) {
        sy_cluster_tile t = {{0, 0, img->width, img->height}, SY_CLUSTER_ENC_F32_SHUFFLE_ZSTD, 5, (uint64_t)P * 20,
                             enc.data, (uint32_t)enc.size};
        double t0 = sy_time_now();
        r = sy_cluster_tile_decode(&t, &back, 0, 0, err);
        double dt = sy_time_now() - t0;
        if (dt < best) best = dt;
    }
    *D = P * 20.0 / best;
    *c = (double)enc.size / P;
    sy_cluster_buf_free(&enc);
    sy_layer_destroy(&back);
    return r;
}

sy_result sy_bench_cluster_scale(sy_scene *scene, const sy_demo_info *d, uint32_t frames, sy_error *err)
{
    long ncpu = sysconf(_SC_NPROCESSORS_ONLN);
    double C = ncpu > 0 ? (double)ncpu : 1.0;
    sy_bench_cluster_server srv[3] = {{0}};
    sy_result r = SY_OK;
    for (int i = 0; i < 3 && r == SY_OK; ++i) r = sy_bench_cluster_spawn_ex(-1, 7200, true, &srv[i], err);
    printf("sy bench cluster --scale: demo scene, 1-3 servers on loopback, each rendering on one core (%ld cores here: "
           "3 servers are oversubscribed); raster (sort-first, balanced) and pathtracer 1 spp per frame in all "
           "(cooperative); medians of %u frames after a warm-up\n", ncpu, frames);
    double L = 0;
    if (r == SY_OK) {
        scale_point tiny;
        r = scale_measure(scene, d, srv, 1, SY_CLUSTER_SORT_FIRST, 64, 36, 15, &tiny, NULL, err);
        L = tiny.overhead;
        if (r == SY_OK) printf("  L = %.2f ms (request latency: 64x36 frames, time beyond the server)\n", L * 1e3);
    }
    static const uint32_t sizes[2][2] = {{1920, 1080}, {3840, 2160}};
    static const uint32_t modes[3] = {SY_CLUSTER_SORT_FIRST, SY_CLUSTER_BALANCED, SY_CLUSTER_COOPERATIVE};
    for (int si = 0; si < 2 && r == SY_OK; ++si) {
        uint32_t w = sizes[si][0], h = sizes[si][1];
        double P = (double)w * h, rb = 20.0; /* RGBA + depth float32 */
        printf("  %ux%u (P = %.2f Mpx, r = 20 bytes per pixel raw):\n", w, h, P / 1e6);
        double D = 0, c = 0, m = 0;
        for (int mi = 0; mi < 3 && r == SY_OK; ++mi)
            for (uint32_t n = 1; n <= 3 && r == SY_OK; ++n) {
                scale_point pt;
                sy_layer img = {0};
                bool coop = modes[mi] == SY_CLUSTER_COOPERATIVE;
                r = scale_measure(scene, d, srv, n, modes[mi], w, h, frames, &pt, n == 1 ? &img : NULL, err);
                if (r == SY_OK && n == 1 && mi != 1) { /* constants of this mode's images */
                    r = codec_of(&img, &D, &c, err);
                    if (r == SY_OK)
                        printf("    %s images: c = %.2f bytes per pixel on the wire, D = %.0f MB/s decode (one core)\n",
                               sy_cluster_mode_name(modes[mi]), c, D / 1e6);
                    if (r == SY_OK && coop) m = fmax(0.0, (pt.overhead - L - P * rb / D) / P);
                }
                sy_layer_destroy(&img);
                if (r != SY_OK) break;
                double per_core = ceil((double)n / C);
                double model = coop ? L + per_core * P * rb / D + n * P * m : L + per_core * (P / n) * rb / D;
                double bytes_model = (coop ? n : 1) * P * c;
                printf("    %-11s N=%u%s: frame %7.3f s, slowest server %7.3f s, protocol %6.1f ms (model %6.1f ms%s), "
                       "back %6.2f MB (model %6.2f MB), out %4.1f KB\n",
                       sy_cluster_mode_name(modes[mi]), n, n > C ? " (oversubscribed)" : "", pt.frame, pt.server,
                       pt.overhead * 1e3, model * 1e3, coop && n == 1 ? ": calibrates m" : "", pt.bytes_back / 1e6,
                       bytes_model / 1e6, pt.bytes_out / 1e3);
            }
        if (r == SY_OK && m > 0) printf("    m = %.1f ns per pixel and server (merge, calibrated at N=1)\n", m * 1e9);
    }
    for (int i = 0; i < 3; ++i)
        if (srv[i].pid) sy_bench_cluster_stop(&srv[i]);
    return r;
}
