/* test_post.c — the display post-process chain (core/sy_post.h): tone-mapping operators, exposure
 * and sRGB on premultiplied layers, and the red-cyan anaglyph. Expected values are computed here
 * independently in double precision. */
#include "../support/sy_check.h"
#include "sy_post.h"

static double srgb_ref(double x)
{
    if (x <= 0.0) return 0.0;
    if (x >= 1.0) return 1.0;
    return x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1.0 / 2.4) - 0.055;
}

static int test_operators(void)
{
    CHECK_NEAR(sy_tonemap_apply(SY_TONEMAP_CLAMP, 0.25f), 0.25, 1e-7);
    CHECK_NEAR(sy_tonemap_apply(SY_TONEMAP_CLAMP, 3.0f), 1.0, 0);
    CHECK_NEAR(sy_tonemap_apply(SY_TONEMAP_REINHARD, 1.0f), 0.5, 1e-7);
    CHECK_NEAR(sy_tonemap_apply(SY_TONEMAP_REINHARD, 3.0f), 0.75, 1e-7);
    /* ACES fit at x = 1: (2.51 + 0.03) / (2.43 + 0.59 + 0.14) */
    CHECK_NEAR(sy_tonemap_apply(SY_TONEMAP_ACES, 1.0f), 2.54 / 3.16, 1e-6);
    CHECK(sy_tonemap_apply(SY_TONEMAP_ACES, NAN) == 0.0f);
    CHECK(sy_tonemap_apply(SY_TONEMAP_REINHARD, -1.0f) == 0.0f);
    CHECK(sy_tonemap_apply(SY_TONEMAP_ACES, INFINITY) == 1.0f);
    for (int i = 0; i <= 100; ++i) {
        double x = i / 100.0;
        CHECK_NEAR(sy_srgb_encode((float)x), srgb_ref(x), 2e-6);
        CHECK_NEAR(sy_srgb_decode(sy_srgb_encode((float)x)), x, 2e-5);
    }
    return 0;
}

static int test_layer_post(void)
{
    sy_error e = {0};
    sy_layer l;
    CHECK_OK(sy_layer_create(3, 1, &l, &e), e);
    /* premultiplied: (0.25 at alpha 0.5) is straight 0.5 */
    float px[12] = {0.25f, 0.25f, 0.25f, 0.5f, 2.0f, 0.0f, 0.1f, 1.0f, 0.7f, 0.7f, 0.7f, 0.0f};
    for (int i = 0; i < 12; ++i) l.rgba[i] = px[i];
    l.depth[0] = 3.0f;
    sy_post_desc off = {0};
    sy_layer_post_apply(&l, &off); /* disabled: identity */
    for (int i = 0; i < 12; ++i) CHECK(l.rgba[i] == px[i]);
    sy_post_desc p = {.enabled = true, .exposure_stops = 1.0f, .tonemap = SY_TONEMAP_REINHARD, .srgb = true};
    sy_layer_post_apply(&l, &p);
    double want0 = srgb_ref(1.0 / 2.0) * 0.5; /* straight 0.5 x 2 = 1 -> Reinhard 0.5 -> sRGB, x alpha */
    CHECK_NEAR(l.rgba[0], want0, 1e-5);
    CHECK(l.rgba[3] == 0.5f && l.depth[0] == 3.0f); /* alpha and depth untouched */
    CHECK_NEAR(l.rgba[4], srgb_ref(4.0 / 5.0), 1e-5);
    CHECK(l.rgba[5] == 0.0f);
    CHECK_NEAR(l.rgba[6], srgb_ref(0.2 / 1.2), 1e-5);
    CHECK(l.rgba[8] == 0.0f && l.rgba[11] == 0.0f); /* alpha 0: nothing to show */
    sy_layer_destroy(&l);
    return 0;
}

static int test_anaglyph(void)
{
    sy_error e = {0};
    sy_layer a, b, o, small;
    CHECK_OK(sy_layer_create(2, 1, &a, &e), e);
    CHECK_OK(sy_layer_create(2, 1, &b, &e), e);
    CHECK_OK(sy_layer_create(2, 1, &o, &e), e);
    CHECK_OK(sy_layer_create(1, 1, &small, &e), e);
    for (int i = 0; i < 8; ++i) a.rgba[i] = 0.1f * (float)(i + 1), b.rgba[i] = 0.05f * (float)(i + 1);
    a.depth[0] = 1.0f, b.depth[0] = 2.0f, a.depth[1] = 5.0f, b.depth[1] = 4.0f;
    CHECK_OK(sy_layer_anaglyph(&a, &b, &o, &e), e);
    CHECK(o.rgba[0] == a.rgba[0] && o.rgba[1] == b.rgba[1] && o.rgba[2] == b.rgba[2]);
    CHECK(o.rgba[3] == a.rgba[3]); /* max alpha */
    CHECK(o.depth[0] == 1.0f && o.depth[1] == 4.0f);
    CHECK_ERR(sy_layer_anaglyph(&a, &small, &o, &e), SY_ERR_INVALID_ARGUMENT, e);
    sy_layer_destroy(&a);
    sy_layer_destroy(&b);
    sy_layer_destroy(&o);
    sy_layer_destroy(&small);
    return 0;
}

SY_CHECK_MAIN("test_post", SY_TEST(test_operators), SY_TEST(test_layer_post), SY_TEST(test_anaglyph))
