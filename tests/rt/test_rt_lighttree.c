/* test_rt_lighttree.c — the light tree (backends/rt/sy_rt_lighttree.h) on its own and through the
 * ray tracers' light_tree setting:
 *   - selection pdf: over 3000 random lights (one- and double-sided triangles, point and spot
 *     lights, two directional lights, and degenerate ones: zero, negative and NaN power, a NaN
 *     box), the pdfs of all lights sum to 1 (within 1e-3) at 64 random shading points with and
 *     without a normal; left-out lights have pdf 0 and are counted;
 *   - sy_rt_lighttree_importance4 equals the scalar importance bit for bit, lane by lane, for a
 *     built tree's nodes and lights from points outside and inside their boxes;
 *   - counting: over 60 lights, 2^18 stratified picks at each of 8 points choose every light as
 *     often as its pdf says (within 0.002 absolute), and every pick's pdf equals
 *     sy_rt_lighttree_pdf of its light exactly; a top light's pdf is its importance over the top
 *     level's total (sy_rt_lighttree_total_importance);
 *   - refit: one light's new power is one changed light, and the pdfs still sum to 1;
 *   - 10^6 lights build in bounded memory (under 200 bytes per light), and a max_bytes below that
 *     is refused;
 *   - through sy_rt_render: a floor lit by 240 small emissive triangles and 24 point lights; the path
 *     tracer with light_tree=on and =off converge to the same image (relMSE of the two 512-spp
 *     renders below 0.01, means within 2 %), also under an environment map (the tree and the
 *     environment share the light samples point by point: means within 1 %), and Whitted's means
 *     agree within 5 %; on a scene with few lights AUTO is bit-identical to OFF (both tracers); a zero-power light and a zero-area
 *     emitter are reported by name in sy_rt_stats. */
#include "rt_test.h"
#include "sy_rt_lighttree.h"

#include <stdint.h>
#include <time.h>

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static uint32_t rng_state = 12345u;
static float frand(void)
{
    rng_state = rng_state * 1664525u + 1013904223u;
    return (float)(rng_state >> 8) * (1.0f / 16777216.0f);
}

static void random_light(sy_rt_lt_light *l, uint32_t i)
{
    memset(l, 0, sizeof *l);
    float c[3] = {frand() * 20.0f - 10.0f, frand() * 4.0f, frand() * 20.0f - 10.0f};
    uint32_t kind = i % 5u;
    float ext = kind < 2u ? 0.3f * frand() : 0.0f;
    for (int k = 0; k < 3; ++k) l->b.lo[k] = c[k] - ext, l->b.hi[k] = c[k] + ext;
    sy_rt_v3 ax = v3_normalize(v3(frand() - 0.5f, frand() - 0.5f, frand() - 0.5f));
    l->b.axis[0] = ax.x, l->b.axis[1] = ax.y, l->b.axis[2] = ax.z;
    l->b.power = 0.01f + 10.0f * frand() * frand();
    switch (kind) {
    case 0: l->b.theta_o = 0.0f, l->b.theta_e = 1.5707964f; break;         /* one-sided triangle */
    case 1: l->b.theta_o = 3.1415927f, l->b.theta_e = 1.5707964f; break;   /* double-sided */
    case 2: l->b.theta_o = 3.1415927f, l->b.theta_e = 1.5707964f; break;   /* point */
    default: l->b.theta_o = 0.2f + frand(), l->b.theta_e = 0.0f; break;    /* spot */
    }
}

static sy_rt_v3 random_point(void) { return v3(frand() * 24.0f - 12.0f, frand() * 5.0f - 0.5f, frand() * 24.0f - 12.0f); }

