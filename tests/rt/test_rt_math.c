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
 *     sphere, the direction 4.5 degrees and more from the poles);
 *   - sy_rt_cdf_find through its guide table (sy_rt_cdf_guide) gives the index the plain binary
 *     search gives (written out here: the last i < n with cdf[i] <= u, then past empty cells) on
 *     tables of 1 to 4097 cells, uniform, random, with runs of empty cells (leading, inside,
 *     trailing), a spike holding nearly all the mass (a sun), and a last entry rounded above 1, for
 *     random u, every table value and its float neighbours, every step start k / n and its
 *     neighbours, 0, the largest float below 1, and NaN. */
#include "../support/sy_check.h"
#include "sy_rt_math.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
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

/* the binary search sy_rt_cdf_find replaces, as the environment's sampling had it */
static uint32_t cdf_find_plain(const float *cdf, uint32_t n, float u)
{
    uint32_t lo = 0, hi = n;
    while (lo + 1u < hi) {
        uint32_t mid = (lo + hi) / 2u;
        if (cdf[mid] <= u) lo = mid;
        else hi = mid;
    }
    while (lo + 1u < n && !(cdf[lo + 1u] > cdf[lo])) ++lo;
    return lo;
}

static uint32_t lcg(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return *s >> 8;
}

static int test_cdf_find(void)
{
    static const uint32_t sizes[] = {1, 2, 3, 7, 64, 1000, 4097};
    enum { KINDS = 6 };
    uint32_t seed = 12345u;
    int bad = 0, checks = 0;
    for (size_t si = 0; si < sizeof sizes / sizeof sizes[0]; ++si)
        for (int kind = 0; kind < KINDS; ++kind) {
            uint32_t n = sizes[si];
            float *cdf = malloc((n + 1u) * sizeof *cdf);
            uint32_t *g = malloc(n * sizeof *g);
            double *wt = malloc(n * sizeof *wt);
            CHECK(cdf && g && wt);
            for (uint32_t i = 0; i < n; ++i) {
                double r = (double)lcg(&seed) / 16777216.0;
                switch (kind) {
                case 0: wt[i] = 1.0; break;                                            /* uniform */
                case 1: wt[i] = r; break;                                              /* random */
                case 2: wt[i] = i < n / 3u || (i > n / 2u && i < n / 2u + 5u) ? 0.0 : r; break; /* empty runs */
                case 3: wt[i] = i == n / 2u ? 1e7 : r; break;                          /* a sun */
                case 4: wt[i] = i + 4u > n ? 0.0 : r + 0.01; break;                   /* trailing empty cells */
                default: wt[i] = i + 1u == n ? 1e-9 : 1.0; break;                      /* last entry above 1 */
                }
            }
            double tot = 0.0;
            for (uint32_t i = 0; i < n; ++i) tot += wt[i];
            if (!(tot > 0.0)) wt[n - 1u] = 1.0, tot = 1.0;
            double acc = 0.0;
            cdf[0] = 0.0f;
            for (uint32_t i = 0; i < n; ++i) acc += wt[i], cdf[i + 1u] = (float)(acc / tot);
            cdf[n] = 1.0f;
            if (kind == 5 && n > 1u) cdf[n - 1u] = nextafterf(1.0f, 2.0f); /* rounding past the end */
            sy_rt_cdf_guide(cdf, n, g);
            float qs[16];
            for (uint32_t q = 0; q < 4000u + 6u * n; ++q) {
                int nq = 0;
                if (q < 4000u) qs[nq++] = (float)lcg(&seed) / 16777216.0f;
                else {
                    uint32_t j = (q - 4000u) / 6u, m = (q - 4000u) % 6u;
                    float b = m < 3u ? cdf[j] : (float)j / (float)n;
                    qs[nq++] = b;
                    qs[nq++] = nextafterf(b, -1.0f);
                    qs[nq++] = nextafterf(b, 2.0f);
                }
                if (q == 0) qs[nq++] = 0.0f, qs[nq++] = nextafterf(1.0f, 0.0f), qs[nq++] = NAN;
                for (int t = 0; t < nq; ++t) {
                    if (!(qs[t] < 1.0f) && !isnan(qs[t])) continue; /* u in [0, 1) (and NaN) */
                    if (qs[t] < 0.0f) continue;
                    uint32_t want = cdf_find_plain(cdf, n, qs[t]), got = sy_rt_cdf_find(cdf, g, n, qs[t]);
                    ++checks;
                    if (want != got && bad++ < 5)
                        printf("n %u kind %d u %.9g: guided %u, binary search %u\n", n, kind, (double)qs[t], got, want);
                }
            }
            free(cdf), free(g), free(wt);
        }
    EXPECT_MSG(bad == 0, "%d of %d look-ups differ from the binary search", bad, checks);
    EXPECT(checks > 100000);
    return 0;
}

SY_CHECK_MAIN("rt_math", SY_TEST(test_atan2), SY_TEST(test_acos), SY_TEST(test_latlong), SY_TEST(test_cdf_find))
