/* test_rt_math.c — sy_rt_math.h's inverse trigonometry and the lat-long mapping built on it
 * (backends/rt internals), against libm in double precision:
 *   - sy_rt_atan2f within 4e-7 rad of atan2 over a grid of the plane with both axes, and atan2f's
 *     results bit for bit where they are exact (signed zeros: 0, -0, pi, -pi; the axes' pi/2);
 *   - sy_rt_acosf within 4.5e-7 rad of acos over [-1, 1] (a million points, the ends exact enough:
 *     acos(1) < 1e-6, acos(-1) within 1e-6 of pi); NaN for a NaN and for |c| > 1, as acosf;
 *   - sy_rt_latlong_uv: the convention (-z at u = 0.5, v = 0.5; +x at u = 0.75; +y at v = 0, -y at
 *     v = 1), u at the poles as atan2f gives it (1: the environment's top and bottom rows are read
 *     where they always were; the Whitted demo's upward floor changed 1.2 % with u = 0.5 there), u
 *     and v within [0, 1], and sy_rt_latlong_dir its inverse within 1e-6 (sin(theta) all over the
 *     sphere, the direction 4.5 degrees and more from the poles). */
#include "../support/sy_check.h"
#include "sy_rt_math.h"

#include <math.h>
#include <stdint.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static int same_bits(float a, float b)
{
    uint32_t x, y;
    memcpy(&x, &a, 4), memcpy(&y, &b, 4);
    return x == y;
}

static int test_atan2(void)
{
    double worst = 0.0;
    float wy = 0.0f, wx = 0.0f;
    for (int i = -400; i <= 400; ++i)
        for (int j = -400; j <= 400; ++j) {
            float y = (float)i * 0.01f, x = (float)j * 0.01f;
            if (i == 0 && j == 0) continue; /* (0, 0): the signed zeros below */
            double e = fabs((double)sy_rt_atan2f(y, x) - atan2((double)y, (double)x));
            if (e > worst) worst = e, wy = y, wx = x;
        }
    EXPECT_MSG(worst <= 4e-7, "atan2 error %g at (%g, %g)", worst, (double)wy, (double)wx);
    /* tiny and huge ratios: relative accuracy near 0 (the solid angle of a small triangle) */
    for (float t = 1e-30f; t < 1e-3f; t *= 10.0f) {
        double want = atan2((double)t, 2.0);
        EXPECT_MSG(fabs((double)sy_rt_atan2f(t, 2.0f) - want) <= 1e-6 * want, "atan2(%g, 2)", (double)t);
        EXPECT_NEAR(sy_rt_atan2f(1.0f, t), atan2(1.0, (double)t), 3e-7);
    }
    static const float z[2] = {0.0f, -0.0f}, one[2] = {1.0f, -1.0f};
    for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b) {
            EXPECT_MSG(same_bits(sy_rt_atan2f(z[a], z[b]), atan2f(z[a], z[b])), "atan2(%g, %g) = %g, atan2f %g",
                       (double)z[a], (double)z[b], (double)sy_rt_atan2f(z[a], z[b]), (double)atan2f(z[a], z[b]));
            EXPECT_MSG(same_bits(sy_rt_atan2f(z[a], one[b]), atan2f(z[a], one[b])), "atan2(%g, %g)", (double)z[a],
                       (double)one[b]);
            EXPECT_NEAR(sy_rt_atan2f(one[a], z[b]), atan2f(one[a], z[b]), 1e-7);
        }
    EXPECT(isnan(sy_rt_atan2f(NAN, 1.0f)) && isnan(sy_rt_atan2f(1.0f, NAN)));
    return 0;
}

static int test_acos(void)
{
    double worst = 0.0;
    float wc = 0.0f;
    for (int i = 0; i <= 1000000; ++i) {
        float c = -1.0f + 2.0f * (float)i / 1000000.0f;
        double e = fabs((double)sy_rt_acosf(c) - acos((double)c));
        if (e > worst) worst = e, wc = c;
    }
    EXPECT_MSG(worst <= 4.5e-7, "acos error %g at %g", worst, (double)wc);
    EXPECT(sy_rt_acosf(1.0f) < 1e-6f);
    EXPECT_NEAR(sy_rt_acosf(-1.0f), M_PI, 1e-6);
    EXPECT(isnan(sy_rt_acosf(NAN)) && isnan(sy_rt_acosf(1.001f)) && isnan(sy_rt_acosf(-1.001f)));
    return 0;
}

static int test_latlong(void)
{
    float u, v;
    sy_rt_latlong_uv(v3(0.0f, 0.0f, -1.0f), &u, &v);
    EXPECT_NEAR(u, 0.5, 1e-7);
    EXPECT_NEAR(v, 0.5, 1e-7);
    sy_rt_latlong_uv(v3(1.0f, 0.0f, 0.0f), &u, &v);
    EXPECT_NEAR(u, 0.75, 1e-7);
    sy_rt_latlong_uv(v3(0.0f, 1.0f, 0.0f), &u, &v);
    EXPECT_MSG(u == 1.0f && v == 0.0f, "up: u %g v %g (want 1, 0)", (double)u, (double)v);
    sy_rt_latlong_uv(v3(0.0f, -1.0f, 0.0f), &u, &v);
    EXPECT_MSG(u == 1.0f && fabsf(v - 1.0f) < 1e-6f, "down: u %g v %g (want 1, 1)", (double)u, (double)v);
    /* over the sphere: u, v inside [0, 1]; sin(theta) as the float d.y's own (acos's conditioning near
     * the poles is the input's: cos theta in float); the round trip away from the poles (there d.y's
     * rounding, 3e-8 near 1, is theta's error / sin(theta), as with libm) */
    double worst = 0.0, worst_st = 0.0;
    int outside = 0;
    for (int i = 1; i < 400; ++i) /* theta from the poles' neighbours; phi all around */
        for (int j = 0; j < 800; ++j) {
            double th = M_PI * i / 400.0, ph = 2.0 * M_PI * j / 800.0 - M_PI;
            sy_rt_v3 d = v3((float)(sin(th) * sin(ph)), (float)cos(th), (float)(-sin(th) * cos(ph)));
            sy_rt_latlong_uv(d, &u, &v);
            outside += !(u >= 0.0f && u <= 1.0f && v >= 0.0f && v <= 1.0f);
            float st;
            sy_rt_v3 e = sy_rt_latlong_dir(u, v, &st);
            double es = fabs((double)st - sin(acos((double)d.y)));
            if (es > worst_st) worst_st = es;
            double dd = fabs((double)e.x - d.x) + fabs((double)e.y - d.y) + fabs((double)e.z - d.z);
            if (i >= 10 && i <= 390 && dd > worst) worst = dd;
        }
    EXPECT_MSG(outside == 0, "%d directions mapped outside [0, 1]^2", outside);
    EXPECT_MSG(worst_st <= 1e-6, "sin(theta) error %g", worst_st);
    EXPECT_MSG(worst <= 1e-6, "round trip error %g", worst);
    return 0;
}

SY_CHECK_MAIN("rt_math", SY_TEST(test_atan2), SY_TEST(test_acos), SY_TEST(test_latlong))
