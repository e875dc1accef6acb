/* test_look.c — the scene-look rules of core/sy_look.h (which lighting and background a view gets),
 * the built-in studio environment, X3D gradients, the lat-long convention, the world fields'
 * validation in the scene, and layer statistics (core/sy_stats.h). */
#include "../support/sy_check.h"
#include "sy_look.h"
#include "sy_scene.h"
#include "sy_stats.h"

#include <stdlib.h>
#include <string.h>

static sy_background_data world(void)
{
    sy_background_data w = *(const sy_background_data *)sy_object_defaults(SY_TYPE_BACKGROUND);
    return w;
}

static int test_resolve(void)
{
    sy_look l;
    /* no world, nothing lights: the studio lights, the camera sees transparency */
    sy_look_resolve(&(sy_look_inputs){0}, &l);
    CHECK(l.env == SY_LOOK_ENV_STUDIO && l.default_lighting && l.env_intensity == 1.0f);
    CHECK(l.background == SY_LOOK_BG_NONE);
    /* a punctual light or a lighting emitter: no studio */
    sy_look_resolve(&(sy_look_inputs){.light_count = 1}, &l);
    CHECK(l.env == SY_LOOK_ENV_NONE && !l.default_lighting);
    sy_look_resolve(&(sy_look_inputs){.emitter_count = 2}, &l);
    CHECK(l.env == SY_LOOK_ENV_NONE);
    /* the world's switch */
    sy_background_data w = world();
    w.default_lighting = 0;
    sy_look_resolve(&(sy_look_inputs){.world = &w}, &l);
    CHECK(l.env == SY_LOOK_ENV_NONE);
    /* default world: opaque black background, studio light */
    w = world();
    sy_look_resolve(&(sy_look_inputs){.world = &w}, &l);
    CHECK(l.env == SY_LOOK_ENV_STUDIO && l.background == SY_LOOK_BG_COLOR && l.bg_color[3] == 1.0f);
    /* an environment: a light, seen by the camera unless hidden; no studio */
    w.environment.id = 77;
    w.intensity = 2.5f;
    sy_look_resolve(&(sy_look_inputs){.world = &w, .world_env_ready = true}, &l);
    CHECK(l.env == SY_LOOK_ENV_TEXTURE && l.env_texture == 77 && l.env_intensity == 2.5f && !l.default_lighting);
    CHECK(l.background == SY_LOOK_BG_ENVIRONMENT);
    w.environment_visible = 0;
    sy_look_resolve(&(sy_look_inputs){.world = &w, .world_env_ready = true}, &l);
    CHECK(l.env == SY_LOOK_ENV_TEXTURE && l.background == SY_LOOK_BG_COLOR);
    /* an environment texture without pixels yet is no light: the studio stands in */
    sy_look_resolve(&(sy_look_inputs){.world = &w, .world_env_ready = false}, &l);
    CHECK(l.env == SY_LOOK_ENV_STUDIO);
    /* a gradient is a background only */
    w = world();
    w.gradient.sky_count = 2;
    w.gradient.sky_color[0][2] = 1.0f;
    w.gradient.sky_color[1][0] = 1.0f;
    w.gradient.sky_angle[0] = 1.5f;
    sy_look_inputs in = {.world = &w, .light_count = 1};
    sy_look_resolve(&in, &l);
    CHECK(l.env == SY_LOOK_ENV_NONE && l.background == SY_LOOK_BG_GRADIENT && l.gradient.sky_count == 2);
    sy_look l2;
    sy_look_resolve(&in, &l2);
    CHECK(sy_look_equal(&l, &l2));
    w.gradient.sky_color[1][0] = 0.5f;
    sy_look_resolve(&in, &l2);
    CHECK(!sy_look_equal(&l, &l2));
    return 0;
}

