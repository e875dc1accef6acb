/* test_rt_look.c — "one scene, one look" in the ray tracers (issue 15), through the public sy_rt API,
 * for the PRIMARY, WHITTED and PATHTRACER integrators where it applies:
 *   - the background is what camera rays that hit nothing see (none, colour, a lat-long texture x
 *     intensity) and never lights anything: a Lambert sphere under a coloured / textured
 *     background alone is black;
 *   - the environment lights and is seen by reflections, never by camera rays: a mirror shows it
 *     exactly, the sky behind stays transparent; a uniform environment is a 1x1 texture: a white
 *     Lambert floor under it has radiance albedo x L (Whitted's importance-sampled environment
 *     light and the path tracer agree within 1 %);
 *   - emission adds to reflected light: an emissive Lambert quad under a point light shows
 *     emission + albedo / pi x E;
 *   - shadow rays: an opaque blocker casts a full shadow, an alpha-blended one (alpha 0.25) lets
 *     0.75 through, a transmissive one (transmission 1, base colour c, IOR 1.5) lets c x 0.96 through
 *     (Whitted; the path tracer the same for punctual lights);
 *   - Whitted anti-aliasing: 4 pixel samples give fractional coverage at edges, interior emitter
 *     pixels stay exact, the image is deterministic and quadrants stitch bit for bit;
 *   - Whitted's soft shadows use a per-pixel scrambled sample set: under a large area light the
 *     error of a 4-sample image against a 1024-sample one is uncorrelated between neighbouring
 *     pixels (a shared pattern shows as correlated bands). */
#include "rt_test.h"

#define PI_F 3.14159265358979f

/* 1x1 float texture of colour c. */
static sy_rt_texture const_texture(sy_rt_device *dev, const float c[3])
{
    sy_rt_texture_desc td = {.width = 1, .height = 1, .channels = 3, .format = SY_RT_TEXEL_FLOAT32, .pixels = c,
                             .wrap_t = SY_RT_WRAP_CLAMP};
    sy_rt_texture t;
    MUST(sy_rt_texture_create(dev, &td, &t));
    return t;
}

/* Renders with any integrator (the path tracer with spp samples into a fresh accumulation;
 * Whitted with spp pixel samples). max_depth 0 = the default. */
static void render_depth(sy_rt_device *dev, const sy_rt_camera *cam, sy_rt_integrator integ, uint32_t w, uint32_t h,
                         uint32_t spp, uint32_t max_depth, float **rgba, float **depth)
{
    sy_rt_render_desc d = rt_desc(integ, w, h);
    d.max_depth = max_depth;
    sy_rt_accum *acc = NULL;
    if (integ == SY_RT_INTEGRATOR_PATHTRACER) {
        MUST(sy_rt_accum_create(dev, w, h, &acc));
        d.accum = acc;
        d.samples = spp;
    } else if (integ == SY_RT_INTEGRATOR_WHITTED) {
        d.pixel_samples = spp;
    }
    rt_render(dev, cam, &d, rgba, depth);
    sy_rt_accum_destroy(acc);
}

static void render(sy_rt_device *dev, const sy_rt_camera *cam, sy_rt_integrator integ, uint32_t w, uint32_t h,
                   uint32_t spp, float **rgba, float **depth)
{
    render_depth(dev, cam, integ, w, h, spp, 0, rgba, depth);
}

/* A Lambert floor: quad of half size h in the XZ plane at y = 0, facing +Y. */
static void floor_xf(float xf[16], float h)
{
    rt_identity(xf);
    xf[0] = h;
    xf[5] = 0.0f, xf[6] = -h; /* local y -> world -z */
    xf[9] = 1.0f, xf[10] = 0.0f; /* local z -> world +y */
}

/* Camera at height y looking straight down, half-tangent t. */
static sy_rt_camera down_camera(float y, float t)
{
    sy_rt_camera cam = rt_camera(0.0f, t);
    memset(cam.camera_to_world, 0, sizeof cam.camera_to_world);
    cam.camera_to_world[0] = 1.0f;
    cam.camera_to_world[6] = -1.0f; /* camera y -> world -z */
    cam.camera_to_world[9] = 1.0f;  /* camera z -> world +y */
    cam.camera_to_world[13] = y;
    cam.camera_to_world[15] = 1.0f;
    return cam;
}

static void mean_rgb(const float *rgba, size_t n, double out[3])
{
    out[0] = out[1] = out[2] = 0.0;
    for (size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c) out[c] += rgba[4 * i + c];
    for (int c = 0; c < 3; ++c) out[c] /= (double)n;
}

