/* test_raster_deferred.c — deferred shading (sy_gl_device_desc.forward) against forward shading:
 * the same scene on two OSMesa devices with 4x MSAA, one shading every surface forward, one
 * shading the eligible surfaces (opaque, untextured, dense meshes without colours) once per pixel
 * after the geometry pass. Every kind of light at once (a point light with a cube shadow, a
 * directional light with a shadow map, an environment, an area light), smooth and faceted meshes,
 * a mirrored instance, metal, unlit and emissive materials, a large quad that stays forward; in
 * perspective and orthographic views, from behind (normals with z < 0), after a material change
 * (the material table's update), and with a blended instance (the whole frame falls back to
 * forward: bit-identical). The deferred pass runs only on the 8-pixel tiles that the G-buffer
 * instances' projected bounds touch (the target, 196 x 146, is no multiple of 8), also with 80
 * small spheres across the image and past its edges. The images must agree to what grouping a
 * pixel's samples into one surface can change (a pixel the deferred pass misses shows the raw
 * G-buffer); the counters must show which instances went which way and where the deferred pass
 * ran. */
#include "sy_gl.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gl_test.h"

#define W 196
#define H 146
#include "gl_sphere.h" /* after e, which it uses */
static float img[2][W * H * 4], dep[2][W * H];

static sy_gl_mesh floor_quad(sy_gl_device *d)
{
    static const float p[12] = {-6, -1.2f, 2, 6, -1.2f, 2, 6, -1.2f, -12, -6, -1.2f, -12}, n[12] = {0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0};
    static const uint32_t ix[6] = {0, 1, 2, 0, 2, 3};
    sy_gl_mesh_desc md = {.positions = p, .normals = n, .indices = ix, .vertex_count = 4, .triangle_count = 2};
    sy_gl_mesh m;
    MUST(sy_gl_mesh_create(d, &md, &m));
    return m;
}

static sy_gl_material material(sy_gl_device *d, float r, float g, float b, float metallic, float rough)
{
    sy_gl_material_desc md;
    sy_gl_material_desc_init(&md);
    md.base_color[0] = r, md.base_color[1] = g, md.base_color[2] = b;
    md.metallic = metallic, md.roughness = rough;
    sy_gl_material h;
    MUST(sy_gl_material_create(d, &md, &h));
    return h;
}

static sy_gl_instance place(sy_gl_device *d, sy_gl_mesh m, sy_gl_material mat, float sx, float x, float y, float z)
{
    sy_gl_instance_desc id = {.mesh = m, .material = mat,
                              .transform = {sx, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, x, y, z, 1}};
    sy_gl_instance h;
    MUST(sy_gl_instance_create(d, &id, &h));
    return h;
}

static void place_small(sy_gl_device *d, sy_gl_mesh m, sy_gl_material mat, float s, float x, float y, float z)
{
    sy_gl_instance_desc id = {.mesh = m, .material = mat, .transform = {s, 0, 0, 0, 0, s, 0, 0, 0, 0, s, 0, x, y, z, 1}};
    sy_gl_instance h;
    MUST(sy_gl_instance_create(d, &id, &h));
}

typedef struct scene {
    sy_gl_device *d;
    sy_gl_material red;
    sy_gl_mesh smooth;
} scene;

