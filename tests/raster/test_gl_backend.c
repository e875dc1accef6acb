/* test_gl_backend.c — the OpenGL rasterizer back-end alone, through its public API (sy_gl.h):
 * exact emission and linear depth, pixel-centre edges and sub-rectangles, Lambert + directional
 * shadow (an alpha-blended occluder's by its cutoff) and spot falloff against analytic values, sorted premultiplied alpha blending, alpha
 * mask, sRGB textures and downscaling with a warning, upload counters, shader-compile logs and the
 * "no display" error. argv[1] = provider (osmesa default; egl / glfw are skipped with the reason
 * when the machine cannot give such a context). */
#include "sy_gl.h"
#include "sy_gl_shaders.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gl_test.h"

#define N 64
#define PI_F 3.14159265358979f
static int warnings;
static char last_warning[512];
static void on_log(void *u, const char *m)
{
    (void)u;
    warnings++;
    snprintf(last_warning, sizeof last_warning, "%s", m);
}

/* Quads here carry texture coordinates (0,0) (1,0) (1,1) (0,1). */
static sy_gl_mesh quad(sy_gl_device *d, const float *p4 /* 4 corners xyz */, const float n[3])
{
    static const float uv[8] = {0, 0, 1, 0, 1, 1, 0, 1};
    return gl_test_quad(d, p4, n, uv);
}

/* An unlit material showing texture t (white factor). */
static sy_gl_material unlit_textured(sy_gl_device *d, sy_gl_texture t)
{
    sy_gl_material_desc md;
    sy_gl_material_desc_init(&md);
    md.unlit = true;
    md.base_color_texture.texture = t;
    sy_gl_material h;
    MUST(sy_gl_material_create(d, &md, &h));
    return h;
}

static sy_gl_material material(sy_gl_device *d, float r, float g, float b, float a, bool unlit, sy_gl_alpha_mode mode)
{
    sy_gl_material_desc md;
    sy_gl_material_desc_init(&md);
    md.base_color[0] = r, md.base_color[1] = g, md.base_color[2] = b, md.base_color[3] = a;
    md.unlit = unlit;
    md.alpha_mode = mode;
    md.metallic = 0.0f;
    md.specular = 0.0f; /* pure Lambert */
    sy_gl_material h;
    MUST(sy_gl_material_create(d, &md, &h));
    return h;
}

static float rgba[N * N * 4], depth[N * N];
static const sy_gl_render_desc full = {N, N, 0, 0, N, N};

static void render(sy_gl_device *d, const sy_gl_camera *cam) { MUST(sy_gl_render(d, cam, &full, rgba, depth)); }
static const float *px(int x, int y) { return rgba + 4 * (y * N + x); }

static bool near_(float a, float b, float tol) { return fabsf(a - b) <= tol * fmaxf(1.0f, fabsf(b)); }

