/* test_pathtracer_cornell.c — the "pathtracer" back-end end to end (glTF -> scene -> window ->
 * mediator -> Embree) on the Cornell box, against Blender Cycles' independent reference
 * ../shared/testdata/cornell/cornell_box_cycles_256_4096.exr (4096 spp, box filter of 1 pixel,
 * 64 bounces, no clamping).
 *
 * The reference's materials are Lambertian (see its README), so the render uses max_depth=64 and
 * specular=0 (no glTF dielectric F0 = 0.04 layer; with it the red channel's mean is 0.9 % lower
 * and the block error ~9 %, as the specular layer trades diffuse red for white reflection).
 * The render is made at W x W (W divides 256); the reference is box-averaged to
 * W x W (with a box pixel filter both estimate the same pixel integrals). Reported and checked:
 *   - mean: relative difference of the whole-image mean, per channel;
 *   - block: mean over 8x8-reference-pixel blocks and channels of |ours - ref| / ref.
 * The issue's acceptance criteria are at W = 256 and 4096 spp: mean < 0.5 %, block < 2 %. That run
 * takes minutes, so ctest uses W = 64 and 64 spp (SY_SANITIZE builds: 16 spp) and the environment
 * variables SY_PT_CORNELL_SIZE / SY_PT_CORNELL_SPP select the full measurement:
 *     SY_PT_CORNELL_SIZE=256 SY_PT_CORNELL_SPP=4096 build/tests/integration/test_it_pathtracer_cornell
 * ctest thresholds (see THRESH_* below for the numbers and how they were validated) are derived
 * from the noise of the low-sample estimate, and still catch a missing bounce or a wrong light pdf.
 * Also: no non-finite pixel and no dropped sample; the light's interior pixels are exactly its
 * radiance 17 12 4 (it has a black base colour, so nothing is reflected on top); AOVs are
 * consistent (direct + indirect = colour, albedo of the white wall = its base colour).
 * light_tree (issue 39): the default (auto: 2 emissive triangles, the alias table) renders bit for
 * bit as light_tree=off (4 spp), and light_tree=on (the light tree) meets the same whole-image mean
 * limit against the reference at the same spp. (The box's light is one quad whose two triangles
 * have the same box, cone and power: the tree picks them with probability 1/2 each, as the alias
 * table does, and the images agree; rt_lighttree compares the two where they differ.) */
#include "it_util.h"
#include "sy_exr.h"
#include "sy_gltf.h"
#include "sy_mediator_rt.h"
#include "sy_png.h"

#ifdef SY_PT_SANITIZE
#define DEFAULT_SPP 16u
#else
#define DEFAULT_SPP 64u
#endif
/* ctest thresholds (W = 64, 64 spp; 16 spp under ASan). The block error expected from our own
 * noise alone is computed from the variance AOV: E|N(0, var_block)| / ref = sqrt(2/pi) sigma / ref,
 * averaged over the block-channels (7.1 % at 64 spp, ~14 % at 16 spp; the reference's own noise is
 * far smaller per 8x8 block). Measured: block error 5.6 %, whole-image mean errors +0.06..+0.08 %.
 * Limits: block error < 1.3 x the expected noise + 0.5 %, whole-image mean within 1 % per channel
 * (its noise is ~0.1 % at 64 spp). Validation by breaking the integrator on purpose:
 *   - max_depth=1 (direct light only, a missing bounce): mean errors R -24.7 % G -20.9 % B -13.7 %,
 *     block error 53.9 % (limit ~2.4 %);
 *   - area-light pdf doubled in sample_light (light samples weighted half): mean errors R -24.4 %
 *     G -22.2 % B -17.6 %, block error 49.2 % (limit ~5.3 %);
 * both fail both checks by an order of magnitude. */
#define THRESH_MEAN 0.01
#define THRESH_BLOCK_NOISE 1.3
#define THRESH_BLOCK_ABS 0.005

/* A fresh window and pool render of the Cornell box with params, spp samples (issue 39's light_tree
 * checks). */
