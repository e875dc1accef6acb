/* test_raster_lights_sum.c — punctual lights add up, whichever way the shader gets them. A shading
 * program with at most 7 lights calls each light with its kind of shadow fixed when the program is
 * built (sy_gl_shaders.c, shade_light), and its type too (point, point with a range, spot,
 * directional); with more lights it loops over the Lights block and reads each kind and type there.
 * On an OSMesa device with 4x MSAA, forward and deferred:
 *  1. eight lights at once (two point lights with cube shadows, two directional and two spot lights
 *     with shadow maps, two lights without shadows; a point and a spot light with ranges: the
 *     loop) equal the sum of two renders of four of them each (the constant-count programs, each
 *     light's shadow of the same kind as in the eight), to float rounding: a light drawn with the
 *     wrong shadow or type, or twice, or not at all, changes whole regions;
 *  2. turning the first point light's shadow off builds programs for the new kinds: the image
 *     brightens where the occluder shadowed it and nowhere darkens; turning it on again takes the
 *     programs kept aside for the first kinds and gives the first image back bit for bit;
 *  3. emissive polygons (area lights, each called with its shadow fixed: shade_area) add up the
 *     same way: three at once (each with its shadow map; a triangle, a quad, a double-sided quad)
 *     equal the three alone.
 * No environment and no ambient term: the image is the lights' light only. */
#include "sy_gl.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gl_test.h"

#define W 192
#define H 144
#include "gl_sphere.h" /* after e, which it uses */
static float img[4][W * H * 4], dep[W * H];

static const sy_gl_light_desc lights[8] = {
    {.type = SY_GL_LIGHT_POINT, .color = {1, 0.9f, 0.8f}, .intensity = 20.0f, .position = {2.0f, 3, -2}},
    {.type = SY_GL_LIGHT_DIRECTIONAL, .color = {0.6f, 0.7f, 1}, .intensity = 1.0f, .direction = {0.3f, -1, -0.4f}},
    {.type = SY_GL_LIGHT_SPOT, .color = {1, 0.5f, 0.3f}, .intensity = 40.0f, .position = {-2, 3, -2},
     .direction = {0.5f, -1, -0.5f}, .inner_cone_angle = 0.3f, .outer_cone_angle = 0.6f, .range = 7.0f},
    {.type = SY_GL_LIGHT_POINT, .color = {0.3f, 1, 0.4f}, .intensity = 6.0f, .position = {0, 1.5f, -1}, .no_shadow = true,
     .range = 3.5f},
    {.type = SY_GL_LIGHT_DIRECTIONAL, .color = {1, 1, 0.8f}, .intensity = 0.7f, .direction = {-0.5f, -1, 0.2f}},
    {.type = SY_GL_LIGHT_POINT, .color = {0.5f, 0.6f, 1}, .intensity = 15.0f, .position = {-2.5f, 2, -3}},
    {.type = SY_GL_LIGHT_SPOT, .color = {0.8f, 0.8f, 1}, .intensity = 30.0f, .position = {1, 4, -4},
     .direction = {-0.2f, -1, 0.1f}, .inner_cone_angle = 0.4f, .outer_cone_angle = 0.7f},
    {.type = SY_GL_LIGHT_DIRECTIONAL, .color = {0.2f, 0.2f, 0.3f}, .intensity = 0.5f, .direction = {0, -1, 1},
     .no_shadow = true},
};