static void test_pdf_sums(void)
{
    const uint32_t n = 3000;
    sy_rt_lt_light *l = malloc(n * sizeof *l);
    for (uint32_t i = 0; i < n; ++i) random_light(&l[i], i);
    l[7].distant = true, l[11].distant = true; /* two directional lights */
    l[20].b.power = 0.0f;
    l[21].b.power = -1.0f;
    l[22].b.power = NAN;
    l[23].b.lo[0] = NAN;
    l[24].dark = true; /* valid records the caller knows emit nothing (black texels): out, not counted */
    l[25].dark = true, l[25].b.power = 0.0f;
    sy_rt_lighttree t;
    bool oom;
    EXPECT_MSG(sy_rt_lighttree_build(&t, l, n, 0, &oom), "build of %u lights", n);
    EXPECT_MSG(t.skipped == 4u && t.first_skipped == 20u, "skipped %u (4), first %u (20)", t.skipped, t.first_skipped);
    EXPECT_MSG(t.top_count == 2u, "directional lights %u (2)", t.top_count);
    double worst = 0.0;
    for (int k = 0; k < 64; ++k) {
        sy_rt_v3 p = random_point(), nrm = k % 2 ? v3_normalize(v3(frand() - 0.5f, 1.0f, frand() - 0.5f)) : v3(0, 0, 0);
        double s = 0.0;
        for (uint32_t i = 0; i < n; ++i) s += sy_rt_lighttree_pdf(&t, p, nrm, i);
        worst = fmax(worst, fabs(s - 1.0));
        for (uint32_t i = 20; i < 26; ++i) EXPECT_MSG(sy_rt_lighttree_pdf(&t, p, nrm, i) == 0.0f, "left-out light %u has pdf 0", i);
    }
    EXPECT_MSG(worst < 1e-3, "the pdfs over all lights sum to 1 at every point (worst |sum - 1| %.2e)", worst);
    /* refit: one light's power */
    l[100].b.power *= 3.0f;
    uint32_t changed = 0;
    EXPECT_MSG(sy_rt_lighttree_refit(&t, l, n, &changed) && changed == 1u, "refit: %u changed (1)", changed);
    sy_rt_v3 p = v3(1.0f, 0.5f, 2.0f);
    double s = 0.0;
    for (uint32_t i = 0; i < n; ++i) s += sy_rt_lighttree_pdf(&t, p, v3(0, 1, 0), i);
    EXPECT_MSG(fabs(s - 1.0) < 1e-3, "after refit the pdfs sum to %.6f (1)", s);
    /* a light that becomes degenerate needs a rebuild */
    l[101].b.power = 0.0f;
    EXPECT_MSG(!sy_rt_lighttree_refit(&t, l, n, &changed), "refit refuses a light that left the set");
    l[101].b.power = 1.0f, l[101].dark = true;
    EXPECT_MSG(!sy_rt_lighttree_refit(&t, l, n, &changed), "refit refuses a light that turned dark");
    l[101].dark = false, l[24].dark = false;
    EXPECT_MSG(!sy_rt_lighttree_refit(&t, l, n, &changed), "refit refuses a dark light that turned lit");
    l[24].dark = true;
    l[32].top = true;
    EXPECT_MSG(!sy_rt_lighttree_refit(&t, l, n, &changed), "refit refuses a light moved beside the root");
    l[32].top = false;
    EXPECT_MSG(sy_rt_lighttree_refit(&t, l, n, &changed), "refit takes the same dark lights");
    for (int k = 0; k < 2000; ++k) {
        float pdf;
        uint32_t pick = sy_rt_lighttree_pick(&t, random_point(), v3(0, 0, 0), frand(), &pdf);
        EXPECT_MSG(pick != 24u && pick != 25u, "a dark light is never picked (%u)", pick);
    }
    sy_rt_lighttree_free(&t);
    free(l);
}

/* sy_rt_lighttree_importance4 (the walk's steps) gives each lane the scalar function's value bit
 * for bit (the root's step and the tests' reference), for the nodes and lights of a built tree
 * (their cosines filled by the build), from points outside, on and inside their boxes, with and
 * without a surface normal. */