static void render_params(sy_scene *scene, const sy_gltf_info *info, sy_node cam, const char *params, uint32_t W,
                          uint32_t spp, sy_layer *out)
{
    sy_viewport_desc vd = {.root = info->root, .camera = cam, .backend = "pathtracer", .params = params};
    sy_window *win = it_window(W, W, &vd, NULL);
    sy_context_pool *pool = it_pool();
    MUST(sy_layer_create(W, W, out, err));
    for (uint32_t done = 0; done < spp;) {
        uint32_t n = spp - done < 64 ? spp - done : 64;
        sy_window_render_opts ro = {.sample_count = n};
        MUST(sy_window_render(win, scene, pool, &ro, out, err));
        done += n;
    }
    sy_context_pool_destroy(pool);
    sy_window_destroy(win);
}

static uint32_t env_u32(const char *name, uint32_t def)
{
    const char *v = getenv(name);
    return v && *v ? (uint32_t)strtoul(v, NULL, 10) : def;
}

int main(void)
{
    it_register();
    char gpath[1024], rpath[1024];
    it_testdata("cornell/cornell_box.gltf", gpath, sizeof gpath);
    it_testdata("cornell/cornell_box_cycles_256_4096.exr", rpath, sizeof rpath);
    uint32_t W = env_u32("SY_PT_CORNELL_SIZE", 64), spp = env_u32("SY_PT_CORNELL_SPP", DEFAULT_SPP);
    if (W == 0 || 256 % W != 0 || spp == 0) {
        fprintf(stderr, "SY_PT_CORNELL_SIZE must divide 256, SY_PT_CORNELL_SPP must be > 0\n");
        return 1;
    }
    bool full = W != 64 || spp != DEFAULT_SPP;
    sy_gltf_info info;
    sy_scene *scene = it_load_gltf(gpath, &info);
    sy_node cam;
    MUST(sy_gltf_find_camera(scene, &info, "camera", &cam, err));
    MUST(sy_scene_commit(scene, NULL, err));
    sy_viewport_desc vd = {.root = info.root, .camera = cam, .backend = "pathtracer", .params = "max_depth=64,specular=0"};
    sy_window *win = it_window(W, W, &vd, NULL);
    sy_context_pool *pool = it_pool();
    sy_layer img;
    MUST(sy_layer_create(W, W, &img, err));
    double t0 = sy_time_now();
    for (uint32_t done = 0; done < spp;) { /* passes of up to 64 samples */
        uint32_t n = spp - done < 64 ? spp - done : 64;
        sy_window_render_opts ro = {.sample_count = n};
        MUST(sy_window_render(win, scene, pool, &ro, &img, err));
        done += n;
    }
    double secs = sy_time_now() - t0;
    sy_params pp;
    MUST(sy_params_parse("max_depth=64,specular=0", &pp, err));
    sy_context *ctx;
    MUST(sy_context_pool_get(pool, scene, "pathtracer", &pp, info.root.id, &ctx, err));
    sy_mediator_stats st;
    sy_context_stats(ctx, &st);
    EXPECT_MSG(st.samples == spp, "stats report %llu samples, expected %u", (unsigned long long)st.samples, spp);
    EXPECT_MSG(sy_layer_count_nonfinite(&img) == 0, "%zu non-finite pixels", sy_layer_count_nonfinite(&img));

    /* AOVs */
    sy_mediator_rt_aovs a;
    MUST(sy_mediator_rt_aovs_get(sy_context_state(ctx), &a, err));
    float *var = malloc((size_t)W * W * 3 * sizeof *var);
    memcpy(var, a.planes[1], (size_t)W * W * 3 * sizeof *var);
    EXPECT_MSG(a.nonfinite_samples == 0, "%llu samples dropped", (unsigned long long)a.nonfinite_samples);
    double worst = 0;
    for (size_t i = 0; i < (size_t)W * W; ++i)
        for (int c = 0; c < 3; ++c) {
            double dsum = a.planes[5][3 * i + c] + a.planes[6][3 * i + c], col = a.planes[0][4 * i + c];
            worst = fmax(worst, fabs(dsum - col) / fmax(1.0, fabs(col)));
        }
    EXPECT_MSG(worst < 1e-4, "direct + indirect differs from colour by %g", worst);
    /* the back wall centre (a little below the middle) is white: albedo 0.725 0.71 0.68 */
    const float *alb = a.planes[2] + 3 * ((size_t)(W * 55 / 100) * W + W / 2);
    EXPECT_MSG(fabsf(alb[0] - 0.725f) < 1e-3f && fabsf(alb[1] - 0.71f) < 1e-3f && fabsf(alb[2] - 0.68f) < 1e-3f,
               "albedo of the back wall %g %g %g", alb[0], alb[1], alb[2]);
    sy_mediator_rt_aovs_free(&a);

    /* light pixels: exactly its radiance where fully covered */
    uint32_t exact = 0;
    for (size_t i = 0; i < (size_t)W * W; ++i)
        exact += img.rgba[4 * i] == 17.0f && img.rgba[4 * i + 1] == 12.0f && img.rgba[4 * i + 2] == 4.0f;
    EXPECT_MSG(exact > 0, "no pixel shows the light's radiance 17 12 4 exactly");

    sy_exr_image *ref;
    MUST(sy_exr_read(rpath, &ref, err));
    EXPECT(ref->width == 256 && ref->height == 256);
    const float *rc[3] = {sy_exr_image_channel(ref, "R"), sy_exr_image_channel(ref, "G"), sy_exr_image_channel(ref, "B")};
    EXPECT(rc[0] && rc[1] && rc[2]);
    uint32_t f = 256 / W, bs = 8 / f ? 8 / f : 1; /* our pixels per reference pixel, block size in our pixels */
    double om[3] = {0, 0, 0}, rm[3] = {0, 0, 0}, block_sum = 0, noise_sum = 0;
    uint32_t blocks = 0;
    for (uint32_t by = 0; by < W; by += bs)
        for (uint32_t bx = 0; bx < W; bx += bs) {
            double o[3] = {0, 0, 0}, r[3] = {0, 0, 0}, v[3] = {0, 0, 0};
            for (uint32_t y = by; y < by + bs; ++y)
                for (uint32_t x = bx; x < bx + bs; ++x)
                    for (int c = 0; c < 3; ++c) {
                        o[c] += img.rgba[4 * ((size_t)y * W + x) + (size_t)c];
                        v[c] += var[3 * ((size_t)y * W + x) + (size_t)c];
                        for (uint32_t j = 0; j < f; ++j)
                            for (uint32_t i = 0; i < f; ++i)
                                r[c] += rc[c][(size_t)(y * f + j) * 256 + x * f + i] / (double)(f * f);
                    }
            for (int c = 0; c < 3; ++c) {
                om[c] += o[c], rm[c] += r[c];
                if (r[c] > 1e-4 * bs * bs) {
                    block_sum += fabs(o[c] - r[c]) / r[c];
                    noise_sum += sqrt(2.0 / 3.14159265358979) * sqrt(v[c]) / r[c]; /* E|N(0, v)| relative */
                    blocks++;
                }
            }
        }
    const char *dump = getenv("SY_PT_CORNELL_DUMP"); /* debugging: PNGs of ours, the reference, 4x|diff| */
    if (dump && *dump) {
        float *rf = malloc((size_t)W * W * 4 * sizeof *rf), *df = malloc((size_t)W * W * 4 * sizeof *df);
        for (uint32_t y = 0; y < W; ++y)
            for (uint32_t x = 0; x < W; ++x) {
                size_t o = (size_t)y * W + x;
                for (int c = 0; c < 3; ++c) {
                    double r = 0;
                    for (uint32_t j = 0; j < f; ++j)
                        for (uint32_t i = 0; i < f; ++i) r += rc[c][(size_t)(y * f + j) * 256 + x * f + i] / (double)(f * f);
                    rf[4 * o + c] = (float)r;
                    df[4 * o + c] = 4.0f * fabsf(img.rgba[4 * o + c] - (float)r);
                }
                rf[4 * o + 3] = df[4 * o + 3] = 1.0f;
            }
        char pth[1024];
        snprintf(pth, sizeof pth, "%s_ours.png", dump);
        MUST(sy_png_write(pth, (int)W, (int)W, img.rgba, NULL, err));
        snprintf(pth, sizeof pth, "%s_ref.png", dump);
        MUST(sy_png_write(pth, (int)W, (int)W, rf, NULL, err));
        snprintf(pth, sizeof pth, "%s_diff.png", dump);
        MUST(sy_png_write(pth, (int)W, (int)W, df, NULL, err));
        free(rf);
        free(df);
    }
    double block = block_sum / blocks, noise = noise_sum / blocks, mean_err[3];
    free(var);
    for (int c = 0; c < 3; ++c) mean_err[c] = om[c] / rm[c] - 1.0;
    printf("pathtracer cornell %ux%u, %u spp, %.1f s: mean error R %+.3f%% G %+.3f%% B %+.3f%%, 8x8-block mean "
           "relative error %.3f%% (%u block-channels; expected from our own noise alone %.3f%%)\n",
           W, W, spp, secs, 100 * mean_err[0], 100 * mean_err[1], 100 * mean_err[2], 100 * block, blocks, 100 * noise);
    double tm = full ? 0.005 : THRESH_MEAN, tb = full ? 0.02 : THRESH_BLOCK_NOISE * noise + THRESH_BLOCK_ABS;
    for (int c = 0; c < 3; ++c)
        EXPECT_MSG(fabs(mean_err[c]) < tm, "channel %d: whole-image mean differs by %.3f%% (limit %.2f%%)", c, 100 * mean_err[c],
                   100 * tm);
    EXPECT_MSG(block < tb, "block error %.3f%% (limit %.2f%%)", 100 * block, 100 * tb);

    /* light_tree (issue 39): auto (2 emissive triangles: the alias table) is bit-identical to off;
     * on (the light tree for the box's light) converges to the same reference (whole-image mean) */
    sy_layer la, lo, lt;
    render_params(scene, &info, cam, "max_depth=64,specular=0", W, 4, &la);
    render_params(scene, &info, cam, "max_depth=64,specular=0,light_tree=off", W, 4, &lo);
    EXPECT_MSG(!memcmp(la.rgba, lo.rgba, (size_t)W * W * 4 * sizeof(float)), "light_tree=auto and =off differ");
    render_params(scene, &info, cam, "max_depth=64,specular=0,light_tree=on", W, spp, &lt);
    double tmean[3] = {0, 0, 0};
    for (size_t i = 0; i < (size_t)W * W; ++i)
        for (int c = 0; c < 3; ++c) tmean[c] += lt.rgba[4 * i + (size_t)c];
    for (int c = 0; c < 3; ++c)
        EXPECT_MSG(fabs(tmean[c] / rm[c] - 1.0) < tm, "light_tree=on: channel %d's mean differs by %.3f%% (limit %.2f%%)",
                   c, 100 * (tmean[c] / rm[c] - 1.0), 100 * tm);
    printf("light_tree=on: mean error R %+.3f%% G %+.3f%% B %+.3f%%\n", 100 * (tmean[0] / rm[0] - 1.0),
           100 * (tmean[1] / rm[1] - 1.0), 100 * (tmean[2] / rm[2] - 1.0));
    sy_layer_destroy(&la);
    sy_layer_destroy(&lo);
    sy_layer_destroy(&lt);
    sy_exr_image_free(ref);
    sy_layer_destroy(&img);
    sy_context_pool_destroy(pool);
    sy_window_destroy(win);
    sy_gltf_info_free(&info);
    sy_scene_destroy(scene);
    return sy_check_finish("integration_pathtracer_cornell");
}
