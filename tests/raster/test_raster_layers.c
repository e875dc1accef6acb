/* test_raster_layers.c — the rasterizer's glTF material extensions (sy_gl.h "Layers"), each on
 * against off on a sphere, through the back-end API:
 *  1. KHR_materials_clearcoat: a rough dark base under a directional light gains a sharp coat
 *     highlight (the brightest pixel at least doubles) and leaves the mean within [0.8, 1.5]x;
 *     its texture scales the weight;
 *  2. KHR_materials_specular: specular 0 removes the dielectric highlight of a black base, and a
 *     red specular colour makes the highlight red;
 *  3. KHR_materials_sheen: white sheen on a dark base lit from the camera brightens the rim (grazing
 *     angles) several times and leaves the centre within a few per cent;
 *  3b. KHR_materials_anisotropy: the highlight stretches along the direction (the uv tangent, or a
 *     quarter turn from it);
 *  4. KHR_materials_volume: attenuation tints what a glass sphere shows through it towards the
 *     attenuation colour (green and blue fall against red), and more with a larger thickness;
 *  4b. KHR_materials_iridescence: a grey metal under a white environment takes colours;
 *  4c. KHR_materials_transmission's texture: R 0 shades as transmission 0, R 1 as the factor;
 *  6. an emissive polygon's reflection in the coat (LTC), its sheen at the rim;
 *  5. a material without extensions renders the same bits with a layered material in the frame
 *     (it then draws with the layered shader variant) as without.
 * argv[1] = provider (osmesa default). */
#include "sy_gl.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gl_test.h"
#include "gl_sphere.h"

#define N 64
static float rgba[N * N * 4];
static const sy_gl_render_desc full = {N, N, 0, 0, N, N};
static const float *px(int x, int y) { return rgba + 4 * (y * N + x); }
static float lum(const float *p) { return 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2]; }

/* statistics over the pixels the sphere covers (alpha 1): mean and brightest luminance */
typedef struct stats {
    float mean, max;
    int at; /* the brightest pixel's index */
} stats;
static stats measure(void)
{
    stats s = {0, 0, -1};
    int n = 0;
    for (int i = 0; i < N * N; ++i) {
        if (rgba[4 * i + 3] < 0.999f) continue;
        float l = lum(rgba + 4 * i);
        s.mean += l, n++;
        if (l > s.max) s.max = l, s.at = i;
    }
    s.mean = n ? s.mean / (float)n : 0.0f;
    return s;
}

static sy_gl_device *d;
static sy_gl_instance sphere;
static const sy_gl_camera cam = {.camera_to_world = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1},
                                 .window = {-0.5f, 0.5f, -0.5f, 0.5f}, .near_clip = 0.1f};

/* renders the sphere with material md */
static void render_with(const sy_gl_material_desc *md)
{
    sy_gl_material m;
    MUST(sy_gl_material_create(d, md, &m));
    MUST(sy_gl_instance_set_material(d, sphere, m));
    MUST(sy_gl_render(d, &cam, &full, rgba, NULL));
    MUST(sy_gl_instance_set_material(d, sphere, (sy_gl_material){0}));
    MUST(sy_gl_material_destroy(d, m));
}

static sy_gl_texture constant_env(float v)
{
    enum { W = 16, H = 8 };
    static float t[W * H * 3];
    for (int i = 0; i < W * H * 3; ++i) t[i] = v;
    sy_gl_texture_desc td = {.width = W, .height = H, .channels = 3, .format = SY_GL_TEXEL_FLOAT32, .pixels = t};
    sy_gl_texture h;
    MUST(sy_gl_texture_create(d, &td, &h));
    return h;
}

/* a 2x2 RGBA texture whose R is v (0..255) everywhere */
static sy_gl_texture texture_r(unsigned char v)
{
    const unsigned char texels[16] = {v, 0, 0, 255, v, 0, 0, 255, v, 0, 0, 255, v, 0, 0, 255};
    sy_gl_texture_desc td = {.width = 2, .height = 2, .channels = 4, .format = SY_GL_TEXEL_UNORM8, .pixels = texels};
    sy_gl_texture t;
    MUST(sy_gl_texture_create(d, &td, &t));
    return t;
}

