/* test_pathtracer_filter.c — the path tracer's display filters (sy_mediator_rt.h "filter=...",
 * backends/filters) end to end: glTF -> window -> pathtracer mediator -> filter -> layer.
 *
 *   1. Quality (issue 7's target, at its own size W = 256): the Cornell box at
 *      4 spp (four progressive frames of 1 spp, as a viewer renders them), specular=0 (the Cycles
 *      reference is Lambertian), pixel filter with the dissertation's defaults: the relative MSE
 *      (eps 0.01) against ../shared/testdata/cornell/cornell_box_cycles_256_4096.exr box-averaged
 *      to W x W must be at least 4x lower than the unfiltered image's (the accumulation's colour
 *      AOV of the same samples). Frames 1-3 precede the first scheduled filter pass (2^i >= 4):
 *      there the output must be exactly the unfiltered estimate. The other filters (atrous, jbu,
 *      adaptive) are reported and must not make the image worse than unfiltered.
 *      Why not smaller: the error left after filtering sits at geometric edges (pixels whose 4
 *      samples straddle an edge: sub-pixel coverage noise is in the low-variance direct part, which
 *      the pixel filter leaves alone, and in the range buffer itself). Their share of the image
 *      grows as 1/W: measured (RelWithDebInfo, this seed) unfiltered/filtered relMSE 2.40x at 64,
 *      4.30x at 128, 11.6x at 256, while on interior pixels it is 12.9x, 20.3x and 25.2x; the
 *      split is printed and the interior ratio is checked too (>= 8x).
 *      The test ran at W = 128 until the path tracer's own noise fell (issue 19: later Russian
 *      roulette, stratification of the first directions): unfiltered relMSE 0.0531 -> 0.0389 at
 *      128 while the edge floor stayed (filtered 0.0123 -> 0.0121), so at 128 the whole-image ratio
 *      measured the edges (3.2x); at 256 it is 9.4x (pixel) and 11.7x (radiance), interior 17.0x
 *      and 26.8x.
 *      Radiance filtering (filter=radiance: the path tracer's stored-sample hook, one filter frame
 *      per 1-spp pass, the same samples) must reach the same 4x: measured 4.6x at 128x128 and
 *      12.7x at 256x256 (it filters the indirect part only, so the same edge/direct floor applies;
 *      a filter that does nothing, or blurs across the box edges, stays well below 4x).
 *   2. Consistency: a tiny view at high spp: the blend operator has switched the filter off where
 *      the unfiltered estimate's perceived variance is under the threshold, so the filtered image
 *      differs from the unfiltered one by less than the unfiltered image's own noise. The same for
 *      radiance filtering (pixels in the correction phase), and with its unbiased buffer every
 *      pixel in the correction phase equals the accumulation.
 *   3. Live changes: sy_mediator_rt_set_filter (filter and threshold) never restarts the
 *      accumulation (sy_mediator_stats.samples keeps growing, no restart counted; a switch to
 *      radiance resumes on the accumulation instead of starting over); "none" gives the
 *      unfiltered estimate exactly; on error nothing changes. A visible scene change restarts the
 *      accumulation and the pixel filter's state with it.
 *   4. Bad parameters are rejected with a message naming them (unknown filter, negative threshold,
 *      zero sigma, bad kernel, the radiance filter's options out of range).
 *   5. The stored-sample hook on the back-end directly (test_hook_records).
 * Exit 77 when the test data is absent. SY_PT_FILTER_SIZE overrides W (a divisor of 256),
 * SY_PT_FILTER_CONS_SIZE the consistency view (default 16; 256 with SY_PT_FILTER_SIZE=256 is the
 * issue's full 256x256 / 1024 spp measurement);
 * SY_PT_FILTER_PARAMS appends back-end params to part 1 (experiments, e.g. "threshold=0,sigma_s=4"). */
#include "it_util.h"
#include "sy_exr.h"
#include "sy_filter_metrics.h"
#include "sy_gltf.h"
#include "sy_mediator_rt.h"
#include "sy_radiance_hook.h"
#include "sy_rt.h"

#define PT_PARAMS "max_depth=64,specular=0"

typedef struct fixture {
    sy_scene *scene;
    sy_gltf_info info;
    sy_node cam;
    sy_context_pool *pool;
} fixture;

/* Renders `frames` progressive frames of 1 spp of a W x H window with the given back-end params
 * into img; returns the context. */