static void test_importance4_exact(void)
{
    const uint32_t n = 3000;
    sy_rt_lt_light *l = malloc(n * sizeof *l);
    for (uint32_t i = 0; i < n; ++i) random_light(&l[i], i);
    sy_rt_lighttree t;
    bool oom;
    EXPECT_MSG(sy_rt_lighttree_build(&t, l, n, 0, &oom), "build of %u lights", n);
    uint32_t total = t.node_count + n, compared = 0, differ = 0, nonzero = 0;
    for (int k = 0; k < 48; ++k) {
        sy_rt_v3 nrm = k % 3 == 0 ? v3(0, 0, 0) : v3_normalize(v3(frand() - 0.5f, frand() - 0.5f, frand() - 0.5f));
        sy_rt_v3 pk = random_point();
        for (uint32_t i = 0; i + 4u <= total; i += 4u) {
            const sy_rt_lt_bounds *b[4];
            for (uint32_t j = 0; j < 4u; ++j)
                b[j] = i + j < t.node_count ? &t.nodes[i + j].b : &t.prims[i + j - t.node_count];
            /* every third group from the centre of its first box (inside it, or on a flat one) */
            sy_rt_v3 p = k % 4 == 3 ? v3(0.5f * (b[0]->lo[0] + b[0]->hi[0]), 0.5f * (b[0]->lo[1] + b[0]->hi[1]),
                                         0.5f * (b[0]->lo[2] + b[0]->hi[2]))
                                    : pk;
            float w[4];
            sy_rt_lighttree_importance4(b, p, nrm, w);
            for (uint32_t j = 0; j < 4u; ++j) {
                float s1 = sy_rt_lighttree_importance(b[j], p, nrm);
                compared++;
                if (memcmp(&s1, &w[j], sizeof s1) != 0) {
                    if (differ++ < 5u) fprintf(stderr, "  lane %u: %.9g, scalar %.9g\n", j, (double)w[j], (double)s1);
                }
                nonzero += s1 > 0.0f;
            }
        }
    }
    EXPECT_MSG(differ == 0u, "importance4 equals the scalar importance bit for bit (%u of %u differ)", differ, compared);
    EXPECT_MSG(nonzero > compared / 4u && nonzero < compared, "both zero and positive importances compared (%u of %u positive)",
               nonzero, compared);
    sy_rt_lighttree_free(&t);
    free(l);
}