/* render_with, then measure. */
static stats render_measure(const sy_gl_material_desc *md)
{
    render_with(md);
    return measure();
}

/* the highlight's extent through the brightest pixel: pixels above half of it along its row, its column */
static void extent(const stats *s, int *wx, int *wy)
{
    int x0 = s->at % N, y0 = s->at / N;
    *wx = *wy = 0;
    for (int x = 0; x < N; ++x) *wx += lum(px(x, y0)) > 0.5f * s->max;
    for (int y = 0; y < N; ++y) *wy += lum(px(x0, y)) > 0.5f * s->max;
}

/* A layer's weight texture (R x its factor) scales the layer: with a 1 x 1 texture of R = 0 the
 * picture is want[0] (the material without the layer), with R = 255 want[1] (the layer, untextured),
 * brightest and mean within tol (relative). slot picks the texture in the material; the sphere has
 * no uv: every point reads texel (0, 0). */
static void expect_texture_scales(const char *what, const sy_gl_material_desc *with,
                                  sy_gl_texture_ref *(*slot)(sy_gl_material_desc *), const stats want[2], float tol)
{
    for (int k = 0; k < 2; ++k) {
        const unsigned char v = k ? 255 : 0;
        sy_gl_material_desc t = *with;
        sy_gl_texture_ref *ref = slot(&t);
        ref->texture = texture_r(v);
        stats st = render_measure(&t);
        printf("%s texture R %d: brightest %g mean %g (want %g %g)\n", what, v, st.max, st.mean, want[k].max, want[k].mean);
        EXPECT_MSG(fabsf(st.max - want[k].max) <= tol * want[k].max && fabsf(st.mean - want[k].mean) <= tol * want[k].mean,
                   "%s texture %d: brightest %g mean %g (want %g %g)", what, v, st.max, st.mean, want[k].max, want[k].mean);
        MUST(sy_gl_texture_destroy(d, ref->texture));
    }
}
static sy_gl_texture_ref *clearcoat_slot(sy_gl_material_desc *m) { return &m->clearcoat_texture; }
static sy_gl_texture_ref *transmission_slot(sy_gl_material_desc *m) { return &m->transmission_texture; }

static sy_gl_material_desc dielectric(float base, float rough)
{
    sy_gl_material_desc md;
    sy_gl_material_desc_init(&md);
    md.base_color[0] = md.base_color[1] = md.base_color[2] = base;
    md.metallic = 0.0f;
    md.roughness = rough;
    return md;
}