static sy_context *render_frames(fixture *fx, sy_window *win, const char *params, uint32_t frames, uint32_t spp_each,
                                 sy_layer *img)
{
    for (uint32_t i = 0; i < frames; ++i) {
        sy_window_render_opts ro = {.sample_count = spp_each};
        MUST(sy_window_render(win, fx->scene, fx->pool, &ro, img, err));
    }
    sy_params pp;
    MUST(sy_params_parse(params, &pp, err));
    sy_context *ctx;
    MUST(sy_context_pool_get(fx->pool, fx->scene, "pathtracer", &pp, fx->info.root.id, &ctx, err));
    return ctx;
}

static sy_window *make_window(fixture *fx, uint32_t w, uint32_t h, const char *params)
{
    sy_viewport_desc vd = {.root = fx->info.root, .camera = fx->cam, .backend = "pathtracer", .params = params};
    return it_window(w, h, &vd, NULL);
}

static double relmse(const float *img, const float *ref, uint32_t w, uint32_t h)
{
    sy_filter_metrics m;
    sy_filter_report fe = {0};
    if (sy_filter_metrics_compute(img, ref, w, h, 4, &m, &fe) != SY_FILTER_OK) {
        fprintf(stderr, "metrics: %s\n", fe.message);
        exit(1);
    }
    return m.relmse;
}

/* Context creation with bad params must fail with a message containing `needle`. */
static void expect_rejected(fixture *fx, const char *params, const char *needle)
{
    sy_params pp;
    MUST(sy_params_parse(params, &pp, err));
    sy_context *ctx = NULL;
    sy_error e = {0};
    sy_result r = sy_context_pool_get(fx->pool, fx->scene, "pathtracer", &pp, fx->info.root.id, &ctx, &e);
    EXPECT_MSG(r != SY_OK, "params '%s' accepted", params);
    EXPECT_MSG(r == SY_OK || strstr(e.message, needle), "params '%s': message '%s' does not mention '%s'", params, e.message,
               needle);
    if (r != SY_OK) printf("rejected %-40s -> %s\n", params, e.message);
}

/* 5. The stored-sample hook itself, on the Embree back-end directly (a floor, a back wall and an
 * area light seen from above; 48x48, 1 spp):
 *   - records change nothing: the accumulation with records is bit-identical to one without;
 *   - a record's colour is the sample the accumulation received, and where it has P0 it splits as
 *     colour = prefix + throughput * f_cos(wi) / pdf(wi) * incident (sy_rt_pt_record_bsdf);
 *   - NaN/Inf records (as a broken back-end could deliver) are counted by the radiance filter,
 *     the output stays finite, and they are kept out of every neighbourhood: every other pixel is
 *     bit-identical to a run where those pixels carried no sample at all. */