static int test_latlong(void)
{
    float u, v, d[3];
    sy_look_latlong_uv((const float[3]){0, 0, -1}, &u, &v);
    CHECK(fabsf(u - 0.5f) < 1e-6f && fabsf(v - 0.5f) < 1e-6f); /* -Z is the image centre */
    sy_look_latlong_uv((const float[3]){0, 1, 0}, &u, &v);
    CHECK(fabsf(v) < 1e-6f); /* +Y is row 0 */
    sy_look_latlong_uv((const float[3]){1, 0, 0}, &u, &v);
    CHECK(fabsf(u - 0.75f) < 1e-6f);
    for (int i = 1; i < 20; ++i)
        for (int j = 1; j < 10; ++j) {
            float uu = (float)i / 20.0f, vv = (float)j / 10.0f;
            sy_look_latlong_dir(uu, vv, d);
            CHECK(fabsf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2] - 1.0f) < 1e-5f);
            sy_look_latlong_uv(d, &u, &v);
            CHECK_MSG(fabsf(u - uu) < 1e-5f && fabsf(v - vv) < 1e-5f, "(%g %g) -> (%g %g)", uu, vv, u, v);
        }
    return 0;
}

static int test_studio(void)
{
    uint32_t W = SY_LOOK_STUDIO_WIDTH, H = SY_LOOK_STUDIO_HEIGHT;
    float *px = malloc(sizeof(float) * 3 * W * H);
    CHECK(px);
    sy_look_studio_pixels(W, H, px);
    /* neutral grey, finite, positive; cosine-weighted irradiance from above and below */
    double e_up = 0, e_down = 0, maxv = 0;
    for (uint32_t j = 0; j < H; ++j)
        for (uint32_t i = 0; i < W; ++i) {
            const float *p = px + 3 * (j * W + i);
            if (!(isfinite(p[0]) && p[0] > 0.0f && p[0] == p[1] && p[1] == p[2])) {
                fprintf(stderr, "texel (%u, %u) = %g %g %g\n", i, j, p[0], p[1], p[2]);
                free(px);
                CHECK(0);
            }
            if (p[0] > maxv) maxv = p[0];
            float d[3];
            sy_look_latlong_dir((i + 0.5f) / W, (j + 0.5f) / H, d);
            double dw = (2.0 * TEST_PI / W) * (TEST_PI / H) * sin(TEST_PI * (j + 0.5) / H);
            if (d[1] > 0) e_up += p[0] * d[1] * dw;
            else e_down -= p[0] * d[1] * dw;
        }
    free(px);
    /* a white Lambertian floor under the studio reflects E/pi: about 1 (a readable image), and the
     * dome is brighter above than below */
    CHECK_MSG(e_up / TEST_PI > 0.7 && e_up / TEST_PI < 1.6, "E_up/pi = %g", e_up / TEST_PI);
    CHECK_MSG(e_down / TEST_PI > 0.15 && e_down / TEST_PI < 0.4, "E_down/pi = %g", e_down / TEST_PI);
    CHECK(maxv <= 5.0 + 1e-6);
    return 0;
}

static int test_gradient(void)
{
    sy_gradient g = {0};
    g.sky_count = 3;
    float sky[3][3] = {{0, 0, 1}, {0, 1, 0}, {1, 0, 0}};
    memcpy(g.sky_color, sky, sizeof sky);
    g.sky_angle[0] = (float)TEST_PI / 4;
    g.sky_angle[1] = (float)TEST_PI / 2;
    g.ground_count = 2;
    g.ground_color[0][0] = 0.2f, g.ground_color[1][1] = 0.4f;
    g.ground_angle[0] = (float)TEST_PI / 2;
    float c[3];
    sy_look_gradient_eval(&g, (const float[3]){0, 1, 0}, c); /* zenith */
    CHECK(c[2] == 1.0f && c[0] == 0.0f);
    float a = (float)TEST_PI / 8; /* half way to the first angle */
    sy_look_gradient_eval(&g, (const float[3]){sinf(a), cosf(a), 0}, c);
    CHECK(fabsf(c[2] - 0.5f) < 1e-4f && fabsf(c[1] - 0.5f) < 1e-4f);
    sy_look_gradient_eval(&g, (const float[3]){1, 1e-4f, 0}, c); /* just above the horizon */
    CHECK(fabsf(c[0] - 1.0f) < 1e-3f);
    sy_look_gradient_eval(&g, (const float[3]){0, -1, 0}, c); /* nadir: the first ground colour */
    CHECK(fabsf(c[0] - 0.2f) < 1e-6f && c[1] == 0.0f);
    /* baked image: rows follow the polar angle */
    float img[4 * 8 * 3];
    sy_look_gradient_pixels(&g, 4, 8, img);
    CHECK(img[2] > 0.5f && img[3 * 4 * 7 + 0] > 0.1f);
    /* ground without angles covers the whole lower hemisphere; no ground: the sky continues */
    g.ground_count = 1;
    sy_look_gradient_eval(&g, (const float[3]){1, -0.01f, 0}, c);
    CHECK(fabsf(c[0] - 0.2f) < 1e-6f);
    g.ground_count = 0;
    sy_look_gradient_eval(&g, (const float[3]){0, -1, 0}, c);
    CHECK(c[0] == 1.0f);
    return 0;
}