int main(int argc, char **argv)
{
    sy_gl_provider prov = SY_GL_PROVIDER_OSMESA;
    if (argc > 1 && !sy_gl_provider_parse(argv[1], &prov)) return 2;
    sy_gl_device_desc dd = {GL_TEST_REPORT, .provider = prov, .msaa = 1, .shadow_map_size = 256};
    MUST(sy_gl_device_create(&dd, &d));
    sy_gl_mesh ball = gl_test_sphere_mesh(d, 64, 0.0f, GL_SPHERE_NORMALS | GL_SPHERE_UV | GL_SPHERE_CCW, NULL);
    sy_gl_instance_desc id = {.mesh = ball, .transform = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, -3.5f, 1}};
    MUST(sy_gl_instance_create(d, &id, &sphere));
    /* a directional light from behind the camera, a little from above and the left */
    sy_gl_light_desc ld = {.type = SY_GL_LIGHT_DIRECTIONAL, .color = {1, 1, 1}, .intensity = 3.0f,
                           .direction = {0.25f, -0.3f, -1.0f}, .no_shadow = true};
    sy_gl_light light;
    MUST(sy_gl_light_create(d, &ld, &light));

    /* 1. clear coat: a highlight under the light */
    sy_gl_material_desc base = dielectric(0.1f, 0.9f), coat = base;
    coat.clearcoat = 1.0f;
    coat.clearcoat_roughness = 0.15f;
    stats s0 = render_measure(&base);
    stats s1 = render_measure(&coat);
    printf("clear coat, directional light: brightest %g -> %g, mean %g -> %g\n", s0.max, s1.max, s0.mean, s1.mean);
    EXPECT_MSG(s0.max > 0.0f && s1.max > 2.0f * s0.max, "the coat adds a highlight: brightest %g -> %g", s0.max, s1.max);
    EXPECT_MSG(s1.mean < 1.5f * s0.mean && s1.mean > 0.8f * s0.mean, "the coat's highlight is small: mean %g -> %g", s0.mean,
               s1.mean);
    /* the clearcoat texture scales the weight (R): 0 leaves the base, 1 the coat */
    expect_texture_scales("clearcoat", &coat, clearcoat_slot, (stats[2]){s0, s1}, 1e-3f);

    /* 2. specular: 0 removes the dielectric highlight; a red specular colour makes it red */
    sy_gl_material_desc black = dielectric(0.0f, 0.3f), nospec = black, red = black;
    nospec.specular = 0.0f;
    red.specular_color[1] = red.specular_color[2] = 0.0f;
    stats b0 = render_measure(&black);
    const float *hp = rgba + 4 * b0.at;
    float white_hl[3] = {hp[0], hp[1], hp[2]};
    stats b1 = render_measure(&nospec);
    render_with(&red);
    const float *rp = rgba + 4 * b0.at;
    printf("specular: brightest %g (specular 0: %g); highlight RGB %g %g %g, red specular colour %g %g %g\n", b0.max, b1.max,
           white_hl[0], white_hl[1], white_hl[2], rp[0], rp[1], rp[2]);
    EXPECT_MSG(b0.max > 0.05f && b1.max < 1e-4f, "specular 0 removes the highlight: %g -> %g", b0.max, b1.max);
    EXPECT_MSG(fabsf(rp[0] - white_hl[0]) <= 0.02f * white_hl[0] && rp[1] < 1e-4f && rp[2] < 1e-4f,
               "a red specular colour: highlight %g %g %g (white %g %g %g)", rp[0], rp[1], rp[2], white_hl[0], white_hl[1],
               white_hl[2]);

    /* anisotropy: the highlight stretches along the direction (the u tangent, horizontal; rotated a
     * quarter turn, vertical) */
    {
        sy_gl_material_desc iso = dielectric(0.0f, 0.25f), an = iso;
        an.anisotropy = 1.0f;
        int w[3][2];
        for (int k = 0; k < 3; ++k) {
            an.anisotropy_rotation = k == 2 ? 1.5707963f : 0.0f;
            stats st = render_measure(k ? &an : &iso);
            extent(&st, &w[k][0], &w[k][1]);
            printf("anisotropy %d: highlight %g, %d x %d pixels\n", k, st.max, w[k][0], w[k][1]);
        }
        EXPECT_MSG(abs(w[0][0] - w[0][1]) <= 2 + w[0][1] / 4, "isotropic highlight %d x %d", w[0][0], w[0][1]);
        EXPECT_MSG(w[1][0] >= 2 * w[1][1] && w[1][0] >= 2 * w[0][0], "anisotropy stretches along u: %d x %d (isotropic %d x %d)",
                   w[1][0], w[1][1], w[0][0], w[0][1]);
        EXPECT_MSG(w[2][1] >= 2 * w[2][0] && w[2][1] >= 2 * w[0][1], "rotated a quarter turn: %d x %d", w[2][0], w[2][1]);
    }

    /* 3. sheen: grazing angles brighten; the centre stays. The light comes from the camera. */
    ld.direction[0] = 0.0f, ld.direction[1] = 0.0f, ld.direction[2] = -1.0f;
    MUST(sy_gl_light_update(d, light, &ld));
    sy_gl_material_desc dark = dielectric(0.05f, 1.0f), sheen = dark;
    dark.specular = sheen.specular = 0.0f;
    sheen.sheen_color[0] = sheen.sheen_color[1] = sheen.sheen_color[2] = 1.0f;
    sheen.sheen_roughness = 0.5f;
    /* the rim: the covered pixel of the middle row furthest right; the centre pixel */
    render_with(&dark);
    int rim = -1;
    for (int x = N / 2; x < N; ++x)
        if (px(x, N / 2)[3] >= 0.999f) rim = x;
    EXPECT_MSG(rim > N / 2 + 4, "the sphere's rim at x = %d", rim);
    if (rim < 1) return sy_check_finish("raster_layers");
    rim -= 1; /* one pixel in: fully covered */
    float rim0 = lum(px(rim, N / 2)), ctr0 = lum(px(N / 2, N / 2));
    render_with(&sheen);
    float rim1 = lum(px(rim, N / 2)), ctr1 = lum(px(N / 2, N / 2));
    printf("sheen: rim %g -> %g, centre %g -> %g\n", rim0, rim1, ctr0, ctr1);
    EXPECT_MSG(rim1 > 3.0f * rim0, "white sheen brightens the rim: %g -> %g", rim0, rim1);
    EXPECT_MSG(ctr1 > 0.85f * ctr0 && ctr1 < 1.15f * ctr0, "sheen leaves the centre: %g -> %g", ctr0, ctr1);

    /* 4. volume: a glass sphere under a constant environment, attenuation towards red */
    MUST(sy_gl_light_destroy(d, light));
    sy_gl_texture env = constant_env(1.0f);
    sy_gl_set_environment(d, env, 1.0f);
    sy_gl_material_desc glass = dielectric(1.0f, 0.0f), tinted = glass, thick = glass;
    glass.transmission = tinted.transmission = thick.transmission = 1.0f;
    tinted.thickness = 0.5f, thick.thickness = 2.0f;
    tinted.attenuation_distance = thick.attenuation_distance = 1.0f;
    float att[3] = {1.0f, 0.3f, 0.3f};
    memcpy(tinted.attenuation_color, att, sizeof att);
    memcpy(thick.attenuation_color, att, sizeof att);
    float c[3][3];
    const sy_gl_material_desc *gl3[3] = {&glass, &tinted, &thick};
    for (int k = 0; k < 3; ++k) {
        render_with(gl3[k]);
        memcpy(c[k], px(N / 2, N / 2), sizeof c[k]);
        printf("volume %d: centre %g %g %g\n", k, c[k][0], c[k][1], c[k][2]);
    }
    EXPECT_MSG(fabsf(c[0][1] - c[0][0]) < 0.02f * c[0][0], "clear glass is grey: %g %g", c[0][0], c[0][1]);
    /* thickness 0.5 at distance 1: 0.3^0.5 = 0.55 of the transmitted green; 2: 0.3^2 = 0.09 */
    float g1 = c[1][1] / c[1][0], g2 = c[2][1] / c[2][0];
    EXPECT_MSG(g1 < 0.8f && g1 > 0.4f, "attenuation tints the glass: green/red %g (want about 0.55 + reflection)", g1);
    EXPECT_MSG(g2 < 0.5f * g1, "a thicker volume is redder: green/red %g (thin %g)", g2, g1);
    EXPECT_MSG(c[1][0] > 0.9f * c[0][0], "red passes: %g (clear %g)", c[1][0], c[0][0]);

    /* iridescence: a grey metal under the white environment takes the film's colours */
    {
        sy_gl_material_desc metal = dielectric(0.5f, 0.2f), film;
        metal.metallic = 1.0f;
        film = metal;
        film.iridescence = 1.0f;
        film.iridescence_ior = 1.33f;
        float spread[2];
        for (int k = 0; k < 2; ++k) {
            render_with(k ? &film : &metal);
            const float *c = px(N / 2, N / 2);
            spread[k] = (fmaxf(c[0], fmaxf(c[1], c[2])) - fminf(c[0], fminf(c[1], c[2]))) / fmaxf(lum(c), 1e-6f);
            printf("iridescence %d: centre %g %g %g\n", k, c[0], c[1], c[2]);
        }
        EXPECT_MSG(spread[0] < 1e-3f && spread[1] > 0.1f, "the film colours the metal: channel spread %g -> %g", spread[0], spread[1]);
    }

    /* 4c. the transmission texture (R x transmission): a dark dielectric sphere under a dim
     * environment and a light from the camera diffuses the light where opaque and lets the
     * environment through where it transmits; texture 0 shades as factor 0, texture 1 as factor 1
     * without a texture (the sphere has no uv: every point reads texel (0, 0)) */
    {
        sy_gl_texture dim = constant_env(0.2f);
        sy_gl_set_environment(d, dim, 1.0f);
        sy_gl_light_desc front = {.type = SY_GL_LIGHT_DIRECTIONAL, .color = {1, 1, 1}, .intensity = 3.0f,
                                  .direction = {0, 0, -1}};
        sy_gl_light fl;
        MUST(sy_gl_light_create(d, &front, &fl));
        sy_gl_material_desc opaque = dielectric(0.5f, 0.3f), clear = opaque;
        clear.transmission = 1.0f;
        stats so = render_measure(&opaque);
        stats sc = render_measure(&clear);
        printf("transmission 0 / 1: mean %g / %g\n", so.mean, sc.mean);
        EXPECT_MSG(so.mean > 1.5f * sc.mean, "an opaque sphere diffuses the light a clear one lets pass: %g vs %g", so.mean,
                   sc.mean);
        expect_texture_scales("transmission", &clear, transmission_slot, (stats[2]){so, sc}, 0.02f);
        MUST(sy_gl_light_destroy(d, fl));
        sy_gl_set_environment(d, env, 1.0f);
        MUST(sy_gl_texture_destroy(d, dim));
    }

    /* 5. a plain material renders the same with a layered one in the frame */
    sy_gl_material_desc plain = dielectric(0.6f, 0.4f);
    render_with(&plain);
    static float ref[N * N * 4];
    memcpy(ref, rgba, sizeof ref);
    sy_gl_material lm;
    MUST(sy_gl_material_create(d, &coat, &lm));
    sy_gl_instance_desc od = {.mesh = ball, .material = lm,
                              .transform = {0.1f, 0, 0, 0, 0, 0.1f, 0, 0, 0, 0, 0.1f, 0, 0, 0, 3.0f, 1}}; /* behind the camera */
    sy_gl_instance other;
    MUST(sy_gl_instance_create(d, &od, &other));
    render_with(&plain);
    double diff = 0.0;
    for (int i = 0; i < N * N * 4; ++i) diff = fmax(diff, fabs((double)rgba[i] - ref[i]));
    printf("plain material with a layered one in the frame: largest difference %g\n", diff);
    EXPECT_MSG(diff <= 1e-5 * 4.0, "a plain material shades as before in the layered variant: %g", diff);
    MUST(sy_gl_instance_destroy(d, other));

    /* 6. the coat under an emissive polygon (LTC): behind the camera, above the axis */
    sy_gl_set_environment(d, (sy_gl_texture){0}, 0.0f);
    sy_gl_area_light al = {.vertices = {{-0.6f, 0.4f, 0.5f}, {0.6f, 0.4f, 0.5f}, {0.6f, 1.6f, 0.5f}, {-0.6f, 1.6f, 0.5f}},
                           .vertex_count = 4, .radiance = {4, 4, 4}, .double_sided = true};
    MUST(sy_gl_set_area_lights(d, &al, 1));
    stats a0 = render_measure(&base);
    stats a1 = render_measure(&coat);
    printf("clear coat under an emissive polygon: brightest %g -> %g, mean %g -> %g\n", a0.max, a1.max, a0.mean, a1.mean);
    EXPECT_MSG(a0.max > 0.0f && a1.max > 2.0f * a0.max, "the coat reflects the polygon: brightest %g -> %g", a0.max, a1.max);
    /* ... and the sheen brightens the rim under it */
    render_with(&dark);
    float arim0 = lum(px(rim, N / 2)), actr0 = lum(px(N / 2, N / 2));
    render_with(&sheen);
    float arim1 = lum(px(rim, N / 2)), actr1 = lum(px(N / 2, N / 2));
    printf("sheen under an emissive polygon: rim %g -> %g, centre %g -> %g\n", arim0, arim1, actr0, actr1);
    /* the polygon's sheen is a wide lobe of albedo E(n.v) (sy_gl_shaders_layers.c): the rim gains
     * several times what the centre gains */
    EXPECT_MSG(arim1 > 3.0f * arim0 && arim1 / arim0 > 2.0f * (actr1 / actr0), "sheen under a polygon: rim %g -> %g, centre %g -> %g",
               arim0, arim1, actr0, actr1);

    sy_gl_device_destroy(d);
    return sy_check_finish("raster_layers");
}