static void test_hook_records(void)
{
    enum { S = 48 };
    sy_rt_device *dev;
    if (sy_rt_device_create(NULL, &dev) != SY_RT_OK) {
        fprintf(stderr, "device: cannot create\n");
        exit(1);
    }
    /* floor y = 0 and back wall z = -1 (grey Lambert), light quad at y = 1.2 (double-sided emitter) */
    const float quads[3][12] = {{-2, 0, 2, 2, 0, 2, 2, 0, -2, -2, 0, -2},
                                {-2, 0, -1, 2, 0, -1, 2, 3, -1, -2, 3, -1},
                                {-0.3f, 1.2f, -0.3f, 0.3f, 1.2f, -0.3f, 0.3f, 1.2f, 0.3f, -0.3f, 1.2f, 0.3f}};
    const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    for (int q = 0; q < 3; ++q) {
        sy_rt_mesh_desc md = {.positions = quads[q], .indices = idx, .vertex_count = 4, .triangle_count = 2};
        sy_rt_mesh mesh;
        sy_rt_material mat;
        sy_rt_instance inst;
        sy_rt_material_desc mt;
        sy_rt_material_desc_init(&mt);
        mt.metallic = 0.0f, mt.specular = 0.0f, mt.double_sided = true;
        mt.base_color[0] = mt.base_color[1] = mt.base_color[2] = q == 2 ? 0.0f : 0.7f;
        if (q == 2) mt.emissive[0] = mt.emissive[1] = mt.emissive[2] = 8.0f;
        sy_rt_instance_desc id = {.transform = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}};
        if (sy_rt_mesh_create(dev, &md, &mesh) || sy_rt_material_create(dev, &mt, &mat))
            fprintf(stderr, "scene: %s\n", sy_rt_device_error(dev)), exit(1);
        id.mesh = mesh, id.material = mat;
        if (sy_rt_instance_create(dev, &id, &inst)) fprintf(stderr, "instance: %s\n", sy_rt_device_error(dev)), exit(1);
    }
    if (sy_rt_commit(dev)) fprintf(stderr, "commit: %s\n", sy_rt_device_error(dev)), exit(1);
    /* camera at (0, 1, 1.6) looking down 35 degrees */
    float c = cosf(0.61f), sn = sinf(0.61f);
    sy_rt_camera cam = {.camera_to_world = {1, 0, 0, 0, 0, c, -sn, 0, 0, sn, c, 0, 0, 1.0f, 1.6f, 1},
                        .projection = SY_RT_PROJECTION_PERSPECTIVE,
                        .window = {-0.6f, 0.6f, -0.6f, 0.6f}};
    sy_rt_accum *acc[2];
    for (int i = 0; i < 2; ++i)
        if (sy_rt_accum_create(dev, S, S, &acc[i])) fprintf(stderr, "accum: %s\n", sy_rt_device_error(dev)), exit(1);
    sy_rt_pt_record *rec = calloc(S * S, sizeof *rec);
    float *rgba = malloc(S * S * 4 * sizeof(float)), *rgba2 = malloc(S * S * 4 * sizeof(float));
    sy_rt_render_desc d = {.integrator = SY_RT_INTEGRATOR_PATHTRACER, .image_width = S, .image_height = S,
                           .width = S, .height = S, .max_depth = 16, .seed = 7, .samples = 1, .accum = acc[0]};
    if (sy_rt_render(dev, &cam, &d, rgba, NULL)) fprintf(stderr, "render: %s\n", sy_rt_device_error(dev)), exit(1);
    d.accum = acc[1], d.records = rec;
    if (sy_rt_render(dev, &cam, &d, rgba2, NULL)) fprintf(stderr, "render: %s\n", sy_rt_device_error(dev)), exit(1);
    size_t differ = 0, p0 = 0, split_bad = 0, color_bad = 0;
    double inc_sum = 0;
    for (size_t i = 0; i < S * S; ++i) {
        differ += memcmp(rgba + 4 * i, rgba2 + 4 * i, 4 * sizeof(float)) != 0;
        const sy_rt_pt_record *r = rec + i;
        for (int k = 0; k < 3; ++k) color_bad += r->color[k] != rgba2[4 * i + k];
        if (!(r->flags & SY_RT_RECORD_P0)) continue;
        p0++;
        float fc[3], pdf;
        sy_rt_pt_record_bsdf(r, r->wi, fc, &pdf);
        for (int k = 0; k < 3; ++k) {
            double want = r->prefix[k] + (pdf > 0 ? r->throughput[k] * fc[k] / pdf * r->incident[k] : 0.0);
            split_bad += fabs(want - r->color[k]) > 1e-4 * (1.0 + fabs(r->color[k]));
            inc_sum += r->incident[k];
        }
    }
    printf("hook: %zu/%d pixels with P0, mean incident %.4f; %zu pixels differ from the render without records, "
           "%zu colour values differ from the accumulation, %zu split mismatches\n",
           p0, S * S, inc_sum / (3.0 * (double)(p0 ? p0 : 1)), differ, color_bad, split_bad);
    EXPECT_MSG(differ == 0, "records changed %zu pixels of the path-traced image", differ);
    EXPECT_MSG(color_bad == 0 && split_bad == 0, "record colour / split mismatches: %zu / %zu", color_bad, split_bad);
    EXPECT_MSG(p0 > S * S * 9 / 10 && inc_sum > 0, "only %zu P0 records, incident sum %g", p0, inc_sum);

    /* NaN/Inf records: counted, output finite, kept out of every neighbourhood */
    const size_t bad[3] = {10 * S + 10, 24 * S + 24, 25 * S + 24};
    sy_filter_radiance_params fp;
    sy_filter_radiance_params_default(&fp);
    float *out[2] = {calloc(S * S * 4, sizeof(float)), calloc(S * S * 4, sizeof(float))};
    sy_filter_stats st[2];
    for (int run = 0; run < 2; ++run) {
        sy_radiance_hook *h;
        sy_rt_pt_record *hr;
        MUST(sy_radiance_hook_create(&fp, &h, err));
        MUST(sy_radiance_hook_records(h, S, S, &hr, err));
        memcpy(hr, rec, S * S * sizeof *rec);
        for (int b = 0; b < 3; ++b) {
            sy_rt_pt_record *r = hr + bad[b];
            if (run == 1) { /* the same pixels without any sample */
                memset(r, 0, sizeof *r);
                continue;
            }
            EXPECT(r->flags & SY_RT_RECORD_P0);
            if (b == 0) r->incident[1] = NAN;
            if (b == 1) r->color[0] = INFINITY;
            if (b == 2) r->position[2] = NAN;
        }
        sy_radiance_hook_frame_desc fd = {.pixel_angle = 1.2f / S};
        MUST(sy_radiance_hook_frame(h, &fd, out[run], &st[run], err));
        sy_radiance_hook_destroy(h);
    }
    size_t nonfinite = 0, other_differ = 0, filtered = 0;
    for (size_t i = 0; i < S * S; ++i) {
        bool is_bad = i == bad[0] || i == bad[1] || i == bad[2];
        for (int k = 0; k < 3; ++k) {
            nonfinite += !isfinite(out[0][4 * i + k]);
            if (!is_bad) other_differ += out[0][4 * i + k] != out[1][4 * i + k];
            filtered += !is_bad && k == 0 && out[0][4 * i] != rec[i].color[0];
        }
    }
    printf("hook NaN/Inf: %llu non-finite records reported, %zu non-finite outputs, %zu values of other pixels differ "
           "from the run without those samples, %zu pixels filtered\n",
           (unsigned long long)st[0].nonfinite_samples, nonfinite, other_differ, filtered);
    EXPECT_MSG(st[0].nonfinite_samples == 3 && st[1].nonfinite_samples == 0, "reported %llu / %llu non-finite records",
               (unsigned long long)st[0].nonfinite_samples, (unsigned long long)st[1].nonfinite_samples);
    EXPECT_MSG(nonfinite == 0 && other_differ == 0, "non-finite outputs %zu, other pixels changed %zu", nonfinite,
               other_differ);
    EXPECT_MSG(filtered > S * S / 2, "only %zu pixels were filtered (frame 1 uses the warm-up radius)", filtered);
    free(out[0]), free(out[1]), free(rec), free(rgba), free(rgba2);
    sy_rt_accum_destroy(acc[0]), sy_rt_accum_destroy(acc[1]);
    sy_rt_device_destroy(dev);
}