static void test_counting(void)
{
    const uint32_t n = 60, picks = 1u << 18;
    sy_rt_lt_light l[60];
    for (uint32_t i = 0; i < n; ++i) random_light(&l[i], i);
    l[3].distant = true;
    l[7].top = true, l[12].top = true; /* two point lights beside the root */
    sy_rt_lighttree t;
    bool oom;
    EXPECT_MSG(sy_rt_lighttree_build(&t, l, n, 0, &oom), "build of 60 lights");
    EXPECT_MSG(t.top_count == 3u && t.top_local[t.light_top[7]] && !t.top_local[t.light_top[3]],
               "beside the root: the directional light and the two marked point lights (%u)", t.top_count);
    uint32_t *count = calloc(n, sizeof *count);
    uint32_t mismatches = 0;
    double worst = 0.0;
    for (int k = 0; k < 8; ++k) {
        sy_rt_v3 p = random_point(), nrm = k % 2 ? v3(0, 1, 0) : v3(0, 0, 0);
        memset(count, 0, n * sizeof *count);
        for (uint32_t j = 0; j < picks; ++j) {
            float pdf;
            uint32_t li = sy_rt_lighttree_pick(&t, p, nrm, ((float)j + 0.5f) / (float)picks, &pdf);
            if (li >= n) {
                mismatches++;
                continue;
            }
            count[li]++;
            if (pdf != sy_rt_lighttree_pdf(&t, p, nrm, li)) mismatches++;
        }
        for (uint32_t i = 0; i < n; ++i)
            worst = fmax(worst, fabs((double)count[i] / picks - sy_rt_lighttree_pdf(&t, p, nrm, i)));
        /* a top point light against the root: their importances' ratio, each by its own bounds */
        float i7 = sy_rt_lighttree_importance(&t.top_b[t.light_top[7]], p, nrm);
        float ir = sy_rt_lighttree_importance(&t.nodes[0].b, p, nrm);
        double want = (double)i7 / ir;
        if (ir > 0.0f && i7 > 0.0f) {
            double root_share = 0.0; /* the root's probability: the sum over the tree's lights */
            for (uint32_t i = 0; i < n; ++i)
                if (i != 3u && i != 7u && i != 12u) root_share += sy_rt_lighttree_pdf(&t, p, nrm, i);
            double ratio = sy_rt_lighttree_pdf(&t, p, nrm, 7) / root_share;
            EXPECT_MSG(fabs(ratio / want - 1.0) < 1e-3, "top point light to root: %.6f (its importance over the root's %.6f)",
                       ratio, want);
            /* the total the path tracer weighs the environment against: the top level's sum */
            double total = sy_rt_lighttree_total_importance(&t, p, nrm);
            double want7 = (double)i7 / total, got7 = sy_rt_lighttree_pdf(&t, p, nrm, 7);
            EXPECT_MSG(fabs(got7 / want7 - 1.0) < 1e-5, "total importance %.6g: top point light's pdf %.6g, its share %.6g",
                       total, got7, want7);
        }
    }
    EXPECT_MSG(mismatches == 0u, "every pick returns a light whose pdf equals sy_rt_lighttree_pdf (%u mismatches)", mismatches);
    EXPECT_MSG(worst < 0.002, "pick frequencies match the pdfs (worst difference %.5f)", worst);
    free(count);
    sy_rt_lighttree_free(&t);
}

static void test_million(void)
{
    const uint32_t n = 1000000;
    sy_rt_lt_light *l = malloc((size_t)n * sizeof *l);
    if (!l) exit(1);
    for (uint32_t i = 0; i < n; ++i) random_light(&l[i], i);
    sy_rt_lighttree t;
    bool oom;
    double t0 = now_s();
    clock_t c0 = clock();
    EXPECT_MSG(sy_rt_lighttree_build(&t, l, n, 0, &oom), "build of 10^6 lights");
    printf("10^6 lights: built in %.2f s wall, %.2f s CPU (informational), %.1f MB, %u nodes, depth %u\n", now_s() - t0,
           (double)(clock() - c0) / CLOCKS_PER_SEC, (double)t.bytes / 1048576.0, t.node_count, t.depth);
    EXPECT_MSG(t.bytes < 200u * (size_t)n, "10^6 lights hold %zu bytes (< 200 per light), depth %u", t.bytes, t.depth);
    EXPECT_MSG(t.depth <= 128u, "depth %u bounded", t.depth);
    float pdf;
    uint32_t li = sy_rt_lighttree_pick(&t, v3(0, 1, 0), v3(0, 1, 0), 0.37f, &pdf);
    EXPECT_MSG(li < n && pdf > 0.0f && pdf == sy_rt_lighttree_pdf(&t, v3(0, 1, 0), v3(0, 1, 0), li), "a pick among 10^6");
    size_t bytes = t.bytes;
    sy_rt_lighttree_free(&t);
    EXPECT_MSG(!sy_rt_lighttree_build(&t, l, n, bytes / 2u, &oom) && !oom, "a limit of half that is refused");
    sy_rt_lighttree_free(&t);
    free(l);
}

/* >>through the ray tracers */

/* A floor (z = 0, half-size 6, albedo 0.7), 240 small emissive triangles facing down at heights
 * 1.5 .. 2.5 of varied radiance, 24 point lights of varied intensity, one occluding quad. */
