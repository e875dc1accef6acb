/* test_rt_texture.c — the ray tracers' texture look-up (backends/rt/sy_rt_texture.h): bilinear
 * taps across the edges of a texture for each wrap mode (repeat, clamp, mirror) and far outside
 * [0, 1], against the same filter written here with an independent wrap; nearest look-ups; the
 * test whether a triangle of texture coordinates reads only zero texels (sy_rt_texture_region_zero,
 * the light tree's dark emitter triangles) against look-ups inside random triangles; the
 * environment light of a 1x1 texture (--env-color; read once, not per direction) against the same
 * texel in a 2x1 texture, which goes through the lat-long look-up: the same radiance and pdf bit for
 * bit in every direction, non-finite and negative texels read as 0 alike. */
#include "rt_test.h"
#include "sy_rt_lights.h"
#include "sy_rt_texture.h"

#define W 5u
#define PI_F 3.14159265358979f

/* The texel a wrap mode reads for integer texel coordinate i (written out, not shared with the
 * back-end): repeat, clamp, mirror (0 1 .. n-1 n-1 .. 1 0 0 1 ..). */
static uint32_t ref_wrap(long long i, uint32_t n, sy_rt_wrap mode)
{
    if (mode == SY_RT_WRAP_CLAMP) return i < 0 ? 0u : (i >= (long long)n ? n - 1u : (uint32_t)i);
    long long p = mode == SY_RT_WRAP_MIRROR ? 2LL * n : (long long)n;
    long long m = i;
    while (m < 0) m += p * (1 + (-m) / p);
    m %= p;
    return (uint32_t)(m < (long long)n ? m : p - 1 - m);
}

static uint32_t lcg(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return *s >> 8;
}
static float rnd(uint32_t *s) { return (float)lcg(s) / 16777216.0f; }

/* Whether any look-up of t inside triangle uv reads a non-zero colour: its corners, edge points
 * and random interior points, with the filter t has. */
static bool region_reads_nonzero(const sy_rt_texture_data *t, const float uv[3][2], uint32_t *seed)
{
    for (int i = 0; i < 400; ++i) {
        float b1, b2;
        if (i < 3) {
            b1 = i == 1, b2 = i == 2;
        } else if (i < 60) { /* along the edges */
            float f = rnd(seed);
            int e = i % 3;
            b1 = e == 0 ? f : (e == 1 ? 1.0f - f : 0.0f), b2 = e == 0 ? 0.0f : (e == 1 ? f : 1.0f - f);
        } else {
            b1 = rnd(seed), b2 = rnd(seed);
            if (b1 + b2 > 1.0f) b1 = 1.0f - b1, b2 = 1.0f - b2;
        }
        float b0 = 1.0f - b1 - b2, out[4];
        float u = b0 * uv[0][0] + b1 * uv[1][0] + b2 * uv[2][0], v = b0 * uv[0][1] + b1 * uv[1][1] + b2 * uv[2][1];
        sy_rt_texture_sample(t, u, v, out);
        if (out[0] != 0.0f || out[1] != 0.0f || out[2] != 0.0f) return true;
    }
    return false;
}

/* Region tests on an RGBA8 texture of w x h texels, black but for `lit` random texels (and one
 * with only alpha set), every wrap mode and filter: a triangle any look-up of which reads a
 * non-zero colour is never called zero; some are (the table is not "never zero"). */
