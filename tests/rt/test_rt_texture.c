/* test_rt_texture.c — the ray tracers' texture look-up (backends/rt/sy_rt_texture.h): bilinear
 * taps across the edges of a texture for each wrap mode (repeat, clamp, mirror) and far outside
 * [0, 1], against the same filter written here with an independent wrap; nearest look-ups. */
#include "rt_test.h"
#include "sy_rt_texture.h"

#define W 5u

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

int main(void)
{
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