static void test_background_never_lights(void)
{
    for (int mode = 0; mode < 2; ++mode) {
        sy_rt_device *dev = rt_device();
        rt_place(dev, rt_quad(dev, 1.0f), NULL, rt_lambert(dev, 0.8f, 0.8f, 0.8f), 0);
        const float c[3] = {0.3f, 0.6f, 0.9f};
        sy_rt_background bg = {.mode = SY_RT_BACKGROUND_COLOR, .color = {c[0], c[1], c[2]}};
        if (mode == 1) bg = (sy_rt_background){.mode = SY_RT_BACKGROUND_TEXTURE, .texture = const_texture(dev, c), .intensity = 2.0f};
        const float k = mode == 1 ? 2.0f : 1.0f;
        MUST(sy_rt_set_background(dev, &bg));
        MUST(sy_rt_commit(dev));
        sy_rt_camera cam = rt_camera(4.0f, 0.5f); /* the quad covers the middle half */
        for (int integ = SY_RT_INTEGRATOR_PRIMARY; integ <= SY_RT_INTEGRATOR_PATHTRACER; ++integ) {
            float *rgba, *depth;
            render(dev, &cam, (sy_rt_integrator)integ, 16, 16, 4, &rgba, &depth);
            const float *corner = rgba, *centre = rgba + 4 * (8 * 16 + 8);
            EXPECT_MSG(fabsf(corner[0] - k * c[0]) < 1e-6f && fabsf(corner[1] - k * c[1]) < 1e-6f &&
                       fabsf(corner[2] - k * c[2]) < 1e-6f && corner[3] == 1.0f,
                       "mode %d integrator %d: background pixel %g %g %g %g, expected %g %g %g 1", mode, integ, corner[0],
                       corner[1], corner[2], corner[3], k * c[0], k * c[1], k * c[2]);
            if (integ != SY_RT_INTEGRATOR_PRIMARY) /* eye-light shading lights everything */
                EXPECT_MSG(centre[0] == 0.0f && centre[1] == 0.0f && centre[2] == 0.0f && centre[3] == 1.0f,
                           "mode %d integrator %d: a surface lit by the background alone: %g %g %g %g", mode, integ, centre[0],
                           centre[1], centre[2], centre[3]);
            rt_image_free(rgba, depth);
        }
        sy_rt_device_destroy(dev);
    }
}

static void test_environment_is_a_light(void)
{
    const float L[3] = {0.5f, 1.0f, 2.0f};
    /* a mirror quad facing the camera reflects the environment exactly; misses stay transparent */
    {
        sy_rt_device *dev = rt_device();
        MUST(sy_rt_set_environment(dev, const_texture(dev, L), 1.5f));
        sy_rt_material mirror = rt_metal(dev, 1.0f, 1.0f, 1.0f, 0.0f); /* a perfect mirror */
        rt_place(dev, rt_quad(dev, 1.0f), NULL, mirror, 0);
        MUST(sy_rt_commit(dev));
        sy_rt_camera cam = rt_camera(4.0f, 0.5f);
        for (int integ = SY_RT_INTEGRATOR_WHITTED; integ <= SY_RT_INTEGRATOR_PATHTRACER; ++integ) {
            float *rgba, *depth;
            render(dev, &cam, (sy_rt_integrator)integ, 16, 16, 4, &rgba, &depth);
            const float *corner = rgba, *centre = rgba + 4 * (8 * 16 + 8);
            EXPECT_MSG(corner[0] == 0.0f && corner[1] == 0.0f && corner[2] == 0.0f && corner[3] == 0.0f,
                       "integrator %d: camera rays see the environment: %g %g %g %g", integ, corner[0], corner[1], corner[2],
                       corner[3]);
            for (int c = 0; c < 3; ++c)
                EXPECT_MSG(rt_near(centre[c], 1.5 * L[c], 1e-5), "integrator %d: mirror channel %d = %g, expected %g", integ, c,
                           centre[c], 1.5 * L[c]);
            rt_image_free(rgba, depth);
        }
        sy_rt_device_destroy(dev);
    }
    /* a white Lambert floor under the uniform environment: radiance = albedo x L */
    {
        sy_rt_device *dev = rt_device();
        MUST(sy_rt_set_environment(dev, const_texture(dev, L), 1.0f));
        float xf[16];
        floor_xf(xf, 100.0f);
        rt_place(dev, rt_quad(dev, 1.0f), xf, rt_lambert(dev, 0.7f, 0.7f, 0.7f), 0);
        MUST(sy_rt_commit(dev));
        sy_rt_camera cam = down_camera(1.0f, 0.2f);
        double m[2][3];
        for (int k = 0; k < 2; ++k) {
            sy_rt_integrator integ = k ? SY_RT_INTEGRATOR_PATHTRACER : SY_RT_INTEGRATOR_WHITTED;
            float *rgba, *depth;
            render(dev, &cam, integ, 32, 32, k ? 64 : 4, &rgba, &depth);
            mean_rgb(rgba, 32 * 32, m[k]);
            for (int c = 0; c < 3; ++c)
                EXPECT_MSG(rt_near(m[k][c], 0.7 * L[c], 0.01), "integrator %d: floor under the uniform environment, channel %d: "
                           "%.5f, expected %.5f", (int)integ, c, m[k][c], 0.7 * L[c]);
            rt_image_free(rgba, depth);
        }
        printf("uniform environment over a floor: whitted %.4f, pathtracer %.4f (x albedo L)\n", m[0][1] / 0.7 / L[1],
               m[1][1] / 0.7 / L[1]);
        sy_rt_device_destroy(dev);
    }
}

