/* test_raster_light.c — the rasterizer's environment light, background and area lights through
 * the back-end API (sy_gl.h), against analytic values:
 *  1. a constant white environment of radiance E lights a Lambert quad (no specular) to exactly
 *     base x E (irradiance pi E); the background stays transparent (the environment is no
 *     background) and a TEXTURE background shows the texel x intensity with alpha 1; beside a
 *     mirror with a scene probe it shades the same, in one program for both;
 *  2. a mirror (metallic 1, roughness 0) under a lat-long environment whose upper half is 2 and lower
 *     half 0.5 reflects one half or the other, not their mean (the prefiltered mip 0 is sharp);
 *     without an environment it reflects the scene around it (an emissive ceiling; its scene
 *     probe), also when an alpha-masked instance makes the probe faces draw with the masked
 *     program, and hiding the ceiling updates the reflection;
 *  3. a square emitter above a Lambert floor: the irradiance under its centre matches the form
 *     factor of a square (LTC, diffuse), the emitter does not light points behind it (one-sided),
 *     a double-sided emitter lights both sides, an occluder casts a shadow; a point light's cube
 *     shadow map shadows the floor under the same occluder and leaves I cos / d^2 beside it;
 *  4. invalid area lights are refused with a message naming the item.
 * argv[1] = provider (osmesa default). */
#include "sy_gl.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gl_test.h"

#define N 32
#define PI_F 3.14159265358979f
static float rgba[N * N * 4], depth[N * N];
static const sy_gl_render_desc full = {N, N, 0, 0, N, N};
static const float *px(int x, int y) { return rgba + 4 * (y * N + x); }
static bool near_(float a, float b, float tol) { return fabsf(a - b) <= tol * fmaxf(1e-3f, fabsf(b)); }

static sy_gl_mesh quad(sy_gl_device *d, const float *p4, const float n[3]) { return gl_test_quad(d, p4, n, NULL); }

/* A perfect mirror: metallic 1, roughness 0 (it gets a scene probe). */
static sy_gl_material mirror(sy_gl_device *d)
{
    sy_gl_material_desc md;
    sy_gl_material_desc_init(&md);
    md.metallic = 1.0f;
    md.roughness = 0.0f;
    sy_gl_material h;
    MUST(sy_gl_material_create(d, &md, &h));
    return h;
}

static sy_gl_material lambert(sy_gl_device *d, float albedo)
{
    sy_gl_material_desc md;
    sy_gl_material_desc_init(&md);
    md.base_color[0] = md.base_color[1] = md.base_color[2] = albedo;
    md.metallic = 0.0f;
    md.specular = 0.0f;
    sy_gl_material h;
    MUST(sy_gl_material_create(d, &md, &h));
    return h;
}

static sy_gl_texture env_texture(sy_gl_device *d, float upper, float lower)
{
    enum { W = 64, H = 32 };
    static float t[W * H * 3];
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W * 3; ++x) t[y * W * 3 + x] = y < H / 2 ? upper : lower;
    sy_gl_texture_desc td = {.width = W, .height = H, .channels = 3, .format = SY_GL_TEXEL_FLOAT32, .pixels = t,
                             .wrap_t = SY_GL_WRAP_CLAMP};
    sy_gl_texture h;
    MUST(sy_gl_texture_create(d, &td, &h));
    return h;
}

/* Form factor from a point to a parallel square of half-size a centred at height h above it. */
static float square_form_factor(float a, float h)
{
    /* four rectangles a x a with a corner above the point: F = 1/(2 pi) (x/sqrt(1+x^2) atan(y/sqrt(1+x^2)) + (x<->y)) */
    float x = a / h, y = a / h;
    float f = (x / sqrtf(1 + x * x) * atanf(y / sqrtf(1 + x * x)) + y / sqrtf(1 + y * y) * atanf(x / sqrtf(1 + y * y))) / (2 * PI_F);
    return 4.0f * f;
}