static sy_rt_device *many_scene(sy_rt_camera *cam)
{
    sy_rt_device *dev = rt_device();
    float xf[16];
    rt_translation(xf, 0, 0, 0);
    sy_rt_mesh quad = rt_quad(dev, 6.0f);
    rt_place(dev, quad, xf, rt_lambert(dev, 0.7f, 0.7f, 0.7f), 0);
    /* the occluder: a quad at height 0.8 */
    rt_translation(xf, 0.5f, 0.5f, 0.8f);
    rt_place(dev, rt_quad(dev, 0.8f), xf, rt_lambert(dev, 0.5f, 0.5f, 0.5f), 0);
    /* emitters: triangles facing -Z (clockwise seen from +Z) */
    const uint32_t ne = 240;
    float *pos = malloc(9 * sizeof(float) * ne);
    uint32_t *idx = malloc(3 * sizeof(uint32_t) * ne);
    rng_state = 777u;
    for (uint32_t i = 0; i < ne; ++i) {
        float cx = frand() * 10.0f - 5.0f, cy = frand() * 10.0f - 5.0f, cz = 1.5f + frand(), s = 0.08f;
        float v[9] = {cx, cy, cz, cx, cy + s, cz, cx + s, cy, cz};
        memcpy(pos + 9 * i, v, sizeof v);
        idx[3 * i] = 3 * i, idx[3 * i + 1] = 3 * i + 1, idx[3 * i + 2] = 3 * i + 2;
    }
    sy_rt_mesh em = rt_mesh_take(dev, pos, idx, 3 * ne, ne);
    rt_translation(xf, 0, 0, 0);
    rt_place(dev, em, xf, rt_emitter(dev, 40.0f, 30.0f, 20.0f), 0);
    for (uint32_t i = 0; i < 24; ++i) {
        sy_rt_light_desc ld = {.type = SY_RT_LIGHT_POINT, .color = {1, 1, 1}, .intensity = 0.05f + 2.0f * frand() * frand(),
                               .position = {frand() * 10.0f - 5.0f, frand() * 10.0f - 5.0f, 0.5f + frand()}};
        sy_rt_light lh;
        MUST(sy_rt_light_create(dev, &ld, &lh));
    }
    MUST(sy_rt_commit(dev));
    *cam = rt_camera(8.0f, 0.7f);
    return dev;
}

static void render_mean(sy_rt_device *dev, const sy_rt_camera *cam, sy_rt_integrator integ, sy_rt_light_tree_mode mode,
                        uint32_t spp, float **rgba_out, double *mean)
{
    const uint32_t w = 48, h = 48;
    sy_rt_render_desc d = rt_desc(integ, w, h);
    d.light_tree = mode;
    d.seed = 3u;
    sy_rt_accum *acc = NULL;
    if (integ == SY_RT_INTEGRATOR_PATHTRACER) {
        MUST(sy_rt_accum_create(dev, w, h, &acc));
        d.accum = acc;
        d.samples = spp;
    } else {
        d.pixel_samples = 4;
        d.area_light_samples = 64;
    }
    float *depth;
    rt_render(dev, cam, &d, rgba_out, &depth);
    free(depth);
    sy_rt_accum_destroy(acc);
    double s = 0.0;
    for (uint32_t i = 0; i < w * h; ++i) s += (*rgba_out)[4 * i] + (*rgba_out)[4 * i + 1] + (*rgba_out)[4 * i + 2];
    *mean = s / (3.0 * w * h);
}

static double rel_mse(const float *a, const float *ref, uint32_t n)
{
    double s = 0.0;
    for (uint32_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c) {
            double r = ref[4 * i + c], d = a[4 * i + c] - r;
            s += d * d / (r * r + 1e-2);
        }
    return s / (3.0 * n);
}