static void test_emission_adds(void)
{
    sy_rt_device *dev = rt_device();
    sy_rt_material_desc md;
    sy_rt_material_desc_init(&md);
    md.base_color[0] = md.base_color[1] = md.base_color[2] = 0.5f;
    md.metallic = 0.0f;
    md.specular = 0.0f;
    md.emissive[0] = 0.1f, md.emissive[1] = 0.2f, md.emissive[2] = 0.3f;
    sy_rt_material m = rt_material(dev, &md);
    rt_place(dev, rt_quad(dev, 1.0f), NULL, m, 0);
    sy_rt_light_desc ld = {.type = SY_RT_LIGHT_DIRECTIONAL, .color = {1, 1, 1}, .intensity = 3.0f, .direction = {0, 0, -1}};
    sy_rt_light l;
    MUST(sy_rt_light_create(dev, &ld, &l));
    MUST(sy_rt_commit(dev));
    sy_rt_camera cam = rt_camera(4.0f, 0.2f); /* inside the quad */
    for (int integ = SY_RT_INTEGRATOR_WHITTED; integ <= SY_RT_INTEGRATOR_PATHTRACER; ++integ) {
        float *rgba, *depth;
        render(dev, &cam, (sy_rt_integrator)integ, 8, 8, 256, &rgba, &depth);
        double mean[3];
        mean_rgb(rgba, 64, mean);
        for (int c = 0; c < 3; ++c) {
            double expect = md.emissive[c] + 0.5 / M_PI * 3.0;
            /* Whitted: exact; path tracer: light category chosen at random (area or punctual) */
            EXPECT_MSG(rt_near(mean[c], expect, integ == SY_RT_INTEGRATOR_WHITTED ? 1e-5 : 0.02),
                       "integrator %d channel %d: emissive surface under a light %.5f, expected emission + reflection %.5f",
                       integ, c, mean[c], expect);
        }
        rt_image_free(rgba, depth);
    }
    sy_rt_device_destroy(dev);
}

/* Floor under a directional light straight down with a blocker quad (material mat) between. */
static void shadow_case(const char *name, const sy_rt_material_desc *bd, const double expect[3], bool pt_too)
{
    sy_rt_device *dev = rt_device();
    float xf[16];
    floor_xf(xf, 10.0f);
    rt_place(dev, rt_quad(dev, 1.0f), xf, rt_lambert(dev, 1.0f, 1.0f, 1.0f), 0);
    sy_rt_material bm = rt_material(dev, bd);
    floor_xf(xf, 5.0f);
    xf[13] = 2.0f; /* the blocker at y = 2, facing up */
    rt_place(dev, rt_quad(dev, 1.0f), xf, bm, 0);
    sy_rt_light_desc ld = {.type = SY_RT_LIGHT_DIRECTIONAL, .color = {1, 1, 1}, .intensity = (float)M_PI, .direction = {0, -1, 0}};
    sy_rt_light l;
    MUST(sy_rt_light_create(dev, &ld, &l));
    MUST(sy_rt_commit(dev));
    /* camera between blocker and floor, looking down: sees the lit floor (radiance 1 unshadowed) */
    sy_rt_camera cam = down_camera(1.0f, 0.2f);
    for (int integ = SY_RT_INTEGRATOR_WHITTED; integ <= (pt_too ? SY_RT_INTEGRATOR_PATHTRACER : SY_RT_INTEGRATOR_WHITTED);
         ++integ) {
        float *rgba, *depth;
        /* direct light only: the path tracer would add light bounced between floor and blocker */
        render_depth(dev, &cam, (sy_rt_integrator)integ, 8, 8, 16, 1, &rgba, &depth);
        double mean[3];
        mean_rgb(rgba, 64, mean);
        for (int c = 0; c < 3; ++c)
            EXPECT_MSG(rt_near(mean[c], expect[c], 1e-4) || (expect[c] == 0 && mean[c] == 0),
                       "%s, integrator %d, channel %d: floor %.6f, expected %.6f", name, integ, c, mean[c], expect[c]);
        rt_image_free(rgba, depth);
    }
    sy_rt_device_destroy(dev);
}