int main(int argc, char **argv)
{
    sy_gl_provider prov = SY_GL_PROVIDER_OSMESA;
    if (argc > 1 && !sy_gl_provider_parse(argv[1], &prov)) return 2;
    sy_gl_device *d;
    sy_gl_device_desc dd = {GL_TEST_REPORT, .provider = prov, .msaa = 1, .shadow_map_size = 512};
    sy_gl_result cr = sy_gl_device_create(&dd, &d);
    if (cr == SY_GL_ERROR_NO_CONTEXT && prov != SY_GL_PROVIDER_OSMESA) {
        printf("SKIP: no %s context: %s\n", sy_gl_provider_name(prov), e);
        return 77;
    }
    MUST(cr);
    sy_gl_camera cam = {.camera_to_world = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}, .window = {-0.5f, 0.5f, -0.5f, 0.5f},
                        .near_clip = 0.1f};
    const float nz[3] = {0, 0, 1};
    const float facing[12] = {-1, -1, -3, 1, -1, -3, 1, 1, -3, -1, 1, -3};

    /* 1. constant environment: Lambert = base x E; no background from it */
    sy_gl_texture env = env_texture(d, 1.5f, 1.5f);
    sy_gl_mesh mq = quad(d, facing, nz);
    sy_gl_instance q = gl_test_place(d, mq, lambert(d, 0.5f));
    sy_gl_set_environment(d, env, 2.0f);
    /* 1a. (the device's first frame) a mirror (it gets a scene probe) in a corner of the view: the
     * Lambert quad shades as without it, and the frame builds one program for both (the quad reads
     * the prefiltered environment through the probe's unit, in the probe pass too); two were built
     * before (issue 32: each costs a compile on llvmpipe) */
    {
        sy_gl_material mm = mirror(d);
        const float corner[12] = {-1.4f, 1.1f, -2.5f, -1.1f, 1.1f, -2.5f, -1.1f, 1.4f, -2.5f, -1.4f, 1.4f, -2.5f};
        sy_gl_instance mi = gl_test_place(d, quad(d, corner, nz), mm);
        sy_gl_stats st0, st1;
        sy_gl_device_stats(d, &st0);
        MUST(sy_gl_render(d, &cam, &full, rgba, depth));
        sy_gl_device_stats(d, &st1);
        printf("Lambert beside a probed mirror %g (want 1.5), programs built %llu\n", px(16, 16)[0],
               (unsigned long long)(st1.programs_built - st0.programs_built));
        EXPECT_MSG(near_(px(16, 16)[0], 0.5f * 3.0f, 0.02f), "Lambert beside a probed mirror: %g (want %g)", px(16, 16)[0], 1.5);
        EXPECT_MSG(st1.programs_built - st0.programs_built == 1, "a frame with a probe built %llu programs (want 1)",
                   (unsigned long long)(st1.programs_built - st0.programs_built));
        MUST(sy_gl_instance_destroy(d, mi));
    }
    MUST(sy_gl_render(d, &cam, &full, rgba, depth));
    printf("Lambert under a constant environment of 3: %g (want 1.5)\n", px(16, 16)[0]);
    EXPECT_MSG(near_(px(16, 16)[0], 0.5f * 3.0f, 0.02f), "Lambert under a constant environment: %g (want %g)", px(16, 16)[0], 1.5);
    MUST(sy_gl_instance_destroy(d, q));
    MUST(sy_gl_render(d, &cam, &full, rgba, depth));
    EXPECT_MSG(px(16, 16)[3] == 0.0f && px(16, 16)[0] == 0.0f, "the environment is not a background: %g %g", px(16, 16)[0], px(16, 16)[3]);
    sy_gl_texture bg = env_texture(d, 3.0f, 0.25f);
    sy_gl_set_background(d, SY_GL_BACKGROUND_TEXTURE, NULL, bg, 2.0f);
    MUST(sy_gl_render(d, &cam, &full, rgba, depth));
    EXPECT_MSG(near_(px(16, 2)[0], 6.0f, 1e-3f) && px(16, 2)[3] == 1.0f && isinf(depth[2 * N + 16]),
               "sky above the horizon %g alpha %g (want 6, 1)", px(16, 2)[0], px(16, 2)[3]);
    EXPECT_MSG(near_(px(16, 29)[0], 0.5f, 1e-3f), "sky below the horizon %g (want 0.5)", px(16, 29)[0]);
    const float red[4] = {0.25f, 0, 0, 0.5f};
    sy_gl_set_background(d, SY_GL_BACKGROUND_COLOR, red, (sy_gl_texture){0}, 1.0f);
    MUST(sy_gl_render(d, &cam, &full, rgba, depth));
    EXPECT_MSG(px(3, 3)[0] == 0.25f && px(3, 3)[3] == 0.5f, "colour background %g %g", px(3, 3)[0], px(3, 3)[3]);
    sy_gl_set_background(d, SY_GL_BACKGROUND_NONE, NULL, (sy_gl_texture){0}, 1.0f);

    /* 2. a mirror reflects the environment sharply: tilted down it sees the lower half (0.5 x 2) */
    {
        sy_gl_set_environment(d, env_texture(d, 2.0f, 0.5f), 1.0f);
        sy_gl_material mm = mirror(d);
        /* a mirror tilted 30 degrees about x, facing up-forward: view rays reflect upwards */
        const float tilt[12] = {-1, -1.2f, -2.5f, 1, -1.2f, -2.5f, 1, 0.6f, -3.5f, -1, 0.6f, -3.5f};
        const float tn[3] = {0, 0.866f, 0.5f};
        sy_gl_instance mi = gl_test_place(d, quad(d, tilt, tn), mm);
        MUST(sy_gl_render(d, &cam, &full, rgba, depth));
        printf("mirror up %g (want 2)\n", px(16, 16)[0]);
        EXPECT_MSG(near_(px(16, 16)[0], 2.0f, 0.03f), "mirror reflects the upper half: %g (want 2)", px(16, 16)[0]);
        const float flip[12] = {-1, 0.6f, -2.5f, 1, 0.6f, -2.5f, 1, -1.2f, -3.5f, -1, -1.2f, -3.5f};
        const float fn[3] = {0, -0.866f, 0.5f};
        MUST(sy_gl_instance_destroy(d, mi));
        mi = gl_test_place(d, quad(d, flip, fn), mm);
        MUST(sy_gl_render(d, &cam, &full, rgba, depth));
        EXPECT_MSG(near_(px(16, 16)[0], 0.5f, 0.03f), "mirror reflects the lower half: %g (want 0.5)", px(16, 16)[0]);
        MUST(sy_gl_instance_destroy(d, mi));
        sy_gl_set_environment(d, (sy_gl_texture){0}, 0.0f);

        /* 2b. the mirror sees the scene (its probe), not only the environment: with no environment,
         * an emissive green ceiling above it is what the upward reflections see; hiding the ceiling
         * re-renders the probe and the mirror goes black */
        mi = gl_test_place(d, quad(d, tilt, tn), mm);
        sy_gl_material_desc gd;
        sy_gl_material_desc_init(&gd);
        gd.base_color[0] = gd.base_color[1] = gd.base_color[2] = 0.0f;
        gd.emissive[1] = 4.0f;
        gd.double_sided = true;
        gd.base_color[3] = 0.3f; /* opaque: alpha is not coverage (and below the default cutoff, 0.5) */
        sy_gl_material gm;
        MUST(sy_gl_material_create(d, &gd, &gm));
        const float ceiling[12] = {-4, 3, 1, 4, 3, 1, 4, 3, -8, -4, 3, -8};
        const float down[3] = {0, -1, 0};
        sy_gl_instance ci = gl_test_place(d, quad(d, ceiling, down), gm);
        MUST(sy_gl_render(d, &cam, &full, rgba, depth));
        printf("mirror under a green ceiling %g %g (want 0 4)\n", px(16, 16)[0], px(16, 16)[1]);
        EXPECT_MSG(near_(px(16, 16)[1], 4.0f, 0.03f) && px(16, 16)[0] < 0.01f, "mirror reflects the ceiling: %g %g (want 0 4)",
                   px(16, 16)[0], px(16, 16)[1]);
        /* with an alpha-masked instance in the scene (far below, out of the mirror's sight) the
         * probe faces draw every material with the masked program (one compile on llvmpipe, not
         * two); the ceiling is opaque and stays in the reflection (it was discarded: its alpha 0.3
         * under the masked program's cutoff) */
        {
            sy_gl_material_desc kd;
            sy_gl_material_desc_init(&kd);
            kd.alpha_mode = SY_GL_ALPHA_MASK;
            kd.alpha_cutoff = 0.5f;
            sy_gl_material km;
            MUST(sy_gl_material_create(d, &kd, &km));
            const float below[12] = {-1, -40, 1, 1, -40, 1, 1, -40, -1, -1, -40, -1};
            const float up[3] = {0, 1, 0};
            sy_gl_instance ki = gl_test_place(d, quad(d, below, up), km);
            MUST(sy_gl_render(d, &cam, &full, rgba, depth));
            printf("mirror under a green ceiling, a masked instance in the scene %g %g (want 0 4)\n", px(16, 16)[0],
                   px(16, 16)[1]);
            EXPECT_MSG(near_(px(16, 16)[1], 4.0f, 0.03f) && px(16, 16)[0] < 0.01f,
                       "with a masked instance in the scene the mirror lost the ceiling: %g %g (want 0 4)", px(16, 16)[0],
                       px(16, 16)[1]);
            MUST(sy_gl_instance_destroy(d, ki));
        }
        /* the same quad as clear glass (no environment either): its Fresnel reflection and
         * refraction see the ceiling through the probe too */
        sy_gl_material_desc glass;
        sy_gl_material_desc_init(&glass);
        glass.metallic = 0.0f;
        glass.roughness = 0.0f;
        glass.transmission = 1.0f;
        sy_gl_material gl_m;
        MUST(sy_gl_material_create(d, &glass, &gl_m));
        MUST(sy_gl_instance_set_material(d, mi, gl_m));
        MUST(sy_gl_render(d, &cam, &full, rgba, depth));
        printf("glass under a green ceiling %g %g\n", px(16, 16)[0], px(16, 16)[1]);
        EXPECT_MSG(px(16, 16)[1] > 0.1f && px(16, 16)[0] < 0.01f, "glass without an environment sees nothing: %g %g",
                   px(16, 16)[0], px(16, 16)[1]);
        /* glass by its metallic-roughness texture: a metal factor of 1 that the texture's blue channel
         * scales to 0 transmits as the glass above (such materials were drawn without transmission,
         * black where the texture says dielectric: TransmissionTest's "Metallic" row) */
        const float glass_px[2] = {px(16, 16)[0], px(16, 16)[1]};
        static const unsigned char mr_px[2 * 2 * 3] = {0, 255, 0, 0, 255, 0, 0, 255, 0, 0, 255, 0};
        sy_gl_texture_desc mtd = {.width = 2, .height = 2, .channels = 3, .format = SY_GL_TEXEL_UNORM8, .pixels = mr_px};
        sy_gl_texture mr_tex;
        MUST(sy_gl_texture_create(d, &mtd, &mr_tex));
        sy_gl_material_desc tglass = glass;
        tglass.metallic = 1.0f;
        tglass.metallic_roughness_texture.texture = mr_tex;
        sy_gl_material tgl_m;
        MUST(sy_gl_material_create(d, &tglass, &tgl_m));
        MUST(sy_gl_instance_set_material(d, mi, tgl_m));
        MUST(sy_gl_render(d, &cam, &full, rgba, depth));
        printf("glass by its texture %g %g (glass %g %g)\n", px(16, 16)[0], px(16, 16)[1], glass_px[0], glass_px[1]);
        EXPECT_MSG(near_(px(16, 16)[1], glass_px[1], 1e-3f) && near_(px(16, 16)[0], glass_px[0], 1e-3f),
                   "metal factor 1, texture metallic 0, transmission 1: %g %g (want the glass's %g %g)", px(16, 16)[0],
                   px(16, 16)[1], glass_px[0], glass_px[1]);
        MUST(sy_gl_instance_set_material(d, mi, mm));
        MUST(sy_gl_instance_set_visible(d, ci, false));
        MUST(sy_gl_render(d, &cam, &full, rgba, depth));
        EXPECT_MSG(px(16, 16)[1] < 0.01f, "hidden ceiling still reflected: %g", px(16, 16)[1]);
        MUST(sy_gl_instance_destroy(d, ci));
        MUST(sy_gl_instance_destroy(d, mi));
    }

    /* 3. a square emitter (half-size 0.5) 1 above a Lambert floor; camera looking down */
    {
        sy_gl_camera top = {.camera_to_world = {1, 0, 0, 0, 0, 0, -1, 0, 0, 1, 0, 0, 0, 5, 0, 1}, .window = {-0.2f, 0.2f, -0.2f, 0.2f},
                            .near_clip = 0.1f};
        const float floor_q[12] = {-5, 0, 5, 5, 0, 5, 5, 0, -5, -5, 0, -5};
        const float ny[3] = {0, 1, 0};
        sy_gl_instance fl = gl_test_place(d, quad(d, floor_q, ny), lambert(d, 0.5f));
        /* counter-clockwise seen from below: the front faces down */
        sy_gl_area_light al = {.vertices = {{-0.5f, 1, -0.5f}, {0.5f, 1, -0.5f}, {0.5f, 1, 0.5f}, {-0.5f, 1, 0.5f}},
                               .vertex_count = 4, .radiance = {10, 10, 10}};
        MUST(sy_gl_set_area_lights(d, &al, 1));
        MUST(sy_gl_render(d, &top, &full, rgba, depth));
        float want = 0.5f * 10.0f * square_form_factor(0.5f, 1.0f);
        printf("floor under a square light %g (want %g)\n", px(16, 16)[0], want);
        EXPECT_MSG(near_(px(16, 16)[0], want, 0.04f), "floor under a square light: %g (want %g)", px(16, 16)[0], want);
        sy_gl_stats st;
        sy_gl_device_stats(d, &st);
        EXPECT_MSG(st.shadow_maps == 1, "area light shadow maps %u", st.shadow_maps);
        /* reversed winding: the front faces up, the floor is behind it and stays dark */
        sy_gl_area_light up = al;
        memcpy(up.vertices[1], al.vertices[3], sizeof up.vertices[1]);
        memcpy(up.vertices[3], al.vertices[1], sizeof up.vertices[3]);
        MUST(sy_gl_set_area_lights(d, &up, 1));
        MUST(sy_gl_render(d, &top, &full, rgba, depth));
        EXPECT_MSG(px(16, 16)[0] == 0.0f, "one-sided emitter lights its back side: %g", px(16, 16)[0]);
        up.double_sided = true;
        MUST(sy_gl_set_area_lights(d, &up, 1));
        MUST(sy_gl_render(d, &top, &full, rgba, depth));
        EXPECT_MSG(near_(px(16, 16)[0], want, 0.04f), "double-sided emitter: %g (want %g)", px(16, 16)[0], want);
        /* an occluder between light and floor: the centre is in (soft) shadow */
        const float occ_q[12] = {-0.3f, 0.5f, 0.3f, 0.3f, 0.5f, 0.3f, 0.3f, 0.5f, -0.3f, -0.3f, 0.5f, -0.3f};
        sy_gl_instance oc = gl_test_place(d, quad(d, occ_q, ny), lambert(d, 0.5f));
        MUST(sy_gl_set_area_lights(d, &al, 1));
        sy_gl_camera under = top;
        under.camera_to_world[13] = 0.4f;
        under.window[0] = under.window[2] = -2.0f, under.window[1] = under.window[3] = 2.0f;
        MUST(sy_gl_render(d, &under, &full, rgba, depth));
        printf("floor under an occluder %g (unshadowed %g)\n", px(16, 16)[0], want);
        EXPECT_MSG(px(16, 16)[0] < 0.5f * want, "floor under an occluder: %g (unshadowed %g)", px(16, 16)[0], want);
        /* 3b. a point light (intensity 10 at 1 above the floor) instead: its cube shadow map darkens
         * the floor under the occluder; beside the shadow the floor has I cos / d^2 x albedo / pi */
        MUST(sy_gl_set_area_lights(d, NULL, 0));
        sy_gl_light_desc pd = {.type = SY_GL_LIGHT_POINT, .color = {1, 1, 1}, .intensity = 10.0f, .position = {0, 1, 0}};
        sy_gl_light pl;
        MUST(sy_gl_light_create(d, &pd, &pl));
        MUST(sy_gl_render(d, &under, &full, rgba, depth));
        float xs = 0.4f * (-2.0f + 4.0f * 0.5f / N), d2 = xs * xs + 1.0f; /* pixel (0, 16) on the floor */
        float lit = 0.5f / PI_F * 10.0f / d2 / sqrtf(d2);
        sy_gl_device_stats(d, &st);
        printf("point light: floor under the occluder %g, beside it %g (want %g), %u shadow maps\n", px(16, 16)[0],
               px(0, 16)[0], lit, st.shadow_maps);
        EXPECT_MSG(px(16, 16)[0] < 0.02f * 0.5f / PI_F * 10.0f, "point light shines through the occluder: %g", px(16, 16)[0]);
        EXPECT_MSG(near_(px(0, 16)[0], lit, 0.03f), "point light beside the shadow: %g (want %g)", px(0, 16)[0], lit);
        EXPECT_MSG(st.shadow_maps == 6, "a point light's cube shadow: %u shadow maps (want 6 faces)", st.shadow_maps);
        MUST(sy_gl_light_destroy(d, pl));
        MUST(sy_gl_instance_destroy(d, oc));
        MUST(sy_gl_instance_destroy(d, fl));
        /* 4. refused input */
        sy_gl_area_light bad = al;
        bad.radiance[1] = -1.0f;
        EXPECT_MSG(sy_gl_set_area_lights(d, &bad, 1) == SY_GL_ERROR_INVALID_ARGUMENT && strstr(e, "area light 0") &&
                   strstr(e, "radiance[1]"),
                   "negative radiance: %s", e);
        bad = al;
        bad.vertices[2][0] = NAN;
        EXPECT_MSG(sy_gl_set_area_lights(d, &bad, 1) == SY_GL_ERROR_INVALID_ARGUMENT && strstr(e, "vertex 2"),
                   "NaN vertex: %s", e);
        EXPECT_MSG(sy_gl_set_area_lights(d, &al, SY_GL_MAX_AREA_LIGHTS + 1) == SY_GL_ERROR_LIMIT, "cap: %s", e);
    }
    sy_gl_device_destroy(d);
    return sy_check_finish("test_raster_light");
}