static int test_world_fields(void)
{
    sy_error e = {0};
    sy_scene *s;
    CHECK_OK(sy_scene_create(&s, &e), e);
    sy_background b;
    CHECK_OK(sy_background_create(s, "w", &b, &e), e);
    sy_background_data d = *sy_background_get(s, b);
    CHECK(d.environment_visible == 1 && d.default_lighting == 1 && d.gradient.sky_count == 0);
    d.name = NULL;
    d.gradient.sky_count = 2;
    d.gradient.sky_angle[0] = 4.0f; /* beyond pi */
    CHECK_ERR(sy_background_set(s, b, &d, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK(strstr(e.message, "sky angle"));
    d.gradient.sky_angle[0] = 1.0f;
    d.gradient.sky_color[1][0] = NAN;
    CHECK_ERR(sy_background_set(s, b, &d, &e), SY_ERR_INVALID_ARGUMENT, e);
    d.gradient.sky_color[1][0] = 0.5f;
    d.gradient.sky_count = SY_GRADIENT_MAX + 1;
    CHECK_ERR(sy_background_set(s, b, &d, &e), SY_ERR_INVALID_ARGUMENT, e);
    d.gradient.sky_count = 2;
    d.default_lighting = 2;
    CHECK_ERR(sy_background_set(s, b, &d, &e), SY_ERR_INVALID_ARGUMENT, e);
    d.default_lighting = 0;
    CHECK_OK(sy_background_set(s, b, &d, &e), e);
    CHECK(sy_background_get(s, b)->default_lighting == 0 && sy_background_get(s, b)->gradient.sky_angle[0] == 1.0f);
    sy_scene_destroy(s);
    return 0;
}

static int test_stats(void)
{
    sy_error e = {0};
    sy_layer a, b;
    CHECK_OK(sy_layer_create(4, 2, &a, &e), e);
    CHECK_OK(sy_layer_create(4, 2, &b, &e), e);
    /* a covers pixels 0..3 (grey 0.5 and white), b covers 2..5 */
    for (int i = 0; i < 4; ++i) {
        a.depth[i] = 1.0f;
        float v = i < 2 ? 0.5f : 1.0f;
        a.rgba[4 * i] = a.rgba[4 * i + 1] = a.rgba[4 * i + 2] = v, a.rgba[4 * i + 3] = 1.0f;
        b.depth[i + 2] = 2.0f;
    }
    sy_layer_stats st;
    sy_layer_stats_get(&a, &st);
    CHECK(st.pixels == 8 && st.covered == 4 && fabs(st.mean_luminance - 0.75) < 1e-6);
    double iou;
    CHECK_OK(sy_layer_coverage_iou(&a, &b, &iou, &e), e);
    CHECK(fabs(iou - 2.0 / 6.0) < 1e-12);
    a.rgba[0] = NAN;
    sy_layer_stats_get(&a, &st);
    CHECK(st.nonfinite == 1 && fabs(st.mean_luminance - (0.5 + 2.0) / 3.0) < 1e-6);
    sy_layer c;
    CHECK_OK(sy_layer_create(2, 2, &c, &e), e);
    CHECK_ERR(sy_layer_coverage_iou(&a, &c, &iou, &e), SY_ERR_INVALID_ARGUMENT, e);
    sy_layer_destroy(&a);
    sy_layer_destroy(&b);
    sy_layer_destroy(&c);
    return 0;
}

SY_CHECK_MAIN("test_look", SY_TEST(test_resolve), SY_TEST(test_latlong), SY_TEST(test_studio), SY_TEST(test_gradient),
              SY_TEST(test_world_fields), SY_TEST(test_stats))