static void test_render_converges(void)
{
    sy_rt_camera cam;
    sy_rt_device *dev = many_scene(&cam);
    float *on, *off;
    double m_on, m_off;
    render_mean(dev, &cam, SY_RT_INTEGRATOR_PATHTRACER, SY_RT_LIGHT_TREE_ON, 512, &on, &m_on);
    render_mean(dev, &cam, SY_RT_INTEGRATOR_PATHTRACER, SY_RT_LIGHT_TREE_OFF, 512, &off, &m_off);
    double e = rel_mse(on, off, 48 * 48);
    EXPECT_MSG(e < 0.01, "path tracer: the tree's image matches the alias table's (relMSE %.5f < 0.01)", e);
    EXPECT_MSG(rt_near(m_on, m_off, 0.02), "path tracer: means %.5f (tree) and %.5f (alias) within 2 %%", m_on, m_off);
    sy_rt_stats st;
    sy_rt_device_stats(dev, &st);
    EXPECT_MSG(st.light_tree_lights == 264u && st.light_tree_builds == 1u && st.light_tree_bytes > 0u,
           "stats: %u lights in the tree (264), %llu builds, %llu bytes", st.light_tree_lights,
           (unsigned long long)st.light_tree_builds, (unsigned long long)st.light_tree_bytes);
    free(on), free(off);
    /* with an environment (a map brighter toward one side): the tree and the environment share the
     * light samples by env_share, point by point, and the MIS weights of BSDF rays that hit an
     * emitter or escape use the previous vertex's shares */
    float env_px[16 * 8 * 3];
    for (int k = 0; k < 16 * 8; ++k)
        env_px[3 * k] = 0.05f + 0.1f * (float)(k % 16), env_px[3 * k + 1] = 0.4f, env_px[3 * k + 2] = 0.2f + 0.05f * (float)(k / 16);
    sy_rt_texture_desc td = {.width = 16, .height = 8, .channels = 3, .format = SY_RT_TEXEL_FLOAT32, .pixels = env_px};
    sy_rt_texture tex;
    MUST(sy_rt_texture_create(dev, &td, &tex));
    MUST(sy_rt_set_environment(dev, tex, 1.0f));
    MUST(sy_rt_commit(dev));
    render_mean(dev, &cam, SY_RT_INTEGRATOR_PATHTRACER, SY_RT_LIGHT_TREE_ON, 512, &on, &m_on);
    render_mean(dev, &cam, SY_RT_INTEGRATOR_PATHTRACER, SY_RT_LIGHT_TREE_OFF, 512, &off, &m_off);
    e = rel_mse(on, off, 48 * 48);
    EXPECT_MSG(e < 0.01, "path tracer with an environment: the tree's image matches the alias table's (relMSE %.5f < 0.01)", e);
    EXPECT_MSG(rt_near(m_on, m_off, 0.01), "path tracer with an environment: means %.5f (tree) and %.5f (alias) within 1 %%",
               m_on, m_off);
    printf("with an environment: relMSE %.5f, means %.5f (tree) %.5f (alias)\n", e, m_on, m_off);
    free(on), free(off);
    MUST(sy_rt_set_environment(dev, (sy_rt_texture){0}, 0.0f));
    MUST(sy_rt_commit(dev));
    render_mean(dev, &cam, SY_RT_INTEGRATOR_WHITTED, SY_RT_LIGHT_TREE_ON, 0, &on, &m_on);
    render_mean(dev, &cam, SY_RT_INTEGRATOR_WHITTED, SY_RT_LIGHT_TREE_OFF, 0, &off, &m_off);
    EXPECT_MSG(rt_near(m_on, m_off, 0.05), "Whitted: means %.5f (tree) and %.5f (alias + every point light) within 5 %%",
           m_on, m_off);
    free(on), free(off);
    sy_rt_device_destroy(dev);
}