/* The same scene on a device; returns what later steps change. */
static scene build(bool forward)
{
    scene s = {0};
    sy_gl_device_desc dd = {GL_TEST_REPORT, .provider = SY_GL_PROVIDER_OSMESA, .msaa = 4, .shadow_map_size = 512, .forward = forward};
    MUST(sy_gl_device_create(&dd, &s.d));
    sy_gl_device *d = s.d;
    /* levels of detail off: the spheres keep the small triangles deferred shading is for (with
     * levels the smooth ones, 18,240 triangles, draw a level whose triangles are large enough on
     * screen to be shaded forward) */
    sy_gl_set_lod(d, 0.0f);
    s.smooth = gl_test_sphere(d, 96, 0.0f, true, NULL);
    sy_gl_mesh faceted = gl_test_sphere(d, 64, 0.0f, false, NULL);
    s.red = material(d, 0.8f, 0.1f, 0.1f, 0.0f, 0.35f);
    sy_gl_material metal = material(d, 0.9f, 0.7f, 0.3f, 1.0f, 0.55f); /* rough enough to get no scene probe */
    sy_gl_material_desc ud;
    sy_gl_material_desc_init(&ud);
    ud.base_color[0] = 0.2f, ud.base_color[1] = 0.5f, ud.base_color[2] = 0.9f;
    ud.emissive[0] = 0.3f, ud.emissive[1] = 0.2f, ud.emissive[2] = 0.0f, ud.unlit = true;
    sy_gl_material unlit;
    MUST(sy_gl_material_create(d, &ud, &unlit));
    place(d, s.smooth, (sy_gl_material){0}, 1.0f, -1.15f, 0.0f, -4.0f); /* the default material */
    place(d, s.smooth, s.red, 1.0f, 1.15f, 0.0f, -4.2f);
    place(d, faceted, metal, 1.0f, 0.0f, 0.9f, -5.0f);
    place(d, s.smooth, unlit, -0.4f, 0.0f, -0.8f, -3.0f); /* mirrored: front faces flip */
    place(d, floor_quad(d), (sy_gl_material){0}, 1.0f, 0, 0, 0);
    sy_gl_light_desc pl = {.type = SY_GL_LIGHT_POINT, .color = {1, 0.9f, 0.8f}, .intensity = 30.0f, .position = {2.5f, 3, -1}};
    sy_gl_light_desc dl = {.type = SY_GL_LIGHT_DIRECTIONAL, .color = {0.6f, 0.7f, 1}, .intensity = 1.5f,
                           .direction = {0.3f, -1, -0.4f}};
    sy_gl_light h;
    MUST(sy_gl_light_create(d, &pl, &h));
    MUST(sy_gl_light_create(d, &dl, &h));
    enum { EW = 64, EH = 32 };
    static float t[EW * EH * 3];
    for (int y = 0; y < EH; ++y)
        for (int x = 0; x < EW; ++x)
            for (int c = 0; c < 3; ++c) t[(y * EW + x) * 3 + c] = y < EH / 2 ? 0.5f + 0.3f * (float)c * (float)x / EW : 0.15f;
    sy_gl_texture_desc td = {.width = EW, .height = EH, .channels = 3, .format = SY_GL_TEXEL_FLOAT32, .pixels = t,
                             .wrap_t = SY_GL_WRAP_CLAMP};
    sy_gl_texture env;
    MUST(sy_gl_texture_create(d, &td, &env));
    sy_gl_set_environment(d, env, 1.0f);
    sy_gl_area_light al = {.vertices = {{-2, 2.5f, -5}, {-1, 2.5f, -5}, {-1, 2.5f, -4}, {-2, 2.5f, -4}}, .vertex_count = 4,
                           .radiance = {4, 4, 3}};
    MUST(sy_gl_set_area_lights(d, &al, 1));
    return s;
}

static sy_gl_camera camera(bool ortho)
{
    sy_gl_camera cam = {.camera_to_world = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0.3f, 0, 1},
                        .window = {-0.8f, 0.8f, -0.6f, 0.6f}, .near_clip = 0.1f, .orthographic = ortho};
    if (ortho) { /* the same framing at the spheres' distance */
        for (int i = 0; i < 4; ++i) cam.window[i] *= 4.0f;
    }
    return cam;
}

/* Renders into slot k; returns the deferred draws, and in *px the pixels the deferred pass shaded. */
static uint64_t render_cam(scene *s, int k, const sy_gl_camera *cam, uint64_t *px)
{
    sy_gl_render_desc rd = {W, H, 0, 0, W, H};
    MUST(sy_gl_render(s->d, cam, &rd, img[k], dep[k]));
    sy_gl_stats st;
    sy_gl_device_stats(s->d, &st);
    if (px) *px = st.deferred_pixels;
    return st.deferred_draws;
}

static uint64_t render(scene *s, int k, bool ortho)
{
    sy_gl_camera cam = camera(ortho);
    return render_cam(s, k, &cam, NULL);
}

/* Forward (slot 0) against deferred (slot 1): relative mean difference of the colour, share of
 * pixels off by more than 2 % of their value (+0.01), and whether depth is equal. Measured: mean
 * 6.3e-4 and 0.22 % of pixels (perspective), 1.2e-3 and 0.18 % (orthographic): specks at the
 * directional light's shadow terminator on the smooth spheres, present in both images. A facet
 * whose stored geometric normal is off enough to put a light on its other side flips as a whole
 * (about 30 pixels, +1e-3 of mean: a 12-bit slope did that here). A wrong material row, normal
 * or light changes whole surfaces. */
static void compare(const char *what, double max_mean, double max_share)
{
    double sum = 0.0, diff = 0.0, worst = 0.0;
    size_t off = 0, depth_off = 0;
    for (size_t i = 0; i < (size_t)W * H; ++i) {
        double px = 0.0;
        for (int c = 0; c < 3; ++c) {
            double a = img[0][4 * i + c], b = img[1][4 * i + c], dd = fabs(a - b);
            sum += fabs(a), diff += dd;
            if (dd > px) px = dd;
            if (dd > 0.02 * fabs(a) + 0.01) px = INFINITY;
        }
        if (isinf(px)) off++;
        else if (px > worst) worst = px;
        if (!(dep[0][i] == dep[1][i])) depth_off++;
    }
    double mean = sum > 0.0 ? diff / sum : 1.0, share = (double)off / ((double)W * H);
    printf("%s: mean difference %.2e of the mean, %.3f %% of pixels off by > 2 %%, depth differs in %zu pixels\n", what, mean,
           100.0 * share, depth_off);
    EXPECT_MSG(sum > 0.0, "%s: a black image", what);
    EXPECT_MSG(mean <= max_mean, "%s: mean difference %.2e > %.2e", what, mean, max_mean);
    EXPECT_MSG(share <= max_share, "%s: %.3f %% of pixels differ (> %.3f %%)", what, 100.0 * share, 100.0 * max_share);
    EXPECT_MSG(depth_off == 0, "%s: depth differs in %zu pixels", what, depth_off);
}