static sy_gl_device *build(bool forward)
{
    sy_gl_device_desc dd = {GL_TEST_REPORT, .provider = SY_GL_PROVIDER_OSMESA, .msaa = 4, .shadow_map_size = 512, .forward = forward};
    sy_gl_device *d;
    MUST(sy_gl_device_create(&dd, &d));
    static const float p[12] = {-6, -1, 2, 6, -1, 2, 6, -1, -12, -6, -1, -12}, n[12] = {0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0};
    static const uint32_t ix[6] = {0, 1, 2, 0, 2, 3};
    sy_gl_mesh_desc fd = {.positions = p, .normals = n, .indices = ix, .vertex_count = 4, .triangle_count = 2};
    sy_gl_mesh quad, smooth = gl_test_sphere(d, 96, 0.0f, true, NULL), faceted = gl_test_sphere(d, 64, 0.0f, false, NULL);
    MUST(sy_gl_mesh_create(d, &fd, &quad));
    sy_gl_material_desc md;
    sy_gl_material_desc_init(&md);
    md.base_color[0] = 0.7f, md.base_color[1] = 0.6f, md.base_color[2] = 0.5f, md.roughness = 0.45f; /* rougher than gets a scene probe */
    sy_gl_material mat;
    MUST(sy_gl_material_create(d, &md, &mat));
    const struct { sy_gl_mesh m; float s, x, y, z; } at[3] = {
        {quad, 1, 0, 0, 0}, {smooth, 0.9f, -1.0f, 0.0f, -4.5f}, {faceted, 0.8f, 1.2f, -0.1f, -4.0f}};
    for (int i = 0; i < 3; ++i) {
        sy_gl_instance_desc id = {.mesh = at[i].m, .material = mat,
                                  .transform = {at[i].s, 0, 0, 0, 0, at[i].s, 0, 0, 0, 0, at[i].s, 0, at[i].x, at[i].y, at[i].z, 1}};
        sy_gl_instance h;
        MUST(sy_gl_instance_create(d, &id, &h));
    }
    return d;
}

static void render(sy_gl_device *d, int k)
{
    sy_gl_camera cam = {.camera_to_world = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0.5f, 0, 1},
                        .window = {-0.8f, 0.8f, -0.6f, 0.6f}, .near_clip = 0.1f};
    sy_gl_render_desc rd = {W, H, 0, 0, W, H};
    MUST(sy_gl_render(d, &cam, &rd, img[k], dep));
}

/* lights first .. last - 1 created on d into h */
static void add(sy_gl_device *d, sy_gl_light *h, int first, int last)
{
    for (int i = first; i < last; ++i) MUST(sy_gl_light_create(d, &lights[i], &h[i]));
}

static void remove_all(sy_gl_device *d, sy_gl_light *h)
{
    for (int i = 0; i < 8; ++i)
        if (h[i].id) sy_gl_light_destroy(d, h[i]), h[i].id = 0;
}

/* Three emissive polygons at once against each alone (slots 0 .. 3 of img hold three, and each). */
static void areas_sum(sy_gl_device *d, const char *how)
{
    static const sy_gl_area_light al[3] = {
        {.vertices = {{-2, 2.5f, -5}, {-1, 2.5f, -5}, {-1, 2.5f, -4}, {-2, 2.5f, -4}}, .vertex_count = 4, .radiance = {40, 30, 20}},
        {.vertices = {{0.5f, 3, -3.5f}, {1.5f, 3, -3.5f}, {1, 3, -2.5f}}, .vertex_count = 3, .radiance = {20, 30, 50}},
        {.vertices = {{2, 2, -6}, {3, 2, -6}, {3, 2, -5}, {2, 2, -5}}, .vertex_count = 4, .radiance = {30, 30, 30},
         .double_sided = true},
    };
    MUST(sy_gl_set_area_lights(d, al, 3));
    render(d, 0);
    static float acc[W * H * 4];
    memset(acc, 0, sizeof acc);
    for (int k = 0; k < 3; ++k) {
        MUST(sy_gl_set_area_lights(d, &al[k], 1));
        render(d, 1 + k);
        for (size_t i = 0; i < (size_t)W * H * 4; ++i) acc[i] += img[1 + k][i];
    }
    double sum = 0.0, diff = 0.0, worst = 0.0;
    for (size_t i = 0; i < (size_t)W * H; ++i)
        for (int c = 0; c < 3; ++c) {
            double all = img[0][4 * i + c], dd = fabs(all - acc[4 * i + c]);
            sum += all, diff += dd;
            if (dd / (fabs(all) + 1e-3) > worst) worst = dd / (fabs(all) + 1e-3);
        }
    printf("%s: three emissive polygons against each alone: mean %.3f, mean difference %.2e of it, worst pixel %.2e\n",
           how, sum / (3.0 * W * H), sum > 0.0 ? diff / sum : 1.0, worst);
    EXPECT_MSG(sum > 0.01 * 3.0 * W * H, "%s: polygons: the image is (nearly) black", how);
    EXPECT_MSG(diff <= 1e-5 * sum, "%s: three polygons differ from the sum of each alone by %.2e of the mean", how, diff / sum);
    EXPECT_MSG(worst <= 1e-3, "%s: polygons: a pixel differs by %.2e (relative)", how, worst);
    MUST(sy_gl_set_area_lights(d, NULL, 0));
}