static void test_region_zero(uint32_t w, uint32_t h, uint32_t lit, uint32_t seed)
{
    uint8_t *px = calloc((size_t)w * h * 4u, 1);
    if (!px) return;
    for (uint32_t i = 0; i < lit; ++i) {
        size_t y = lcg(&seed) % h, x = lcg(&seed) % w;
        px[(y * w + x) * 4u + lcg(&seed) % 3u] = (uint8_t)(1u + lcg(&seed) % 255u);
    }
    px[((size_t)(h / 2u) * w + w / 2u) * 4u + 3u] = 255u; /* alpha only */
    static const sy_rt_wrap modes[3] = {SY_RT_WRAP_REPEAT, SY_RT_WRAP_CLAMP, SY_RT_WRAP_MIRROR};
    for (int mi = 0; mi < 3; ++mi)
        for (int f = 0; f < 2; ++f) {
            sy_rt_texture_data t = {.width = w, .height = h, .channels = 4, .format = SY_RT_TEXEL_UNORM8, .pixels = px,
                                    .wrap_s = modes[mi], .wrap_t = modes[(mi + 1) % 3],
                                    .filter = f ? SY_RT_FILTER_NEAREST : SY_RT_FILTER_LINEAR};
            uint32_t zero = 0, wrong = 0, tris = 3000;
            for (uint32_t k = 0; k < tris; ++k) {
                float uv[3][2], size = k % 3u == 0 ? 0.3f : (k % 3u == 1 ? 0.02f : 0.002f);
                float cu = rnd(&seed) * 4.0f - 2.0f, cv = rnd(&seed) * 4.0f - 2.0f;
                for (int c = 0; c < 3; ++c) uv[c][0] = cu + size * rnd(&seed), uv[c][1] = cv + size * rnd(&seed);
                bool z = sy_rt_texture_region_zero(&t, (const float(*)[2])uv);
                zero += z;
                if (z && region_reads_nonzero(&t, (const float(*)[2])uv, &seed) && wrong++ == 0)
                    EXPECT_MSG(false, "%ux%u, wrap %d/%d, %s: triangle (%g,%g) (%g,%g) (%g,%g) called zero, reads a non-zero texel",
                               w, h, (int)t.wrap_s, (int)t.wrap_t, f ? "nearest" : "bilinear", uv[0][0], uv[0][1], uv[1][0],
                               uv[1][1], uv[2][0], uv[2][1]);
            }
            EXPECT_MSG(wrong == 0, "%ux%u: %u triangles wrongly called zero", w, h, wrong);
            EXPECT_MSG(zero > tris / 10u, "%ux%u, wrap %d/%d: only %u of %u triangles called zero (mostly black texture)", w, h,
                       (int)t.wrap_s, (int)t.wrap_t, zero, tris);
            float nan_uv[3][2] = {{NAN, 0.0f}, {0.0f, 0.0f}, {0.0f, 0.0f}};
            EXPECT_MSG(!sy_rt_texture_region_zero(&t, (const float(*)[2])nan_uv), "a non-finite coordinate is never zero");
            free(t.zero_sat);
        }
    free(px);
}

/* A device whose environment light is a w x 1 float texture of one colour, at intensity k. */
static sy_rt_device *env_device(uint32_t w, const float c[3], float k, sy_rt_env *env)
{
    sy_rt_device *dev = rt_device();
    float px[2 * 3];
    for (uint32_t i = 0; i < w; ++i) px[3 * i] = c[0], px[3 * i + 1] = c[1], px[3 * i + 2] = c[2];
    sy_rt_texture_desc td = {.width = w, .height = 1, .channels = 3, .format = SY_RT_TEXEL_FLOAT32, .pixels = px};
    sy_rt_texture tex;
    MUST(sy_rt_texture_create(dev, &td, &tex));
    MUST(sy_rt_set_environment(dev, tex, k));
    MUST(sy_rt_commit(dev));
    sy_rt_env_get(dev, env);
    return dev;
}