static void test_shadows(void)
{
    sy_rt_material_desc d;
    sy_rt_material_desc_init(&d);
    d.metallic = 0.0f;
    const double opaque[3] = {0, 0, 0};
    shadow_case("opaque blocker", &d, opaque, true);
    d.alpha_mode = SY_RT_ALPHA_BLEND;
    d.base_color[3] = 0.25f;
    const double blend[3] = {0.75, 0.75, 0.75};
    shadow_case("alpha-blended blocker", &d, blend, true);
    sy_rt_material_desc_init(&d);
    d.metallic = 0.0f;
    d.transmission = 1.0f;
    d.roughness = 0.0f;
    d.base_color[0] = 0.5f, d.base_color[1] = 0.8f, d.base_color[2] = 1.0f;
    const double glass[3] = {0.5 * 0.96, 0.8 * 0.96, 0.96};
    shadow_case("transmissive blocker", &d, glass, true);
    sy_rt_material_desc_init(&d);
    d.alpha_mode = SY_RT_ALPHA_MASK;
    d.base_color[3] = 0.25f; /* below the cutoff everywhere: no shadow */
    const double mask[3] = {1, 1, 1};
    shadow_case("alpha-masked blocker", &d, mask, true);
}

static void test_whitted_antialiasing(void)
{
    sy_rt_device *dev = rt_device();
    sy_rt_material_desc ed;
    sy_rt_material_desc_init(&ed);
    ed.base_color[0] = ed.base_color[1] = ed.base_color[2] = 0.0f;
    ed.emissive[0] = 17, ed.emissive[1] = 12, ed.emissive[2] = 4;
    sy_rt_material em = rt_material(dev, &ed);
    float xf[16];
    rt_rot_y(xf, 0.0f, 0.0f, 0.0f, 0.0f);
    xf[0] = xf[5] = cosf(0.3f), xf[1] = sinf(0.3f), xf[4] = -sinf(0.3f); /* rotated about Z: slanted edges */
    rt_place(dev, rt_quad(dev, 1.0f), xf, em, 0);
    MUST(sy_rt_commit(dev));
    sy_rt_camera cam = rt_camera(4.0f, 0.5f);
    const uint32_t W = 32;
    float *a, *da, *b, *db;
    render(dev, &cam, SY_RT_INTEGRATOR_WHITTED, W, W, 4, &a, &da);
    render(dev, &cam, SY_RT_INTEGRATOR_WHITTED, W, W, 4, &b, &db);
    EXPECT_MSG(!memcmp(a, b, W * W * 4 * sizeof(float)), "Whitted with 4 pixel samples is not deterministic");
    uint32_t partial = 0, inner = 0, wrong = 0;
    double coverage = 0;
    for (uint32_t i = 0; i < W * W; ++i) {
        const float *p = a + 4 * i;
        coverage += p[3];
        if (p[3] > 0.0f && p[3] < 1.0f) {
            partial++;
            if (fabsf(p[0] - 17.0f * p[3]) > 1e-4f) wrong++; /* premultiplied */
        }
        if (p[3] == 1.0f) {
            inner++;
            if (!(p[0] == 17.0f && p[1] == 12.0f && p[2] == 4.0f)) wrong++;
        }
    }
    /* the quad covers 4 m^2 of the 4 x 4 m window at distance 4 (1/4 of the image) */
    coverage /= (double)(W * W);
    EXPECT_MSG(partial > 40 && inner > 100, "anti-aliasing: %u partial and %u inner pixels", partial, inner);
    EXPECT_MSG(wrong == 0, "%u pixels are not the emitter's radiance x coverage", wrong);
    EXPECT_MSG(fabs(coverage - 0.25) < 0.01, "mean coverage %.4f, expected 0.25", coverage);
    /* quadrants stitch */
    size_t diff = 0;
    for (uint32_t q = 0; q < 4; ++q) {
        sy_rt_render_desc d = rt_desc(SY_RT_INTEGRATOR_WHITTED, W, W);
        d.pixel_samples = 4;
        d.x = (q & 1) * W / 2, d.y = (q >> 1) * W / 2, d.width = d.height = W / 2;
        float *r, *dp;
        rt_render(dev, &cam, &d, &r, &dp);
        for (uint32_t y = 0; y < W / 2; ++y)
            diff += memcmp(r + 4 * y * (W / 2), a + 4 * ((d.y + y) * W + d.x), W / 2 * 4 * sizeof(float)) != 0;
        free(r);
        free(dp);
    }
    EXPECT_MSG(diff == 0, "%zu quadrant rows differ from the full image", diff);
    free(a), free(da), free(b), free(db);
    sy_rt_device_destroy(dev);
}