static void run(bool forward)
{
    const char *how = forward ? "forward" : "deferred";
    sy_gl_device *d = build(forward);
    sy_gl_light h[8];
    memset(h, 0, sizeof h);
    /* the eight in the order that gives each the same shadow as in the halves: point lights take
     * the cube slots, directional and spot lights the 2D maps, in creation order. The halves'
     * kinds differ (cube, map, map, none against map, cube, map, none): each half's programs are
     * built for its own, and part 2 finds the first half's kept aside */
    add(d, h, 0, 8);
    render(d, 0);
    remove_all(d, h);
    add(d, h, 0, 4);
    render(d, 1);
    remove_all(d, h);
    add(d, h, 4, 8);
    render(d, 2);
    sy_gl_stats st;
    sy_gl_device_stats(d, &st);
    printf("%s: %llu instances shaded deferred in the last frame\n", how, (unsigned long long)st.deferred_draws);
    EXPECT_MSG(forward ? st.deferred_draws == 0 : st.deferred_draws == 2, "%s: %llu deferred draws (want %d)", how,
               (unsigned long long)st.deferred_draws, forward ? 0 : 2);
    double sum = 0.0, diff = 0.0, worst = 0.0;
    for (size_t i = 0; i < (size_t)W * H; ++i)
        for (int c = 0; c < 3; ++c) {
            double all = img[0][4 * i + c], parts = (double)img[1][4 * i + c] + img[2][4 * i + c], dd = fabs(all - parts);
            sum += all, diff += dd;
            if (dd / (fabs(all) + 1e-3) > worst) worst = dd / (fabs(all) + 1e-3);
        }
    printf("%s: eight lights against four + four: mean %.3f, mean difference %.2e of it, worst pixel %.2e\n", how,
           sum / (3.0 * W * H), sum > 0.0 ? diff / sum : 1.0, worst);
    EXPECT_MSG(sum > 0.01 * 3.0 * W * H, "%s: the image is (nearly) black", how);
    EXPECT_MSG(diff <= 1e-5 * sum, "%s: eight lights differ from the sum of their halves by %.2e of the mean", how, diff / sum);
    EXPECT_MSG(worst <= 1e-3, "%s: a pixel differs by %.2e (relative)", how, worst);
    /* 2. the first half again; its point light's shadow off, then on */
    remove_all(d, h);
    add(d, h, 0, 4);
    render(d, 1);
    sy_gl_light_desc off = lights[0];
    off.no_shadow = true;
    MUST(sy_gl_light_update(d, h[0], &off));
    render(d, 3);
    size_t brighter = 0, darker = 0;
    for (size_t i = 0; i < (size_t)W * H * 4; ++i) {
        if (i % 4 == 3) continue;
        float a = img[1][i], b = img[3][i];
        if (b > a * 1.05f + 1e-3f) brighter++;
        if (b < a * (1.0f - 1e-5f) - 1e-6f) darker++;
    }
    printf("%s: the point light's shadow off: %zu channel values brighter, %zu darker\n", how, brighter, darker);
    EXPECT_MSG(brighter >= 60, "%s: without the point light's shadow only %zu values brighter", how, brighter);
    EXPECT_MSG(darker == 0, "%s: without the point light's shadow %zu values darker", how, darker);
    MUST(sy_gl_light_update(d, h[0], &lights[0]));
    render(d, 3);
    EXPECT_MSG(memcmp(img[1], img[3], sizeof img[1]) == 0, "%s: the shadow back on does not give the first image back", how);
    /* 3. emissive polygons, the punctual lights gone */
    remove_all(d, h);
    areas_sum(d, how);
    sy_gl_device_destroy(d);
}

int main(void)
{
    run(true);
    run(false);
    return sy_check_finish("test_raster_lights_sum");
}