static void test_env_constant(void)
{
    const float colours[][3] = {{0.25f, 0.5f, 1.0f}, {1.0f / 3.0f, 0.1f, 7.77f}, {2.0f, -1.0f, 0.3f},
                                {INFINITY, 1.0f, 0.5f}, {NAN, 0.0f, 1.0f}};
    for (size_t ci = 0; ci < sizeof colours / sizeof colours[0]; ++ci) {
        const float *c = colours[ci];
        bool finite = isfinite(c[0]) && isfinite(c[1]) && isfinite(c[2]);
        sy_rt_env one, two;
        sy_rt_device *d1 = env_device(1u, c, 1.7f, &one), *d2 = env_device(2u, c, 1.7f, &two);
        EXPECT_MSG(one.mode == 2 && two.mode == 2, "colour %zu: environment light present", ci);
        uint32_t seed = 99u + (uint32_t)ci;
        int bad_eval = 0, bad_pdf = 0;
        for (int i = 0; i < 4000; ++i) {
            sy_rt_v3 d;
            if (i < 6) { /* the poles and the seam of atan2 */
                const float ax[6][3] = {{0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {-1, 0, 0}};
                d = v3(ax[i][0], ax[i][1], ax[i][2]);
            } else {
                float z = 2.0f * rnd(&seed) - 1.0f, ph = 2.0f * PI_F * rnd(&seed), r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
                d = v3(r * cosf(ph), z, r * sinf(ph));
            }
            sy_rt_v3 a = sy_rt_env_eval(&one, d), b = sy_rt_env_eval(&two, d);
            if (memcmp(&a, &b, sizeof a) != 0) ++bad_eval;
            if (finite && sy_rt_env_pdf(&one, d) != sy_rt_env_pdf(&two, d)) ++bad_pdf;
        }
        sy_rt_v3 a = sy_rt_env_eval(&one, v3(0.0f, 0.0f, -1.0f));
        float want[3];
        for (int k = 0; k < 3; ++k) want[k] = isfinite(c[0]) && isfinite(c[1]) && isfinite(c[2]) ? fmaxf(c[k] * 1.7f, 0.0f) : 0.0f;
        EXPECT_MSG(a.x == want[0] && a.y == want[1] && a.z == want[2], "colour %zu: radiance %g %g %g, want %g %g %g", ci,
                   a.x, a.y, a.z, want[0], want[1], want[2]);
        EXPECT_MSG(bad_eval == 0, "colour %zu: 1x1 and 2x1 environments differ in %d of 4000 directions", ci, bad_eval);
        EXPECT_MSG(bad_pdf == 0, "colour %zu: 1x1 and 2x1 pdfs differ in %d of 4000 directions", ci, bad_pdf);
        sy_rt_device_destroy(d1);
        sy_rt_device_destroy(d2);
    }
}

int main(void)
{
    test_env_constant();
    test_region_zero(37, 29, 6, 1u);      /* blocks of 8 texels, a partial block at each edge */
    test_region_zero(4500, 40, 300, 2u);  /* wider than 512 blocks of 8: blocks of 16 */
    float px[W] = {0.0f, 10.0f, 20.0f, 30.0f, 40.0f}; /* one row, one channel */
    static const sy_rt_wrap modes[3] = {SY_RT_WRAP_REPEAT, SY_RT_WRAP_CLAMP, SY_RT_WRAP_MIRROR};
    static const char *const names[3] = {"repeat", "clamp", "mirror"};
    const float us[] = {0.0f, 0.05f, 0.1f, 0.5f, 0.95f, 0.99f, 1.0f, 1.05f, -0.05f, -0.95f, -1.0f, -2.3f, 3.7f, 1234.56f, -777.77f};
    for (int mi = 0; mi < 3; ++mi) {
        sy_rt_texture_data t = {.width = W, .height = 1, .channels = 1, .format = SY_RT_TEXEL_FLOAT32, .pixels = px,
                                .wrap_s = modes[mi], .wrap_t = modes[mi], .filter = SY_RT_FILTER_LINEAR};
        for (size_t k = 0; k < sizeof us / sizeof us[0]; ++k) {
            double x = (double)us[k] * W - 0.5, x0 = floor(x);
            float fx = (float)(x - x0);
            float a = px[ref_wrap((long long)x0, W, modes[mi])], b = px[ref_wrap((long long)x0 + 1, W, modes[mi])];
            float want = a + (b - a) * fx, out[4];
            sy_rt_texture_sample(&t, us[k], 0.5f, out);
            EXPECT_MSG(fabsf(out[0] - want) <= 1e-3f, "%s, bilinear at u = %g: %g (want %g)", names[mi], us[k], out[0], want);
            EXPECT_MSG(out[0] == out[1] && out[0] == out[2] && out[3] == 1.0f, "%s at u = %g: grey replicated, alpha 1", names[mi], us[k]);
            t.filter = SY_RT_FILTER_NEAREST;
            sy_rt_texture_sample(&t, us[k], 0.5f, out);
            float wn = px[ref_wrap((long long)floor((double)us[k] * W), W, modes[mi])];
            EXPECT_MSG(out[0] == wn, "%s, nearest at u = %g: %g (want %g)", names[mi], us[k], out[0], wn);
            t.filter = SY_RT_FILTER_LINEAR;
        }
    }
    return sy_check_finish("test_rt_texture");
}