int main(void)
{
    scene fw = build(true), df = build(false);
    /* 1. perspective: the four spheres deferred, the floor (two large triangles) forward; the
     * deferred pass on their tiles only */
    const sy_gl_camera persp = camera(false);
    uint64_t px = 0, n0 = render(&fw, 0, false), n1 = render_cam(&df, 1, &persp, &px);
    printf("deferred draws: forward device %llu, deferred device %llu, on %llu of %d pixels\n", (unsigned long long)n0,
           (unsigned long long)n1, (unsigned long long)px, W * H);
    EXPECT_MSG(n0 == 0 && n1 == 4, "deferred draws %llu / %llu (want 0 / 4)", (unsigned long long)n0, (unsigned long long)n1);
    EXPECT_MSG(px > 0 && px < (uint64_t)W * H, "the deferred pass shaded %llu of %d pixels", (unsigned long long)px, W * H);
    compare("perspective", 2.5e-3, 0.006);
    /* 2. orthographic (the G-buffer pass's orthographic variant) */
    render(&fw, 0, true);
    n1 = render(&df, 1, true);
    EXPECT_MSG(n1 == 4, "orthographic: %llu deferred draws", (unsigned long long)n1);
    compare("orthographic", 2.5e-3, 0.006);
    /* 2b. from behind the spheres, looking along +z: the visible normals have z < 0 (world), which
     * the G-buffer keeps in the depth's sign */
    const sy_gl_camera back = {.camera_to_world = {-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -1, 0, 0, 0.3f, -9.5f, 1},
                               .window = {-0.8f, 0.8f, -0.6f, 0.6f}, .near_clip = 0.1f};
    render_cam(&fw, 0, &back, NULL);
    n1 = render_cam(&df, 1, &back, NULL);
    EXPECT_MSG(n1 == 4, "from behind: %llu deferred draws", (unsigned long long)n1);
    compare("from behind", 2.5e-3, 0.006);
    /* 3. a material change reaches the deferred pass (its table row) */
    sy_gl_material_desc md;
    sy_gl_material_desc_init(&md);
    md.base_color[0] = 0.1f, md.base_color[1] = 0.7f, md.base_color[2] = 0.2f, md.roughness = 0.2f;
    MUST(sy_gl_material_update(fw.d, fw.red, &md));
    MUST(sy_gl_material_update(df.d, df.red, &md));
    render(&fw, 0, false);
    render(&df, 1, false);
    compare("after a material change", 2.5e-3, 0.006);
    /* 4. 80 small spheres (about 3 pixels across) over the image and past its edges: the deferred
     * pass on the tiles they touch, in many rectangles */
    for (int k = 0; k < 2; ++k)
        for (int i = 0; i < 80; ++i)
            place_small(k ? df.d : fw.d, k ? df.smooth : fw.smooth, k ? df.red : fw.red, 0.045f,
                        -2.55f + 0.5f * (float)(i % 11) + 0.031f * (float)(i / 11), -1.75f + 0.49f * (float)(i / 11), -3.0f);
    render(&fw, 0, false);
    n1 = render_cam(&df, 1, &persp, &px);
    printf("small spheres: %llu deferred draws on %llu pixels\n", (unsigned long long)n1, (unsigned long long)px);
    EXPECT_MSG(n1 > 60 && px < (uint64_t)W * H * 3 / 4, "small spheres: %llu deferred draws on %llu of %d pixels",
               (unsigned long long)n1, (unsigned long long)px, W * H);
    compare("small spheres", 2.5e-3, 0.006);
    /* 5. a blended instance: the frame is forward on both devices, so the images are the same */
    for (int k = 0; k < 2; ++k) {
        scene *s = k ? &df : &fw;
        sy_gl_material_desc bd;
        sy_gl_material_desc_init(&bd);
        bd.alpha_mode = SY_GL_ALPHA_BLEND, bd.base_color[3] = 0.5f;
        sy_gl_material glassy;
        MUST(sy_gl_material_create(s->d, &bd, &glassy));
        place(s->d, s->smooth, glassy, 0.3f, 0.6f, -0.6f, -2.5f);
    }
    render(&fw, 0, false);
    n1 = render(&df, 1, false);
    EXPECT_MSG(n1 == 0, "with a blended instance: %llu deferred draws", (unsigned long long)n1);
    EXPECT_MSG(memcmp(img[0], img[1], sizeof img[0]) == 0, "with a blended instance the images differ");
    sy_gl_device_destroy(fw.d);
    sy_gl_device_destroy(df.d);
    return sy_check_finish("test_raster_deferred");
}