static void test_auto_is_off_with_few_lights(void)
{
    sy_rt_device *dev = rt_device();
    float xf[16];
    rt_translation(xf, 0, 0, 0);
    rt_place(dev, rt_quad(dev, 3.0f), xf, rt_lambert(dev, 0.7f, 0.6f, 0.5f), 0);
    rt_translation(xf, 0.3f, 0.2f, 1.5f);
    float flip[16];
    rt_identity(flip);
    flip[5] = -1.0f, flip[10] = -1.0f, flip[12] = 0.3f, flip[13] = 0.2f, flip[14] = 1.5f; /* facing -Z */
    rt_place(dev, rt_quad(dev, 0.3f), flip, rt_emitter(dev, 8.0f, 8.0f, 8.0f), 0);
    sy_rt_light_desc ld = {.type = SY_RT_LIGHT_POINT, .color = {1, 1, 1}, .intensity = 1.0f, .position = {-1, 0, 1}};
    sy_rt_light lh;
    MUST(sy_rt_light_create(dev, &ld, &lh));
    MUST(sy_rt_commit(dev));
    sy_rt_camera cam = rt_camera(5.0f, 0.6f);
    for (int k = 0; k < 2; ++k) {
        sy_rt_integrator integ = k ? SY_RT_INTEGRATOR_WHITTED : SY_RT_INTEGRATOR_PATHTRACER;
        float *a, *b;
        double ma, mb;
        render_mean(dev, &cam, integ, SY_RT_LIGHT_TREE_AUTO, 8, &a, &ma);
        render_mean(dev, &cam, integ, SY_RT_LIGHT_TREE_OFF, 8, &b, &mb);
        EXPECT_MSG(!memcmp(a, b, 48u * 48u * 4u * sizeof(float)), "%s: AUTO with 3 lights is bit-identical to OFF",
               k ? "Whitted" : "path tracer");
        free(a), free(b);
    }
    sy_rt_stats st;
    sy_rt_device_stats(dev, &st);
    EXPECT_MSG(st.light_tree_builds == 0u, "no tree was built for 3 lights (%llu builds)", (unsigned long long)st.light_tree_builds);
    /* degenerate emitters: a zero-intensity light and a zero-area emissive triangle, named */
    sy_rt_light_desc dark = {.type = SY_RT_LIGHT_POINT, .color = {1, 1, 1}, .intensity = 0.0f, .position = {0, 0, 1}};
    sy_rt_light dl;
    MUST(sy_rt_light_create(dev, &dark, &dl));
    float *pos = malloc(9 * sizeof(float));
    uint32_t *idx = malloc(3 * sizeof(uint32_t));
    float v[9] = {0, 0, 1, 1, 0, 1, 2, 0, 1}; /* collinear */
    memcpy(pos, v, sizeof v);
    idx[0] = 0, idx[1] = 1, idx[2] = 2;
    rt_translation(xf, 0, 0, 0);
    rt_place(dev, rt_mesh_take(dev, pos, idx, 3, 1), xf, rt_emitter(dev, 1, 1, 1), 0);
    MUST(sy_rt_commit(dev));
    float *a;
    double ma;
    render_mean(dev, &cam, SY_RT_INTEGRATOR_PATHTRACER, SY_RT_LIGHT_TREE_ON, 4, &a, &ma);
    free(a);
    sy_rt_device_stats(dev, &st);
    char want[32];
    snprintf(want, sizeof want, "0x%08x", dl.id);
    EXPECT_MSG(st.light_warnings == 2u && strstr(st.light_warning, want),
           "2 emitters left out (%u), the last message names light %s: %s", st.light_warnings, want, st.light_warning);
    EXPECT_MSG(isfinite(ma) && ma > 0.0, "the render with them is finite (%g)", ma);
    sy_rt_device_destroy(dev);
}

int main(void)
{
    test_pdf_sums();
    test_importance4_exact();
    test_counting();
    test_million();
    test_render_converges();
    test_auto_is_off_with_few_lights();
    return sy_check_finish("rt_lighttree");
}