static void test_whitted_soft_shadow_noise(void)
{
    sy_rt_device *dev = rt_device();
    float xf[16];
    floor_xf(xf, 10.0f);
    rt_place(dev, rt_quad(dev, 1.0f), xf, rt_lambert(dev, 1.0f, 1.0f, 1.0f), 0);
    /* a 2 x 2 m emitter 2 m up facing down, and a thin occluder bar casting a wide penumbra */
    float lx[16];
    floor_xf(lx, 1.0f);
    lx[6] = 1.0f, lx[9] = -1.0f, lx[13] = 2.0f; /* facing down */
    rt_place(dev, rt_quad(dev, 1.0f), lx, rt_emitter(dev, 1.0f, 1.0f, 1.0f), 0);
    float bx[16];
    floor_xf(bx, 1.0f);
    bx[0] = 0.2f, bx[13] = 1.0f;
    bx[6] = -3.0f;
    rt_place(dev, rt_quad(dev, 1.0f), bx, rt_lambert(dev, 0.0f, 0.0f, 0.0f), 0);
    MUST(sy_rt_commit(dev));
    sy_rt_camera cam = down_camera(0.9f, 0.5f);
    const uint32_t W = 48;
    float *lo, *dl, *hi, *dh;
    sy_rt_render_desc d = rt_desc(SY_RT_INTEGRATOR_WHITTED, W, W);
    d.area_light_samples = 4;
    rt_render(dev, &cam, &d, &lo, &dl);
    d.area_light_samples = 1024;
    rt_render(dev, &cam, &d, &hi, &dh);
    /* correlation of the error between horizontal neighbours, over penumbra pixels */
    double sxy = 0, sxx = 0;
    uint32_t n = 0;
    for (uint32_t y = 0; y < W; ++y)
        for (uint32_t x = 0; x + 1 < W; ++x) {
            float r0 = hi[4 * (y * W + x)], r1 = hi[4 * (y * W + x + 1)];
            if (!(r0 > 0.02f && r1 > 0.02f)) continue;
            double e0 = lo[4 * (y * W + x)] - r0, e1 = lo[4 * (y * W + x + 1)] - r1;
            sxy += e0 * e1;
            sxx += e0 * e0;
            n++;
        }
    double corr = sxx > 0 ? sxy / sxx : 0;
    printf("soft shadow, 4 samples: neighbour error correlation %.3f over %u pixels\n", corr, n);
    EXPECT_MSG(n > 500, "only %u lit pixels", n);
    EXPECT_MSG(fabs(corr) < 0.2, "the errors of neighbouring pixels are correlated (%.3f): a shared sample pattern", corr);
    /* no bias: the 16-sample image's mean matches the 1024-sample one within 4 standard errors
     * of its own per-pixel noise (a wrong light pdf or a lost stratum is off by far more) */
    float *mid, *dm;
    d.area_light_samples = 16;
    rt_render(dev, &cam, &d, &mid, &dm);
    double es = 0, ess = 0, rs = 0;
    uint32_t m = 0;
    for (uint32_t i = 0; i < W * W; ++i) {
        if (!(hi[4 * i] > 0.02f)) continue;
        double e = mid[4 * i] - hi[4 * i];
        es += e, ess += e * e, rs += hi[4 * i], m++;
    }
    double se = sqrt(fmax(ess / m - (es / m) * (es / m), 0.0) / m) * m; /* standard error of the sum */
    printf("soft shadow, 16 samples: mean error %.4f %% (4 standard errors: %.4f %%)\n", 100.0 * es / rs,
           400.0 * se / rs);
    EXPECT_MSG(fabs(es) < 4.0 * se + 1e-4 * rs, "16-sample soft shadow mean differs from the 1024-sample one by %.3f %%",
               100.0 * es / rs);
    free(mid), free(dm);
    free(lo), free(dl), free(hi), free(dh);
    sy_rt_device_destroy(dev);
}

int main(void)
{
    test_background_never_lights();
    test_environment_is_a_light();
    test_emission_adds();
    test_shadows();
    test_whitted_antialiasing();
    test_whitted_soft_shadow_noise();
    return sy_check_finish("rt_look");
}