int main(void)
{
    it_register();
    char gpath[1024], rpath[1024];
    it_testdata("cornell/cornell_box.gltf", gpath, sizeof gpath);
    it_testdata("cornell/cornell_box_cycles_256_4096.exr", rpath, sizeof rpath);
    const char *ws = getenv("SY_PT_FILTER_SIZE");
    uint32_t W = ws && *ws ? (uint32_t)strtoul(ws, NULL, 10) : 256;
    if (W == 0 || 256 % W != 0) {
        fprintf(stderr, "SY_PT_FILTER_SIZE must divide 256\n");
        return 1;
    }
    fixture fx;
    memset(&fx, 0, sizeof fx);
    fx.scene = it_load_gltf(gpath, &fx.info);
    MUST(sy_gltf_find_camera(fx.scene, &fx.info, "camera", &fx.cam, err));
    MUST(sy_scene_commit(fx.scene, NULL, err));
    MUST(sy_context_pool_create(&fx.pool, err));

    /* reference, box-averaged to W x W (RGBA, alpha 1) */
    sy_exr_image *ref;
    MUST(sy_exr_read(rpath, &ref, err));
    EXPECT(ref->width == 256 && ref->height == 256);
    const float *rc[3] = {sy_exr_image_channel(ref, "R"), sy_exr_image_channel(ref, "G"), sy_exr_image_channel(ref, "B")};
    if (!rc[0] || !rc[1] || !rc[2]) {
        fprintf(stderr, "reference lacks R, G or B\n");
        return 1;
    }
    size_t n = (size_t)W * W;
    uint32_t f = 256 / W;
    float *refw = calloc(n * 4, sizeof *refw);
    for (uint32_t y = 0; y < W; ++y)
        for (uint32_t x = 0; x < W; ++x) {
            for (int c = 0; c < 3; ++c) {
                double s = 0;
                for (uint32_t j = 0; j < f; ++j)
                    for (uint32_t i = 0; i < f; ++i) s += rc[c][(size_t)(y * f + j) * 256 + x * f + i];
                refw[4 * ((size_t)y * W + x) + c] = (float)(s / (f * f));
            }
            refw[4 * ((size_t)y * W + x) + 3] = 1.0f;
        }
    sy_exr_image_free(ref);

    /* 1. quality at 4 spp: pixel filter, then the baselines on the same seed */
    const char *names[] = {"pixel", "radiance", "atrous", "jbu", "adaptive"};
#ifdef SY_PT_SANITIZE
    const int methods = 2; /* sanitizer builds: pixel and radiance filter only (the baselines have unit tests) */
#else
    const int methods = 5;
#endif
    double unfiltered_relmse = 0, pixel_relmse = 0, radiance_relmse = 0;
    for (int k = 0; k < methods; ++k) {
        char params[256];
        const char *extra = getenv("SY_PT_FILTER_PARAMS"); /* experiments: e.g. "threshold=0,sigma_s=4" */
        snprintf(params, sizeof params, PT_PARAMS ",filter=%s%s%s", names[k], extra && *extra ? "," : "",
                 extra && *extra ? extra : "");
        sy_window *win = make_window(&fx, W, W, params);
        sy_layer img;
        MUST(sy_layer_create(W, W, &img, err));
        sy_context *ctx = NULL;
        for (uint32_t frame = 1; frame <= 4; ++frame) {
            ctx = render_frames(&fx, win, params, 1, 1, &img);
            sy_mediator_rt_aovs a;
            MUST(sy_mediator_rt_aovs_get(sy_context_state(ctx), &a, err));
            EXPECT_MSG(a.samples == frame, "%s: %u samples after frame %u", names[k], a.samples, frame);
            if (k == 0 && frame < 4) { /* before the first scheduled pass: exactly unfiltered */
                size_t diff = 0;
                for (size_t i = 0; i < n * 4; ++i) diff += img.rgba[i] != a.planes[0][i];
                EXPECT_MSG(diff == 0, "pixel filter, frame %u (before the first pass): %zu values differ from unfiltered",
                           frame, diff);
            }
            if (frame == 4) {
                double u = relmse(a.planes[0], refw, W, W), fr = relmse(img.rgba, refw, W, W);
                sy_mediator_rt_filter_info fi;
                sy_mediator_rt_filter_info_get(sy_context_state(ctx), &fi);
                printf("cornell %ux%u, 4 spp, filter %-8s: relMSE unfiltered %.5f filtered %.5f (%.2fx lower), "
                       "filter %.2f ms, NaN/Inf pixels %llu%s\n",
                       W, W, names[k], u, fr, u / fr, fi.seconds * 1e3, (unsigned long long)fi.nonfinite_pixels,
                       k == 0 ? (fi.filter_pass ? ", pass ran" : ", NO PASS") : "");
                if (k <= 1) { /* where the error sits: geometric edges (sub-pixel coverage) vs interiors */
                    double se[2][2] = {{0, 0}, {0, 0}};
                    size_t ne = 0;
                    for (uint32_t y = 0; y < W; ++y)
                        for (uint32_t x = 0; x < W; ++x) {
                            size_t i = (size_t)y * W + x;
                            float l = sy_filter_luminance(refw + 4 * i);
                            bool edge = false;
                            const int dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};
                            for (int q = 0; q < 4; ++q) {
                                int xx = (int)x + dx[q], yy = (int)y + dy[q];
                                if (xx < 0 || yy < 0 || xx >= (int)W || yy >= (int)W) continue;
                                float l2 = sy_filter_luminance(refw + 4 * ((size_t)yy * W + (size_t)xx));
                                edge = edge || fabsf(l2 - l) > 0.25f * fmaxf(l, l2);
                            }
                            ne += edge;
                            for (int c = 0; c < 3; ++c) {
                                double r = refw[4 * i + c], du = a.planes[0][4 * i + c] - r, df = img.rgba[4 * i + c] - r;
                                se[edge][0] += du * du / (r * r + 0.01);
                                se[edge][1] += df * df / (r * r + 0.01);
                            }
                        }
                    double tot = 3.0 * (double)n;
                    /* radiance: 27.9x measured; the same filter without the world-space prism
                     * (rf_prism_thickness=100, rf_grazing_epsilon=1: samples leak across surfaces) gets 14.3x */
                    double want = k == 1 ? 20.0 : 8.0;
                    EXPECT_MSG(se[0][0] >= want * se[0][1], "%s, interior pixels: relMSE only %.2fx lower (want %.0fx)",
                               names[k], se[0][0] / se[0][1], want);
                    printf("  relMSE split: %zu edge pixels (%.1f%%) contribute unfiltered %.5f filtered %.5f; interior "
                           "pixels unfiltered %.5f filtered %.5f (%.2fx lower)\n",
                           ne, 100.0 * (double)ne / (double)n, se[1][0] / tot, se[1][1] / tot, se[0][0] / tot,
                           se[0][1] / tot, se[0][0] / se[0][1]);
                }
                EXPECT_MSG(!strcmp(fi.name, names[k]), "filter info names '%s'", fi.name);
                EXPECT_MSG(fi.nonfinite_pixels == 0 && fi.nonfinite_samples == 0, "non-finite: %llu pixels %llu samples",
                           (unsigned long long)fi.nonfinite_pixels, (unsigned long long)fi.nonfinite_samples);
                EXPECT_MSG(sy_layer_count_nonfinite(&img) == 0, "%s: non-finite output", names[k]);
                EXPECT_MSG(fr < u, "%s: filtered relMSE %.5f not below unfiltered %.5f", names[k], fr, u);
                if (k == 0) {
                    unfiltered_relmse = u, pixel_relmse = fr;
                    EXPECT(fi.filter_pass && fi.last_pass_samples == 4);
                }
                if (k == 1) radiance_relmse = fr;
            }
            sy_mediator_rt_aovs_free(&a);
        }
        sy_layer_destroy(&img);
        sy_window_destroy(win);
    }
    EXPECT_MSG(pixel_relmse * 4.0 <= unfiltered_relmse, "pixel filter relMSE %.5f is not 4x below unfiltered %.5f (%.2fx)",
               pixel_relmse, unfiltered_relmse, unfiltered_relmse / pixel_relmse);
    EXPECT_MSG(radiance_relmse * 4.0 <= unfiltered_relmse,
               "radiance filter relMSE %.5f is not 4x below unfiltered %.5f (%.2fx)", radiance_relmse, unfiltered_relmse,
               unfiltered_relmse / radiance_relmse);

    /* 3. live changes never restart the accumulation */
    {
        const char *params = PT_PARAMS ",filter=pixel,threshold=0.01";
        sy_window *win = make_window(&fx, W, W, params);
        sy_layer img;
        MUST(sy_layer_create(W, W, &img, err));
        sy_context *ctx = render_frames(&fx, win, params, 4, 1, &img);
        void *st = sy_context_state(ctx);
        sy_mediator_rt_counters c0;
        sy_mediator_rt_counters_get(st, &c0);
        const char *seq[] = {"atrous", NULL, "jbu", "adaptive", "radiance", "none", "pixel"};
        uint64_t last = 4;
        for (int i = 0; i < 7; ++i) {
            sy_params opts = {0};
            if (!seq[i]) MUST(sy_params_set(&opts, "threshold", "0.04", err)); /* threshold alone */
            MUST(sy_mediator_rt_set_filter(st, seq[i], &opts, err));
            render_frames(&fx, win, params, 1, 1, &img);
            sy_mediator_stats ms;
            sy_context_stats(ctx, &ms);
            EXPECT_MSG(ms.samples == last + 1, "after switching to %s: %llu samples (expected %llu)", seq[i] ? seq[i] : "t=0.04",
                       (unsigned long long)ms.samples, (unsigned long long)(last + 1));
            last = ms.samples;
            sy_mediator_rt_filter_info fi;
            sy_mediator_rt_filter_info_get(st, &fi);
            EXPECT_MSG(fabsf(fi.threshold - (i ? 0.04f : 0.01f)) < 1e-7f, "threshold %g after the change", (double)fi.threshold);
            sy_mediator_rt_aovs a;
            MUST(sy_mediator_rt_aovs_get(st, &a, err));
            size_t diff = 0;
            for (size_t j = 0; j < n * 4; ++j) diff += img.rgba[j] != a.planes[0][j];
            if (seq[i] && !strcmp(seq[i], "none")) EXPECT_MSG(diff == 0, "filter none: %zu values differ from unfiltered", diff);
            if (seq[i] && !strcmp(seq[i], "radiance")) { /* resumed on the accumulation, not restarted */
                double rel = relmse(img.rgba, a.planes[0], W, W);
                printf("switch to radiance at %llu spp: relMSE against the unfiltered accumulation %.5f\n",
                       (unsigned long long)ms.samples, rel);
                EXPECT_MSG(diff > 0 && rel < 0.005, "radiance after the switch: %zu values differ, relMSE %.5f to unfiltered",
                           diff, rel);
            }
            if (seq[i] && !strcmp(seq[i], "pixel"))
                EXPECT_MSG(diff > n, "pixel filter re-enabled: only %zu values differ (no pass ran?)", diff);
            sy_mediator_rt_aovs_free(&a);
        }
        sy_mediator_rt_counters c1;
        sy_mediator_rt_counters_get(st, &c1);
        EXPECT_MSG(c1.accum_restarts == c0.accum_restarts, "filter changes restarted the accumulation (%u -> %u)",
                   c0.accum_restarts, c1.accum_restarts);
        /* a visible scene change (a node of the box moved) restarts this slot's accumulation: the
         * pixel filter's state restarts with it (no stale filtered buffer: the first frames are
         * exactly the new unfiltered estimate, the pass comes back at 4 samples) */
        uint32_t nkids = 0;
        const uint32_t *kids = sy_node_children(sy_node_get(fx.scene, fx.info.root), &nkids);
        sy_node moved = {0};
        for (uint32_t q = 0; q < nkids && !moved.id; ++q)
            if (kids[q] != fx.cam.id) moved.id = kids[q];
        EXPECT(moved.id != 0);
        sy_mat4 m0 = sy_node_get(fx.scene, moved)->transform.matrix, m1 = m0;
        m1.m[12] += 0.01f;
        MUST(sy_node_set_matrix(fx.scene, moved, &m1, err));
        MUST(sy_scene_commit(fx.scene, NULL, err));
        for (uint32_t frame = 1; frame <= 4; ++frame) {
            render_frames(&fx, win, params, 1, 1, &img);
            sy_mediator_rt_aovs a;
            MUST(sy_mediator_rt_aovs_get(st, &a, err));
            size_t diff = 0;
            for (size_t j = 0; j < n * 4; ++j) diff += img.rgba[j] != a.planes[0][j];
            EXPECT_MSG(a.samples == frame, "after the scene change: %u samples at frame %u", a.samples, frame);
            if (frame < 4) EXPECT_MSG(diff == 0, "after the scene change, frame %u: %zu values differ from unfiltered", frame, diff);
            else EXPECT_MSG(diff > n, "after the scene change, frame 4: no filter pass (%zu values differ)", diff);
            sy_mediator_rt_aovs_free(&a);
        }
        MUST(sy_node_set_matrix(fx.scene, moved, &m0, err));
        MUST(sy_scene_commit(fx.scene, NULL, err));
        /* a rejected change changes nothing */
        sy_error e = {0};
        EXPECT(sy_mediator_rt_set_filter(st, "bogus", NULL, &e) != SY_OK && strstr(e.message, "bogus"));
        sy_params bad = {0};
        MUST(sy_params_set(&bad, "sigma_s", "0", err));
        e = (sy_error){0};
        EXPECT(sy_mediator_rt_set_filter(st, "atrous", &bad, &e) != SY_OK && strstr(e.message, "sigma_s"));
        sy_mediator_rt_filter_info fi;
        sy_mediator_rt_filter_info_get(st, &fi);
        EXPECT_MSG(!strcmp(fi.name, "pixel") && fabsf(fi.threshold - 0.04f) < 1e-7f, "after rejected changes: %s t=%g",
                   fi.name, (double)fi.threshold);
        sy_layer_destroy(&img);
        sy_window_destroy(win);
    }

    /* 2. consistency at high spp on a tiny view (SY_PT_FILTER_CONS_SIZE overrides T = 16, e.g. 256
     * for the issue's full measurement): the pixel filter's blend operator has switched the filter
     * off where the threshold allows; the radiance filter's pixels have entered the correction
     * phase (plain path tracing: its bias decays as O(1/N)). Either way the filtered image is
     * within the unfiltered image's own noise of the reference */
    const char *cs = getenv("SY_PT_FILTER_CONS_SIZE");
    const uint32_t T = cs && *cs ? (uint32_t)strtoul(cs, NULL, 10) : 16;
    if (T == 0 || 256 % T != 0 || T > W) {
        fprintf(stderr, "SY_PT_FILTER_CONS_SIZE must divide 256 and be <= SY_PT_FILTER_SIZE\n");
        return 1;
    }
    for (int fk = 0; fk < 3; ++fk) {
        /* fk 2: the radiance filter's unbiased buffer: pixels in the correction phase show the plain
         * path-traced mean (equal to the accumulation up to float rounding) */
        const char *fname = fk ? "radiance" : "pixel";
#ifdef SY_PT_SANITIZE
        const uint32_t SPP = 256, ft = 256 / T; /* sanitizer builds: 4x fewer samples */
#else
        const uint32_t SPP = 1024, ft = 256 / T;
#endif
        char params[128];
        snprintf(params, sizeof params, PT_PARAMS ",filter=%s%s", fname, fk == 2 ? ",rf_unbiased=1" : "");
        sy_window *win = make_window(&fx, T, T, params);
        sy_layer img;
        MUST(sy_layer_create(T, T, &img, err));
        /* progressive frames of 64 spp: passes at 64, 128, ..., 1024 (the powers of two crossed) */
        sy_context *ctx = render_frames(&fx, win, params, SPP / 64, 64, &img);
        sy_mediator_rt_aovs a;
        MUST(sy_mediator_rt_aovs_get(sy_context_state(ctx), &a, err));
        EXPECT_MSG(a.samples == SPP, "%u samples", a.samples);
        sy_mediator_rt_filter_info fi;
        sy_mediator_rt_filter_info_get(sy_context_state(ctx), &fi);
        double zu = 0, zf = 0, zd = 0, worst = 0;
        size_t m = (size_t)T * T, exact = 0, cnt = 0, close = 0;
        for (size_t i = 0; i < m; ++i) {
            size_t x = i % T, y = i / T;
            bool same = true, near = true;
            for (int c = 0; c < 3; ++c) {
                double r = 0; /* the reference box-averaged to T x T */
                for (uint32_t j = 0; j < ft; ++j)
                    for (uint32_t q = 0; q < ft; ++q) r += refw[4 * ((y * ft + j) / f * W + (x * ft + q) / f) + c];
                r /= (double)(ft * ft);
                double u = a.planes[0][4 * i + c], fv = img.rgba[4 * i + c], v = a.planes[1][3 * i + c];
                same = same && u == fv;
                near = near && fabs(fv - u) <= 1e-4 * (fabs(u) + 1e-3);
                if (!(v > 0)) continue; /* the light's interior: exact */
                zu += (u - r) * (u - r) / v;
                zf += (fv - r) * (fv - r) / v;
                zd += (fv - u) * (fv - u) / v;
                worst = fmax(worst, (fv - u) * (fv - u) / v);
                cnt++;
            }
            exact += same;
            close += near;
        }
        zu /= (double)cnt, zf /= (double)cnt, zd /= (double)cnt;
        printf("consistency %ux%u, %u spp, %s filter%s: mean blend s / correction share %.4f, last pass at %u spp, "
               "%zu/%zu pixels exactly (%zu within 1e-4) unfiltered; mean squared error / Var against the reference: "
               "unfiltered %.3f, filtered %.3f; (filtered - unfiltered)^2 / Var mean %.3f worst %.3f\n",
               T, T, SPP, fname, fk == 2 ? " (unbiased buffer)" : "", fi.mean_blend, fi.last_pass_samples, exact, m,
               close, zu, zf, zd, worst);
        if (fk == 2)
            EXPECT_MSG((double)close >= fi.mean_blend * (double)m - 0.5,
                       "unbiased buffer: %zu pixels equal the accumulation, %.0f are in the correction phase", close,
                       fi.mean_blend * (double)m);
        EXPECT_MSG(fi.last_pass_samples == SPP, "last pass at %u spp", fi.last_pass_samples);
        EXPECT_MSG(zf < zu + 0.5, "filtered image is %.3f variances from the reference (unfiltered: %.3f)", zf, zu);
        EXPECT_MSG(zd < 0.5, "filtered differs from unfiltered by %.3f times its own variance on average", zd);
        sy_mediator_rt_aovs_free(&a);
        sy_layer_destroy(&img);
        sy_window_destroy(win);
    }

    /* 4. bad parameters: refused, the message naming the parameter */
    static const struct {
        const char *params, *names;
    } bad[] = {
        {PT_PARAMS ",filter=bogus", "bogus"},
        {PT_PARAMS ",filter=radiance,threshold=0", "threshold"},
        {PT_PARAMS ",filter=radiance,rf_max_radius=0.5", "rf_max_radius"},
        {PT_PARAMS ",filter=radiance,rf_warmup_radius=0", "warmup_radius"},
        {PT_PARAMS ",filter=radiance,rf_warmup_frames=65", "rf_warmup_frames"},
        {PT_PARAMS ",filter=radiance,rf_kernel=box", "rf_kernel"},
        {PT_PARAMS ",filter=radiance,rf_unbiased=2", "rf_unbiased"},
        {PT_PARAMS ",filter=pixel,rf_prism_thickness=0", "prism_thickness"}, /* checked whatever the filter */
        {PT_PARAMS ",filter=pixel,threshold=-1", "threshold"},
        {PT_PARAMS ",filter=pixel,sigma_s=0", "sigma_s"},
        {PT_PARAMS ",filter=pixel,sigma_c=0", "sigma_c"},
        {PT_PARAMS ",filter=pixel,filter_kernel=box", "filter_kernel"},
        {PT_PARAMS ",filter=pixel,filter_start=3", "schedule_start"},
        {PT_PARAMS ",filter=adaptive,threshold=0", "threshold"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; ++k) expect_rejected(&fx, bad[k].params, bad[k].names);

    test_hook_records();

    free(refw);
    sy_context_pool_destroy(fx.pool);
    sy_gltf_info_free(&fx.info);
    sy_scene_destroy(fx.scene);
    return sy_check_finish("integration_pathtracer_filter");
}