int main(int argc, char **argv)
{
    sy_gl_provider prov = SY_GL_PROVIDER_OSMESA;
    if (argc > 1 && !sy_gl_provider_parse(argv[1], &prov)) {
        fprintf(stderr, "unknown provider %s\n", argv[1]);
        return 2;
    }
    sy_gl_device *d;
    sy_gl_device_desc dd = {GL_TEST_REPORT, .provider = prov, .msaa = 1, .shadow_map_size = 1024, .max_texture_size = 4, .log = on_log};
    sy_gl_result cr = sy_gl_device_create(&dd, &d);
    if (cr == SY_GL_ERROR_NO_CONTEXT && prov != SY_GL_PROVIDER_OSMESA) {
        printf("SKIP: no %s context on this machine: %s\n", sy_gl_provider_name(prov), e);
        return 77;
    }
    MUST(cr);
    printf("%s\n", sy_gl_device_info(d));

    /* 1. emission is radiance, depth is the axial distance; edges at pixel centres */
    sy_gl_camera cam = {.camera_to_world = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}, .window = {-1, 1, -1, 1}, .near_clip = 0.1f};
    /* x in [-0.9, 1.3], y in [-0.6, 1.2] at z = -3 */
    const float q1[12] = {-0.9f, -0.6f, -3, 1.3f, -0.6f, -3, 1.3f, 1.2f, -3, -0.9f, 1.2f, -3};
    const float nz[3] = {0, 0, 1};
    sy_gl_mesh mq = quad(d, q1, nz);
    sy_gl_material_desc emd;
    sy_gl_material_desc_init(&emd);
    emd.emissive[0] = 17, emd.emissive[1] = 12, emd.emissive[2] = 4;
    sy_gl_material em;
    MUST(sy_gl_material_create(d, &emd, &em));
    sy_gl_instance iq = gl_test_place(d, mq, em);
    render(d, &cam);
    const float *c = px(30, 30);
    EXPECT_MSG(c[0] == 17.0f && c[1] == 12.0f && c[2] == 4.0f && c[3] == 1.0f, "emitter pixel %g %g %g %g", c[0], c[1], c[2], c[3]);
    EXPECT_MSG(near_(depth[30 * N + 30], 3.0f, 1e-5f), "depth %g (want 3)", depth[30 * N + 30]);
    EXPECT_MSG(px(0, 0)[3] == 0.0f && isinf(depth[0]) && depth[0] > 0, "background alpha %g depth %g", px(0, 0)[3], depth[0]);
    /* x tangent [-0.3, 0.4333] -> columns 22..45; y tangent [-0.2, 0.4] -> rows 19..37 */
    EXPECT_MSG(px(21, 30)[3] == 0.0f && px(22, 30)[3] == 1.0f && px(45, 30)[3] == 1.0f && px(46, 30)[3] == 0.0f,
               "column edges %g %g %g %g", px(21, 30)[3], px(22, 30)[3], px(45, 30)[3], px(46, 30)[3]);
    EXPECT_MSG(px(30, 18)[3] == 0.0f && px(30, 19)[3] == 1.0f && px(30, 37)[3] == 1.0f && px(30, 38)[3] == 0.0f,
               "row edges %g %g %g %g", px(30, 18)[3], px(30, 19)[3], px(30, 37)[3], px(30, 38)[3]);

    /* 2. a sub-rectangle is exactly the crop of the full image */
    {
        static float sub[40 * 30 * 4], subd[40 * 30];
        sy_gl_render_desc rd = {N, N, 16, 8, 40, 30};
        MUST(sy_gl_render(d, &cam, &rd, sub, subd));
        int bad = 0;
        for (int y = 0; y < 30; ++y)
            for (int x = 0; x < 40; ++x) {
                const float *a = sub + 4 * (y * 40 + x), *b = px(16 + x, 8 + y);
                if (a[3] != b[3] || fabsf(a[0] - b[0]) > 1e-5f) bad++;
            }
        EXPECT_MSG(bad == 0, "%d sub-rectangle pixels differ from the full image", bad);
    }

    /* 3. transform only: no vertex data uploaded, one model-matrix update */
    sy_gl_stats st;
    sy_gl_device_stats(d, &st);
    EXPECT_MSG(st.total.vertex_buffer_uploads == 2, "vertex uploads so far %llu (one interleaved vertex buffer + indices)",
               (unsigned long long)st.total.vertex_buffer_uploads);
    /* 4 vertices of a float position, a normal packed into 4 bytes and a uv in [0, 1] in two 16-bit
     * numbers, then 6 indices (3 floats of normal and 2 of uv made it 152) */
    EXPECT_MSG(st.total.vertex_bytes == 4u * (12u + 4u + 4u) + 6u * 4u, "vertex bytes so far %llu (want 104)",
               (unsigned long long)st.total.vertex_bytes);
    float moved[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0.1f, 0, 0, 1};
    MUST(sy_gl_instance_set_transform(d, iq, moved));
    render(d, &cam);
    sy_gl_device_stats(d, &st);
    EXPECT_MSG(st.frame.vertex_buffer_uploads == 0 && st.frame.vertex_bytes == 0 && st.frame.texture_uploads == 0,
               "transform-only frame uploaded %llu vertex buffers", (unsigned long long)st.frame.vertex_buffer_uploads);
    EXPECT_MSG(st.frame.model_matrix_updates == 1, "model matrix updates %llu", (unsigned long long)st.frame.model_matrix_updates);
    EXPECT_MSG(px(22, 30)[3] == 0.0f && px(46, 30)[3] == 1.0f, "the quad did not move right");
    MUST(sy_gl_material_update(d, em, &emd));
    render(d, &cam);
    sy_gl_device_stats(d, &st);
    EXPECT_MSG(st.frame.uniform_buffer_uploads == 1 && st.frame.vertex_buffer_uploads == 0, "material change: %llu UBO, %llu VBO uploads",
               (unsigned long long)st.frame.uniform_buffer_uploads, (unsigned long long)st.frame.vertex_buffer_uploads);
    MUST(sy_gl_instance_destroy(d, iq));

    /* 4. sorted, premultiplied alpha blending (nearest created first), and an alpha-masked cut-out */
    {
        const float near_q[12] = {-1, -1, -2, 1, -1, -2, 1, 1, -2, -1, 1, -2};
        const float far_q[12] = {-1, -1, -4, 1, -1, -4, 1, 1, -4, -1, 1, -4};
        sy_gl_mesh mn = quad(d, near_q, nz), mf = quad(d, far_q, nz);
        sy_gl_instance a = gl_test_place(d, mn, material(d, 1, 0, 0, 0.5f, true, SY_GL_ALPHA_BLEND));
        sy_gl_instance b = gl_test_place(d, mf, material(d, 0, 0, 1, 0.5f, true, SY_GL_ALPHA_BLEND));
        render(d, &cam);
        c = px(32, 32);
        EXPECT_MSG(near_(c[0], 0.5f, 1e-5f) && c[1] == 0.0f && near_(c[2], 0.25f, 1e-5f) && near_(c[3], 0.75f, 1e-5f),
                   "blend %g %g %g %g (want 0.5 0 0.25 0.75)", c[0], c[1], c[2], c[3]);
        EXPECT_MSG(near_(depth[32 * N + 32], 2.0f, 1e-5f), "blend depth %g (want the nearest surface, 2)", depth[32 * N + 32]);
        MUST(sy_gl_instance_destroy(d, a));
        MUST(sy_gl_instance_destroy(d, b));
        sy_gl_instance m = gl_test_place(d, mn, material(d, 1, 1, 1, 0.3f, true, SY_GL_ALPHA_MASK));
        render(d, &cam);
        EXPECT_MSG(px(32, 32)[3] == 0.0f && isinf(depth[32 * N + 32]), "masked-out quad is visible (alpha %g)", px(32, 32)[3]);
        MUST(sy_gl_instance_destroy(d, m));
    }

    /* 4b. depth precision under a tiny near plane: TransmissionTest's camera has znear 5.6e-5 and
     * its labels' two faces lie 1.6e-3 apart 1.5 units away; the back face showed through in
     * stripes. Two tilted quads that close: only the front one (red) may show */
    {
        const float dz = 1.6e-3f;
        float fq[12] = {-1, -1, -1.2f, 1, -1, -1.2f, 1, 1, -1.8f, -1, 1, -1.8f}, bq[12];
        memcpy(bq, fq, sizeof bq);
        for (int k = 0; k < 4; ++k) bq[3 * k + 2] -= dz;
        sy_gl_mesh mf = quad(d, fq, nz), mb = quad(d, bq, nz);
        sy_gl_material red = material(d, 1, 0, 0, 1, true, SY_GL_ALPHA_OPAQUE), blue = material(d, 0, 0, 1, 1, true, SY_GL_ALPHA_OPAQUE);
        sy_gl_instance b = gl_test_place(d, mb, blue), f = gl_test_place(d, mf, red); /* the back one first */
        sy_gl_camera tiny = cam;
        tiny.near_clip = 5.6e-5f;
        tiny.far_clip = 0.0f;
        render(d, &tiny);
        int covered = 0, behind = 0;
        for (int i = 0; i < N * N; ++i) {
            covered += rgba[4 * i + 3] > 0.0f;
            behind += rgba[4 * i + 2] > rgba[4 * i];
        }
        printf("near 5.6e-5: %d pixels covered, %d show the face 1.6e-3 behind\n", covered, behind);
        EXPECT_MSG(covered > N * N / 4 && behind == 0, "%d of %d covered pixels show the back face", behind, covered);
        MUST(sy_gl_instance_destroy(d, f));
        MUST(sy_gl_instance_destroy(d, b));
    }

    /* 4c. picks (sy_gl_pick): the nearest instance and its triangle at each pixel centre, computed
     * by hand (near quad at z = -2 over tangents |t| < 0.5, far one at z = -4 over |t| < 0.25,
     * triangle 0 below the diagonal); an alpha-masked quad in front where its alpha is under the
     * cutoff is seen through, one above it is hit; a pixel outside the image is refused */
    {
        const float near_q[12] = {-1, -1, -2, 1, -1, -2, 1, 1, -2, -1, 1, -2};
        const float far_q[12] = {-1, -1, -4, 1, -1, -4, 1, 1, -4, -1, 1, -4};
        const float front_q[12] = {-9, -9, -1, 9, -9, -1, 9, 9, -1, -9, 9, -1};
        sy_gl_mesh mn = quad(d, near_q, nz), mf = quad(d, far_q, nz), mfr = quad(d, front_q, nz);
        sy_gl_material opaque = material(d, 1, 1, 1, 1, true, SY_GL_ALPHA_OPAQUE);
        sy_gl_instance in_n = gl_test_place(d, mn, opaque), in_f = gl_test_place(d, mf, opaque);
        sy_gl_instance cut = gl_test_place(d, mfr, material(d, 1, 1, 1, 0.3f, true, SY_GL_ALPHA_MASK));
        int wrong = 0, hits = 0, tested = 0;
        for (int y = 0; y < N; ++y)
            for (int x = 0; x < N; ++x) {
                float tx = -1.0f + 2.0f * ((float)x + 0.5f) / N, ty = 1.0f - 2.0f * ((float)y + 0.5f) / N;
                /* centres within 1e-3 of an edge or the diagonal are left out (either side is right) */
                if (fabsf(fabsf(tx) - 0.5f) < 1e-3f || fabsf(fabsf(ty) - 0.5f) < 1e-3f || fabsf(tx - ty) < 1e-3f ||
                    fabsf(fabsf(tx) - 0.25f) < 1e-3f || fabsf(fabsf(ty) - 0.25f) < 1e-3f)
                    continue;
                uint32_t want = 0, tri = 0;
                if (fabsf(tx) < 0.5f && fabsf(ty) < 0.5f) want = in_n.id, tri = tx >= ty ? 0 : 1;
                else if (fabsf(tx) < 0.25f && fabsf(ty) < 0.25f) want = in_f.id, tri = tx >= ty ? 0 : 1;
                sy_gl_pick_hit ph;
                MUST(sy_gl_pick(d, &cam, N, N, (uint32_t)x, (uint32_t)y, &ph));
                wrong += ph.instance.id != want || (want && ph.triangle != tri);
                hits += want != 0;
                tested++;
            }
        EXPECT_MSG(wrong == 0 && hits > 100, "%d of %d picks wrong (%d hits expected)", wrong, tested, hits);
        MUST(sy_gl_instance_destroy(d, cut));
        cut = gl_test_place(d, mfr, material(d, 1, 1, 1, 0.8f, true, SY_GL_ALPHA_MASK));
        sy_gl_pick_hit ph;
        MUST(sy_gl_pick(d, &cam, N, N, N / 2, N / 2, &ph));
        EXPECT_MSG(ph.instance.id == cut.id, "a masked quad above its cutoff is not picked (%#x)", ph.instance.id);
        EXPECT_MSG(sy_gl_pick(d, &cam, N, N, N, 0, &ph) == SY_GL_ERROR_INVALID_ARGUMENT && ph.instance.id == 0 &&
                       strstr(e, "outside"), "a pick outside the image: %s", e);
        MUST(sy_gl_instance_destroy(d, cut));
        MUST(sy_gl_instance_destroy(d, in_n));
        MUST(sy_gl_instance_destroy(d, in_f));
    }


    {
        unsigned char tex[8 * 8 * 3];
        memset(tex, 188, sizeof tex);
        sy_gl_texture_desc td = {.width = 8, .height = 8, .channels = 3, .format = SY_GL_TEXEL_UNORM8_SRGB, .pixels = tex};
        sy_gl_texture t;
        int w0 = warnings;
        MUST(sy_gl_texture_create(d, &td, &t));
        EXPECT_MSG(warnings == w0 + 1 && strstr(last_warning, "downscaled to 4x4"), "warning: '%s'", last_warning);
        sy_gl_material mt = unlit_textured(d, t);
        const float near_q[12] = {-1, -1, -2, 1, -1, -2, 1, 1, -2, -1, 1, -2};
        sy_gl_instance it = gl_test_place(d, quad(d, near_q, nz), mt);
        render(d, &cam);
        float want = powf((188.0f / 255.0f + 0.055f) / 1.055f, 2.4f);
        EXPECT_MSG(near_(px(32, 32)[0], want, 0.01f), "sRGB texel %g (want %g)", px(32, 32)[0], want);
        MUST(sy_gl_instance_destroy(d, it));
        sy_gl_stats s2;
        sy_gl_device_stats(d, &s2);
        EXPECT_MSG(s2.total.texture_uploads == 1, "texture uploads %llu", (unsigned long long)s2.total.texture_uploads);
    }

    /* 5b. the mipmap chain of an sRGB texture is filtered in linear light: a 4x4 black-and-white
     * checker drawn into one pixel samples its 1x1 level, the linear mean 0.5 (sRGB-space averaging
     * would give 0.21) */
    {
        unsigned char tex[4 * 4];
        for (int i = 0; i < 16; ++i) tex[i] = ((i & 1) ^ ((i >> 2) & 1)) ? 255 : 0;
        sy_gl_texture_desc td = {.width = 4, .height = 4, .channels = 1, .format = SY_GL_TEXEL_UNORM8_SRGB, .pixels = tex};
        sy_gl_texture t;
        MUST(sy_gl_texture_create(d, &td, &t));
        sy_gl_material mt = unlit_textured(d, t);
        /* one pixel: 1/32 of the view's width of 2 at depth 1, i.e. 0.0625 at depth 2 */
        const float one_px[12] = {0, 0, -2, 0.0625f, 0, -2, 0.0625f, 0.0625f, -2, 0, 0.0625f, -2};
        sy_gl_instance it = gl_test_place(d, quad(d, one_px, nz), mt);
        render(d, &cam);
        int covered = 0;
        float v = 0.0f;
        for (int i = 0; i < N * N; ++i)
            if (rgba[4 * i + 3] > 0.0f) covered++, v = rgba[4 * i];
        EXPECT_MSG(covered == 1 && near_(v, 0.5f, 0.01f), "checker in one pixel: %d pixels covered, value %g (want 1, 0.5)",
                   covered, v);
        MUST(sy_gl_instance_destroy(d, it));
    }

    /* 6. Lambert under a directional light, with a shadow from an occluder; then a spot light */
    {
        sy_gl_camera top = {.camera_to_world = {1, 0, 0, 0, 0, 0, -1, 0, 0, 1, 0, 0, 0, 5, 0, 1}, .window = {-0.6f, 0.6f, -0.6f, 0.6f}, .near_clip = 0.1f};
        const float floor_q[12] = {-5, 0, 5, 5, 0, 5, 5, 0, -5, -5, 0, -5};
        const float occ_q[12] = {-0.5f, 1, 0.5f, 0.5f, 1, 0.5f, 0.5f, 1, -0.5f, -0.5f, 1, -0.5f};
        const float ny[3] = {0, 1, 0};
        sy_gl_material grey = material(d, 0.5f, 0.5f, 0.5f, 1, false, SY_GL_ALPHA_OPAQUE);
        sy_gl_instance fl = gl_test_place(d, quad(d, floor_q, ny), grey);
        sy_gl_instance oc = gl_test_place(d, quad(d, occ_q, ny), grey);
        sy_gl_light_desc ld = {.type = SY_GL_LIGHT_DIRECTIONAL, .color = {1, 1, 1}, .intensity = 3, .direction = {1, -1, 0}};
        sy_gl_light l;
        MUST(sy_gl_light_create(d, &ld, &l));
        render(d, &top);
        float lit = 3.0f * sqrtf(0.5f) * 0.5f / PI_F;
        /* world x = -2 -> column 10, x = +1 -> column 42 (row 31 ~ z = 0) */
        EXPECT_MSG(near_(px(10, 31)[0], lit, 0.01f), "lit floor %g (want %g)", px(10, 31)[0], lit);
        EXPECT_MSG(px(42, 31)[0] < 0.05f * lit, "shadowed floor %g (lit %g)", px(42, 31)[0], lit);
        sy_gl_device_stats(d, &st);
        EXPECT_MSG(st.shadow_maps == 1, "shadow maps %u", st.shadow_maps);
        /* an alpha-blended occluder blocks where its opacity reaches the cutoff (0.5), as the ray
         * tracers' shadow rays threshold it: opacity 0.3 casts no shadow, 0.7 does (0.3 cast one
         * while non-masked materials had cutoff 0 in their block) */
        for (int k = 0; k < 2; ++k) {
            MUST(sy_gl_instance_set_material(d, oc, material(d, 0.5f, 0.5f, 0.5f, k ? 0.7f : 0.3f, false, SY_GL_ALPHA_BLEND)));
            render(d, &top);
            EXPECT_MSG(k ? px(42, 31)[0] < 0.05f * lit : near_(px(42, 31)[0], lit, 0.01f),
                       "floor under a blended occluder of opacity %g: %g (lit %g)", k ? 0.7 : 0.3, px(42, 31)[0], lit);
        }
        MUST(sy_gl_light_destroy(d, l));
        MUST(sy_gl_instance_destroy(d, oc));
        /* spot at (0, 2, 0) pointing down: I / d^2 under it, zero beyond the outer cone */
        sy_gl_light_desc sd = {.type = SY_GL_LIGHT_SPOT, .color = {1, 1, 1}, .intensity = 10, .position = {0, 2, 0},
                               .direction = {0, -1, 0}, .inner_cone_angle = 0.2f, .outer_cone_angle = 0.4f};
        MUST(sy_gl_light_create(d, &sd, &l));
        render(d, &top);
        /* pixel (31, 31) centre: x = z = -0.5/64*1.2*5 */
        float x = (31.5f / N * 1.2f - 0.6f) * 5.0f, r2 = 2 * x * x, dist2 = r2 + 4.0f, cosl = 2.0f / sqrtf(dist2);
        float want = 10.0f / dist2 * cosl * 0.5f / PI_F;
        EXPECT_MSG(near_(px(31, 31)[0], want, 0.01f), "spot centre %g (want %g)", px(31, 31)[0], want);
        /* world x = 1.2: angle atan(0.6) = 0.54 > outer 0.4 -> dark; column (1.2/5 + 0.6)/1.2*64 = 44.8 */
        EXPECT_MSG(px(44, 31)[0] == 0.0f && px(44, 31)[3] == 1.0f, "outside the cone %g", px(44, 31)[0]);
        /* between inner and outer: x = 0.6 (angle 0.29) -> column 38.4 => pixel 38 centre */
        float x2 = (38.5f / N * 1.2f - 0.6f) * 5.0f, z2 = x;
        float dd2 = x2 * x2 + z2 * z2 + 4.0f, dl = sqrtf(dd2), cd = 2.0f / dl;
        float ci = cosf(0.2f), co = cosf(0.4f), s = fminf(fmaxf((cd - co) / (ci - co), 0.0f), 1.0f);
        float want2 = 10.0f / dd2 * s * s * cd * 0.5f / PI_F;
        EXPECT_MSG(near_(px(38, 31)[0], want2, 0.02f), "spot penumbra %g (want %g)", px(38, 31)[0], want2);
        MUST(sy_gl_light_destroy(d, l));
        MUST(sy_gl_instance_destroy(d, fl));
        /* a failure is reported once through the desc's error callback (into e) and kept as the
         * device's last message */
        e[0] = '\0';
        EXPECT_MSG(sy_gl_instance_destroy(d, fl) == SY_GL_ERROR_INVALID_HANDLE && strstr(e, "stale handle") &&
                       strcmp(e, sy_gl_device_error(d)) == 0,
                   "stale instance: '%s' / '%s'", e, sy_gl_device_error(d));
        /* no device: refused, never dereferenced */
        sy_gl_material_desc nd;
        sy_gl_material_desc_init(&nd);
        sy_gl_material nm = {0};
        EXPECT(sy_gl_material_create(NULL, &nd, &nm) == SY_GL_ERROR_INVALID_ARGUMENT && nm.id == 0);
        EXPECT(sy_gl_material_update(NULL, em, &nd) == SY_GL_ERROR_INVALID_HANDLE);
        EXPECT(sy_gl_material_destroy(NULL, em) == SY_GL_ERROR_INVALID_HANDLE);
        EXPECT(sy_gl_light_destroy(NULL, l) == SY_GL_ERROR_INVALID_HANDLE);
    }
    sy_gl_device_destroy(d);

    /* 7. MSAA: interior pixels stay exact, edge pixels get partial coverage, background stays empty */
    {
        sy_gl_device_desc md = {GL_TEST_REPORT, .provider = prov, .msaa = 4, .shadow_map_size = 256};
        MUST(sy_gl_device_create(&md, &d));
        sy_gl_mesh m = quad(d, q1, nz);
        MUST(sy_gl_material_create(d, &emd, &em));
        gl_test_place(d, m, em);
        render(d, &cam);
        c = px(30, 30);
        EXPECT_MSG(c[0] == 17.0f && c[1] == 12.0f && c[2] == 4.0f && c[3] == 1.0f, "MSAA interior %g %g %g %g", c[0], c[1], c[2], c[3]);
        EXPECT_MSG(near_(depth[30 * N + 30], 3.0f, 1e-5f), "MSAA depth %g", depth[30 * N + 30]);
        /* column 22 is partly covered (the edge crosses it at 22.4) */
        float a22 = px(22, 30)[3];
        EXPECT_MSG(a22 > 0.0f && a22 < 1.0f && px(20, 30)[3] == 0.0f && isinf(depth[30 * N + 20]), "MSAA edge alpha %g", a22);
        EXPECT_MSG(near_(px(22, 30)[0], 17.0f * a22, 1e-5f), "MSAA edge is not premultiplied: %g vs alpha %g", px(22, 30)[0], a22);
        sy_gl_device_stats(d, &st);
        EXPECT_MSG(st.msaa_samples == 4, "msaa samples %u", st.msaa_samples);
        sy_gl_device_destroy(d);
    }

    /* 7b. a draw of more triangles than the throttle's chunk (THROTTLE_TRIANGLES, 65536: llvmpipe's
     * draws are cut into chunks with fences between) is drawn whole: a 300 x 300 grid at z = -3
     * past every edge of the view, 180,000 triangles row after row, so a lost or repeated chunk
     * leaves a band of the image empty; indexed, then as a triangle list. Levels of detail off. */
    {
        enum { G = 300 };
        sy_gl_device_desc gd = {GL_TEST_REPORT, .provider = prov, .msaa = 1, .shadow_map_size = 256};
        MUST(sy_gl_device_create(&gd, &d));
        sy_gl_set_lod(d, 0.0f);
        MUST(sy_gl_material_create(d, &emd, &em));
        float *pos = malloc(sizeof *pos * 3u * (G + 1u) * (G + 1u)), *flat = malloc(sizeof *flat * 18u * G * G);
        uint32_t *idx = malloc(sizeof *idx * 6u * G * G);
        if (!pos || !flat || !idx) {
            fprintf(stderr, "test_gl_backend: out of memory\n");
            return 1;
        }
        for (uint32_t y = 0; y <= G; ++y)
            for (uint32_t x = 0; x <= G; ++x) {
                float *p = pos + 3u * (y * (G + 1u) + x);
                p[0] = -3.3f + 6.6f * (float)x / G, p[1] = -3.3f + 6.6f * (float)y / G, p[2] = -3.0f;
            }
        for (uint32_t y = 0; y < G; ++y)
            for (uint32_t x = 0; x < G; ++x) {
                const uint32_t v = y * (G + 1u) + x, q[6] = {v, v + 1u, v + G + 2u, v, v + G + 2u, v + G + 1u};
                for (int k = 0; k < 6; ++k) {
                    idx[6u * (y * G + x) + (uint32_t)k] = q[k];
                    memcpy(flat + 3u * (6u * (y * G + x) + (uint32_t)k), pos + 3u * q[k], 3 * sizeof(float));
                }
            }
        for (int indexed = 1; indexed >= 0; --indexed) {
            sy_gl_mesh_desc gm = {.positions = indexed ? pos : flat, .indices = indexed ? idx : NULL,
                                  .vertex_count = indexed ? (G + 1u) * (G + 1u) : 6u * G * G, .triangle_count = 2u * G * G};
            sy_gl_mesh m;
            MUST(sy_gl_mesh_create(d, &gm, &m));
            sy_gl_instance in = gl_test_place(d, m, em);
            render(d, &cam);
            int empty = 0, first = -1;
            for (int i = 0; i < N * N; ++i)
                if (rgba[4 * i + 3] != 1.0f || rgba[4 * i] != 17.0f || !near_(depth[i], 3.0f, 1e-5f)) empty += first < 0 ? (first = i, 1) : 1;
            sy_gl_device_stats(d, &st);
            EXPECT_MSG(empty == 0 && st.triangles_drawn == 2u * G * G,
                       "%s grid of %u triangles: %d of %d pixels not covered (the first at row %d), %llu triangles drawn",
                       indexed ? "indexed" : "unindexed", 2u * G * G, empty, N * N, first / N, (unsigned long long)st.triangles_drawn);
            MUST(sy_gl_instance_destroy(d, in));
            MUST(sy_gl_mesh_destroy(d, m));
        }
        /* an update of a mesh whose vertex buffer is in the order of its levels (90,601 vertices:
         * more than LOD_REORDER_VERTICES; its order is freed after the upload and read back from
         * the index buffer by the first update): the grid tilted and moved as an update and as a
         * new mesh give the same depth at every pixel */
        static float upd_depth[N * N];
        for (int fresh = 0; fresh < 2; ++fresh) {
            sy_gl_mesh_desc gm = {.positions = pos, .indices = idx, .vertex_count = (G + 1u) * (G + 1u), .triangle_count = 2u * G * G};
            sy_gl_mesh m;
            if (fresh)
                for (uint32_t v = 0; v < gm.vertex_count; ++v) pos[3u * v + 2] = -3.0f - 0.05f * pos[3u * v] + 0.03f * pos[3u * v + 1];
            MUST(sy_gl_mesh_create(d, &gm, &m));
            if (!fresh) {
                /* refused before the order is read back: no indices, an index out of range, other
                 * indices than the mesh's */
                sy_gl_mesh_desc bad = gm;
                bad.indices = NULL;
                EXPECT_MSG(sy_gl_mesh_update(d, m, &bad) == SY_GL_ERROR_INVALID_ARGUMENT && strstr(e, "indices are required"),
                           "update without indices: %s", e);
                const uint32_t keep = idx[0];
                idx[0] = gm.vertex_count + 7u;
                EXPECT_MSG(sy_gl_mesh_update(d, m, &gm) == SY_GL_ERROR_INVALID_ARGUMENT && strstr(e, "not the ones it was made with"),
                           "update with an index out of range: %s", e);
                idx[0] = keep ^ 1u;
                EXPECT_MSG(sy_gl_mesh_update(d, m, &gm) == SY_GL_ERROR_INVALID_ARGUMENT && strstr(e, "not the ones it was made with"),
                           "update with other indices: %s", e);
                idx[0] = keep;
                for (uint32_t v = 0; v < gm.vertex_count; ++v) pos[3u * v + 2] = -3.0f - 0.05f * pos[3u * v] + 0.03f * pos[3u * v + 1];
                MUST(sy_gl_mesh_update(d, m, &gm));
                for (uint32_t v = 0; v < gm.vertex_count; ++v) pos[3u * v + 2] = -3.0f;
            }
            sy_gl_instance in = gl_test_place(d, m, em);
            render(d, &cam);
            if (!fresh) memcpy(upd_depth, depth, sizeof depth);
            MUST(sy_gl_instance_destroy(d, in));
            MUST(sy_gl_mesh_destroy(d, m));
        }
        int differ = 0;
        for (int i = 0; i < N * N; ++i) differ += upd_depth[i] != depth[i] || !(depth[i] > 2.0f && depth[i] < 4.0f);
        EXPECT_MSG(differ == 0, "the updated grid's depth differs from the new grid's at %d of %d pixels", differ, N * N);
        free(pos), free(flat), free(idx);

        /* 7c. a uv set beyond [0, 1] stays in floats (8 bytes a vertex, not 4), and a mesh's first
         * update turns its packed buffer to floats: a quad updated from uv 0..1 to 0..2 (a
         * repeating 4x4 texture of 16 values) shows what the same quad made with 0..2 shows, at
         * every pixel */
        unsigned char tex[4 * 4 * 3];
        for (int i = 0; i < 48; ++i) tex[i] = (unsigned char)(i * 5);
        sy_gl_texture_desc td = {.width = 4, .height = 4, .channels = 3, .format = SY_GL_TEXEL_UNORM8, .pixels = tex};
        sy_gl_texture t;
        MUST(sy_gl_texture_create(d, &td, &t));
        sy_gl_material mt = unlit_textured(d, t);
        const float near_q[12] = {-1, -1, -2, 1, -1, -2, 1, 1, -2, -1, 1, -2};
        static const float uv1[8] = {0, 0, 1, 0, 1, 1, 0, 1}, uv2[8] = {0, 0, 2, 0, 2, 2, 0, 2};
        static float upd_rgba[N * N * 4];
        for (int fresh = 0; fresh < 2; ++fresh) {
            sy_gl_device_stats(d, &st);
            const uint64_t before = st.total.vertex_bytes;
            sy_gl_mesh m = gl_test_quad(d, near_q, nz, fresh ? uv2 : uv1);
            sy_gl_device_stats(d, &st);
            const uint64_t want = 4u * (12u + 4u + (fresh ? 8u : 4u)) + 6u * 4u;
            EXPECT_MSG(st.total.vertex_bytes - before == want, "a quad with uv 0..%d: %llu vertex bytes (want %llu)", fresh ? 2 : 1,
                       (unsigned long long)(st.total.vertex_bytes - before), (unsigned long long)want);
            if (!fresh) {
                static const uint32_t qi[6] = {0, 1, 2, 0, 2, 3};
                float qn[12];
                for (int i = 0; i < 4; ++i) memcpy(qn + 3 * i, nz, sizeof nz);
                sy_gl_mesh_desc ud = {.positions = near_q, .normals = qn, .uv = {uv2, NULL}, .indices = qi, .vertex_count = 4, .triangle_count = 2};
                MUST(sy_gl_mesh_update(d, m, &ud));
            }
            sy_gl_instance in = gl_test_place(d, m, mt);
            render(d, &cam);
            if (!fresh) memcpy(upd_rgba, rgba, sizeof rgba);
            MUST(sy_gl_instance_destroy(d, in));
            MUST(sy_gl_mesh_destroy(d, m));
        }
        int texel_differ = 0, textured = 0;
        for (int i = 0; i < N * N; ++i) {
            texel_differ += memcmp(upd_rgba + 4 * i, rgba + 4 * i, 4 * sizeof(float)) != 0;
            textured += rgba[4 * i + 3] == 1.0f;
        }
        EXPECT_MSG(texel_differ == 0 && textured == 32 * 32, "the quad updated to uv 0..2 differs at %d pixels (%d covered)",
                   texel_differ, textured);
        sy_gl_device_destroy(d);
    }

    if (prov == SY_GL_PROVIDER_OSMESA) {
        /* 8. shader compile failures return the driver's log */
        sy_gl_context *ctx;
        sy_gl_report rep = {gl_test_on_error, NULL, ""};
        MUST(sy_gl_context_create(SY_GL_PROVIDER_OSMESA, 0, 0, &ctx, &rep));
        GLuint p = 0;
        sy_gl_result r = sy_gl_program_build(sy_gl_context_fns(ctx), "broken", sy_gl_floor_vs,
                                             "#version 330 core\nout vec4 o; void main() { o = undefined_name; }\n", NULL, &p, &rep);
        EXPECT_MSG(r == SY_GL_ERROR_GL && strstr(rep.message, "broken shader: fragment compile failed") &&
                       strstr(rep.message, "undefined_name") && strcmp(rep.message, e) == 0,
                   "compile failure message: %s", rep.message);
        sy_gl_context_destroy(ctx);
        /* 9. the largest shadow_map_size the parameter allows (16384: four maps are 4 GiB, more
         * than llvmpipe gives one texture) renders with smaller maps and says so; it failed with
         * GL_OUT_OF_MEMORY before (issue 32). The maps are made by the first frame with a
         * shadowed light: creating the device, and a frame without lights, allocate none. */
        warnings = 0;
        sy_gl_device_desc bd = {GL_TEST_REPORT, .provider = SY_GL_PROVIDER_OSMESA, .msaa = 1, .shadow_map_size = 16384, .log = on_log};
        r = sy_gl_device_create(&bd, &d);
        EXPECT_MSG(r == SY_GL_OK, "shadow_map_size 16384: %s", e);
        if (r == SY_GL_OK) {
            sy_gl_camera top = {.camera_to_world = {1, 0, 0, 0, 0, 0, -1, 0, 0, 1, 0, 0, 0, 5, 0, 1}, .window = {-0.6f, 0.6f, -0.6f, 0.6f}, .near_clip = 0.1f};
            const float floor_q[12] = {-5, 0, 5, 5, 0, 5, 5, 0, -5, -5, 0, -5};
            const float occ_q[12] = {-0.5f, 1, 0.5f, 0.5f, 1, 0.5f, 0.5f, 1, -0.5f, -0.5f, 1, -0.5f};
            const float ny[3] = {0, 1, 0};
            sy_gl_material grey = material(d, 0.5f, 0.5f, 0.5f, 1, false, SY_GL_ALPHA_OPAQUE);
            gl_test_place(d, quad(d, floor_q, ny), grey);
            gl_test_place(d, quad(d, occ_q, ny), grey);
            render(d, &top);
            EXPECT_MSG(warnings == 0, "a frame without lights made shadow maps: %s", last_warning);
            sy_gl_light_desc ld = {.type = SY_GL_LIGHT_DIRECTIONAL, .color = {1, 1, 1}, .intensity = 3, .direction = {1, -1, 0}};
            sy_gl_light l;
            MUST(sy_gl_light_create(d, &ld, &l));
            render(d, &top);
            EXPECT_MSG(warnings == 1 && strstr(last_warning, "shadow_map_size 16384"), "shadow map warning (%d): %s", warnings,
                       last_warning);
            float lit = 3.0f * sqrtf(0.5f) * 0.5f / PI_F;
            EXPECT_MSG(near_(px(10, 31)[0], lit, 0.01f), "lit floor %g (want %g), smaller maps", px(10, 31)[0], lit);
            EXPECT_MSG(px(42, 31)[0] < 0.05f * lit, "shadowed floor %g (lit %g), smaller maps", px(42, 31)[0], lit);
            sy_gl_device_destroy(d);
        }
        /* 10. no display: GLFW names itself and the fallback */
        unsetenv("DISPLAY");
        unsetenv("WAYLAND_DISPLAY");
        sy_gl_device_desc gd = {GL_TEST_REPORT, .provider = SY_GL_PROVIDER_GLFW};
        r = sy_gl_device_create(&gd, &d);
        EXPECT_MSG(r == SY_GL_ERROR_NO_CONTEXT && strstr(e, "glfw") && strstr(e, "--gl osmesa"), "no-display error: %s", e);
        if (r == SY_GL_OK) sy_gl_device_destroy(d);
    }
    printf("test_gl_backend (%s):\n", sy_gl_provider_name(prov));
    return sy_check_finish("test_gl_backend");
}
